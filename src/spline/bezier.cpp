#include "seam/spline/bezier.h"

#include <cassert>

#include "seam/spline/bspline_curve.h"
#include "seam/spline/bspline_surface.h"
#include "spline/spline_internal.h"

namespace seam {

namespace {
Matrix toHomogeneous(const Matrix& points, const VecX& weights) {
  if (weights.size() == 0) return points;
  Matrix h(points.rows(), points.cols() + 1);
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    h.row(i).head(points.cols()) = weights[i] * points.row(i);
    h(i, points.cols()) = weights[i];
  }
  return h;
}

void fromHomogeneousRows(const Matrix& h, Matrix& points, VecX& weights) {
  const auto d = h.cols() - 1;
  weights = h.col(d);
  points = h.leftCols(d);
  for (Eigen::Index i = 0; i < points.rows(); ++i) points.row(i) /= weights[i];
}

}  // namespace

// ---------------------------------------------------------------------------------------------------------------
BezierCurve::BezierCurve(Matrix points, VecX weights) : points_(std::move(points)), weights_(std::move(weights)) {
  assert(weights_.size() == 0 || weights_.size() == points_.rows());
}

BernsteinPoly BezierCurve::homogeneous() const { return BernsteinPoly(toHomogeneous(points_, weights_)); }

BernsteinPoly BezierCurve::numerator() const {
  if (!isRational()) return BernsteinPoly(points_);
  return BernsteinPoly(Matrix(toHomogeneous(points_, weights_).leftCols(points_.cols())));
}

BernsteinPoly BezierCurve::denominator() const {
  if (!isRational()) return BernsteinPoly::constant(1.0, 0);
  return BernsteinPoly(Matrix(weights_));
}

VecX BezierCurve::evaluate(double t) const { return derivatives(t, 0).row(0).transpose(); }

Matrix BezierCurve::derivatives(double t, int order) const {
  const BernsteinPoly h = homogeneous();
  Matrix H(order + 1, h.dim());
  for (int k = 0; k <= order; ++k) H.row(k) = h.derivative(k)(t).transpose();
  return isRational() ? detail::curveQuotientRule(H) : H;
}

BSplineCurve BezierCurve::toBSpline(double a, double b) const {
  return BSplineCurve(degree(), KnotVector::bezier(degree(), a, b), points_, weights_);
}

BezierCurve BezierCurve::fromHomogeneous(const BernsteinPoly& h) {
  Matrix p;
  VecX w;
  fromHomogeneousRows(h.coeffs(), p, w);
  return BezierCurve(std::move(p), std::move(w));
}

// ---------------------------------------------------------------------------------------------------------------
BezierPatch::BezierPatch(int degreeU, int degreeV, Matrix points, VecX weights)
    : du_(degreeU), dv_(degreeV), points_(std::move(points)), weights_(std::move(weights)) {
  assert(points_.rows() == (du_ + 1) * (dv_ + 1));
  assert(weights_.size() == 0 || weights_.size() == points_.rows());
}

BernsteinPatch BezierPatch::homogeneous() const {
  return BernsteinPatch(du_, dv_, toHomogeneous(points_, weights_));
}

BernsteinPatch BezierPatch::numerator() const {
  if (!isRational()) return BernsteinPatch(du_, dv_, points_);
  return BernsteinPatch(du_, dv_, Matrix(toHomogeneous(points_, weights_).leftCols(points_.cols())));
}

BernsteinPatch BezierPatch::denominator() const {
  if (!isRational()) return BernsteinPatch(0, 0, Matrix::Constant(1, 1, 1.0));
  return BernsteinPatch(du_, dv_, Matrix(weights_));
}

VecX BezierPatch::evaluate(double u, double v) const { return derivatives(u, v, 0)[0][0]; }

std::vector<std::vector<VecX>> BezierPatch::derivatives(double u, double v, int order) const {
  const BernsteinPatch h = homogeneous();
  std::vector<std::vector<VecX>> H(static_cast<size_t>(order + 1));
  for (int k = 0; k <= order; ++k)
    for (int l = 0; l <= order - k; ++l) H[static_cast<size_t>(k)].push_back(h.derivative(k, l)(u, v));
  if (!isRational()) return H;
  return detail::surfaceQuotientRule(H);
}

BSplineSurface BezierPatch::toBSpline(Interval u, Interval v) const {
  return BSplineSurface(du_, dv_, KnotVector::bezier(du_, u.lo, u.hi), KnotVector::bezier(dv_, v.lo, v.hi), du_ + 1,
                        dv_ + 1, points_, weights_);
}

BezierPatch BezierPatch::fromHomogeneous(const BernsteinPatch& h) {
  Matrix p;
  VecX w;
  fromHomogeneousRows(h.coeffs(), p, w);
  return BezierPatch(h.degreeU(), h.degreeV(), std::move(p), std::move(w));
}

}  // namespace seam
