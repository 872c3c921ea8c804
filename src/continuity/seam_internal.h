#pragma once

#include <optional>

#include "seam/continuity/seam.h"

namespace seam::detail {

/// analyzeSeam with the patches' control-box diagonals given (controlBox(surface).diagonal() of a and b, the seam's
/// scale): checkModel computes them once per patch instead of once per seam. The same report, bit for bit.
Result<SeamReport> analyzeSeamScaled(const Patch& a, Edge ea, const Patch& b, Edge eb, const SeamOptions& options,
                                     std::optional<Interval> aRange, double patchDiagA, double patchDiagB);

}  // namespace seam::detail
