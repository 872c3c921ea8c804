#include "continuity/sampling.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace seam::detail {

// Second fundamental form of a side in the orthonormal frame (e1, e2), with unit normal n.
Eigen::Matrix2d shapeInFrame(const Vec3& su, const Vec3& sv, const Vec3& suu, const Vec3& suv, const Vec3& svv,
                             const Vec3& n, const Vec3& e1, const Vec3& e2) {
  Eigen::Matrix<double, 3, 2> J;
  J << su, sv;
  const Eigen::Matrix2d G = J.transpose() * J;
  Eigen::Matrix2d II;
  II << suu.dot(n), suv.dot(n), suv.dot(n), svv.dot(n);
  Eigen::Matrix<double, 2, 2> C;
  const Eigen::Matrix2d Ginv = G.inverse();
  C.col(0) = Ginv * (J.transpose() * e1);
  C.col(1) = Ginv * (J.transpose() * e2);
  return C.transpose() * II * C;
}

double chartConditioning(const Vec3& a, const Vec3& b) {
  return chartConditioning(a.cross(b).norm(), a.squaredNorm() + b.squaredNorm());
}

std::optional<Vec3> limitNormal(const Vec3& a, const Vec3& b, const Vec3& da, const Vec3& db, double side) {
  const Vec3 n = a.cross(b);
  const double size = a.squaredNorm() + b.squaredNorm();
  if (!normalVanishes(n.norm(), size)) return Vec3(n.normalized());
  const Vec3 dn = da.cross(b) + a.cross(db);
  const double dsize = 2.0 * (a.norm() + b.norm()) * (da.norm() + db.norm());
  if (normalVanishes(dn.norm(), dsize) || !std::isfinite(dn.norm())) return std::nullopt;
  return Vec3(side * dn.normalized());
}

double spectralNorm(const Eigen::Matrix2d& m) {
  const Eigen::Matrix2d s = 0.5 * (m + m.transpose());
  const double tr = 0.5 * (s(0, 0) + s(1, 1));
  const double det = s(0, 0) * s(1, 1) - s(0, 1) * s(1, 0);
  const double disc = std::sqrt(std::max(0.0, tr * tr - det));
  return std::max(std::abs(tr + disc), std::abs(tr - disc));
}

// Golden-section refinement of a local maximum of f on [lo, hi].
std::pair<double, double> refineMax(const std::function<double(double)>& f, double lo, double hi, int iterations) {
  const double g = (std::sqrt(5.0) - 1.0) / 2.0;
  double a = lo, b = hi;
  double x1 = b - g * (b - a), x2 = a + g * (b - a);
  double f1 = f(x1), f2 = f(x2);
  for (int i = 0; i < iterations; ++i) {
    if (f1 < f2) {
      a = x1;
      x1 = x2;
      f1 = f2;
      x2 = a + g * (b - a);
      f2 = f(x2);
    } else {
      b = x2;
      x2 = x1;
      f2 = f1;
      x1 = b - g * (b - a);
      f1 = f(x1);
    }
  }
  return f1 > f2 ? std::pair{x1, f1} : std::pair{x2, f2};
}

std::pair<double, double> refineMaxParabolic(const std::function<double(double)>& f, double lo, double hi,
                                             double relTol) {
  // Minimises g = -f (the textbook form). a, b bracket the minimum; x is the best point so far, w the second best,
  // v the previous w; d is the last step and e the one before it (a parabolic step must be shorter than half of e).
  const double golden = 0.5 * (3.0 - std::sqrt(5.0));
  auto g = [&](double t) {
    const double y = f(t);
    return std::isnan(y) ? std::numeric_limits<double>::infinity() : -y;
  };
  double a = std::min(lo, hi), b = std::max(lo, hi);
  double x = a + golden * (b - a), w = x, v = x;
  double gx = g(x), gw = gx, gv = gx;
  double d = 0.0, e = 0.0;
  const double xtol = relTol * (b - a);
  for (int evaluations = 1; evaluations < kParabolicMaxEvaluations; ++evaluations) {
    const double m = 0.5 * (a + b);
    // Absolute resolution, never below a few ulps of x (no step that rounds back onto x).
    const double tol1 = std::max(xtol, 4.0 * std::numeric_limits<double>::epsilon() * std::abs(x)), tol2 = 2.0 * tol1;
    if (std::abs(x - m) <= tol2 - 0.5 * (b - a)) break;
    bool parabolic = false;
    if (std::abs(e) > tol1) {
      const double r = (x - w) * (gx - gv);
      double q = (x - v) * (gx - gw);
      double p = (x - v) * q - (x - w) * r;
      q = 2.0 * (q - r);
      if (q > 0.0) p = -p;
      q = std::abs(q);
      const double previous = e;
      e = d;
      // Accept the parabola's vertex when it falls inside (a, b) and the step is less than half the one before last.
      if (std::abs(p) < std::abs(0.5 * q * previous) && p > q * (a - x) && p < q * (b - x)) {
        d = p / q;
        const double u = x + d;
        if (u - a < tol2 || b - u < tol2) d = x < m ? tol1 : -tol1;
        parabolic = true;
      }
    }
    if (!parabolic) {
      e = x >= m ? a - x : b - x;
      d = golden * e;
    }
    const double u = std::abs(d) >= tol1 ? x + d : x + (d > 0.0 ? tol1 : -tol1);
    const double gu = g(u);
    if (gu <= gx) {
      (u >= x ? a : b) = x;
      v = w, gv = gw;
      w = x, gw = gx;
      x = u, gx = gu;
    } else {
      (u < x ? a : b) = u;
      if (gu <= gw || w == x) {
        v = w, gv = gw;
        w = u, gw = gu;
      } else if (gu <= gv || v == x || v == w) {
        v = u, gv = gu;
      }
    }
  }
  return {x, std::isinf(gx) && gx > 0.0 ? std::numeric_limits<double>::quiet_NaN() : -gx};
}

// Refines the kRefinedMaxima largest local maxima of values[i] (sampled at xs[i]) and returns the best (x, value).
std::pair<double, double> refinedMaximum(const std::vector<double>& xs, const std::vector<double>& values,
                                         const std::function<double(double)>& f, double relTol) {
  std::vector<size_t> locals;
  for (size_t i = 0; i < values.size(); ++i) {
    const bool leftOk = i == 0 || values[i] >= values[i - 1];
    const bool rightOk = i + 1 == values.size() || values[i] >= values[i + 1];
    if (leftOk && rightOk) locals.push_back(i);
  }
  std::sort(locals.begin(), locals.end(), [&](size_t a, size_t b) { return values[a] > values[b]; });
  if (locals.size() > static_cast<size_t>(kRefinedMaxima)) locals.resize(kRefinedMaxima);
  double bestX = xs.empty() ? 0.0 : xs[0], best = values.empty() ? 0.0 : values[0];
  for (size_t i = 0; i < values.size(); ++i)
    if (values[i] > best) {
      best = values[i];
      bestX = xs[i];
    }
  for (size_t i : locals) {
    const double lo = xs[i == 0 ? 0 : i - 1], hi = xs[i + 1 == xs.size() ? i : i + 1];
    if (!(hi > lo)) continue;
    const auto [x, v] = refineMaxParabolic(f, lo, hi, relTol);
    if (v > best) {
      best = v;
      bestX = x;
    }
  }
  return {bestX, best};
}


}  // namespace seam::detail
