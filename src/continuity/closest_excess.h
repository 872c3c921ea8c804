#pragma once
// Private (continuity/pcurve_seam.cpp, continuity/seam.cpp): how much the angle between the normals at closest points
// can exceed the angle at the points a seam route pairs (SeamOptions::closestPointsOn,
// PCurveSeamBounds::g1ClosestExcessDeg, SeamReport::g1ClosestExcessDeg). docs/algorithms/seam-measures.md, "Angles
// between closest points".
#include <cstddef>
#include <limits>
#include <vector>

#include "seam/core/bernstein.h"

namespace seam::detail {

/// What bounds, on one leaf (local parameter x in [0, 1]), how far B's point closest to A(x) lies from the paired
/// B(x) (SeamOptions::closestPointsOn; kOnA: A and B exchanged): Bernstein coefficient bounds, A = X_A / w_A,
/// B = X_B / w_B.
struct ClosestData {
  double f = 0.0;        ///< max |(A - B) . B_x|, the closest-point equation's residual at the paired point
  double speedLo = 0.0;  ///< min |B_x| (0: not bounded away from zero)
  double gapHi = 0.0;    ///< max |A - B|
  /// max curvature of B's edge (1 / length; infinite where not bounded): independent of the parametrisation, so a
  /// speed that varies along the edge (uneven knots) does not count as bending, as |B_xx| / |B_x|^2 would.
  double curvatureHi = std::numeric_limits<double>::infinity();
  double turnHi = std::numeric_limits<double>::infinity();  ///< max |d(N_B / |N_B|) / dx| (radians per unit x)
};

/// A piece [x0, x1] of a leaf, [t0, t1] of the edge (A's parameter), with its ClosestData (per unit of its own local
/// parameter).
struct ClosestCell {
  size_t leaf = 0;
  double x0 = 0.0, x1 = 1.0, t0 = 0.0, t1 = 0.0;
  ClosestData d;
};

/// One leaf's sides for the closest-point excess (SeamOptions::closestPointsOn): A = xa / wa, the side whose points
/// are taken, B = xb / wb, the side their closest points lie on, nb B's normal numerator (end roots divided out),
/// and the leaf as one cell.
struct ClosestLeaf {
  BernsteinPoly xa, wa, xb, wb, nb;
  ClosestCell whole;
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

/// The leaf `index` of a seam with A = xa / wa, B = xb / wb and B's normal numerator nb along local x in [0, 1],
/// over [t0, t1] of the edge parameter both sides are written in (t0 < t1; leaves in increasing t), as one cell.
ClosestLeaf closestLeaf(BernsteinPoly xa, BernsteinPoly wa, BernsteinPoly xb, BernsteinPoly wb, BernsteinPoly nb,
                        size_t index, double t0, double t1);

/// How much the angle between A's normal and B's at B's (local) closest point can exceed the angle at the paired
/// points, in radians (SeamOptions::closestPointsOn; kOnA: A and B exchanged in what follows; infinite where it cannot
/// be bounded): first over each leaf as a whole, then with the cells above `target` halved (ClosestRefinement).
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
double closestExcess(const std::vector<ClosestLeaf>& leaves, double target, const ClosestRefinement& how = {});

}  // namespace seam::detail
