#pragma once
// Johansson Section 4 on a model (`seam fill`): the 4th patch at a vertex (4.1), filling a four-sided hole
// (4.2) and fillets between two strips (4.3). Every new patch comes from buildG1Patch (g1_patch.h); the input
// patches are never modified. checkFill verifies the result with the certified seam and corner analyses.
#include <array>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "seam/construct/g1_patch.h"
#include "seam/continuity/corner.h"
#include "seam/continuity/seam.h"
#include "seam/core/result.h"
#include "seam/core/tolerances.h"
#include "seam/model/model.h"

namespace seam {

struct FillOptions {
  /// The new patches: start bi-degree (default (5,5)), raising, kappa == 0, interior rule. Fillet bridges ignore it
  /// (they are built with the strips' degree along, degree 3 across and kappa == 0, Section 4.3).
  G1PatchOptions patch;
  /// Distance/angle tolerances: matching edges and corners (distance) and the G1 verdicts (angle).
  /// Default: Tolerances::forModelSize(bounding-box diagonal of the model).
  std::optional<Tolerances> tolerances;
  /// Name of the new patch (the first one); further ones get _2, _3, ... Default: "fill" ("fillet" for
  /// fillets).
  std::string name;
  /// Hole filling: analyse every seam among the surrounding patches first and build nothing when one is not
  /// G1.
  bool checkSurrounding = true;
  /// Settings of the seam analyses (their `tol` is replaced by the tolerances above).
  SeamOptions seam;
};

/// A seam between a new patch and a patch it was built against (an input patch or an earlier new patch).
struct FillSeam {
  std::string newPatch;
  Edge newEdge = Edge::U0;
  std::string neighbour;
  Edge neighbourEdge = Edge::U0;
  bool reversed = false;  ///< the new patch's edge parameter runs against the neighbour's
  ConnectingFunctions
      functions;  ///< N_cross = lambda A_out + kappa A_t in the neighbour's edge parameter (g1_patch.h)
};

/// One new patch and how it was built.
struct FilledPatch {
  Patch patch;       ///< kind kBezier
  std::string role;  ///< "quad", "hole", "fillet-bridge" or "fillet-fill"
  G1PatchResult construction;
};

/// A four-sided hole bounded by free edges of four patches (Figure 5: r2, r4, r6, r8 around r5).
struct Hole {
  /// The sides in order around the hole: patch index (into Model::patches) and edge. Side k runs from
  /// corners[k] to corners[(k+1) % 4].
  std::array<int, 4> sidePatch{};
  std::array<Edge, 4> sideEdge{};
  std::array<Vec3, 4> corners{};
  /// Every patch touching the hole (the four sides and the patches with a corner at a hole corner: r1..r9
  /// \ r5).
  std::vector<int> around;
};

struct FillResult {
  std::vector<FilledPatch> patches;  ///< in the order built
  std::vector<FillSeam> seams;       ///< every seam of a new patch with a patch it was built against
  /// Hole filling with checkSurrounding: the seams among the surrounding patches, analysed before filling.
  std::vector<SeamReport> surrounding;
  /// False when a surrounding seam is not G1 (see `surrounding`): then nothing is built and `patches` is
  /// empty.
  bool surroundingG1 = true;
  std::vector<std::string> notes;
};

/// Section 4.1: the 4th patch at the vertex where `corner` (r1) meets its two neighbours `b` (r2) and `c`
/// (r4), G1 to b and c. The vertex is the corner point the three patches share; b and c must each share an
/// edge with `corner` through it; the new patch takes the other edge of b and of c through the vertex.
/// Errors: kNotFound for unknown names or no common vertex/shared edges, kUnsupported for rational or
/// multi-span patches, kNoSolution when the engine fails (see G1PatchResult::notes: inexact results are
/// returned, not errors).
Result<FillResult> fillQuad(const Model& model, const std::string& corner, const std::string& b,
                            const std::string& c, const FillOptions& options = {});

/// Four-sided holes among the patches `candidates` (indices into model.patches; empty: all): cycles of four
/// free edges (edges no other patch shares) of four different patches. `distance` matches edges and corners.
std::vector<Hole> findHoles(const Model& model, std::span<const int> candidates, double distance);

/// Section 4.2: fills the hole(s) among `around` (patch names; empty: every four-sided hole of the model)
/// with one patch each, G1 to the four sides. With checkSurrounding, every seam among the patches around a
/// hole is analysed first; when one is below G1 nothing is built (surroundingG1 == false, numbers in
/// `surrounding`). Errors: kNotFound for unknown names or when no hole is found, kUnsupported for rational or
/// multi-span sides.
Result<FillResult> fillHole(const Model& model, const std::vector<std::string>& around,
                            const FillOptions& options = {});

/// Section 4.3: a fillet between two G1 strips facing each other, strip1[k] opposite strip2[k] (names in
/// order along the strips). Bridges (kappa == 0, the strips' degree across, two constant lambdas chosen by
/// fairness) join strip1[k] and strip2[k] for even k; the patches between consecutive bridges (odd k) are
/// built like hole fills against strip1[k], strip2[k] and the bridges on either side (three sides at an end
/// of the strip). Errors: kInvalidInput for strips of different lengths or empty, kNotFound for unknown names
/// or strips that do not face each other, kUnsupported for rational or multi-span patches.
Result<FillResult> fillFillet(const Model& model, const std::vector<std::string>& strip1,
                              const std::vector<std::string>& strip2, const FillOptions& options = {});

/// The input model with the new patches appended (input patches and curves unchanged).
Model withFill(const Model& model, const FillResult& fill);

/// Certified verification of a fill: analyzeSeam on every seam of FillResult::seams and analyzeCorner at
/// every corner of every new patch (all patches of withFill(model, fill) with a corner there).
struct FillCheck {
  std::vector<SeamReport> seams;  ///< one per FillResult::seams entry (A = the neighbour, B = the new patch)
  std::vector<CornerReport> corners;  ///< one per distinct corner point of the new patches
  /// Every seam at least G1 (certified) and every interior corner's normal spread within the angle tolerance.
  bool g1 = true;
  std::vector<std::string> problems;  ///< what is not G1, with the numbers
};
Result<FillCheck> checkFill(const Model& model, const FillResult& fill, const FillOptions& options = {});

}  // namespace seam
