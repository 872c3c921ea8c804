#pragma once
// Whole-model continuity check (`seam check`): pairs every two boundary edges that coincide (fully or partly, e.g.
// T-junctions), analyses each pair with analyzeSeam, finds every vertex where patch corners meet and analyses it with
// analyzeCorner, and lists free and collapsed (degenerate) edges. The pairing uses a spatial index (a uniform grid
// over the edges' bounding boxes, sorted cell keys), so its cost grows as O(N log N) in the number of patches.
#include <array>
#include <optional>
#include <string>
#include <vector>

#include "seam/continuity/corner.h"
#include "seam/continuity/overlap.h"
#include "seam/continuity/seam.h"
#include "seam/core/result.h"
#include "seam/core/tolerances.h"
#include "seam/model/model.h"

namespace seam {

/// One boundary edge of a model patch.
struct EdgeRef {
  int patch = 0;  ///< index into Model::patches
  Edge edge = Edge::U0;
  friend bool operator==(const EdgeRef&, const EdgeRef&) = default;
  friend auto operator<=>(const EdgeRef&, const EdgeRef&) = default;
};

/// Two edges found to coincide on a common part (the pairing step, before any seam analysis).
struct EdgePair {
  EdgeRef a;  ///< the edge of the patch with the smaller index (or the smaller edge of one patch)
  EdgeRef b;
  Interval overlapA;  ///< the shared part in A's own edge parameter
  Interval overlapB;  ///< the shared part in B's own edge parameter
  bool fullA = true;  ///< the shared part is all of A's edge
  bool fullB = true;
  bool reversed = false;  ///< B's parameter decreases where A's increases
  /// Largest distance between the edges over the shared part found by the pairing (sampled, or the control-point
  /// bound when the two control polygons agree point by point). analyzeSeam then measures it properly.
  double distance = 0.0;
  /// The fast path: the control polygons agree point by point (in the same or reversed order) within the pairing
  /// tolerance, with equivalent knots and weights; `distance` is then the largest control-point distance (0 for
  /// exactly shared boundaries).
  bool identicalControlPolygons = false;
};

/// A paired seam and its analysis.
struct ModelSeam {
  EdgePair pair;
  std::optional<SeamReport> report;  ///< empty when analyzeSeam failed (see `error`)
  Status error;                      ///< why analyzeSeam failed
};

/// A boundary edge (or the part of one) that no other edge shares.
struct FreeEdge {
  EdgeRef edge;
  Interval range;        ///< the free part, in the edge's own parameter
  bool partial = false;  ///< only a part of the edge is free (the rest is paired)
};

/// An edge collapsed to a point (a pole): skipped by the pairing.
struct DegenerateEdge {
  EdgeRef edge;
  Vec3 point = Vec3::Zero();
};

/// Three or more boundary edges that coincide (the same end points and mid point, within tolerances.distance): a
/// duplicated face, a CAD defect. Only the first two of them (in EdgeRef order) take part in the pairing, so that
/// N copies of a face cost O(N log N), not N^2 candidate pairs; the others are neither seams nor free edges.
struct CoincidentEdges {
  std::vector<EdgeRef> edges;  ///< all of them, in EdgeRef order
  Vec3 point = Vec3::Zero();   ///< the mid point of the first
};

/// A vertex of the model and its analysis; corners are given as (patch, corner) in CornerReport::corners.
struct ModelCorner {
  CornerReport report;
};

struct ModelCheckSummary {
  int seams = 0;
  int corners = 0;
  int fourValentCorners = 0;
  int degenerateCorners = 0;  ///< vertices with a corner whose normal vanishes (poles)
  int freeEdges = 0;
  int degenerateEdges = 0;
  int coincidentEdgeGroups = 0;  ///< groups of 3 or more coincident edges (duplicated faces)
  int overlaps = 0;              ///< overlapping face pairs (when ModelCheckOptions::findOverlaps)
  int failedSeams = 0;        ///< analyzeSeam returned an error
  int certifiedSeams = 0;
  std::array<int, 4> geometric{};   ///< counts per GeometricClass (kNone, kG0, kG1, kG2)
  std::array<int, 4> parametric{};  ///< counts per ParametricClass
  GeometricClass worstGeometric = GeometricClass::kG2;     ///< over the analysed seams (kG2 when there are none)
  ParametricClass worstParametric = ParametricClass::kC2;
  double g0Max = 0.0, g1MaxDeg = 0.0, g2Max = 0.0, g2RelMax = 0.0;  ///< worst values over the seams
  int g0Seam = -1, g1Seam = -1, g2Seam = -1;                       ///< where (index into seams), -1 if none
  double normalSpreadMaxDeg = 0.0;         ///< over the corners
  double cornerG1ResidualMax = 0.0;        ///< over the 4-valent corners
  std::optional<double> cornerG2ResidualMax;
  /// Largest CornerReport::curvatureSpreadRel over the corners (empty when no corner has one).
  std::optional<double> cornerCurvatureSpreadRelMax;
  /// With ModelCheckOptions::require: the number of seams below it (failed seams count as below).
  int belowRequired = 0;
};

struct ModelCheckOptions {
  /// Classification tolerances. Default: Tolerances::forModelSize(bounding-box diagonal of the model).
  std::optional<Tolerances> tolerances;
  /// Analysis settings for every seam (its `tol` is replaced by the tolerances above).
  SeamOptions seam;
  /// When set, ModelCheckSummary::belowRequired counts the seams whose geometric class is below this one.
  std::optional<GeometricClass> require;
  /// Pairing: two edges are candidates when they come within pairingRelTol x (bounding-box diagonal) of each other
  /// over a common part (default 1 %, the near-gap criterion of shared/data/README.md), never less than
  /// tolerances.distance. See docs/tolerances.md.
  double pairingRelTol = 0.01;
  /// Pairing: a pair with a gap above tolerances.distance is kept only when the gap is below this fraction of the
  /// width of both patches across the edge (so the opposite edge of a narrow neighbour is never taken for a partner).
  double maxGapToWidth = 0.25;
  /// Pairing: a part shared by two edges must be longer than this fraction of the shorter edge (edges that only
  /// touch at an end point are not a seam).
  double minOverlapFraction = 0.01;
  /// Corners whose points lie within this distance are one vertex (besides corners joined by a paired edge or a
  /// collapsed edge). Default: tolerances.distance.
  std::optional<double> cornerTolerance;
  bool analyzeSeams = true;    ///< false: pairing only (seams carry no report)
  bool analyzeCorners = true;  ///< false: vertices are found but not analysed beyond valence and normals
  /// Threads (TBB) for the seam analyses and the parallel stages of the pairing and of the vertices (edge data,
  /// candidate tests, corner analyses): 0 = all hardware threads, 1 = serial on the calling thread. The report does
  /// not depend on it (every task writes its own slot; seams and vertices are kept in pairing order).
  int threads = 0;
  /// Overlapping faces (findOverlaps, seam/continuity/overlap.h) within tolerances.distance: off by default (an extra
  /// pass over the patch pairs whose boxes meet); `seam check` and `seam report` turn it on. Not searched in a model
  /// with trimmed faces (Model::trimmedFaces, Model::brep): its patches are the faces' whole surfaces, and two faces
  /// trimmed from one surface would overlap as patches (ModelCheckReport::overlapsSearched says so).
  bool findOverlaps = false;
  OverlapOptions overlap;  ///< its settings (its threads are `threads` above)
};

struct ModelCheckReport {
  Tolerances tolerances;
  double pairingTolerance = 0.0;
  std::vector<ModelSeam> seams;
  std::vector<ModelCorner> corners;
  std::vector<FreeEdge> freeEdges;
  std::vector<DegenerateEdge> degenerateEdges;
  std::vector<CoincidentEdges> coincidentEdges;
  std::vector<FaceOverlap> overlaps;  ///< ModelCheckOptions::findOverlaps; empty otherwise
  bool overlapsSearched = false;      ///< findOverlaps was asked for and the model has no trimmed faces
  ModelCheckSummary summary;
};

/// Checks the whole model (seams in parallel, see ModelCheckOptions::threads). Errors: kInvalidInput for a model
/// without patches, with a non-3-D patch, or with an edge whose points are not finite doubles (control points or
/// weights near 1e308 overflow in evaluation).
Result<ModelCheckReport> checkModel(const Model& model, const ModelCheckOptions& options = {});

/// Converts every length of `report` to another unit (issue 38 §1): the distance tolerance, the pairing tolerance,
/// each seam and corner (scaleLengths), points and distances; the absolute curvature jump is divided by `scale`.
void scaleLengths(ModelCheckReport& report, double scale);

/// The pairing step alone (spatial index + overlap test), for tests and benchmarks. `tolerances` as in
/// ModelCheckOptions (empty: from the model size). Also returns the collapsed edges.
struct EdgePairing {
  double pairingTolerance = 0.0;
  std::vector<EdgePair> pairs;
  std::vector<DegenerateEdge> degenerateEdges;
  std::vector<FreeEdge> freeEdges;
  std::vector<CoincidentEdges> coincidentEdges;
};
Result<EdgePairing> pairEdges(const Model& model, const ModelCheckOptions& options = {});

/// The pairing used by the repairs (join, heal, the local scheme): edges closer than max(maxGap, tol.distance) pair,
/// no seam or corner analysis. `diagonal` is the model's bounding-box diagonal.
Result<EdgePairing> pairEdgesWithin(const Model& model, const Tolerances& tol, double maxGap, double diagonal);

/// True when `c` is at least `required` (G2 >= G1 >= G0 >= none).
inline bool meets(GeometricClass c, GeometricClass required) { return static_cast<int>(c) >= static_cast<int>(required); }

}  // namespace seam
