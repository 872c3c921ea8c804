#include "seam/spline/bspline_surface.h"

#include <fmt/format.h>

#include <algorithm>
#include <cassert>
#include <cctype>
#include <cmath>
#include <type_traits>

#include "seam/core/bernstein.h"
#include "spline/spline_internal.h"

namespace seam {

std::string_view edgeName(Edge e) {
  switch (e) {
    case Edge::U0: return "u0";
    case Edge::U1: return "u1";
    case Edge::V0: return "v0";
    case Edge::V1: return "v1";
  }
  return "?";
}

Result<Edge> parseEdge(std::string_view name) {
  std::string s(name);
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  for (Edge e : kAllEdges)
    if (s == edgeName(e)) return e;
  return invalidInput(fmt::format("unknown edge \"{}\" (expected u0, u1, v0 or v1)", name));
}

namespace detail {
Matrix transposeGrid(const Matrix& rows, int nu, int nv) {
  Matrix out(rows.rows(), rows.cols());
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) out.row(j * nu + i) = rows.row(i * nv + j);
  return out;
}
}  // namespace detail

namespace {

// Surface rows (nu*nv) x d seen as nu rows of nv*d coefficients, and back.
Matrix asURows(const Matrix& h, int nu) { return Eigen::Map<const Matrix>(h.data(), nu, h.size() / nu); }
Matrix fromURows(const Matrix& rows, int d) { return Eigen::Map<const Matrix>(rows.data(), rows.size() / d, d); }

// Applies a curve algorithm fn(degree, knots, rows) to the u direction of homogeneous surface rows.
template <class Fn>
void applyU(int degree, std::vector<double>& knots, Matrix& h, int& nu, int nv, Fn fn) {
  const auto d = h.cols();
  Matrix rows = asURows(h, nu);
  fn(degree, knots, rows);
  nu = static_cast<int>(rows.rows());
  h = fromURows(rows, static_cast<int>(d));
  (void)nv;
}

template <class Fn>
void applyV(int degree, std::vector<double>& knots, Matrix& h, int nu, int& nv, Fn fn) {
  Matrix t = detail::transposeGrid(h, nu, nv);
  applyU(degree, knots, t, nv, nu, fn);
  h = detail::transposeGrid(t, nv, nu);
}

}  // namespace

Result<BSplineSurface> BSplineSurface::create(int degreeU, int degreeV, std::vector<double> knotsU,
                                              std::vector<double> knotsV, int numU, int numV, Matrix points,
                                              VecX weights) {
  if (degreeU < 1 || degreeV < 1)
    return invalidInput(fmt::format("degree ({}, {}) is below 1", degreeU, degreeV));
  if (numU < 1 || numV < 1 || points.rows() != static_cast<Eigen::Index>(numU) * numV)
    return invalidInput(fmt::format("{} control points given for a {} x {} grid", points.rows(), numU, numV));
  if (points.cols() < 1) return invalidInput("control points have no coordinates");
  for (Eigen::Index r = 0; r < points.rows(); ++r)
    if (!points.row(r).allFinite())
      return invalidInput(fmt::format("control point [{}][{}] has a coordinate that is not a finite number",
                                      r / numV, r % numV));
  if (weights.size() > 0) {
    if (weights.size() != points.rows())
      return invalidInput(fmt::format("{} weights given for {} control points", weights.size(), points.rows()));
    for (Eigen::Index r = 0; r < weights.size(); ++r)
      if (!std::isfinite(weights[r]) || !(weights[r] > 0.0))
        return invalidInput(fmt::format("weight [{}][{}] is {}, weights must be positive finite numbers", r / numV,
                                        r % numV, weights[r]));
  }
  KnotVector ku(std::move(knotsU)), kv(std::move(knotsV));
  if (Status s = ku.validate(degreeU, numU); !s) return s.withContext("u");
  if (Status s = kv.validate(degreeV, numV); !s) return s.withContext("v");
  return BSplineSurface(degreeU, degreeV, std::move(ku), std::move(kv), numU, numV, std::move(points),
                        std::move(weights));
}

BSplineSurface::BSplineSurface(int degreeU, int degreeV, KnotVector knotsU, KnotVector knotsV, int numU, int numV,
                               Matrix points, VecX weights)
    : pu_(degreeU),
      pv_(degreeV),
      ku_(std::move(knotsU)),
      kv_(std::move(knotsV)),
      nu_(numU),
      nv_(numV),
      points_(std::move(points)),
      weights_(std::move(weights)) {
  assert(points_.rows() == static_cast<Eigen::Index>(nu_) * nv_);
  assert(ku_.size() == nu_ + pu_ + 1 && kv_.size() == nv_ + pv_ + 1);
  assert(weights_.size() == 0 || weights_.size() == points_.rows());
}

BSplineSurface BSplineSurface::fromHomogeneous(int degreeU, int degreeV, KnotVector knotsU, KnotVector knotsV,
                                               int numU, int numV, const Matrix& h, bool rational) {
  if (!rational) return BSplineSurface(degreeU, degreeV, std::move(knotsU), std::move(knotsV), numU, numV, h);
  const auto d = h.cols() - 1;
  VecX w = h.col(d);
  Matrix pts = h.leftCols(d);
  for (Eigen::Index i = 0; i < pts.rows(); ++i) pts.row(i) /= w[i];
  return BSplineSurface(degreeU, degreeV, std::move(knotsU), std::move(knotsV), numU, numV, std::move(pts),
                        std::move(w));
}

Matrix BSplineSurface::homogeneous() const {
  if (!isRational()) return points_;
  Matrix h(points_.rows(), points_.cols() + 1);
  for (Eigen::Index i = 0; i < points_.rows(); ++i) {
    h.row(i).head(points_.cols()) = weights_[i] * points_.row(i);
    h(i, points_.cols()) = weights_[i];
  }
  return h;
}

VecX BSplineSurface::evaluate(double u, double v) const {
  // Points in 3-D: the allocation-free loops of pointAndFirstDerivatives, whose point is derivatives()'s
  // [0][0] operation for operation (the same basis arithmetic, the same sums in the same order, the same division
  // by w), so the same bits. The general route allocates a vector of vectors per call, which dominated the callers
  // that evaluate densely (samplers, closest-point searches), above all under AddressSanitizer.
  if (points_.cols() == 3 && pu_ <= detail::kMaxFastBasisDegree && pv_ <= detail::kMaxFastBasisDegree) {
    Vec3 point, du, dv;
    detail::pointAndFirstDerivativesFast(*this, u, v, true, point, du, dv);
    return point;
  }
  return derivatives(u, v, 0)[0][0];
}

std::vector<std::vector<VecX>> BSplineSurface::derivatives(double u, double v, int order) const {
  assert(order >= 0);
  const int su = ku_.findSpan(pu_, u), sv = kv_.findSpan(pv_, v);
  const Matrix Nu = basisFunctionDerivatives(ku_, pu_, su, u, std::min(order, pu_));
  const Matrix Nv = basisFunctionDerivatives(kv_, pv_, sv, v, std::min(order, pv_));
  const bool rational = isRational();
  const auto d = points_.cols();
  const auto dh = d + (rational ? 1 : 0);
  std::vector<std::vector<VecX>> H(static_cast<size_t>(order + 1));
  for (int k = 0; k <= order; ++k) {
    for (int l = 0; l <= order - k; ++l) {
      VecX acc = VecX::Zero(dh);
      if (k <= pu_ && l <= pv_) {
        for (int r = 0; r <= pu_; ++r) {
          VecX row = VecX::Zero(dh);
          for (int s = 0; s <= pv_; ++s) {
            const Eigen::Index idx = static_cast<Eigen::Index>(su - pu_ + r) * nv_ + (sv - pv_ + s);
            if (rational) {
              row.head(d) += (Nv(l, s) * weights_[idx]) * points_.row(idx).transpose();
              row[d] += Nv(l, s) * weights_[idx];
            } else {
              row += Nv(l, s) * points_.row(idx).transpose();
            }
          }
          acc += Nu(k, r) * row;
        }
      }
      H[static_cast<size_t>(k)].push_back(std::move(acc));
    }
  }
  return rational ? detail::surfaceQuotientRule(H) : H;
}

namespace {
// Largest degree handled by the allocation-free paths (higher degrees use the general algorithm).
constexpr int kMaxFastDegree = detail::kMaxFastBasisDegree;

// Values and first derivatives of the p+1 non-zero basis functions at t in `span` (Cox-de Boor triangle on the
// stack; N'_{i,p} = p (N_{i,p-1} / (t_{i+p} - t_i) - N_{i+1,p-1} / (t_{i+p+1} - t_{i+1}))).
// `p` an int, or a std::integral_constant for the common low degrees (withLowDegree): the same operations in the
// same order either way, so the same bits; with the degree known at compile time the loops unroll.
template <class Degree>
void basisAndDerivative(const std::vector<double>& U, Degree p, int span, double t, double* N, double* dN) {
  double left[kMaxFastDegree + 1], right[kMaxFastDegree + 1], low[kMaxFastDegree + 1];
  N[0] = 1.0;
  for (int j = 1; j <= p; ++j) {
    left[j] = t - U[static_cast<size_t>(span + 1 - j)];
    right[j] = U[static_cast<size_t>(span + j)] - t;
    double saved = 0.0;
    if (j == p)
      for (int r = 0; r < p; ++r) low[r] = N[r];
    for (int r = 0; r < j; ++r) {
      const double temp = N[r] / (right[r + 1] + left[j - r]);
      N[r] = saved + right[r + 1] * temp;
      saved = left[j - r] * temp;
    }
    N[j] = saved;
  }
  if (p == 0) {
    dN[0] = 0.0;
    return;
  }
  // low[r] = N_{span-p+1+r, p-1}, r = 0..p-1.
  for (int r = 0; r <= p; ++r) {
    const int i = span - p + r;
    double d = 0.0;
    if (r >= 1) d += low[r - 1] / (U[static_cast<size_t>(i + p)] - U[static_cast<size_t>(i)]);
    if (r <= p - 1) d -= low[r] / (U[static_cast<size_t>(i + p + 1)] - U[static_cast<size_t>(i + 1)]);
    dN[r] = p * d;
  }
}

/// Degrees up to this one get their own compile-time instance of the evaluation loops (withLowDegree).
constexpr int kUnrolledDegree = 3;

/// f(std::integral_constant<int, p>) for p in [1, kUnrolledDegree], else f(p).
template <class F>
decltype(auto) withLowDegree(int p, F&& f) {
  static_assert(kUnrolledDegree == 3);
  switch (p) {
    case 1: return f(std::integral_constant<int, 1>{});
    case 2: return f(std::integral_constant<int, 2>{});
    case 3: return f(std::integral_constant<int, 3>{});
    default: return f(p);
  }
}

/// S, S_u, S_v (homogeneous sums, then the quotient rule when rational) from the basis values at (span su, sv):
/// BSplineSurface::pointAndFirstDerivatives' loops, for int or compile-time degrees (the same operations in the
/// same order).
template <class DegU, class DegV>
void pointAndFirstDerivativesAt(DegU pu, DegV pv, const std::vector<double>& ku, const std::vector<double>& kv,
                                const double* P, const VecX& weights, bool rational, int nv, double u, double v,
                                int su, int sv, Vec3& point, Vec3& du, Vec3& dv) {
  double Nu[kMaxFastDegree + 1], dNu[kMaxFastDegree + 1], Nv[kMaxFastDegree + 1], dNv[kMaxFastDegree + 1];
  basisAndDerivative(ku, pu, su, u, Nu, dNu);
  basisAndDerivative(kv, pv, sv, v, Nv, dNv);
  double S[4] = {0, 0, 0, 0}, Su[4] = {0, 0, 0, 0}, Sv[4] = {0, 0, 0, 0};
  for (int r = 0; r <= pu; ++r) {
    double row[4] = {0, 0, 0, 0}, rowV[4] = {0, 0, 0, 0};
    const int i = su - pu + r;
    for (int c = 0; c <= pv; ++c) {
      const int idx = i * nv + (sv - pv + c);
      const double w = rational ? weights[idx] : 1.0;
      const double* x = P + 3 * static_cast<size_t>(idx);
      const double a = Nv[c] * w, b = dNv[c] * w;
      for (int k = 0; k < 3; ++k) {
        row[k] += a * x[k];
        rowV[k] += b * x[k];
      }
      row[3] += a;
      rowV[3] += b;
    }
    for (int k = 0; k < 4; ++k) {
      S[k] += Nu[r] * row[k];
      Su[k] += dNu[r] * row[k];
      Sv[k] += Nu[r] * rowV[k];
    }
  }
  if (rational) {
    const double w = S[3];
    for (int k = 0; k < 3; ++k) {
      S[k] /= w;
      Su[k] = (Su[k] - Su[3] * S[k]) / w;
      Sv[k] = (Sv[k] - Sv[3] * S[k]) / w;
    }
  }
  point = Vec3(S[0], S[1], S[2]);
  du = Vec3(Su[0], Su[1], Su[2]);
  dv = Vec3(Sv[0], Sv[1], Sv[2]);
}
}  // namespace

void BSplineSurface::pointAndFirstDerivatives(double u, double v, Vec3& point, Vec3& du, Vec3& dv) const {
  assert(dim() == 3);
  if (pu_ > kMaxFastDegree || pv_ > kMaxFastDegree) {
    const auto d = derivatives(u, v, 1);
    point = d[0][0];
    du = d[1][0];
    dv = d[0][1];
    return;
  }
  detail::pointAndFirstDerivativesFast(*this, u, v, true, point, du, dv);
}

namespace detail {

void pointAndFirstDerivativesFast(const BSplineSurface& s, double u, double v, bool unrolled, Vec3& point, Vec3& du,
                                  Vec3& dv) {
  assert(s.dim() == 3 && s.degreeU() <= kMaxFastDegree && s.degreeV() <= kMaxFastDegree);
  const int pu = s.degreeU(), pv = s.degreeV();
  const std::vector<double>&ku = s.knotsU().values(), &kv = s.knotsV().values();
  const int su = s.knotsU().findSpan(pu, u), sv = s.knotsV().findSpan(pv, v);
  auto eval = [&](auto degU, auto degV) {
    pointAndFirstDerivativesAt(degU, degV, ku, kv, s.points().data(), s.weights(), s.isRational(), s.numV(), u, v,
                               su, sv, point, du, dv);
  };
  if (!unrolled) {
    eval(pu, pv);
    return;
  }
  withLowDegree(pu, [&](auto degU) { withLowDegree(pv, [&](auto degV) { eval(degU, degV); }); });
}

}  // namespace detail


void BSplineSurface::secondOrderDerivatives(double u, double v, std::array<Vec3, 6>& out) const {
  assert(dim() == 3);
  if (pu_ > kMaxFastDegree || pv_ > kMaxFastDegree) {
    const auto d = derivatives(u, v, 2);
    out = {Vec3(d[0][0]), Vec3(d[1][0]), Vec3(d[0][1]), Vec3(d[2][0]), Vec3(d[1][1]), Vec3(d[0][2])};
    return;
  }
  const int su = ku_.findSpan(pu_, u), sv = kv_.findSpan(pv_, v);
  double Nu[3][kMaxFastDegree + 1], Nv[3][kMaxFastDegree + 1];
  detail::basisUpTo2(ku_.values(), pu_, su, u, Nu);
  detail::basisUpTo2(kv_.values(), pv_, sv, v, Nv);
  const bool rational = isRational();
  // H[k][l] homogeneous derivative d^{k+l}/du^k dv^l, k + l <= 2, 4 coordinates.
  double H[3][3][4] = {};
  const double* P = points_.data();
  for (int r = 0; r <= pu_; ++r) {
    double row[3][4] = {};
    const int i = su - pu_ + r;
    for (int c = 0; c <= pv_; ++c) {
      const int idx = i * nv_ + (sv - pv_ + c);
      const double w = rational ? weights_[idx] : 1.0;
      const double* x = P + 3 * static_cast<size_t>(idx);
      for (int l = 0; l <= 2; ++l) {
        const double f = Nv[l][c] * w;
        row[l][0] += f * x[0];
        row[l][1] += f * x[1];
        row[l][2] += f * x[2];
        row[l][3] += f;
      }
    }
    for (int k = 0; k <= 2; ++k)
      for (int l = 0; l <= 2 - k; ++l)
        for (int q = 0; q < 4; ++q) H[k][l][q] += Nu[k][r] * row[l][q];
  }
  Vec3 S[3][3];
  for (int k = 0; k <= 2; ++k)
    for (int l = 0; l <= 2 - k; ++l) S[k][l] = Vec3(H[k][l][0], H[k][l][1], H[k][l][2]);
  if (rational) {
    // Quotient rule (NURBS Book A4.4) for order 2.
    auto w = [&](int k, int l) { return H[k][l][3]; };
    const double w0 = w(0, 0);
    S[0][0] /= w0;
    S[1][0] = (S[1][0] - w(1, 0) * S[0][0]) / w0;
    S[0][1] = (S[0][1] - w(0, 1) * S[0][0]) / w0;
    S[2][0] = (S[2][0] - 2.0 * w(1, 0) * S[1][0] - w(2, 0) * S[0][0]) / w0;
    S[0][2] = (S[0][2] - 2.0 * w(0, 1) * S[0][1] - w(0, 2) * S[0][0]) / w0;
    S[1][1] = (S[1][1] - w(1, 0) * S[0][1] - w(0, 1) * S[1][0] - w(1, 1) * S[0][0]) / w0;
  }
  out = {S[0][0], S[1][0], S[0][1], S[2][0], S[1][1], S[0][2]};
}

Vec3 BSplineSurface::normal(double u, double v) const {
  const auto d = derivatives(u, v, 1);
  const Vec3 n = Vec3(d[1][0].head<3>()).cross(Vec3(d[0][1].head<3>()));
  const double len = n.norm();
  return len > 0.0 ? Vec3(n / len) : Vec3::Zero();
}

BSplineSurface BSplineSurface::withKnotInsertedU(double u, int times) const {
  std::vector<double> k = ku_.values();
  Matrix h = homogeneous();
  int nu = nu_;
  applyU(pu_, k, h, nu, nv_, [&](int p, auto& kn, auto& rows) { detail::insertKnot(p, kn, rows, u, times); });
  return fromHomogeneous(pu_, pv_, KnotVector(std::move(k)), kv_, nu, nv_, h, isRational());
}

BSplineSurface BSplineSurface::withKnotInsertedV(double v, int times) const {
  std::vector<double> k = kv_.values();
  Matrix h = homogeneous();
  int nv = nv_;
  applyV(pv_, k, h, nu_, nv, [&](int p, auto& kn, auto& rows) { detail::insertKnot(p, kn, rows, v, times); });
  return fromHomogeneous(pu_, pv_, ku_, KnotVector(std::move(k)), nu_, nv, h, isRational());
}

BSplineSurface BSplineSurface::refinedU(const std::vector<double>& newKnots) const {
  std::vector<double> k = ku_.values();
  Matrix h = homogeneous();
  int nu = nu_;
  applyU(pu_, k, h, nu, nv_, [&](int p, auto& kn, auto& rows) { detail::refineKnots(p, kn, rows, newKnots); });
  return fromHomogeneous(pu_, pv_, KnotVector(std::move(k)), kv_, nu, nv_, h, isRational());
}

BSplineSurface BSplineSurface::refinedV(const std::vector<double>& newKnots) const {
  std::vector<double> k = kv_.values();
  Matrix h = homogeneous();
  int nv = nv_;
  applyV(pv_, k, h, nu_, nv, [&](int p, auto& kn, auto& rows) { detail::refineKnots(p, kn, rows, newKnots); });
  return fromHomogeneous(pu_, pv_, ku_, KnotVector(std::move(k)), nu_, nv, h, isRational());
}

std::vector<BezierPatchPiece> BSplineSurface::bezierPatches() const {
  std::vector<double> kU = ku_.values(), kV = kv_.values();
  Matrix h = homogeneous();
  int nu = nu_, nv = nv_;
  std::vector<Interval> spansU, spansV;
  applyU(pu_, kU, h, nu, nv, [&](int p, auto& kn, auto& rows) { spansU = detail::decompose(p, kn, rows); });
  applyV(pv_, kV, h, nu, nv, [&](int p, auto& kn, auto& rows) { spansV = detail::decompose(p, kn, rows); });
  std::vector<BezierPatchPiece> out;
  out.reserve(spansU.size() * spansV.size());
  const auto d = h.cols();
  for (size_t a = 0; a < spansU.size(); ++a)
    for (size_t b = 0; b < spansV.size(); ++b) {
      Matrix c((pu_ + 1) * (pv_ + 1), d);
      for (int i = 0; i <= pu_; ++i)
        for (int j = 0; j <= pv_; ++j)
          c.row(i * (pv_ + 1) + j) =
              h.row((static_cast<Eigen::Index>(a) * pu_ + i) * nv + static_cast<Eigen::Index>(b) * pv_ + j);
      const BernsteinPatch bp(pu_, pv_, std::move(c));
      out.push_back({isRational() ? BezierPatch::fromHomogeneous(bp) : BezierPatch(pu_, pv_, bp.coeffs()),
                     spansU[a], spansV[b], static_cast<int>(a), static_cast<int>(b)});
    }
  return out;
}

namespace {

// One derivative of a curve net (degree p over `knots`, one control row each): degree p - 1 over the knots without
// their end values. A degree-0 net differentiates to zero (and stays degree 0).
void differentiateNet(int& p, std::vector<double>& knots, Matrix& rows) {
  if (p == 0) {
    rows.setZero();
    return;
  }
  const Eigen::Index n = rows.rows();
  Matrix q = Matrix::Zero(n - 1, rows.cols());
  for (Eigen::Index i = 0; i + 1 < n; ++i) {
    const double den = knots[static_cast<size_t>(i + p + 1)] - knots[static_cast<size_t>(i + 1)];
    if (den > 0.0) q.row(i) = (static_cast<double>(p) / den) * (rows.row(i + 1) - rows.row(i));
  }
  knots = std::vector<double>(knots.begin() + 1, knots.end() - 1);
  --p;
  rows = std::move(q);
}

// The p + 1 Bezier rows of every span of a curve net that may be discontinuous: interior knots of multiplicity
// p + 1 or more cut the net into parts, each decomposed on its own.
std::vector<Matrix> bezierRowsBySpan(int p, const std::vector<double>& knots, const Matrix& rows) {
  std::vector<Matrix> out;
  const auto n = static_cast<size_t>(rows.rows());
  const double lo = knots[static_cast<size_t>(p)], hi = knots[n];
  size_t start = 0;
  auto flush = [&](size_t knotEnd) {
    std::vector<double> kn(knots.begin() + static_cast<std::ptrdiff_t>(start),
                           knots.begin() + static_cast<std::ptrdiff_t>(knotEnd));
    Matrix part = rows.middleRows(static_cast<Eigen::Index>(start),
                                  static_cast<Eigen::Index>(knotEnd - start) - p - 1);
    const std::vector<Interval> spans = detail::decompose(p, kn, part);
    for (size_t k = 0; k < spans.size(); ++k)
      out.emplace_back(part.middleRows(static_cast<Eigen::Index>(k) * p, p + 1));
  };
  for (size_t a = static_cast<size_t>(p) + 1; a < n; ++a) {
    const double b = knots[a];
    if (!(b > lo && b < hi) || knots[a - 1] == b) continue;
    size_t m = 0;
    while (a + m < knots.size() && knots[a + m] == b) ++m;
    if (m < static_cast<size_t>(p) + 1) continue;
    flush(a + static_cast<size_t>(p) + 1);
    start = a + m - static_cast<size_t>(p) - 1;
  }
  flush(knots.size());
  return out;
}

}  // namespace

std::vector<BernsteinPatch> BSplineSurface::homogeneousDerivativePatches(int ku, int kv) const {
  std::vector<double> kU = ku_.values(), kV = kv_.values();
  const Matrix h = homogeneous();
  const auto d = static_cast<int>(h.cols());
  int p = pu_, q = pv_, nu = nu_;
  Matrix ur = asURows(h, nu_);
  for (int k = 0; k < ku; ++k) differentiateNet(p, kU, ur);
  nu = static_cast<int>(ur.rows());
  Matrix vr = asURows(detail::transposeGrid(fromURows(ur, d), nu, nv_), nv_);
  for (int k = 0; k < kv; ++k) differentiateNet(q, kV, vr);
  const std::vector<Matrix> vSpans = bezierRowsBySpan(q, kV, vr);
  std::vector<std::vector<BernsteinPatch>> byV;  // [v span][u span]
  for (const Matrix& block : vSpans) {
    // block: (q + 1) x (nu d), entry (j, i d + c); as u rows: nu x ((q + 1) d), entry (i, j d + c).
    Matrix u(nu, (q + 1) * d);
    for (int j = 0; j <= q; ++j)
      for (int i = 0; i < nu; ++i) u.block(i, j * d, 1, d) = block.block(j, i * d, 1, d);
    std::vector<BernsteinPatch> col;
    for (const Matrix& piece : bezierRowsBySpan(p, kU, u))
      col.emplace_back(p, q, Matrix(Eigen::Map<const Matrix>(piece.data(), (p + 1) * (q + 1), d)));
    byV.push_back(std::move(col));
  }
  std::vector<BernsteinPatch> out;
  const size_t nU = byV.empty() ? 0 : byV.front().size();
  out.reserve(nU * byV.size());
  for (size_t a = 0; a < nU; ++a)
    for (size_t b = 0; b < byV.size(); ++b) out.push_back(byV[b][a]);
  return out;
}

BSplineSurface BSplineSurface::degreeElevated(int byU, int byV) const {
  std::vector<double> kU = ku_.values(), kV = kv_.values();
  Matrix h = homogeneous();
  int nu = nu_, nv = nv_;
  if (byU > 0)
    applyU(pu_, kU, h, nu, nv, [&](int p, auto& kn, auto& rows) { detail::elevateDegree(p, kn, rows, byU); });
  if (byV > 0)
    applyV(pv_, kV, h, nu, nv, [&](int p, auto& kn, auto& rows) { detail::elevateDegree(p, kn, rows, byV); });
  return fromHomogeneous(pu_ + std::max(byU, 0), pv_ + std::max(byV, 0), KnotVector(std::move(kU)),
                         KnotVector(std::move(kV)), nu, nv, h, isRational());
}

BSplineSurface BSplineSurface::reversedU() const {
  Matrix p(points_.rows(), points_.cols());
  VecX w(weights_.size());
  for (int i = 0; i < nu_; ++i)
    for (int j = 0; j < nv_; ++j) {
      p.row((nu_ - 1 - i) * nv_ + j) = points_.row(i * nv_ + j);
      if (isRational()) w[(nu_ - 1 - i) * nv_ + j] = weights_[i * nv_ + j];
    }
  return BSplineSurface(pu_, pv_, ku_.reversed(pu_), kv_, nu_, nv_, std::move(p), std::move(w));
}

BSplineSurface BSplineSurface::reversedV() const { return swappedUV().reversedU().swappedUV(); }

BSplineSurface BSplineSurface::swappedUV() const {
  Matrix p = detail::transposeGrid(points_, nu_, nv_);
  VecX w;
  if (isRational()) w = detail::transposeGrid(Matrix(weights_), nu_, nv_).col(0);
  return BSplineSurface(pv_, pu_, kv_, ku_, nv_, nu_, std::move(p), std::move(w));
}

BSplineSurface BSplineSurface::reparametrized(Interval u, Interval v) const {
  return BSplineSurface(pu_, pv_, ku_.reparametrized(pu_, u.lo, u.hi), kv_.reparametrized(pv_, v.lo, v.hi), nu_,
                        nv_, points_, weights_);
}

BSplineCurve BSplineSurface::homogeneousCrossDerivative(Edge e, int order) const {
  if (!isUEdge(e)) return swappedUV().homogeneousCrossDerivative(e == Edge::V0 ? Edge::U0 : Edge::U1, order);
  const Matrix h = homogeneous();
  const double u = (e == Edge::U0) ? domainU().lo : domainU().hi;
  Matrix rows = Matrix::Zero(nv_, h.cols());
  if (order <= pu_) {
    const int span = ku_.findSpan(pu_, u);
    const Matrix N = basisFunctionDerivatives(ku_, pu_, span, u, order);
    for (int r = 0; r <= pu_; ++r) {
      const double c = N(order, r);
      if (c == 0.0) continue;
      rows += c * h.middleRows(static_cast<Eigen::Index>(span - pu_ + r) * nv_, nv_);
    }
  }
  return BSplineCurve(pv_, kv_, std::move(rows));
}

Matrix BSplineSurface::crossDerivativeRows(Edge e, int maxOrder) const {
  assert(maxOrder >= 0);
  const bool uEdge = isUEdge(e), atEnd = e == Edge::U1 || e == Edge::V1;
  const int p = uEdge ? pu_ : pv_, nAlong = uEdge ? nv_ : nu_;
  const KnotVector& kc = uEdge ? ku_ : kv_;
  const double c = atEnd ? kc.domain(p).hi : kc.domain(p).lo;
  const bool rational = isRational();
  const int d = dim(), hd = d + (rational ? 1 : 0);
  Matrix out = Matrix::Zero(nAlong, static_cast<Eigen::Index>(maxOrder + 1) * hd);
  const int top = std::min(maxOrder, p);
  const int span = kc.findSpan(p, c);
  // Up to second derivatives on the stack (basisUpTo2 is A2.3 with the same arithmetic, so the same values).
  double fast[3][detail::kMaxFastBasisDegree + 1];
  Matrix slow;
  const bool onStack = top <= 2 && p <= detail::kMaxFastBasisDegree;
  if (onStack)
    detail::basisUpTo2(kc.values(), p, span, c, fast);
  else
    slow = basisFunctionDerivatives(kc, p, span, c, top);
  // kD > 0: three coordinates known at compile time (the common case; the same operations as kD = 0, which reads d).
  const auto accumulate = [&]<int kD>(std::integral_constant<int, kD>) {
    const int dd = kD > 0 ? kD : d;
    const double* pts = points_.data();
    const Eigen::Index cols = out.cols();
    for (int r = 0; r <= p; ++r) {
      const int across = span - p + r;
      for (int k = 0; k <= top; ++k) {
        const double nkr = onStack ? fast[k][r] : slow(k, r);
        // Reversed cross direction at the far edge: d/dn = -d/du there.
        const double coef = (atEnd && k % 2 == 1) ? -nkr : nkr;
        if (coef == 0.0) continue;
        for (int j = 0; j < nAlong; ++j) {
          const int flat = uEdge ? across * nv_ + j : j * nv_ + across;
          const double cw = coef * (rational ? weights_[flat] : 1.0);
          double* o = out.data() + j * cols + static_cast<Eigen::Index>(k) * hd;
          const double* x = pts + static_cast<Eigen::Index>(flat) * dd;
          for (int q = 0; q < dd; ++q) o[q] += cw * x[q];
          if (rational) o[dd] += cw;
        }
      }
    }
  };
  if (d == 3)
    accumulate(std::integral_constant<int, 3>{});
  else
    accumulate(std::integral_constant<int, 0>{});
  return out;
}

BSplineCurve BSplineSurface::crossDerivativeCurve(Edge e, int order) const {
  assert(order >= 0 && order <= 2);
  if (!isRational()) return homogeneousCrossDerivative(e, order);
  const BSplineCurve h0 = homogeneousCrossDerivative(e, 0);
  if (order == 0) return BSplineCurve::fromHomogeneous(h0.degree(), h0.knots(), h0.points(), true);
  // Cartesian derivatives of S = A / w across the edge, piece by piece in Bernstein form:
  //   S_n  = (w A_n - w_n A) / w^2
  //   S_nn = (w^2 A_nn - w w_nn A - 2 w_n (w A_n - w_n A)) / w^3.
  const BSplineCurve h1 = homogeneousCrossDerivative(e, 1);
  const BSplineCurve h2 = order == 2 ? homogeneousCrossDerivative(e, 2) : h1;
  auto piecesOf = [](const BSplineCurve& c, std::vector<Interval>& spans) {
    std::vector<double> k = c.knots().values();
    Matrix rows = c.points();
    spans = detail::decompose(c.degree(), k, rows);
    std::vector<BernsteinPoly> out;
    for (size_t s = 0; s < spans.size(); ++s)
      out.emplace_back(Matrix(rows.middleRows(static_cast<Eigen::Index>(s) * c.degree(), c.degree() + 1)));
    return out;
  };
  std::vector<Interval> spans;
  const auto P0 = piecesOf(h0, spans), P1 = piecesOf(h1, spans), P2 = piecesOf(h2, spans);
  const int d = dim();
  std::vector<BernsteinPoly> out;
  for (size_t s = 0; s < spans.size(); ++s) {
    const BernsteinPoly A = BernsteinPoly(Matrix(P0[s].coeffs().leftCols(d))), w = P0[s].component(d);
    const BernsteinPoly An = BernsteinPoly(Matrix(P1[s].coeffs().leftCols(d))), wn = P1[s].component(d);
    const BernsteinPoly num1 = product(w, An) - product(wn, A);
    BernsteinPoly num, den;
    if (order == 1) {
      num = num1;
      den = product(w, w);
    } else {
      const BernsteinPoly Ann = BernsteinPoly(Matrix(P2[s].coeffs().leftCols(d))), wnn = P2[s].component(d);
      num = product(product(w, w), Ann) - product(product(w, wnn), A) - 2.0 * product(wn, num1);
      den = product(product(w, w), w);
    }
    const int deg = std::max(num.degree(), den.degree());
    num = num.elevatedTo(deg);
    den = den.elevatedTo(deg);
    Matrix hrow(deg + 1, d + 1);
    hrow.leftCols(d) = num.coeffs();
    hrow.col(d) = den.coeffs().col(0);
    out.emplace_back(std::move(hrow));
  }
  return detail::curveFromBezierPieces(out, spans, true);
}

BSplineCurve BSplineSurface::boundaryCurve(Edge e) const {
  const bool uEdge = isUEdge(e), atEnd = e == Edge::U1 || e == Edge::V1;
  // Clamped across the edge (every Bezier patch, almost every B-spline patch): the boundary curve's control points
  // and weights are the surface's first or last row, copied (no basis functions, and exactly the stored values).
  const KnotVector& kc = uEdge ? ku_ : kv_;
  const int p = uEdge ? pu_ : pv_, n = uEdge ? nu_ : nv_;
  bool clamped = true;
  for (int i = 1; i <= p && clamped; ++i)
    clamped = atEnd ? kc[kc.size() - 1 - i] == kc[kc.size() - 1] : kc[i] == kc[0];
  if (clamped) {
    const int across = atEnd ? n - 1 : 0, nAlong = uEdge ? nv_ : nu_;
    Matrix pts(nAlong, points_.cols());
    VecX w(isRational() ? nAlong : 0);
    for (int j = 0; j < nAlong; ++j) {
      const int flat = uEdge ? across * nv_ + j : j * nv_ + across;
      pts.row(j) = points_.row(flat);
      if (isRational()) w[j] = weights_[flat];
    }
    return BSplineCurve(uEdge ? pv_ : pu_, uEdge ? kv_ : ku_, std::move(pts), std::move(w));
  }
  return BSplineCurve::fromHomogeneous(uEdge ? pv_ : pu_, uEdge ? kv_ : ku_, crossDerivativeRows(e, 0), isRational());
}

BSplineSurface BSplineSurface::orientedFrom(Edge e) const {
  switch (e) {
    case Edge::U0: return *this;
    case Edge::U1: return reversedU();
    case Edge::V0: return swappedUV();
    case Edge::V1: return swappedUV().reversedU();
  }
  return *this;
}

// ---------------------------------------------------------------------------------------------------------------
// GridEvaluator

GridEvaluator::GridEvaluator(const BSplineSurface& surface, std::vector<double> us, std::vector<double> vs)
    : s_(&surface), us_(std::move(us)), vs_(std::move(vs)) {
  const int p = surface.degreeU(), q = surface.degreeV();
  spanU_.resize(us_.size());
  spanV_.resize(vs_.size());
  basisU_.resize(static_cast<Eigen::Index>(us_.size()), 2 * (p + 1));
  basisV_.resize(static_cast<Eigen::Index>(vs_.size()), 2 * (q + 1));
  for (size_t a = 0; a < us_.size(); ++a) {
    spanU_[a] = surface.knotsU().findSpan(p, us_[a]);
    const Matrix N = basisFunctionDerivatives(surface.knotsU(), p, spanU_[a], us_[a], 1);
    basisU_.row(static_cast<Eigen::Index>(a)) << N.row(0), N.row(1);
  }
  for (size_t b = 0; b < vs_.size(); ++b) {
    spanV_[b] = surface.knotsV().findSpan(q, vs_[b]);
    const Matrix N = basisFunctionDerivatives(surface.knotsV(), q, spanV_[b], vs_[b], 1);
    basisV_.row(static_cast<Eigen::Index>(b)) << N.row(0), N.row(1);
  }
}

namespace {
// The per-point blend of GridEvaluator, for D = 3 (polynomial) or 4 (homogeneous) coordinates.
template <int D>
void gridKernel(const double* H, int p, int q, int nv, const std::vector<int>& spanU, const std::vector<int>& spanV,
                const Matrix& basisU, const Matrix& basisV, double* out0, double* outU, double* outV) {
  std::vector<double> T(static_cast<size_t>(nv * D)), Tu(static_cast<size_t>(nv * D));
  const size_t nvs = spanV.size();
  for (size_t a = 0; a < spanU.size(); ++a) {
    const double* Nu = basisU.row(static_cast<Eigen::Index>(a)).data();
    const double* Nu1 = Nu + (p + 1);
    const int i0 = spanU[a] - p;
    std::fill(T.begin(), T.end(), 0.0);
    std::fill(Tu.begin(), Tu.end(), 0.0);
    for (int r = 0; r <= p; ++r) {
      const double* row = H + static_cast<size_t>(i0 + r) * static_cast<size_t>(nv * D);
      const double n0 = Nu[r], n1 = Nu1[r];
      double* t = T.data();
      double* tu = Tu.data();
      for (int k = 0; k < nv * D; ++k) {
        t[k] += n0 * row[k];
        tu[k] += n1 * row[k];
      }
    }
    for (size_t b = 0; b < nvs; ++b) {
      const double* Nv = basisV.row(static_cast<Eigen::Index>(b)).data();
      const double* Nv1 = Nv + (q + 1);
      const double* t = T.data() + static_cast<size_t>((spanV[b] - q) * D);
      const double* tu = Tu.data() + static_cast<size_t>((spanV[b] - q) * D);
      double S[D] = {}, Su[D] = {}, Sv[D] = {};
      for (int c = 0; c <= q; ++c) {
        const double m0 = Nv[c], m1 = Nv1[c];
        for (int k = 0; k < D; ++k) {
          S[k] += m0 * t[c * D + k];
          Su[k] += m0 * tu[c * D + k];
          Sv[k] += m1 * t[c * D + k];
        }
      }
      if constexpr (D == 4) {
        const double w = S[3];
        for (int k = 0; k < 3; ++k) {
          S[k] /= w;
          Su[k] = (Su[k] - Su[3] * S[k]) / w;
          Sv[k] = (Sv[k] - Sv[3] * S[k]) / w;
        }
      }
      const size_t o = 3 * (a * nvs + b);
      for (int k = 0; k < 3; ++k) {
        if (out0) out0[o + static_cast<size_t>(k)] = S[k];
        if (outU) outU[o + static_cast<size_t>(k)] = Su[k];
        if (outV) outV[o + static_cast<size_t>(k)] = Sv[k];
      }
    }
  }
}
}  // namespace

void GridEvaluator::evaluate(Matrix* points, Matrix* du, Matrix* dv) const {
  const BSplineSurface& s = *s_;
  assert(s.dim() == 3);
  const auto total = static_cast<Eigen::Index>(us_.size() * vs_.size());
  if (points) points->resize(total, 3);
  if (du) du->resize(total, 3);
  if (dv) dv->resize(total, 3);
  double* o0 = points ? points->data() : nullptr;
  double* oU = du ? du->data() : nullptr;
  double* oV = dv ? dv->data() : nullptr;
  if (s.isRational()) {
    const Matrix h = s.homogeneous();
    gridKernel<4>(h.data(), s.degreeU(), s.degreeV(), s.numV(), spanU_, spanV_, basisU_, basisV_, o0, oU, oV);
  } else {
    gridKernel<3>(s.points().data(), s.degreeU(), s.degreeV(), s.numV(), spanU_, spanV_, basisU_, basisV_, o0, oU,
                  oV);
  }
}

}  // namespace seam

namespace seam::detail {

Result<BSplineSurface> extendedSurface(const BSplineSurface& s, Interval u, Interval v) {
  const Interval du = s.domainU(), dv = s.domainV();
  if (!(u.lo <= du.lo && u.hi >= du.hi && v.lo <= dv.lo && v.hi >= dv.hi) || !std::isfinite(u.lo) ||
      !std::isfinite(u.hi) || !std::isfinite(v.lo) || !std::isfinite(v.hi))
    return invalidInput(fmt::format("the domain [{}, {}] x [{}, {}] does not contain the surface's [{}, {}] x [{}, {}]",
                                    u.lo, u.hi, v.lo, v.hi, du.lo, du.hi, dv.lo, dv.hi));
  std::vector<double> kU = s.knotsU().values(), kV = s.knotsV().values();
  Matrix h = s.homogeneous();
  int nu = s.numU(), nv = s.numV();
  applyU(s.degreeU(), kU, h, nu, nv, [&](int p, auto& kn, auto& rows) { extendDomain(p, kn, rows, u.lo, u.hi); });
  applyV(s.degreeV(), kV, h, nu, nv, [&](int p, auto& kn, auto& rows) { extendDomain(p, kn, rows, v.lo, v.hi); });
  if (!h.allFinite()) return invalidInput("the continued control net is not finite");
  if (s.isRational() && (h.col(h.cols() - 1).array() <= 0.0).any())
    return invalidInput("the continued control net has a weight that is not positive");
  return BSplineSurface::fromHomogeneous(s.degreeU(), s.degreeV(), KnotVector(std::move(kU)),
                                         KnotVector(std::move(kV)), nu, nv, h, s.isRational());
}

}  // namespace seam::detail
