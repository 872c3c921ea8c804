#pragma once
// Surfaces for the rational GC^n analysis (Zheng, Wang & Liang, CAGD 1995; docs/algorithms/zheng-wang-liang.md):
// a rational surface r = R / w is handled through its homogeneous surface Q = (R, w) : R^2 -> R^4 (eq. 2.7 with
// rho = 1) and the partial derivatives of Q up to some order. Three sources are provided: B-spline / NURBS surfaces
// of the kernel (exact basis derivatives), C++ callables (forward-mode automatic differentiation,
// seam/rational/autodiff_surface.h) and symbolic expressions (seam/rational/expression.h).
#include <functional>
#include <string>
#include <vector>

#include "seam/core/result.h"
#include "seam/core/types.h"
#include "seam/spline/bspline_surface.h"

namespace seam::rational {

/// d[a][b] = d^{a+b} Q / du^a dv^b at one point, for a + b <= order (d[a] holds order - a + 1 entries).
using DerivativeTable = std::vector<std::vector<Vec4>>;

/// A homogeneous surface Q(u, v) in R^4 with its partial derivatives. A value type (cheap to copy: the evaluator
/// shares its state).
class HomogeneousSurface {
 public:
  /// Fills all partial derivatives of total order <= `order` at (u, v); an error names the surface and the point
  /// (e.g. an expression that is not finite there).
  using Evaluator = std::function<Result<DerivativeTable>(double u, double v, int order)>;

  HomogeneousSurface() = default;
  /// `maxOrder`: the highest derivative order the evaluator supports.
  HomogeneousSurface(std::string name, Interval domainU, Interval domainV, int maxOrder, Evaluator evaluator);

  [[nodiscard]] const std::string& name() const { return name_; }
  [[nodiscard]] Interval domainU() const { return u_; }
  [[nodiscard]] Interval domainV() const { return v_; }
  [[nodiscard]] int maxOrder() const { return maxOrder_; }
  [[nodiscard]] bool empty() const { return !eval_; }

  /// All partial derivatives up to `order` at (u, v). kInvalidInput when order > maxOrder() or order < 0, or
  /// the evaluator's error.
  [[nodiscard]] Result<DerivativeTable> derivatives(double u, double v, int order) const;
  /// The Cartesian point R / w at (u, v) (kDegenerate where w = 0).
  [[nodiscard]] Result<Vec3> point(double u, double v) const;

  /// The same surface in an edge frame (a, b) -> (u, v), an axis-aligned affine map with a = 0 on edge `e` and b
  /// the original parameter along the edge (v for U0/U1, u for V0/V1). `outward` = true: a increases away from the
  /// patch (a <= 0 inside, so Q_a = -d/dn is the outward cross derivative, the paper's Q_u at u = 1); false: a
  /// increases into the patch (a >= 0 inside, the paper's Qbar_ubar at ubar = 0). Domain: a over the patch's
  /// width across the edge, b over the edge.
  [[nodiscard]] HomogeneousSurface edgeFrame(Edge e, bool outward) const;

  /// The surface whose Cartesian points are (r - center) / scale (R' = (R - center w) / scale, w' = w): an affine
  /// map of space, under which GC^n is invariant; used to balance point and weight coordinates.
  [[nodiscard]] HomogeneousSurface normalized(const Vec3& center, double scale) const;

 private:
  std::string name_;
  Interval u_, v_;
  int maxOrder_ = 0;
  Evaluator eval_;
};

/// The homogeneous surface (w P, w) of a B-spline / NURBS surface (P, 1 when polynomial); derivatives of every
/// order from the basis-function derivatives (zero beyond the degree). At a knot the span to the right is used
/// (the last span at the upper end of the domain). The surface is captured by value.
HomogeneousSurface homogeneousSurface(const BSplineSurface& surface, std::string name);

}  // namespace seam::rational
