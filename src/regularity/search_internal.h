#pragma once
// Shared pieces of the curve and surface defect searches.
#include <span>
#include <vector>

#include "seam/core/types.h"
#include "seam/regularity/defect_search.h"
#include "seam/spline/bspline_curve.h"
#include "seam/spline/bspline_surface.h"

namespace seam::regularity::detail {

/// Margin of the floating-point direction tests of the search, relative to |c| x max|v|: covers the round-off of
/// repeated Bezier subdivision (each level adds a few units in the last place of the coefficients).
inline constexpr double kConeMarginRel = 1e-10;

/// Is there a c with c . v > kConeMarginRel |c| max|v| for every v (0 strictly outside conv(vs))? Doubles only:
/// sum of unit vectors first, then Wolfe's minimum-norm point. An empty set or a zero vector: false.
bool positiveDirection(std::span<const Vec3> vs);

/// Axis-aligned box.
struct Box3 {
  Vec3 lo = Vec3::Constant(1e300);
  Vec3 hi = Vec3::Constant(-1e300);
  void add(const Vec3& p) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  void add(const Box3& b) {
    lo = lo.cwiseMin(b.lo);
    hi = hi.cwiseMax(b.hi);
  }
  /// Closed boxes grown by `gap` overlap.
  [[nodiscard]] bool overlaps(const Box3& b, double gap) const {
    return (lo.array() - gap <= b.hi.array()).all() && (b.lo.array() - gap <= hi.array()).all();
  }
};

/// Control-box diagonal based default of SearchOptions::distance.
double defaultDistance(double diagonal);

/// BSplineCurve::bezierPieces() and BSplineSurface::bezierPatches(), bit for bit, in time linear in the number of
/// spans (those cost O(spans^2): every Boehm step copies all rows; 200 000 segments did not finish in minutes).
std::vector<BezierCurvePiece> bezierPiecesLinear(const BSplineCurve& curve);
std::vector<BezierPatchPiece> bezierPatchesLinear(const BSplineSurface& surface);

}  // namespace seam::regularity::detail
