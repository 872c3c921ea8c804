#pragma once
// `seam heal`: the whole-model version of `seam join`, like CATIA Healing but with a certified verdict, and a
// promise: healing never makes a seam worse than it was in the input.
//
// Regions are the connected components of the seam graph (the model check's pairing, seams within maxGap that are not
// design creases). Design creases are left alone: a seam whose certified kink angle (before.g1MaxDeg) is above
// HealOptions::maxAngleDeg (default kDefaultMaxHealAngleDeg = 20 degrees) is a designed crease, not a defect (the
// Newell teacup's wall meets its saucer at 122 degrees): like a seam above maxGap it is skipped (action "crease
// kept"), does not join regions, and neither of its sides moves: the successive joins lock both its rows and reject
// any step that would change its boundary curve or the cross-boundary derivative along it, the local scheme keeps it
// as a free edge (LocalSchemeOptions::keepEdges, as for seams above maxGap). Every other seam whose continuity is
// below the requested one is to be joined, by one of two methods (HealOptions::method):
//  * successive: the successive least-squares joins of Lai-Lian-Cassidy §4.1 in breadth-first order from the first
//    patch of each group (each patch moves once, onto all of its already settled neighbours at the same time,
//    corners included). A patch's edge that is already joined to a neighbour that has not moved yet is locked; one
//    whose neighbour has settled stays a constraint of the solve, so it remains joined. Every step (one patch move)
//    passes an acceptance test: every seam touching the moved patch is analysed (certified analyzeSeam) and compared
//    with its state before the step and with the input; if any got worse (gap larger by more than tol.distance,
//    angle larger by more than tol.angleDeg, a lower class, a fold, lost certification) the step is reverted (the
//    patch stays as it was) and the reason recorded (HealStep). A first run defers the verdict on a seam whose other
//    patch moves later to that patch's step (which must leave it no worse than in the input); a region where that run
//    leaves any seam worse than in the input, or falls short, is also run strictly (every seam judged at every step)
//    and the better of the two that makes nothing worse is kept.
//  * local: the local G1 scheme (repair/local_scheme.h) on the region's patches, G1 requests only. Its result is
//    accepted only when every seam of the region is certified, meets G1 and is nowhere worse than in the input, and
//    the region's free edges stay where they were; otherwise the region is left as it was. Where the local scheme
//    does not apply or has no solution (a straight boundary vertex with unequal tangent lengths, knots off the
//    middle, ...), the network solve with the G1 identities only (g2_network.h, continuity kG1) takes the region on
//    the same terms (the region's method stays "local"; its note says which solve ran).
//  * auto (default): successive, and for G1 requests also the local scheme on the input (on every region the
//    successive joins did not leave as it was); whichever is kept has, in order: no seam worse, more seams achieved,
//    then the smaller largest surface displacement relative to the patch's size (HealPatch::maxSurfaceDisplacementRel;
//    then fewer moved points). The region's note gives both candidates' displacements ("successive moved 34 % of a
//    patch, local 6.9 %: local kept").
//  * G2 requests (auto or local; successive is refused): the G2 network solve (repair/g2_network.h) on the region's
//    patches, accepted when every seam is certified and none is worse than in the input and the free edges stay;
//    a partial result is kept on those terms (seams ending where a straight free boundary has a curvature jump
//    cannot be G2 with the free edges kept: the region's notes name each such vertex).
// A region that is not fully achieved keeps its partial improvements only when no seam in it is worse than in the
// input; otherwise it is reset to the input. Patches that need not move are bit-identical in the output. Every seam
// is reported before and after, every region with its method and verdict, every patch with its displacement.
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "seam/continuity/seam.h"
#include "seam/continuity/verdict.h"
#include "seam/core/result.h"
#include "seam/core/tolerances.h"
#include "seam/model/model.h"
#include "seam/repair/g2_network.h"

namespace seam {

enum class HealMethod { kAuto, kSuccessive, kLocal };
std::string_view toString(HealMethod m);  ///< "auto", "successive", "local"
/// Parses "auto", "successive" or "local" (exact, lower case). Errors: kInvalidInput naming the accepted values.
Result<HealMethod> parseHealMethod(std::string_view text);

/// A seam whose tangent planes meet at this angle or more (degrees), or whose connecting function lambda is <= 0
/// somewhere, is a fold: one patch turns back over the other.
inline constexpr double kFoldAngleDeg = 90.0;

/// Default HealOptions::maxAngleDeg: a seam whose certified kink angle is above the crease angle (20 degrees,
/// kDefaultCreaseAngleDeg, the same as `seam check`'s) is a design crease, left alone by heal. Kinks from tolerance
/// problems (translation losses, perturbed control points) are a few degrees.
inline constexpr double kDefaultMaxHealAngleDeg = kDefaultCreaseAngleDeg;

/// Largest region (in patches) that heal G1 gives to the G1 network solve where the local scheme does not apply. The
/// solve is global per region and its sparse factorisation grows faster than the region (measured 2026-11-30, open
/// grids, whole CLI: 144 patches 8.3 s, 324 patches 50 s and 611 MB); above this a region keeps the successive joins'
/// result and its note says why, so that a large model is not held up for minutes.
inline constexpr int kMaxG1NetworkPatches = 200;

struct HealOptions {
  GeometricClass continuity = GeometricClass::kG1;  ///< G0, G1 or G2 (G2: the network solve, method auto or local)
  HealMethod method = HealMethod::kAuto;            ///< local needs a G1 request
  /// Seams with a larger gap are left alone (default kDefaultMaxGapRel x the model's bounding-box diagonal).
  std::optional<double> maxGap;
  /// Seams whose certified kink angle (before.g1MaxDeg, degrees) is above this are design creases and left alone
  /// (default kDefaultMaxHealAngleDeg; must be in (0, 180]; 180 heals every seam, folds included: a bound at 180 is
  /// not above it). `seam heal --crease-angle` (alias --max-angle).
  std::optional<double> maxAngleDeg;
  /// Classification tolerances (default Tolerances::forModelSize(diagonal)); also the acceptance margins.
  std::optional<Tolerances> tolerances;
  SeamOptions seam;  ///< analysis settings (its `tol` is replaced by the tolerances above)
  /// G2: G2NetworkOptions::fairness of the network solve (must be finite and >= 0).
  double g2Fairness = kDefaultG2Fairness;
};

struct HealSeam {
  std::string a, b;
  Edge aEdge = Edge::U0, bEdge = Edge::U0;
  int region = -1;                  ///< index into HealReport::regions
  SeamReport before;                ///< the input (before.certified: the values are certified bounds)
  std::optional<SeamReport> after;  ///< empty when the analysis failed after healing
  std::string moved;                ///< the patch that moved to meet this seam ("" if none did)
  /// How far the seam's two boundary curves moved against the input (the larger of the two; 33 samples at equal
  /// normalised edge parameters), in the model's length unit: 0 when neither side moved.
  double edgeMoved = 0.0;
  /// "kept" (already at the requested continuity), "joined" (reaches it now), "skipped" (gap above maxGap),
  /// "crease kept" (kink angle above maxAngleDeg: a design crease, left alone, no gap), "crease: gap closed" /
  /// "crease: gap narrowed" (a design crease whose gap was closed, its angle kept: one side's boundary row and the
  /// row next to it moved by the same amount), "crease: gap not closed" (the notes say why), "failed" (should have
  /// been joined and was not; left as good as it was, possibly improved).
  std::string action;
  bool achieved = false;            ///< after.geometric meets the requested continuity
  /// After is worse than before (larger gap or angle beyond the tolerances, lower class, a fold): never expected,
  /// the self-check of the promise above.
  bool worse = false;
  std::vector<std::string> notes;
};

/// One patch move of the successive joins.
struct HealStep {
  std::string patch;
  int region = -1;
  bool accepted = false;  ///< the move passed the acceptance test (and changed the patch)
  /// The move is in the output model: accepted, and the region's result is this run of successive joins. Steps of a
  /// run that was not kept (the region is "none" or "local") are reported with kept = false and the region's note.
  bool kept = false;
  std::string reason;  ///< why the step was reverted ("" when accepted)
  std::vector<std::string> notes;  ///< degree raised, edges unlocked, constraints not met exactly
};

/// A connected component of the seam graph.
struct HealRegion {
  std::vector<std::string> patches;
  int seams = 0, seamsAchieved = 0;
  std::string method = "none";  ///< what the output holds for the region: "successive", "local" or "none" (input)
  bool achieved = false;        ///< every seam of the region (within maxGap) meets the requested continuity
  std::string note;             ///< why a method was not used, why the region was not achieved, auto's comparison
  /// The candidates' largest surface displacement relative to the patch's size (negative: not computed).
  double successiveDisplacementRel = -1.0, localDisplacementRel = -1.0;
};

/// How far a patch's surface moved. For polynomial patches the largest control-point displacement against the input
/// expressed in the new knots and degrees bounds the surface's displacement at equal parameters (partition of unity).
struct HealPatch {
  std::string name;
  int region = -1;
  double size = 0.0;                     ///< bounding-box diagonal of the input patch's control net
  double maxDisplacement = 0.0;          ///< largest control-point displacement (see above)
  int movedPoints = 0;
  double maxSurfaceDisplacement = 0.0;   ///< the bound when certified, else the sampled value
  bool surfaceDisplacementCertified = false;
  double maxSurfaceDisplacementSampled = 0.0;  ///< the largest |S_new(u,v) - S_old(u,v)| over a 21 x 21 grid
  double maxSurfaceDisplacementRel = 0.0;      ///< maxSurfaceDisplacement / size
};

struct HealReport {
  GeometricClass requested = GeometricClass::kG1;
  HealMethod method = HealMethod::kAuto;  ///< as requested
  double maxGap = 0.0;
  double maxAngleDeg = kDefaultMaxHealAngleDeg;  ///< the crease angle used
  std::vector<HealSeam> seams;
  std::vector<HealRegion> regions;         ///< regions with at least one seam
  std::vector<HealStep> steps;             ///< the successive joins tried (every region, also those not kept)
  std::vector<std::string> order;          ///< the patches in the order they moved (accepted steps)
  std::vector<std::string> patchesChanged;
  std::vector<HealPatch> patches;          ///< the changed patches
  double maxDisplacement = 0.0;            ///< largest control-point displacement
  int movedPoints = 0;
  double maxSurfaceDisplacement = 0.0;     ///< largest over the changed patches
  double maxSurfaceDisplacementRel = 0.0;  ///< largest over the changed patches (each relative to its own size)
  bool surfaceDisplacementCertified = true;  ///< every changed patch's value is a certified bound
  int seamsAchieved = 0;                   ///< seams to reach that meet the requested continuity after
  int seamsToReach = 0;                    ///< seams within maxGap and not design creases
  int creasesKept = 0;                     ///< seams left alone as design creases (their angle kept)
  /// Design creases whose gap was closed or narrowed (their angle kept): "crease: gap closed" / "... narrowed".
  int creaseGapsClosed = 0;
  int seamsWorse = 0;                      ///< seams worse than in the input (0 by construction)
  int stepsReverted = 0;
  GeometricClass worst = GeometricClass::kG2;  ///< worst geometric class over the seams after healing
  double worstG0 = 0.0, worstG1Deg = 0.0;      ///< worst values after healing
  bool achieved = false;                        ///< every seam to reach meets the requested continuity
  std::vector<std::string> notes;
};

struct HealResult {
  Model model;
  HealReport report;
};

/// Heals the model. Errors: kInvalidInput (no patches, a non-3-D patch, continuity other than G0/G1, method local
/// with a G0 request, maxAngleDeg outside (0, 180]), and those of the pairing (continuity/model_check.h). Seams that cannot be joined, and errors
/// of the local scheme, are reported, not errors.
Result<HealResult> healModel(const Model& model, const HealOptions& options = {});

}  // namespace seam
