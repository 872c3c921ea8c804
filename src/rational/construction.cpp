// Theorem 6 / eq. (4.8) of Zheng-Wang-Liang; see include/seam/rational/construction.h.
#include "seam/rational/construction.h"

#include <fmt/format.h>

#include <cmath>

#include "rational/rational_internal.h"
#include "seam/core/tolerances.h"
#include "seam/rational/connecting.h"
#include "seam/spline/bezier.h"

namespace seam::rational {

namespace {
using detail::factorial;

/// nabla_1^h nabla_2^k Q_{i0, j0} (forward differences in the first and the second index).
Eigen::RowVectorXd nabla(const BernsteinPatch& q, int h, int k, int i0, int j0) {
  Eigen::RowVectorXd out = Eigen::RowVectorXd::Zero(q.dim());
  for (int a = 0; a <= h; ++a)
    for (int b = 0; b <= k; ++b) {
      const double sgn = ((h - a) + (k - b)) % 2 == 0 ? 1.0 : -1.0;
      out += (sgn * binomial(h, a) * binomial(k, b)) * q.coeff(i0 + a, j0 + b);
    }
  return out;
}
}  // namespace

Result<Matrix> gcnColumns(const BernsteinPatch& q, const ShapeParameters& sp, int mbar) {
  const int n = sp.order();
  if (static_cast<int>(sp.alpha.size()) != n || static_cast<int>(sp.beta0.size()) != n ||
      static_cast<int>(sp.beta1.size()) != n)
    return invalidInput(fmt::format("shape parameters: gamma, alpha, beta0, beta1 must all have n entries (found {}, "
                                    "{}, {}, {})", sp.gamma.size(), sp.alpha.size(), sp.beta0.size(), sp.beta1.size()));
  if (n > kMaxGcnOrder) return invalidInput(fmt::format("shape parameters: order {} > {}", n, kMaxGcnOrder));
  if (mbar < n)
    return invalidInput(fmt::format("degree {} across the edge is too low for GC^{} (at least {} needed)", mbar, n, n));
  for (const auto* v : {&sp.gamma, &sp.alpha, &sp.beta0, &sp.beta1})
    for (double x : *v)
      if (!std::isfinite(x)) return invalidInput("shape parameters must be finite");
  if (n >= 1 && sp.alpha[0] == 0.0)
    return invalidInput("shape parameter alpha_1 must not be 0 (p_1 = alpha_1 is the transversal speed, Theorem 2)");
  const int m = q.degreeU(), l = q.degreeV();
  auto gamma = [&](int s) { return s == 0 ? 1.0 : sp.gamma[static_cast<size_t>(s - 1)]; };
  Matrix out(static_cast<Eigen::Index>((n + 1) * (l + 1)), q.dim());
  for (int i = 0; i <= l; ++i) out.row(i) = q.coeff(m, i);
  for (int s = 1; s <= n; ++s) {
    Matrix acc(l + 1, q.dim());
    for (int i = 0; i <= l; ++i) acc.row(i) = gamma(s) * q.coeff(m, i);
    for (int d = 1; d <= s; ++d)
      for (int k = 1; k <= d; ++k)
        for (const std::vector<int>& r : detail::compositions(d, k))
          for (int h = 0; h <= k; ++h) {
            if (h > m || k - h > l) continue;  // the derivative d^k Q / du^h dv^{k-h} vanishes
            const int L = l - k + h;
            double base = binomial(s, d) * detail::lemma1Coefficient(d, h, r) * factorial(m) / factorial(m - h) *
                          factorial(l) / factorial(L) * gamma(s - d);
            for (int e = 0; e < h; ++e) base *= sp.alpha[static_cast<size_t>(r[static_cast<size_t>(e)] - 1)];
            if (base == 0.0) continue;
            const int nb = k - h;  // linear factors q_{r_{h+1}}(v) .. q_{r_k}(v)
            for (int j = 0; j <= L; ++j) {
              const Eigen::RowVectorXd diff = nabla(q, h, nb, m - h, j);
              for (int mask = 0; mask < (1 << nb); ++mask) {
                double beta = 1.0;
                int ones = 0;
                for (int e = 0; e < nb; ++e) {
                  const size_t idx = static_cast<size_t>(r[static_cast<size_t>(h + e)] - 1);
                  if (mask & (1 << e)) {
                    beta *= sp.beta1[idx];
                    ++ones;
                  } else {
                    beta *= sp.beta0[idx];
                  }
                }
                const int ii = j + ones;
                acc.row(ii) += (base * beta * binomial(L, j) / binomial(l, ii)) * diff;
              }
            }
          }
    const double scale = factorial(mbar - s) / factorial(mbar);
    for (int i = 0; i <= l; ++i) {
      Eigen::RowVectorXd v = scale * acc.row(i);
      for (int j = 0; j < s; ++j) {
        const double sgn = (s - j) % 2 == 0 ? 1.0 : -1.0;
        v -= (binomial(s, j) * sgn) * out.row(j * (l + 1) + i);
      }
      out.row(s * (l + 1) + i) = v;
    }
  }
  return out;
}

Result<BernsteinPatch> extendBezier(const BernsteinPatch& q, const ShapeParameters& sp, const ExtensionOptions& opt) {
  if (q.dim() != 4) return invalidInput(fmt::format("extendBezier: homogeneous patch of dimension 4 expected, found {}", q.dim()));
  const int n = sp.order(), m = q.degreeU(), l = q.degreeV();
  const int mbar = opt.degree < 0 ? std::max(m, n) : opt.degree;
  auto cols = gcnColumns(q, sp, mbar);
  if (!cols) return cols.status();
  Matrix all(static_cast<Eigen::Index>((mbar + 1) * (l + 1)), 4);
  all.topRows(cols->rows()) = *cols;
  const int rest = mbar - n;
  if (rest > 0) {
    if (opt.remainingColumns) {
      const Matrix& rc = *opt.remainingColumns;
      if (rc.rows() != rest * (l + 1) || rc.cols() != 4)
        return invalidInput(fmt::format("remaining columns: {} x 4 homogeneous points expected (columns {}..{} of "
                                        "{} points), found {} x {}", rest * (l + 1), n + 1, mbar, l + 1, rc.rows(),
                                        rc.cols()));
      all.bottomRows(rc.rows()) = rc;
    } else {
      const BernsteinPatch qe = m < mbar ? q.elevatedTo(mbar, l) : q;
      const int M = qe.degreeU();
      for (int s = n + 1; s <= mbar; ++s)
        for (int i = 0; i <= l; ++i) {
          const auto edge = qe.coeff(M, i);
          const auto src = qe.coeff(M - s, i);
          const double we = edge[3], ws = src[3];
          const Eigen::RowVector3d p = 2.0 * edge.head(3) / we - src.head(3) / ws;
          Eigen::RowVector4d h;
          h << ws * p, ws;
          all.row(s * (l + 1) + i) = h;
        }
    }
  }
  for (int s = 0; s <= mbar; ++s)
    for (int i = 0; i <= l; ++i) {
      const double w = all(s * (l + 1) + i, 3);
      if (!(w > 0.0) || !all.row(s * (l + 1) + i).allFinite())
        return Status(ErrorCode::kNoSolution,
                      fmt::format("the constructed control point ({}, {}) has weight {} (must be positive): choose "
                                  "other shape parameters (gamma, alpha, beta)", s, i, w));
    }
  return BernsteinPatch(mbar, l, std::move(all));
}

Result<BSplineSurface> extendSurface(const BSplineSurface& surface, Edge e, const ShapeParameters& sp,
                                     const ExtensionOptions& opt) {
  if (surface.dim() != 3) return invalidInput("extendSurface: 3-D control points expected");
  const BSplineSurface oriented = surface.orientedFrom(e);
  const std::vector<BezierPatchPiece> pieces = oriented.bezierPatches();
  const BezierPatchPiece* piece = nullptr;
  int along = 0;
  for (const BezierPatchPiece& p : pieces)
    if (p.spanU == 0) {
      ++along;
      piece = &p;
    }
  if (along != 1 || piece == nullptr)
    return Status(ErrorCode::kUnsupported,
                  fmt::format("edge {} consists of {} Bezier spans; the construction (4.8) needs a single span along "
                              "the edge (split the patch at its knots first)", edgeName(e), along));
  // Homogeneous piece (w P, w), in the paper's frame: reversed across so that the edge is u = 1.
  const BezierPatch& bp = piece->patch;
  Matrix h(bp.points().rows(), 4);
  for (int i = 0; i <= bp.degreeU(); ++i)
    for (int j = 0; j <= bp.degreeV(); ++j) {
      const int row = i * (bp.degreeV() + 1) + j;
      const double w = bp.weight(i, j);
      h.row(row).head(3) = w * bp.point(i, j).head(3);
      h(row, 3) = w;
    }
  const BernsteinPatch q = BernsteinPatch(bp.degreeU(), bp.degreeV(), std::move(h)).reversedU();
  auto rbar = extendBezier(q, sp, opt);
  if (!rbar) return rbar.status();
  const BernsteinPatch& Q = *rbar;
  bool polynomial = true;
  for (Eigen::Index r = 0; r < Q.coeffs().rows(); ++r)
    if (std::abs(Q.coeffs()(r, 3) - 1.0) > kRoundoff) polynomial = false;
  Matrix pts(Q.coeffs().rows(), 3);
  VecX w(Q.coeffs().rows());
  for (Eigen::Index r = 0; r < Q.coeffs().rows(); ++r) {
    w[r] = Q.coeffs()(r, 3);
    pts.row(r) = Q.coeffs().row(r).head(3) / w[r];
  }
  const BezierPatch out = polynomial ? BezierPatch(Q.degreeU(), Q.degreeV(), pts)
                                     : BezierPatch(Q.degreeU(), Q.degreeV(), pts, w);
  return out.toBSpline({0.0, piece->u.length()}, piece->v);
}

}  // namespace seam::rational
