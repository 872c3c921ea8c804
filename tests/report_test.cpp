// HTML report and OBJ mesh (src/report/report.cpp), and the `seam report` / `seam export-mesh` / `seam convert`
// commands. Expected values: counts from the check report itself (one table row per seam), explicit Bernstein
// sums for mesh vertices, the analytic normal of a plane, and files that must not change.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <utility>

#include "hinge_models.h"
#include "seam/continuity/model_check.h"
#include "seam/io/file.h"
#include "seam/io/json.h"
#include "seam/report/report.h"

namespace seam {
namespace {

namespace fs = std::filesystem;

size_t count(const std::string& text, const std::string& what) {
  size_t n = 0;
  for (size_t p = text.find(what); p != std::string::npos; p = text.find(what, p + what.size())) ++n;
  return n;
}

Model teapot() { return io::readModel(std::string(SEAM_SHARED_DATA_DIR) + "/bezier/teapot.bpt").value(); }

// The "overlapping faces" fact, shared by the patch-model and the B-rep report (issue 38 §11): "none", one pair in
// the singular, the first 20 of more listed and the rest counted, each spelled by the callers' own formatting.
TEST(HtmlReport, OverlapsFactListsTwentyPairsAndCountsTheRest) {
  const auto name = [](int i) { return fmt::format("P{}", i); };
  const auto number = [](double x) { return fmt::format("{:g}", x); };
  const auto distance = [](double x) { return fmt::format("{:g} mm", x); };
  EXPECT_EQ(report::overlapsFact({}, name, number, distance), "none");
  FaceOverlap one;
  one.a = 3;
  one.b = 7;
  one.fraction = 0.25;
  one.maxDistance = 0.5;
  EXPECT_EQ(report::overlapsFact({one}, name, number, distance), "1 pair: P3 / P7 (25 %, within 0.5 mm)");
  std::vector<FaceOverlap> many(25, one);
  for (int k = 0; k < 25; ++k) many[static_cast<size_t>(k)].a = k;
  const std::string text = report::overlapsFact(many, name, number, distance);
  EXPECT_EQ(text.rfind("25 pairs: P0 / P7 (25 %, within 0.5 mm), P1 / P7", 0), 0u) << text;
  EXPECT_NE(text.find(", P19 / P7 (25 %, within 0.5 mm) and 5 more"), std::string::npos) << text;
  EXPECT_EQ(text.find("P20 /"), std::string::npos) << text;
}

TEST(HtmlReport, OneRowPerSeamAPlotPerSampledSeamAndNothingExternal) {
  const Model m = teapot();
  ModelCheckOptions o;
  o.seam.keepSamples = true;
  const ModelCheckReport r = checkModel(m, o).value();
  ASSERT_EQ(r.seams.size(), 52u);  // README: 52 shared boundaries
  const std::string h = report::htmlReport(m, r);
  EXPECT_EQ(h.rfind("<!DOCTYPE html>", 0), 0u);
  EXPECT_NE(h.find("</html>"), std::string::npos);
  EXPECT_EQ(count(h, "<tr><td><a href=\"#seam-"), r.seams.size());
  EXPECT_EQ(count(h, "<div class=\"seam\" id=\"seam-"), r.seams.size());
  EXPECT_EQ(count(h, "<svg class=\"plot\""), 3 * r.seams.size());
  // The drawing: one polyline per patch edge.
  EXPECT_GE(count(h, "<polyline"), 4 * m.patches.size() + 3 * r.seams.size());
  // Self-contained: no external scripts, styles, images or links.
  EXPECT_EQ(count(h, "http://"), 0u);
  EXPECT_EQ(count(h, "https://"), 0u);
  EXPECT_EQ(count(h, " src="), 0u);
  EXPECT_EQ(count(h, "<link"), 0u);
  // Balanced structure.
  EXPECT_EQ(count(h, "<svg"), count(h, "</svg>"));
  EXPECT_EQ(count(h, "<table"), count(h, "</table>"));
  EXPECT_EQ(count(h, "<tr>"), count(h, "</tr>"));
}

TEST(HtmlReport, NamesAreEscapedAndThePlotLimitHolds) {
  Model m = teapot();
  m.patches[0].name = "<b>&\"rim\"";
  ModelCheckOptions o;
  o.seam.keepSamples = true;
  const ModelCheckReport r = checkModel(m, o).value();
  report::HtmlReportOptions ro;
  ro.maxPlottedSeams = 5;
  ro.title = "a < b";
  const std::string h = report::htmlReport(m, r, ro);
  EXPECT_EQ(count(h, "<b>&\"rim\""), 0u);
  EXPECT_GT(count(h, "&lt;b&gt;&amp;&quot;rim&quot;"), 0u);
  EXPECT_NE(h.find("<title>a &lt; b</title>"), std::string::npos);
  EXPECT_EQ(count(h, "<div class=\"seam\" id=\"seam-"), 5u);
}

/// The seam numbers of the table rows, in page order.
std::vector<int> rowSeams(const std::string& h) {
  std::vector<int> out;
  const std::string key = "<tr><td><a href=\"#seam-";
  for (size_t p = h.find(key); p != std::string::npos; p = h.find(key, p + key.size()))
    out.push_back(std::stoi(h.substr(p + key.size())));
  return out;
}

// Issue 17: kinks first (largest angle first), then gaps, then the rest; the design creases in a table of their own.
TEST(HtmlReport, KinksFirstAndCreasesApart) {
  //                                   0     1     2     3      4    5    6
  const Model m = test::hingeModel({10.0, 45.0, 90.0, 150.0, 0.0, 0.0, 3.0}, {0.0, 0.0, 0.0, 0.0, 0.01, 0.0, 0.0});
  const ModelCheckReport r = checkModel(m).value();
  ASSERT_EQ(r.seams.size(), 7u);
  std::string h = report::htmlReport(m, r);
  EXPECT_EQ(rowSeams(h), (std::vector<int>{0, 6, 4, 5, 3, 2, 1}));
  EXPECT_LT(h.find("id=\"seams\""), h.find("id=\"creases\""));
  EXPECT_LT(h.find("id=\"creases\""), h.find("<a href=\"#seam-3\">"));
  EXPECT_NE(h.find("gap 1, kink 2, crease 3"), std::string::npos);
  EXPECT_NE(h.find("<a href=\"#seam-0\">#0</a> A0:u1 / B0:u0 at [0, "), std::string::npos);  // the worst kink
  report::HtmlReportOptions o;
  o.selection.only = SeamFilter::kProblems;
  o.selection.sort = SeamSortKey::kGap;
  o.selection.top = 2;
  h = report::htmlReport(m, r, o);
  EXPECT_EQ(rowSeams(h), (std::vector<int>{4, 0}));
  EXPECT_NE(h.find("Showing 2 of 4."), std::string::npos);
  EXPECT_EQ(count(h, "<div class=\"seam\" id=\"seam-"), 0u);  // no samples kept: no plots
  EXPECT_EQ(count(h, "<table"), count(h, "</table>"));
}

// Issue 38 §11: value labels on the worst gaps and kinks (the hinges' exact angles and gap as the expected values),
// in the table's order, none on creases or smooth seams; the limit holds; 0 turns them off.
struct Label {
  int seam = 0, rank = 0;
  std::string verdict;
  double value = 0.0;
};
std::vector<Label> viewLabels(const std::string& h) {
  std::vector<Label> out;
  const std::string key = "\"l\":\"#";
  for (size_t p = h.find(key); p != std::string::npos; p = h.find(key, p + 1)) {
    Label l;
    std::istringstream in(h.substr(p + key.size(), 80));
    in >> l.seam >> l.verdict >> l.value;
    l.rank = std::stoi(h.substr(h.find("\"lr\":", p) + 5));
    out.push_back(l);
  }
  return out;
}

TEST(HtmlReport, ValueLabelsGoToTheWorstGapsAndKinksInTableOrder) {
  //                                   0     1     2     3      4    5    6
  const Model m = test::hingeModel({10.0, 45.0, 90.0, 150.0, 0.0, 0.0, 3.0}, {0.0, 0.0, 0.0, 0.0, 0.01, 0.0, 0.0});
  const ModelCheckReport r = checkModel(m).value();
  ASSERT_EQ(r.seams.size(), 7u);
  report::HtmlReportOptions o;
  std::string h = report::htmlReport(m, r, o);
  // The 2-D drawing has them in every build.
  EXPECT_EQ(count(h, "class=\"vlabel\""), 3u);
  for (const char* seam : {"0", "6", "4"})
    EXPECT_EQ(count(h, fmt::format("class=\"vlabel\" data-seam=\"{}\">#{} ", seam, seam)), 1u) << seam;
  if (report::hasViewer3d()) {
    const std::vector<Label> labels = viewLabels(h);
    ASSERT_EQ(labels.size(), 3u);
    std::map<int, Label> bySeam;
    for (const Label& l : labels) bySeam[l.seam] = l;
    ASSERT_EQ(bySeam.size(), 3u);
    // Kinks first, the larger angle first, then the gap; values within the bounds' 1 % refinement (and 4 digits).
    EXPECT_EQ(bySeam[0].rank, 0);
    EXPECT_EQ(bySeam[0].verdict, "kink");
    EXPECT_NEAR(bySeam[0].value, 10.0, 0.011 * 10.0);
    EXPECT_EQ(bySeam[6].rank, 1);
    EXPECT_EQ(bySeam[6].verdict, "kink");
    EXPECT_NEAR(bySeam[6].value, 3.0, 0.011 * 3.0);
    EXPECT_EQ(bySeam[4].rank, 2);
    EXPECT_EQ(bySeam[4].verdict, "gap");
    EXPECT_NEAR(bySeam[4].value, 0.01, 0.011 * 0.01);
  }
  o.maxValueLabels = 2;
  h = report::htmlReport(m, r, o);
  EXPECT_EQ(count(h, "class=\"vlabel\""), 2u);
  EXPECT_EQ(count(h, "class=\"vlabel\" data-seam=\"4\""), 0u);  // the gap comes after both kinks
  o.maxValueLabels = 0;
  h = report::htmlReport(m, r, o);
  EXPECT_EQ(count(h, "class=\"vlabel\""), 0u);
  EXPECT_EQ(count(h, "\"l\":"), 0u);
}

/// Bernstein polynomial B_i^n(t), written out.
double bern(int n, int i, double t) {
  double c = 1.0;
  for (int k = 1; k <= i; ++k) c = c * (n - i + k) / k;
  return c * std::pow(t, i) * std::pow(1.0 - t, n - i);
}

TEST(ObjMesh, VerticesLieOnTheSurfaceAndNormalsAreUnitAndOriented) {
  std::mt19937 rng(71);
  std::uniform_real_distribution<double> d(-1.0, 1.0);
  Matrix pts(16, 3);
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) pts.row(i * 4 + j) << i + 0.2 * d(rng), j + 0.2 * d(rng), 0.3 * d(rng);
  const std::vector<double> k{0, 0, 0, 0, 1, 1, 1, 1};
  Model m;
  m.patches.push_back({"P", PatchKind::kBezier, BSplineSurface::create(3, 3, k, k, 4, 4, pts).value()});
  report::MeshOptions mo;
  mo.samplesPerSpan = 6;
  const std::string obj = report::objMesh(m, mo).value();
  std::istringstream in(obj);
  std::string tag;
  std::vector<Vec3> v, vn;
  int faces = 0;
  for (std::string line; std::getline(in, line);) {
    std::istringstream ls(line);
    ls >> tag;
    double x = 0, y = 0, z = 0;
    if (tag == "v") {
      ls >> x >> y >> z;
      v.emplace_back(x, y, z);
    } else if (tag == "vn") {
      ls >> x >> y >> z;
      vn.emplace_back(x, y, z);
    } else if (tag == "f") {
      ++faces;
    }
  }
  ASSERT_EQ(v.size(), 49u);
  ASSERT_EQ(vn.size(), 49u);
  EXPECT_EQ(faces, 2 * 36);
  for (int i = 0; i <= 6; ++i)
    for (int j = 0; j <= 6; ++j) {
      const double u = i / 6.0, w = j / 6.0;
      Vec3 p = Vec3::Zero(), pu = Vec3::Zero(), pv = Vec3::Zero();
      for (int a = 0; a < 4; ++a)
        for (int b = 0; b < 4; ++b) {
          const Vec3 c = pts.row(a * 4 + b).transpose();
          p += bern(3, a, u) * bern(3, b, w) * c;
          // d/du B_a^3 = 3 (B_{a-1}^2 - B_a^2)
          const double du = 3.0 * ((a > 0 ? bern(2, a - 1, u) : 0.0) - (a < 3 ? bern(2, a, u) : 0.0));
          const double dv = 3.0 * ((b > 0 ? bern(2, b - 1, w) : 0.0) - (b < 3 ? bern(2, b, w) : 0.0));
          pu += du * bern(3, b, w) * c;
          pv += bern(3, a, u) * dv * c;
        }
      const size_t idx = static_cast<size_t>(i * 7 + j);
      EXPECT_LE((v[idx] - p).norm(), 1e-12);
      EXPECT_NEAR(vn[idx].norm(), 1.0, 1e-8);
      EXPECT_GT(vn[idx].dot(pu.cross(pv).normalized()), 1.0 - 1e-8);
    }
}

TEST(ObjMesh, PolesGetTheLimitNormal) {
  const Model m = teapot();  // patches 20-23 and 28-31 collapse a boundary row to a point (README)
  const std::string obj = report::objMesh(m).value();
  std::istringstream in(obj);
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("vn ", 0) != 0) continue;
    std::istringstream ls(line.substr(3));
    double x = 0, y = 0, z = 0;
    ls >> x >> y >> z;
    ASSERT_NEAR(std::sqrt(x * x + y * y + z * z), 1.0, 1e-6) << line;
  }
}

// ---- the commands
struct CliRun {
  int code = -1;
  std::string out, err;
};

std::string readText(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

CliRun run(const std::string& args) {
  static int n = 0;
  const fs::path o = fs::temp_directory_path() / ("seam_report_test_" + std::to_string(::getpid()) + "_" +
                                                  std::to_string(n) + ".out");
  const fs::path e = fs::temp_directory_path() / ("seam_report_test_" + std::to_string(::getpid()) + "_" +
                                                  std::to_string(n++) + ".err");
  const std::string cmd = std::string("'") + SEAM_CLI_PATH + "' " + args + " >'" + o.string() + "' 2>'" + e.string() + "'";
  const int st = std::system(cmd.c_str());
  CliRun r;
  r.code = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  r.out = readText(o);
  r.err = readText(e);
  fs::remove(o);
  fs::remove(e);
  return r;
}

TEST(ReportCli, ReportAndMeshAreWrittenAndBadInputIsExitTwo) {
  const fs::path dir = fs::temp_directory_path() / ("seam_report_cli_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string tea = std::string(SEAM_SHARED_DATA_DIR) + "/bezier/teapot.bpt";
  const std::string before = readText(tea);
  CliRun r = run("report '" + tea + "' -o '" + (dir / "t.html").string() + "'");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(readText(dir / "t.html").find("seam report: teapot.bpt"), std::string::npos);
  r = run("export-mesh '" + tea + "' -o '" + (dir / "t.obj").string() + "' --per-span 4");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(count(readText(dir / "t.obj"), "\no "), 32u);  // one object per patch (after the header comment)
  EXPECT_EQ(readText(tea), before);  // input untouched

  std::ofstream(dir / "bad.json") << "{\"patches\": [ {\"name\": \"X\", \"type\": \"bezier\"} ]}";
  r = run("report '" + (dir / "bad.json").string() + "' -o '" + (dir / "bad.html").string() + "'");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("bad.json"), std::string::npos);
  EXPECT_FALSE(fs::exists(dir / "bad.html"));
  r = run("export-mesh '" + (dir / "missing.json").string() + "' -o '" + (dir / "m.obj").string() + "'");
  EXPECT_EQ(r.code, 2);
  EXPECT_FALSE(fs::exists(dir / "m.obj"));
  fs::remove_all(dir);
}

// `seam report --max-labels N`: N labels on network_fan5 (25 kinks), none with 0; a negative count is exit 2.
TEST(ReportCli, MaxLabelsSetsHowManySeamsAreLabelled) {
  const fs::path dir = fs::temp_directory_path() / ("seam_report_labels_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string fan = std::string(SEAM_EXAMPLES_DIR) + "/models/network_fan5.json";
  const std::string html = (dir / "fan.html").string();
  for (const auto& [option, want] : std::vector<std::pair<std::string, size_t>>{{"", 12}, {" --max-labels 3", 3},
                                                                                {" --max-labels 0", 0}}) {
    const CliRun r = run("report '" + fan + "' -o '" + html + "'" + option);
    EXPECT_EQ(r.code, 0) << option << r.err;
    EXPECT_EQ(count(readText(html), "class=\"vlabel\""), want) << option;
  }
  fs::remove(html);
  const CliRun r = run("report '" + fan + "' -o '" + html + "' --max-labels -1");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--max-labels"), std::string::npos);
  EXPECT_FALSE(fs::exists(html));
  fs::remove_all(dir);
}

// The plots of one seam: for each of G0, G1, G2 the plotted maximum (data-peak), the table's value (data-table) and
// the tolerance line's value; and whether the seam is certified (its header says so).
struct SeamPlots {
  size_t seam = 0;
  bool certified = false;
  std::vector<double> peak, table, tol;
};

double attribute(const std::string& text, size_t from, const std::string& name) {
  const size_t a = text.find(name + "=\"", from);
  if (a == std::string::npos) return std::nan("");
  const size_t b = a + name.size() + 2;
  const std::string v = text.substr(b, text.find('"', b) - b);
  return v == "null" ? std::nan("") : std::stod(v);
}

std::vector<SeamPlots> seamPlots(const std::string& h) {
  std::vector<SeamPlots> out;
  for (size_t p = h.find("<div class=\"seam\" id=\"seam-"); p != std::string::npos;
       p = h.find("<div class=\"seam\" id=\"seam-", p + 1)) {
    const size_t end = h.find("</div>", p);
    SeamPlots s;
    const std::string prefix = "<div class=\"seam\" id=\"seam-";
    s.seam = std::stoul(h.substr(p + prefix.size(), 12));
    const size_t br = h.find("<br>", p);
    s.certified = h.substr(p, br - p).find(", certified") != std::string::npos;
    for (size_t q = h.find("<svg class=\"plot\"", p); q < end; q = h.find("<svg class=\"plot\"", q + 1)) {
      s.peak.push_back(attribute(h, q, "data-peak"));
      s.table.push_back(attribute(h, q, "data-table"));
      const size_t t = h.find(">tol ", q);
      s.tol.push_back(std::stod(h.substr(t + 5)));
    }
    out.push_back(std::move(s));
  }
  return out;
}

// Issue 38 goal 5: a seam's plots and its table row show the same measure. trj3 seam #125 once plotted a G0 peak of
// 0.328 mm beside a table value of 0.5244. Each plot now peaks at the seam's refined maximum at least, and never
// above the table's value: equal to it where the seam is sampled, at or below it where the table shows a certified
// bound (a dotted line marks the bound then). The table's numbers come from the check report (SeamReport), the
// plot's from its samples; values below a millionth of the tolerance are round-off and not compared.
void expectPlotsAgreeWithTable(const std::string& h, const ModelCheckReport* r, const std::string& what) {
  const std::vector<SeamPlots> plots = seamPlots(h);
  ASSERT_FALSE(plots.empty()) << what;
  int compared = 0;
  for (const SeamPlots& s : plots) {
    ASSERT_EQ(s.peak.size(), 3u) << what << " seam #" << s.seam;
    for (size_t i = 0; i < 3; ++i) {
      const double floor = 1e-6 * s.tol[i];
      if (std::isnan(s.peak[i]) || std::isnan(s.table[i])) continue;
      ++compared;
      EXPECT_LE(s.peak[i], s.table[i] * (1.0 + 1e-9) + floor) << what << " seam #" << s.seam << " plot " << i;
      if (!s.certified) {
        EXPECT_NEAR(s.peak[i], s.table[i], 1e-12 * s.table[i] + floor) << what << " seam #" << s.seam << " plot " << i;
      }
      if (r != nullptr) {
        const SeamReport& x = *r->seams[s.seam].report;
        const double table[3] = {x.g0Max, x.g1MaxDeg, x.g2RelMax};
        const double sampled[3] = {x.g0Sampled, x.g1SampledDeg, x.g2RelSampled};
        EXPECT_NEAR(s.table[i], table[i], 1e-12 * std::abs(table[i])) << what << " seam #" << s.seam;
        EXPECT_GE(s.peak[i], sampled[i] * (1.0 - 1e-12) - floor) << what << " seam #" << s.seam << " plot " << i;
      }
    }
  }
  EXPECT_GT(compared, 0) << what;
}

TEST(HtmlReport, EachPlotPeaksAtTheSeamsMaximumAndNeverAboveItsTableValue) {
  for (const std::string& file : {std::string(SEAM_SHARED_DATA_DIR) + "/bezier/teapot.bpt",
                                 std::string(SEAM_SHARED_DATA_DIR) + "/bezier/teaspoon.bpt",
                                 std::string(SEAM_EXAMPLES_DIR) + "/models/network_fan5.json"}) {
    const Model m = io::readModel(file).value();
    ModelCheckOptions o;
    o.seam.keepSamples = true;
    const ModelCheckReport r = checkModel(m, o).value();
    expectPlotsAgreeWithTable(report::htmlReport(m, r), &r, file);
    // The report's table holds what `seam check` prints, bit for bit: the plots' samples are measured apart and
    // do not change where the bounds start (fan seam 11 was 1.461 deg in the report, 1.4575 in check).
    o.seam.keepSamples = false;
    const ModelCheckReport c = checkModel(m, o).value();
    ASSERT_EQ(c.seams.size(), r.seams.size()) << file;
    for (size_t k = 0; k < c.seams.size(); ++k) {
      const SeamReport &x = *r.seams[k].report, &y = *c.seams[k].report;
      EXPECT_FALSE(x.samples.empty()) << file << " seam " << k;
      EXPECT_TRUE(y.samples.empty()) << file << " seam " << k;
      const double reportValues[] = {x.g0Max, x.g1MaxDeg, x.g2Max, x.g2RelMax, x.g0Sampled, x.g1SampledDeg,
                                     x.g2Sampled, x.g2RelSampled};
      const double checkValues[] = {y.g0Max, y.g1MaxDeg, y.g2Max, y.g2RelMax, y.g0Sampled, y.g1SampledDeg,
                                    y.g2Sampled, y.g2RelSampled};
      for (size_t i = 0; i < std::size(checkValues); ++i)
        EXPECT_EQ(reportValues[i], checkValues[i]) << file << " seam " << k << " value " << i;
      EXPECT_EQ(x.geometric, y.geometric) << file << " seam " << k;
    }
  }
}

#ifdef SEAM_HAVE_OCCT_CLI
TEST(ReportCli, TheBRepReportsPlotsAgreeWithItsTable) {
  const std::string trj3 = std::string(SEAM_SHARED_DATA_DIR) + "/step/trj3_s1-al-214.stp";
  if (!fs::exists(trj3)) GTEST_SKIP() << trj3 << " is missing";
  const fs::path out = fs::temp_directory_path() / ("seam_report_plots_" + std::to_string(::getpid()) + ".html");
  const CliRun run1 = run("report '" + trj3 + "' -o '" + out.string() + "'");
  ASSERT_EQ(run1.code, 0) << run1.err;
  const std::string h = readText(out);
  fs::remove(out);
  expectPlotsAgreeWithTable(h, nullptr, trj3);
  // Seam #125 (edge 161) in particular: certified, its G0 plot peaks within 1 % below its table value (0.3278
  // against a bound of 0.3282 mm; it once peaked at 0.328 beside a table value of 0.5244).
  bool found = false;
  for (const SeamPlots& s : seamPlots(h))
    if (s.seam == 125) {
      found = true;
      EXPECT_GE(s.peak[0], 0.99 * s.table[0]);
      EXPECT_LE(s.peak[0], s.table[0]);
    }
  EXPECT_TRUE(found);
}
#endif

TEST(ReportCli, ConvertJsonRoundTripIsBitExactAndRefusesUnknownFormats) {
  const fs::path dir = fs::temp_directory_path() / ("seam_convert_cli_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string src = std::string(SEAM_EXAMPLES_DIR) + "/models/two_patches.json";
  CliRun r = run("convert '" + src + "' '" + (dir / "a.json").string() + "'");
  ASSERT_EQ(r.code, 0) << r.err;
  const Model a = io::readModel(src).value(), b = io::readModel(dir / "a.json").value();
  ASSERT_EQ(a.patches.size(), b.patches.size());
  for (size_t i = 0; i < a.patches.size(); ++i) {
    EXPECT_EQ(a.patches[i].surface.points(), b.patches[i].surface.points());
    EXPECT_EQ(a.patches[i].surface.knotsU().values(), b.patches[i].surface.knotsU().values());
  }
#ifdef SEAM_HAVE_OCCT_CLI
  r = run("convert '" + src + "' '" + (dir / "a.step").string() + "'");
  ASSERT_EQ(r.code, 0) << r.err;
  r = run("convert '" + (dir / "a.step").string() + "' '" + (dir / "b.json").string() + "'");
  ASSERT_EQ(r.code, 0) << r.err;
  const Model c = io::readModel(dir / "b.json").value();
  ASSERT_EQ(c.patches.size(), a.patches.size());
  for (size_t i = 0; i < a.patches.size(); ++i) EXPECT_EQ(a.patches[i].surface.points(), c.patches[i].surface.points());
#endif
#ifdef SEAM_HAVE_OCCT_CLI
  {  // STEP -> JSON -> STEP -> JSON: the second JSON equals the first (the round trip preserves every number)
    const std::string fus = std::string(SEAM_SHARED_DATA_DIR) + "/step/bug28366_fuselage.stp";
    ASSERT_EQ(run("convert '" + fus + "' '" + (dir / "f1.json").string() + "'").code, 0);
    ASSERT_EQ(run("convert '" + (dir / "f1.json").string() + "' '" + (dir / "f2.step").string() + "'").code, 0);
    ASSERT_EQ(run("convert '" + (dir / "f2.step").string() + "' '" + (dir / "f3.json").string() + "'").code, 0);
    EXPECT_EQ(readText(dir / "f1.json"), readText(dir / "f3.json"));
    // The report of a STEP file is the B-rep check, with OpenCASCADE's verdict as a column.
    const CliRun rep = run("report '" + fus + "' -o '" + (dir / "f.html").string() + "'");
    ASSERT_EQ(rep.code, 0) << rep.err;
    const std::string h = readText(dir / "f.html");
    EXPECT_EQ(count(h, "<tr><td><a href=\"#seam-"), 14u);  // README: 14 shared edges
    EXPECT_NE(h.find("<th class=\"l\">OpenCASCADE</th>"), std::string::npos);
  }
#endif
  r = run("convert '" + src + "' '" + (dir / "a.xyz").string() + "'");
  EXPECT_EQ(r.code, 2);
  EXPECT_FALSE(fs::exists(dir / "a.xyz"));
  fs::remove_all(dir);
}

TEST(HtmlReport, TheThreeDViewHasItsDataAndTheTwoDDrawingStays) {
  Model m = teapot();
  m.patches[0].name = "</script><b>";  // must not end the view's data <script>
  ModelCheckOptions o;
  o.seam.keepSamples = true;
  const ModelCheckReport r = checkModel(m, o).value();
  const std::string h = report::htmlReport(m, r);
  EXPECT_EQ(count(h, "</script><b>"), 0u);
  if (report::hasViewer3d()) {
    EXPECT_EQ(count(h, "<script id=\"seam-view-data\" type=\"application/json\">"), 1u);
    EXPECT_EQ(count(h, "<div id=\"view3d-canvas\">"), 1u);
    EXPECT_EQ(count(h, "<script"), count(h, "</script>"));
    EXPECT_EQ(count(h, "<script"), 3u);  // the table sorter, the view's data, the view
    EXPECT_EQ(count(h, "<details id=\"view2d\" open>"), 1u);
    // One mesh per patch, one seam entry per seam.
    EXPECT_EQ(count(h, "{\"name\":"), m.patches.size());
    EXPECT_EQ(count(h, "{\"k\":"), r.seams.size());
  } else {
    GTEST_LOG_(INFO) << "this build has no 3-D view (web/node_modules missing at configure time)";
  }
  report::HtmlReportOptions ro;
  ro.view3d = false;
  const std::string flat = report::htmlReport(m, r, ro);
  EXPECT_EQ(count(flat, "seam-view-data"), 0u);
  EXPECT_EQ(count(flat, "<script"), 1u);
  EXPECT_EQ(count(flat, "<polyline"), count(h, "<polyline"));  // the 2-D drawing is there either way
  if (report::hasViewer3d()) {
    EXPECT_LT(flat.size(), h.size());
  } else {
    EXPECT_EQ(flat, h);  // without the viewer both options give the same page
  }
}

TEST(ReportMeshes, OnePerShadedPatchUnitNormalsWithinTheBudget) {
  const Model m = teapot();
  const std::vector<report::ReportMesh> all = report::reportMeshes(m);
  ASSERT_EQ(all.size(), m.patches.size());
  for (const report::ReportMesh& mesh : all) {
    ASSERT_EQ(mesh.points.size(), 81u);  // one bicubic span: 8 x 8 cells
    ASSERT_EQ(mesh.normals.size(), mesh.points.size());
    ASSERT_EQ(mesh.triangles.size(), 6u * 64u);
    for (const Vec3& n : mesh.normals) EXPECT_NEAR(n.norm(), 1.0, 1e-12);
    for (int i : mesh.triangles) EXPECT_LT(static_cast<size_t>(i), mesh.points.size());
  }
  std::vector<bool> shade(m.patches.size(), false);
  shade[3] = shade[7] = true;
  const std::vector<report::ReportMesh> two = report::reportMeshes(m, shade);
  ASSERT_EQ(two.size(), 2u);
  EXPECT_EQ(two[0].name, m.patches[3].name);
  EXPECT_EQ(two[1].name, m.patches[7].name);
  size_t total = 0;
  for (const report::ReportMesh& mesh : report::reportMeshes(m, {}, 1000)) total += mesh.points.size();
  EXPECT_LE(total, 1000u);
  EXPECT_GE(total, 32u * 9u);  // never below 2 x 2 cells per patch
}

}  // namespace
}  // namespace seam
