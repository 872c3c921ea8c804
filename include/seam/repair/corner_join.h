#pragma once
// Lai-Lian-Cassidy §4.1: three and four C1 bicubic B-spline surfaces around a corner, joined G1 by successive joins,
// with the knot proportionality conditions checked and reported (docs/algorithms/lai-lian-cassidy.md §5 derives
// every condition and the corrections of the extracted text).
//
// Three surfaces (the paper's Fig. 1): S and S~ share an edge (S moves onto S~, Theorem 1 or Algorithm 3.3); S^ lies
// along the far side of both, its edge split at the corner into the part that meets S~ and the part that meets S.
// The corner is a T-junction of S^'s edge (an interior breakpoint of it), so G1 is possible there (contrast §4.2).
// Second join: S^ moves onto the union S* u S~ (Theorem 1 on the compound surface when the conditions hold, the
// general least-squares join onto both neighbours at once otherwise).
//
// Four surfaces around a 4-valent vertex: S1..S4 in cyclic order; S2 joins S1 and S4 joins S3 (Theorem 1 when the
// pairs are proportional), then the compound S3 u S4 joins the compound S1 u S2 (Theorem 1 when the compounds are
// proportional, otherwise the least-squares joins of healModel).
#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "seam/continuity/seam.h"
#include "seam/core/result.h"
#include "seam/core/tolerances.h"
#include "seam/model/model.h"
#include "seam/repair/gap_removal.h"
#include "seam/repair/join.h"

namespace seam {

/// The conditions of §4.1 (docs/algorithms/lai-lian-cassidy.md §5). Knot indices are those of edge frames that start
/// at the corner: S's u runs along the S/S~ seam from the corner, its v along the S/S^ seam from the corner; S^'s
/// breakpoints b^_0 < ... < b^_q run along its edge from S~'s side to S's side and the corner is at b^_K.
enum class CornerCondition {
  // Three surfaces.
  kUProportional,     ///< (a) Def. 3.1: alpha_i = alpha~_i, i = 1..m^-1. Residual max |alpha_i - alpha~_i|.
  kUEqualSpans,       ///< (c) u_{2i+2} - u_{2i} = u~_{2i+2} - u~_{2i}, i = 1..m^. Residual max relative difference.
  kBreakpointsMatch,  ///< (4.1), (4.2): b^_{K-j} on S~'s breakpoint j, b^_{K+j} on S's. Residual: largest distance.
  kHatTildeJunctions, ///< (b) eta^_{K-i} = xi~_i, i = 1..n^1-1. Residual max |difference|.
  kHatSJunctions,     ///< (b) xi^_{K+i} = xi_i, i = 1..n^2-1. Residual max |difference|.
  kRatioChain,        ///< (c) every S^ span over its partner's span is the same ratio (corner junction included).
                      ///< Residual (max - min) / max over the ratios.
  // Four surfaces.
  kPair12Proportional,  ///< Def. 3.1 between S1 and S2 along their shared edge
  kPair12EqualSpans,    ///< S1 and S2 have equal spans along it (S1 u S2 is one C1 bicubic B-spline)
  kPair34Proportional,  ///< the same for S3 and S4
  kPair34EqualSpans,
  kCompoundChain,       ///< the compound edges of S3 u S4 and S1 u S2 are proportional: every span of S4 (S3) along
                        ///< S1 (S2) over the partner span is the same ratio. Residual (max - min) / max.
};
std::string_view toString(CornerCondition c);

/// One checked condition.
struct ConditionCheck {
  CornerCondition condition = CornerCondition::kUProportional;
  std::string statement;   ///< the condition as a formula (seam's corrected indexing)
  double residual = 0.0;   ///< measured, as defined on CornerCondition
  double tolerance = 0.0;  ///< holds when residual <= tolerance
  bool holds = false;
  std::string detail;      ///< the worst index and the two values compared (empty when there is nothing to compare)
};

/// Fig. 1 of §4.1: which patches and which edges. S's edges sToTilde and sToHat (and S~'s two edges) must pass through
/// one corner of the patch, the common corner of S, S~ and S^.
struct ThreePatchCorner {
  std::string s, sTilde, sHat;
  Edge sToTilde = Edge::V0;    ///< S's edge against S~ (the paper's v = v_2)
  Edge tildeToS = Edge::V0;    ///< S~'s edge against S (v~ = v~_2)
  Edge sToHat = Edge::U0;      ///< S's edge along S^ (u = u_2)
  Edge tildeToHat = Edge::U0;  ///< S~'s edge along S^ (u~ = u~_2)
  Edge hatEdge = Edge::U1;     ///< S^'s edge that meets both (u^ = u^_2)
};

/// The proportionality report of the three-surface corner.
struct ThreePatchProportionality {
  std::vector<ConditionCheck> checks;  ///< kUProportional .. kRatioChain, in this order
  bool allHold = false;
  int m = 0, mTilde = 0;      ///< spans of S and S~ along their shared edge
  int n = 0, nTilde = 0;      ///< spans of S and S~ along S^
  int q = 0;                  ///< spans of S^'s edge
  int cornerIndex = 0;        ///< K (the paper's J - 1: the corner is v^_{2J} = b^_{J-1})
  int nHat1 = 0, nHat2 = 0;   ///< spans of S^ paired with S~ and with S
  /// S^ span / partner span, from S~'s far end to the corner (n^1 values) then from the corner to S's far end (n^2).
  std::vector<double> chainRatios;
  /// Theorem 1 can join S^ to the compound: every condition holds and S^'s edge ends where S~'s (or S's) edge ends, so
  /// that span i pairs with span i from a common corner.
  bool theorem1ForHat = false;
  std::vector<std::string> notes;
  [[nodiscard]] const ConditionCheck* find(CornerCondition c) const;
};

/// Four patches around a 4-valent vertex, in cyclic order S1, S2, S3, S4 (S_k shares an edge with S_{k+1 mod 4}).
struct FourPatchCorner {
  std::array<std::string, 4> patches;
  std::array<Edge, 4> toNext{};  ///< S_k's edge against S_{k+1}
  std::array<Edge, 4> toPrev{};  ///< S_k's edge against S_{k-1}
};

struct FourPatchProportionality {
  std::vector<ConditionCheck> checks;  ///< kPair12Proportional .. kCompoundChain, in this order
  bool allHold = false;
  /// Span of S4 (S3) along the compound seam over the paired span of S1 (S2): S1/S4 side from the corner, then S2/S3.
  std::vector<double> chainRatios;
  [[nodiscard]] const ConditionCheck* find(CornerCondition c) const;
};

/// How the corner is joined.
struct CornerJoinOptions {
  /// kAuto: Theorem 1 for each join whose conditions hold, the fallback otherwise. kBSpline: Theorem 1 for every join
  /// or an error (kUnsupported for patches that are not C1 bicubic, kNoSolution when a condition fails).
  JoinMethod method = JoinMethod::kAuto;
  /// The first join(s) when Theorem 1 does not apply: kBezierStrip (the paper's Algorithm 3.3, used when both
  /// patches are C1 bicubic and their spans correspond, else least squares) or kLeastSquares.
  JoinMethod fallback = JoinMethod::kBezierStrip;
  /// Refuse to join edges farther apart (default kDefaultMaxGapRel x the model's bounding-box diagonal). Also the
  /// tolerance of kBreakpointsMatch and of the corner check.
  std::optional<double> maxGap;
  double proportionalTol = kProportionalKnotTol;  ///< tolerance of every knot condition
  std::optional<Tolerances> tolerances;           ///< classification (default Tolerances::forModelSize(diagonal))
  SeamOptions seam;                               ///< analysis settings (its `tol` is replaced by the above)
};

/// One successive join.
struct CornerJoinStep {
  std::vector<std::string> moved;  ///< the patch(es) that moved
  std::vector<std::string> onto;   ///< the fixed neighbours
  JoinMethod method = JoinMethod::kLeastSquares;
  std::string reason;              ///< why this method
  double maxDisplacement = 0.0;    ///< largest control-point displacement of this step
  int movedPoints = 0;
  std::vector<std::string> notes;
};

/// A seam at the corner, before and after all joins.
struct CornerSeam {
  std::string a, b;
  Edge aEdge = Edge::U0, bEdge = Edge::U0;
  /// The same pair of edges in the INPUT model (analyzeSeam; empty only when that analysis failed, with a note in
  /// CornerJoinReport::notes: the seam then cannot be compared).
  std::optional<SeamReport> before;
  /// After all joins (span by span where a pair was joined by the Bezier strip). When the corner was reverted
  /// (CornerJoinReport::reverted) this is `before`: the model is the input (a seam without `before` then keeps the
  /// analysis of the undone result, with achieved = false).
  SeamReport after;
  bool achieved = false;  ///< after.geometric is G1 or better
  /// The joins made this seam worse than in the input (certified values: the gap bound grew by more than
  /// tol.distance, the angle bound by more than tol.angleDeg, the class dropped, a fold appeared, or a certified seam
  /// lost its certificate). Any worse seam reverts the whole corner; `worseWhy` says what got worse, in plain words,
  /// with the values the joins would have left.
  bool worse = false;
  std::string worseWhy;
};

struct CornerJoinReport {
  std::vector<CornerJoinStep> steps;  ///< the joins run (also when they were undone, see `reverted`)
  std::vector<CornerSeam> seams;
  /// Every seam is G1 or better (false whenever the joins were reverted).
  bool achieved = false;
  /// A corner join never makes a seam worse: when any seam got worse, every join is undone, the model returned is
  /// the input (bit-identical), each seam's after is its before, and the displacements are 0.
  bool reverted = false;
  int seamsWorse = 0;            ///< seams the joins made worse (the reason for the revert)
  double maxDisplacement = 0.0;  ///< largest control-point displacement over all patches, against the input
  /// Largest displacement of the SURFACE against the input over the changed patches (same parameters before and
  /// after): a certified bound (surfaceDisplacement in repair/join.h; for polynomial patches the largest control-
  /// point displacement against the input expressed in the output's knots and degrees), the largest value found on
  /// a 33 x 33 grid of each changed patch's domain, and the bound over the moved patch's size (the diagonal of its
  /// input control points' bounding box; the largest ratio over the changed patches).
  double maxSurfaceDisplacement = 0.0;
  double maxSurfaceDisplacementSampled = 0.0;
  double maxSurfaceDisplacementRel = 0.0;
  double worstG0 = 0.0, worstG1Deg = 0.0;  ///< over the seams' `after`
  std::vector<std::string> notes;
};

struct ThreePatchJoinResult {
  Model model;  ///< the input with S and S^ replaced (S~ and every other patch bit-identical)
  /// Empty when a patch is not C1 bicubic (then the conditions are not defined; the joins are least squares).
  std::optional<ThreePatchProportionality> proportionality;
  CornerJoinReport report;
};

struct FourPatchJoinResult {
  Model model;
  std::optional<FourPatchProportionality> proportionality;
  CornerJoinReport report;
};

/// Checks the §4.1 conditions for the three-surface corner. Errors: kNotFound (a patch name), kInvalidInput (the same
/// patch twice, edges that do not pass through one corner, corners of S and S~ farther apart than maxGap, S^'s edge
/// not passing the corner in its interior), kUnsupported (a patch that is not C1 bicubic).
Result<ThreePatchProportionality> checkThreePatchCorner(const Model& model, const ThreePatchCorner& corner,
                                                        const CornerJoinOptions& options = {});

/// The successive joins of §4.1 for three surfaces: S onto S~, then S^ onto S* u S~. Errors: those of
/// checkThreePatchCorner (kUnsupported only with method kBSpline), kNoSolution (kBSpline and a condition fails), and
/// those of the joins. A join that misses G1 is not an error: see CornerJoinReport::achieved.
///
/// Never worse: each of the three seams is analysed in the input and after the joins (certified); when any seam got
/// worse (see CornerSeam::worse) the input model is returned unchanged with report.reverted and achieved = false.
Result<ThreePatchJoinResult> joinThreePatchCorner(const Model& model, const ThreePatchCorner& corner,
                                                  const CornerJoinOptions& options = {});

/// The conditions for the four-surface strategy (pairs S1/S2 and S3/S4 by Theorem 1, then the compounds). Errors as
/// checkThreePatchCorner.
Result<FourPatchProportionality> checkFourPatchCorner(const Model& model, const FourPatchCorner& corner,
                                                      const CornerJoinOptions& options = {});

/// The successive joins for four surfaces: S2 onto S1, S4 onto S3, then S3 u S4 onto S1 u S2. With every condition
/// this is Theorem 1 throughout (the compound join is done as S3 onto S2 and S4 onto S1, which the conditions make
/// the same as Theorem 1 on the compounds); otherwise the pairs by the fallback and the compounds by healModel.
/// Never worse, as joinThreePatchCorner: the four seams before and after, the input returned when one got worse.
Result<FourPatchJoinResult> joinFourPatchCorner(const Model& model, const FourPatchCorner& corner,
                                                const CornerJoinOptions& options = {});

}  // namespace seam
