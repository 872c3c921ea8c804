#pragma once
// Private: closest points on B-spline curves (coarse sampling per span, then safeguarded Newton).
#include <optional>

#include "seam/core/types.h"
#include "seam/spline/bspline_curve.h"

namespace seam::detail {

struct CurvePoint {
  double t = 0.0;
  double distance = 0.0;
};

/// Closest point of `curve` to `p` over [range.lo, range.hi] (default: the whole domain). With a guess, Newton
/// starts there and the coarse search is skipped when Newton converges to a point no farther than the guess.
CurvePoint closestPoint(const BSplineCurve& curve, const Vec3& p, std::optional<Interval> range = std::nullopt,
                        std::optional<double> guess = std::nullopt);

}  // namespace seam::detail
