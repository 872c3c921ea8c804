// Tests of the model readers and writers (src/io, src/model): one test per validation rule (each checks the
// whole message: file, object, problem), bit-identical JSON round trips of random models, the .bpt reader on
// the Newell tea set, and atomic writes.
#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <functional>
#include <new>
#include <string_view>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "seam/io/bpt.h"
#include "seam/io/file.h"
#include "seam/io/json.h"
#include "seam/model/model.h"

namespace seam {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;
using ::testing::HasSubstr;
using ::testing::StartsWith;

// ---------------------------------------------------------------------------------------------------------------
// Helpers

std::string readText(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

void writeText(const fs::path& file, const std::string& text) {
  std::ofstream out(file, std::ios::binary);
  out << text;
}

/// A fresh, empty folder for one test (several engineers and ctest -j run tests at the same time).
class TempDir {
 public:
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path_ = fs::temp_directory_path() /
            fmt::format("seam_io_test_{}_{}_{}", ::getpid(), info->test_suite_name(), info->name());
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempDir() { fs::remove_all(path_); }
  [[nodiscard]] const fs::path& path() const { return path_; }
  [[nodiscard]] std::vector<std::string> entries() const {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(path_)) names.push_back(e.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
  }

 private:
  fs::path path_;
};

/// A valid model: a bicubic-by-linear B-spline patch "S1" (5 x 2 points), a rational Bezier patch "B1" (3 x
/// 2) and a quadratic B-spline curve "C1". Tests break one thing at a time.
Json validModel() {
  Json s1 = {{"name", "S1"},
             {"type", "bspline"},
             {"degree", {3, 1}},
             {"knots", {{0, 0, 0, 0, 0.5, 1, 1, 1, 1}, {0, 0, 1, 1}}},
             {"points", Json::array()}};
  for (int i = 0; i < 5; ++i) s1["points"].push_back({{i, 0, 0.5 * i}, {i, 1, 0.25 * i}});
  Json b1 = {{"name", "B1"},
             {"type", "bezier"},
             {"points", {{{0, 0, 2}, {0, 1, 2}}, {{1, 0, 3}, {1, 1, 3}}, {{2, 0, 2}, {2, 1, 2}}}},
             {"weights", {{1, 1}, {0.5, 0.5}, {1, 1}}}};
  Json c1 = {{"name", "C1"},
             {"type", "bspline"},
             {"degree", 2},
             {"knots", {0, 0, 0, 1, 1, 1}},
             {"points", {{0, 0, 0}, {1, 1, 0}, {2, 0, 0}}}};
  return {{"patches", {s1, b1}}, {"curves", {c1}}};
}

/// The message of parsing `text` as "model.json" (the test fails if it parses).
std::string errorOfText(const std::string& text) {
  const Result<Model> r = io::parseModelJson(text, "model.json");
  EXPECT_FALSE(r.isOk()) << "expected an error for: " << text;
  if (r.isOk()) return "";
  EXPECT_EQ(r.status().code(), ErrorCode::kInvalidInput);
  return r.status().message();
}
std::string errorOf(const Json& j) { return errorOfText(j.dump()); }

// ---------------------------------------------------------------------------------------------------------------
// Valid input

TEST(JsonRead, ValidModelHasTheGivenData) {
  const Result<Model> r = io::parseModelJson(validModel().dump(), "model.json");
  ASSERT_TRUE(r.isOk()) << r.status().message();
  const Model& m = *r;
  ASSERT_EQ(m.patches.size(), 2u);
  ASSERT_EQ(m.curves.size(), 1u);

  const Patch& s1 = m.patches[0];
  EXPECT_EQ(s1.name, "S1");
  EXPECT_EQ(s1.kind, PatchKind::kBSpline);
  EXPECT_EQ(s1.surface.degreeU(), 3);
  EXPECT_EQ(s1.surface.degreeV(), 1);
  EXPECT_EQ(s1.surface.numU(), 5);
  EXPECT_EQ(s1.surface.numV(), 2);
  EXPECT_EQ(s1.surface.knotsU().values(), (std::vector<double>{0, 0, 0, 0, 0.5, 1, 1, 1, 1}));
  EXPECT_EQ(s1.surface.knotsV().values(), (std::vector<double>{0, 0, 1, 1}));
  EXPECT_FALSE(s1.surface.isRational());
  // points[i][j] with i along u: point (3, 1) is the file's [3][1] = [3, 1, 0.75].
  EXPECT_EQ(s1.surface.point(3, 1)[0], 3.0);
  EXPECT_EQ(s1.surface.point(3, 1)[1], 1.0);
  EXPECT_EQ(s1.surface.point(3, 1)[2], 0.75);

  const Patch& b1 = m.patches[1];
  EXPECT_EQ(b1.kind, PatchKind::kBezier);
  EXPECT_EQ(b1.surface.degreeU(), 2);
  EXPECT_EQ(b1.surface.degreeV(), 1);
  EXPECT_EQ(b1.surface.knotsU().values(), (std::vector<double>{0, 0, 0, 1, 1, 1}));
  EXPECT_EQ(b1.surface.knotsV().values(), (std::vector<double>{0, 0, 1, 1}));
  ASSERT_TRUE(b1.surface.isRational());
  EXPECT_EQ(b1.surface.weight(1, 0), 0.5);
  EXPECT_EQ(b1.surface.point(2, 1)[2], 2.0);

  const Curve& c1 = m.curves[0];
  EXPECT_EQ(c1.name, "C1");
  EXPECT_EQ(c1.curve.degree(), 2);
  EXPECT_EQ(c1.curve.dim(), 3);
  EXPECT_EQ(c1.curve.numPoints(), 3);

  EXPECT_EQ(m.findPatch("B1"), &m.patches[1]);
  EXPECT_EQ(m.findPatch("C1"), nullptr);
  EXPECT_EQ(m.findCurve("C1"), &m.curves[0]);
  EXPECT_EQ(m.findCurve("S1"), nullptr);
}

TEST(JsonRead, BoundingBoxIsTheBoxOfAllControlPoints) {
  const Result<Model> r = io::parseModelJson(validModel().dump(), "model.json");
  ASSERT_TRUE(r.isOk()) << r.status().message();
  // S1: x 0..4, y 0..1, z 0..2; B1: x 0..2, y 0..1, z 2..3; C1: x 0..2, y 0..1, z 0.
  const BoundingBox box = r->boundingBox();
  EXPECT_EQ(box.min, Vec3(0, 0, 0));
  EXPECT_EQ(box.max, Vec3(4, 1, 3));
  EXPECT_EQ(box.diagonal(), std::sqrt(16.0 + 1.0 + 9.0));
  const BoundingBox b1 = controlBox(r->patches[1].surface);
  EXPECT_EQ(b1.min, Vec3(0, 0, 2));
  EXPECT_EQ(b1.max, Vec3(2, 1, 3));
  EXPECT_TRUE(Model{}.boundingBox().empty());
}

TEST(JsonRead, PlanarCurvesAndBezierCurvesAreAccepted) {
  const Json j = {
      {"curves",
       {{{"name", "arc"}, {"type", "bezier"}, {"points", {{1, 0}, {1, 1}, {0, 1}}}, {"weights", {1, 0.5, 1}}},
        {{"name", "line"},
         {"type", "bspline"},
         {"degree", 1},
         {"knots", {0, 0, 2, 2}},
         {"points", {{0, 0}, {3, 4}}}}}}};
  const Result<Model> r = io::parseModelJson(j.dump(), "curves.json");
  ASSERT_TRUE(r.isOk()) << r.status().message();
  ASSERT_EQ(r->curves.size(), 2u);
  EXPECT_TRUE(r->patches.empty());
  EXPECT_EQ(r->curves[0].curve.dim(), 2);
  EXPECT_EQ(r->curves[0].curve.degree(), 2);
  EXPECT_EQ(r->curves[0].curve.knots().values(), (std::vector<double>{0, 0, 0, 1, 1, 1}));
  EXPECT_TRUE(r->curves[0].curve.isRational());
  EXPECT_EQ(r->curves[1].curve.dim(), 2);
  // 2-D control points lie in the plane z = 0 of the bounding box.
  const BoundingBox box = controlBox(r->curves[1].curve);
  EXPECT_EQ(box.min, Vec3(0, 0, 0));
  EXPECT_EQ(box.max, Vec3(3, 4, 0));
}

TEST(JsonRead, EmptyPatchListIsAValidEmptyModel) {
  const Result<Model> r = io::parseModelJson(R"({"patches": []})", "empty.json");
  ASSERT_TRUE(r.isOk()) << r.status().message();
  EXPECT_TRUE(r->patches.empty());
  EXPECT_TRUE(r->curves.empty());
}

TEST(JsonRead, BezierMayRepeatAConsistentDegree) {
  Json j = validModel();
  j["patches"][1]["degree"] = {2, 1};
  j["curves"][0] = {
      {"name", "C1"}, {"type", "bezier"}, {"degree", 2}, {"points", {{0, 0, 0}, {1, 1, 0}, {2, 0, 0}}}};
  const Result<Model> r = io::parseModelJson(j.dump(), "model.json");
  EXPECT_TRUE(r.isOk()) << r.status().message();
}

// ---------------------------------------------------------------------------------------------------------------
// Validation: one test per rule; every message names the file, the object and the problem.

TEST(JsonValidation, NotJsonReportsTheParsePosition) {
  const std::string message = errorOfText("{\n  \"patches\": [1, ]\n}");
  EXPECT_THAT(message, StartsWith("model.json: not valid JSON: parse error at line 2, column 18: "));
}

TEST(JsonValidation, EmptyText) {
  EXPECT_THAT(errorOfText(std::string()),
              StartsWith("model.json: not valid JSON: parse error at line 1, column 1: "));
}

TEST(JsonValidation, TopLevelMustBeAnObject) {
  EXPECT_EQ(errorOfText("[1, 2]"),
            "model.json: the top level must be an object with \"patches\" and/or \"curves\", found array");
}

TEST(JsonValidation, MissingPatchesAndCurves) {
  EXPECT_EQ(errorOfText("{}"), "model.json: no \"patches\" or \"curves\" array at the top level");
}

TEST(JsonValidation, UnknownTopLevelKey) {
  Json j = validModel();
  j["patchez"] = Json::array();
  EXPECT_EQ(errorOf(j),
            "model.json: unknown top-level key \"patchez\" (expected \"patches\" and/or \"curves\", and \"brep\")");
}

TEST(JsonValidation, PatchesMustBeAnArray) {
  EXPECT_EQ(errorOfText(R"({"patches": {"name": "S1"}})"),
            "model.json: \"patches\" must be an array, found object");
  EXPECT_EQ(errorOfText(R"({"curves": 3})"), "model.json: \"curves\" must be an array, found number");
}

TEST(JsonValidation, PatchMustBeAnObject) {
  EXPECT_EQ(errorOfText(R"({"patches": [[1, 2]]})"),
            "model.json: patches[0]: must be an object, found array");
}

TEST(JsonValidation, MissingName) {
  Json j = validModel();
  j["patches"][1].erase("name");
  EXPECT_EQ(errorOf(j), "model.json: patches[1]: missing \"name\"");
  j = validModel();
  j["curves"][0].erase("name");
  EXPECT_EQ(errorOf(j), "model.json: curves[0]: missing \"name\"");
}

TEST(JsonValidation, NameMustBeANonEmptyString) {
  Json j = validModel();
  j["patches"][0]["name"] = "";
  EXPECT_EQ(errorOf(j), "model.json: patches[0]: \"name\" must be a non-empty string, found \"\"");
  j["patches"][0]["name"] = 7;
  EXPECT_EQ(errorOf(j), "model.json: patches[0]: \"name\" must be a non-empty string, found 7");
}

TEST(JsonValidation, DuplicateNamesAcrossPatchesAndCurves) {
  Json j = validModel();
  j["curves"][0]["name"] = "S1";
  EXPECT_EQ(errorOf(j), "model.json: curve \"S1\": duplicate name (already used by patch \"S1\")");
  j = validModel();
  j["patches"][1]["name"] = "S1";
  EXPECT_EQ(errorOf(j), "model.json: patch \"S1\": duplicate name (already used by patch \"S1\")");
}

TEST(JsonValidation, MissingType) {
  Json j = validModel();
  j["patches"][0].erase("type");
  EXPECT_EQ(errorOf(j), "model.json: patch \"S1\": missing \"type\" (\"bspline\" or \"bezier\")");
}

TEST(JsonValidation, UnknownType) {
  Json j = validModel();
  j["patches"][0]["type"] = "nurbs";
  EXPECT_EQ(errorOf(j),
            "model.json: patch \"S1\": unknown type \"nurbs\" (expected \"bspline\" or \"bezier\")");
  j = validModel();
  j["curves"][0]["type"] = 3;
  EXPECT_EQ(errorOf(j),
            "model.json: curve \"C1\": \"type\" must be the string \"bspline\" or \"bezier\", found 3");
}

TEST(JsonValidation, UnknownKey) {
  Json j = validModel();
  j["patches"][0]["weight"] = Json::array();
  EXPECT_EQ(errorOf(j), "model.json: patch \"S1\": unknown key \"weight\"");
}

TEST(JsonValidation, BezierHasNoKnots) {
  Json j = validModel();
  j["patches"][1]["knots"] = {{0, 0, 0, 1, 1, 1}, {0, 0, 1, 1}};
  EXPECT_EQ(errorOf(j),
            "model.json: patch \"B1\": a bezier patch has no \"knots\" (its degree is the number of points "
            "minus 1; "
            "use type \"bspline\" to give knots)");
}

TEST(JsonValidation, BezierDegreeMustMatchThePoints) {
  Json j = validModel();
  j["patches"][1]["degree"] = {3, 3};
  EXPECT_EQ(
      errorOf(j),
      "model.json: patch \"B1\": \"degree\" [3,3] does not match the control points: a bezier degree is the "
      "number of points minus 1, here [2, 1]");
}

TEST(JsonValidation, MissingPoints) {
  Json j = validModel();
  j["patches"][0].erase("points");
  EXPECT_EQ(errorOf(j), "model.json: patch \"S1\": missing \"points\"");
}

TEST(JsonValidation, EmptyPoints) {
  Json j = validModel();
  j["patches"][1]["points"] = Json::array();
  EXPECT_EQ(
      errorOf(j),
      "model.json: patch \"B1\": \"points\" must be a non-empty array of rows of points [[[x, y, z], ...], "
      "...], found []");
  j = validModel();
  j["curves"][0]["points"] = Json::array();
  EXPECT_EQ(errorOf(j),
            "model.json: curve \"C1\": \"points\" must be a non-empty array of points [[x, y, z], ...], "
            "found []");
}

TEST(JsonValidation, RaggedPointGrid) {
  Json j = validModel();
  j["patches"][0]["points"][2].push_back({2, 2, 2});
  EXPECT_EQ(errorOf(j), "model.json: patch \"S1\": ragged point grid: row 2 has 3 points, row 0 has 2");
}

TEST(JsonValidation, PatchPointsMustBe3D) {
  Json j = validModel();
  j["patches"][0]["points"][1][0] = {1, 0};
  EXPECT_EQ(errorOf(j), "model.json: patch \"S1\": point [1][0] has 2 coordinates, expected 3");
  j["patches"][0]["points"][1][0] = 5;
  EXPECT_EQ(errorOf(j), "model.json: patch \"S1\": point [1][0] must be an array of 3 numbers, found 5");
}

TEST(JsonValidation, CurvePointsMustAllHaveTheSameDimension) {
  Json j = validModel();
  j["curves"][0]["points"][2] = {2, 0};
  EXPECT_EQ(errorOf(j), "model.json: curve \"C1\": point 2 has 2 coordinates, expected 3 like point 0");
  j["curves"][0]["points"][0] = {0, 0, 0, 1};
  EXPECT_EQ(errorOf(j), "model.json: curve \"C1\": point 0 has 4 coordinates, expected 2 or 3");
}

TEST(JsonValidation, CoordinateMustBeANumber) {
  Json j = validModel();
  j["patches"][0]["points"][4][1][1] = "1";
  EXPECT_EQ(errorOf(j), "model.json: patch \"S1\": point [4][1]: y is not a number (found \"1\")");
  j = validModel();
  j["curves"][0]["points"][1][2] = nullptr;
  EXPECT_EQ(errorOf(j), "model.json: curve \"C1\": point 1: z is not a number (found null)");
}

TEST(JsonValidation, OverflowingNumbersAreNotFinite) {
  // JSON cannot hold NaN or infinity, but 1e999 overflows a double while parsing.
  std::string text = validModel().dump();
  const std::string point = "[2,1,0.5]";  // S1 point [2][1]
  ASSERT_NE(text.find(point), std::string::npos);
  text.replace(text.find(point), point.size(), "[2,1,1e999]");
  EXPECT_EQ(
      errorOfText(text),
      "model.json: patch \"S1\": point [2][1]: z = 1e999 is not a finite number (it overflows a double)");

  text = validModel().dump();
  const std::string knots = "[0,0,1,1]";  // S1 v knots
  ASSERT_NE(text.find(knots), std::string::npos);
  text.replace(text.find(knots), knots.size(), "[0,0,1,-1E+400]");
  EXPECT_EQ(errorOfText(text),
            "model.json: patch \"S1\": v knot 3 = -1E+400 is not a finite number (it overflows a double)");

  text = validModel().dump();
  const std::string weights = "[0.5,0.5]";  // B1 weights row 1
  ASSERT_NE(text.find(weights), std::string::npos);
  text.replace(text.find(weights), weights.size(), "[0.5,2e308]");
  EXPECT_EQ(errorOfText(text),
            "model.json: patch \"B1\": weight [1][1] = 2e308 is not a finite number (it overflows a double)");
}

TEST(JsonValidation, OverflowInABrokenFileReportsItsPosition) {
  EXPECT_EQ(
      errorOfText("{\"patches\": [\n  [1e999, }"),
      "model.json: not valid JSON: line 2, column 4: number 1e999 is not a finite number (it overflows a "
      "double)");
}

TEST(JsonValidation, NumbersInsideStringsAreNotNumbers) {
  // The overflow rewrite must not touch string contents.
  Json j = validModel();
  j["patches"][0]["name"] = "1e999";
  const Result<Model> r = io::parseModelJson(j.dump(), "model.json");
  ASSERT_TRUE(r.isOk()) << r.status().message();
  EXPECT_EQ(r->patches[0].name, "1e999");
}

TEST(JsonValidation, NonPositiveWeights) {
  Json j = validModel();
  j["patches"][1]["weights"][2][0] = 0;
  EXPECT_EQ(errorOf(j), "model.json: patch \"B1\": weight [2][0] = 0 is not positive (weights must be > 0)");
  j["patches"][1]["weights"][2][0] = -0.5;
  EXPECT_EQ(errorOf(j),
            "model.json: patch \"B1\": weight [2][0] = -0.5 is not positive (weights must be > 0)");
  j = validModel();
  j["curves"][0]["weights"] = {1, -1, 1};
  EXPECT_EQ(errorOf(j), "model.json: curve \"C1\": weight 1 = -1 is not positive (weights must be > 0)");
}

TEST(JsonValidation, WeightsMustHaveTheShapeOfThePoints) {
  Json j = validModel();
  j["patches"][1]["weights"].erase(2);
  EXPECT_EQ(errorOf(j), "model.json: patch \"B1\": \"weights\" has 2 rows, expected 3 like \"points\"");
  j = validModel();
  j["patches"][1]["weights"][1] = {0.5};
  EXPECT_EQ(errorOf(j),
            "model.json: patch \"B1\": \"weights\"[1] must be an array of 2 numbers like \"points\"[1], "
            "found [0.5]");
  j = validModel();
  j["curves"][0]["weights"] = {1, 1};
  EXPECT_EQ(errorOf(j), "model.json: curve \"C1\": \"weights\" has 2 entries, expected 3 (one per point)");
  j["curves"][0]["weights"] = 1;
  EXPECT_EQ(errorOf(j), "model.json: curve \"C1\": \"weights\" must be an array of numbers, found 1");
}

TEST(JsonValidation, MissingDegreeOrKnots) {
  Json j = validModel();
  j["patches"][0].erase("degree");
  EXPECT_EQ(errorOf(j), "model.json: patch \"S1\": missing \"degree\" ([p, q] for a bspline patch)");
  j = validModel();
  j["patches"][0].erase("knots");
  EXPECT_EQ(errorOf(j),
            "model.json: patch \"S1\": missing \"knots\" ([[u knots], [v knots]] for a bspline patch)");
  j = validModel();
  j["curves"][0].erase("degree");
  EXPECT_EQ(errorOf(j), "model.json: curve \"C1\": missing \"degree\" (an integer for a bspline curve)");
  j = validModel();
  j["curves"][0].erase("knots");
  EXPECT_EQ(errorOf(j),
            "model.json: curve \"C1\": missing \"knots\" (an array of numbers for a bspline curve)");
}

TEST(JsonValidation, DegreeMustBeIntegers) {
  Json j = validModel();
  j["patches"][0]["degree"] = {3.5, 1};
  EXPECT_EQ(errorOf(j),
            "model.json: patch \"S1\": \"degree\" must be an array of two integers [p, q], found [3.5,1]");
  j["patches"][0]["degree"] = 3;
  EXPECT_EQ(errorOf(j),
            "model.json: patch \"S1\": \"degree\" must be an array of two integers [p, q], found 3");
  j = validModel();
  j["curves"][0]["degree"] = "2";
  EXPECT_EQ(errorOf(j), "model.json: curve \"C1\": \"degree\" must be an integer, found \"2\"");
}

TEST(JsonValidation, DegreeLessThanOne) {
  Json j = validModel();
  j["patches"][0]["degree"] = {3, 0};
  EXPECT_EQ(errorOf(j), "model.json: patch \"S1\": v degree is 0, must be at least 1");
  j = validModel();
  j["curves"][0]["degree"] = -2;
  EXPECT_EQ(errorOf(j), "model.json: curve \"C1\": degree is -2, must be at least 1");
  // A bezier with one row of points would have degree 0.
  j = validModel();
  j["patches"][1]["points"] = Json::parse("[[[0, 0, 0], [0, 1, 0]]]");
  j["patches"][1].erase("weights");
  EXPECT_EQ(errorOf(j), "model.json: patch \"B1\": u degree is 0, must be at least 1");
}

TEST(JsonValidation, DegreeTooHighForThePoints) {
  Json j = validModel();
  j["patches"][0]["degree"] = {5, 1};
  EXPECT_EQ(
      errorOf(j),
      "model.json: patch \"S1\": u degree 5 needs at least 6 control points in that direction, found 5");
  j = validModel();
  j["curves"][0]["degree"] = 3;
  EXPECT_EQ(errorOf(j), "model.json: curve \"C1\": degree 3 needs at least 4 control points, found 3");
}

TEST(JsonValidation, OverflowingDegreeIsNamedNotPrintedNegative) {
  Json j = validModel();
  j["patches"][0]["degree"] = {std::numeric_limits<std::int64_t>::max(), 1};
  EXPECT_EQ(errorOf(j),
            "model.json: patch \"S1\": u degree 9223372036854775807 is too large (at most 2147483646, and at most "
            "the number of control points in that direction minus 1, here 4)");
  j = validModel();
  j["curves"][0]["degree"] = std::numeric_limits<std::int64_t>::max();
  EXPECT_EQ(errorOf(j),
            "model.json: curve \"C1\": degree 9223372036854775807 is too large (at most 2147483646, and at most the "
            "number of control points minus 1, here 2)");
  // The largest degree that still fits keeps the usual message (degree + 1 computed without overflow).
  j = validModel();
  j["patches"][0]["degree"] = {2147483646, 1};
  EXPECT_EQ(errorOf(j),
            "model.json: patch \"S1\": u degree 2147483646 needs at least 2147483647 control points in that "
            "direction, found 5");
}

TEST(JsonValidation, DeepNestingIsRefusedBeforeParsing) {
  // 80 000 levels overflowed the stack while the message was built (issue 15); 257 is already refused, 256 is
  // parsed (and then rejected as a model for what it is).
  auto nested = [](int depth) {
    return "{\"patches\": [{\"name\": " + std::string(static_cast<size_t>(depth), '[') +
           std::string(static_cast<size_t>(depth), ']') + "}]}";
  };
  EXPECT_EQ(errorOfText(nested(80000)),
            // '{' '[' '{' then the brackets from column 23: the 254th (column 276) is level 257.
            "model.json: not valid as a model: line 1, column 276: arrays and objects nested more than 256 deep (a "
            "model needs 6 levels)");
  EXPECT_THAT(errorOfText(nested(254)), HasSubstr("nested more than 256 deep"));  // 3 + 254 = 257 levels
  EXPECT_EQ(errorOfText(nested(253)),
            "model.json: patches[0]: \"name\" must be a non-empty string, found " + std::string(40, '[') + "...");
  // Brackets inside strings do not count.
  Json j = validModel();
  j["patches"][0]["name"] = std::string(1000, '[');
  EXPECT_TRUE(io::parseModelJson(j.dump(), "model.json").isOk());
}

TEST(JsonValidation, NulByteIsRefusedWithItsPosition) {
  const std::string valid = validModel().dump(1);
  ASSERT_TRUE(io::parseModelJson(valid, "model.json").isOk());
  // Text after a NUL byte used to be ignored.
  EXPECT_EQ(errorOfText(valid + std::string(1, '\0') + "garbage"),
            fmt::format("model.json: not valid JSON: line {}, column 2: a NUL byte (JSON text cannot hold one; the "
                        "file is binary or damaged)",
                        std::count(valid.begin(), valid.end(), '\n') + 1));
  EXPECT_EQ(errorOfText(std::string("{\"patches\": \"a\0b\"}", 18)),
            "model.json: not valid JSON: line 1, column 15: a NUL byte (JSON text cannot hold one; the file is "
            "binary or damaged)");
}

TEST(JsonValidation, KnotCountMustMatchPointsAndDegree) {
  // The example of the issue: 6 control points of degree 3 need 10 knots.
  Json j = validModel();
  Json s2 = j["patches"][0];
  s2["name"] = "S2";
  s2["points"].push_back({{5, 0, 0}, {5, 1, 0}});
  j["patches"].push_back(s2);
  EXPECT_EQ(
      errorOf(j),
      "model.json: patch \"S2\": u knot vector has 9 entries, expected 10 for 6 control points of degree 3");
  j = validModel();
  j["curves"][0]["knots"] = {0, 0, 0, 1, 1, 1, 1};
  EXPECT_EQ(errorOf(j),
            "model.json: curve \"C1\": knot vector has 7 entries, expected 6 for 3 control points of "
            "degree 2");
}

TEST(JsonValidation, DegreeMismatchWithKnots) {
  // Degree 2 with the knots of a cubic: the count no longer matches.
  Json j = validModel();
  j["patches"][0]["degree"] = {2, 1};
  EXPECT_EQ(
      errorOf(j),
      "model.json: patch \"S1\": u knot vector has 9 entries, expected 8 for 5 control points of degree 2");
}

TEST(JsonValidation, KnotsMustBeNumbers) {
  Json j = validModel();
  j["patches"][0]["knots"][0][4] = "0.5";
  EXPECT_EQ(errorOf(j), "model.json: patch \"S1\": u knot 4 is not a number (found \"0.5\")");
  j = validModel();
  j["patches"][0]["knots"] = Json::parse("[[0, 0, 0, 0, 0.5, 1, 1, 1, 1]]");
  EXPECT_EQ(errorOf(j),
            "model.json: patch \"S1\": \"knots\" must be an array of two knot vectors [[u knots], [v "
            "knots]], found [[0,0,0,0,0.5,1,1,1,1]]");
  j = validModel();
  j["patches"][0]["knots"][1] = 1;
  EXPECT_EQ(errorOf(j), "model.json: patch \"S1\": v knot vector must be an array of numbers, found 1");
}

TEST(JsonValidation, NonMonotoneKnots) {
  Json j = validModel();
  j["patches"][0]["knots"][0] = {0, 0, 0, 0, 0.7, 0.6, 1, 1, 1};
  EXPECT_EQ(errorOf(j),
            "model.json: patch \"S1\": u knots must be non-decreasing, but knot 5 (0.6) < knot 4 (0.7)");
}

TEST(JsonValidation, InteriorMultiplicityAboveDegree) {
  Json j = validModel();
  j["curves"][0]["points"] = {{0, 0, 0}, {1, 1, 0}, {2, 0, 0}, {3, 1, 0}, {4, 0, 0}, {5, 1, 0}};
  j["curves"][0]["knots"] = {0, 0, 0, 0.5, 0.5, 0.5, 1, 1, 1};
  EXPECT_EQ(
      errorOf(j),
      "model.json: curve \"C1\": knot 0.5 has multiplicity 3 inside the domain, more than the degree 2");
}

TEST(JsonValidation, FullMultiplicityAtTheDomainEndIsNotInterior) {
  // Degree 2, 5 points: the domain is [t_2, t_5] = [0, 0.5], so the triple knot 0.5 is an end knot (allowed).
  Json j = validModel();
  j["curves"][0]["points"] = {{0, 0, 0}, {1, 1, 0}, {2, 0, 0}, {3, 1, 0}, {4, 0, 0}};
  j["curves"][0]["knots"] = {0, 0, 0, 0.5, 0.5, 0.5, 1, 1};
  const Result<Model> r = io::parseModelJson(j.dump(), "model.json");
  ASSERT_TRUE(r.isOk()) << r.status().message();
  EXPECT_EQ(r->curves[0].curve.domain(), (Interval{0.0, 0.5}));
}

TEST(JsonValidation, EndMultiplicityAboveDegreePlusOne) {
  Json j = validModel();
  j["curves"][0]["degree"] = 1;
  j["curves"][0]["knots"] = {0, 0, 0, 1, 2};
  EXPECT_EQ(errorOf(j), "model.json: curve \"C1\": knot 0 has multiplicity 3, more than degree + 1 = 2");
}

TEST(JsonValidation, EmptyDomain) {
  Json j = validModel();
  j["curves"][0]["degree"] = 1;
  j["curves"][0]["points"] = {{0, 0, 0}, {1, 1, 0}};
  j["curves"][0]["knots"] = {0, 1, 1, 2};
  EXPECT_EQ(errorOf(j),
            "model.json: curve \"C1\": parameter domain [1, 1] is empty (knots 1 and 2 are equal)");
}

TEST(JsonValidation, MessagesNameTheFileAsGiven) {
  TempDir dir;
  const fs::path file = dir.path() / "broken model.json";
  Json j = validModel();
  j["patches"][0]["type"] = "nurbs";
  writeText(file, j.dump());
  const Result<Model> r = io::readModelJson(file);
  ASSERT_FALSE(r.isOk());
  EXPECT_EQ(r.status().message(),
            file.string() + ": patch \"S1\": unknown type \"nurbs\" (expected \"bspline\" or \"bezier\")");
  const Result<Model> viaDispatch = io::readModel(file);
  ASSERT_FALSE(viaDispatch.isOk());
  EXPECT_EQ(viaDispatch.status().message(), r.status().message());
}

// ---------------------------------------------------------------------------------------------------------------
// Round trip: write, read back, compare every double bit for bit.

/// Deterministic random numbers that do not depend on the standard library's distributions.
class Random {
 public:
  explicit Random(std::uint64_t seed) : engine_(seed) {}
  /// Uniform in [0, 1) with all 53 bits random.
  double unit() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }
  int integer(int lo, int hi) {
    return lo + static_cast<int>(engine_() % static_cast<std::uint64_t>(hi - lo + 1));
  }
  /// A double that needs all 17 significant digits, of varied sign and magnitude, sometimes a special value.
  double nasty() {
    static const double kSpecial[] = {-0.0,
                                      0.0,
                                      5e-324,
                                      2.2250738585072014e-308,
                                      1.7976931348623157e308,
                                      0.1,
                                      1.0 / 3.0,
                                      9007199254740993.0,
                                      -1e-300,
                                      123456789.123456789};
    if (integer(0, 9) == 0) return kSpecial[integer(0, 9)];
    const double mantissa = 1.0 + unit();
    const int exponent = integer(-40, 40);
    return (integer(0, 1) != 0 ? -1.0 : 1.0) * std::ldexp(mantissa, exponent);
  }
  /// A positive weight with a random mantissa.
  double weight() { return std::ldexp(0.5 + unit(), integer(-3, 3)); }

 private:
  std::mt19937_64 engine_;
};

/// A valid knot vector for n points of degree p with random interior knots (multiplicity <= p) on a random
/// domain.
std::vector<double> randomKnots(Random& rng, int p, int n) {
  const double a = rng.integer(0, 3) == 0 ? -0.0 : std::ldexp(rng.unit() - 0.5, rng.integer(-4, 4));
  const double length = std::ldexp(0.5 + rng.unit(), rng.integer(-4, 4));
  std::vector<double> interior;
  const int numInterior = n - p - 1;
  while (static_cast<int>(interior.size()) < numInterior) {
    const double t = a + length * (0.01 + 0.98 * rng.unit());
    const int mult = std::min(rng.integer(1, p), numInterior - static_cast<int>(interior.size()));
    for (int k = 0; k < mult; ++k) interior.push_back(t);
  }
  std::sort(interior.begin(), interior.end());
  std::vector<double> knots(static_cast<size_t>(p + 1), a);
  knots.insert(knots.end(), interior.begin(), interior.end());
  knots.insert(knots.end(), static_cast<size_t>(p + 1), a + length);
  return knots;
}

Model randomModel(Random& rng) {
  Model m;
  const int numPatches = rng.integer(1, 4);
  for (int k = 0; k < numPatches; ++k) {
    const bool bezier = rng.integer(0, 2) == 0;
    const bool rational = rng.integer(0, 1) == 1;
    const int pu = rng.integer(1, 5);
    const int pv = rng.integer(1, 5);
    const int nu = bezier ? pu + 1 : pu + 1 + rng.integer(0, 6);
    const int nv = bezier ? pv + 1 : pv + 1 + rng.integer(0, 6);
    std::vector<double> ku(static_cast<size_t>(2 * pu + 2), 0.0);
    std::vector<double> kv(static_cast<size_t>(2 * pv + 2), 0.0);
    if (bezier) {
      std::fill(ku.begin() + pu + 1, ku.end(), 1.0);
      std::fill(kv.begin() + pv + 1, kv.end(), 1.0);
    } else {
      ku = randomKnots(rng, pu, nu);
      kv = randomKnots(rng, pv, nv);
    }
    Matrix points(nu * nv, 3);
    for (Eigen::Index r = 0; r < points.rows(); ++r) {
      for (Eigen::Index c = 0; c < 3; ++c) points(r, c) = rng.nasty();
    }
    VecX weights;
    if (rational) {
      weights.resize(nu * nv);
      for (Eigen::Index r = 0; r < weights.size(); ++r) weights[r] = rng.weight();
    }
    Result<BSplineSurface> s = BSplineSurface::create(pu, pv, ku, kv, nu, nv, points, weights);
    EXPECT_TRUE(s.isOk()) << s.status().message();
    if (!s) continue;
    m.patches.push_back({fmt::format("patch {}{}", k, bezier ? " (bezier)" : " \"quoted\""),
                         bezier ? PatchKind::kBezier : PatchKind::kBSpline, std::move(s).value()});
  }
  const int numCurves = rng.integer(0, 3);
  for (int k = 0; k < numCurves; ++k) {
    const int p = rng.integer(1, 7);
    const int n = p + 1 + rng.integer(0, 8);
    const int dim = rng.integer(2, 3);
    Matrix points(n, dim);
    for (Eigen::Index r = 0; r < points.rows(); ++r) {
      for (Eigen::Index c = 0; c < dim; ++c) points(r, c) = rng.nasty();
    }
    VecX weights;
    if (rng.integer(0, 1) == 1) {
      weights.resize(n);
      for (Eigen::Index r = 0; r < n; ++r) weights[r] = rng.weight();
    }
    Result<BSplineCurve> c = BSplineCurve::create(p, randomKnots(rng, p, n), points, weights);
    EXPECT_TRUE(c.isOk()) << c.status().message();
    if (!c) continue;
    m.curves.push_back({fmt::format("curve/{}", k), std::move(c).value()});
  }
  return m;
}

void expectBitIdentical(const std::vector<double>& a, const std::vector<double>& b, const std::string& what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  for (size_t k = 0; k < a.size(); ++k) {
    EXPECT_EQ(std::bit_cast<std::uint64_t>(a[k]), std::bit_cast<std::uint64_t>(b[k]))
        << what << " [" << k << "]: " << a[k] << " vs " << b[k];
  }
}

std::vector<double> valuesOf(const Matrix& m) { return {m.data(), m.data() + m.size()}; }
std::vector<double> valuesOf(const VecX& v) { return {v.data(), v.data() + v.size()}; }

void expectSameModel(const Model& a, const Model& b) {
  ASSERT_EQ(a.patches.size(), b.patches.size());
  for (size_t k = 0; k < a.patches.size(); ++k) {
    const Patch& p = a.patches[k];
    const Patch& q = b.patches[k];
    EXPECT_EQ(p.name, q.name);
    EXPECT_EQ(p.kind, q.kind) << p.name;
    EXPECT_EQ(p.surface.degreeU(), q.surface.degreeU()) << p.name;
    EXPECT_EQ(p.surface.degreeV(), q.surface.degreeV()) << p.name;
    EXPECT_EQ(p.surface.numU(), q.surface.numU()) << p.name;
    EXPECT_EQ(p.surface.numV(), q.surface.numV()) << p.name;
    expectBitIdentical(p.surface.knotsU().values(), q.surface.knotsU().values(), p.name + " u knots");
    expectBitIdentical(p.surface.knotsV().values(), q.surface.knotsV().values(), p.name + " v knots");
    expectBitIdentical(valuesOf(p.surface.points()), valuesOf(q.surface.points()), p.name + " points");
    expectBitIdentical(valuesOf(p.surface.weights()), valuesOf(q.surface.weights()), p.name + " weights");
  }
  ASSERT_EQ(a.curves.size(), b.curves.size());
  for (size_t k = 0; k < a.curves.size(); ++k) {
    const Curve& c = a.curves[k];
    const Curve& d = b.curves[k];
    EXPECT_EQ(c.name, d.name);
    EXPECT_EQ(c.curve.degree(), d.curve.degree()) << c.name;
    EXPECT_EQ(c.curve.dim(), d.curve.dim()) << c.name;
    expectBitIdentical(c.curve.knots().values(), d.curve.knots().values(), c.name + " knots");
    expectBitIdentical(valuesOf(c.curve.points()), valuesOf(d.curve.points()), c.name + " points");
    expectBitIdentical(valuesOf(c.curve.weights()), valuesOf(d.curve.weights()), c.name + " weights");
  }
}

TEST(JsonRoundTrip, RandomModelsAreBitIdentical) {
  Random rng(20240611);
  constexpr int kModels = 50;
  for (int k = 0; k < kModels; ++k) {
    SCOPED_TRACE(fmt::format("model {}", k));
    const Model model = randomModel(rng);
    const std::string text = io::modelToJson(model);
    const Result<Model> back = io::parseModelJson(text, "roundtrip.json");
    ASSERT_TRUE(back.isOk()) << back.status().message();
    expectSameModel(model, *back);
    // Writing the model read back gives the same text.
    EXPECT_EQ(io::modelToJson(*back), text);
  }
}

TEST(JsonRoundTrip, ValidModelSurvivesTwoRoundTrips) {
  const Result<Model> first = io::parseModelJson(validModel().dump(), "model.json");
  ASSERT_TRUE(first.isOk()) << first.status().message();
  const Result<Model> second = io::parseModelJson(io::modelToJson(*first), "model.json");
  ASSERT_TRUE(second.isOk()) << second.status().message();
  expectSameModel(*first, *second);
}

TEST(JsonWrite, BezierPatchesAreWrittenAsBezier) {
  const Result<Model> m = io::parseModelJson(validModel().dump(), "model.json");
  ASSERT_TRUE(m.isOk()) << m.status().message();
  const Json j = Json::parse(io::modelToJson(*m));
  EXPECT_EQ(j["patches"][0]["type"], "bspline");
  EXPECT_EQ(j["patches"][0]["degree"], Json({3, 1}));
  EXPECT_EQ(j["patches"][1]["type"], "bezier");
  EXPECT_FALSE(j["patches"][1].contains("knots"));
  EXPECT_FALSE(j["patches"][1].contains("degree"));
  EXPECT_EQ(j["patches"][1]["weights"], Json({{1.0, 1.0}, {0.5, 0.5}, {1.0, 1.0}}));
  EXPECT_EQ(j["patches"][1]["points"][2][1], Json({2.0, 1.0, 2.0}));
  EXPECT_FALSE(j["patches"][0].contains("weights"));
  EXPECT_EQ(j["curves"][0]["name"], "C1");
}

TEST(JsonWrite, OnePointPerLine) {
  const Result<Model> m = io::parseModelJson(validModel().dump(), "model.json");
  ASSERT_TRUE(m.isOk());
  const std::string text = io::modelToJson(*m);
  EXPECT_THAT(text, HasSubstr("\n          [3.0, 0.0, 1.5],\n          [3.0, 1.0, 0.75]\n        ],\n"));
  EXPECT_THAT(text, HasSubstr("\"knots\": [\n        [0.0, 0.0, 0.0, 0.0, 0.5, 1.0, 1.0, 1.0, 1.0],\n"));
}

// ---------------------------------------------------------------------------------------------------------------
// Files: atomic writes, extension dispatch.

TEST(FileIo, AtomicWriteLeavesNoTemporaryFileAndKeepsTheInput) {
  TempDir dir;
  const fs::path input = dir.path() / "input.json";
  const fs::path output = dir.path() / "output.json";
  const std::string original = validModel().dump(2);
  writeText(input, original);
  const auto inputTime = fs::last_write_time(input);

  const Result<Model> m = io::readModel(input);
  ASSERT_TRUE(m.isOk()) << m.status().message();
  ASSERT_TRUE(io::writeModelJson(*m, output).isOk());
  EXPECT_EQ(readText(output), io::modelToJson(*m));
  EXPECT_EQ(readText(input), original);
  EXPECT_EQ(fs::last_write_time(input), inputTime);
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"input.json", "output.json"}));

  // Overwriting replaces the whole file (a longer old content leaves nothing behind).
  writeText(output, std::string(100000, 'x'));
  fs::permissions(output, fs::perms::owner_read | fs::perms::owner_write);
  ASSERT_TRUE(io::writeFileAtomically(output, "short\n").isOk());
  EXPECT_EQ(readText(output), "short\n");
  EXPECT_EQ(fs::status(output).permissions(), fs::perms::owner_read | fs::perms::owner_write)
      << "replacing a file keeps its permissions";
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"input.json", "output.json"}));
}

TEST(FileIo, AStreamedWriteIsItsPiecesInOrderAndAFailingProducerLeavesNothing) {
  TempDir dir;
  const fs::path file = dir.path() / "out.txt";
  ASSERT_TRUE(io::writeFileAtomically(file, [](const std::function<void(std::string_view)>& emit) {
                emit("first ");
                emit("");
                emit(std::string(3 << 20, 'y'));  // a piece larger than any buffer
                emit(" last\n");
              }).isOk());
  EXPECT_EQ(readText(file), "first " + std::string(3 << 20, 'y') + " last\n");
  // A producer that throws half-way (out of memory while building a piece): the old file stays, nothing else.
  EXPECT_THROW((void)io::writeFileAtomically(file,
                                             [](const std::function<void(std::string_view)>& emit) {
                                               emit("partial");
                                               throw std::bad_alloc();
                                             }),
               std::bad_alloc);
  EXPECT_EQ(readText(file), "first " + std::string(3 << 20, 'y') + " last\n");
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"out.txt"}));
}

TEST(JsonWrite, AModelOfManyMegabytesIsWrittenInPiecesThatReadBackBitForBit) {
  // writeModelJson passes the text to the file about 1 MB at a time (never the whole text in memory): a model of
  // about 6 MB of text, read back by the reader (an independent route: simdjson), is the model written.
  Random rng(3703);
  Model model;
  while (model.patches.size() < 4000) {
    Model part = randomModel(rng);
    for (Patch& p : part.patches) {
      p.name = "P" + std::to_string(model.patches.size());
      model.patches.push_back(std::move(p));
    }
  }
  TempDir dir;
  const fs::path file = dir.path() / "big.json";
  ASSERT_TRUE(io::writeModelJson(model, file).isOk());
  EXPECT_GT(fs::file_size(file), 4u << 20);
  const Result<Model> back = io::readModel(file);
  ASSERT_TRUE(back.isOk()) << back.status().message();
  expectSameModel(model, *back);
  EXPECT_EQ(readText(file), io::modelToJson(model));
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"big.json"}));
}

TEST(FileIo, FailedWriteReportsTheFileAndLeavesNothing) {
  TempDir dir;
  const fs::path file = dir.path() / "missing-folder" / "out.json";
  const Status s = io::writeFileAtomically(file, "{}");
  ASSERT_FALSE(s.isOk());
  EXPECT_EQ(s.code(), ErrorCode::kIoError);
  EXPECT_THAT(s.message(), StartsWith(file.string() + ": cannot create temporary file "));
  EXPECT_TRUE(dir.entries().empty());
}

TEST(FileIo, ReadMissingFile) {
  TempDir dir;
  const fs::path file = dir.path() / "nothing.json";
  const Result<Model> r = io::readModel(file);
  ASSERT_FALSE(r.isOk());
  EXPECT_EQ(r.status().code(), ErrorCode::kIoError);
  EXPECT_EQ(r.status().message(), file.string() + ": cannot read file: no such file");
  const Result<std::string> d = io::readFile(dir.path());
  ASSERT_FALSE(d.isOk());
  EXPECT_EQ(d.status().message(), dir.path().string() + ": cannot read file: it is a directory");
}

TEST(FileIo, NonRegularInputsAreRefusedWithoutBlocking) {
  TempDir dir;
  // A FIFO with no writer would block a plain open(); /dev/zero would be read until memory runs out.
  const fs::path fifo = dir.path() / "pipe.json";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  Result<Model> r = io::readModel(fifo);
  ASSERT_FALSE(r.isOk());
  EXPECT_EQ(r.status().code(), ErrorCode::kIoError);
  EXPECT_EQ(r.status().message(), fifo.string() + ": cannot read file: not a regular file (a FIFO)");
  const fs::path zero = dir.path() / "zero.bpt";
  fs::create_symlink("/dev/zero", zero);
  r = io::readModel(zero);
  ASSERT_FALSE(r.isOk());
  EXPECT_EQ(r.status().message(), zero.string() + ": cannot read file: not a regular file (a character device)");
  const fs::path folder = dir.path() / "folder.bpt";
  fs::create_directory(folder);
  r = io::readModel(folder);
  ASSERT_FALSE(r.isOk());
  EXPECT_EQ(r.status().message(), folder.string() + ": cannot read file: it is a directory");
  // A symbolic link to a regular file is read.
  const fs::path target = dir.path() / "model.json";
  writeText(target, validModel().dump());
  fs::create_symlink(target, dir.path() / "link.json");
  EXPECT_TRUE(io::readModel(dir.path() / "link.json").isOk());
}

TEST(FileIo, SizeLimitIsCheckedBeforeReading) {
  TempDir dir;
  const fs::path file = dir.path() / "big.json";
  writeText(file, std::string(1000, ' '));
  EXPECT_TRUE(io::readFile(file, 1000).isOk());
  const Result<std::string> r = io::readFile(file, 999);
  ASSERT_FALSE(r.isOk());
  EXPECT_EQ(r.status().message(), file.string() + ": cannot read file: too large (1000 bytes, at most 999 are read)");
  EXPECT_EQ(io::checkInputFile(file, 999).message(), r.status().message());
  EXPECT_TRUE(io::checkInputFile(file).isOk());
}

TEST(FileIo, AtomicWriteRefusesNonRegularTargetsAndLeavesThemAlone) {
  TempDir dir;
  const fs::path real = dir.path() / "real.json";
  writeText(real, "original");
  const fs::path link = dir.path() / "link.json";
  fs::create_symlink(real, link);
  Status s = io::writeFileAtomically(link, "new");
  ASSERT_FALSE(s.isOk());
  EXPECT_EQ(s.code(), ErrorCode::kIoError);
  EXPECT_EQ(s.message(), link.string() + ": cannot write: refusing to replace a symbolic link (only a regular file "
                                         "or a new name can be an output)");
  EXPECT_TRUE(fs::is_symlink(link));
  EXPECT_EQ(readText(real), "original");
  const fs::path fifo = dir.path() / "pipe.obj";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  s = io::writeFileAtomically(fifo, "new");
  EXPECT_EQ(s.message(), fifo.string() + ": cannot write: refusing to replace a FIFO (only a regular file or a new "
                                         "name can be an output)");
  EXPECT_TRUE(fs::is_fifo(fifo));
  s = io::writeFileAtomically("/dev/null", "new");
  EXPECT_EQ(s.message(), "/dev/null: cannot write: refusing to replace a character device (only a regular file or "
                         "a new name can be an output)");
  s = io::writeFileAtomically(dir.path(), "new");
  EXPECT_EQ(s.message(), dir.path().string() + ": cannot write: it is a directory");
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"link.json", "pipe.obj", "real.json"}));
}

TEST(FileIo, LongestLegalOutputNameWorks) {
  // 255 bytes is the file-name limit of ext4/tmpfs; a temporary name derived from the output's name would not fit.
  TempDir dir;
  for (const size_t length : {249u, 255u}) {
    const fs::path file = dir.path() / (std::string(length - 5, 'a') + ".json");
    ASSERT_EQ(file.filename().string().size(), length);
    const Status s = io::writeFileAtomically(file, "content");
    ASSERT_TRUE(s.isOk()) << s.message();
    EXPECT_EQ(readText(file), "content");
    fs::remove(file);
    // The temporary name is short and in the same folder (a rename never crosses file systems).
    const fs::path temp = io::temporaryPathFor(file);
    EXPECT_EQ(temp.parent_path(), file.parent_path());
    EXPECT_LT(temp.filename().string().size(), 40u);
    EXPECT_NE(io::temporaryPathFor(file), temp) << "two calls give two names";
  }
  EXPECT_TRUE(dir.entries().empty());
}

TEST(FileIo, ReadModelDispatchesOnTheExtension) {
  TempDir dir;
  const fs::path upper = dir.path() / "MODEL.JSON";
  writeText(upper, validModel().dump());
  EXPECT_TRUE(io::readModel(upper).isOk());

  const Result<Model> step = io::readModel("part.step");
  ASSERT_FALSE(step.isOk());
  EXPECT_EQ(step.status().code(), ErrorCode::kUnsupported);
  // io_test does not link seam::occt: no STEP/IGES reader is registered (occt_cad_io_test checks the one that is).
  ASSERT_FALSE(io::hasCadReader());
  EXPECT_EQ(step.status().message(),
            "part.step: STEP/IGES support needs a build with SEAM_WITH_OCCT, linking seam::occt");
  for (const char* name : {"a.stp", "b.IGES", "c.igs"}) {
    const Result<Model> r = io::readModel(name);
    ASSERT_FALSE(r.isOk());
    EXPECT_EQ(r.status().message(),
              std::string(name) + ": STEP/IGES support needs a build with SEAM_WITH_OCCT, linking seam::occt");
  }
  const Result<Model> obj = io::readModel("mesh.obj");
  ASSERT_FALSE(obj.isOk());
  EXPECT_EQ(obj.status().code(), ErrorCode::kUnsupported);
  EXPECT_EQ(obj.status().message(), "mesh.obj: unsupported file extension \".obj\" (supported: .json, .bpt "
                                    "(STEP/IGES need a build with SEAM_WITH_OCCT))");
  const Result<Model> none = io::readModel("model");
  ASSERT_FALSE(none.isOk());
  EXPECT_EQ(none.status().message(), "model: no file extension, cannot tell the format (supported: .json, .bpt "
                                     "(STEP/IGES need a build with SEAM_WITH_OCCT))");
}

// ---------------------------------------------------------------------------------------------------------------
// .bpt (Newell tea set)

const fs::path kBezierData = fs::path(SEAM_SHARED_DATA_DIR) / "bezier";

TEST(Bpt, TeapotHas32BicubicPatches) {
  const Result<Model> r = io::readModel(kBezierData / "teapot.bpt");
  ASSERT_TRUE(r.isOk()) << r.status().message();
  ASSERT_EQ(r->patches.size(), 32u);
  EXPECT_TRUE(r->curves.empty());
  for (size_t k = 0; k < r->patches.size(); ++k) {
    const Patch& p = r->patches[k];
    EXPECT_EQ(p.name, fmt::format("P{}", k));
    EXPECT_EQ(p.kind, PatchKind::kBezier);
    EXPECT_EQ(p.surface.degreeU(), 3);
    EXPECT_EQ(p.surface.degreeV(), 3);
    EXPECT_EQ(p.surface.knotsU().values(), (std::vector<double>{0, 0, 0, 0, 1, 1, 1, 1}));
    EXPECT_FALSE(p.surface.isRational());
  }
  // Hand-checked against the file: line 3 is "1.4 0.0 2.4" (first point of P0), line 7 "1.3375 0.0 2.53125"
  // (the first point of the second row, i = 1), line 18 "0.0 -1.5 2.4" (last point of P0).
  const BSplineSurface& s = r->patches[0].surface;
  EXPECT_EQ(s.point(0, 0)[0], 1.4);
  EXPECT_EQ(s.point(0, 0)[1], 0.0);
  EXPECT_EQ(s.point(0, 0)[2], 2.4);
  EXPECT_EQ(s.point(1, 0)[0], 1.3375);
  EXPECT_EQ(s.point(1, 0)[2], 2.53125);
  EXPECT_EQ(s.point(0, 1)[1], -0.784);
  EXPECT_EQ(s.point(3, 3)[0], 0.0);
  EXPECT_EQ(s.point(3, 3)[1], -1.5);
  EXPECT_EQ(s.point(3, 3)[2], 2.4);
  // The teapot is about 6.4 x 4 x 3.15 (z up, from 0 to 3.15).
  const BoundingBox box = r->boundingBox();
  EXPECT_EQ(box.min.z(), 0.0);
  EXPECT_EQ(box.max.z(), 3.15);
}

TEST(Bpt, TeacupAndTeaspoon) {
  const Result<Model> cup = io::readModel(kBezierData / "teacup.bpt");
  ASSERT_TRUE(cup.isOk()) << cup.status().message();
  EXPECT_EQ(cup->patches.size(), 26u);
  const Result<Model> spoon = io::readModel(kBezierData / "teaspoon.bpt");
  ASSERT_TRUE(spoon.isOk()) << spoon.status().message();
  EXPECT_EQ(spoon->patches.size(), 16u);
}

TEST(Bpt, LineEndingsLfAndCrlfAndNonSquareDegrees) {
  // One patch of degree 1 x 2: (du+1)(dv+1) = 6 points, row-major with i along u.
  const std::string lf = "1\n1 2\n0 0 0\n0 1 0\n0 2 1\n1 0 0\n1 1 0\n1 2 1.5\n";
  std::string crlf;
  for (const char c : lf) crlf += c == '\n' ? std::string("\r\n") : std::string(1, c);
  for (const std::string& text : {lf, crlf}) {
    const Result<Model> r = io::parseBpt(text, "small.bpt");
    ASSERT_TRUE(r.isOk()) << r.status().message();
    ASSERT_EQ(r->patches.size(), 1u);
    const BSplineSurface& s = r->patches[0].surface;
    EXPECT_EQ(s.degreeU(), 1);
    EXPECT_EQ(s.degreeV(), 2);
    EXPECT_EQ(s.point(1, 2)[2], 1.5);
    EXPECT_EQ(s.point(0, 2)[2], 1.0);
  }
}

TEST(Bpt, MalformedFiles) {
  auto message = [](const std::string& text) {
    const Result<Model> r = io::parseBpt(text, "bad.bpt");
    EXPECT_FALSE(r.isOk()) << text;
    return r.isOk() ? std::string() : r.status().message();
  };
  const std::string patch = "1 1\r\n0 0 0\r\n0 1 0\r\n1 0 0\r\n1 1 0\r\n";
  EXPECT_EQ(message(""), "bad.bpt: empty file (expected the number of patches on the first line)");
  EXPECT_EQ(message("two\r\n"),
            "bad.bpt: line 1: expected the number of patches (a non-negative integer), found \"two\"");
  EXPECT_EQ(message("2\r\n" + patch), "bad.bpt: file ends after 1 of 2 patches (the first line announces 2)");
  EXPECT_EQ(message("1\r\n1\r\n"),
            "bad.bpt: patch P0: line 2: expected the degrees \"du dv\" (two integers), found \"1\"");
  EXPECT_EQ(message("1\r\n0 3\r\n0 0 0\r\n"),
            "bad.bpt: patch P0: line 2: degrees 0 3: both must be at least 1");
  EXPECT_EQ(message("1\r\n1 1\r\n0 0 0\r\n0 1\r\n1 0 0\r\n1 1 0\r\n"),
            "bad.bpt: patch P0: line 4: expected a point \"x y z\" (3 numbers), found \"0 1\"");
  EXPECT_EQ(message("1\r\n1 1\r\n0 0 0\r\n0 1 nan\r\n1 0 0\r\n1 1 0\r\n"),
            "bad.bpt: patch P0: line 4: \"nan\" is not a finite number");
  EXPECT_EQ(message("1\r\n1 1\r\n0 0 0\r\n0 1 1e999\r\n1 0 0\r\n1 1 0\r\n"),
            "bad.bpt: patch P0: line 4: \"1e999\" is not a finite number");
  EXPECT_EQ(message("1\r\n1 1\r\n0 0 0\r\n0 1 0x\r\n1 0 0\r\n1 1 0\r\n"),
            "bad.bpt: patch P0: line 4: \"0x\" is not a finite number");
  EXPECT_EQ(message("1\r\n" + patch + "7 7 7\r\n"),
            "bad.bpt: line 7: unexpected content after the last of the 1 patches: \"7 7 7\"");
  // A huge degree must not allocate: the file cannot hold that many points.
  EXPECT_EQ(
      message("1\r\n100000 100000\r\n0 0 0\r\n"),
      "bad.bpt: patch P0: file ends before the 100001 x 100001 control points of degree 100000 100000 (only "
      "3 numbers left, 30000600003 needed)");
  // Degrees that overflow (du + 1) are refused by name, never printed as a negative count of points.
  EXPECT_EQ(message("1\n9223372036854775807 1\n0 0 0\n"),
            "bad.bpt: patch P0: line 2: degrees 9223372036854775807 1: too large (at most 2147483646)");
  EXPECT_EQ(message("1\n1 99999999999999999999\n0 0 0\n"),
            "bad.bpt: patch P0: line 2: expected the degrees \"du dv\" (two integers), found "
            "\"1 99999999999999999999\"");
}

// The .bpt variants found in the wild (issue 18): comments, the whole file on one line, one degree pair shared by
// all patches. Every expected point is written here by hand, not taken from the reader.

/// Two patches: P0 of degree 1 x 2 (6 points), P1 of degree 1 x 1 (4 points), row-major with i along u.
struct HandPatch {
  int du, dv;
  std::vector<std::array<double, 3>> points;
};
const std::vector<HandPatch> kTwoPatches = {
    {1, 2, {{0, 0, 0}, {0, 1, 0.5}, {0, 2, 1}, {1, 0, 0}, {1, 1, -0.25}, {1, 2, 1.5}}},
    {1, 1, {{2, 0, 0}, {2, 1, 0}, {3, 0, 0.125}, {3, 1, 7e-3}}},
};

/// Checks that `m` holds exactly `expected`, point by point (bit-exact: the numbers are short decimals).
void expectPatches(const Result<Model>& m, const std::vector<HandPatch>& expected, const std::string& what) {
  ASSERT_TRUE(m.isOk()) << what << ": " << m.status().message();
  ASSERT_EQ(m->patches.size(), expected.size()) << what;
  for (size_t k = 0; k < expected.size(); ++k) {
    const BSplineSurface& s = m->patches[k].surface;
    EXPECT_EQ(m->patches[k].name, fmt::format("P{}", k)) << what;
    ASSERT_EQ(s.degreeU(), expected[k].du) << what;
    ASSERT_EQ(s.degreeV(), expected[k].dv) << what;
    for (int i = 0; i <= expected[k].du; ++i) {
      for (int j = 0; j <= expected[k].dv; ++j) {
        const std::array<double, 3>& p = expected[k].points[static_cast<size_t>(i * (expected[k].dv + 1) + j)];
        for (int c = 0; c < 3; ++c) EXPECT_EQ(s.point(i, j)[c], p[static_cast<size_t>(c)]) << what << " P" << k;
      }
    }
  }
}

TEST(Bpt, CommentLinesAndTrailingComments) {
  const std::string text =
      "# Two patches, written by hand\n"
      "2   # patch count\n"
      "# first patch\n"
      "1 2\n0 0 0\n0 1 0.5  # a trailing comment\n0 2 1\n1 0 0\n1 1 -0.25\n1 2 1.5\n"
      "   # an indented comment line\n"
      "1 1\r\n2 0 0\r\n2 1 0\r\n3 0 0.125\r\n3 1 7e-3\r\n"
      "#\n";
  expectPatches(io::parseBpt(text, "comments.bpt"), kTwoPatches, "comments");
}

TEST(Bpt, WholeFileOnOneLine) {
  const std::string text =
      "2 1 2 0 0 0 0 1 0.5 0 2 1 1 0 0 1 1 -0.25 1 2 1.5 1 1 2 0 0 2 1 0 3 0 0.125 3 1 7e-3";
  expectPatches(io::parseBpt(text, "oneline.bpt"), kTwoPatches, "one line");
  // Several points per line, tabs, and a comment at the end.
  const std::string rows = "2\n1 2\n0 0 0\t0 1 0.5 0 2 1\n1 0 0 1 1 -0.25 1 2 1.5\n1 1 2 0 0 2 1 0\n3 0 0.125 3 1 7e-3 #end";
  expectPatches(io::parseBpt(rows, "rows.bpt"), kTwoPatches, "rows");
}

TEST(Bpt, OneDegreeLineSharedByAllPatches) {
  // Three bilinear patches after a single "1 1".
  const std::vector<HandPatch> expected = {
      {1, 1, {{0, 0, 0}, {0, 1, 0}, {1, 0, 0}, {1, 1, 0}}},
      {1, 1, {{1, 0, 0}, {1, 1, 0}, {2, 0, 0.5}, {2, 1, 0.5}}},
      {1, 1, {{2, 0, 0.5}, {2, 1, 0.5}, {3, 0, -1.5}, {3, 1, 2.25}}},
  };
  const std::string text =
      "3\n1 1\n"
      "0 0 0\n0 1 0\n1 0 0\n1 1 0\n"
      "1 0 0\n1 1 0\n2 0 0.5\n2 1 0.5\n"
      "2 0 0.5\n2 1 0.5\n3 0 -1.5\n3 1 2.25\n";
  expectPatches(io::parseBpt(text, "shared.bpt"), expected, "shared degrees");
  // The same on one line with a comment.
  std::string oneLine = "# shared degrees\n";
  for (const char c : text) oneLine += c == '\n' ? ' ' : c;
  expectPatches(io::parseBpt(oneLine, "shared1.bpt"), expected, "shared degrees, one line");
  // Bicubic patches sharing "3 3" (16 points each).
  std::string cubic = "2 3 3";
  for (int k = 0; k < 2; ++k)
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) cubic += fmt::format(" {} {} {}", i + 3 * k, j, k == 0 ? i * j : -i);
  const Result<Model> m = io::parseBpt(cubic, "cubic.bpt");
  ASSERT_TRUE(m.isOk()) << m.status().message();
  ASSERT_EQ(m->patches.size(), 2u);
  EXPECT_EQ(m->patches[1].surface.degreeU(), 3);
  EXPECT_EQ(m->patches[0].surface.point(2, 3)[2], 6.0);   // i * j
  EXPECT_EQ(m->patches[1].surface.point(3, 1)[0], 6.0);   // i + 3
  EXPECT_EQ(m->patches[1].surface.point(3, 1)[2], -3.0);  // -i
}

TEST(Bpt, MalformedVariantsStillNamePatchAndLine) {
  auto message = [](const std::string& text) {
    const Result<Model> r = io::parseBpt(text, "bad.bpt");
    EXPECT_FALSE(r.isOk()) << text;
    return r.isOk() ? std::string() : r.status().message();
  };
  // One line: the bad number of the second patch is on line 1.
  EXPECT_EQ(message("2 1 1 0 0 0 0 1 0 1 0 0 1 1 0 1 1 2 0 0 2 1 0 3 0 x 3 1 0"),
            "bad.bpt: patch P1: line 1: \"x\" is not a finite number");
  // Shared degrees: the count fits, the bad number is reported in patch P1 on its line.
  EXPECT_EQ(message("2\n1 1\n0 0 0\n0 1 0\n1 0 0\n1 1 0\n1 0 0\n1 1 nan\n2 0 0\n2 1 0\n"),
            "bad.bpt: patch P1: line 8: \"nan\" is not a finite number");
  // A comment does not hide a missing number: the line holds two.
  EXPECT_EQ(message("1\n1 1\n0 0 0\n0 1 # 0\n1 0 0\n1 1 0\n"),
            "bad.bpt: patch P0: line 4: expected a point \"x y z\" (3 numbers), found \"0 1\"");
  // A file of comments only is empty.
  EXPECT_EQ(message("# nothing\n# here\n"),
            "bad.bpt: empty file (expected the number of patches on the first line)");
  // Neither layout fits: one point short in the last patch.
  EXPECT_EQ(message("2 1 1 0 0 0 0 1 0 1 0 0 1 1 0 1 1 2 0 0 2 1 0 3 0 0"),
            "bad.bpt: patch P1: file ends before the 2 x 2 control points of degree 1 1 (only 9 numbers left, 12 "
            "needed)");
}

}  // namespace
}  // namespace seam
