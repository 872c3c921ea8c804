#pragma once
// Private (continuity/pcurve_seam.cpp, continuity/seam.cpp): how much the angle between the normals at closest points
// can exceed the angle at the points a seam route pairs (SeamOptions::closestPointsOn,
// PCurveSeamBounds::g1ClosestExcessDeg, SeamReport::g1ClosestExcessDeg). docs/algorithms/seam-measures.md, "Angles
// between closest points".
#include <cstddef>
#include <limits>
#include <optional>
#include <vector>

#include "seam/core/bernstein.h"

namespace seam::detail {

/// The part of B's turning across its edge, and how far A's normal leans along B's edge (ClosestData::split).
struct ClosestSplit {
  /// max |n_B' . (n_B x T_B)| per unit x, n_B, T_B the unit normal and edge tangent: the edge's geodesic torsion
  /// times its speed (0 along a line of curvature); infinite where not bounded.
  double acrossTurnHi = std::numeric_limits<double>::infinity();
  /// max |n_A . T_B| at the paired points (0 where the edges are parallel: n_A is perpendicular to A's own edge);
  /// 1 where not bounded.
  double tangentSinHi = 1.0;
};

/// What bounds, on one leaf (local parameter x in [0, 1]), how far B's point closest to A(x) lies from the paired
/// B(x) (SeamOptions::closestPointsOn; kOnA: A and B exchanged): Bernstein coefficient bounds, A = X_A / w_A,
/// B = X_B / w_B.
struct ClosestData {
  double f = 0.0;        ///< max |(A - B) . B_x|, the closest-point equation's residual at the paired point
  double speedLo = 0.0;  ///< min |B_x| (0: not bounded away from zero)
  double speedHi = std::numeric_limits<double>::infinity();  ///< max |B_x|: B's arc length over the piece
  double gapHi = 0.0;    ///< max |A - B|
  /// max curvature of B's edge (1 / length; infinite where not bounded): independent of the parametrisation, so a
  /// speed that varies along the edge (uneven knots) does not count as bending, as |B_xx| / |B_x|^2 would.
  double curvatureHi = std::numeric_limits<double>::infinity();
  double turnHi = std::numeric_limits<double>::infinity();  ///< max |d(N_B / |N_B|) / dx| (radians per unit x)
  ClosestSplit split;  ///< the part of that turning across B's edge, and A's normal's lean
};

/// A piece [x0, x1] of a leaf, [t0, t1] of the edge (A's parameter), with its ClosestData (per unit of its own local
/// parameter).
struct ClosestCell {
  size_t leaf = 0;
  double x0 = 0.0, x1 = 1.0, t0 = 0.0, t1 = 0.0;
  ClosestData d;
  double cap = std::numeric_limits<double>::infinity();  ///< the excess of the cell it was halved from
};

/// B's edge on a window around a short leaf, for the bound of its curvature (ClosestData::curvatureHi). On a sliver
/// leaf (linkrods.step: a surface knot 2e-9 of the edge from a pcurve's breakpoint) the second derivative of the
/// leaf's own polynomials is the round-off of their coefficients (of the model's size) over the leaf's length squared:
/// a curvature bound of 4e5 / mm where the edge bends by about 1, which left the closest-point excess unbounded. On a
/// window where B is the same polynomial (one piece of its pcurve, one span of its surface) and that is not short,
/// the derivatives are formed first and then restricted to the leaf's part of it, so they keep their own size.
struct ClosestWindow {
  BernsteinPoly t, t1, acc, w;  ///< T = X_B' w_B - X_B w_B', T', T' w_B - 2 T w_B' and w_B on the window
  double y0 = 0.0, y1 = 1.0;    ///< the leaf's local x in [0, 1] is y0 + x (y1 - y0) of the window's
};

/// The ClosestWindow of B = x / w over a window of B's parameter, the leaf being [y0, y1] of its local parameter.
ClosestWindow closestWindow(const BernsteinPoly& x, const BernsteinPoly& w, double y0, double y1);

/// One leaf's sides for the closest-point excess (SeamOptions::closestPointsOn): A = xa / wa, the side whose points
/// are taken, B = xb / wb, the side their closest points lie on, na and nb their normal numerators (end roots divided
/// out), and the leaf as one cell; `window`: B on a window around a short leaf, whose curvature bound is taken where
/// it is lower than the leaf's own.
struct ClosestLeaf {
  BernsteinPoly xa, wa, xb, wb, na, nb;
  ClosestCell whole;
  std::optional<ClosestWindow> window;
};

/// How far closestExcess halves the cells above its target: at most `rounds` times, only while a round lowers the
/// largest excess below `gain` times the last (or, with `whileUnboundedShrink`, leaves fewer cells unbounded), and
/// only the cells above `splitShare` of the largest excess. The pcurve route keeps the defaults (8 cells per leaf at
/// most, every cell above the target; its leaves are many and short). A patch seam has a few long pieces, along which
/// the normal's turning and the residual vary by a hundred times (SeamGap.AcrossAGap...: the first halving lowers
/// the excess by 25 %, the next five by 2.6 times more): kPatchClosestRefinement halves up to 10 times, the cells
/// within a quarter of the largest excess only, while a round still lowers it by 5 %. `clipNeighbours`: a cell's
/// bounds take in only the parts of its neighbours within its reach (one more closestData per neighbour reached),
/// else whole neighbours (as the pcurve route, whose leaves are short: clipping doubled its cost on occ22470.igs).
/// "The largest excess" is followed both as bounded (closestExcess) and from B's whole turning alone, the bound before
/// the along / across split: a round that lowers either goes on, the cells above the share by either are halved,
/// and a half keeps its parent's excess where its own is larger.
struct ClosestRefinement {
  int rounds = 3;
  double gain = 0.75;
  double splitShare = 0.0;
  bool whileUnboundedShrink = false;
  bool clipNeighbours = false;
};
inline constexpr ClosestRefinement kPatchClosestRefinement{10, 0.95, 0.25, true, true};

/// The leaf's data over [x0, x1] of it (see closest_excess.cpp).
ClosestData closestData(const ClosestLeaf& L, double x0, double x1, bool refine);

/// The leaf `index` of a seam with A = xa / wa, B = xb / wb and normal numerators na, nb along local x in [0, 1],
/// over [t0, t1] of the edge parameter both sides are written in (t0 < t1; leaves in increasing t), as one cell.
ClosestLeaf closestLeaf(BernsteinPoly xa, BernsteinPoly wa, BernsteinPoly xb, BernsteinPoly wb, BernsteinPoly na,
                        BernsteinPoly nb, size_t index, double t0, double t1,
                        std::optional<ClosestWindow> window = std::nullopt);

/// How much the angle between A's normal and B's at B's (local) closest point can exceed the angle at the paired
/// points, in radians, where that angle is at most `paired` (radians) everywhere (SeamOptions::closestPointsOn; kOnA:
/// A and B exchanged in what follows; infinite where it cannot be bounded): first over each leaf as a whole, then
/// with the cells above `target` halved (ClosestRefinement).
/// At a point t of a cell (A's edge parameter; B is written in it too), with sigma the arc length of B's edge:
/// h(sigma) = |A(t) - B(sigma)|^2 / 2 has h' = -(A - B) . T_B and h'' = 1 - (A - B) . kappa n_B >= 1 - G kappa_max
/// =: c, so it is strictly convex where |A - B| <= G and the curvature is at most kappa_max. At the paired point
/// |h'| = |f| / |B_t| <= |f| / m =: r (f = (A - B) . B_t, m = min |B_t|): the least value of h on B's range lies within
/// r / c of it in arc length (clamped at an end of the range likewise). Taking d = 2 r and G = |A - B|(cell) + d,
/// c >= 1 / 2 makes r / c <= d consistent; the cells reached are those within d / m in t. B's unit normal turns by at
/// most K / m per unit of arc length (K = max |d(N_B / |N_B|) / dt|), so the excess is at most (K / m) (r / c).
/// Local: a closest point elsewhere would need B's edge to come back within the gap of itself. In arc length the
/// argument holds wherever the parametric one (|B_tt| in place of the curvature, 2 |f| / m^2 |B_t|max in place of d)
/// did, and gives at most its excess: grid3x3's uneven knots make |B_tt| 56 where the curvature is 2.
/// Sharper where B's normal turns along the edge rather than across it (a fillet along a line of curvature): with a
/// = n_A(t) fixed and s = |a - n_B| the chord of the angle, (s^2 / 2)' = -a . n_B' = -(a . T_B) k_n - (a . b) tau
/// (b = n_B x T_B; k_n, tau the parts of n_B' along T_B and b), |a . b| <= s and |a . T_B| <= eps := |n_A . T_B|
/// at the paired point + kappa_max (r / c) (the tangent turns by at most that much within the reach). So
/// (s^2 / 2)' <= k_n eps + tau s, whence s <= sqrt(s0^2 + 2 k_n eps l) + tau l after an arc length l <= r / c, and
/// the angle at the closest point is at most 2 asin(that / 2), increasing in s0 <= 2 sin(paired / 2). A crease of
/// angle theta along a line of curvature (tau = 0) then adds about k_n eps l / theta instead of k_n l. k_n is taken
/// as B's whole turning K / m (nearly all of it wherever tau is small, where the split pays), tau bounded through
/// N x N' (ClosestSplit); the excess is the smaller of this and (K / m) (r / c).
double closestExcess(const std::vector<ClosestLeaf>& leaves, double target, double paired,
                     const ClosestRefinement& how = {});

}  // namespace seam::detail
