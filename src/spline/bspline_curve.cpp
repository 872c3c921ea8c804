#include "seam/spline/bspline_curve.h"

#include <fmt/format.h>

#include <cassert>
#include <cmath>

#include "seam/core/bernstein.h"
#include "spline/spline_internal.h"

namespace seam {

namespace detail {
namespace {
// kP > 0: the degree is known at compile time (the loops unroll; the same operations in the same order, so the same
// bits as kP = 0, where p is read at run time).
template <int kP>
void basisUpTo2Impl(const double* U, int p, int span, double t, double (*ders)[kMaxFastBasisDegree + 1]) {
  if constexpr (kP > 0) p = kP;
  double ndu[kMaxFastBasisDegree + 1][kMaxFastBasisDegree + 1], a[2][kMaxFastBasisDegree + 1];
  double left[kMaxFastBasisDegree + 1], right[kMaxFastBasisDegree + 1];
  ndu[0][0] = 1.0;
  for (int j = 1; j <= p; ++j) {
    left[j] = t - U[span + 1 - j];
    right[j] = U[span + j] - t;
    double saved = 0.0;
    for (int r = 0; r < j; ++r) {
      ndu[j][r] = right[r + 1] + left[j - r];
      const double temp = ndu[r][j - 1] / ndu[j][r];
      ndu[r][j] = saved + right[r + 1] * temp;
      saved = left[j - r] * temp;
    }
    ndu[j][j] = saved;
  }
  for (int j = 0; j <= p; ++j) {
    ders[0][j] = ndu[j][p];
    ders[1][j] = ders[2][j] = 0.0;
  }
  const int n = std::min(2, p);
  for (int r = 0; r <= p; ++r) {
    int s1 = 0, s2 = 1;
    a[0][0] = 1.0;
    for (int k = 1; k <= n; ++k) {
      double d = 0.0;
      const int rk = r - k, pk = p - k;
      if (r >= k) {
        a[s2][0] = a[s1][0] / ndu[pk + 1][rk];
        d = a[s2][0] * ndu[rk][pk];
      }
      const int j1 = rk >= -1 ? 1 : -rk;
      const int j2 = (r - 1 <= pk) ? k - 1 : p - r;
      for (int j = j1; j <= j2; ++j) {
        a[s2][j] = (a[s1][j] - a[s1][j - 1]) / ndu[pk + 1][rk + j];
        d += a[s2][j] * ndu[rk + j][pk];
      }
      if (r <= pk) {
        a[s2][k] = -a[s1][k - 1] / ndu[pk + 1][r];
        d += a[s2][k] * ndu[r][pk];
      }
      ders[k][r] = d;
      std::swap(s1, s2);
    }
  }
  double f = p;
  for (int k = 1; k <= n; ++k) {
    for (int j = 0; j <= p; ++j) ders[k][j] *= f;
    f *= (p - k);
  }
}
}  // namespace

// Values, first and second derivatives of the p+1 non-zero basis functions (NURBS Book A2.3 on the stack).
void basisUpTo2(const std::vector<double>& U, int p, int span, double t, double (*ders)[kMaxFastBasisDegree + 1]) {
  switch (p) {  // the common degrees unrolled
    case 1: return basisUpTo2Impl<1>(U.data(), p, span, t, ders);
    case 2: return basisUpTo2Impl<2>(U.data(), p, span, t, ders);
    case 3: return basisUpTo2Impl<3>(U.data(), p, span, t, ders);
    case 4: return basisUpTo2Impl<4>(U.data(), p, span, t, ders);
    case 5: return basisUpTo2Impl<5>(U.data(), p, span, t, ders);
    default: return basisUpTo2Impl<0>(U.data(), p, span, t, ders);
  }
}
}  // namespace detail

namespace {

Status checkPointsAndWeights(const Matrix& points, const VecX& weights) {
  if (points.cols() < 1) return invalidInput("control points have no coordinates");
  for (Eigen::Index i = 0; i < points.rows(); ++i)
    if (!points.row(i).allFinite())
      return invalidInput(fmt::format("control point {} has a coordinate that is not a finite number", i));
  if (weights.size() > 0) {
    if (weights.size() != points.rows())
      return invalidInput(fmt::format("{} weights given for {} control points", weights.size(), points.rows()));
    for (Eigen::Index i = 0; i < weights.size(); ++i)
      if (!std::isfinite(weights[i]) || !(weights[i] > 0.0))
        return invalidInput(fmt::format("weight {} is {}, weights must be positive finite numbers", i, weights[i]));
  }
  return Status::ok();
}

}  // namespace

Result<BSplineCurve> BSplineCurve::create(int degree, std::vector<double> knots, Matrix points, VecX weights) {
  if (degree < 1) return invalidInput(fmt::format("degree {} is below 1", degree));
  if (Status s = checkPointsAndWeights(points, weights); !s) return s;
  KnotVector kv(std::move(knots));
  if (Status s = kv.validate(degree, static_cast<int>(points.rows())); !s) return s;
  return BSplineCurve(degree, std::move(kv), std::move(points), std::move(weights));
}

BSplineCurve::BSplineCurve(int degree, KnotVector knots, Matrix points, VecX weights)
    : p_(degree), knots_(std::move(knots)), points_(std::move(points)), weights_(std::move(weights)) {
  assert(knots_.size() == points_.rows() + p_ + 1);
  assert(weights_.size() == 0 || weights_.size() == points_.rows());
}

BSplineCurve BSplineCurve::fromHomogeneous(int degree, KnotVector knots, const Matrix& h, bool rational) {
  if (!rational) return BSplineCurve(degree, std::move(knots), h);
  const auto d = h.cols() - 1;
  VecX w = h.col(d);
  Matrix pts = h.leftCols(d);
  for (Eigen::Index i = 0; i < pts.rows(); ++i) pts.row(i) /= w[i];
  return BSplineCurve(degree, std::move(knots), std::move(pts), std::move(w));
}

Matrix BSplineCurve::homogeneous() const {
  if (!isRational()) return points_;
  Matrix h(points_.rows(), points_.cols() + 1);
  for (Eigen::Index i = 0; i < points_.rows(); ++i) {
    h.row(i).head(points_.cols()) = weights_[i] * points_.row(i);
    h(i, points_.cols()) = weights_[i];
  }
  return h;
}

namespace {
/// Degrees up to this use the allocation-free evaluation (stack arrays); higher degrees go through derivatives().
constexpr int kMaxFastEvalDegree = detail::kMaxFastBasisDegree;

void basisValues(const std::vector<double>& U, int p, int span, double t, double* N) {
  switch (p) {  // the common degrees unrolled
    case 1: return detail::basisValuesImpl<1>(U.data(), p, span, t, N);
    case 2: return detail::basisValuesImpl<2>(U.data(), p, span, t, N);
    case 3: return detail::basisValuesImpl<3>(U.data(), p, span, t, N);
    case 4: return detail::basisValuesImpl<4>(U.data(), p, span, t, N);
    case 5: return detail::basisValuesImpl<5>(U.data(), p, span, t, N);
    default: return detail::basisValuesImpl<0>(U.data(), p, span, t, N);
  }
}
}  // namespace

VecX BSplineCurve::evaluate(double t) const {
  if (p_ > kMaxFastEvalDegree) return derivatives(t, 0).row(0).transpose();
  // Basis functions by the triangular Cox-de Boor scheme (The NURBS Book A2.2), then the (weighted) sum.
  const int span = knots_.findSpan(p_, t);
  double N[kMaxFastEvalDegree + 1];
  basisValues(knots_.values(), p_, span, t, N);
  const auto d = points_.cols();
  VecX out = VecX::Zero(d);
  if (!isRational()) {
    for (int r = 0; r <= p_; ++r) out += N[r] * points_.row(span - p_ + r).transpose();
    return out;
  }
  double w = 0.0;
  for (int r = 0; r <= p_; ++r) {
    const int i = span - p_ + r;
    const double nw = N[r] * weights_[i];
    out += nw * points_.row(i).transpose();
    w += nw;
  }
  return out / w;
}

Vec3 BSplineCurve::point3(double t) const {
  assert(dim() >= 3);
  if (p_ > kMaxFastEvalDegree) return derivatives(t, 0).row(0).head<3>().transpose();
  const int span = knots_.findSpan(p_, t);
  double N[kMaxFastEvalDegree + 1];
  basisValues(knots_.values(), p_, span, t, N);
  Vec3 out = Vec3::Zero();
  double w = 0.0;
  const bool rational = isRational();
  for (int r = 0; r <= p_; ++r) {
    const int i = span - p_ + r;
    const double nw = N[r] * (rational ? weights_[i] : 1.0);
    out += nw * points_.row(i).head<3>().transpose();
    w += nw;
  }
  return rational ? Vec3(out / w) : out;
}

void BSplineCurve::derivatives2(double t, Vec3& c, Vec3& d1, Vec3& d2) const {
  assert(dim() >= 3);
  if (p_ > kMaxFastEvalDegree) {
    const Matrix d = derivatives(t, 2);
    c = d.row(0).head<3>().transpose();
    d1 = d.row(1).head<3>().transpose();
    d2 = d.row(2).head<3>().transpose();
    return;
  }
  const int span = knots_.findSpan(p_, t);
  double N[3][detail::kMaxFastBasisDegree + 1];
  detail::basisUpTo2(knots_.values(), p_, span, t, N);
  const bool rational = isRational();
  Vec3 A[3] = {Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};
  double w[3] = {0.0, 0.0, 0.0};
  for (int r = 0; r <= p_; ++r) {
    const int i = span - p_ + r;
    const double wi = rational ? weights_[i] : 1.0;
    const Vec3 x = points_.row(i).head<3>().transpose();
    for (int k = 0; k < 3; ++k) {
      A[k] += (N[k][r] * wi) * x;
      w[k] += N[k][r] * wi;
    }
  }
  if (!rational) {
    c = A[0];
    d1 = A[1];
    d2 = A[2];
    return;
  }
  // A = w C differentiated (NURBS Book A4.2): C' = (A' - w' C) / w, C'' = (A'' - 2 w' C' - w'' C) / w.
  c = A[0] / w[0];
  d1 = (A[1] - w[1] * c) / w[0];
  d2 = (A[2] - 2.0 * w[1] * d1 - w[2] * c) / w[0];
}

void BSplineCurve::derivatives1(double t, Vec2& c, Vec2& d1) const {
  assert(dim() == 2);
  if (p_ > kMaxFastEvalDegree) {
    const Matrix d = derivatives(t, 1);
    c = d.row(0).transpose();
    d1 = d.row(1).transpose();
    return;
  }
  // derivatives(t, 1) on the stack: basisUpTo2's rows 0 and 1 are those of basisFunctionDerivatives (row 1 does not
  // depend on row 2), summed in the same order, then the same quotient rule.
  const int span = knots_.findSpan(p_, t);
  double N[3][detail::kMaxFastBasisDegree + 1];
  detail::basisUpTo2(knots_.values(), p_, span, t, N);
  const bool rational = isRational();
  Vec2 A[2] = {Vec2::Zero(), Vec2::Zero()};
  double w[2] = {0.0, 0.0};
  for (int k = 0; k < 2; ++k)
    for (int r = 0; r <= p_; ++r) {
      const int i = span - p_ + r;
      if (rational) {
        A[k] += (N[k][r] * weights_[i]) * points_.row(i).transpose();
        w[k] += N[k][r] * weights_[i];
      } else {
        A[k] += N[k][r] * points_.row(i).transpose();
      }
    }
  if (!rational) {
    c = A[0];
    d1 = A[1];
    return;
  }
  // C' = (A' - w' C) / w (NURBS Book A4.2), as derivatives() computes it (its factor binomial(1, 1) = 1 is exact).
  c = A[0] / w[0];
  d1 = (A[1] - w[1] * c) / w[0];
}

Matrix BSplineCurve::derivatives(double t, int order) const {
  assert(order >= 0);
  const int span = knots_.findSpan(p_, t);
  const int du = std::min(order, p_);
  const Matrix N = basisFunctionDerivatives(knots_, p_, span, t, du);
  const bool rational = isRational();
  const auto dh = points_.cols() + (rational ? 1 : 0);
  Matrix H = Matrix::Zero(order + 1, dh);
  for (int k = 0; k <= du; ++k)
    for (int r = 0; r <= p_; ++r) {
      const int i = span - p_ + r;
      if (rational) {
        H.row(k).head(points_.cols()) += (N(k, r) * weights_[i]) * points_.row(i);
        H(k, points_.cols()) += N(k, r) * weights_[i];
      } else {
        H.row(k) += N(k, r) * points_.row(i);
      }
    }
  if (!rational) return H;
  // Quotient rule (The NURBS Book A4.2): C^(k) = (A^(k) - sum_{i=1}^{k} C(k,i) w^(i) C^(k-i)) / w.
  const auto d = points_.cols();
  Matrix C(order + 1, d);
  for (int k = 0; k <= order; ++k) {
    Eigen::RowVectorXd v = H.row(k).head(d);
    for (int i = 1; i <= k; ++i) v -= binomial(k, i) * H(i, d) * C.row(k - i);
    C.row(k) = v / H(0, d);
  }
  return C;
}

BSplineCurve BSplineCurve::withKnotInserted(double t, int times) const {
  std::vector<double> k = knots_.values();
  Matrix h = homogeneous();
  detail::insertKnot(p_, k, h, t, times);
  return fromHomogeneous(p_, KnotVector(std::move(k)), h, isRational());
}

BSplineCurve BSplineCurve::refined(const std::vector<double>& newKnots) const {
  std::vector<double> k = knots_.values();
  Matrix h = homogeneous();
  detail::refineKnots(p_, k, h, newKnots);
  return fromHomogeneous(p_, KnotVector(std::move(k)), h, isRational());
}

std::vector<BezierCurvePiece> BSplineCurve::bezierPieces() const {
  std::vector<double> k = knots_.values();
  Matrix h = homogeneous();
  const auto spans = detail::decompose(p_, k, h);
  std::vector<BezierCurvePiece> out;
  out.reserve(spans.size());
  for (size_t s = 0; s < spans.size(); ++s) {
    const BernsteinPoly piece(Matrix(h.middleRows(static_cast<Eigen::Index>(s) * p_, p_ + 1)));
    out.push_back({isRational() ? BezierCurve::fromHomogeneous(piece) : BezierCurve(piece.coeffs()), spans[s]});
  }
  return out;
}

BSplineCurve BSplineCurve::degreeElevated(int by) const {
  std::vector<double> k = knots_.values();
  Matrix h = homogeneous();
  detail::elevateDegree(p_, k, h, by);
  return fromHomogeneous(p_ + std::max(by, 0), KnotVector(std::move(k)), h, isRational());
}

BSplineCurve BSplineCurve::reversed() const {
  VecX w = isRational() ? VecX(weights_.reverse()) : VecX();
  return BSplineCurve(p_, knots_.reversed(p_), Matrix(points_.colwise().reverse()), std::move(w));
}

BSplineCurve BSplineCurve::reparametrized(double a, double b) const {
  return BSplineCurve(p_, knots_.reparametrized(p_, a, b), points_, weights_);
}

}  // namespace seam
