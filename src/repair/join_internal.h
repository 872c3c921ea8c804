#pragma once
// The general least-squares join (docs/algorithms/lai-lian-cassidy.md, "Beyond the paper"): one moving patch, one or
// more of its edges constrained to fixed targets, minimal control-point displacement subject to linear G0/G1/G2
// equations written coefficient by coefficient in Bernstein form on every knot span of the seam.
//
// Unknowns: the control points (homogeneous when any side is rational) of rows 0..K of each constrained edge (K = 0,
// 1, 2 for G0, G1, G2) and the coefficients of the connecting functions, global polynomials over each seam:
//   G0: S(u)            = rho(u) T(u)                                  (rho = 1 for polynomial patches)
//   G1: S_n(u)          = -lambda(u) T_n(u) + kappa(u) T_t(u) + nu(u) T(u)   (nu = 0 for polynomial patches)
//   G2: S_nn(u)         = lambda^2 T_nn - 2 lambda kappa T_nt + kappa^2 T_tt - mu T_n + nu2 T_t
// where S_n is the derivative of the moving patch away from the edge (into it), T_n the target's derivative into the
// target, T_t = d/du T(u) along the seam (u = the moving patch's own edge parameter), lambda > 0 for a proper join.
// Since T is fixed these equations are linear in all unknowns jointly (G2 is solved after G1 with lambda, kappa
// fixed). The solution minimises sum |P* - P|^2 over the moved points (nullspace method, rank-revealing QR).
#include <optional>
#include <string>
#include <vector>

#include "core/bernstein_internal.h"
#include "seam/continuity/seam.h"
#include "seam/core/bernstein.h"
#include "seam/core/result.h"
#include "seam/core/types.h"
#include "seam/spline/bspline_surface.h"

namespace seam::detail {

/// Residual of the linear constraints below which a solution counts as exact, relative to the scale of the data.
/// The constraint rows are normalised to unit size; the residual of an exact solve is round-off, ~1e-13 relative.
inline constexpr double kConstraintRelTol = 1e-9;

/// Joins never fold (docs/algorithms/lai-lian-cassidy.md, "Joins never fold"). The G1 connecting function lambda of a
/// join must stay above this fraction of lambda0, the geometric ratio of the moving patch's cross derivative to the
/// target's (components normal to the seam tangent, sampled before the join; in homogeneous units when rational). A
/// lambda at or below 0 folds the patch back over its neighbour; a lambda that is positive but far below lambda0
/// squeezes the first moved row onto the edge, so that the patch's normal nearly vanishes at the seam. 1 % of the
/// patch's own cross derivative is clearly regular and never binds for a join that only straightens a kink.
inline constexpr double kLambdaFloorRel = 1e-2;


/// min sum_k w_k^2 (x_k - x0_k)^2 subject to C x = d (w_k = 0: free, minimum norm), by the nullspace method
/// (rank-revealing QR of C^T with the threshold kIdentityRelTol). `residual` (if given): max |C x - d|. Used by the
/// joins and by the local scheme's corner and edge systems.
Eigen::VectorXd constrainedLeastSquares(const Eigen::MatrixXd& C, const Eigen::VectorXd& d, const Eigen::VectorXd& x0,
                                        const Eigen::VectorXd& w, double* residual = nullptr);
/// The same problem from one decomposition: the particular solution (minimum norm, least squares on the rows when
/// C is rank deficient) from the rank-revealing QR of C^T that gives the nullspace, and only the nullspace columns
/// of Q formed, instead of a second decomposition of C and the whole of Q. Used by the local scheme's small corner
/// and edge systems (issue 13 §2: they were most of the scheme's time); systems up to 48 x 48 without heap allocation.
Eigen::VectorXd constrainedLeastSquaresQR(const Eigen::MatrixXd& C, const Eigen::VectorXd& d, const Eigen::VectorXd& x0,
                                          const Eigen::VectorXd& w, double* residual = nullptr);

/// The fixed side of a seam as seen from the moving patch: polynomial pieces over intervals of the moving patch's
/// own edge parameter u (homogeneous coordinates when `rational`). Cross derivatives are taken INTO the target with
/// respect to the target's across parameter.
struct TargetPiece {
  Interval u;
  BernsteinPoly point;   ///< T(u) on u, local parameter on [0,1]
  BernsteinPoly cross1;  ///< T_n
  BernsteinPoly cross2;  ///< T_nn (empty: G2 unavailable)
};
struct SeamTarget {
  std::vector<TargetPiece> pieces;  ///< consecutive, covering the seam range
  bool rational = false;
  int dimH = 3;                     ///< 3, or 4 when rational
  /// Breakpoints inside the range with the continuity order c of the target data there (C^c): the moving patch
  /// needs multiplicity >= p - c at u.
  std::vector<std::pair<double, int>> breaks;
  [[nodiscard]] Interval range() const { return {pieces.front().u.lo, pieces.back().u.hi}; }
  /// Largest (effective) degree over the pieces of the point, of T_n and of T_nn (-1 when absent).
  [[nodiscard]] int degree() const;
  [[nodiscard]] int degreeCross1() const;
  [[nodiscard]] int degreeCross2() const;
};

/// The polynomial written in its effective degree: trailing degrees whose highest forward difference vanishes (to
/// kIdentityRelTol of the coefficient scale) are removed by exact degree reduction. A target that is a degree-3
/// curve stored as degree 4 (after degree elevation) then leaves room for connecting functions of higher degree.
BernsteinPoly reducedToEffectiveDegree(const BernsteinPoly& p);

/// Target data from a fixed patch's edge frame (edge V0, u along) and the affine map u_T = c0 + c1 (u - range.lo),
/// c1 > 0, from the moving patch's edge parameter on `range` to the target frame's along parameter.
SeamTarget targetFromFrame(const BSplineSurface& targetFrame, Interval range, double c0, double c1, int order);

/// The target re-expressed in the parameter u' = a + b u (b != 0; b < 0 reverses the order of the pieces).
SeamTarget mappedTarget(const SeamTarget& t, double a, double b);

/// The middle of two sides for `average` joins. `own` is the moving patch's own data written as a target (its edge and
/// its cross derivative INTO itself), `other` the other patch's, both over the same range of the same parameter. The
/// result has point (own + other) / 2 and cross derivative -X with X = (own_n - lambda0 other_n) / 2, i.e. it is a
/// target lying on the other patch's side; negate cross1 for the other patch's view. Rational when either side is.
SeamTarget averagedTarget(const SeamTarget& own, const SeamTarget& other, double lambda0);

/// One constrained edge of the moving patch.
struct EdgeConstraint {
  Edge edge = Edge::V0;
  SeamTarget target;
  /// Force kappa = 0 at the seam's ends (keeps seam lines straight through vertices where several joins meet).
  bool kappaZeroAtStart = false, kappaZeroAtEnd = false;
};

struct LsJoinOptions {
  GeometricClass continuity = GeometricClass::kG1;
  double scale = 1.0;                  ///< model size: weights changes cost like displacements of this length
  /// Edges whose rows 0..lockedRows-1 must not move (joined before and not part of this join).
  std::vector<Edge> lockedEdges;
  int lockedRows = 2;
  /// Raise the patch's degree by this much in both directions first (exact): more freedom for the connecting
  /// functions (heal uses it when a patch closes a vertex where four patches meet and the first try is infeasible).
  int elevate = 0;
};

struct LsJoinOutcome {
  BSplineSurface surface;            ///< the moved patch (refined / elevated where needed, rational if a side was)
  bool feasible = false;             ///< the constraints hold to kConstraintRelTol
  double residual = 0.0;             ///< largest normalised constraint residual
  std::vector<double> insertedKnotsU, insertedKnotsV;
  int elevatedU = 0, elevatedV = 0;  ///< degree raised by
  std::vector<std::string> notes;
  std::vector<BernsteinPoly> lambda, kappa;  ///< per constraint (global over the seam range)
  /// Certified lower bound of lambda over all seams (certifiedMinimum, tight to ~1e-9 relative); +inf for G0.
  double lambdaMin = 0.0;
  /// Per constraint: the geometric ratio lambda0 (see kLambdaFloorRel) and whether lambda had to be fixed to it
  /// because the free solve's lambda was not certified above kLambdaFloorRel x lambda0.
  std::vector<double> lambda0;
  std::vector<char> lambdaFixed;
  /// Rational: the solve kept the moved rows' weights (Cartesian unknowns); false when that had no solution and the
  /// weights were solved for too (or for polynomial patches).
  bool weightsFixed = false;
  /// The constraints could not be met without a fold (lambda fixed and still infeasible): `surface` is the input
  /// surface unchanged (no knots inserted, no elevation) and `feasible` is false.
  bool unchanged = false;
};

/// Moves rows of `s` so that each constrained edge meets its target with the requested continuity. G1/G2: lambda > 0
/// is a constraint, not an afterthought. The free solve (lambda, kappa, nu unknown) is kept when its lambda is
/// certified above kLambdaFloorRel x lambda0 on the whole seam; otherwise that seam's lambda is fixed to the constant
/// lambda0 (the system stays linear, kappa and nu stay free) and the rows are solved again from the input. When the
/// fixed-lambda system is infeasible too, the outcome is `unchanged` (the input surface, with a note). Errors:
/// kUnsupported (G2 for rational patches, an unclamped edge), kInvalidInput (empty target).
Result<LsJoinOutcome> leastSquaresJoin(const BSplineSurface& s, const std::vector<EdgeConstraint>& constraints,
                                       const LsJoinOptions& options);

/// The parts of two edges that a join pairs. analyzeSeam finds the overlap by projecting end points, so an edge
/// whose corner was moved along its partner (a gap with a tangential component, as in any perturbed model) can come
/// out as a T-junction that covers only part of the partner edge, and a join along it would leave the rest of the
/// partner open. Here an end of the overlap is moved to the corners of both edges whenever those two corners (paired
/// by the seam's orientation) are at most `maxGap` apart: corners that close belong together.
struct JoinOverlap {
  Interval s, t;  ///< in each patch's own edge parameter
};
JoinOverlap cornerSnappedOverlap(const BSplineSurface& s, Edge es, const BSplineSurface& t, Edge et, Interval overlapS,
                                 Interval overlapT, bool reversed, double maxGap);

/// The original surface expressed in the knots and degrees of `like` (degree elevation + exact knot insertion), for
/// displacement measures. Requires like's knots to contain s's (after elevation).
BSplineSurface expressedLike(const BSplineSurface& s, const BSplineSurface& like);

/// The patch with a new surface, name kept; its kind becomes B-spline unless degrees and knots are unchanged.
Patch replacedSurface(const Patch& p, BSplineSurface s);

}  // namespace seam::detail
