// apps/common: the JSON of `seam check --json` streamed record by record (writeModelCheckJson, what the CLI prints)
// against the document route (modelCheckJson + withInputFile, what the Python module returns), and the text writer's
// scalars against nlohmann's own serialiser.
#include <gtest/gtest.h>

#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <numbers>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "check_json.h"
#include "json_text.h"
#include "seam/continuity/model_check.h"
#include "seam/continuity/verdict.h"
#include "seam/model/model.h"
#include "seam/spline/bspline_surface.h"

namespace seam::cli {
namespace {

/// A bicubic Bezier patch over the unit square [x0, x0 + 1] x [y0, y0 + 1] with heights z(x, y) at its control points.
template <class Height>
Patch gridPatch(const std::string& name, double x0, double y0, Height z) {
  constexpr int kOrder = 4;
  Matrix pts(kOrder * kOrder, 3);
  for (int i = 0; i < kOrder; ++i)
    for (int j = 0; j < kOrder; ++j) {
      const double x = x0 + i / 3.0, y = y0 + j / 3.0;
      pts.row(i * kOrder + j) << x, y, z(x, y);
    }
  const std::vector<double> knots{0, 0, 0, 0, 1, 1, 1, 1};
  return {name, PatchKind::kBezier, BSplineSurface::create(3, 3, knots, knots, kOrder, kOrder, pts).value()};
}

/// 4 x 2 unit patches: columns 0 and 1 flat, column 2 tilted by 5 degrees (kinks at x = 2), column 3 by 45 degrees
/// (a 40 degree crease at x = 3), patch (0, 1) lifted by 1e-3 (gaps); interior vertices of valence 4 (corner
/// records with the four-patch relations). Patch names hold quotes, backslashes, a newline, a tab and non-ASCII text.
Model testModel() {
  const double slope5 = std::tan(5.0 * std::numbers::pi / 180.0), slope45 = 1.0;
  auto height = [&](int column, int row) {
    return [=](double x, double) {
      if (column == 0 && row == 1) return 1e-3;
      if (column == 2) return slope5 * (x - 2.0);
      if (column == 3) return slope5 + slope45 * (x - 3.0);
      return 0.0;
    };
  };
  const std::vector<std::string> names{"P0 \"quoted\"", "back\\slash", "new\nline", "tab\there",
                                       "na\xc3\xafve \xe2\x88\x82S", "P5", "ctrl\x01", "P7"};
  Model m;
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 2; ++r)
      m.patches.push_back(gridPatch(names[static_cast<size_t>(2 * c + r)], c, r, height(c, r)));
  return m;
}

struct Checked {
  Model model;
  ModelCheckReport report;
};

/// The test model checked, with one seam's analysis replaced by a failure (as checkModel reports one).
Checked checkedModel() {
  Checked c{testModel(), {}};
  Result<ModelCheckReport> r = checkModel(c.model, ModelCheckOptions{});
  EXPECT_TRUE(r.isOk()) << r.status().message();
  c.report = std::move(r).value();
  EXPECT_GE(c.report.seams.size(), 3u);
  ModelSeam& failed = c.report.seams[1];
  failed.report.reset();
  failed.error = invalidInput("analysis failed: \"degenerate\" \\ edge\nsecond line");
  return c;
}

OrderedJson streamed(const Checked& c, const std::string& file, const std::vector<size_t>& order,
                     const std::optional<GeometricClass>& require, double crease) {
  std::ostringstream out;
  writeModelCheckJson(out, file, c.model, c.report, order, require, c.report.pairingTolerance, crease, ModelUnits{},
                      DistanceSource::kRelative);
  return OrderedJson::parse(out.str());
}

/// The document route, serialised and parsed back by nlohmann alone (non-finite numbers become null, as in text).
OrderedJson documentRoute(const Checked& c, const std::string& file, const std::vector<size_t>& order,
                          const std::optional<GeometricClass>& require, double crease) {
  const OrderedJson dom = withInputFile(file, modelCheckJson(c.model, c.report, order, require,
                                                             c.report.pairingTolerance, crease, ModelUnits{},
                                                             DistanceSource::kRelative));
  return OrderedJson::parse(dom.dump(-1, ' ', false, OrderedJson::error_handler_t::replace));
}

TEST(CheckJson, TestModelHasEveryKindOfRecord) {
  const Checked c = checkedModel();
  const std::vector<const SeamReport*> reports = reportsOf(c.report);
  const std::array<int, kSeamVerdictCount> verdicts = countVerdicts(reports, kDefaultCreaseAngleDeg);
  EXPECT_GT(verdicts[static_cast<size_t>(SeamVerdict::kGap)], 0);
  EXPECT_GT(verdicts[static_cast<size_t>(SeamVerdict::kKink)], 0);
  EXPECT_GT(verdicts[static_cast<size_t>(SeamVerdict::kCrease)], 0);
  EXPECT_GT(verdicts[static_cast<size_t>(SeamVerdict::kG2)], 0);
  bool fourPatch = false;
  for (const ModelCorner& k : c.report.corners) fourPatch = fourPatch || k.report.fourPatch.has_value();
  EXPECT_TRUE(fourPatch);
  EXPECT_FALSE(c.report.freeEdges.empty());
}

TEST(CheckJson, StreamedEqualsDocumentRoute) {
  const Checked c = checkedModel();
  const std::vector<const SeamReport*> reports = reportsOf(c.report);
  SeamSelection all;
  SeamSelection problems;
  problems.sort = SeamSortKey::kAngle;
  problems.only = SeamFilter::kProblems;
  problems.top = 3;
  for (const SeamSelection& sel : {all, problems}) {
    for (const std::optional<GeometricClass>& require : {std::optional<GeometricClass>(),
                                                         std::optional<GeometricClass>(GeometricClass::kG1)}) {
      const std::vector<size_t> order = selectSeams(reports, sel);
      for (const std::string file : {"model.json", "dir/\"odd\" name\\x.BPT", "na\xc3\xafve.step"}) {
        const OrderedJson expected = documentRoute(c, file, order, require, sel.creaseAngleDeg);
        const OrderedJson got = streamed(c, file, order, require, sel.creaseAngleDeg);
        EXPECT_EQ(got, expected) << file;  // ordered_json: key order compared too
        ASSERT_TRUE(got.contains("seams"));
        EXPECT_EQ(got["seams"].size(), order.size());
      }
    }
  }
  // The failed seam is listed with its message, the names come back unescaped.
  const OrderedJson got = streamed(c, "m.json", selectSeams(reports, all), std::nullopt, kDefaultCreaseAngleDeg);
  EXPECT_EQ(got["seams"][1]["verdict"], "error");
  EXPECT_EQ(got["seams"][1]["error"], "analysis failed: \"degenerate\" \\ edge\nsecond line");
  EXPECT_EQ(got["seams"][0]["a"], "P0 \"quoted\"");
}

TEST(CheckJson, StreamedTextEqualsDocumentTextByteForByte) {
  const Checked c = checkedModel();
  const std::vector<size_t> order = selectSeams(reportsOf(c.report), SeamSelection{});
  std::ostringstream out;
  writeModelCheckJson(out, "model.json", c.model, c.report, order, std::nullopt, c.report.pairingTolerance,
                      kDefaultCreaseAngleDeg);
  std::string expected;
  appendJsonText(expected, withInputFile("model.json", modelCheckJson(c.model, c.report, order, std::nullopt,
                                                                      c.report.pairingTolerance,
                                                                      kDefaultCreaseAngleDeg)),
                 0);
  EXPECT_EQ(out.str(), expected + "\n");
}

#ifdef SEAM_HAVE_OCCT
// The B-rep check's JSON as the CLI streams it (writeBRepCheckJson) against the document route (brepCheckJson +
// withInputFile, what `seam batch` and the Python module return), on a STEP file with free edges, a sewn IGES file
// and, for each, the full listing and a selection (sorted, cut, with --require).
TEST(CheckJson, BRepStreamedTextEqualsDocumentTextByteForByte) {
  const std::filesystem::path data = SEAM_SHARED_DATA_DIR;
  for (const char* name : {"step/bug28366_fuselage.stp", "iges/BUC50025.igs", "iges/occ22470.igs"}) {
    const std::filesystem::path file = data / name;
    const Result<occt::BRepCheckReport> r = occt::checkBRepFile(file, {});
    ASSERT_TRUE(r) << r.status().message();
    std::vector<const SeamReport*> reports;
    for (const occt::BRepSeam& s : r->seams) reports.push_back(&s.report);
    SeamSelection cut;
    cut.sort = SeamSortKey::kAngle;
    cut.only = SeamFilter::kProblems;
    cut.top = 3;
    for (const auto& [selection, require] : {std::pair{SeamSelection{}, std::optional<GeometricClass>{}},
                                             std::pair{cut, std::optional{GeometricClass::kG2}}}) {
      const std::vector<size_t> order = selectSeams(reports, selection);
      std::ostringstream out;
      writeBRepCheckJson(out, file, *r, order, require, selection.creaseAngleDeg);
      std::string expected;
      appendJsonText(expected, withInputFile(file, brepCheckJson(*r, order, require, selection.creaseAngleDeg)), 0);
      EXPECT_EQ(out.str(), expected + "\n") << name;
      EXPECT_EQ(OrderedJson::parse(out.str())["seams"].size(), order.size()) << name;
    }
  }
}
#endif

TEST(JsonText, ScalarsAreNlohmannsText) {
  std::mt19937_64 rng(7);
  std::uniform_int_distribution<std::uint64_t> bits;
  std::vector<double> xs{0.0, -0.0, 1.0, -1.0, 0.1, 1e-5, 1e-4, 123456789012345.0, 1e15, 1e16, 1e300, 5e-324,
                         std::numeric_limits<double>::max(), std::numeric_limits<double>::quiet_NaN(),
                         std::numeric_limits<double>::infinity()};
  for (int k = 0; k < 10000; ++k) xs.push_back(std::bit_cast<double>(bits(rng)));
  for (double x : xs) {
    std::string text;
    appendJsonNumber(text, x);
    EXPECT_EQ(text, OrderedJson(x).dump()) << x;  // nlohmann prints non-finite numbers as null too
    if (std::isfinite(x)) {
      EXPECT_EQ(std::bit_cast<std::uint64_t>(OrderedJson::parse(text).get<double>()),
                std::bit_cast<std::uint64_t>(x));
    }
  }
  for (const std::string s : {"", "plain", "quote\"", "back\\slash", "new\nline", "tab\t", "\x01\x1f\x7f",
                              "na\xc3\xafve", "bad \xff utf-8", "\xe2\x88"}) {
    std::string text;
    appendJsonString(text, s);
    EXPECT_EQ(text, OrderedJson(s).dump(-1, ' ', false, OrderedJson::error_handler_t::replace)) << s;
  }
  for (long long x : {0LL, -1LL, 42LL, std::numeric_limits<long long>::min()}) {
    std::string text;
    appendJsonInteger(text, x);
    EXPECT_EQ(text, OrderedJson(x).dump());
  }
}

TEST(JsonText, WriterLayoutEqualsDocumentLayout) {
  const OrderedJson doc = OrderedJson::parse(R"({"a": [], "b": {}, "c": [1, 2.5, "x", null, true],
    "d": [{"e": [[1, 2], [3]], "f": {}}, {}], "g": [[]], "h": -0.0})");
  JsonTextWriter w;
  w.beginObject();
  w.key("a");
  w.beginArray();
  w.endArray();
  w.key("b");
  w.beginObject();
  w.endObject();
  w.key("c");
  w.value(doc["c"]);
  w.key("d");
  w.beginArray();
  w.beginObject();
  w.key("e");
  w.beginArray();
  w.numbers(std::vector<double>{1, 2});
  w.numbers(std::vector<double>{3});
  w.endArray();
  w.key("f");
  w.beginObject();
  w.endObject();
  w.endObject();
  w.beginObject();
  w.endObject();
  w.endArray();
  w.key("g");
  w.beginArray();
  w.strings(std::vector<std::string>{});
  w.endArray();
  w.key("h");
  w.value(-0.0);
  w.endObject();
  std::string expected;
  appendJsonText(expected, doc, 0);
  // numbers() writes doubles: 1.0 where the parsed document holds the integer 1.
  std::string got = w.text();
  EXPECT_EQ(OrderedJson::parse(got), doc);
  expected.clear();
  OrderedJson asDoubles = doc;
  asDoubles["d"][0]["e"] = OrderedJson::array({OrderedJson::array({1.0, 2.0}), OrderedJson::array({3.0})});
  appendJsonText(expected, asDoubles, 0);
  EXPECT_EQ(got, expected);
}

}  // namespace
}  // namespace seam::cli
