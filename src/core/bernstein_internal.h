#pragma once
// Private: allocation-free views of Bernstein coefficients for the hot loops of the certified bounds.
#include <vector>

#include "seam/core/bernstein.h"

namespace seam::detail {

/// The coefficients of p restricted to [a, b], exactly as p.restricted(a, b).coeffs() (the same arithmetic, so the
/// same bits), without allocating: written to `scratch` (grown when too small, never shrunk), or a view of p's own
/// coefficients for [0, 1]. The view is valid until `scratch` or p changes.
Eigen::Map<const Matrix> restrictedCoeffs(const BernsteinPoly& p, double a, double b, std::vector<double>& scratch);

}  // namespace seam::detail
