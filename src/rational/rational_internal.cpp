// Private helpers of the rational GC^n module; see rational_internal.h.
#include "rational/rational_internal.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <numbers>

#include <Eigen/Dense>

namespace seam::rational::detail {

double factorial(int n) {
  double f = 1.0;
  for (int i = 2; i <= n; ++i) f *= i;
  return f;
}

namespace {
void compositionsRec(int n, int k, std::vector<int>& cur, std::vector<std::vector<int>>& out) {
  if (k == 0) {
    if (n == 0) out.push_back(cur);
    return;
  }
  for (int r = 1; r <= n - (k - 1); ++r) {
    cur.push_back(r);
    compositionsRec(n - r, k - 1, cur, out);
    cur.pop_back();
  }
}
}  // namespace

std::vector<std::vector<int>> compositions(int n, int k) {
  std::vector<std::vector<int>> out;
  std::vector<int> cur;
  if (k >= 1 && n >= k) compositionsRec(n, k, cur, out);
  return out;
}

double lemma1Coefficient(int s, int h, const std::vector<int>& r) {
  const int k = static_cast<int>(r.size());
  double den = factorial(h) * factorial(k - h);
  for (int x : r) den *= factorial(x);
  return factorial(s) / den;
}

Series seriesProduct(const Series& a, const Series& b, int order) {
  Series c(static_cast<size_t>(order + 1), 0.0);
  const int na = std::min(order, static_cast<int>(a.size()) - 1), nb = std::min(order, static_cast<int>(b.size()) - 1);
  for (int i = 0; i <= na; ++i) {
    if (a[static_cast<size_t>(i)] == 0.0) continue;
    for (int j = 0; j <= nb && i + j <= order; ++j)
      c[static_cast<size_t>(i + j)] += a[static_cast<size_t>(i)] * b[static_cast<size_t>(j)];
  }
  return c;
}

// ---------------------------------------------------------------------------------------------------------------
namespace {
/// The 3-vector polynomial made of components (i0, i1, i2) of a 4-vector polynomial.
BernsteinPoly pick(const BernsteinPoly& p, int i0, int i1, int i2) {
  Matrix m(p.coeffs().rows(), 3);
  m.col(0) = p.coeffs().col(i0);
  m.col(1) = p.coeffs().col(i1);
  m.col(2) = p.coeffs().col(i2);
  return BernsteinPoly(std::move(m));
}
}  // namespace

BernsteinPoly bracket4(int i, const BernsteinPoly& r, const BernsteinPoly& s, const BernsteinPoly& t) {
  assert(i >= 1 && i <= 4 && r.dim() == 4 && s.dim() == 4 && t.dim() == 4);
  // 1-based rows i+1, i+2, i+3 (mod 4) = 0-based i, i+1, i+2 (mod 4).
  const int a = i % 4, b = (i + 1) % 4, c = (i + 2) % 4;
  // det of the 3x3 matrix whose COLUMNS are the picked R, S, T (= det of its transpose) = <R, S x T>.
  BernsteinPoly d = triple(pick(r, a, b, c), pick(s, a, b, c), pick(t, a, b, c));
  if ((i + 1) % 2 != 0) d *= -1.0;
  return d;
}

BernsteinPoly bracket3(int i, const BernsteinPoly& s, const BernsteinPoly& t) {
  assert(i >= 0 && i <= 2 && s.dim() == 3 && t.dim() == 3);
  return cross(s, t).component(i);
}

double bracket4(int i, const Vec4& r, const Vec4& s, const Vec4& t) {
  const int a = i % 4, b = (i + 1) % 4, c = (i + 2) % 4;
  const Vec3 R(r[a], r[b], r[c]), S(s[a], s[b], s[c]), T(t[a], t[b], t[c]);
  const double d = R.dot(S.cross(T));
  return (i + 1) % 2 != 0 ? -d : d;
}

// ---------------------------------------------------------------------------------------------------------------
namespace {
SignCheck positiveRec(const BernsteinPoly& p, double floor, int depth, int maxDepth) {
  const Matrix& c = p.coeffs();
  const auto n = c.rows() - 1;
  if (c(0, 0) <= floor || c(n, 0) <= floor) return SignCheck::kNotPositive;
  if (c.col(0).minCoeff() > floor) return SignCheck::kPositive;
  if (depth >= maxDepth) return SignCheck::kUndecided;
  const auto [l, r] = p.subdivided(0.5);
  const SignCheck a = positiveRec(l, floor, depth + 1, maxDepth);
  if (a == SignCheck::kNotPositive) return a;
  const SignCheck b = positiveRec(r, floor, depth + 1, maxDepth);
  if (b == SignCheck::kNotPositive) return b;
  return (a == SignCheck::kPositive && b == SignCheck::kPositive) ? SignCheck::kPositive : SignCheck::kUndecided;
}
}  // namespace

SignCheck certifyPositive(const BernsteinPoly& p, double floor, int maxDepth) {
  assert(p.dim() == 1);
  return positiveRec(p, floor, 0, maxDepth);
}

int effectiveDegree(const BernsteinPoly& p, double zeroTol) {
  const int n = p.degree();
  if (n < 0) return -1;
  if (n == 0) return p.maxAbsCoeff() > zeroTol ? 0 : -1;
  std::vector<VecX> f(static_cast<size_t>(n + 1));
  for (int j = 0; j <= n; ++j) f[static_cast<size_t>(j)] = p(0.5 * (1.0 - std::cos(std::numbers::pi * j / n)));
  int deg = -1;
  for (int k = 0; k <= n; ++k) {
    VecX a = VecX::Zero(p.dim());
    for (int j = 0; j <= n; ++j) {
      const double w = (j == 0 || j == n) ? 0.5 : 1.0;
      a += (w * std::cos(std::numbers::pi * j * k / n)) * f[static_cast<size_t>(j)];
    }
    a *= (k == 0 || k == n) ? 1.0 / n : 2.0 / n;
    if (a.cwiseAbs().maxCoeff() > zeroTol) deg = k;
  }
  return deg;
}

std::vector<double> rootsInUnitInterval(const BernsteinPoly& p, double zeroTol) {
  assert(p.dim() == 1);
  constexpr double kMinWidth = 1e-7;  // candidate intervals are narrowed to this width, then refined
  std::vector<std::pair<double, double>> cand;
  struct Item {
    BernsteinPoly q;
    double a, b;
  };
  std::vector<Item> stack{{p, 0.0, 1.0}};
  while (!stack.empty()) {
    Item it = std::move(stack.back());
    stack.pop_back();
    const Matrix& c = it.q.coeffs();
    if (c.col(0).minCoeff() > zeroTol || c.col(0).maxCoeff() < -zeroTol) continue;
    if (it.b - it.a <= kMinWidth) {
      cand.emplace_back(it.a, it.b);
      continue;
    }
    const auto [l, r] = it.q.subdivided(0.5);
    const double m = 0.5 * (it.a + it.b);
    stack.push_back({r, m, it.b});
    stack.push_back({l, it.a, m});
  }
  std::sort(cand.begin(), cand.end());
  // Merge adjacent candidates into clusters; the root of a cluster minimises |p| (golden section).
  std::vector<double> roots;
  size_t i = 0;
  while (i < cand.size()) {
    double a = cand[i].first, b = cand[i].second;
    size_t j = i + 1;
    while (j < cand.size() && cand[j].first <= b + kMinWidth) b = std::max(b, cand[j++].second);
    // Sign change inside? bisection; else golden search of |p|.
    double fa = p.scalar(a), fb = p.scalar(b);
    double x;
    if (fa == 0.0) {
      x = a;
    } else if (fb == 0.0) {
      x = b;
    } else if ((fa < 0.0) != (fb < 0.0)) {
      for (int it = 0; it < 80; ++it) {
        const double m = 0.5 * (a + b), fm = p.scalar(m);
        if ((fm < 0.0) == (fa < 0.0)) {
          a = m;
          fa = fm;
        } else {
          b = m;
        }
      }
      x = 0.5 * (a + b);
    } else {
      const double g = 0.5 * (std::sqrt(5.0) - 1.0);
      double lo = a, hi = b;
      for (int it = 0; it < 80; ++it) {
        const double x1 = hi - g * (hi - lo), x2 = lo + g * (hi - lo);
        if (std::abs(p.scalar(x1)) < std::abs(p.scalar(x2)))
          hi = x2;
        else
          lo = x1;
      }
      x = 0.5 * (lo + hi);
    }
    if (std::abs(p.scalar(x)) <= zeroTol) roots.push_back(std::clamp(x, 0.0, 1.0));
    i = j;
  }
  return roots;
}

std::pair<BernsteinPoly, double> divideExactly(const BernsteinPoly& p, const BernsteinPoly& d) {
  const int n = p.degree(), k = d.degree();
  if (n < k) return {BernsteinPoly::zero(0, p.dim()), p.maxAbsCoeff()};
  const int qn = n - k;
  Eigen::MatrixXd M(n + 1, qn + 1);
  for (int j = 0; j <= qn; ++j) {
    Matrix e = Matrix::Zero(qn + 1, 1);
    e(j, 0) = 1.0;
    M.col(j) = product(d, BernsteinPoly(std::move(e))).coeffs().col(0);
  }
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(M);
  Matrix q(qn + 1, p.dim());
  double residual = 0.0;
  for (int c = 0; c < p.dim(); ++c) {
    const Eigen::VectorXd rhs = p.coeffs().col(c);
    const Eigen::VectorXd x = qr.solve(rhs);
    q.col(c) = x;
    residual = std::max(residual, (M * x - rhs).cwiseAbs().maxCoeff());
  }
  return {BernsteinPoly(std::move(q)), residual};
}

}  // namespace seam::rational::detail
