#pragma once
// Visual reports of a whole-model check: a self-contained HTML file (no external resources, opens offline) and a
// triangle mesh (Wavefront OBJ with per-vertex normals) for any mesh viewer.
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "seam/continuity/model_check.h"
#include "seam/continuity/verdict.h"
#include "seam/core/result.h"
#include "seam/model/model.h"

namespace seam::report {

struct HtmlReportOptions {
  std::string title = "seam report";  ///< page title (the CLI uses the file name)
  /// Seams with a plot of G0/G1/G2 along the seam; the worst seams (by geometric class, then angle) come first.
  /// Every seam is in the table regardless.
  int maxPlottedSeams = 400;
  int plotWidth = 560, plotHeight = 130;  ///< pixels per plot
  int overviewSize = 720;                 ///< pixels (square) of the model drawing
  int samplesPerEdge = 24;                ///< polyline points per patch edge in the drawing
  /// The seam tables (issue 17): design creases (angle at or above creaseAngleDeg) in a table of their own; the
  /// other seams kinks first (largest angle first), then gaps (largest first), then the rest in file order, unless
  /// `selection.sort` names a measure; `only` and `top` cut each table. The plots follow the same order.
  SeamSelection selection;
  /// The WebGL view (docs/report.md): shaded patches (ReportData::meshes), seams coloured by verdict, worst points,
  /// zebra stripes, G1/G2 spikes along the seams, click a seam for its plots. Needs a build with the bundled viewer
  /// (web/, hasViewer3d()); the 2-D drawing stays in the page as the fallback when WebGL is unavailable.
  bool view3d = true;
  /// At most this many spike samples in the page (over all seams; each seam's samples are thinned evenly to at most
  /// 64).
  int maxSpikeSamples = 20000;
  /// Value labels (issue 38 §11, as Rhino's edge analysis labels its edges): the worst gaps and kinks, at most this
  /// many, in the order of the seam table (kinks by angle, then gaps by size), get a label at their worst point in the
  /// 3-D view and in the 2-D drawing, "#k kink 0.618°" or "#k gap 0.0012 mm", with the table's digits. 0: none.
  /// Design creases get none (they are intended).
  int maxValueLabels = 12;
};

/// A triangle mesh of one patch for the 3-D view: a grid of (nu + 1) x (nv + 1) points with unit normals.
struct ReportMesh {
  std::string name;
  std::vector<Vec3> points, normals;
  std::vector<int> triangles;  ///< three vertex indices per triangle
};

/// One seam of the report: names, its analysis (or the error), and its curve for the drawing.
struct ReportSeam {
  std::string a, aEdge, b, bEdge;     ///< patch/face names and edge names (edge names may be empty)
  std::optional<SeamReport> report;   ///< empty when the analysis failed
  std::string error;                  ///< why it failed
  std::string extra;                  ///< an extra column (e.g. OpenCASCADE's verdict); empty: no column
  std::vector<Vec3> curve;            ///< points along the seam for the drawing
};

/// What a report shows, from either check (patch model or B-rep).
struct ReportData {
  Tolerances tolerances;
  /// The model's length unit ("mm", "in"; "" for a unit-less model): printed after every length of the page.
  std::string lengthUnit;
  /// Where the unit comes from, e.g. "mm (file header: INCH)" (a summary row "length unit"; "" = no row).
  std::string unitNote;
  /// Where the distance tolerance comes from, e.g. "default for models with a length unit" ("" = not said).
  std::string distanceSource;
  std::string angleSource;  ///< where the angle tolerance comes from (angleSourceText)
  std::vector<std::pair<std::string, std::string>> facts;  ///< summary rows after the computed ones
  std::string extraHeader;                                 ///< header of ReportSeam::extra ("" = none)
  std::vector<ReportSeam> seams;
  std::vector<std::vector<Vec3>> outline;       ///< every boundary curve (drawn thin grey under the seams)
  std::vector<std::string> freeEdges, degenerateEdges;   ///< labels
  /// The free (naked) edges' curves: drawn in kNakedEdgeColour over the outline, in the 3-D view and the 2-D
  /// drawing, with a legend entry (issue 38 §9).
  std::vector<std::vector<Vec3>> freeEdgeCurves;
  std::vector<const CornerReport*> corners;     ///< not owned (unless they point into ownedCorners)
  /// The corners converted by scaleLengths (which points `corners` here); empty otherwise.
  std::vector<CornerReport> ownedCorners;
  std::vector<std::string> cornerPatchNames;    ///< per corner: the names of its patches, space separated
  std::vector<ReportMesh> meshes;               ///< shaded surfaces of the 3-D view (may be empty)
  /// The reader's warnings (entities lost, roots not transferred, faces skipped): a section of their own at the top
  /// of the page and a summary row; none: neither.
  std::vector<std::string> warnings;
};

/// Converts every length of `data` to another unit (issue 38 §1, display units): the distance tolerance, each
/// seam's measures, the curves, outlines, meshes and corners (copied into ownedCorners); curvatures as 1/length.
/// lengthUnit and unitNote are the caller's to set; the facts' text is not converted.
void scaleLengths(ReportData& data, double scale);
/// Converts the geometry of `data` only (seam curves, outlines, free edges' curves, meshes): for data made by
/// reportData from a ModelCheckReport already converted by scaleLengths(ModelCheckReport&).
void scaleGeometry(ReportData& data, double scale);

/// True when this build inlines the 3-D view (three.js) into reports; false: the 2-D drawing only.
bool hasViewer3d();

/// The default vertex budget of the 3-D view's meshes (all patches together); about 60 bytes per vertex in the page.
inline constexpr int kDefaultViewVertexBudget = 60000;

/// Meshes of the patches of `model` for the 3-D view (those with shade[i] true; all when `shade` is empty): 8 cells
/// per Bezier span and direction (at least 2, at most 64 per direction), coarsened evenly so that the total number
/// of vertices stays within `vertexBudget`. Patches that are not 3-D are skipped.
std::vector<ReportMesh> reportMeshes(const Model& model, const std::vector<bool>& shade = {},
                                     int vertexBudget = kDefaultViewVertexBudget);

/// ReportData for a patch-model check (with the meshes of every patch).
/// The "overlapping faces" fact of a report (issue 38 §11), as `seam check` lists the pairs: "none", or "n pairs:"
/// ("1 pair:")
/// and the first kOverlapsListed of them as "A / B (p %, within d)", then "and m more". `name` spells a face or
/// patch by its index, `number` a percentage, `distance` a distance with its unit where it has one.
std::string overlapsFact(const std::vector<FaceOverlap>& overlaps, const std::function<std::string(int)>& name,
                         const std::function<std::string(double)>& number,
                         const std::function<std::string(double)>& distance);
inline constexpr size_t kOverlapsListed = 20;

ReportData reportData(const Model& model, const ModelCheckReport& report, int samplesPerEdge = 24);

/// The HTML page. Sections: summary, the model drawn in an axonometric view with every seam coloured by its class
/// (other boundary curves thin grey), a sortable seam table (click a header), per-seam plots of the G0 gap, G1
/// angle and relative G2 jump along the seam with the tolerance drawn as a dashed line, corners, free and
/// degenerate edges.
std::string htmlReport(const ReportData& data, const HtmlReportOptions& options = {});

/// The HTML page for `report` (made by checkModel on `model`, ideally with SeamOptions::keepSamples so that the
/// seams have samples to plot; seams without samples get no plot). Sections: summary, the model drawn in an
/// axonometric view with every patch edge coloured by the class of its seam (free edges grey), a sortable seam table
/// (click a header), per-seam plots of the G0 gap, G1 angle and relative G2 jump along A's edge parameter with the
/// tolerance drawn as a dashed line, corners, free and degenerate edges.
std::string htmlReport(const Model& model, const ModelCheckReport& report, const HtmlReportOptions& options = {});

struct MeshOptions {
  int samplesPerSpan = 8;   ///< grid cells per Bezier span in each direction
  int maxSamplesPerPatch = 256;  ///< cap per direction
};

/// The patches as a Wavefront OBJ text: one object per patch, a grid of vertices with unit normals
/// (S_u x S_v; at a pole, the normal of the nearest regular point inward), two triangles per cell.
/// Errors: kInvalidInput for a non-3-D patch or option values below 1.
Result<std::string> objMesh(const Model& model, const MeshOptions& options = {});

}  // namespace seam::report
