// Hostile STEP/IGES input (issue 15): files corrupted by one byte, truncated, or with reals set to E+308/E+999 used
// to crash seam inside OpenCASCADE (SIGSEGV in StepToGeom, IGESGeom_BSplineSurface::Init, ...). Each must now be an
// error (exit 2, a message naming the file) or, where OpenCASCADE recovers part of the model, a warning saying what
// is missing; never a crash, and the input is never modified. Also `convert` to STEP of surfaces OpenCASCADE drops
// when writing (knots near 1e307, all control points equal, coordinates near 1e+-300): exit 2, nothing written.
// The files in tests/data/hostile_cad/ were made from ../shared/data/{step,iges} (fixed seed; see
// docs/reliability.md, "OpenCASCADE guards") and each crashed the Release build before the guards.
#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <csignal>
#if defined(SEAM_SANITIZED)  // the sanitizer build (AddressSanitizer with GCC or Clang)
#include <sanitizer/lsan_interface.h>
#endif
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <tuple>
#include <vector>

#include <nlohmann/json.hpp>

#include "seam/occt/brep_check.h"

namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

const fs::path kDir = fs::path(SEAM_TEST_DATA_DIR) / "hostile_cad";

struct RunResult {
  int exitCode = -1;  ///< -1 when the process did not exit normally (a crash)
  int signal = 0;     ///< the signal that ended it, if any
  std::string out;
  std::string err;
};

std::string shellQuote(const std::string& s) {
  std::string q = "'";
  for (const char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

std::string readText(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// `prefix`: a command the CLI runs under (taskset), through the shell like the rest.
RunResult run(const std::vector<std::string>& args, const std::string& prefix = "") {
  static int counter = 0;
  const fs::path errFile = fs::temp_directory_path() / fmt::format("seam_hostile_{}_{}.stderr", ::getpid(), counter++);
  std::string command = prefix + shellQuote(SEAM_CLI_PATH);
  for (const std::string& a : args) command += ' ' + shellQuote(a);
  command += " 2>" + shellQuote(errFile.string());
  RunResult r;
  FILE* pipe = ::popen(command.c_str(), "r");
  if (pipe == nullptr) return r;
  std::array<char, 4096> buffer{};
  size_t n = 0;
  while ((n = std::fread(buffer.data(), 1, buffer.size(), pipe)) > 0) r.out.append(buffer.data(), n);
  const int status = ::pclose(pipe);
  r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  // popen runs the command through sh: a crash shows as the shell's exit code 128 + signal.
  if (r.exitCode > 128) r.signal = r.exitCode - 128;
  if (WIFSIGNALED(status)) r.signal = WTERMSIG(status);
  r.err = readText(errFile);
  fs::remove(errFile);
  return r;
}

std::string describe(const RunResult& r) {
  return fmt::format("exit {} (signal {})\n--- stdout ---\n{}--- stderr ---\n{}", r.exitCode, r.signal, r.out,
                     r.err);
}

struct HostileCase {
  const char* file;
  int exitCode;              ///< expected for `info` and `check`
  const char* message;       ///< a fragment of the expected message on stderr
  const char* checkMessage;  ///< the same for `check` (the B-rep check) when it differs, else nullptr
};

// Expected outcomes: exit 2 where OpenCASCADE's reader reports the file as broken (or seam refuses it), exit 0 with
// a warning where OpenCASCADE recovers part of the model (the warning says how much is missing).
const HostileCase kCases[] = {
    // SIGSEGV in IGESGeom_BSplineSurface::Init while loading
    {"iges_bspline_init_crash.igs", 2, "reader reports", nullptr},
    // SIGSEGV while loading
    {"iges_flipped_byte_crash.igs", 2, "no shape or surface", nullptr},
    // SIGSEGV in the transfer
    {"iges_reals_e999_crash.igs", 2, "not a finite number", "no faces"},
    // SIGSEGV in StepToGeom::MakeCartesianPoint
    {"step_cartesian_point_crash.stp", 2, "reader reports", nullptr},
    // SIGSEGV in StepToGeom
    {"step_flipped_byte_crash.stp", 2, "reader reports", nullptr},
    // reals set to 1.5E+308: refused before shape healing
    {"step_reals_e308.stp", 2, "beyond", nullptr},
    // SIGSEGV while loading; now one root is lost, and said so
    {"iges_truncated_crash.igs", 0, "only 14 of 15 root entities", nullptr},
    // used to look clean with 3 faces of 7
    {"iges_truncated_3_of_7.igs", 0, "only 3 of 7 root entities", nullptr},
    // BUC50025.igs with one B-spline surface's upper indices K1, K2 set to 9999 (parameter line 30, "128,2,12,2,12,"
    // -> "128,9999,9999,"; its directory entry is "D      3"): OpenCASCADE allocated 10^8 poles and weights before
    // reading one (2.4 GB, the fuzzer's out-of-memory of the CI run of 2026-12-03); refused before it reads them
    {"iges_bspline_counts_oom.igs", 2, "type 128 (directory entry 3) declares", nullptr},
    // the fuzzer's mutation of the file above (seed 7, 508th input): the line that holds the counts is one byte too
    // long (81 columns, its section letter in column 74), and OpenCASCADE's line reader still gives the counts to
    // the entity; a split of the file by 80-column lines missed them
    {"iges_bspline_counts_long_line.igs", 2, "type 128 (directory entry 3) declares", nullptr},
};

class HostileCad : public ::testing::TestWithParam<HostileCase> {};

TEST_P(HostileCad, IsAnErrorOrAWarningNeverACrashAndTheInputIsUnchanged) {
  const HostileCase& c = GetParam();
  const fs::path file = kDir / c.file;
  ASSERT_TRUE(fs::is_regular_file(file)) << file;
  ASSERT_LT(fs::file_size(file), 200u * 1024u) << "hostile inputs stay small";
  const std::string before = readText(file);
  for (const char* command : {"info", "check"}) {
    const RunResult r = run({command, file.string()});
    SCOPED_TRACE(fmt::format("seam {} {}\n{}", command, c.file, describe(r)));
    EXPECT_EQ(r.signal, 0);
    EXPECT_EQ(r.exitCode, c.exitCode);
    EXPECT_THAT(r.err, HasSubstr(c.file));
    EXPECT_THAT(r.err, HasSubstr(std::string(command) == "check" && c.checkMessage ? c.checkMessage : c.message));
    if (c.exitCode == 2) {
      EXPECT_THAT(r.err, HasSubstr("seam: error:"));
    }
  }
  EXPECT_EQ(readText(file), before) << "the input was modified";
}

INSTANTIATE_TEST_SUITE_P(Files, HostileCad, ::testing::ValuesIn(kCases),
                         [](const ::testing::TestParamInfo<HostileCase>& param) {
                           std::string name = fs::path(param.param.file).stem().string();
                           for (char& ch : name)
                             if (ch == '.' || ch == '-') ch = '_';
                           return name;
                         });

// A model OpenCASCADE writes without its faces (it drops B-spline surfaces it cannot represent): `convert` reads
// the written file back, finds fewer faces than patches, and fails without leaving a file.
class HostileConvert : public ::testing::TestWithParam<const char*> {};

TEST_P(HostileConvert, ToStepFailsWhenFacesAreLostAndWritesNothing) {
  const fs::path in = kDir / GetParam();
  // In a folder of its own, so that no temporary of the writer (".seam-<pid>-<n>.tmp") can hide among others.
  const fs::path dir = fs::temp_directory_path() / fmt::format("seam_hostile_{}_{}", ::getpid(),
                                                                fs::path(GetParam()).stem().string());
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path out = dir / "out.step";
  const std::string before = readText(in);
  const RunResult r = run({"convert", in.string(), out.string()});
  SCOPED_TRACE(describe(r));
  EXPECT_EQ(r.signal, 0);
  EXPECT_EQ(r.exitCode, 2);
  EXPECT_THAT(r.err, HasSubstr(out.string()));
  EXPECT_FALSE(fs::exists(out)) << "a file without the faces was left";
  EXPECT_EQ(readText(in), before);
  // No temporary left beside it either.
  EXPECT_TRUE(fs::is_empty(dir)) << "a temporary was left in " << dir;
  fs::remove_all(dir);
}

INSTANTIATE_TEST_SUITE_P(Models, HostileConvert,
                         ::testing::Values("convert_knots_1e307.json", "convert_equal_points.json",
                                           "convert_coords_1e300.json"),
                         [](const ::testing::TestParamInfo<const char*>& param) {
                           return fs::path(param.param).stem().string();
                         });

// The guard does not change what a valid file gives: the same model with and without it is checked elsewhere
// (occt_cad_io_test); here, one valid file still reads cleanly (no warning) through the guarded path.
TEST(HostileCadControl, ValidFileReadsWithoutWarnings) {
  const fs::path file = fs::path(SEAM_SHARED_DATA_DIR) / "iges" / "BUC50025.igs";
  if (!fs::exists(file)) GTEST_SKIP() << file << " not present";
  const RunResult r = run({"info", file.string()});
  SCOPED_TRACE(describe(r));
  EXPECT_EQ(r.exitCode, 0);
  EXPECT_THAT(r.out, HasSubstr("7 patches"));
  EXPECT_THAT(r.err, ::testing::Not(HasSubstr("warning")));
}

// The B-rep check (sewing, BRepLib::ContinuityOfFaces, pcurves, surface evaluation) runs under the same guard as
// the reader: a segmentation fault raised while it runs comes back as an error naming the file, not a crash of
// the process. The fault is made by the progress callback, which the check calls inside its guarded block
// (OpenCASCADE cannot be made to crash on purpose); without the guard this test process dies of SIGSEGV.
TEST(HostileCadCheck, ASignalDuringTheBRepCheckIsAnError) {
  using namespace seam;
  const fs::path file = kDir / "iges_truncated_3_of_7.igs";
  occt::BRepCheckOptions options;
  int calls = 0;
  options.progress = [&](int, int, int) {
    ++calls;
    // SIGSEGV, delivered to this thread as a fault would be. A real null store would work too, but UBSan (the
    // sanitizer build) stops the process at the store, before any signal.
    std::raise(SIGSEGV);
  };
  // OpenCASCADE's signal conversion leaves the guarded block by longjmp, so the containers that the check had
  // built inside it (a few hundred bytes here) are never destroyed: a crash in a corrupt file costs that memory,
  // which LeakSanitizer would report. Allocations made while it is disabled are not reported.
#if defined(SEAM_SANITIZED)  // the sanitizer build (AddressSanitizer with GCC or Clang)
  __lsan_disable();
#endif
  const Result<occt::BRepCheckReport> r = occt::checkBRepFile(file, options);
#if defined(SEAM_SANITIZED)  // the sanitizer build (AddressSanitizer with GCC or Clang)
  __lsan_enable();
#endif
  EXPECT_EQ(calls, 1);
  ASSERT_FALSE(r.isOk());
  EXPECT_EQ(r.status().code(), ErrorCode::kInvalidInput);
  EXPECT_THAT(r.status().message(), HasSubstr(file.string()));
  EXPECT_THAT(r.status().message(),
              HasSubstr("OpenCASCADE crashed on this model (a defect of the file or of OpenCASCADE) during the B-rep "
                        "check"));
  // The guard is gone afterwards and the next check of the same file works, with the reader's warning passed on.
  const Result<occt::BRepCheckReport> again = occt::checkBRepFile(file);
  ASSERT_TRUE(again.isOk()) << again.status().message();
  EXPECT_EQ(again->import.model.patches.size(), 3u);
  EXPECT_THAT(again->import.warnings, ::testing::Contains(HasSubstr("only 3 of 7 root entities")));
  EXPECT_EQ(again->unanalysedEdges, 0);
}

}  // namespace

// Wall-clock limit (issue 15 §2): OpenCASCADE's shape healing can run for minutes on a corrupt file in code that
// never looks at a clock, so the CLI's watchdog ends the process with exit 2 and a message once --time-limit has
// passed. No corrupt file stalls deterministically (the stalls seen come from OpenCASCADE's reads of uninitialised
// memory, docs/reliability.md), so a valid file with a limit far below its reading time stands in for one: reading
// trj3 takes about 0.15 s, the limit is 1 ms.
TEST(HostileCadTimeLimit, AReadPastTheLimitStopsWithExitTwoAndWritesNothing) {
  const fs::path file = fs::path(SEAM_SHARED_DATA_DIR) / "step" / "trj3_s1-al-214.stp";
  if (!fs::exists(file)) GTEST_SKIP() << file << " not present";
  const std::string before = readText(file);
  const fs::path html = fs::temp_directory_path() / fmt::format("seam_time_limit_{}.html", ::getpid());
  fs::remove(html);
  const std::vector<std::vector<std::string>> commands{
      {"check", file.string(), "--time-limit", "0.001"},
      {"--time-limit", "0.001", "info", file.string()},  // before the command as well
      {"report", file.string(), "-o", html.string(), "--time-limit", "0.001"},
      {"check", file.string(), "--json", "--time-limit", "0.001"},
  };
  for (const std::vector<std::string>& args : commands) {
    const RunResult r = run(args);
    SCOPED_TRACE(describe(r));
    EXPECT_EQ(r.exitCode, 2);
    EXPECT_EQ(r.signal, 0);
    EXPECT_THAT(r.err, HasSubstr(file.string()));
    EXPECT_THAT(r.err, HasSubstr("took longer than the time limit of 0.001 s"));
    EXPECT_THAT(r.err, HasSubstr("--time-limit"));
    EXPECT_EQ(r.out, "");  // no partial table or JSON
  }
  EXPECT_FALSE(fs::exists(html));
  EXPECT_EQ(readText(file), before);
  // Without a limit (0), and with the default, the same file is checked.
  for (const std::vector<std::string>& args : {std::vector<std::string>{"check", file.string(), "--time-limit", "0"},
                                               std::vector<std::string>{"check", file.string()}}) {
    const RunResult r = run(args);
    SCOPED_TRACE(describe(r));
    EXPECT_LE(r.exitCode, 1);
    EXPECT_THAT(r.out, HasSubstr("seams"));
    EXPECT_THAT(r.err, ::testing::Not(HasSubstr("time limit")));
  }
}

// Issue 39 §1: --time-limit bounds the whole command, not only reading: `regularity` of linkrods (reading 0.6 s; the
// defect search on its two degree 6 x 8 faces with nearly singular points inside runs to its work budget, about
// 31 s on one core; trj3 took 57 s until pole sides were divided out of the search, and 0.55 s since; reading linkrods
// takes 3.6 s under the sanitizers on a busy machine, and the test requires that reading is not what the limit stops,
// so the limit is set from the reading time measured in the same run) and the B-rep `heal` of trj3 at the strict angle (about 9 s; at the CAD default angle of
// 0.5 deg it has fewer kinks to heal and finishes in under 4 s, so the strict angle keeps it well past its limit of
// 3 s) are stopped after reading, the message names the file and the stage (not "reading"), and the folder of the
// heal's output holds neither the output nor a temporary file. (The heal of the sunglasses lens, the issue's case, took 38 s; it takes 3 s since its joins are
// solved by sparse routes, so it no longer runs past the limit.)
TEST(HostileCadTimeLimit, TheLimitBoundsTheWholeCommandAndNamesTheStage) {
  const fs::path trj3 = fs::path(SEAM_SHARED_DATA_DIR) / "step" / "trj3_s1-al-214.stp";
  const fs::path linkrods = fs::path(SEAM_SHARED_DATA_DIR) / "step" / "linkrods.step";
  if (!fs::exists(trj3) || !fs::exists(linkrods)) GTEST_SKIP() << "real files not present";
  const fs::path dir = fs::temp_directory_path() / fmt::format("seam_whole_run_limit_{}", ::getpid());
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path out = dir / "healed.step";
  // On one core (taskset: the regularity search runs on all of TBB's threads, 7.5 s on two idle cores, which the
  // earlier limit of 10 s did not reach on an idle machine), with a limit of twice the time reading takes in this run
  // (`info` reads the same way) plus a second: past the reading on any machine and build, far below the search.
  const std::string oneCore = "taskset -c 0 ";
  const auto start = std::chrono::steady_clock::now();
  const RunResult info = run({"info", linkrods.string()}, oneCore);
  const double reading = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_EQ(info.exitCode, 0) << describe(info);
  const std::string readLimit = std::to_string(static_cast<int>(std::ceil(2.0 * reading + 1.0)));
  const std::vector<std::tuple<std::vector<std::string>, std::string, fs::path, std::string>> commands{
      {{"--time-limit", readLimit, "regularity", linkrods.string()}, readLimit, linkrods, oneCore},
      {{"heal", trj3.string(), "-o", out.string(), "--tol-angle", "0.01", "--time-limit", "3"}, "3", trj3, ""},
  };
  for (const auto& [args, limit, file, prefix] : commands) {
    const RunResult r = run(args, prefix);
    SCOPED_TRACE(describe(r));
    EXPECT_EQ(r.exitCode, 2);
    EXPECT_EQ(r.signal, 0);
    EXPECT_THAT(r.err, HasSubstr(file.string()));
    EXPECT_THAT(r.err, HasSubstr(fmt::format("took longer than the time limit of {} s", limit)));
    EXPECT_THAT(r.err, ::testing::Not(HasSubstr("reading the file took longer")));
  }
  EXPECT_TRUE(fs::is_empty(dir)) << "no output, no temporary file";
  fs::remove_all(dir);
}

TEST(HostileCadTimeLimit, ALimitThatIsNotANumberOfSecondsIsAUsageError) {
  for (const char* value : {"-1", "nan", "inf", "abc"}) {
    const RunResult r = run({"check", "x.step", "--time-limit", value});
    SCOPED_TRACE(describe(r));
    EXPECT_EQ(r.exitCode, 2);
    EXPECT_THAT(r.err, HasSubstr("--time-limit"));
  }
}

// ---------------------------------------------------------------------------------------------------------------
// A partly read file carries the reader's warning on every output (issue 39 goal 3): iges_truncated_3_of_7.igs
// lost 4 of its 7 root entities (made by truncating a file of 7 faces); `check` and `info` said so already (kCases);
// the table, the JSON, the HTML report and the batch rows now say it too.

TEST(HostileCadWarnings, EveryOutputOfAPartlyReadFileCarriesTheWarning) {
  const fs::path file = kDir / "iges_truncated_3_of_7.igs";
  const std::string warning = "only 3 of 7 root entities";
  const fs::path dir = fs::temp_directory_path() / fmt::format("seam_hostile_warnings_{}", ::getpid());
  fs::remove_all(dir);
  fs::create_directories(dir);
  {  // the table
    const RunResult r = run({"check", file.string()});
    SCOPED_TRACE(describe(r));
    EXPECT_EQ(r.signal, 0);
    EXPECT_THAT(r.out, HasSubstr("reader warnings (2)"));  // 4 entities failed to load; 3 of 7 roots
    EXPECT_THAT(r.out, HasSubstr(warning));
  }
  for (const bool patches : {false, true}) {  // the JSON, of the B-rep check and of the faces as patches
    std::vector<std::string> args{"check", file.string(), "--json"};
    if (patches) args.emplace_back("--patches");
    const RunResult r = run(args);
    SCOPED_TRACE(describe(r));
    const nlohmann::json j = nlohmann::json::parse(r.out, nullptr, false);
    ASSERT_TRUE(j.is_object());
    ASSERT_TRUE(j.contains("warnings"));
    ASSERT_EQ(j["warnings"].size(), 2u);
    EXPECT_THAT(j["warnings"][0].get<std::string>(), HasSubstr(file.string() + ": 4 entities of the IGES file failed"));
    EXPECT_THAT(j["warnings"][1].get<std::string>(), HasSubstr(warning));
    EXPECT_THAT(j["warnings"][1].get<std::string>(), HasSubstr(file.string()));
  }
  {  // the HTML report: exit 0, the warning on stderr and in a section of the page
    const fs::path html = dir / "report.html";
    const RunResult r = run({"report", file.string(), "-o", html.string()});
    SCOPED_TRACE(describe(r));
    EXPECT_EQ(r.exitCode, 0);
    EXPECT_THAT(r.err, HasSubstr("seam: warning:"));
    EXPECT_THAT(r.err, HasSubstr(warning));
    const std::string page = readText(html);
    EXPECT_THAT(page, HasSubstr("<h2 id=\"warnings\">Warnings (2)</h2>"));
    EXPECT_THAT(page, HasSubstr(warning));
  }
  {  // the batch row (JSON and table)
    const RunResult r = run({"batch", file.string(), "--json"});
    SCOPED_TRACE(describe(r));
    const nlohmann::json j = nlohmann::json::parse(r.out, nullptr, false);
    ASSERT_TRUE(j.is_object());
    const nlohmann::json& row = j["files"][0];
    ASSERT_EQ(row["warnings"].size(), 2u);
    EXPECT_THAT(row["warnings"][1].get<std::string>(), HasSubstr(warning));
    const RunResult t = run({"batch", file.string()});
    EXPECT_THAT(t.out, HasSubstr(file.string() + ": warning: only 3 of 7 root entities"));
    EXPECT_THAT(t.err, HasSubstr(warning));
  }
  fs::remove_all(dir);
}

// Export errors in the user's words (issue 39 goal 5): a patch OpenCASCADE cannot take is refused before it is
// handed over, with the output file, the patch and the reason; none of OpenCASCADE's own text, no temporary file.
TEST(HostileCadExport, PatchesOpenCascadeCannotTakeAreNamedWithTheReason) {
  const fs::path dir = fs::temp_directory_path() / fmt::format("seam_hostile_export_{}", ::getpid());
  fs::remove_all(dir);
  fs::create_directories(dir);
  // Degree 26 in u: a bezier of 27 x 2 points (OpenCASCADE's Geom_BSplineSurface::MaxDegree() is 25).
  std::string rows;
  for (int i = 0; i < 27; ++i) rows += fmt::format("{}[[{}, 0, 0], [{}, 1, 0]]", i == 0 ? "" : ", ", i, i);
  const std::string bilinear = R"("points": [[[0, 0, 0], [0, 1, 0]], [[1, 0, 0], [1, 1, 0]]])";
  struct Case {
    const char* name;
    std::string model;
    const char* reason;
  };
  std::vector<Case> cases = {
      {"degree26", R"({"patches": [{"name": "High", "type": "bezier", "points": [)" + rows + "]}]}",
       "u degree 26 is above 25"},
      {"tiny_weight",
       R"({"patches": [{"name": "Light", "type": "bezier", )" + bilinear +
           R"(, "weights": [[1, 1e-310], [1, 1]]}]})",
       "weight [0][1] = 1e-310 is too small"},
      {"ulp_knots",
       // A double knot at 0.5 whose two copies differ in the last bit (seam reads them as one knot of multiplicity 2).
       R"({"patches": [{"name": "Close", "type": "bspline", "degree": [2, 1], )"
       R"("knots": [[0, 0, 0, 0.5, 0.50000000000000011, 1, 1, 1], [0, 0, 1, 1]], )"
       R"("points": [[[0, 0, 0], [0, 1, 0]], [[1, 0, 0], [1, 1, 0]], [[2, 0, 0], [2, 1, 0]], [[3, 0, 0], [3, 1, 0]], )"
       R"([[4, 0, 0], [4, 1, 0]]]}]})",
       "u knots 3 (0.5) and 4 (0.5000000000000001) differ by one unit in the last place"},
  };
  // IGES only: a weight of 1e-10 (OpenCASCADE's IGES writer makes of it an entity its reader cannot transfer; 1e-9
  // is read back; STEP takes both).
  cases.push_back({"iges_weight",
                   R"({"patches": [{"name": "Faint", "type": "bezier", )" + bilinear +
                       R"(, "weights": [[1, 1e-10], [1, 1]]}]})",
                   "weight [0][1] = 1e-10 is too small for OpenCASCADE's IGES"});
  for (const Case& c : cases) {
    const fs::path in = dir / (std::string(c.name) + ".json");
    std::ofstream(in) << c.model;
    for (const char* ext : {".step", ".igs"}) {
      const fs::path out = dir / (std::string(c.name) + ext);
      if (std::string(c.name) == "iges_weight" && std::string(ext) == ".step") {
        EXPECT_EQ(run({"convert", in.string(), out.string()}).exitCode, 0);
        continue;
      }
      const RunResult r = run({"convert", in.string(), out.string()});
      SCOPED_TRACE(fmt::format("{} -> {}\n{}", c.name, ext, describe(r)));
      EXPECT_EQ(r.signal, 0);
      EXPECT_EQ(r.exitCode, 2);
      EXPECT_THAT(r.err, HasSubstr(out.string() + ": patch \""));
      EXPECT_THAT(r.err, HasSubstr(c.reason));
      EXPECT_THAT(r.err, ::testing::Not(HasSubstr("Geom_")));
      EXPECT_THAT(r.err, ::testing::Not(HasSubstr(".tmp")));
      EXPECT_FALSE(fs::exists(out));
    }
  }
  fs::remove_all(dir);
}
