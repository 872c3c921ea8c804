#pragma once
// Private helpers of the rational GC^n module (Zheng-Wang-Liang): Lemma 1 combinatorics, truncated Taylor series,
// the brackets <.,.,.>_i of (2.8) on Bernstein polynomials, certified positivity, effective degrees and the
// deflation used to eliminate common roots of D (proof of Theorem 5).
#include <array>
#include <vector>

#include "seam/core/bernstein.h"
#include "seam/core/types.h"

namespace seam::rational::detail {

/// n! as a double (exact for n <= 20).
double factorial(int n);

/// All ordered compositions (r_1, ..., r_k) of n into k positive parts (the inner sums of Lemma 1).
std::vector<std::vector<int>> compositions(int n, int k);

/// Lemma 1: A^{skh}_{r_1..r_k} = s! / (h! (k-h)! r_1! ... r_k!).
double lemma1Coefficient(int s, int h, const std::vector<int>& r);

// ---------------------------------------------------------------------------------------------------------------
// Truncated Taylor series in t: a[k] = coefficient of t^k (the k-th derivative divided by k!).

using Series = std::vector<double>;
/// Product of two scalar series, truncated to `order`.
Series seriesProduct(const Series& a, const Series& b, int order);

/// Taylor coefficients of t -> Q(u0 + du(t), v0 + dv(t)) up to t^order, where du, dv have no constant term
/// (du[0] = dv[0] = 0) and d[a][b] = d^{a+b}Q/du^a dv^b at (u0, v0). Faa di Bruno by series composition: the
/// route independent of the Lemma 1 sums.
template <class Vec>
std::vector<Vec> composeSeries(const std::vector<std::vector<Vec>>& d, const Series& du, const Series& dv,
                               int order) {
  std::vector<Vec> out(static_cast<size_t>(order + 1), Vec::Zero(d[0][0].size()));
  // powers of du and dv
  std::vector<Series> pu(static_cast<size_t>(order + 1)), pv(static_cast<size_t>(order + 1));
  pu[0] = Series(static_cast<size_t>(order + 1), 0.0);
  pu[0][0] = 1.0;
  pv[0] = pu[0];
  for (int a = 1; a <= order; ++a) {
    pu[static_cast<size_t>(a)] = seriesProduct(pu[static_cast<size_t>(a - 1)], du, order);
    pv[static_cast<size_t>(a)] = seriesProduct(pv[static_cast<size_t>(a - 1)], dv, order);
  }
  for (int a = 0; a <= order; ++a)
    for (int b = 0; a + b <= order; ++b) {
      const Series w = seriesProduct(pu[static_cast<size_t>(a)], pv[static_cast<size_t>(b)], order);
      const double f = 1.0 / (factorial(a) * factorial(b));
      const Vec& q = d[static_cast<size_t>(a)][static_cast<size_t>(b)];
      for (int k = 0; k <= order; ++k)
        if (w[static_cast<size_t>(k)] != 0.0) out[static_cast<size_t>(k)] += (f * w[static_cast<size_t>(k)]) * q;
    }
  return out;
}

// ---------------------------------------------------------------------------------------------------------------
// Bernstein-form helpers.

/// <R, S, T>_i of (2.8), i = 1..4, for 4-vector polynomials: (-1)^{i+1} det of rows i+1, i+2, i+3 (cyclic,
/// 1-based). For every X: det[X, R, S, T] = sum_i X_i <R, S, T>_i (the brackets are the cofactors of column 1).
BernsteinPoly bracket4(int i, const BernsteinPoly& r, const BernsteinPoly& s, const BernsteinPoly& t);
/// The 3-D analogue used for integral patches (Case 2): component i (0..2) of s x t.
BernsteinPoly bracket3(int i, const BernsteinPoly& s, const BernsteinPoly& t);

/// The same at one point (doubles), for the sampled route.
double bracket4(int i, const Vec4& r, const Vec4& s, const Vec4& t);

/// Outcome of a certified sign test of a scalar polynomial on [0,1].
enum class SignCheck { kPositive, kNotPositive, kUndecided };
/// Is p(t) > floor for every t in [0,1]? Bernstein coefficients (convex hull) with subdivision up to maxDepth; an
/// end value <= floor of any sub-piece is an actual value, so kNotPositive is certain too.
SignCheck certifyPositive(const BernsteinPoly& p, double floor, int maxDepth = 24);

/// Degree of the polynomial with coefficients below `zeroTol` treated as zero: the highest index of a Chebyshev
/// coefficient (computed from exact values at Chebyshev-Lobatto points, a well-conditioned route, unlike forward
/// differences) above zeroTol. -1 for the zero polynomial.
int effectiveDegree(const BernsteinPoly& p, double zeroTol);

/// Roots of a scalar polynomial in [0,1] (sign changes and touching zeros found by subdivision, refined by
/// bisection / golden search), each listed once; `zeroTol` is the value below which |p| counts as zero.
std::vector<double> rootsInUnitInterval(const BernsteinPoly& p, double zeroTol);

/// Divides p by d in Bernstein form: the quotient q of degree deg p - deg d minimising the coefficients of
/// p - d q (linear least squares on the coefficient map, QR), and the largest coefficient of that remainder. Stable
/// for divisors with multiple roots, where repeated deflation at a numerical root is not.
std::pair<BernsteinPoly, double> divideExactly(const BernsteinPoly& p, const BernsteinPoly& d);

}  // namespace seam::rational::detail
