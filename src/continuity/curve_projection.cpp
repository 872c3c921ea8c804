#include "continuity/curve_projection.h"

#include <algorithm>
#include <cmath>
#include <span>
#include <vector>

#include "continuity/one_span_curve.h"
#include "spline/spline_internal.h"

namespace seam::detail {

namespace {
// Coarse samples per knot span before Newton; 8 separates the minima of the cubic/quintic distance functions met
// in practice, and Newton then converges quadratically.
constexpr int kCoarseSamplesPerSpan = 8;
constexpr int kNewtonIterations = 12;

// `start`, when given: the curve point at the starting t (the first iteration's x).
double newton(const OneSpanCurve& c, const Vec3& p, double t, Interval r, Vec3* start = nullptr) {
  for (int it = 0; it < kNewtonIterations; ++it) {
    Vec3 x, d1, d2;
    c.derivatives2(t, x, d1, d2);
    if (it == 0 && start) *start = x;
    const Vec3 diff = x - p;
    const double f = diff.dot(d1);
    const double fp = d1.squaredNorm() + diff.dot(d2);
    if (!(fp > 0.0)) break;
    const double next = std::clamp(t - f / fp, r.lo, r.hi);
    if (std::abs(next - t) <= 1e-15 * std::max(1.0, std::abs(t)) + 1e-16 * r.length()) {
      t = next;
      break;
    }
    t = next;
  }
  return t;
}
}  // namespace

CurvePoint closestPoint(const BSplineCurve& curve, const Vec3& p, std::optional<Interval> range,
                        std::optional<double> guess) {
  const Interval r = range.value_or(curve.domain());
  const OneSpanCurve ev(curve);  // the curve's own values, without the span search on Bezier edges
  auto distAt = [&](double t) { return (ev.point3(t) - p).norm(); };
  if (guess && curve.degree() <= kMaxFastBasisDegree) {
    // As below, with the points at g and t taken from derivatives2, which forms them with point3's operations
    // (the same basis values, the same sums: the same bits) for these degrees: two evaluations fewer.
    const double g = std::clamp(*guess, r.lo, r.hi);
    Vec3 xg;
    const double t = newton(ev, p, g, r, &xg);
    Vec3 x, d1, d2;
    ev.derivatives2(t, x, d1, d2);
    const Vec3 diff = x - p;
    const double d = diff.norm();
    if (d <= (xg - p).norm()) {
      const double grad = diff.dot(d1);
      const bool boundary = (t == r.lo && grad >= 0.0) || (t == r.hi && grad <= 0.0);
      if (boundary || std::abs(grad) <= 1e-9 * (diff.norm() + 1e-300) * d1.norm() || d == 0.0)
        return {t, d};
    }
  } else if (guess) {
    const double g = std::clamp(*guess, r.lo, r.hi);
    const double t = newton(ev, p, g, r);
    const double d = distAt(t);
    if (d <= distAt(g)) {
      // Accept when the projection is locally optimal (Newton converged or hit the range boundary).
      Vec3 x, d1, d2;
      ev.derivatives2(t, x, d1, d2);
      const Vec3 diff = x - p;
      const double grad = diff.dot(d1);
      const bool boundary = (t == r.lo && grad >= 0.0) || (t == r.hi && grad <= 0.0);
      if (boundary || std::abs(grad) <= 1e-9 * (diff.norm() + 1e-300) * d1.norm() || d == 0.0)
        return {t, d};
    }
  }
  // Coarse search over the spans inside the range.
  // One clamped Bezier span (every patch edge of a Bezier model) has no interior breakpoints: the range's ends
  // are the only cuts (no allocation); otherwise the spans' breakpoints inside the range are added.
  const std::vector<double>& U = curve.knots().values();
  const size_t p1 = static_cast<size_t>(curve.degree()) + 1;
  const bool oneSpan = curve.degree() >= 1 && U.size() == 2 * p1 && U[p1 - 1] < U[p1] &&
                       std::all_of(U.begin(), U.begin() + static_cast<std::ptrdiff_t>(p1),
                                   [&](double k) { return k == U.front(); }) &&
                       std::all_of(U.begin() + static_cast<std::ptrdiff_t>(p1), U.end(),
                                   [&](double k) { return k == U.back(); });
  std::vector<double> cutsHeap;
  const double oneSpanCuts[2] = {r.lo, r.hi};
  if (!oneSpan) {
    cutsHeap.push_back(r.lo);
    for (double b : curve.knots().interiorBreakpoints(curve.degree()))
      if (b > r.lo && b < r.hi) cutsHeap.push_back(b);
    cutsHeap.push_back(r.hi);
  }
  const std::span<const double> cuts = oneSpan ? std::span<const double>(oneSpanCuts, 2)
                                               : std::span<const double>(cutsHeap);
  double bestT = r.lo, bestD = distAt(r.lo);
  for (size_t k = 0; k + 1 < cuts.size(); ++k)
    for (int i = 1; i <= kCoarseSamplesPerSpan; ++i) {
      const double t = cuts[k] + (cuts[k + 1] - cuts[k]) * i / kCoarseSamplesPerSpan;
      const double d = distAt(t);
      if (d < bestD) {
        bestD = d;
        bestT = t;
      }
    }
  const double t = newton(ev, p, bestT, r);
  const double d = distAt(t);
  return d <= bestD ? CurvePoint{t, d} : CurvePoint{bestT, bestD};
}

}  // namespace seam::detail
