#pragma once
// Private helpers shared by corner.cpp, model_check.cpp and overlap.cpp: closest points on edge curves, collapsed-edge
// tests, distances to boxes.
#include <optional>

#include "seam/core/types.h"
#include "seam/model/model.h"
#include "seam/spline/bspline_curve.h"
#include "seam/spline/bspline_surface.h"

namespace seam::detail {

/// Closest point of `curve` to `p` restricted to `range` (default: the domain): coarse samples per knot span, then a
/// safeguarded Newton iteration on (C(t) - p) . C'(t) = 0. Returns the parameter and the distance.
struct EdgeProjection {
  double t = 0.0;
  double distance = 0.0;
};
EdgeProjection projectOntoCurve(const BSplineCurve& curve, const Vec3& p, std::optional<Interval> range = std::nullopt);

/// Largest distance of a control point of `curve` from its first control point (a bound for the curve's extent:
/// convex hull property). An edge whose extent is at most the distance tolerance is collapsed (a pole).
double controlExtent(const BSplineCurve& curve);

/// The parameter range of edge `e` of `s` (v-domain for U0/U1, u-domain for V0/V1).
Interval edgeDomain(const BSplineSurface& s, Edge e);

/// The surface parameters (u, v) of the point at edge parameter t on edge `e`.
Vec2 edgePointUV(const BSplineSurface& s, Edge e, double t);

/// Distance from p to an axis-aligned box (0 inside).
double boxDistance(const BoundingBox& b, const Vec3& p);

}  // namespace seam::detail
