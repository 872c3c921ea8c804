// Tests of healModel (include/seam/repair/heal.h) and `seam heal`: a 3 x 3 grid of patches cut from one
// surface, perturbed, then healed; kept and skipped seams; the command line.
//
// Every healed seam is verified by the certified referee (analyzeSeam) and by the dense reference of
// seam_test_support.h; patches that need not move are bit-identical.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "seam/continuity/seam.h"
#include "seam/io/json.h"
#include "seam/repair/heal.h"
#include "seam/repair/join.h"
#include "seam_test_support.h"
#include "test_helpers.h"

namespace seam {
namespace {

using seamtest::Rng;
using seamtest::urand;

/// Joins exact to round-off: 1e-6 degrees (analyzeSeam's default tolerance is 0.01 degrees).
constexpr double kExactAngleDeg = 1e-6;
/// Gaps after healing relative to the model size.
constexpr double kExactGapRel = 1e-9;
/// Dense reference samples per seam.
constexpr int kDenseSamples = 600;

/// The referee's bounds within 25 % of the sampled worst values (cheaper curvature bounds; not under test here).
HealOptions healOpts() {
  HealOptions o;
  o.seam.boundRelGap = 0.25;
  o.seam.maxSubdivisionDepth = 12;
  return o;
}

bool atLeastG1(GeometricClass c) { return c == GeometricClass::kG1 || c == GeometricClass::kG2; }

/// A 3 x 3 grid cut from one bicubic surface (split at two interior parameters in each direction), named
/// P<row><col>.
Model grid3x3(Rng& rng) {
  const BSplineSurface F = seamtest::randomGraphSurface(rng, 3, 3, 8, 8, false, 0.3);
  const Interval du = F.domainU(), dv = F.domainV();
  const double u1 = du.lo + du.length() * urand(rng, 0.28, 0.38),
               u2 = du.lo + du.length() * urand(rng, 0.62, 0.72);
  const double v1 = dv.lo + dv.length() * urand(rng, 0.28, 0.38),
               v2 = dv.lo + dv.length() * urand(rng, 0.62, 0.72);
  Model m;
  auto [c0, rest] = seamtest::splitU(F, u1);
  auto [c1, c2] = seamtest::splitU(rest, u2);
  int col = 0;
  for (const BSplineSurface& column : {c0, c1, c2}) {
    auto [r0, rr] = seamtest::splitV(column, v1);
    auto [r1, r2] = seamtest::splitV(rr, v2);
    int row = 0;
    for (const BSplineSurface& p : {r0, r1, r2}) {
      std::string name = "P";
      name += std::to_string(row);
      name += std::to_string(col);
      m.patches.push_back(Patch{name, PatchKind::kBSpline, p});
      ++row;
    }
    ++col;
  }
  return m;
}

/// Moves every control point within two rows of any edge by up to `amp` (gaps and kinks on every seam,
/// corners too).
Model perturbed(Rng& rng, const Model& m, double amp, const std::vector<std::string>& keep = {}) {
  Model out = m;
  for (Patch& p : out.patches) {
    if (std::find(keep.begin(), keep.end(), p.name) != keep.end()) continue;
    const BSplineSurface& s = p.surface;
    Matrix pts = s.points();
    for (int i = 0; i < s.numU(); ++i)
      for (int j = 0; j < s.numV(); ++j) {
        const bool near = i <= 1 || j <= 1 || i >= s.numU() - 2 || j >= s.numV() - 2;
        if (!near) continue;
        for (int c = 0; c < 3; ++c) pts(i * s.numV() + j, c) += urand(rng, -amp, amp);
      }
    p.surface = BSplineSurface(s.degreeU(), s.degreeV(), s.knotsU(), s.knotsV(), s.numU(), s.numV(), pts,
                               s.weights());
  }
  return out;
}

void checkHealedSeams(const Model& healed, const HealReport& rep, double size) {
  int joined = 0;
  for (const HealSeam& s : rep.seams) {
    if (s.action == "skipped") continue;
    ASSERT_TRUE(s.after.has_value()) << s.a << "/" << s.b;
    EXPECT_TRUE(s.after->certified) << s.a << "/" << s.b;
    EXPECT_TRUE(atLeastG1(s.after->geometric))
        << s.a << ":" << edgeName(s.aEdge) << " / " << s.b << ":" << edgeName(s.bEdge) << " is "
        << toString(s.after->geometric) << ", g1 " << s.after->g1MaxDeg << " deg, gap " << s.after->g0Max;
    EXPECT_LE(s.after->g0Max, kExactGapRel * size);
    EXPECT_LE(s.after->g1MaxDeg, kExactAngleDeg);
    const Patch* a = healed.findPatch(s.a);
    const Patch* b = healed.findPatch(s.b);
    ASSERT_TRUE(a && b);
    seamtest::RefOptions ro;
    ro.samples = kDenseSamples;
    ro.g2 = false;
    const seamtest::RefMeasures ref = seamtest::denseReference(a->surface, s.aEdge, b->surface, s.bEdge, ro);
    EXPECT_LE(ref.g1Deg, kExactAngleDeg) << s.a << "/" << s.b;
    EXPECT_LE(ref.g0, kExactGapRel * size) << s.a << "/" << s.b;
    if (s.action == "joined") ++joined;
  }
  EXPECT_GT(joined, 0);
}

TEST(Heal, Grid3x3CutFromOneSurfacePerturbedThenHealed) {
  Rng rng(5150);
  for (int trial = 0; trial < 2; ++trial) {
    const Model clean = grid3x3(rng);
    const double size = clean.boundingBox().diagonal();
    const Model broken = perturbed(rng, clean, 2e-4 * size);
    auto r = healModel(broken, healOpts());
    ASSERT_TRUE(r.isOk()) << r.status().message();
    EXPECT_EQ(r->report.seams.size(), 12u);
    for (const HealSeam& s : r->report.seams) EXPECT_EQ(s.action == "skipped", false) << s.a << "/" << s.b;
    checkHealedSeams(r->model, r->report, size);
    EXPECT_TRUE(r->report.achieved);
    EXPECT_EQ(r->report.worst == GeometricClass::kG1 || r->report.worst == GeometricClass::kG2, true);
    // The first patch of the group stays; patches keep their names and order.
    ASSERT_EQ(r->model.patches.size(), broken.patches.size());
    for (size_t k = 0; k < broken.patches.size(); ++k)
      EXPECT_EQ(r->model.patches[k].name, broken.patches[k].name);
    EXPECT_TRUE(r->model.patches[0].surface.points() == broken.patches[0].surface.points());
  }
}

TEST(Heal, KeepsJoinedSeamsAndSkipsWideGaps) {
  Rng rng(616);
  const Model clean = grid3x3(rng);
  const double size = clean.boundingBox().diagonal();
  // Only P11 is perturbed: its four seams open, the eight others stay G1 (kept, never moved).
  Model m = perturbed(rng, clean, 2e-4 * size, {"P00", "P01", "P02", "P10", "P12", "P20", "P21", "P22"});
  auto r = healModel(m, healOpts());
  ASSERT_TRUE(r.isOk()) << r.status().message();
  int kept = 0, joined = 0;
  for (const HealSeam& s : r->report.seams) {
    if (s.action == "kept") ++kept;
    if (s.action == "joined") {
      ++joined;
      EXPECT_TRUE(s.a == "P11" || s.b == "P11");
    }
  }
  EXPECT_EQ(kept, 8);
  EXPECT_EQ(joined, 4);
  checkHealedSeams(r->model, r->report, size);
  // Only the perturbed patch moved (its neighbours were settled before it).
  EXPECT_EQ(r->report.patchesChanged, std::vector<std::string>{"P11"});
  for (const Patch& p : r->model.patches)
    if (p.name != "P11") {
      EXPECT_TRUE(p.surface.points() == m.findPatch(p.name)->surface.points()) << p.name;
    }
  // A gap limit below the gaps: everything skipped, nothing moves.
  HealOptions tight = healOpts();
  tight.maxGap = 1e-12;
  auto t = healModel(m, tight);
  ASSERT_TRUE(t.isOk());
  EXPECT_TRUE(t->report.patchesChanged.empty());
  for (const HealSeam& s : t->report.seams)
    if (s.before.g0Max > 1e-12) {
      EXPECT_EQ(s.action, "skipped");
    }
  EXPECT_FALSE(healModel(Model{}).isOk());
}

#ifdef SEAM_CLI_PATH
TEST(HealCli, HealsAndReports) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("seam_heal_cli_test_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  Rng rng(777);
  const Model clean = grid3x3(rng);
  const Model broken = perturbed(rng, clean, 2e-4 * clean.boundingBox().diagonal());
  const std::filesystem::path in = dir / "in.json", out = dir / "out.json", log = dir / "stdout.txt";
  ASSERT_TRUE(io::writeModelJson(broken, in).isOk());
  const std::string cmd = std::string(SEAM_CLI_PATH) + " heal " + in.string() + " -o " + out.string() +
                          " --json > " + log.string() + " 2>&1";
  const int rc = std::system(cmd.c_str());
  std::ifstream f(log);
  std::stringstream ss;
  ss << f.rdbuf();
  ASSERT_TRUE(WIFEXITED(rc));
  EXPECT_EQ(WEXITSTATUS(rc), 0) << ss.str();
  const nlohmann::json j = nlohmann::json::parse(ss.str());
  EXPECT_EQ(j["seams"].size(), 12u);
  EXPECT_TRUE(j["achieved"].get<bool>());
  EXPECT_TRUE(j["seams"][0]["after"].contains("g1_max_deg"));
  auto back = io::readModelJson(out);
  ASSERT_TRUE(back.isOk());
  EXPECT_EQ(back->patches.size(), 9u);
  const std::string bad = std::string(SEAM_CLI_PATH) + " heal " + in.string() + " -o " + out.string() +
                          " --continuity G7 > " + log.string() + " 2>&1";
  const int rc2 = std::system(bad.c_str());
  EXPECT_EQ(WEXITSTATUS(rc2), 2);
}
#endif

}  // namespace
}  // namespace seam
