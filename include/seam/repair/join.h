#pragma once
// `seam join`: make two patches meet G0, G1 (or G2) along a seam by moving the fewest rows of control points of one
// of them (or of both with `average`), keeping B-spline form, and report the continuity actually achieved with the
// certified seam analysis (continuity/seam.h). Methods (docs/algorithms/lai-lian-cassidy.md):
//  * bspline        Lai-Lian-Cassidy Theorem 1: C1 bicubic patches with proportional knots; rows d_{i,0}, d_{i,1} of
//                   the moved patch are replaced, its knots are kept; the join is C1 after the reflection of v.
//  * bezier-strip   Algorithm 3.3: C1 bicubic patches with arbitrary knots; the wrinkled knots of the moved patch are
//                   raised to multiplicity 3 (exact), the strip is G1 inside, the rest stays C1.
//  * least-squares  any degree, multiplicity, polynomial or rational: minimal displacement of rows 0..K (K = 0, 1, 2
//                   for G0, G1, G2) subject to the linear seam equations with polynomial connecting functions;
//                   knots are inserted (and degrees raised) only where the neighbour's edge does not fit otherwise.
//  * auto           bspline when it applies (C1 bicubic, corresponding and proportional knots, G1), else
//                   least-squares.
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "seam/continuity/seam.h"
#include "seam/continuity/verdict.h"
#include "seam/core/result.h"
#include "seam/core/tolerances.h"
#include "seam/model/model.h"
#include "seam/regularity/defect_search.h"
#include "seam/repair/gap_removal.h"

namespace seam {

enum class JoinMethod { kAuto, kBSpline, kBezierStrip, kLeastSquares };
/// "auto", "bspline", "bezier-strip", "least-squares".
std::string_view toString(JoinMethod m);
Result<JoinMethod> parseJoinMethod(std::string_view name);
/// "G0"/"G1"/"G2" (case-insensitive) for the requested continuity.
Result<GeometricClass> parseContinuity(std::string_view name);

/// Default largest gap that `join` and `heal` close: this fraction of the model's bounding-box diagonal (the same 1 %
/// as the pairing tolerance of `seam check`, docs/tolerances.md).
inline constexpr double kDefaultMaxGapRel = 0.01;

/// Default largest surface displacement of a join, relative to the moved patch's size (the bounding-box diagonal of
/// its control points): a join may not move a patch by more than its own size (docs/algorithms/lai-lian-cassidy.md,
/// "Joins never fold").
inline constexpr double kMaxJoinDisplacementRel = 1.0;
/// A rational G1 join that has no solution with the patch's own degree is retried with the degree raised by up to
/// this much (exact elevation: more degree for the connecting functions of the homogeneous equations).
inline constexpr int kRationalJoinMaxElevation = 3;

struct JoinOptions {
  JoinMethod method = JoinMethod::kAuto;
  GeometricClass continuity = GeometricClass::kG1;  ///< G0, G1 or G2 (G2: least squares; rational too)
  /// Algorithm 3.3's l = xi_2 / xi_0 (bezier-strip only). Default: per junction, the l minimising the displacement.
  std::optional<double> ell;
  /// Move both patches onto a common middle edge and tangent plane (least squares only), like Rhino's MatchSrf
  /// "average"; the default moves only the --move patch.
  bool average = false;
  /// Refuse to join edges farther apart than this (default kDefaultMaxGapRel x the model's bounding-box diagonal).
  std::optional<double> maxGap;
  /// Revert a join whose certified surface displacement (JoinReport::maxSurfaceDisplacementRel) exceeds this
  /// multiple of the moved patch's size. Must be >= 0.
  double maxDisplacementRel = kMaxJoinDisplacementRel;
  /// A G1/G2 request on a seam whose angle before (SeamReport::g1MaxDeg) is at or above this (degrees, in (0, 180])
  /// leaves the seam as it is, a design crease (JoinReport::creaseKept). Empty: any angle is joined (the library
  /// call names one seam); `seam join` passes kDefaultCreaseAngleDeg unless --crease-angle is given. G0 requests
  /// close the gap of a crease without touching its angle and are not affected.
  std::optional<double> creaseAngleDeg;
  /// Classification tolerances for the before/after analysis (default Tolerances::forModelSize(diagonal)).
  std::optional<Tolerances> tolerances;
  /// Settings of the before/after seam analysis (its `tol` is replaced by the tolerances above).
  SeamOptions seam;
  /// Revert a join that folds a moved patch (foldOf: a new point where S_u x S_v vanishes, or a normal turned
  /// against the input's by more than 90 degrees plus the seam's angle before). Off only to inspect what a refused
  /// join would have made (the tests do, to check each refusal independently).
  bool refuseFolds = true;
};

/// What a join did and what it achieved.
struct JoinReport {
  JoinMethod method = JoinMethod::kLeastSquares;  ///< the method used (never kAuto)
  std::string reason;                             ///< why this method (and what made auto choose it)
  /// Def. 3.1 for the two edges when both patches are C1 bicubic in the paper's sense; empty otherwise.
  std::optional<bool> proportionalKnots;
  SeamReport before, after;
  GeometricClass requested = GeometricClass::kG1;
  bool achieved = false;          ///< after.geometric meets the requested continuity
  /// The join was undone because it would have made the seam worse or folded the patch (see joinSeam): the model is
  /// the input, after == before, nothing moved, and `notes` say why.
  bool reverted = false;
  /// The seam is a design crease (angle at or above JoinOptions::creaseAngleDeg) and a G1/G2 join was requested: it
  /// is left as designed, the model is the input, after == before, and a note says so.
  bool creaseKept = false;
  double maxDisplacement = 0.0;   ///< largest control-point displacement (against the input expressed in the new knots)
  /// Largest displacement of the SURFACE (same parameters before and after), over the changed patches: a certified
  /// upper bound (surfaceDisplacement: for polynomial patches the largest control-point displacement, by the
  /// partition of unity), and the largest value found on a 33 x 33 grid of each changed patch's domain.
  double maxSurfaceDisplacement = 0.0;
  double maxSurfaceDisplacementSampled = 0.0;
  /// maxSurfaceDisplacement divided by the bounding-box diagonal of the moved patch's control points (the largest
  /// ratio over the changed patches).
  double maxSurfaceDisplacementRel = 0.0;
  int movedPoints = 0;            ///< control points displaced by more than kRoundoff x the model size
  std::vector<std::string> patchesChanged;
  std::vector<double> insertedKnotsU, insertedKnotsV;  ///< knots inserted into the moved patch (its own parameters)
  int elevatedU = 0, elevatedV = 0;                    ///< degree raised by
  std::vector<StripJunction> junctions;                ///< bezier-strip: the junctions and their l
  /// bezier-strip: the worst tangent-plane angle inside the strip across the wrinkled junctions (certified, degrees).
  std::optional<double> stripInternalG1MaxDeg;
  /// Least squares, G1/G2: certified lower bound of the connecting function lambda of the kept join (> 0: joins never
  /// fold); empty when the join was reverted or left the patch unchanged.
  std::optional<double> lambdaMin;
  /// Least squares, G1: lambda had to be fixed to the geometric ratio lambda0 (the free solve would have folded or
  /// squeezed the rows), and that lambda0 (the smallest over the moved patches). Empty / false when not fixed.
  bool lambdaFixed = false;
  std::optional<double> lambda0;
  /// Least squares, rational: the kept solution left the moved rows' weights as they were (Cartesian solve).
  bool weightsFixed = false;
  std::vector<std::string> notes;
};

struct JoinResult {
  Model model;  ///< the input with the moved patch(es) replaced; every other patch bit-identical
  JoinReport report;
};

/// Joins edge `moveEdge` of patch `moveName` to edge `toEdge` of patch `toName`.
///
/// A join never makes the seam worse (docs/algorithms/lai-lian-cassidy.md, "Joins never fold"): the input model is
/// returned unchanged (bit-identical, report.reverted, achieved = false unless the input already met the request)
/// when, by the certified before/after analysis, the after G1 angle bound exceeds the worst angle found before by
/// more than tol.angleDeg, the after gap bound exceeds the worst gap found before by more than tol.distance, the
/// geometric class drops, (G1/G2 requests) lambda is not positive, or the certified surface displacement
/// exceeds options.maxDisplacementRel x the moved patch's size (JoinReport::maxSurfaceDisplacementRel). The least-squares join keeps lambda > 0 as a
/// constraint (leastSquaresJoin), so a kept G1 join has a certified lambdaMin > 0.
///
/// Errors: kNotFound (no such patch,
/// or the edges do not overlap), kInvalidInput (the same edge twice, non-3-D patches, a gap above maxGap, options that
/// the method does not take), kUnsupported (a method that does not apply to these patches, with the reason),
/// kDegenerate (a collapsed edge). A join that runs but misses the requested continuity is not an error: see
/// JoinReport::achieved.
Result<JoinResult> joinSeam(const Model& model, const std::string& moveName, Edge moveEdge, const std::string& toName,
                            Edge toEdge, const JoinOptions& options = {});

/// Control-point displacement of `after` against `before` expressed in after's knots and degrees (exact refinement).
struct Displacement {
  double max = 0.0;
  int moved = 0;
};
Displacement controlPointDisplacement(const BSplineSurface& before, const BSplineSurface& after, double threshold);

/// Displacement of the surface itself, max over (u, v) of |after(u, v) - before(u, v)|, for `after` a refinement /
/// elevation of `before` with moved control points (same domain and parametrisation). `bound` is certified: per knot
/// cell, with before expressed in after's knots and r_i = w_after,i / w_before,i over the cell's active points,
/// max_i |P_after,i - P_before,i| + (max r / min r - 1) x (half the diagonal of the before points' box), which for
/// polynomial patches is the largest control-point displacement (partition of unity). `sampled` is the largest value
/// on a `grid` x `grid` lattice of the domain (<= the true maximum <= bound). +inf when the nets do not correspond.
struct SurfaceDisplacement {
  double bound = 0.0, sampled = 0.0;
};
SurfaceDisplacement surfaceDisplacement(const BSplineSurface& before, const BSplineSurface& after, int grid = 33);
/// The same, with the bound sharpened until it is within `ratio` of the largest displacement found (the grid's and
/// the exact values at the corners and centres of the regions split): per knot cell the difference is written in
/// Bernstein form, E = P_after - P_before (polynomial) or E / Q = (N_after W_before - N_before W_after) /
/// (W_after W_before) (rational, homogeneous N = w P), bounded by max |E_k| / min Q_k (convex hull), and the region
/// with the largest bound is split in four until that bound is within `ratio` of the largest value found or
/// `maxSplits` splits were made. Never above surfaceDisplacement's bound. Used before a refusal rests on the bound.
SurfaceDisplacement surfaceDisplacementSharp(const BSplineSurface& before, const BSplineSurface& after,
                                             double ratio = 1.5, int maxSplits = 4096);
/// Round-off margin of the turnover test's cosine comparison.
inline constexpr double kTurnoverCosineSlack = 1e-9;
/// Where |S_u x S_v| is below this fraction of its largest Bernstein coefficient on the piece (a pole, a collapsed
/// edge), the normal has no direction: no turnover is reported there.
inline constexpr double kTurnoverPoleRel = 1e-9;

/// Whether the normal of `after` turns by more than `minAngleDeg` (default 90: it points against the input's)
/// against that of `before` anywhere, the two at equal parameters (a repair moves control points, not parameters).
/// Per knot cell of the common refinement of both, D = N_after . N_before in Bernstein form, N the normal numerator
/// (cross product of partialNumerators: S_u x S_v, or w^4 S_u x S_v for rational patches). A region whose
/// coefficients of D are all >= -kIdentityRelTol x its scale has no normal turned by 90 degrees or more; the others
/// are split in four (most negative first) and their corners and centres evaluated, up to `maxSplits` splits.
/// `found` rests on an evaluated point, never on a bound; `certified` says that every region was settled. Domains
/// that differ: a 41 x 41 lattice of the normalised domain, never certified. minAngleDeg is clamped to [90, 180].
struct NormalTurnover {
  bool found = false;       ///< a point where the normals are more than minAngleDeg apart
  double u = 0.0, v = 0.0;  ///< where (parameters of `after`)
  double angleDeg = 0.0;    ///< the angle between the normals there
  bool certified = false;   ///< no normal turns by 90 degrees or more (every region settled by its coefficients)
  int splits = 0;
};
NormalTurnover normalTurnover(const BSplineSurface& before, const BSplineSurface& after, double minAngleDeg = 90.0,
                              int maxSplits = 2048);

/// Budget (region visits) of the critical-point search on a moved patch (newFoldPoint): a regular patch settles in a
/// few hundred; what an unfinished search did not find is not a fold.
inline constexpr long kFoldSearchWork = 20'000;
/// A point where sin(angle between S_u and S_v) of the input patch is above this is regular: a critical point of the
/// moved patch there is new (a fold line or cusp the repair made), not the input's pole or cusp.
inline constexpr double kFoldRegularSine = 1e-6;

struct FoldPoint {
  double u = 0.0, v = 0.0;
};
/// A point where S_u x S_v of `after` vanishes (regularity::searchSurfaceDefects, budget kFoldSearchWork) while
/// `before` is regular there (kFoldRegularSine): the moved patch folds (its orientation reverses across a curve
/// through it) or got a new cusp. Parameters of `after`, equal to `before`'s (a repair moves points, not parameters).
/// `searched`: searchMovedPatch(after) when already run (its critical points are used instead of a new search).
std::optional<FoldPoint> newFoldPoint(const BSplineSurface& before, const BSplineSurface& after,
                                      const regularity::SurfaceSearchResult* searched = nullptr);
/// The defect search of a moved patch: regularity::searchSurfaceDefects with the budget kFoldSearchWork.
Result<regularity::SurfaceSearchResult> searchMovedPatch(const BSplineSurface& s);
/// Why moving a patch from `before` to `after` folds it ("" when it does not): a normal turned by more than
/// `maxTurnDeg` (normalTurnover), or a new critical point (newFoldPoint; `searched` as there). The text continues
/// "patch P ...".
std::string foldOf(const BSplineSurface& before, const BSplineSurface& after, double maxTurnDeg = 90.0,
                   const regularity::SurfaceSearchResult* searched = nullptr);

/// Largest distance between two surfaces at equal normalised parameters on a grid x grid lattice of each one's domain
/// (batch evaluation, GridEvaluator).
double sampledSurfaceDistance(const BSplineSurface& a, const BSplineSurface& b, int grid);

/// Seam analysis over consecutive sub-ranges of A's edge (A's own parameter), merged into one report: for a
/// correspondence that is affine on each sub-range but not globally (the Bezier strip matches span i to span i).
Result<SeamReport> analyzeSeamPiecewise(const Patch& a, Edge ea, const Patch& b, Edge eb, const SeamOptions& options,
                                        const std::vector<double>& breaks);

}  // namespace seam
