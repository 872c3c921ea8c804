#pragma once
// Continuity check of a trimmed B-rep model (STEP/IGES): every edge shared by two faces, evaluated on each face
// through its pcurve, with the G0/G1/G2 measures of analyzeSeam (issue 8, section 2).
//
// Topology comes from OpenCASCADE. A file whose faces leave free edges is sewn first (BRepBuilderAPI_Sewing with
// `sewingRelTol` x the model diagonal), so that files without topology (bare surfaces, IGES trimmed surfaces) get
// their shared edges. For each shared edge:
//  * when the edge is a whole natural side of both faces (untrimmed faces whose pcurve runs along a full side of
//    the parameter box), the faces' patches are analysed by analyzeSeam: exact Bernstein data, certified bounds;
//  * otherwise the seam is sampled along the edge (samplesPerSpan points per span of the edge's 3-D curve, at
//    least 64, each local maximum refined by golden section) through the two pcurves, with the faces' own
//    orientation giving the normals' sense; then, when both faces were converted exactly, each patch reproduces
//    its face's surface in the same parameters (checked along the pcurve to kSameParametrisationRel) and both
//    pcurves are polynomial, G0 and G1 are certified by composition (certifyPCurveSeam, continuity/seam.h) and
//    replace the sampled values; G2 too where G1 holds as an identity (elsewhere G2 stays sampled, and the note
//    says why); else `certified` is false and a note says why.
// OpenCASCADE's own verdict (BRepLib::ContinuityOfFaces with the angle tolerance) is recorded next to seam's.
#include <array>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "seam/continuity/overlap.h"
#include "seam/continuity/seam.h"
#include "seam/core/result.h"
#include "seam/core/tolerances.h"
#include "seam/occt/cad_io.h"

namespace seam::occt {

/// The report's 3-D view meshes the B-rep faces with OpenCASCADE (BRepMesh_IncrementalMesh, which keeps the trims):
/// their linear deflection, the largest distance between a triangle and its face, as a fraction of the model's
/// bounding-box diagonal. 1e-3 keeps the facets below a pixel of a whole-model view (a 1000-pixel canvas) and a part
/// of the 100 000-vertex range on ../shared/data's files (docs/report.md).
inline constexpr double kFaceMeshDeflectionRel = 1e-3;
/// Their angular deflection, radians (BRepMesh's default: a circle gets at least 2 pi / 0.5 = 13 segments).
inline constexpr double kFaceMeshAngle = 0.5;
/// How many times the deflection is doubled while the meshes exceed BRepCheckOptions::meshVertexBudget.
inline constexpr int kFaceMeshCoarsenings = 4;

/// One B-rep face triangulated for a view: the face's own trimmed region, in model coordinates (its location
/// applied), triangles counter-clockwise seen from the side its normal points to (its orientation respected).
struct BRepFaceMesh {
  std::string face;                   ///< "F<n>", as the seams name it
  std::vector<Vec3> points, normals;  ///< unit normals of the face (the surface's, reversed on a reversed face)
  std::vector<int> triangles;         ///< three 0-based vertex indices per triangle
  /// True when OpenCASCADE's mesher left the face without triangles and seam's grid fallback made them (the surface
  /// sampled on a grid, the triangles inside the trims kept: the trims respected to within one grid cell).
  bool gridFallback = false;
};

/// SeamOptions::maxCertifiedDegree of the B-rep check (BRepCheckOptions::seam): a pcurve composed with its surface
/// reaches degree 300-750 on real files (linkrods.step, bearing.iges: 53 seams between 256 and 744), which the
/// default of 256 left sampled. Products and samples stay O(n^2) and O(n) up to this degree (bernstein.cpp's
/// power-of-two scaled products, seam_piece.cpp's scaled Horner samples). G0 and G1 only: the pcurve route's G2
/// polynomials stay within kPCurveG2MaxDegree (256; pcurve_seam.cpp).
inline constexpr int kBRepMaxCertifiedDegree = 1000;

struct BRepCheckOptions {
  /// Classification tolerances: resolveTolerances of these overrides (the distance defaults to
  /// kDefaultAbsoluteDistanceMm: a CAD file has a length unit). `tolerances.units` states the unit of the file's
  /// coordinates (as CadReadOptions::statedUnitMm, which it replaces).
  ToleranceOverrides tolerances;
  /// Analysis settings (samplesPerSpan, keepSamples, bounds); its `tol` is replaced by the tolerances. Its
  /// maxCertifiedDegree defaults to kBRepMaxCertifiedDegree here.
  SeamOptions seam = [] {
    SeamOptions o;
    o.maxCertifiedDegree = kBRepMaxCertifiedDegree;
    return o;
  }();
  /// Sewing tolerance relative to the model diagonal, used when the file leaves free edges (1e-4: gaps up to this
  /// are sewn, then measured and classified with the distance tolerance).
  double sewingRelTol = 1e-4;
  /// Sew a model with free edges before the check (as above). Off: the shape's own topology is checked as it is
  /// (the B-rep heal checks the shape it writes, whose topology it keeps).
  bool sewFreeEdges = true;
  CadReadOptions read;
  /// Threads for the shared edges (analysed kProgressEdgeStep at a time, merged in edge order: the report is the same
  /// for every value): 0 = all hardware threads (the default: 25-30 % less wall time on 2 idle cores for the larger
  /// files of ../shared/data, docs/performance.md "STEP/IGES check against OpenCASCADE"), 1 = serial on the calling
  /// thread.
  int threads = 0;
  /// Called with (faces, edges done, edges in all) once the faces are converted (done = 0) and then after every
  /// kProgressEdgeStep edges and at the end; empty: no calls. The CLI prints a line on stderr for large models.
  std::function<void(int faces, int done, int total)> progress;
  /// Triangulate the faces into BRepCheckReport::faceMeshes (for the report's 3-D view); off by default.
  bool meshFaces = false;
  bool meshTrimmedOnly = false;  ///< only the trimmed faces (the untrimmed ones are shaded from their patches)
  double meshDeflectionRel = kFaceMeshDeflectionRel;  ///< linear deflection / model diagonal
  /// Time OpenCASCADE's mesher may take for the view: meshBudgetFactor x the time the check took before it, at
  /// least meshBudgetMinSeconds (issue 35 §4: an 11-face file whose check takes 0.3 s ran into the 300 s limit
  /// inside BRepMesh). Faces not meshed by then are triangulated by seam's grid over their trims. Factor 0: no bound.
  double meshBudgetFactor = 3.0;
  double meshBudgetMinSeconds = 5.0;  ///< see meshBudgetFactor
  /// The deflection is doubled (up to kFaceMeshCoarsenings times) while the meshes have more vertices; 0: no limit.
  int meshVertexBudget = 0;
  /// Search for faces that lie on each other within the distance tolerance, inside both faces' trims
  /// (BRepCheckReport::overlaps; docs/check-output.md, "Overlapping faces"). Off by default, as for patch models
  /// (ModelCheckOptions::findOverlaps): `seam check`, `seam report` and the Python module turn it on; the heal's own
  /// checks leave it off. `overlap.threads` is replaced by `threads`.
  bool findOverlaps = false;
  OverlapOptions overlap;
};

/// Edges between two progress calls.
inline constexpr int kProgressEdgeStep = 100;

struct BRepSeam {
  int edge = 0;                 ///< 1-based index of the edge in the model's edge map
  std::string a, b;             ///< patch (face) names, "F<n>"
  SeamReport report;            ///< measures; t is A's patch-edge parameter (certified) or the edge parameter
  bool viaPatchEdges = false;   ///< analysed as a patch seam (certified route)
  std::string occtContinuity;   ///< BRepLib::ContinuityOfFaces: "C0", "G1", "C1", "G2", "C2", "C3" or "CN"
  std::vector<Vec3> curve;      ///< points along the 3-D edge (for drawings)
};

struct BRepFreeEdge {
  int edge = 0;
  std::string face;
  Vec3 midpoint = Vec3::Zero();
  std::vector<Vec3> curve;  ///< points along the 3-D edge (for drawings)
};

struct BRepNonManifoldEdge {
  int edge = 0;
  std::vector<std::string> faces;
  Vec3 midpoint = Vec3::Zero();
};

struct BRepCheckReport {
  Tolerances tolerances;
  DistanceSource distanceSource = DistanceSource::kAbsoluteDefault;  ///< where tolerances.distance comes from
  AngleSource angleSource = AngleSource::kCadDefault;                ///< where tolerances.angleDeg comes from
  ModelUnits units;           ///< millimetres; the file's unit name and declared resolution (cadModelUnits)
  bool sewn = false;          ///< the file was sewn before the check
  CadImport import;           ///< the faces as patches (same names as in the seams)
  std::vector<BRepSeam> seams;
  std::vector<BRepFreeEdge> freeEdges;
  std::vector<BRepNonManifoldEdge> nonManifoldEdges;
  int degenerateEdges = 0;
  int looseEdges = 0;         ///< edges of the file that bound no face (loose 3-D curves): not seams, counted only
  int unanalysedEdges = 0;    ///< edges where OpenCASCADE failed (each named in import.warnings): not seams
  int certifiedSeams = 0;
  std::array<int, 4> geometric{};  ///< counts per GeometricClass
  GeometricClass worstGeometric = GeometricClass::kG2;
  int occtAgreement = 0;      ///< seams where "G1 or better" agrees between seam and OpenCASCADE
  std::vector<BRepFaceMesh> faceMeshes;  ///< with BRepCheckOptions::meshFaces: the faces' triangles
  double meshDeflection = 0.0;           ///< the linear deflection they were made with (model units; 0: none)
  /// > 0 when OpenCASCADE's mesher was stopped at its budget (BRepCheckOptions::meshBudgetFactor): that budget (s).
  double meshStoppedAfterSeconds = 0.0;
  /// BRepCheckOptions::findOverlaps: the face pairs that lie on each other; `a` and `b` are 0-based indices of the
  /// faces in TopExp::MapShapes order (face "F<a + 1>", as the seams name them), `fraction` is the larger share of
  /// one face's samples inside its trims that lie on the other face inside its trims.
  std::vector<FaceOverlap> overlaps;
  /// The solids each overlapping pair's faces belong to (1-based, in TopExp::MapShapes order; 0: the face is in no
  /// solid), one pair per overlap: faces of two solids of an assembly lying on each other are the solids' contact.
  std::vector<std::pair<int, int>> overlapSolids;
  bool overlapsSearched = false;  ///< findOverlaps was asked for (overlaps is complete but for the faces below)
  /// Faces with samples on another face whose trims the samples do not read right (a face of zero area, a sliver:
  /// the area of its inside samples and its own area differ by more than 4 times): left out of the search.
  int overlapFacesSkipped = 0;
};

/// Reads and checks a STEP/IGES file. Errors as readCadFile; a crash inside OpenCASCADE during the check (a signal,
/// caught) is an error too, while an OpenCASCADE failure on one edge only leaves that edge out (unanalysedEdges, with
/// a warning).
Result<BRepCheckReport> checkBRepFile(const std::filesystem::path& file, const BRepCheckOptions& options = {});

/// Converts every length of `report` to another unit (issue 38 §1, display units): the distance tolerance, each
/// seam's measures (scaleLengths(SeamReport&)), the drawn curves and meshes, midpoints; curvatures as 1/length.
/// `units` is left as it is: the caller shows the converted report with ModelUnits::shown().
void scaleLengths(BRepCheckReport& report, double scale);
/// `report` in the unit its lengths are shown in (report.units.displayScale(): the file's own unit, or
/// --display-units): scaleLengths, and report.units becomes report.units.shown(). A second call changes nothing.
void toShownUnits(BRepCheckReport& report);

}  // namespace seam::occt
