#pragma once
// Bezier curves and patches as first-class types (polynomial or rational), with exact conversion to and from
// single-span B-splines.
#include "seam/core/bernstein.h"
#include "seam/core/types.h"

namespace seam {

class BSplineCurve;
class BSplineSurface;

/// A Bezier curve on [0,1]. Rational when weights are present: C(t) = sum w_i P_i B_i / sum w_i B_i.
class BezierCurve {
 public:
  BezierCurve() = default;
  /// points: (n+1) x dim. weights: empty (polynomial) or n+1 positive values.
  explicit BezierCurve(Matrix points, VecX weights = {});

  [[nodiscard]] int degree() const { return static_cast<int>(points_.rows()) - 1; }
  [[nodiscard]] int dim() const { return static_cast<int>(points_.cols()); }
  [[nodiscard]] bool isRational() const { return weights_.size() > 0; }
  [[nodiscard]] const Matrix& points() const { return points_; }
  [[nodiscard]] const VecX& weights() const { return weights_; }
  /// Homogeneous polynomial (w P, w) of dimension dim()+1 when rational, else the polynomial P itself.
  [[nodiscard]] BernsteinPoly homogeneous() const;
  /// The polynomial P (dimension dim()); for a rational curve the numerator w P without the weight.
  [[nodiscard]] BernsteinPoly numerator() const;
  /// The denominator w (scalar; constant 1 for a polynomial curve).
  [[nodiscard]] BernsteinPoly denominator() const;
  [[nodiscard]] VecX evaluate(double t) const;
  /// Rows 0..order: the point and derivatives at t (rational: quotient rule).
  [[nodiscard]] Matrix derivatives(double t, int order) const;
  /// Exact single-span B-spline on [a, b].
  [[nodiscard]] BSplineCurve toBSpline(double a = 0.0, double b = 1.0) const;
  /// Builds from homogeneous coefficients (last column = weight) of dimension dim+1.
  static BezierCurve fromHomogeneous(const BernsteinPoly& h);

 private:
  Matrix points_;
  VecX weights_;
};

/// A tensor-product Bezier patch on [0,1]^2. points: (n+1)(m+1) x dim, row i*(m+1)+j (i along u).
class BezierPatch {
 public:
  BezierPatch() = default;
  BezierPatch(int degreeU, int degreeV, Matrix points, VecX weights = {});

  [[nodiscard]] int degreeU() const { return du_; }
  [[nodiscard]] int degreeV() const { return dv_; }
  [[nodiscard]] int dim() const { return static_cast<int>(points_.cols()); }
  [[nodiscard]] bool isRational() const { return weights_.size() > 0; }
  [[nodiscard]] const Matrix& points() const { return points_; }
  [[nodiscard]] const VecX& weights() const { return weights_; }
  [[nodiscard]] auto point(int i, int j) const { return points_.row(i * (dv_ + 1) + j); }
  [[nodiscard]] double weight(int i, int j) const { return isRational() ? weights_[i * (dv_ + 1) + j] : 1.0; }
  [[nodiscard]] BernsteinPatch homogeneous() const;
  [[nodiscard]] BernsteinPatch numerator() const;
  [[nodiscard]] BernsteinPatch denominator() const;
  [[nodiscard]] VecX evaluate(double u, double v) const;
  /// out[k][l] = d^{k+l} S / du^k dv^l for k + l <= order.
  [[nodiscard]] std::vector<std::vector<VecX>> derivatives(double u, double v, int order) const;
  [[nodiscard]] BSplineSurface toBSpline(Interval u = {}, Interval v = {}) const;
  static BezierPatch fromHomogeneous(const BernsteinPatch& h);

 private:
  int du_ = 0;
  int dv_ = 0;
  Matrix points_;
  VecX weights_;
};

}  // namespace seam
