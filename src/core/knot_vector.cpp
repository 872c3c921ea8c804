#include "seam/core/knot_vector.h"

#include <fmt/format.h>

#include <algorithm>
#include <cassert>
#include <cmath>

#include "seam/core/tolerances.h"

namespace seam {

namespace {
double knotTolerance(const std::vector<double>& t) {
  if (t.empty()) return 0.0;
  const double span = std::abs(t.back() - t.front());
  const double mag = std::max(std::abs(t.front()), std::abs(t.back()));
  return kKnotRelTol * std::max(span, mag);
}
}  // namespace

Status KnotVector::validate(int degree, int numPoints) const {
  if (degree < 1) return invalidInput(fmt::format("degree {} is below 1", degree));
  if (numPoints < degree + 1)
    return invalidInput(
        fmt::format("{} control points are too few for degree {} (need at least {})", numPoints, degree, degree + 1));
  const int expected = numPoints + degree + 1;
  if (size() != expected)
    return invalidInput(fmt::format("knot vector has {} entries, expected {} for {} control points of degree {}",
                                    size(), expected, numPoints, degree));
  for (int i = 0; i < size(); ++i)
    if (!std::isfinite(t_[static_cast<size_t>(i)]))
      return invalidInput(fmt::format("knot {} is not a finite number", i));
  for (int i = 1; i < size(); ++i)
    if (t_[static_cast<size_t>(i)] < t_[static_cast<size_t>(i - 1)])
      return invalidInput(fmt::format("knots are not non-decreasing: knot {} = {} is less than knot {} = {}", i,
                                      t_[static_cast<size_t>(i)], i - 1, t_[static_cast<size_t>(i - 1)]));
  const Interval dom = domain(degree);
  if (!(dom.hi > dom.lo))
    return invalidInput(fmt::format("empty parameter domain [{}, {}] (knots {} and {} are equal)", dom.lo, dom.hi,
                                    degree, numPoints));
  // Multiplicities: exact equality of stored doubles (what a file says is what it is).
  int i = 0;
  while (i < size()) {
    int j = i;
    while (j + 1 < size() && t_[static_cast<size_t>(j + 1)] == t_[static_cast<size_t>(i)]) ++j;
    const int mult = j - i + 1;
    const double value = t_[static_cast<size_t>(i)];
    const bool atEnd = (i == 0) || (j == size() - 1);
    const bool interior = value > dom.lo && value < dom.hi;
    if (interior && mult > degree)
      return invalidInput(fmt::format("interior knot {} has multiplicity {}, more than the degree {}", value, mult,
                                      degree));
    if (!interior && mult > degree + 1)
      return invalidInput(fmt::format("end knot {} has multiplicity {}, more than degree + 1 = {}", value, mult,
                                      degree + 1));
    (void)atEnd;
    i = j + 1;
  }
  return Status::ok();
}

Interval KnotVector::domain(int degree) const {
  const int n = size() - degree - 1;
  if (n <= degree || degree < 0) return {0.0, 0.0};
  return {t_[static_cast<size_t>(degree)], t_[static_cast<size_t>(n)]};
}

int KnotVector::findSpan(std::span<const double> knots, int degree, double t) {
  const int n = static_cast<int>(knots.size()) - degree - 1;  // number of control points
  assert(n > degree);
  const double lo = knots[static_cast<size_t>(degree)];
  const double hi = knots[static_cast<size_t>(n)];
  if (t >= hi) {
    int k = n - 1;
    while (k > degree && knots[static_cast<size_t>(k)] == hi) --k;  // last non-empty span
    return k;
  }
  if (t <= lo) {
    int k = degree;
    while (k < n - 1 && knots[static_cast<size_t>(k + 1)] == lo) ++k;  // first non-empty span
    return k;
  }
  // upper_bound over [t_p, t_n]: first knot strictly greater than t, minus one.
  const auto first = knots.begin() + degree;
  const auto last = knots.begin() + n + 1;
  const auto it = std::upper_bound(first, last, t);
  return static_cast<int>(it - knots.begin()) - 1;
}

int KnotVector::multiplicity(double t) const {
  const double tol = knotTolerance(t_);
  int m = 0;
  for (double k : t_)
    if (std::abs(k - t) <= tol) ++m;
  return m;
}

std::vector<double> KnotVector::breakpoints() const {
  std::vector<double> out;
  const double tol = knotTolerance(t_);
  for (double k : t_)
    if (out.empty() || k - out.back() > tol) out.push_back(k);
  return out;
}

std::vector<int> KnotVector::multiplicities() const {
  std::vector<int> out;
  const double tol = knotTolerance(t_);
  double last = 0.0;
  for (size_t i = 0; i < t_.size(); ++i) {
    if (i == 0 || t_[i] - last > tol) {
      out.push_back(1);
      last = t_[i];
    } else {
      ++out.back();
    }
  }
  return out;
}

std::vector<double> KnotVector::interiorBreakpoints(int degree) const {
  const Interval d = domain(degree);
  const double tol = knotTolerance(t_);
  std::vector<double> out;
  for (double b : breakpoints())
    if (b > d.lo + tol && b < d.hi - tol) out.push_back(b);
  return out;
}

KnotVector KnotVector::reparametrized(int degree, double a, double b) const {
  const Interval d = domain(degree);
  const double s = (b - a) / d.length();
  std::vector<double> out(t_.size());
  for (size_t i = 0; i < t_.size(); ++i) out[i] = a + (t_[i] - d.lo) * s;
  // Pin the domain ends exactly.
  for (size_t i = 0; i < t_.size(); ++i) {
    if (t_[i] == d.lo) out[i] = a;
    if (t_[i] == d.hi) out[i] = b;
  }
  return KnotVector(std::move(out));
}

KnotVector KnotVector::reversed(int degree) const {
  const Interval d = domain(degree);
  std::vector<double> out(t_.size());
  const size_t m = t_.size();
  for (size_t i = 0; i < m; ++i) {
    const double k = t_[m - 1 - i];
    out[i] = (k == d.lo) ? d.hi : (k == d.hi) ? d.lo : d.lo + d.hi - k;
  }
  return KnotVector(std::move(out));
}

KnotVector KnotVector::clampedUniform(int degree, int numPoints, double a, double b) {
  std::vector<double> t;
  t.reserve(static_cast<size_t>(numPoints + degree + 1));
  for (int i = 0; i <= degree; ++i) t.push_back(a);
  const int interior = numPoints - degree - 1;
  for (int i = 1; i <= interior; ++i) t.push_back(a + (b - a) * i / (interior + 1));
  for (int i = 0; i <= degree; ++i) t.push_back(b);
  return KnotVector(std::move(t));
}

KnotVector KnotVector::bezier(int degree, double a, double b) { return clampedUniform(degree, degree + 1, a, b); }

Matrix basisFunctionDerivatives(const KnotVector& knots, int degree, int span, double t, int order) {
  // The NURBS Book, algorithm A2.3.
  const int p = degree;
  const auto& U = knots.values();
  Matrix ders = Matrix::Zero(order + 1, p + 1);
  Matrix ndu(p + 1, p + 1);
  std::vector<double> left(static_cast<size_t>(p + 1)), right(static_cast<size_t>(p + 1));
  ndu(0, 0) = 1.0;
  for (int j = 1; j <= p; ++j) {
    left[static_cast<size_t>(j)] = t - U[static_cast<size_t>(span + 1 - j)];
    right[static_cast<size_t>(j)] = U[static_cast<size_t>(span + j)] - t;
    double saved = 0.0;
    for (int r = 0; r < j; ++r) {
      ndu(j, r) = right[static_cast<size_t>(r + 1)] + left[static_cast<size_t>(j - r)];
      const double temp = ndu(r, j - 1) / ndu(j, r);
      ndu(r, j) = saved + right[static_cast<size_t>(r + 1)] * temp;
      saved = left[static_cast<size_t>(j - r)] * temp;
    }
    ndu(j, j) = saved;
  }
  for (int j = 0; j <= p; ++j) ders(0, j) = ndu(j, p);
  const int n = std::min(order, p);
  Matrix a(2, p + 1);
  for (int r = 0; r <= p; ++r) {
    int s1 = 0, s2 = 1;
    a(0, 0) = 1.0;
    for (int k = 1; k <= n; ++k) {
      double d = 0.0;
      const int rk = r - k, pk = p - k;
      if (r >= k) {
        a(s2, 0) = a(s1, 0) / ndu(pk + 1, rk);
        d = a(s2, 0) * ndu(rk, pk);
      }
      const int j1 = rk >= -1 ? 1 : -rk;
      const int j2 = (r - 1 <= pk) ? k - 1 : p - r;
      for (int j = j1; j <= j2; ++j) {
        a(s2, j) = (a(s1, j) - a(s1, j - 1)) / ndu(pk + 1, rk + j);
        d += a(s2, j) * ndu(rk + j, pk);
      }
      if (r <= pk) {
        a(s2, k) = -a(s1, k - 1) / ndu(pk + 1, r);
        d += a(s2, k) * ndu(r, pk);
      }
      ders(k, r) = d;
      std::swap(s1, s2);
    }
  }
  double f = p;
  for (int k = 1; k <= n; ++k) {
    ders.row(k) *= f;
    f *= (p - k);
  }
  return ders;
}

}  // namespace seam
