#pragma once
// File helpers shared by every reader and writer.
#include <filesystem>
#include <string>

#include "seam/core/result.h"
#include "seam/model/model.h"

namespace seam::io {

/// Reads a whole file; kIoError naming the file when it cannot be read.
Result<std::string> readFile(const std::filesystem::path& file);
/// Writes `content` to a temporary file next to `file`, then renames it over `file` (never a partial file).
Status writeFileAtomically(const std::filesystem::path& file, const std::string& content);
/// Reads a model by extension: .json, .bpt (Newell Bezier patch text format); later .step/.stp/.iges/.igs.
Result<Model> readModel(const std::filesystem::path& file);

}  // namespace seam::io
