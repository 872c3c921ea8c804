// Runs the seam binary (SEAM_CLI_PATH) and checks its output, its messages and its exit codes. Expected
// values are computed here by hand or by explicit Bernstein sums, never by the library.
#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "seam/version.h"

namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;
using ::testing::HasSubstr;
using ::testing::IsEmpty;
using ::testing::Not;

/// Relative tolerance for values the binary computes in floating point (a few round-offs of the data's
/// scale).
constexpr double kRelTol = 1e-13;

struct RunResult {
  int exitCode = -1;  ///< -1 when the process did not exit normally (crash)
  std::string out;
  std::string err;
};

std::string shellQuote(const std::string& s) {
  std::string q = "'";
  for (const char c : s) {
    if (c == '\'') {
      q += "'\\''";
    } else {
      q += c;
    }
  }
  return q + "'";
}

std::string readText(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// A fresh folder for one test (other engineers and ctest -j run tests at the same time).
class TempDir {
 public:
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path_ = fs::temp_directory_path() /
            fmt::format("seam_cli_test_{}_{}_{}", ::getpid(), info->test_suite_name(), info->name());
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempDir() { fs::remove_all(path_); }
  [[nodiscard]] const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

/// Runs `seam args...`, capturing stdout, stderr and the exit code.
RunResult run(const std::vector<std::string>& args) {
  static int counter = 0;
  const fs::path errFile =
      fs::temp_directory_path() / fmt::format("seam_cli_test_{}_{}.stderr", ::getpid(), counter++);
  std::string command = shellQuote(SEAM_CLI_PATH);
  for (const std::string& a : args) {
    command += ' ';
    command += shellQuote(a);
  }
  command += " 2>";
  command += shellQuote(errFile.string());
  RunResult result;
  FILE* pipe = ::popen(command.c_str(), "r");
  if (pipe == nullptr) return result;
  std::array<char, 4096> buffer{};
  size_t n = 0;
  while ((n = std::fread(buffer.data(), 1, buffer.size(), pipe)) > 0) result.out.append(buffer.data(), n);
  const int status = ::pclose(pipe);
  result.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  result.err = readText(errFile);
  fs::remove(errFile);
  return result;
}

std::string describe(const RunResult& r) {
  return fmt::format("exit {}\n--- stdout ---\n{}--- stderr ---\n{}", r.exitCode, r.out, r.err);
}

// ---------------------------------------------------------------------------------------------------------------
// The test model, and its values computed by hand.

using V3 = std::array<double, 3>;

// Bilinear patch "L" on [2,4] x [0,1]: S(u,v) = sum P_ij of the hat functions in s = (u-2)/2 and t = v.
constexpr V3 kL00 = {1.0 / 3.0, 0.1, 0.0};
constexpr V3 kL01 = {0.0, 2.0, 1.0};
constexpr V3 kL10 = {3.0, 0.0, 1.0};
constexpr V3 kL11 = {3.0, 2.0, 5.0};

// Bicubic Bezier patch "B": P_ij = (i, j, z_ij).
double bezierZ(int i, int j) { return 0.5 * ((7 * i + 3 * j) % 5) - 1.0 + 0.1 * i * j; }

// Rational quadratic quarter circle "Q" (2-D): weights 1, c, 1 with c the double nearest to sqrt(2)/2.
constexpr double kC = 0.7071067811865476;

Json testModel() {
  Json l = {{"name", "L"},
            {"type", "bspline"},
            {"degree", {1, 1}},
            {"knots", {{2, 2, 4, 4}, {0, 0, 1, 1}}},
            {"points", {{kL00, kL01}, {kL10, kL11}}}};
  Json b = {{"name", "B"}, {"type", "bezier"}, {"points", Json::array()}};
  for (int i = 0; i < 4; ++i) {
    Json row = Json::array();
    for (int j = 0; j < 4; ++j) row.push_back({i, j, bezierZ(i, j)});
    b["points"].push_back(row);
  }
  // "K": degree 2 x 1 with a double interior u knot (2 spans) and one interior v knot (2 spans).
  Json k = {{"name", "K"},
            {"type", "bspline"},
            {"degree", {2, 1}},
            {"knots", {{0, 0, 0, 0.5, 0.5, 1, 1, 1}, {0, 0, 0.25, 1, 1}}},
            {"points", Json::array()}};
  for (int i = 0; i < 5; ++i) {
    Json row = Json::array();
    for (int j = 0; j < 3; ++j) row.push_back({i, j, -1.0});
    k["points"].push_back(row);
  }
  Json q = {
      {"name", "Q"}, {"type", "bezier"}, {"points", {{1, 0}, {1, 1}, {0, 1}}}, {"weights", {1.0, kC, 1.0}}};
  Json poly = {{"name", "Poly"},
               {"type", "bspline"},
               {"degree", 1},
               {"knots", {0, 0, 1, 2, 2}},
               {"points", {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}}}};
  return {{"patches", {l, b, k}}, {"curves", {q, poly}}};
}

/// Writes the test model (or any text) into `dir` and returns its path.
std::string writeModel(const TempDir& dir, const std::string& name = "model.json",
                       const std::string& text = testModel().dump(2)) {
  const fs::path file = dir.path() / name;
  std::ofstream(file, std::ios::binary) << text;
  return file.string();
}

/// d^k/dx^k of the cubic Bernstein polynomial B_i^3 at x, written out term by term.
double bernstein3(int i, int k, double x) {
  const double y = 1.0 - x;
  switch (k) {
    case 0: {
      const double b[] = {y * y * y, 3 * x * y * y, 3 * x * x * y, x * x * x};
      return b[i];
    }
    case 1: {
      const double b[] = {-3 * y * y, 3 * y * y - 6 * x * y, 6 * x * y - 3 * x * x, 3 * x * x};
      return b[i];
    }
    case 2: {
      const double b[] = {6 * y, -12 + 18 * x, 6 - 18 * x, 6 * x};
      return b[i];
    }
    case 3: {
      const double b[] = {-6, 18, -18, 6};
      return b[i];
    }
    default:
      return 0.0;
  }
}

/// d^{k+l} B / du^k dv^l of patch "B" by the explicit Bernstein sum.
V3 bezierDerivative(int k, int l, double u, double v) {
  V3 s = {0, 0, 0};
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 4; ++j) {
      const double w = bernstein3(i, k, u) * bernstein3(j, l, v);
      s[0] += w * i;
      s[1] += w * j;
      s[2] += w * bezierZ(i, j);
    }
  }
  return s;
}

void expectNear(const Json& actual, const V3& expected, double scale, const std::string& what) {
  ASSERT_TRUE(actual.is_array()) << what << ": " << actual.dump();
  ASSERT_EQ(actual.size(), 3u) << what;
  for (size_t c = 0; c < 3; ++c) {
    EXPECT_NEAR(actual[c].get<double>(), expected[c], kRelTol * scale) << what << " coordinate " << c;
  }
}

Json parseJson(const RunResult& r) {
  try {
    return Json::parse(r.out);
  } catch (const Json::exception& e) {
    ADD_FAILURE() << "stdout is not JSON: " << e.what() << "\n" << describe(r);
    return Json();
  }
}

// ---------------------------------------------------------------------------------------------------------------
// Version, help, usage

TEST(Cli, VersionPrintsTheVersion) {
  const RunResult r = run({"--version"});
  EXPECT_EQ(r.exitCode, 0) << describe(r);
  EXPECT_EQ(r.out, fmt::format("seam {}\n", seam::kVersion));
}

TEST(Cli, HelpListsTheCommands) {
  const RunResult r = run({"--help"});
  EXPECT_EQ(r.exitCode, 0) << describe(r);
  EXPECT_THAT(r.out, HasSubstr("info"));
  EXPECT_THAT(r.out, HasSubstr("eval"));
  EXPECT_THAT(r.out, HasSubstr("Exit codes"));
  EXPECT_LT(r.out.find("eval"), r.out.find("info")) << "commands are listed sorted by name";
}

TEST(Cli, CommandHelp) {
  const RunResult info = run({"info", "--help"});
  EXPECT_EQ(info.exitCode, 0) << describe(info);
  EXPECT_THAT(info.out, HasSubstr("--json"));
  const RunResult eval = run({"eval", "--help"});
  EXPECT_EQ(eval.exitCode, 0) << describe(eval);
  for (const char* option : {"--patch", "--uv", "--curve", "--t", "--derivs", "--json"}) {
    EXPECT_THAT(eval.out, HasSubstr(option));
  }
}

TEST(Cli, ASubcommandIsRequired) {
  const RunResult r = run({});
  EXPECT_EQ(r.exitCode, 2) << describe(r);
  EXPECT_THAT(r.err, HasSubstr("subcommand"));
}

TEST(Cli, UnknownCommandIsBadUsage) {
  const RunResult r = run({"frobnicate", "x.json"});
  EXPECT_EQ(r.exitCode, 2) << describe(r);
  EXPECT_THAT(r.err, Not(IsEmpty()));
}

// ---------------------------------------------------------------------------------------------------------------
// info

TEST(CliInfo, Table) {
  TempDir dir;
  const std::string file = writeModel(dir);
  const RunResult r = run({"info", file});
  ASSERT_EQ(r.exitCode, 0) << describe(r);
  EXPECT_THAT(r.err, IsEmpty());
  EXPECT_THAT(r.out, HasSubstr(file + ": 3 patches, 2 curves"));
  // One row per object: kind, name, type, degree, points, spans, rational.
  EXPECT_THAT(r.out, ::testing::ContainsRegex("patch +L +bspline +1x1 +2x2 +1x1 +no "));
  EXPECT_THAT(r.out, ::testing::ContainsRegex("patch +B +bezier +3x3 +4x4 +1x1 +no "));
  EXPECT_THAT(r.out, ::testing::ContainsRegex("patch +K +bspline +2x1 +5x3 +2x2 +no "));
  EXPECT_THAT(r.out, ::testing::ContainsRegex("curve +Q +bezier +2 +3 +1 +yes "));
  EXPECT_THAT(r.out, ::testing::ContainsRegex("curve +Poly +bspline +1 +3 +2 +no "));
}

TEST(CliInfo, Json) {
  TempDir dir;
  const std::string file = writeModel(dir);
  const RunResult r = run({"info", file, "--json"});
  ASSERT_EQ(r.exitCode, 0) << describe(r);
  const Json j = parseJson(r);
  ASSERT_TRUE(j.is_object());
  EXPECT_EQ(j["file"], file);
  ASSERT_EQ(j["patches"].size(), 3u);
  ASSERT_EQ(j["curves"].size(), 2u);

  const Json& l = j["patches"][0];
  EXPECT_EQ(l["name"], "L");
  EXPECT_EQ(l["type"], "bspline");
  EXPECT_EQ(l["degree"], Json({1, 1}));
  EXPECT_EQ(l["points"], Json({2, 2}));
  EXPECT_EQ(l["spans"], Json({1, 1}));
  EXPECT_EQ(l["rational"], false);
  EXPECT_EQ(l["domain"]["u"], Json({2.0, 4.0}));
  EXPECT_EQ(l["domain"]["v"], Json({0.0, 1.0}));
  // Box of the four control points, by hand.
  EXPECT_EQ(l["bbox"]["min"], Json({0.0, 0.0, 0.0}));
  EXPECT_EQ(l["bbox"]["max"], Json({3.0, 2.0, 5.0}));

  const Json& b = j["patches"][1];
  EXPECT_EQ(b["type"], "bezier");
  EXPECT_EQ(b["degree"], Json({3, 3}));
  EXPECT_EQ(b["points"], Json({4, 4}));

  const Json& k = j["patches"][2];
  EXPECT_EQ(k["degree"], Json({2, 1}));
  EXPECT_EQ(k["points"], Json({5, 3}));
  EXPECT_EQ(k["spans"], Json({2, 2}));
  EXPECT_EQ(k["bbox"]["min"], Json({0.0, 0.0, -1.0}));
  EXPECT_EQ(k["bbox"]["max"], Json({4.0, 2.0, -1.0}));

  const Json& q = j["curves"][0];
  EXPECT_EQ(q["name"], "Q");
  EXPECT_EQ(q["type"], "bezier");
  EXPECT_EQ(q["degree"], 2);
  EXPECT_EQ(q["points"], 3);
  EXPECT_EQ(q["dimension"], 2);
  EXPECT_EQ(q["rational"], true);
  EXPECT_EQ(q["domain"], Json({0.0, 1.0}));
  EXPECT_EQ(q["bbox"]["max"], Json({1.0, 1.0, 0.0}));

  const Json& poly = j["curves"][1];
  EXPECT_EQ(poly["type"], "bspline");
  EXPECT_EQ(poly["spans"], 2);
  EXPECT_EQ(poly["domain"], Json({0.0, 2.0}));

  // All control points: x in [0, 4], y in [0, 3] (B has j up to 3), z in [-1, 5].
  double zMin = -1.0;
  for (int i = 0; i < 4; ++i) {
    for (int jj = 0; jj < 4; ++jj) zMin = std::min(zMin, bezierZ(i, jj));
  }
  const Json& s = j["summary"];
  EXPECT_EQ(s["patches"], 3);
  EXPECT_EQ(s["curves"], 2);
  EXPECT_EQ(s["bbox"]["min"], Json({0.0, 0.0, zMin}));
  EXPECT_EQ(s["bbox"]["max"], Json({4.0, 3.0, 5.0}));
  EXPECT_NEAR(s["diagonal"].get<double>(), std::sqrt(16.0 + 9.0 + (5.0 - zMin) * (5.0 - zMin)), kRelTol * 10);
}

TEST(CliInfo, TeapotBpt) {
  const RunResult r = run({"info", std::string(SEAM_SHARED_DATA_DIR) + "/bezier/teapot.bpt", "--json"});
  ASSERT_EQ(r.exitCode, 0) << describe(r);
  const Json j = parseJson(r);
  ASSERT_EQ(j["patches"].size(), 32u);
  EXPECT_EQ(j["patches"][0]["name"], "P0");
  EXPECT_EQ(j["patches"][31]["type"], "bezier");
  EXPECT_EQ(j["summary"]["bbox"]["max"][2], 3.15);
}

// ---------------------------------------------------------------------------------------------------------------
// eval

TEST(CliEval, BilinearPatchJson) {
  TempDir dir;
  const std::string file = writeModel(dir);
  const RunResult r = run({"eval", file, "--patch", "L", "--uv", "3", "0.25", "--derivs", "2", "--json"});
  ASSERT_EQ(r.exitCode, 0) << describe(r);
  const Json j = parseJson(r);
  // s = (u - 2) / 2 = 0.5, t = 0.25.
  const double s = 0.5;
  const double t = 0.25;
  V3 point{};
  V3 du{};
  V3 dv{};
  V3 duv{};
  for (size_t c = 0; c < 3; ++c) {
    point[c] = (1 - s) * (1 - t) * kL00[c] + (1 - s) * t * kL01[c] + s * (1 - t) * kL10[c] + s * t * kL11[c];
    du[c] = 0.5 * ((1 - t) * (kL10[c] - kL00[c]) + t * (kL11[c] - kL01[c]));  // ds/du = 1/2
    dv[c] = (1 - s) * (kL01[c] - kL00[c]) + s * (kL11[c] - kL10[c]);
    duv[c] = 0.5 * (kL11[c] - kL10[c] - kL01[c] + kL00[c]);
  }
  expectNear(j["point"], point, 5.0, "point");
  const Json& d = j["derivatives"];
  const nlohmann::ordered_json ordered = nlohmann::ordered_json::parse(r.out);
  std::vector<std::string> keys;
  for (const auto& [key, value] : ordered["derivatives"].items()) keys.push_back(key);
  EXPECT_EQ(keys, (std::vector<std::string>{"1,0", "0,1", "2,0", "1,1", "0,2"}))
      << "keys in order of total order";
  expectNear(d["1,0"], du, 5.0, "d/du");
  expectNear(d["0,1"], dv, 5.0, "d/dv");
  expectNear(d["1,1"], duv, 5.0, "d2/dudv");
  expectNear(d["2,0"], {0, 0, 0}, 5.0, "d2/du2");
  expectNear(d["0,2"], {0, 0, 0}, 5.0, "d2/dv2");
}

TEST(CliEval, JsonKeepsFullPrecision) {
  // At the corner (u, v) = (2, 0) the point is the control point (1/3, 0.1, 0) exactly; it must come back
  // bit-identical through the printed JSON.
  TempDir dir;
  const std::string file = writeModel(dir);
  const RunResult r = run({"eval", file, "--patch", "L", "--uv", "2", "0", "--json"});
  ASSERT_EQ(r.exitCode, 0) << describe(r);
  const Json j = parseJson(r);
  EXPECT_EQ(j["point"][0].get<double>(), 1.0 / 3.0);
  EXPECT_EQ(j["point"][1].get<double>(), 0.1);
  EXPECT_EQ(j["point"][2].get<double>(), 0.0);
  EXPECT_TRUE(j["derivatives"].is_object());
  EXPECT_TRUE(j["derivatives"].empty());
}

TEST(CliEval, BezierPatchMatchesBernsteinSums) {
  TempDir dir;
  const std::string file = writeModel(dir);
  const double u = 0.3;
  const double v = 0.6;
  const RunResult r = run({"eval", file, "--patch", "B", "--uv", "0.3", "0.6", "--derivs", "3", "--json"});
  ASSERT_EQ(r.exitCode, 0) << describe(r);
  const Json j = parseJson(r);
  const double scale = 100.0;  // derivatives of order 3 reach about 6 * 3^2 x the coordinates (<= 4)
  expectNear(j["point"], bezierDerivative(0, 0, u, v), scale, "point");
  ASSERT_EQ(j["derivatives"].size(), 9u);
  for (int order = 1; order <= 3; ++order) {
    for (int k = 0; k <= order; ++k) {
      const std::string key = fmt::format("{},{}", k, order - k);
      ASSERT_TRUE(j["derivatives"].contains(key)) << key;
      expectNear(j["derivatives"][key], bezierDerivative(k, order - k, u, v), scale, key);
    }
  }
}

TEST(CliEval, Table) {
  TempDir dir;
  const std::string file = writeModel(dir);
  const RunResult r = run({"eval", file, "--patch", "L", "--uv", "3", "0.25", "--derivs", "1"});
  ASSERT_EQ(r.exitCode, 0) << describe(r);
  // By hand: S(3, 0.25) = (1.625, 0.5375, 1.125); S_u = 0.5 (0.75 (P10 - P00) + 0.25 (P11 - P01)) =
  // (1.375, -0.0375, 0.875).
  EXPECT_THAT(r.out, ::testing::ContainsRegex("point +1.625 +0.5375 +1.125\n"));
  EXPECT_THAT(r.out, ::testing::ContainsRegex("1,0 +1.375 +-0.0375 +0.875\n"));
  EXPECT_THAT(r.out, HasSubstr("0,1 "));
}

TEST(CliEval, RationalCurve) {
  TempDir dir;
  const std::string file = writeModel(dir);
  const double t = 0.3;
  const RunResult r = run({"eval", file, "--curve", "Q", "--t", "0.3", "--derivs", "2", "--json"});
  ASSERT_EQ(r.exitCode, 0) << describe(r);
  const Json j = parseJson(r);
  // C = N / W with N = (1-t)^2 P0 + 2t(1-t) c P1 + t^2 P2 and W = (1-t)^2 + 2t(1-t) c + t^2; quotient rule.
  const double p[3][2] = {{1, 0}, {1, 1}, {0, 1}};
  const double b[3] = {(1 - t) * (1 - t), 2 * t * (1 - t) * kC, t * t};
  const double b1[3] = {-2 * (1 - t), 2 * (1 - 2 * t) * kC, 2 * t};
  const double b2[3] = {2, -4 * kC, 2};
  const double w = b[0] + b[1] + b[2];
  const double w1 = b1[0] + b1[1] + b1[2];
  const double w2 = b2[0] + b2[1] + b2[2];
  ASSERT_EQ(j["point"].size(), 2u);
  for (size_t c = 0; c < 2; ++c) {
    const double n = b[0] * p[0][c] + b[1] * p[1][c] + b[2] * p[2][c];
    const double n1 = b1[0] * p[0][c] + b1[1] * p[1][c] + b1[2] * p[2][c];
    const double n2 = b2[0] * p[0][c] + b2[1] * p[1][c] + b2[2] * p[2][c];
    const double value = n / w;
    const double d1 = (n1 - w1 * value) / w;
    const double d2 = (n2 - 2 * w1 * d1 - w2 * value) / w;
    EXPECT_NEAR(j["point"][c].get<double>(), value, kRelTol);
    EXPECT_NEAR(j["derivatives"]["1"][c].get<double>(), d1, 10 * kRelTol);
    EXPECT_NEAR(j["derivatives"]["2"][c].get<double>(), d2, 100 * kRelTol);
  }
  // And the point is on the unit circle (c is sqrt(2)/2 rounded, so up to round-off).
  EXPECT_NEAR(std::hypot(j["point"][0].get<double>(), j["point"][1].get<double>()), 1.0, kRelTol);
}

TEST(CliEval, PolylineCurve) {
  TempDir dir;
  const std::string file = writeModel(dir);
  const RunResult r = run({"eval", file, "--curve", "Poly", "--t", "1.5", "--derivs", "1", "--json"});
  ASSERT_EQ(r.exitCode, 0) << describe(r);
  const Json j = parseJson(r);
  // Second segment from (1,0,0) at t = 1 to (1,1,0) at t = 2.
  EXPECT_EQ(j["point"], Json({1.0, 0.5, 0.0}));
  EXPECT_EQ(j["derivatives"]["1"], Json({0.0, 1.0, 0.0}));
  const RunResult table = run({"eval", file, "--curve", "Poly", "--t", "1.5"});
  ASSERT_EQ(table.exitCode, 0) << describe(table);
  EXPECT_THAT(table.out, ::testing::ContainsRegex("point +1 +0.5 +0\n"));
}

TEST(CliEval, ExampleModel) {
  const std::string file = std::string(SEAM_EXAMPLES_DIR) + "/models/two_patches.json";
  const RunResult info = run({"info", file, "--json"});
  ASSERT_EQ(info.exitCode, 0) << describe(info);
  const Json j = parseJson(info);
  EXPECT_EQ(j["summary"]["patches"], 3);
  EXPECT_EQ(j["summary"]["curves"], 1);
  EXPECT_EQ(j["patches"][0]["spans"], Json({2, 1}));  // the interior double knot makes 2 spans along u
  EXPECT_EQ(j["patches"][2]["rational"], true);

  // The quarter cylinder: axis x = 0, y = 3, radius 1, height 0..1.
  const RunResult q = run({"eval", file, "--patch", "QuarterCylinder", "--uv", "0.3", "0.7", "--json"});
  ASSERT_EQ(q.exitCode, 0) << describe(q);
  const Json p = parseJson(q)["point"];
  EXPECT_NEAR(std::hypot(p[0].get<double>(), p[1].get<double>() - 3.0), 1.0, 10 * kRelTol);
  EXPECT_NEAR(p[2].get<double>(), 0.7, kRelTol);

  // A and B share an edge: A(1, v) = B(0, v).
  for (const char* v : {"0", "0.3", "0.8", "1"}) {
    const Json a = parseJson(run({"eval", file, "--patch", "A", "--uv", "1", v, "--json"}))["point"];
    const Json b = parseJson(run({"eval", file, "--patch", "B", "--uv", "0", v, "--json"}))["point"];
    ASSERT_EQ(a.size(), 3u);
    ASSERT_EQ(b.size(), 3u);
    for (size_t c = 0; c < 3; ++c) EXPECT_NEAR(a[c].get<double>(), b[c].get<double>(), 10 * kRelTol) << v;
  }
}

// ---------------------------------------------------------------------------------------------------------------
// Errors: exit code 2 and a message on stderr.

void expectBadInput(const RunResult& r, const std::string& messagePart) {
  EXPECT_EQ(r.exitCode, 2) << describe(r);
  EXPECT_THAT(r.err, HasSubstr(messagePart)) << describe(r);
}

TEST(CliErrors, MissingFile) {
  TempDir dir;
  const std::string file = (dir.path() / "absent.json").string();
  const RunResult info = run({"info", file});
  expectBadInput(info, file + ": cannot read file: no such file");
  EXPECT_THAT(info.out, IsEmpty());
  expectBadInput(run({"eval", file, "--patch", "L", "--uv", "0", "0"}), file);
}

TEST(CliErrors, MalformedJson) {
  TempDir dir;
  const std::string file = writeModel(dir, "broken.json", "{\"patches\": [");
  expectBadInput(run({"info", file}), file + ": not valid JSON: parse error at line 1, column 14");
}

TEST(CliErrors, InvalidModel) {
  TempDir dir;
  Json j = testModel();
  j["patches"][0]["knots"][0] = {2, 2, 4};
  const std::string file = writeModel(dir, "invalid.json", j.dump());
  expectBadInput(
      run({"info", file, "--json"}),
      file + ": patch \"L\": u knot vector has 3 entries, expected 4 for 2 control points of degree 1");
}

TEST(CliErrors, UnsupportedFormat) {
  TempDir dir;
  const std::string step = writeModel(dir, "part.step", "ISO-10303-21;");
#ifdef SEAM_HAVE_OCCT_CLI
  expectBadInput(run({"info", step}), step + ": not a readable STEP file");  // read through OpenCASCADE
#else
  expectBadInput(run({"info", step}), "STEP/IGES support needs a build with SEAM_WITH_OCCT");
#endif
  const std::string txt = writeModel(dir, "notes.txt", "hello");
  expectBadInput(run({"info", txt}), "unsupported file extension \".txt\"");
}

TEST(CliErrors, UnknownPatchOrCurve) {
  TempDir dir;
  const std::string file = writeModel(dir);
  expectBadInput(run({"eval", file, "--patch", "Nope", "--uv", "0", "0"}),
                 file + ": no patch named \"Nope\" (patches: L, B, K)");
  expectBadInput(run({"eval", file, "--curve", "L", "--t", "0"}),
                 file + ": no curve named \"L\" (curves: Q, Poly)");
}

TEST(CliErrors, ParameterOutsideTheDomain) {
  TempDir dir;
  const std::string file = writeModel(dir);
  expectBadInput(run({"eval", file, "--patch", "L", "--uv", "1", "0.5"}),
                 file + ": patch \"L\": u = 1 is outside the parameter domain [2, 4]");
  expectBadInput(run({"eval", file, "--patch", "L", "--uv", "3", "-0.5"}),
                 file + ": patch \"L\": v = -0.5 is outside the parameter domain [0, 1]");
  expectBadInput(run({"eval", file, "--curve", "Poly", "--t", "2.5"}),
                 file + ": curve \"Poly\": t = 2.5 is outside the parameter domain [0, 2]");
  const RunResult nan = run({"eval", file, "--patch", "L", "--uv", "nan", "0.5"});
  EXPECT_EQ(nan.exitCode, 2) << describe(nan);
  EXPECT_THAT(nan.err, Not(IsEmpty()));
}

TEST(CliErrors, NegativeDerivativeOrder) {
  TempDir dir;
  const std::string file = writeModel(dir);
  expectBadInput(run({"eval", file, "--patch", "L", "--uv", "3", "0.5", "--derivs", "-1"}), "--derivs -1");
  expectBadInput(run({"eval", file, "--patch", "L", "--uv", "3", "0.5", "--derivs", "1000"}),
                 "--derivs 1000");
}

TEST(CliErrors, BadUsage) {
  TempDir dir;
  const std::string file = writeModel(dir);
  const std::vector<std::vector<std::string>> cases = {
      {"eval", file, "--patch", "L"},                                                // --patch needs --uv
      {"eval", file, "--uv", "0", "0"},                                              // --uv needs --patch
      {"eval", file, "--patch", "L", "--uv", "0"},                                   // two values
      {"eval", file, "--patch", "L", "--uv", "0", "x"},                              // not a number
      {"eval", file, "--patch", "L", "--uv", "3", "0", "--curve", "Q", "--t", "0"},  // both
      {"eval", file},                                                                // nothing to evaluate
      {"eval", "--patch", "L", "--uv", "3", "0"},                                    // no FILE
      {"info"},                                                                      // no FILE
      {"info", file, "--bogus"},                                                     // unknown option
      {"eval", file, "--patch", "L", "--uv", "3", "0", "--derivs", "two"},
  };
  for (const auto& args : cases) {
    const RunResult r = run(args);
    EXPECT_EQ(r.exitCode, 2) << fmt::format("{}", fmt::join(args, " ")) << "\n" << describe(r);
    EXPECT_THAT(r.err, Not(IsEmpty())) << fmt::format("{}", fmt::join(args, " "));
  }
}

// Minor refusals of issue 39 §5 (each: exit 2 and a message naming the problem).
TEST(CliErrors, TimeLimitIsADecimalNumber) {
  TempDir dir;
  const std::string file = writeModel(dir);
  // CLI11 reads "0x10" as 16 and "0b11" as 3: refused, as are words and negative numbers.
  for (const char* bad : {"0x10", "0X1A", "0b11", "ten", "-1", "inf", "nan", ""}) {
    const RunResult r = run({"--time-limit", bad, "info", file});
    EXPECT_EQ(r.exitCode, 2) << bad << "\n" << describe(r);
    EXPECT_THAT(r.err, HasSubstr("--time-limit")) << bad;
  }
  for (const char* good : {"16", "0", "1.5", "1e3"}) {
    const RunResult r = run({"--time-limit", good, "info", file});
    EXPECT_EQ(r.exitCode, 0) << good << "\n" << describe(r);
  }
}

TEST(CliErrors, ExportMeshPerSpanIsBounded) {
  TempDir dir;
  const std::string file = writeModel(dir);
  const std::string out = (dir.path() / "m.obj").string();
  const RunResult big = run({"export-mesh", file, "-o", out, "--per-span", "1024"});
  expectBadInput(big, "--per-span");
  EXPECT_FALSE(fs::exists(out));
  EXPECT_EQ(run({"export-mesh", file, "-o", out, "--per-span", "64"}).exitCode, 0);
  fs::remove(out);
  // The whole mesh is bounded too: 2 000 patches of one span at 64 cells per direction are 8.45 M vertices.
  std::string text = R"({"patches": [)";
  for (int k = 0; k < 2000; ++k)
    text += fmt::format(R"({}{{"name": "P{}", "type": "bezier", "points": [[[0,0,{}],[1,0,0]],[[0,1,0],[1,1,0]]]}})",
                        k == 0 ? "" : ",", k, k);
  const std::string many = writeModel(dir, "many.json", text + "]}");
  const RunResult r = run({"export-mesh", many, "-o", out, "--per-span", "64"});
  expectBadInput(r, many + ": --per-span 64 would make a mesh of 8450000 vertices");
  EXPECT_FALSE(fs::exists(out));
}

}  // namespace
