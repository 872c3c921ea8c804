// seam batch DIR|GLOB... [--json] [-j N] [--timeout SEC] [--require G0|G1|G2] [--tol-* / --preset] [--patches]
// Checks many model files (.json, .bpt, .step/.stp, .iges/.igs): each file is `seam check FILE --json` in a child
// process of its own (OpenCASCADE's STEP/IGES readers keep global state, so files are not read on threads of one
// process; a file that crashes the reader or runs past --timeout costs only its own row), N children at a time.
// One line per file as it finishes (stderr), then the combined table (stdout), or with --json one object holding
// a row per file (the keys of seam.batch.check_file in the Python module) and the totals.
// Exit codes, the rule of `seam check` (docs/check-output.md, "Exit codes"): 0 every file read (and, with
// --require, every seam of every file meets it), 1 some file has a seam below --require (a seam whose analysis
// failed counts as below), 2 bad usage, no files, or some file unreadable / invalid / crashed / timed out. Without
// --require gaps and kinks are reported (status "problem") but do not change the exit code. A bad file never stops
// the batch.
#include <fcntl.h>
#include <fmt/format.h>
#include <glob.h>
#include <signal.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "cli_util.h"
#include "command_registry.h"
#include "seam/continuity/verdict.h"

extern char** environ;

namespace seam::cli {

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

struct BatchOptions {
  std::vector<std::string> inputs;
  bool json = false;
  int jobs = 0;  // 0: one per core
  double timeoutSec = 600.0;
  std::string require;
  ToleranceOverrides tol;
  bool patches = false;
};

bool isModelFile(const fs::path& p) {
  const std::string ext = lowerExtension(p);
  return ext == ".json" || ext == ".bpt" || isCadFile(p);
}

/// A file name or message on one line: a control character (a newline in a file name) as a C escape ("\\n",
/// "\\x1b"), a backslash doubled, so that a row is always one line.
std::string oneLine(std::string_view s) {
  std::string out;
  for (const char c : s) {
    const auto u = static_cast<unsigned char>(c);
    if (c == '\\') {
      out += "\\\\";
    } else if (c == '\n') {
      out += "\\n";
    } else if (c == '\r') {
      out += "\\r";
    } else if (c == '\t') {
      out += "\\t";
    } else if (u < 0x20 || u == 0x7f) {
      out += fmt::format("\\x{:02x}", u);
    } else {
      out += c;
    }
  }
  return out;
}

/// Why a path with a model file's name is not checked ("a FIFO", "a dangling symbolic link", "a symbolic link to
/// a character device (/dev/zero)"), or "" for a regular file (or a link to one).
std::string notARegularFile(const fs::path& p) {
  std::error_code ec;
  const fs::file_status link = fs::symlink_status(p, ec);
  if (ec) return "cannot be examined: " + ec.message();
  const bool isLink = fs::is_symlink(link);
  const fs::file_status target = isLink ? fs::status(p, ec) : link;
  if (isLink && (ec || !fs::exists(target))) return "a dangling symbolic link";
  if (fs::is_regular_file(target)) return "";
  std::string kind = fs::is_directory(target)           ? "a directory"
                     : fs::is_fifo(target)               ? "a FIFO"
                     : fs::is_character_file(target)     ? "a character device"
                     : fs::is_block_file(target)         ? "a block device"
                     : fs::is_socket(target)             ? "a socket"
                                                         : "not a regular file";
  if (!isLink) return kind;
  const fs::path to = fs::read_symlink(p, ec);
  return fmt::format("a symbolic link to {}{}", kind, ec ? "" : " (" + to.string() + ")");
}

/// The model files of the inputs (directories recursively, else glob patterns), sorted, without duplicates; an
/// input that names no model file is an error (a typo must not look like an empty, successful batch). A path with
/// a model file's name that is not a regular file (a FIFO, a device, a dangling link) is skipped with a warning.
std::optional<std::vector<std::string>> collectFiles(const std::vector<std::string>& inputs) {
  std::vector<std::string> files;
  auto consider = [&](const fs::path& p) {
    if (!isModelFile(p)) return;
    const std::string why = notARegularFile(p);
    if (why.empty()) {
      files.push_back(p.string());
    } else if (!fs::is_directory(p)) {
      std::cerr << fmt::format("seam: warning: {}: skipped: {}, not a regular file\n", oneLine(p.string()), why);
    }
  };
  for (const std::string& in : inputs) {
    size_t before = files.size();
    std::error_code ec;
    if (fs::is_directory(in, ec)) {
      for (auto it = fs::recursive_directory_iterator(in, fs::directory_options::skip_permission_denied, ec);
           !ec && it != fs::recursive_directory_iterator(); it.increment(ec)) {
        consider(it->path());
      }
    } else {
      glob_t g{};
      if (::glob(in.c_str(), 0, nullptr, &g) == 0)
        for (size_t k = 0; k < g.gl_pathc; ++k) consider(g.gl_pathv[k]);
      globfree(&g);
    }
    if (files.size() == before) {
      printError(fmt::format("{}: no .json/.bpt/.step/.stp/.iges/.igs files (a directory or a glob pattern)", in));
      return std::nullopt;
    }
  }
  std::sort(files.begin(), files.end());
  files.erase(std::unique(files.begin(), files.end()), files.end());
  return files;
}

/// One file's result: the row of the table and of --json.
struct Row {
  std::string file;
  std::string status = "error";  // ok, problem, error
  std::string error;
  int seams = 0;
  std::array<int, kSeamVerdictCount> verdicts{};  // gap, kink, crease, G1, G2, undetermined
  int failed = 0;                  // seams whose analysis failed (a degenerate edge: "collapses to a point")
  int belowRequired = 0;           // seams below --require (failed ones included); 0 without --require
  std::vector<std::string> warnings;  // the reader's (a partly read STEP/IGES file is never "ok" without them)
  std::optional<double> worstGap, worstAngleDeg;
  std::string unit;                    // the model's length unit ("mm"; "" for a unit-less model)
  std::optional<double> gapTolerance;  // the distance tolerance the gaps were judged by, in `unit`
  double seconds = 0.0;
};

constexpr const char* kVerdictKeys[kSeamVerdictCount] = {"gap", "kink", "crease", "G1", "G2", "undetermined"};

std::string readText(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// The last non-empty line of the child's stderr without the "seam: error: " prefix (the message of a bad file).
std::string lastError(const std::string& text) {
  std::istringstream in(text);
  std::string line, last;
  while (std::getline(in, line))
    if (!line.empty() && line.rfind("seam: warning", 0) != 0 && line.rfind("seam: note", 0) != 0) last = line;
  const std::string prefix = "seam: error: ";
  if (last.rfind(prefix, 0) == 0) last = last.substr(prefix.size());
  return last.empty() ? "no message" : last;
}

void fillFromJson(Row& row, const std::string& text, bool require) {
  const nlohmann::json j = nlohmann::json::parse(text, nullptr, false);
  if (j.is_discarded() || !j.is_object()) {
    row.error = "the check printed no JSON";
    return;
  }
  const nlohmann::json summary = j.value("summary", nlohmann::json::object());
  row.seams = summary.value("seams", 0);
  const nlohmann::json verdicts = summary.value("verdicts", nlohmann::json::object());
  for (size_t k = 0; k < kSeamVerdictCount; ++k) row.verdicts[k] = verdicts.value(kVerdictKeys[k], 0);
  auto number = [](const nlohmann::json& o, const char* key) -> std::optional<double> {
    if (!o.is_object() || !o.contains(key) || !o[key].is_number()) return std::nullopt;
    return o[key].get<double>();
  };
  row.worstGap = number(summary.value("worst_gap", nlohmann::json()), "gap");
  row.worstAngleDeg = number(summary.value("worst_kink", nlohmann::json()), "angle_deg");
  const nlohmann::json units = j.value("units", nlohmann::json::object());
  if (units.is_object() && units.contains("length") && units["length"].is_string())
    row.unit = units["length"].get<std::string>();
  row.gapTolerance = number(j.value("tolerances", nlohmann::json()), "distance");
  row.failed = summary.value("failed", 0);
  const nlohmann::json warnings = j.value("warnings", nlohmann::json::array());
  if (warnings.is_array())
    for (const nlohmann::json& w : warnings)
      if (w.is_string()) row.warnings.push_back(w.get<std::string>());
  row.belowRequired = require ? summary.value("below_required", 0) : 0;
  row.status = row.verdicts[0] > 0 || row.verdicts[1] > 0 || row.failed > 0 || row.belowRequired > 0 ? "problem" : "ok";
}

/// A running child: `seam check FILE --json` with stdout and stderr in temporary files.
struct Child {
  size_t index = 0;
  pid_t pid = -1;
  Clock::time_point start;
  fs::path out, err;
};

std::string selfExe() {
  std::error_code ec;
  const fs::path p = fs::read_symlink("/proc/self/exe", ec);
  return ec ? std::string() : p.string();
}

fs::path tempFile(const fs::path& dir, const char* stem) {
  std::string name = (dir / fmt::format("{}.XXXXXX", stem)).string();
  const int fd = ::mkstemp(name.data());
  if (fd >= 0) ::close(fd);
  return fd >= 0 ? fs::path(name) : fs::path();
}

std::optional<Child> spawnCheck(const std::string& exe, const std::vector<std::string>& extra, const Row& row,
                                size_t index, const fs::path& tmp, std::string& error) {
  Child c;
  c.index = index;
  c.out = tempFile(tmp, "out");
  c.err = tempFile(tmp, "err");
  if (c.out.empty() || c.err.empty()) {
    error = fmt::format("cannot create a temporary file in {}", tmp.string());
    return std::nullopt;
  }
  // The batch's own --timeout stops a child (and names the option): the child's --time-limit is off.
  std::vector<std::string> args{exe, "check", row.file, "--json", "--time-limit", "0"};
  args.insert(args.end(), extra.begin(), extra.end());
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, 1, c.out.c_str(), O_WRONLY | O_TRUNC, 0);
  posix_spawn_file_actions_addopen(&actions, 2, c.err.c_str(), O_WRONLY | O_TRUNC, 0);
  const int rc = posix_spawn(&c.pid, exe.c_str(), &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0) {
    error = fmt::format("cannot start {}: {}", exe, std::strerror(rc));
    return std::nullopt;
  }
  c.start = Clock::now();
  return c;
}

std::string number(const std::optional<double>& x) { return x ? formatNumber(*x) : "-"; }

/// A length of the row's model with its unit ("0.0012 mm"; the number alone for a unit-less model; "-" for none).
std::string length(const std::optional<double>& x, const Row& r) {
  return x && !r.unit.empty() ? formatNumber(*x) + " " + r.unit : number(x);
}

/// A warning of the row's file without the file name in front (the row names the file already).
std::string warningOf(const Row& r, const std::string& w) {
  const std::string prefix = r.file + ": ";
  return oneLine(w.rfind(prefix, 0) == 0 ? w.substr(prefix.size()) : w);
}

std::string rowLine(const Row& r) {
  if (r.status == "error") return fmt::format("{}: error: {}", oneLine(r.file), oneLine(r.error));
  std::string line =
      fmt::format("{}: {}: {} seams (gap {}, kink {}, crease {}, G1 {}, G2 {}{}{}), worst gap {}, worst kink {} deg, "
                  "gap tolerance {}, {:.2f} s",
                  oneLine(r.file), r.status, r.seams, r.verdicts[0], r.verdicts[1], r.verdicts[2], r.verdicts[3],
                  r.verdicts[4], r.verdicts[5] > 0 ? fmt::format(", undetermined {}", r.verdicts[5]) : "",
                  r.failed > 0 ? fmt::format(", failed {}", r.failed) : "", length(r.worstGap, r),
                  number(r.worstAngleDeg), length(r.gapTolerance, r), r.seconds);
  for (const std::string& w : r.warnings) line += "\n  warning: " + warningOf(r, w);
  return line;
}

OrderedJson rowJson(const Row& r) {
  auto opt = [](const std::optional<double>& x) { return x ? OrderedJson(*x) : OrderedJson(nullptr); };
  OrderedJson j{{"file", r.file},
                {"status", r.status},
                {"error", r.status == "error" ? OrderedJson(r.error) : OrderedJson(nullptr)},
                {"seams", r.seams}};
  for (size_t k = 0; k < kSeamVerdictCount; ++k) j[kVerdictKeys[k]] = r.verdicts[k];
  j["failed"] = r.failed;
  j["below_required"] = r.belowRequired;
  j["warnings"] = r.warnings;
  j["worst_gap"] = opt(r.worstGap);
  j["worst_angle_deg"] = opt(r.worstAngleDeg);
  j["length_unit"] = r.unit.empty() ? OrderedJson(nullptr) : OrderedJson(r.unit);
  j["gap_tolerance"] = opt(r.gapTolerance);
  j["seconds"] = r.seconds;
  return j;
}

int runBatch(const BatchOptions& o) {
  if (!validToleranceOptions(o.tol)) return kExitBadInput;
  if (!o.require.empty() && o.require != "G0" && o.require != "G1" && o.require != "G2") {
    printError(fmt::format("--require: \"{}\" is not G0, G1 or G2", o.require));
    return kExitBadInput;
  }
  if (!(o.timeoutSec > 0.0) || !std::isfinite(o.timeoutSec)) {
    printError("--timeout must be a positive number of seconds");
    return kExitBadInput;
  }
  if (o.jobs < 0) {
    printError("-j must be at least 1 (0: one per core)");
    return kExitBadInput;
  }
  const std::optional<std::vector<std::string>> files = collectFiles(o.inputs);
  if (!files) return kExitBadInput;
  const std::string exe = selfExe();
  if (exe.empty()) {
    printError("cannot find the seam executable (/proc/self/exe) to run the checks");
    return kExitBadInput;
  }
  std::vector<std::string> extra;
  auto addNumber = [&](const char* flag, const std::optional<double>& x) {
    if (x) extra.insert(extra.end(), {flag, fmt::format("{:.17g}", *x)});
  };
  addNumber("--tol-distance", o.tol.distance);
  addNumber("--tol-angle", o.tol.angleDeg);
  addNumber("--tol-curvature", o.tol.curvatureRel);
  if (!o.tol.preset.empty()) extra.insert(extra.end(), {"--preset", o.tol.preset});  // its distance, in mm
  if (o.tol.units) extra.insert(extra.end(), {"--units", lengthUnitInfo(*o.tol.units).name});
  if (o.tol.display) extra.insert(extra.end(), {"--display-units", lengthUnitInfo(*o.tol.display).name});
  if (!o.require.empty()) extra.insert(extra.end(), {"--require", o.require});
  if (o.patches) extra.emplace_back("--patches");
  const size_t jobs =
      o.jobs > 0 ? static_cast<size_t>(o.jobs) : std::max<size_t>(1, std::thread::hardware_concurrency());

  std::error_code ec;
  std::string tmpName = (fs::temp_directory_path(ec) / "seam-batch.XXXXXX").string();
  if (ec || ::mkdtemp(tmpName.data()) == nullptr) {
    printError("cannot create a temporary directory for the checks' output");
    return kExitBadInput;
  }
  const fs::path tmp = tmpName;

  std::vector<Row> rows(files->size());
  for (size_t k = 0; k < files->size(); ++k) rows[k].file = (*files)[k];
  std::vector<Child> running;
  size_t next = 0, done = 0;
  const auto batchStart = Clock::now();
  const auto timeout = std::chrono::duration<double>(o.timeoutSec);
  auto finish = [&](const Child& c, int status, bool timedOut) {
    Row& row = rows[c.index];
    row.seconds = std::chrono::duration<double>(Clock::now() - c.start).count();
    if (timedOut) {
      row.error = fmt::format("timed out after {} s (--timeout)", formatNumber(o.timeoutSec));
    } else if (WIFSIGNALED(status)) {
      row.error = fmt::format("the check crashed (signal {}: {})", WTERMSIG(status), strsignal(WTERMSIG(status)));
    } else if (WIFEXITED(status) && (WEXITSTATUS(status) == kExitOk || WEXITSTATUS(status) == kExitGeometryProblem)) {
      fillFromJson(row, readText(c.out), !o.require.empty());
    } else {
      row.error = lastError(readText(c.err));
    }
    fs::remove(c.out, ec);
    fs::remove(c.err, ec);
    ++done;
    std::cerr << fmt::format("[{}/{}] {}\n", done, rows.size(), rowLine(row));
  };
  while (done < rows.size()) {
    while (running.size() < jobs && next < rows.size()) {
      std::string error;
      std::optional<Child> c = spawnCheck(exe, extra, rows[next], next, tmp, error);
      if (!c) {
        rows[next].error = error;
        ++done;
        std::cerr << fmt::format("[{}/{}] {}\n", done, rows.size(), rowLine(rows[next]));
      } else {
        running.push_back(*c);
      }
      ++next;
    }
    bool reaped = false;
    for (auto it = running.begin(); it != running.end();) {
      int status = 0;
      const pid_t r = ::waitpid(it->pid, &status, WNOHANG);
      bool timedOut = false;
      if (r == 0 && Clock::now() - it->start > timeout) {
        ::kill(it->pid, SIGKILL);
        ::waitpid(it->pid, &status, 0);
        timedOut = true;
      } else if (r == 0) {
        ++it;
        continue;
      }
      finish(*it, status, timedOut);
      it = running.erase(it);
      reaped = true;
    }
    if (!reaped && !running.empty()) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  fs::remove_all(tmp, ec);
  const double seconds = std::chrono::duration<double>(Clock::now() - batchStart).count();

  int ok = 0, problem = 0, error = 0;
  for (const Row& r : rows) (r.status == "ok" ? ok : r.status == "problem" ? problem : error) += 1;
  if (o.json) {
    OrderedJson list = OrderedJson::array();
    for (const Row& r : rows) list.push_back(rowJson(r));
    printJson(OrderedJson{{"files", list},
                          {"summary", {{"files", rows.size()},
                                       {"ok", ok},
                                       {"problem", problem},
                                       {"error", error},
                                       {"jobs", jobs},
                                       {"seconds", seconds},
                                       {"files_per_second", static_cast<double>(rows.size()) / seconds}}}});
  } else {
    std::vector<std::vector<std::string>> table;
    for (const Row& r : rows) {
      if (r.status == "error") {
        table.push_back({oneLine(r.file), "error", "-", "-", "-", "-", "-", "-", "-", "-", "-", "-", "-",
                         fmt::format("{:.2f}", r.seconds)});
        continue;
      }
      std::vector<std::string> line{oneLine(r.file), r.status, std::to_string(r.seams)};
      for (int v : r.verdicts) line.push_back(std::to_string(v));
      line.insert(line.end(), {std::to_string(r.failed), std::to_string(r.warnings.size()), length(r.worstGap, r),
                               number(r.worstAngleDeg), length(r.gapTolerance, r), fmt::format("{:.2f}", r.seconds)});
      table.push_back(line);
    }
    fmt::print("{}", formatTable({"file", "status", "seams", "gap", "kink", "crease", "G1", "G2", "undetermined",
                                  "failed", "warnings", "worst gap", "worst kink (deg)", "gap tolerance", "seconds"},
                                 table,
                                 {false, false, true, true, true, true, true, true, true, true, true, true, true, true,
                                  true}));
    for (const Row& r : rows) {
      if (r.status == "error") fmt::print("{}: error: {}\n", oneLine(r.file), oneLine(r.error));
      for (const std::string& w : r.warnings) fmt::print("{}: warning: {}\n", oneLine(r.file), warningOf(r, w));
    }
    fmt::print("\n{} files: {} ok, {} with gaps, kinks or failed seams, {} unreadable; {:.2f} s with {} jobs ({:.3g} files/s)\n",
               rows.size(), ok, problem, error, seconds, jobs, static_cast<double>(rows.size()) / seconds);
  }
  const bool below = std::any_of(rows.begin(), rows.end(), [](const Row& r) { return r.belowRequired > 0; });
  return error > 0 ? kExitBadInput : below ? kExitGeometryProblem : kExitOk;
}

void addBatch(CLI::App& app, int& exit) {
  auto o = std::make_shared<BatchOptions>();
  CLI::App* cmd = app.add_subcommand("batch", "Check many model files, each in a child process, several at a time");
  cmd->add_option("INPUT", o->inputs,
                  "Directories (searched recursively) or glob patterns (quote them) of .json, .bpt, .step/.stp, "
                  ".iges/.igs files")
      ->required();
  cmd->add_flag("--json", o->json, "Print one JSON object (a row per file and the totals) instead of the table");
  cmd->add_option("-j,--jobs", o->jobs, "Files checked at once (default: one per core)")->type_name("N");
  cmd->add_option("--timeout", o->timeoutSec, "Seconds one file may take before its check is stopped (default 600)");
  cmd->add_option("--require", o->require, "A file with a seam below this class (G0, G1 or G2) is a problem");
  addToleranceOptions(*cmd, o->tol);
  addDisplayUnitsOption(*cmd, o->tol);
  cmd->add_flag("--patches", o->patches, "STEP/IGES: check the faces as patches instead of the B-rep edges");
  cmd->footer("Exit codes (as seam check): 0 every file read and, with --require, every seam meets it; 1 some seam is below "
              "--require (a failed seam counts as below); 2 bad usage or some file unreadable, invalid, crashed or timed "
              "out. Gaps and kinks alone make a file's status \"problem\", not the exit code.");
  cmd->callback([o, &exit]() {
    suspendRunTimeLimitUnlessGiven();  // each file has its own --timeout; the whole batch only a given --time-limit
    exit = runBatch(*o);
  });
}

}  // namespace

static CommandRegistrar registerBatch("batch", addBatch);

}  // namespace seam::cli
