// Overlapping faces (src/continuity/overlap.cpp, issue 38 §11). Expected values come from the constructions: planes
// whose overlap is a known share of the sample grid, copies offset by a known distance, copies whose control points
// moved by at most a known amount (the surface moves by at most that: the basis functions sum to 1), neighbours
// that only share an edge, surfaces that cross.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <string>

#include "hinge_models.h"
#include "seam/continuity/model_check.h"
#include "seam/continuity/overlap.h"
#include "seam/model/model.h"
#include "seam/spline/bspline_surface.h"
#include "test_helpers.h"

namespace seam {
namespace {

using test::planarPatch;

constexpr double kTol = 1e-3;  // the distance tolerance of these tests

/// A random bicubic Bezier height field over [x0, x0 + 1] x [0, 1] (heights in [-0.3, 0.3]).
Patch bumpyPatch(const std::string& name, std::mt19937_64& rng, double x0 = 0.0) {
  Matrix pts(16, 3);
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j)
      pts.row(i * 4 + j) = Vec3(x0 + i / 3.0, j / 3.0, test::uniformReal(rng, -0.3, 0.3)).transpose();
  return Patch{name, PatchKind::kBezier, BSplineSurface(3, 3, KnotVector::bezier(3), KnotVector::bezier(3), 4, 4, pts)};
}

Model modelOf(std::vector<Patch> patches) {
  Model m;
  m.patches = std::move(patches);
  return m;
}

TEST(Overlap, ADuplicatedFaceOverlapsAllOverAtDistanceZeroWhateverItsOrientation) {
  std::mt19937_64 rng(20261129);
  for (int trial = 0; trial < 20; ++trial) {
    const Patch a = bumpyPatch("A", rng);
    Patch b = a;
    b.name = "B";
    if (trial % 2 == 1) b.surface = b.surface.reversedU();  // the copy with the opposite normal
    if (trial % 4 == 3) b.surface = b.surface.swappedUV();
    const std::vector<FaceOverlap> o = findOverlaps(modelOf({a, b}), kTol);
    ASSERT_EQ(o.size(), 1u) << trial;
    EXPECT_EQ(o[0].a, 0);
    EXPECT_EQ(o[0].b, 1);
    EXPECT_EQ(o[0].fraction, 1.0);
    EXPECT_LE(o[0].maxDistance, 1e-12);
  }
}

TEST(Overlap, ACopyOffsetBelowTheToleranceOverlapsAndAboveItDoesNot) {
  const Patch a = planarPatch("A", Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0));
  for (const double offset : {0.25 * kTol, 0.9 * kTol, 1.1 * kTol, 4.0 * kTol}) {
    const Patch b = planarPatch("B", Vec3(0, 0, offset), Vec3(1, 0, 0), Vec3(0, 1, 0));
    const std::vector<FaceOverlap> o = findOverlaps(modelOf({a, b}), kTol);
    if (offset < kTol) {
      ASSERT_EQ(o.size(), 1u) << offset;
      EXPECT_EQ(o[0].fraction, 1.0);
      EXPECT_NEAR(o[0].maxDistance, offset, 1e-12);  // the planes are exactly `offset` apart
      // A sample of one of them (of A: z = 0, or of B: z = offset), inside both in x and y.
      EXPECT_TRUE(std::abs(o[0].point.z()) <= 1e-15 || std::abs(o[0].point.z() - offset) <= 1e-15) << o[0].point.z();
      EXPECT_GT(o[0].point.x(), 0.0);
      EXPECT_LT(o[0].point.x(), 1.0);
    } else {
      EXPECT_TRUE(o.empty()) << offset;
    }
  }
}

// A over [0, 1]^2, B over [0.5, 1.5] x [0, 1] in the same plane: 4 of A's 8 sample columns (x = 0.5625 .. 0.9375)
// lie on B's interior, and 4 of B's on A's: a fraction of 1/2. Over [0.9, 1.9]: one column of 8 (x = 0.9375), 1/8,
// exactly the threshold; over [0.95, 1.95]: none.
TEST(Overlap, APartialOverlapIsTheShareOfTheSamplesOnTheOther) {
  const Patch a = planarPatch("A", Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0));
  const std::vector<std::pair<double, double>> cases{{0.5, 0.5}, {0.9, 0.125}, {0.95, 0.0}};
  for (const auto& [x0, fraction] : cases) {
    const Patch b = planarPatch("B", Vec3(x0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0));
    const std::vector<FaceOverlap> o = findOverlaps(modelOf({a, b}), kTol);
    if (fraction == 0.0) {
      EXPECT_TRUE(o.empty()) << x0;
      continue;
    }
    ASSERT_EQ(o.size(), 1u) << x0;
    EXPECT_EQ(o[0].fraction, fraction) << x0;
    EXPECT_LE(o[0].maxDistance, 1e-15);
  }
}

TEST(Overlap, NeighboursThatShareAnEdgeAndSurfacesThatCrossDoNotOverlap) {
  std::mt19937_64 rng(7);
  // A 3 x 3 network of bicubic height fields sharing their edges (C0): 9 patches, no overlap.
  Model net;
  Matrix heights(10, 10);
  for (int i = 0; i < 10; ++i)
    for (int j = 0; j < 10; ++j) heights(i, j) = test::uniformReal(rng, -0.3, 0.3);
  for (int pi = 0; pi < 3; ++pi)
    for (int pj = 0; pj < 3; ++pj) {
      Matrix pts(16, 3);
      for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j)
          pts.row(i * 4 + j) = Vec3(pi + i / 3.0, pj + j / 3.0, heights(3 * pi + i, 3 * pj + j)).transpose();
      net.patches.push_back(Patch{"P" + std::to_string(pi) + std::to_string(pj), PatchKind::kBezier,
                                  BSplineSurface(3, 3, KnotVector::bezier(3), KnotVector::bezier(3), 4, 4, pts)});
    }
  EXPECT_TRUE(findOverlaps(net, kTol).empty());
  // Hinges at small angles: the two planes share an edge and meet at 0.5 and 3 degrees.
  EXPECT_TRUE(findOverlaps(test::hingeModel({0.5, 3.0, 0.0}), kTol).empty());
  // Two planes that cross at right angles, and at 2 degrees (the samples next to the line where they cross lie
  // 1/16 x sin 2 deg = 2.2e-3 > kTol from the other plane).
  for (const double deg : {90.0, 2.0}) {
    const double phi = deg * std::numbers::pi / 180.0;
    const Patch a = planarPatch("A", Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0));
    const Patch b = planarPatch("B", Vec3(0.5 - 0.5 * std::cos(phi), 0, -0.5 * std::sin(phi)),
                                Vec3(std::cos(phi), 0, std::sin(phi)), Vec3(0, 1, 0));
    EXPECT_TRUE(findOverlaps(modelOf({a, b}), kTol).empty()) << deg;
  }
}

// A copy whose control points moved by at most kTol / 10 lies within kTol / 10 of the original (partition of unity).
TEST(Overlap, AJitteredCopyOverlapsWithinItsJitterAndTheResultIsTheSameOnAnyThreadCount) {
  std::mt19937_64 rng(11);
  std::vector<Patch> patches;
  for (int k = 0; k < 6; ++k) patches.push_back(bumpyPatch("P" + std::to_string(k), rng, 1.5 * k));
  Patch copy = patches[3];
  copy.name = "copy";
  Matrix pts = copy.surface.points();
  for (Eigen::Index i = 0; i < pts.rows(); ++i)
    for (int c = 0; c < 3; ++c) pts(i, c) += test::uniformReal(rng, -0.1, 0.1) * kTol / std::sqrt(3.0);
  copy.surface = BSplineSurface(3, 3, KnotVector::bezier(3), KnotVector::bezier(3), 4, 4, pts);
  patches.push_back(copy);
  const Model m = modelOf(patches);
  for (const int threads : {1, 2, 0}) {
    OverlapOptions oo;
    oo.threads = threads;
    const std::vector<FaceOverlap> o = findOverlaps(m, kTol, oo);
    ASSERT_EQ(o.size(), 1u) << threads;
    EXPECT_EQ(o[0].a, 3);
    EXPECT_EQ(o[0].b, 6);
    EXPECT_EQ(o[0].fraction, 1.0);
    EXPECT_LE(o[0].maxDistance, 0.1 * kTol);
  }
}

TEST(Overlap, CheckModelReportsThemWhenAskedAndOnlyThen) {
  Model m = test::hingeModel({10.0});
  Patch dup = m.patches[0];
  dup.name = "A0 copy";
  m.patches.push_back(dup);
  ModelCheckOptions o;
  o.tolerances = Tolerances{};
  EXPECT_TRUE(checkModel(m, o).value().overlaps.empty());  // off by default
  o.findOverlaps = true;
  const ModelCheckReport r = checkModel(m, o).value();
  ASSERT_EQ(r.overlaps.size(), 1u);
  EXPECT_EQ(r.summary.overlaps, 1);
  EXPECT_EQ(m.patches[static_cast<size_t>(r.overlaps[0].a)].name, "A0");
  EXPECT_EQ(m.patches[static_cast<size_t>(r.overlaps[0].b)].name, "A0 copy");
}

}  // namespace
}  // namespace seam
