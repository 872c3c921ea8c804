// Tests of analyzeSeam (include/seam/continuity/seam.h), issue 3 section 7.
//
// Every expected value comes from an independent route: an exact construction whose answer is known by
// construction (knot insertion and slicing, affine / polynomial reparametrisation, Johansson's Lemma 1 and 2
// written as Bezier row formulas, planar patches at a known dihedral angle, rigid translations, weight
// scaling), or a dense evaluation written in seam_test_support.h from the kernel's surface derivatives only.
// analyzeSeam is never used to produce an expected value (the weight-scaling test compares two analyses, but
// of the same geometry, which is the property under test).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <numbers>
#include <cstdint>
#include <iostream>
#include <limits>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "continuity/sampling.h"
#include "continuity/seam_internal.h"
#include "continuity/seam_correspondence.h"
#include "seam/continuity/seam.h"
#include "seam/continuity/verdict.h"
#include "seam/io/file.h"
#include "seam/model/brep.h"
#include "hinge_models.h"
#include "seam_test_support.h"

namespace seam {
namespace {

using namespace seamtest;  // NOLINT(google-build-using-namespace): test-only helpers

// =====================================================================================================================
// Named thresholds (why each bound).
// =====================================================================================================================

/// Exact constructions (knot insertion + slicing, Bernstein elevation/products, copies of control points)
/// agree to a few ulps, ~1e-15 relative. The analysis adds elevation, products and a division by |n|; a few
/// thousand ulps is the realistic worst case. 1e-10 relative to the patch size is far below the default
/// distance tolerance (1e-6), so it proves "zero up to round-off", not just "within tolerance".
constexpr double kExactDistanceRel = 1e-10;
/// Angle of exact G1 constructions: normals agree to ~1e-14 relative, i.e. ~1e-12 degrees; 1e-6 degrees
/// leaves a wide margin and is the accuracy the issue asks for known kink angles (item iv).
constexpr double kExactAngleDeg = 1e-6;
/// Known angles (items iv, vi) must be reproduced within 1e-6 degrees (brief, item iv).
constexpr double kKnownAngleTolDeg = 1e-6;
/// Curvature jump of exact G2 constructions, relative to the curvature scale: second derivatives lose ~2 more
/// digits than first derivatives to round-off (differences of control points divided by squared knot spans).
constexpr double kExactCurvatureRel = 1e-7;
/// Connecting functions (lambda, kappa) of exact constructions: a 2x2 least-squares solve with condition
/// number
/// <= ~1e3 on data exact to ~1e-15 relative. Also allows for the sampled range being taken at the seam ends,
/// where the extremes of linear lambda/kappa occur (the header calls the ranges "sampled").
constexpr double kExactFunctionTol = 1e-8;
/// Parametric mismatch of exact constructions: the header's relative c1/c2 mismatch is computed from the same
/// data.
constexpr double kExactMismatch = 1e-9;
/// Overlap intervals of exact constructions (knot values copied exactly; found by projection of end points):
/// the projection converges to ~1e-15 but is only as well-conditioned as the edge speed; 1e-9 of the edge
/// length.
constexpr double kOverlapTol = 1e-9;
/// Overlap ends of gap cases (item v): the ends are found by closest-point projection of end points at a gap;
/// the projection of a point at distance h from a straight edge is exact, so only round-off remains.
constexpr double kGapOverlapTol = 1e-7;
/// Certified bounds must be within 1 % of the sampled worst value (issue 3, section 3).
constexpr double kBoundRelGap = 0.01;
/// The test's own 10^4-point sampling can miss a smooth maximum by ~f'' h^2 / 8 relative, h = 1e-4 of the
/// seam:
/// <= 1e-6 for the polynomials here. 1e-4 also absorbs the O(eps^2) difference between a closest-point
/// correspondence and a parametric one for the eps ~ 1e-4 edge perturbations of the bounds test.
constexpr double kDenseSlackRel = 1e-4;
/// Values the header calls "sampled" (64 points per span, refined) against the test's denser sampling: a
/// smooth maximum is missed by ~ f'' h^2 / 8 relative, h = 1/64, i.e. a few 1e-3 for the degree <= 12 data
/// here.
constexpr double kSampledRel = 0.02;
/// Round-off floors under which a measured value counts as zero in the bounds test (relative to patch size
/// for g0, absolute degrees for g1, relative to the curvature scale for g2): the exact-G0 pairs there have g0
/// ~ 1e-16.
constexpr double kFloorDistanceRel = 1e-11;
constexpr double kFloorAngleDeg = 1e-7;
constexpr double kFloorCurvatureRel = 1e-8;
/// A reference value this many times above a tolerance is unambiguously above it (and this many times below,
/// unambiguously below), so an expected class does not hang on sampling details: the sampled maxima here (64 per span
/// in the implementation, 400 or more in the test) agree to well under 1 %, far inside a factor 3.
constexpr double kClearMargin = 3.0;

// =====================================================================================================================
// Small helpers.
// =====================================================================================================================

std::string describe(const SeamReport& r) {
  std::ostringstream os;
  os.precision(10);
  os << "report: geometric " << toString(r.geometric) << ", parametric " << toString(r.parametric)
     << ", certified " << r.certified << ", corr " << toString(r.correspondence) << " deg "
     << r.correspondenceDegree << ", reversed " << r.reversed << ", overlapA [" << r.overlapA.lo << ", "
     << r.overlapA.hi << "], overlapB [" << r.overlapB.lo << ", " << r.overlapB.hi << "], g0 " << r.g0Max
     << " (" << r.g0Sampled << "), g1 " << r.g1MaxDeg << " (" << r.g1SampledDeg << "), g2 " << r.g2Max << " ("
     << r.g2Sampled << "), g2rel " << r.g2RelMax << ", lambda [" << r.lambdaRange.lo << ", "
     << r.lambdaRange.hi << "], kappa [" << r.kappaRange.lo << ", " << r.kappaRange.hi << "], c1 "
     << r.c1Mismatch << ", c2 " << r.c2Mismatch << ", g1Id " << r.g1Identity << ", g2Id " << r.g2Identity;
  for (const auto& n : r.notes) os << "\n  note: " << n;
  return os.str();
}

/// Runs analyzeSeam on two unnamed patches; records a failure (and returns nullopt) on an error.
std::optional<SeamReport> analyze(const BSplineSurface& a, Edge ea, const BSplineSurface& b, Edge eb,
                                  const SeamOptions& opt = {},
                                  std::optional<Interval> aRange = std::nullopt) {
  const Patch pa = makePatch("A", a), pb = makePatch("B", b);
  Result<SeamReport> r = aRange ? analyzeSeam(pa, ea, pb, eb, opt, aRange) : analyzeSeam(pa, ea, pb, eb, opt);
  if (!r) {
    ADD_FAILURE() << "analyzeSeam(A:" << edgeName(ea) << ", B:" << edgeName(eb)
                  << ") failed: " << r.status().message();
    return std::nullopt;
  }
  return std::move(r).value();
}

::testing::AssertionResult near(double expected, double actual, double tol, const char* what) {
  if (std::abs(expected - actual) <= tol) return ::testing::AssertionSuccess();
  std::ostringstream os;
  os.precision(15);
  os << what << ": expected " << expected << ", got " << actual << " (|diff| " << std::abs(expected - actual)
     << " > " << tol << ")";
  return ::testing::AssertionFailure() << os.str();
}

::testing::AssertionResult sameInterval(Interval expected, Interval actual, double tol, const char* what) {
  if (std::abs(expected.lo - actual.lo) <= tol && std::abs(expected.hi - actual.hi) <= tol)
    return ::testing::AssertionSuccess();
  std::ostringstream os;
  os.precision(15);
  os << what << ": expected [" << expected.lo << ", " << expected.hi << "], got [" << actual.lo << ", "
     << actual.hi << "] (tol " << tol << ")";
  return ::testing::AssertionFailure() << os.str();
}

/// A certified angle bound for a seam of constant known angle theta: never below theta, and within the requested
/// relative gap above it (issue 3 section 3: "subdivided until the bound is within 1 % of the best sampled value").
::testing::AssertionResult certifiedAngleBound(double thetaDeg, double boundDeg, double relGap) {
  if (boundDeg >= thetaDeg - kKnownAngleTolDeg && boundDeg <= thetaDeg * (1.0 + relGap) + kKnownAngleTolDeg)
    return ::testing::AssertionSuccess();
  std::ostringstream os;
  os.precision(15);
  os << "certified angle bound " << boundDeg << " outside [" << thetaDeg << ", " << thetaDeg * (1.0 + relGap)
     << "] (+/- " << kKnownAngleTolDeg << ")";
  return ::testing::AssertionFailure() << os.str();
}

bool atLeastC1(ParametricClass c) { return c == ParametricClass::kC1 || c == ParametricClass::kC2; }

/// The expectations shared by every exact G2 construction: zero gap, angle and curvature jump to round-off,
/// certified, proved as identities.
void expectExactG2(const SeamReport& r, double scale, double curvScale) {
  EXPECT_EQ(r.geometric, GeometricClass::kG2);
  EXPECT_TRUE(r.certified);
  EXPECT_TRUE(r.g1Identity);
  EXPECT_TRUE(r.g2Identity);
  EXPECT_LE(r.g0Max, kExactDistanceRel * scale);
  EXPECT_LE(r.g1MaxDeg, kExactAngleDeg);
  EXPECT_LE(r.g2Max, kExactCurvatureRel * curvScale);
  EXPECT_LE(r.g2RelMax, kExactCurvatureRel);
}

// =====================================================================================================================
// (i) A C2 bicubic B-spline split at an interior knot: G2 and C2, certified, in every edge pairing
// orientation.
// =====================================================================================================================

struct SplitPair {
  BSplineSurface s, a, b;  // a = part on [u_min, k], b = part on [k, u_max] (or in v)
  double k = 0.0;
};

SplitPair randomSplitU(Rng& rng, int p, bool rational) {
  const BSplineSurface s = randomGraphSurface(rng, p, p, p + 4, p + 3, rational);
  const std::vector<double> ks = interiorKnots(s.knotsU(), p);
  const double k = ks[static_cast<size_t>(irand(rng, 0, static_cast<int>(ks.size()) - 1))];
  auto [a, b] = splitU(s, k);
  return {s, a, b, k};
}

/// Construction self-check: both parts reproduce the surface (same parameter values), so the pair is C^(p-1).
void checkSplitReproduces(const SplitPair& sp, bool inU) {
  const double scale = patchScale(sp.s);
  for (int i = 0; i <= 10; ++i)
    for (int j = 0; j <= 10; ++j) {
      const double f = i / 10.0, g = j / 10.0;
      const Interval da = inU ? sp.a.domainU() : sp.a.domainV(), db = inU ? sp.b.domainU() : sp.b.domainV();
      const Interval other = inU ? sp.s.domainV() : sp.s.domainU();
      const double x = other.lo + g * other.length();
      const double ua = da.lo + f * da.length(), ub = db.lo + f * db.length();
      const VecX sa = inU ? sp.s.evaluate(ua, x) : sp.s.evaluate(x, ua);
      const VecX sb = inU ? sp.s.evaluate(ub, x) : sp.s.evaluate(x, ub);
      const VecX pa = inU ? sp.a.evaluate(ua, x) : sp.a.evaluate(x, ua);
      const VecX pb = inU ? sp.b.evaluate(ub, x) : sp.b.evaluate(x, ub);
      ASSERT_LE((sa - pa).norm(), 1e-12 * scale) << "split part A does not reproduce the surface";
      ASSERT_LE((sb - pb).norm(), 1e-12 * scale) << "split part B does not reproduce the surface";
    }
}

TEST(SeamSplit, WithoutTheG2CertificateAG2SeamIsClaimedG1AtMost) {
  // SeamOptions::certifyG2 = false skips the G2 subdivision: the G0/G1 verdict is unchanged, the class is capped at
  // G1 (the split of one C2 surface is G2 by construction, and the full analysis says so).
  Rng rng(3002);
  const SplitPair sp = randomSplitU(rng, 3, false);
  SeamOptions o;
  o.certifyG2 = false;
  auto full = analyze(sp.a, Edge::U1, sp.b, Edge::U0);
  auto fast = analyze(sp.a, Edge::U1, sp.b, Edge::U0, o);
  ASSERT_TRUE(full && fast);
  EXPECT_EQ(full->geometric, GeometricClass::kG2);
  EXPECT_EQ(fast->geometric, GeometricClass::kG1);
  EXPECT_TRUE(fast->certified);
  EXPECT_TRUE(fast->g1Identity);
  EXPECT_EQ(full->g1MaxDeg, fast->g1MaxDeg);
  EXPECT_EQ(full->g0Max, fast->g0Max);
}

TEST(SeamSplit, BicubicSplitInUIsG2AndC2) {
  Rng rng(3001);
  for (int trial = 0; trial < 4; ++trial) {
    SCOPED_TRACE("trial " + std::to_string(trial));
    const SplitPair sp = randomSplitU(rng, 3, false);
    checkSplitReproduces(sp, true);
    const double scale = patchScale(sp.s);
    const RefMeasures ref = denseReference(sp.a, Edge::U1, sp.b, Edge::U0, refOpts(200, identityMap, false));
    auto r = analyze(sp.a, Edge::U1, sp.b, Edge::U0);
    ASSERT_TRUE(r);
    SCOPED_TRACE(describe(*r));
    expectExactG2(*r, scale, ref.curvScale);
    EXPECT_EQ(r->parametric, ParametricClass::kC2);
    EXPECT_LE(r->c1Mismatch, kExactMismatch);
    EXPECT_LE(r->c2Mismatch, kExactMismatch);
    EXPECT_FALSE(r->reversed);
    EXPECT_EQ(r->correspondence, Correspondence::kAffine);
    EXPECT_EQ(r->correspondenceDegree, 1);
    EXPECT_TRUE(sameInterval(sp.a.domainV(), r->overlapA, kOverlapTol, "overlapA"));
    EXPECT_TRUE(sameInterval(sp.b.domainV(), r->overlapB, kOverlapTol, "overlapB"));
    // Same parametrisation on both sides: B_cross = B_u = A_u = A_out, so lambda == 1 and kappa == 0 exactly.
    EXPECT_TRUE(sameInterval({1.0, 1.0}, r->lambdaRange, kExactFunctionTol, "lambdaRange"));
    EXPECT_TRUE(sameInterval({0.0, 0.0}, r->kappaRange, kExactFunctionTol, "kappaRange"));
    EXPECT_LE(r->g2ResidualMax, kExactCurvatureRel * ref.secondScale);
  }
}

TEST(SeamSplit, BicubicSplitInVIsG2AndC2) {
  Rng rng(3002);
  for (int trial = 0; trial < 3; ++trial) {
    SCOPED_TRACE("trial " + std::to_string(trial));
    const BSplineSurface s = randomGraphSurface(rng, 3, 3, 6, 7, false);
    const std::vector<double> ks = interiorKnots(s.knotsV(), 3);
    const double k = ks[static_cast<size_t>(irand(rng, 0, static_cast<int>(ks.size()) - 1))];
    auto [a, b] = splitV(s, k);
    const SplitPair sp{s, a, b, k};
    checkSplitReproduces(sp, false);
    const RefMeasures ref = denseReference(a, Edge::V1, b, Edge::V0, refOpts(200, identityMap, false));
    auto r = analyze(a, Edge::V1, b, Edge::V0);
    ASSERT_TRUE(r);
    SCOPED_TRACE(describe(*r));
    expectExactG2(*r, patchScale(s), ref.curvScale);
    EXPECT_EQ(r->parametric, ParametricClass::kC2);
    EXPECT_FALSE(r->reversed);
    EXPECT_TRUE(sameInterval(a.domainU(), r->overlapA, kOverlapTol, "overlapA"));
    EXPECT_TRUE(sameInterval(b.domainU(), r->overlapB, kOverlapTol, "overlapB"));
    EXPECT_TRUE(sameInterval({1.0, 1.0}, r->lambdaRange, kExactFunctionTol, "lambdaRange"));
    EXPECT_TRUE(sameInterval({0.0, 0.0}, r->kappaRange, kExactFunctionTol, "kappaRange"));
  }
}

// A seam that crosses a crease or a curvature break of the surface: v has a double or triple interior knot (the
// surface is only C1 or C0 across the iso-line there; the triple knot's control row is lifted to make a real
// crease), and the split in u runs across it. Along the seam the edge curve has a corner (or a curvature jump) at
// the knot, but the two parts are one surface: G2 on each side of the knot, certified, in both orientations. With the
// neighbour reversed along the edge, the sampled route used to take A's limit from one side of the knot and B's
// from the other, saw the crease as a kink across the seam, and called the seam G0 (an angle of 10-50 degrees).
TEST(SeamSplit, AMirroredNeighbourAcrossADoubleOrTripleKnotAlongTheEdgeKeepsItsClass) {
  Rng rng(3010);
  for (const std::vector<double>& kv : {std::vector<double>{0, 0, 0, 0, 0.5, 0.5, 1, 1, 1, 1},
                                        std::vector<double>{0, 0, 0, 0, 0.4, 0.4, 0.4, 1, 1, 1, 1},
                                        std::vector<double>{0, 0, 0, 0, 0.3, 0.6, 0.6, 0.6, 1, 1, 1, 1}}) {
    const int nu = 6, nv = static_cast<int>(kv.size()) - 4;
    Matrix p = graphNet(rng, nu, nv, 0.25);
    const auto tripleAt = std::adjacent_find(kv.begin(), kv.end(), [&](double x, double y) {
      return x == y && x > 0.0 && x < 1.0 && std::count(kv.begin(), kv.end(), x) == 3;
    });
    if (tripleAt != kv.end()) {  // the row interpolated at the triple knot: lift it, a crease along u
      const int j = static_cast<int>(std::distance(kv.begin(), tripleAt)) - 1;
      for (int i = 0; i < nu; ++i) p(i * nv + j, 2) += 0.3;
    }
    const BSplineSurface s(3, 3, KnotVector::clampedUniform(3, nu), KnotVector(kv), nu, nv, p, VecX());
    auto [a, b] = splitU(s, KnotVector::clampedUniform(3, nu)[4]);
    const SplitPair sp{s, a, b, 0.0};
    checkSplitReproduces(sp, true);
    for (const bool mirrored : {false, true}) {
      SCOPED_TRACE(std::string(mirrored ? "mirrored, " : "") + "knots v " + std::to_string(kv.size()));
      auto r = analyze(a, Edge::U1, mirrored ? b.reversedV() : b, Edge::U0);
      ASSERT_TRUE(r);
      SCOPED_TRACE(describe(*r));
      EXPECT_EQ(r->reversed, mirrored);
      EXPECT_EQ(r->geometric, GeometricClass::kG2);
      EXPECT_TRUE(r->certified);
      EXPECT_LE(r->g1MaxDeg, kExactAngleDeg);
      EXPECT_LE(r->g1SampledDeg, kExactAngleDeg);
      EXPECT_LE(r->g2RelMax, kExactCurvatureRel);
    }
  }
}

// Every way of presenting the same split pair. Seen from their edges (seam.h: A' = A.orientedFrom(ea)) the
// swapped and cross-reversed copies are the identical oriented surfaces, so everything is unchanged. A copy
// reversed ALONG the edge is the same surface with its edge parameter run backwards (s = a + b - t):
// `reversed` is set, the geometry is unchanged (G2), lambda stays 1 and kappa flips sign only if A's along
// direction flips (it is 0 here). The header defines the parametric mismatch on the oriented cross
// derivatives at corresponding points, max |B'_u^k - (-1)^k A'_u^k| / max |A'_u^k|, which is exactly 0 for
// all of these; and a reversal is an isometry of the edge parameter (|phi'| = 1, knot values kept), so the
// parametrisations match: C2 throughout.
TEST(SeamSplit, EveryEdgePairingOrientationGivesTheSameClasses) {
  Rng rng(3003);
  const SplitPair sp = randomSplitU(rng, 3, false);
  const BSplineSurface &a = sp.a, &b = sp.b;
  struct Variant {
    std::string name;
    BSplineSurface a;
    Edge ea;
    BSplineSurface b;
    Edge eb;
    bool reversed;
  };
  // Where the shared edge goes: a's edge is u = max (U1); b's is u = min (U0).
  //  swappedUV: u <-> v, so U1 -> V1 and U0 -> V0, along direction kept.
  //  reversedU: u -> a + b - u, so U0 <-> U1, along direction (v) kept.
  //  reversedV: the edge stays (U0/U1) but its parameter v runs backwards.
  const std::vector<Variant> variants = {
      {"base", a, Edge::U1, b, Edge::U0, false},
      {"A swapped", a.swappedUV(), Edge::V1, b, Edge::U0, false},
      {"B swapped", a, Edge::U1, b.swappedUV(), Edge::V0, false},
      {"both swapped", a.swappedUV(), Edge::V1, b.swappedUV(), Edge::V0, false},
      {"B reversed across", a, Edge::U1, b.reversedU(), Edge::U1, false},
      {"A reversed across", a.reversedU(), Edge::U0, b, Edge::U0, false},
      {"B reversed along", a, Edge::U1, b.reversedV(), Edge::U0, true},
      {"A reversed along", a.reversedV(), Edge::U1, b, Edge::U0, true},
      {"B swapped, reversed along", a, Edge::U1, b.swappedUV().reversedU(), Edge::V0, true},
      {"B swapped, reversed across", a, Edge::U1, b.swappedUV().reversedV(), Edge::V1, false},
      {"roles exchanged", b, Edge::U0, a, Edge::U1, false},
      {"roles exchanged, A reversed along", b.reversedV(), Edge::U0, a, Edge::U1, true},
  };
  const double scale = patchScale(sp.s);
  for (const Variant& v : variants) {
    SCOPED_TRACE(v.name);
    const RefMeasures ref =
        denseReference(v.a, v.ea, v.b, v.eb, refOpts(100, nullptr, false));  // closest-point correspondence
    ASSERT_LE(ref.g1Deg, kExactAngleDeg) << "construction: variant is not an exact G1 presentation";
    ASSERT_LE(ref.g2Rel, kExactCurvatureRel) << "construction: variant is not an exact G2 presentation";
    auto r = analyze(v.a, v.ea, v.b, v.eb);
    ASSERT_TRUE(r);
    SCOPED_TRACE(describe(*r));
    expectExactG2(*r, scale, ref.curvScale);
    EXPECT_EQ(r->reversed, v.reversed);
    EXPECT_EQ(r->correspondence, Correspondence::kAffine);
    EXPECT_LE(r->c1Mismatch, kExactMismatch);
    EXPECT_LE(r->c2Mismatch, kExactMismatch);
    EXPECT_EQ(r->parametric, ParametricClass::kC2);
    EXPECT_TRUE(sameInterval({1.0, 1.0}, r->lambdaRange, kExactFunctionTol, "lambdaRange"));
    EXPECT_TRUE(sameInterval({0.0, 0.0}, r->kappaRange, kExactFunctionTol, "kappaRange"));
    const Interval ea = isUEdge(v.ea) ? v.a.domainV() : v.a.domainU();
    const Interval eb = isUEdge(v.eb) ? v.b.domainV() : v.b.domainU();
    EXPECT_TRUE(sameInterval(ea, r->overlapA, kOverlapTol, "overlapA"));
    EXPECT_TRUE(sameInterval(eb, r->overlapB, kOverlapTol, "overlapB"));
  }
}

// =====================================================================================================================
// (ii) One side reparametrised: affine maps (along and/or across) and a monotone polynomial w(t) along the
// edge.
// =====================================================================================================================

TEST(SeamReparametrised, AffineAcrossOnlyIsG2AndC0WithKnownLambdaAndMismatch) {
  Rng rng(3101);
  for (int trial = 0; trial < 3; ++trial) {
    SCOPED_TRACE("trial " + std::to_string(trial));
    const SplitPair sp = randomSplitU(rng, 3, trial == 2);
    const Interval du = sp.b.domainU();
    const double c = factorAwayFromOne(rng, 0.3, 3.0, 1.3);  // new length / old length across
    const double lo = urand(rng, -5.0, 5.0);
    const BSplineSurface b2 = sp.b.reparametrized({lo, lo + c * du.length()}, sp.b.domainV());
    // b2(u2, v) = b(u(u2), v) with du/du2 = 1/c: B_cross = B_u / c = A_out / c, B_uu = A_uu / c^2. Hence
    // lambda = 1/c, kappa = 0, and the header's relative mismatches are exactly |1/c - 1| and |1/c^2 - 1|.
    // The edge parameter is untouched, so the positions match parametrically: C0, and not C1.
    auto r = analyze(sp.a, Edge::U1, b2, Edge::U0);
    ASSERT_TRUE(r);
    SCOPED_TRACE(describe(*r));
    const RefMeasures ref = denseReference(sp.a, Edge::U1, b2, Edge::U0, refOpts(100, identityMap, false));
    expectExactG2(*r, patchScale(sp.s), ref.curvScale);
    EXPECT_EQ(r->parametric, ParametricClass::kC0);
    EXPECT_TRUE(near(std::abs(1.0 / c - 1.0), r->c1Mismatch, kExactFunctionTol, "c1Mismatch"));
    EXPECT_TRUE(near(std::abs(1.0 / (c * c) - 1.0), r->c2Mismatch, kExactFunctionTol, "c2Mismatch"));
    EXPECT_TRUE(sameInterval({1.0 / c, 1.0 / c}, r->lambdaRange, kExactFunctionTol, "lambdaRange"));
    EXPECT_TRUE(sameInterval({0.0, 0.0}, r->kappaRange, kExactFunctionTol, "kappaRange"));
    EXPECT_TRUE(near(1.0 / c, ref.lambdaMin, kExactFunctionTol, "reference lambda (construction check)"));
  }
}

TEST(SeamReparametrised, AffineAlongTheEdgeIsG2ButNotC1) {
  Rng rng(3102);
  for (int trial = 0; trial < 6; ++trial) {
    SCOPED_TRACE("trial " + std::to_string(trial));
    const bool rational = trial % 2 == 1;
    const bool alsoAcross = trial >= 2;
    const bool reverse = trial >= 4;
    const SplitPair sp = randomSplitU(rng, 3, rational);
    const Interval dv = sp.b.domainV(), du = sp.b.domainU();
    const double alpha = factorAwayFromOne(rng, 0.25, 4.0, 1.3);
    const double beta = urand(rng, -3.0, 3.0);
    const double c = alsoAcross ? factorAwayFromOne(rng, 0.3, 3.0, 1.3) : 1.0;
    const double ulo = urand(rng, -2.0, 2.0);
    const BSplineSurface bBase = reverse ? sp.b.reversedV() : sp.b;
    const BSplineSurface b2 =
        bBase.reparametrized({ulo, ulo + c * du.length()}, {beta, beta + alpha * dv.length()});
    // s = phi(t): t -> (t - v0) (reversed: v1 - t), then scaled by alpha and shifted to beta.
    const auto phi = [&](double t) {
      const double x = reverse ? dv.hi - t : t - dv.lo;
      return beta + alpha * x;
    };
    auto r = analyze(sp.a, Edge::U1, b2, Edge::U0);
    ASSERT_TRUE(r);
    SCOPED_TRACE(describe(*r));
    const RefMeasures ref = denseReference(sp.a, Edge::U1, b2, Edge::U0, refOpts(100, phi, false));
    expectExactG2(*r, patchScale(sp.s), ref.curvScale);
    // The issue (7.ii): an along-edge reparametrisation (|phi'| = alpha != 1) is G2 but never C1.
    EXPECT_FALSE(atLeastC1(r->parametric)) << "parametric " << toString(r->parametric);
    EXPECT_EQ(r->correspondence, Correspondence::kAffine);
    EXPECT_EQ(r->correspondenceDegree, 1);
    EXPECT_EQ(r->reversed, reverse);
    EXPECT_TRUE(sameInterval(sp.a.domainV(), r->overlapA, kOverlapTol, "overlapA"));
    EXPECT_TRUE(
        sameInterval({beta, beta + alpha * dv.length()}, r->overlapB, kOverlapTol * alpha, "overlapB"));
    // The cross derivative is untouched by the along map: lambda = 1/c, kappa = 0.
    EXPECT_TRUE(sameInterval({1.0 / c, 1.0 / c}, r->lambdaRange, kExactFunctionTol, "lambdaRange"));
    EXPECT_TRUE(sameInterval({0.0, 0.0}, r->kappaRange, kExactFunctionTol, "kappaRange"));
  }
}

struct BezierSplit {
  BezierPatch p, a, b;  // a = p on u in [0, 1/2], b = p on [1/2, 1], both reparametrised to [0,1]^2
};

BezierSplit randomBezierSplit(Rng& rng, int n, int m, bool rational) {
  const BezierPatch p = randomGraphBezier(rng, n, m, rational);
  const BernsteinPatch h = p.homogeneous();
  // a(u,v) = p(u/2, v), b(u,v) = p(1/2 + u/2, v): a_u = b_u = p_u / 2 on the shared edge, so the pair is
  // C-infinity.
  return {p, bezierFromHomogeneous(h.restricted(0.0, 0.5, 0.0, 1.0), rational),
          bezierFromHomogeneous(h.restricted(0.5, 1.0, 0.0, 1.0), rational)};
}

TEST(SeamReparametrised, MonotonePolynomialAlongTheEdgeIsG2NotC1Certified) {
  Rng rng(3103);
  for (int trial = 0; trial < 6; ++trial) {
    SCOPED_TRACE("trial " + std::to_string(trial));
    const bool rational = trial % 2 == 1;
    const bool reverse = trial >= 4;
    const int dw = 2 + trial / 2 % 2;  // 2, 2, 3, 3, 2, 2
    const BezierSplit bs = randomBezierSplit(rng, 3, 3, rational);
    BernsteinPoly w = randomMonotone(rng, dw);
    if (reverse)
      w = BernsteinPoly::constant(1.0, dw) - w;  // decreasing: the edges run in opposite directions
    const BezierPatch bw = composedAlongV(bs.b, w);
    ASSERT_EQ(bw.degreeV(), 3 * dw);
    // Construction check: bw(u, s) == b(u, w(s)).
    for (int i = 0; i <= 8; ++i)
      for (int j = 0; j <= 8; ++j) {
        const double u = i / 8.0, s = j / 8.0;
        ASSERT_LE((bw.evaluate(u, s) - bs.b.evaluate(u, w.scalar(s))).norm(), 1e-13 * 10.0);
      }
    const BSplineSurface A = bs.a.toBSpline(), B = bw.toBSpline();
    const double scale = patchScale(bs.p.toBSpline());
    // Both directions of the analysis: A against B (t = w(s), phi = w^-1) and B against A (phi = w).
    for (int dir = 0; dir < 2; ++dir) {
      SCOPED_TRACE(dir == 0 ? "A vs B(w)" : "B(w) vs A");
      auto r = dir == 0 ? analyze(A, Edge::U1, B, Edge::U0) : analyze(B, Edge::U0, A, Edge::U1);
      ASSERT_TRUE(r);
      SCOPED_TRACE(describe(*r));
      const RefMeasures ref = dir == 0
                                  ? denseReference(A, Edge::U1, B, Edge::U0, refOpts(100, nullptr, false))
                                  : denseReference(B, Edge::U0, A, Edge::U1, refOpts(100, nullptr, false));
      expectExactG2(*r, scale, ref.curvScale);
      EXPECT_FALSE(atLeastC1(r->parametric)) << "parametric " << toString(r->parametric);
      EXPECT_EQ(r->correspondence, Correspondence::kPolynomial);
      EXPECT_EQ(r->correspondenceDegree, dw);
      EXPECT_EQ(r->reversed, reverse);
      EXPECT_TRUE(sameInterval({0.0, 1.0}, r->overlapA, kOverlapTol, "overlapA"));
      EXPECT_TRUE(sameInterval({0.0, 1.0}, r->overlapB, kOverlapTol, "overlapB"));
      // bw_u(0, s) = b_u(0, w(s)) = a_out at the same point: lambda = 1, kappa = 0 in both directions.
      EXPECT_TRUE(sameInterval({1.0, 1.0}, r->lambdaRange, kExactFunctionTol, "lambdaRange"));
      EXPECT_TRUE(sameInterval({0.0, 0.0}, r->kappaRange, kExactFunctionTol, "kappaRange"));
    }
  }
}

// =====================================================================================================================
// (iii) G1-but-not-G2 pairs from Johansson's Lemma 1 (and G2 pairs from Lemma 2).
// =====================================================================================================================

struct LambdaKappa {
  BernsteinPoly lambda, kappa;
  double l0, l1, k0, k1;  // values at t = 0 and t = 1
};

LambdaKappa randomLambdaKappa(Rng& rng, bool linearLambda, bool linearKappa) {
  // lambda > 0 and clearly not 1 (so the pair is never C1); kappa of either sign.
  const double l0 = factorAwayFromOne(rng, 0.3, 3.0, 1.25);
  const double l1 = linearLambda ? factorAwayFromOne(rng, 0.3, 3.0, 1.25) : l0;
  const double k0 = urand(rng, -1.0, 1.0);
  const double k1 = linearKappa ? urand(rng, -1.0, 1.0) : k0;
  return {BernsteinPoly::linear(l0, l1), BernsteinPoly::linear(k0, k1), l0, l1, k0, k1};
}

/// The refined Lemma 2 residual against the dense reference's 400 samples, whose maximum lies within about h^2 of the
/// true one (h = 1/400).
constexpr double kRefinedResidualRel = 1e-4;

TEST(SeamLemma1, G1NotG2WithRandomLambdaAndKappa) {
  Rng rng(3201);
  SeamOptions opt;
  for (int trial = 0; trial < 8; ++trial) {
    SCOPED_TRACE("trial " + std::to_string(trial));
    const int n = irand(rng, 2, 4), m = irand(rng, 2, 4), nB = irand(rng, 2, 4);
    const LambdaKappa lk = randomLambdaKappa(rng, trial % 2 == 1, trial % 4 >= 2);
    const BezierPatch a0 = randomGraphBezier(rng, n, m, false);
    const Lemma1Pair pr = lemma1Pair(rng, a0, lk.lambda, lk.kappa, nB, false, trial >= 4);
    const BSplineSurface A = pr.a.toBSpline(), B = pr.b.toBSpline();
    ASSERT_LE(lemma1Residual(A, B, lk.lambda, lk.kappa), 1e-12) << "construction: Lemma 1 relation not exact";
    const RefMeasures ref = denseReference(A, Edge::U0, B, Edge::U0, refOpts(400, identityMap, false));
    ASSERT_GE(ref.g2Rel, kClearMargin * opt.tol.curvatureRel) << "construction: pair happens to be near G2";
    const double scale = patchScale(A);

    // Exchanging roles: A_cross' = -A_out = lambda' B_out + kappa' B_t with B_out = -B_cross, B_t = A_t gives
    // lambda' = 1/lambda and kappa' = kappa/lambda; both are monotone in t for linear lambda, kappa (a
    // Moebius map and a reciprocal), so their ranges are spanned by the end values.
    for (int dir = 0; dir < 2; ++dir) {
      SCOPED_TRACE(dir == 0 ? "A vs B" : "B vs A");
      auto r = dir == 0 ? analyze(A, Edge::U0, B, Edge::U0) : analyze(B, Edge::U0, A, Edge::U0);
      ASSERT_TRUE(r);
      SCOPED_TRACE(describe(*r));
      EXPECT_EQ(r->geometric, GeometricClass::kG1);
      EXPECT_TRUE(r->certified);
      EXPECT_TRUE(r->g1Identity);
      EXPECT_FALSE(r->g2Identity);
      EXPECT_FALSE(atLeastC1(r->parametric));
      EXPECT_EQ(r->correspondence, Correspondence::kAffine);
      EXPECT_FALSE(r->reversed);
      EXPECT_LE(r->g0Max, kExactDistanceRel * scale);
      EXPECT_LE(r->g1MaxDeg, kExactAngleDeg);
      EXPECT_GE(r->g2RelMax, ref.g2Rel * (1.0 - kDenseSlackRel));
      EXPECT_GE(r->g2Max, ref.g2 * (1.0 - kDenseSlackRel));
      if (dir == 0) {  // the Lemma 2 residual (refined on the exact pieces): as measured densely here
        // (The start samples alone came 3.6 % below the dense maximum in the case Clang's argument order draws;
        // refined, the 8 cases here agree with it to 1.3e-6.)
        EXPECT_GE(r->g2ResidualMax, ref.g2Residual * (1.0 - 1e-12));
        EXPECT_TRUE(near(ref.g2Residual, r->g2ResidualMax, kRefinedResidualRel * ref.g2Residual, "g2ResidualMax"));
      }
      const double la = dir == 0 ? lk.l0 : 1.0 / lk.l0, lb = dir == 0 ? lk.l1 : 1.0 / lk.l1;
      const double ka = dir == 0 ? lk.k0 : lk.k0 / lk.l0, kb = dir == 0 ? lk.k1 : lk.k1 / lk.l1;
      EXPECT_TRUE(sameInterval({std::min(la, lb), std::max(la, lb)}, r->lambdaRange, kExactFunctionTol,
                               "lambdaRange"));
      EXPECT_TRUE(
          sameInterval({std::min(ka, kb), std::max(ka, kb)}, r->kappaRange, kExactFunctionTol, "kappaRange"));
    }
  }
}

// The same Lemma 1 pair presented with other orientations. Reversing A along its edge (t -> 1 - t) flips A_t,
// so kappa changes sign: B_cross = lambda(1-t) A_out + (-kappa(1-t)) A_t.
TEST(SeamLemma1, OrientationsMapLambdaAndKappaAsDerived) {
  Rng rng(3202);
  const LambdaKappa lk = randomLambdaKappa(rng, true, true);
  const BezierPatch a0 = randomGraphBezier(rng, 3, 3, false);
  const Lemma1Pair pr = lemma1Pair(rng, a0, lk.lambda, lk.kappa, 3, false, true);
  const BSplineSurface A = pr.a.toBSpline(), B = pr.b.toBSpline();
  struct Variant {
    std::string name;
    BSplineSurface a;
    Edge ea;
    BSplineSurface b;
    Edge eb;
    bool reversed;
    double kappaSign;
  };
  const std::vector<Variant> variants = {
      {"A swapped", A.swappedUV(), Edge::V0, B, Edge::U0, false, 1.0},
      {"A reversed across", A.reversedU(), Edge::U1, B, Edge::U0, false, 1.0},
      {"B swapped, reversed across", A, Edge::U0, B.swappedUV().reversedV(), Edge::V1, false, 1.0},
      {"B reversed along", A, Edge::U0, B.reversedV(), Edge::U0, true, 1.0},
      {"A reversed along", A.reversedV(), Edge::U0, B, Edge::U0, true, -1.0},
      {"both reversed along", A.reversedV(), Edge::U0, B.reversedV(), Edge::U0, false, -1.0},
  };
  for (const Variant& v : variants) {
    SCOPED_TRACE(v.name);
    auto r = analyze(v.a, v.ea, v.b, v.eb);
    ASSERT_TRUE(r);
    SCOPED_TRACE(describe(*r));
    EXPECT_EQ(r->geometric, GeometricClass::kG1);
    EXPECT_TRUE(r->certified);
    EXPECT_EQ(r->reversed, v.reversed);
    EXPECT_LE(r->g1MaxDeg, kExactAngleDeg);
    EXPECT_TRUE(sameInterval({std::min(lk.l0, lk.l1), std::max(lk.l0, lk.l1)}, r->lambdaRange,
                             kExactFunctionTol, "lambdaRange"));
    const double ka = v.kappaSign * lk.k0, kb = v.kappaSign * lk.k1;
    EXPECT_TRUE(
        sameInterval({std::min(ka, kb), std::max(ka, kb)}, r->kappaRange, kExactFunctionTol, "kappaRange"));
  }
}

TEST(SeamLemma2, CurvatureConditionGivesG2ButNotC1) {
  Rng rng(3203);
  for (int trial = 0; trial < 4; ++trial) {
    SCOPED_TRACE("trial " + std::to_string(trial));
    const LambdaKappa lk = randomLambdaKappa(rng, trial % 2 == 1, true);
    const double mu1 = urand(rng, -1, 1), mu0 = urand(rng, -1, 1);  // drawn last argument first (test_helpers.h)
    const BernsteinPoly mu = BernsteinPoly::linear(mu0, mu1);
    const BernsteinPoly nu = BernsteinPoly::constant(urand(rng, -1, 1));
    const BezierPatch a0 = randomGraphBezier(rng, 3, irand(rng, 2, 3), false);
    const Lemma1Pair pr = lemma1Pair(rng, a0, lk.lambda, lk.kappa, 3, true, trial >= 2, mu, nu);
    const BSplineSurface A = pr.a.toBSpline(), B = pr.b.toBSpline();
    ASSERT_LE(lemma1Residual(A, B, lk.lambda, lk.kappa), 1e-12);
    const RefMeasures ref = denseReference(A, Edge::U0, B, Edge::U0, refOpts(400, identityMap, false));
    ASSERT_LE(ref.g2Rel, kExactCurvatureRel) << "construction: Lemma 2 pair is not G2";
    auto r = analyze(A, Edge::U0, B, Edge::U0);
    ASSERT_TRUE(r);
    SCOPED_TRACE(describe(*r));
    expectExactG2(*r, patchScale(A), ref.curvScale);
    EXPECT_FALSE(atLeastC1(r->parametric));
    EXPECT_LE(r->g2ResidualMax, kExactCurvatureRel * ref.secondScale);
    EXPECT_TRUE(sameInterval({std::min(lk.l0, lk.l1), std::max(lk.l0, lk.l1)}, r->lambdaRange,
                             kExactFunctionTol, "lambdaRange"));
  }
}

// =====================================================================================================================
// (iv) Kinks of known angle: planar patches on two planes through a common straight edge.
// =====================================================================================================================

struct KinkPair {
  BSplineSurface a, b;  // both with edge U0; edge parameter identical
};

/// A lies in the plane z = 0 on the side y <= 0 (control points (X_j, -Y_i, 0)); B is the half-plane y >= 0
/// turned about the x axis by theta (control points (X_j, Y'_i cos theta, Y'_i sin theta)), with the same
/// edge row. Seen from the edge, A_out = +y, A_t = +x, n_A = x X y = +z; B_cross ~ (0, cos, sin), n_B = (0,
/// -sin, cos): the oriented normals make exactly the angle theta (180 = B folded back onto A). `uniformEdge`
/// spaces the edge control points evenly, which makes the edge parametrisation linear (Bernstein linear
/// precision).
KinkPair planarKink(Rng& rng, double thetaDeg, int nA, int nB, int m, bool rational, bool uniformEdge,
                    const Eigen::Matrix3d& rot, const Vec3& shift) {
  const double th = radians(thetaDeg);
  std::vector<double> x(static_cast<size_t>(m + 1));
  double acc = 0.0;
  for (int j = 0; j <= m; ++j)
    x[static_cast<size_t>(j)] = (acc += uniformEdge ? 1.0 / m : urand(rng, 0.4, 1.6) / m);
  auto rowsY = [&](int n) {
    std::vector<double> y{0.0};
    for (int i = 1; i <= n; ++i) y.push_back(y.back() + urand(rng, 0.4, 1.6) / n);
    return y;
  };
  const std::vector<double> ya = rowsY(nA), yb = rowsY(nB);
  Matrix pa((nA + 1) * (m + 1), 3), pb((nB + 1) * (m + 1), 3);
  for (int i = 0; i <= nA; ++i)
    for (int j = 0; j <= m; ++j) pa.row(i * (m + 1) + j) << x[j], -ya[i], 0.0;
  for (int i = 0; i <= nB; ++i)
    for (int j = 0; j <= m; ++j) pb.row(i * (m + 1) + j) << x[j], yb[i] * std::cos(th), yb[i] * std::sin(th);
  VecX wa, wb;
  if (rational) {
    wa = randomWeights(rng, (nA + 1) * (m + 1));
    wb = randomWeights(rng, (nB + 1) * (m + 1));
    wb.head(m + 1) = wa.head(m + 1) * urand(rng, 0.5, 2.0);  // same edge curve, same parametrisation
  }
  const BSplineSurface a = BezierPatch(nA, m, pa, wa).toBSpline(), b = BezierPatch(nB, m, pb, wb).toBSpline();
  return {transformed(a, rot, shift), transformed(b, rot, shift)};
}

TEST(SeamKink, DihedralAngleIsMeasuredExactly) {
  Rng rng(3301);
  for (const double theta : {0.02, 0.5, 7.0, 30.0, 90.0, 135.0, 170.0}) {
    for (int variant = 0; variant < 3; ++variant) {
      SCOPED_TRACE("theta " + std::to_string(theta) + " variant " + std::to_string(variant));
      // (drawn last argument first: test_helpers.h, "Random draws and argument order")
      const double y = urand(rng, -3, 3), x = urand(rng, -3, 3);
      const Eigen::Matrix3d rot = randomRotation(rng);
      const int d3 = irand(rng, 1, 3), d2 = irand(rng, 1, 3), d1 = irand(rng, 1, 3);
      const KinkPair k = planarKink(rng, theta, d1, d2, d3, false, false, rot, Vec3(x, y, 0.5));
      // variant 1: B reversed along the edge; variant 2: A swapped (edge V0).
      const BSplineSurface a = variant == 2 ? k.a.swappedUV() : k.a;
      const Edge ea = variant == 2 ? Edge::V0 : Edge::U0;
      const BSplineSurface b = variant == 1 ? k.b.reversedV() : k.b;
      auto r = analyze(a, ea, b, Edge::U0);
      ASSERT_TRUE(r);
      SCOPED_TRACE(describe(*r));
      EXPECT_TRUE(near(theta, r->g1SampledDeg, kKnownAngleTolDeg, "g1SampledDeg"));
      EXPECT_TRUE(certifiedAngleBound(theta, r->g1MaxDeg, SeamOptions{}.boundRelGap));
      EXPECT_EQ(r->geometric, GeometricClass::kG0);  // every theta here is above the 0.01 degree default
      EXPECT_FALSE(r->g1Identity);
      EXPECT_TRUE(r->certified);
      EXPECT_LE(r->g0Max, kExactDistanceRel * patchScale(a));
      EXPECT_EQ(r->reversed, variant == 1);
      // Where: a point on A's edge at A's own parameter.
      EXPECT_TRUE(r->overlapA.contains(r->g1Worst.t));
      const Vec3 at = v3(a.boundaryCurve(ea).evaluate(r->g1Worst.t));
      EXPECT_LE((at - r->g1Worst.point).norm(), 1e-9 * patchScale(a))
          << "g1Worst.point is not A's edge at g1Worst.t";
    }
  }
}

// The certified bound honours a tighter requested gap. (The brief asked for g1MaxDeg == theta within 1e-6 degrees;
// the bound's cost grows like 1 / boundRelGap -- 0.03 s at 1e-3, 3 s at 1e-5 for one seam -- so 1e-6 degrees at
// 30 degrees (gap 3e-8) is out of reach of a unit test; the sampled value is checked to 1e-6 degrees instead.)
TEST(SeamKink, TighterBoundGapIsHonoured) {
  Rng rng(3304);
  constexpr double kTightGap = 1e-3;
  for (const double theta : {0.5, 30.0, 150.0}) {
    SCOPED_TRACE("theta " + std::to_string(theta));
    const KinkPair k = planarKink(rng, theta, 2, 3, 3, theta > 100.0, false, randomRotation(rng), Vec3::Zero());
    SeamOptions opt;
    opt.boundRelGap = kTightGap;
    auto r = analyze(k.a, Edge::U0, k.b, Edge::U0, opt);
    ASSERT_TRUE(r);
    SCOPED_TRACE(describe(*r));
    EXPECT_TRUE(near(theta, r->g1SampledDeg, kKnownAngleTolDeg, "g1SampledDeg"));
    EXPECT_TRUE(certifiedAngleBound(theta, r->g1MaxDeg, kTightGap));
  }
}

TEST(SeamKink, KeptSamplesLieOnTheOverlapAndShowTheAngle) {
  Rng rng(3303);
  const KinkPair k = planarKink(rng, 33.0, 2, 2, 3, false, false, randomRotation(rng), Vec3::Zero());
  SeamOptions opt;
  opt.keepSamples = true;
  auto r = analyze(k.a, Edge::U0, k.b, Edge::U0, opt);
  ASSERT_TRUE(r);
  SCOPED_TRACE(describe(*r));
  ASSERT_GE(r->samples.size(), static_cast<size_t>(opt.samplesPerSpan));
  for (const SeamSample& s : r->samples) {
    EXPECT_TRUE(r->overlapA.contains(s.t)) << s.t;
    EXPECT_TRUE(near(33.0, s.g1Deg, kKnownAngleTolDeg, "sample g1Deg"));
    EXPECT_LE(s.g0, kExactDistanceRel * patchScale(k.a));
  }
  auto r2 = analyze(k.a, Edge::U0, k.b, Edge::U0);  // default: no samples kept
  ASSERT_TRUE(r2);
  EXPECT_TRUE(r2->samples.empty());
}

TEST(SeamKink, AngleBelowTheToleranceCountsAsTangent) {
  Rng rng(3302);
  // 0.004 degrees is below the default 0.01 degree angle tolerance: G1 (both planes have zero curvature, so
  // the curvature jump is 0 as well and G2 is also acceptable).
  const KinkPair k = planarKink(rng, 0.004, 2, 3, 3, false, false, randomRotation(rng), Vec3::Zero());
  auto r = analyze(k.a, Edge::U0, k.b, Edge::U0);
  ASSERT_TRUE(r);
  SCOPED_TRACE(describe(*r));
  EXPECT_TRUE(near(0.004, r->g1SampledDeg, kKnownAngleTolDeg, "g1SampledDeg"));
  EXPECT_TRUE(certifiedAngleBound(0.004, r->g1MaxDeg, SeamOptions{}.boundRelGap));
  EXPECT_GE(static_cast<int>(r->geometric), static_cast<int>(GeometricClass::kG1));
}

// =====================================================================================================================
// (v) Gaps of known size.
// =====================================================================================================================

/// A Lemma 1 (lambda = 1, kappa = 0: C1, not G2) pair whose shared edge lies in the plane z = 0 of the local
/// frame. Translating B by d = h e_z moves B's edge perpendicular to that plane: |A(t) - B(s)|^2 = |A(t) -
/// A(s)|^2 + h^2, so the closest-point distance is exactly h both ways (at s = t), everywhere along the seam.
struct PlanarEdgePair {
  BSplineSurface a, b;
  Eigen::Matrix3d rot;
  Vec3 shift;
};
PlanarEdgePair planarEdgeLemma1Pair(Rng& rng) {
  const BSplineSurface s =
      randomGraphSurface(rng, 3, 3, 4, 4, false);  // only for a random rigid motion below
  Matrix net = graphNet(rng, 4, 4, 0.25);
  for (int j = 0; j < 4; ++j) net(j, 2) = 0.0;  // edge row (u = 0) in the plane z = 0
  const BezierPatch a0(3, 3, net);
  const Lemma1Pair pr =
      lemma1Pair(rng, a0, BernsteinPoly::constant(1.0), BernsteinPoly::constant(0.0), 3, false, false);
  const Eigen::Matrix3d rot = randomRotation(rng);
  const Vec3 shift = randomVec3(rng, -2, 2);
  return {transformed(pr.a.toBSpline(), rot, shift), transformed(pr.b.toBSpline(), rot, shift), rot, shift};
}

TEST(SeamGap, TranslationPerpendicularToAPlanarEdgeGivesTheGap) {
  Rng rng(3401);
  const SeamOptions opt;  // tol.distance = 1e-6
  for (const double h : {1e-3, 0.1, 0.4e-6}) {
    SCOPED_TRACE("h = " + std::to_string(h));
    const PlanarEdgePair pp = planarEdgeLemma1Pair(rng);
    const BSplineSurface b = translated(pp.b, pp.rot * Vec3(0, 0, h));
    const RefMeasures ref = denseReference(pp.a, Edge::U0, b, Edge::U0, refOpts(300, nullptr, true));
    ASSERT_TRUE(near(h, ref.g0, 1e-12, "reference gap (construction check)"));
    auto r = analyze(pp.a, Edge::U0, b, Edge::U0);
    ASSERT_TRUE(r);
    SCOPED_TRACE(describe(*r));
    EXPECT_TRUE(near(h, r->g0Max, h * kBoundRelGap, "g0Max"));
    EXPECT_GE(r->g0Max, h * (1.0 - 1e-9));
    EXPECT_TRUE(near(h, r->g0Sampled, h * 1e-6, "g0Sampled"));
    EXPECT_TRUE(sameInterval({0.0, 1.0}, r->overlapA, kGapOverlapTol, "overlapA"));
    EXPECT_TRUE(sameInterval({0.0, 1.0}, r->overlapB, kGapOverlapTol, "overlapB"));
    // A translation leaves the tangent planes parallel: the angle stays 0.
    EXPECT_LE(r->g1MaxDeg, kExactAngleDeg);
    if (h > opt.tol.distance) {
      EXPECT_EQ(r->geometric, GeometricClass::kNone);
    } else {
      ASSERT_GE(ref.g2Rel, kClearMargin * opt.tol.curvatureRel);
      EXPECT_EQ(r->geometric, GeometricClass::kG1);  // closed within tolerance, tangent, curvature jumps
    }
  }
}

TEST(SeamGap, KinkWithASubToleranceGapIsG0) {
  Rng rng(3402);
  const Eigen::Matrix3d rot = randomRotation(rng);
  const KinkPair k = planarKink(rng, 25.0, 2, 2, 3, false, false, rot, Vec3(1, 2, 3));
  // The edge is a straight line along the local x axis; moving B by d perpendicular to it (local (0, 0.3,
  // 0.4) h) puts every point of B's edge at distance |d| = h/2 from A's edge line and vice versa.
  const double h = 0.8e-6;
  const BSplineSurface b = translated(k.b, rot * Vec3(0.0, 0.3, 0.4) * (h / 0.5));
  auto r = analyze(k.a, Edge::U0, b, Edge::U0);
  ASSERT_TRUE(r);
  SCOPED_TRACE(describe(*r));
  EXPECT_TRUE(near(h, r->g0Max, h * kBoundRelGap, "g0Max"));
  EXPECT_TRUE(near(25.0, r->g1SampledDeg, kKnownAngleTolDeg, "g1SampledDeg"));
  EXPECT_TRUE(certifiedAngleBound(25.0, r->g1MaxDeg, SeamOptions{}.boundRelGap));
  EXPECT_EQ(r->geometric, GeometricClass::kG0);
}

// A translation with a component along a straight, uniformly parametrised edge (A(0,t) = P0 + t L e): the
// closest point of A(t) on B's edge is B(t - dx/L), at distance |d_perp| (the component of d perpendicular to
// the edge). So the edges overlap on A's [dx/L, 1] and B's [0, 1 - dx/L], and over that shared part the gap
// is |d_perp|, not |d|
// (|d| is only reached from A's end point to B's end point, which lie outside the overlap).
TEST(SeamGap, TranslationAlongTheEdgeShortensTheOverlapAndLeavesThePerpendicularGap) {
  Rng rng(3403);
  for (int trial = 0; trial < 3; ++trial) {
    SCOPED_TRACE("trial " + std::to_string(trial));
    const Eigen::Matrix3d rot = randomRotation(rng);
    const KinkPair k = planarKink(rng, 20.0, 2, 3, 3, trial == 2, true, rot, Vec3(0.5, -1, 2));
    // Edge control points are x_j = (j+1)/m for j = 0..m, so L = 1 along the local x axis.
    const double L = 1.0;
    const double dx = urand(rng, 0.1, 0.3), dy = urand(rng, -1e-3, 1e-3), dz = urand(rng, 1e-3, 2e-3);
    const double dPerp = std::hypot(dy, dz);
    const BSplineSurface b = translated(k.b, rot * Vec3(dx, dy, dz));
    // Overlap ends: A's parameter where the local x of A's edge is x0 + dx, and B's (untranslated) parameter
    // where it is x1 - dx. Found by bisection on the kernel's evaluation of the (monotone) edge; for the
    // polynomial pairs the edge is linear and this is exactly dx / L.
    const BSplineCurve edge = k.a.boundaryCurve(Edge::U0);
    const auto localX = [&](double t) {
      return (rot.transpose() * (v3(edge.evaluate(t)) - Vec3(0.5, -1, 2)))[0];
    };
    const auto solve = [&](double x) {
      double lo = 0.0, hi = 1.0;
      for (int it = 0; it < 200; ++it) (localX(0.5 * (lo + hi)) < x ? lo : hi) = 0.5 * (lo + hi);
      return 0.5 * (lo + hi);
    };
    const double tA = solve(localX(0.0) + dx), tB = solve(localX(1.0) - dx);
    if (trial < 2) {
      ASSERT_TRUE(near(dx / L, tA, 1e-12, "linear edge (construction check)"));
    }
    auto r = analyze(k.a, Edge::U0, b, Edge::U0);
    ASSERT_TRUE(r);
    SCOPED_TRACE(describe(*r));
    EXPECT_TRUE(sameInterval({tA, 1.0}, r->overlapA, kGapOverlapTol, "overlapA"));
    EXPECT_TRUE(sameInterval({0.0, tB}, r->overlapB, kGapOverlapTol, "overlapB"));
    EXPECT_TRUE(near(dPerp, r->g0Max, dPerp * kBoundRelGap, "g0Max"));
    EXPECT_GE(r->g0Max, dPerp * (1.0 - 1e-9));
    EXPECT_TRUE(near(20.0, r->g1SampledDeg, kKnownAngleTolDeg, "g1SampledDeg"));
    EXPECT_EQ(r->geometric, GeometricClass::kNone);
  }
}

// Issue 15 section 4: B's edge overhangs A's by o along the edge and lies h above it (o < sqrt(3) h, so that each
// edge's end point is matched to the other's end point rather than to its closest point). Over the common part the
// edges are h apart; between the matched corner points the distance is hypot(o, h), and that is the seam's gap.
// Planar bilinear patches: A(1, t) = (0, t, 0), B(0, s) = (0, (1 + o) s, h) (reversed: (0, (1 + o)(1 - s), h)).
TEST(SeamGap, AnOverhangingEndCountsInTheGap) {
  for (const bool reversedB : {false, true}) {
    SCOPED_TRACE(reversedB ? "B reversed" : "B same direction");
    const double h = 0.00108, o = 0.0017;
    const double corner = std::hypot(o, h);  // 0.002014..., the distance between the matched corner points
    const Patch a = test::planarPatch("A", Vec3(-1, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0));
    const Patch b = reversedB ? test::planarPatch("B", Vec3(0, 1 + o, h), Vec3(1, 0, 0), Vec3(0, -(1 + o), 0))
                              : test::planarPatch("B", Vec3(0, 0, h), Vec3(1, 0, 0), Vec3(0, 1 + o, 0));
    SeamOptions opt;
    opt.tol.distance = 0.0015;  // between the common-part gap h and the corner distance
    Result<SeamReport> r = analyzeSeam(a, Edge::U1, b, Edge::U0, opt);
    ASSERT_TRUE(r) << r.status().message();
    SCOPED_TRACE(describe(*r));
    EXPECT_EQ(r->reversed, reversedB);
    EXPECT_TRUE(near(corner, r->endMismatch, 1e-15, "endMismatch"));
    EXPECT_GE(r->g0Max, corner * (1.0 - 1e-12));
    EXPECT_LE(r->g0Max, corner * (1.0 + kBoundRelGap));
    EXPECT_TRUE(near(corner, r->g0Sampled, 1e-12, "g0Sampled"));
    EXPECT_TRUE(near(1.0, r->g0Worst.t, 1e-12, "the worst gap is at the overhanging end"));
    EXPECT_TRUE(std::any_of(r->notes.begin(), r->notes.end(),
                            [](const std::string& n) { return n.find("runs past") != std::string::npos; }));
    EXPECT_EQ(r->geometric, GeometricClass::kNone);  // h alone would pass the tolerance; the ends do not
  }
}

// The ends of a seam are matched both ways only: an edge that goes on well past its partner (here B is twice as
// long as A, a T- or L-junction) has an end that is nobody's partner, so no end mismatch is added and the gap is
// the gap over the common part.
TEST(SeamGap, AnEdgeGoingOnPastItsPartnerAddsNoEndMismatch) {
  const double h = 1e-4;
  const Patch a = test::planarPatch("A", Vec3(-1, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0));
  const Patch b = test::planarPatch("B", Vec3(0, 0, h), Vec3(1, 0, 0), Vec3(0, 2, 0));
  Result<SeamReport> r = analyzeSeam(a, Edge::U1, b, Edge::U0, SeamOptions{});
  ASSERT_TRUE(r) << r.status().message();
  SCOPED_TRACE(describe(*r));
  EXPECT_TRUE(sameInterval({0.0, 0.5}, r->overlapB, kGapOverlapTol, "overlapB"));
  EXPECT_TRUE(near(h, r->endMismatch, 1e-15, "endMismatch (the shared start only)"));
  EXPECT_TRUE(near(h, r->g0Max, h * kBoundRelGap, "g0Max"));
}

// Across a gap the affine correspondence pairs A(v) with B(v), not with B's point closest to A(v) (issue 35). Here
// the paired normals are parallel everywhere (N_A x N_B = 0 as a polynomial, the seam's own G1 identity) while the
// angle between closest points is not 0. A(u, v) = (v, -u, -beta u v) (bilinear): its edge u = 0 is the x axis and
// its normal there is (0, -beta v, 1). B(u, v) = (x(v), u, h + beta u v), x(v) = (1 + e) v - e v^2 (degree 2 in v):
// its edge is the line y = 0, z = h, and its normal there is parallel to (0, beta v, -1). B's point closest to
// A(v) = (v, 0, 0) is B(s) with x(s) = v, where the tangent planes are atan(beta v) - atan(beta s) apart (in the
// y-z plane), up to 0.540 deg; the gap along the pairing, sqrt(h^2 + (e v (1 - v))^2), is within 1 % of h, so the
// affine correspondence is kept as good as projection. Before the closest-point excess the seam was reported as a
// G1 identity with an angle of 1e-14 deg.
TEST(SeamGap, AcrossAGapTheAngleBoundCoversTheAngleBetweenClosestPoints) {
  const double h = 0.1, e = 0.02, beta = 20.0;
  Matrix pa(4, 3), pb(6, 3);
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j) pa.row(i * 2 + j) = Vec3(j, -i, -beta * i * j).transpose();
  const double xb[3] = {0.0, 0.5 * (1.0 + e), 1.0};
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 3; ++j) pb.row(i * 3 + j) = Vec3(xb[j], i, h + beta * i * (0.5 * j)).transpose();
  const BSplineSurface A(1, 1, KnotVector::bezier(1), KnotVector::bezier(1), 2, 2, pa);
  const BSplineSurface B(1, 2, KnotVector::bezier(1), KnotVector::bezier(2), 2, 3, pb);
  // The truth in closed form: s = x^-1(v), the angle atan(beta v) - atan(beta s), maximised on a dense grid (the
  // function is smooth with one maximum; 2e5 points put the grid's maximum within 1e-9 of it).
  double truthDeg = 0.0;
  constexpr int kTruthSamples = 200000;
  for (int k = 0; k <= kTruthSamples; ++k) {
    const double v = static_cast<double>(k) / kTruthSamples;
    const double s = ((1.0 + e) - std::sqrt((1.0 + e) * (1.0 + e) - 4.0 * e * v)) / (2.0 * e);
    truthDeg = std::max(truthDeg, std::abs(std::atan(beta * v) - std::atan(beta * s)) * 180.0 / std::numbers::pi);
  }
  ASSERT_GT(truthDeg, 0.5);  // construction check
  const RefMeasures ref = denseReference(A, Edge::U0, B, Edge::U0, refOpts(4000, nullptr, true));
  ASSERT_TRUE(near(truthDeg, ref.g1Deg, 1e-3 * truthDeg, "dense closest-point reference (construction check)"));
  ASSERT_TRUE(near(h, ref.g0, 1e-9, "reference gap (construction check)"));
  auto r = analyze(A, Edge::U0, B, Edge::U0);
  ASSERT_TRUE(r);
  SCOPED_TRACE(describe(*r));
  EXPECT_TRUE(r->certified);
  EXPECT_EQ(r->correspondence, Correspondence::kAffine);
  EXPECT_FALSE(r->g1Identity);  // an identity along the pairing, not between closest points
  EXPECT_LE(r->g1SampledDeg, kExactAngleDeg);  // the samples follow the pairing
  EXPECT_GE(r->g1MaxDeg, truthDeg);
  EXPECT_GT(r->g1ClosestExcessDeg, 0.0);
  // How close the bound comes: 0.588 deg against 0.540 (2026-12-02; 7.07 before the cells' neighbours were clipped
  // to the reach, see closest_excess.cpp).
  EXPECT_LE(r->g1MaxDeg, 1.25 * truthDeg);
  EXPECT_EQ(r->geometric, GeometricClass::kNone);  // the gap h is far above the distance tolerance
}

// =====================================================================================================================
// (vi) Fold-back: B lies back over A (lambda < 0), the oriented normals are opposite (180 degrees).
// =====================================================================================================================

TEST(SeamFold, PatchAgainstItselfIsAFoldWithNegativeLambda) {
  Rng rng(3501);
  for (int trial = 0; trial < 3; ++trial) {
    SCOPED_TRACE("trial " + std::to_string(trial));
    const BSplineSurface a = randomGraphSurface(rng, 3, 3, 5, 5, trial == 2);
    // B = A with its cross parameter scaled: B(u, v) = A(u / c, v), so B'_u = A'_u / c = -A_out / c:
    // lambda = -1/c, kappa = 0, n_B = A_t x (-A_out) = -n_A: 180 degrees. c = 1 is A itself.
    const double c = trial == 0 ? 1.0 : urand(rng, 0.3, 3.0);
    const BSplineSurface b = a.reparametrized({0.0, c}, a.domainV());
    auto r = analyze(a, Edge::U0, b, Edge::U0);
    ASSERT_TRUE(r);
    SCOPED_TRACE(describe(*r));
    EXPECT_TRUE(near(180.0, r->g1MaxDeg, kKnownAngleTolDeg, "g1MaxDeg"));
    EXPECT_TRUE(sameInterval({-1.0 / c, -1.0 / c}, r->lambdaRange, kExactFunctionTol, "lambdaRange"));
    EXPECT_TRUE(sameInterval({0.0, 0.0}, r->kappaRange, kExactFunctionTol, "kappaRange"));
    EXPECT_LT(r->lambdaRange.hi, 0.0);
    EXPECT_EQ(r->geometric, GeometricClass::kG0);
    EXPECT_LE(r->g0Max, kExactDistanceRel * patchScale(a));
  }
}

TEST(SeamFold, PlanarFoldAt180Degrees) {
  Rng rng(3502);
  const KinkPair k = planarKink(rng, 180.0, 2, 3, 2, false, false, randomRotation(rng), Vec3(0, 0, 1));
  auto r = analyze(k.a, Edge::U0, k.b, Edge::U0);
  ASSERT_TRUE(r);
  SCOPED_TRACE(describe(*r));
  EXPECT_TRUE(near(180.0, r->g1MaxDeg, kKnownAngleTolDeg, "g1MaxDeg"));
  EXPECT_LT(r->lambdaRange.hi, 0.0);
  EXPECT_EQ(r->geometric, GeometricClass::kG0);
}

// =====================================================================================================================
// (vii) Rational pairs.
// =====================================================================================================================

TEST(SeamRational, RationalSurfaceSplitAtAKnotIsG2AndC2) {
  Rng rng(3601);
  for (int trial = 0; trial < 3; ++trial) {
    SCOPED_TRACE("trial " + std::to_string(trial));
    const SplitPair sp = randomSplitU(rng, 3, true);
    checkSplitReproduces(sp, true);
    const RefMeasures ref = denseReference(sp.a, Edge::U1, sp.b, Edge::U0, refOpts(200, identityMap, false));
    auto r = analyze(sp.a, Edge::U1, sp.b, Edge::U0);
    ASSERT_TRUE(r);
    SCOPED_TRACE(describe(*r));
    expectExactG2(*r, patchScale(sp.s), ref.curvScale);
    EXPECT_EQ(r->parametric, ParametricClass::kC2);
    EXPECT_TRUE(sameInterval({1.0, 1.0}, r->lambdaRange, kExactFunctionTol, "lambdaRange"));
    EXPECT_TRUE(sameInterval({0.0, 0.0}, r->kappaRange, kExactFunctionTol, "kappaRange"));
  }
}

TEST(SeamRational, RationalKinkOfKnownAngle) {
  Rng rng(3602);
  for (const double theta : {3.0, 60.0, 120.0}) {
    SCOPED_TRACE("theta " + std::to_string(theta));
    const KinkPair k = planarKink(rng, theta, 2, 2, 3, true, false, randomRotation(rng), Vec3(1, 1, 1));
    auto r = analyze(k.a, Edge::U0, k.b, Edge::U0);
    ASSERT_TRUE(r);
    SCOPED_TRACE(describe(*r));
    EXPECT_TRUE(near(theta, r->g1SampledDeg, kKnownAngleTolDeg, "g1SampledDeg"));
    EXPECT_TRUE(certifiedAngleBound(theta, r->g1MaxDeg, SeamOptions{}.boundRelGap));
    EXPECT_EQ(r->geometric, GeometricClass::kG0);
    EXPECT_TRUE(r->certified);
  }
}

// Multiplying all of B's weights by a common factor changes no point of B: every verdict and value must be
// the same as for the unscaled pair (compared field by field), and the same as known by construction.
TEST(SeamRational, WeightsScaledByACommonFactorChangeNothing) {
  Rng rng(3603);
  const SplitPair sp = randomSplitU(rng, 3, true);
  const KinkPair kink = planarKink(rng, 40.0, 2, 3, 3, true, false, randomRotation(rng), Vec3::Zero());
  // A Lemma-1-like non-G2 rational pair: the split pair with B's second row moved (G1 kept: only row 2
  // changes).
  BSplineSurface bCurv = sp.b;
  {
    Matrix p = bCurv.points();
    for (int j = 0; j < bCurv.numV(); ++j) p.row(2 * bCurv.numV() + j) += Vec3(0.05, -0.08, 0.1).transpose();
    bCurv = BSplineSurface(bCurv.degreeU(), bCurv.degreeV(), bCurv.knotsU(), bCurv.knotsV(), bCurv.numU(),
                           bCurv.numV(), p, bCurv.weights());
  }
  struct Case {
    std::string name;
    BSplineSurface a, b;
    Edge ea, eb;
  };
  const std::vector<Case> cases = {{"split", sp.a, sp.b, Edge::U1, Edge::U0},
                                   {"kink", kink.a, kink.b, Edge::U0, Edge::U0},
                                   {"curvature jump", sp.a, bCurv, Edge::U1, Edge::U0}};
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    auto r0 = analyze(c.a, c.ea, c.b, c.eb);
    ASSERT_TRUE(r0);
    for (const double factor : {1e-3, 0.37, 5.0, 1e3}) {
      SCOPED_TRACE("factor " + std::to_string(factor));
      const BSplineSurface bs = weightsScaled(c.b, factor);
      for (int i = 0; i < 5; ++i) {  // construction check: the same points
        const double u = bs.domainU().lo + bs.domainU().length() * i / 4.0, v = bs.domainV().lo + 0.3;
        ASSERT_LE((bs.evaluate(u, v) - c.b.evaluate(u, v)).norm(), 1e-13 * patchScale(c.b));
      }
      auto r = analyze(c.a, c.ea, bs, c.eb);
      ASSERT_TRUE(r);
      SCOPED_TRACE(describe(*r));
      EXPECT_EQ(r->geometric, r0->geometric);
      EXPECT_EQ(r->parametric, r0->parametric);
      EXPECT_EQ(r->certified, r0->certified);
      EXPECT_EQ(r->g1Identity, r0->g1Identity);
      EXPECT_EQ(r->g2Identity, r0->g2Identity);
      EXPECT_EQ(r->reversed, r0->reversed);
      EXPECT_EQ(r->correspondence, r0->correspondence);
      // Values: equal up to the round-off of the analysis (bounds of the same polynomials, rescaled).
      const double s = patchScale(c.a);
      EXPECT_TRUE(near(r0->g0Max, r->g0Max, kExactDistanceRel * s, "g0Max"));
      EXPECT_TRUE(near(r0->g1MaxDeg, r->g1MaxDeg, kExactAngleDeg + 1e-9 * r0->g1MaxDeg, "g1MaxDeg"));
      EXPECT_TRUE(near(r0->g2Max, r->g2Max, 1e-6 * std::max(1.0, r0->g2Max), "g2Max"));
      EXPECT_TRUE(near(r0->g2RelMax, r->g2RelMax, 1e-6, "g2RelMax"));
      EXPECT_TRUE(sameInterval(r0->lambdaRange, r->lambdaRange, kExactFunctionTol, "lambdaRange"));
      EXPECT_TRUE(sameInterval(r0->kappaRange, r->kappaRange, kExactFunctionTol, "kappaRange"));
      EXPECT_TRUE(sameInterval(r0->overlapA, r->overlapA, kOverlapTol, "overlapA"));
      EXPECT_TRUE(sameInterval(r0->overlapB, r->overlapB, kOverlapTol, "overlapB"));
    }
  }
  // And the verdicts known by construction.
  auto rs = analyze(sp.a, Edge::U1, weightsScaled(sp.b, 7.0), Edge::U0);
  ASSERT_TRUE(rs);
  EXPECT_EQ(rs->geometric, GeometricClass::kG2);
  EXPECT_EQ(rs->parametric, ParametricClass::kC2);
  auto rk = analyze(kink.a, Edge::U0, weightsScaled(kink.b, 7.0), Edge::U0);
  ASSERT_TRUE(rk);
  EXPECT_TRUE(near(40.0, rk->g1SampledDeg, kKnownAngleTolDeg, "kink g1SampledDeg"));
  auto rc = analyze(sp.a, Edge::U1, weightsScaled(bCurv, 7.0), Edge::U0);
  ASSERT_TRUE(rc);
  EXPECT_EQ(rc->geometric, GeometricClass::kG1);
  EXPECT_TRUE(rc->g1Identity);
}

// =====================================================================================================================
// (viii) T-junctions: one long edge against two short ones.
// =====================================================================================================================

TEST(SeamTJunction, EachShortEdgeGetsItsOverlapAndClass) {
  Rng rng(3701);
  for (int trial = 0; trial < 3; ++trial) {
    SCOPED_TRACE("trial " + std::to_string(trial));
    const SplitPair sp = randomSplitU(rng, 3, trial == 2);
    // Split B along the edge at a value that is NOT a knot of A (inside one of A's spans).
    const Interval dv = sp.b.domainV();
    const double kv = dv.lo + dv.length() * urand(rng, 0.3, 0.7);
    const auto [b1, b2] = splitV(sp.b, kv);
    const std::vector<std::pair<BSplineSurface, Interval>> shorts = {{b1, {dv.lo, kv}}, {b2, {kv, dv.hi}}};
    const double scale = patchScale(sp.s);
    for (size_t i = 0; i < shorts.size(); ++i) {
      const auto& [bi, part] = shorts[i];
      SCOPED_TRACE("short edge " + std::to_string(i));
      const RefMeasures ref =
          denseReference(sp.a, Edge::U1, bi, Edge::U0, refOpts(100, identityMap, false, part));
      // Found by overlap detection, and with A's range given explicitly.
      for (int how = 0; how < 2; ++how) {
        SCOPED_TRACE(how == 0 ? "overlap detection" : "aRange overload");
        auto r = how == 0 ? analyze(sp.a, Edge::U1, bi, Edge::U0)
                          : analyze(sp.a, Edge::U1, bi, Edge::U0, SeamOptions{}, part);
        ASSERT_TRUE(r);
        SCOPED_TRACE(describe(*r));
        EXPECT_TRUE(sameInterval(part, r->overlapA, kOverlapTol, "overlapA"));
        EXPECT_TRUE(sameInterval(part, r->overlapB, kOverlapTol, "overlapB"));  // knot values were kept
        expectExactG2(*r, scale, ref.curvScale);
        EXPECT_EQ(r->parametric, ParametricClass::kC2);
        EXPECT_FALSE(r->reversed);
      }
      // The short edge against the long one: B's overlap is the part.
      auto rr = analyze(bi, Edge::U0, sp.a, Edge::U1);
      ASSERT_TRUE(rr);
      SCOPED_TRACE(describe(*rr));
      EXPECT_TRUE(sameInterval(part, rr->overlapA, kOverlapTol, "reverse overlapA"));
      EXPECT_TRUE(sameInterval(part, rr->overlapB, kOverlapTol, "reverse overlapB"));
      EXPECT_EQ(rr->geometric, GeometricClass::kG2);
    }
  }
}

TEST(SeamTJunction, KinkedTJunctionWithAReparametrisedShortEdge) {
  Rng rng(3702);
  const KinkPair k = planarKink(rng, 12.0, 2, 2, 3, false, false, randomRotation(rng), Vec3(0, 1, 0));
  const double kv = 0.4;
  const auto [b1, b2] = splitV(k.b, kv);
  // b2 reparametrised along its edge to [10, 13] and reversed: overlap on B is all of [10, 13].
  const BSplineSurface b2r = b2.reparametrized(b2.domainU(), {10.0, 13.0}).reversedV();
  auto r1 = analyze(k.a, Edge::U0, b1, Edge::U0);
  ASSERT_TRUE(r1);
  SCOPED_TRACE(describe(*r1));
  EXPECT_TRUE(sameInterval({0.0, kv}, r1->overlapA, kOverlapTol, "overlapA 1"));
  EXPECT_TRUE(sameInterval({0.0, kv}, r1->overlapB, kOverlapTol, "overlapB 1"));
  EXPECT_TRUE(near(12.0, r1->g1SampledDeg, kKnownAngleTolDeg, "g1 1"));
  EXPECT_EQ(r1->geometric, GeometricClass::kG0);
  auto r2 = analyze(k.a, Edge::U0, b2r, Edge::U0);
  ASSERT_TRUE(r2);
  SCOPED_TRACE(describe(*r2));
  EXPECT_TRUE(sameInterval({kv, 1.0}, r2->overlapA, kOverlapTol, "overlapA 2"));
  EXPECT_TRUE(sameInterval({10.0, 13.0}, r2->overlapB, kOverlapTol, "overlapB 2"));
  EXPECT_TRUE(r2->reversed);
  EXPECT_TRUE(near(12.0, r2->g1SampledDeg, kKnownAngleTolDeg, "g1 2"));
  EXPECT_EQ(r2->geometric, GeometricClass::kG0);
}

// =====================================================================================================================
// (ix) Certified bounds against the test's own 10^4-point dense sampling, on random perturbed pairs.
// =====================================================================================================================

/// bound >= dense maximum (never below the sampling), and bound <= (1 + 1 %) of it when it is above `floor`.
::testing::AssertionResult boundMatchesDense(const char* what, double bound, double dense, double floor) {
  std::ostringstream os;
  os.precision(12);
  if (bound < dense * (1.0 - kDenseSlackRel) - floor) {
    os << what << ": certified bound " << bound << " is BELOW the dense sampled maximum " << dense;
    return ::testing::AssertionFailure() << os.str();
  }
  if (dense > floor && bound > dense * (1.0 + kBoundRelGap + kDenseSlackRel) + floor) {
    os << what << ": bound " << bound << " is not within 1 % of the dense maximum " << dense << " (ratio "
       << bound / dense << ")";
    return ::testing::AssertionFailure() << os.str();
  }
  if (dense <= floor && bound > 10.0 * floor) {
    os << what << ": dense maximum " << dense << " is round-off but the bound is " << bound;
    return ::testing::AssertionFailure() << os.str();
  }
  return ::testing::AssertionSuccess();
}

TEST(SeamBounds, CertifiedBoundsAgreeWithDenseSampling) {
  Rng rng(3801);
  constexpr int kNearG1Pairs = 16;  // exact G0, tiny or zero angle, curvature jump (g1 and g2 bounds)
  constexpr int kGapPairs = 8;      // planar edge moved perpendicular to its plane, random kink (g0 and g1 bounds)
  for (int pair = 0; pair < kNearG1Pairs + kGapPairs; ++pair) {
    const BoundsPair bp = makeBoundsPair(rng, pair < kNearG1Pairs, pair % 2 == 1, pair / 2);
    SCOPED_TRACE("pair " + std::to_string(pair) + ": " + bp.what);
    const BSplineSurface &A = bp.a, &B = bp.b;
    const Edge ea = bp.ea, eb = bp.eb;
    const RefOptions& ro = bp.ref;
    const RefMeasures ref = denseReference(A, ea, B, eb, ro);
    auto r = analyze(A, ea, B, eb);
    ASSERT_TRUE(r);
    SCOPED_TRACE(describe(*r));
    const double scale = patchScale(A);
    EXPECT_TRUE(boundMatchesDense("g0", r->g0Max, ref.g0, kFloorDistanceRel * scale));
    EXPECT_TRUE(boundMatchesDense("g1", r->g1MaxDeg, ref.g1Deg, kFloorAngleDeg));
    if (ro.g2) {
      EXPECT_TRUE(boundMatchesDense("g2", r->g2Max, ref.g2, kFloorCurvatureRel * ref.curvScale));
    }
    // The reported sampled values never exceed the bounds.
    EXPECT_LE(r->g0Sampled, r->g0Max * (1.0 + 1e-12) + kFloorDistanceRel * scale);
    EXPECT_LE(r->g1SampledDeg, r->g1MaxDeg * (1.0 + 1e-12) + kFloorAngleDeg);
    if (ro.g2) {
      EXPECT_LE(r->g2Sampled, r->g2Max * (1.0 + 1e-12) + kFloorCurvatureRel * ref.curvScale);
    }
    if (pair < kNearG1Pairs) {
      EXPECT_TRUE(r->certified);  // exact affine correspondence
      EXPECT_EQ(r->g1Identity, bp.exactG1);
    }
    // Where the worst angle occurs: the reference angle at the reported parameter is the reported sampled
    // value.
    RefOptions at = ro;
    at.samples = 2;
    at.aRange = {r->g1Worst.t, r->g1Worst.t};
    at.g0 = false;
    at.g2 = false;
    const RefMeasures there = denseReference(A, ea, B, eb, at);
    EXPECT_TRUE(
        near(r->g1SampledDeg, there.g1Deg, 1e-3 * r->g1SampledDeg + kFloorAngleDeg, "angle at g1Worst.t"));
  }
}

// =====================================================================================================================
// Seams that share their control rows (SeamOptions::sharedRows, issue 16): C^k splits take the row route, rows
// that differ by more than rounding do not, and every bound still covers the independent dense reference.
// =====================================================================================================================

namespace {

/// b with its control point (i, j) moved by d (i along u).
BSplineSurface withPointMoved(const BSplineSurface& b, int i, int j, const Vec3& d) {
  Matrix p = b.points();
  p.row(i * b.numV() + j) += d.transpose();
  return BSplineSurface(b.degreeU(), b.degreeV(), b.knotsU(), b.knotsV(), b.numU(), b.numV(), std::move(p),
                        b.weights());
}

/// The report's bounds cover the dense reference (closest-point correspondence, both-way gap).
void expectBoundsCoverReference(const SeamReport& r, const BSplineSurface& a, Edge ea, const BSplineSurface& b,
                                Edge eb) {
  const RefMeasures ref = denseReference(a, ea, b, eb, refOpts(400, nullptr, true));
  // Floors: the reference's own evaluation round-off (as in SeamBounds.CertifiedBoundsAgreeWithDenseSampling).
  EXPECT_GE(r.g0Max * (1.0 + 1e-9) + kFloorDistanceRel * patchScale(a), ref.g0) << "gap bound below the sampled gap";
  EXPECT_GE(r.g1MaxDeg * (1.0 + 1e-9) + kFloorAngleDeg, ref.g1Deg) << "angle bound below the sampled angle";
  EXPECT_GE(r.g0Max, r.g0Sampled);
  EXPECT_GE(r.g1MaxDeg, r.g1SampledDeg);
  EXPECT_GE(r.g2Max, r.g2Sampled);
}

}  // namespace

TEST(SeamSharedRows, KnotInsertionSplitsTakeTheRowRouteWithTheGeneralRoutesClasses) {
  Rng rng(3901);
  for (int trial = 0; trial < 6; ++trial) {
    SCOPED_TRACE("trial " + std::to_string(trial));
    const SplitPair sp = randomSplitU(rng, 3, false);
    // Every presentation: along-edge reversal mirrors the rows, exchanged roles swap A and B.
    const BSplineSurface bRev = sp.b.reversedV();
    struct Case {
      const BSplineSurface *a, *b;
      Edge ea, eb;
    };
    for (const Case& c : {Case{&sp.a, &sp.b, Edge::U1, Edge::U0}, Case{&sp.b, &sp.a, Edge::U0, Edge::U1},
                          Case{&sp.a, &bRev, Edge::U1, Edge::U0}}) {
      SeamOptions general;
      general.sharedRows = false;
      auto fast = analyze(*c.a, c.ea, *c.b, c.eb);
      auto full = analyze(*c.a, c.ea, *c.b, c.eb, general);
      ASSERT_TRUE(fast && full);
      SCOPED_TRACE(describe(*fast));
      EXPECT_TRUE(fast->sharedRows) << "a knot-insertion split did not take the shared-row route";
      EXPECT_FALSE(full->sharedRows);
      // Independent route: G2 with identities and C2, as the split of one C2 surface is by construction.
      EXPECT_EQ(fast->geometric, GeometricClass::kG2);
      EXPECT_EQ(fast->parametric, ParametricClass::kC2);
      EXPECT_TRUE(fast->certified && fast->g1Identity && fast->g2Identity);
      // The same classes and identities as the general route, bounds at round-off level.
      EXPECT_EQ(fast->geometric, full->geometric);
      EXPECT_EQ(fast->parametric, full->parametric);
      EXPECT_EQ(fast->g1Identity, full->g1Identity);
      EXPECT_EQ(fast->g2Identity, full->g2Identity);
      EXPECT_EQ(fast->reversed, full->reversed);
      EXPECT_LE(fast->g0Max, kExactDistanceRel * patchScale(sp.s));
      EXPECT_LE(fast->g1MaxDeg, kExactAngleDeg);
      EXPECT_LE(fast->g2RelMax, kExactCurvatureRel);
      expectBoundsCoverReference(*fast, *c.a, c.ea, *c.b, c.eb);
      // The angle and the curvature jump, zero in exact arithmetic, are not sampled on the row route (0, not their
      // round-off); the other sampled measures are, and agree with the general route's.
      EXPECT_EQ(fast->g1SampledDeg, 0.0);
      EXPECT_EQ(fast->g2Sampled, 0.0);
      EXPECT_EQ(fast->g2RelSampled, 0.0);
      EXPECT_TRUE(near(full->lambdaRange.lo, fast->lambdaRange.lo, 1e-9, "lambda lo"));
      EXPECT_TRUE(near(full->lambdaRange.hi, fast->lambdaRange.hi, 1e-9, "lambda hi"));
      EXPECT_LE(std::abs(fast->kappaRange.lo), 1e-9);
      EXPECT_LE(std::abs(fast->kappaRange.hi), 1e-9);
      // The plots' dense samples (keepSamples) still measure every quantity on both sides.
      SeamOptions plots;
      plots.keepSamples = true;
      auto dense = analyze(*c.a, c.ea, *c.b, c.eb, plots);
      ASSERT_TRUE(dense);
      EXPECT_TRUE(dense->sharedRows);
      EXPECT_EQ(dense->geometric, fast->geometric);
      EXPECT_FALSE(dense->samples.empty());
      EXPECT_LE(dense->g1SampledDeg, kExactAngleDeg);
    }
  }
}

TEST(SeamSharedRows, ACrossScaleLambdaIsStillTheRowRoute) {
  // B reparametrised across by an affine map of factor f: B_1 = A_out / f and B_2 = A_oo / f^2 exactly in the
  // geometry, lambda = 1 / f constant: G2 (identity), not C1.
  Rng rng(3902);
  const SplitPair sp = randomSplitU(rng, 3, false);
  const Interval du = sp.b.domainU();
  const double f = 2.5;
  const BSplineSurface b(sp.b.degreeU(), sp.b.degreeV(),
                         sp.b.knotsU().reparametrized(sp.b.degreeU(), du.lo, du.lo + f * du.length()), sp.b.knotsV(),
                         sp.b.numU(), sp.b.numV(), sp.b.points(), sp.b.weights());
  auto r = analyze(sp.a, Edge::U1, b, Edge::U0);
  ASSERT_TRUE(r);
  SCOPED_TRACE(describe(*r));
  EXPECT_TRUE(r->sharedRows);
  EXPECT_EQ(r->geometric, GeometricClass::kG2);
  EXPECT_TRUE(r->g1Identity && r->g2Identity);
  EXPECT_NE(r->parametric, ParametricClass::kC1);
  EXPECT_NE(r->parametric, ParametricClass::kC2);
  EXPECT_TRUE(near(1.0 / f, r->lambdaRange.lo, 1e-9, "lambda"));
  expectBoundsCoverReference(*r, sp.a, Edge::U1, b, Edge::U0);
}

TEST(SeamSharedRows, RowsEqualButForAPerturbationOf1e12TakeTheGeneralRoute) {
  // A perturbation of 1e-12 of the coordinates is far above rounding: the row route must not call these rows
  // shared, and the bounds (general route) must cover the sampled gap and angle.
  Rng rng(3903);
  for (int trial = 0; trial < 4; ++trial) {
    SCOPED_TRACE("trial " + std::to_string(trial));
    const SplitPair sp = randomSplitU(rng, 3, false);
    const double scale = patchScale(sp.s);
    const int j = irand(rng, 1, sp.b.numV() - 2);
    const double y = urand(rng, -1, 1), x = urand(rng, -1, 1);  // drawn last argument first (test_helpers.h)
    const Vec3 d = 1e-12 * scale * Vec3(x, y, 1.0).normalized();
    SeamOptions general;
    general.sharedRows = false;
    for (int row = 0; row < 3; ++row) {  // the boundary row, the first and the second cross row
      SCOPED_TRACE("row " + std::to_string(row));
      const BSplineSurface b = withPointMoved(sp.b, row, j, d);
      auto r = analyze(sp.a, Edge::U1, b, Edge::U0);
      auto full = analyze(sp.a, Edge::U1, b, Edge::U0, general);
      ASSERT_TRUE(r && full);
      SCOPED_TRACE(describe(*r));
      EXPECT_FALSE(r->sharedRows) << "rows 1e-12 apart were taken for shared rows";
      EXPECT_EQ(r->g0Max, full->g0Max);  // the general route, bit for bit
      EXPECT_EQ(r->g1MaxDeg, full->g1MaxDeg);
      EXPECT_EQ(r->geometric, full->geometric);
      expectBoundsCoverReference(*r, sp.a, Edge::U1, b, Edge::U0);
      if (row == 0) {
        // No floor: the moved point makes a gap of about 1e-12 x scale, which the bound must cover.
        const RefMeasures ref = denseReference(sp.a, Edge::U1, b, Edge::U0, refOpts(400, nullptr, true));
        EXPECT_GT(ref.g0, 0.1 * d.norm()) << "construction: the moved point makes no gap";
        EXPECT_GE(r->g0Max, ref.g0 * (1.0 - 1e-3)) << "gap bound below the sampled gap";
      }
    }
  }
}

TEST(SeamSharedRows, OnlyBitIdenticalBoundaryRowsHaveASampledGapOfExactlyZero) {
  // The row route skips evaluating B when B's boundary row is A's value for value (its points would be A's, bit for
  // bit). Boundary rows a few ulps apart are still shared rows (within the rounding allowance), but B must then be
  // evaluated: the sampled gap is the rounding-sized distance, not 0.
  Rng rng(3904);
  int exercised = 0;
  for (int trial = 0; trial < 8; ++trial) {
    SCOPED_TRACE("trial " + std::to_string(trial));
    const SplitPair sp = randomSplitU(rng, 3, false);
    auto same = analyze(sp.a, Edge::U1, sp.b, Edge::U0);
    ASSERT_TRUE(same);
    // Some random splits leave the row route for its normal bound (a cross row nearly along the edge): not this test.
    if (!same->sharedRows) continue;
    ++exercised;
    // Every interior boundary point of B moved by 4 ulps of the largest coordinate (along z): far below the shared-row
    // allowance of 16 (n + 1) ulps, far above nothing.
    double mag = 0.0;
    for (int j = 0; j < sp.b.numV(); ++j) mag = std::max(mag, sp.b.points().row(j).cwiseAbs().maxCoeff());
    const Vec3 d(0.0, 0.0, 4.0 * std::numeric_limits<double>::epsilon() * mag);
    BSplineSurface b = sp.b;
    for (int j = 1; j + 1 < sp.b.numV(); ++j) b = withPointMoved(b, 0, j, d);
    auto r = analyze(sp.a, Edge::U1, b, Edge::U0);
    ASSERT_TRUE(r);
    SCOPED_TRACE(describe(*r));
    EXPECT_TRUE(r->sharedRows) << "construction: rows 4 ulps apart should still be shared rows";
    EXPECT_GT(r->g0Sampled, 0.0) << "rows 4 ulps apart were taken for bit-identical rows (gap reported as 0)";
    EXPECT_LE(r->g0Sampled, 2.0 * d.norm());
    EXPECT_GE(r->g0Max, r->g0Sampled);
  }
  EXPECT_GE(exercised, 4) << "too few random splits took the shared-row route";
}

// =====================================================================================================================
// Errors.
// =====================================================================================================================

TEST(SeamErrors, EdgesThatDoNotOverlapAreNotFound) {
  Rng rng(3901);
  // The edge is the segment from local x = 1/3 to 4/3 (length 1). Moving B along it by 2 (also with a small
  // offset off the line) makes the collinear segments disjoint: every end point projects onto an END of the
  // other edge, so the overlap is empty.
  for (const Vec3& d : {Vec3(2.0, 0, 0), Vec3(-1.5, 0, 0), Vec3(2.0, 1e-3, -1e-3)}) {
    const Eigen::Matrix3d rot = randomRotation(rng);
    const KinkPair k = planarKink(rng, 30.0, 2, 2, 3, false, true, rot, Vec3::Zero());
    const BSplineSurface far = translated(k.b, rot * d);
    const Result<SeamReport> r = analyzeSeam(makePatch("A", k.a), Edge::U0, makePatch("B", far), Edge::U0);
    ASSERT_FALSE(r.isOk()) << describe(r.value());
    EXPECT_EQ(r.status().code(), ErrorCode::kNotFound) << r.status().message();
  }
}

TEST(SeamErrors, CollapsedEdgeIsDegenerate) {
  Rng rng(3902);
  Matrix na = graphNet(rng, 4, 4, 0.2);
  for (int j = 1; j < 4; ++j) na.row(j) = na.row(0);  // the edge u = 0 collapses to one point (a pole)
  const BSplineSurface a = BezierPatch(3, 3, na).toBSpline();
  Matrix nb = graphNet(rng, 4, 4, 0.2);
  for (int j = 0; j < 4; ++j) nb.row(j) = na.row(0);
  const BSplineSurface b = BezierPatch(3, 3, nb).toBSpline();
  for (int which = 0; which < 2; ++which) {
    const Result<SeamReport> r = which == 0
                                     ? analyzeSeam(makePatch("A", a), Edge::U0, makePatch("B", b), Edge::U0)
                                     : analyzeSeam(makePatch("B", b), Edge::U0, makePatch("A", a), Edge::U0);
    ASSERT_FALSE(r.isOk()) << describe(r.value());
    EXPECT_EQ(r.status().code(), ErrorCode::kDegenerate) << r.status().message();
  }
}

TEST(SeamErrors, NonSpatialPatchIsInvalidInput) {
  Matrix p2(4, 2);
  p2 << 0, 0, 0, 1, 1, 0, 1, 1;
  const BSplineSurface flat = BezierPatch(1, 1, p2).toBSpline();
  const Result<SeamReport> r = analyzeSeam(makePatch("A", flat), Edge::U0, makePatch("B", flat), Edge::U0);
  ASSERT_FALSE(r.isOk());
  EXPECT_EQ(r.status().code(), ErrorCode::kInvalidInput) << r.status().message();
}

// =====================================================================================================================
// The teapot: its exact seams (identical boundary control polygons) found here by comparing control points.
// =====================================================================================================================

struct SharedEdge {
  int a, b;
  Edge ea, eb;
  bool sameDirection;
  bool degenerate;  // the boundary row collapses to one point
};

Matrix boundaryRow(const BSplineSurface& s, Edge e) {
  const int nu = s.numU(), nv = s.numV();
  const bool uEdge = isUEdge(e);
  const int n = uEdge ? nv : nu;
  Matrix r(n, 3);
  for (int k = 0; k < n; ++k) {
    const int i = uEdge ? (e == Edge::U0 ? 0 : nu - 1) : k;
    const int j = uEdge ? k : (e == Edge::V0 ? 0 : nv - 1);
    r.row(k) = s.point(i, j);
  }
  return r;
}

std::vector<SharedEdge> exactSharedEdges(const Model& m) {
  std::vector<SharedEdge> out;
  const int n = static_cast<int>(m.patches.size());
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j)
      for (Edge ea : kAllEdges)
        for (Edge eb : kAllEdges) {
          const Matrix ra = boundaryRow(m.patches[static_cast<size_t>(i)].surface, ea);
          const Matrix rb = boundaryRow(m.patches[static_cast<size_t>(j)].surface, eb);
          if (ra.rows() != rb.rows()) continue;
          const bool same = ra == rb;
          const bool rev = ra == rb.colwise().reverse();
          if (!same && !rev) continue;
          bool degenerate = true;
          for (Eigen::Index k = 1; k < ra.rows(); ++k) degenerate = degenerate && ra.row(k) == ra.row(0);
          out.push_back({i, j, ea, eb, same, degenerate});
        }
  return out;
}

TEST(SeamTeapot, ExactSeamsAreTangentContinuous) {
  const Result<Model> model = io::readModel(std::string(SEAM_SHARED_DATA_DIR) + "/bezier/teapot.bpt");
  ASSERT_TRUE(model.isOk()) << model.status().message();
  ASSERT_EQ(model->patches.size(), 32U);
  const std::vector<SharedEdge> shared = exactSharedEdges(*model);
  const auto nondegenerate =
      std::count_if(shared.begin(), shared.end(), [](const auto& e) { return !e.degenerate; });
  // data/README.md: 52 boundary pairs with identical control polygons (plus the collapsed lid/bottom poles).
  EXPECT_EQ(nondegenerate, 52);
  // Patches 0 and 1 (rim) share a boundary: P0's v1 is P1's v0, in the same direction.
  EXPECT_TRUE(std::any_of(shared.begin(), shared.end(), [](const SharedEdge& e) {
    return e.a == 0 && e.b == 1 && e.ea == Edge::V1 && e.eb == Edge::V0 && e.sameDirection;
  }));
  SeamOptions opt;
  opt.tol = Tolerances::forModelSize(model->boundingBox().diagonal());
  const double scale = model->boundingBox().diagonal();
  int checked = 0;
  for (const SharedEdge& e : shared) {
    const Patch& pa = model->patches[static_cast<size_t>(e.a)];
    const Patch& pb = model->patches[static_cast<size_t>(e.b)];
    SCOPED_TRACE(pa.name + ":" + std::string(edgeName(e.ea)) + " - " + pb.name + ":" +
                 std::string(edgeName(e.eb)));
    const Result<SeamReport> rr = analyzeSeam(pa, e.ea, pb, e.eb, opt);
    if (e.degenerate) {  // a pole shared by several patches is a vertex, not a seam
      ASSERT_FALSE(rr.isOk());
      EXPECT_EQ(rr.status().code(), ErrorCode::kDegenerate) << rr.status().message();
      continue;
    }
    ASSERT_TRUE(rr.isOk()) << rr.status().message();
    const SeamReport& r = rr.value();
    SCOPED_TRACE(describe(r));
    ++checked;
    EXPECT_EQ(r.a, pa.name);
    EXPECT_EQ(r.b, pb.name);
    EXPECT_EQ(r.reversed, !e.sameDirection);
    EXPECT_TRUE(sameInterval({0.0, 1.0}, r.overlapA, kOverlapTol, "overlapA"));
    EXPECT_TRUE(sameInterval({0.0, 1.0}, r.overlapB, kOverlapTol, "overlapB"));
    EXPECT_LE(r.g0Max, kExactDistanceRel * scale);  // identical control polygons: identical curves
    // Independent reference: 2000 samples (the seam ends at a pole are excluded by the reference's own
    // normalisation only if the normal vanishes there; the README measured 0.000 degrees on 25 samples).
    RefOptions ro;
    ro.samples = 2000;
    ro.g0 = false;
    ro.phi = e.sameDirection ? std::function<double(double)>([](double t) { return t; })
                             : std::function<double(double)>([](double t) { return 1.0 - t; });
    const RefMeasures ref = denseReference(pa.surface, e.ea, pb.surface, e.eb, ro);
    ASSERT_LE(ref.g1Deg, opt.tol.angleDeg / kClearMargin) << "reference: teapot seam not tangent";
    EXPECT_GE(static_cast<int>(r.geometric), static_cast<int>(GeometricClass::kG1));
    EXPECT_GE(r.g1MaxDeg, ref.g1Deg * (1.0 - kDenseSlackRel) - kFloorAngleDeg);
    EXPECT_LE(r.g1MaxDeg, opt.tol.angleDeg);
    if (ref.g2Rel >= kClearMargin * opt.tol.curvatureRel) {
      EXPECT_EQ(r.geometric, GeometricClass::kG1);
    } else if (ref.g2Rel <= opt.tol.curvatureRel / kClearMargin) {
      EXPECT_EQ(r.geometric, GeometricClass::kG2);
    }
  }
  EXPECT_EQ(checked, 52);
}

// ---------------------------------------------------------------------------------------------------------------------
// Seams along parameter curves (trimmed B-rep edges): certifyPCurveSeam
// ---------------------------------------------------------------------------------------------------------------------

namespace pcurve {

/// The Greville abscissae of a knot vector: control points P_ij = (g_i, g'_j, 0) make the plane z = 0 with
/// S(u, v) = (u, v, 0) exactly (linear precision), whatever the degrees and knots.
std::vector<double> greville(const std::vector<double>& k, int p, int n) {
  std::vector<double> g(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) {
    double s = 0.0;
    for (int r = 1; r <= p; ++r) s += k[static_cast<size_t>(i + r)];
    g[static_cast<size_t>(i)] = s / p;
  }
  return g;
}

BSplineSurface identityPlane(seamtest::Rng& rng, int p, int n) {
  const std::vector<double> ku = seamtest::randomClampedKnots(rng, p, n), kv = seamtest::randomClampedKnots(rng, p, n);
  const auto gu = greville(ku, p, n), gv = greville(kv, p, n);
  Matrix pts(n * n, 3);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) pts.row(i * n + j) << gu[static_cast<size_t>(i)], gv[static_cast<size_t>(j)], 0.0;
  return BSplineSurface(p, p, KnotVector(ku), KnotVector(kv), n, n, std::move(pts));
}

BSplineCurve line2d(Vec2 a, Vec2 b) {
  Matrix pts(2, 2);
  pts.row(0) = a.transpose();
  pts.row(1) = b.transpose();
  return BSplineCurve::create(1, {0.0, 0.0, 1.0, 1.0}, std::move(pts)).value();
}

PCurveSide side(const BSplineSurface& s, BSplineCurve c, double sign = 1.0) {
  PCurveSide out;
  out.surface = &s;
  out.range = c.domain();
  out.pcurve = std::move(c);
  out.faceU = s.domainU();
  out.faceV = s.domainV();
  out.normalSign = sign;
  return out;
}

}  // namespace pcurve

TEST(PCurveSeam, CreaseAlongASlantedTrimmingLineHasItsExactAngle) {
  // A = the plane z = 0 as a bicubic B-spline with random interior knots; B = A rotated by theta about the 3-D
  // line over the slanted pcurve c(t) = (0.1 + 0.8 t, 0.2 + 0.6 t), which crosses knot lines of both directions.
  // Both faces meet along c with normals at exactly theta everywhere, and without a gap.
  seamtest::Rng rng(8101);
  for (double thetaDeg : {0.5, 30.0, 135.0}) {
    const BSplineSurface A = pcurve::identityPlane(rng, 3, 8);
    const Vec3 p0(0.1, 0.2, 0.0), dir = Vec3(0.8, 0.6, 0.0).normalized();
    const Eigen::Matrix3d R = Eigen::AngleAxisd(seamtest::radians(thetaDeg), dir).toRotationMatrix();
    const BSplineSurface B = seamtest::transformed(A, R, p0 - R * p0);
    const BSplineCurve c = pcurve::line2d({0.1, 0.2}, {0.9, 0.8});
    const Result<PCurveSeamBounds> r = certifyPCurveSeam(pcurve::side(A, c), pcurve::side(B, c));
    ASSERT_TRUE(r) << r.status().message();
    EXPECT_GT(r->pieces, 2);  // cut at the knot lines the pcurve crosses
    EXPECT_NEAR(r->g1SampledDeg, thetaDeg, 1e-9 * std::max(1.0, thetaDeg));
    EXPECT_GE(r->g1BoundDeg, thetaDeg - 1e-9);
    EXPECT_LE(r->g1BoundDeg, 1.01 * thetaDeg + 1e-6);
    EXPECT_LE(r->g0Bound, 1e-12);
    EXPECT_FALSE(r->g1Identity);
  }
}

TEST(PCurveSeam, GapOfKnownWidthAndTheSameSurfaceTwice) {
  // B = A translated by d along A's normal (A is the plane z = 0): the distance along any common pcurve is d.
  seamtest::Rng rng(8102);
  const BSplineSurface A = pcurve::identityPlane(rng, 2, 6);
  const double d = 3e-4;
  const BSplineSurface B = seamtest::translated(A, Vec3(0.0, 0.0, d));
  const BSplineCurve c = pcurve::line2d({0.05, 0.9}, {0.95, 0.15});
  const Result<PCurveSeamBounds> r = certifyPCurveSeam(pcurve::side(A, c), pcurve::side(B, c));
  ASSERT_TRUE(r) << r.status().message();
  EXPECT_NEAR(r->g0Sampled, d, 1e-12);
  EXPECT_GE(r->g0Bound, d - 1e-12);
  EXPECT_LE(r->g0Bound, 1.01 * d);
  EXPECT_TRUE(r->g1Identity);
}

TEST(PCurveSeam, CurvedPcurveOnACurvedSurfaceAndItsSwappedCopyIsAnIdentity) {
  // A curved NURBS graph surface F, and the same surface with u and v exchanged (its normal reversed, so the face
  // sense is -1); a cubic pcurve that wanders across knot lines, and its swapped image on the copy. The two faces
  // are the same surface: no gap, G1 as an identity, whatever the composition degree.
  seamtest::Rng rng(8103);
  for (bool rational : {false, true}) {
    const BSplineSurface F = seamtest::randomGraphSurface(rng, 3, 2, 7, 6, rational, 0.3);
    const BSplineSurface G = F.swappedUV();
    Matrix pa(5, 2), pb(5, 2);
    pa << 0.05, 0.1, 0.3, 0.8, 0.5, 0.2, 0.7, 0.9, 0.95, 0.4;
    for (int i = 0; i < 5; ++i) pb.row(i) << pa(i, 1), pa(i, 0);
    const std::vector<double> k{0, 0, 0, 0, 0.4, 1, 1, 1, 1};
    const BSplineCurve ca = BSplineCurve::create(3, k, pa).value(), cb = BSplineCurve::create(3, k, pb).value();
    const Result<PCurveSeamBounds> r = certifyPCurveSeam(pcurve::side(F, ca), pcurve::side(G, cb, -1.0));
    ASSERT_TRUE(r) << r.status().message();
    EXPECT_TRUE(r->g1Identity) << "rational " << rational << " bound " << r->g1BoundDeg;
    EXPECT_GE(r->pieces, 4);        // the pcurve's own knot and the knot lines it crosses
    EXPECT_GE(r->maxDegree, 96);    // |N_A|^2 |N_B|^2 of the composed normals: 4 x (9 + 6 + 9) for bi-degree (3, 2)
    EXPECT_LE(r->g1BoundDeg, 1e-6);
    EXPECT_LE(r->g0Bound, 1e-11);
    // Independent check of the composition: the two evaluations along the curve coincide pointwise.
    for (int i = 0; i <= 50; ++i) {
      const double t = i / 50.0;
      const VecX uv = ca.evaluate(t);
      const Vec3 x = F.evaluate(uv[0], uv[1]).head<3>(), y = G.evaluate(uv[1], uv[0]).head<3>();
      ASSERT_LE((x - y).norm(), 1e-12);
    }
  }
}

TEST(PCurveSeam, CurvatureJumpAcrossACurvedTrimmingCurveIsCertified) {
  // A = the plane z = 0 (bicubic, random knots); B = the graph z = k/2 (v - u^2)^2 over [0, 1]^2, a Bezier patch of
  // degree (4, 2) whose z coefficients are those of the monomials (the coefficient of u^m in degree n at index i is
  // C(i, m) / C(n, m)). B touches the plane along v = u^2, so the seam along the pcurve c(t) = (t, t^2) is G1
  // exactly, and B's shape operator there is the Hessian k grad(g) grad(g)^T of g = v - u^2: the jump is
  // k (1 + 4 t^2), largest (5 k) at t = 1.
  seamtest::Rng rng(8105);
  auto binom = [](int n, int m) { return m < 0 || m > n ? 0.0 : std::tgamma(n + 1.0) / (std::tgamma(m + 1.0) * std::tgamma(n - m + 1.0)); };
  for (double k : {0.25, 2.0}) {
    const BSplineSurface A = pcurve::identityPlane(rng, 3, 7);
    Matrix pts(15, 3);
    for (int i = 0; i <= 4; ++i)
      for (int j = 0; j <= 2; ++j) {
        const double z = 0.5 * k * ((j == 2 ? 1.0 : 0.0) - 2.0 * (j / 2.0) * binom(i, 2) / 6.0 + (i == 4 ? 1.0 : 0.0));
        pts.row(i * 3 + j) << i / 4.0, j / 2.0, z;
      }
    const BSplineSurface B(4, 2, KnotVector({0, 0, 0, 0, 0, 1, 1, 1, 1, 1}), KnotVector({0, 0, 0, 1, 1, 1}), 5, 3,
                           std::move(pts));
    // Independent check of the construction at a few points.
    for (double u : {0.2, 0.7})
      for (double v : {0.1, 0.9})
        ASSERT_NEAR(B.evaluate(u, v)[2], 0.5 * k * (v - u * u) * (v - u * u), 1e-14);
    Matrix cp(3, 2);
    cp << 0.0, 0.0, 0.5, 0.0, 1.0, 1.0;  // (t, t^2) as a quadratic Bezier curve
    const BSplineCurve c = BSplineCurve::create(2, {0, 0, 0, 1, 1, 1}, cp).value();
    const Result<PCurveSeamBounds> r = certifyPCurveSeam(pcurve::side(A, c), pcurve::side(B, c));
    ASSERT_TRUE(r) << r.status().message();
    EXPECT_TRUE(r->g1Identity) << r->g1BoundDeg;
    ASSERT_TRUE(r->g2Certified) << r->g2Why;
    EXPECT_FALSE(r->g2Identity);
    EXPECT_NEAR(r->g2Sampled, 5.0 * k, 1e-9 * k);
    EXPECT_NEAR(r->g2At, 1.0, 1e-9);
    EXPECT_GE(r->g2Bound, 5.0 * k * (1.0 - 1e-12));
    EXPECT_LE(r->g2Bound, 1.01 * 5.0 * k);
    EXPECT_NEAR(r->curvatureMax, 5.0 * k, 1e-9 * k);
    // The same seam seen from B (swapped sides): the jump is symmetric.
    const Result<PCurveSeamBounds> s = certifyPCurveSeam(pcurve::side(B, c), pcurve::side(A, c));
    ASSERT_TRUE(s && s->g2Certified);
    EXPECT_NEAR(s->g2Sampled, 5.0 * k, 1e-9 * k);
  }
}

TEST(PCurveSeam, OneSurfaceOnBothSidesOfASlantedCurveIsG2AsAnIdentity) {
  // The same curved surface on both sides of a slanted straight pcurve that crosses knot lines: no jump at all.
  seamtest::Rng rng(8106);
  for (bool rational : {false, true}) {
    const BSplineSurface F = seamtest::randomGraphSurface(rng, 3, 3, 6, 6, rational, 0.3);
    const BSplineCurve c = pcurve::line2d({0.05, 0.3}, {0.9, 0.75});
    const Result<PCurveSeamBounds> r = certifyPCurveSeam(pcurve::side(F, c), pcurve::side(F, c));
    ASSERT_TRUE(r) << r.status().message();
    EXPECT_TRUE(r->g1Identity);
    ASSERT_TRUE(r->g2Certified) << "rational " << rational << ": " << r->g2Why;
    EXPECT_TRUE(r->g2Identity) << r->g2Bound;
    EXPECT_LE(r->g2Bound, 1e-8 * r->curvatureMax);
    EXPECT_GT(r->curvatureMax, 0.0);
  }
}

TEST(PCurveSeam, ASliverSpanAndANearlyIsoparametricPcurveStayG2) {
  // A curved surface F and the same surface with a span 1e-7 long inserted at u = 0.45 (as CAD files get when a
  // face is cut just past a knot); the pcurve runs inside the sliver, nearly along v (u moves by 6e-8 while v moves
  // by 0.8). Both faces are one surface: the seam is G2 as an identity. With the chart direction taken as the
  // rotated pcurve derivative in the sliver's own coordinates, the two chart directions were nearly parallel in
  // 3-D and the curvature read ~0.5 where it is 0 (trj3 F2/F3).
  seamtest::Rng rng(8108);
  for (bool rational : {false, true}) {
    const BSplineSurface F = seamtest::randomGraphSurface(rng, 3, 3, 5, 5, rational, 0.3);
    const Interval du = F.domainU();
    const double k0 = du.lo + 0.45 * du.length(), h = 1e-7 * du.length();
    const BSplineSurface S = F.withKnotInsertedU(k0, 1).withKnotInsertedU(k0 + h, 1);
    const Interval dv = F.domainV();
    const BSplineCurve c = pcurve::line2d({k0 + 0.2 * h, dv.lo + 0.1 * dv.length()},
                                          {k0 + 0.8 * h, dv.lo + 0.9 * dv.length()});
    const Result<PCurveSeamBounds> r = certifyPCurveSeam(pcurve::side(F, c), pcurve::side(S, c));
    ASSERT_TRUE(r) << r.status().message();
    EXPECT_TRUE(r->g1Identity) << r->g1BoundDeg;
    ASSERT_TRUE(r->g2Certified) << r->g2Why;
    EXPECT_TRUE(r->g2Identity) << "rational " << rational << " bound " << r->g2Bound << " curvature "
                               << r->curvatureMax;
    EXPECT_LE(r->g2Bound, 1e-6 * r->curvatureMax);
  }
}

TEST(PCurveSeam, APcurveMayOvershootTheDomainWithinTheSlack) {
  // The same plane on both sides of a pcurve that starts 0.1 kPCurveDomainSlackRel before u = 0 (accepted: the end
  // span's polynomial is used there) and of one that starts 10 kPCurveDomainSlackRel before it (refused).
  seamtest::Rng rng(8109);
  const BSplineSurface A = pcurve::identityPlane(rng, 3, 6);
  const Interval du = A.domainU();
  const double inside = du.lo - 0.1 * kPCurveDomainSlackRel * du.length();
  const BSplineCurve ok = pcurve::line2d({inside, 0.2}, {0.7, 0.9});
  const Result<PCurveSeamBounds> r = certifyPCurveSeam(pcurve::side(A, ok), pcurve::side(A, ok));
  ASSERT_TRUE(r) << r.status().message();
  EXPECT_TRUE(r->g1Identity);
  EXPECT_LE(r->g0Bound, 1e-15);
  const double outside = du.lo - 10.0 * kPCurveDomainSlackRel * du.length();
  const BSplineCurve bad = pcurve::line2d({outside, 0.2}, {0.7, 0.9});
  const Result<PCurveSeamBounds> q = certifyPCurveSeam(pcurve::side(A, bad), pcurve::side(A, bad));
  ASSERT_FALSE(q);
  EXPECT_EQ(q.status().code(), ErrorCode::kUnsupported);
}

TEST(PCurveSeam, APcurveMayOvershootTheDomainByItsSidesSlack) {
  // A B-rep pcurve overshoots its bounded surface by up to its edge's tolerance (trj3_s1-al-214.stp: 4e-4 of the
  // domain). With PCurveSide::domainSlackRel = kBRepDomainRelTol the end span's polynomial continues the surface.
  // Independent route: the graph z = u^3 + v^2 over (x, y) = (u, v) is one polynomial, built here twice as bicubic
  // B-splines from its blossoms: A on [0, 1]^2 with interior knots, B on [-0.01, 1] x [0, 1]. A's pcurve starts
  // 5e-4 before u = 0, B's is the same line inside B's domain: the seam is exact only if A is continued by its
  // end span's polynomial (clamped, the gap would be about 5e-4).
  auto graph = [](std::vector<double> ku, std::vector<double> kv) {
    const int p = 3, nu = static_cast<int>(ku.size()) - p - 1, nv = static_cast<int>(kv.size()) - p - 1;
    Matrix pts(nu * nv, 3);
    for (int i = 0; i < nu; ++i)
      for (int j = 0; j < nv; ++j) {
        const double* a = &ku[static_cast<size_t>(i) + 1];
        const double* b = &kv[static_cast<size_t>(j) + 1];
        const double u = (a[0] + a[1] + a[2]) / 3.0, v = (b[0] + b[1] + b[2]) / 3.0;  // blossoms of u and v
        const double u3 = a[0] * a[1] * a[2], v2 = (b[0] * b[1] + b[0] * b[2] + b[1] * b[2]) / 3.0;
        pts.row(i * nv + j) << u, v, u3 + v2;
      }
    return BSplineSurface(p, p, KnotVector(ku), KnotVector(kv), nu, nv, std::move(pts));
  };
  const std::vector<double> kv{0, 0, 0, 0, 0.5, 1, 1, 1, 1};
  const BSplineSurface A = graph({0, 0, 0, 0, 0.3, 0.6, 1, 1, 1, 1}, kv);
  const BSplineSurface B = graph({-0.01, -0.01, -0.01, -0.01, 0.45, 1, 1, 1, 1}, kv);
  ASSERT_NEAR(A.evaluate(0.0, 0.5)[2], 0.25, 1e-15);  // the blossoms reproduce the polynomial
  ASSERT_NEAR(B.evaluate(-0.005, 0.5)[2], 0.25 - 1.25e-7, 1e-15);
  const BSplineCurve c = pcurve::line2d({-5e-4, 0.2}, {0.7, 0.9});
  PCurveSide a = pcurve::side(A, c);
  const PCurveSide b = pcurve::side(B, c);
  ASSERT_FALSE(certifyPCurveSeam(a, b));  // the default slack (kPCurveDomainSlackRel) refuses it
  a.domainSlackRel = kBRepDomainRelTol;
  const Result<PCurveSeamBounds> r = certifyPCurveSeam(a, b);
  ASSERT_TRUE(r) << r.status().message();
  EXPECT_LE(r->g0Bound, 1e-12);
  EXPECT_TRUE(r->g1Identity) << r->g1BoundDeg;
  a.domainSlackRel = 0.1 * kBRepDomainRelTol;  // short of the overshoot
  EXPECT_FALSE(certifyPCurveSeam(a, b));
  a.domainSlackRel = std::numeric_limits<double>::quiet_NaN();
  const Result<PCurveSeamBounds> bad = certifyPCurveSeam(a, b);
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.status().code(), ErrorCode::kInvalidInput);
}

TEST(PCurveSeam, RationalPcurvesAreComposedHomogeneously) {
  // The parabola (t, t^2) reparametrised by the Moebius map t = l s / ((1 - s) + l s): the same control points
  // with weights (1, l, l^2). On the plane / parabolic-graph pair of CurvatureJumpAcrossACurvedTrimmingCurve the
  // jump along it is k (1 + 4 t^2), 5 k at s = t = 1; on a plane and its copy rotated by theta about the line over
  // a rational pcurve the crease is theta; and on a rational surface and its u/v-swapped copy it is an identity.
  seamtest::Rng rng(8110);
  auto binom = [](int n, int m) { return m < 0 || m > n ? 0.0 : std::tgamma(n + 1.0) / (std::tgamma(m + 1.0) * std::tgamma(n - m + 1.0)); };
  const double k = 1.5;
  const BSplineSurface A = pcurve::identityPlane(rng, 1, 4);  // bilinear: keeps the homogenised degrees small
  Matrix pts(15, 3);
  for (int i = 0; i <= 4; ++i)
    for (int j = 0; j <= 2; ++j)
      pts.row(i * 3 + j) << i / 4.0, j / 2.0,
          0.5 * k * ((j == 2 ? 1.0 : 0.0) - 2.0 * (j / 2.0) * binom(i, 2) / 6.0 + (i == 4 ? 1.0 : 0.0));
  const BSplineSurface B(4, 2, KnotVector({0, 0, 0, 0, 0, 1, 1, 1, 1, 1}), KnotVector({0, 0, 0, 1, 1, 1}), 5, 3,
                         std::move(pts));
  for (double l : {0.5, 3.0}) {
    Matrix cp(3, 2);
    cp << 0.0, 0.0, 0.5, 0.0, 1.0, 1.0;
    VecX w(3);
    w << 1.0, l, l * l;
    const BSplineCurve c = BSplineCurve::create(2, {0, 0, 0, 1, 1, 1}, cp, w).value();
    // Independent check of the reparametrisation: c(s) = (t, t^2) with t = l s / ((1 - s) + l s).
    for (double sv : {0.3, 0.8}) {
      const double t = l * sv / ((1.0 - sv) + l * sv);
      ASSERT_LE((c.evaluate(sv) - Vec2(t, t * t)).norm(), 1e-14);
    }
    const Result<PCurveSeamBounds> r = certifyPCurveSeam(pcurve::side(A, c), pcurve::side(B, c));
    ASSERT_TRUE(r) << r.status().message();
    EXPECT_TRUE(r->g1Identity) << r->g1BoundDeg;
    EXPECT_LE(r->g0Bound, 1e-11);  // W^(p+q) with weights up to 9 costs digits
    ASSERT_TRUE(r->g2Certified) << r->g2Why;
    EXPECT_NEAR(r->g2Sampled, 5.0 * k, 1e-9 * k);
    EXPECT_NEAR(r->g2At, 1.0, 1e-9);
    EXPECT_LE(r->g2Bound, 1.01 * 5.0 * k);
    // A crease of 40 degrees along a rational pcurve that is a straight segment (weights (1, l) on a line).
    Matrix lp(2, 2);
    lp << 0.1, 0.2, 0.9, 0.8;
    VecX lw(2);
    lw << 1.0, l;
    const BSplineCurve line = BSplineCurve::create(1, {0, 0, 1, 1}, lp, lw).value();
    const Vec3 p0(0.1, 0.2, 0.0), dir = Vec3(0.8, 0.6, 0.0).normalized();
    const Eigen::Matrix3d R = Eigen::AngleAxisd(seamtest::radians(40.0), dir).toRotationMatrix();
    const BSplineSurface Rot = seamtest::transformed(A, R, p0 - R * p0);
    const Result<PCurveSeamBounds> q = certifyPCurveSeam(pcurve::side(A, line), pcurve::side(Rot, line));
    ASSERT_TRUE(q) << q.status().message();
    EXPECT_NEAR(q->g1SampledDeg, 40.0, 1e-9 * 40.0);
    EXPECT_LE(q->g1BoundDeg, 1.01 * 40.0);
    EXPECT_LE(q->g0Bound, 1e-12);
  }
  // Rational surface, rational pcurve crossing knot lines, and the swapped copy: G1 and G2 identities.
  const BSplineSurface F = seamtest::randomGraphSurface(rng, 3, 2, 6, 5, true, 0.3);
  const BSplineSurface G = F.swappedUV();
  Matrix pa(3, 2), pb(3, 2);
  pa << 0.1, 0.15, 0.6, 0.95, 0.9, 0.3;
  for (int i = 0; i < 3; ++i) pb.row(i) << pa(i, 1), pa(i, 0);
  VecX w(3);
  w << 1.0, 0.6, 1.4;
  const BSplineCurve ca = BSplineCurve::create(2, {0, 0, 0, 1, 1, 1}, pa, w).value(),
                     cb = BSplineCurve::create(2, {0, 0, 0, 1, 1, 1}, pb, w).value();
  const Result<PCurveSeamBounds> r = certifyPCurveSeam(pcurve::side(F, ca), pcurve::side(G, cb, -1.0));
  ASSERT_TRUE(r) << r.status().message();
  EXPECT_GE(r->pieces, 3);
  EXPECT_TRUE(r->g1Identity) << r->g1BoundDeg;
  EXPECT_LE(r->g0Bound, 1e-11);
  if (r->g2Certified) EXPECT_TRUE(r->g2Identity) << r->g2Bound;
  else EXPECT_FALSE(r->g2Why.empty());
}

namespace pcurve {

/// B's pcurve lagging along the u axis: the quadratic (0, 0), (c1, 0), (1, 0) with middle weight w (1: polynomial),
/// x = u(t) = (w b1 c1 + t^2) / ((1 - t)^2 + w b1 + t^2), b1 = 2 t (1 - t): lagU, from the Bernstein form.
BSplineCurve lagging(double c1, double w) {
  Matrix cp(3, 2);
  cp << 0.0, 0.0, c1, 0.0, 1.0, 0.0;
  VecX weights(3);
  weights << 1.0, w, 1.0;
  return BSplineCurve::create(2, {0, 0, 0, 1, 1, 1}, cp, w != 1.0 ? weights : VecX()).value();
}
double lagU(double t, double c1, double w) {
  const double b1 = 2.0 * t * (1.0 - t);
  return (w * b1 * c1 + t * t) / ((1.0 - t) * (1.0 - t) + w * b1 + t * t);
}

/// B a cylinder of radius s below the quarter circle s (cos phi, sin phi, 0), A the cone above it through the circle
/// s (1 + a) (cos phi, sin phi, 1) at height s h (rational quadratic in u, linear in v); u runs along the circle.
std::pair<BSplineSurface, BSplineSurface> coneOnCylinder(double s, double a, double h) {
  const double r2 = std::sqrt(0.5);
  Matrix pa(6, 3), pb(6, 3);
  const double arc[3][2] = {{1, 0}, {1, 1}, {0, 1}};
  for (int i = 0; i < 3; ++i) {
    pa.row(2 * i) << s * arc[i][0], s * arc[i][1], 0.0;
    pa.row(2 * i + 1) << s * (1 + a) * arc[i][0], s * (1 + a) * arc[i][1], s * h;
    pb.row(2 * i) << s * arc[i][0], s * arc[i][1], 0.0;
    pb.row(2 * i + 1) << s * arc[i][0], s * arc[i][1], -s;
  }
  VecX w(6);
  w << 1.0, 1.0, r2, r2, 1.0, 1.0;
  return {BSplineSurface(2, 1, KnotVector({0, 0, 0, 1, 1, 1}), KnotVector({0, 0, 1, 1}), 3, 2, std::move(pa), w),
          BSplineSurface(2, 1, KnotVector({0, 0, 0, 1, 1, 1}), KnotVector({0, 0, 1, 1}), 3, 2, std::move(pb), w)};
}

/// Independent: the largest angle between the quarter circle's points at lagU(t) and t, densely (the rational
/// quarter circle's angle phi(u) = atan2(y, x) from its Bernstein form).
double quarterCircleLag(double c1, double w) {
  const double r2 = std::sqrt(0.5);
  const auto phi = [&](double u) {
    const double b0 = (1 - u) * (1 - u), b1 = 2 * u * (1 - u), b2 = u * u;
    return std::atan2(r2 * b1 + b2, b0 + r2 * b1);
  };
  double dphi = 0.0;
  for (int i = 0; i <= 20000; ++i) {
    const double t = i / 20000.0;
    dphi = std::max(dphi, phi(lagU(t, c1, w)) - phi(t));
  }
  return dphi;
}

}  // namespace pcurve

TEST(PCurveSeam, TheClosestPointExcessCoversAPairingThatLags) {
  // A = s (u, v, k u v) and B = s (u, -v, k v (1 - u)) (bilinear) meet along the segment s (x, 0, 0), their normals
  // tilted about it by atan(k x) and atan(k (1 - x)) to either side: between closest points (the same x) the angle
  // is atan(k x) + atan(k (1 - x)), largest at x = 1/2: 2 atan(k / 2). A's pcurve is (t, 0); B's lags, x = u(t)
  // with u(t) - t up to 0.03 (a quadratic t + eps t (1 - t), or a rational quadratic with middle weight 1.1), so
  // at equal t the route pairs A(t) with a point of B's edge up to s 0.03 away, where B's normal has turned: the
  // angle at the paired points stays about 1 deg below the closest points'. The excess
  // (SeamOptions::closestPointsOn) must cover the difference, and stay within twice k max |u(t) - t| (the turning
  // rate of B's normal times the largest distance between paired and closest points), at sizes 1e-3, 1, 1e4; the
  // same seam with its sides exchanged has the same excess on its first side (kOnA).
  const double k = 1.0, eps = 0.1, c1 = 0.5 + 0.5 * eps, deg = 180.0 / std::numbers::pi;
  const double truth = 2.0 * std::atan(0.5 * k) * deg;
  for (const double s : {1e-3, 1.0, 1e4})
    for (const bool rational : {false, true}) {
      SCOPED_TRACE(::testing::Message() << "size " << s << " rational " << rational);
      Matrix pa(4, 3), pb(4, 3);
      pa << 0, 0, 0, 0, s, 0, s, 0, 0, s, s, k * s;
      pb << 0, 0, 0, 0, -s, k * s, s, 0, 0, s, -s, 0;
      const BSplineSurface A(1, 1, KnotVector({0, 0, 1, 1}), KnotVector({0, 0, 1, 1}), 2, 2, std::move(pa));
      const BSplineSurface B(1, 1, KnotVector({0, 0, 1, 1}), KnotVector({0, 0, 1, 1}), 2, 2, std::move(pb));
      const double w = rational ? 1.1 : 1.0;
      const BSplineCurve cb = pcurve::lagging(c1, w);
      // Independent: the largest |u(t) - t| of the (rational) quadratic, densely.
      double lag = 0.0;
      for (int i = 0; i <= 20000; ++i) {
        const double t = i / 20000.0, u = pcurve::lagU(t, c1, w);
        ASSERT_GE(u - t, -1e-15);  // a lag everywhere
        lag = std::max(lag, u - t);
      }
      SeamOptions opt;
      opt.boundRelGap = 1e-4;  // the bound within 1e-4 of the paired points' largest angle
      const Result<PCurveSeamBounds> plain =
          certifyPCurveSeam(pcurve::side(A, pcurve::line2d({0, 0}, {1, 0})), pcurve::side(B, cb, -1.0), opt);
      ASSERT_TRUE(plain) << plain.status().message();
      EXPECT_EQ(plain->g1ClosestExcessDeg, 0.0);  // not asked for
      opt.closestPointsOn = ClosestPoints::kOnB;
      const Result<PCurveSeamBounds> r =
          certifyPCurveSeam(pcurve::side(A, pcurve::line2d({0, 0}, {1, 0})), pcurve::side(B, cb, -1.0), opt);
      ASSERT_TRUE(r) << r.status().message();
      // One segment, no gap between the edges: the route's distance is the paired points', s max |u(t) - t|.
      EXPECT_GE(r->g0Bound, s * lag * (1.0 - 1e-9));
      EXPECT_LE(r->g0Bound, 1.011 * s * lag);
      EXPECT_LT(r->g1BoundDeg, truth - 0.5);  // the paired points alone miss the closest points' angle
      EXPECT_GE(r->g1BoundDeg + r->g1ClosestExcessDeg, truth);
      EXPECT_LE(r->g1ClosestExcessDeg, 2.0 * k * lag * deg);
      opt.closestPointsOn = ClosestPoints::kOnA;
      const Result<PCurveSeamBounds> swapped =
          certifyPCurveSeam(pcurve::side(B, cb, -1.0), pcurve::side(A, pcurve::line2d({0, 0}, {1, 0})), opt);
      ASSERT_TRUE(swapped) << swapped.status().message();
      EXPECT_NEAR(swapped->g1ClosestExcessDeg, r->g1ClosestExcessDeg, 1e-9 * r->g1ClosestExcessDeg);
    }
}

TEST(PCurveSeam, TheClosestPointExcessAlongALineOfCurvatureIsSecondOrderInTheLag) {
  // B a cylinder of radius s below the quarter circle s (cos phi, sin phi, 0), A the cone above it through the circle
  // s (1 + a) (cos phi, sin phi, 1) at height s h (rational quadratic in u, linear in v): their normals make the
  // angle theta = atan(a / h) all along the circle, a line of curvature of both (the normals turn along it, not
  // across). B's pcurve lags as in the test above, so the route pairs A's normal at phi with B's at phi + dphi,
  // dphi up to 0.008 or 0.021 rad: B's normal has turned by dphi there, but the angle at the paired points only grows
  // to acos(cos theta cos dphi). Between closest points (the same phi) the angle is theta. The certified angle must
  // cover theta, and the closest-point excess stay below a fifth of dphi (the whole turning of B's normal between
  // paired and closest points, which is what the excess was before the along / across split) and be of second order
  // in dphi, at sizes 1e-3, 1, 1e4 (dphi 0.0083 with the polynomial pcurve, 0.0207 with the rational one).
  const double a = 0.364, h = 1.0, eps = 0.02, c1 = 0.5 + 0.5 * eps, deg = 180.0 / std::numbers::pi;
  const double theta = std::atan(a / h) * deg;
  for (const double s : {1e-3, 1.0, 1e4})
    for (const bool rational : {false, true}) {
      SCOPED_TRACE(::testing::Message() << "size " << s << " rational pcurve " << rational);
      const auto [A, B] = pcurve::coneOnCylinder(s, a, h);
      const double pw = rational ? 1.1 : 1.0;
      const BSplineCurve cb = pcurve::lagging(c1, pw);
      const double dphi = pcurve::quarterCircleLag(c1, pw);
      ASSERT_GT(dphi, 0.005);
      SeamOptions opt;
      opt.boundRelGap = 1e-4;
      opt.closestPointsOn = ClosestPoints::kOnB;
      const Result<PCurveSeamBounds> r =
          certifyPCurveSeam(pcurve::side(A, pcurve::line2d({0, 0}, {1, 0})), pcurve::side(B, cb, -1.0), opt);
      ASSERT_TRUE(r) << r.status().message();
      EXPECT_NEAR(r->g1SampledDeg, std::acos(std::cos(theta / deg) * std::cos(dphi)) * deg, 1e-3 * theta);
      EXPECT_GE(r->g1BoundDeg + r->g1ClosestExcessDeg, theta);
      // Second order: B's normal turns by dphi between paired and closest points while A's leans along B's edge by
      // at most about 2 dphi, so the chord of the angle grows from that of theta by about 2 dphi^2 / theta; a
      // factor 3 leaves room for the coefficient bounds (the whole turning, the bound before, is dphi).
      EXPECT_LE(r->g1ClosestExcessDeg, 3.0 * dphi * dphi / (theta / deg) * deg);
      EXPECT_LE(r->g1ClosestExcessDeg, 0.2 * dphi * deg);
    }
}

TEST(PCurveSeam, TheClosestPointExcessIsBoundedNextToSliverPieces) {
  // The cone on the cylinder of the test above (angle theta along a quarter circle of radius s, B's pcurve lagging
  // by up to dphi), with a sliver of 1e-9 of the edge cut into it: two knots 1e-9 apart inserted into A's pcurve (a
  // leaf that short, B's pcurve whole across it) or into B's (a piece of B's pcurve that short). Knot insertion
  // leaves both edges as they were, so the angle between closest points is theta still and the edge's curvature
  // 1 / s. On the sliver the second derivative of B's composed polynomial is round-off over (1e-9)^2, a curvature
  // of about 1e3 / s, which next to the pairing's distance of 0.008 s made the excess unbounded: it must stay bounded,
  // cover theta, and stay within a fifth of dphi as without the sliver, at sizes 1e-3, 1, 1e4, polynomial and rational
  // pcurves.
  const double a = 0.364, h = 1.0, eps = 0.02, c1 = 0.5 + 0.5 * eps, deg = 180.0 / std::numbers::pi;
  const double theta = std::atan(a / h) * deg, at = 0.41, sliver = 1e-9;
  for (const double s : {1e-3, 1.0, 1e4})
    for (const bool rational : {false, true})
      for (const bool inA : {true, false}) {
        SCOPED_TRACE(::testing::Message() << "size " << s << " rational pcurve " << rational << " sliver in "
                                          << (inA ? "A" : "B"));
        const auto [A, B] = pcurve::coneOnCylinder(s, a, h);
        const double pw = rational ? 1.1 : 1.0;
        BSplineCurve ca = pcurve::line2d({0, 0}, {1, 0}), cb = pcurve::lagging(c1, pw);
        BSplineCurve& cut = inA ? ca : cb;
        cut = cut.withKnotInserted(at).withKnotInserted(at + sliver);
        const double dphi = pcurve::quarterCircleLag(c1, pw);
        ASSERT_GT(dphi, 0.005);
        SeamOptions opt;
        opt.boundRelGap = 1e-4;
        opt.closestPointsOn = ClosestPoints::kOnB;
        const Result<PCurveSeamBounds> r = certifyPCurveSeam(pcurve::side(A, ca), pcurve::side(B, cb, -1.0), opt);
        ASSERT_TRUE(r) << r.status().message();
        ASSERT_TRUE(std::isfinite(r->g1ClosestExcessDeg));
        EXPECT_GE(r->g1BoundDeg + r->g1ClosestExcessDeg, theta);
        EXPECT_LE(r->g1ClosestExcessDeg, 0.2 * dphi * deg);
      }
}

TEST(PCurveSeam, CreaseHasNoCertifiedG2) {
  seamtest::Rng rng(8107);
  const BSplineSurface A = pcurve::identityPlane(rng, 2, 5);
  const Vec3 dir = Vec3(1.0, 1.0, 0.0).normalized();
  const BSplineSurface B = seamtest::transformed(A, Eigen::AngleAxisd(0.3, dir).toRotationMatrix(), Vec3::Zero());
  const BSplineCurve c = pcurve::line2d({0.0, 0.0}, {1.0, 1.0});
  const Result<PCurveSeamBounds> r = certifyPCurveSeam(pcurve::side(A, c), pcurve::side(B, c));
  ASSERT_TRUE(r) << r.status().message();
  EXPECT_FALSE(r->g1Identity);
  EXPECT_FALSE(r->g2Certified);
  EXPECT_FALSE(r->g2Why.empty());
}

TEST(PCurveSeam, UnsupportedAndInvalidInputAreErrors) {
  seamtest::Rng rng(8104);
  const BSplineSurface A = pcurve::identityPlane(rng, 3, 5);
  // A pcurve that leaves the surface's domain.
  const BSplineCurve out = pcurve::line2d({0.5, 0.5}, {1.5, 0.5});
  const Result<PCurveSeamBounds> r1 = certifyPCurveSeam(pcurve::side(A, out), pcurve::side(A, out));
  ASSERT_FALSE(r1);
  EXPECT_EQ(r1.status().code(), ErrorCode::kUnsupported);
  // A rational pcurve that leaves the domain.
  Matrix pts(3, 2);
  pts << 0.1, 0.1, 0.5, 1.9, 0.9, 0.1;
  VecX w(3);
  w << 1.0, 2.0, 1.0;
  const BSplineCurve rat = BSplineCurve::create(2, {0, 0, 0, 1, 1, 1}, pts, w).value();
  const Result<PCurveSeamBounds> r2 = certifyPCurveSeam(pcurve::side(A, rat), pcurve::side(A, rat));
  ASSERT_FALSE(r2);
  EXPECT_EQ(r2.status().code(), ErrorCode::kUnsupported);
  // No surface.
  PCurveSide none = pcurve::side(A, pcurve::line2d({0.1, 0.1}, {0.2, 0.2}));
  none.surface = nullptr;
  const Result<PCurveSeamBounds> r3 = certifyPCurveSeam(none, none);
  ASSERT_FALSE(r3);
  EXPECT_EQ(r3.status().code(), ErrorCode::kInvalidInput);
}

TEST(SeamPieces, PartnerThroughPiecesInvertsEachPiecesMonotoneMap) {
  // detail::partnerThroughPieces (B's parameter at A's t on a certified seam, instead of a projection): pieces whose
  // t(x) are monotone cubics, increasing and decreasing. Expected values by construction: pick x, form t = t(x) and
  // s = s(x) from the explicit Bernstein basis (not de Casteljau), and ask for s back from t alone.
  auto cubic = [](double c0, double c1, double c2, double c3) {
    Matrix c(4, 1);
    c << c0, c1, c2, c3;
    return BernsteinPoly(c);
  };
  auto basis = [](const BernsteinPoly& p, double x) {
    const Matrix& c = p.coeffs();
    const double y = 1.0 - x;
    return c(0, 0) * y * y * y + 3.0 * c(1, 0) * x * y * y + 3.0 * c(2, 0) * x * x * y + c(3, 0) * x * x * x;
  };
  std::vector<detail::Piece> pieces(2);
  pieces[0].tOf = cubic(0.0, 0.05, 0.35, 0.4);  // t in [0, 0.4], increasing, steep in the middle
  pieces[0].sOf = cubic(2.0, 1.9, 1.7, 1.6);
  pieces[1].tOf = cubic(1.0, 0.9, 0.45, 0.4);  // t in [0.4, 1], decreasing in x (B is the master here)
  pieces[1].sOf = cubic(1.0, 1.2, 1.4, 1.6);
  Rng rng(3702);
  for (int k = 0; k < 200; ++k) {
    const size_t i = static_cast<size_t>(k % 2);
    const double x = urand(rng, 0.0, 1.0);
    const double t = basis(pieces[i].tOf, x);
    const std::optional<double> s = detail::partnerThroughPieces(pieces, t);
    ASSERT_TRUE(s) << "t = " << t;
    // |ds/dt| <= 6 on these pieces; x is recovered to about 1e-16 (bisection), far inside the tolerance.
    EXPECT_NEAR(*s, basis(pieces[i].sOf, x), 1e-13) << "piece " << i << ", x = " << x;
  }
  EXPECT_FALSE(detail::partnerThroughPieces(pieces, -0.01));
  EXPECT_FALSE(detail::partnerThroughPieces(pieces, 1.01));
  EXPECT_EQ(*detail::partnerThroughPieces(pieces, 0.0), 2.0);
}

TEST(SeamPieces, TheSampledAngleIsTheNormalsAngleUpToDegree1000) {
  // detail::g1ValueIfDefined on pieces whose P, Q, R reach degree 500-960 (the pcurve route on real B-reps: the
  // B-rep check certifies up to kBRepMaxCertifiedDegree), with normals of size 1e-4 and 1e6, where Q's and R's
  // Horner sums would overflow unscaled. Expected: the angle between the two normals evaluated by an explicit
  // Bernstein sum whose basis values come from lgamma and logarithms (neither Horner nor de Casteljau).
  auto basisSum = [](const BernsteinPoly& p, double x) {
    const int n = p.degree();
    Vec3 v = Vec3::Zero();
    for (int i = 0; i <= n; ++i) {
      const double lb = std::lgamma(n + 1.0) - std::lgamma(i + 1.0) - std::lgamma(n - i + 1.0) +
                        i * std::log(x) + (n - i) * std::log1p(-x);
      v += std::exp(lb) * p.coeffs().row(i).transpose().head<3>();
    }
    return v;
  };
  std::mt19937_64 rng(1000);
  std::uniform_real_distribution<double> U(-0.3, 0.3);
  const std::pair<int, int> degrees[] = {{250, 230}, {400, 80}, {240, 240}};
  for (auto [na, nb] : degrees)
    for (double scale : {1e-4, 1e6}) {
      auto normal = [&](int n) {
        Matrix c(n + 1, 3);
        for (int i = 0; i <= n; ++i) c.row(i) << U(rng), U(rng), 1.0 + U(rng);
        return BernsteinPoly(c * scale);
      };
      const BernsteinPoly NA = normal(na), NB = normal(nb);
      detail::Piece pc;
      pc.P = dot(NA, NB);
      pc.cross = cross(NA, NB);
      pc.Q = dot(pc.cross, pc.cross);
      pc.R = product(dot(NA, NA), dot(NB, NB));
      ASSERT_GT(pc.R.degree(), 512);
      for (int k = 1; k < 20; ++k) {
        const double x = k / 20.0 + 0.013;
        const Vec3 a = basisSum(NA, x), b = basisSum(NB, x);
        const std::optional<double> v = detail::g1ValueIfDefined(pc, x);
        ASSERT_TRUE(v) << "degrees " << na << ", " << nb << " scale " << scale << " x " << x;
        // The reference's lgamma-based weights are good to ~1e-12 relative; the angle is O(0.3) rad.
        EXPECT_NEAR(*v, std::atan2(a.cross(b).norm(), a.dot(b)), 1e-9)
            << "degrees " << na << ", " << nb << " scale " << scale << " x " << x;
      }
    }
}

TEST(SeamPieces, ACertifiedMaximumNextToTheToleranceIsDecided) {
  // detail::certifyMax with the verdict's tolerance as threshold: normals N_A = (0, 0, 1) and N_B = (a (x - x^3), 0, 1)
  // make the angle atan(a (x - x^3)), whose maximum atan(2 a / (3 sqrt 3)) lies at x = 1 / sqrt 3 (no midpoint of
  // the subdivision reaches it exactly). With the tolerance 1-4 % above the maximum, inside the 5 % the bounds close
  // at here (boundRelGap), the bound must come out at or below the tolerance (the seam is G1); as far below it, the
  // best value must pass the tolerance (a kink). Expected values from the closed form only.
  const double a = 0.3;
  const double maxAngle = std::atan(2.0 * a / (3.0 * std::sqrt(3.0)));
  VecX power(4);
  power << 0.0, 1.0, 0.0, -1.0;
  const BernsteinPoly px = BernsteinPoly::fromPowerBasis(power);
  Matrix nb = Matrix::Zero(4, 3), na = Matrix::Zero(4, 3);
  nb.col(0) = a * px.coeffs().col(0);
  nb.col(2).setOnes();
  na.col(2).setOnes();
  const BernsteinPoly NA(na), NB(nb);
  std::vector<detail::Piece> pieces(1);
  detail::Piece& pc = pieces[0];
  pc.P = dot(NA, NB);
  pc.cross = cross(NA, NB);
  pc.Q = dot(pc.cross, pc.cross);
  pc.R = product(dot(NA, NA), dot(NB, NB));
  SeamOptions opt;
  opt.boundRelGap = 0.05;
  int closedAbove = 0;
  for (double rel : {1.01, 1.02, 1.04}) {
    const double tolerance = maxAngle * rel;
    for (bool decide : {false, true}) {
      double best = 0.0, bx = 0.0;
      int bp = -1;
      bool ok = true;
      const double bound =
          detail::certifyMax(pieces, detail::g1Bound, detail::g1Value, best, bx, bp, 1e-15, opt, ok, nullptr,
                             nullptr, decide ? tolerance : std::numeric_limits<double>::infinity());
      ASSERT_TRUE(ok);
      EXPECT_GE(bound, maxAngle * (1.0 - 1e-12)) << rel;
      EXPECT_LE(best, maxAngle * (1.0 + 1e-12)) << rel;
      if (decide) EXPECT_LE(bound, tolerance) << "tolerance " << rel << " x the maximum";
      else closedAbove += bound > tolerance ? 1 : 0;
    }
    double best = 0.0, bx = 0.0;
    int bp = -1;
    bool ok = true;
    detail::certifyMax(pieces, detail::g1Bound, detail::g1Value, best, bx, bp, 1e-15, opt, ok, nullptr, nullptr,
                       maxAngle / rel);
    EXPECT_GT(best, maxAngle / rel) << "tolerance " << rel << " below the maximum: the samples must pass it";
  }
  // Without the threshold the slack leaves some bound above its tolerance: the case the threshold decides.
  EXPECT_GT(closedAbove, 0);
}

TEST(SampledMaxima, ParabolicRefinementFindsTheMaximaGoldenSectionFinds) {
  // detail::refineMaxParabolic (the sampled maxima's refinement) against exact maxima and against golden section
  // (detail::refineMax, the route it replaced): smooth peaks are found to round-off in far fewer evaluations; a kink
  // (no parabola fits) and a maximum at the end of the bracket are found to the bracket resolution; NaN values lose.
  std::mt19937_64 rng(4242);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  int total = 0, peaks = 0;
  for (int k = 0; k < 200; ++k) {
    const double lo = -1.0 + U(rng), hi = lo + 1e-3 + U(rng);
    const double c = lo + (0.05 + 0.9 * U(rng)) * (hi - lo);  // the peak, inside the bracket
    const double amp = std::pow(10.0, -12.0 + 14.0 * U(rng)), width = (0.2 + U(rng)) * (hi - lo);
    // A smooth, asymmetric peak: exp(-((x - c) / width)^2) (1 + 0.3 (x - c) / width)^2 has its maximum where
    // the derivative vanishes; solved here by bisection on the derivative's sign (an independent route).
    auto f = [&](double x) {
      const double y = (x - c) / width, g = 1.0 + 0.3 * y;
      return amp * std::exp(-y * y) * g * g;
    };
    auto df = [&](double x) {  // sign of f'(x) / (amp exp(-y^2) g / width): 0.6 - 2 y g
      const double y = (x - c) / width;
      return 0.6 - 2.0 * y * (1.0 + 0.3 * y);
    };
    double a = c - width, b = c + width;
    for (int i = 0; i < 200; ++i) (df(0.5 * (a + b)) > 0.0 ? a : b) = 0.5 * (a + b);
    const double xStar = 0.5 * (a + b);
    if (!(xStar > lo && xStar < hi)) continue;
    int evaluations = 0;
    const auto [x, v] = detail::refineMaxParabolic(
        [&](double t) {
          ++evaluations;
          return f(t);
        },
        lo, hi);
    const auto [xg, vg] = detail::refineMax(f, lo, hi);
    EXPECT_NEAR(x, xStar, 1e-6 * (hi - lo)) << k;
    EXPECT_NEAR(v, f(xStar), 1e-13 * amp) << k;
    EXPECT_NEAR(v, vg, 1e-13 * amp) << k;  // golden section's value
    EXPECT_LE(evaluations, 32) << k;  // golden section: 42
    total += evaluations;
    ++peaks;
    EXPECT_EQ(v, f(x)) << k;  // the value is f at the point returned
  }
  ASSERT_GT(peaks, 150);
  std::cout << "mean evaluations " << static_cast<double>(total) / peaks << "\n";
  EXPECT_LE(total, 22 * peaks);  // on average about half of golden section's 42
  // A kink: f = -|x - c|. No parabola is trusted near it; golden-section steps find it to the resolution.
  {
    const double c = 0.3141592653589793;
    const auto [x, v] = detail::refineMaxParabolic([&](double t) { return -std::abs(t - c); }, 0.0, 1.0);
    EXPECT_NEAR(x, c, 3.0 * detail::kRefineRelTol);
    EXPECT_LE(-v, 3.0 * detail::kRefineRelTol);
  }
  // Increasing on the bracket: the maximum is at its upper end.
  {
    const auto [x, v] = detail::refineMaxParabolic([](double t) { return t * t * t; }, 0.0, 2.0);
    EXPECT_NEAR(x, 2.0, 3.0 * 2.0 * detail::kRefineRelTol);
    EXPECT_NEAR(v, 8.0, 1e-6);
  }
  // NaN where the measure has no value (a pole): never chosen over a number.
  {
    const auto [x, v] = detail::refineMaxParabolic(
        [](double t) { return t > 0.5 ? std::numeric_limits<double>::quiet_NaN() : t; }, 0.0, 1.0);
    EXPECT_FALSE(std::isnan(v));
    EXPECT_LE(x, 0.5);
    EXPECT_NEAR(v, 0.5, 1e-6);
  }
}

// The seam samples' fused pass over a polynomial side (degrees 2 to 5, src/continuity/seam_side.cpp polynomialEdgeJet)
// against the generic route it replaces (three Bernstein jets, the route every other degree and every rational side
// takes): bit for bit, the sign of zeros included, on multi-span sides with simple, double and triple knots, at
// random parameters, at every breakpoint from both sides, and at the domain ends. Rational and degree-6 sides take
// the generic route either way (the same bits trivially).
TEST(SideJet, FusedPassGivesTheGenericBits) {
  Rng rng(16021);
  auto bits = [](double x) { return std::bit_cast<std::uint64_t>(x); };
  int compared = 0;
  for (int p = 1; p <= 6; ++p) {
    for (const bool rational : {false, true}) {
      for (int variant = 0; variant < 3; ++variant) {
        // variant 0: simple random knots; 1: a double knot along v; 2: a triple knot along v.
        const int nu = p + 3, nvSimple = p + 4;
        std::vector<double> kv = randomClampedKnots(rng, p, nvSimple);
        if (variant > 0) {
          const double k = kv[static_cast<size_t>(p + 1)];
          for (int extra = 0; extra < variant && extra + 1 < p; ++extra) kv.insert(kv.begin() + p + 1, k);
        }
        const int nv = static_cast<int>(kv.size()) - p - 1;
        Matrix pts = graphNet(rng, nu, nv, 0.25);
        pts(0, 2) = -0.0;  // a negative zero coordinate (its sign must survive both routes alike)
        VecX w = rational ? randomWeights(rng, nu * nv) : VecX();  // drawn last argument first (test_helpers.h)
        const BSplineSurface s(p, p, KnotVector(randomClampedKnots(rng, p, nu)), KnotVector(kv), nu, nv,
                               std::move(pts), std::move(w));
        const Patch patch = makePatch("S", s);
        for (const Edge e : {Edge::U0, Edge::U1, Edge::V0, Edge::V1}) {
          const KnotVector& along = isUEdge(e) ? s.knotsV() : s.knotsU();
          std::vector<double> ts = along.breakpoints();
          for (int i = 0; i < 12; ++i) ts.push_back(urand(rng, 0.0, 1.0));
          for (const double t : ts)
            for (const bool fromRight : {false, true}) {
              const std::array<Vec3, 6> fused = detail::sideJet(patch, e, t, fromRight, true);
              const std::array<Vec3, 6> generic = detail::sideJet(patch, e, t, fromRight, false);
              for (size_t d = 0; d < 6; ++d)
                for (int c = 0; c < 3; ++c) {
                  SCOPED_TRACE("degree " + std::to_string(p) + (rational ? " rational" : "") + ", variant " +
                               std::to_string(variant) + ", edge " + std::string(edgeName(e)) + ", t " +
                               std::to_string(t) + ", derivative " + std::to_string(d));
                  ASSERT_EQ(bits(fused[d][c]), bits(generic[d][c]));
                }
              ++compared;
            }
        }
      }
    }
  }
  EXPECT_GT(compared, 1000);
}


// The seam analysis writes each side's cross-derivative rows into storage reused from seam to seam
// (src/continuity/seam_side.cpp crossDerivativeRowsInto): bit for bit BSplineSurface::crossDerivativeRows(e, 2), the
// surface's own function, on polynomial and rational surfaces of degrees 1 to 5 (clamped and unclamped knots across
// the edge, a negative zero coordinate), with one storage matrix reused through sizes that grow and shrink.
TEST(SideRows, ReusedStorageGivesTheSurfaceRows) {
  Rng rng(16022);
  auto bits = [](double x) { return std::bit_cast<std::uint64_t>(x); };
  Matrix storage(2, 5);
  storage.setConstant(7.0);  // stale values from "a previous seam"
  int compared = 0;
  for (int round = 0; round < 3; ++round)
    for (int pu = 1; pu <= 5; ++pu)
      for (int pv = 1; pv <= 5; pv += 2)
        for (const bool rational : {false, true})
          for (const bool clamped : {true, false}) {
            const int nu = pu + 1 + irand(rng, 0, 3), nv = pv + 1 + irand(rng, 0, 3);
            std::vector<double> ku = randomClampedKnots(rng, pu, nu), kv = randomClampedKnots(rng, pv, nv);
            if (!clamped) {  // end knots spread out: the boundary is not a control row
              for (int i = 0; i < pu; ++i) ku[static_cast<size_t>(i)] = -0.1 * (pu - i);
              for (int i = 0; i < pv; ++i) kv[kv.size() - 1 - static_cast<size_t>(i)] = 1.0 + 0.1 * (pv - i);
            }
            Matrix pts = graphNet(rng, nu, nv, 0.25);
            pts(0, 0) = -0.0;
            const BSplineSurface s(pu, pv, KnotVector(ku), KnotVector(kv), nu, nv, std::move(pts),
                                   rational ? randomWeights(rng, nu * nv) : VecX());
            for (const Edge e : {Edge::U0, Edge::U1, Edge::V0, Edge::V1}) {
              SCOPED_TRACE("degrees " + std::to_string(pu) + " " + std::to_string(pv) + (rational ? " rational" : "") +
                           (clamped ? "" : " unclamped") + ", edge " + std::string(edgeName(e)));
              const Matrix expected = s.crossDerivativeRows(e, 2);
              detail::sideCrossRows(s, e, storage);
              ASSERT_EQ(storage.rows(), expected.rows());
              ASSERT_EQ(storage.cols(), expected.cols());
              for (Eigen::Index i = 0; i < expected.rows(); ++i)
                for (Eigen::Index j = 0; j < expected.cols(); ++j) ASSERT_EQ(bits(storage(i, j)), bits(expected(i, j)));
              ++compared;
            }
          }
  EXPECT_EQ(compared, 3 * 5 * 3 * 2 * 2 * 4);
}


// =====================================================================================================================
// Poles at an end of the seam (issue 35 §2): graph surfaces z = f(x, y) over two triangles that meet along y = 0,
// 0 <= x <= 1, parametrised so that the row u = 0 collapses to the origin, A: (x, y) = (u, u v), B: (x, y) =
// (u, u (v - 1)). The normal of the parametrisation vanishes at the seam's end x = 0; the surfaces' own normals
// (-f_x, -f_y, 1) and shape operators (Hess f / W in the graph chart) are the independent route.
// =====================================================================================================================

/// c x^a y^b terms of f.
struct GraphTerm {
  int a, b;
  double c;
};

/// The Bezier patch of degree (d, d) of the graph of f over the triangle (x, y) = (u, u (v + shift)) (shift 0 for A,
/// -1 for B): exact control points from the power basis (Bernstein coefficients C(k, i) / C(n, i)).
BSplineSurface poleTriangle(const std::vector<GraphTerm>& f, double shift, int d) {
  // Power-basis coefficients p[i][j] of u^i v^j for x, y and z.
  using Poly = std::vector<std::vector<double>>;
  auto zero = [d] { return Poly(static_cast<size_t>(d + 1), std::vector<double>(static_cast<size_t>(d + 1), 0.0)); };
  Poly px = zero(), py = zero(), pz = zero();
  px[1][0] = 1.0;
  py[1][1] = 1.0;
  py[1][0] = shift;
  for (const GraphTerm& t : f)  // x^a y^b = u^(a + b) (v + shift)^b
    for (int j = 0; j <= t.b; ++j)
      pz[static_cast<size_t>(t.a + t.b)][static_cast<size_t>(j)] +=
          t.c * binomial(t.b, j) * std::pow(shift, t.b - j);
  Matrix net(static_cast<Eigen::Index>((d + 1) * (d + 1)), 3);
  for (int k = 0; k <= d; ++k)
    for (int l = 0; l <= d; ++l) {
      Vec3 q = Vec3::Zero();
      for (int i = 0; i <= k; ++i)
        for (int j = 0; j <= l; ++j) {
          const double w = binomial(k, i) / binomial(d, i) * binomial(l, j) / binomial(d, j);
          const auto ui = static_cast<size_t>(i), vj = static_cast<size_t>(j);
          q += w * Vec3(px[ui][vj], py[ui][vj], pz[ui][vj]);
        }
      net.row(k * (d + 1) + l) = q.transpose();
    }
  return BezierPatch(d, d, net).toBSpline();
}

/// f_x, f_y, f_xx, f_xy, f_yy at (x, 0).
std::array<double, 5> graphJet(const std::vector<GraphTerm>& f, double x) {
  std::array<double, 5> out{};
  for (const GraphTerm& t : f) {
    const auto xp = [&](int p) { return p < 0 ? 0.0 : std::pow(x, p); };
    if (t.b == 0) out[0] += t.c * t.a * xp(t.a - 1), out[2] += t.c * t.a * (t.a - 1) * xp(t.a - 2);
    if (t.b == 1) out[1] += t.c * xp(t.a), out[3] += t.c * t.a * xp(t.a - 1);
    if (t.b == 2) out[4] += 2.0 * t.c * xp(t.a);
  }
  return out;
}

/// The angle between the two graphs' normals at (x, 0), degrees.
double graphAngleDeg(const std::vector<GraphTerm>& fa, const std::vector<GraphTerm>& fb, double x) {
  const auto ja = graphJet(fa, x), jb = graphJet(fb, x);
  const Vec3 na(-ja[0], -ja[1], 1.0), nb(-jb[0], -jb[1], 1.0);
  return std::atan2(na.cross(nb).norm(), na.dot(nb)) * 180.0 / std::numbers::pi;
}

/// The spectral norm of the difference of the two graphs' shape operators at (x, 0) in an orthonormal frame of the
/// common tangent plane (the graphs are G1 there: the same f_x, f_y).
double graphCurvatureJump(const std::vector<GraphTerm>& fa, const std::vector<GraphTerm>& fb, double x) {
  const auto ja = graphJet(fa, x), jb = graphJet(fb, x);
  const Vec3 xx(1.0, 0.0, ja[0]), xy(0.0, 1.0, ja[1]);
  const double w = std::sqrt(1.0 + ja[0] * ja[0] + ja[1] * ja[1]);
  const Vec3 n = xx.cross(xy).normalized(), e1 = xx.normalized(), e2 = n.cross(e1);
  Eigen::Matrix<double, 3, 2> J;
  J << xx, xy;
  Eigen::Matrix2d E;  // the frame's chart coordinates, column by column
  E.col(0) = J.colPivHouseholderQr().solve(e1);
  E.col(1) = J.colPivHouseholderQr().solve(e2);
  Eigen::Matrix2d dHess;
  dHess << jb[2] - ja[2], jb[3] - ja[3], jb[3] - ja[3], jb[4] - ja[4];
  const Eigen::Matrix2d dS = E.transpose() * (dHess / w) * E;
  return Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(dS).eigenvalues().cwiseAbs().maxCoeff();
}

/// The seam of the two triangles (A's v0 against B's v1: both run from the pole at x = 0 to x = 1).
Result<SeamReport> poleSeam(const std::vector<GraphTerm>& fa, const std::vector<GraphTerm>& fb) {
  const Patch a = makePatch("A", poleTriangle(fa, 0.0, 3)), b = makePatch("B", poleTriangle(fb, -1.0, 3));
  return analyzeSeam(a, Edge::V0, b, Edge::V1);
}

const std::vector<GraphTerm> kPoleBase{{2, 0, 0.5}, {0, 2, 1.0}, {1, 1, 0.25}, {1, 0, 0.1}};

TEST(SeamPole, OneSurfaceThroughThePoleIsG1NeverACrease) {
  const Result<SeamReport> r = poleSeam(kPoleBase, kPoleBase);
  ASSERT_TRUE(r.isOk()) << r.status().message();
  EXPECT_TRUE(r->certified) << describe(*r);
  EXPECT_GE(r->geometric, GeometricClass::kG1) << describe(*r);
  EXPECT_LE(r->g1MaxDeg, kExactAngleDeg) << describe(*r);
  EXPECT_LE(r->g1SampledDeg, kExactAngleDeg) << describe(*r);  // the pole sample is the limit from inside: 0
  EXPECT_TRUE(std::any_of(r->notes.begin(), r->notes.end(),
                          [](const std::string& n) { return n.find("normal vanishes") != std::string::npos; }))
      << describe(*r);
}

TEST(SeamPole, AKinkOfAFifthOfADegreeAtThePoleIsAKinkOfThatAngle) {
  const double s = std::tan(0.2 * std::numbers::pi / 180.0);
  std::vector<GraphTerm> fb = kPoleBase;
  fb.push_back({0, 1, s});  // z_y jumps by s along y = 0
  const Result<SeamReport> r = poleSeam(kPoleBase, fb);
  ASSERT_TRUE(r.isOk()) << r.status().message();
  double expected = 0.0;  // dense independent maximum of the angle along the edge (it is at the pole, x = 0)
  for (int i = 0; i <= 10000; ++i) expected = std::max(expected, graphAngleDeg(kPoleBase, fb, i / 10000.0));
  EXPECT_NEAR(expected, graphAngleDeg(kPoleBase, fb, 0.0), 1e-12);
  EXPECT_NEAR(expected, 0.2, 0.002);
  EXPECT_EQ(r->geometric, GeometricClass::kG0) << describe(*r);
  // The angle at the pole is the limit along the edge from inside: the sampled maximum is the exact angle there.
  EXPECT_NEAR(r->g1SampledDeg, expected, 1e-6 * expected) << describe(*r);
  EXPECT_GE(r->g1MaxDeg, expected * (1.0 - 1e-9)) << describe(*r);
  EXPECT_LE(r->g1MaxDeg, expected * (1.0 + kBoundRelGap) + 1e-6) << describe(*r);
  EXPECT_LT(r->g1MaxDeg, 1.0) << describe(*r);  // never a crease or 180 degrees
}

TEST(SeamPole, CurvatureJumpNextToThePoleIsPrintedAwayFromItAndMarked) {
  std::vector<GraphTerm> fb = kPoleBase;
  fb.push_back({0, 2, 0.5});  // G1; z_yy jumps by 1 along y = 0
  const Result<SeamReport> r = poleSeam(kPoleBase, fb);
  ASSERT_TRUE(r.isOk()) << r.status().message();
  EXPECT_EQ(r->geometric, GeometricClass::kG1) << describe(*r);
  EXPECT_LE(r->g1MaxDeg, kExactAngleDeg) << describe(*r);
  double sup = 0.0;  // the jump along the whole edge, pole included (the graphs are smooth there)
  for (int i = 0; i <= 10000; ++i) sup = std::max(sup, graphCurvatureJump(kPoleBase, fb, i / 10000.0));
  EXPECT_NEAR(sup, graphCurvatureJump(kPoleBase, fb, 0.0), 1e-12);  // largest at the pole
  // Printed away from the pole (at the samples: the start samples of a certified seam are 8 per piece) and marked,
  // never pole noise: between the jump at the first sample inside and the supremum.
  const double inside = graphCurvatureJump(kPoleBase, fb, 1.0 / SeamOptions{}.certifiedSamplesPerPiece);
  ASSERT_TRUE(std::isfinite(r->g2Max)) << describe(*r);
  EXPECT_LE(r->g2Max, sup * (1.0 + kDenseSlackRel)) << describe(*r);
  EXPECT_GE(r->g2Max, inside * (1.0 - kDenseSlackRel)) << describe(*r);
  EXPECT_TRUE(std::any_of(r->notes.begin(), r->notes.end(),
                          [](const std::string& n) { return n.find("next to the pole") != std::string::npos; }))
      << describe(*r);
}

TEST(SeamPole, TheTeaspoonsHandleEndPrintsNoPoleNoise) {
  // The handle end of the Newell teaspoon: patches 12 to 15 close on a corner whose cross derivative vanishes (a
  // pole). The curvature jump grows toward it without bound; before issue 35 §2 its refinement ran up to the chart
  // threshold next to the pole and printed 4.2e10 (relative 1.05e7).
  const Result<Model> model = io::readModel(std::string(SEAM_SHARED_DATA_DIR) + "/bezier/teaspoon.bpt");
  ASSERT_TRUE(model.isOk()) << model.status().message();
  SeamOptions opt;
  opt.tol = Tolerances::forModelSize(model->boundingBox().diagonal());
  const Result<SeamReport> r = analyzeSeam(model->patches[12], Edge::V1, model->patches[13], Edge::V0, opt);
  ASSERT_TRUE(r.isOk()) << r.status().message();
  EXPECT_EQ(r->geometric, GeometricClass::kG1) << describe(*r);
  EXPECT_TRUE(std::isfinite(r->g2RelMax)) << describe(*r);
  EXPECT_LT(r->g2RelMax, 10.0) << describe(*r);
  EXPECT_TRUE(std::any_of(r->notes.begin(), r->notes.end(),
                          [](const std::string& n) { return n.find("next to the pole") != std::string::npos; }))
      << describe(*r);
}

// A normal that vanishes inside the edge (issue 35 §2): A's cross-boundary derivative along its edge v = 1 is
// S_v(t, 1) = 3 (t - 1/2)^k c, zero at t = 1/2 (k = 2: a double zero, the normal keeps its direction; k = 1: it
// reverses, A folds back over the edge on t > 1/2). B continues A across the edge; `lift` raises B's second row in
// z (a kink of about lift / 0.3 radians). Bicubic Bezier nets, row index i * 4 + j (i along u = x, j along v = y).
struct VanishingNormalPair {
  Matrix a, b;
};
VanishingNormalPair vanishingNormalPair(int order, double lift) {
  // Bernstein coefficients (cubic) of (t - 1/2)^2 and of t - 1/2.
  const std::array<double, 4> d = order == 2 ? std::array<double, 4>{0.25, -1.0 / 12, -1.0 / 12, 0.25}
                                             : std::array<double, 4>{-0.5, -1.0 / 6, 1.0 / 6, 0.5};
  auto z = [](double x) { return 0.2 * x * x; };
  VanishingNormalPair p{Matrix(16, 3), Matrix(16, 3)};
  for (int i = 0; i < 4; ++i) {
    const double x = i / 3.0;
    const std::array<double, 4> ya{0.0, 0.5, 1.0 - 0.3 * d[static_cast<size_t>(i)], 1.0}, yb{1.0, 1.3, 1.6, 2.0};
    for (int j = 0; j < 4; ++j) {
      p.a.row(i * 4 + j) = Vec3(x, ya[static_cast<size_t>(j)], z(x)).transpose();
      p.b.row(i * 4 + j) = Vec3(x, yb[static_cast<size_t>(j)], z(x) + (j == 1 ? lift : 0.0)).transpose();
    }
  }
  return p;
}

/// The unit normal of a bicubic Bezier net at (u, v), from the Bernstein derivative formulas (nullopt where
/// |S_u x S_v| is below 1e-12).
std::optional<Vec3> bezierNormal(const Matrix& net, double u, double v) {
  auto b = [](int i, double t) { return binomial(3, i) * std::pow(t, i) * std::pow(1.0 - t, 3 - i); };
  auto db = [](int i, double t) {  // d/dt of the cubic Bernstein polynomial B_i
    const double up = i >= 1 ? binomial(2, i - 1) * std::pow(t, i - 1) * std::pow(1.0 - t, 3 - i) : 0.0;
    const double down = i <= 2 ? binomial(2, i) * std::pow(t, i) * std::pow(1.0 - t, 2 - i) : 0.0;
    return 3.0 * (up - down);
  };
  Vec3 su = Vec3::Zero(), sv = Vec3::Zero();
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) {
      const Vec3 q = net.row(i * 4 + j).transpose();
      su += db(i, u) * b(j, v) * q;
      sv += b(i, u) * db(j, v) * q;
    }
  const Vec3 n = su.cross(sv);
  if (!(n.norm() > 1e-12)) return std::nullopt;
  return n.normalized();
}

/// The largest angle (degrees) between A's normal at (t, 1) and B's at (t, 0) on 20 001 even t in [0, tMax], where
/// both exist.
double densestVanishingNormalAngle(const VanishingNormalPair& p, double tMax = 1.0) {
  double best = 0.0;
  for (int k = 0; k <= 20000; ++k) {
    const double t = tMax * k / 20000.0;
    const auto na = bezierNormal(p.a, t, 1.0), nb = bezierNormal(p.b, t, 0.0);
    if (na && nb) best = std::max(best, std::atan2(na->cross(*nb).norm(), na->dot(*nb)) * 180.0 / std::numbers::pi);
  }
  return best;
}

Result<SeamReport> vanishingNormalSeam(const VanishingNormalPair& p) {
  return analyzeSeam(makePatch("A", BezierPatch(3, 3, p.a).toBSpline()), Edge::V1,
                     makePatch("B", BezierPatch(3, 3, p.b).toBSpline()), Edge::V0);
}

TEST(SeamPole, ANormalVanishingInsideTheEdgeIsNeverACertified180DegreeCrease) {
  // Before: the angle bound returned 180 degrees on every interval holding the zero, and the seam was certified a
  // 180-degree crease; with lift 1e-5 the subdivision's midpoints next to t = 1/2 also "sampled" 89 degrees of
  // round-off. Now the angle is the one measured where both normals exist, the seam is not certified, and one within
  // the G1 tolerance is undetermined, with the vanishing point named.
  for (const double lift : {1e-7, 1e-5}) {
    const VanishingNormalPair p = vanishingNormalPair(2, lift);
    const double expected = densestVanishingNormalAngle(p);
    const Result<SeamReport> r = vanishingNormalSeam(p);
    ASSERT_TRUE(r.isOk()) << r.status().message();
    EXPECT_FALSE(r->certified) << describe(*r);
    ASSERT_TRUE(r->g1PoleT.has_value()) << describe(*r);
    EXPECT_NEAR(*r->g1PoleT, 0.5, 1e-3) << describe(*r);
    EXPECT_NEAR(r->g1MaxDeg, expected, 1e-3 * expected) << lift << ": " << describe(*r);
    EXPECT_LT(r->g1MaxDeg, SeamOptions{}.tol.angleDeg) << describe(*r);
    EXPECT_EQ(seamVerdict(*r), SeamVerdict::kUndetermined) << describe(*r);
    EXPECT_TRUE(passes(SeamFilter::kProblems, &*r, kDefaultCreaseAngleDeg));
  }
  // A kink of about 0.2 degrees along the whole seam: a kink of the measured angle, not undetermined.
  const VanishingNormalPair kinked = vanishingNormalPair(2, 0.3 * std::tan(0.2 * std::numbers::pi / 180.0));
  const double expected = densestVanishingNormalAngle(kinked);
  const Result<SeamReport> r = vanishingNormalSeam(kinked);
  ASSERT_TRUE(r.isOk()) << r.status().message();
  EXPECT_NEAR(r->g1MaxDeg, expected, 1e-3 * expected) << describe(*r);
  EXPECT_EQ(seamVerdict(*r), SeamVerdict::kKink) << describe(*r);
}

TEST(SeamPole, ThePCurveRouteMeasuresTheAngleWhereANormalVanishesInsideTheEdge) {
  // The same pairs seen as trimmed faces: A's pcurve v = 1 and B's v = 0, sharing the edge parameter, over u in
  // [0, end]. Before, the pcurve route refused the whole seam ("a bound could not be closed"), and the B-rep check
  // fell back to samples with no word of the vanishing normal. Now G0 is certified and the angle bound either closes
  // (round-off leaves |N_A|^2 a tiny positive value at the double zero: then it must still bound the dense measure
  // and stay sharp) or stays open: then the angle is the one measured where both normals exist, and the point is
  // named. Which of the two happens depends on the last bits at the zero; both must occur among these edges. A
  // tangent surface (lift 0) stays a G1 identity with no pole.
  int open = 0, closed = 0;
  for (const double end : {1.0, 0.9, 0.8, 0.7}) {
    const BSplineCurve top = pcurve::line2d({0.0, 1.0}, {end, 1.0}), bottom = pcurve::line2d({0.0, 0.0}, {end, 0.0});
    for (const double lift : {1e-7, 1e-5, 0.0}) {
      const VanishingNormalPair p = vanishingNormalPair(2, lift);
      const BSplineSurface A = BezierPatch(3, 3, p.a).toBSpline(), B = BezierPatch(3, 3, p.b).toBSpline();
      const Result<PCurveSeamBounds> r = certifyPCurveSeam(pcurve::side(A, top), pcurve::side(B, bottom));
      ASSERT_TRUE(r) << end << " " << lift << ": " << r.status().message();
      EXPECT_LE(r->g0Bound, 1e-12) << lift;  // B's first row is A's last: no gap
      if (lift == 0.0) {
        EXPECT_TRUE(r->g1Identity) << end;
        EXPECT_FALSE(r->g1PoleT.has_value()) << end;
        continue;
      }
      const double expected = densestVanishingNormalAngle(p, end);
      EXPECT_FALSE(r->g1Identity) << end << " " << lift;
      EXPECT_NEAR(r->g1SampledDeg, expected, 1e-3 * expected) << end << " " << lift;
      if (r->g1PoleT) {
        ++open;
        EXPECT_NEAR(*r->g1PoleT, 0.5 / end, 1e-3) << end << " " << lift;
        EXPECT_NEAR(r->g1BoundDeg, expected, 1e-3 * expected) << end << " " << lift;
      } else {
        ++closed;
        EXPECT_GE(r->g1BoundDeg, expected * (1.0 - 1e-9)) << end << " " << lift;
        EXPECT_LE(r->g1BoundDeg, 1.05 * expected) << end << " " << lift;
      }
    }
  }
  EXPECT_GE(open, 1);
  std::cout << "vanishing normal on the pcurve route: " << open << " open, " << closed << " closed\n";
}

TEST(SeamPole, ATangentSurfaceWithADoubleZeroOfItsNormalIsAG1Identity) {
  // lift 0: B continues A's cylinder z = 0.2 x^2 exactly, N_A x N_B = 0 as a polynomial. N_A . N_B = (t - 1/2)^2 (...)
  // has negative Bernstein coefficients but no negative value: no fold, G1 proved (before: a "fold", then 180).
  const VanishingNormalPair p = vanishingNormalPair(2, 0.0);
  const Result<SeamReport> r = vanishingNormalSeam(p);
  ASSERT_TRUE(r.isOk()) << r.status().message();
  EXPECT_TRUE(r->g1Identity) << describe(*r);
  EXPECT_FALSE(r->g1PoleT.has_value()) << describe(*r);
  EXPECT_GE(r->geometric, GeometricClass::kG1) << describe(*r);
  EXPECT_LE(r->g1MaxDeg, densestVanishingNormalAngle(p) + kExactAngleDeg) << describe(*r);
}

TEST(SeamPole, ANormalThatReversesInsideTheEdgeIsAFoldOfItsMeasuredAngle) {
  // k = 1: A's normal reverses at t = 1/2, so on t > 1/2 A and B face opposite ways (180 degrees, measured on a
  // whole half of the seam, not at one point): a crease of that angle, never undetermined.
  const VanishingNormalPair p = vanishingNormalPair(1, 0.0);
  const double expected = densestVanishingNormalAngle(p);
  EXPECT_GT(expected, 179.0);
  const Result<SeamReport> r = vanishingNormalSeam(p);
  ASSERT_TRUE(r.isOk()) << r.status().message();
  EXPECT_FALSE(r->g1Identity) << describe(*r);
  EXPECT_NEAR(r->g1MaxDeg, expected, 1e-3 * expected) << describe(*r);
  EXPECT_EQ(seamVerdict(*r), SeamVerdict::kCrease) << describe(*r);
}

}  // namespace
}  // namespace seam
