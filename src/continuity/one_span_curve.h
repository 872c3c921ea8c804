#pragma once
// Private: evaluation of the edge curves of Bezier patches (one clamped polynomial span) with the arithmetic of
// BSplineCurve::point3 and BSplineCurve::derivatives2, without their span search and general loops. Used by the
// pairing's edge data (model_check.cpp) and the closest-point projections (curve_projection.cpp).
#include <algorithm>
#include <vector>

#include "seam/core/types.h"
#include "seam/spline/bspline_curve.h"
#include "spline/spline_internal.h"

namespace seam::detail {

/// Largest degree evaluated here (the cubic and quintic edges of Bezier models; higher degrees go to BSplineCurve).
inline constexpr int kOneSpanMaxDegree = 5;

/// A curve's point and derivatives up to order 2, bit for bit as BSplineCurve::point3 / derivatives2 give them.
/// When the curve is polynomial, of degree 1..kOneSpanMaxDegree, with 3 coordinates and one span clamped at both
/// ends (knots a^(p+1) b^(p+1), a < b: every edge of a Bezier patch), KnotVector::findSpan returns p for every t in
/// the domain, and the values are formed here from that span with the same operations in the same order: the basis
/// values by the triangular Cox-de Boor scheme (The NURBS Book A2.2, as point3), the three rows of A2.3 by
/// detail::basisUpTo2 (as derivatives2), and the sums from zero over the control points in order (the weight 1.0 of
/// a polynomial curve multiplies exactly). Any other curve is evaluated by the curve itself.
class OneSpanCurve {
 public:
  explicit OneSpanCurve(const BSplineCurve& c) : c_(c) {
    const std::vector<double>& U = c.knots().values();
    const int p = c.degree();
    const size_t p1 = static_cast<size_t>(p) + 1;
    fast_ = !c.isRational() && p >= 1 && p <= kOneSpanMaxDegree && c.points().cols() == 3 &&
            c.numPoints() == p + 1 && U.size() == 2 * p1 && U[p1 - 1] < U[p1] &&
            std::all_of(U.begin(), U.begin() + static_cast<std::ptrdiff_t>(p1),
                        [&](double k) { return k == U.front(); }) &&
            std::all_of(U.begin() + static_cast<std::ptrdiff_t>(p1), U.end(), [&](double k) { return k == U.back(); });
  }

  /// True when the evaluation takes the one-span route (for tests).
  [[nodiscard]] bool oneSpan() const { return fast_; }

  /// BSplineCurve::point3(t).
  [[nodiscard]] Vec3 point3(double t) const {
    if (!fast_) return c_.point3(t);
    switch (c_.degree()) {
      case 3: return pointImpl<3>(t);
      default: return pointImpl<0>(t);
    }
  }

  /// BSplineCurve::derivatives2(t, x, d1, d2).
  void derivatives2(double t, Vec3& x, Vec3& d1, Vec3& d2) const {
    if (!fast_) return c_.derivatives2(t, x, d1, d2);
    const int p = c_.degree();
    double N[3][kMaxFastBasisDegree + 1];
    basisUpTo2(c_.knots().values(), p, p, t, N);
    const double* P = c_.points().data();
    Vec3 A[3] = {Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};
    for (int r = 0; r <= p; ++r) {
      const Vec3 q(P[3 * r], P[3 * r + 1], P[3 * r + 2]);
      for (int k = 0; k < 3; ++k) A[k] += N[k][r] * q;
    }
    x = A[0];
    d1 = A[1];
    d2 = A[2];
  }

 private:
  /// kP > 0: the degree known at compile time (the same operations as the run-time loop).
  template <int kP>
  [[nodiscard]] Vec3 pointImpl(double t) const {
    const int p = kP > 0 ? kP : c_.degree();
    const double* U = c_.knots().values().data();
    const int span = p;
    double N[kOneSpanMaxDegree + 1];
    basisValuesImpl<kP>(U, p, span, t, N);
    const double* P = c_.points().data();
    Vec3 out = Vec3::Zero();
    for (int r = 0; r <= p; ++r) out += N[r] * Vec3(P[3 * r], P[3 * r + 1], P[3 * r + 2]);
    return out;
  }

  const BSplineCurve& c_;
  bool fast_ = false;
};

}  // namespace seam::detail
