#pragma once
// The .bpt Bezier-patch text format (Newell tea set files): first line the number of patches, then per patch a
// line "du dv" and (du+1)(dv+1) lines "x y z", row-major (i along u). CRLF or LF line endings.
#include <filesystem>
#include <string_view>

#include "seam/core/result.h"
#include "seam/model/model.h"

namespace seam::io {

/// Patches are named "P0", "P1", ... in file order and have kind kBezier.
Result<Model> parseBpt(std::string_view text, std::string_view source);
Result<Model> readBpt(const std::filesystem::path& file);

}  // namespace seam::io
