#pragma once
// Private: exact algebra of rational polynomials whose denominators are powers of two positive weight polynomials
// wa (side A) and wb (side B): X = num / (wa^ea wb^eb). Keeping the exponents symbolic keeps degrees minimal; for
// polynomial patches wa = wb = 1 (degree 0) and nothing grows.
#include <algorithm>
#include <cmath>
#include <vector>

#include "seam/core/bernstein.h"

namespace seam::detail {

struct RationalPoly {
  BernsteinPoly num;
  int ea = 0;
  int eb = 0;
};

class WeightContext {
 public:
  WeightContext(BernsteinPoly wa, BernsteinPoly wb) : wa_({std::move(wa)}), wb_({std::move(wb)}) {}

  [[nodiscard]] const BernsteinPoly& wa() const { return wa_[0]; }
  [[nodiscard]] const BernsteinPoly& wb() const { return wb_[0]; }

  /// num * wa^da * wb^db.
  BernsteinPoly lift(const BernsteinPoly& num, int da, int db) {
    BernsteinPoly out = num;
    if (da > 0) out = product(power(wa_, da), out);
    if (db > 0) out = product(power(wb_, db), out);
    return out;
  }
  /// Brings x to the exponents (ea, eb) >= its own.
  BernsteinPoly numeratorAt(const RationalPoly& x, int ea, int eb) { return lift(x.num, ea - x.ea, eb - x.eb); }

  RationalPoly add(const RationalPoly& x, const RationalPoly& y, double sy = 1.0) {
    const int ea = std::max(x.ea, y.ea), eb = std::max(x.eb, y.eb);
    return {numeratorAt(x, ea, eb) + sy * numeratorAt(y, ea, eb), ea, eb};
  }
  static RationalPoly mul(const RationalPoly& x, const RationalPoly& y) {
    return {product(x.num, y.num), x.ea + y.ea, x.eb + y.eb};
  }
  static RationalPoly dot(const RationalPoly& x, const RationalPoly& y) {
    return {seam::dot(x.num, y.num), x.ea + y.ea, x.eb + y.eb};
  }
  static RationalPoly cross(const RationalPoly& x, const RationalPoly& y) {
    return {seam::cross(x.num, y.num), x.ea + y.ea, x.eb + y.eb};
  }
  static RationalPoly scaled(RationalPoly x, double s) {
    x.num *= s;
    return x;
  }

 private:
  static const BernsteinPoly& power(std::vector<BernsteinPoly>& cache, int k) {
    while (static_cast<int>(cache.size()) < k) cache.push_back(product(cache.back(), cache.front()));
    return cache[static_cast<size_t>(k - 1)];
  }
  std::vector<BernsteinPoly> wa_, wb_;
};

/// Lower and upper bounds of a positive polynomial on [0,1] from its coefficients (convex-hull property).
inline double lowerBound(const BernsteinPoly& p) { return p.coeffs().col(0).minCoeff(); }
inline double upperBound(const BernsteinPoly& p) { return p.coeffs().col(0).maxCoeff(); }

/// Bounds of the denominator wa^ea wb^eb on [0,1].
inline double denominatorLower(const BernsteinPoly& wa, const BernsteinPoly& wb, int ea, int eb) {
  return std::pow(lowerBound(wa), ea) * std::pow(lowerBound(wb), eb);
}
inline double denominatorUpper(const BernsteinPoly& wa, const BernsteinPoly& wb, int ea, int eb) {
  return std::pow(upperBound(wa), ea) * std::pow(upperBound(wb), eb);
}

/// Divides out the factor t (or 1 - t) while the first (last) coefficient row vanishes relative to `threshold`:
/// p = t q with q_i = n c_{i+1} / (i+1). Used where a normal vanishes at a piece end (poles): the direction of
/// p is unchanged by dividing with a positive scalar function.
inline BernsteinPoly stripEndRoots(BernsteinPoly p, double threshold) {
  while (p.degree() >= 1 && p.coeffs().row(0).norm() <= threshold) {
    const int n = p.degree();
    Matrix q(n, p.dim());
    for (int i = 0; i < n; ++i) q.row(i) = (static_cast<double>(n) / (i + 1)) * p.coeffs().row(i + 1);
    p = BernsteinPoly(std::move(q));
  }
  while (p.degree() >= 1 && p.coeffs().row(p.degree()).norm() <= threshold) {
    const int n = p.degree();
    Matrix q(n, p.dim());
    for (int i = 0; i < n; ++i) q.row(i) = (static_cast<double>(n) / (n - i)) * p.coeffs().row(i);
    p = BernsteinPoly(std::move(q));
  }
  return p;
}

}  // namespace seam::detail
