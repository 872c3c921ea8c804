// Knot vectors (include/seam/core/knot_vector.h): validation with messages, span search against a linear
// search, multiplicities and breakpoints on hand examples, reparametrisation, and basis functions against the
// Cox-de Boor recursion written in test_helpers.h.
#include "seam/core/knot_vector.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "seam/core/tolerances.h"
#include "test_helpers.h"

namespace seam {
namespace {

using test::coxDeBoor;
using test::coxDeBoorDerivative;
using test::failsMentioning;
using test::randomKnots;
using test::referenceSpan;
using test::ssize;
using test::uniformInt;
using test::uniformReal;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

/// A random valid knot vector (clamped or not) with its degree.
struct Case {
  int degree;
  std::vector<double> knots;
  int numPoints() const { return static_cast<int>(knots.size()) - degree - 1; }
};

Case randomCase(std::mt19937_64& rng, bool clamped) {
  const int p = uniformInt(rng, 1, 7);
  const double lo = uniformReal(rng, -5.0, 5.0);
  return {p, randomKnots(rng, p, uniformInt(rng, 1, 5), lo, lo + uniformReal(rng, 0.1, 10.0), clamped)};
}

// ---------------------------------------------------------------------------------------------------------------------
// The reference recursion itself, on a published example, so that the tests below compare against something
// known to be right: The NURBS Book, Ex. 2.3/2.4, U = {0,0,0,1,2,3,4,4,5,5,5}, p = 2, u = 5/2.
// ---------------------------------------------------------------------------------------------------------------------

const std::vector<double> kBookKnots = {0, 0, 0, 1, 2, 3, 4, 4, 5, 5, 5};

TEST(ReferenceCoxDeBoor, MatchesPublishedExample) {
  const double u = 2.5;
  EXPECT_NEAR(coxDeBoor(kBookKnots, 2, 2, 2, u), 1.0 / 8, test::kFewUlps);
  EXPECT_NEAR(coxDeBoor(kBookKnots, 2, 3, 2, u), 6.0 / 8, test::kFewUlps);
  EXPECT_NEAR(coxDeBoor(kBookKnots, 2, 4, 2, u), 1.0 / 8, test::kFewUlps);
  EXPECT_EQ(coxDeBoor(kBookKnots, 2, 1, 2, u), 0.0);
  EXPECT_EQ(coxDeBoor(kBookKnots, 2, 5, 2, u), 0.0);
  // N_{2,2} = (3-u)^2/2, N_{3,2} = -11/2 + 5u - u^2, N_{4,2} = (u-2)^2/2 on [2,3].
  EXPECT_NEAR(coxDeBoorDerivative(kBookKnots, 2, 2, 2, 1, u), -0.5, test::kFewUlps);
  EXPECT_NEAR(coxDeBoorDerivative(kBookKnots, 2, 3, 2, 1, u), 0.0, test::kFewUlps);
  EXPECT_NEAR(coxDeBoorDerivative(kBookKnots, 2, 4, 2, 1, u), 0.5, test::kFewUlps);
  EXPECT_NEAR(coxDeBoorDerivative(kBookKnots, 2, 2, 2, 2, u), 1.0, test::kFewUlps);
  EXPECT_NEAR(coxDeBoorDerivative(kBookKnots, 2, 3, 2, 2, u), -2.0, test::kFewUlps);
  EXPECT_NEAR(coxDeBoorDerivative(kBookKnots, 2, 4, 2, 2, u), 1.0, test::kFewUlps);
  EXPECT_EQ(coxDeBoorDerivative(kBookKnots, 2, 3, 2, 3, u), 0.0);
  // Right end: the last function is 1 at u = 5 (clamped end interpolation).
  EXPECT_NEAR(coxDeBoor(kBookKnots, 2, 7, 2, 5.0), 1.0, test::kFewUlps);
}

TEST(ReferenceCoxDeBoor, BottomUpTableMatchesRecursion) {
  std::mt19937_64 rng(301);
  for (int trial = 0; trial < 40; ++trial) {
    const Case c = randomCase(rng, trial % 2 == 0);
    const Interval d{c.knots[static_cast<size_t>(c.degree)], c.knots[static_cast<size_t>(c.numPoints())]};
    for (double t : test::sampleParams(rng, d, 5)) {
      const Matrix table = test::basisTable(c.knots, c.degree, t, c.degree + 1);
      for (int k = 0; k <= c.degree + 1; ++k)
        for (int i = 0; i < c.numPoints(); ++i)
          ASSERT_NEAR(table(k, i), coxDeBoorDerivative(c.knots, c.degree, i, c.degree, k, t),
                      test::kRoundoffTol * std::max(1.0, std::abs(table(k, i))));
    }
  }
}

TEST(ReferenceCoxDeBoor, FastPathIsBitIdenticalToTable) {
  std::mt19937_64 rng(308);
  std::vector<double> fast;
  for (int trial = 0; trial < 60; ++trial) {
    const Case c = randomCase(rng, trial % 2 == 0);
    const Interval d{c.knots[static_cast<size_t>(c.degree)], c.knots[static_cast<size_t>(c.numPoints())]};
    std::vector<double> ts = test::sampleParams(rng, d, 10);
    for (double b : test::distinctValues(c.knots)) ts.push_back(b);
    for (double t : ts) {
      const Matrix table = test::basisTable(c.knots, c.degree, t, 0);
      test::basisValuesInto(c.knots, c.degree, t, fast);
      ASSERT_EQ(static_cast<int>(fast.size()), c.numPoints());
      for (int i = 0; i < c.numPoints(); ++i) ASSERT_EQ(fast[static_cast<size_t>(i)], table(0, i)) << t;
    }
  }
}

// ---------------------------------------------------------------------------------------------------------------------
// validate()
// ---------------------------------------------------------------------------------------------------------------------

TEST(KnotVectorValidate, AcceptsGoodVectors) {
  EXPECT_TRUE(KnotVector({0, 0, 1, 1}).validate(1, 2).isOk());
  EXPECT_TRUE(KnotVector({0, 0, 0, 0, 1, 1, 1, 1}).validate(3, 4).isOk());
  EXPECT_TRUE(KnotVector(kBookKnots).validate(2, 8).isOk());
  // Interior multiplicity == degree (C0 joint), unclamped ends, negative values.
  EXPECT_TRUE(KnotVector({0, 0, 0, 0.5, 0.5, 1, 1, 1}).validate(2, 5).isOk());
  EXPECT_TRUE(KnotVector({-3, -2, -1, 0, 1, 2, 3}).validate(2, 4).isOk());
  EXPECT_TRUE(KnotVector({0, 0, 0, 1, 2, 3, 3, 3}).validate(2, 5).isOk());
  std::mt19937_64 rng(302);
  for (int trial = 0; trial < 100; ++trial) {
    const Case c = randomCase(rng, trial % 2 == 0);
    const Status s = KnotVector(c.knots).validate(c.degree, c.numPoints());
    EXPECT_TRUE(s.isOk()) << s.message() << " (degree " << c.degree << ")";
  }
}

TEST(KnotVectorValidate, RejectsWrongSize) {
  // Degree 2, 4 points need 7 knots.
  const Status tooFew = KnotVector({0, 0, 0, 1, 1, 1}).validate(2, 4);
  EXPECT_EQ(tooFew.code(), ErrorCode::kInvalidInput);
  EXPECT_TRUE(failsMentioning(tooFew, {"7"})) << "the expected count should be named";
  EXPECT_TRUE(failsMentioning(tooFew, {"6"})) << "the actual count should be named";
  const Status tooMany = KnotVector({0, 0, 0, 0.5, 0.7, 1, 1, 1}).validate(2, 4);
  EXPECT_TRUE(failsMentioning(tooMany, {"7"}));
  EXPECT_TRUE(failsMentioning(KnotVector().validate(3, 4), {"8"}));
}

TEST(KnotVectorValidate, RejectsDecreasingKnots) {
  const Status s = KnotVector({0, 0, 0, 0.6, 0.4, 1, 1, 1}).validate(2, 5);
  EXPECT_EQ(s.code(), ErrorCode::kInvalidInput);
  EXPECT_TRUE(failsMentioning(s, {"decreas", "monoton", "order", "sorted", "increas"}));
  EXPECT_TRUE(failsMentioning(KnotVector({1, 1, 1, 0, 0, 0}).validate(2, 3),
                              {"decreas", "monoton", "order", "sorted", "increas"}));
}

TEST(KnotVectorValidate, RejectsNonFiniteValues) {
  for (double bad : {kNaN, kInf, -kInf}) {
    for (size_t pos : {size_t{0}, size_t{3}, size_t{6}}) {
      std::vector<double> t = {0, 0, 0, 0.5, 1, 1, 1};
      t[pos] = bad;
      const Status s = KnotVector(t).validate(2, 4);
      EXPECT_EQ(s.code(), ErrorCode::kInvalidInput) << bad << " at " << pos;
      EXPECT_TRUE(failsMentioning(s, {"finite", "nan", "inf"})) << bad << " at " << pos;
    }
  }
}

TEST(KnotVectorValidate, RejectsInteriorMultiplicityAboveDegree) {
  const Status s = KnotVector({0, 0, 0, 0.5, 0.5, 0.5, 1, 1, 1}).validate(2, 6);
  EXPECT_EQ(s.code(), ErrorCode::kInvalidInput);
  EXPECT_TRUE(failsMentioning(s, {"multiplicity"}));
  EXPECT_TRUE(failsMentioning(KnotVector({0, 0, 0.3, 0.3, 1, 1}).validate(1, 4), {"multiplicity"}));
}

TEST(KnotVectorValidate, RejectsEndMultiplicityAboveDegreePlusOne) {
  const Status left = KnotVector({0, 0, 0, 0, 0.5, 1, 1, 1}).validate(2, 5);
  EXPECT_EQ(left.code(), ErrorCode::kInvalidInput);
  EXPECT_TRUE(failsMentioning(left, {"multiplicity"}));
  const Status right = KnotVector({0, 0, 0, 0.5, 1, 1, 1, 1}).validate(2, 5);
  EXPECT_TRUE(failsMentioning(right, {"multiplicity"}));
}

TEST(KnotVectorValidate, RejectsEmptyDomain) {
  // Degree 2, 3 points: domain [t_2, t_3] = [2, 2] although every multiplicity is allowed.
  const Status s = KnotVector({0, 1, 2, 2, 3, 4}).validate(2, 3);
  EXPECT_EQ(s.code(), ErrorCode::kInvalidInput);
  EXPECT_TRUE(failsMentioning(s, {"domain", "empty"}));
  // All knots equal: nothing is valid about it, but it must be rejected.
  EXPECT_FALSE(KnotVector({1, 1, 1, 1, 1, 1}).validate(2, 3).isOk());
  // Fewer points than degree + 1 (domain [t_3, t_2] reversed).
  EXPECT_FALSE(KnotVector({0, 0, 0, 1, 1, 1}).validate(3, 2).isOk());
}

// ---------------------------------------------------------------------------------------------------------------------
// Domain, span search, multiplicities, breakpoints
// ---------------------------------------------------------------------------------------------------------------------

TEST(KnotVector, HandExample) {
  const KnotVector k({0, 0, 0, 1, 2, 2, 3, 3, 3});  // degree 2, 6 points
  EXPECT_EQ(k.size(), 9);
  EXPECT_EQ(k[3], 1.0);
  EXPECT_EQ(k.domain(2), (Interval{0, 3}));
  EXPECT_EQ(k.findSpan(2, 0.0), 2);
  EXPECT_EQ(k.findSpan(2, 0.5), 2);
  EXPECT_EQ(k.findSpan(2, 1.0), 3);
  EXPECT_EQ(k.findSpan(2, 1.999), 3);
  EXPECT_EQ(k.findSpan(2, 2.0), 5);  // span 4 = [2,2) is empty
  EXPECT_EQ(k.findSpan(2, 2.5), 5);
  EXPECT_EQ(k.findSpan(2, 3.0), 5);  // right end: last non-empty span
  EXPECT_EQ(k.findSpan(2, 7.0), 5);
  EXPECT_EQ(k.findSpan(2, -1.0), 2);
  EXPECT_EQ(k.multiplicity(0.0), 3);
  EXPECT_EQ(k.multiplicity(1.0), 1);
  EXPECT_EQ(k.multiplicity(2.0), 2);
  EXPECT_EQ(k.multiplicity(3.0), 3);
  EXPECT_EQ(k.multiplicity(0.5), 0);
  // Within kKnotRelTol * length of a knot counts as that knot; clearly off it does not.
  EXPECT_EQ(k.multiplicity(2.0 + 0.01 * kKnotRelTol), 2);
  EXPECT_EQ(k.multiplicity(2.0 + 1e-6), 0);
  EXPECT_EQ(k.breakpoints(), (std::vector<double>{0, 1, 2, 3}));
  EXPECT_EQ(k.multiplicities(), (std::vector<int>{3, 1, 2, 3}));
  EXPECT_EQ(k.interiorBreakpoints(2), (std::vector<double>{1, 2}));
}

TEST(KnotVector, UnclampedHandExample) {
  const KnotVector k({-1, 0, 0, 1, 2, 3, 3, 4});  // degree 2, 5 points, domain [t_2, t_5] = [0, 3]
  EXPECT_EQ(k.domain(2), (Interval{0, 3}));
  EXPECT_EQ(k.breakpoints(), (std::vector<double>{-1, 0, 1, 2, 3, 4}));
  EXPECT_EQ(k.multiplicities(), (std::vector<int>{1, 2, 1, 1, 2, 1}));
  EXPECT_EQ(k.interiorBreakpoints(2), (std::vector<double>{1, 2}));
  EXPECT_EQ(k.findSpan(2, 0.0), 2);
  EXPECT_EQ(k.findSpan(2, 3.0), 4);
  EXPECT_EQ(k.findSpan(2, 3.5), 4);
  EXPECT_EQ(k.findSpan(2, -0.5), 2);
}

TEST(KnotVector, FindSpanMatchesLinearSearch) {
  std::mt19937_64 rng(303);
  for (int trial = 0; trial < 200; ++trial) {
    const Case c = randomCase(rng, trial % 3 != 0);
    const KnotVector k(c.knots);
    const int p = c.degree;
    const Interval d = k.domain(p);
    ASSERT_EQ(d.lo, c.knots[static_cast<size_t>(p)]);
    ASSERT_EQ(d.hi, c.knots[static_cast<size_t>(c.numPoints())]);
    std::vector<double> ts = test::sampleParams(rng, d, 30);
    const double off = 1e-9 * d.length();  // far outside the knot tolerance (1e-12 relative)
    for (double b : test::distinctValues(c.knots)) {
      ts.push_back(b);
      ts.push_back(b - off);
      ts.push_back(b + off);
    }
    ts.push_back(d.lo - 0.5 * d.length());
    ts.push_back(d.hi + 0.5 * d.length());
    for (double t : ts) {
      const int span = k.findSpan(p, t);
      ASSERT_EQ(span, referenceSpan(c.knots, p, t)) << "degree " << p << " t " << t;
      ASSERT_GE(span, p);
      ASSERT_LT(span, c.numPoints());
      ASSERT_LT(c.knots[static_cast<size_t>(span)], c.knots[static_cast<size_t>(span) + 1])
          << "span is empty";
    }
  }
}

TEST(KnotVector, MultiplicitiesOfRandomVectors) {
  std::mt19937_64 rng(304);
  for (int trial = 0; trial < 100; ++trial) {
    const Case c = randomCase(rng, trial % 2 == 0);
    const KnotVector k(c.knots);
    const std::vector<double> bp = test::distinctValues(c.knots);
    ASSERT_EQ(k.breakpoints(), bp);
    std::vector<int> mult;
    for (double b : bp) mult.push_back(static_cast<int>(std::count(c.knots.begin(), c.knots.end(), b)));
    ASSERT_EQ(k.multiplicities(), mult);
    for (size_t i = 0; i < bp.size(); ++i) ASSERT_EQ(k.multiplicity(bp[i]), mult[i]);
    std::vector<double> interior;
    const Interval d = k.domain(c.degree);
    for (double b : bp)
      if (b > d.lo && b < d.hi) interior.push_back(b);
    ASSERT_EQ(k.interiorBreakpoints(c.degree), interior);
  }
}

TEST(KnotVector, ReparametrizedAndReversed) {
  std::mt19937_64 rng(305);
  for (int trial = 0; trial < 100; ++trial) {
    const Case c = randomCase(rng, trial % 2 == 0);
    const KnotVector k(c.knots);
    const Interval d = k.domain(c.degree);
    const double a = uniformReal(rng, -10.0, 10.0), b = a + uniformReal(rng, 0.01, 20.0);
    const KnotVector r = k.reparametrized(c.degree, a, b);
    ASSERT_EQ(r.size(), k.size());
    const double tol = 8 * std::numeric_limits<double>::epsilon() *
                       (std::abs(a) + std::abs(b) + std::abs(c.knots.front()) + std::abs(c.knots.back()) +
                        (b - a) / d.length() * (std::abs(c.knots.front()) + std::abs(c.knots.back())));
    for (int i = 0; i < k.size(); ++i)
      ASSERT_NEAR(r[i], a + (k[i] - d.lo) * (b - a) / d.length(), tol) << "knot " << i;
    ASSERT_NEAR(r.domain(c.degree).lo, a, tol);
    ASSERT_NEAR(r.domain(c.degree).hi, b, tol);
    // Multiplicities survive (no knots merged or split by round-off).
    ASSERT_EQ(r.multiplicities(), k.multiplicities());

    // Reversal t -> lo + hi - t of the domain [lo, hi] (the domain maps onto itself).
    const KnotVector rev = k.reversed(c.degree);
    ASSERT_EQ(rev.size(), k.size());
    const double rtol =
        4 * std::numeric_limits<double>::epsilon() *
        (std::abs(d.lo) + std::abs(d.hi) + std::abs(c.knots.front()) + std::abs(c.knots.back()));
    for (int i = 0; i < k.size(); ++i)
      ASSERT_NEAR(rev[i], d.lo + d.hi - k[k.size() - 1 - i], rtol) << "knot " << i;
    ASSERT_NEAR(rev.domain(c.degree).lo, d.lo, rtol);
    ASSERT_NEAR(rev.domain(c.degree).hi, d.hi, rtol);
    std::vector<int> revMult = k.multiplicities();
    std::reverse(revMult.begin(), revMult.end());
    ASSERT_EQ(rev.multiplicities(), revMult);
  }
}

TEST(KnotVector, ClampedUniformAndBezier) {
  for (int p = 1; p <= 6; ++p)
    for (int n = p + 1; n <= p + 6; ++n) {
      const double a = -1.5, b = 2.5;
      const KnotVector k = KnotVector::clampedUniform(p, n, a, b);
      ASSERT_EQ(k.size(), n + p + 1);
      ASSERT_TRUE(k.validate(p, n).isOk());
      for (int i = 0; i <= p; ++i) {
        ASSERT_EQ(k[i], a);
        ASSERT_EQ(k[n + i], b);
      }
      for (int i = p + 1; i < n; ++i)
        ASSERT_NEAR(k[i], a + (b - a) * (i - p) / (n - p), test::kFewUlps) << p << " " << n;
    }
  const KnotVector d = KnotVector::clampedUniform(2, 4);
  EXPECT_EQ(d.values(), (std::vector<double>{0, 0, 0, 0.5, 1, 1, 1}));
  EXPECT_EQ(KnotVector::bezier(3).values(), (std::vector<double>{0, 0, 0, 0, 1, 1, 1, 1}));
  EXPECT_EQ(KnotVector::bezier(2, -1, 4).values(), (std::vector<double>{-1, -1, -1, 4, 4, 4}));
}

// ---------------------------------------------------------------------------------------------------------------------
// Basis functions
// ---------------------------------------------------------------------------------------------------------------------

TEST(BasisFunctions, PublishedExample) {
  const Matrix out = basisFunctionDerivatives(KnotVector(kBookKnots), 2, 4, 2.5, 2);
  ASSERT_EQ(out.rows(), 3);
  ASSERT_EQ(out.cols(), 3);
  EXPECT_NEAR(out(0, 0), 1.0 / 8, test::kFewUlps);
  EXPECT_NEAR(out(0, 1), 6.0 / 8, test::kFewUlps);
  EXPECT_NEAR(out(0, 2), 1.0 / 8, test::kFewUlps);
  EXPECT_NEAR(out(1, 0), -0.5, test::kFewUlps);
  EXPECT_NEAR(out(1, 1), 0.0, test::kFewUlps);
  EXPECT_NEAR(out(1, 2), 0.5, test::kFewUlps);
  EXPECT_NEAR(out(2, 0), 1.0, test::kFewUlps);
  EXPECT_NEAR(out(2, 1), -2.0, test::kFewUlps);
  EXPECT_NEAR(out(2, 2), 1.0, test::kFewUlps);
}

TEST(BasisFunctions, DerivativesMatchCoxDeBoorUpToOrderPPlusOne) {
  std::mt19937_64 rng(306);
  for (int trial = 0; trial < 150; ++trial) {
    const Case c = randomCase(rng, trial % 3 != 0);
    const KnotVector k(c.knots);
    const int p = c.degree;
    std::vector<double> ts = test::sampleParams(rng, k.domain(p), 6);
    for (double b : k.interiorBreakpoints(p)) ts.push_back(b);
    for (double t : ts) {
      const int span = referenceSpan(c.knots, p, t);
      const Matrix out = basisFunctionDerivatives(k, p, span, t, p + 1);
      ASSERT_EQ(out.rows(), p + 2);
      ASSERT_EQ(out.cols(), p + 1);
      const Matrix magnitude = test::basisTable(c.knots, p, t, p + 1, true);
      for (int order = 0; order <= p + 1; ++order) {
        double sum = 0.0, sumMagnitude = 0.0;
        for (int r = 0; r <= p; ++r) {
          const int i = span - p + r;
          const double expected = coxDeBoorDerivative(c.knots, p, i, p, order, t);
          const double bound = test::kRoundoffTol * std::max(1.0, magnitude(order, i));
          ASSERT_NEAR(out(order, r), expected, bound)
              << "degree " << p << " t " << t << " order " << order << " function " << i;
          sum += out(order, r);
          sumMagnitude += magnitude(order, i);
        }
        // Partition of unity: the functions sum to 1, their derivatives to 0.
        ASSERT_NEAR(sum, order == 0 ? 1.0 : 0.0, test::kRoundoffTol * std::max(1.0, sumMagnitude))
            << "degree " << p << " t " << t << " order " << order;
      }
      // The functions are non-negative.
      for (int r = 0; r <= p; ++r) ASSERT_GE(out(0, r), -test::kRoundoffTol);
    }
  }
}

TEST(BasisFunctions, OrderBeyondDegreeIsZero) {
  std::mt19937_64 rng(307);
  for (int trial = 0; trial < 20; ++trial) {
    const Case c = randomCase(rng, true);
    const KnotVector k(c.knots);
    const int p = c.degree;
    const double t = uniformReal(rng, k.domain(p).lo, k.domain(p).hi);
    const Matrix out = basisFunctionDerivatives(k, p, k.findSpan(p, t), t, p + 3);
    ASSERT_EQ(out.rows(), p + 4);
    for (int order = p + 1; order <= p + 3; ++order)
      for (int r = 0; r <= p; ++r) ASSERT_EQ(out(order, r), 0.0) << "order " << order;
  }
}

}  // namespace
}  // namespace seam
