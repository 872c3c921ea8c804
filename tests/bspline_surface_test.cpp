// Tensor-product B-spline / NURBS surfaces (include/seam/spline/bspline_surface.h) against brute-force double
// sums of Cox-de Boor basis functions, the two-variable quotient rule and finite differences
// (test_helpers.h). Degrees 1..5 in each direction (mixed), rational and polynomial; 2000 random parameters
// per geometry check and 10^4 for a few cases.
#include "seam/spline/bspline_surface.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cstdint>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "spline/spline_internal.h"
#include "test_helpers.h"

namespace seam {
namespace {

using test::closeTo;
using test::describe;
using test::failsMentioning;
using test::randomSurface;
using test::refSurfaceDerivMagnitudes;
using test::refSurfaceDerivs;
using test::refSurfacePoint;
using test::sameSurface;
using test::uniformInt;
using test::uniformReal;

/// normal() vs the normalised brute-force S_u x S_v: the direction of a cross product is perturbed by about
/// eps |S_u| |S_v| / |S_u x S_v|; points where the sine of the angle between S_u and S_v is below kMinSine
/// are skipped, so kNormalTol (~1e7 eps) bounds the comparison with a wide margin.
constexpr double kMinSine = 1e-6;
constexpr double kNormalTol = 1e-9;

constexpr int kSamples = 2000;
constexpr int kManySamples = 10000;

struct SurfaceCase {
  BSplineSurface surface;
  int samples;
};

/// Every bi-degree (pu, pv) in 1..5 x 1..5, rational on alternate cases, plus two 10^4-sample cases and two
/// unclamped ones.
std::vector<SurfaceCase> geometryCases(std::mt19937_64& rng) {
  std::vector<SurfaceCase> cases;
  for (int pu = 1; pu <= 5; ++pu)
    for (int pv = 1; pv <= 5; ++pv)
      cases.push_back(
          {randomSurface(rng, pu, pv, 3, {.rational = (pu + pv) % 2 == 1, .minSpans = 1, .maxSpans = 3}),
           kSamples});
  cases.push_back(
      {randomSurface(rng, 3, 3, 3, {.rational = true, .minSpans = 2, .maxSpans = 3}), kManySamples});
  cases.push_back(
      {randomSurface(rng, 5, 2, 3, {.rational = false, .minSpans = 2, .maxSpans = 3}), kManySamples});
  cases.push_back({randomSurface(rng, 2, 4, 3, {.rational = true, .clamped = false}), kSamples});
  cases.push_back({randomSurface(rng, 3, 1, 3, {.rational = false, .clamped = false}), kSamples});
  return cases;
}

std::vector<double> interiorBreakpoints(const std::vector<double>& knots, Interval d) {
  std::vector<double> out;
  for (double b : test::distinctValues(knots))
    if (b > d.lo && b < d.hi) out.push_back(b);
  return out;
}

int multiplicityOf(const std::vector<double>& knots, double t) {
  return static_cast<int>(std::count(knots.begin(), knots.end(), t));
}

/// A parameter at least 1% of the domain away from every knot.
double freshParameter(std::mt19937_64& rng, const std::vector<double>& knots, Interval d) {
  for (;;) {
    const double t = uniformReal(rng, d.lo, d.hi);
    bool ok = true;
    for (double k : knots) ok = ok && std::abs(t - k) > 0.01 * d.length();
    if (ok) return t;
  }
}

std::vector<double> merged(std::vector<double> a, const std::vector<double>& b) {
  a.insert(a.end(), b.begin(), b.end());
  std::sort(a.begin(), a.end());
  return a;
}

/// The edge's fixed parameter and the interval of the parameter that runs along it.
struct EdgeGeometry {
  double fixed;
  Interval along;
  bool isU;  // the fixed parameter is u (edge U0/U1)
};
EdgeGeometry edgeGeometry(const BSplineSurface& s, Edge e) {
  switch (e) {
    case Edge::U0:
      return {s.domainU().lo, s.domainV(), true};
    case Edge::U1:
      return {s.domainU().hi, s.domainV(), true};
    case Edge::V0:
      return {s.domainV().lo, s.domainU(), false};
    case Edge::V1:
      return {s.domainV().hi, s.domainU(), false};
  }
  return {};
}

// ---------------------------------------------------------------------------------------------------------------------
// Evaluation and derivatives
// ---------------------------------------------------------------------------------------------------------------------

TEST(BSplineSurface, EvaluateMatchesBruteForce) {
  std::mt19937_64 rng(501);
  for (int pu = 1; pu <= 5; ++pu)
    for (int pv = 1; pv <= 5; ++pv)
      for (bool rational : {false, true}) {
        const int dim = (pu + pv) % 3 == 0 ? 4 : 3;
        const BSplineSurface s =
            randomSurface(rng, pu, pv, dim, {.rational = rational, .clamped = (pu + 2 * pv) % 4 != 0});
        ASSERT_EQ(s.degreeU(), pu);
        ASSERT_EQ(s.degreeV(), pv);
        ASSERT_EQ(s.dim(), dim);
        auto uvs = test::sampleParams2(rng, s.domainU(), s.domainV(), 60);
        for (double b : interiorBreakpoints(s.knotsU().values(), s.domainU()))
          uvs.emplace_back(b, uniformReal(rng, s.domainV().lo, s.domainV().hi));
        for (const Vec2& uv : uvs) {
          const double bound = test::kRoundoffTol * refSurfaceDerivMagnitudes(s, uv[0], uv[1], 0)[0][0];
          ASSERT_TRUE(closeTo(refSurfacePoint(s, uv[0], uv[1]), s.evaluate(uv[0], uv[1]), bound))
              << describe(s) << " at " << uv.transpose();
        }
      }
}

TEST(BSplineSurface, DerivativesMatchBruteForce) {
  constexpr int kOrder = 3;
  std::mt19937_64 rng(502);
  for (int pu = 1; pu <= 5; ++pu)
    for (int pv = 1; pv <= 5; ++pv)
      for (bool rational : {false, true}) {
        const BSplineSurface s =
            randomSurface(rng, pu, pv, 3, {.rational = rational, .clamped = (pu + pv) % 3 != 0});
        auto uvs = test::sampleParams2(rng, s.domainU(), s.domainV(), 12);
        for (double b : interiorBreakpoints(s.knotsV().values(), s.domainV()))  // right-sided at knots
          uvs.emplace_back(uniformReal(rng, s.domainU().lo, s.domainU().hi), b);
        for (const Vec2& uv : uvs) {
          const auto got = s.derivatives(uv[0], uv[1], kOrder);
          ASSERT_GE(static_cast<int>(got.size()), kOrder + 1);
          const auto expected = refSurfaceDerivs(s, uv[0], uv[1], kOrder);
          const auto magnitude = refSurfaceDerivMagnitudes(s, uv[0], uv[1], kOrder);
          for (int k = 0; k <= kOrder; ++k) {
            ASSERT_GE(static_cast<int>(got[static_cast<size_t>(k)].size()), kOrder - k + 1);
            for (int l = 0; k + l <= kOrder; ++l)
              ASSERT_TRUE(closeTo(expected[k][l], got[k][l],
                                  test::kRoundoffTol * magnitude[k][l] + test::kExactZeroFloor))
                  << describe(s) << " at " << uv.transpose() << " derivative (" << k << "," << l << ")";
          }
        }
      }
}

TEST(BSplineSurface, DerivativesMatchFiniteDifferences) {
  constexpr int kOrder = 3;
  std::mt19937_64 rng(503);
  for (int pu = 1; pu <= 5; ++pu)
    for (int pv = 1; pv <= 5; pv += 2)
      for (bool rational : {false, true}) {
        const BSplineSurface s = randomSurface(rng, pu, pv, 3, {.rational = rational});
        for (int trial = 0; trial < 3; ++trial) {
          const auto [u, lu] = test::paramInsideSpan(rng, s.knotsU().values(), pu);
          const auto [v, lv] = test::paramInsideSpan(rng, s.knotsV().values(), pv);
          const auto got = s.derivatives(u, v, kOrder);
          const auto magnitude = refSurfaceDerivMagnitudes(s, u, v, kOrder);
          for (int k = 0; k <= kOrder; ++k)
            for (int l = 0; k + l <= kOrder; ++l) {
              if (k + l == 0) continue;
              // Difference the brute-force lower-order derivative in u (k > 0) or v.
              const VecX fd =
                  k > 0 ? test::richardsonDerivative(
                              [&, v0 = v](double x) { return VecX(refSurfaceDerivs(s, x, v0, kOrder)[k - 1][l]); }, u,
                              lu / test::kFdStepDivisor)
                        : test::richardsonDerivative(
                              [&, u0 = u](double y) { return VecX(refSurfaceDerivs(s, u0, y, kOrder)[k][l - 1]); }, v,
                              lv / test::kFdStepDivisor);
              ASSERT_TRUE(closeTo(fd, got[k][l], test::kFdRelTol * magnitude[k][l]))
                  << describe(s) << " at " << u << "," << v << " derivative (" << k << "," << l << ")";
            }
        }
      }
}

TEST(BSplineSurface, NormalIsNormalisedCrossProduct) {
  std::mt19937_64 rng(504);
  for (int pu = 1; pu <= 5; ++pu)
    for (bool rational : {false, true}) {
      const BSplineSurface s = randomSurface(rng, pu, 6 - pu, 3, {.rational = rational});
      for (const Vec2& uv : test::sampleParams2(rng, s.domainU(), s.domainV(), 30)) {
        const auto d = refSurfaceDerivs(s, uv[0], uv[1], 1);
        const Vec3 n = Vec3(d[1][0]).cross(Vec3(d[0][1]));
        if (n.norm() < kMinSine * d[1][0].norm() * d[0][1].norm())
          continue;  // nearly degenerate: direction unstable
        ASSERT_TRUE(closeTo(n.normalized(), s.normal(uv[0], uv[1]), kNormalTol))
            << describe(s) << " at " << uv.transpose();
      }
    }
}

TEST(BSplineSurface, NormalAtACollapsedEdgeIsFinite) {
  // A bilinear-by-quadratic patch whose whole U0 row is the origin: S_v vanishes along u = 0.
  Matrix pts(3 * 3, 3);
  pts << 0, 0, 0, 0, 0, 0, 0, 0, 0,  //
      1, 0, 0, 1, 1, 0, 0, 1, 0,     //
      2, 0, 1, 2, 2, 1, 0, 2, 1;
  const BSplineSurface s(2, 2, KnotVector::bezier(2), KnotVector::bezier(2), 3, 3, pts);
  for (double v : {0.0, 0.3, 1.0}) {
    const Vec3 n = s.normal(0.0, v);
    ASSERT_TRUE(n.allFinite()) << n.transpose();
    ASSERT_TRUE(n.norm() == 0.0 || std::abs(n.norm() - 1.0) < test::kFewUlps) << n.transpose();
  }
  const Vec3 inner = s.normal(0.5, 0.5);
  EXPECT_NEAR(inner.norm(), 1.0, test::kFewUlps);
}

TEST(BSplineSurface, RationalSphereOctantIsExact) {
  // The octant of the unit sphere as a biquadratic NURBS (surface of revolution of a quarter circle, The
  // NURBS Book section 8.5): circle control points (1,0),(1,1),(0,1) with weights 1, sqrt(2)/2, 1 in both
  // directions, P_ij = (r_j c_i, z_j), w_ij = w_i w_j. Every point is at radius 1 and the unit normal is the
  // point itself.
  const double w = std::sqrt(0.5);
  const double cw[3] = {1, w, 1};
  const Vec2 c[3] = {{1, 0}, {1, 1}, {0, 1}};  // circle around the z axis (u)
  const double r[3] = {1, 1, 0},
               z[3] = {0, 1, 1};  // meridian quarter circle (v), from the equator to the pole
  Matrix pts(9, 3);
  VecX wts(9);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      pts.row(i * 3 + j) << r[j] * c[i][0], r[j] * c[i][1], z[j];
      wts[i * 3 + j] = cw[i] * cw[j];
    }
  const BSplineSurface s(2, 2, KnotVector::bezier(2), KnotVector::bezier(2), 3, 3, pts, wts);
  std::mt19937_64 rng(505);
  for (const Vec2& uv : test::sampleParams2(rng, s.domainU(), s.domainV(), 400)) {
    const Vec3 p = s.evaluate(uv[0], uv[1]);
    ASSERT_NEAR(p.norm(), 1.0, test::kFewUlps) << uv.transpose();
    // |S|^2 = 1 identically, so S . S_u = S . S_v = 0 (a check of the rational derivatives).
    const auto d = s.derivatives(uv[0], uv[1], 1);
    ASSERT_NEAR(p.dot(Vec3(d[1][0])), 0.0, test::kIdentityTol * (1 + d[1][0].norm()));
    ASSERT_NEAR(p.dot(Vec3(d[0][1])), 0.0, test::kIdentityTol * (1 + d[0][1].norm()));
    if (uv[1] < 0.999) {
      ASSERT_TRUE(closeTo(p, s.normal(uv[0], uv[1]), kNormalTol)) << uv.transpose();
    }
  }
  // The pole (v = 1): S_u vanishes; the normal must not be NaN.
  const Vec3 pole = s.normal(0.4, 1.0);
  EXPECT_TRUE(pole.allFinite()) << pole.transpose();
}

// ---------------------------------------------------------------------------------------------------------------------
// Knot insertion and refinement
// ---------------------------------------------------------------------------------------------------------------------

TEST(BSplineSurface, KnotInsertionKeepsGeometry) {
  std::mt19937_64 rng(511);
  for (const auto& [s, samples] : geometryCases(rng)) {
    const double u = freshParameter(rng, s.knotsU().values(), s.domainU());
    const int tu = uniformInt(rng, 1, s.degreeU());
    const BSplineSurface ru = s.withKnotInsertedU(u, tu);
    ASSERT_EQ(ru.numU(), s.numU() + tu);
    ASSERT_EQ(ru.numV(), s.numV());
    ASSERT_EQ(ru.knotsU().values(), merged(s.knotsU().values(), std::vector<double>(tu, u)));
    ASSERT_EQ(ru.knotsV().values(), s.knotsV().values());
    ASSERT_TRUE(sameSurface(s, ru, rng, samples)) << describe(s) << " u " << u << " x" << tu;

    // In v: at an existing interior knot when there is one with room, else at a fresh value.
    double v = freshParameter(rng, s.knotsV().values(), s.domainV());
    for (double b : interiorBreakpoints(s.knotsV().values(), s.domainV()))
      if (multiplicityOf(s.knotsV().values(), b) < s.degreeV()) v = b;
    const int room = s.degreeV() - multiplicityOf(s.knotsV().values(), v);
    const BSplineSurface rv = s.withKnotInsertedV(v, room);
    ASSERT_EQ(rv.numV(), s.numV() + room);
    ASSERT_EQ(rv.knotsV().values(), merged(s.knotsV().values(), std::vector<double>(room, v)));
    ASSERT_TRUE(sameSurface(s, rv, rng, samples)) << describe(s) << " v " << v << " x" << room;
  }
}

TEST(BSplineSurface, RefinementKeepsGeometry) {
  std::mt19937_64 rng(512);
  for (const auto& [s, samples] : geometryCases(rng)) {
    std::vector<double> nu, nv;
    for (int i = uniformInt(rng, 1, 4); i > 0; --i)
      nu.push_back(freshParameter(rng, s.knotsU().values(), s.domainU()));
    for (int i = uniformInt(rng, 1, 4); i > 0; --i)
      nv.push_back(freshParameter(rng, s.knotsV().values(), s.domainV()));
    for (double b : interiorBreakpoints(s.knotsV().values(), s.domainV()))
      if (multiplicityOf(s.knotsV().values(), b) < s.degreeV()) nv.push_back(b);
    std::sort(nu.begin(), nu.end());
    std::sort(nv.begin(), nv.end());
    const BSplineSurface r = s.refinedU(nu).refinedV(nv);
    ASSERT_EQ(r.knotsU().values(), merged(s.knotsU().values(), nu));
    ASSERT_EQ(r.knotsV().values(), merged(s.knotsV().values(), nv));
    ASSERT_EQ(r.numU(), s.numU() + static_cast<int>(nu.size()));
    ASSERT_EQ(r.numV(), s.numV() + static_cast<int>(nv.size()));
    ASSERT_TRUE(sameSurface(s, r, rng, samples)) << describe(s);
  }
}

// ---------------------------------------------------------------------------------------------------------------------
// Bezier patches, degree elevation, reversal, swap, reparametrisation
// ---------------------------------------------------------------------------------------------------------------------

TEST(BSplineSurface, BezierPatchesTileTheDomainAndEvaluateCorrectly) {
  std::mt19937_64 rng(521);
  for (const auto& [s, samples] : geometryCases(rng)) {
    const auto patches = s.bezierPatches();
    std::vector<double> bu{s.domainU().lo}, bv{s.domainV().lo};
    for (double b : interiorBreakpoints(s.knotsU().values(), s.domainU())) bu.push_back(b);
    for (double b : interiorBreakpoints(s.knotsV().values(), s.domainV())) bv.push_back(b);
    bu.push_back(s.domainU().hi);
    bv.push_back(s.domainV().hi);
    const int nu = static_cast<int>(bu.size()) - 1, nv = static_cast<int>(bv.size()) - 1;
    ASSERT_EQ(static_cast<int>(patches.size()), nu * nv) << describe(s);
    // Every (spanU, spanV) appears exactly once, with the box of those spans: the boxes tile the domain.
    std::vector<int> seen(static_cast<size_t>(nu * nv), 0);
    for (const auto& piece : patches) {
      ASSERT_GE(piece.spanU, 0);
      ASSERT_LT(piece.spanU, nu);
      ASSERT_GE(piece.spanV, 0);
      ASSERT_LT(piece.spanV, nv);
      ++seen[static_cast<size_t>(piece.spanU * nv + piece.spanV)];
      ASSERT_DOUBLE_EQ(piece.u.lo, bu[static_cast<size_t>(piece.spanU)]);
      ASSERT_DOUBLE_EQ(piece.u.hi, bu[static_cast<size_t>(piece.spanU) + 1]);
      ASSERT_DOUBLE_EQ(piece.v.lo, bv[static_cast<size_t>(piece.spanV)]);
      ASSERT_DOUBLE_EQ(piece.v.hi, bv[static_cast<size_t>(piece.spanV) + 1]);
      ASSERT_EQ(piece.patch.degreeU(), s.degreeU());
      ASSERT_EQ(piece.patch.degreeV(), s.degreeV());
      ASSERT_EQ(piece.patch.isRational(), s.isRational());
    }
    for (int count : seen) ASSERT_EQ(count, 1) << describe(s);
    // Each patch, evaluated by an explicit Bernstein double sum at the mapped parameters, is the surface.
    const int perPatch = std::max(20, samples / static_cast<int>(patches.size()));
    for (const auto& piece : patches) {
      const auto& bp = piece.patch;
      ASSERT_TRUE(test::agreeAt2(
          test::sampleParams2(rng, piece.u, piece.v, perPatch),
          [&surface = s](double u, double v) { return refSurfacePoint(surface, u, v); },
          [&](double u, double v) {
            return test::refBezierPatchPoint(bp.degreeU(), bp.degreeV(), bp.points(), bp.weights(),
                                             (u - piece.u.lo) / piece.u.length(),
                                             (v - piece.v.lo) / piece.v.length());
          },
          test::controlScale(s.points()), test::kGeometryRelTol))
          << describe(s) << " patch " << piece.spanU << "," << piece.spanV;
    }
  }
}

TEST(BSplineSurface, DegreeElevationKeepsGeometry) {
  std::mt19937_64 rng(531);
  for (const auto& [s, samples] : geometryCases(rng)) {
    const int byU = uniformInt(rng, 0, 2), byV = uniformInt(rng, byU == 0 ? 1 : 0, 2);
    const BSplineSurface e = s.degreeElevated(byU, byV);
    ASSERT_EQ(e.degreeU(), s.degreeU() + byU);
    ASSERT_EQ(e.degreeV(), s.degreeV() + byV);
    ASSERT_EQ(e.isRational(), s.isRational());
    ASSERT_EQ(e.domainU(), s.domainU());
    ASSERT_EQ(e.domainV(), s.domainV());
    ASSERT_TRUE(sameSurface(s, e, rng, samples)) << describe(s) << " elevated by " << byU << "," << byV;
    // Clamped inputs: same breakpoints, multiplicities up by the elevation.
    const auto check = [](const KnotVector& before, const KnotVector& after, int by) {
      std::vector<int> m = before.multiplicities();
      for (int& x : m) x += by;
      return after.breakpoints() == before.breakpoints() && after.multiplicities() == m;
    };
    const bool clamped =
        s.knotsU().values().front() == s.domainU().lo && s.knotsU().values().back() == s.domainU().hi &&
        s.knotsV().values().front() == s.domainV().lo && s.knotsV().values().back() == s.domainV().hi;
    if (clamped) {
      EXPECT_TRUE(check(s.knotsU(), e.knotsU(), byU)) << describe(s);
      EXPECT_TRUE(check(s.knotsV(), e.knotsV(), byV)) << describe(s);
    }
  }
}

TEST(BSplineSurface, ReversedSwappedAndReparametrized) {
  std::mt19937_64 rng(541);
  for (const auto& [s, samples] : geometryCases(rng)) {
    const Interval du = s.domainU(), dv = s.domainV();
    const int n = samples / 2;
    const BSplineSurface ru = s.reversedU();
    ASSERT_EQ(ru.degreeU(), s.degreeU());
    ASSERT_TRUE(sameSurface(s, ru, rng, n, [&](double u, double v) { return Vec2(du.lo + du.hi - u, v); }))
        << "reversedU " << describe(s);
    const BSplineSurface rv = s.reversedV();
    ASSERT_TRUE(sameSurface(s, rv, rng, n, [&](double u, double v) { return Vec2(u, dv.lo + dv.hi - v); }))
        << "reversedV " << describe(s);
    const BSplineSurface sw = s.swappedUV();
    ASSERT_EQ(sw.degreeU(), s.degreeV());
    ASSERT_EQ(sw.degreeV(), s.degreeU());
    ASSERT_EQ(sw.numU(), s.numV());
    ASSERT_EQ(sw.numV(), s.numU());
    ASSERT_EQ(sw.domainU(), dv);
    ASSERT_EQ(sw.domainV(), du);
    ASSERT_TRUE(sameSurface(s, sw, rng, n, [](double u, double v) { return Vec2(v, u); }))
        << "swapped " << describe(s);
    const Interval a{uniformReal(rng, -5, 5), 0}, b{uniformReal(rng, -5, 5), 0};
    const Interval nu{a.lo, a.lo + uniformReal(rng, 0.1, 10)}, nv{b.lo, b.lo + uniformReal(rng, 0.1, 10)};
    const BSplineSurface rp = s.reparametrized(nu, nv);
    ASSERT_NEAR(rp.domainU().lo, nu.lo, test::kFewUlps * (1 + std::abs(nu.lo) + std::abs(nu.hi)));
    ASSERT_NEAR(rp.domainU().hi, nu.hi, test::kFewUlps * (1 + std::abs(nu.lo) + std::abs(nu.hi)));
    ASSERT_NEAR(rp.domainV().lo, nv.lo, test::kFewUlps * (1 + std::abs(nv.lo) + std::abs(nv.hi)));
    ASSERT_NEAR(rp.domainV().hi, nv.hi, test::kFewUlps * (1 + std::abs(nv.lo) + std::abs(nv.hi)));
    ASSERT_TRUE(sameSurface(s, rp, rng, n,
                            [&](double u, double v) {
                              return Vec2(du.lo + (u - nu.lo) / nu.length() * du.length(),
                                          dv.lo + (v - nv.lo) / nv.length() * dv.length());
                            }))
        << "reparametrized " << describe(s);
  }
}

// ---------------------------------------------------------------------------------------------------------------------
// Edges: boundary curves, cross-boundary derivatives, re-orientation
// ---------------------------------------------------------------------------------------------------------------------

TEST(BSplineSurface, EdgeNames) {
  EXPECT_EQ(edgeName(Edge::U0), "u0");
  EXPECT_EQ(edgeName(Edge::U1), "u1");
  EXPECT_EQ(edgeName(Edge::V0), "v0");
  EXPECT_EQ(edgeName(Edge::V1), "v1");
  for (Edge e : kAllEdges) {
    const auto parsed = parseEdge(edgeName(e));
    ASSERT_TRUE(parsed.isOk());
    EXPECT_EQ(*parsed, e);
  }
  ASSERT_TRUE(parseEdge("V1").isOk());
  EXPECT_EQ(*parseEdge("V1"), Edge::V1);
  EXPECT_FALSE(parseEdge("w0").isOk());
  EXPECT_FALSE(parseEdge("").isOk());
  EXPECT_TRUE(isUEdge(Edge::U0));
  EXPECT_TRUE(isUEdge(Edge::U1));
  EXPECT_FALSE(isUEdge(Edge::V0));
  EXPECT_FALSE(isUEdge(Edge::V1));
}

TEST(BSplineSurface, BoundaryCurveIsTheSurfaceAlongTheEdge) {
  std::mt19937_64 rng(551);
  for (const auto& [s, samples] : geometryCases(rng))
    for (Edge e : kAllEdges) {
      const BSplineCurve c = s.boundaryCurve(e);
      const EdgeGeometry g = edgeGeometry(s, e);
      ASSERT_EQ(c.domain(), g.along) << describe(s) << " edge " << edgeName(e);
      ASSERT_EQ(c.degree(), g.isU ? s.degreeV() : s.degreeU());
      ASSERT_EQ(c.isRational(), s.isRational());
      ASSERT_TRUE(test::agreeAt(
          test::sampleParams(rng, g.along, samples / 4),
          [&, &surface = s](double t) {
            return g.isU ? refSurfacePoint(surface, g.fixed, t) : refSurfacePoint(surface, t, g.fixed);
          },
          [&](double t) { return test::refCurvePoint(c, t); }, test::controlScale(s.points()),
          test::kGeometryRelTol))
          << describe(s) << " edge " << edgeName(e);
    }
}

TEST(BSplineSurface, CrossDerivativeCurvesMatchPartialDerivativesAcrossTheEdge) {
  std::mt19937_64 rng(552);
  for (const auto& [s, samples] : geometryCases(rng))
    for (Edge e : kAllEdges)
      for (int k = 0; k <= 2; ++k) {
        const BSplineCurve c = s.crossDerivativeCurve(e, k);
        const EdgeGeometry g = edgeGeometry(s, e);
        ASSERT_EQ(c.domain(), g.along) << describe(s) << " edge " << edgeName(e) << " order " << k;
        ASSERT_EQ(c.dim(), s.dim());
        ASSERT_EQ(c.isRational(), s.isRational());
        std::vector<double> ts = test::sampleParams(rng, g.along, 60);
        for (double b : interiorBreakpoints(g.isU ? s.knotsV().values() : s.knotsU().values(), g.along))
          ts.push_back(b);
        for (double t : ts) {
          const double u = g.isU ? g.fixed : t, v = g.isU ? t : g.fixed;
          const auto expected = refSurfaceDerivs(s, u, v, k);
          const VecX& want = g.isU ? expected[k][0] : expected[0][k];
          const auto magnitude = refSurfaceDerivMagnitudes(s, u, v, k);
          const double bound = test::kRoundoffTol * ((g.isU ? magnitude[k][0] : magnitude[0][k]) +
                                                     test::refCurveDerivMagnitudes(c, t, 0)[0]);
          const VecX got = test::refCurvePoint(c, t);
          ASSERT_TRUE(closeTo(want, got, bound))
              << describe(s) << " edge " << edgeName(e) << " order " << k << " t " << t;
          // The same quantity through seam's own derivatives() (two routes in the library must agree too).
          const auto lib = s.derivatives(u, v, k);
          ASSERT_TRUE(closeTo(g.isU ? lib[k][0] : lib[0][k], got, bound))
              << describe(s) << " edge " << edgeName(e) << " order " << k << " t " << t;
        }
      }
}

TEST(BSplineSurface, RationalCrossDerivativesMatchFiniteDifferences) {
  // d^k S / dn^k at the edge vs central differences of the brute-force rational surface (extended past the
  // edge by its end piece, which is the same rational function).
  std::mt19937_64 rng(553);
  for (int trial = 0; trial < 8; ++trial) {
    const BSplineSurface s =
        randomSurface(rng, uniformInt(rng, 1, 5), uniformInt(rng, 1, 5), 3, {.rational = true});
    for (Edge e : kAllEdges) {
      const EdgeGeometry g = edgeGeometry(s, e);
      const std::vector<double>& across = g.isU ? s.knotsU().values() : s.knotsV().values();
      const int pAcross = g.isU ? s.degreeU() : s.degreeV();
      // Length of the end span next to the edge sets the step.
      const int span = test::referenceSpan(across, pAcross, g.fixed);
      const double h =
          (across[static_cast<size_t>(span) + 1] - across[static_cast<size_t>(span)]) / test::kFdStepDivisor;
      for (int k = 1; k <= 2; ++k) {
        const BSplineCurve c = s.crossDerivativeCurve(e, k);
        for (int i = 0; i < 10; ++i) {
          const double t = uniformReal(rng, g.along.lo, g.along.hi);
          const auto lower = [&](double x) {
            const auto d = g.isU ? refSurfaceDerivs(s, x, t, k - 1) : refSurfaceDerivs(s, t, x, k - 1);
            return VecX(g.isU ? d[k - 1][0] : d[0][k - 1]);
          };
          const VecX fd = test::richardsonDerivative(lower, g.fixed, h);
          const auto magnitude = g.isU ? refSurfaceDerivMagnitudes(s, g.fixed, t, k)
                                       : refSurfaceDerivMagnitudes(s, t, g.fixed, k);
          ASSERT_TRUE(closeTo(fd, test::refCurvePoint(c, t),
                              test::kFdRelTol * (g.isU ? magnitude[k][0] : magnitude[0][k])))
              << describe(s) << " edge " << edgeName(e) << " order " << k << " t " << t;
        }
      }
    }
  }
}

TEST(BSplineSurface, HomogeneousCrossDerivativeIsPolynomial) {
  std::mt19937_64 rng(554);
  for (const auto& [s, samples] : geometryCases(rng))
    for (Edge e : kAllEdges)
      for (int k = 0; k <= 2; ++k) {
        const BSplineCurve c = s.homogeneousCrossDerivative(e, k);
        const EdgeGeometry g = edgeGeometry(s, e);
        ASSERT_FALSE(c.isRational());
        ASSERT_EQ(c.dim(), s.isRational() ? s.dim() + 1 : s.dim());
        ASSERT_EQ(c.domain(), g.along);
        const Matrix h = test::refHomogeneous(s.points(), s.weights());
        for (double t : test::sampleParams(rng, g.along, 40)) {
          const double u = g.isU ? g.fixed : t, v = g.isU ? t : g.fixed;
          const auto expected = test::refTensorSum(s.degreeU(), s.degreeV(), s.knotsU().values(),
                                                   s.knotsV().values(), s.numV(), h, u, v, k);
          const auto magnitude = test::refTensorSum(s.degreeU(), s.degreeV(), s.knotsU().values(),
                                                    s.knotsV().values(), s.numV(), h, u, v, k, true);
          const VecX& want = g.isU ? expected[k][0] : expected[0][k];
          const double bound = test::kRoundoffTol * ((g.isU ? magnitude[k][0] : magnitude[0][k]).maxCoeff() +
                                                     test::refCurveDerivMagnitudes(c, t, 0)[0]);
          ASSERT_TRUE(closeTo(want, test::refCurvePoint(c, t), bound))
              << describe(s) << " edge " << edgeName(e) << " order " << k << " t " << t;
        }
      }
}

TEST(BSplineSurface, CrossDerivativeRowsAreTheInwardDerivativesOfTheOrientedSurface) {
  // Block k of crossDerivativeRows(e, 3) against the brute-force tensor sum of the oriented surface's k-th
  // u-derivative at u' = start (orientedFrom is itself checked against the original surface above); orders above
  // the cross degree are zero.
  std::mt19937_64 rng(556);
  constexpr int kMaxOrder = 3;
  for (const auto& [s, samples] : geometryCases(rng))
    for (Edge e : kAllEdges) {
      const Matrix rows = s.crossDerivativeRows(e, kMaxOrder);
      const BSplineSurface o = s.orientedFrom(e);
      const Eigen::Index hd = s.isRational() ? s.dim() + 1 : s.dim();
      ASSERT_EQ(rows.cols(), (kMaxOrder + 1) * hd);
      ASSERT_EQ(rows.rows(), o.numV());
      const Matrix h = test::refHomogeneous(o.points(), o.weights());
      for (int k = 0; k <= kMaxOrder; ++k) {
        const BSplineCurve c(o.degreeV(), o.knotsV(), Matrix(rows.middleCols(k * hd, hd)));
        for (double t : test::sampleParams(rng, o.domainV(), 20)) {
          const double u0 = o.domainU().lo;
          const auto expected = test::refTensorSum(o.degreeU(), o.degreeV(), o.knotsU().values(),
                                                   o.knotsV().values(), o.numV(), h, u0, t, std::min(kMaxOrder, o.degreeU()));
          const auto magnitude = test::refTensorSum(o.degreeU(), o.degreeV(), o.knotsU().values(),
                                                    o.knotsV().values(), o.numV(), h, u0, t, std::min(kMaxOrder, o.degreeU()), true);
          const VecX want = k <= o.degreeU() ? VecX(expected[static_cast<size_t>(k)][0]) : VecX::Zero(hd);
          const double bound = test::kRoundoffTol * (magnitude[static_cast<size_t>(std::min(k, o.degreeU()))][0]
                                                         .maxCoeff() +
                                                     test::refCurveDerivMagnitudes(c, t, 0)[0]) +
                               test::kExactZeroFloor;
          ASSERT_TRUE(closeTo(want, test::refCurvePoint(c, t), bound))
              << describe(s) << " edge " << edgeName(e) << " order " << k << " t " << t;
        }
      }
    }
}

TEST(BSplineSurface, CrossDerivativeRowsOnTheStackAndOffItGiveTheSameBits) {
  // Up to second order and degree 15 crossDerivativeRows takes the basis from the stack (basisUpTo2), beyond that
  // from basisFunctionDerivatives: both are algorithm A2.3 with the same arithmetic, so the rows are the same bits
  // as the sum formed from basisFunctionDerivatives here. Degrees 1-5 and 16 (off the stack), orders 0-3.
  std::mt19937_64 rng(1602);
  std::vector<BSplineSurface> cases;
  for (int pu = 1; pu <= 5; ++pu)
    for (bool rational : {false, true})
      cases.push_back(randomSurface(rng, pu, 6 - pu, 3, {.rational = rational, .minSpans = 1, .maxSpans = 3}));
  cases.push_back(randomSurface(rng, 16, 2, 3, {.rational = true, .minSpans = 1, .maxSpans = 1}));
  cases.push_back(randomSurface(rng, 2, 16, 4, {.rational = false, .minSpans = 1, .maxSpans = 1}));
  for (const BSplineSurface& s : cases)
    for (Edge e : kAllEdges)
      for (int order = 0; order <= 3; ++order) {
        const Matrix rows = s.crossDerivativeRows(e, order);
        const bool uEdge = isUEdge(e), atEnd = e == Edge::U1 || e == Edge::V1;
        const int p = uEdge ? s.degreeU() : s.degreeV(), nAlong = uEdge ? s.numV() : s.numU();
        const KnotVector& kc = uEdge ? s.knotsU() : s.knotsV();
        const double c = atEnd ? kc.domain(p).hi : kc.domain(p).lo;
        const int d = s.dim(), hd = d + (s.isRational() ? 1 : 0), top = std::min(order, p);
        const int span = kc.findSpan(p, c);
        const Matrix N = basisFunctionDerivatives(kc, p, span, c, top);
        Matrix want = Matrix::Zero(nAlong, static_cast<Eigen::Index>(order + 1) * hd);
        for (int r = 0; r <= p; ++r)
          for (int k = 0; k <= top; ++k) {
            const double coef = (atEnd && k % 2 == 1) ? -N(k, r) : N(k, r);
            if (coef == 0.0) continue;
            for (int j = 0; j < nAlong; ++j) {
              const int flat = uEdge ? (span - p + r) * s.numV() + j : j * s.numV() + (span - p + r);
              const double cw = coef * (s.isRational() ? s.weights()[flat] : 1.0);
              want.block(j, static_cast<Eigen::Index>(k) * hd, 1, d) += cw * s.points().row(flat);
              if (s.isRational()) want(j, static_cast<Eigen::Index>(k) * hd + d) += cw;
            }
          }
        ASSERT_EQ(rows.rows(), want.rows());
        ASSERT_EQ(rows.cols(), want.cols());
        for (Eigen::Index i = 0; i < want.size(); ++i)
          ASSERT_EQ(rows.data()[i], want.data()[i]) << describe(s) << " edge " << edgeName(e) << " order " << order;
      }
}

/// Parameters in u and in v: the domain's ends, every knot, then `count` uniformly random ones.
std::pair<std::vector<double>, std::vector<double>> endsKnotsAndRandomParams(std::mt19937_64& rng,
                                                                            const BSplineSurface& s, int count) {
  const Interval du = s.domainU(), dv = s.domainV();
  std::vector<double> us{du.lo, du.hi}, vs{dv.lo, dv.hi};
  for (double k : s.knotsU().values()) us.push_back(k);
  for (double k : s.knotsV().values()) vs.push_back(k);
  for (int i = 0; i < count; ++i) {
    us.push_back(uniformReal(rng, du.lo, du.hi));
    vs.push_back(uniformReal(rng, dv.lo, dv.hi));
  }
  return {us, vs};
}

TEST(BSplineSurface, PointAndFirstDerivativesWithCompileTimeDegreesGiveTheSameBits) {
  // pointAndFirstDerivatives runs its loops with the degrees known at compile time up to degree 3: the same
  // operations in the same order as with run-time degrees, so the same bits. Degrees 1-4 in each direction (4:
  // the run-time loops on both routes), rational and polynomial, parameters inside, on knots and at the ends.
  std::mt19937_64 rng(2611);
  for (int pu = 1; pu <= 4; ++pu)
    for (int pv = 1; pv <= 4; ++pv)
      for (bool rational : {false, true}) {
        const BSplineSurface s =
            randomSurface(rng, pu, pv, 3, {.rational = rational, .minSpans = 1, .maxSpans = 4});
        const auto [us, vs] = endsKnotsAndRandomParams(rng, s, 200);
        for (size_t i = 0; i < us.size(); ++i)
          for (size_t j : {i % vs.size(), (i * 7 + 3) % vs.size()}) {
            Vec3 p0, u0, v0, p1, u1, v1, p2, u2, v2;
            detail::pointAndFirstDerivativesFast(s, us[i], vs[j], false, p0, u0, v0);
            detail::pointAndFirstDerivativesFast(s, us[i], vs[j], true, p1, u1, v1);
            s.pointAndFirstDerivatives(us[i], vs[j], p2, u2, v2);
            auto bits = [](double x) { return std::bit_cast<std::uint64_t>(x); };
            for (int k = 0; k < 3; ++k) {
              ASSERT_EQ(bits(p0[k]), bits(p1[k])) << describe(s);
              ASSERT_EQ(bits(u0[k]), bits(u1[k])) << describe(s);
              ASSERT_EQ(bits(v0[k]), bits(v1[k])) << describe(s);
              ASSERT_EQ(bits(p1[k]), bits(p2[k])) << describe(s);
              ASSERT_EQ(bits(u1[k]), bits(u2[k])) << describe(s);
              ASSERT_EQ(bits(v1[k]), bits(v2[k])) << describe(s);
            }
          }
      }
}

TEST(BSplineSurface, EvaluateIsTheZerothDerivativeBitForBitAndTheDeBoorPoint) {
  // evaluate() of a 3-D surface takes the allocation-free loops (degrees <= 15); derivatives(u, v, 0)[0][0] is the
  // general algorithm (NURBS Book A2.3 and A3.6, A4.4 when rational). The two must give the same bits, so that a
  // caller mixing them never sees a point move. Independently of both, the point is the de Boor point: tensor-product
  // de Boor recursion on the control net (homogeneous when rational), within a few ulps of the net's size.
  std::mt19937_64 rng(2811);
  std::vector<BSplineSurface> cases;
  for (int pu = 1; pu <= 5; ++pu)
    for (int pv : {1, 3, 4})
      for (bool rational : {false, true})
        cases.push_back(randomSurface(rng, pu, pv, 3, {.rational = rational, .minSpans = 1, .maxSpans = 4}));
  cases.push_back(randomSurface(rng, 16, 2, 3, {.rational = true, .minSpans = 1, .maxSpans = 1}));
  cases.push_back(randomSurface(rng, 2, 3, 2, {.rational = false, .minSpans = 1, .maxSpans = 3}));
  cases.push_back(randomSurface(rng, 3, 2, 4, {.rational = true, .minSpans = 1, .maxSpans = 3}));
  auto deBoor = [](const std::vector<double>& U, int p, double t, std::vector<VecX> d) {
    // d: the n control values; de Boor's algorithm on the span of t (the last non-empty span at the right end).
    const int n = static_cast<int>(d.size());
    int k = p;
    while (k + 1 < n && U[static_cast<size_t>(k + 1)] <= t) ++k;
    std::vector<VecX> w(d.begin() + (k - p), d.begin() + (k + 1));
    for (int r = 1; r <= p; ++r)
      for (int j = p; j >= r; --j) {
        const int i = k - p + j;
        const double a = (t - U[static_cast<size_t>(i)]) / (U[static_cast<size_t>(i + p - r + 1)] - U[static_cast<size_t>(i)]);
        w[static_cast<size_t>(j)] = (1.0 - a) * w[static_cast<size_t>(j - 1)] + a * w[static_cast<size_t>(j)];
      }
    return w[static_cast<size_t>(p)];
  };
  for (const BSplineSurface& s : cases) {
    const Matrix h = s.homogeneous();
    const double size = h.leftCols(s.dim()).cwiseAbs().maxCoeff();
    const auto [us, vs] = endsKnotsAndRandomParams(rng, s, 60);
    for (size_t i = 0; i < us.size(); ++i) {
      const double u = us[i], v = vs[(i * 7 + 3) % vs.size()];
      const VecX fast = s.evaluate(u, v), general = s.derivatives(u, v, 0)[0][0];
      ASSERT_EQ(fast.size(), s.dim()) << describe(s);
      ASSERT_EQ(general.size(), s.dim()) << describe(s);
      for (Eigen::Index k = 0; k < fast.size(); ++k)
        ASSERT_EQ(std::bit_cast<std::uint64_t>(fast[k]), std::bit_cast<std::uint64_t>(general[k]))
            << describe(s) << " at (" << u << ", " << v << ")";
      std::vector<VecX> columns;
      for (int a = 0; a < s.numU(); ++a) {
        std::vector<VecX> row;
        for (int b = 0; b < s.numV(); ++b) row.push_back(h.row(a * s.numV() + b).transpose());
        columns.push_back(deBoor(s.knotsV().values(), s.degreeV(), v, row));
      }
      const VecX hp = deBoor(s.knotsU().values(), s.degreeU(), u, columns);
      const VecX want = s.isRational() ? VecX(hp.head(s.dim()) / hp[s.dim()]) : hp;
      EXPECT_LT((fast - want).norm(), 1e-12 * size) << describe(s) << " at (" << u << ", " << v << ")";
    }
  }
}

TEST(BSplineSurface, OrientedFromMakesTheEdgeU0) {
  std::mt19937_64 rng(555);
  for (const auto& [s, samples] : geometryCases(rng)) {
    const Interval du = s.domainU(), dv = s.domainV();
    for (Edge e : kAllEdges) {
      const BSplineSurface o = s.orientedFrom(e);
      const EdgeGeometry g = edgeGeometry(s, e);
      // The edge parameter runs along v' over the same interval; u' starts at the edge and goes inwards.
      ASSERT_EQ(o.domainV(), g.along) << describe(s) << " edge " << edgeName(e);
      const auto map = [&](double u, double v) -> Vec2 {
        switch (e) {
          case Edge::U0:
            return {u, v};
          case Edge::U1:
            return {du.lo + du.hi - u, v};
          case Edge::V0:
            return {v, u};
          case Edge::V1:
            return {v, dv.lo + dv.hi - u};
        }
        return {};
      };
      ASSERT_TRUE(sameSurface(s, o, rng, samples / 4, map)) << describe(s) << " edge " << edgeName(e);
      // S'(u'_min, t) is the original edge at the same parameter t.
      const double u0 = o.domainU().lo;
      ASSERT_TRUE(test::agreeAt(
          test::sampleParams(rng, g.along, 200),
          [&, &surface = s](double t) {
            return g.isU ? refSurfacePoint(surface, g.fixed, t) : refSurfacePoint(surface, t, g.fixed);
          },
          [&](double t) { return refSurfacePoint(o, u0, t); }, test::controlScale(s.points()),
          test::kGeometryRelTol))
          << describe(s) << " edge " << edgeName(e);
    }
  }
}

// ---------------------------------------------------------------------------------------------------------------------
// Batch evaluation
// ---------------------------------------------------------------------------------------------------------------------

TEST(GridEvaluator, MatchesBruteForceOnRandomGrids) {
  std::mt19937_64 rng(561);
  for (int trial = 0; trial < 16; ++trial) {
    const BSplineSurface s = randomSurface(rng, uniformInt(rng, 1, 5), uniformInt(rng, 1, 5), 3,
                                           {.rational = trial % 2 == 1, .clamped = trial % 5 != 4});
    std::vector<double> us = test::sampleParams(rng, s.domainU(), uniformInt(rng, 2, 25));
    std::vector<double> vs = test::sampleParams(rng, s.domainV(), uniformInt(rng, 2, 25));
    for (double b : interiorBreakpoints(s.knotsU().values(), s.domainU())) us.push_back(b);
    if (trial % 2 == 0) {
      std::sort(us.begin(), us.end());
      std::sort(vs.begin(), vs.end());
    }
    const GridEvaluator grid(s, us, vs);
    ASSERT_EQ(grid.numU(), static_cast<int>(us.size()));
    ASSERT_EQ(grid.numV(), static_cast<int>(vs.size()));
    Matrix pts, du, dv;
    grid.evaluate(&pts, &du, &dv);
    const int n = static_cast<int>(us.size() * vs.size());
    ASSERT_EQ(pts.rows(), n);
    ASSERT_EQ(pts.cols(), 3);
    ASSERT_EQ(du.rows(), n);
    ASSERT_EQ(dv.rows(), n);
    Matrix onlyPts, onlyDv;
    grid.evaluate(&onlyPts, nullptr, nullptr);
    grid.evaluate(nullptr, nullptr, &onlyDv);
    for (size_t a = 0; a < us.size(); ++a)
      for (size_t b = 0; b < vs.size(); ++b) {
        const int row = static_cast<int>(a * vs.size() + b);
        const auto expected = refSurfaceDerivs(s, us[a], vs[b], 1);
        const auto magnitude = refSurfaceDerivMagnitudes(s, us[a], vs[b], 1);
        ASSERT_TRUE(closeTo(expected[0][0], pts.row(row).transpose(), test::kRoundoffTol * magnitude[0][0]))
            << describe(s) << " at " << us[a] << "," << vs[b];
        ASSERT_TRUE(closeTo(expected[1][0], du.row(row).transpose(), test::kRoundoffTol * magnitude[1][0]))
            << describe(s) << " at " << us[a] << "," << vs[b];
        ASSERT_TRUE(closeTo(expected[0][1], dv.row(row).transpose(), test::kRoundoffTol * magnitude[0][1]))
            << describe(s) << " at " << us[a] << "," << vs[b];
        // And the same values as seam's own derivatives() (the pointwise route).
        const auto lib = s.derivatives(us[a], vs[b], 1);
        ASSERT_TRUE(closeTo(lib[0][0], pts.row(row).transpose(), test::kRoundoffTol * magnitude[0][0]));
        ASSERT_TRUE(closeTo(lib[1][0], du.row(row).transpose(), test::kRoundoffTol * magnitude[1][0]));
        ASSERT_TRUE(closeTo(lib[0][1], dv.row(row).transpose(), test::kRoundoffTol * magnitude[0][1]));
        ASSERT_EQ(Matrix(onlyPts.row(row)), Matrix(pts.row(row)));
        ASSERT_EQ(Matrix(onlyDv.row(row)), Matrix(dv.row(row)));
      }
  }
}

// ---------------------------------------------------------------------------------------------------------------------
// Construction
// ---------------------------------------------------------------------------------------------------------------------

TEST(BSplineSurface, CreateValidatesInput) {
  const std::vector<double> ku = {0, 0, 0, 1, 1, 1};  // degree 2, 3 points
  const std::vector<double> kv = {0, 0, 0.5, 1, 1};   // degree 1, 3 points
  std::mt19937_64 rng(571);
  const Matrix pts = test::randomMatrix(rng, 9, 3);
  VecX w = VecX::Constant(9, 0.8);
  ASSERT_TRUE(BSplineSurface::create(2, 1, ku, kv, 3, 3, pts).isOk());
  const auto good = BSplineSurface::create(2, 1, ku, kv, 3, 3, pts, w);
  ASSERT_TRUE(good.isOk()) << good.status().message();
  EXPECT_TRUE(good->isRational());
  EXPECT_EQ(good->numU(), 3);
  EXPECT_EQ(good->numV(), 3);
  EXPECT_EQ(good->weight(1, 2), 0.8);

  const auto status = [](const Result<BSplineSurface>& r) { return r.status(); };
  // Point count does not match numU * numV.
  EXPECT_TRUE(failsMentioning(status(BSplineSurface::create(2, 1, ku, kv, 3, 3, Matrix(pts.topRows(8)))),
                              {"point", "9", "8"}));
  // Knot vectors of the wrong size (each direction); the message says which direction.
  EXPECT_TRUE(failsMentioning(status(BSplineSurface::create(2, 1, {0, 0, 0, 1, 1}, kv, 3, 3, pts)), {"u"}));
  EXPECT_TRUE(failsMentioning(status(BSplineSurface::create(2, 1, ku, {0, 0, 1, 1}, 3, 3, pts)), {"v"}));
  // End multiplicity above degree + 1 in u (which here also leaves an empty domain).
  EXPECT_TRUE(failsMentioning(status(BSplineSurface::create(2, 1, {0, 0, 0, 0, 1, 1}, kv, 3, 3, pts)),
                              {"multiplicity", "domain"}));
  // Non-finite point, bad weights.
  Matrix bad = pts;
  bad(4, 2) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_TRUE(failsMentioning(status(BSplineSurface::create(2, 1, ku, kv, 3, 3, bad)), {"finite", "nan"}));
  VecX bw = w;
  bw[5] = -0.1;
  EXPECT_TRUE(failsMentioning(status(BSplineSurface::create(2, 1, ku, kv, 3, 3, pts, bw)), {"weight"}));
  EXPECT_TRUE(
      failsMentioning(status(BSplineSurface::create(2, 1, ku, kv, 3, 3, pts, VecX::Ones(4))), {"weight"}));
}

}  // namespace
}  // namespace seam

namespace seam {
namespace {

TEST(BSplineSurface, DerivativePatchesAreThePartialsSpanBySpan) {
  // homogeneousDerivativePatches(ku, kv) on span (a, b), at the local point of (u, v), against the brute-force
  // tensor sum of basis-function derivatives. Cases: the random geometry cases, a C^0 knot (multiplicity p, so the
  // first derivative net has a full-multiplicity knot and is cut there) and a span 1e-7 long (whose Bezier points
  // agree to 7 digits: the partials must keep their relative accuracy there).
  std::mt19937_64 rng(5581);
  // (surface, reference): knot insertion does not change the geometry, so the surfaces with an inserted C^0 knot
  // or sliver span are checked against the partials of the surface they came from (well conditioned there).
  std::vector<std::pair<BSplineSurface, BSplineSurface>> surfaces;
  for (const auto& c : geometryCases(rng)) surfaces.emplace_back(c.surface, c.surface);
  const BSplineSurface base = randomSurface(rng, 3, 2, 3, {.rational = true, .minSpans = 2, .maxSpans = 3});
  const Interval du = base.domainU();
  const double mid = du.lo + 0.437 * du.length();
  surfaces.emplace_back(base.withKnotInsertedU(mid, 3), base);
  surfaces.emplace_back(base.withKnotInsertedU(mid, 1).withKnotInsertedU(mid + 1e-7 * du.length(), 1), base);
  const std::array<std::array<int, 2>, 6> orders{{{0, 0}, {1, 0}, {0, 1}, {2, 0}, {1, 1}, {0, 2}}};
  for (const auto& [s, ref] : surfaces) {
    const std::vector<BezierPatchPiece> pieces = s.bezierPatches();
    int nV = 0;
    for (const auto& p : pieces) nV = std::max(nV, p.spanV + 1);
    const Matrix h = test::refHomogeneous(ref.points(), ref.weights());
    for (const auto& [ku, kv] : orders) {
      const std::vector<BernsteinPatch> d = s.homogeneousDerivativePatches(ku, kv);
      ASSERT_EQ(d.size(), pieces.size()) << describe(s);
      for (const BezierPatchPiece& p : pieces)
        for (int k = 0; k < 3; ++k) {
          // A point inside the span (the sliver included), away from its ends.
          const double x = uniformReal(rng, 0.05, 0.95), y = uniformReal(rng, 0.05, 0.95);
          const double u = p.u.lo + x * p.u.length(), v = p.v.lo + y * p.v.length();
          const auto want = test::refTensorSum(ref.degreeU(), ref.degreeV(), ref.knotsU().values(),
                                               ref.knotsV().values(), ref.numV(), h, u, v, 2);
          const auto mag = test::refTensorSum(ref.degreeU(), ref.degreeV(), ref.knotsU().values(),
                                              ref.knotsV().values(), ref.numV(), h, u, v, 2, true);
          const VecX got = d[static_cast<size_t>(p.spanU * nV + p.spanV)](x, y);
          const double tol = 1e-11 * (mag[ku][kv].maxCoeff() + want[ku][kv].norm()) + test::kExactZeroFloor;
          ASSERT_LE((got - want[ku][kv]).norm(), tol)
              << describe(s) << " order (" << ku << ", " << kv << ") span (" << p.spanU << ", " << p.spanV << ")";
        }
    }
  }
}

// The Bernstein polynomial of a Bezier patch at any (x, y), [0,1] or beyond, as explicit sums of binomial terms
// (rational: the homogeneous sum divided by its weight sum); `mag` gets the sum of the terms' magnitudes.
VecX explicitBernstein(const BezierPatch& b, double x, double y, double& mag) {
  auto basis = [](int n, int i, double t) {
    return std::tgamma(n + 1.0) / (std::tgamma(i + 1.0) * std::tgamma(n - i + 1.0)) * std::pow(t, i) *
           std::pow(1.0 - t, n - i);
  };
  const auto d = b.points().cols();
  VecX num = VecX::Zero(d);
  double den = 0.0;
  mag = 0.0;
  for (int i = 0; i <= b.degreeU(); ++i)
    for (int j = 0; j <= b.degreeV(); ++j) {
      const double c = basis(b.degreeU(), i, x) * basis(b.degreeV(), j, y) * b.weight(i, j);
      num += c * b.point(i, j).transpose();
      den += c;
      mag += std::abs(c) * b.point(i, j).norm();
    }
  return num / den;
}

// detail::extendedSurface (the domain of a trimmed face whose pcurves run past its surface's bounds, issue 34 §1): inside the old
// domain the surface is unchanged; beyond it, it is the polynomial of the end piece continued, here the end piece's
// Bernstein form evaluated outside [0,1] by explicit sums. Random degrees 1..4, uneven and unclamped knots, rational
// half of the time, one side or both extended by up to 10 % of the domain (real overhangs are below 1 %).
TEST(BSplineSurfaceExtension, ContinuesTheEndPiecesExactly) {
  std::mt19937_64 rng(20261129);
  int checkedOutside = 0, refused = 0;
  for (int trial = 0; trial < 80; ++trial) {
    test::RandomSplineOptions o;
    o.rational = trial % 2 == 1;
    o.clamped = trial % 3 != 0;
    const int pv = uniformInt(rng, 1, 4), pu = uniformInt(rng, 1, 4);  // drawn last argument first (test_helpers.h)
    BSplineSurface s = randomSurface(rng, pu, pv, 3, o);
    if (o.rational)  // weights as CAD systems write them (neighbours within a factor 1.6; 0.3..3 continued by
                     // 10 % reaches negative control weights in most nets, which extendedSurface refuses)
      s = BSplineSurface(s.degreeU(), s.degreeV(), s.knotsU(), s.knotsV(), s.numU(), s.numV(), s.points(),
                         test::randomWeights(rng, s.numU() * s.numV(), 0.8, 1.25));
    const Interval du = s.domainU(), dv = s.domainV();
    auto grow = [&](double len) { return uniformInt(rng, 0, 3) == 0 ? 0.0 : uniformReal(rng, 0.0, 0.1) * len; };
    const Interval U{du.lo - grow(du.length()), du.hi + grow(du.length())};
    const Interval V{dv.lo - grow(dv.length()), dv.hi + grow(dv.length())};
    const Result<BSplineSurface> e = detail::extendedSurface(s, U, V);
    if (!e && s.isRational() && e.status().message().find("weight") != std::string::npos) {
      ++refused;  // random weights continued far enough can reach zero: said, not written
      continue;
    }
    ASSERT_TRUE(e.isOk()) << describe(s) << ": " << e.status().message();
    EXPECT_EQ(e->domainU(), U);
    EXPECT_EQ(e->domainV(), V);
    EXPECT_EQ(e->isRational(), s.isRational());
    const std::vector<BezierPatchPiece> pieces = s.bezierPatches();
    for (int k = 0; k < 60; ++k) {
      const double u = uniformReal(rng, U.lo, U.hi), v = uniformReal(rng, V.lo, V.hi);
      const double cu = std::clamp(u, du.lo, du.hi), cv = std::clamp(v, dv.lo, dv.hi);
      const auto piece = std::find_if(pieces.begin(), pieces.end(), [&](const BezierPatchPiece& p) {
        return p.u.contains(cu) && p.v.contains(cv);
      });
      ASSERT_NE(piece, pieces.end());
      double mag = 0.0;
      const VecX want = explicitBernstein(piece->patch, (u - piece->u.lo) / piece->u.length(),
                                          (v - piece->v.lo) / piece->v.length(), mag);
      const VecX got = e->evaluate(u, v);
      ASSERT_LE((got - want).norm(), 1e-10 * mag + test::kExactZeroFloor)
          << describe(s) << " at (" << u << ", " << v << "), domain [" << du.lo << ", " << du.hi << "] x ["
          << dv.lo << ", " << dv.hi << "]";
      checkedOutside += (u != cu || v != cv) ? 1 : 0;
    }
  }
  EXPECT_GT(checkedOutside, 600);
  EXPECT_LT(refused, 10);
  // A domain that does not contain the surface's is an error, not a cut.
  std::mt19937_64 rng2(7);
  const BSplineSurface s = randomSurface(rng2, 3, 3, 3);
  EXPECT_FALSE(detail::extendedSurface(s, {s.domainU().lo + 0.1, s.domainU().hi}, s.domainV()).isOk());
  EXPECT_FALSE(
      detail::extendedSurface(s, {s.domainU().lo, std::numeric_limits<double>::infinity()}, s.domainV()).isOk());
}

}  // namespace
}  // namespace seam
