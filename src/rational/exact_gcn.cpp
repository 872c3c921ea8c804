// Theorem 5 (Zheng-Wang-Liang), exactly in Bernstein form; see include/seam/rational/exact_gcn.h and
// docs/algorithms/zheng-wang-liang.md for the re-derivation.
#include "seam/rational/exact_gcn.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "rational/rational_internal.h"
#include "seam/rational/connecting.h"

namespace seam::rational {

std::string_view toString(GcnCase c) {
  switch (c) {
    case GcnCase::kGeneral: return "general";
    case GcnCase::kPositionC0: return "C0-position";
    case GcnCase::kIntegral: return "integral";
  }
  return "?";
}

namespace {

using detail::SignCheck;

/// A division by a power of the root factor VJ of D (proof of Theorem 5) is accepted when its remainder is below
/// kDivisionRelTol x the magnitude of the terms the dividend was formed from: the roots of D are found to full
/// precision for simple roots, so true factors leave round-off (~1e-14); 1e-8 leaves margin for clustered roots.
constexpr double kDivisionRelTol = 1e-8;
/// Samples used to rank the four minors by their smallest magnitude along the edge.
constexpr int kMinorSamples = 64;

double mag(const BernsteinPoly& p) { return p.maxAbsCoeff(); }

BernsteinPoly one() { return BernsteinPoly::constant(1.0, 0); }

/// p^k for k = 0..count-1.
std::vector<BernsteinPoly> powers(const BernsteinPoly& p, int count) {
  std::vector<BernsteinPoly> out;
  out.push_back(BernsteinPoly::constant(1.0, 0));
  for (int k = 1; k < count; ++k) out.push_back(product(out.back(), p));
  return out;
}

BernsteinPoly rootFactor(double a) { return BernsteinPoly::linear(-a, 1.0 - a); }

}  // namespace

Result<ExactGcnResult> exactGcnFromBoundary(const std::vector<std::vector<BernsteinPoly>>& x,
                                            const std::vector<BernsteinPoly>& y, const ExactGcnOptions& opt) {
  const int n = opt.order;
  if (n < 0 || n > kMaxGcnOrder)
    return invalidInput(fmt::format("exact GC^n: order {} out of range [0, {}]", n, kMaxGcnOrder));
  if (static_cast<int>(y.size()) < n + 1 || static_cast<int>(x.size()) < n + 1)
    return invalidInput(fmt::format("exact GC^n: boundary data up to order {} needed", n));
  for (int a = 0; a <= n; ++a)
    if (static_cast<int>(x[static_cast<size_t>(a)].size()) < n - a + 1)
      return invalidInput(fmt::format("exact GC^n: mixed derivatives of Q up to order {} needed", n));
  const int dim = y[0].dim();
  if (dim != 3 && dim != 4) return invalidInput("exact GC^n: boundary data must be 3-D (integral) or 4-D (homogeneous)");
  for (int a = 0; a <= n; ++a) {
    if (y[static_cast<size_t>(a)].dim() != dim) return invalidInput("exact GC^n: mixed dimensions in Qbar's data");
    for (int b = 0; a + b <= n; ++b)
      if (x[static_cast<size_t>(a)][static_cast<size_t>(b)].dim() != dim)
        return invalidInput("exact GC^n: Q and Qbar have different dimensions (both homogeneous or both integral)");
  }
  const bool integral = dim == 3;
  auto X = [&](int a, int b) -> const BernsteinPoly& { return x[static_cast<size_t>(a)][static_cast<size_t>(b)]; };
  const BernsteinPoly& x00 = X(0, 0);
  const int l = std::max(x00.degree(), y[0].degree());
  {
    const int top = (2 * n - 1) * (3 * l - 1) + (n - 1) * l + l + 3 * l;
    if (n >= 1 && top > opt.maxDegree)
      return Status(ErrorCode::kUnsupported,
                    fmt::format("exact GC^{}: the polynomials of (4.1) reach degree {} (> {}) for edge degree {}", n,
                                top, opt.maxDegree, l));
  }
  const double tol = opt.identityRelTol;
  ExactGcnResult res;
  ExactConnecting& f = res.functions;

  // ---- order 0: G Qbar = H Q.
  BernsteinPoly R0;
  double scale0 = 0.0;
  if (integral) {
    res.gcnCase = GcnCase::kIntegral;
    f.G = one();
    f.H = one();
    R0 = y[0] - x00;
    scale0 = std::max(mag(y[0]), mag(x00));
  } else {
    f.G = x00.component(3);
    f.H = y[0].component(3);
    if (mag(f.G - f.H) <= tol * std::max(mag(f.G), mag(f.H))) {
      res.gcnCase = GcnCase::kPositionC0;
      f.G = one();
      f.H = one();
    }
    R0 = product(f.G, y[0]) - product(f.H, x00);
    scale0 = std::max(mag(f.G) * mag(y[0]), mag(f.H) * mag(x00));
    if (detail::certifyPositive(product(f.G, f.H), kRoundoff * mag(f.G) * mag(f.H)) != SignCheck::kPositive) {
      res.notes.push_back("the weights along the edge are not provably positive (G H > 0 of Theorem 5)");
      res.certified = false;
    }
  }
  res.residuals.push_back(scale0 > 0.0 ? mag(R0) / scale0 : 0.0);
  if (!(res.residuals[0] <= tol)) {
    res.notes.push_back("the edges do not coincide as rational curves (no GC^0)");
    return res;
  }
  res.gcOrder = 0;
  res.cOrder = 0;
  if (n == 0) return res;

  // ---- D: the best-conditioned minor (largest smallest magnitude along the edge); regularity of both sides.
  const BernsteinPoly& x10 = X(1, 0);
  const BernsteinPoly& x01 = X(0, 1);
  const int minors = integral ? 3 : 4;
  auto bracketQ = [&](int i, const BernsteinPoly& a, const BernsteinPoly& b, const BernsteinPoly& c) {
    return integral ? detail::bracket3(i - 1, b, c) : detail::bracket4(i, a, b, c);
  };
  std::vector<BernsteinPoly> Dall;
  double bestMin = -1.0;
  BernsteinPoly sumSq;
  for (int i = 1; i <= minors; ++i) {
    Dall.push_back(bracketQ(i, x00, x10, x01));
    double lo = std::numeric_limits<double>::infinity();
    for (int k = 0; k <= kMinorSamples; ++k) lo = std::min(lo, std::abs(Dall.back().scalar(k / double(kMinorSamples))));
    if (lo > bestMin) {
      bestMin = lo;
      f.minor = i;
    }
    const BernsteinPoly sq = product(Dall.back(), Dall.back());
    sumSq = i == 1 ? sq : sumSq + sq;
  }
  const double volume = integral ? mag(x10) * mag(x01) : mag(x00) * mag(x10) * mag(x01);
  if (!(mag(sumSq) > kRoundoff * volume * volume))
    return Status(ErrorCode::kDegenerate, "exact GC^n: Q, Q_u, Q_v are dependent along the whole edge (Lemma 2)");
  if (detail::certifyPositive(sumSq, kRoundoff * volume * volume) != SignCheck::kPositive) {
    res.notes.push_back("r is not provably regular along the edge (Q, Q_u, Q_v dependent somewhere): Theorem 5 "
                        "assumes regular surfaces");
    res.certified = false;
  }
  {
    // rbar regular along the edge: Qbar, Qbar_u, Qbar_v independent.
    const BernsteinPoly yv = y[0].derivative();
    BernsteinPoly s2;
    for (int i = 1; i <= minors; ++i) {
      const BernsteinPoly b = bracketQ(i, y[0], y[1], yv);
      s2 = i == 1 ? product(b, b) : s2 + product(b, b);
    }
    const double vb = integral ? mag(y[1]) * mag(yv) : mag(y[0]) * mag(y[1]) * mag(yv);
    if (detail::certifyPositive(s2, kRoundoff * vb * vb) != SignCheck::kPositive) {
      res.notes.push_back("rbar is not provably regular along the edge: Theorem 5 assumes regular surfaces");
      res.certified = false;
    }
  }
  if (opt.forceMinor != 0) {
    if (opt.forceMinor < 1 || opt.forceMinor > minors)
      return invalidInput(fmt::format("exact GC^n: minor {} out of range [1, {}]", opt.forceMinor, minors));
    if (!(mag(Dall[static_cast<size_t>(opt.forceMinor - 1)]) > kRoundoff * volume))
      return Status(ErrorCode::kDegenerate, fmt::format("exact GC^n: the minor <Q, Q_u, Q_v>_{} vanishes identically",
                                                        opt.forceMinor));
    f.minor = opt.forceMinor;
  }
  f.D = Dall[static_cast<size_t>(f.minor - 1)];
  const BernsteinPoly& D = f.D;
  const std::vector<BernsteinPoly> Dp = powers(D, 2 * n + 1), Gp = powers(f.G, n + 1), Hp = powers(f.H, n + 1);
  std::vector<double> magC, magP, magQ;  // magnitudes the underlined p_s, q_s were formed from (for identity tests)

  // Products p_{r_1}..p_{r_h} q_{r_{h+1}}..q_{r_k} of the underlined functions.
  auto pq = [&](const std::vector<int>& r, int h) {
    BernsteinPoly prod = one();
    for (int i = 0; i < static_cast<int>(r.size()); ++i) {
      const size_t idx = static_cast<size_t>(r[static_cast<size_t>(i)] - 1);
      prod = product(prod, i < h ? f.p[idx] : f.q[idx]);
    }
    return prod;
  };

  for (int s = 1; s <= n; ++s) {
    // delta-bar of the proof: D^{2s-2} H^{s-1} d^s Qbar - (known terms).
    BernsteinPoly delta = product(product(Dp[static_cast<size_t>(2 * s - 2)], Hp[static_cast<size_t>(s - 1)]),
                                  y[static_cast<size_t>(s)]);
    double magDelta = mag(delta);
    for (int k = 2; k <= s; ++k)
      for (const std::vector<int>& r : detail::compositions(s, k))
        for (int h = 0; h <= k; ++h) {
          const BernsteinPoly scal = product(product(Gp[static_cast<size_t>(k - 1)], Dp[static_cast<size_t>(k - 2)]), pq(r, h));
          const BernsteinPoly term = detail::lemma1Coefficient(s, h, r) * product(scal, X(h, k - h));
          magDelta = std::max(magDelta, mag(term));
          delta = delta - term;
        }
    if (!integral)
      for (int d = 1; d <= s - 1; ++d)
        for (int k = 1; k <= d; ++k)
          for (const std::vector<int>& r : detail::compositions(d, k))
            for (int h = 0; h <= k; ++h) {
              const BernsteinPoly scal =
                  product(product(product(f.c[static_cast<size_t>(s - d - 1)], Gp[static_cast<size_t>(k)]),
                                  Dp[static_cast<size_t>(k - 1)]),
                          pq(r, h));
              const BernsteinPoly term =
                  (binomial(s, d) * detail::lemma1Coefficient(d, h, r)) * product(scal, X(h, k - h));
              magDelta = std::max(magDelta, mag(term));
              delta = delta - term;
            }
    // (4.4): Cramer's rule with the chosen minor.
    const int i = f.minor;
    BernsteinPoly cs = integral ? BernsteinPoly::zero(0, 1) : bracketQ(i, delta, x10, x01);
    BernsteinPoly ps = bracketQ(i, x00, delta, x01);
    BernsteinPoly qs = bracketQ(i, x00, x10, delta);
    BernsteinPoly R = product(D, delta) - product(ps, x10) - product(qs, x01);
    if (!integral) R = R - product(cs, x00);
    const double scale = std::max({mag(D) * magDelta, mag(cs) * mag(x00), mag(ps) * mag(x10), mag(qs) * mag(x01)});
    res.residuals.push_back(scale > 0.0 ? mag(R) / scale : 0.0);
    if (!(res.residuals.back() <= tol)) {
      res.notes.push_back(fmt::format("order {}: d^{} Qbar is not in span(Q, Q_u, Q_v) with the order-{} connecting "
                                      "functions (relative residual {:.3g})", s, s, s - 1, res.residuals.back()));
      break;
    }
    if (s == 1) {
      // p_1 = (G/H) p_1(underlined) / D with any minor; summing over all minors, sign(p_1) = sign(G H P) with
      // P = sum_i <Q, Qbar_u, Q_v>_i <Q, Q_u, Q_v>_i, which cannot vanish through D's roots.
      BernsteinPoly P;
      for (int j = 1; j <= minors; ++j) {
        const BernsteinPoly pj = product(bracketQ(j, x00, y[1], x01), Dall[static_cast<size_t>(j - 1)]);
        P = j == 1 ? pj : P + pj;
      }
      const double floor = kRoundoff * mag(y[1]) * volume * (integral ? mag(x01) : mag(x00) * mag(x01));
      const SignCheck pos = detail::certifyPositive(P, floor);
      if (pos == SignCheck::kNotPositive) {
        const bool fold = detail::certifyPositive(-1.0 * P, floor) == SignCheck::kPositive;
        res.notes.push_back(fold ? "p_1 < 0 along the edge: rbar folds back over r (no GC^1 join)"
                                 : "p_1 vanishes on the edge: the cross-boundary derivative of rbar is tangent to r "
                                   "(no GC^1)");
        break;
      }
      if (pos == SignCheck::kUndecided) {
        res.notes.push_back("the sign of p_1 could not be certified (assumed positive)");
        res.certified = false;
      }
    }
    f.c.push_back(std::move(cs));
    f.p.push_back(std::move(ps));
    f.q.push_back(std::move(qs));
    magC.push_back(magDelta * mag(x10) * mag(x01));
    magP.push_back(magDelta * (integral ? mag(x01) : mag(x00) * mag(x01)));
    magQ.push_back(magDelta * (integral ? mag(x10) : mag(x00) * mag(x10)));
    res.gcOrder = s;
  }

  // ---- rational C^k (Corollary): p_1 == 1, q_1 == 0, p_i == q_i == 0 as identities.
  for (int k = 1; k <= res.gcOrder; ++k) {
    const size_t i = static_cast<size_t>(k - 1);
    bool ok = true;
    if (k == 1) {
      // p_1 = G p / (D H) == 1  <=>  G p - D H == 0
      const BernsteinPoly a = product(f.G, f.p[0]), b = product(D, f.H);
      ok = mag(a - b) <= tol * std::max(mag(f.G) * magP[0], mag(b));
    } else {
      ok = mag(f.p[i]) <= tol * magP[i];
    }
    ok = ok && mag(f.q[i]) <= tol * magQ[i];
    if (!ok) break;
    res.cOrder = k;
  }

  // ---- degrees against Theorem 5's table (Corollary 1 / 2 in Cases 1 / 2), and the elimination of D's roots.
  const double dTol = tol * mag(D);
  f.rootsOfD = detail::rootsInUnitInterval(D, dTol);
  // VJ = prod (t - v_k)^{mult_k}; the multiplicity is the highest power that divides D.
  BernsteinPoly VJ = one();
  for (double rt : f.rootsOfD) {
    BernsteinPoly power = one();
    for (int j = 1; j <= D.degree(); ++j) {
      const BernsteinPoly next = product(power, rootFactor(rt));
      if (!(detail::divideExactly(D, next).second <= kDivisionRelTol * mag(D))) break;
      power = next;
    }
    VJ = product(VJ, power);
  }
  f.Dbar = detail::divideExactly(D, VJ).first;
  auto eliminate = [&](const BernsteinPoly& p, int s, double scale) {
    if (VJ.degree() == 0) return p;
    BernsteinPoly div = one();
    for (int k = 0; k < 2 * s - 1; ++k) div = product(div, VJ);
    auto [q, rem] = detail::divideExactly(p, div);
    if (!(rem <= kDivisionRelTol * scale)) {
      res.notes.push_back(fmt::format("order {}: the roots of D are not roots of multiplicity {} of the order-{} "
                                      "functions (elimination incomplete, remainder {:.3g})", s, 2 * s - 1, s,
                                      rem / scale));
      return p;
    }
    return q;
  };
  const int bD = integral ? 2 * l - 1 : 3 * l - 1;
  auto deg = [&](const BernsteinPoly& p, double scale) { return detail::effectiveDegree(p, tol * scale); };
  if (res.gcnCase == GcnCase::kGeneral) {
    res.degrees.push_back({"G", deg(f.G, mag(f.G)), l, deg(f.G, mag(f.G))});
    res.degrees.push_back({"H", deg(f.H, mag(f.H)), l, deg(f.H, mag(f.H))});
  }
  res.degrees.push_back({"D", deg(D, mag(D)), bD, deg(f.Dbar, mag(D))});
  for (int s = 1; s <= res.gcOrder; ++s) {
    const size_t i = static_cast<size_t>(s - 1);
    const int extra = res.gcnCase == GcnCase::kGeneral ? (s - 1) * l : 0;
    const int bound = (2 * s - 1) * bD + extra;
    f.cbar.push_back(integral ? f.c[i] : eliminate(f.c[i], s, magC[i]));
    f.pbar.push_back(eliminate(f.p[i], s, magP[i]));
    f.qbar.push_back(eliminate(f.q[i], s, magQ[i]));
    if (!integral) {
      res.degrees.push_back({fmt::format("c_{}", s), deg(f.c[i], magC[i]), bound, deg(f.cbar[i], magC[i])});
    }
    res.degrees.push_back({fmt::format("p_{}", s), deg(f.p[i], magP[i]), bound, deg(f.pbar[i], magP[i])});
    res.degrees.push_back({fmt::format("q_{}", s), deg(f.q[i], magQ[i]), bound + 1, deg(f.qbar[i], magQ[i])});
  }
  for (const DegreeEntry& e : res.degrees)
    if (e.found > e.bound)
      res.notes.push_back(fmt::format("degree of {} is {} > the bound {} of Theorem 5's table", e.name, e.found,
                                      e.bound));
  return res;
}

Result<ExactGcnResult> exactGcnBezier(const BernsteinPatch& q, const BernsteinPatch& qbar,
                                      const ExactGcnOptions& opt) {
  if (q.dim() != qbar.dim() || (q.dim() != 3 && q.dim() != 4))
    return invalidInput(fmt::format("exact GC^n: patches of dimension {} and {} (both 4: homogeneous, or both 3: "
                                    "integral)", q.dim(), qbar.dim()));
  const int n = opt.order;
  if (n < 0 || n > kMaxGcnOrder)
    return invalidInput(fmt::format("exact GC^n: order {} out of range [0, {}]", n, kMaxGcnOrder));
  std::vector<std::vector<BernsteinPoly>> x(static_cast<size_t>(n + 1));
  std::vector<BernsteinPoly> y;
  for (int a = 0; a <= n; ++a) {
    for (int b = 0; a + b <= n; ++b) x[static_cast<size_t>(a)].push_back(q.derivative(a, b).isoU(1.0));
    y.push_back(qbar.derivative(a, 0).isoU(0.0));
  }
  return exactGcnFromBoundary(x, y, opt);
}

}  // namespace seam::rational
