// The two routes of the JSON model reader (src/io/json.cpp, issue 16 goal 4): the fast route (simdjson's DOM) and
// the nlohmann route go through one converter; the fast route declines anything that is not a valid model, so every
// message stays the nlohmann route's. Tests: random model texts (numbers spelt in many ways, duplicate keys,
// whitespace) give bit-identical Models on both routes and the doubles strtod gives for the same literals; every
// hostile input gives the same message through parseModelJson as through the nlohmann route; the fast route is
// taken for valid files. The streamed route of readModelJson (issue 37 goal 4: a file read in chunks, one element at
// a time) gives the same models where it reads one, and declines everything else.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>
#include <nlohmann/json.hpp>
#include "io/json_read.h"
#include "seam/io/json.h"
#include "seam/model/brep.h"
#include "seam/model/model.h"

namespace seam {
namespace {

namespace fs = std::filesystem;

std::string readText(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::uint64_t bits(double x) { return std::bit_cast<std::uint64_t>(x); }

void expectSameValues(const double* a, const double* b, Eigen::Index n, const std::string& what) {
  for (Eigen::Index k = 0; k < n; ++k) {
    EXPECT_EQ(bits(a[k]), bits(b[k])) << what << " [" << k << "]: " << a[k] << " vs " << b[k];
  }
}

void expectSameModel(const Model& a, const Model& b) {
  ASSERT_EQ(a.patches.size(), b.patches.size());
  for (size_t k = 0; k < a.patches.size(); ++k) {
    const BSplineSurface& p = a.patches[k].surface;
    const BSplineSurface& q = b.patches[k].surface;
    const std::string& name = a.patches[k].name;
    EXPECT_EQ(name, b.patches[k].name);
    EXPECT_EQ(a.patches[k].kind, b.patches[k].kind) << name;
    ASSERT_EQ(p.degreeU(), q.degreeU()) << name;
    ASSERT_EQ(p.degreeV(), q.degreeV()) << name;
    ASSERT_EQ(p.numU(), q.numU()) << name;
    ASSERT_EQ(p.numV(), q.numV()) << name;
    ASSERT_EQ(p.knotsU().values().size(), q.knotsU().values().size()) << name;
    ASSERT_EQ(p.knotsV().values().size(), q.knotsV().values().size()) << name;
    expectSameValues(p.knotsU().values().data(), q.knotsU().values().data(),
                     static_cast<Eigen::Index>(p.knotsU().values().size()), name + " u knots");
    expectSameValues(p.knotsV().values().data(), q.knotsV().values().data(),
                     static_cast<Eigen::Index>(p.knotsV().values().size()), name + " v knots");
    ASSERT_EQ(p.points().size(), q.points().size()) << name;
    expectSameValues(p.points().data(), q.points().data(), p.points().size(), name + " points");
    ASSERT_EQ(p.weights().size(), q.weights().size()) << name;
    expectSameValues(p.weights().data(), q.weights().data(), p.weights().size(), name + " weights");
  }
  ASSERT_EQ(a.curves.size(), b.curves.size());
  for (size_t k = 0; k < a.curves.size(); ++k) {
    const BSplineCurve& c = a.curves[k].curve;
    const BSplineCurve& d = b.curves[k].curve;
    const std::string& name = a.curves[k].name;
    EXPECT_EQ(name, b.curves[k].name);
    ASSERT_EQ(c.degree(), d.degree()) << name;
    ASSERT_EQ(c.dim(), d.dim()) << name;
    ASSERT_EQ(c.knots().values().size(), d.knots().values().size()) << name;
    expectSameValues(c.knots().values().data(), d.knots().values().data(),
                     static_cast<Eigen::Index>(c.knots().values().size()), name + " knots");
    ASSERT_EQ(c.points().size(), d.points().size()) << name;
    expectSameValues(c.points().data(), d.points().data(), c.points().size(), name + " points");
    ASSERT_EQ(c.weights().size(), d.weights().size()) << name;
    expectSameValues(c.weights().data(), d.weights().data(), c.weights().size(), name + " weights");
  }
}

/// Both routes on `text`: when the fast route reads a model, the nlohmann route reads the same one; the public
/// function gives exactly the nlohmann route's result. Returns whether the fast route was taken.
/// `text` written to a file of the test's own and read by the streamed route (readModelJson's first).
std::optional<Model> streamedFromFile(const std::string& text, const std::string& source) {
  const fs::path file = fs::temp_directory_path() / fmt::format("seam_json_read_test_{}.json", ::getpid());
  {
    std::ofstream os(file, std::ios::binary);
    os << text;
  }
  std::optional<Model> m = io::detail::readModelJsonStreamed(file, source);
  fs::remove(file);
  return m;
}

bool expectSameOnBothRoutes(const std::string& text, const std::string& source) {
  const std::optional<Model> fast = io::detail::parseModelJsonFast(text, source);
  const std::optional<Model> streamed = streamedFromFile(text, source);
  const Result<Model> slow = io::detail::parseModelJsonNlohmann(text, source);
  const Result<Model> pub = io::parseModelJson(text, source);
  EXPECT_EQ(pub.isOk(), slow.isOk());
  if (fast) {
    EXPECT_TRUE(slow.isOk()) << "the fast route read a model that the nlohmann route refuses: "
                             << slow.status().message();
    if (slow) expectSameModel(*fast, *slow);
  }
  if (streamed) {
    EXPECT_TRUE(slow.isOk()) << "the streamed route read a model that the nlohmann route refuses: "
                             << slow.status().message();
    if (slow) expectSameModel(*streamed, *slow);
    EXPECT_TRUE(fast.has_value()) << "the streamed route read a model that the fast route declines";
  }
  if (slow && pub) {
    expectSameModel(*pub, *slow);
  } else if (!slow && !pub) {
    EXPECT_EQ(pub.status().message(), slow.status().message());
    EXPECT_EQ(pub.status().code(), slow.status().code());
  }
  return fast.has_value();
}

// ---------------------------------------------------------------------------------------------------------------
// Random model texts, written by the test with numbers spelt in many ways; the expected value of every number is
// strtod of its literal (glibc's correctly rounded conversion), an independent route.

class TextGen {
 public:
  explicit TextGen(std::uint32_t seed) : rng_(seed) {}

  /// A number literal and its value. `positive`: > 0 (weights); `integral`: an integer literal.
  std::string number(double& value, bool positive = false) {
    std::string s;
    const int kind = pick(12);
    const double x = std::uniform_real_distribution<double>(-1000.0, 1000.0)(rng_);
    switch (kind) {
      case 0: s = fmt::format("{}", x); break;                   // shortest round trip
      case 1: s = fmt::format("{:.17g}", x); break;               // 17 digits
      case 2: s = fmt::format("{:.25e}", x); break;               // more digits than a double holds
      case 3: s = fmt::format("{:.3E}", x); break;                // capital E
      case 4: s = fmt::format("{}", static_cast<long long>(x)); break;  // integer literal
      case 5: s = pick(2) ? "-0" : "-0.0"; break;
      case 6: s = fmt::format("{}", std::bit_cast<double>(
                                    (rng_() | std::uint64_t{rng_()} << 32) & 0x000fffffffffffffULL));
        break;  // subnormal
      case 7: s = fmt::format("{}e{}", static_cast<int>(x), pick(600) - 300); break;
      case 8: s = fmt::format("{}", static_cast<std::uint64_t>(rng_()) << 31 | rng_()); break;  // big integer
      case 9: s = "9007199254740993"; break;                        // 2^53 + 1, not a double
      case 10: s = fmt::format("0.{}e-5", rng_()); break;
      default: s = fmt::format("{:.{}f}", x, pick(20)); break;
    }
    if (positive) {
      if (s[0] == '-') s = s.substr(1);
      if (std::strtod(s.c_str(), nullptr) <= 0.0) s = "1e-3";
    }
    value = std::strtod(s.c_str(), nullptr);
    if (s == "-0") value = 0.0;  // an integer literal: integer 0 on both parsers, read as +0.0 (as before)
    return s;
  }

  std::string ws() {
    static const char* const kSpaces[] = {"", " ", "\n", "\t", " \r\n  "};
    return kSpaces[pick(5)];
  }

  /// A clamped knot vector of `count` knots for degree p (non-decreasing by construction).
  std::string knots(int p, int count, std::vector<double>& values) {
    std::string s = "[";
    const int inner = count - 2 * (p + 1);
    values.clear();
    const double scale = 0.1 * (1 + pick(30));
    for (int k = 0; k < count; ++k) {
      const int level = k <= p ? 0 : (k >= count - p - 1 ? inner + 1 : k - p);
      const std::string lit = fmt::format("{}", level * scale);
      values.push_back(std::strtod(lit.c_str(), nullptr));
      s += (k ? "," : "") + ws() + lit;
    }
    return s + "]";
  }

  int pick(int n) { return std::uniform_int_distribution<int>(0, n - 1)(rng_); }

  std::mt19937 rng_;
};

/// A random model text; `expected` gets the strtod value of every point coordinate and weight in file order.
std::string randomModelText(TextGen& g, std::vector<double>& expected) {
  std::string s = "{" + g.ws() + "\"patches\":" + g.ws() + "[";
  const int patches = 1 + g.pick(4);
  for (int n = 0; n < patches; ++n) {
    const bool bezier = g.pick(3) == 0;
    const int p = 1 + g.pick(3);
    const int q = 1 + g.pick(3);
    const int nu = bezier ? p + 1 : p + 1 + g.pick(3);
    const int nv = bezier ? q + 1 : q + 1 + g.pick(3);
    const bool rational = g.pick(2) == 0;
    std::string obj = fmt::format("{{\"name\":\"P{}\",{}\"type\":\"{}\"", n, g.ws(), bezier ? "bezier" : "bspline");
    if (g.pick(4) == 0) obj += fmt::format(",\"name\":\"dup{}\"", n);  // a repeated key: nlohmann keeps the last
    obj += ",\"points\":[";
    for (int i = 0; i < nu; ++i) {
      obj += i ? ",[" : "[";
      for (int j = 0; j < nv; ++j) {
        obj += j ? ",[" : "[";
        for (int c = 0; c < 3; ++c) {
          double v = 0.0;
          obj += (c ? "," : "") + g.ws() + g.number(v);
          expected.push_back(v);
        }
        obj += "]";
      }
      obj += "]";
    }
    obj += "]";
    if (rational) {
      obj += ",\"weights\":[";
      for (int i = 0; i < nu; ++i) {
        obj += i ? ",[" : "[";
        for (int j = 0; j < nv; ++j) {
          double v = 0.0;
          obj += (j ? "," : "") + g.number(v, true);
          expected.push_back(v);
        }
        obj += "]";
      }
      obj += "]";
    }
    if (!bezier) {
      std::vector<double> ku;
      std::vector<double> kv;
      obj += fmt::format(",\"degree\":[{},{}]", p, q);
      obj += ",\"knots\":[" + g.knots(p, nu + p + 1, ku) + "," + g.knots(q, nv + q + 1, kv) + "]";
    }
    s += (n ? "," : "") + g.ws() + obj + "}";
  }
  s += "]";
  if (g.pick(2)) {
    s += ",\"curves\":[";
    const int curves = 1 + g.pick(3);
    for (int n = 0; n < curves; ++n) {
      const int p = 1 + g.pick(3);
      const int count = p + 1 + g.pick(4);
      const int dim = 2 + g.pick(2);
      std::string obj = fmt::format("{{\"name\":\"C{}\",\"type\":\"bspline\",\"degree\":{},\"points\":[", n, p);
      for (int i = 0; i < count; ++i) {
        obj += i ? ",[" : "[";
        for (int c = 0; c < dim; ++c) {
          double v = 0.0;
          obj += (c ? "," : "") + g.number(v);
          expected.push_back(v);
        }
        obj += "]";
      }
      std::vector<double> k;
      obj += "],\"knots\":" + g.knots(p, count + p + 1, k);
      s += (n ? "," : "") + obj + "}";
    }
    s += "]";
  }
  return s + g.ws() + "}" + g.ws();
}

/// Every point coordinate and weight of a model read from randomModelText, in file order.
std::vector<double> valuesInFileOrder(const Model& m) {
  std::vector<double> out;
  for (const Patch& patch : m.patches) {
    const BSplineSurface& s = patch.surface;
    const Eigen::Index n = static_cast<Eigen::Index>(s.numU()) * s.numV();
    for (Eigen::Index r = 0; r < n; ++r) {
      for (Eigen::Index c = 0; c < 3; ++c) out.push_back(s.points()(r, c));
    }
    for (Eigen::Index r = 0; r < s.weights().size(); ++r) out.push_back(s.weights()[r]);
  }
  for (const Curve& curve : m.curves) {
    for (Eigen::Index r = 0; r < curve.curve.points().rows(); ++r) {
      for (Eigen::Index c = 0; c < curve.curve.dim(); ++c) out.push_back(curve.curve.points()(r, c));
    }
  }
  return out;
}

TEST(JsonReadRoutes, RandomModelTextsGiveBitIdenticalModelsOnBothRoutes) {
  TextGen g(20261126);
  constexpr int kModels = 300;
  int fastTaken = 0;
  for (int k = 0; k < kModels; ++k) {
    SCOPED_TRACE(fmt::format("model {}", k));
    std::vector<double> expected;
    const std::string text = randomModelText(g, expected);
    const std::optional<Model> fast = io::detail::parseModelJsonFast(text, "random.json");
    const Result<Model> slow = io::detail::parseModelJsonNlohmann(text, "random.json");
    ASSERT_TRUE(slow.isOk()) << slow.status().message() << "\n" << text;
    ASSERT_TRUE(fast.has_value()) << text;
    ++fastTaken;
    expectSameModel(*fast, *slow);
    // Independent route: strtod of each literal. Non-rational surfaces keep no weights, so compare per value.
    const std::vector<double> got = valuesInFileOrder(*fast);
    ASSERT_EQ(got.size(), expected.size()) << text;
    for (size_t i = 0; i < got.size(); ++i) EXPECT_EQ(bits(got[i]), bits(expected[i])) << i << "\n" << text;
    if (HasFailure()) break;
  }
  EXPECT_EQ(fastTaken, kModels);
}

TEST(JsonReadRoutes, WriterOutputAndExampleModelsTakeTheFastRoute) {
  for (const auto& entry : fs::directory_iterator(fs::path(SEAM_EXAMPLES_DIR) / "models")) {
    if (entry.path().extension() != ".json" || entry.path().stem() == "zwl_example") continue;
    SCOPED_TRACE(entry.path().string());
    const std::string text = readText(entry.path());
    EXPECT_TRUE(expectSameOnBothRoutes(text, entry.path().string()));
    // What seam writes reads back on the fast route too.
    const Result<Model> model = io::parseModelJson(text, "m.json");
    ASSERT_TRUE(model.isOk());
    EXPECT_TRUE(expectSameOnBothRoutes(io::modelToJson(*model), "written.json"));
  }
}

// A model of several megabytes, so that elements straddle the streamed route's 1 MB chunks: the same model as the
// nlohmann route, point for point. The same text with one bad patch near its end (a degree below 1): the streamed
// route declines, and readModelJson gives the nlohmann route's message.
TEST(JsonReadRoutes, AModelOfManyChunksIsStreamedAndItsLastErrorIsTheOtherRoutesMessage) {
  std::mt19937 rng(37);
  std::uniform_real_distribution<double> coord(-1e3, 1e3);
  constexpr int kPatches = 6000;
  std::string text = "{\n  \"$schema\": \"seam-model\",\n  \"patches\": [";
  for (int k = 0; k < kPatches; ++k) {
    text += fmt::format("{}\n    {{\"name\": \"P{}\", \"type\": \"bspline\", \"degree\": [3, 2], "
                        "\"knots\": [[0, 0, 0, 0, 1, 1, 1, 1], [0, 0, 0, 0.25, 1, 1, 1]], \"points\": [",
                        k == 0 ? "" : ",", k);
    for (int i = 0; i < 4; ++i) {
      text += i == 0 ? "[" : ", [";
      for (int j = 0; j < 4; ++j) {
        const double z = coord(rng), y = coord(rng), x = coord(rng);  // drawn last argument first (test_helpers.h)
        text += fmt::format("{}[{:.17g}, {:.17g}, {:.17g}]", j == 0 ? "" : ", ", x, y, z);
      }
      text += "]";
    }
    text += "]}";
  }
  text += "\n  ],\n  \"curves\": [{\"name\": \"C\", \"type\": \"bezier\", \"points\": [[0, 0], [1, 2]]}]\n}\n";
  ASSERT_GT(text.size(), size_t{4} << 20);
  const std::optional<Model> streamed = streamedFromFile(text, "many.json");
  const Result<Model> slow = io::detail::parseModelJsonNlohmann(text, "many.json");
  ASSERT_TRUE(slow.isOk()) << slow.status().message();
  ASSERT_TRUE(streamed.has_value());
  expectSameModel(*streamed, *slow);
  ASSERT_EQ(streamed->curves.size(), 1u);
  EXPECT_EQ(streamed->curves[0].curve.numPoints(), 2);

  const std::string good = "\"degree\": [3, 2]", bad = "\"degree\": [0, 2]";
  text.replace(text.rfind(good), good.size(), bad);
  const fs::path file = fs::temp_directory_path() / fmt::format("seam_json_many_{}.json", ::getpid());
  {
    std::ofstream os(file, std::ios::binary);
    os << text;
  }
  EXPECT_FALSE(io::detail::readModelJsonStreamed(file, file.string()).has_value());
  const Result<Model> viaFile = io::readModelJson(file);
  const Result<Model> expected = io::detail::parseModelJsonNlohmann(text, file.string());
  fs::remove(file);
  ASSERT_FALSE(expected.isOk());
  ASSERT_FALSE(viaFile.isOk());
  EXPECT_EQ(viaFile.status().message(), expected.status().message());
  EXPECT_NE(expected.status().message().find(fmt::format("P{}", kPatches - 1)), std::string::npos)
      << expected.status().message();
}

TEST(JsonReadRoutes, HostileFilesGiveTheSameMessageOnBothRoutes) {
  int files = 0;
  for (const auto& entry : fs::directory_iterator(fs::path(SEAM_TEST_DATA_DIR) / "hostile")) {
    if (entry.path().extension() != ".json") continue;
    SCOPED_TRACE(entry.path().string());
    expectSameOnBothRoutes(readText(entry.path()), entry.path().string());
    ++files;
  }
  EXPECT_GE(files, 5);
}

TEST(JsonReadRoutes, InputsTheParsersTreatDifferentlyGoTheNlohmannWay) {
  const std::string patch =
      R"("type":"bezier","points":[[[0,0,0],[1,0,0]],[[0,1,0],[1,1,X]]])";
  auto model = [&](const std::string& z, const std::string& extra = "") {
    std::string p = patch;
    p.replace(p.find('X'), 1, z);
    return R"({"patches":[{"name":"A",)" + p + extra + "}]}";
  };
  struct Case {
    std::string text;
    bool fast;  ///< the fast route reads it
  };
  const std::vector<Case> cases = {
      {model("0"), true},
      {model("1e999"), false},                   // overflows a double: the nlohmann route names the point
      {model("-1e999"), false},
      {model("18446744073709551616"), false},    // beyond 64 bits: nlohmann reads a double
      {model("-9223372036854775809"), false},
      {model("18446744073709551615"), true},     // uint64
      {model("1e-400"), true},                   // underflows to 0
      {model("-1e-400"), true},                  // -0
      {model("-0"), true},                       // integer 0: +0.0 on both routes
      {model("0", R"(,"name":"B")"), true},      // repeated key: the last one
      {model("0", R"(,"name":"\u00e9")"), false},  // \u escapes: the nlohmann route
      {model("0", R"(,"name":"\ud800")"), false},  // lone surrogate: an error on both
      {model("0", R"(,"name":"\udc00x")"), false},
      {"\xEF\xBB\xBF" + model("0"), false},       // byte-order mark: nlohmann skips it
      {model("0", ",\"name\":\"\xC3\x28\""), false},  // invalid UTF-8
      {model("0", ",\"name\":\"caf\xC3\xA9\""), true},  // valid UTF-8
      {model("0", R"(,"degree":[1,1])"), true},
      {model("0", R"(,"degree":[1.0,1])"), false},  // not an integer
      {model("0", R"(,"degree":[2,1])"), false},
      {model("\"1\""), false},
      {model("null"), false},
      {model("true"), false},
      {model("0") + ",", false},
      {model("0") + "{}", false},
      {model("[0]"), false},
      {model("0", R"(,"extra":1)"), false},
      {R"({"patches":[]})", true},
      {R"({"curves":[]})", true},
      {R"({"patches":{}})", false},
      {R"([])", false},
      {"", false},
      {"   ", false},
      {R"({"patches":[],"patches":{}})", false},  // repeated key, the last one is wrong
      {R"({"patches":{},"patches":[]})", true},   // repeated key, the last one is right
  };
  for (size_t k = 0; k < cases.size(); ++k) {
    SCOPED_TRACE(fmt::format("case {}: {}", k, cases[k].text));
    EXPECT_EQ(expectSameOnBothRoutes(cases[k].text, "case.json"), cases[k].fast);
  }
}

TEST(JsonReadRoutes, NestingAtTheDepthLimitIsReadAlikeOnBothRoutes) {
  // "$schema" is not read, so its value may nest as deep as scanJsonText allows (256 with the top level).
  for (int depth = 250; depth <= 260; ++depth) {
    SCOPED_TRACE(depth);
    const std::string nested = std::string(static_cast<size_t>(depth - 1), '[') + std::string(static_cast<size_t>(depth - 1), ']');
    const std::string text = R"({"patches":[],"$schema":)" + nested + "}";
    const bool fast = expectSameOnBothRoutes(text, "deep.json");
    EXPECT_EQ(io::detail::parseModelJsonNlohmann(text, "deep.json").isOk(), depth <= 256);
    if (depth > 256) {
      EXPECT_FALSE(fast);
    }
  }
  // A NUL byte, outside and inside a string.
  EXPECT_FALSE(expectSameOnBothRoutes(std::string(R"({"patches":[]})") + '\0', "nul.json"));
  EXPECT_FALSE(expectSameOnBothRoutes(std::string(R"({"patches":[],"$schema":"a)") + '\0' + "\"}", "nul.json"));
  EXPECT_FALSE(expectSameOnBothRoutes("{\"patches\":[],\"$schema\":\"a\tb\"}", "tab.json"));
}


// Long rows (issue 39 goal 2): a patch of 2 rows of 100 000 points and a curve of 100 000 points, read on both
// routes. Every coordinate and knot is a number the test writes from a formula (integers and binary fractions,
// exact in decimal), and each value read is compared with the formula: not with another reader.
double longRowX(int i) { return i * 0.5 + 0.25; }
double longRowY(int j) { return j * 0.0009765625; }  // j / 2^10
double longRowZ(int i, int j) { return ((i + j) % 7) * 0.125 - 0.5; }

std::string longRowKnots(int n) {  // uniform cubic, clamped: 0 0 0 0 1 2 ... n-4 n-3 n-3 n-3 n-3
  std::string knots = "[0, 0, 0, 0";
  for (int k = 1; k < n - 3; ++k) knots += fmt::format(", {}", k);
  return knots + fmt::format(", {0}, {0}, {0}, {0}]", n - 3);
}

std::string longRow(int i, int n) {
  std::string row = "[";
  for (int j = 0; j < n; ++j)
    row += fmt::format("{}[{}, {}, {}]", j == 0 ? "" : ", ", longRowX(i), longRowY(j), longRowZ(i, j));
  return row + "]";
}

// The model of `text` read by the fast route and by the nlohmann route; fewer than two when a route fails (a
// failure is recorded).
std::vector<Model> readOnBothRoutes(const std::string& text, const std::string& source) {
  std::vector<Model> out;
  std::optional<Model> fast = io::detail::parseModelJsonFast(text, source);
  Result<Model> slow = io::detail::parseModelJsonNlohmann(text, source);
  if (!fast) ADD_FAILURE() << source << ": the fast route failed";
  if (!slow) ADD_FAILURE() << source << ": " << slow.status().message();
  std::optional<Model> streamed = streamedFromFile(text, source);
  if (!streamed) ADD_FAILURE() << source << ": the streamed route declined";
  if (fast) out.push_back(std::move(*fast));
  if (slow) out.push_back(std::move(slow).value());
  if (streamed) out.push_back(std::move(*streamed));
  return out;
}

void expectLongRowKnots(const std::vector<double>& t, int n) {
  ASSERT_EQ(t.size(), static_cast<size_t>(n + 4));
  for (int k = 0; k < n + 4; ++k) EXPECT_EQ(t[static_cast<size_t>(k)], std::clamp(k - 3, 0, n - 3)) << "knot " << k;
}

TEST(JsonReadLongRows, TwoRowsOf100000PointsAreReadExactlyOnBothRoutes) {
  constexpr int kPoints = 100000;
  const std::string text =
      fmt::format(R"({{"patches": [{{"name": "long", "type": "bspline", "degree": [1, 3], )"
                  R"("knots": [[0, 0, 1, 1], {}], "points": [{}, {}]}}]}})",
                  longRowKnots(kPoints), longRow(0, kPoints), longRow(1, kPoints));
  const std::vector<Model> routes = readOnBothRoutes(text, "long.json");
  ASSERT_EQ(routes.size(), 3u);
  for (const Model* m : {&routes[0], &routes[1], &routes[2]}) {
    ASSERT_EQ(m->patches.size(), 1u);
    const BSplineSurface& s = m->patches[0].surface;
    ASSERT_EQ(s.numU(), 2);
    ASSERT_EQ(s.numV(), kPoints);
    EXPECT_EQ(s.degreeU(), 1);
    EXPECT_EQ(s.degreeV(), 3);
    expectLongRowKnots(s.knotsV().values(), kPoints);
    int wrong = 0;
    for (int i = 0; i < 2; ++i) {
      for (int j = 0; j < kPoints; ++j) {
        const auto p = s.point(i, j);
        if (p(0) != longRowX(i) || p(1) != longRowY(j) || p(2) != longRowZ(i, j)) {
          if (++wrong <= 3) ADD_FAILURE() << "point [" << i << "][" << j << "] = " << p.transpose();
        }
      }
    }
    EXPECT_EQ(wrong, 0);
  }
}

TEST(JsonReadLongRows, ACurveOf100000PointsIsReadExactlyOnBothRoutes) {
  constexpr int kPoints = 100000;
  const std::string text =
      fmt::format(R"({{"curves": [{{"name": "c", "type": "bspline", "degree": 3, "knots": {}, "points": {}}}]}})",
                  longRowKnots(kPoints), longRow(1, kPoints));
  const std::vector<Model> routes = readOnBothRoutes(text, "curve.json");
  ASSERT_EQ(routes.size(), 3u);
  for (const Model* m : {&routes[0], &routes[1], &routes[2]}) {
    ASSERT_EQ(m->curves.size(), 1u);
    const BSplineCurve& c = m->curves[0].curve;
    ASSERT_EQ(c.numPoints(), kPoints);
    expectLongRowKnots(c.knots().values(), kPoints);
    int wrong = 0;
    for (int j = 0; j < kPoints; ++j) {
      if (c.points()(j, 0) != longRowX(1) || c.points()(j, 1) != longRowY(j) || c.points()(j, 2) != longRowZ(1, j))
        ++wrong;
    }
    EXPECT_EQ(wrong, 0);
  }
}

// A hostile shape is refused before its points are read: one row of 200 000 points whose last point is not a
// number gets the degree's message (which needs only the counts), not the point's (which needs every point read).
TEST(JsonReadLongRows, ASingleLongRowIsRefusedBeforeItsPointsAreRead) {
  constexpr int kPoints = 200000;
  std::string row = longRow(0, kPoints);
  row.replace(row.rfind(']', row.size() - 2), 1, ", \"x\"]");  // the last point gets a fourth, non-number entry
  const std::string text =
      fmt::format(R"({{"patches": [{{"name": "row", "type": "bspline", "degree": [1, 3], )"
                  R"("knots": [[0, 0, 1, 1], {}], "points": [{}]}}]}})",
                  longRowKnots(kPoints), row);
  const Result<Model> m = io::parseModelJson(text, "row.json");
  ASSERT_FALSE(m.isOk());
  EXPECT_EQ(m.status().message(), "row.json: patch \"row\": u degree 1 needs at least 2 control points in that "
                                  "direction, found 1");
  // The bezier case: a 1 x n bezier patch has u degree 0.
  const std::string bezier =
      fmt::format(R"({{"patches": [{{"name": "b", "type": "bezier", "points": [{}]}}]}})", row);
  const Result<Model> b = io::parseModelJson(bezier, "row.json");
  ASSERT_FALSE(b.isOk());
  EXPECT_EQ(b.status().message(), "row.json: patch \"b\": u degree is 0, must be at least 1");
}

// ---------------------------------------------------------------------------------------------------------------
// Trimmed faces: the "brep" object (issue 34 §1, docs/format.md). tests/data/brep_plate_with_hole.json is
// written by hand: the unit square z = 0 (a bilinear Bezier patch, S(u, v) = (u, v, 0)) with a square hole
// [0.25, 0.75]^2, one face of two loops of four line edges (pcurves = the edges' own (x, y)).

nlohmann::json plateWithHole() {
  return nlohmann::json::parse(readText(fs::path(SEAM_TEST_DATA_DIR) / "brep_plate_with_hole.json"));
}

// The streamed route's own scanner (object and array boundaries, strings, escapes) against mutated texts: a valid
// model of patches, curves and a B-rep, cut at random places or with one byte replaced by a structural character.
// Wherever the streamed route reads a model, the nlohmann route reads the same one (expectSameOnBothRoutes); and
// readModelJson of the file gives the nlohmann route's message or model. Fixed seed.
TEST(JsonReadRoutes, MutatedTextsAreStreamedOnlyWhenTheyAreTheSameModel) {
  std::mt19937 rng(20261129);
  TextGen g(7);
  std::vector<double> unused;
  const std::string base = randomModelText(g, unused);
  const std::string brep = plateWithHole().dump(2);
  const char structural[] = {'"', '[', ']', '{', '}', ',', ':', '\\', ' ', '\n', '0', 'e', '-', '\0'};
  int streamed = 0;
  for (int k = 0; k < 300; ++k) {
    std::string text = k % 2 == 0 ? base : brep;
    std::uniform_int_distribution<size_t> at(0, text.size() - 1);
    if (k % 3 == 0) {
      text.resize(at(rng));
    } else {
      text[at(rng)] = structural[std::uniform_int_distribution<size_t>(0, sizeof structural - 1)(rng)];
    }
    SCOPED_TRACE(fmt::format("mutation {}", k));
    if (streamedFromFile(text, "mutated.json")) ++streamed;
    expectSameOnBothRoutes(text, "mutated.json");
    if (HasFailure()) {
      ADD_FAILURE() << text;
      break;
    }
  }
  std::printf("[mutations] %d of 300 still read as a model by the streamed route\n", streamed);
}

TEST(JsonBRep, ReadsTheHandWrittenPlateWithItsHole) {
  const std::string text = plateWithHole().dump();
  expectSameOnBothRoutes(text, "plate.json");
  const Result<Model> m = io::parseModelJson(text, "plate.json");
  ASSERT_TRUE(m) << m.status().message();
  ASSERT_TRUE(m->brep);
  EXPECT_EQ(m->brep->vertices.size(), 8u);
  EXPECT_EQ(m->brep->edges.size(), 8u);
  ASSERT_EQ(m->brep->faces.size(), 1u);
  EXPECT_EQ(m->brep->faces[0].loops.size(), 2u);
  EXPECT_EQ(m->trimmedFaces, 1);  // a hole: trimmed
  EXPECT_EQ(m->brep->shells.size(), 1u);
  EXPECT_EQ(m->brep->roots.size(), 1u);
  // Written and read again: the same text (every number bit for bit), and the writer accepts the trimmed
  // model.
  const std::string written = io::modelToJson(*m);
  const Result<Model> again = io::parseModelJson(written, "again.json");
  ASSERT_TRUE(again) << again.status().message();
  EXPECT_EQ(io::modelToJson(*again), written);
  // The streamed route (readModelJson's first) reads the B-rep too, before ("brep" sorts first in the dump) and
  // after the patches: the same model, written alike.
  for (const std::string& t : {text, written}) {
    const std::optional<Model> streamed = streamedFromFile(t, "plate.json");
    ASSERT_TRUE(streamed.has_value());
    EXPECT_EQ(io::modelToJson(*streamed), written);
  }
  const fs::path out = fs::temp_directory_path() / fmt::format("seam_brep_{}.json", ::getpid());
  EXPECT_TRUE(io::writeModelJson(*m, out));
  fs::remove(out);
}

TEST(JsonBRep, WithoutBRepATrimmedModelIsStillRefusedByThePatchWriter) {
  Result<Model> m = io::parseModelJson(plateWithHole().dump(), "plate.json");
  ASSERT_TRUE(m);
  m->brep.reset();
  const Status st = io::writeModelJson(*m, "never_written.json");
  EXPECT_FALSE(st);
  EXPECT_NE(st.message().find("1 faces of the model are trimmed"), std::string::npos) << st.message();
  EXPECT_FALSE(fs::exists("never_written.json"));
}

// A face whose loops do not close in its source file (trj3_s1-al-214.stp: 12 faces OpenCASCADE finds invalid as
// read) is kept as read with "open_as_read": "yes": the same open loop is accepted with the flag, refused without
// it, written back with it, and the flag takes only "yes".
TEST(JsonBRep, AFaceOpenAsReadKeepsItsOpenLoop) {
  nlohmann::json doc = plateWithHole();
  doc["brep"]["faces"][0]["loops"][0][1]["pcurve"]["points"][0] = {1.0, 0.5};  // the loop no longer closes
  ASSERT_FALSE(io::parseModelJson(doc.dump(), "open.json"));
  doc["brep"]["faces"][0]["open_as_read"] = "yes";
  const std::string text = doc.dump();
  expectSameOnBothRoutes(text, "open.json");
  const Result<Model> m = io::parseModelJson(text, "open.json");
  ASSERT_TRUE(m) << m.status().message();
  ASSERT_TRUE(m->brep);
  EXPECT_TRUE(m->brep->faces[0].openAsRead);
  const std::string written = io::modelToJson(*m);
  EXPECT_NE(written.find("\"open_as_read\": \"yes\""), std::string::npos);
  const Result<Model> again = io::parseModelJson(written, "again.json");
  ASSERT_TRUE(again) << again.status().message();
  EXPECT_TRUE(again->brep->faces[0].openAsRead);
  EXPECT_EQ(io::modelToJson(*again), written);
  // A closed face is written without the key.
  const Result<Model> plate = io::parseModelJson(plateWithHole().dump(), "plate.json");
  ASSERT_TRUE(plate);
  EXPECT_EQ(io::modelToJson(*plate).find("open_as_read"), std::string::npos);
  for (const nlohmann::json& bad : {nlohmann::json(true), nlohmann::json("no"), nlohmann::json(1)}) {
    doc["brep"]["faces"][0]["open_as_read"] = bad;
    const Result<Model> r = io::parseModelJson(doc.dump(), "bad.json");
    ASSERT_FALSE(r) << bad.dump();
    EXPECT_EQ(r.status().message(),
              "bad.json: brep face 0: \"open_as_read\" must be \"yes\" (the face's loops do not close in the file "
              "it was read from), found " + bad.dump());
  }
}

/// A hostile variant of the plate: `edit` changes the document; the message must be `expected` exactly, on
/// both routes (a crash or an exception fails the test; they run under ASan+UBSan in CI).
void expectRefused(const std::function<void(nlohmann::json&)>& edit, const std::string& expected) {
  nlohmann::json doc = plateWithHole();
  edit(doc);
  const std::string text = doc.dump();
  expectSameOnBothRoutes(text, "bad.json");
  const Result<Model> m = io::parseModelJson(text, "bad.json");
  ASSERT_FALSE(m) << "accepted: " << expected;
  EXPECT_EQ(m.status().code(), ErrorCode::kInvalidInput);
  EXPECT_EQ(m.status().message(), expected);
}

TEST(JsonBRep, HostileInputIsRefusedWithFileObjectAndProblem) {
  expectRefused([](auto& d) { d["brep"]["faces"][0]["loops"][0][2]["edge"] = 42; },
                "bad.json: brep face 0: loop 0: coedge 2: edge id 42 does not exist (there are 8 edges)");
  expectRefused([](auto& d) { d["brep"]["edges"][3]["vertices"][1] = 9; },
                "bad.json: brep edge 3: vertex id 9 does not exist (there are 8 vertices)");
  expectRefused([](auto& d) { d["brep"]["faces"][0]["loops"][0][1]["edge"] = -1; },
                "bad.json: brep face 0: loop 0: coedge 1: edge must be an id (an integer >= 0), found -1");
  // A loop that does not close: the second side of the outer loop moved off the square's corner.
  expectRefused(
      [](auto& d) {
        d["brep"]["faces"][0]["loops"][0][1]["pcurve"]["points"][0] = {1.0, 0.5};
      },
      "bad.json: brep face 0: loop 0: coedge 0: the loop does not close: the pcurve of edge 0 ends at "
      "(u, v) = (1, 0), the next coedge's (edge 1) starts at (1, 0.5): 0.5 apart on the surface, more than "
      "the tolerance 5.01e-07");  // two vertices, two edges, the face: 5 x 1e-7, + 1e-9 x sqrt(2)
  // A zero-length pcurve: both points the same, on an edge that is not degenerate.
  expectRefused(
      [](auto& d) {
        d["brep"]["faces"][0]["loops"][1][0]["pcurve"]["points"][1] = {0.25, 0.25};
      },
      "bad.json: brep face 0: loop 1: coedge 0: the pcurve of edge 4 has zero length (all its points are "
      "equal) but the edge is not degenerate");
  expectRefused(
      [](auto& d) {
        d["brep"]["faces"][0]["loops"][0][0]["range"] = {0.5, 0.5};
      },
      "bad.json: brep face 0: loop 0: coedge 0: range [0.5, 0.5] is empty (t1 must be > t0)");
  // NaN cannot be written in JSON; a literal that overflows a double is the same problem.
  {
    std::string text = plateWithHole().dump();
    const std::string tol = "\"tolerance\":1e-07";  // nlohmann sorts the keys: edge 0 comes first
    const size_t at = text.find(tol);
    ASSERT_NE(at, std::string::npos);
    text.replace(at, tol.size(), "\"tolerance\":1e999");
    const Result<Model> m = io::parseModelJson(text, "bad.json");
    ASSERT_FALSE(m);
    EXPECT_EQ(m.status().message(),
              "bad.json: brep edge 0: tolerance = 1e999 is not a finite number (it overflows a double)");
  }
  expectRefused([](auto& d) { d["brep"]["faces"][0]["patch"] = "Nope"; },
                "bad.json: brep face 0: no patch named \"Nope\"");
  expectRefused(
      [](auto& d) { d["brep"]["faces"][0]["orientation"] = "inside"; },
      "bad.json: brep face 0: \"orientation\" must be \"forward\" or \"reversed\", found \"inside\"");
  expectRefused(
      [](auto& d) {
        d["brep"]["edges"][0]["curve"]["knots"] = {0, 1, 0, 1};
      },
      "bad.json: brep edge 0: curve: knots must be non-decreasing, but knot 2 (0) < knot 1 (1)");
  expectRefused(
      [](auto& d) {
        d["brep"]["faces"][0]["loops"][0][0]["pcurve"]["points"][1] = {1.0, 0.0, 0.0};
      },
      "bad.json: brep face 0: loop 0: coedge 0: pcurve: point 1 has 3 coordinates, expected 2 like point 0");
  expectRefused([](auto& d) { d["brep"]["shells"][0]["faces"][0]["face"] = 3; },
                "bad.json: brep shell 0: face id 3 does not exist (there are 1 faces)");
  expectRefused(
      [](auto& d) {
        d["brep"]["faces"][0]["loops"][0][0]["pcurve"]["points"][0] = {-0.5, 0.0};
      },
      "bad.json: brep face 0: loop 0: coedge 0: the pcurve leaves the patch's domain [0, 1] x [0, 1]: "
      "(u, v) = (-0.5, 0)");
  expectRefused([](auto& d) { d["brep"]["wires"] = nlohmann::json::array(); },
                "bad.json: brep: unknown key \"wires\"");
  expectRefused([](auto& d) { d["brep"]["faces"][0]["loops"] = nlohmann::json::array(); },
                "bad.json: brep face 0: has no loop (a face needs its outer loop)");
}

}  // namespace
}  // namespace seam
