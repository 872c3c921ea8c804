// STEP/IGES -> STEP/IGES conversion keeping the B-rep (issue 34 §1), with the seams of the file written and read
// back compared with the input's (issue 34: a conversion never makes a seam worse silently).
#include <fmt/format.h>

#include <Standard_ErrorHandler.hxx>
#include <Standard_Failure.hxx>
#include <TDocStd_Document.hxx>
#include <TopoDS_Shape.hxx>
#include <optional>

#include "occt/brep_check_internal.h"
#include "occt/cad_internal.h"
#include "seam/occt/cad_io.h"

namespace seam::occt {

namespace fs = std::filesystem;

Result<CadConvertReport> convertCadFile(const fs::path& in, const fs::path& out, const CadReadOptions& options,
                                        const CadConvertOptions& convert) {
  const std::optional<CadFormat> inFormat = cadFormatOf(in), outFormat = cadFormatOf(out);
  if (!inFormat || !outFormat)
    return invalidInput(fmt::format("{} -> {}: the B-rep conversion is from STEP/IGES to STEP/IGES", in.string(),
                                    out.string()));
  CadConvertReport report;
  detail::FileUnits units;
  units.statedUnitMm = options.statedUnitMm;
  const Handle(TDocStd_Document) doc = detail::newCadDocument();
  detail::FaceLabels labels;
  Result<TopoDS_Shape> shape =
      detail::readShape(in, *inFormat, &report.warnings, detail::kTransferTimeLimit, &labels, &units, &doc);
  if (!shape) return shape.status();
  report.units = units.units;
  if (units.units.statedScale != 1.0)
    return invalidInput(fmt::format("{}: --units rescales the model; the B-rep conversion keeps the file's own "
                                    "coordinates and unit ({}), so it takes no --units",
                                    in.string(), units.units.fileUnit.empty() ? "MM" : units.units.fileUnit));
  {
    detail::OcctSignalGuard guard;
    try {
      OCC_CATCH_SIGNALS
      detail::setCounts(report, detail::countShape(*shape));
    } catch (const Standard_Failure& f) {
      return invalidInput(fmt::format("{}: OpenCASCADE {} measuring the model: {}", in.string(),
                                      detail::isSignal(f) ? "crashed" : "failed", f.GetMessageString()));
    }
  }
  if (report.faces == 0) return invalidInput(fmt::format("{}: the file holds no face to convert", in.string()));
  report.writtenUnit = detail::cadUnitName(units.units.millimetresPerFileUnit, *outFormat);
  detail::ShapeCounts expected;
  expected.faces = report.faces;
  expected.trimmedFaces = report.trimmedFaces;
  expected.solids = report.solids;
  expected.area = report.area;
  // The seams of the input, checked before writing (the reader of the written file hands back its own shape).
  std::optional<BRepCheckReport> before;
  BRepCheckOptions co;
  co.tolerances = convert.tolerances;
  co.threads = convert.threads;
  co.sewFreeEdges = false;  // the file's own topology is what is written and compared
  if (convert.compareSeams) {
    Result<BRepCheckReport> checked = detail::checkBRepShape(*shape, in, labels, units, {}, co);
    if (!checked) return checked.status();
    before = std::move(*checked);
  }
  detail::WrittenBack back;
  if (Status st = detail::writeCadDocument(doc, out, *outFormat, report.writtenUnit, expected, &report.warnings, 0.0,
                                           0.0, before ? &back : nullptr);
      !st)
    return st;
  if (before) {
    Result<BRepCheckReport> after = detail::checkBRepShape(back.shape, out, back.labels, back.units, {}, co);
    if (!after) {
      report.warnings.push_back(fmt::format("{}: the written file was not checked again: {}", out.string(),
                                            after.status().message()));
      return report;
    }
    report.seamsCompared = static_cast<int>(after->seams.size());
    for (const detail::SeamWorse& w : detail::seamsWorse(before->seams, after->seams, before->tolerances,
                                                         convert.creaseAngleDeg, before->units))
      report.seamsWorse.push_back(fmt::format(
          "the seam of {} and {} (edge {}) is worse in {} as read back than in {}: {}; OpenCASCADE's writer "
          "keeps the surfaces and 3-D edges bit for bit and its reader builds the trims again from them",
          w.before->a, w.before->b, w.before->edge, out.filename().string(), in.filename().string(), w.why));
  }
  return report;
}

}  // namespace seam::occt
