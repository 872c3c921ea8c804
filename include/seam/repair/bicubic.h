#pragma once
// C1 bicubic B-spline surfaces in the sense of Lai-Lian-Cassidy (docs/algorithms/lai-lian-cassidy.md, §2 of the
// paper): degree 3 in both directions, 4-fold end knots, every interior knot exactly double. Such a surface is a net
// of m x n bicubic Bezier patches, and the paper's conversions between its de Boor points d_{i,j} and the per-patch
// Bezier coefficients c_{i,j,k,l} (§2.2, eq. (2.12); §2.3, eqs. (2.13)-(2.18)) are implemented here literally.
//
// Indexing. The paper numbers knots u_0..u_{2m+5}, breakpoints u_2 < u_4 < ... < u_{2m+2}, spans i = 1..m and de Boor
// points d_0..d_{2m+1}. Here breakpoints are b_0 < ... < b_m (b_k = u_{2k+2}), spans and patches are 0-based
// (patch (i, j) of this header is the paper's (i+1, j+1)), de Boor points keep the paper's numbering (0..2m+1).
#include <vector>

#include "seam/core/knot_vector.h"
#include "seam/core/result.h"
#include "seam/core/tolerances.h"
#include "seam/core/types.h"
#include "seam/spline/bspline_surface.h"

namespace seam {

/// Checks the structure of a C1 cubic knot vector (2.1): 4-fold ends, every interior knot exactly double (knots
/// closer than kKnotRelTol x the knot-vector length are one knot, as in KnotVector).
/// Errors: kUnsupported with a message saying which knot breaks the pattern.
Status checkC1CubicKnots(const KnotVector& knots);

/// ok when `s` is a polynomial C1 bicubic B-spline in the paper's sense (degree (3,3), knots as in (2.1)/(2.3)).
/// Errors: kUnsupported (rational, other degree, other multiplicities) with the reason.
Status checkC1Bicubic(const BSplineSurface& s);

/// The breakpoints b_0 < ... < b_m of a C1 cubic knot vector (m = number of spans).
std::vector<double> c1CubicBreakpoints(const KnotVector& knots);

/// alpha_i of (2.7), i = 0..m: alpha_i = (u_{2i+4} - u_{2i+2}) / (u_{2i+4} - u_{2i}), so alpha_0 = 1, alpha_m = 0 and,
/// at an interior breakpoint b_i with neighbouring spans h_i = b_i - b_{i-1}, h_{i+1} = b_{i+1} - b_i,
/// alpha_i = h_{i+1} / (h_i + h_{i+1}). beta_i = 1 - alpha_i. The Bezier junction point at b_i is
/// alpha_i d_{2i} + beta_i d_{2i+1}.
std::vector<double> c1CubicAlphas(const KnotVector& knots);

/// The Bezier coefficients of a C1 bicubic B-spline surface, one 4 x 4 block per polynomial patch.
struct BicubicBezierNet {
  int m = 0;                          ///< patches along u
  int n = 0;                          ///< patches along v
  std::vector<double> breaksU;        ///< b_0..b_m
  std::vector<double> breaksV;        ///< b_0..b_n
  /// patches[i * n + j]: 16 x dim, row k * 4 + l = c_{i,j,k,l} (k along u, l along v), 0-based patch (i, j).
  std::vector<Matrix> patches;

  [[nodiscard]] const Matrix& patch(int i, int j) const { return patches[static_cast<size_t>(i * n + j)]; }
  Matrix& patch(int i, int j) { return patches[static_cast<size_t>(i * n + j)]; }
};

/// §2.2: the Bezier coefficients from the de Boor points by the paper's explicit formulas (arrays h, v, a and the
/// unified form (2.12)). Errors: those of checkC1Bicubic.
Result<BicubicBezierNet> c1BicubicToBezier(const BSplineSurface& s);

/// §2.3: the de Boor points from Bezier coefficients by (2.15)-(2.18), after checking the C1 conditions (2.13) along
/// the interior u-lines and (2.14) along the interior v-lines to `relTol` x (coefficient scale; default
/// kIdentityRelTol, the level at which seam calls a polynomial identity exact).
/// Errors: kInvalidInput for an inconsistent net (sizes, breakpoints), kNoSolution when (2.13)/(2.14) fail (the
/// message names the first failing grid line and the size of the violation).
Result<BSplineSurface> c1BicubicFromBezier(const BicubicBezierNet& net, double relTol = kIdentityRelTol);

/// The C1 cubic knot vector (2.1) with the given breakpoints (4-fold ends, double interior knots).
KnotVector c1CubicKnots(const std::vector<double>& breakpoints);

}  // namespace seam
