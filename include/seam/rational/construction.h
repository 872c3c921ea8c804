#pragma once
// Theorem 6 of Zheng-Wang-Liang with sigma = 0 (eq. 4.8): given a rational Bezier patch r and shape parameters,
// the first n+1 columns of control points of a patch rbar that meets r with GC^n along r(1, v) = rbar(0, v).
// docs/algorithms/zheng-wang-liang.md re-derives (4.8) (the extracted text is damaged) and relates it to the bicubic
// GC^1 formulas at the end of Section 4.2.
//
// With D = 1, c_s = gamma_s, p_s = alpha_s, q_s(v) = beta_s^0 (1 - v) + beta_s^1 v in (4.6) (Case 1: Qbar = Q on the
// edge), the cross derivatives of Qbar are fixed, s = 1..n:
//   d^s Qbar/dubar^s (0, v) = gamma_s Q + sum_{d=1}^s C(s,d) gamma_{s-d} sum_{k,r,h} A^{dkh}_r alpha_r1..alpha_rh
//                             q_{r_h+1}(v)..q_{r_k}(v) d^k Q / du^h dv^{k-h} (1, v)        (gamma_0 = 1)
// and (4.8) writes them in control points (homogeneous Qbar_{s,i} = (w P, w)).
#include <optional>
#include <vector>

#include "seam/core/bernstein.h"
#include "seam/core/result.h"
#include "seam/spline/bspline_surface.h"

namespace seam::rational {

/// The shape parameters of (4.8), one entry per order s = 1..n (all four vectors of the same length n).
struct ShapeParameters {
  std::vector<double> gamma;  ///< gamma_s = c_s (the weight-scaling connecting function); gamma_0 = 1 is implied
  std::vector<double> alpha;  ///< alpha_s = p_s; alpha_1 != 0 (alpha_1 > 0 for a proper join; < 0 folds back)
  std::vector<double> beta0;  ///< q_s(v) = beta0_s (1 - v) + beta1_s v
  std::vector<double> beta1;
  [[nodiscard]] int order() const { return static_cast<int>(gamma.size()); }
};

/// (4.8): the first n+1 columns Qbar_{s,i}, s = 0..n, i = 0..l, of the homogeneous control net of rbar (degree
/// mbar along ubar, l along v) for the homogeneous Bezier patch q (degree m x l, any dimension; the edge is u = 1).
/// Rows s * (l + 1) + i. Errors (kInvalidInput): parameter vectors of different lengths, n > kMaxGcnOrder,
/// mbar < n, alpha_1 = 0, non-finite values.
Result<Matrix> gcnColumns(const BernsteinPatch& q, const ShapeParameters& shape, int mbar);

struct ExtensionOptions {
  /// mbar, the degree of rbar across the edge; -1: max(m, n).
  int degree = -1;
  /// Columns n+1..mbar of rbar as homogeneous control points ((mbar - n)(l + 1) rows, row (s - n - 1)(l + 1) + i,
  /// (w P, w)). Default (empty): the reflected copy of q (elevated to mbar when m < mbar): Cartesian points
  /// 2 P_{M,i} - P_{M-s,i} with the mirrored weights w_{M-s,i} (M the u-degree of the elevated q), which keeps
  /// every weight positive.
  std::optional<Matrix> remainingColumns;
};

/// The whole rbar in the paper's frame (edge ubar = 0), homogeneous of dimension 4: the (4.8) columns and the
/// remaining ones. q: homogeneous (w P, w) of dimension 4. Errors: those of gcnColumns; kInvalidInput for a
/// remainingColumns of the wrong size; kNoSolution when a weight of rbar is not positive (other shape parameters
/// are needed), naming the control point.
Result<BernsteinPatch> extendBezier(const BernsteinPatch& q, const ShapeParameters& shape,
                                    const ExtensionOptions& options = {});

/// The construction on a model surface: rbar is attached to edge `e` of `surface`. r is the Bezier piece of
/// `surface` at the edge (the edge must be a single Bezier span: kUnsupported otherwise). The result is a Bezier
/// patch whose edge u0 lies on e, with v along e's own parameter; its domain is [0, h] x (e's domain), h the width of
/// the span of `surface` next to e, so that alpha_1 = 1, gamma = beta = 0 continues `surface` with C^1 in the
/// patches' own parameters. Polynomial when every weight of rbar is 1, else rational.
Result<BSplineSurface> extendSurface(const BSplineSurface& surface, Edge e, const ShapeParameters& shape,
                                     const ExtensionOptions& options = {});

}  // namespace seam::rational
