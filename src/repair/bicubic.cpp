// C1 bicubic B-splines <-> per-patch Bezier coefficients, following Lai-Lian-Cassidy §2.2 and §2.3 literally
// (paper indices in the comments; see docs/algorithms/lai-lian-cassidy.md).
#include "seam/repair/bicubic.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace seam {

Status checkC1CubicKnots(const KnotVector& knots) {
  const std::vector<double> b = knots.breakpoints();
  const std::vector<int> mult = knots.multiplicities();
  if (b.size() < 2) return {ErrorCode::kUnsupported, "the knot vector has an empty domain"};
  if (mult.front() != 4 || mult.back() != 4)
    return {ErrorCode::kUnsupported,
            fmt::format("end knots have multiplicities {} and {} (a C1 bicubic B-spline has 4-fold ends)",
                        mult.front(), mult.back())};
  for (size_t k = 1; k + 1 < b.size(); ++k)
    if (mult[k] != 2)
      return {ErrorCode::kUnsupported,
              fmt::format("interior knot {} has multiplicity {} (a C1 bicubic B-spline has double interior knots)",
                          b[k], mult[k])};
  return Status::ok();
}

Status checkC1Bicubic(const BSplineSurface& s) {
  if (s.isRational()) return {ErrorCode::kUnsupported, "the surface is rational (the paper's method is polynomial)"};
  if (s.degreeU() != 3 || s.degreeV() != 3)
    return {ErrorCode::kUnsupported,
            fmt::format("degree ({}, {}) is not bicubic", s.degreeU(), s.degreeV())};
  if (Status st = checkC1CubicKnots(s.knotsU()); !st) return st.withContext("u");
  if (Status st = checkC1CubicKnots(s.knotsV()); !st) return st.withContext("v");
  return Status::ok();
}

std::vector<double> c1CubicBreakpoints(const KnotVector& knots) { return knots.breakpoints(); }

std::vector<double> c1CubicAlphas(const KnotVector& knots) {
  const std::vector<double> b = knots.breakpoints();
  const int m = static_cast<int>(b.size()) - 1;
  std::vector<double> alpha(static_cast<size_t>(m) + 1);
  // Paper: u_{2i} = b_{i-1} for i = 1..m+1, u_0 = u_2 and u_{2m+4} = u_{2m+2}.
  auto u2 = [&](int i) {  // u_{2i}
    const int k = std::clamp(i - 1, 0, m);
    return b[static_cast<size_t>(k)];
  };
  for (int i = 0; i <= m; ++i) {
    const double num = u2(i + 2) - u2(i + 1), den = u2(i + 2) - u2(i);
    alpha[static_cast<size_t>(i)] = den > 0.0 ? num / den : 0.0;
  }
  alpha.front() = 1.0;
  alpha.back() = 0.0;
  return alpha;
}

KnotVector c1CubicKnots(const std::vector<double>& breakpoints) {
  std::vector<double> t;
  for (int r = 0; r < 4; ++r) t.push_back(breakpoints.front());
  for (size_t k = 1; k + 1 < breakpoints.size(); ++k) {
    t.push_back(breakpoints[k]);
    t.push_back(breakpoints[k]);
  }
  for (int r = 0; r < 4; ++r) t.push_back(breakpoints.back());
  return KnotVector(std::move(t));
}

Result<BicubicBezierNet> c1BicubicToBezier(const BSplineSurface& s) {
  if (Status st = checkC1Bicubic(s); !st) return st;
  const std::vector<double> alpha = c1CubicAlphas(s.knotsU()), xi = c1CubicAlphas(s.knotsV());
  BicubicBezierNet net;
  net.breaksU = s.knotsU().breakpoints();
  net.breaksV = s.knotsV().breakpoints();
  net.m = static_cast<int>(net.breaksU.size()) - 1;
  net.n = static_cast<int>(net.breaksV.size()) - 1;
  const int dim = s.dim();
  auto A = [&](int i) { return alpha[static_cast<size_t>(i)]; };
  auto B = [&](int i) { return 1.0 - alpha[static_cast<size_t>(i)]; };
  auto X = [&](int j) { return xi[static_cast<size_t>(j)]; };
  auto E = [&](int j) { return 1.0 - xi[static_cast<size_t>(j)]; };
  auto d = [&](int i, int j) -> VecX { return s.point(i, j).transpose(); };
  // The paper's arrays (§2.2): h_{k,j} (k = 0..2m+1, j = 1..n+1), v_{i,l} (i = 1..m+1, l = 0..2n+1), a_{i,j}.
  auto h = [&](int k, int j) -> VecX { return X(j - 1) * d(k, 2 * j - 2) + E(j - 1) * d(k, 2 * j - 1); };
  auto v = [&](int i, int l) -> VecX { return A(i - 1) * d(2 * i - 2, l) + B(i - 1) * d(2 * i - 1, l); };
  auto a = [&](int i, int j) -> VecX { return A(i - 1) * h(2 * i - 2, j) + B(i - 1) * h(2 * i - 1, j); };
  net.patches.assign(static_cast<size_t>(net.m * net.n), Matrix(16, dim));
  for (int i = 1; i <= net.m; ++i)
    for (int j = 1; j <= net.n; ++j) {
      // (2.12): [c_{i,j,l,3-k}]_{k,l}; row k of the paper's matrix holds Bezier v-index 3-k, column l u-index l.
      const VecX rowsK[4][4] = {
          {a(i, j + 1), h(2 * i - 1, j + 1), h(2 * i, j + 1), a(i + 1, j + 1)},
          {v(i, 2 * j), d(2 * i - 1, 2 * j), d(2 * i, 2 * j), v(i + 1, 2 * j)},
          {v(i, 2 * j - 1), d(2 * i - 1, 2 * j - 1), d(2 * i, 2 * j - 1), v(i + 1, 2 * j - 1)},
          {a(i, j), h(2 * i - 1, j), h(2 * i, j), a(i + 1, j)},
      };
      Matrix& c = net.patch(i - 1, j - 1);
      for (int k = 0; k < 4; ++k)
        for (int l = 0; l < 4; ++l) c.row(l * 4 + (3 - k)) = rowsK[k][l].transpose();
    }
  return net;
}

Result<BSplineSurface> c1BicubicFromBezier(const BicubicBezierNet& net, double relTol) {
  const int m = net.m, n = net.n;
  if (m < 1 || n < 1 || static_cast<int>(net.breaksU.size()) != m + 1 ||
      static_cast<int>(net.breaksV.size()) != n + 1 || static_cast<int>(net.patches.size()) != m * n)
    return invalidInput("Bezier net: sizes of breakpoints and patches do not match");
  const auto dim = net.patches.front().cols();
  double scale = 0.0;
  for (const Matrix& c : net.patches) {
    if (c.rows() != 16 || c.cols() != dim) return invalidInput("Bezier net: every patch needs 16 coefficients");
    scale = std::max(scale, c.cwiseAbs().maxCoeff());
  }
  for (size_t k = 0; k + 1 < net.breaksU.size(); ++k)
    if (!(net.breaksU[k] < net.breaksU[k + 1])) return invalidInput("Bezier net: u breakpoints must increase");
  for (size_t k = 0; k + 1 < net.breaksV.size(); ++k)
    if (!(net.breaksV[k] < net.breaksV[k + 1])) return invalidInput("Bezier net: v breakpoints must increase");
  const KnotVector ku = c1CubicKnots(net.breaksU), kv = c1CubicKnots(net.breaksV);
  const std::vector<double> alpha = c1CubicAlphas(ku), xi = c1CubicAlphas(kv);
  // c(i, j, k, l) with the paper's 1-based patch indices.
  auto c = [&](int i, int j, int k, int l) -> VecX { return net.patch(i - 1, j - 1).row(k * 4 + l).transpose(); };
  const double tol = relTol * std::max(scale, 1.0);
  // (2.13): along the interior u-lines, c_{i,j,0,l} = c_{i-1,j,3,l} = alpha_{i-1} c_{i-1,j,2,l} + beta_{i-1} c_{i,j,1,l}.
  for (int i = 2; i <= m; ++i)
    for (int j = 1; j <= n; ++j)
      for (int l = 0; l < 4; ++l) {
        const double a = alpha[static_cast<size_t>(i - 1)];
        const double e1 = (c(i, j, 0, l) - c(i - 1, j, 3, l)).norm();
        const double e2 = (c(i, j, 0, l) - (a * c(i - 1, j, 2, l) + (1.0 - a) * c(i, j, 1, l))).norm();
        if (e1 > tol || e2 > tol)
          return Status(ErrorCode::kNoSolution,
                        fmt::format("condition (2.13) fails on the u-line {} (patches {} and {}, v-row {}): "
                                    "mismatch {:.3g}",
                                    net.breaksU[static_cast<size_t>(i - 1)], i - 1, i, l, std::max(e1, e2)));
      }
  // (2.14): along the interior v-lines, c_{i,j,k,0} = c_{i,j-1,k,3} = xi_{j-1} c_{i,j-1,k,2} + eta_{j-1} c_{i,j,k,1}.
  for (int i = 1; i <= m; ++i)
    for (int j = 2; j <= n; ++j)
      for (int k = 0; k < 4; ++k) {
        const double x = xi[static_cast<size_t>(j - 1)];
        const double e1 = (c(i, j, k, 0) - c(i, j - 1, k, 3)).norm();
        const double e2 = (c(i, j, k, 0) - (x * c(i, j - 1, k, 2) + (1.0 - x) * c(i, j, k, 1))).norm();
        if (e1 > tol || e2 > tol)
          return Status(ErrorCode::kNoSolution,
                        fmt::format("condition (2.14) fails on the v-line {} (patches {} and {}, u-column {}): "
                                    "mismatch {:.3g}",
                                    net.breaksV[static_cast<size_t>(j - 1)], j - 1, j, k, std::max(e1, e2)));
      }
  const int nu = 2 * m + 2, nv = 2 * n + 2;
  Matrix pts(static_cast<Eigen::Index>(nu) * nv, dim);
  auto d = [&](int i, int j) { return pts.row(static_cast<Eigen::Index>(i) * nv + j); };
  // (2.15) corners.
  d(0, 0) = c(1, 1, 0, 0).transpose();
  d(2 * m + 1, 0) = c(m, 1, 3, 0).transpose();
  d(0, 2 * n + 1) = c(1, n, 0, 3).transpose();
  d(2 * m + 1, 2 * n + 1) = c(m, n, 3, 3).transpose();
  // (2.16) horizontal boundaries.
  for (int i = 1; i <= m; ++i) {
    d(2 * i - 1, 0) = c(i, 1, 1, 0).transpose();
    d(2 * i, 0) = c(i, 1, 2, 0).transpose();
    d(2 * i - 1, 2 * n + 1) = c(i, n, 1, 3).transpose();
    d(2 * i, 2 * n + 1) = c(i, n, 2, 3).transpose();
  }
  // (2.17) vertical boundaries.
  for (int j = 1; j <= n; ++j) {
    d(0, 2 * j - 1) = c(1, j, 0, 1).transpose();
    d(0, 2 * j) = c(1, j, 0, 2).transpose();
    d(2 * m + 1, 2 * j - 1) = c(m, j, 3, 1).transpose();
    d(2 * m + 1, 2 * j) = c(m, j, 3, 2).transpose();
  }
  // (2.18) interior.
  for (int i = 1; i <= m; ++i)
    for (int j = 1; j <= n; ++j) {
      d(2 * i - 1, 2 * j) = c(i, j, 1, 2).transpose();
      d(2 * i, 2 * j) = c(i, j, 2, 2).transpose();
      d(2 * i - 1, 2 * j - 1) = c(i, j, 1, 1).transpose();
      d(2 * i, 2 * j - 1) = c(i, j, 2, 1).transpose();
    }
  return BSplineSurface(3, 3, ku, kv, nu, nv, std::move(pts));
}

}  // namespace seam
