#pragma once
// One shared edge of the B-rep check (checkBRepShape's edge loop, src/occt/brep_check.cpp): the two faces' sides
// through OpenCASCADE and the sampled measures along the edge (src/occt/brep_edge.cpp), and the certified route
// through the pcurves composed with the converted patches (src/occt/brep_edge_certificate.cpp).
#include <cmath>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include <BRepTools.hxx>
#include <Geom2dAdaptor_Curve.hxx>
#include <GeomAdaptor_Surface.hxx>
#include <Geom2d_Curve.hxx>
#include <Geom_Surface.hxx>
#include <TopTools_IndexedDataMapOfShapeListOfShape.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Edge.hxx>
#include <gp_Pnt.hxx>
#include <gp_Vec.hxx>

#include "occt/brep_check_internal.h"
#include "occt/cad_internal.h"
#include "occt/pcurve_correspondence.h"
#include "seam/continuity/seam.h"
#include "seam/model/brep.h"
#include "seam/occt/brep_check.h"

namespace seam::occt::detail {

/// Minimum samples along a sampled edge (issue: >= 64 per span).
inline constexpr int kMinSamples = 64;
/// Normal curvatures below this / (model size) count as flat when forming relative jumps (as in analyzeSeam).
inline constexpr double kFlatCurvatureRatio = 1e-3;
inline constexpr double kRadToDeg = 180.0 / std::numbers::pi;
/// The note of a seam sampled through the pcurves (replaced when G0 and G1 are certified afterwards).
inline constexpr const char* kSampledNote =
    "sampled through the pcurves of the shared B-rep edge (trimmed faces): not certified";

inline Vec3 toVec(const gp_Vec& v) { return {v.X(), v.Y(), v.Z()}; }
inline Vec3 toVec(const gp_Pnt& p) { return {p.X(), p.Y(), p.Z()}; }

/// Per face of the check, its parameter box (BRepTools::UVBounds, which bounds the pcurves of all the face's edges,
/// projecting a plane's edges onto it afresh each time: ~3 % of a check when it was called per edge and side):
/// computed once, on first use, by whichever thread needs it first (std::call_once per face, as SpansCache), then
/// shared read-only by the face's edges. UVBounds looks at the face FORWARD, so the box does not depend on the
/// orientation in which an edge's ancestor list holds the face.
class FaceBoxCache {
 public:
  explicit FaceBoxCache(const TopTools_IndexedMapOfShape& faces)
      : faces_(faces), once_(static_cast<size_t>(faces.Extent())), boxes_(static_cast<size_t>(faces.Extent())) {}
  /// The box of face `index` (1-based, as in the map). A Standard_Failure of UVBounds reaches the caller (and the
  /// next caller tries again: std::call_once sets nothing when its function throws).
  [[nodiscard]] const detail::ParamBox& at(int index) const {
    const size_t k = static_cast<size_t>(index - 1);
    std::call_once(once_[k], [&] {
      detail::ParamBox& b = boxes_[k];
      BRepTools::UVBounds(TopoDS::Face(faces_(index)), b.u0, b.u1, b.v0, b.v1);
    });
    return boxes_[k];
  }

 private:
  const TopTools_IndexedMapOfShape& faces_;
  mutable std::vector<std::once_flag> once_;
  mutable std::vector<detail::ParamBox> boxes_;
};

/// Per converted patch, its spans for certifyPCurveSeam (surfaceSpans): built once, on first use, by
/// whichever thread needs them first (std::call_once per patch, no global lock), then shared read-only by all
/// its seams.
class SpansCache {
 public:
  explicit SpansCache(const std::vector<Patch>& patches)
      : patches_(patches), once_(patches.size()), spans_(patches.size()) {}
  [[nodiscard]] const SurfaceSpans* at(size_t k) const {
    std::call_once(once_[k], [&] { spans_[k] = surfaceSpans(patches_[k].surface); });
    return spans_[k].get();
  }

 private:
  const std::vector<Patch>& patches_;
  mutable std::vector<std::once_flag> once_;
  mutable std::vector<std::shared_ptr<const SurfaceSpans>> spans_;
};

/// One face seen from the shared edge: its surface, the edge's pcurve on it and the sense of its normal.
struct FaceSide {
  Handle(Geom_Surface) surface;
  Handle(Geom2d_Curve) pcurve;
  double first = 0, last = 0;  // pcurve parameter range
  double sign = 1.0;           // -1 for a reversed face
  GeomAdaptor_Surface surfaceEval;  // the surface through its span cache (the sampled route's evaluations)
  Geom2dAdaptor_Curve pcurveEval;   // the pcurve through its span cache
};

struct PointData {
  Vec3 point = Vec3::Zero();
  double g0 = 0, g1 = 0, g2 = 0, curvature = 0;
  bool normalsOk = true;    // G1 measured (normals or their one-sided limits)
  bool curvatureOk = true;  // curvatures measured (well-conditioned charts)
};

/// Measures at edge parameter t (A's pcurve parameter; B's partner point on B's edge, the closest to A's point).
PointData measure(const FaceSide& A, const FaceSide& B, double t);

/// The samples of an edge's measures through the pcurves: kMinSamples + 1 or more evenly spaced points (A's
/// parameter), the curvature reference and whether a normal vanishes at one of them.
struct EdgeSamples {
  std::vector<double> ts;
  std::vector<PointData> ms;
  double curvRef = 0.0;
  bool degenerate = false;
};

/// The samples of the edge `edge` between sides A and B (kMinSamples + 1, or samplesPerSpan per C2 span of the edge).
EdgeSamples sampleEdge(const TopoDS_Edge& edge, const FaceSide& A, const FaceSide& B, const SeamOptions& opt,
                       double modelSize);

/// The sampled seam report through the pcurves (certified = false). The maxima are refined (Brent's parabolic
/// steps, detail::refinedMaximum) where `refineG0G1` / `refineG2` ask for it; where the certified route replaces
/// a measure's values afterwards (certifyThroughPCurves) its refinement is skipped and the best sample stands in
/// (the report does not keep it).
SeamReport sampledSeam(const EdgeSamples& s, const FaceSide& A, const FaceSide& B, const std::string& a,
                       const std::string& b, const SeamOptions& opt, bool refineG0G1 = true, bool refineG2 = true);

/// A face's edge for the certified route: an exact curve in the patch's parameters, either in the edge's own
/// parameter (`ownParameter` false: the pcurve's B-spline form over [first, last]) or in a parameter of its own
/// (`ownParameter` true: the rational B-spline form of a circle or ellipse, whose parameter is not the angle; or an
/// iso-line of a converted analytic surface, whose patch parameter along a circle is not the angle). A side with
/// its own parameter is paired with the other face's edge by detail::correspondInParameterOf.
struct FacePCurve {
  PCurveSide side;
  bool ownParameter = false;
  std::string how;  ///< for the seam's notes, when ownParameter
  /// The polynomial patch side.surface points to when the face is an analytic surface whose converted patch runs in
  /// other parameters and the edge is no iso-line (analyticPatch): the pcurve is then composed with this patch in the
  /// face's own parameters. Shared by the copies of this side. Null otherwise.
  std::shared_ptr<const BSplineSurface> ownSurface;
  std::string surfaceNote;  ///< for the seam's notes, when ownSurface
};

/// The certified route of an edge, tried before its sampled report is made (the sampled values the certified ones
/// replace are then not refined): both sides' exact pcurves (pcurveSide), and when the two faces' edges do not
/// share a parameter, B's side (or A's, when only B has a parameter of its own, or when B's pcurve has the higher
/// degree) re-expressed in the other's parameter by a monotone piecewise-cubic correspondence
/// (detail::correspondInParameterOf); then certifyPCurveSeam. Filled in place (a and b point into it).
/// The part of a pcurve route's angle bound that covers closest points beyond the paired ones, as the B-rep check
/// adds it (PCurveSeamBounds::g1ClosestExcessDeg, degrees): 0 where it could not be bounded (the paired bound then
/// stands, held to the samples) and where a normal vanishes (g1PoleT: the angle is measured, not bounded).
inline double closestExcessDeg(const PCurveSeamBounds& r) {
  return r.g1PoleT || !std::isfinite(r.g1ClosestExcessDeg) ? 0.0 : r.g1ClosestExcessDeg;
}
/// The same for one direction: A's points and their closest points on B (onB), or B's and theirs on A.
inline double closestExcessDeg(const PCurveSeamBounds& r, bool onB) {
  const double e = onB ? r.g1ClosestExcessOnBDeg : r.g1ClosestExcessOnADeg;
  return r.g1PoleT || !std::isfinite(e) ? 0.0 : e;
}

struct EdgeCertificate {
  std::optional<Result<FacePCurve>> sideA, sideB;
  std::optional<Result<detail::Correspondence>> correspondence;
  bool byCorrespondence = false, masterA = true, sameParameter = false;
  SeamOptions opt;
  const PCurveSide *a = nullptr, *b = nullptr;           ///< the sides composed, when the route was tried
  std::optional<Result<PCurveSeamBounds>> bounds;        ///< certifyPCurveSeam(*a, *b, opt), when tried
  std::string failure;                                   ///< the note when the route could not be tried
  /// The certified gap at equal edge parameters, when it was above the tolerance and the closest-point pairing
  /// certified a smaller one (which replaced it); 0 otherwise.
  double equalParameterGap = 0.0;
  /// The certified angle at equal edge parameters (degrees), when samples between closest points lay above it and
  /// the closest-point pairing certified the edge instead (retryAngleByClosestPoints); 0 otherwise.
  double equalParameterAngleDeg = 0.0;
  /// The bound of the reverse direction from a pairing made from the other side's points (sharpenReverseDirection),
  /// degrees; 0 where not made.
  double reverseAngleDeg = 0.0;
  /// The reverse direction's sampled angle where no pairing from the other side certified (sharpenReverseDirection),
  /// degrees; 0 where not sampled.
  double reverseSampleAngleDeg = 0.0;
  /// The largest angle of the sampled route (A's edge points and the closest points of B's edge), degrees.
  double closestSampleAngleDeg = 0.0;
  /// The certified angle lies above seam's strict angle (kStrictAngleDeg, or the tolerance when smaller), the samples
  /// between closest points do not, the pcurves drift and the closest-point pairing could not be certified
  /// (retryAngleByClosestPoints): the angle is the pairing's, and the samples' angle is shown.
  bool angleFromPairing = false;
  /// G0 and G1 (g2: and G2) values will come from the certified route (unless reconcileVerdict withdraws them).
  [[nodiscard]] bool certifies() const { return bounds && bounds->isOk(); }
  /// The certified angle between closest points in the pairing's own direction (degrees; when certifies()): the
  /// paired points' bound plus how much the closest points' angle can exceed it that way (forwardExcessDeg), where
  /// that is bounded; where it is not (or a normal vanishes, g1PoleT), the paired points' angle. The two-sided angle
  /// the report shows (PCurveSeamBounds::g1ClosestExcessDeg) is settled by sharpenReverseDirection.
  [[nodiscard]] double angleBoundDeg() const { return (*bounds)->g1BoundDeg + forwardExcessDeg(); }
  /// The pairing was made from A's points (equal edge parameters, or a correspondence with A as the master): its
  /// closest-point excess toward B is the sharp one, the other direction's may be loose (sharpenReverseDirection).
  [[nodiscard]] bool pairedFromA() const { return !byCorrespondence || masterA; }
  /// The closest-point excess in the pairing's own direction (degrees; 0 where not bounded, as closestExcessDeg).
  [[nodiscard]] double forwardExcessDeg() const { return closestExcessDeg(**bounds, pairedFromA()); }
  [[nodiscard]] bool certifiesG2() const { return certifies() && (*bounds)->g2Certified; }
};

/// The certified route of the edge between faces fa and fb (1-based face indices; patches pa and pb, indices
/// patchA and patchB of the model) into `c`: see EdgeCertificate. `exactA` / `exactB`: the face's patch converts
/// its surface exactly; where it only approximates it, the side is composed with the surface's own polynomial patch
/// (a cylinder, cone, sphere or torus: analyticSide), or the route fails.
void tryCertificate(EdgeCertificate& c, const FaceSide& A, const FaceSide& B, const FaceBoxCache& boxes, int fa,
                    int fb, const BSplineSurface& pa, const BSplineSurface& pb,
                    const TopoDS_Edge& edge, const std::string& nameA, const std::string& nameB,
                    const SeamOptions& opt, double modelSize, const SpansCache& spans, size_t patchA,
                    size_t patchB, bool exactA, bool exactB);

/// The largest angle between closest points of an edge whose equal-parameter route certified `c` (degrees; 0 next
/// to a pole and where G1 is an identity): the samples', refined next to the certified worst point.
double closestAngleOfEdgeDeg(const EdgeSamples& s, const EdgeCertificate& c, const FaceSide& A, const FaceSide& B);

/// Whether an angle between closest points exceeds `boundDeg` beyond the retry slack (false next to a pole).
bool closestAnglesAboveDeg(const FaceSide& A, const FaceSide& B, double boundDeg);

/// Where the equal-parameter bound lies below a sample between closest points, or is loose above the strict angle,
/// the edge is certified again through the closest-point correspondence (issue 35 section 1 for angles).
void retryAngleByClosestPoints(EdgeCertificate& c, const SpansCache& spans, size_t patchA, size_t patchB);

/// The angle between closest points both ways (SeamOptions::closestPointsOn = kBoth): a pairing made from one side's
/// points bounds the other direction's excess only loosely (trj3_s1-al-214.stp edge 81: 0.0367 deg paired, 0.085 deg
/// of excess from B's side, where the probe measures 0.0367 both ways). Where that direction's excess is more than
/// the certification gap above the pairing's own, the edge is paired again from the other side's points, whose own
/// direction is then the sharp one; the angle shown is the larger of the two directions' sharp bounds. Where that
/// pairing does not certify, the reverse direction is sampled (kMinSamples + 1 points of the other side's edge and
/// their closest points): within the pairing's own bound, that bound stands (its direction certified, the other held
/// to the samples, as before the two-sided angle); above it, the loose two-sided bound, or where that is not finite,
/// the samples withdraw the certificate.
void sharpenReverseDirection(EdgeCertificate& c, const FaceSide& A, const FaceSide& B, const SpansCache& spans,
                             size_t patchA, size_t patchB);

/// Applies the certified route (tryCertificate) to the edge's sampled report.
void applyCertificate(SeamReport& rep, const EdgeCertificate& c, const std::string& nameA, const std::string& nameB,
                      double modelSize);

/// What one edge of the model contributes to the report (checkBRepFile's edge loop).
struct EdgeOutcome {
  enum Kind { kNone, kDegenerate, kLoose, kNonManifold, kFree, kSeam, kUnanalysed } kind = kNone;
  BRepSeam seam;
  BRepFreeEdge free;
  BRepNonManifoldEdge nonManifold;
  std::string warning;  ///< kUnanalysed: why
};

/// What checkBRepShape's edge loop shares with analyseEdge: the read-only state of one check (the shape's maps,
/// the converted patches, the tolerances and the caches), so that edges can be analysed on several threads.
struct EdgeCheckContext {
  const std::filesystem::path& file;
  const TopTools_IndexedMapOfShape& faceMap;
  const TopTools_IndexedDataMapOfShapeListOfShape& edgeFaces;
  const EdgeFilter& onlyEdges;
  const CadImport& import;
  const std::map<int, size_t>& patchOfFace;  ///< 1-based face index -> patch index
  const Tolerances& tolerances;
  const SeamOptions& seamOpt;  ///< with the check's tolerances
  double modelSize = 0.0;
  int threads = 0;  ///< BRepCheckOptions::threads
  const FaceBoxCache& faceBoxes;
  const SpansCache& spans;
};

/// Edge i (1-based, in edgeFaces' order): everything it contributes to the report. A Standard_Failure on it makes
/// it kUnanalysed with a warning; a signal caught inside OpenCASCADE is thrown on.
EdgeOutcome analyseEdge(const EdgeCheckContext& ctx, int i);

}  // namespace seam::occt::detail
