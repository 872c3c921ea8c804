#pragma once
// Independent reference implementations, random generators and geometry-aware assertions used ONLY by the
// tests.
//
// Rule: every expected value in the kernel tests comes from here, computed straight from the definitions
// (Cox-de Boor recursion, explicit Bernstein sums with binomials and pow, the quotient rule, finite
// differences), never from the code under test. Nothing in this header calls a seam algorithm; it only reads
// the plain data (degree, knots, points, weights) of seam objects.
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <initializer_list>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "seam/core/result.h"
#include "seam/core/types.h"
#include "seam/spline/bezier.h"
#include "seam/spline/bspline_curve.h"
#include "seam/spline/bspline_surface.h"

namespace seam::test {

// =====================================================================================================================
// Named tolerances (see the derivation next to each one).
// =====================================================================================================================

/// Acceptance bound of the issue for geometry-preserving operations (knot insertion, refinement, Bezier
/// decomposition, degree elevation, reversal, reparametrisation): max point error relative to the
/// control-point scale (bounding-box diagonal of the control points).
inline constexpr double kGeometryRelTol = 1e-12;

/// Round-off allowed when two evaluation routes of the same quantity are compared, relative to the MAGNITUDE
/// of the terms that are summed (see the *Magnitude helpers: the same formula with every term replaced by its
/// absolute value). Double precision gives ~1.1e-16 per operation; the algorithms here do O(p^2) <= ~100
/// dependent operations, so a few hundred ulps is the real level; 1e-12 (~4500 ulps) leaves a wide margin and
/// still catches any wrong coefficient (which produces O(1) relative errors).
inline constexpr double kRoundoffTol = 1e-12;

/// Results of a handful of operations on exact or O(1) data (hand examples, copied coefficients, radii of
/// exact conics, affinely mapped end knots): a few ulps. 1e-14 is ~45 ulps of 1; multiply by the data's
/// magnitude.
inline constexpr double kFewUlps = 1e-14;

/// Exact differential identities of rational conics (|C|^2 = 1 gives C.C' = 0 and C.C'' + |C'|^2 = 0): each
/// side comes from quotient-rule derivatives (tens of operations); relative to the magnitude of the
/// derivatives.
inline constexpr double kIdentityTol = 1e-13;

/// Added to relative bounds whose magnitude can be exactly zero (derivatives beyond the degree): then the
/// value must be zero as well, up to denormals.
inline constexpr double kExactZeroFloor = 1e-300;

/// Finite differences: a Richardson-extrapolated central difference with step h has truncation error
/// ~ h^4 |f^(5)| / 480 and round-off ~ eps |f| / h. The tests use h = (local knot-span length) /
/// kFdStepDivisor, so for a degree-p piece the truncation relative to the derivative magnitude is ~ (p /
/// kFdStepDivisor)^4 / 480
/// <= 1e-12 for p <= 9; rational pieces with weights in [0.3, 3] have higher derivatives growing several
/// orders faster (a step of span/200 was observed to give 1e-5), which is why the step is this small. The
/// round-off, ~ eps * kFdStepDivisor / p relative, stays below ~1e-12. 1e-6 relative to the derivative
/// magnitude is therefore safe and still detects any real error (a wrong term is an O(1) relative error).
inline constexpr double kFdStepDivisor = 1000.0;
inline constexpr double kFdRelTol = 1e-6;

// =====================================================================================================================
// Small utilities.
// =====================================================================================================================

// Random draws and argument order: C++ leaves open the order in which a call's arguments are evaluated (GCC takes
// them last to first, Clang first to last), so a call with two draws among its arguments builds another case under
// another compiler (CornerJoin3 and the Lemma 2 residual failed under Clang only, stop 64). The tests draw into named
// values before the call instead, in the order GCC evaluated the calls they replace (last argument first), so that
// every compiler builds the cases the tests were written against. (Braced lists and `<<`, `,` are evaluated in order.)

inline double uniformReal(std::mt19937_64& rng, double a, double b) {
  return std::uniform_real_distribution<double>(a, b)(rng);
}
inline int uniformInt(std::mt19937_64& rng, int a, int b) {
  return std::uniform_int_distribution<int>(a, b)(rng);
}

inline int rows(const Matrix& m) { return static_cast<int>(m.rows()); }
inline int cols(const Matrix& m) { return static_cast<int>(m.cols()); }
inline int ssize(const std::vector<double>& v) { return static_cast<int>(v.size()); }

/// Binomial coefficient by the multiplicative formula (independent of seam::binomial).
inline double refBinomial(int n, int k) {
  if (k < 0 || k > n) return 0.0;
  double r = 1.0;
  for (int i = 1; i <= k; ++i) r = r * (n - k + i) / i;
  return std::round(r);  // exact integers for the sizes used here (n <= 60)
}

/// n (n-1) ... (n-k+1); 0 when k > n.
inline double fallingFactorial(int n, int k) {
  if (k > n) return 0.0;
  double r = 1.0;
  for (int i = 0; i < k; ++i) r *= (n - i);
  return r;
}

/// Largest absolute entry (0 for an empty matrix).
inline double maxAbs(const Matrix& m) { return m.size() == 0 ? 0.0 : m.cwiseAbs().maxCoeff(); }
inline double maxAbs(const VecX& v) { return v.size() == 0 ? 0.0 : v.cwiseAbs().maxCoeff(); }

/// Scale of a set of control points: the diagonal of their bounding box, but never below their largest
/// coordinate (so a degenerate or far-away set still has a meaningful scale).
inline double controlScale(const Matrix& points) {
  if (points.size() == 0) return 1.0;
  const VecX lo = points.colwise().minCoeff().transpose();
  const VecX hi = points.colwise().maxCoeff().transpose();
  const double diag = (hi - lo).norm();
  return std::max({diag, maxAbs(points), std::numeric_limits<double>::min()});
}

/// Case-insensitive check that a status is an error whose message mentions one of `keywords`.
inline ::testing::AssertionResult failsMentioning(const Status& status,
                                                  std::initializer_list<std::string> keywords) {
  if (status.isOk()) return ::testing::AssertionFailure() << "expected an error, got ok";
  if (status.message().empty()) return ::testing::AssertionFailure() << "error without a message";
  std::string msg = status.message();
  std::transform(msg.begin(), msg.end(), msg.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  for (const auto& k : keywords) {
    std::string key = k;
    std::transform(key.begin(), key.end(), key.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    if (msg.find(key) != std::string::npos) return ::testing::AssertionSuccess();
  }
  std::ostringstream os;
  os << "message \"" << status.message() << "\" mentions none of:";
  for (const auto& k : keywords) os << " \"" << k << "\"";
  return ::testing::AssertionFailure() << os.str();
}

/// |expected - actual|_inf <= bound (component-wise maximum), with a readable failure message.
inline ::testing::AssertionResult closeTo(const VecX& expected, const VecX& actual, double bound) {
  if (expected.size() != actual.size())
    return ::testing::AssertionFailure()
           << "size mismatch: expected " << expected.size() << ", got " << actual.size();
  double err = expected.size() ? (expected - actual).cwiseAbs().maxCoeff() : 0.0;
  if (std::isnan(err)) err = std::numeric_limits<double>::infinity();
  if (err <= bound) return ::testing::AssertionSuccess();
  std::ostringstream os;
  os.precision(17);
  os << "error " << err << " > bound " << bound << "; expected [" << expected.transpose() << "], got ["
     << actual.transpose() << "]";
  return ::testing::AssertionFailure() << os.str();
}

// =====================================================================================================================
// Bernstein polynomials: explicit sums with binomials and pow.
// =====================================================================================================================

/// B_i^n(t) = C(n,i) t^i (1-t)^(n-i), for any real t.
inline double refBernstein(int n, int i, double t) {
  if (i < 0 || i > n) return 0.0;
  return refBinomial(n, i) * std::pow(t, i) * std::pow(1.0 - t, n - i);
}

/// d^k/dt^k B_i^n(t) by the Leibniz rule on t^i (1-t)^(n-i) (no coefficient differencing involved).
inline double refBernsteinDerivative(int n, int i, int k, double t) {
  if (i < 0 || i > n) return 0.0;
  double s = 0.0;
  for (int j = 0; j <= k; ++j) {
    const int m = k - j;  // derivatives on (1-t)^(n-i)
    if (j > i || m > n - i) continue;
    const double a = fallingFactorial(i, j) * std::pow(t, i - j);
    const double b = ((m % 2) ? -1.0 : 1.0) * fallingFactorial(n - i, m) * std::pow(1.0 - t, n - i - m);
    s += refBinomial(k, j) * a * b;
  }
  return refBinomial(n, i) * s;
}

/// sum_i c_i d^k B_i^n(t); coefficients one per row.
inline VecX refBernsteinEval(const Matrix& c, double t, int k = 0) {
  const int n = rows(c) - 1;
  VecX r = VecX::Zero(c.cols());
  for (int i = 0; i <= n; ++i) r += refBernsteinDerivative(n, i, k, t) * c.row(i).transpose();
  return r;
}

/// sum_i |d^k B_i^n(t)|: the factor by which coefficient errors (and round-off) are amplified at t.
inline double refBernsteinAbsSum(int n, double t, int k = 0) {
  double s = 0.0;
  for (int i = 0; i <= n; ++i) s += std::abs(refBernsteinDerivative(n, i, k, t));
  return s;
}

/// Power-basis coefficients a_k (p(t) = sum a_k t^k) of a Bernstein polynomial:
/// a_k = C(n,k) sum_{i<=k} (-1)^(k-i) C(k,i) c_i.
inline Matrix refBernsteinToPower(const Matrix& c) {
  const int n = rows(c) - 1;
  Matrix a = Matrix::Zero(c.rows(), c.cols());
  for (int k = 0; k <= n; ++k)
    for (int i = 0; i <= k; ++i)
      a.row(k) += refBinomial(n, k) * (((k - i) % 2) ? -1.0 : 1.0) * refBinomial(k, i) * c.row(i);
  return a;
}

/// Horner evaluation of a power series (one row per coefficient).
inline VecX refPowerEval(const Matrix& a, double t) {
  VecX r = VecX::Zero(a.cols());
  for (int k = rows(a) - 1; k >= 0; --k) r = r * t + a.row(k).transpose();
  return r;
}

/// Derivative of a power series.
inline Matrix refPowerDerivative(const Matrix& a) {
  if (a.rows() <= 1) return Matrix::Zero(1, a.cols());
  Matrix d(a.rows() - 1, a.cols());
  for (int k = 1; k < rows(a); ++k) d.row(k - 1) = k * a.row(k);
  return d;
}

/// Tensor-product Bernstein patch sum_ij c_ij d^ku B_i^n(u) d^kv B_j^m(v); row i*(m+1)+j.
inline VecX refPatchEval(int n, int m, const Matrix& c, double u, double v, int ku = 0, int kv = 0) {
  VecX r = VecX::Zero(c.cols());
  for (int i = 0; i <= n; ++i) {
    const double bu = refBernsteinDerivative(n, i, ku, u);
    for (int j = 0; j <= m; ++j)
      r += bu * refBernsteinDerivative(m, j, kv, v) * c.row(i * (m + 1) + j).transpose();
  }
  return r;
}

inline double refPatchAbsSum(int n, int m, double u, double v, int ku = 0, int kv = 0) {
  return refBernsteinAbsSum(n, u, ku) * refBernsteinAbsSum(m, v, kv);
}

inline Matrix randomMatrix(std::mt19937_64& rng, int r, int c, double lo = -1.0, double hi = 1.0) {
  Matrix m(r, c);
  for (int i = 0; i < r; ++i)
    for (int j = 0; j < c; ++j) m(i, j) = uniformReal(rng, lo, hi);
  return m;
}

inline VecX randomWeights(std::mt19937_64& rng, int n, double lo = 0.3, double hi = 3.0) {
  VecX w(n);
  for (int i = 0; i < n; ++i) w[i] = uniformReal(rng, lo, hi);
  return w;
}

// =====================================================================================================================
// Rational Bezier (explicit Bernstein sums + quotient rule).
// =====================================================================================================================

/// Leibniz inversion of A = W C: C^(k) = (A^(k) - sum_{j=1..k} C(k,j) W^(j) C^(k-j)) / W. Rows of A:
/// A^(0..order).
inline Matrix quotientRule(const Matrix& a, const VecX& w) {
  Matrix c(a.rows(), a.cols());
  for (int k = 0; k < rows(a); ++k) {
    VecX r = a.row(k).transpose();
    for (int j = 1; j <= k; ++j) r -= refBinomial(k, j) * w[j] * c.row(k - j).transpose();
    c.row(k) = (r / w[0]).transpose();
  }
  return c;
}

/// Rows 0..order of a (rational when weights are non-empty) Bezier curve at t, from explicit Bernstein sums.
inline Matrix refBezierCurveDerivs(const Matrix& points, const VecX& weights, double t, int order) {
  const int n = rows(points) - 1;
  Matrix a = Matrix::Zero(order + 1, points.cols());
  VecX w = VecX::Zero(order + 1);
  for (int k = 0; k <= order; ++k)
    for (int i = 0; i <= n; ++i) {
      const double b = refBernsteinDerivative(n, i, k, t);
      const double wi = weights.size() ? weights[i] : 1.0;
      a.row(k) += b * wi * points.row(i);
      w[k] += b * wi;
    }
  return weights.size() ? quotientRule(a, w) : a;
}

/// Point of a (rational) Bezier curve by the explicit sum (fast path of refBezierCurveDerivs for order 0).
inline VecX refBezierCurvePoint(const Matrix& points, const VecX& weights, double t) {
  const int n = rows(points) - 1;
  VecX r = VecX::Zero(points.cols());
  double w = 0.0;
  for (int i = 0; i <= n; ++i) {
    const double b = refBernstein(n, i, t) * (weights.size() ? weights[i] : 1.0);
    r += b * points.row(i).transpose();
    w += b;
  }
  return weights.size() ? VecX(r / w) : r;
}

/// Point of a (rational) Bezier patch by the explicit double sum (fast path of refBezierPatchDerivs for order
/// 0).
inline VecX refBezierPatchPoint(int n, int m, const Matrix& points, const VecX& weights, double u, double v) {
  thread_local std::vector<double> bu, bv;
  bu.resize(static_cast<size_t>(n + 1));
  bv.resize(static_cast<size_t>(m + 1));
  for (int i = 0; i <= n; ++i) bu[static_cast<size_t>(i)] = refBernstein(n, i, u);
  for (int j = 0; j <= m; ++j) bv[static_cast<size_t>(j)] = refBernstein(m, j, v);
  VecX r = VecX::Zero(points.cols());
  double w = 0.0;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= m; ++j) {
      const int k = i * (m + 1) + j;
      const double b =
          bu[static_cast<size_t>(i)] * bv[static_cast<size_t>(j)] * (weights.size() ? weights[k] : 1.0);
      r += b * points.row(k).transpose();
      w += b;
    }
  return weights.size() ? VecX(r / w) : r;
}

/// Two-variable Leibniz inversion of A = W S: S^(k,l) = (A^(k,l) - sum_{(i,j) != (0,0)} C(k,i) C(l,j) W^(i,j)
/// S^(k-i,l-j)) / W. a[k][l], w[k][l] for k + l <= order.
inline std::vector<std::vector<VecX>> quotientRule2(const std::vector<std::vector<VecX>>& a,
                                                    const std::vector<std::vector<double>>& w, int order) {
  std::vector<std::vector<VecX>> s(order + 1, std::vector<VecX>(order + 1));
  for (int k = 0; k <= order; ++k)
    for (int l = 0; k + l <= order; ++l) {
      VecX r = a[k][l];
      for (int i = 0; i <= k; ++i)
        for (int j = 0; j <= l; ++j) {
          if (i == 0 && j == 0) continue;
          r -= refBinomial(k, i) * refBinomial(l, j) * w[i][j] * s[k - i][l - j];
        }
      s[k][l] = r / w[0][0];
    }
  return s;
}

/// out[k][l] = d^{k+l} S / du^k dv^l (k + l <= order) of a (rational) Bezier patch, explicit sums.
inline std::vector<std::vector<VecX>> refBezierPatchDerivs(int n, int m, const Matrix& points,
                                                           const VecX& weights, double u, double v,
                                                           int order) {
  std::vector<std::vector<VecX>> a(order + 1, std::vector<VecX>(order + 1));
  std::vector<std::vector<double>> w(order + 1, std::vector<double>(order + 1, 0.0));
  for (int k = 0; k <= order; ++k)
    for (int l = 0; k + l <= order; ++l) {
      a[k][l] = VecX::Zero(points.cols());
      for (int i = 0; i <= n; ++i)
        for (int j = 0; j <= m; ++j) {
          const int r = i * (m + 1) + j;
          const double b = refBernsteinDerivative(n, i, k, u) * refBernsteinDerivative(m, j, l, v);
          const double wr = weights.size() ? weights[r] : 1.0;
          a[k][l] += b * wr * points.row(r).transpose();
          w[k][l] += b * wr;
        }
    }
  return weights.size() ? quotientRule2(a, w, order) : a;
}

// =====================================================================================================================
// B-spline basis: Cox-de Boor recursion written from the definition.
// =====================================================================================================================

/// The span that carries N_{i,0} = 1 in the recursion below, found by linear search: the k in [p, n-1] with
/// t_k <= x < t_{k+1}. Right-end handling: at (or beyond) the right end of the domain it is the last
/// non-empty span (so the curve is continuous up to its end point); before the left end, the first non-empty
/// span. (Outside the domain this yields the polynomial extension of the end pieces.) Returns -1 for an empty
/// domain.
inline int referenceSpan(const std::vector<double>& t, int p, double x) {
  const int n = ssize(t) - p - 1;
  int first = -1, last = -1;
  for (int k = p; k <= n - 1; ++k)
    if (t[k] < t[k + 1]) {
      if (first < 0) first = k;
      last = k;
    }
  if (first < 0) return -1;
  if (x < t[first]) return first;
  for (int k = first; k <= last; ++k)
    if (t[k] <= x && x < t[k + 1]) return k;
  return last;
}

namespace detail {
inline double coxDeBoorAt(const std::vector<double>& t, int span, int i, int j, double x) {
  if (j == 0) return i == span ? 1.0 : 0.0;
  double r = 0.0;
  const double d1 = t[i + j] - t[i];
  if (d1 != 0.0) r += (x - t[i]) / d1 * coxDeBoorAt(t, span, i, j - 1, x);
  const double d2 = t[i + j + 1] - t[i + 1];
  if (d2 != 0.0) r += (t[i + j + 1] - x) / d2 * coxDeBoorAt(t, span, i + 1, j - 1, x);
  return r;
}
inline double coxDeBoorDerivativeAt(const std::vector<double>& t, int span, int i, int j, int k, double x) {
  if (k == 0) return coxDeBoorAt(t, span, i, j, x);
  if (j == 0) return 0.0;
  double r = 0.0;
  const double d1 = t[i + j] - t[i];
  if (d1 != 0.0) r += j / d1 * coxDeBoorDerivativeAt(t, span, i, j - 1, k - 1, x);
  const double d2 = t[i + j + 1] - t[i + 1];
  if (d2 != 0.0) r -= j / d2 * coxDeBoorDerivativeAt(t, span, i + 1, j - 1, k - 1, x);
  return r;
}
}  // namespace detail

/// N_{i,j}(x) by the Cox-de Boor recursion
///   N_{i,0}(x) = 1 on the span of x (see referenceSpan), else 0;
///   N_{i,j}(x) = (x - t_i)/(t_{i+j} - t_i) N_{i,j-1}(x) + (t_{i+j+1} - x)/(t_{i+j+1} - t_{i+1})
///   N_{i+1,j-1}(x),
/// with the 0/0 := 0 convention (a term whose knot difference is zero is dropped). `p` is the degree of the
/// spline (it fixes the domain for the right-end handling).
inline double coxDeBoor(const std::vector<double>& t, int p, int i, int j, double x) {
  return detail::coxDeBoorAt(t, referenceSpan(t, p, x), i, j, x);
}

/// d^k/dx^k N_{i,j}(x) by N'_{i,j} = j/(t_{i+j}-t_i) N_{i,j-1} - j/(t_{i+j+1}-t_{i+1}) N_{i+1,j-1}, applied
/// recursively (0/0 := 0). Zero when k > j.
inline double coxDeBoorDerivative(const std::vector<double>& t, int p, int i, int j, int k, double x) {
  return detail::coxDeBoorDerivativeAt(t, referenceSpan(t, p, x), i, j, k, x);
}

/// The same two recursions evaluated bottom-up for ALL basis functions at once (fast enough for 10^4-point
/// checks): out(k, i) = d^k/dx^k N_{i,p}(x), k = 0..order, i = 0..n-1. With `absolute`, every term is
/// replaced by its absolute value: the result bounds the magnitude of the summed terms (the round-off scale).
inline Matrix basisTable(const std::vector<double>& t, int p, double x, int order, bool absolute = false) {
  const int m = ssize(t);
  const int n = m - p - 1;
  const int span = referenceSpan(t, p, x);
  const auto f = [absolute](double v) { return absolute ? std::abs(v) : v; };
  // d[k](j, i) = d^k N_{i,j}
  std::vector<Matrix> d(order + 1, Matrix::Zero(p + 1, m));
  d[0](0, span) = 1.0;
  for (int j = 1; j <= p; ++j)
    for (int i = 0; i + j + 1 < m; ++i) {
      const double d1 = t[i + j] - t[i];
      const double d2 = t[i + j + 1] - t[i + 1];
      double v = 0.0;
      if (d1 != 0.0) v += f((x - t[i]) / d1 * d[0](j - 1, i));
      if (d2 != 0.0) v += f((t[i + j + 1] - x) / d2 * d[0](j - 1, i + 1));
      d[0](j, i) = v;
      for (int k = 1; k <= order; ++k) {
        double s = 0.0;
        if (d1 != 0.0) s += f(j / d1 * d[k - 1](j - 1, i));
        if (d2 != 0.0) s += f(-j / d2 * d[k - 1](j - 1, i + 1));
        d[k](j, i) = s;
      }
    }
  Matrix out(order + 1, n);
  for (int k = 0; k <= order; ++k) out.row(k) = d[k].row(p).head(n);
  return out;
}

/// Order-0 fast path of basisTable (same recursion, bottom-up in place over one vector): N[i] = N_{i,p}(x)
/// for i = 0..n-1. Only the terms that can be non-zero (i in [span - j, span] at level j) are visited; every
/// other N_{i,j} is an exact zero in the full recursion, so the result is bit-identical to it.
inline void basisValuesInto(const std::vector<double>& t, int p, double x, std::vector<double>& out) {
  const int m = ssize(t);
  const int span = referenceSpan(t, p, x);
  out.assign(static_cast<size_t>(m - 1), 0.0);
  out[static_cast<size_t>(span)] = 1.0;
  for (int j = 1; j <= p; ++j)
    for (int i = std::max(0, span - j); i <= span && i + j + 1 < m; ++i) {
      const size_t u = static_cast<size_t>(i);
      const double d1 = t[u + j] - t[u];
      const double d2 = t[u + j + 1] - t[u + 1];
      double v = 0.0;
      if (d1 != 0.0) v += (x - t[u]) / d1 * out[u];
      if (d2 != 0.0) v += (t[u + j + 1] - x) / d2 * out[u + 1];
      out[u] = v;
    }
  out.resize(static_cast<size_t>(m - p - 1));
}

// =====================================================================================================================
// Brute-force B-spline / NURBS curves and surfaces: sum_i N_i P_i (rational: sum w_i P_i N_i / sum w_i N_i).
// =====================================================================================================================

/// Rows 0..order: C, C', ..., C^(order) at x. Rational when weights are non-empty (quotient rule on
/// A = sum N w P, W = sum N w).
inline Matrix refCurveDerivs(int p, const std::vector<double>& knots, const Matrix& points,
                             const VecX& weights, double x, int order) {
  const Matrix b = basisTable(knots, p, x, order);
  const int n = rows(points);
  Matrix a = Matrix::Zero(order + 1, points.cols());
  VecX w = VecX::Zero(order + 1);
  for (int k = 0; k <= order; ++k)
    for (int i = 0; i < n; ++i) {
      const double wi = weights.size() ? weights[i] : 1.0;
      a.row(k) += b(k, i) * wi * points.row(i);
      w[k] += b(k, i) * wi;
    }
  return weights.size() ? quotientRule(a, w) : a;
}

/// Magnitude of the terms behind refCurveDerivs (same formulas on absolute values): the round-off scale of
/// derivative k at x (component-wise maximum).
inline VecX refCurveDerivMagnitudes(int p, const std::vector<double>& knots, const Matrix& points,
                                    const VecX& weights, double x, int order) {
  const Matrix b = basisTable(knots, p, x, order, true);
  const Matrix b0 = basisTable(knots, p, x, 0);
  VecX ma = VecX::Zero(order + 1), mw = VecX::Zero(order + 1);
  double w0 = 0.0;
  for (int i = 0; i < rows(points); ++i) {
    const double wi = weights.size() ? weights[i] : 1.0;
    for (int k = 0; k <= order; ++k) {
      ma[k] += b(k, i) * wi * points.row(i).cwiseAbs().maxCoeff();
      mw[k] += b(k, i) * wi;
    }
    w0 += b0(0, i) * wi;
  }
  if (!weights.size()) return ma;
  VecX mc(order + 1);
  for (int k = 0; k <= order; ++k) {
    double r = ma[k];
    for (int j = 1; j <= k; ++j) r += refBinomial(k, j) * mw[j] * mc[k - j];
    mc[k] = r / w0;
  }
  return mc;
}

inline Matrix refCurveDerivs(const BSplineCurve& c, double x, int order) {
  return refCurveDerivs(c.degree(), c.knots().values(), c.points(), c.weights(), x, order);
}
/// C(x) = sum N_i w_i P_i / sum N_i w_i (fast path of refCurveDerivs for order 0).
inline VecX refCurvePoint(const BSplineCurve& c, double x) {
  thread_local std::vector<double> n;
  basisValuesInto(c.knots().values(), c.degree(), x, n);
  VecX r = VecX::Zero(c.dim());
  double w = 0.0;
  const bool rational = c.isRational();
  for (int i = 0; i < c.numPoints(); ++i) {
    const double ni = n[static_cast<size_t>(i)];
    if (ni == 0.0) continue;
    const double wi = rational ? c.weights()[i] : 1.0;
    r += (ni * wi) * c.points().row(i).transpose();
    w += ni * wi;
  }
  return rational ? VecX(r / w) : r;
}
inline VecX refCurveDerivMagnitudes(const BSplineCurve& c, double x, int order) {
  return refCurveDerivMagnitudes(c.degree(), c.knots().values(), c.points(), c.weights(), x, order);
}

/// Homogeneous control rows (w P, w) built directly from the data (not via seam's homogeneous()).
inline Matrix refHomogeneous(const Matrix& points, const VecX& weights) {
  if (!weights.size()) return points;
  Matrix h(points.rows(), points.cols() + 1);
  for (int i = 0; i < rows(points); ++i) {
    h.row(i).head(points.cols()) = weights[i] * points.row(i);
    h(i, points.cols()) = weights[i];
  }
  return h;
}

/// Unweighted tensor sum out[k][l] = sum_ij d^k N_i(u) d^l N_j(v) H_ij (k + l <= order) of any coefficient
/// rows H.
inline std::vector<std::vector<VecX>> refTensorSum(int pu, int pv, const std::vector<double>& ku,
                                                   const std::vector<double>& kv, int numV, const Matrix& h,
                                                   double u, double v, int order, bool absolute = false) {
  const Matrix bu = basisTable(ku, pu, u, order, absolute);
  const Matrix bv = basisTable(kv, pv, v, order, absolute);
  const int numU = rows(h) / numV;
  std::vector<std::vector<VecX>> out(order + 1, std::vector<VecX>(order + 1));
  for (int k = 0; k <= order; ++k)
    for (int l = 0; k + l <= order; ++l) {
      VecX r = VecX::Zero(h.cols());
      for (int i = 0; i < numU; ++i) {
        if (bu(k, i) == 0.0) continue;
        for (int j = 0; j < numV; ++j) {
          const auto row = h.row(i * numV + j).transpose();
          if (absolute)
            r += bu(k, i) * bv(l, j) * row.cwiseAbs();
          else
            r += bu(k, i) * bv(l, j) * row;
        }
      }
      out[k][l] = r;
    }
  return out;
}

/// out[k][l] = d^{k+l} S / du^k dv^l, k + l <= order, by brute force (rational: two-variable quotient rule).
inline std::vector<std::vector<VecX>> refSurfaceDerivs(const BSplineSurface& s, double u, double v,
                                                       int order) {
  const Matrix h = refHomogeneous(s.points(), s.weights());
  auto a = refTensorSum(s.degreeU(), s.degreeV(), s.knotsU().values(), s.knotsV().values(), s.numV(), h, u, v,
                        order);
  if (!s.isRational()) return a;
  const int d = s.dim();
  std::vector<std::vector<VecX>> num(order + 1, std::vector<VecX>(order + 1));
  std::vector<std::vector<double>> w(order + 1, std::vector<double>(order + 1, 0.0));
  for (int k = 0; k <= order; ++k)
    for (int l = 0; k + l <= order; ++l) {
      num[k][l] = a[k][l].head(d);
      w[k][l] = a[k][l][d];
    }
  return quotientRule2(num, w, order);
}

/// S(u,v) by brute force (fast path of refSurfaceDerivs for order 0).
inline VecX refSurfacePoint(const BSplineSurface& s, double u, double v) {
  thread_local std::vector<double> nu, nv;
  basisValuesInto(s.knotsU().values(), s.degreeU(), u, nu);
  basisValuesInto(s.knotsV().values(), s.degreeV(), v, nv);
  VecX r = VecX::Zero(s.dim());
  double w = 0.0;
  const bool rational = s.isRational();
  for (int i = 0; i < s.numU(); ++i) {
    const double a = nu[static_cast<size_t>(i)];
    if (a == 0.0) continue;
    for (int j = 0; j < s.numV(); ++j) {
      const double b = nv[static_cast<size_t>(j)];
      if (b == 0.0) continue;
      const double wij = rational ? s.weights()[i * s.numV() + j] : 1.0;
      r += (a * b * wij) * s.points().row(i * s.numV() + j).transpose();
      w += a * b * wij;
    }
  }
  return rational ? VecX(r / w) : r;
}

/// Round-off scale of refSurfaceDerivs: the same formulas on absolute values (maximum over components).
inline std::vector<std::vector<double>> refSurfaceDerivMagnitudes(const BSplineSurface& s, double u, double v,
                                                                  int order) {
  const Matrix h = refHomogeneous(s.points(), s.weights());
  auto a = refTensorSum(s.degreeU(), s.degreeV(), s.knotsU().values(), s.knotsV().values(), s.numV(), h, u, v,
                        order, true);
  std::vector<std::vector<double>> m(order + 1, std::vector<double>(order + 1, 0.0));
  const int d = s.dim();
  if (!s.isRational()) {
    for (int k = 0; k <= order; ++k)
      for (int l = 0; k + l <= order; ++l) m[k][l] = a[k][l].maxCoeff();
    return m;
  }
  const double w0 = refTensorSum(s.degreeU(), s.degreeV(), s.knotsU().values(), s.knotsV().values(), s.numV(),
                                 h, u, v, 0)[0][0][d];
  for (int k = 0; k <= order; ++k)
    for (int l = 0; k + l <= order; ++l) {
      double r = a[k][l].head(d).maxCoeff();
      for (int i = 0; i <= k; ++i)
        for (int j = 0; j <= l; ++j)
          if (i || j) r += refBinomial(k, i) * refBinomial(l, j) * a[i][j][d] * m[k - i][l - j];
      m[k][l] = r / w0;
    }
  return m;
}

// =====================================================================================================================
// Finite differences.
// =====================================================================================================================

/// Richardson-extrapolated central difference of a vector function: D(h) = (f(x+h) - f(x-h)) / 2h,
/// result (4 D(h/2) - D(h)) / 3 (error ~ h^4 f^(5) / 480 + round-off ~ eps |f| / h). f must be smooth on
/// [x - h, x + h].
template <class F>
VecX richardsonDerivative(F&& f, double x, double h) {
  const VecX d1 = (f(x + h) - f(x - h)) / (2.0 * h);
  const VecX d2 = (f(x + 0.5 * h) - f(x - 0.5 * h)) / h;
  return (4.0 * d2 - d1) / 3.0;
}

// =====================================================================================================================
// Random generators (always driven by a caller-owned std::mt19937_64 with a literal seed).
// =====================================================================================================================

/// Random knot vector on [lo, hi] for degree p with `numSpans` non-empty spans: span lengths random in a
/// ratio of at most 1:3.3, random interior multiplicities 1..p. Clamped: p+1 copies of each end; otherwise
/// each end has a random multiplicity 1..p+1 and the remaining end knots lie outside the domain (still a
/// valid B-spline knot vector).
inline std::vector<double> randomKnots(std::mt19937_64& rng, int p, int numSpans, double lo, double hi,
                                       bool clamped = true) {
  std::vector<double> len(static_cast<size_t>(numSpans));
  double total = 0.0;
  for (auto& l : len) total += (l = uniformReal(rng, 0.3, 1.0));
  std::vector<double> bp{lo};
  double acc = 0.0;
  for (int k = 0; k + 1 < numSpans; ++k) {
    acc += len[static_cast<size_t>(k)];
    bp.push_back(lo + (hi - lo) * acc / total);
  }
  bp.push_back(hi);
  const double h = (hi - lo) / numSpans;  // typical span, used for the outside knots
  std::vector<double> t;
  const int eLo = clamped ? p + 1 : uniformInt(rng, 1, p + 1);
  const int eHi = clamped ? p + 1 : uniformInt(rng, 1, p + 1);
  std::vector<double> outside;
  double x = lo;
  for (int k = 0; k < p + 1 - eLo; ++k) outside.push_back(x -= h * uniformReal(rng, 0.3, 1.0));
  t.insert(t.end(), outside.rbegin(), outside.rend());
  for (int k = 0; k < eLo; ++k) t.push_back(lo);
  for (int b = 1; b < numSpans; ++b) {
    const int mult = uniformInt(rng, 1, p);
    for (int k = 0; k < mult; ++k) t.push_back(bp[static_cast<size_t>(b)]);
  }
  for (int k = 0; k < eHi; ++k) t.push_back(hi);
  x = hi;
  for (int k = 0; k < p + 1 - eHi; ++k) t.push_back(x += h * uniformReal(rng, 0.3, 1.0));
  return t;
}

struct RandomSplineOptions {
  bool rational = false;
  bool clamped = true;
  int minSpans = 1;
  int maxSpans = 4;
};

/// Random control points: uniform in an axis box of random size (0.5 .. 50) around a random offset.
inline Matrix randomPoints(std::mt19937_64& rng, int n, int dim) {
  const double size = std::pow(10.0, uniformReal(rng, -0.3, 1.7));
  Matrix p = randomMatrix(rng, n, dim, -size, size);
  for (int c = 0; c < dim; ++c) p.col(c).array() += uniformReal(rng, -size, size);
  return p;
}

inline BSplineCurve randomCurve(std::mt19937_64& rng, int p, int dim, const RandomSplineOptions& o = {}) {
  const double lo = uniformReal(rng, -3.0, 3.0);
  const double hi = lo + uniformReal(rng, 0.5, 4.0);
  std::vector<double> t = randomKnots(rng, p, uniformInt(rng, o.minSpans, o.maxSpans), lo, hi, o.clamped);
  const int n = ssize(t) - p - 1;
  Matrix pts = randomPoints(rng, n, dim);
  VecX w = o.rational ? randomWeights(rng, n) : VecX();
  return BSplineCurve(p, KnotVector(std::move(t)), std::move(pts), std::move(w));
}

inline BSplineSurface randomSurface(std::mt19937_64& rng, int pu, int pv, int dim,
                                    const RandomSplineOptions& o = {}) {
  const double ulo = uniformReal(rng, -3.0, 3.0), uhi = ulo + uniformReal(rng, 0.5, 4.0);
  const double vlo = uniformReal(rng, -3.0, 3.0), vhi = vlo + uniformReal(rng, 0.5, 4.0);
  std::vector<double> tu = randomKnots(rng, pu, uniformInt(rng, o.minSpans, o.maxSpans), ulo, uhi, o.clamped);
  std::vector<double> tv = randomKnots(rng, pv, uniformInt(rng, o.minSpans, o.maxSpans), vlo, vhi, o.clamped);
  const int nu = ssize(tu) - pu - 1, nv = ssize(tv) - pv - 1;
  Matrix pts = randomPoints(rng, nu * nv, dim);
  VecX w = o.rational ? randomWeights(rng, nu * nv) : VecX();
  return BSplineSurface(pu, pv, KnotVector(std::move(tu)), KnotVector(std::move(tv)), nu, nv, std::move(pts),
                        std::move(w));
}

/// Distinct knot values in increasing order (computed from the raw values, exact comparison).
inline std::vector<double> distinctValues(const std::vector<double>& t) {
  std::vector<double> b;
  for (double x : t)
    if (b.empty() || x != b.back()) b.push_back(x);
  return b;
}

/// `count` parameters in [lo, hi]: both ends, then uniformly random ones.
inline std::vector<double> sampleParams(std::mt19937_64& rng, Interval d, int count) {
  std::vector<double> ts{d.lo, d.hi};
  while (ssize(ts) < count) ts.push_back(uniformReal(rng, d.lo, d.hi));
  return ts;
}

/// A parameter well inside a random non-empty span of the domain (relative position in [0.1, 0.9]) and the
/// span length, for finite differences that must not straddle a knot.
inline std::pair<double, double> paramInsideSpan(std::mt19937_64& rng, const std::vector<double>& t, int p) {
  const int n = ssize(t) - p - 1;
  std::vector<int> spans;
  for (int k = p; k < n; ++k)
    if (t[k] < t[k + 1]) spans.push_back(k);
  const int k = spans[static_cast<size_t>(uniformInt(rng, 0, static_cast<int>(spans.size()) - 1))];
  const double len = t[k + 1] - t[k];
  return {t[k] + len * uniformReal(rng, 0.1, 0.9), len};
}

// =====================================================================================================================
// Geometry-aware assertions: compare two parametric objects by evaluating at many parameters.
// =====================================================================================================================

/// max_t |expected(t) - actual(t)|_inf <= relTol * scale over all ts (reports the worst parameter).
template <class FE, class FA>
::testing::AssertionResult agreeAt(const std::vector<double>& ts, FE&& expected, FA&& actual, double scale,
                                   double relTol) {
  double worst = -1.0, worstT = 0.0;
  for (double t : ts) {
    const VecX e = expected(t);
    const VecX a = actual(t);
    if (e.size() != a.size())
      return ::testing::AssertionFailure()
             << "dimension mismatch at t=" << t << ": " << e.size() << " vs " << a.size();
    double err = (e - a).cwiseAbs().maxCoeff();
    if (std::isnan(err)) err = std::numeric_limits<double>::infinity();
    if (err > worst) {
      worst = err;
      worstT = t;
    }
  }
  if (worst <= relTol * scale) return ::testing::AssertionSuccess();
  std::ostringstream os;
  os.precision(17);
  os << "max error " << worst << " (relative " << worst / scale << ") > " << relTol << " * scale " << scale
     << " at t = " << worstT << "; expected " << expected(worstT).transpose() << ", got "
     << actual(worstT).transpose();
  return ::testing::AssertionFailure() << os.str();
}

/// Two-parameter version.
template <class FE, class FA>
::testing::AssertionResult agreeAt2(const std::vector<Vec2>& uvs, FE&& expected, FA&& actual, double scale,
                                    double relTol) {
  double worst = -1.0;
  Vec2 worstUv = Vec2::Zero();
  for (const Vec2& uv : uvs) {
    const VecX e = expected(uv[0], uv[1]);
    const VecX a = actual(uv[0], uv[1]);
    if (e.size() != a.size())
      return ::testing::AssertionFailure()
             << "dimension mismatch at " << uv.transpose() << ": " << e.size() << " vs " << a.size();
    double err = (e - a).cwiseAbs().maxCoeff();
    if (std::isnan(err)) err = std::numeric_limits<double>::infinity();
    if (err > worst) {
      worst = err;
      worstUv = uv;
    }
  }
  if (worst <= relTol * scale) return ::testing::AssertionSuccess();
  std::ostringstream os;
  os.precision(17);
  os << "max error " << worst << " (relative " << worst / scale << ") > " << relTol << " * scale " << scale
     << " at (u,v) = (" << worstUv[0] << ", " << worstUv[1] << "); expected "
     << expected(worstUv[0], worstUv[1]).transpose() << ", got "
     << actual(worstUv[0], worstUv[1]).transpose();
  return ::testing::AssertionFailure() << os.str();
}

/// `count` (u,v) pairs in the box: the four corners, then uniformly random ones.
inline std::vector<Vec2> sampleParams2(std::mt19937_64& rng, Interval du, Interval dv, int count) {
  std::vector<Vec2> uv{{du.lo, dv.lo}, {du.hi, dv.lo}, {du.lo, dv.hi}, {du.hi, dv.hi}};
  while (static_cast<int>(uv.size()) < count) {
    // drawn last argument first (test_helpers.h)
    const double v = uniformReal(rng, dv.lo, dv.hi), u = uniformReal(rng, du.lo, du.hi);
    uv.emplace_back(u, v);
  }
  return uv;
}

/// The curve `actual` traces the same points as `expected`: actual(t) == expected(map(t)) at `count`
/// parameters of actual's domain, both evaluated by brute force, within kGeometryRelTol of expected's
/// control-point scale.
template <class Map>
::testing::AssertionResult sameCurve(const BSplineCurve& expected, const BSplineCurve& actual,
                                     std::mt19937_64& rng, int count, Map&& map,
                                     double relTol = kGeometryRelTol) {
  const auto ts = sampleParams(rng, actual.domain(), count);
  return agreeAt(
      ts, [&](double t) { return refCurvePoint(expected, map(t)); },
      [&](double t) { return refCurvePoint(actual, t); }, controlScale(expected.points()), relTol);
}
inline ::testing::AssertionResult sameCurve(const BSplineCurve& expected, const BSplineCurve& actual,
                                            std::mt19937_64& rng, int count,
                                            double relTol = kGeometryRelTol) {
  return sameCurve(
      expected, actual, rng, count, [](double t) { return t; }, relTol);
}

/// Surface version: actual(u,v) == expected(map(u,v)) (map returns Vec2).
template <class Map>
::testing::AssertionResult sameSurface(const BSplineSurface& expected, const BSplineSurface& actual,
                                       std::mt19937_64& rng, int count, Map&& map,
                                       double relTol = kGeometryRelTol) {
  const auto uvs = sampleParams2(rng, actual.domainU(), actual.domainV(), count);
  return agreeAt2(
      uvs,
      [&](double u, double v) {
        const Vec2 m = map(u, v);
        return refSurfacePoint(expected, m[0], m[1]);
      },
      [&](double u, double v) { return refSurfacePoint(actual, u, v); }, controlScale(expected.points()),
      relTol);
}
inline ::testing::AssertionResult sameSurface(const BSplineSurface& expected, const BSplineSurface& actual,
                                              std::mt19937_64& rng, int count,
                                              double relTol = kGeometryRelTol) {
  return sameSurface(
      expected, actual, rng, count, [](double u, double v) { return Vec2(u, v); }, relTol);
}

/// A short description of a random case for failure messages.
inline std::string describe(const BSplineCurve& c) {
  std::ostringstream os;
  os.precision(17);
  os << "degree " << c.degree() << (c.isRational() ? " rational" : " polynomial") << ", " << c.numPoints()
     << " points, knots [";
  for (double t : c.knots().values()) os << t << ' ';
  os << "]";
  return os.str();
}
inline std::string describe(const BSplineSurface& s) {
  std::ostringstream os;
  os.precision(17);
  os << "degrees (" << s.degreeU() << "," << s.degreeV() << ")"
     << (s.isRational() ? " rational" : " polynomial") << ", " << s.numU() << "x" << s.numV()
     << " points, u knots [";
  for (double t : s.knotsU().values()) os << t << ' ';
  os << "], v knots [";
  for (double t : s.knotsV().values()) os << t << ' ';
  os << "]";
  return os.str();
}

}  // namespace seam::test
