#pragma once
// The .bpt Bezier-patch text format (Newell tea set files): the number of patches N, then per patch the degrees
// "du dv" and (du+1)(dv+1) points "x y z", row-major (i along u).
//
// Variants found in the wild are read too:
// - '#' starts a comment that runs to the end of its line;
// - the file is read as a stream of whitespace-separated tokens, not lines: the whole file may be on one line, or
//   several points on a line (a point that starts a line needs a line holding whole points, so that a line of
//   two numbers is reported where it is); LF, CRLF or CR line endings;
// - one degree pair "du dv" after N shared by every patch. Rule: the per-patch layout is tried first (it is the
//   usual one); when it does not read and the token count is exactly 3 + 3 N (du+1)(dv+1) for the integers du dv
//   after N, the file is read with shared degrees. For N = 1 both layouts are the same. When neither reads, the
//   message is the one of the reading that got further into the file.
// Errors name the file, the patch and the line ("bad.bpt: patch P0: line 4: "nan" is not a finite number").
#include <filesystem>
#include <string_view>

#include "seam/core/result.h"
#include "seam/model/model.h"

namespace seam::io {

/// Patches are named "P0", "P1", ... in file order and have kind kBezier. kInvalidInput naming the file, the patch
/// and the line for a malformed file.
Result<Model> parseBpt(std::string_view text, std::string_view source);
/// readFile (a regular file of at most kMaxModelFileBytes), then parseBpt; kIoError when the file cannot be read.
Result<Model> readBpt(const std::filesystem::path& file);

}  // namespace seam::io
