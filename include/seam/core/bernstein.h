#pragma once
// Bernstein-form polynomial algebra on [0,1], univariate and tensor-product, scalar- or vector-valued.
// This is the exact algebra every seam algorithm is written in: products, elevation, subdivision, restriction,
// composition, derivatives and coefficient bounds never leave Bernstein form.
#include <utility>

#include "seam/core/types.h"

namespace seam {

/// p(t) = sum_i c_i B_i^n(t), t in [0,1]. Coefficients: (n+1) x dim matrix, one row per coefficient.
class BernsteinPoly {
 public:
  BernsteinPoly() = default;
  explicit BernsteinPoly(Matrix coefficients);
  /// The zero polynomial of the given degree and dimension.
  static BernsteinPoly zero(int degree, int dim);
  /// A constant (all coefficients equal to `value`) written with degree `degree`.
  static BernsteinPoly constant(const VecX& value, int degree = 0);
  static BernsteinPoly constant(double value, int degree = 0);
  /// The linear scalar polynomial a + (b - a) t.
  static BernsteinPoly linear(double a, double b);
  /// Scalar polynomial from power-basis coefficients a_0 + a_1 t + ... (exact change of basis).
  static BernsteinPoly fromPowerBasis(const VecX& a);

  [[nodiscard]] int degree() const { return static_cast<int>(c_.rows()) - 1; }
  [[nodiscard]] int dim() const { return static_cast<int>(c_.cols()); }
  [[nodiscard]] bool empty() const { return c_.size() == 0; }
  [[nodiscard]] const Matrix& coeffs() const { return c_; }
  Matrix& coeffs() { return c_; }

  /// Value at t (de Casteljau; stable for t in [0,1], valid for any t).
  [[nodiscard]] VecX operator()(double t) const;
  /// Scalar value at t (dim() must be 1).
  [[nodiscard]] double scalar(double t) const;
  /// The order-th derivative (degree drops by `order`; zero polynomial of degree 0 when order > degree).
  [[nodiscard]] BernsteinPoly derivative(int order = 1) const;
  /// The same polynomial written with degree + by.
  [[nodiscard]] BernsteinPoly elevated(int by) const;
  /// The same polynomial written with degree `degree` (>= current degree).
  [[nodiscard]] BernsteinPoly elevatedTo(int degree) const;
  /// Pieces on [0,t] and [t,1], each reparametrised to [0,1].
  [[nodiscard]] std::pair<BernsteinPoly, BernsteinPoly> subdivided(double t) const;
  /// q(s) = p(a + s (b - a)); any a != b (also outside [0,1], and a > b reverses).
  [[nodiscard]] BernsteinPoly restricted(double a, double b) const;
  /// q(s) = p(1 - s).
  [[nodiscard]] BernsteinPoly reversed() const;
  /// Composition p(w(s)) with a scalar polynomial w; degree = degree() * w.degree().
  [[nodiscard]] BernsteinPoly composed(const BernsteinPoly& w) const;
  /// Component k as a scalar polynomial.
  [[nodiscard]] BernsteinPoly component(int k) const;

  /// Componentwise min / max of the coefficients: bounds of p on [0,1] (convex-hull property).
  [[nodiscard]] VecX minCoeff() const;
  [[nodiscard]] VecX maxCoeff() const;
  /// max_i |c_i| over all components (a bound for the sup-norm of every component).
  [[nodiscard]] double maxAbsCoeff() const;
  /// max_i ||c_i||_2 (a bound for max_t ||p(t)||_2).
  [[nodiscard]] double maxCoeffNorm() const;

  BernsteinPoly& operator*=(double s);
  friend BernsteinPoly operator*(double s, BernsteinPoly p) { return p *= s; }
  friend BernsteinPoly operator*(BernsteinPoly p, double s) { return p *= s; }
  /// Sums and differences elevate the lower-degree operand; dimensions must agree.
  friend BernsteinPoly operator+(const BernsteinPoly& a, const BernsteinPoly& b);
  friend BernsteinPoly operator-(const BernsteinPoly& a, const BernsteinPoly& b);
  BernsteinPoly operator-() const;

 private:
  Matrix c_;
};

/// Product of two polynomials: scalar * scalar, scalar * vector, vector * scalar, or componentwise when both have
/// the same dimension. Degree = sum of the degrees.
BernsteinPoly product(const BernsteinPoly& a, const BernsteinPoly& b);
/// Scalar polynomial <a, b> (dimensions must agree).
BernsteinPoly dot(const BernsteinPoly& a, const BernsteinPoly& b);
/// Vector polynomial a x b (both of dimension 3).
BernsteinPoly cross(const BernsteinPoly& a, const BernsteinPoly& b);
/// Scalar polynomial det[a, b, c] = <a, b x c> (all of dimension 3).
BernsteinPoly triple(const BernsteinPoly& a, const BernsteinPoly& b, const BernsteinPoly& c);
/// Binomial coefficient as a double (exact for the degrees used here).
double binomial(int n, int k);

/// p(u,v) = sum_ij c_ij B_i^n(u) B_j^m(v) on [0,1]^2. Coefficients: (n+1)(m+1) x dim, row i*(m+1)+j.
class BernsteinPatch {
 public:
  BernsteinPatch() = default;
  BernsteinPatch(int degreeU, int degreeV, Matrix coefficients);
  static BernsteinPatch zero(int degreeU, int degreeV, int dim);

  [[nodiscard]] int degreeU() const { return du_; }
  [[nodiscard]] int degreeV() const { return dv_; }
  [[nodiscard]] int dim() const { return static_cast<int>(c_.cols()); }
  [[nodiscard]] const Matrix& coeffs() const { return c_; }
  Matrix& coeffs() { return c_; }
  [[nodiscard]] auto coeff(int i, int j) const { return c_.row(i * (dv_ + 1) + j); }
  auto coeff(int i, int j) { return c_.row(i * (dv_ + 1) + j); }

  [[nodiscard]] VecX operator()(double u, double v) const;
  /// Partial derivative d^{ku+kv} / du^ku dv^kv.
  [[nodiscard]] BernsteinPatch derivative(int ku, int kv) const;
  [[nodiscard]] BernsteinPatch elevated(int byU, int byV) const;
  [[nodiscard]] BernsteinPatch elevatedTo(int degreeU, int degreeV) const;
  /// Restriction to [u0,u1] x [v0,v1], reparametrised to [0,1]^2.
  [[nodiscard]] BernsteinPatch restricted(double u0, double u1, double v0, double v1) const;
  /// The curve v -> p(u, v) (an iso-line at fixed u), exactly.
  [[nodiscard]] BernsteinPoly isoU(double u) const;
  /// The curve u -> p(u, v) at fixed v, exactly.
  [[nodiscard]] BernsteinPoly isoV(double v) const;
  /// The curve t -> p(u(t), v(t)) for scalar polynomials u, v (exactly; degree = degreeU() deg u + degreeV() deg v).
  [[nodiscard]] BernsteinPoly composed(const BernsteinPoly& u, const BernsteinPoly& v) const;
  /// w^(du + dv) p(u / w, v / w) for scalar polynomials u, v, w: the composition with a rational parameter curve
  /// (u / w, v / w), homogenised so that it stays a polynomial (degree = (du + dv) max(deg u, deg v, deg w)).
  [[nodiscard]] BernsteinPoly composed(const BernsteinPoly& u, const BernsteinPoly& v, const BernsteinPoly& w) const;
  /// q(u,v) = p(v,u).
  [[nodiscard]] BernsteinPatch swapped() const;
  [[nodiscard]] BernsteinPatch reversedU() const;
  [[nodiscard]] BernsteinPatch reversedV() const;
  [[nodiscard]] VecX minCoeff() const;
  [[nodiscard]] VecX maxCoeff() const;
  [[nodiscard]] double maxAbsCoeff() const;

 private:
  int du_ = 0;
  int dv_ = 0;
  Matrix c_;
};

/// Products of patches (same rules as for curves); degrees add per direction.
BernsteinPatch product(const BernsteinPatch& a, const BernsteinPatch& b);
BernsteinPatch dot(const BernsteinPatch& a, const BernsteinPatch& b);
BernsteinPatch cross(const BernsteinPatch& a, const BernsteinPatch& b);
/// Numerators of S_u and S_v of a patch given by its homogeneous form h (columns x w, y w, z w, w; w = 1 when not
/// `rational`): A_u w - A w_u and A_v w - A w_v, i.e. w^2 S_u and w^2 S_v (A_u and A_v when polynomial). Their cross
/// product is w^4 S_u x S_v: the sign and zeros of the normal, exactly, as a polynomial.
std::pair<BernsteinPatch, BernsteinPatch> partialNumerators(const BernsteinPatch& h, bool rational);

}  // namespace seam
