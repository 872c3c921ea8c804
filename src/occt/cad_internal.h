#pragma once
// Shared by the OpenCASCADE readers and the B-rep check.
#include <TopoDS_Face.hxx>
#include <TopoDS_Shape.hxx>
#include <filesystem>
#include <vector>

#include "seam/occt/cad_io.h"

namespace seam::occt::detail {

/// Reads a STEP or IGES file into one shape; errors name the file.
Result<TopoDS_Shape> readShape(const std::filesystem::path& file, CadFormat format);

/// One patch per face, in the given order (faces that fail are skipped with a warning naming them; CadImport::faces
/// stays aligned with the patches, and CadFace::patch is "F<n>" with n the face's 1-based position).
Result<CadImport> convertFaces(const std::filesystem::path& file, const std::vector<TopoDS_Face>& faces,
                               const CadReadOptions& options);

}  // namespace seam::occt::detail
