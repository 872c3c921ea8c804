// The general GC^n condition (3.8), sampled; see include/seam/rational/connecting.h and
// docs/algorithms/zheng-wang-liang.md.
#include "seam/rational/connecting.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "rational/rational_internal.h"
#include "seam/core/tolerances.h"

namespace seam::rational {

namespace {

using detail::factorial;
using detail::Series;

Series taylorOf(const std::vector<double>& derivs, int n) {
  // derivs[i-1] = i-th derivative; Taylor coefficient = derivative / i!
  Series s(static_cast<size_t>(n + 1), 0.0);
  for (int i = 1; i <= n && i <= static_cast<int>(derivs.size()); ++i)
    s[static_cast<size_t>(i)] = derivs[static_cast<size_t>(i - 1)] / factorial(i);
  return s;
}

/// Taylor coefficients of the Cartesian curve R(t) / w(t) from those of (R, w), and the magnitudes of the terms of
/// each coefficient (for relative comparisons).
void cartesianSeries(const std::vector<Vec4>& h, std::vector<Vec3>& r, std::vector<double>& mag) {
  const size_t n = h.size();
  r.assign(n, Vec3::Zero());
  mag.assign(n, 0.0);
  const double w0 = h[0][3];
  for (size_t k = 0; k < n; ++k) {
    Vec3 acc = h[k].head<3>();
    double m = h[k].head<3>().norm();
    for (size_t j = 1; j <= k; ++j) {
      acc -= h[j][3] * r[k - j];
      m += std::abs(h[j][3]) * r[k - j].norm();
    }
    r[k] = acc / w0;
    mag[k] = m / std::abs(w0);
  }
}

}  // namespace

Vec4 totalDifferential(const DerivativeTable& d, std::span<const double> p, std::span<const double> q, int m) {
  Vec4 out = Vec4::Zero();
  if (m == 0) return d[0][0];
  for (int k = 1; k <= m; ++k)
    for (const std::vector<int>& r : detail::compositions(m, k))
      for (int h = 0; h <= k; ++h) {
        double f = detail::lemma1Coefficient(m, h, r);
        for (int i = 0; i < k; ++i)
          f *= (i < h ? p : q)[static_cast<size_t>(r[static_cast<size_t>(i)] - 1)];
        out += f * d[static_cast<size_t>(h)][static_cast<size_t>(k - h)];
      }
  return out;
}

Result<ConnectingSample> connectingFunctionsAt(const HomogeneousSurface& r, const ParameterLine& e1,
                                               const HomogeneousSurface& rbar, const ParameterLine& e2, double s,
                                               const ConnectingOptions& opt) {
  const int n = opt.order;
  if (n < 0 || n > kMaxGcnOrder)
    return invalidInput(fmt::format("GC^n order {} out of range [0, {}]", n, kMaxGcnOrder));
  for (const HomogeneousSurface* x : {&r, &rbar})
    if (x->maxOrder() < n)
      return invalidInput(fmt::format("surface \"{}\" provides derivatives up to order {} only, order {} needed",
                                      x->name(), x->maxOrder(), n));
  std::vector<double> pbar(static_cast<size_t>(n), 0.0), qbar(static_cast<size_t>(n), 0.0);
  for (size_t i = 0; i < pbar.size() && i < opt.pbar.size(); ++i) pbar[i] = opt.pbar[i];
  for (size_t i = 0; i < qbar.size() && i < opt.qbar.size(); ++i) qbar[i] = opt.qbar[i];
  if (n >= 1) {
    const double det = pbar[0] * e2.direction.y() - qbar[0] * e2.direction.x();
    const double ref = std::hypot(pbar[0], qbar[0]) * e2.direction.norm();
    if (!(std::abs(det) > opt.transversalTol * ref))
      return invalidInput(fmt::format("transversal (pbar_1, qbar_1) = ({}, {}) is tangent to the boundary E2 of "
                                      "\"{}\" (det[pbar_1 qbar_1; ubar' vbar'] = 0, Theorem 2)",
                                      pbar[0], qbar[0], rbar.name()));
  }
  const Vec2 x1 = e1.at(s), x2 = e2.at(s);
  auto dr = r.derivatives(x1.x(), x1.y(), n);
  if (!dr) return dr.status();
  auto drb = rbar.derivatives(x2.x(), x2.y(), n);
  if (!drb) return drb.status();
  const DerivativeTable& d = *dr;

  ConnectingSample out;
  out.s = s;
  // Left side of (3.4): the t-series of Qbar(psi1).
  const std::vector<Vec4> L = detail::composeSeries(*drb, taylorOf(pbar, n), taylorOf(qbar, n), n);

  // Order 0: Qbar = c_0 Q.
  const Vec4& Q = d[0][0];
  if (!(Q.norm() > 0.0))
    return Status(ErrorCode::kDegenerate, fmt::format("surface \"{}\": Q = 0 at s = {}", r.name(), s));
  Series e(static_cast<size_t>(n + 1), 0.0), P(static_cast<size_t>(n + 1), 0.0), C(static_cast<size_t>(n + 1), 0.0);
  e[0] = L[0].dot(Q) / Q.squaredNorm();
  {
    const double scale = std::max(L[0].norm(), std::abs(e[0]) * Q.norm());
    out.residual.push_back(scale > 0.0 ? (L[0] - e[0] * Q).norm() / scale : 0.0);
  }
  out.c.push_back(e[0]);
  if (!(L[0].norm() > 0.0))
    return Status(ErrorCode::kDegenerate, fmt::format("surface \"{}\": Qbar = 0 at s = {}", rbar.name(), s));
  if (!(std::abs(e[0]) * Q.norm() > kRoundoff * L[0].norm())) {
    // Qbar is orthogonal to Q: no GC^0, and nothing of higher order can be solved.
    out.residual[0] = 1.0;
    out.residual.resize(static_cast<size_t>(n + 1), 1.0);
    out.c.resize(static_cast<size_t>(n + 1), 0.0);
    out.p.assign(static_cast<size_t>(n), 0.0);
    out.q.assign(static_cast<size_t>(n), 0.0);
    out.cartesianMismatch.assign(static_cast<size_t>(n + 1), 1.0);
    return out;
  }

  if (n >= 1) {
    const Vec4& Qu = d[1][0];
    const Vec4& Qv = d[0][1];
    // Lemma 2: the best-conditioned minor of [Q Q_u Q_v] (columns normalised).
    const Vec4 nQ = Q.normalized(), nQu = Qu.norm() > 0 ? Vec4(Qu.normalized()) : Qu,
               nQv = Qv.norm() > 0 ? Vec4(Qv.normalized()) : Qv;
    double best = -1.0;
    for (int i = 1; i <= 4; ++i) {
      const double b = std::abs(detail::bracket4(i, nQ, nQu, nQv));
      if (b > best) {
        best = b;
        out.minor = i;
      }
    }
    if (!(best > kRoundoff))
      return Status(ErrorCode::kDegenerate,
                    fmt::format("surface \"{}\" is not regular at s = {}: Q, Q_u, Q_v are dependent (Lemma 2)",
                                r.name(), s));
    const int mi = out.minor;
    const double D = detail::bracket4(mi, Q, Qu, Qv);
    for (int m = 1; m <= n; ++m) {
      // Known part of the t^m coefficient of e(t) Q(psi2(t)) with e_m = P_m = C_m = 0 (P_m, C_m enter J_m only
      // through P_m Q_u + C_m Q_v; e_m only through e_m Q).
      const std::vector<Vec4> J = detail::composeSeries(d, P, C, m);
      Vec4 known = Vec4::Zero();
      double mag = L[static_cast<size_t>(m)].norm();
      for (int j = 1; j <= m; ++j) {
        known += e[static_cast<size_t>(m - j)] * J[static_cast<size_t>(j)];
        mag = std::max(mag, std::abs(e[static_cast<size_t>(m - j)]) * J[static_cast<size_t>(j)].norm());
      }
      const Vec4 F = L[static_cast<size_t>(m)] - known;
      const double x0 = detail::bracket4(mi, F, Qu, Qv) / D;
      const double xu = detail::bracket4(mi, Q, F, Qv) / D;
      const double xv = detail::bracket4(mi, Q, Qu, F) / D;
      const Vec4 fit = x0 * Q + xu * Qu + xv * Qv;
      mag = std::max({mag, std::abs(x0) * Q.norm(), std::abs(xu) * Qu.norm(), std::abs(xv) * Qv.norm()});
      out.residual.push_back(mag > 0.0 ? (F - fit).norm() / mag : 0.0);
      e[static_cast<size_t>(m)] = x0;
      P[static_cast<size_t>(m)] = xu / e[0];
      C[static_cast<size_t>(m)] = xv / e[0];
      out.c.push_back(x0 * factorial(m));
      out.p.push_back(P[static_cast<size_t>(m)] * factorial(m));
      out.q.push_back(C[static_cast<size_t>(m)] * factorial(m));
    }
    const double ref = std::hypot(out.p[0], out.q[0]) * e1.direction.norm();
    const double det = out.p[0] * e1.direction.y() - out.q[0] * e1.direction.x();
    out.jacobian = ref > 0.0 ? det / ref : 0.0;
  }
  // The C^n claim: r(psi2) and rbar(psi1) have equal t-derivatives at t = 0.
  {
    const std::vector<Vec4> J = detail::composeSeries(d, P, C, n);
    std::vector<Vec3> ra, rb;
    std::vector<double> ma, mb;
    cartesianSeries(J, ra, ma);
    cartesianSeries(L, rb, mb);
    for (int k = 0; k <= n; ++k) {
      const double scale = std::max(ma[static_cast<size_t>(k)], mb[static_cast<size_t>(k)]);
      const double diff = (ra[static_cast<size_t>(k)] - rb[static_cast<size_t>(k)]).norm();
      out.cartesianMismatch.push_back(scale > 0.0 ? diff / scale : 0.0);
    }
  }
  return out;
}

Result<ConnectingReport> solveConnectingFunctions(const HomogeneousSurface& r, const ParameterLine& e1,
                                                  const HomogeneousSurface& rbar, const ParameterLine& e2,
                                                  std::span<const double> samples, const ConnectingOptions& opt) {
  if (samples.empty()) return invalidInput("no boundary samples");
  ConnectingReport rep;
  const int n = opt.order;
  rep.residuals.assign(static_cast<size_t>(n + 1), 0.0);
  rep.cartesianMismatch.assign(static_cast<size_t>(n + 1), 0.0);
  for (double s : samples) {
    auto x = connectingFunctionsAt(r, e1, rbar, e2, s, opt);
    if (!x) return x.status();
    for (int m = 0; m <= n; ++m) {
      rep.residuals[static_cast<size_t>(m)] = std::max(rep.residuals[static_cast<size_t>(m)], x->residual[static_cast<size_t>(m)]);
      rep.cartesianMismatch[static_cast<size_t>(m)] =
          std::max(rep.cartesianMismatch[static_cast<size_t>(m)], x->cartesianMismatch[static_cast<size_t>(m)]);
    }
    rep.samples.push_back(std::move(x).value());
  }
  // GC^m: residuals of orders 0..m within tolerance; m >= 1 also needs a transversal psi2 of one sign.
  rep.gcOrder = -1;
  for (int m = 0; m <= n; ++m) {
    if (!(rep.residuals[static_cast<size_t>(m)] <= opt.residualTol)) break;
    if (m == 1) {
      double lo = rep.samples[0].jacobian, hi = lo;
      for (const ConnectingSample& x : rep.samples) {
        lo = std::min(lo, x.jacobian);
        hi = std::max(hi, x.jacobian);
      }
      rep.minJacobian = lo;
      rep.maxJacobian = hi;
      const bool positive = lo > opt.transversalTol, negative = hi < -opt.transversalTol;
      if (!(positive || (negative && !opt.requirePositiveJacobian))) {
        rep.notes.push_back(
            negative ? fmt::format("p_1 < 0 along the boundary: the surfaces fold back onto each other (sine of the "
                                   "transversal angle in [{:.3g}, {:.3g}])", lo, hi)
                     : fmt::format("psi2 is not transversal along the whole boundary (sine of the angle between "
                                   "(p_1, q_1) and E1' in [{:.3g}, {:.3g}])", lo, hi));
        break;
      }
    }
    rep.gcOrder = m;
  }
  // Rational C^k: the connecting functions of the identity.
  rep.cOrder = rep.gcOrder >= 0 ? 0 : -1;
  for (int k = 1; k <= rep.gcOrder; ++k) {
    bool ok = true;
    for (const ConnectingSample& x : rep.samples) {
      const size_t i = static_cast<size_t>(k - 1);
      const double pTarget = k == 1 ? 1.0 : 0.0;
      if (!(std::abs(x.p[i] - pTarget) <= opt.parametricTol) || !(std::abs(x.q[i]) <= opt.parametricTol)) ok = false;
    }
    if (!ok) break;
    rep.cOrder = k;
  }
  rep.cnClaimVerified = true;
  for (int k = 0; k <= rep.gcOrder; ++k)
    if (!(rep.cartesianMismatch[static_cast<size_t>(k)] <= opt.residualTol)) rep.cnClaimVerified = false;
  if (rep.gcOrder >= 0 && !rep.cnClaimVerified)
    rep.notes.push_back("r(psi2) and rbar(psi1) do not agree to the GC order numerically");
  return rep;
}

}  // namespace seam::rational
