#pragma once
// Private helpers shared by the constructions in src/construct (Johansson Section 4).
#include <optional>
#include <string>
#include <vector>

#include "seam/core/bernstein.h"
#include "seam/core/result.h"
#include "seam/core/types.h"
#include "seam/model/model.h"
#include "seam/spline/bezier.h"
#include "seam/spline/bspline_surface.h"

namespace seam::construct_internal {

/// A patch seen from one of its edges: the boundary curve, the cross derivative pointing OUT of the patch and
/// the derivative along the edge, all as exact polynomials in the patch's own edge parameter (increasing).
struct EdgeJet {
  BernsteinPoly curve;
  BernsteinPoly out;
  BernsteinPoly along;
};
EdgeJet edgeJet(const BernsteinPatch& a, Edge e);

/// The scalar Bernstein basis polynomial B_a^d as a BernsteinPoly (coefficient a is 1, the others 0).
BernsteinPoly unitPoly(int degree, int a);

/// Row index in N's control net of the point k rows away from edge e (k = 0: on the edge) and l-th along it
/// (in N's own increasing parameter). N has bi-degree (nu, nv).
int netIndex(Edge e, int k, int l, int nu, int nv);
/// N's degree along / across edge e.
inline int alongDegree(Edge e, int nu, int nv) { return isUEdge(e) ? nv : nu; }
inline int crossDegree(Edge e, int nu, int nv) { return isUEdge(e) ? nu : nv; }
/// +1 for U0/V0 (the parameter increases into the patch), -1 for U1/V1.
inline double intoSign(Edge e) { return (e == Edge::U0 || e == Edge::V0) ? 1.0 : -1.0; }

/// The single Bezier piece of a model patch; kUnsupported for rational or multi-span patches (the
/// constructions of Johansson Section 4 are for polynomial Bezier patches), kInvalidInput for non-3-D ones.
Result<BezierPatch> singleBezier(const Patch& patch);

/// A model patch holding `b` (kind kBezier).
Patch bezierModelPatch(std::string name, const BezierPatch& b);

/// Corner points of a Bezier patch: index 0 (u,v)=(0,0), 1 (1,0), 2 (0,1), 3 (1,1).
Vec3 cornerPoint(const BezierPatch& b, int corner);
/// The two end points of edge e, in increasing edge parameter.
std::pair<Vec3, Vec3> edgeEnds(const BezierPatch& b, Edge e);
/// The corner index of the end of edge e at parameter end `atEnd` (false: start).
int edgeCorner(Edge e, bool atEnd);
/// True when the corner lies on edge e.
bool cornerOnEdge(int corner, Edge e);

/// Largest distance between two edge curves (sampled densely; `reversed`: compare b at 1 - t).
double edgeDistance(const BezierPatch& a, Edge ea, const BezierPatch& b, Edge eb, bool reversed);

/// Unique new patch name: `base` if unused in `taken`, else base_2, base_3, ...
std::string uniqueName(const std::string& base, const std::vector<std::string>& taken);

}  // namespace seam::construct_internal
