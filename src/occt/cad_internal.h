#pragma once
// Shared by the OpenCASCADE readers and the B-rep check.
#include <TopoDS_Edge.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Shape.hxx>
#include <filesystem>
#include <optional>
#include <vector>

#include "seam/occt/cad_io.h"

namespace seam::occt::detail {

/// A face's parameter box [u0, u1] x [v0, v1].
struct ParamBox {
  double u0 = 0, u1 = 0, v0 = 0, v1 = 0;
};

/// The side of `box` along which the edge's pcurve on `face` runs (an iso-parameter edge), within
/// kIsoEdgeRelTol of the box size; with `wholeSide`, only when it also runs from one corner of that side to the other.
std::optional<Edge> boxSideOf(const TopoDS_Edge& edge, const TopoDS_Face& face, const ParamBox& box, bool wholeSide);

/// Reads a STEP or IGES file into one shape; errors name the file.
Result<TopoDS_Shape> readShape(const std::filesystem::path& file, CadFormat format);

/// One patch per face, in the given order (faces that fail are skipped with a warning naming them; CadImport::faces
/// stays aligned with the patches, and CadFace::patch is "F<n>" with n the face's 1-based position).
Result<CadImport> convertFaces(const std::filesystem::path& file, const std::vector<TopoDS_Face>& faces,
                               const CadReadOptions& options);

}  // namespace seam::occt::detail
