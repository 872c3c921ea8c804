// seam report FILE -o report.html [--tol-distance D] [--tol-angle DEG] [--tol-curvature K]
//   one self-contained HTML page: summary, model drawing coloured by seam class, sortable seam table, plots of
//   G0/G1/G2 along every seam with the tolerances, corners, free and degenerate edges.
// seam export-mesh FILE -o out.obj [--per-span N]
//   the patches tessellated (Wavefront OBJ, per-vertex normals) for any mesh viewer.
#include <fmt/format.h>

#include <algorithm>

#include <cmath>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "brep_report.h"
#include "cli_util.h"
#include "command_registry.h"
#include "seam/continuity/model_check.h"
#include "seam/report/report.h"

namespace seam::cli {

namespace {

/// `name` with every control character (bytes below 0x20 and 0x7f) replaced by '_'.
std::string objSafeName(std::string name) {
  for (char& c : name) {
    const auto u = static_cast<unsigned char>(c);
    if (u < 0x20 || u == 0x7f) c = '_';
  }
  return name;
}

struct ReportOptions {
  std::string file, out;
  ToleranceOverrides tol;
  int maxPlots = 400;
  int maxLabels = 12;
  std::optional<double> creaseAngle;
  std::string sort = "file";
  std::optional<size_t> top;
  std::string only;
};

/// --crease-angle, --sort, --top, --only (as `seam check`); false with the message on stderr when one is wrong.
bool parseSelection(const ReportOptions& o, SeamSelection& sel) {
  if (o.creaseAngle) {
    if (!validCreaseAngle(*o.creaseAngle)) {
      printError("--crease-angle must be an angle in degrees in (0, 180]");
      return false;
    }
    sel.creaseAngleDeg = *o.creaseAngle;
  }
  const Result<SeamSortKey> key = parseSeamSortKey(o.sort);
  if (!key) {
    printError("--sort: " + key.status().message());
    return false;
  }
  sel.sort = *key;
  if (!o.only.empty()) {
    const Result<SeamFilter> only = parseSeamFilter(o.only);
    if (!only) {
      printError("--only: " + only.status().message());
      return false;
    }
    sel.only = *only;
  }
  sel.top = o.top;
  return true;
}

#ifdef SEAM_HAVE_OCCT
/// STEP/IGES: the B-rep check (every shared edge through the pcurves), OpenCASCADE's verdict as an extra column
/// (brepReportPage, apps/common/brep_report.h: the same page as Python's seam.report). `model`: a JSON model with
/// its B-rep topology (Model::brep), reported as the shape made from it (as `seam check` of it); else o.file is read.
int runBRepReport(const ReportOptions& o, const report::HtmlReportOptions& ro, const Model* model = nullptr) {
  const Result<BRepReportPage> page = [&] {
    const CadTimeLimit limit(o.file, "reading and checking");
    // The last progress call comes when every edge is checked: the 3-D view's meshing follows (the time limit's
    // message names it: issue 35 §4).
    const auto printer = brepProgressPrinter(o.file);
    return brepReportPage(o.file, o.tol, ro, [printer, file = o.file](int faces, int done, int total) {
      printer(faces, done, total);
      if (done == total) setActivity(fmt::format("{}: meshing the faces for the 3-D view", file));
    }, model);
  }();
  if (!page) {
    printError(page.status().message());
    return kExitBadInput;
  }
  for (const std::string& w : page->warnings) std::cerr << "seam: warning: " << w << "\n";
  if (!writeOutputFile(o.out, page->html)) return kExitBadInput;
  fmt::print("wrote {} ({} B-rep seams, worst {}{})\n", o.out, page->seams, toString(page->worst),
             page->warnings.empty() ? "" : fmt::format("; {} reader warnings, in the report", page->warnings.size()));
  return kExitOk;
}
#endif

int runReport(const ReportOptions& o) {
  if (!validToleranceOptions(o.tol)) return kExitBadInput;
  if (!checkOutputPath(o.file, o.out)) return kExitBadInput;
  report::HtmlReportOptions ro;
  ro.title = "seam report: " + std::filesystem::path(o.file).filename().string();
  ro.maxPlottedSeams = o.maxPlots;
  ro.maxValueLabels = o.maxLabels;
  if (!parseSelection(o, ro.selection)) return kExitBadInput;
#ifdef SEAM_HAVE_OCCT
  if (isCadFile(o.file)) {
    // A directory, a FIFO or a device: the same message as for .json/.bpt (never handed to OpenCASCADE).
    if (!checkInputPath(o.file)) return kExitBadInput;
    return runBRepReport(o, ro);
  }
#endif
  ModelUnits units;
  std::vector<std::string> warnings;
  const std::optional<Model> model = loadModel(o.file, o.tol, &units, &warnings);
  if (!model || !displayUnitsApply(o.file, units)) return kExitBadInput;
  if (model->patches.empty()) {
    fmt::print("{}: the model has no patches: nothing to check (no report written)\n", o.file);
    return kExitOk;
  }
#ifdef SEAM_HAVE_OCCT
  // A JSON with trimmed faces and their topology: the B-rep route, as `seam check` of it (its faces' real edges,
  // not the patches of their parameter boxes).
  if (model->brep) return runBRepReport(o, ro, &*model);
#endif
  ModelCheckOptions mo;
  const ResolvedTolerances resolved = resolveTolerances(o.tol, units, model->boundingBox().diagonal());
  mo.tolerances = resolved.tolerances;
  mo.seam.keepSamples = true;
  mo.findOverlaps = true;
  if (model->patches.size() > kProgressPatches) std::cerr << fmt::format("seam: checking {} patches...\n", model->patches.size());
  Result<ModelCheckReport> report = checkModel(*model, mo);
  if (!report) {
    printError(fmt::format("{}: {}", o.file, report.status().message()));
    return kExitBadInput;
  }
  // Lengths in the shown unit (issue 38 §1, --display-units): the measures first, then the drawn geometry.
  const double scale = units.displayScale();
  if (scale != 1.0) scaleLengths(*report, scale);
  report::ReportData d = report::reportData(*model, *report, ro.samplesPerEdge);
  if (scale != 1.0) report::scaleGeometry(d, scale);
  setReportUnits(d, units.shown(), resolved);
  d.warnings = warnings;
  if (!writeOutputFile(o.out, report::htmlReport(d, ro))) return kExitBadInput;
  fmt::print("wrote {} ({} seams, worst {})\n", o.out, report->seams.size(), toString(report->summary.worstGeometric));
  return kExitOk;
}

void addReport(CLI::App& app, int& exit) {
  auto o = std::make_shared<ReportOptions>();
  CLI::App* cmd = app.add_subcommand("report", "Write a self-contained HTML report of the continuity check");
  cmd->add_option("FILE", o->file, modelFileHelp())->required();
  cmd->add_option("-o,--output", o->out, "HTML file to write")->required();
  addToleranceOptions(*cmd, o->tol);
  addDisplayUnitsOption(*cmd, o->tol);
  cmd->add_option("--max-plots", o->maxPlots, "Seams plotted, worst first (default 400)")->check(CLI::Range(0, 1000000));
  cmd->add_option("--max-labels", o->maxLabels,
                  "Value labels (\"#12 kink 0.618°\") on the worst gaps and kinks in the 3-D view and the drawing "
                  "(default 12; 0: none)")
      ->check(CLI::Range(0, 1000000));
  cmd->add_option("--crease-angle", o->creaseAngle,
                  "Seams whose angle is at or above this (degrees, in (0, 180]) are design creases, in a table of "
                  "their own (default 20)");
  cmd->add_option("--sort", o->sort,
                  "Order of the seam tables: verdict (the default: kinks, then gaps, then the rest), angle, gap or "
                  "curvature (largest first), or file");
  cmd->add_option("--top", o->top, "List at most N seams per table")->type_name("N");
  cmd->add_option("--only", o->only,
                  "List only: problems (gaps, kinks and failed analyses), gaps, kinks, creases, or all (the default)");
  cmd->callback([o, &exit]() { exit = runReport(*o); });
}

/// export-mesh's bounds: grid cells per span and direction, vertices of the whole mesh (about 120 bytes of OBJ text
/// each with its normal and two triangles: 2 000 000 vertices are about 230 MB).
constexpr int kMaxPerSpan = 64;
constexpr long long kMaxMeshVertices = 2'000'000;
constexpr long long kObjBytesPerVertex = 120;

/// The vertices report::objMesh makes for `model` (per patch and direction: samplesPerSpan x spans cells, at most
/// maxSamplesPerPatch).
long long meshVertices(const Model& model, const report::MeshOptions& mo) {
  long long total = 0;
  for (const Patch& p : model.patches) {
    const BSplineSurface& s = p.surface;
    const auto spans = [](const KnotVector& k, int degree) {
      return static_cast<long long>(k.interiorBreakpoints(degree).size()) + 1;
    };
    const long long cu = std::min<long long>(mo.samplesPerSpan * spans(s.knotsU(), s.degreeU()), mo.maxSamplesPerPatch);
    const long long cv = std::min<long long>(mo.samplesPerSpan * spans(s.knotsV(), s.degreeV()), mo.maxSamplesPerPatch);
    total += (cu + 1) * (cv + 1);
  }
  return total;
}

void addExportMesh(CLI::App& app, int& exit) {
  struct Options {
    std::string file, out;
    int perSpan = 8;
  };
  auto o = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand("export-mesh", "Tessellate the patches into a Wavefront OBJ mesh with normals");
  cmd->add_option("FILE", o->file, modelFileHelp())->required();
  cmd->add_option("-o,--output", o->out, "OBJ file to write")->required();
  cmd->add_option("--per-span", o->perSpan,
                  fmt::format("Grid cells per Bezier span and direction (default 8, at most {}; the whole mesh at "
                              "most {} vertices)",
                              kMaxPerSpan, kMaxMeshVertices))
      ->check(CLI::Range(1, kMaxPerSpan));
  cmd->callback([o, &exit]() {
    if (!checkOutputPath(o->file, o->out)) {
      exit = kExitBadInput;
      return;
    }
    std::optional<Model> model = loadModel(o->file);
    if (!model) {
      exit = kExitBadInput;
      return;
    }
    // An OBJ line "o <name>" ends at the line break: control characters in a name (a newline would start a
    // line of its own) are written as '_', with a note.
    for (Patch& p : model->patches) {
      const std::string safe = objSafeName(p.name);
      if (safe == p.name) continue;
      std::cerr << fmt::format("seam: note: {}: a patch name holds control characters; it is written to the OBJ "
                               "file as \"{}\" (each replaced by '_')\n",
                               o->file, safe);
      p.name = safe;
    }
    report::MeshOptions mo;
    mo.samplesPerSpan = o->perSpan;
    // The size of the mesh before it is made: a fine --per-span on a model of many spans is refused with a message,
    // not written as hundreds of megabytes.
    const long long vertices = meshVertices(*model, mo);
    if (vertices > kMaxMeshVertices) {
      printError(fmt::format("{}: --per-span {} would make a mesh of {} vertices (about {} MB of OBJ text), more than "
                             "the limit of {}; use a smaller --per-span",
                             o->file, o->perSpan, vertices, vertices * kObjBytesPerVertex / (1 << 20),
                             kMaxMeshVertices));
      exit = kExitBadInput;
      return;
    }
    const Result<std::string> obj = report::objMesh(*model, mo);
    if (!obj) {
      printError(fmt::format("{}: {}", o->file, obj.status().message()));
      exit = kExitBadInput;
      return;
    }
    if (!writeOutputFile(o->out, *obj)) {
      exit = kExitBadInput;
      return;
    }
    fmt::print("wrote {} ({} patches)\n", o->out, model->patches.size());
    exit = kExitOk;
  });
}

}  // namespace

static CommandRegistrar registerReport("report", addReport);
static CommandRegistrar registerExportMesh("export-mesh", addExportMesh);

}  // namespace seam::cli
