#pragma once
// B-spline and NURBS curves of any degree and dimension. Rational curves are handled in homogeneous coordinates:
// every knot operation acts on (w P, w) and is exact up to round-off.
#include <string>
#include <vector>

#include "seam/core/knot_vector.h"
#include "seam/core/result.h"
#include "seam/core/types.h"
#include "seam/spline/bezier.h"

namespace seam {

/// A Bezier piece of a B-spline curve with the parameter interval it covers.
struct BezierCurvePiece {
  BezierCurve curve;
  Interval interval;
};

class BSplineCurve {
 public:
  BSplineCurve() = default;
  /// Validates everything (sizes, finite values, knots, positive weights) and says what is wrong.
  static Result<BSplineCurve> create(int degree, std::vector<double> knots, Matrix points, VecX weights = {});
  /// Unchecked: the caller guarantees validity (asserted in debug builds).
  BSplineCurve(int degree, KnotVector knots, Matrix points, VecX weights = {});
  /// From homogeneous control points (last column = weight) when `rational`, else from plain points.
  static BSplineCurve fromHomogeneous(int degree, KnotVector knots, const Matrix& homogeneous, bool rational);

  [[nodiscard]] int degree() const { return p_; }
  [[nodiscard]] const KnotVector& knots() const { return knots_; }
  [[nodiscard]] int numPoints() const { return static_cast<int>(points_.rows()); }
  [[nodiscard]] int dim() const { return static_cast<int>(points_.cols()); }
  [[nodiscard]] bool isRational() const { return weights_.size() > 0; }
  [[nodiscard]] const Matrix& points() const { return points_; }
  [[nodiscard]] const VecX& weights() const { return weights_; }
  /// (w P, w) rows when rational, else the points.
  [[nodiscard]] Matrix homogeneous() const;
  [[nodiscard]] Interval domain() const { return knots_.domain(p_); }

  [[nodiscard]] VecX evaluate(double t) const;
  /// The point at t of a curve with dim() >= 3 (its first three coordinates), without heap allocation.
  [[nodiscard]] Vec3 point3(double t) const;
  /// C(t), C'(t), C''(t) (first three coordinates; dim() >= 3; rational: quotient rule), without heap allocation.
  void derivatives2(double t, Vec3& c, Vec3& d1, Vec3& d2) const;
  /// C(t) and C'(t) of a plane curve (dim() == 2; rational: quotient rule) without heap allocation: the same
  /// values, bit for bit, as rows 0 and 1 of derivatives(t, 1) (the same operations in the same order).
  void derivatives1(double t, Vec2& c, Vec2& d1) const;
  /// Rows 0..order: C(t), C'(t), ..., C^(order)(t) (rational: quotient-rule recursion, NURBS Book A4.2).
  [[nodiscard]] Matrix derivatives(double t, int order) const;

  /// Inserts t `times` times (Boehm). The result's multiplicity of t is capped at degree (interior) / degree+1.
  [[nodiscard]] BSplineCurve withKnotInserted(double t, int times = 1) const;
  /// Inserts all of `newKnots` (non-decreasing, inside the domain).
  [[nodiscard]] BSplineCurve refined(const std::vector<double>& newKnots) const;
  /// The Bezier pieces (one per non-empty knot span) with their intervals.
  [[nodiscard]] std::vector<BezierCurvePiece> bezierPieces() const;
  /// The same curve with degree raised by `by` (interior multiplicities rise by `by`).
  [[nodiscard]] BSplineCurve degreeElevated(int by) const;
  /// The same point set traversed backwards: C*(t) = C(a + b - t) on the same domain [a,b].
  [[nodiscard]] BSplineCurve reversed() const;
  /// Affine reparametrisation to the domain [a,b].
  [[nodiscard]] BSplineCurve reparametrized(double a, double b) const;

 private:
  int p_ = 0;
  KnotVector knots_;
  Matrix points_;
  VecX weights_;
};

namespace detail {
/// Generic knot algorithms on rows of coefficients (any number of columns): used for curves and for each
/// parameter direction of surfaces. Knots and rows are updated in place.
void insertKnot(int degree, std::vector<double>& knots, Matrix& rows, double t, int times);
void refineKnots(int degree, std::vector<double>& knots, Matrix& rows, const std::vector<double>& newKnots);
/// Knots and rows after raising the degree by `by` (exact: Bezier decomposition, elevation, and a consistent
/// least-squares return to the smoothest spline space, verified to round-off).
void elevateDegree(int degree, std::vector<double>& knots, Matrix& rows, int by);
/// Bezier decomposition: knots become full multiplicity; returns the non-empty span intervals.
std::vector<Interval> decompose(int degree, std::vector<double>& knots, Matrix& rows);
}  // namespace detail

}  // namespace seam
