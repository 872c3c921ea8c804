// Seam verdicts for CAD users (continuity/verdict.h, issue 17 §1): planar hinges whose angle and gap are known by
// construction, classified as gap / kink / crease / G1 / G2; the listing order (--sort, --top, --only problems) and
// the worst defects of a summary.
#include "seam/continuity/verdict.h"

#include <gtest/gtest.h>

#include <vector>

#include "hinge_models.h"
#include "seam/continuity/model_check.h"

namespace seam {
namespace {

/// The analysed seams of a hinge model, in hinge order (one seam per hinge, A<k>:u1 / B<k>:u0).
std::vector<SeamReport> hingeSeams(const Model& m) {
  const Result<ModelCheckReport> r = checkModel(m);
  EXPECT_TRUE(r.isOk()) << r.status().message();
  std::vector<SeamReport> out;
  if (!r) return out;
  EXPECT_EQ(r->seams.size(), m.patches.size() / 2);
  for (const ModelSeam& s : r->seams) {
    EXPECT_TRUE(s.report.has_value()) << s.error.message();
    EXPECT_EQ(s.pair.b.patch, s.pair.a.patch + 1);  // each hinge pairs with itself only
    if (s.report) out.push_back(*s.report);
  }
  return out;
}

std::vector<const SeamReport*> pointers(const std::vector<SeamReport>& v) {
  std::vector<const SeamReport*> p;
  for (const SeamReport& r : v) p.push_back(&r);
  return p;
}

TEST(SeamVerdict, HingesAtKnownAnglesAreKinksOrCreases) {
  const std::vector<double> angles{10.0, 45.0, 90.0, 150.0, 0.0};
  const std::vector<SeamReport> seams = hingeSeams(test::hingeModel(angles));
  ASSERT_EQ(seams.size(), angles.size());
  const std::vector<SeamVerdict> expected{SeamVerdict::kKink, SeamVerdict::kCrease, SeamVerdict::kCrease,
                                          SeamVerdict::kCrease, SeamVerdict::kG2};
  for (size_t k = 0; k < angles.size(); ++k) {
    EXPECT_NEAR(seams[k].g1MaxDeg, angles[k], 1e-9) << k;  // the angle is measured, whatever the verdict
    EXPECT_EQ(seamVerdict(seams[k]), expected[k]) << angles[k] << " deg";
    EXPECT_EQ(seamVerdict(seams[k], kDefaultCreaseAngleDeg), expected[k]);
  }
  // The crease angle moves the line between kink and crease: at 50 deg, 45 deg is a kink; at 5 deg, 10 is a crease.
  EXPECT_EQ(seamVerdict(seams[1], 50.0), SeamVerdict::kKink);
  EXPECT_EQ(seamVerdict(seams[0], 5.0), SeamVerdict::kCrease);
  EXPECT_EQ(seamVerdict(seams[3], 180.0), SeamVerdict::kKink);  // 150 deg below a crease angle of 180
  EXPECT_TRUE(isProblem(SeamVerdict::kKink));
  EXPECT_FALSE(isProblem(SeamVerdict::kCrease));
  EXPECT_EQ(toString(SeamVerdict::kCrease), "crease");
}

TEST(SeamVerdict, AVanishingNormalMakesATangentSeamUndeterminedNeverAKinkOrACrease) {
  // The analysis sets g1PoleT where a normal vanishes and G1 is neither bounded nor an identity (tests/seam_test.cpp,
  // SeamPole.ANormalVanishingInsideTheEdge...); here the verdict alone, on the hinges' own reports.
  std::vector<SeamReport> seams = hingeSeams(test::hingeModel({0.0, 10.0, 45.0}));
  ASSERT_EQ(seams.size(), 3u);
  for (SeamReport& r : seams) r.g1PoleT = 0.5;
  EXPECT_EQ(seamVerdict(seams[0]), SeamVerdict::kUndetermined);  // measured within the tolerance: undecided
  EXPECT_EQ(seamVerdict(seams[1]), SeamVerdict::kKink);          // measured above it: a kink of that angle
  EXPECT_EQ(seamVerdict(seams[2]), SeamVerdict::kCrease);
  EXPECT_EQ(toString(SeamVerdict::kUndetermined), "undetermined");
  EXPECT_FALSE(isProblem(SeamVerdict::kUndetermined));
  EXPECT_TRUE(passes(SeamFilter::kProblems, &seams[0], kDefaultCreaseAngleDeg));
  EXPECT_FALSE(passes(SeamFilter::kKinks, &seams[0], kDefaultCreaseAngleDeg));
  const std::vector<const SeamReport*> p = pointers(seams);
  EXPECT_EQ(countVerdicts(p), (std::array<int, kSeamVerdictCount>{0, 1, 1, 0, 0, 1}));
  // By verdict: the kink, then the undetermined seam (with the failed analyses), then the crease.
  SeamSelection byVerdict;
  byVerdict.sort = SeamSortKey::kVerdict;
  EXPECT_EQ(selectSeams(p, byVerdict), (std::vector<size_t>{1, 0, 2}));
}

TEST(SeamVerdict, AGapIsAGapAtAnyAngleAndKeepsItsAngle) {
  // Gaps of 0.01 (the default distance tolerance is 1e-6 x diagonal, ~4e-6): one flat, one at 45 deg.
  const std::vector<SeamReport> seams = hingeSeams(test::hingeModel({0.0, 45.0}, {0.01, 0.01}));
  ASSERT_EQ(seams.size(), 2u);
  for (const SeamReport& s : seams) {
    EXPECT_EQ(s.geometric, GeometricClass::kNone);
    EXPECT_EQ(seamVerdict(s), SeamVerdict::kGap);
    EXPECT_NEAR(s.g0Max, 0.01, 1e-9);
  }
  EXPECT_NEAR(seams[1].g1MaxDeg, 45.0, 1e-6);  // shown, not hidden behind "none"
  EXPECT_TRUE(isProblem(seamVerdict(seams[1])));
}

TEST(SeamVerdict, SortTopOnlyProblemsAndWorstDefects) {
  //                                  0     1     2     3      4    5    6
  const std::vector<double> angles{10.0, 45.0, 90.0, 150.0, 0.0, 3.0, 0.0};
  const std::vector<double> gaps{0.0, 0.0, 0.0, 0.0, 0.01, 0.0, 0.002};
  const std::vector<SeamReport> seams = hingeSeams(test::hingeModel(angles, gaps));
  ASSERT_EQ(seams.size(), angles.size());
  const std::vector<const SeamReport*> p = pointers(seams);

  SeamSelection sel;
  EXPECT_EQ(selectSeams(p, sel), (std::vector<size_t>{0, 1, 2, 3, 4, 5, 6}));  // file order
  sel.sort = SeamSortKey::kAngle;
  EXPECT_EQ(selectSeams(p, sel), (std::vector<size_t>{3, 2, 1, 0, 5, 4, 6}));  // stable among equal angles
  sel.top = 3;
  EXPECT_EQ(selectSeams(p, sel), (std::vector<size_t>{3, 2, 1}));
  sel.only = SeamFilter::kProblems;
  EXPECT_EQ(selectSeams(p, sel), (std::vector<size_t>{0, 5, 4}));  // kinks and gaps only, largest angle first
  sel.top.reset();
  sel.sort = SeamSortKey::kGap;
  EXPECT_EQ(selectSeams(p, sel), (std::vector<size_t>{4, 6, 0, 5}));
  sel.top = 0;
  EXPECT_TRUE(selectSeams(p, sel).empty());

  // A failed analysis (null) is listed, counts as a problem, and comes last when sorted.
  std::vector<const SeamReport*> withFailed = p;
  withFailed.insert(withFailed.begin(), nullptr);
  SeamSelection byAngle;
  byAngle.sort = SeamSortKey::kAngle;
  byAngle.only = SeamFilter::kProblems;
  EXPECT_EQ(selectSeams(withFailed, byAngle), (std::vector<size_t>{1, 6, 5, 7, 0}));

  const WorstDefects w = worstDefects(p);
  ASSERT_TRUE(w.kink && w.gap);
  EXPECT_EQ(*w.kink, 0u);  // 10 deg: the largest angle below the crease angle
  EXPECT_EQ(*w.gap, 4u);
  EXPECT_EQ(countVerdicts(p), (std::array<int, kSeamVerdictCount>{2, 2, 3, 0, 0, 0}));
  const WorstDefects none = worstDefects(std::vector<const SeamReport*>{&seams[1], &seams[2]});
  EXPECT_FALSE(none.kink || none.gap);

  // By verdict (issue 38 goal 3): kinks 0 (10 deg) and 5 (3 deg), gaps 4 (0.01) and 6 (0.002), the failed
  // analysis, then the creases 3, 2, 1 (150, 90, 45 deg); the verdicts follow from the hinges' construction.
  SeamSelection byVerdict;
  byVerdict.sort = SeamSortKey::kVerdict;
  EXPECT_EQ(selectSeams(withFailed, byVerdict), (std::vector<size_t>{1, 6, 5, 7, 0, 4, 3, 2}));
  byVerdict.only = SeamFilter::kKinks;
  EXPECT_EQ(selectSeams(withFailed, byVerdict), (std::vector<size_t>{1, 6}));
  byVerdict.only = SeamFilter::kGaps;
  EXPECT_EQ(selectSeams(withFailed, byVerdict), (std::vector<size_t>{5, 7}));
  byVerdict.only = SeamFilter::kCreases;
  EXPECT_EQ(selectSeams(withFailed, byVerdict), (std::vector<size_t>{4, 3, 2}));
  for (const char* name : {"all", "problems", "gaps", "kinks", "creases"})
    EXPECT_EQ(toString(*parseSeamFilter(name)), name);
  EXPECT_FALSE(parseSeamFilter("bumps").isOk());

  EXPECT_EQ(*parseSeamSortKey("curvature"), SeamSortKey::kCurvature);
  EXPECT_EQ(*parseSeamSortKey("verdict"), SeamSortKey::kVerdict);
  EXPECT_FALSE(parseSeamSortKey("size").isOk());
  EXPECT_FALSE(validCreaseAngle(0.0));
  EXPECT_TRUE(validCreaseAngle(180.0));
}

}  // namespace
}  // namespace seam
