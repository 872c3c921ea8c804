// B-spline / NURBS curves (include/seam/spline/bspline_curve.h) against brute-force evaluation (Cox-de Boor
// sums, quotient rule) and finite differences from test_helpers.h. Geometry-preserving operations are checked
// at 10^4 random parameters per case, relative error <= 1e-12 of the control-point scale, for degrees 1-7,
// random multiplicities, rational and polynomial, clamped and unclamped.
#include "seam/spline/bspline_curve.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
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
using test::randomCurve;
using test::refCurveDerivMagnitudes;
using test::refCurveDerivs;
using test::refCurvePoint;
using test::sameCurve;
using test::uniformInt;
using test::uniformReal;

/// Parameters per geometry-preservation check (the acceptance criterion).
constexpr int kGeometrySamples = 10000;
/// Fewer for the extra (unclamped) variants, to keep the suite fast.
constexpr int kExtraSamples = 1000;

struct CurveCase {
  BSplineCurve curve;
  int samples;
};

/// One case per degree 1..7, polynomial and rational (10^4 samples each), plus unclamped variants (fewer
/// samples).
std::vector<CurveCase> geometryCases(std::mt19937_64& rng, int dim = 3) {
  std::vector<CurveCase> cases;
  for (int p = 1; p <= 7; ++p)
    for (bool rational : {false, true}) {
      cases.push_back(
          {randomCurve(rng, p, dim, {.rational = rational, .clamped = true, .minSpans = 2, .maxSpans = 4}),
           kGeometrySamples});
      cases.push_back(
          {randomCurve(rng, p, dim, {.rational = rational, .clamped = false, .minSpans = 1, .maxSpans = 4}),
           kExtraSamples});
    }
  return cases;
}

/// A parameter strictly inside the domain and at least 1% of the domain away from every knot.
double freshParameter(std::mt19937_64& rng, const BSplineCurve& c) {
  const Interval d = c.domain();
  for (;;) {
    const double t = uniformReal(rng, d.lo, d.hi);
    bool ok = true;
    for (double k : c.knots().values()) ok = ok && std::abs(t - k) > 0.01 * d.length();
    if (ok) return t;
  }
}

/// Interior breakpoints of the domain with their multiplicities, from the raw knot values.
std::vector<std::pair<double, int>> interiorKnots(const BSplineCurve& c) {
  std::vector<std::pair<double, int>> out;
  const Interval d = c.domain();
  for (double b : test::distinctValues(c.knots().values()))
    if (b > d.lo && b < d.hi)
      out.emplace_back(b,
                       static_cast<int>(std::count(c.knots().values().begin(), c.knots().values().end(), b)));
  return out;
}

std::vector<double> mergedKnots(std::vector<double> knots, const std::vector<double>& extra) {
  knots.insert(knots.end(), extra.begin(), extra.end());
  std::sort(knots.begin(), knots.end());
  return knots;
}

// ---------------------------------------------------------------------------------------------------------------------
// Evaluation and derivatives
// ---------------------------------------------------------------------------------------------------------------------

TEST(BSplineCurve, EvaluateMatchesBruteForce) {
  std::mt19937_64 rng(401);
  for (int p = 1; p <= 7; ++p)
    for (int dim : {1, 2, 3, 4})
      for (bool rational : {false, true})
        for (bool clamped : {true, false}) {
          const BSplineCurve c = randomCurve(rng, p, dim, {.rational = rational, .clamped = clamped});
          ASSERT_EQ(c.degree(), p);
          ASSERT_EQ(c.dim(), dim);
          ASSERT_EQ(c.isRational(), rational);
          std::vector<double> ts = test::sampleParams(rng, c.domain(), 60);
          for (const auto& [b, m] : interiorKnots(c)) ts.push_back(b);
          for (double t : ts) {
            const double bound = test::kRoundoffTol * refCurveDerivMagnitudes(c, t, 0).maxCoeff();
            const VecX expected = refCurvePoint(c, t);
            ASSERT_TRUE(closeTo(expected, c.evaluate(t), bound)) << describe(c) << " t " << t;
            const Matrix d0 = c.derivatives(t, 0);
            ASSERT_EQ(d0.rows(), 1);
            ASSERT_TRUE(closeTo(expected, d0.row(0).transpose(), bound)) << describe(c) << " t " << t;
          }
        }
}

TEST(BSplineCurve, ClampedCurveInterpolatesEndPoints) {
  std::mt19937_64 rng(402);
  for (int p = 1; p <= 7; ++p)
    for (bool rational : {false, true}) {
      const BSplineCurve c = randomCurve(rng, p, 3, {.rational = rational});
      const double scale = test::controlScale(c.points());
      EXPECT_TRUE(
          closeTo(c.points().row(0).transpose(), c.evaluate(c.domain().lo), test::kRoundoffTol * scale));
      EXPECT_TRUE(closeTo(c.points().row(c.numPoints() - 1).transpose(), c.evaluate(c.domain().hi),
                          test::kRoundoffTol * scale));
    }
}

TEST(BSplineCurve, DerivativesMatchRecursiveFormula) {
  constexpr int kMaxOrder = 4;
  std::mt19937_64 rng(403);
  for (int p = 1; p <= 7; ++p)
    for (bool rational : {false, true})
      for (bool clamped : {true, false})
        for (int trial = 0; trial < 2; ++trial) {
          const BSplineCurve c = randomCurve(rng, p, 3, {.rational = rational, .clamped = clamped});
          std::vector<double> ts = test::sampleParams(rng, c.domain(), 25);
          for (const auto& [b, m] : interiorKnots(c)) ts.push_back(b);  // right-sided derivatives at knots
          for (double t : ts) {
            const Matrix got = c.derivatives(t, kMaxOrder);
            ASSERT_EQ(got.rows(), kMaxOrder + 1);
            ASSERT_EQ(got.cols(), 3);
            const Matrix expected = refCurveDerivs(c, t, kMaxOrder);
            const VecX magnitude = refCurveDerivMagnitudes(c, t, kMaxOrder);
            for (int k = 0; k <= kMaxOrder; ++k)
              ASSERT_TRUE(closeTo(expected.row(k).transpose(), got.row(k).transpose(),
                                  test::kRoundoffTol * magnitude[k] + test::kExactZeroFloor))
                  << describe(c) << " t " << t << " order " << k;
          }
        }
}

TEST(BSplineCurve, AllocationFreePathsMatchTheRecursiveFormula) {
  // point3 and derivatives2 (the projection and seam fast paths) against the brute-force recursion, degrees up to
  // 16 (one above the stack path, which then falls back to the general algorithm), at knots too.
  std::mt19937_64 rng(406);
  for (int p : {1, 2, 3, 5, 9, 15, 16})
    for (bool rational : {false, true})
      for (bool clamped : {true, false}) {
        const BSplineCurve c = randomCurve(rng, p, 3, {.rational = rational, .clamped = clamped});
        std::vector<double> ts = test::sampleParams(rng, c.domain(), 20);
        for (const auto& [b, m] : interiorKnots(c)) ts.push_back(b);
        for (double t : ts) {
          const Matrix expected = refCurveDerivs(c, t, 2);
          const VecX magnitude = refCurveDerivMagnitudes(c, t, 2);
          Vec3 x, d1, d2;
          c.derivatives2(t, x, d1, d2);
          const std::array<Vec3, 3> got{x, d1, d2};
          for (int k = 0; k <= 2; ++k)
            ASSERT_TRUE(closeTo(expected.row(k).transpose(), got[static_cast<size_t>(k)],
                                test::kRoundoffTol * magnitude[k] + test::kExactZeroFloor))
                << describe(c) << " t " << t << " order " << k;
          ASSERT_TRUE(closeTo(expected.row(0).transpose(), c.point3(t),
                              test::kRoundoffTol * magnitude[0] + test::kExactZeroFloor))
              << describe(c) << " t " << t;
        }
      }
}

TEST(BSplineCurve, PlaneCurveDerivatives1MatchTheRecursiveFormulaAndDerivativesBitForBit) {
  // derivatives1 (the pcurve correspondence's fast path) against the brute-force recursion, degrees up to 16 (one
  // above the stack path), at knots too; and bit for bit against rows 0 and 1 of derivatives(t, 1), whose values
  // the B-rep check reported before (its reports must not change).
  std::mt19937_64 rng(407);
  for (int p : {1, 2, 3, 5, 9, 15, 16})
    for (bool rational : {false, true})
      for (bool clamped : {true, false}) {
        const BSplineCurve c = randomCurve(rng, p, 2, {.rational = rational, .clamped = clamped});
        std::vector<double> ts = test::sampleParams(rng, c.domain(), 20);
        for (const auto& [b, m] : interiorKnots(c)) ts.push_back(b);
        for (double t : ts) {
          const Matrix expected = refCurveDerivs(c, t, 1);
          const VecX magnitude = refCurveDerivMagnitudes(c, t, 1);
          Vec2 x, d1;
          c.derivatives1(t, x, d1);
          ASSERT_TRUE(
              closeTo(expected.row(0).transpose(), x, test::kRoundoffTol * magnitude[0] + test::kExactZeroFloor))
              << describe(c) << " t " << t;
          ASSERT_TRUE(
              closeTo(expected.row(1).transpose(), d1, test::kRoundoffTol * magnitude[1] + test::kExactZeroFloor))
              << describe(c) << " t " << t;
          const Matrix general = c.derivatives(t, 1);
          for (int k = 0; k < 2; ++k) {
            ASSERT_EQ(general(0, k), x[k]) << describe(c) << " t " << t;
            ASSERT_EQ(general(1, k), d1[k]) << describe(c) << " t " << t;
          }
        }
      }
}

TEST(BSplineCurve, DerivativesMatchFiniteDifferencesOfTheQuotient) {
  // Derivative k from seam vs the Richardson central difference of the brute-force (k-1)-th derivative; for k
  // = 1 that is the difference quotient of the rational point A(t) / W(t) itself.
  constexpr int kMaxOrder = 4;
  std::mt19937_64 rng(404);
  for (int p = 1; p <= 7; ++p)
    for (bool rational : {false, true})
      for (int trial = 0; trial < 3; ++trial) {
        const BSplineCurve c = randomCurve(rng, p, 3, {.rational = rational, .clamped = trial != 2});
        for (int s = 0; s < 8; ++s) {
          const auto [t, spanLength] = test::paramInsideSpan(rng, c.knots().values(), p);
          const double h = spanLength / test::kFdStepDivisor;
          const Matrix got = c.derivatives(t, kMaxOrder);
          const VecX magnitude = refCurveDerivMagnitudes(c, t, kMaxOrder);
          for (int k = 1; k <= kMaxOrder; ++k) {
            const VecX fd = test::richardsonDerivative(
                [&](double x) { return VecX(refCurveDerivs(c, x, k - 1).row(k - 1).transpose()); }, t, h);
            ASSERT_TRUE(
                closeTo(fd, got.row(k).transpose(), test::kFdRelTol * magnitude[k] + test::kExactZeroFloor))
                << describe(c) << " t " << t << " order " << k;
          }
        }
      }
}

TEST(BSplineCurve, DerivativesBeyondDegreeVanishForPolynomials) {
  std::mt19937_64 rng(405);
  for (int p = 1; p <= 5; ++p) {
    const BSplineCurve c = randomCurve(rng, p, 3);
    const double t = freshParameter(rng, c);
    const Matrix d = c.derivatives(t, p + 2);
    ASSERT_EQ(d.rows(), p + 3);
    EXPECT_EQ(d.row(p + 1).cwiseAbs().maxCoeff(), 0.0);
    EXPECT_EQ(d.row(p + 2).cwiseAbs().maxCoeff(), 0.0);
  }
}

// ---------------------------------------------------------------------------------------------------------------------
// Knot insertion and refinement
// ---------------------------------------------------------------------------------------------------------------------

TEST(BSplineCurve, SingleKnotInsertionKeepsGeometry) {
  std::mt19937_64 rng(411);
  for (const auto& [c, samples] : geometryCases(rng)) {
    const double t = freshParameter(rng, c);
    const BSplineCurve r = c.withKnotInserted(t);
    ASSERT_EQ(r.degree(), c.degree());
    ASSERT_EQ(r.numPoints(), c.numPoints() + 1) << describe(c);
    ASSERT_EQ(r.isRational(), c.isRational());
    ASSERT_EQ(r.knots().values(), mergedKnots(c.knots().values(), {t})) << describe(c);
    ASSERT_TRUE(sameCurve(c, r, rng, samples)) << describe(c) << " inserted " << t;
  }
}

TEST(BSplineCurve, RepeatedKnotInsertionUpToFullMultiplicity) {
  std::mt19937_64 rng(412);
  for (const auto& [c, samples] : geometryCases(rng)) {
    const int p = c.degree();
    const double t = freshParameter(rng, c);
    for (int times = 2; times <= p; ++times) {
      const BSplineCurve r = c.withKnotInserted(t, times);
      ASSERT_EQ(r.numPoints(), c.numPoints() + times) << describe(c);
      ASSERT_EQ(r.knots().values(), mergedKnots(c.knots().values(), std::vector<double>(times, t)))
          << describe(c);
      ASSERT_TRUE(sameCurve(c, r, rng, times == p ? samples : kExtraSamples)) << describe(c) << " x" << times;
    }
    // Asking for more than the degree caps the multiplicity at the degree.
    const BSplineCurve capped = c.withKnotInserted(t, p + 2);
    ASSERT_EQ(capped.knots().multiplicity(t), p) << describe(c);
    ASSERT_EQ(capped.numPoints(), c.numPoints() + p);
    ASSERT_TRUE(sameCurve(c, capped, rng, kExtraSamples)) << describe(c);
  }
}

TEST(BSplineCurve, KnotInsertionAtExistingKnots) {
  std::mt19937_64 rng(413);
  int tested = 0;
  for (const auto& [c, samples] : geometryCases(rng)) {
    const int p = c.degree();
    bool first = true;  // full sample count for the first knot of each case, fewer for the others
    for (const auto& [b, m] : interiorKnots(c)) {
      // Once, and up to the full multiplicity p.
      for (int times : {1, std::max(1, p - m)}) {
        const BSplineCurve r = c.withKnotInserted(b, times);
        const int added = std::min(times, p - m);
        ASSERT_EQ(r.numPoints(), c.numPoints() + added) << describe(c) << " at " << b << " x" << times;
        ASSERT_EQ(r.knots().values(), mergedKnots(c.knots().values(), std::vector<double>(added, b)));
        ASSERT_TRUE(sameCurve(c, r, rng, first ? samples : kExtraSamples))
            << describe(c) << " at " << b << " x" << times;
        ++tested;
      }
      first = false;
    }
  }
  EXPECT_GT(tested, 20);
}

TEST(BSplineCurve, RefinementKeepsGeometry) {
  std::mt19937_64 rng(414);
  for (const auto& [c, samples] : geometryCases(rng)) {
    const int p = c.degree();
    std::vector<double> extra;
    // New values (some of them repeated) ...
    const int fresh = uniformInt(rng, 1, 6);
    for (int i = 0; i < fresh; ++i) {
      const double t = freshParameter(rng, c);
      for (int k = uniformInt(rng, 1, p); k > 0; --k) extra.push_back(t);
    }
    // ... and existing interior knots, up to their remaining multiplicity.
    for (const auto& [b, m] : interiorKnots(c))
      for (int k = uniformInt(rng, 0, p - m); k > 0; --k) extra.push_back(b);
    std::sort(extra.begin(), extra.end());
    const BSplineCurve r = c.refined(extra);
    // Fresh values may coincide (same t drawn twice is impossible with probability 1), so no capping happens.
    ASSERT_EQ(r.numPoints(), c.numPoints() + static_cast<int>(extra.size())) << describe(c);
    ASSERT_EQ(r.knots().values(), mergedKnots(c.knots().values(), extra)) << describe(c);
    ASSERT_TRUE(sameCurve(c, r, rng, samples)) << describe(c);
  }
}

TEST(BSplineCurve, RefinementWithNothingIsIdentity) {
  std::mt19937_64 rng(415);
  const BSplineCurve c = randomCurve(rng, 3, 3, {.rational = true});
  const BSplineCurve r = c.refined({});
  EXPECT_EQ(r.knots().values(), c.knots().values());
  EXPECT_TRUE(sameCurve(c, r, rng, kExtraSamples));
}

// ---------------------------------------------------------------------------------------------------------------------
// Bezier decomposition, degree elevation, reversal, reparametrisation
// ---------------------------------------------------------------------------------------------------------------------

TEST(BSplineCurve, BezierPiecesEvaluateToTheCurve) {
  std::mt19937_64 rng(421);
  for (const auto& [c, samples] : geometryCases(rng)) {
    const std::vector<BezierCurvePiece> pieces = c.bezierPieces();
    // One piece per non-empty span of the domain, in order, tiling the domain.
    std::vector<double> bp{c.domain().lo};
    for (const auto& [b, m] : interiorKnots(c)) bp.push_back(b);
    bp.push_back(c.domain().hi);
    ASSERT_EQ(pieces.size() + 1, bp.size()) << describe(c);
    for (size_t i = 0; i < pieces.size(); ++i) {
      ASSERT_DOUBLE_EQ(pieces[i].interval.lo, bp[i]) << describe(c);
      ASSERT_DOUBLE_EQ(pieces[i].interval.hi, bp[i + 1]) << describe(c);
      ASSERT_EQ(pieces[i].curve.degree(), c.degree());
      ASSERT_EQ(pieces[i].curve.dim(), c.dim());
      ASSERT_EQ(pieces[i].curve.isRational(), c.isRational());
    }
    // Each piece, mapped to [0,1] and evaluated by an explicit Bernstein sum, is the curve on its interval.
    const auto ts = test::sampleParams(rng, c.domain(), samples);
    const auto pieceValue = [&](double t) {
      size_t i = 0;
      while (i + 1 < pieces.size() && t > pieces[i].interval.hi) ++i;
      const Interval iv = pieces[i].interval;
      const double s = (t - iv.lo) / iv.length();
      return test::refBezierCurvePoint(pieces[i].curve.points(), pieces[i].curve.weights(), s);
    };
    ASSERT_TRUE(test::agreeAt(
        ts, [&curve = c](double t) { return refCurvePoint(curve, t); }, pieceValue, test::controlScale(c.points()),
        test::kGeometryRelTol))
        << describe(c);
  }
}

TEST(BSplineCurve, BezierPiecesDerivativesMatchTheCurve) {
  // Derivatives by two routes: the B-spline's own derivative, and the derivative of the explicit Bernstein
  // form of the piece (scaled by the chain rule 1 / |interval|^k).
  std::mt19937_64 rng(422);
  for (int p = 1; p <= 7; ++p)
    for (bool rational : {false, true}) {
      const BSplineCurve c = randomCurve(rng, p, 3, {.rational = rational});
      const auto pieces = c.bezierPieces();
      const std::vector<double> bezierKnots = KnotVector::bezier(p).values();
      for (const auto& piece : pieces)
        for (int s = 0; s < 4; ++s) {
          const double u = uniformReal(rng, 0.0, 1.0);
          const double t = piece.interval.lo + u * piece.interval.length();
          const Matrix expected = refCurveDerivs(c, t, 3);
          const Matrix bez = test::refBezierCurveDerivs(piece.curve.points(), piece.curve.weights(), u, 3);
          // Round-off scale: the B-spline side plus the Bezier side (the piece as a single-span spline on
          // [0,1]).
          const VecX magnitude = refCurveDerivMagnitudes(c, t, 3);
          const VecX bezMagnitude =
              refCurveDerivMagnitudes(p, bezierKnots, piece.curve.points(), piece.curve.weights(), u, 3);
          for (int k = 0; k <= 3; ++k) {
            const double chain = std::pow(piece.interval.length(), k);  // d/dt = (1 / length) d/du
            ASSERT_TRUE(closeTo(
                expected.row(k).transpose(), bez.row(k).transpose() / chain,
                test::kRoundoffTol * (magnitude[k] + bezMagnitude[k] / chain) + test::kExactZeroFloor))
                << describe(c) << " order " << k;
          }
        }
    }
}

TEST(BSplineCurve, DegreeElevationKeepsGeometryAndRaisesMultiplicities) {
  std::mt19937_64 rng(431);
  for (const auto& [c, samples] : geometryCases(rng)) {
    for (int by = 1; by <= 3; ++by) {
      const BSplineCurve e = c.degreeElevated(by);
      ASSERT_EQ(e.degree(), c.degree() + by) << describe(c);
      ASSERT_EQ(e.isRational(), c.isRational());
      ASSERT_EQ(e.domain(), c.domain()) << describe(c);
      ASSERT_TRUE(sameCurve(c, e, rng, by == 1 ? samples : samples / 4))
          << describe(c) << " elevated by " << by;
      const bool clamped = c.knots().multiplicity(c.domain().lo) == c.degree() + 1 &&
                           c.knots().multiplicity(c.domain().hi) == c.degree() + 1;
      if (!clamped) continue;
      // Same breakpoints; every multiplicity rises by `by` (the continuity is unchanged).
      const auto oldB = c.knots().breakpoints();
      const auto oldM = c.knots().multiplicities();
      ASSERT_EQ(e.knots().breakpoints(), oldB) << describe(c);
      std::vector<int> expectedM;
      for (int m : oldM) expectedM.push_back(m + by);
      ASSERT_EQ(e.knots().multiplicities(), expectedM) << describe(c) << " elevated by " << by;
      ASSERT_EQ(e.numPoints(), c.numPoints() + by * (static_cast<int>(oldB.size()) - 1)) << describe(c);
    }
  }
}

TEST(BSplineCurve, ReversedTracesTheCurveBackwards) {
  std::mt19937_64 rng(441);
  for (const auto& [c, samples] : geometryCases(rng)) {
    const BSplineCurve r = c.reversed();
    const Interval d = c.domain();
    ASSERT_EQ(r.degree(), c.degree());
    ASSERT_NEAR(r.domain().lo, d.lo, test::kFewUlps * (1 + std::abs(d.lo)));
    ASSERT_NEAR(r.domain().hi, d.hi, test::kFewUlps * (1 + std::abs(d.hi)));
    ASSERT_TRUE(sameCurve(c, r, rng, samples, [&](double t) { return d.lo + d.hi - t; })) << describe(c);
    // Reversing twice gives the same parametrisation back.
    ASSERT_TRUE(sameCurve(c, r.reversed(), rng, kExtraSamples)) << describe(c);
  }
}

TEST(BSplineCurve, ReparametrizedIsAffineChangeOfParameter) {
  std::mt19937_64 rng(442);
  for (const auto& [c, samples] : geometryCases(rng)) {
    const double a = uniformReal(rng, -100.0, 100.0), b = a + std::pow(10.0, uniformReal(rng, -2.0, 2.0));
    const BSplineCurve r = c.reparametrized(a, b);
    const Interval d = c.domain();
    ASSERT_NEAR(r.domain().lo, a, test::kFewUlps * (std::abs(a) + std::abs(b)));
    ASSERT_NEAR(r.domain().hi, b, test::kFewUlps * (std::abs(a) + std::abs(b)));
    ASSERT_TRUE(
        sameCurve(c, r, rng, samples, [&](double t) { return d.lo + (t - a) / (b - a) * d.length(); }))
        << describe(c) << " onto [" << a << ", " << b << "]";
  }
}

TEST(BSplineCurve, DecomposeKeepsAClampedBezierSpanAsItIs) {
  // decompose returns a single clamped Bezier span at once (its shortcut); the general route gives that very span
  // for it. Every piece the general route cuts from a random curve (clamped or not, several spans) is such a span:
  // decomposing it again must give back the same rows, knots and interval, bit for bit.
  std::mt19937_64 rng(1603);
  for (int p = 1; p <= 5; ++p)
    for (bool clamped : {true, false}) {
      const BSplineCurve c = randomCurve(rng, p, 3, {.rational = p % 2 == 0, .clamped = clamped, .minSpans = 1,
                                                     .maxSpans = 4});
      std::vector<double> knots = c.knots().values();
      Matrix rows = c.homogeneous();
      const std::vector<Interval> spans = detail::decompose(p, knots, rows);
      ASSERT_EQ(rows.rows(), static_cast<Eigen::Index>(spans.size()) * p + 1);
      for (size_t k = 0; k < spans.size(); ++k) {
        std::vector<double> pieceKnots(static_cast<size_t>(2 * (p + 1)), spans[k].lo);
        std::fill(pieceKnots.begin() + p + 1, pieceKnots.end(), spans[k].hi);
        const std::vector<double> knotsBefore = pieceKnots;
        Matrix piece = rows.middleRows(static_cast<Eigen::Index>(k) * p, p + 1);
        const Matrix before = piece;
        const std::vector<Interval> again = detail::decompose(p, pieceKnots, piece);
        ASSERT_EQ(again.size(), 1u);
        EXPECT_EQ(again[0].lo, spans[k].lo);
        EXPECT_EQ(again[0].hi, spans[k].hi);
        EXPECT_EQ(pieceKnots, knotsBefore);
        ASSERT_EQ(piece.rows(), before.rows());
        for (Eigen::Index i = 0; i < piece.size(); ++i) ASSERT_EQ(piece.data()[i], before.data()[i]);
      }
    }
}

TEST(BSplineCurve, DecomposeInsertsIntoOneMatrixAsInsertKnotDoes) {
  // decompose raises each interior breakpoint to multiplicity `degree` in one matrix of the final size
  // (insertions in place); the route it replaces is clampEnds, then insertKnot(degree, knots, rows, b, degree) per
  // interior breakpoint b, a new matrix per insertion. The same knots and rows, bit for bit: random curves of
  // degrees 1-5, clamped or not, some interior knots already of higher multiplicity, with their homogeneous rows
  // and with random rows of 16 columns (a surface's rows decomposed along one direction).
  std::mt19937_64 rng(2612);
  for (int p = 1; p <= 5; ++p)
    for (bool clamped : {true, false})
      for (int trial = 0; trial < 4; ++trial) {
        BSplineCurve c = randomCurve(rng, p, 3, {.rational = trial % 2 == 1, .clamped = clamped, .minSpans = 1,
                                                 .maxSpans = 6});
        const std::vector<double> inner = c.knots().interiorBreakpoints(p);
        if (trial >= 2 && !inner.empty()) {
          const int times = uniformInt(rng, 1, p);  // drawn last argument first (test_helpers.h)
          c = c.withKnotInserted(inner[static_cast<size_t>(uniformInt(rng, 0, static_cast<int>(inner.size()) - 1))],
                                 times);
        }
        for (const Matrix& start : {c.homogeneous(), test::randomMatrix(rng, c.numPoints(), 16)}) {
          std::vector<double> knots = c.knots().values(), oldKnots = knots;
          Matrix rows = start, oldRows = start;
          const std::vector<Interval> spans = detail::decompose(p, knots, rows);
          detail::clampEnds(p, oldKnots, oldRows);
          const Interval dom = KnotVector(oldKnots).domain(p);
          std::vector<double> interior;
          for (double k : oldKnots)
            if (k > dom.lo && k < dom.hi && (interior.empty() || k != interior.back())) interior.push_back(k);
          for (double b : interior) detail::insertKnot(p, oldKnots, oldRows, b, p);
          ASSERT_EQ(spans.size(), interior.size() + 1) << describe(c);
          ASSERT_EQ(knots, oldKnots) << describe(c);
          ASSERT_EQ(rows.rows(), oldRows.rows()) << describe(c);
          ASSERT_EQ(rows.cols(), oldRows.cols()) << describe(c);
          for (Eigen::Index i = 0; i < rows.size(); ++i)
            ASSERT_EQ(std::bit_cast<std::uint64_t>(rows.data()[i]), std::bit_cast<std::uint64_t>(oldRows.data()[i]))
                << describe(c) << " coefficient " << i;
        }
      }
}

// Known kernel bug, reported to the lead (final report of the kernel-test session): two distinct knots closer
// than kKnotRelTol * length are merged by interiorBreakpoints()/multiplicity() but not by the knot algorithms
// (detail::insertKnot counts multiplicity exactly), so detail::decompose produces rows that do not match its
// spans: bezierPieces() returns 2 pieces with O(1) geometric error and degreeElevated() changes the curve.
// Such knot vectors pass validate()/create(), and withKnotInserted(b + 1e-14 * length) next to a knot b
// creates them. Either rejecting them in create() (with a message) or handling them exactly makes this test
// pass.
TEST(BSplineCurve, KnotsCloserThanTheKnotToleranceKeepGeometry) {
  std::mt19937_64 rng(461);
  Matrix pts(6, 2);
  pts << 0, 0, 1, 2, 2, -1, 3, 3, 4, 0, 5, 1;
  for (double delta : {1e-14, 1e-13, 1e-12}) {
    const auto created = BSplineCurve::create(3, {0, 0, 0, 0, 0.5, 0.5 + delta, 1, 1, 1, 1}, pts);
    if (!created.isOk()) continue;  // rejecting such input is an acceptable fix
    const BSplineCurve& c = *created;
    const auto pieces = c.bezierPieces();
    const auto pieceValue = [&](double t) {
      size_t i = 0;
      while (i + 1 < pieces.size() && t > pieces[i].interval.hi) ++i;
      const Interval iv = pieces[i].interval;
      return test::refBezierCurvePoint(pieces[i].curve.points(), pieces[i].curve.weights(),
                                       iv.length() > 0 ? (t - iv.lo) / iv.length() : 0.0);
    };
    EXPECT_TRUE(test::agreeAt(
        test::sampleParams(rng, c.domain(), 1000), [&](double t) { return refCurvePoint(c, t); }, pieceValue,
        test::controlScale(c.points()), test::kGeometryRelTol))
        << "bezierPieces, delta " << delta;
    EXPECT_TRUE(sameCurve(c, c.degreeElevated(1), rng, 1000)) << "degreeElevated, delta " << delta;
  }
  // The same situation created by the library's own knot insertion next to an existing knot.
  const BSplineCurve c = randomCurve(rng, 3, 3, {.rational = true, .minSpans = 3, .maxSpans = 3});
  const double b = c.knots().interiorBreakpoints(3).front();
  const BSplineCurve r = c.withKnotInserted(b + 1e-14 * c.domain().length(), 3);
  EXPECT_TRUE(sameCurve(c, r.degreeElevated(1), rng, 1000)) << describe(r);
}

// ---------------------------------------------------------------------------------------------------------------------
// Construction
// ---------------------------------------------------------------------------------------------------------------------

TEST(BSplineCurve, HomogeneousRoundTrip) {
  std::mt19937_64 rng(451);
  for (bool rational : {false, true}) {
    const BSplineCurve c = randomCurve(rng, 3, 3, {.rational = rational});
    const Matrix h = c.homogeneous();
    const Matrix expected = test::refHomogeneous(c.points(), c.weights());
    ASSERT_EQ(h.rows(), expected.rows());
    ASSERT_EQ(h.cols(), expected.cols());
    EXPECT_LE(test::maxAbs(Matrix(h - expected)), test::kFewUlps * test::maxAbs(expected));
    const BSplineCurve back = BSplineCurve::fromHomogeneous(c.degree(), c.knots(), h, rational);
    EXPECT_EQ(back.isRational(), rational);
    EXPECT_LE(test::maxAbs(Matrix(back.points() - c.points())), test::kFewUlps * test::maxAbs(c.points()));
    if (rational) {
      EXPECT_LE(test::maxAbs(VecX(back.weights() - c.weights())), test::kFewUlps * test::maxAbs(c.weights()));
    }
  }
}

TEST(BSplineCurve, CreateAcceptsValidInput) {
  std::mt19937_64 rng(452);
  for (int p = 1; p <= 7; ++p)
    for (bool rational : {false, true})
      for (bool clamped : {true, false}) {
        const BSplineCurve c = randomCurve(rng, p, 3, {.rational = rational, .clamped = clamped});
        const Result<BSplineCurve> r = BSplineCurve::create(p, c.knots().values(), c.points(), c.weights());
        ASSERT_TRUE(r.isOk()) << r.status().message() << " for " << describe(c);
        EXPECT_EQ(r->degree(), p);
        EXPECT_EQ(r->knots().values(), c.knots().values());
        EXPECT_EQ(r->points(), c.points());
        EXPECT_EQ(r->isRational(), rational);
      }
}

TEST(BSplineCurve, CreateRejectsBadInputWithMessage) {
  const std::vector<double> knots = {0, 0, 0, 0.5, 1, 1, 1};  // degree 2, 4 points
  Matrix pts(4, 3);
  pts << 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 1;
  VecX w(4);
  w << 1, 2, 0.5, 1;
  ASSERT_TRUE(BSplineCurve::create(2, knots, pts, w).isOk());
  ASSERT_TRUE(BSplineCurve::create(2, knots, pts).isOk());

  const auto status = [](const Result<BSplineCurve>& r) { return r.status(); };
  // Wrong number of knots for the points.
  EXPECT_TRUE(failsMentioning(status(BSplineCurve::create(2, {0, 0, 0, 1, 1, 1}, pts)), {"knot"}));
  EXPECT_TRUE(failsMentioning(status(BSplineCurve::create(3, knots, pts)), {"knot", "point"}));
  // Decreasing knots.
  Matrix pts5(5, 3);
  pts5 << 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 1, 2, 2, 2;
  EXPECT_TRUE(failsMentioning(status(BSplineCurve::create(2, {0, 0, 0, 0.7, 0.3, 1, 1, 1}, pts5)),
                              {"decreas", "monoton", "order", "sorted", "increas"}));
  // Non-finite coordinates.
  for (double bad : {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    Matrix p = pts;
    p(2, 1) = bad;
    const Status s = status(BSplineCurve::create(2, knots, p));
    EXPECT_EQ(s.code(), ErrorCode::kInvalidInput);
    EXPECT_TRUE(failsMentioning(s, {"finite", "nan", "inf"}));
    std::vector<double> k = knots;
    k[3] = bad;
    EXPECT_TRUE(failsMentioning(status(BSplineCurve::create(2, k, pts)), {"finite", "nan", "inf"}));
  }
  // Weights: non-positive, NaN, wrong count.
  for (double bad : {0.0, -1.0, std::numeric_limits<double>::quiet_NaN()}) {
    VecX ww = w;
    ww[1] = bad;
    const Status s = status(BSplineCurve::create(2, knots, pts, ww));
    EXPECT_EQ(s.code(), ErrorCode::kInvalidInput) << bad;
    EXPECT_TRUE(failsMentioning(s, {"weight"})) << bad;
  }
  EXPECT_TRUE(failsMentioning(status(BSplineCurve::create(2, knots, pts, VecX::Ones(3))), {"weight"}));
  // Interior multiplicity above the degree.
  EXPECT_TRUE(
      failsMentioning(status(BSplineCurve::create(1, {0, 0, 0.5, 0.5, 1, 1}, pts)), {"multiplicity"}));
  // Nonsense sizes.
  EXPECT_FALSE(BSplineCurve::create(-1, knots, pts).isOk());
  EXPECT_FALSE(BSplineCurve::create(2, knots, Matrix(0, 3)).isOk());
  EXPECT_FALSE(BSplineCurve::create(3, {0, 0, 0, 1, 1, 1}, Matrix(pts.topRows(2))).isOk());
}

}  // namespace
}  // namespace seam
