#pragma once
// The B-rep check of a shape already in memory: checkBRepFile's work after reading (the B-rep heal checks the
// shape it is about to write, before and after each change).
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <TopoDS_Edge.hxx>
#include <TopoDS_Shape.hxx>

#include "occt/cad_internal.h"
#include "seam/occt/brep_check.h"

namespace seam::occt::detail {

/// Checks `shape` as checkBRepFile checks the shape it reads from `file` (which names the model in messages and
/// warnings): `labels` give the faces' entities, `units` the file's unit, `readWarnings` come first in the
/// report's warnings. Faces are named "F<n>" in TopExp::MapShapes order, edges numbered in the edge map's order.
/// `onlyEdges`, when given, selects the edges analysed (the others are left out of the report: the heal checks again
/// only the edges its changes can reach).
using EdgeFilter = std::function<bool(const TopoDS_Edge&)>;
Result<BRepCheckReport> checkBRepShape(const TopoDS_Shape& shape, const std::filesystem::path& file,
                                       FaceLabels labels, const FileUnits& units,
                                       const std::vector<std::string>& readWarnings,
                                       const BRepCheckOptions& options, const EdgeFilter& onlyEdges = {});

}  // namespace seam::occt::detail
