// How much the angle between the normals at closest points can exceed the angle at paired points
// (continuity/closest_excess.h).
#include "continuity/closest_excess.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <utility>
#include <vector>

#include "core/bernstein_internal.h"

namespace seam::detail {

namespace {

/// Halvings of a leaf while bounding the length of a vector polynomial from below (normLowerBound).
constexpr int kNormBoundDepth = 4;
/// normLowerBound accepts a piece's bound once it reaches this share of the length at the piece's middle.
constexpr double kNormBoundShare = 0.5;

/// A lower bound of |v(x)| on [0, 1]: per piece (halved up to kNormBoundDepth times), the least Bernstein coefficient
/// of v . e, with e the unit direction of v at the piece's middle (|v| >= v . e); 0 where no positive bound is found.
double normLowerBound(const BernsteinPoly& v, int depth = 0) {
  const VecX mid = v(0.5);
  const double len = mid.norm();
  double lo = 0.0;
  if (len > 0.0 && std::isfinite(len)) lo = (v.coeffs() * (mid / len)).minCoeff();
  if (lo >= kNormBoundShare * len || depth >= kNormBoundDepth) return std::max(lo, 0.0);
  const auto [left, right] = v.subdivided(0.5);
  return std::min(normLowerBound(left, depth + 1), normLowerBound(right, depth + 1));
}

/// Halvings while bounding max |F| of the closest-point residual on a leaf (maxAbsBound), and the share above the
/// largest end value (of the pieces reached) at which a piece's coefficient bound is accepted.
constexpr int kResidualBoundDepth = 2;
constexpr double kResidualBoundRel = 0.1;
/// Halvings of the cells whose closest-point excess exceeds the target (closestExcess): a cell's own bounds of the
/// residual, |B_x| and the normal's turning lie closer to the values at each point than the leaf's (a rational
/// quadratic edge: 10.5 deg of excess from the whole leaf, 2.2 deg from 8 cells, 1.75 deg true). The halving stops
/// when a round lowers the largest excess by less than a quarter (ClosestRefinement::gain): where the pcurves
/// drift, the excess is the drift times the normal's turning, which smaller cells do not lower (linkrods.step: 0.36 s
/// of CPU for 8 cells per leaf, and the same bound).
constexpr double kInf = std::numeric_limits<double>::infinity();

/// An upper bound of max |p| on [0, 1]: the largest |coefficient|, on halves (up to `depth` times) where it exceeds
/// the piece's end values (which are values of p) by more than kResidualBoundRel.
double maxAbsBound(const BernsteinPoly& p, int depth) {
  const Matrix& c = p.coeffs();
  const double b = p.maxAbsCoeff(), ends = std::max(std::abs(c(0, 0)), std::abs(c(c.rows() - 1, 0)));
  if (b <= (1.0 + kResidualBoundRel) * ends || depth <= 0) return b;
  const auto [left, right] = p.subdivided(0.5);
  return std::max(maxAbsBound(left, depth - 1), maxAbsBound(right, depth - 1));
}

/// Rounds of widening the reach of a cell's excess (excessOfCells): each round's reach is kReachGrowth times the
/// distance the last round's bounds asked for, so that a reach that settles needs two or three rounds.
constexpr int kReachRounds = 6;
constexpr double kReachGrowth = 1.5;

/// The curvature and arc length of each part of B's edge within reach of a cell (excessOfCells).
using Bends = std::vector<std::pair<double, double>>;

/// The sum of curvature times arc length over the parts of `bends` whose curvature is above `level`: how far B's
/// tangent turns over them.
double bentAbove(const Bends& bends, double level) {
  double above = 0.0;
  for (const auto& [k, a] : bends)
    if (k > level) above += k * a;
  return above;
}

/// How far (arc length) B's point closest to A(t) lies from the paired point, where |h'| <= r there (closestExcess),
/// |A - B| <= G within that far, and `bends` holds the parts of B's edge within reach. h'(s) - h'(0) >= s - G int_0^s
/// kappa, and int_0^s kappa <= k0 s + bentAbove(k0) for any level k0, so h' has the sign of s beyond l(k0) = (r + G
/// bentAbove(k0)) / (1 - G k0) where 1 > G k0. The least over the parts' curvatures and 0: the largest gives r / (1 -
/// G kappa), the pointwise bound; a lower level counts a short sharp bend by its turning (a pcurve of degree 9 with
/// knots 1e-8 apart bends its edge at 4 500 / mm over them, linkrods.step, where G kappa = 1.9; a sliver leaf's
/// curvature bound is round-off over its length squared). Infinite where no level gives a bound.
double closestWithin(const Bends& bends, double r, double G) {
  double best = kInf;
  const auto level = [&](double k0) {
    const double c = 1.0 - G * k0;
    if (c > 0.0) best = std::min(best, (r + G * bentAbove(bends, k0)) / c);
  };
  level(0.0);
  for (const auto& bend : bends) level(bend.first);
  return best;
}

/// How far B's tangent turns within arc length l of the paired point: at most k0 l + bentAbove(k0) for any level k0,
/// the least over the parts' curvatures and 0 (the largest gives kappa l).
double turnWithin(const Bends& bends, double l) {
  double best = bentAbove(bends, 0.0);
  for (const auto& bend : bends) best = std::min(best, bend.first * l + bentAbove(bends, bend.first));
  return best;
}

/// The excess (radians) of each of `cells` (in edge order, the cells of `leaves`): see closestExcess; infinite where
/// a cell's excess cannot be bounded. The bounds of B's speed, curvature and normal turning are taken over the cell
/// and over the parts of its neighbours within the reach in t (whole neighbours made the normal's turning at a far
/// end of a neighbour count: SeamGap.AcrossAGap... stopped at 13 times the true angle). `whole`: the excess from B's
/// whole turning alone (the bound before the along / across split), which closestExcess's halving also follows.
std::vector<double> excessOfCells(const std::vector<ClosestLeaf>& leaves, const std::vector<ClosestCell>& cells,
                                  double paired, bool clip, std::vector<double>& whole) {
  const double s0 = 2.0 * std::sin(0.5 * std::min(paired, std::numbers::pi));  // the chord of the paired angle
  std::vector<double> out(cells.size(), kInf);
  whole.assign(cells.size(), kInf);
  const auto len = [&](size_t j) { return cells[j].t1 - cells[j].t0; };
  std::vector<std::pair<ClosestSplit, double>> reached;  // the split of each part taken, and its length in t
  Bends bends;                                           // the curvature of each part taken, and its arc length
  for (size_t i = 0; i < cells.size(); ++i) {
    const double f = cells[i].d.f / len(i);  // per unit of t
    const double lo = cells[i].t0, hi = cells[i].t1;
    double reach = 0.0, need = 0.0;  // need: the arc length the last round's closest point asked for
    for (int round = 0; round < kReachRounds; ++round) {
      double m = kInf, K = 0.0;
      reached.clear();
      bends.clear();
      // B's bounds on [a, b] of cell j (per unit of t).
      const auto take = [&](size_t j, double a, double b) {  // (whole cells where !clip)
        const ClosestCell& c = cells[j];
        ClosestData d = c.d;
        if (!clip) {
          a = c.t0;
          b = c.t1;
        } else if (a > c.t0 || b < c.t1) {
          const auto x = [&](double t) { return c.x0 + (t - c.t0) / len(j) * (c.x1 - c.x0); };
          d = closestData(leaves[c.leaf], x(a), x(b), false);
        }
        m = std::min(m, d.speedLo / (b - a));
        K = std::max(K, d.turnHi / (b - a));
        reached.emplace_back(d.split, b - a);
        bends.emplace_back(d.curvatureHi, d.speedHi);
      };
      take(i, lo, hi);
      for (size_t j = i; j > 0 && cells[j - 1].t1 > lo - reach; --j)
        take(j - 1, std::max(cells[j - 1].t0, lo - reach), cells[j - 1].t1);
      for (size_t j = i + 1; j < cells.size() && cells[j].t0 < hi + reach; ++j)
        take(j, cells[j].t0, std::min(cells[j].t1, hi + reach));
      // Arc lengths, and the reach they ask for in t: d = 2 r (the closest point within r / (1/2) = d wherever h'' >=
      // 1/2), or what the last round's closest point asked for.
      const double r = f / m, gap = cells[i].d.gapHi, d = std::max(need, 2.0 * r), dt = d / m;
      if (!(m > 0.0) || !std::isfinite(dt)) break;
      // A reach over every cell on both sides takes in B's whole range: a longer one adds nothing.
      const bool atEnds = lo - reach <= cells.front().t0 && hi + reach >= cells.back().t1;
      if (dt <= reach || (atEnds && round > 0)) {
        const double l = closestWithin(bends, r, gap + d);  // l: paired to closest, arc length
        if (!(l <= d)) {  // (or NaN, infinite) not within the reach
          if (!(l < kInf)) break;
          need = kReachGrowth * l;
          reach = std::max(reach, kReachGrowth * need / m);
          continue;
        }
        double e = K / m * l;
        whole[i] = e;
        // Split along and across the edge (closestExcess), per unit of arc length: the part along it is taken as the
        // whole turning (nearly all of it wherever the split pays), the part across at most that.
        double across = 0.0;
        for (const auto& [sp, length] : reached) across = std::max(across, sp.acrossTurnHi / length);
        const double kn = K / m, tau = std::min(across, K) / m;
        const double eps = std::min(1.0, cells[i].d.split.tangentSinHi + turnWithin(bends, l));
        const double chord = std::sqrt(s0 * s0 + 2.0 * kn * eps * l) + tau * l;
        if (chord < 2.0) e = std::min(e, std::max(0.0, 2.0 * std::asin(0.5 * chord) - paired));
        // A halved cell keeps its parent's bound where that is lower.
        if (e >= 0.0) out[i] = std::min(e, cells[i].cap);
        break;
      }
      reach = kReachGrowth * dt;
    }
  }
  return out;
}

/// The curvature of an edge x / w, where T = x' w - x w' (|T| >= tLo), T1 = T' and acc = T' w - 2 T w', w in
/// [wLo, wHi] (infinite where tLo = 0): |B_x x B_xx| / |B_x|^3 with B_x = T / w^2, B_xx = acc / w^3, so
/// B_x x B_xx = T x T' / w^4 and kappa = w^2 |T x T'| / |T|^3; also at most |B_xx| / |B_x|^2 (the smaller bound is
/// taken). Independent of the parametrisation: T and T1 may be per unit of any affine parameter.
double curvatureBound(const BernsteinPoly& T, double tLo, const BernsteinPoly& T1, const BernsteinPoly& acc,
                      double wLo, double wHi) {
  if (!(tLo > 0.0) || !(wLo > 0.0)) return kInf;
  const double speedLo = tLo / (wHi * wHi);
  const double byCross = wHi * wHi * cross(T, T1).maxCoeffNorm() / (tLo * tLo * tLo);
  const double byAccel = acc.maxCoeffNorm() / (wLo * wLo * wLo) / (speedLo * speedLo);
  return std::min(byCross, byAccel);
}

}  // namespace

/// B_x = T / w_B^2 with T = X_B' w_B - X_B w_B'; B_xx = (T' w_B - 2 T w_B') / w_B^3; A - B = D / (w_A w_B) with
/// D = X_A w_B - X_B w_A; so (A - B) . B_x = (D . T) / (w_A w_B^3). The unit normal turns by at most
/// |N x N'| / |N|^2 <= |N'| / |N| for any numerator N of it. On [x0, x1] of the leaf, per unit of the local
/// parameter of [x0, x1]; `refine`: the residual's bound made closer by halving (maxAbsBound) where its coefficients
/// bound it loosely (A - B turning against B's tangent along the piece).
ClosestData closestData(const ClosestLeaf& L, double x0, double x1, bool refine) {
  ClosestData d;
  const auto on = [&](const BernsteinPoly& p) { return x0 == 0.0 && x1 == 1.0 ? p : p.restricted(x0, x1); };
  const BernsteinPoly xa = on(L.xa), wa = on(L.wa), xb = on(L.xb), wb = on(L.wb), nb = on(L.nb);
  const double waLo = wa.coeffs().minCoeff(), wbLo = wb.coeffs().minCoeff(), wbHi = wb.coeffs().maxCoeff();
  if (!(waLo > 0.0 && wbLo > 0.0)) return d;
  const BernsteinPoly D = product(xa, wb) - product(xb, wa);
  const BernsteinPoly wb1 = wb.derivative();
  const BernsteinPoly T = product(xb.derivative(), wb) - product(xb, wb1);
  const BernsteinPoly T1 = T.derivative();
  const BernsteinPoly acc = product(T1, wb) - 2.0 * product(T, wb1);
  const BernsteinPoly F = dot(D, T);
  const double den = waLo * wbLo * wbLo * wbLo;
  d.f = (refine ? maxAbsBound(F, kResidualBoundDepth) : F.maxAbsCoeff()) / den;
  const double tLo = normLowerBound(T);
  d.speedLo = tLo / (wbHi * wbHi);
  d.speedHi = T.maxCoeffNorm() / (wbLo * wbLo);
  d.gapHi = D.maxCoeffNorm() / (waLo * wbLo);
  d.curvatureHi = curvatureBound(T, tLo, T1, acc, wbLo, wbHi);
  if (L.window) {
    // The same curvature from the derivatives formed on the window, restricted to [x0, x1] of the leaf
    // (ClosestWindow): each bound holds, the smaller is taken.
    const ClosestWindow& W = *L.window;
    const double y0 = W.y0 + x0 * (W.y1 - W.y0), y1 = W.y0 + x1 * (W.y1 - W.y0);
    const BernsteinPoly Tw = W.t.restricted(y0, y1), w = W.w.restricted(y0, y1);
    d.curvatureHi = std::min(d.curvatureHi, curvatureBound(Tw, normLowerBound(Tw), W.t1.restricted(y0, y1),
                                                           W.acc.restricted(y0, y1), w.coeffs().minCoeff(),
                                                           w.coeffs().maxCoeff()));
  }
  // d(N / |N|) / dx = (N' - (n . N') n) / |N| with n = N / |N|: its length is |N x N'| / |N|^2 <= |N'| / |N|. The
  // first is zero for a plane whose normal numerator only changes length (HealCrease: a vertical plane with a
  // lifted boundary row, 90 deg everywhere); either bound holds, the smaller is taken.
  // The split (ClosestSplit): N x N' = |N|^2 n_B x n_B', which turns n_B''s parts (along T_B, across b = n_B x T_B)
  // into (across, -along), so n_B' . b = -(N x N') . T / (|N|^2 |T|), from the product formed for turnHi anyway.
  // And n_A . T_B = N_A . T / (|N_A| |T|).
  if (const double nLo = normLowerBound(nb); nLo > 0.0) {
    const BernsteinPoly nb1 = nb.derivative(), C = cross(nb, nb1);
    d.turnHi = std::min(nb1.maxCoeffNorm() / nLo, C.maxCoeffNorm() / (nLo * nLo));
    if (tLo > 0.0) d.split.acrossTurnHi = dot(C, T).maxAbsCoeff() / (nLo * nLo * tLo);
  }
  if (tLo > 0.0) {
    const BernsteinPoly na = on(L.na);
    if (const double naLo = normLowerBound(na); naLo > 0.0)
      d.split.tangentSinHi = std::min(1.0, dot(na, T).maxAbsCoeff() / (naLo * tLo));
  }
  return d;
}

ClosestWindow closestWindow(const BernsteinPoly& x, const BernsteinPoly& w, double y0, double y1) {
  const BernsteinPoly w1 = w.derivative();
  BernsteinPoly T = product(x.derivative(), w) - product(x, w1);
  BernsteinPoly T1 = T.derivative();
  BernsteinPoly acc = product(T1, w) - 2.0 * product(T, w1);
  return {std::move(T), std::move(T1), std::move(acc), w, y0, y1};
}

ClosestLeaf closestLeaf(BernsteinPoly xa, BernsteinPoly wa, BernsteinPoly xb, BernsteinPoly wb, BernsteinPoly na,
                        BernsteinPoly nb, size_t index, double t0, double t1, std::optional<ClosestWindow> window) {
  ClosestLeaf c{std::move(xa), std::move(wa), std::move(xb), std::move(wb), std::move(na), std::move(nb), {},
                std::move(window)};
  c.whole = {index, 0.0, 1.0, t0, t1, closestData(c, 0.0, 1.0, false)};
  return c;
}

namespace {

/// Where the local argument fails somewhere (closestExcess), the excess is still at most the total turning of B's
/// unit normal along the whole edge: the closest point lies on B's edge, and the angle from A's normal to B's normal
/// there exceeds the paired angle by at most the angle between B's two normals. Zero on a plane (trj3_s1-al-214.stp:
/// four 90 deg seams whose planar side's edge bends at 1 400 / mm next to a 0.03 mm gap). Infinite (not bounded) from
/// pi on, where it says nothing (teaspoon.bpt: a seam next to a pole keeps its sampled angle, not certified).
double turning(const std::vector<ClosestCell>& cells) {
  double total = 0.0;
  for (const ClosestCell& c : cells) total += c.d.turnHi;
  return total < std::numbers::pi ? total : kInf;
}

}  // namespace

double closestExcess(const std::vector<ClosestLeaf>& closest, double target, double paired,
                     const ClosestRefinement& how) {
  std::vector<ClosestCell> cells;
  for (const ClosestLeaf& c : closest) cells.push_back(c.whole);
  double previous = std::numeric_limits<double>::infinity(), previousWhole = previous;
  size_t previousUnbounded = cells.size() + 1;
  std::vector<double> whole;
  for (int round = 0;; ++round) {
    const std::vector<double> e = excessOfCells(closest, cells, paired, how.clipNeighbours, whole);
    const auto largest = [](const std::vector<double>& v) {
      return v.empty() ? 0.0 : *std::max_element(v.begin(), v.end());
    };
    const double worst = largest(e), worstWhole = largest(whole);
    const auto unbounded = static_cast<size_t>(std::count_if(e.begin(), e.end(), [](double x) { return !(x < kInf); }));
    // (An excess that cannot be bounded over a whole leaf may be over its halves: the first round always halves.)
    // The halving goes on while either bound gains (as it did before the split bound): the split one may stall where
    // the whole turning's still falls below it (linkrods.step edge 58 stopped at 0.00046 deg, where the whole
    // turning's went on to 0.00037).
    const bool gained = worst < how.gain * previous || worstWhole < how.gain * previousWhole ||
                        (how.whileUnboundedShrink && unbounded > 0 && unbounded < previousUnbounded);
    if (worst <= target || round >= how.rounds || (round > 0 && !gained)) return worst < kInf ? worst : turning(cells);
    previous = worst;
    previousWhole = worstWhole;
    previousUnbounded = unbounded;
    std::vector<size_t> split;
    const double splitAbove = std::max(target, how.splitShare * (std::isfinite(worst) ? worst : 0.0));
    // Cells above it by either bound (a whole neighbour left unhalved widens the bounds next to it).
    for (size_t i = 0; i < cells.size(); ++i)
      if (!(e[i] <= splitAbove) || !(whole[i] <= splitAbove)) split.push_back(i);
    std::vector<std::array<ClosestCell, 2>> halves(split.size());
    tbb::parallel_for(size_t{0}, split.size(), [&](size_t k) {
      const ClosestCell& c = cells[split[k]];
      const double xm = 0.5 * (c.x0 + c.x1), tm = 0.5 * (c.t0 + c.t1);
      const ClosestLeaf& L = closest[c.leaf];
      halves[k] = {ClosestCell{c.leaf, c.x0, xm, c.t0, tm, closestData(L, c.x0, xm, true), e[split[k]]},
                   ClosestCell{c.leaf, xm, c.x1, tm, c.t1, closestData(L, xm, c.x1, true), e[split[k]]}};
    });
    std::vector<ClosestCell> next;
    for (size_t i = 0, k = 0; i < cells.size(); ++i) {
      if (k < split.size() && split[k] == i) {
        next.push_back(halves[k][0]);
        next.push_back(halves[k][1]);
        ++k;
      } else {
        next.push_back(cells[i]);
      }
    }
    cells = std::move(next);
  }
}


}  // namespace seam::detail
