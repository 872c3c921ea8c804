#pragma once
// The HTML report of a model (`seam report FILE`, Python `seam.report`): the page's units, and for a STEP/IGES file
// the B-rep check's page (every shared edge, OpenCASCADE's verdict alongside, trimmed faces shaded from
// OpenCASCADE's triangulation), one builder for the CLI and the Python module (docs/report.md).
#include <cstddef>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "seam/continuity/seam.h"
#include "seam/core/result.h"
#include "seam/core/tolerances.h"
#include "seam/core/units.h"
#include "seam/model/model.h"
#include "seam/report/report.h"

namespace seam::cli {

/// Sets the page's length unit, where it comes from and where the distance tolerance comes from.
void setReportUnits(report::ReportData& d, const ModelUnits& units, const ResolvedTolerances& tol);

/// A STEP/IGES file's report page.
struct BRepReportPage {
  std::string html;
  size_t seams = 0;                           ///< B-rep seams (edges shared by two faces)
  GeometricClass worst = GeometricClass::kG2;
  std::vector<std::string> warnings;          ///< the reader's and the check's warnings
};

/// True in a build with OpenCASCADE (SEAM_HAVE_OCCT), where brepReportPage reads STEP/IGES files.
bool hasBRepReport();

/// The report page of a STEP/IGES file: occt::checkBRepFile with the tolerances `tol` (--tol-* / --preset /
/// --units) and `options.view3d`'s face meshes; with `model` (a JSON model with its B-rep topology, Model::brep,
/// read from `file`), occt::checkBRepModel of it instead, as `seam check` of that JSON. Errors: the file cannot be
/// read, is not STEP/IGES, or OpenCASCADE failed on it (the message names the file); without OpenCASCADE, always an
/// error.
Result<BRepReportPage> brepReportPage(const std::filesystem::path& file, const ToleranceOverrides& tol,
                                      const report::HtmlReportOptions& options,
                                      const std::function<void(int, int, int)>& progress = {},
                                      const Model* model = nullptr);

}  // namespace seam::cli
