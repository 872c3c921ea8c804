#pragma once
// Private: allocation-free views of Bernstein coefficients for the hot loops of the certified bounds.
#include <vector>

#include "seam/core/bernstein.h"

namespace seam::detail {

/// The coefficients of p restricted to [a, b], exactly as p.restricted(a, b).coeffs() (the same arithmetic, so the
/// same bits), without allocating: written to `scratch` (grown when too small, never shrunk), or a view of p's own
/// coefficients for [0, 1]. The view is valid until `scratch` or p changes.
Eigen::Map<const Matrix> restrictedCoeffs(const BernsteinPoly& p, double a, double b, std::vector<double>& scratch);

/// Both halves at 1/2 of the Bernstein coefficients `c` ((n + 1) rows of d values, row-major) from one de Casteljau
/// triangle: `left` gets the coefficients on [0, 1/2], `right` those on [1/2, 1] (each (n + 1) * d values; neither
/// may overlap c). Each value is one rounding of 0.5 a + 0.5 b per level, so the halves agree with
/// restrictedCoeffs(p, 0, 1/2) and (1/2, 1) to round-off, not bit for bit.
void splitHalves(const double* c, Eigen::Index n, Eigen::Index d, double* left, double* right);

/// The minimum of a scalar polynomial on [0,1], certified: `lower` <= min p <= `attained` = p(at). Branch and bound on
/// the Bernstein coefficients (their minimum bounds p from below on each piece, the end coefficients are values);
/// pieces are split until their bound is within `tolAbs` of the best value found (or at depth `maxDepth`).
struct CertifiedMin {
  double lower = 0.0, attained = 0.0, at = 0.0;
};
CertifiedMin certifiedMinimum(const BernsteinPoly& p, double tolAbs, int maxDepth = 40);

}  // namespace seam::detail
