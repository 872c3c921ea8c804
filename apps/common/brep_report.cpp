#include "brep_report.h"

#include <fmt/format.h>

#include <algorithm>
#include <string_view>

#include "units_text.h"
#ifdef SEAM_HAVE_OCCT
#include "seam/occt/brep_check.h"
#include "seam/occt/brep_model.h"
#endif

namespace seam::cli {

void setReportUnits(report::ReportData& d, const ModelUnits& units, const ResolvedTolerances& tol) {
  d.lengthUnit = units.name();
  constexpr std::string_view kPrefix = "length unit: ";
  d.unitNote = unitText(units).substr(kPrefix.size());
  d.distanceSource = distanceSourceText(tol.distanceSource, tol.preset);
  d.angleSource = angleSourceText(tol.angleSource, tol.preset);
}

#ifdef SEAM_HAVE_OCCT
bool hasBRepReport() { return true; }

Result<BRepReportPage> brepReportPage(const std::filesystem::path& file, const ToleranceOverrides& tol,
                                      const report::HtmlReportOptions& options,
                                      const std::function<void(int, int, int)>& progress, const Model* model) {
  occt::BRepCheckOptions bo;
  bo.seam.keepSamples = true;
  bo.tolerances = tol;
  bo.progress = progress;
  bo.findOverlaps = true;  // as `seam check`
  // The trimmed faces are shaded from OpenCASCADE's triangulation (their patch is the whole parameter box, larger
  // than the face); half of the view's vertex budget is theirs at most, the untrimmed faces' patch meshes get the rest.
  bo.meshFaces = options.view3d;
  bo.meshTrimmedOnly = true;
  bo.meshVertexBudget = report::kDefaultViewVertexBudget / 2;
  const Result<occt::BRepCheckReport> r =
      model != nullptr ? occt::checkBRepModel(*model, file, bo) : occt::checkBRepFile(file, bo);
  if (!r) return r.status();
  report::ReportData d;
  d.warnings = r->import.warnings;
  d.tolerances = r->tolerances;
  setReportUnits(d, r->units.shown(), {r->tolerances, r->distanceSource, r->angleSource, tol.preset});
  d.extraHeader = "OpenCASCADE";
  d.facts.emplace_back("faces", fmt::format("{}{}", r->import.faces.size(), r->sewn ? " (sewn)" : ""));
  d.facts.emplace_back("non-manifold edges", std::to_string(r->nonManifoldEdges.size()));
  d.facts.emplace_back("agrees with OpenCASCADE (G1 or not)",
                       fmt::format("{} of {}", r->occtAgreement, r->seams.size()));
  {  // faces lying on each other inside their trims (issue 38 §11), as `seam check` lists them
    const double scale = r->units.displayScale();
    d.facts.emplace_back(
        "overlapping faces",
        report::overlapsFact(
            r->overlaps, [](int f) { return fmt::format("F{}", f + 1); }, [](double x) { return formatNumber(x); },
            [&](double x) { return withUnit(formatNumber(x * scale), r->units.shown()); }));
  }
  for (const occt::BRepSeam& s : r->seams) {
    report::ReportSeam rs;
    rs.a = s.a;
    rs.b = s.b;
    rs.aEdge = fmt::format("edge {}", s.edge);  // one spelling of an edge (issue 38 §7), as `check` prints it
    rs.report = s.report;
    rs.extra = s.occtContinuity;
    rs.curve = s.curve;
    d.seams.push_back(std::move(rs));
  }
  for (const occt::BRepFreeEdge& f : r->freeEdges) {
    d.freeEdges.push_back(fmt::format("edge {} ({})", f.edge, f.face));
    if (!f.curve.empty()) d.freeEdgeCurves.push_back(f.curve);
  }
  for (int k = 0; k < r->degenerateEdges; ++k) d.degenerateEdges.push_back("pole");
  // The 3-D view: the untrimmed faces' patches meshed as for a patch model, the trimmed faces by OpenCASCADE
  // (BRepMesh_IncrementalMesh, kFaceMeshDeflectionRel x the diagonal: the trims and holes kept).
  std::vector<bool> shade;
  size_t trimmed = 0;
  for (const occt::CadFace& f : r->import.faces) {
    shade.push_back(!f.trimmed);
    trimmed += f.trimmed ? 1 : 0;
  }
  int faceMeshVertices = 0;
  for (const occt::BRepFaceMesh& m : r->faceMeshes) faceMeshVertices += static_cast<int>(m.points.size());
  d.meshes = report::reportMeshes(r->import.model, shade,
                                  std::max(report::kDefaultViewVertexBudget - faceMeshVertices,
                                           report::kDefaultViewVertexBudget / 2));
  for (const occt::BRepFaceMesh& m : r->faceMeshes) d.meshes.push_back({m.face, m.points, m.normals, m.triangles});
  // Lengths in the shown unit (issue 38 §1: the file's own, or --display-units).
  const double scale = r->units.displayScale();
  if (scale != 1.0) report::scaleLengths(d, scale);
  if (trimmed > 0) {
    // Faces OpenCASCADE's mesher skips (e.g. an open trim) come from seam's grid fallback (src/occt/face_mesh.cpp).
    const auto fallback = std::count_if(r->faceMeshes.begin(), r->faceMeshes.end(),
                                        [](const occt::BRepFaceMesh& m) { return m.gridFallback; });
    d.facts.emplace_back(
        "3-D view",
        fmt::format("{} of {} trimmed faces shaded from OpenCASCADE's triangulation (deflection {}){}",
                    r->faceMeshes.size() - static_cast<size_t>(fallback), trimmed,
                    withUnit(formatNumber(r->meshDeflection * scale), r->units.shown()),
                    fallback > 0 ? fmt::format("; {} more, which OpenCASCADE could not mesh{}, from seam's grid "
                                               "over their trims",
                                               fallback,
                                               r->meshStoppedAfterSeconds > 0.0
                                                   ? fmt::format(" within its budget of {} s (3 x the check)",
                                                                 formatNumber(r->meshStoppedAfterSeconds))
                                                   : std::string())
                                 : std::string()));
  }
  BRepReportPage page;
  page.html = report::htmlReport(d, options);
  page.seams = r->seams.size();
  page.worst = r->worstGeometric;
  page.warnings = r->import.warnings;
  return page;
}
#else
bool hasBRepReport() { return false; }

Result<BRepReportPage> brepReportPage(const std::filesystem::path& file, const ToleranceOverrides&,
                                      const report::HtmlReportOptions&, const std::function<void(int, int, int)>&,
                                      const Model*) {
  return Status(ErrorCode::kInvalidInput,
                fmt::format("{}: STEP/IGES need a build with SEAM_WITH_OCCT (OpenCASCADE)", file.string()));
}
#endif

}  // namespace seam::cli
