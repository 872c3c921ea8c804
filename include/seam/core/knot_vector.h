#pragma once
// Knot vectors of B-splines: validation, span search, multiplicities, breakpoints, reparametrisation.
#include <span>
#include <vector>

#include "seam/core/result.h"
#include "seam/core/types.h"

namespace seam {

class KnotVector {
 public:
  KnotVector() = default;
  explicit KnotVector(std::vector<double> knots) : t_(std::move(knots)) {}

  [[nodiscard]] const std::vector<double>& values() const { return t_; }
  [[nodiscard]] int size() const { return static_cast<int>(t_.size()); }
  double operator[](int i) const { return t_[static_cast<size_t>(i)]; }

  /// Checks the knot vector of a B-spline of `degree` with `numPoints` control points: finite values,
  /// non-decreasing, size == numPoints + degree + 1, interior multiplicities <= degree, end multiplicities
  /// <= degree + 1, and a non-empty domain [t_degree, t_numPoints]. The message says what is wrong.
  [[nodiscard]] Status validate(int degree, int numPoints) const;

  /// The parameter domain [t_p, t_n] of a B-spline of degree p with n = size() - p - 1 control points.
  [[nodiscard]] Interval domain(int degree) const;
  /// The index k with t_k <= t < t_{k+1}, restricted to the domain spans p <= k <= n - 1 (t at or beyond the
  /// right end of the domain returns the last non-empty span; t before the left end the first).
  [[nodiscard]] int findSpan(int degree, double t) const { return findSpan(t_, degree, t); }
  /// findSpan of the knot vector `knots` (without copying it into a KnotVector).
  [[nodiscard]] static int findSpan(std::span<const double> knots, int degree, double t);
  /// How many knots equal t (within kKnotRelTol of the knot-vector length).
  [[nodiscard]] int multiplicity(double t) const;
  /// Distinct knot values in increasing order, and their multiplicities.
  [[nodiscard]] std::vector<double> breakpoints() const;
  [[nodiscard]] std::vector<int> multiplicities() const;
  /// Distinct knot values strictly inside the domain of a degree-p B-spline.
  [[nodiscard]] std::vector<double> interiorBreakpoints(int degree) const;
  /// Knots mapped by the affine map that sends the domain [t_p, t_n] onto [a, b] (a < b).
  [[nodiscard]] KnotVector reparametrized(int degree, double a, double b) const;
  /// Knots of the reversed parametrisation t -> a + b - t, where [a,b] = domain(degree) (the domain maps onto
  /// itself).
  [[nodiscard]] KnotVector reversed(int degree) const;
  /// Clamped uniform knot vector on [a,b] for n points of the given degree.
  static KnotVector clampedUniform(int degree, int numPoints, double a = 0.0, double b = 1.0);
  /// Bezier knots: degree+1 copies of a then of b.
  static KnotVector bezier(int degree, double a = 0.0, double b = 1.0);

 private:
  std::vector<double> t_;
};

/// Values of the degree+1 non-zero B-spline basis functions and their derivatives up to `order` at t in span
/// `span`: out(k, r) = d^k/dt^k N_{span-degree+r, degree}(t). (The NURBS Book, A2.3.)
Matrix basisFunctionDerivatives(const KnotVector& knots, int degree, int span, double t, int order);

}  // namespace seam
