#pragma once
// A polynomial patch that stands for an analytic surface (cylinder, cone, sphere, torus) in the surface's own
// parameters, for the certified pcurve route (issue 35). The exact B-spline form of such a surface (OpenCASCADE's
// conversion) runs in a parameter of its own along each circle (a rational function of tan(angle / 2)), so a pcurve
// in the surface's angle parameter does not compose with it; this patch does. Each circle's cos and sin are replaced
// on spans of at most kTrigSpanMax radians by their Taylor polynomials of degree kTrigDegree (ends pinned to the
// values), whose remainder lies below the unit round-off of the surface's size (docs/algorithms/seam-measures.md,
// "Analytic faces in their own parameters").
#include <Geom_Surface.hxx>

#include "seam/core/result.h"
#include "seam/spline/bspline_surface.h"

namespace seam::occt::detail {

/// The largest angle of one span of the patch along a circle, and the degree there: on a span of h radians the
/// Taylor remainder of cos / sin about its middle is at most (h / 2)^(n + 1) / (n + 1)! for the values and
/// (h / 2)^(n + 1 - r) / (n + 1 - r)! for the r-th derivative: 2.2e-17, 2.3e-15 and 2.0e-13 (r = 0, 1, 2) at
/// pi / 16 and degree 9 (relative to the radius), below the round-off of the composition for the values and normals.
inline constexpr double kTrigSpanMax = 3.14159265358979323846 / 16.0;
inline constexpr int kTrigDegree = 9;

/// The patch and what it stands for.
struct AnalyticPatch {
  BSplineSurface surface;       ///< polynomial, in the analytic surface's own (u, v), over the box given
  double positionError = 0.0;   ///< a bound of |patch(u, v) - surface(u, v)| over the box (the Taylor remainders)
  std::string kind;             ///< "cylinder", "cone", "sphere" or "torus"
};

/// Whether analyticPatch makes a patch for `surface` (a cylinder, cone, sphere or torus under any trims).
bool hasAnalyticPatch(const Handle(Geom_Surface) & surface);

/// The patch of `surface` (under any Geom_RectangularTrimmedSurface) over [u0, u1] x [v0, v1] of its parameters.
/// kUnsupported for other surface types, kInvalidInput for an empty or non-finite box.
Result<AnalyticPatch> analyticPatch(const Handle(Geom_Surface) & surface, double u0, double u1, double v0, double v1);

}  // namespace seam::occt::detail
