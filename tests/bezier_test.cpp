// Bezier curves and patches (include/seam/spline/bezier.h): evaluation and derivatives against explicit
// Bernstein sums and the quotient rule (test_helpers.h), conversion to single-span B-splines and back, and
// exact rational conics (the quarter circle with weights 1, sqrt(2)/2, 1 lies on the unit circle).
#include "seam/spline/bezier.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "seam/spline/bspline_curve.h"
#include "seam/spline/bspline_surface.h"
#include "test_helpers.h"

namespace seam {
namespace {

using test::closeTo;
using test::randomMatrix;
using test::randomWeights;
using test::refBezierCurveDerivs;
using test::refBezierPatchDerivs;
using test::uniformInt;
using test::uniformReal;

BezierCurve randomBezierCurve(std::mt19937_64& rng, int degree, int dim, bool rational) {
  const VecX w = rational ? randomWeights(rng, degree + 1) : VecX();  // drawn last argument first (test_helpers.h)
  return BezierCurve(randomMatrix(rng, degree + 1, dim, -5.0, 5.0), w);
}

BezierPatch randomBezierPatch(std::mt19937_64& rng, int du, int dv, int dim, bool rational) {
  const int n = (du + 1) * (dv + 1);
  const VecX w = rational ? randomWeights(rng, n) : VecX();  // (drawn last argument first, as above)
  return BezierPatch(du, dv, randomMatrix(rng, n, dim, -5.0, 5.0), w);
}

/// Round-off scale of the explicit sums: the B-spline magnitude helper on Bezier knots (a Bezier curve is the
/// single-span B-spline on them).
VecX curveMagnitudes(const BezierCurve& c, double t, int order) {
  return test::refCurveDerivMagnitudes(c.degree(), KnotVector::bezier(c.degree()).values(), c.points(),
                                       c.weights(), t, order);
}

std::vector<double> unitParams(std::mt19937_64& rng, int count) {
  return test::sampleParams(rng, Interval{0.0, 1.0}, count);
}

// ---------------------------------------------------------------------------------------------------------------------
// Curves
// ---------------------------------------------------------------------------------------------------------------------

TEST(BezierCurve, EvaluateAndDerivativesMatchExplicitBernsteinSums) {
  constexpr int kOrder = 4;
  std::mt19937_64 rng(601);
  for (int p = 0; p <= 9; ++p)
    for (int dim : {2, 3})
      for (bool rational : {false, true}) {
        const BezierCurve c = randomBezierCurve(rng, p, dim, rational);
        ASSERT_EQ(c.degree(), p);
        ASSERT_EQ(c.dim(), dim);
        ASSERT_EQ(c.isRational(), rational);
        for (double t : unitParams(rng, 15)) {
          const Matrix expected = refBezierCurveDerivs(c.points(), c.weights(), t, kOrder);
          const VecX magnitude = curveMagnitudes(c, t, kOrder);
          ASSERT_TRUE(closeTo(expected.row(0).transpose(), c.evaluate(t), test::kRoundoffTol * magnitude[0]))
              << "degree " << p << " t " << t;
          const Matrix got = c.derivatives(t, kOrder);
          ASSERT_EQ(got.rows(), kOrder + 1);
          ASSERT_EQ(got.cols(), dim);
          for (int k = 0; k <= kOrder; ++k)
            ASSERT_TRUE(closeTo(expected.row(k).transpose(), got.row(k).transpose(),
                                test::kRoundoffTol * magnitude[k] + test::kExactZeroFloor))
                << "degree " << p << (rational ? " rational" : "") << " t " << t << " order " << k;
        }
      }
}

TEST(BezierCurve, RationalDerivativesMatchFiniteDifferencesOfTheQuotient) {
  std::mt19937_64 rng(602);
  constexpr double kStep = 1.0 / test::kFdStepDivisor;  // the single span has length 1
  for (int p = 1; p <= 9; ++p) {
    const BezierCurve c = randomBezierCurve(rng, p, 3, true);
    for (int s = 0; s < 6; ++s) {
      const double t = uniformReal(rng, 0.1, 0.9);
      const Matrix got = c.derivatives(t, 3);
      const VecX magnitude = curveMagnitudes(c, t, 3);
      for (int k = 1; k <= 3; ++k) {
        const VecX fd = test::richardsonDerivative(
            [&](double x) {
              return VecX(refBezierCurveDerivs(c.points(), c.weights(), x, k - 1).row(k - 1).transpose());
            },
            t, kStep);
        ASSERT_TRUE(closeTo(fd, got.row(k).transpose(), test::kFdRelTol * magnitude[k]))
            << "degree " << p << " order " << k;
      }
    }
  }
}

TEST(BezierCurve, HomogeneousNumeratorAndDenominator) {
  std::mt19937_64 rng(603);
  for (int p = 0; p <= 7; ++p)
    for (bool rational : {false, true}) {
      const BezierCurve c = randomBezierCurve(rng, p, 3, rational);
      const BernsteinPoly h = c.homogeneous(), num = c.numerator(), den = c.denominator();
      ASSERT_EQ(h.degree(), p);
      ASSERT_EQ(h.dim(), rational ? 4 : 3);
      ASSERT_EQ(num.dim(), 3);
      ASSERT_EQ(den.dim(), 1);
      const Matrix expectedH = test::refHomogeneous(c.points(), c.weights());
      ASSERT_LE(test::maxAbs(Matrix(h.coeffs() - expectedH)), test::kFewUlps * test::maxAbs(expectedH));
      for (double t : unitParams(rng, 8)) {
        const VecX point = refBezierCurveDerivs(c.points(), c.weights(), t, 0).row(0).transpose();
        const double w = den.scalar(t);
        if (!rational) {
          ASSERT_NEAR(w, 1.0, test::kFewUlps);
        }
        ASSERT_TRUE(closeTo(point, num(t) / w, test::kRoundoffTol * test::maxAbs(c.points()))) << "t " << t;
      }
    }
}

TEST(BezierCurve, ToBSplineIsTheSameCurveOnTheInterval) {
  std::mt19937_64 rng(604);
  for (int p = 1; p <= 9; ++p)
    for (bool rational : {false, true}) {
      const BezierCurve c = randomBezierCurve(rng, p, 3, rational);
      const double a = uniformReal(rng, -3.0, 3.0), b = a + uniformReal(rng, 0.1, 5.0);
      const BSplineCurve s = c.toBSpline(a, b);
      ASSERT_EQ(s.degree(), p);
      ASSERT_EQ(s.isRational(), rational);
      ASSERT_EQ(s.numPoints(), p + 1);
      ASSERT_EQ(s.knots().values(), KnotVector::bezier(p, a, b).values());
      ASSERT_TRUE(test::agreeAt(
          test::sampleParams(rng, Interval{a, b}, 200),
          [&](double t) { return test::refBezierCurvePoint(c.points(), c.weights(), (t - a) / (b - a)); },
          [&](double t) { return test::refCurvePoint(s, t); }, test::controlScale(c.points()),
          test::kGeometryRelTol))
          << "degree " << p;
      // Default interval [0,1].
      ASSERT_EQ(c.toBSpline().domain(), (Interval{0.0, 1.0}));
    }
}

TEST(BezierCurve, FromHomogeneousRoundTrip) {
  std::mt19937_64 rng(605);
  for (int p = 0; p <= 7; ++p) {
    const BezierCurve c = randomBezierCurve(rng, p, 3, true);
    const BezierCurve back =
        BezierCurve::fromHomogeneous(BernsteinPoly(test::refHomogeneous(c.points(), c.weights())));
    ASSERT_TRUE(back.isRational());
    ASSERT_EQ(back.dim(), 3);
    ASSERT_LE(test::maxAbs(Matrix(back.points() - c.points())), test::kFewUlps * test::maxAbs(c.points()));
    ASSERT_LE(test::maxAbs(VecX(back.weights() - c.weights())), test::kFewUlps * test::maxAbs(c.weights()));
    // Through seam's own homogeneous(): the same geometry.
    const BezierCurve again = BezierCurve::fromHomogeneous(c.homogeneous());
    for (double t : unitParams(rng, 10))
      ASSERT_TRUE(closeTo(test::refBezierCurvePoint(c.points(), c.weights(), t),
                          test::refBezierCurvePoint(again.points(), again.weights(), t),
                          test::kGeometryRelTol * test::controlScale(c.points())));
  }
  // A polynomial curve written homogeneously with unit weights is the same curve.
  const BezierCurve poly = randomBezierCurve(rng, 4, 3, false);
  const BezierCurve fromUnit =
      BezierCurve::fromHomogeneous(BernsteinPoly(test::refHomogeneous(poly.points(), VecX::Ones(5))));
  for (double t : unitParams(rng, 10))
    ASSERT_TRUE(closeTo(test::refBezierCurvePoint(poly.points(), VecX(), t),
                        test::refBezierCurvePoint(fromUnit.points(), fromUnit.weights(), t),
                        test::kGeometryRelTol * test::controlScale(poly.points())));
}

// Exact conics
// ------------------------------------------------------------------------------------------------------

/// Quarter of the unit circle: (1,0), (1,1), (0,1) with weights 1, sqrt(2)/2, 1 (The NURBS Book, Ex. 7.1).
BezierCurve quarterCircle() {
  Matrix p(3, 3);
  p << 1, 0, 0, 1, 1, 0, 0, 1, 0;
  VecX w(3);
  w << 1, std::sqrt(2.0) / 2, 1;
  return BezierCurve(p, w);
}

/// |C|^2 = 1 identically, so C.C' = 0 and C.C'' + |C'|^2 = 0: exact identities that also check the rational
/// first and second derivatives.
void expectOnUnitCircle(const Matrix& d, double t) {
  const Vec3 c = d.row(0).transpose(), c1 = d.row(1).transpose(), c2 = d.row(2).transpose();
  EXPECT_NEAR(c.norm(), 1.0, test::kFewUlps) << "t " << t;
  EXPECT_NEAR(c.dot(c1), 0.0, test::kFewUlps * (1 + c1.norm())) << "t " << t;
  EXPECT_NEAR(c.dot(c2) + c1.squaredNorm(), 0.0, test::kIdentityTol * (1 + c2.norm() + c1.squaredNorm()))
      << "t " << t;
}

TEST(BezierCurve, RationalQuarterCircleHasRadiusOne) {
  const BezierCurve q = quarterCircle();
  for (int i = 0; i <= 1000; ++i) {
    const double t = i / 1000.0;
    expectOnUnitCircle(q.derivatives(t, 2), t);
    EXPECT_NEAR(q.evaluate(t).norm(), 1.0, test::kFewUlps);
  }
  // Midpoint is (sqrt(2)/2, sqrt(2)/2): the arc is symmetric.
  EXPECT_NEAR(q.evaluate(0.5)[0], std::sqrt(0.5), test::kFewUlps);
  EXPECT_NEAR(q.evaluate(0.5)[1], std::sqrt(0.5), test::kFewUlps);
}

TEST(BezierCurve, FullNurbsCircleHasRadiusOne) {
  // The nine-point degree-2 NURBS circle (The NURBS Book, Ex. 7.2): knots
  // {0,0,0,1/4,1/4,1/2,1/2,3/4,3/4,1,1,1}.
  const double w = std::sqrt(2.0) / 2;
  Matrix p(9, 3);
  p << 1, 0, 0, 1, 1, 0, 0, 1, 0, -1, 1, 0, -1, 0, 0, -1, -1, 0, 0, -1, 0, 1, -1, 0, 1, 0, 0;
  VecX wt(9);
  wt << 1, w, 1, w, 1, w, 1, w, 1;
  const auto created = BSplineCurve::create(2, {0, 0, 0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1, 1, 1}, p, wt);
  ASSERT_TRUE(created.isOk()) << created.status().message();
  const BSplineCurve& circle = *created;
  for (int i = 0; i <= 2000; ++i) {
    const double t = i / 2000.0;
    expectOnUnitCircle(circle.derivatives(t, 2), t);
  }
  // Its Bezier pieces are the four quarter circles.
  const auto pieces = circle.bezierPieces();
  ASSERT_EQ(pieces.size(), 4u);
  for (const auto& piece : pieces)
    for (int i = 0; i <= 100; ++i) EXPECT_NEAR(piece.curve.evaluate(i / 100.0).norm(), 1.0, test::kFewUlps);
  // Degree elevation keeps it on the circle.
  const BSplineCurve elevated = circle.degreeElevated(2);
  for (int i = 0; i <= 500; ++i) EXPECT_NEAR(elevated.evaluate(i / 500.0).norm(), 1.0, test::kFewUlps);
}

// ---------------------------------------------------------------------------------------------------------------------
// Patches
// ---------------------------------------------------------------------------------------------------------------------

TEST(BezierPatch, EvaluateAndDerivativesMatchExplicitBernsteinSums) {
  constexpr int kOrder = 3;
  std::mt19937_64 rng(611);
  for (int du = 0; du <= 6; ++du)
    for (int dv = 0; dv <= 6; dv += 2)
      for (bool rational : {false, true}) {
        const BezierPatch s = randomBezierPatch(rng, du, dv, 3, rational);
        ASSERT_EQ(s.degreeU(), du);
        ASSERT_EQ(s.degreeV(), dv);
        ASSERT_EQ(s.isRational(), rational);
        const int i = uniformInt(rng, 0, du), j = uniformInt(rng, 0, dv);
        ASSERT_EQ(Matrix(s.point(i, j)), Matrix(s.points().row(i * (dv + 1) + j)));
        ASSERT_EQ(s.weight(i, j), rational ? s.weights()[i * (dv + 1) + j] : 1.0);
        // Round-off scale from the B-spline magnitude helper (the patch is a single-span B-spline surface).
        const BSplineSurface asSpline(du, dv, KnotVector::bezier(du), KnotVector::bezier(dv), du + 1, dv + 1,
                                      s.points(), s.weights());
        for (const Vec2& uv : test::sampleParams2(rng, {0, 1}, {0, 1}, 10)) {
          const auto expected = refBezierPatchDerivs(du, dv, s.points(), s.weights(), uv[0], uv[1], kOrder);
          const auto magnitude = test::refSurfaceDerivMagnitudes(asSpline, uv[0], uv[1], kOrder);
          ASSERT_TRUE(
              closeTo(expected[0][0], s.evaluate(uv[0], uv[1]), test::kRoundoffTol * magnitude[0][0]));
          const auto got = s.derivatives(uv[0], uv[1], kOrder);
          for (int k = 0; k <= kOrder; ++k)
            for (int l = 0; k + l <= kOrder; ++l)
              ASSERT_TRUE(closeTo(expected[k][l], got[k][l],
                                  test::kRoundoffTol * magnitude[k][l] + test::kExactZeroFloor))
                  << "degrees " << du << "," << dv << (rational ? " rational" : "") << " at "
                  << uv.transpose() << " derivative (" << k << "," << l << ")";
        }
      }
}

TEST(BezierPatch, HomogeneousNumeratorAndDenominator) {
  std::mt19937_64 rng(612);
  for (bool rational : {false, true}) {
    const BezierPatch s = randomBezierPatch(rng, 3, 2, 3, rational);
    const BernsteinPatch h = s.homogeneous(), num = s.numerator(), den = s.denominator();
    ASSERT_EQ(h.degreeU(), 3);
    ASSERT_EQ(h.degreeV(), 2);
    ASSERT_EQ(h.dim(), rational ? 4 : 3);
    ASSERT_EQ(num.dim(), 3);
    ASSERT_EQ(den.dim(), 1);
    const Matrix expectedH = test::refHomogeneous(s.points(), s.weights());
    ASSERT_LE(test::maxAbs(Matrix(h.coeffs() - expectedH)), test::kFewUlps * test::maxAbs(expectedH));
    for (const Vec2& uv : test::sampleParams2(rng, {0, 1}, {0, 1}, 10)) {
      const VecX point = test::refBezierPatchPoint(3, 2, s.points(), s.weights(), uv[0], uv[1]);
      const double w = den(uv[0], uv[1])[0];
      ASSERT_TRUE(closeTo(point, num(uv[0], uv[1]) / w, test::kRoundoffTol * test::maxAbs(s.points())));
    }
  }
}

TEST(BezierPatch, ToBSplineAndFromHomogeneousRoundTrip) {
  std::mt19937_64 rng(613);
  for (int trial = 0; trial < 12; ++trial) {
    const int du = uniformInt(rng, 1, 6), dv = uniformInt(rng, 1, 6);
    const bool rational = trial % 2 == 1;
    const BezierPatch s = randomBezierPatch(rng, du, dv, 3, rational);
    const Interval iu{uniformReal(rng, -2, 2), 0}, iv{uniformReal(rng, -2, 2), 0};
    const Interval u{iu.lo, iu.lo + uniformReal(rng, 0.1, 3)}, v{iv.lo, iv.lo + uniformReal(rng, 0.1, 3)};
    const BSplineSurface b = s.toBSpline(u, v);
    ASSERT_EQ(b.degreeU(), du);
    ASSERT_EQ(b.degreeV(), dv);
    ASSERT_EQ(b.isRational(), rational);
    ASSERT_EQ(b.knotsU().values(), KnotVector::bezier(du, u.lo, u.hi).values());
    ASSERT_EQ(b.knotsV().values(), KnotVector::bezier(dv, v.lo, v.hi).values());
    ASSERT_TRUE(test::agreeAt2(
        test::sampleParams2(rng, u, v, 200),
        [&](double x, double y) {
          return test::refBezierPatchPoint(du, dv, s.points(), s.weights(), (x - u.lo) / u.length(),
                                           (y - v.lo) / v.length());
        },
        [&](double x, double y) { return test::refSurfacePoint(b, x, y); }, test::controlScale(s.points()),
        test::kGeometryRelTol));
    if (rational) {
      const BezierPatch back =
          BezierPatch::fromHomogeneous(BernsteinPatch(du, dv, test::refHomogeneous(s.points(), s.weights())));
      ASSERT_TRUE(back.isRational());
      ASSERT_EQ(back.degreeU(), du);
      ASSERT_LE(test::maxAbs(Matrix(back.points() - s.points())), test::kFewUlps * test::maxAbs(s.points()));
      ASSERT_LE(test::maxAbs(VecX(back.weights() - s.weights())), test::kFewUlps * test::maxAbs(s.weights()));
    }
  }
}

TEST(BezierPatch, RationalCylinderAndSphereAreExact) {
  const double w = std::sqrt(2.0) / 2;
  const double cw[3] = {1, w, 1};
  const Vec2 c[3] = {{1, 0}, {1, 1}, {0, 1}};
  // Quarter cylinder of radius 1: circle in u, straight line (degree 1) in z along v.
  Matrix cyl(6, 3);
  VecX cylW(6);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 2; ++j) {
      cyl.row(i * 2 + j) << c[i][0], c[i][1], 2.0 * j;
      cylW[i * 2 + j] = cw[i];
    }
  const BezierPatch cylinder(2, 1, cyl, cylW);
  // Octant of the unit sphere (revolution of the quarter meridian, weights w_i w_j).
  const double r[3] = {1, 1, 0}, z[3] = {0, 1, 1};
  Matrix sph(9, 3);
  VecX sphW(9);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      sph.row(i * 3 + j) << r[j] * c[i][0], r[j] * c[i][1], z[j];
      sphW[i * 3 + j] = cw[i] * cw[j];
    }
  const BezierPatch sphere(2, 2, sph, sphW);
  std::mt19937_64 rng(614);
  for (const Vec2& uv : test::sampleParams2(rng, {0, 1}, {0, 1}, 500)) {
    const VecX p = cylinder.evaluate(uv[0], uv[1]);
    EXPECT_NEAR(std::hypot(p[0], p[1]), 1.0, test::kFewUlps) << uv.transpose();
    EXPECT_NEAR(p[2], 2.0 * uv[1], test::kFewUlps);
    const auto d = sphere.derivatives(uv[0], uv[1], 1);
    const Vec3 q = d[0][0];
    EXPECT_NEAR(q.norm(), 1.0, test::kFewUlps) << uv.transpose();
    EXPECT_NEAR(q.dot(Vec3(d[1][0])), 0.0, test::kIdentityTol * (1 + d[1][0].norm()));
    EXPECT_NEAR(q.dot(Vec3(d[0][1])), 0.0, test::kIdentityTol * (1 + d[0][1].norm()));
  }
}

}  // namespace
}  // namespace seam
