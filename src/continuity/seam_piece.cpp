// Exact seam pieces and their certified bounds (continuity/seam_piece.h): the pieces' rational polynomials, the
// G0 / G1 / G2 bounds on sub-intervals, their subdivision (certifyMax) and the Lemma 1 ranges.
#include "continuity/seam_piece.h"

#include <cassert>
#include <cmath>

#include <Eigen/Dense>
#include <algorithm>
#include <limits>

#include "continuity/sampling.h"
#include "core/bernstein_internal.h"
#include "seam/core/tolerances.h"

namespace seam::detail {

/// Samples per piece for the ranges of Johansson's connecting functions lambda, kappa on certified seams.
constexpr int kLemma1Samples = 16;
/// Golden-section steps per interior extreme: the bracket (1/16) shrinks to 4e-5 of the piece; at a smooth extreme
/// the value error is quadratic in that (~1e-9 relative).
constexpr int kLemma1GoldenIterations = 16;
/// lambda or kappa varying by less than this (relative) over a piece is constant to round-off: not refined.
constexpr double kLemma1ConstantRel = 1e-9;

// Cartesian derivatives of S = x / w from homogeneous cross-derivative polynomials X0, X1, X2 (k-th u-derivative
// along the edge, as functions of tau). `slot` selects which weight exponent (A = 0, B = 1) the result carries.
CartesianSide cartesian(const BernsteinPoly& X0, const BernsteinPoly& X1, const BernsteinPoly& X2, bool rational,
                        int slot) {
  auto rp = [&](BernsteinPoly num, int e) {
    return slot == 0 ? RationalPoly{std::move(num), e, 0} : RationalPoly{std::move(num), 0, e};
  };
  CartesianSide c;
  if (!rational) {
    c.S = rp(X0, 0);
    c.Su = rp(X1, 0);
    c.Sv = rp(X0.derivative(), 0);
    c.Suu = rp(X2, 0);
    c.Suv = rp(X1.derivative(), 0);
    c.Svv = rp(X0.derivative(2), 0);
    return c;
  }
  const int d = X0.dim() - 1;
  auto xyz = [d](const BernsteinPoly& p) { return BernsteinPoly(Matrix(p.coeffs().leftCols(d))); };
  const BernsteinPoly x = xyz(X0), xu = xyz(X1), xuu = xyz(X2);
  const BernsteinPoly w = X0.component(d), wu = X1.component(d), wuu = X2.component(d);
  const BernsteinPoly xv = x.derivative(), xvv = x.derivative(2), xuv = xu.derivative();
  const BernsteinPoly wv = w.derivative(), wvv = w.derivative(2), wuv = wu.derivative();
  const BernsteinPoly Nu = product(w, xu) - product(wu, x);  // S_u = Nu / w^2
  const BernsteinPoly Nv = product(w, xv) - product(wv, x);  // S_v = Nv / w^2
  const BernsteinPoly ww = product(w, w);
  c.S = rp(x, 1);
  c.Su = rp(Nu, 2);
  c.Sv = rp(Nv, 2);
  c.Suu = rp(product(ww, xuu) - product(product(w, wuu), x) - 2.0 * product(wu, Nu), 3);
  c.Svv = rp(product(ww, xvv) - product(product(w, wvv), x) - 2.0 * product(wv, Nv), 3);
  // S_uv = d/dv (Nu / w^2) = (Nu' w - 2 Nu w') / w^3, Nu' = w' xu + w xuv - wuv x - wu xv.
  const BernsteinPoly dNu = product(wv, xu) + product(w, xuv) - product(wuv, x) - product(wu, xv);
  c.Suv = rp(product(dNu, w) - 2.0 * product(Nu, wv), 3);
  return c;
}

namespace {

/// A piece whose normals make an angle above this (its sine, relative: |N_A x N_B| / (|N_A| |N_B|)) at one of its
/// ends or its middle is not G1 as an identity: its cross coefficients exceed kIdentityRelTol (a value is a convex
/// combination of them) and its angle bound exceeds the round-off floor of the identity test (2e-9 rad) by far.
constexpr double kNotTangentSine = 1e-6;

/// True when the piece is certainly not G1 as an identity (kNotTangentSine at x = 0, 1/2 or 1; crossScale bounds
/// |N_A| |N_B| from above, so the sine there is at least the ratio tested). Only a G1 identity reads the Lemma 1
/// and Lemma 2 polynomials (the G2 bound and the connecting functions' ranges), so buildPiece leaves them out: on a
/// network whose seams are kinks they were half of the pieces' products (issue 37 goal 1).
bool clearlyNotTangent(const Piece& pc) {
  const double limit = kNotTangentSine * pc.crossScale;
  const Matrix& c = pc.cross.coeffs();
  if (c.rows() == 0 || !(limit > 0.0)) return false;
  return c.row(0).norm() > limit || c.row(c.rows() - 1).norm() > limit || pc.cross(0.5).norm() > limit;
}

}  // namespace

/// Degree of the Lemma 2 residual buildPiece forms from these sides: 2 deg D + deg B_cc + deg n_A + 2 (deg w_A +
/// deg w_B), with n_A = A_t x A_o and D = -|n_A|^2. Known before any product is formed.
int lemma2Degree(const CartesianSide& A, const CartesianSide& B, int waDegree, int wbDegree) {
  const int nA = A.Su.num.degree() + A.Sv.num.degree();
  return 2 * (2 * nA) + B.Suu.num.degree() + nA + 2 * (waDegree + wbDegree);
}

/// The piece from both sides' Cartesian forms (cartesian) and weights (1 for a polynomial side).
Piece buildPiece(const CartesianSide& A, const CartesianSide& B, BernsteinPoly wa, BernsteinPoly wb,
                 BernsteinPoly tOf, BernsteinPoly sOf, int maxDegree, PieceData data) {
  Piece pc;
  pc.tOf = std::move(tOf);
  pc.sOf = std::move(sOf);
  pc.wa = std::move(wa);
  pc.wb = std::move(wb);
  WeightContext ctx(pc.wa, pc.wb);
  const RationalPoly T = A.Sv, O = WeightContext::scaled(A.Su, -1.0), Aoo = A.Suu,
                     Aot = WeightContext::scaled(A.Suv, -1.0), Att = A.Svv;
  const RationalPoly Bc = B.Su, Bt = B.Sv, Bcc = B.Suu;
  const RationalPoly nA = WeightContext::cross(T, O);
  // |n_A|^2 once: where no end root was stripped NA is n_A's numerator itself (the same product, the same bits).
  const RationalPoly nA2 = WeightContext::dot(nA, nA);
  if (data == PieceData::kAll) {
    pc.g0 = ctx.add(A.S, B.S, -1.0);
    const RationalPoly nB = WeightContext::cross(Bt, Bc);
    const double stripA = kRoundoff * nA.num.maxCoeffNorm(), stripB = kRoundoff * nB.num.maxCoeffNorm();
    const BernsteinPoly NA = detail::stripEndRoots(nA.num, stripA), NB = detail::stripEndRoots(nB.num, stripB);
    pc.P = dot(NA, NB);
    pc.cross = seam::cross(NA, NB);
    pc.Q = dot(pc.cross, pc.cross);
    pc.R = product(NA.degree() == nA.num.degree() ? nA2.num : dot(NA, NA), dot(NB, NB));
    pc.crossScale = NA.maxCoeffNorm() * NB.maxCoeffNorm();
    pc.xa = A.S.num;
    pc.xb = B.S.num;
    pc.na = NA;
    pc.nb = NB;
    pc.c1 = ctx.add(Bc, O, -1.0);
    pc.c2 = ctx.add(Bcc, Aoo, -1.0);
    pc.O = O;
    pc.Aoo = Aoo;
    if (clearlyNotTangent(pc)) return pc;
  }
  // Lemma 2 with lambda = L / D, kappa = K / D (D = (O x T).nA):  rho~ = nA . (D^2 Bcc - L^2 Aoo - 2 L K Aot - K^2 Att)
  const RationalPoly BcT = WeightContext::cross(Bc, T);  // also |Bc x T|^2 below
  const RationalPoly L = WeightContext::dot(BcT, nA);
  const RationalPoly K = WeightContext::dot(WeightContext::cross(O, Bc), nA);
  pc.L = L;
  pc.K = K;
  // D = (O x T) . nA = -|nA|^2 since nA = T x O.
  const RationalPoly D = WeightContext::scaled(nA2, -1.0);
  pc.D = D;
  const int estimate = lemma2Degree(A, B, pc.wa.degree(), pc.wb.degree());
  assert(estimate == 2 * D.num.degree() + Bcc.num.degree() + nA.num.degree() + 2 * (pc.wa.degree() + pc.wb.degree()));
  if (estimate <= maxDegree) {
    const RationalPoly t1 = WeightContext::mul(WeightContext::mul(D, D), Bcc);
    const RationalPoly t2 = WeightContext::mul(WeightContext::mul(L, L), Aoo);
    const RationalPoly t3 = WeightContext::scaled(WeightContext::mul(WeightContext::mul(L, K), Aot), 2.0);
    const RationalPoly t4 = WeightContext::mul(WeightContext::mul(K, K), Att);
    const RationalPoly V = ctx.add(ctx.add(ctx.add(t1, t2, -1.0), t3, -1.0), t4, -1.0);
    pc.rho = WeightContext::dot(nA, V);
    const double sD = D.num.maxAbsCoeff(), sL = L.num.maxAbsCoeff(), sK = K.num.maxAbsCoeff();
    pc.rhoScale = nA.num.maxCoeffNorm() * (sD * sD * Bcc.num.maxCoeffNorm() + sL * sL * Aoo.num.maxCoeffNorm() +
                                           2.0 * sL * sK * Aot.num.maxCoeffNorm() + sK * sK * Att.num.maxCoeffNorm());
    pc.T2 = WeightContext::dot(T, T);
    pc.O2 = WeightContext::dot(O, O);
    pc.nA2 = nA2;
    pc.BcT2 = WeightContext::dot(BcT, BcT);
    pc.g2Available = true;
  }
  return pc;
}

Piece buildPiece(const std::array<BernsteinPoly, 3>& XA, const std::array<BernsteinPoly, 3>& XB, bool ratA,
                 bool ratB, BernsteinPoly tOf, BernsteinPoly sOf, int maxDegree) {
  return buildPiece(cartesian(XA[0], XA[1], XA[2], ratA, 0), cartesian(XB[0], XB[1], XB[2], ratB, 1),
                    ratA ? XA[0].component(XA[0].dim() - 1) : BernsteinPoly::constant(1.0),
                    ratB ? XB[0].component(XB[0].dim() - 1) : BernsteinPoly::constant(1.0), std::move(tOf),
                    std::move(sOf), maxDegree, PieceData::kAll);
}

namespace {

// Bounds of a rational quantity on a sub-interval [x0, x1] of the piece. The restrictions go through a per-thread
// scratch buffer (detail::restrictedCoeffs: the coefficients BernsteinPoly::restricted gives, without allocating),
// each reduced to its bound before the next one is formed; the reductions are the expressions of
// detail::lowerBound / upperBound and BernsteinPoly::maxAbsCoeff / maxCoeffNorm, so the bounds keep their bits.
using CoeffView = Eigen::Map<const Matrix>;
std::vector<double>& boundScratch() {
  thread_local std::vector<double> scratch;
  return scratch;
}

// Restrictions at high degree split from the parent interval (certifyMax's subdivision tree). The composed pieces of
// the pcurve route carry P, Q, R, ... of degree 100-500; restricting each sub-interval from the whole piece costs two
// de Casteljau subdivisions (n^2 operations) per polynomial and interval. Instead, the coefficients a node of the
// tree restricted are kept, and when the node is split both children's coefficients come from one triangle at 1/2
// (detail::splitHalves: n^2 / 2 operations for both): 4x less work. The halves agree with the direct restriction to
// round-off (each level one rounding of 0.5 a + 0.5 b, which is exact up to that rounding), not bit for bit; below
// kSplitFromParentDegree every restriction stays direct (the same bits as before).
constexpr int kSplitFromParentDegree = 32;
struct SplitTree {
  struct Entry {
    const BernsteinPoly* poly;
    std::vector<double> coeffs;
  };
  struct Node {
    std::vector<Entry> entries;
  };
  std::vector<Node> nodes;
  std::vector<int> freeNodes;
  std::vector<std::vector<double>> freeBuffers;
  bool active = false;  // inside certifyMax
  int current = -1;     // the node of the interval being bounded (-1: none yet)
  double x0 = 0.0, x1 = 1.0;

  std::vector<double> buffer(size_t size) {
    std::vector<double> b;
    if (!freeBuffers.empty()) {
      b = std::move(freeBuffers.back());
      freeBuffers.pop_back();
    }
    b.resize(size);
    return b;
  }
  int newNode() {
    if (!freeNodes.empty()) {
      const int n = freeNodes.back();
      freeNodes.pop_back();
      return n;
    }
    nodes.emplace_back();
    return static_cast<int>(nodes.size()) - 1;
  }
  void release(int n) {
    if (n < 0) return;
    for (Entry& e : nodes[static_cast<size_t>(n)].entries) freeBuffers.push_back(std::move(e.coeffs));
    nodes[static_cast<size_t>(n)].entries.clear();
    freeNodes.push_back(n);
  }
  /// The two children's nodes of node n, their entries split from n's (n is released); {-1, -1} when n is -1.
  std::pair<int, int> split(int n) {
    if (n < 0) return {-1, -1};
    const int l = newNode(), r = newNode();
    for (Entry& e : nodes[static_cast<size_t>(n)].entries) {
      const Matrix& c = e.poly->coeffs();
      std::vector<double> left = buffer(e.coeffs.size()), right = buffer(e.coeffs.size());
      detail::splitHalves(e.coeffs.data(), c.rows() - 1, c.cols(), left.data(), right.data());
      nodes[static_cast<size_t>(l)].entries.push_back({e.poly, std::move(left)});
      nodes[static_cast<size_t>(r)].entries.push_back({e.poly, std::move(right)});
    }
    release(n);
    return {l, r};
  }
  /// p restricted to [x0, x1] (the current interval): from the node when it has p, else directly (then kept).
  CoeffView view(const BernsteinPoly& p) {
    const Matrix& c = p.coeffs();
    if (current < 0) current = newNode();
    std::vector<Entry>& entries = nodes[static_cast<size_t>(current)].entries;
    for (const Entry& e : entries)
      if (e.poly == &p) return {e.coeffs.data(), c.rows(), c.cols()};
    const CoeffView direct = detail::restrictedCoeffs(p, x0, x1, boundScratch());
    std::vector<double> kept = buffer(static_cast<size_t>(c.size()));
    std::copy(direct.data(), direct.data() + c.size(), kept.data());
    entries.push_back({&p, std::move(kept)});
    return {entries.back().coeffs.data(), c.rows(), c.cols()};
  }
};
SplitTree& splitTree() {
  thread_local SplitTree tree;
  return tree;
}

CoeffView restrictedView(const BernsteinPoly& p, double x0, double x1) {
  SplitTree& tree = splitTree();
  if (tree.active && p.degree() >= kSplitFromParentDegree && x0 == tree.x0 && x1 == tree.x1) return tree.view(p);
  return detail::restrictedCoeffs(p, x0, x1, boundScratch());
}
double lowerBoundOf(const CoeffView& c) { return c.col(0).minCoeff(); }
double upperBoundOf(const CoeffView& c) { return c.col(0).maxCoeff(); }
double maxAbsCoeffOf(const CoeffView& c) { return c.size() ? c.cwiseAbs().maxCoeff() : 0.0; }
double maxCoeffNormOf(const CoeffView& c) { return c.size() ? c.rowwise().norm().maxCoeff() : 0.0; }

// Scalar Bernstein polynomial at x in [0, 1] (coefficient column 0) in O(n), no allocation: Horner's scheme in
// s = x / (1 - x) (or, mirrored, in (1 - x) / x for x > 1/2, so that |s| <= 1), times (1 - x)^n. For the samples
// of the connecting functions only (bounds never use it). Up to kScalarAtUnscaledDegree the sum stays far inside
// the double range; above it (it may reach max|c_i| 2^n) the coefficients are taken times 2^-e, e the exponent of
// their largest magnitude (exact: the same bits up to that power of two), and the value multiplied back. Up to
// kScalarAtMaxDegree the binomials stay below C(1000, 500) ~ 2.7e299 and (1/2)^n normal.
constexpr int kScalarAtUnscaledDegree = 512;
constexpr int kScalarAtMaxDegree = 1000;
double scalarAt(const BernsteinPoly& p, double x) {
  const int n = p.degree();
  const double* c = p.coeffs().data();
  if (n <= 0) return n == 0 ? c[0] : 0.0;
  if (x <= 0.0) return c[0];
  if (x >= 1.0) return c[n];
  const bool mirror = x > 0.5;
  const double y = mirror ? 1.0 - x : x, s = y / (1.0 - y);
  // sum_i c_i C(n, i) s^i from the top: C(n, i - 1) = C(n, i) i / (n - i + 1). Up to kScalarAtTableDegree the
  // factors come from a table filled by the same recurrence (the same bits), which takes the chain of divisions
  // out of the loop (most of its time: the Lemma 1 refinement evaluates degree-18 numerators thousands of times).
  constexpr int kScalarAtTableDegree = 64;
  static const std::vector<double> table = [] {
    std::vector<double> t(static_cast<size_t>((kScalarAtTableDegree + 1) * (kScalarAtTableDegree + 1)), 0.0);
    for (int m = 1; m <= kScalarAtTableDegree; ++m) {
      double b = 1.0;
      for (int i = m; i >= 1; --i) {
        b = b * i / (m - i + 1);
        t[static_cast<size_t>(m * (kScalarAtTableDegree + 1) + i)] = b;
      }
    }
    return t;
  }();
  double acc = mirror ? c[0] : c[n], binom = 1.0;
  if (n <= kScalarAtTableDegree) {
    const double* row = table.data() + static_cast<size_t>(n) * (kScalarAtTableDegree + 1);
    for (int i = n; i >= 1; --i) acc = acc * s + row[i] * (mirror ? c[n - i + 1] : c[i - 1]);
    return acc * std::pow(1.0 - y, n);
  }
  int e = 0;
  if (n > kScalarAtUnscaledDegree) {
    double big = std::numeric_limits<double>::min();
    for (int i = 0; i <= n; ++i) big = std::max(big, std::abs(c[i]));
    e = std::ilogb(big);
  }
  const double f = std::ldexp(1.0, -e);
  acc *= f;
  for (int i = n; i >= 1; --i) {
    binom = binom * i / (n - i + 1);
    acc = acc * s + binom * (f * (mirror ? c[n - i + 1] : c[i - 1]));
  }
  return std::ldexp(acc * std::pow(1.0 - y, n), e);
}

// A sample, never a bound: from degree kSampleHornerDegree (the pcurve route's composed P, Q, rho, ..., degree
// ~40-500) in O(n) by scalarAt instead of de Casteljau's O(n^2), which differs in the last bits only (issue 16 goal
// 6). Below it (every quantity of a bicubic or biquartic seam: rho of a bicubic one has degree 28) de Casteljau, as
// before. Above kScalarAtMaxDegree the binomial factors of scalarAt may overflow: de Casteljau again.
constexpr int kSampleHornerDegree = 32;
double sampleAt(const BernsteinPoly& p, double x) {
  if (p.degree() < kSampleHornerDegree || p.degree() > kScalarAtMaxDegree) return p.scalar(x);
  const double v = scalarAt(p, x);
  return std::isfinite(v) ? v : p.scalar(x);
}

// Lemma 1 connecting functions on a piece at x: lambda = L / D and kappa = (K / D) * dt/dx (K / D is per unit of
// the piece parameter; the report gives kappa per unit of A's edge parameter t). nullopt where D vanishes (a pole).
struct Lemma1Piece {
  const Piece* pc;
  BernsteinPoly dt;  // d tOf / dx
  [[nodiscard]] std::optional<std::pair<double, double>> at(double x) const {
    const Weights w = weightsAt(x);
    const double d = value(pc->D, x, w);
    if (!(std::abs(d) > 0.0) || !std::isfinite(d)) return std::nullopt;
    return std::pair{value(pc->L, x, w) / d, value(pc->K, x, w) / d * scalarAt(dt, x)};
  }
  /// lambda (kappa = false) or kappa alone at x, the same values as at(x) (the refinement needs one of them).
  [[nodiscard]] std::optional<double> one(double x, bool kappa) const {
    const Weights w = weightsAt(x);
    const double d = value(pc->D, x, w);
    if (!(std::abs(d) > 0.0) || !std::isfinite(d)) return std::nullopt;
    return kappa ? value(pc->K, x, w) / d * scalarAt(dt, x) : value(pc->L, x, w) / d;
  }

 private:
  struct Weights {
    double a, b;
  };
  [[nodiscard]] Weights weightsAt(double x) const { return {scalarAt(pc->wa, x), scalarAt(pc->wb, x)}; }
  /// r at x: its numerator over the weights' powers.
  static double value(const RationalPoly& r, double x, Weights w) {
    const double v = scalarAt(r.num, x);
    return r.ea == 0 && r.eb == 0 ? v : v / (std::pow(w.a, r.ea) * std::pow(w.b, r.eb));
  }
};

}  // namespace

SubPiece::SubPiece(const Piece& p, double x0, double x1) {
  const CoeffView wa = restrictedView(p.wa, x0, x1);
  waLo = lowerBoundOf(wa);
  waHi = upperBoundOf(wa);
  const CoeffView wb = restrictedView(p.wb, x0, x1);
  wbLo = lowerBoundOf(wb);
  wbHi = upperBoundOf(wb);
}

double evalRational(const RationalPoly& r, const Piece& pc, double x, VecX* vec) {
  const VecX v = r.num(x);
  const double den = std::pow(pc.wa.scalar(x), r.ea) * std::pow(pc.wb.scalar(x), r.eb);
  if (vec) *vec = v / den;
  return v.norm() / den;
}

double g0Bound(const Piece& pc, double x0, double x1) {
  const SubPiece sp(pc, x0, x1);
  return maxCoeffNormOf(restrictedView(pc.g0.num, x0, x1)) / sp.denLower(pc.g0);
}
double g0Value(const Piece& pc, double x) { return evalRational(pc.g0, pc, x); }

/// An upper bound of Q / R on an interval from the two polynomials' Bernstein coefficients there (R's all positive,
/// rLo their minimum). Q and R of one degree (Q = |N_A x N_B|^2, R = |N_A|^2 |N_B|^2 are): Q_i <= m R_i for every i
/// with m = max_i Q_i / R_i, so Q = sum Q_i B_i <= m sum R_i B_i = m R (the B_i >= 0). Each ratio compares the two
/// polynomials at about the same point (the coefficients converge to the values at the Greville abscissae as the
/// interval shrinks), so m exceeds the maximum of Q / R by O(h^2) on an interval of width h, where Q_hi / R_lo (the
/// extremes of two coefficient lists, taken at different points) exceeds it by O(h): the subdivision closes in
/// fewer steps (issue 37 goal 1). The smaller of the two is returned (both are bounds); `byRatios` false: Q_hi / R_lo.
namespace {
double sineSquaredBound(const CoeffView& q, const std::vector<double>& r, double rLo, bool byRatios) {
  const double qHi = std::max(0.0, upperBoundOf(q));
  double bound = qHi / rLo;
  if (byRatios && static_cast<size_t>(q.rows()) == r.size()) {
    double m = 0.0;
    for (Eigen::Index i = 0; i < q.rows(); ++i) m = std::max(m, q(i, 0) / r[static_cast<size_t>(i)]);
    bound = std::min(bound, m);
  }
  return bound;
}
}  // namespace

/// g1Bound adds the cosine's bound where the sine's bound reaches this sin^2 (45 degrees): above it the arcsine is
/// the worse conditioned of the two (at 45 degrees both have slope 1 / cos = 1 / sin = sqrt 2).
constexpr double kG1CosineBoundMinSin2 = 0.5;
namespace {
double g1BoundOf(const Piece& pc, double x0, double x1, bool byRatios) {
  // R's restricted coefficients are kept (a direct restriction of Q below reuses the scratch R's view points into).
  thread_local std::vector<double> rKept;
  double rLo = 0.0, rHi = 0.0;
  {
    const CoeffView r = restrictedView(pc.R, x0, x1);
    rLo = lowerBoundOf(r);
    rHi = upperBoundOf(r);
    if (byRatios) rKept.assign(r.data(), r.data() + r.rows());
  }
  // A normal may vanish in [x0, x1] (a pole, or a point where a side's cross-boundary derivative meets the edge's
  // tangent): no angle bound. The subdivision either separates the zero or ends unclosed (certifyMax: ok = false);
  // pi here let a seam be certified a 180-degree crease on the strength of that one point (issue 35 §2).
  if (!(rLo > 0.0)) return std::numeric_limits<double>::infinity();
  const double pLo = lowerBoundOf(restrictedView(pc.P, x0, x1));
  if (pLo > 0.0) {
    // Below 90 degrees two bounds hold: sin^2(angle) = Q / R <= max_i Q_i / R_i, and cos(angle) = P / sqrt(R) >=
    // P_lo / sqrt(R_hi). The sine's is the sharp one at small angles; next to 90 degrees (a crease) the arcsine of
    // a value close to 1 is ill-conditioned (a 0.06 % overestimate of Q / R moves an 88.5-degree bound by 0.9
    // degrees) and the cosine's is the sharp one. Above 45 degrees (sin^2 > 1/2) the smaller of the two.
    const double sin2 = std::min(1.0, sineSquaredBound(restrictedView(pc.Q, x0, x1), rKept, rLo, byRatios));
    const double bySine = std::asin(std::sqrt(sin2));
    if (!(sin2 > kG1CosineBoundMinSin2)) return bySine;
    return std::min(bySine, std::acos(std::min(1.0, pLo / std::sqrt(rHi))));
  }
  return std::acos(std::clamp(pLo / std::sqrt(rLo), -1.0, 1.0));
}
}  // namespace
double g1Bound(const Piece& pc, double x0, double x1) { return g1BoundOf(pc, x0, x1, false); }
double g1BoundByRatios(const Piece& pc, double x0, double x1) { return g1BoundOf(pc, x0, x1, true); }
std::optional<double> g1ValueIfDefined(const Piece& pc, double x) {
  const double p = sampleAt(pc.P, x), q = std::max(0.0, sampleAt(pc.Q, x)), r = sampleAt(pc.R, x);
  // The angle is atan2(sqrt(Q), P) with P^2 + Q = R = |N_A|^2 |N_B|^2. Each value is off by at most about
  // 2 (n + 1) eps times its largest coefficient (n the degree; the evaluation's error bound); an error dP moves the
  // angle by at most dP / sqrt(R), an error dQ moves sqrt(Q) by at most dQ / (sqrt(Q) + sqrt(dQ)).
  const double e = 2.0 * (std::max({pc.P.degree(), pc.Q.degree(), pc.R.degree()}) + 1) *
                   std::numeric_limits<double>::epsilon();
  const double dP = e * pc.P.maxAbsCoeff(), dQ = e * pc.Q.maxAbsCoeff(), dR = e * pc.R.maxAbsCoeff();
  const double norm = std::sqrt(std::max(0.0, r - dR));
  if (!(norm > 0.0) || !((dP + dQ / (std::sqrt(q) + std::sqrt(dQ))) <= kG1ValueNoise * norm)) return std::nullopt;
  return std::atan2(std::sqrt(q), p);
}
double g1Value(const Piece& pc, double x) { return g1ValueIfDefined(pc, x).value_or(0.0); }

bool g1IdentityOf(const std::vector<Piece>& pieces, bool boundClosed, double boundDeg, bool foldSeen) {
  bool coeffIdentity = true, fold = foldSeen;
  for (const Piece& pc : pieces) {
    if (pc.cross.maxAbsCoeff() > kIdentityRelTol * pc.crossScale) coeffIdentity = false;
    if (!fold && folds(pc, kIdentityRelTol * pc.crossScale)) fold = true;
  }
  const bool angleAtRoundoff = boundClosed && boundDeg <= kIdentityBoundFactor * kAngleBoundFloor * kRadToDeg;
  return (coeffIdentity && !fold) || angleAtRoundoff;
}

double g2Bound(const Piece& pc, double x0, double x1) {
  const SubPiece sp(pc, x0, x1);
  const double rho = maxAbsCoeffOf(restrictedView(pc.rho.num, x0, x1)) / sp.denLower(pc.rho);
  const double t2 = upperBoundOf(restrictedView(pc.T2.num, x0, x1)) / sp.denLower(pc.T2);
  const double n2 = lowerBoundOf(restrictedView(pc.nA2.num, x0, x1)) / sp.denUpper(pc.nA2);
  const double b2 = lowerBoundOf(restrictedView(pc.BcT2.num, x0, x1)) / sp.denUpper(pc.BcT2);
  if (!(n2 > 0.0) || !(b2 > 0.0)) return std::numeric_limits<double>::infinity();
  return rho * t2 / (std::pow(n2, 2.5) * b2);
}
// The G2 quotient at x, or nullopt where it has no value: a vanishing normal or tangent, or a chart too
// ill-conditioned for curvature (next to a pole the quotient is round-off over a vanishing normal, as in measureAt).
std::optional<double> g2ValueIfDefined(const Piece& pc, double x) {
  // The weights once (each quotient formed them again: the same values); the numerators as samples (sampleAt).
  const double wa = pc.wa.scalar(x), wb = pc.wb.scalar(x);
  auto val = [&](const RationalPoly& r) { return sampleAt(r.num, x) / (std::pow(wa, r.ea) * std::pow(wb, r.eb)); };
  const double n2 = val(pc.nA2), b2 = val(pc.BcT2);
  if (!(n2 > 0.0) || !(b2 > 0.0)) return std::nullopt;
  const double o2 = val(pc.O2);
  if (std::sqrt(n2) < kCurvatureChartRel * (val(pc.T2) + o2)) return std::nullopt;
  return std::abs(val(pc.rho)) * val(pc.T2) / (std::pow(n2, 2.5) * b2);
}
double g2Value(const Piece& pc, double x) { return g2ValueIfDefined(pc, x).value_or(0.0); }

// The largest Lemma 2 residual over all pieces (as lemma1Ranges: kLemma1Samples per piece, the largest sample refined
// by golden section between its neighbours), where the curvature quotient is defined (g2ValueIfDefined).
std::optional<double> lemma2ResidualMax(const std::vector<Piece>& pieces) {
  double out = 0.0;
  for (const Piece& pc : pieces) {
    if (!pc.g2Available) return std::nullopt;
    const auto value = [&](double x) {
      if (!g2ValueIfDefined(pc, x)) return 0.0;
      const double wa = pc.wa.scalar(x), wb = pc.wb.scalar(x);
      auto val = [&](const RationalPoly& r) { return sampleAt(r.num, x) / (std::pow(wa, r.ea) * std::pow(wb, r.eb)); };
      return std::abs(val(pc.rho)) / std::pow(val(pc.nA2), 2.5);  // |n_A . res| / |n_A| with D^2 = |n_A|^4
    };
    double best = -1.0, where = 0.0;
    for (int i = 0; i <= kLemma1Samples; ++i) {
      const double x = static_cast<double>(i) / kLemma1Samples, v = value(x);
      if (v > best) best = v, where = x;
    }
    if (where > 0.0 && where < 1.0) {
      const double h = 1.0 / kLemma1Samples;
      best = std::max(best, refineMax(value, where - h, where + h, kLemma1GoldenIterations).second);
    }
    out = std::max(out, best);
  }
  return out;
}

// Ranges of lambda and kappa over all pieces: kLemma1Samples per piece, the extreme sample of each refined by golden
// section between its neighbours (cheap rational polynomials here, unlike the pointwise measures).
void lemma1Ranges(const std::vector<Piece>& pieces, Interval& lambda, Interval& kappa) {
  double lmin = std::numeric_limits<double>::infinity(), lmax = -lmin, kmin = lmin, kmax = -lmin;
  for (const Piece& pc : pieces) {
    if (pc.D.num.coeffs().size() == 0) return;  // not built: keep the sampled ranges
    const Lemma1Piece lp{&pc, pc.tOf.derivative()};
    std::array<double, 4> best{-lmin, -lmin, -lmin, -lmin};  // -lambda, lambda, -kappa, kappa
    std::array<double, 4> where{0, 0, 0, 0};
    auto value = [&](int k, double x) {
      const auto v = lp.one(x, k >= 2);
      if (!v) return -std::numeric_limits<double>::infinity();
      const double f = *v;
      return k % 2 == 0 ? -f : f;
    };
    for (int i = 0; i <= kLemma1Samples; ++i) {
      const double x = static_cast<double>(i) / kLemma1Samples;
      const auto v = lp.at(x);
      if (!v) continue;
      for (int k = 0; k < 4; ++k) {
        const double f = (k < 2 ? v->first : v->second) * (k % 2 == 0 ? -1.0 : 1.0);
        if (f > best[static_cast<size_t>(k)]) {
          best[static_cast<size_t>(k)] = f;
          where[static_cast<size_t>(k)] = x;
        }
      }
    }
    for (int k = 0; k < 4; ++k) {
      const double x = where[static_cast<size_t>(k)], h = 1.0 / kLemma1Samples;
      if (x == 0.0 || x == 1.0) continue;  // extreme at a piece end: attained there (the end is sampled)
      // Constant to round-off (the common case of exact G1 splits): nothing to refine.
      const size_t pair = static_cast<size_t>(k / 2) * 2;  // (-f, f) slots of this function
      const double spread = best[pair] + best[pair + 1], scale = std::max(std::abs(best[pair + 1]), 1.0);
      if (spread <= kLemma1ConstantRel * scale) continue;
      const auto [xr, fr] =
          refineMax([&](double y) { return value(k, y); }, x - h, x + h, kLemma1GoldenIterations);
      (void)xr;
      best[static_cast<size_t>(k)] = std::max(best[static_cast<size_t>(k)], fr);
    }
    lmin = std::min(lmin, -best[0]);
    lmax = std::max(lmax, best[1]);
    kmin = std::min(kmin, -best[2]);
    kmax = std::max(kmax, best[3]);
  }
  if (lmin <= lmax) {
    lambda = {lmin, lmax};
    kappa = {kmin, kmax};
  }
}

// Certified maximum over all pieces: subdivides each piece until its bound is within the relative gap of the best
// value seen (`best`, raised by the values found at midpoints). Returns the bound; `ok` false when some interval
// could not be bounded (infinite bound at the depth limit).
double certifyMax(const std::vector<Piece>& pieces, const std::function<double(const Piece&, double, double)>& bound,
                  const std::function<double(const Piece&, double)>& value, double& best, double& bestX,
                  int& bestPiece, double floor, const SeamOptions& opt, bool& ok, const bool* stop,
                  std::pair<int, double>* unclosed, double threshold) {
  struct Item {
    int piece;
    double x0, x1;
    int depth;
    int node;  // the interval's high-degree restrictions, split from its parent's (SplitTree), or -1
  };
  // The subdivision tree's kept restrictions (per thread; released however this returns).
  SplitTree& tree = splitTree();
  std::vector<Item> stack;
  struct Release {
    SplitTree& tree;
    std::vector<Item>& stack;
    ~Release() {
      for (const Item& it : stack) tree.release(it.node);
      tree.release(tree.current);
      tree.current = -1;
      tree.active = false;
    }
  } release{tree, stack};
  tree.active = true;
  for (int i = 0; i < static_cast<int>(pieces.size()); ++i) stack.push_back({i, 0.0, 1.0, 0, -1});
  double result = 0.0;
  ok = true;
  long work = 0;
  while (!stack.empty()) {
    if (stop != nullptr && *stop) {  // the caller's value function met a point where no bound can close
      ok = false;
      return std::numeric_limits<double>::infinity();
    }
    const Item it = stack.back();
    stack.pop_back();
    const Piece& pc = pieces[static_cast<size_t>(it.piece)];
    tree.current = it.node;
    tree.x0 = it.x0;
    tree.x1 = it.x1;
    const double ub = bound(pc, it.x0, it.x1);
    const int node = tree.current;  // created by the bound when it restricted a high-degree polynomial
    tree.current = -1;
    ++work;
    const bool straddles = best <= threshold && ub > threshold + floor;
    if (ub <= (1.0 + opt.boundRelGap) * best + floor && !straddles) {
      result = std::max(result, ub);
      tree.release(node);
      continue;
    }
    if (it.depth >= opt.maxSubdivisionDepth || work >= opt.maxBoundWork) {
      if (!std::isfinite(ub)) {
        if (ok && unclosed != nullptr) *unclosed = {it.piece, 0.5 * (it.x0 + it.x1)};
        ok = false;
      }
      result = std::max(result, ub);
      tree.release(node);
      continue;
    }
    const double xm = 0.5 * (it.x0 + it.x1);
    const double v = value(pc, xm);
    if (v > best) {
      best = v;
      bestX = xm;
      bestPiece = it.piece;
    }
    const auto [left, right] = tree.split(node);
    stack.push_back({it.piece, it.x0, xm, it.depth + 1, left});
    stack.push_back({it.piece, xm, it.x1, it.depth + 1, right});
  }
  return std::max(result, best);
}

}  // namespace seam::detail
