#pragma once
// Model::brep <-> OpenCASCADE shapes (private to seam::occt).
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <TopoDS_Face.hxx>
#include <TopoDS_Shape.hxx>

#include "seam/model/brep.h"
#include "seam/occt/cad_io.h"

namespace seam::occt::detail {

/// The topology of `faces` (the file's faces in TopExp_Explorer order of `shape`, one per patch of `import`,
/// same order). Null with `whyNot` saying why when it cannot be made: a face used twice, a face skipped by
/// the reader, an edge without 3-D curve or pcurve, a pcurve that cannot be carried onto its face's converted
/// patch within the tolerances. Pcurves are kept where the patch has its face's parameterisation (checked by
/// sampling); elsewhere (analytic faces converted to rational patches, approximated faces) each pcurve is
/// fitted again through the points of the face's surface projected onto the patch, and kept only within the
/// edge's tolerance. A patch that is its face's B-spline surface is continued exactly where the face's pcurves
/// run past its bounds (import.model.patches changes; said in `notes`). 3-D curves likewise: converted exactly
/// where the parameterisation is kept (lines, B-splines, Bezier), fitted otherwise (circles, ellipses, ...).
/// `notes` says how many were fitted and their largest error. A face whose wire does not connect and that
/// OpenCASCADE's BRepCheck_Analyzer finds invalid as read is kept as read (BRepFace::openAsRead);
/// `invalidInputFaces` (optional) gets the 1-based indices of those faces.
std::shared_ptr<const BRepTopology> brepFromFaces(const TopoDS_Shape& shape,
                                                  const std::vector<TopoDS_Face>& faces,
                                                  CadImport& import, std::string& whyNot,
                                                  std::vector<std::string>& notes,
                                                  std::vector<int>* invalidInputFaces = nullptr);

/// The shape of model.brep: a compound of its roots (solids, shells, faces), in the topology's order, so that
/// the faces of TopExp::MapShapes are the topology's faces in order (when every face is reached once). Errors
/// name `source` and the face or edge.
Result<TopoDS_Shape> shapeFromBRep(const Model& model, const std::string& source);

}  // namespace seam::occt::detail
