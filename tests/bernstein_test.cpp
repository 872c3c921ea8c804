// Bernstein algebra (include/seam/core/bernstein.h) against explicit Bernstein sums (binomials and pow), the
// power basis, finite differences and pointwise products of the factors. All expected values come from
// test_helpers.h.
#include "seam/core/bernstein.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "core/bernstein_internal.h"
#include "test_helpers.h"

namespace seam {
namespace {

using test::closeTo;
using test::fallingFactorial;
using test::maxAbs;
using test::randomMatrix;
using test::refBernsteinEval;
using test::refPatchEval;
using test::uniformInt;
using test::uniformReal;

constexpr int kMaxDegree = 9;
constexpr int kDims[] = {1, 3, 4};

/// Bernstein coefficients converted to the power basis amplify round-off by up to sum_k C(n,k) 2^k = 3^n
/// (~2e4 for n = 9): comparisons through the power basis get this looser relative bound.
constexpr double kPowerBasisTol = 1e-10;

/// Step of the finite differences on [0,1]-polynomials of degree <= 9: truncation ~ h^4 n^5 2^5 / 480
/// relative to the coefficients (~4e-9 at h = 1e-3), round-off ~ eps / h = 1e-13.
constexpr double kFdStep = 1e-3;

/// (|t| + |1-t|)^n = sum_i |B_i^n(t)|: how much coefficient-level round-off is amplified when evaluating at t
/// (1 on [0,1]).
double amplification(int n, double t) { return std::pow(std::abs(t) + std::abs(1.0 - t), n); }

/// Round-off scale of the k-th derivative of a degree-n polynomial with coefficients bounded by `c` on [0,1]:
/// the differenced coefficients are bounded by n (n-1) ... (n-k+1) 2^k c.
double derivativeScale(int n, int k, double c) { return fallingFactorial(n, k) * std::pow(2.0, k) * c; }

BernsteinPoly randomPoly(std::mt19937_64& rng, int degree, int dim) {
  return BernsteinPoly(randomMatrix(rng, degree + 1, dim));
}

BernsteinPatch randomPatch(std::mt19937_64& rng, int du, int dv, int dim) {
  return BernsteinPatch(du, dv, randomMatrix(rng, (du + 1) * (dv + 1), dim));
}

std::vector<double> unitSamples(std::mt19937_64& rng, int count) {
  std::vector<double> ts{0.0, 1.0, 0.5};
  while (static_cast<int>(ts.size()) < count) ts.push_back(uniformReal(rng, 0.0, 1.0));
  return ts;
}

/// a(t) * b(t) with the broadcasting rules of seam::product (scalar * vector, vector * scalar, or
/// componentwise).
VecX pointwiseProduct(const VecX& a, const VecX& b) {
  if (a.size() == 1) return a[0] * b;
  if (b.size() == 1) return b[0] * a;
  return a.cwiseProduct(b);
}

// ---------------------------------------------------------------------------------------------------------------------
// Univariate
// ---------------------------------------------------------------------------------------------------------------------

TEST(BernsteinPoly, BinomialMatchesMultiplicativeFormula) {
  for (int n = 0; n <= 40; ++n)
    for (int k = 0; k <= n; ++k) EXPECT_EQ(binomial(n, k), test::refBinomial(n, k)) << n << " choose " << k;
}

TEST(BernsteinPoly, EvaluationMatchesExplicitSum) {
  std::mt19937_64 rng(101);
  for (int dim : kDims)
    for (int n = 0; n <= kMaxDegree; ++n) {
      const BernsteinPoly p = randomPoly(rng, n, dim);
      ASSERT_EQ(p.degree(), n);
      ASSERT_EQ(p.dim(), dim);
      std::vector<double> ts = unitSamples(rng, 20);
      for (int k = 0; k < 5; ++k) ts.push_back(uniformReal(rng, -0.5, 1.5));  // "valid for any t"
      for (double t : ts) {
        const VecX expected = refBernsteinEval(p.coeffs(), t);
        const double bound = test::kRoundoffTol * maxAbs(p.coeffs()) * amplification(n, t);
        ASSERT_TRUE(closeTo(expected, p(t), bound)) << "degree " << n << " dim " << dim << " t " << t;
        if (dim == 1) {
          ASSERT_NEAR(p.scalar(t), expected[0], bound) << "degree " << n << " t " << t;
        }
      }
    }
}

TEST(BernsteinPoly, DerivativeMatchesExplicitSumPowerBasisAndFiniteDifferences) {
  std::mt19937_64 rng(102);
  for (int dim : kDims)
    for (int n = 0; n <= kMaxDegree; ++n) {
      const BernsteinPoly p = randomPoly(rng, n, dim);
      const double c = maxAbs(p.coeffs());
      Matrix power = test::refBernsteinToPower(p.coeffs());
      for (int k = 0; k <= n + 2; ++k) {
        const BernsteinPoly d = p.derivative(k);
        ASSERT_EQ(d.degree(), std::max(n - k, 0)) << "degree " << n << " order " << k;
        ASSERT_EQ(d.dim(), dim);
        const double scale = derivativeScale(n, k, c);
        for (double t : unitSamples(rng, 12)) {
          // Explicit derivative of the Bernstein basis (Leibniz rule on t^i (1-t)^(n-i)).
          ASSERT_TRUE(closeTo(refBernsteinEval(p.coeffs(), t, k), d(t),
                              test::kRoundoffTol * scale + test::kExactZeroFloor))
              << "explicit, degree " << n << " order " << k << " t " << t;
          // Differentiated power series.
          ASSERT_TRUE(closeTo(test::refPowerEval(power, t), d(t), kPowerBasisTol * std::max(scale, c)))
              << "power basis, degree " << n << " order " << k << " t " << t;
        }
        // Finite differences of the explicit (k-1)-th derivative, away from the ends so the stencil stays in
        // [0,1].
        if (k >= 1 && k <= 3) {
          for (int s = 0; s < 5; ++s) {
            const double t = uniformReal(rng, 0.05, 0.95);
            const VecX fd = test::richardsonDerivative(
                [&](double x) { return refBernsteinEval(p.coeffs(), x, k - 1); }, t, kFdStep);
            ASSERT_TRUE(closeTo(fd, d(t), test::kFdRelTol * std::max(scale, c)))
                << "finite differences, degree " << n << " order " << k << " t " << t;
          }
        }
        power = test::refPowerDerivative(power);
      }
    }
}

TEST(BernsteinPoly, ProductIsPointwiseProductOfFactors) {
  std::mt19937_64 rng(103);
  const std::pair<int, int> dimPairs[] = {{1, 1}, {1, 3}, {3, 1}, {3, 3}, {4, 4}, {1, 4}, {4, 1}};
  for (auto [da, db] : dimPairs)
    for (int trial = 0; trial < 12; ++trial) {
      const int na = uniformInt(rng, 0, kMaxDegree), nb = uniformInt(rng, 0, kMaxDegree);
      const BernsteinPoly a = randomPoly(rng, na, da), b = randomPoly(rng, nb, db);
      const BernsteinPoly ab = product(a, b);
      ASSERT_EQ(ab.degree(), na + nb);
      ASSERT_EQ(ab.dim(), std::max(da, db));
      const double bound = test::kRoundoffTol * maxAbs(a.coeffs()) * maxAbs(b.coeffs());
      for (double t : unitSamples(rng, 15)) {
        const VecX expected =
            pointwiseProduct(refBernsteinEval(a.coeffs(), t), refBernsteinEval(b.coeffs(), t));
        ASSERT_TRUE(closeTo(expected, ab(t), bound))
            << "dims " << da << "x" << db << " degrees " << na << "+" << nb;
      }
    }
}

TEST(BernsteinPoly, DotCrossTripleArePointwise) {
  std::mt19937_64 rng(104);
  for (int dim : kDims)
    for (int trial = 0; trial < 15; ++trial) {
      const int na = uniformInt(rng, 0, kMaxDegree), nb = uniformInt(rng, 0, kMaxDegree);
      const BernsteinPoly a = randomPoly(rng, na, dim), b = randomPoly(rng, nb, dim);
      const BernsteinPoly d = dot(a, b);
      ASSERT_EQ(d.degree(), na + nb);
      ASSERT_EQ(d.dim(), 1);
      const double bound = test::kRoundoffTol * dim * maxAbs(a.coeffs()) * maxAbs(b.coeffs());
      for (double t : unitSamples(rng, 10)) {
        const double expected = refBernsteinEval(a.coeffs(), t).dot(refBernsteinEval(b.coeffs(), t));
        ASSERT_NEAR(d.scalar(t), expected, bound) << "dot, dim " << dim << " degrees " << na << "+" << nb;
      }
    }
  for (int trial = 0; trial < 25; ++trial) {
    const int na = uniformInt(rng, 0, kMaxDegree), nb = uniformInt(rng, 0, kMaxDegree),
              nc = uniformInt(rng, 0, 6);
    const BernsteinPoly a = randomPoly(rng, na, 3), b = randomPoly(rng, nb, 3), c = randomPoly(rng, nc, 3);
    const BernsteinPoly x = cross(a, b);
    const BernsteinPoly tr = triple(a, b, c);
    ASSERT_EQ(x.degree(), na + nb);
    ASSERT_EQ(x.dim(), 3);
    ASSERT_EQ(tr.degree(), na + nb + nc);
    ASSERT_EQ(tr.dim(), 1);
    const double ab = maxAbs(a.coeffs()) * maxAbs(b.coeffs());
    for (double t : unitSamples(rng, 10)) {
      const Vec3 va = refBernsteinEval(a.coeffs(), t), vb = refBernsteinEval(b.coeffs(), t),
                 vc = refBernsteinEval(c.coeffs(), t);
      ASSERT_TRUE(closeTo(va.cross(vb), x(t), test::kRoundoffTol * 2 * ab))
          << "cross, degrees " << na << "," << nb;
      ASSERT_NEAR(tr.scalar(t), va.dot(vb.cross(vc)), test::kRoundoffTol * 6 * ab * maxAbs(c.coeffs()))
          << "triple, degrees " << na << "," << nb << "," << nc;
    }
  }
}

/// Products of degree 500-1000 take the power-of-two scaled binomials, above 1000 the per-term weights (the pcurve
/// route's compositions on real B-reps reach 750). Coefficients far from 1 (1e-9, 1e9) would overflow or lose the
/// unscaled form's binomial products (C(500, 250) C(480, 240) ~ 1e293); the values must still be the pointwise
/// products. Relative tolerance: the reference's own sums of ~1000 terms and the products' ~(n + m) eps each.
constexpr double kHighDegreeTol = 1e-10;
TEST(BernsteinPoly, HighDegreeProductsDotsAndCrossesArePointwise) {
  std::mt19937_64 rng(1000);
  const std::pair<int, int> degrees[] = {{260, 250}, {480, 500}, {700, 200}, {520, 500}, {0, 900}};
  const double scales[] = {1e-9, 1.0, 1e9};
  for (auto [na, nb] : degrees)
    for (double sa : scales) {
      const double sb = scales[static_cast<size_t>(uniformInt(rng, 0, 2))];
      const BernsteinPoly a(randomMatrix(rng, na + 1, 3, -sa, sa)), b(randomMatrix(rng, nb + 1, 3, -sb, sb));
      const BernsteinPoly ax = a.component(0), p = product(ax, b), d = dot(a, b), x = cross(a, b);
      ASSERT_EQ(p.degree(), na + nb);
      ASSERT_EQ(x.degree(), na + nb);
      const double bound = kHighDegreeTol * sa * sb;
      for (double t : unitSamples(rng, 8)) {
        const VecX va = refBernsteinEval(a.coeffs(), t), vb = refBernsteinEval(b.coeffs(), t);
        const std::string at = "degrees " + std::to_string(na) + "+" + std::to_string(nb) + " scales " +
                               std::to_string(sa) + "," + std::to_string(sb) + " t " + std::to_string(t);
        ASSERT_TRUE(closeTo(VecX(va[0] * vb), p(t), bound)) << "product, " << at;
        ASSERT_NEAR(d.scalar(t), va.dot(vb), 3 * bound) << "dot, " << at;
        ASSERT_TRUE(closeTo(VecX(Vec3(va).cross(Vec3(vb))), x(t), 2 * bound)) << "cross, " << at;
      }
    }
}

TEST(BernsteinPoly, ElevationByAnyAmountPreservesValues) {
  std::mt19937_64 rng(105);
  for (int dim : kDims)
    for (int n = 0; n <= kMaxDegree; ++n)
      for (int by = 0; by <= 6; ++by) {
        const BernsteinPoly p = randomPoly(rng, n, dim);
        const BernsteinPoly e = p.elevated(by);
        const BernsteinPoly f = p.elevatedTo(n + by);
        ASSERT_EQ(e.degree(), n + by);
        ASSERT_EQ(f.degree(), n + by);
        ASSERT_EQ(e.dim(), dim);
        const double bound = test::kRoundoffTol * maxAbs(p.coeffs());
        for (double t : unitSamples(rng, 10)) {
          const VecX expected = refBernsteinEval(p.coeffs(), t);
          ASSERT_TRUE(closeTo(expected, e(t), bound)) << "elevated(" << by << ") of degree " << n;
          ASSERT_TRUE(closeTo(expected, f(t), bound)) << "elevatedTo(" << n + by << ") of degree " << n;
        }
        // Elevated coefficients are convex combinations of the old ones: the hull can only shrink.
        ASSERT_LE(maxAbs(e.coeffs()), maxAbs(p.coeffs()) * (1 + test::kRoundoffTol));
      }
}

TEST(BernsteinPoly, SubdivisionPiecesReproduceThePolynomial) {
  std::mt19937_64 rng(106);
  for (int dim : kDims)
    for (int n = 0; n <= kMaxDegree; ++n) {
      const BernsteinPoly p = randomPoly(rng, n, dim);
      for (double t : {0.5, uniformReal(rng, 0.0, 1.0), uniformReal(rng, 0.0, 0.05), 0.0, 1.0}) {
        const auto [left, right] = p.subdivided(t);
        ASSERT_EQ(left.degree(), n);
        ASSERT_EQ(right.degree(), n);
        const double bound = test::kRoundoffTol * maxAbs(p.coeffs());
        for (double s : unitSamples(rng, 10)) {
          ASSERT_TRUE(closeTo(refBernsteinEval(p.coeffs(), t * s), left(s), bound))
              << "left piece, degree " << n << " t " << t << " s " << s;
          ASSERT_TRUE(closeTo(refBernsteinEval(p.coeffs(), t + s * (1 - t)), right(s), bound))
              << "right piece, degree " << n << " t " << t << " s " << s;
        }
      }
    }
}

TEST(BernsteinPoly, RestrictionToAnyIntervalIncludingReversedAndOutside) {
  std::mt19937_64 rng(107);
  for (int dim : kDims)
    for (int n = 0; n <= kMaxDegree; ++n) {
      const BernsteinPoly p = randomPoly(rng, n, dim);
      std::vector<std::pair<double, double>> intervals = {{0.0, 1.0}, {1.0, 0.0}, {0.25, 0.75}};
      for (int k = 0; k < 3; ++k) {
        const double a = uniformReal(rng, 0.0, 1.0), b = uniformReal(rng, 0.0, 1.0);
        intervals.emplace_back(a, b);  // inside, any order
        const double p1 = uniformReal(rng, -1.0, 2.0), p0 = uniformReal(rng, -1.0, 2.0);  // drawn last first
        intervals.emplace_back(p0, p1);  // partly outside
      }
      intervals.emplace_back(1.2, 1.9);    // entirely right of [0,1]
      intervals.emplace_back(-0.3, -1.1);  // entirely left, reversed
      for (auto [a, b] : intervals) {
        if (a == b) continue;
        const BernsteinPoly q = p.restricted(a, b);
        ASSERT_EQ(q.degree(), n);
        ASSERT_EQ(q.dim(), dim);
        const double bound =
            test::kRoundoffTol * maxAbs(p.coeffs()) * std::max(amplification(n, a), amplification(n, b));
        for (double s : unitSamples(rng, 10))
          ASSERT_TRUE(closeTo(refBernsteinEval(p.coeffs(), a + s * (b - a)), q(s), bound))
              << "degree " << n << " [" << a << ", " << b << "] s " << s;
      }
    }
}

// De Casteljau on whole coefficient rows, as BernsteinPoly::restricted computed it before it worked on the raw
// coefficients (issue 16 goal 2): the restriction routes must keep those bits.
Matrix restrictedByRows(Matrix w, double a, double b) {
  const Eigen::Index n = w.rows() - 1;
  auto subdivide = [&](double t, bool keepLeft) {
    const double s = 1.0 - t;
    if (keepLeft) {
      for (Eigen::Index r = 1; r <= n; ++r)
        for (Eigen::Index i = n; i >= r; --i) w.row(i) = s * w.row(i - 1) + t * w.row(i);
    } else {
      for (Eigen::Index r = 1; r <= n; ++r)
        for (Eigen::Index i = 0; i <= n - r; ++i) w.row(i) = s * w.row(i) + t * w.row(i + 1);
    }
  };
  if (b < 1.0) subdivide(b, true);
  if (a > 0.0) subdivide(a / b, false);
  return w;
}

TEST(BernsteinPoly, RestrictionRoutesGiveTheSameBits) {
  // restricted() and the allocation-free detail::restrictedCoeffs (the certified bounds' route) against the row-wise
  // de Casteljau they replace, bit for bit inside [0, 1]; elsewhere (reversed, outside) restrictedCoeffs gives
  // restricted()'s coefficients. The scratch buffer is reused across sizes (grown, never shrunk).
  std::mt19937_64 rng(1601);
  std::vector<double> scratch;
  // Degrees 63..480 in one component: the four-lane scalar subdivision (the pcurve route's P, Q, R).
  std::vector<std::pair<int, int>> cases;
  for (int dim : {1, 2, 3, 4, 7})
    for (int n = 0; n <= 14; ++n) cases.emplace_back(dim, n);
  for (int n : {63, 64, 65, 66, 67, 100, 257, 480}) cases.emplace_back(1, n);
  for (auto [dim, n] : cases) {
    const BernsteinPoly p = randomPoly(rng, n, dim);
    std::vector<std::pair<double, double>> intervals = {{0.0, 1.0}, {0.0, 0.5}, {0.5, 1.0}, {0.25, 0.75},
                                                        {1.0, 0.0}, {1.2, 1.9},  {-0.3, 0.4}};
    for (int k = 0; k < 6; ++k) {
      const double a = uniformReal(rng, 0.0, 1.0), b = uniformReal(rng, 0.0, 1.0);
      intervals.emplace_back(std::min(a, b), std::max(a, b));
      intervals.emplace_back(std::max(a, b), std::min(a, b));
    }
    for (auto [a, b] : intervals) {
      if (a == b) continue;
      const Matrix viaPoly = p.restricted(a, b).coeffs();
      const Eigen::Map<const Matrix> viaScratch = detail::restrictedCoeffs(p, a, b, scratch);
      ASSERT_EQ(viaScratch.rows(), viaPoly.rows());
      ASSERT_EQ(viaScratch.cols(), viaPoly.cols());
      for (Eigen::Index i = 0; i < viaPoly.size(); ++i)
        ASSERT_EQ(viaScratch.data()[i], viaPoly.data()[i]) << "degree " << n << " dim " << dim << " [" << a << ", " << b << "]";
      if (a >= 0.0 && a < b && b <= 1.0) {
        const Matrix byRows = restrictedByRows(p.coeffs(), a, b);
        for (Eigen::Index i = 0; i < byRows.size(); ++i)
          ASSERT_EQ(viaPoly.data()[i], byRows.data()[i]) << "degree " << n << " dim " << dim << " [" << a << ", " << b << "]";
        // The bounds' reductions on the view are those of BernsteinPoly on the copy.
        ASSERT_EQ(viaScratch.col(0).minCoeff(), p.restricted(a, b).coeffs().col(0).minCoeff());
        ASSERT_EQ(viaScratch.rowwise().norm().maxCoeff(), p.restricted(a, b).maxCoeffNorm());
        ASSERT_EQ(viaScratch.cwiseAbs().maxCoeff(), p.restricted(a, b).maxAbsCoeff());
      }
    }
  }
}

TEST(BernsteinPoly, SplitHalvesAreTheRestrictionsToEachHalf) {
  // detail::splitHalves (the certified bounds' subdivision tree at degree >= 32) against the restriction route:
  // one split gives restricted(0, 1/2) and restricted(1/2, 1) bit for bit (the same lerps 0.5 a + 0.5 b, with one
  // subdivision each there); ten nested splits down to [k / 1024, (k + 1) / 1024] agree with the direct restriction
  // of the whole polynomial to within the round-off of the levels (each a convex combination: one rounding of the
  // largest coefficient per level), and with the polynomial's values at the ends of the interval.
  std::mt19937_64 rng(2711);
  std::vector<std::pair<int, int>> cases;
  for (int dim : {1, 3})
    for (int n = 0; n <= 14; ++n) cases.emplace_back(dim, n);
  for (int n : {31, 32, 33, 63, 64, 65, 100, 257, 480}) cases.emplace_back(1, n);
  cases.emplace_back(3, 40);
  std::vector<double> scratch;
  for (auto [dim, n] : cases) {
    const BernsteinPoly p = randomPoly(rng, n, dim);
    const auto size = static_cast<size_t>((n + 1) * dim);
    std::vector<double> left(size), right(size);
    detail::splitHalves(p.coeffs().data(), n, dim, left.data(), right.data());
    const Matrix l = p.restricted(0.0, 0.5).coeffs(), r = p.restricted(0.5, 1.0).coeffs();
    for (size_t i = 0; i < size; ++i) {
      ASSERT_EQ(left[i], l.data()[i]) << "degree " << n << " dim " << dim;
      ASSERT_EQ(right[i], r.data()[i]) << "degree " << n << " dim " << dim;
    }
    // Ten nested splits along a random path.
    std::vector<double> cur(p.coeffs().data(), p.coeffs().data() + size);
    double lo = 0.0, hi = 1.0;
    for (int depth = 1; depth <= 10; ++depth) {
      detail::splitHalves(cur.data(), n, dim, left.data(), right.data());
      const double mid = 0.5 * (lo + hi);
      if (rng() % 2 == 0) {
        cur = left;
        hi = mid;
      } else {
        cur = right;
        lo = mid;
      }
    }
    const Eigen::Map<const Matrix> direct = detail::restrictedCoeffs(p, lo, hi, scratch);
    const double scale = p.coeffs().cwiseAbs().maxCoeff();
    const double tol = 4.0 * 10 * (n + 1) * std::numeric_limits<double>::epsilon() * scale;
    for (size_t i = 0; i < size; ++i) ASSERT_NEAR(cur[i], direct.data()[i], tol) << "degree " << n << " dim " << dim;
    const VecX atLo = p(lo), atHi = p(hi);
    for (int k = 0; k < dim; ++k) {
      EXPECT_NEAR(cur[static_cast<size_t>(k)], atLo[k], tol) << "degree " << n;
      EXPECT_NEAR(cur[static_cast<size_t>(n * dim + k)], atHi[k], tol) << "degree " << n;
    }
  }
}

TEST(BernsteinPoly, EvaluationKeepsTheRowWiseBits) {
  // operator() runs de Casteljau on a stack copy of the coefficients (a heap copy above 256 values) instead of
  // whole-row expressions: the same value bit for bit, below and above that size (degree 80 in 4 components).
  std::mt19937_64 rng(1604);
  for (int dim : {1, 3, 4})
    for (int n : {0, 1, 2, 3, 5, 9, 20, 64, 65, 80, 200, 480}) {
      const BernsteinPoly p = randomPoly(rng, n, dim);
      for (double t : {0.0, 1.0, 0.5, uniformReal(rng, 0.0, 1.0), uniformReal(rng, -0.5, 1.5)}) {
        Matrix w = p.coeffs();
        for (Eigen::Index r = 1; r <= n; ++r)
          for (Eigen::Index i = 0; i <= n - r; ++i) w.row(i) = (1.0 - t) * w.row(i) + t * w.row(i + 1);
        const VecX v = p(t);
        ASSERT_EQ(v.size(), dim);
        for (int k = 0; k < dim; ++k) ASSERT_EQ(v[k], w(0, k)) << "degree " << n << " dim " << dim << " t " << t;
      }
    }
}

// Products column by column through binomially scaled copies, as productRows computed them before it worked on
// whole rows (issue 16 goal 6): products, compositions and their bounds must keep those bits.
Matrix productByColumns(const Matrix& a, const Matrix& b) {
  const int n = static_cast<int>(a.rows()) - 1, m = static_cast<int>(b.rows()) - 1;
  const Eigen::Index dim = std::max(a.cols(), b.cols());
  Matrix out = Matrix::Zero(n + m + 1, dim);
  std::vector<double> sa(static_cast<size_t>(n) + 1), sb(static_cast<size_t>(m) + 1), so(static_cast<size_t>(n + m) + 1);
  for (Eigen::Index c = 0; c < dim; ++c) {
    const Eigen::Index ca = a.cols() == 1 ? 0 : c, cb = b.cols() == 1 ? 0 : c;
    for (int i = 0; i <= n; ++i) sa[static_cast<size_t>(i)] = a(i, ca) * binomial(n, i);
    for (int j = 0; j <= m; ++j) sb[static_cast<size_t>(j)] = b(j, cb) * binomial(m, j);
    std::fill(so.begin(), so.end(), 0.0);
    for (int i = 0; i <= n; ++i)
      for (int j = 0; j <= m; ++j) so[static_cast<size_t>(i + j)] += sa[static_cast<size_t>(i)] * sb[static_cast<size_t>(j)];
    for (int k = 0; k <= n + m; ++k) out(k, c) = so[static_cast<size_t>(k)] / binomial(n + m, k);
  }
  return out;
}

// p(w) by de Casteljau with polynomial arithmetic through product() and operator+ (b_i <- (1 - w) b_i + w b_{i+1}).
BernsteinPoly composedByProducts(const Matrix& rows, int n, int m0, const BernsteinPoly& a, const BernsteinPoly& w) {
  std::vector<BernsteinPoly> b;
  for (int i = 0; i <= n; ++i) b.emplace_back(Matrix(rows.middleRows(static_cast<Eigen::Index>(i) * (m0 + 1), m0 + 1)));
  for (int r = 1; r <= n; ++r)
    for (int i = 0; i <= n - r; ++i)
      b[static_cast<size_t>(i)] = product(a, b[static_cast<size_t>(i)]) + product(w, b[static_cast<size_t>(i + 1)]);
  return b.front();
}

void expectSameBits(const Matrix& x, const Matrix& y, const std::string& what) {
  ASSERT_EQ(x.rows(), y.rows()) << what;
  ASSERT_EQ(x.cols(), y.cols()) << what;
  for (Eigen::Index i = 0; i < x.size(); ++i) ASSERT_EQ(x.data()[i], y.data()[i]) << what << " value " << i;
}

TEST(BernsteinPoly, ProductsAndCompositionsKeepTheColumnWiseBits) {
  std::mt19937_64 rng(1606);
  const std::pair<int, int> dims[] = {{1, 1}, {1, 3}, {3, 1}, {3, 3}, {1, 4}, {4, 1}, {4, 4}, {2, 2}, {1, 7}};
  for (int trial = 0; trial < 60; ++trial) {
    const int n = trial % 3 == 0 ? uniformInt(rng, 0, 12) : uniformInt(rng, 0, 250);
    const int m = trial % 3 == 0 ? uniformInt(rng, 0, 40) : uniformInt(rng, 0, 250);
    for (auto [da, db] : dims) {
      const BernsteinPoly a = randomPoly(rng, n, da), b = randomPoly(rng, m, db);
      expectSameBits(product(a, b).coeffs(), productByColumns(a.coeffs(), b.coeffs()),
                     "product " + std::to_string(n) + " x " + std::to_string(m));
    }
  }
  for (int trial = 0; trial < 120; ++trial) {
    const int k = trial % 5, kv = (trial / 5) % 4, dim = 1 + trial % 4;
    const int n = uniformInt(rng, 0, 10), du = uniformInt(rng, 0, 7), dv = uniformInt(rng, 0, 7);
    const BernsteinPoly p = randomPoly(rng, n, dim), w = randomPoly(rng, k, 1);
    const BernsteinPoly oneMinus = BernsteinPoly::constant(1.0, k) - w;
    expectSameBits(p.composed(w).coeffs(), composedByProducts(p.coeffs(), n, 0, oneMinus, w).coeffs(), "composed");
    const BernsteinPatch P(du, dv, test::randomMatrix(rng, (du + 1) * (dv + 1), dim));
    const BernsteinPoly u = randomPoly(rng, k, 1), v = randomPoly(rng, kv, 1);
    const BernsteinPoly oneMinusV = BernsteinPoly::constant(1.0, kv) - v, oneMinusU = BernsteinPoly::constant(1.0, k) - u;
    Matrix rows(static_cast<Eigen::Index>(du + 1) * (dv * kv + 1), dim);
    for (int i = 0; i <= du; ++i)
      rows.middleRows(static_cast<Eigen::Index>(i) * (dv * kv + 1), dv * kv + 1) =
          composedByProducts(P.coeffs().middleRows(static_cast<Eigen::Index>(i) * (dv + 1), dv + 1), dv, 0, oneMinusV, v)
              .coeffs();
    expectSameBits(P.composed(u, v).coeffs(), composedByProducts(rows, du, dv * kv, oneMinusU, u).coeffs(),
                   "patch composed");
    // Rational: w^(du + dv) P(u / w, v / w) by the homogeneous de Casteljau ((w - x) b_i + x b_{i+1}).
    const BernsteinPoly hu = randomPoly(rng, k, 1), hv = randomPoly(rng, k, 1), hw = randomPoly(rng, k, 1);
    const BernsteinPoly wMinusV = hw - hv, wMinusU = hw - hu;
    Matrix hrows(static_cast<Eigen::Index>(du + 1) * (dv * k + 1), dim);
    for (int i = 0; i <= du; ++i)
      hrows.middleRows(static_cast<Eigen::Index>(i) * (dv * k + 1), dv * k + 1) =
          composedByProducts(P.coeffs().middleRows(static_cast<Eigen::Index>(i) * (dv + 1), dv + 1), dv, 0, wMinusV, hv)
              .coeffs();
    expectSameBits(P.composed(hu, hv, hw).coeffs(), composedByProducts(hrows, du, dv * k, wMinusU, hu).coeffs(),
                   "rational patch composed");
  }
}

// The cross product row by row through binomially scaled copies with Eigen's Vector3d::cross, as cross() computed it
// before its sums ran by column (issue 16 goal 6): the composed normals and everything bounded from them keep those
// bits.
Matrix crossByRows(const Matrix& a, const Matrix& b) {
  const int n = static_cast<int>(a.rows()) - 1, m = static_cast<int>(b.rows()) - 1;
  Matrix as = a, bs = b;
  for (int i = 0; i <= n; ++i) as.row(i) *= binomial(n, i);
  for (int j = 0; j <= m; ++j) bs.row(j) *= binomial(m, j);
  Matrix out = Matrix::Zero(n + m + 1, 3);
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= m; ++j)
      out.row(i + j) += Eigen::Vector3d(as.row(i).transpose()).cross(Eigen::Vector3d(bs.row(j).transpose())).transpose();
  for (int k = 0; k <= n + m; ++k) out.row(k) /= binomial(n + m, k);
  return out;
}

TEST(BernsteinPoly, CrossKeepsTheRowWiseBits) {
  std::mt19937_64 rng(1627);
  for (int trial = 0; trial < 80; ++trial) {
    // Both sides of the four-lane threshold (degree 8 of B) and up to the scaled form's limit (n + m <= 500).
    const int n = trial % 4 == 0 ? uniformInt(rng, 0, 12) : uniformInt(rng, 0, 250);
    const int m = trial % 4 == 1 ? uniformInt(rng, 0, 12) : uniformInt(rng, 0, 250);
    const BernsteinPoly a = randomPoly(rng, n, 3), b = randomPoly(rng, m, 3);
    expectSameBits(cross(a, b).coeffs(), crossByRows(a.coeffs(), b.coeffs()),
                   "cross " + std::to_string(n) + " x " + std::to_string(m));
  }
}

// Degree elevation by row expressions with binomial() per term, as elevateRows computed it before it ran on raw rows
// (issue 16 goal 6): the sums of the rational pieces (WeightContext::add) keep those bits.
Matrix elevatedByRows(const Matrix& c, int by) {
  const int n = static_cast<int>(c.rows()) - 1;
  Matrix out = Matrix::Zero(n + by + 1, c.cols());
  for (int i = 0; i <= n + by; ++i) {
    const double denom = binomial(n + by, i);
    for (int j = std::max(0, i - by); j <= std::min(n, i); ++j)
      out.row(i) += (binomial(n, j) * binomial(by, i - j) / denom) * c.row(j);
  }
  return out;
}

TEST(BernsteinPoly, ElevationKeepsTheRowWiseBits) {
  std::mt19937_64 rng(1631);
  for (int trial = 0; trial < 60; ++trial) {
    const int n = trial % 3 == 0 ? uniformInt(rng, 0, 12) : uniformInt(rng, 0, 250);
    const int by = trial % 3 == 1 ? uniformInt(rng, 1, 12) : uniformInt(rng, 1, 250);
    const BernsteinPoly p = randomPoly(rng, n, 1 + trial % 4);
    expectSameBits(p.elevated(by).coeffs(), elevatedByRows(p.coeffs(), by),
                   "elevated " + std::to_string(n) + " by " + std::to_string(by));
  }
}

TEST(BernsteinPoly, ReversedIsPOfOneMinusS) {
  std::mt19937_64 rng(108);
  for (int dim : kDims)
    for (int n = 0; n <= kMaxDegree; ++n) {
      const BernsteinPoly p = randomPoly(rng, n, dim);
      const BernsteinPoly r = p.reversed();
      ASSERT_EQ(r.degree(), n);
      for (int i = 0; i <= n; ++i)  // exact: the coefficients are simply read backwards
        ASSERT_EQ(Matrix(r.coeffs().row(i)), Matrix(p.coeffs().row(n - i))) << "degree " << n << " row " << i;
      for (double s : unitSamples(rng, 8))
        ASSERT_TRUE(
            closeTo(refBernsteinEval(p.coeffs(), 1 - s), r(s), test::kRoundoffTol * maxAbs(p.coeffs())));
    }
}

TEST(BernsteinPoly, CompositionWithRandomPolynomial) {
  std::mt19937_64 rng(109);
  for (int dim : kDims)
    for (int n = 0; n <= 6; ++n)
      for (int m = 0; m <= 4; ++m) {
        const BernsteinPoly p = randomPoly(rng, n, dim);
        // w has coefficients in [-0.5, 1.5]: w(s) leaves [0,1] sometimes.
        const BernsteinPoly w(randomMatrix(rng, m + 1, 1, -0.5, 1.5));
        const BernsteinPoly q = p.composed(w);
        ASSERT_EQ(q.degree(), n * m) << "degree " << n << " o degree " << m;
        ASSERT_EQ(q.dim(), dim);
        // Round-off of the composition: coefficients of p amplified by at most (|w_i| + |1-w_i|)^n <= 2^n,
        // plus the error of w(s) times |p'| <= 2 n 2^n max|c| (a generous but still O(1e-9) bound).
        double amp = 1.0;
        for (int i = 0; i <= m; ++i) amp = std::max(amp, amplification(n, w.coeffs()(i, 0)));
        const double bound = test::kRoundoffTol * maxAbs(p.coeffs()) * amp * (1 + 2 * n);
        for (double s : unitSamples(rng, 12)) {
          const double ws = refBernsteinEval(w.coeffs(), s)[0];
          ASSERT_TRUE(closeTo(refBernsteinEval(p.coeffs(), ws), q(s), bound))
              << "degree " << n << " o degree " << m << " s " << s << " w(s) " << ws;
        }
      }
}

TEST(BernsteinPoly, CompositionWithAffineMapEqualsRestriction) {
  // p(a + (b-a) s) by composition with the linear polynomial and by restriction: two routes, one result.
  std::mt19937_64 rng(110);
  for (int n = 0; n <= kMaxDegree; ++n) {
    const BernsteinPoly p = randomPoly(rng, n, 3);
    const double a = uniformReal(rng, -0.5, 1.5), b = uniformReal(rng, -0.5, 1.5);
    const BernsteinPoly q = p.composed(BernsteinPoly::linear(a, b));
    ASSERT_EQ(q.degree(), n);
    for (double s : unitSamples(rng, 8))
      ASSERT_TRUE(closeTo(refBernsteinEval(p.coeffs(), a + (b - a) * s), q(s),
                          test::kRoundoffTol * maxAbs(p.coeffs()) * std::pow(2.0, n)));
  }
}

TEST(BernsteinPoly, FromPowerBasisMatchesPowerSeries) {
  // Hand cases: t^2 = B_2^2, t = B_1^1, and 1 - 2t + t^2 = (1-t)^2 = B_0^2.
  {
    VecX a(3);
    a << 0, 0, 1;
    const BernsteinPoly p = BernsteinPoly::fromPowerBasis(a);
    ASSERT_EQ(p.degree(), 2);
    EXPECT_NEAR(p.coeffs()(0, 0), 0.0, test::kFewUlps);
    EXPECT_NEAR(p.coeffs()(1, 0), 0.0, test::kFewUlps);
    EXPECT_NEAR(p.coeffs()(2, 0), 1.0, test::kFewUlps);
    a << 1, -2, 1;
    const BernsteinPoly q = BernsteinPoly::fromPowerBasis(a);
    EXPECT_NEAR(q.coeffs()(0, 0), 1.0, test::kFewUlps);
    EXPECT_NEAR(q.coeffs()(1, 0), 0.0, test::kFewUlps);
    EXPECT_NEAR(q.coeffs()(2, 0), 0.0, test::kFewUlps);
  }
  std::mt19937_64 rng(111);
  for (int size = 1; size <= 10; ++size)
    for (int trial = 0; trial < 5; ++trial) {
      VecX a(size);
      for (int k = 0; k < size; ++k) a[k] = uniformReal(rng, -1.0, 1.0);
      const BernsteinPoly p = BernsteinPoly::fromPowerBasis(a);
      ASSERT_EQ(p.degree(), size - 1);
      ASSERT_EQ(p.dim(), 1);
      const Matrix am = a;
      for (double t : unitSamples(rng, 12))
        ASSERT_NEAR(p.scalar(t), test::refPowerEval(am, t)[0], test::kRoundoffTol * a.cwiseAbs().sum())
            << "size " << size << " t " << t;
    }
}

TEST(BernsteinPoly, CoefficientBoundsEncloseTheValues) {
  std::mt19937_64 rng(112);
  constexpr int kSamples = 1001;  // dense sampling of [0,1]
  for (int dim : kDims)
    for (int n = 0; n <= kMaxDegree; ++n) {
      const BernsteinPoly p = randomPoly(rng, n, dim);
      const VecX lo = p.minCoeff(), hi = p.maxCoeff();
      // They are the coefficient extremes (computed here directly).
      ASSERT_TRUE(closeTo(p.coeffs().colwise().minCoeff().transpose(), lo, 0.0));
      ASSERT_TRUE(closeTo(p.coeffs().colwise().maxCoeff().transpose(), hi, 0.0));
      ASSERT_EQ(p.maxAbsCoeff(), maxAbs(p.coeffs()));
      double maxNorm = 0.0;
      for (int i = 0; i <= n; ++i) maxNorm = std::max(maxNorm, p.coeffs().row(i).norm());
      ASSERT_NEAR(p.maxCoeffNorm(), maxNorm, test::kFewUlps * maxNorm);
      const double slack = test::kRoundoffTol * maxAbs(p.coeffs());
      for (int s = 0; s < kSamples; ++s) {
        const double t = static_cast<double>(s) / (kSamples - 1);
        const VecX v = refBernsteinEval(p.coeffs(), t);
        for (int c = 0; c < dim; ++c) {
          ASSERT_GE(v[c], lo[c] - slack) << "degree " << n << " t " << t;
          ASSERT_LE(v[c], hi[c] + slack) << "degree " << n << " t " << t;
        }
        ASSERT_LE(v.cwiseAbs().maxCoeff(), p.maxAbsCoeff() + slack);
        ASSERT_LE(v.norm(), p.maxCoeffNorm() + slack);
      }
    }
}

TEST(BernsteinPoly, ConstructorsAndArithmetic) {
  std::mt19937_64 rng(113);
  const BernsteinPoly z = BernsteinPoly::zero(4, 3);
  ASSERT_EQ(z.degree(), 4);
  ASSERT_EQ(z.dim(), 3);
  EXPECT_EQ(maxAbs(z.coeffs()), 0.0);
  EXPECT_TRUE(BernsteinPoly().empty());

  VecX c(3);
  c << 1.5, -2.0, 0.25;
  const BernsteinPoly k = BernsteinPoly::constant(c, 3);
  ASSERT_EQ(k.degree(), 3);
  const BernsteinPoly ks = BernsteinPoly::constant(-7.0);
  ASSERT_EQ(ks.degree(), 0);
  const BernsteinPoly lin = BernsteinPoly::linear(2.0, -1.0);
  ASSERT_EQ(lin.degree(), 1);
  for (double t : unitSamples(rng, 8)) {
    EXPECT_TRUE(closeTo(c, k(t), test::kFewUlps));
    EXPECT_NEAR(ks.scalar(t), -7.0, test::kFewUlps);
    EXPECT_NEAR(lin.scalar(t), 2.0 - 3.0 * t, test::kFewUlps);
  }

  for (int trial = 0; trial < 30; ++trial) {
    const int na = uniformInt(rng, 0, kMaxDegree), nb = uniformInt(rng, 0, kMaxDegree);
    const BernsteinPoly a = randomPoly(rng, na, 3), b = randomPoly(rng, nb, 3);
    const double s = uniformReal(rng, -3.0, 3.0);
    const BernsteinPoly sum = a + b, diff = a - b, neg = -a, left = s * a, right = a * s;
    BernsteinPoly inPlace = a;
    inPlace *= s;
    ASSERT_EQ(sum.degree(), std::max(na, nb));
    ASSERT_EQ(diff.degree(), std::max(na, nb));
    const double bound = test::kRoundoffTol * 4 * (maxAbs(a.coeffs()) + maxAbs(b.coeffs()));
    for (double t : unitSamples(rng, 6)) {
      const VecX va = refBernsteinEval(a.coeffs(), t), vb = refBernsteinEval(b.coeffs(), t);
      ASSERT_TRUE(closeTo(va + vb, sum(t), bound));
      ASSERT_TRUE(closeTo(va - vb, diff(t), bound));
      ASSERT_TRUE(closeTo(-va, neg(t), bound));
      ASSERT_TRUE(closeTo(s * va, left(t), bound));
      ASSERT_TRUE(closeTo(s * va, right(t), bound));
      ASSERT_TRUE(closeTo(s * va, inPlace(t), bound));
      for (int comp = 0; comp < 3; ++comp) {
        const BernsteinPoly ci = a.component(comp);
        ASSERT_EQ(ci.dim(), 1);
        ASSERT_NEAR(ci.scalar(t), va[comp], bound);
      }
    }
  }
}

TEST(BernsteinPoly, ProductOfDerivativesObeysLeibnizRule) {
  // (a b)' = a' b + a b': three routes through product and derivative, checked pointwise against explicit
  // sums.
  std::mt19937_64 rng(114);
  for (int trial = 0; trial < 20; ++trial) {
    const int na = uniformInt(rng, 0, kMaxDegree), nb = uniformInt(rng, 0, kMaxDegree);
    const BernsteinPoly a = randomPoly(rng, na, 1), b = randomPoly(rng, nb, 3);
    const BernsteinPoly lhs = product(a, b).derivative();
    const double bound = test::kRoundoffTol * 4 * (na + nb + 1) * maxAbs(a.coeffs()) * maxAbs(b.coeffs());
    for (double t : unitSamples(rng, 6)) {
      const VecX expected = refBernsteinEval(a.coeffs(), t, 1)[0] * refBernsteinEval(b.coeffs(), t) +
                            refBernsteinEval(a.coeffs(), t)[0] * refBernsteinEval(b.coeffs(), t, 1);
      ASSERT_TRUE(closeTo(expected, lhs(t), bound)) << "degrees " << na << "," << nb;
    }
  }
}

// ---------------------------------------------------------------------------------------------------------------------
// Tensor-product patches
// ---------------------------------------------------------------------------------------------------------------------

std::vector<Vec2> unitSamples2(std::mt19937_64& rng, int count) {
  std::vector<Vec2> uv{{0, 0}, {1, 0}, {0, 1}, {1, 1}};
  while (static_cast<int>(uv.size()) < count) {
    const double v = uniformReal(rng, 0, 1), u = uniformReal(rng, 0, 1);  // drawn last argument first (test_helpers.h)
    uv.emplace_back(u, v);
  }
  return uv;
}

TEST(BernsteinPatch, EvaluationMatchesExplicitSum) {
  std::mt19937_64 rng(201);
  for (int dim : kDims)
    for (int n = 0; n <= kMaxDegree; ++n)
      for (int m = 0; m <= kMaxDegree; m += 1 + (n % 2)) {
        const BernsteinPatch p = randomPatch(rng, n, m, dim);
        ASSERT_EQ(p.degreeU(), n);
        ASSERT_EQ(p.degreeV(), m);
        ASSERT_EQ(p.dim(), dim);
        // coeff(i, j) addresses row i*(m+1)+j.
        const int i = uniformInt(rng, 0, n), j = uniformInt(rng, 0, m);
        ASSERT_EQ(Matrix(p.coeff(i, j)), Matrix(p.coeffs().row(i * (m + 1) + j)));
        for (const Vec2& uv : unitSamples2(rng, 8))
          ASSERT_TRUE(closeTo(refPatchEval(n, m, p.coeffs(), uv[0], uv[1]), p(uv[0], uv[1]),
                              test::kRoundoffTol * maxAbs(p.coeffs())))
              << "degrees " << n << "," << m << " at " << uv.transpose();
      }
}

TEST(BernsteinPatch, DerivativeMatchesExplicitSumAndFiniteDifferences) {
  std::mt19937_64 rng(202);
  for (int dim : kDims)
    for (int trial = 0; trial < 12; ++trial) {
      const int n = uniformInt(rng, 0, kMaxDegree), m = uniformInt(rng, 0, kMaxDegree);
      const BernsteinPatch p = randomPatch(rng, n, m, dim);
      const double c = maxAbs(p.coeffs());
      for (int ku = 0; ku <= 3; ++ku)
        for (int kv = 0; kv <= 3; ++kv) {
          const BernsteinPatch d = p.derivative(ku, kv);
          ASSERT_EQ(d.degreeU(), std::max(n - ku, 0));
          ASSERT_EQ(d.degreeV(), std::max(m - kv, 0));
          ASSERT_EQ(d.dim(), dim);
          const double scale = derivativeScale(n, ku, 1.0) * derivativeScale(m, kv, 1.0) * c;
          for (const Vec2& uv : unitSamples2(rng, 6))
            ASSERT_TRUE(closeTo(refPatchEval(n, m, p.coeffs(), uv[0], uv[1], ku, kv), d(uv[0], uv[1]),
                                test::kRoundoffTol * scale + test::kExactZeroFloor))
                << "degrees " << n << "," << m << " derivative " << ku << "," << kv;
          if (ku + kv == 0) continue;
          // Finite differences of the explicit lower-order derivative (in u if ku > 0, else in v).
          for (int s = 0; s < 3; ++s) {
            const double u = uniformReal(rng, 0.05, 0.95), v = uniformReal(rng, 0.05, 0.95);
            const VecX fd =
                ku > 0 ? test::richardsonDerivative(
                             [&](double x) { return refPatchEval(n, m, p.coeffs(), x, v, ku - 1, kv); }, u,
                             kFdStep)
                       : test::richardsonDerivative(
                             [&](double y) { return refPatchEval(n, m, p.coeffs(), u, y, ku, kv - 1); }, v,
                             kFdStep);
            ASSERT_TRUE(closeTo(fd, d(u, v), test::kFdRelTol * std::max(scale, c)))
                << "finite differences, degrees " << n << "," << m << " derivative " << ku << "," << kv;
          }
        }
    }
}

TEST(BernsteinPatch, ElevationPreservesValues) {
  std::mt19937_64 rng(203);
  for (int dim : kDims)
    for (int trial = 0; trial < 15; ++trial) {
      const int n = uniformInt(rng, 0, 7), m = uniformInt(rng, 0, 7);
      const int bu = uniformInt(rng, 0, 4), bv = uniformInt(rng, 0, 4);
      const BernsteinPatch p = randomPatch(rng, n, m, dim);
      const BernsteinPatch e = p.elevated(bu, bv), f = p.elevatedTo(n + bu, m + bv);
      ASSERT_EQ(e.degreeU(), n + bu);
      ASSERT_EQ(e.degreeV(), m + bv);
      ASSERT_EQ(f.degreeU(), n + bu);
      ASSERT_EQ(f.degreeV(), m + bv);
      for (const Vec2& uv : unitSamples2(rng, 10)) {
        const VecX expected = refPatchEval(n, m, p.coeffs(), uv[0], uv[1]);
        ASSERT_TRUE(closeTo(expected, e(uv[0], uv[1]), test::kRoundoffTol * maxAbs(p.coeffs())));
        ASSERT_TRUE(closeTo(expected, f(uv[0], uv[1]), test::kRoundoffTol * maxAbs(p.coeffs())));
      }
    }
}

TEST(BernsteinPatch, RestrictionIncludingReversedAndOutsideIntervals) {
  std::mt19937_64 rng(204);
  for (int dim : kDims)
    for (int trial = 0; trial < 20; ++trial) {
      const int n = uniformInt(rng, 0, 7), m = uniformInt(rng, 0, 7);
      const BernsteinPatch p = randomPatch(rng, n, m, dim);
      const bool outside = trial % 2;
      const double lo = outside ? -1.0 : 0.0, hi = outside ? 2.0 : 1.0;
      const double u0 = uniformReal(rng, lo, hi), u1 = uniformReal(rng, lo, hi);  // any order: may reverse
      const double v0 = uniformReal(rng, lo, hi), v1 = uniformReal(rng, lo, hi);
      const BernsteinPatch q = p.restricted(u0, u1, v0, v1);
      ASSERT_EQ(q.degreeU(), n);
      ASSERT_EQ(q.degreeV(), m);
      const double bound = test::kRoundoffTol * maxAbs(p.coeffs()) *
                           std::max(amplification(n, u0), amplification(n, u1)) *
                           std::max(amplification(m, v0), amplification(m, v1));
      for (const Vec2& st : unitSamples2(rng, 10)) {
        const double u = u0 + st[0] * (u1 - u0), v = v0 + st[1] * (v1 - v0);
        ASSERT_TRUE(closeTo(refPatchEval(n, m, p.coeffs(), u, v), q(st[0], st[1]), bound))
            << "degrees " << n << "," << m << " box [" << u0 << "," << u1 << "]x[" << v0 << "," << v1 << "]";
      }
    }
}

TEST(BernsteinPatch, IsoCurvesAreExactSections) {
  std::mt19937_64 rng(205);
  for (int dim : kDims)
    for (int trial = 0; trial < 15; ++trial) {
      const int n = uniformInt(rng, 0, kMaxDegree), m = uniformInt(rng, 0, kMaxDegree);
      const BernsteinPatch p = randomPatch(rng, n, m, dim);
      const double fixed = trial == 0 ? 0.0 : trial == 1 ? 1.0 : uniformReal(rng, 0.0, 1.0);
      const BernsteinPoly cu = p.isoU(fixed);  // v -> p(fixed, v)
      const BernsteinPoly cv = p.isoV(fixed);  // u -> p(u, fixed)
      ASSERT_EQ(cu.degree(), m);
      ASSERT_EQ(cv.degree(), n);
      ASSERT_EQ(cu.dim(), dim);
      for (double s : unitSamples(rng, 8)) {
        ASSERT_TRUE(closeTo(refPatchEval(n, m, p.coeffs(), fixed, s), cu(s),
                            test::kRoundoffTol * maxAbs(p.coeffs())));
        ASSERT_TRUE(closeTo(refPatchEval(n, m, p.coeffs(), s, fixed), cv(s),
                            test::kRoundoffTol * maxAbs(p.coeffs())));
      }
    }
}

TEST(BernsteinPatch, CompositionWithAParameterCurveIsExact) {
  // p(u(t), v(t)) against the brute-force Bernstein sums of p at the brute-force values of u and v (scalar
  // polynomials with values in [0, 1] and beyond: composition is algebraic, not restricted to the unit square).
  std::mt19937_64 rng(207);
  for (int dim : kDims)
    for (int trial = 0; trial < 12; ++trial) {
      const int n = uniformInt(rng, 0, 5), m = uniformInt(rng, 0, 5);
      const int ru = uniformInt(rng, 0, 3), rv = uniformInt(rng, 0, 3);
      const BernsteinPatch p = randomPatch(rng, n, m, dim);
      const BernsteinPoly u = randomPoly(rng, ru, 1), v = randomPoly(rng, rv, 1);
      const BernsteinPoly c = p.composed(u, v);
      ASSERT_EQ(c.degree(), n * ru + m * rv);
      ASSERT_EQ(c.dim(), dim);
      for (double t : unitSamples(rng, 10)) {
        const double ut = refBernsteinEval(u.coeffs(), t)[0], vt = refBernsteinEval(v.coeffs(), t)[0];
        const double scale = maxAbs(p.coeffs()) * std::pow(1.0 + std::abs(ut) + std::abs(1.0 - ut), n) *
                             std::pow(1.0 + std::abs(vt) + std::abs(1.0 - vt), m);
        ASSERT_TRUE(closeTo(refPatchEval(n, m, p.coeffs(), ut, vt), c(t), test::kRoundoffTol * scale))
            << "n " << n << " m " << m << " ru " << ru << " rv " << rv << " t " << t;
      }
    }
}

TEST(BernsteinPatch, CompositionWithARationalParameterCurveIsHomogenised) {
  // w^(n+m) p(u/w, v/w) against w(t)^(n+m) times the brute-force Bernstein sums at u(t)/w(t), v(t)/w(t), with w
  // positive on [0, 1] (coefficients in [0.5, 2]).
  std::mt19937_64 rng(208);
  for (int dim : kDims)
    for (int trial = 0; trial < 12; ++trial) {
      const int n = uniformInt(rng, 0, 4), m = uniformInt(rng, 0, 4);
      const int r = uniformInt(rng, 0, 3);
      const BernsteinPatch p = randomPatch(rng, n, m, dim);
      const BernsteinPoly u = randomPoly(rng, r, 1), v = randomPoly(rng, r, 1);
      Matrix wc(r + 1, 1);
      for (int k = 0; k <= r; ++k) wc(k, 0) = std::uniform_real_distribution<double>(0.5, 2.0)(rng);
      const BernsteinPoly w(wc);
      const BernsteinPoly c = p.composed(u, v, w);
      ASSERT_EQ(c.degree(), (n + m) * r);
      ASSERT_EQ(c.dim(), dim);
      for (double t : unitSamples(rng, 10)) {
        const double wt = refBernsteinEval(w.coeffs(), t)[0];
        const double ut = refBernsteinEval(u.coeffs(), t)[0] / wt, vt = refBernsteinEval(v.coeffs(), t)[0] / wt;
        const double f = std::pow(wt, n + m);
        const double scale = f * maxAbs(p.coeffs()) * std::pow(1.0 + std::abs(ut) + std::abs(1.0 - ut), n) *
                             std::pow(1.0 + std::abs(vt) + std::abs(1.0 - vt), m);
        ASSERT_TRUE(closeTo(VecX(f * refPatchEval(n, m, p.coeffs(), ut, vt)), c(t), test::kRoundoffTol * scale))
            << "n " << n << " m " << m << " r " << r << " t " << t;
      }
    }
}

TEST(BernsteinPatch, SwappedAndReversed) {
  std::mt19937_64 rng(206);
  for (int dim : kDims)
    for (int trial = 0; trial < 15; ++trial) {
      const int n = uniformInt(rng, 0, kMaxDegree), m = uniformInt(rng, 0, kMaxDegree);
      const BernsteinPatch p = randomPatch(rng, n, m, dim);
      const BernsteinPatch sw = p.swapped(), ru = p.reversedU(), rv = p.reversedV();
      ASSERT_EQ(sw.degreeU(), m);
      ASSERT_EQ(sw.degreeV(), n);
      ASSERT_EQ(ru.degreeU(), n);
      ASSERT_EQ(rv.degreeV(), m);
      const double bound = test::kRoundoffTol * maxAbs(p.coeffs());
      for (const Vec2& uv : unitSamples2(rng, 8)) {
        const double u = uv[0], v = uv[1];
        ASSERT_TRUE(closeTo(refPatchEval(n, m, p.coeffs(), v, u), sw(u, v), bound)) << "swapped";
        ASSERT_TRUE(closeTo(refPatchEval(n, m, p.coeffs(), 1 - u, v), ru(u, v), bound)) << "reversedU";
        ASSERT_TRUE(closeTo(refPatchEval(n, m, p.coeffs(), u, 1 - v), rv(u, v), bound)) << "reversedV";
      }
    }
}

TEST(BernsteinPatch, ProductDotCrossArePointwise) {
  std::mt19937_64 rng(207);
  const std::pair<int, int> dimPairs[] = {{1, 1}, {1, 3}, {3, 1}, {3, 3}, {4, 4}};
  for (auto [da, db] : dimPairs)
    for (int trial = 0; trial < 6; ++trial) {
      const int na = uniformInt(rng, 0, 5), ma = uniformInt(rng, 0, 5), nb = uniformInt(rng, 0, 5),
                mb = uniformInt(rng, 0, 5);
      const BernsteinPatch a = randomPatch(rng, na, ma, da), b = randomPatch(rng, nb, mb, db);
      const BernsteinPatch ab = product(a, b);
      ASSERT_EQ(ab.degreeU(), na + nb);
      ASSERT_EQ(ab.degreeV(), ma + mb);
      ASSERT_EQ(ab.dim(), std::max(da, db));
      const double bound = test::kRoundoffTol * 4 * maxAbs(a.coeffs()) * maxAbs(b.coeffs());
      for (const Vec2& uv : unitSamples2(rng, 8)) {
        const VecX va = refPatchEval(na, ma, a.coeffs(), uv[0], uv[1]);
        const VecX vb = refPatchEval(nb, mb, b.coeffs(), uv[0], uv[1]);
        ASSERT_TRUE(closeTo(pointwiseProduct(va, vb), ab(uv[0], uv[1]), bound))
            << "product " << da << "x" << db;
        if (da == db) {
          const BernsteinPatch d = dot(a, b);
          ASSERT_EQ(d.dim(), 1);
          ASSERT_EQ(d.degreeU(), na + nb);
          ASSERT_TRUE(closeTo(VecX::Constant(1, va.dot(vb)), d(uv[0], uv[1]), bound)) << "dot dim " << da;
        }
        if (da == 3 && db == 3) {
          const BernsteinPatch x = cross(a, b);
          ASSERT_EQ(x.dim(), 3);
          ASSERT_EQ(x.degreeV(), ma + mb);
          ASSERT_TRUE(closeTo(Vec3(va).cross(Vec3(vb)), x(uv[0], uv[1]), bound)) << "cross";
        }
      }
    }
}

TEST(BernsteinPatch, CoefficientBoundsEncloseTheValues) {
  std::mt19937_64 rng(208);
  constexpr int kGrid = 41;  // dense 41 x 41 sampling of [0,1]^2
  for (int dim : kDims)
    for (int trial = 0; trial < 8; ++trial) {
      const int n = uniformInt(rng, 0, kMaxDegree), m = uniformInt(rng, 0, kMaxDegree);
      const BernsteinPatch p = randomPatch(rng, n, m, dim);
      const VecX lo = p.minCoeff(), hi = p.maxCoeff();
      ASSERT_TRUE(closeTo(p.coeffs().colwise().minCoeff().transpose(), lo, 0.0));
      ASSERT_TRUE(closeTo(p.coeffs().colwise().maxCoeff().transpose(), hi, 0.0));
      ASSERT_EQ(p.maxAbsCoeff(), maxAbs(p.coeffs()));
      const double slack = test::kRoundoffTol * maxAbs(p.coeffs());
      for (int a = 0; a < kGrid; ++a)
        for (int b = 0; b < kGrid; ++b) {
          const VecX v = refPatchEval(n, m, p.coeffs(), double(a) / (kGrid - 1), double(b) / (kGrid - 1));
          for (int c = 0; c < dim; ++c) {
            ASSERT_GE(v[c], lo[c] - slack);
            ASSERT_LE(v[c], hi[c] + slack);
          }
        }
    }
  const BernsteinPatch z = BernsteinPatch::zero(2, 3, 4);
  EXPECT_EQ(z.degreeU(), 2);
  EXPECT_EQ(z.degreeV(), 3);
  EXPECT_EQ(z.dim(), 4);
  EXPECT_EQ(z.coeffs().rows(), 12);
  EXPECT_EQ(maxAbs(z.coeffs()), 0.0);
}

}  // namespace
}  // namespace seam
