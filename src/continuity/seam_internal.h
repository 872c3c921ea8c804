#pragma once

#include <array>
#include <optional>

#include "seam/continuity/seam.h"

namespace seam::detail {

/// analyzeSeam with the patches' control-box diagonals given (controlBox(surface).diagonal() of a and b, the seam's
/// scale): checkModel computes them once per patch instead of once per seam. The same report, bit for bit.
Result<SeamReport> analyzeSeamScaled(const Patch& a, Edge ea, const Patch& b, Edge eb, const SeamOptions& options,
                                     std::optional<Interval> aRange, double patchDiagA, double patchDiagB);

/// Test hook: the seam analysis's cross-derivative rows of s at edge e (orders 0, 1, 2), written into `rows` (its
/// storage reused when the size does not change); bit for bit s.crossDerivativeRows(e, 2).
void sideCrossRows(const BSplineSurface& s, Edge e, Matrix& rows);

/// Test hook: S, S_u, S_v, S_uu, S_uv, S_vv of patch p seen from edge e (the edge is u = 0, v = t runs along it, u
/// into the surface) at edge parameter t, as the seam analysis's samples evaluate them (`fromRight`: the limit from
/// the right at a breakpoint). `fused` false: the generic route (three Bernstein jets) also where polynomial sides
/// of degree 2 to 5 take the fused pass; the two give the same bits.
std::array<Vec3, 6> sideJet(const Patch& p, Edge e, double t, bool fromRight, bool fused);

}  // namespace seam::detail
