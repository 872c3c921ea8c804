#pragma once
// Private helpers of the repair module: a patch seen from one of its edges ("edge frame"), exact in both directions.
//
// In an edge frame the edge is v = v_min (V0) and u runs along it, as in Lai-Lian-Cassidy (the paper joins the
// edges v = v_2 of S and S~). The frame is built by permuting control points and by the exact knot map t -> -t
// (with the knot order reversed) where a direction must be reversed, so toEdgeFrame followed by fromEdgeFrame gives
// back the very same numbers (knots and points bit-identical), and knots inserted in the frame map back exactly.
#include <vector>

#include "seam/core/knot_vector.h"
#include "seam/core/types.h"
#include "seam/spline/bspline_surface.h"

namespace seam::detail {

/// t -> -t with the order reversed (exact in floating point).
KnotVector negatedKnots(const KnotVector& k);

/// The surface seen from edge e: u along the edge (the surface's own edge parameter, negated when flipAlong), v away
/// from the edge starting at v_min (the own across parameter, negated for U1/V1 edges).
BSplineSurface toEdgeFrame(const BSplineSurface& s, Edge e, bool flipAlong);
/// Inverse of toEdgeFrame (also for a frame whose knots were refined or whose points were changed).
BSplineSurface fromEdgeFrame(const BSplineSurface& frame, Edge e, bool flipAlong);

/// The frame's along parameter of the surface's own edge parameter t (and back): -t when flipAlong.
inline double frameAlong(double t, bool flipAlong) { return flipAlong ? -t : t; }

/// Index of the frame's control point (a along, b across) in the original surface's grid (row i * numV + j).
int originalIndex(const BSplineSurface& original, Edge e, bool flipAlong, int a, int b);

/// Knots closer than kKnotRelTol x (knot-vector length) to an existing breakpoint of `k` are snapped onto it.
double snapToKnot(const KnotVector& k, double t);

}  // namespace seam::detail
