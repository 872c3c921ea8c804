#pragma once
// The B-rep topology of a model (Model::brep, include/seam/model/brep.h) through OpenCASCADE (issue 34 §1):
// made from a STEP/IGES shape by readCadFile, made into a shape again for STEP/IGES output and for the B-rep
// check of a JSON model with trimmed faces.
#include <filesystem>

#include "seam/core/result.h"
#include "seam/model/model.h"
#include "seam/occt/brep_check.h"
#include "seam/occt/cad_io.h"

namespace seam::occt {

/// What writeBRepCadFile wrote (counted by OpenCASCADE on the shape made from the topology; the file, read
/// back, has the same faces, trimmed faces, solids and area, else nothing is written).
struct BRepWriteReport {
  int faces = 0, trimmedFaces = 0, edges = 0, freeEdges = 0, shells = 0, solids = 0;
  double area = 0.0;
  bool valid = false;  ///< BRepCheck_Analyzer on the shape made
  std::vector<std::string> warnings;
};

/// Writes a model with a B-rep topology (model.brep must be set) as STEP (AP214) or IGES: the shape made from
/// the topology (every face on its patch, bounded by its loops of pcurves, edges shared, shells and solids),
/// through the XDE writer of convertCadFile, in millimetres, read back and compared (faces, trimmed faces,
/// solids, area), written atomically. Errors (kInvalidInput) name `file` and the face or edge OpenCASCADE
/// refuses.
Result<BRepWriteReport> writeBRepCadFile(const Model& model, const std::filesystem::path& file,
                                         CadFormat format);

/// `seam check` of a model with a B-rep topology: the shape made from it is checked as checkBRepFile checks a
/// STEP/IGES file (every shared edge through its pcurves; faces named "F<n>" in the order of the topology's
/// faces, which readCadFile keeps from the file). `file` names the model in messages. The model is taken to
/// be in millimetres (as a JSON written from STEP/IGES is) unless options.tolerances.units says otherwise.
Result<BRepCheckReport> checkBRepModel(const Model& model, const std::filesystem::path& file,
                                       const BRepCheckOptions& options = {});

}  // namespace seam::occt
