// Seams along parameter curves (trimmed B-rep edges): certified G0 / G1 by composition, G2 through charts that have
// the edge as a coordinate line (certifyPCurveSeam, include/seam/continuity/seam.h; docs/algorithms/seam-measures.md,
// "Seams along parameter curves").
#include <fmt/format.h>

#include <cassert>

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <vector>

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "continuity/sampling.h"
#include "continuity/seam_piece.h"
#include "continuity/seam_side.h"
#include "core/bernstein_internal.h"
#include "seam/continuity/seam.h"
#include "seam/core/bernstein.h"
#include "seam/core/tolerances.h"

namespace seam {

namespace {

using detail::CartesianSide;
using detail::certifyMax;
using detail::evalRational;
using detail::kAngleBoundFloor;
using detail::kFlatCurvatureRatio;
using detail::kIdentityBoundFactor;
using detail::kRadToDeg;
using detail::Piece;
using detail::PieceData;
using detail::RationalPoly;
using detail::shapeInFrame;
using detail::spectralNorm;
using detail::WeightContext;

/// Deepest bisection while isolating the knot-line crossings of a pcurve (2^-60 of a pcurve piece).
constexpr int kPCurveSplitDepth = 60;
/// Bisection steps for a crossing of a monotone pcurve coordinate with a knot line (to the last bit).
constexpr int kCrossingBisections = 80;
/// Start samples per composed piece (the bound subdivision refines).
constexpr int kPCurveSamplesPerPiece = 8;
/// A chart whose two directions make an angle with sine below this is ill-conditioned at that point (a pole):
/// its curvature samples are skipped, for the curvature reference and for refuting a G2 identity.
constexpr double kChartRegularSin = 1e-3;
/// The pcurve route certifies its Lemma 2 (G2) polynomials up to this degree, whatever SeamOptions::maxCertifiedDegree
/// allows G0 and G1 (the B-rep check: 1000). Above it, on the 8 files of ../shared/data, they certified only the
/// curvature jumps of seams that are G1 and not G2 anyway (boxed_sphere: 8 seams, jumps of 100 % bounded at 101 %),
/// and cost boxed_sphere's check 1.26 s of CPU instead of 0.81 s (2026-12-01).
constexpr int kPCurveG2MaxDegree = 256;
/// A chart curvature sample whose round-off estimate exceeds this share of its value (or of a plane's) is skipped
/// (chartCurvature).
constexpr double kChartCurvatureNoiseShare = 0.01;
/// The unit round-off of double arithmetic (the evaluation error of each coefficient operation).
constexpr double kUnitRoundoff = std::numeric_limits<double>::epsilon();

/// The largest of value(piece, x) at kPCurveSamplesPerPiece + 1 evenly spaced x on every piece (the start value
/// of certifyMax).
struct BestSample {
  double value = 0.0, x = 0.0;
  int piece = 0;
};
BestSample bestSample(const std::vector<Piece>& pieces, double (*value)(const Piece&, double)) {
  BestSample b;
  for (size_t i = 0; i < pieces.size(); ++i)
    for (int k = 0; k <= kPCurveSamplesPerPiece; ++k) {
      const double x = static_cast<double>(k) / kPCurveSamplesPerPiece;
      if (const double v = value(pieces[i], x); v > b.value) b = {v, x, static_cast<int>(i)};
    }
  return b;
}

/// The Bezier patches of a surface by span, with their homogeneous Bernstein forms and partials up to order 2.
struct SpanPatches {
  std::vector<Interval> us, vs;  // spans along u and v
  /// Per (iu, iv): H, H_u, H_v, H_uu, H_uv, H_vv, per unit of the span's local parameters.
  std::vector<std::array<BernsteinPatch, 6>> h;
  [[nodiscard]] const std::array<BernsteinPatch, 6>& at(size_t iu, size_t iv) const { return h[iu * vs.size() + iv]; }
};

/// The partials come from the differenced control net (BSplineSurface::homogeneousDerivativePatches), not from
/// differencing each span's Bezier points: on a short span (CAD files have spans of 1e-7 of the domain) those agree
/// to many digits and their differences would carry round-off amplified by 1 / (span length)^k.
SpanPatches spanPatches(const BSplineSurface& s) {
  SpanPatches out;
  const std::vector<BezierPatchPiece> pieces = s.bezierPatches();
  for (const BezierPatchPiece& p : pieces) {
    if (p.spanV == 0) out.us.push_back(p.u);
    if (p.spanU == 0) out.vs.push_back(p.v);
  }
  const size_t n = out.us.size() * out.vs.size();
  constexpr std::array<std::array<int, 2>, 5> kOrders{{{1, 0}, {0, 1}, {2, 0}, {1, 1}, {0, 2}}};
  std::array<std::vector<BernsteinPatch>, 5> partials;
  for (size_t k = 0; k < kOrders.size(); ++k) {
    partials[k] = s.homogeneousDerivativePatches(kOrders[k][0], kOrders[k][1]);
    assert(partials[k].size() == n);
  }
  out.h.resize(n);
  for (const BezierPatchPiece& p : pieces) {
    const size_t i = static_cast<size_t>(p.spanU) * out.vs.size() + static_cast<size_t>(p.spanV);
    auto& h = out.h[i];
    h[0] = p.patch.homogeneous();
    for (size_t k = 0; k < kOrders.size(); ++k) {
      h[k + 1] = std::move(partials[k][i]);
      h[k + 1].coeffs() *= std::pow(p.u.length(), kOrders[k][0]) * std::pow(p.v.length(), kOrders[k][1]);
    }
  }
  return out;
}

/// The span containing the coordinate range [lo, hi] (slack: a pcurve may overshoot a knot or the domain by
/// round-off); where it lies on a knot line, the span on the face's side. nullopt when none or ambiguous.
std::optional<size_t> spanOf(const std::vector<Interval>& spans, double lo, double hi, Interval face,
                             double endSlackRel) {
  const double range = spans.back().hi - spans.front().lo;
  const double slack = kKnotRelTol * range, endSlack = endSlackRel * range;
  std::optional<size_t> found;
  int count = 0;
  for (size_t i = 0; i < spans.size(); ++i) {
    const double below = i == 0 ? endSlack : slack, above = i + 1 == spans.size() ? endSlack : slack;
    if (!(spans[i].lo - below <= lo && hi <= spans[i].hi + above)) continue;
    const double overlap = std::min(spans[i].hi, face.hi) - std::max(spans[i].lo, face.lo);
    if (overlap > 0.0 || !found) {
      if (overlap > 0.0) ++count;
      found = i;
    }
  }
  if (count > 1) return std::nullopt;  // on a knot line inside the face's box on both sides: ambiguous
  return found;
}

/// An interior knot of `spans` strictly inside (lo, hi) beyond round-off, if any.
std::optional<double> knotInside(const std::vector<Interval>& spans, double lo, double hi) {
  const double slack = kKnotRelTol * (spans.back().hi - spans.front().lo);
  for (size_t i = 0; i + 1 < spans.size(); ++i) {
    const double k = spans[i].hi;
    if (k > lo + slack && k < hi - slack) return k;
  }
  return std::nullopt;
}

/// Where a scalar polynomial on [0, 1] crosses `level`, when it is monotone there (coefficients of the derivative
/// of one sign) and takes values on both sides at the ends; bisection to the last bit.
std::optional<double> monotoneCrossing(const BernsteinPoly& f, double level) {
  const BernsteinPoly df = f.derivative();
  const Matrix& d = df.coeffs();
  const bool up = (d.array() > 0.0).all(), down = (d.array() < 0.0).all();
  const double f0 = f.coeffs()(0, 0) - level, f1 = f.coeffs()(f.degree(), 0) - level;
  if (!(up || down) || !(f0 * f1 < 0.0)) return std::nullopt;
  double lo = 0.0, hi = 1.0;
  for (int i = 0; i < kCrossingBisections && hi - lo > 0.0; ++i) {
    const double mid = 0.5 * (lo + hi);
    if (mid <= lo || mid >= hi) break;
    ((f.scalar(mid) - level) * f0 > 0.0 ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

/// A pcurve on a leaf: (u / w, v / w) with w = 1 (degree 0) for polynomial pcurves; local parameter [0, 1].
struct PCurvePiece {
  BernsteinPoly u, v, w;
  bool rational = false;
  /// The coordinate k (0 = u, 1 = v) as a numerator over w.
  [[nodiscard]] const BernsteinPoly& num(int k) const { return k == 0 ? u : v; }
  /// Where coordinate k can be: the hull of the ratios of its coefficients to w's (the control points' coordinate;
  /// a curve with positive weights lies in their hull). w's coefficients all equal (elevated) when w is constant.
  [[nodiscard]] std::pair<double, double> hull(int k) const {
    const BernsteinPoly& n = num(k);
    const Eigen::ArrayXd r = n.coeffs().col(0).array() / w.elevatedTo(n.degree()).coeffs().col(0).array();
    return {r.minCoeff(), r.maxCoeff()};
  }
};

struct PCurveLeaf {
  double t0 = 0, t1 = 0;   // in A's parameter
  PCurvePiece ca, cb;      // each side's pcurve on the leaf
  size_t aiu = 0, aiv = 0, biu = 0, biv = 0;
};

/// One side's pcurve on [s0, s1] of its own parameter: the Bezier piece containing it, restricted (homogeneous
/// (w u, w v, w) for a rational pcurve).
PCurvePiece pcurveOn(const std::vector<BezierCurvePiece>& pieces, double s0, double s1) {
  const double mid = 0.5 * (s0 + s1);
  size_t k = 0;
  while (k + 1 < pieces.size() && mid > pieces[k].interval.hi) ++k;
  const Interval iv = pieces[k].interval;
  const bool rational = pieces[k].curve.isRational();
  const BernsteinPoly c = rational ? pieces[k].curve.homogeneous() : BernsteinPoly(pieces[k].curve.points());
  const BernsteinPoly r = c.restricted((s0 - iv.lo) / iv.length(), (s1 - iv.lo) / iv.length());
  if (!rational) return {r.component(0), r.component(1), BernsteinPoly::constant(1.0), false};
  return {r.component(0), r.component(1), r.component(2), true};
}

/// A side's pcurve in the span's local coordinates, and composition with the span's patches: P(u / w, v / w),
/// homogenised (times w^(deg P)) for a rational pcurve; a polynomial surface is then lifted to homogeneous form
/// (weight 1, its partials weight 0) so that the composed side is rational x / w like a NURBS side.
struct LocalPCurve {
  BernsteinPoly u, v, w;
  bool rationalCurve = false, lift = false;
  LocalPCurve(const PCurvePiece& c, Interval U, Interval V, bool surfaceRational)
      : u((c.u - U.lo * c.w) * (1.0 / U.length())),
        v((c.v - V.lo * c.w) * (1.0 / V.length())),
        w(c.w),
        rationalCurve(c.rational),
        lift(c.rational && !surfaceRational) {}
  /// `order` = 0 for the surface itself, > 0 for a partial derivative (lifted weight 0).
  [[nodiscard]] BernsteinPoly compose(const BernsteinPatch& P, int order) const {
    if (!rationalCurve) return P.composed(u, v);
    if (!lift) return P.composed(u, v, w);
    Matrix c(P.coeffs().rows(), P.coeffs().cols() + 1);
    c.leftCols(P.coeffs().cols()) = P.coeffs();
    c.col(P.coeffs().cols()).setConstant(order == 0 ? 1.0 : 0.0);
    return BernsteinPatch(P.degreeU(), P.degreeV(), std::move(c)).composed(u, v, w);
  }
  /// The parameter-plane tangent's numerator: c' for a polynomial pcurve, (u' w - u w', v' w - v w') otherwise.
  [[nodiscard]] std::array<BernsteinPoly, 2> tangent() const {
    if (!rationalCurve) return {u.derivative(), v.derivative()};
    return {product(u.derivative(), w) - product(u, w.derivative()),
            product(v.derivative(), w) - product(v, w.derivative())};
  }
  [[nodiscard]] Vec2 at(double x) const { return Vec2(u.scalar(x), v.scalar(x)) / w.scalar(x); }
};

/// The composed side on a leaf: homogeneous S, S_u, S_v of the surface along the pcurve.
struct ComposedSide {
  BernsteinPoly x, w;   // Cartesian numerator and weight (w = 1 for polynomial surfaces)
  BernsteinPoly normal; // numerator of S_u x S_v (a positive factor dropped), with the face's sense
  /// H, H_u, H_v composed with the pcurve (LocalPCurve::compose, per unit of the span's local parameters):
  /// the first rows of the G2 chart (chartRows), which reuses them.
  std::array<BernsteinPoly, 3> h;
};

ComposedSide composeSide(const SpanPatches& sp, size_t iu, size_t iv, const PCurvePiece& c, bool surfaceRational,
                         double sign) {
  const Interval U = sp.us[iu], V = sp.vs[iv];
  const LocalPCurve lc(c, U, V, surfaceRational);
  const auto& H = sp.at(iu, iv);
  ComposedSide out;
  out.h = {lc.compose(H[0], 0), lc.compose(H[1], 1), lc.compose(H[2], 1)};
  const BernsteinPoly& X = out.h[0];
  const BernsteinPoly Xu = out.h[1] * (1.0 / U.length()), Xv = out.h[2] * (1.0 / V.length());
  if (!surfaceRational && !c.rational) {
    out.x = X;
    out.w = BernsteinPoly::constant(1.0);
    out.normal = cross(Xu, Xv) * sign;
    return out;
  }
  auto xyz = [](const BernsteinPoly& p) { return BernsteinPoly(Matrix(p.coeffs().leftCols(3))); };
  out.x = xyz(X);
  out.w = X.component(3);
  // S = x / w: S_u = (w x_u - w_u x) / w^2; the normal direction is that of the product of the numerators (the
  // homogenising powers of a rational pcurve's weight are positive factors too).
  const BernsteinPoly Nu = product(out.w, xyz(Xu)) - product(Xu.component(3), out.x);
  const BernsteinPoly Nv = product(out.w, xyz(Xv)) - product(Xv.component(3), out.x);
  out.normal = cross(Nu, Nv) * sign;
  return out;
}

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
/// Halvings of the cells whose closest-point excess exceeds the target (PCurveSeam::closestExcess): a cell's own
/// bounds of the residual, |B_x| and the normal's turning lie closer to the values at each point than the leaf's (a
/// rational quadratic edge: 10.5 deg of excess from the whole leaf, 2.2 deg from 8 cells, 1.75 deg true). The
/// halving stops when a round lowers the largest excess by less than kClosestRefineGain: where the pcurves drift,
/// the excess is the drift times the normal's turning, which smaller cells do not lower (linkrods.step: 0.36 s of
/// CPU for 8 cells per leaf, and the same bound).
constexpr int kClosestRefineRounds = 3;
constexpr double kClosestRefineGain = 0.75;

/// An upper bound of max |p| on [0, 1]: the largest |coefficient|, on halves (up to `depth` times) where it exceeds
/// the piece's end values (which are values of p) by more than kResidualBoundRel.
double maxAbsBound(const BernsteinPoly& p, int depth) {
  const Matrix& c = p.coeffs();
  const double b = p.maxAbsCoeff(), ends = std::max(std::abs(c(0, 0)), std::abs(c(c.rows() - 1, 0)));
  if (b <= (1.0 + kResidualBoundRel) * ends || depth <= 0) return b;
  const auto [left, right] = p.subdivided(0.5);
  return std::max(maxAbsBound(left, depth - 1), maxAbsBound(right, depth - 1));
}

/// What bounds, on one leaf (local parameter x in [0, 1]), how far B's point closest to A(x) lies from the paired
/// B(x) (SeamOptions::closestPointsOn; kOnA: A and B exchanged): Bernstein coefficient bounds, A = X_A / w_A,
/// B = X_B / w_B.
struct ClosestData {
  double f = 0.0;        ///< max |(A - B) . B_x|, the closest-point equation's residual at the paired point
  double speedLo = 0.0;  ///< min |B_x| (0: not bounded away from zero)
  double speedHi = 0.0;  ///< max |B_x|
  double accelHi = 0.0;  ///< max |B_xx|
  double gapHi = 0.0;    ///< max |A - B|
  double turnHi = std::numeric_limits<double>::infinity();  ///< max |d(N_B / |N_B|) / dx| (radians per unit x)
};

/// A piece [x0, x1] of a leaf, [t0, t1] of the edge (A's parameter), with its ClosestData (per unit of its own local
/// parameter).
struct ClosestCell {
  size_t leaf = 0;
  double x0 = 0.0, x1 = 1.0, t0 = 0.0, t1 = 0.0;
  ClosestData d;
};

/// One leaf's sides for the closest-point excess (SeamOptions::closestPointsOn): A = xa / wa, the side whose points
/// are taken, B = xb / wb, the side their closest points lie on, nb B's normal numerator (end roots divided out),
/// and the leaf as one cell.
struct ClosestLeaf {
  BernsteinPoly xa, wa, xb, wb, nb;
  ClosestCell whole;
};

/// B_x = T / w_B^2 with T = X_B' w_B - X_B w_B'; B_xx = (T' w_B - 2 T w_B') / w_B^3; A - B = D / (w_A w_B) with
/// D = X_A w_B - X_B w_A; so (A - B) . B_x = (D . T) / (w_A w_B^3). The unit normal turns by at most |N'| / |N| for
/// any numerator N of it. On [x0, x1] of the leaf, per unit of the local parameter of [x0, x1]; `refine`: the
/// residual's bound made closer by halving (maxAbsBound) where its coefficients bound it loosely (A - B turning
/// against B's tangent along the piece).
ClosestData closestData(const ClosestLeaf& L, double x0, double x1, bool refine) {
  ClosestData d;
  const auto on = [&](const BernsteinPoly& p) { return x0 == 0.0 && x1 == 1.0 ? p : p.restricted(x0, x1); };
  const BernsteinPoly xa = on(L.xa), wa = on(L.wa), xb = on(L.xb), wb = on(L.wb), nb = on(L.nb);
  const double waLo = wa.coeffs().minCoeff(), wbLo = wb.coeffs().minCoeff(), wbHi = wb.coeffs().maxCoeff();
  if (!(waLo > 0.0 && wbLo > 0.0)) return d;
  const BernsteinPoly D = product(xa, wb) - product(xb, wa);
  const BernsteinPoly wb1 = wb.derivative();
  const BernsteinPoly T = product(xb.derivative(), wb) - product(xb, wb1);
  const BernsteinPoly acc = product(T.derivative(), wb) - 2.0 * product(T, wb1);
  const BernsteinPoly F = dot(D, T);
  const double den = waLo * wbLo * wbLo * wbLo;
  d.f = (refine ? maxAbsBound(F, kResidualBoundDepth) : F.maxAbsCoeff()) / den;
  d.speedLo = normLowerBound(T) / (wbHi * wbHi);
  d.speedHi = T.maxCoeffNorm() / (wbLo * wbLo);
  d.accelHi = acc.maxCoeffNorm() / (wbLo * wbLo * wbLo);
  d.gapHi = D.maxCoeffNorm() / (waLo * wbLo);
  if (const double nLo = normLowerBound(nb); nLo > 0.0) d.turnHi = nb.derivative().maxCoeffNorm() / nLo;
  return d;
}

/// One side's homogeneous rows along a leaf in the chart (s, tau) -> H(c(tau) + s d(tau)) (span-local coordinates):
/// H(c), dH/ds = d_u H_u + d_v H_v and d2H/ds2 = d_u^2 H_uu + 2 d_u d_v H_uv + d_v^2 H_vv, all composed with the
/// pcurve, in the form `cartesian` and `buildPiece` take for patch edges (row k: k-th derivative across the edge).
/// d = rot(G c'), G the first fundamental form at the leaf's midpoint (normalised): transversal wherever the pcurve
/// moves (det(c', d) = c'^T G c' > 0), polynomial of the pcurve's degree, and orthogonal to the edge in 3-D at the
/// midpoint, so the chart stays well conditioned however unequal the parameter scales are (a span of 1e-6 against
/// one of 1: with d = rot(c') the two chart directions would be nearly parallel in 3-D).
/// For a rational pcurve (u / w, v / w) the chart is K(s, t) = sum P_ij B_i(u + s D_u, w) B_j(v + s D_v, w) with
/// homogeneous Bernstein polynomials B(x, w) = w^n b(x / w): a polynomial in (s, t) representing S((u + s D_u) / w,
/// (v + s D_v) / w), whose s-derivatives at s = 0 are the compositions of H_u, ..., H_vv homogenised the same way;
/// D = rot(G N) with N the numerator of c' (transversal as above, since w > 0).
/// `composed`: H, H_u, H_v composed with the pcurve on this leaf (ComposedSide::h), reused.
std::array<BernsteinPoly, 3> chartRows(const SpanPatches& sp, size_t iu, size_t iv, const PCurvePiece& c,
                                       bool surfaceRational, const std::array<BernsteinPoly, 3>& composed) {
  const Interval U = sp.us[iu], V = sp.vs[iv];
  const LocalPCurve lc(c, U, V, surfaceRational);
  const auto& H = sp.at(iu, iv);
  // First fundamental form at the midpoint (Cartesian partials).
  const Vec2 m = lc.at(0.5);
  const VecX h = H[0](m[0], m[1]), hu = H[1](m[0], m[1]), hv = H[2](m[0], m[1]);
  Vec3 su, sv;
  if (surfaceRational) {
    const double w = h[3];
    su = (w * hu.head<3>() - hu[3] * h.head<3>()) / (w * w);
    sv = (w * hv.head<3>() - hv[3] * h.head<3>()) / (w * w);
  } else {
    su = hu.head<3>();
    sv = hv.head<3>();
  }
  Eigen::Matrix2d G;
  G << su.dot(su), su.dot(sv), su.dot(sv), sv.dot(sv);
  const double trace = G.trace();
  if (!(G.determinant() > 0.0) || !std::isfinite(trace)) G.setIdentity();
  else G /= trace;
  const auto [du, dv] = lc.tangent();
  const BernsteinPoly gu = G(0, 0) * du + G(0, 1) * dv, gv = G(1, 0) * du + G(1, 1) * dv;  // G c'
  const BernsteinPoly a = -1.0 * gv, b = gu;                                                 // d = rot(G c')
  const BernsteinPoly &Hu = composed[1], &Hv = composed[2];
  const BernsteinPoly Huu = lc.compose(H[3], 2), Huv = lc.compose(H[4], 2), Hvv = lc.compose(H[5], 2);
  return {composed[0], product(a, Hu) + product(b, Hv),
          product(product(a, a), Huu) + 2.0 * product(product(a, b), Huv) + product(product(b, b), Hvv)};
}

/// Largest normal curvature of either side at x of a piece built from chart rows (spectral norm of the shape
/// operator), or nullopt where a chart is ill-conditioned (its two directions within kChartRegularSin of parallel:
/// next to a pole the curvature of a chart is round-off divided by a vanishing normal), or where its round-off may
/// exceed kChartCurvatureNoiseShare of the curvature (or of `flat`, the curvature of a plane): the second
/// derivative along the leaf carries about kUnitRoundoff deg^2 |S| of round-off (the chart's coefficients, of the
/// model's size, differenced twice; the cross derivatives are composed from the surface's own, without that
/// cancellation), divided by the squared first derivative along the leaf. On a sliver leaf that is tiny (linkrods edge
/// 53: a surface knot 1e-9 before the pcurve's end; |S_v| = 1.2e-10, curvature 6e7 from round-off where
/// OpenCASCADE's is 8), and the sample would make the curvature reference of the relative jump.
std::optional<double> chartCurvature(const CartesianSide& A, const CartesianSide& B, const Piece& pc, double x,
                                     double flat) {
  double out = 0.0;
  for (const CartesianSide* c : {&A, &B}) {
    VecX su, sv, suu, suv, svv;
    evalRational(c->Su, pc, x, &su);
    evalRational(c->Sv, pc, x, &sv);
    evalRational(c->Suu, pc, x, &suu);
    evalRational(c->Suv, pc, x, &suv);
    evalRational(c->Svv, pc, x, &svv);
    const Vec3 a = su, t = sv;
    const Vec3 n = t.cross(a);
    if (!(n.norm() > kChartRegularSin * t.norm() * a.norm())) return std::nullopt;
    const Vec3 nh = n.normalized(), e1 = t.normalized(), e2 = nh.cross(e1);
    const double curvature = spectralNorm(shapeInFrame(a, t, suu, suv, svv, nh, e1, e2));
    const double den = std::pow(pc.wa.scalar(x), c->S.ea) * std::pow(pc.wb.scalar(x), c->S.eb);
    const double deg = std::max(1, c->S.num.degree());
    const double noise =
        kUnitRoundoff * deg * deg * c->S.num.maxCoeffNorm() / den / t.squaredNorm();
    if (!(noise <= kChartCurvatureNoiseShare * std::max(curvature, flat))) return std::nullopt;
    out = std::max(out, curvature);
  }
  return out;
}


/// The G2 data of a leaf: its piece (G2 only) and the chart curvature and jump at its start samples.
struct G2Leaf {
  bool tooHigh = false;
  Piece pc;
  std::array<std::optional<double>, kPCurveSamplesPerPiece + 1> curvature;  // chartCurvature at the samples
  std::array<double, kPCurveSamplesPerPiece + 1> jump{};                      // g2Value there (g2Available)
};

/// One pcurve seam's certification, step by step: the edge cut into leaves on which each pcurve lies in one span of
/// its surface, the composed G0 / G1 data and bounds, then G2 through the charts of both faces.
struct PCurveSeam {
  PCurveSeam(const PCurveSide& sideA, const PCurveSide& sideB, const SeamOptions& options, const SpanPatches& spansA,
             const SpanPatches& spansB)
      : a(sideA), b(sideB), opt(options), spA(spansA), spB(spansB), pcA(a.pcurve.bezierPieces()),
        pcB(b.pcurve.bezierPieces()), ra(a.surface->isRational() || a.pcurve.isRational()),
        rb(b.surface->isRational() || b.pcurve.isRational()),
        batch(static_cast<size_t>(std::max(1, tbb::this_task_arena::max_concurrency()))) {}

  Status splitIntoLeaves();
  Status composeG1Pieces();
  Status certifyG0G1();
  void certifyG2();
  PCurveSeamBounds out;

  const PCurveSide& a;
  const PCurveSide& b;
  const SeamOptions& opt;
  const SpanPatches& spA;
  const SpanPatches& spB;
  const std::vector<BezierCurvePiece> pcA, pcB;
  // A side is rational when its surface or its pcurve is (x / w after composition).
  const bool ra, rb;
  // Leaves composed at a time: as many as the arena has threads (one: the loop of one leaf after the other).
  const size_t batch;
  std::vector<PCurveLeaf> leaves;
  std::vector<Piece> pieces;                                             // the G0 / G1 data per leaf
  std::vector<std::array<std::array<BernsteinPoly, 3>, 2>> composed;  // A's and B's ComposedSide::h per leaf
  std::vector<ClosestLeaf> closest;  // per leaf, with SeamOptions::closestPointsOn
  double edgeScale = 0.0;
  std::vector<Piece> g2Pieces;
  double curvMax = 0.0;
  std::vector<std::array<double, 2>> regular;  // (jump, curvature) at the well-conditioned start samples

  double toB(double t) const { return b.range.lo + (t - a.range.lo) / a.range.length() * b.range.length(); }
  /// The degree up to which the Lemma 2 polynomials are certified: maxCertifiedDegree, at most kPCurveG2MaxDegree.
  int g2MaxDegree() const { return std::min(opt.maxCertifiedDegree, kPCurveG2MaxDegree); }
  /// The curvature of a plane at this seam's scale (kFlatCurvatureRatio / the larger surface's control diagonal).
  double flatCurvature() const { return kFlatCurvatureRatio / std::max(edgeScale, std::numeric_limits<double>::min()); }
  std::vector<double> edgeCuts() const;
  bool place(const PCurvePiece& c, const SpanPatches& sp, const PCurveSide& side, size_t& iu, size_t& iv,
             bool& ok, double& cutAt) const;
  bool split(double t0, double t1, int depth);
  void composeLeaf(size_t li);
  double closestExcess(double target);
  G2Leaf buildG2Leaf(size_t li) const;
  bool buildG2Pieces();
  void boundG2(double flat);
};

// Cuts: the range ends and both pcurves' breakpoints (B's mapped into A's parameter).
std::vector<double> PCurveSeam::edgeCuts() const {
  std::vector<double> cuts{a.range.lo, a.range.hi};
  for (const auto& p : pcA)
    for (double x : {p.interval.lo, p.interval.hi})
      if (x > a.range.lo && x < a.range.hi) cuts.push_back(x);
  for (const auto& p : pcB)
    for (double x : {p.interval.lo, p.interval.hi}) {
      const double t = a.range.lo + (x - b.range.lo) / b.range.length() * a.range.length();
      if (t > a.range.lo && t < a.range.hi) cuts.push_back(t);
    }
  std::sort(cuts.begin(), cuts.end());
  // Breakpoints closer than kSameBreakpointRel of the edge are one breakpoint written with different digits in the
  // two faces' pcurves (6e-13 apart in a real file): a leaf between them would hold nothing but round-off.
  const double minGap = detail::kSameBreakpointRel * a.range.length();
  std::vector<double> kept{cuts.front()};
  for (size_t i = 1; i + 1 < cuts.size(); ++i)
    if (cuts[i] - kept.back() > minGap && a.range.hi - cuts[i] > minGap) kept.push_back(cuts[i]);
  kept.push_back(a.range.hi);
  return kept;
}

// The spans (iu, iv) of a side's surface holding its pcurve c on a leaf; false when none. A coordinate whose hull
// contains a knot leaves `ok` false and, the first time, `cutAt` at its exact crossing where it is monotone.
bool PCurveSeam::place(const PCurvePiece& c, const SpanPatches& sp, const PCurveSide& side, size_t& iu, size_t& iv,
                       bool& ok, double& cutAt) const {
  for (int k = 0; k < 2; ++k) {
    const std::vector<Interval>& spans = k == 0 ? sp.us : sp.vs;
    const auto [lo, hi] = c.hull(k);  // the curve lies in the hull of its (projected) control points
    if (const auto knot = knotInside(spans, lo, hi)) {
      ok = false;
      // The crossing of u / w with the knot line is the root of u - knot w.
      if (cutAt < 0.0)
        if (const auto x = monotoneCrossing(c.num(k) - *knot * c.w, 0.0)) cutAt = *x;
      continue;
    }
    const auto idx = spanOf(spans, lo, hi, k == 0 ? side.faceU : side.faceV, side.domainSlackRel);
    if (!idx) return false;
    (k == 0 ? iu : iv) = *idx;
  }
  return true;
}

// Splits [t0, t1] until each side's pcurve lies in one span of its surface; at an exact crossing where the
// coordinate is monotone, else in the middle.
bool PCurveSeam::split(double t0, double t1, int depth) {
  PCurveLeaf L;
  L.t0 = t0;
  L.t1 = t1;
  L.ca = pcurveOn(pcA, t0, t1);
  L.cb = pcurveOn(pcB, toB(t0), toB(t1));
  double cutAt = -1.0;
  bool ok = true;
  if (!place(L.ca, spA, a, L.aiu, L.aiv, ok, cutAt) || !place(L.cb, spB, b, L.biu, L.biv, ok, cutAt)) return false;
  if (ok) {
    leaves.push_back(std::move(L));
    return true;
  }
  if (depth >= kPCurveSplitDepth) return false;
  const double x = cutAt > 0.0 && cutAt < 1.0 ? cutAt : 0.5;
  const double tm = t0 + x * (t1 - t0);
  if (!(tm > t0 && tm < t1)) return false;
  return split(t0, tm, depth + 1) && split(tm, t1, depth + 1);
}

Status PCurveSeam::splitIntoLeaves() {
  const std::vector<double> cuts = edgeCuts();
  for (size_t i = 0; i + 1 < cuts.size(); ++i)
    if (!split(cuts[i], cuts[i + 1], 0))
      return Status(ErrorCode::kUnsupported,
                    "pcurve seam: a pcurve leaves its surface's domain or its knot-line crossings cannot be isolated");
  return Status::ok();
}

// Exact data of a leaf, in the same form as the patch seams (g0 and G1 only): a pure function of the leaf's data.
void PCurveSeam::composeLeaf(size_t li) {
  const PCurveLeaf& L = leaves[li];
  ComposedSide A = composeSide(spA, L.aiu, L.aiv, L.ca, a.surface->isRational(), a.normalSign);
  ComposedSide B = composeSide(spB, L.biu, L.biv, L.cb, b.surface->isRational(), b.normalSign);
  Piece& pc = pieces[li];
  pc.tOf = BernsteinPoly::linear(L.t0, L.t1);
  pc.sOf = BernsteinPoly::linear(toB(L.t0), toB(L.t1));
  pc.wa = A.w;
  pc.wb = B.w;
  WeightContext ctx(pc.wa, pc.wb);
  const int ea = ra ? 1 : 0, eb = rb ? 1 : 0;
  pc.g0 = ctx.add(RationalPoly{A.x, ea, 0}, RationalPoly{B.x, 0, eb}, -1.0);
  const BernsteinPoly NA = detail::stripEndRoots(A.normal, kRoundoff * A.normal.maxCoeffNorm());
  const BernsteinPoly NB = detail::stripEndRoots(B.normal, kRoundoff * B.normal.maxCoeffNorm());
  pc.P = dot(NA, NB);
  pc.cross = seam::cross(NA, NB);
  pc.Q = dot(pc.cross, pc.cross);
  pc.R = product(dot(NA, NA), dot(NB, NB));
  pc.crossScale = NA.maxCoeffNorm() * NB.maxCoeffNorm();
  if (opt.closestPointsOn != ClosestPoints::kNone) {
    const bool onB = opt.closestPointsOn == ClosestPoints::kOnB;
    const ComposedSide &from = onB ? A : B, &to = onB ? B : A;
    ClosestLeaf& c = closest[li];
    c = {from.x, from.w, to.x, to.w, onB ? NB : NA, {}};
    c.whole = {li, 0.0, 1.0, L.t0, L.t1, closestData(c, 0.0, 1.0, false)};
  }
  composed[li] = {std::move(A.h), std::move(B.h)};
}

// The leaves are composed on the calling thread's arena (each leaf a pure function of its own data: the same
// values on any number of threads, so that one heavy seam does not hold a core alone), then taken in leaf order:
// each batch checked in leaf order before the next is composed, so a degree above the limit ends the route after
// at most a batch of leaves, as the serial loop ended it after one.
Status PCurveSeam::composeG1Pieces() {
  pieces.resize(leaves.size());
  composed.resize(leaves.size());
  if (opt.closestPointsOn != ClosestPoints::kNone) closest.resize(leaves.size());
  for (size_t first = 0; first < leaves.size(); first += batch) {
    const size_t last = std::min(leaves.size(), first + batch);
    if (last - first > 1) tbb::parallel_for(first, last, [this](size_t li) { composeLeaf(li); });
    else composeLeaf(first);
    for (size_t li = first; li < last; ++li) {
      const Piece& pc = pieces[li];
      out.maxDegree = std::max(out.maxDegree, pc.R.degree());
      if (pc.R.degree() > opt.maxCertifiedDegree)
        return Status(ErrorCode::kUnsupported,
                      fmt::format("pcurve seam: composed degree {} above maxCertifiedDegree {}", pc.R.degree(),
                                  opt.maxCertifiedDegree));
    }
  }
  out.pieces = static_cast<int>(pieces.size());
  return Status::ok();
}

// Start samples, then the certified maxima (the subdivision raises the best values it meets); the G1 identity.
Status PCurveSeam::certifyG0G1() {
  edgeScale = std::max(detail::controlDiagonal(*a.surface), detail::controlDiagonal(*b.surface));
  auto [g0Best, g0x, g0p] = bestSample(pieces, detail::g0Value);
  auto [g1Best, g1x, g1p] = bestSample(pieces, detail::g1Value);
  bool ok0 = true, ok1 = true;
  // The tolerances as thresholds: a maximum within the bounds' relative gap of one is decided (certifyMax).
  out.g0Bound = certifyMax(pieces, detail::g0Bound, detail::g0Value, g0Best, g0x, g0p, kRoundoff * edgeScale, opt,
                           ok0, nullptr, nullptr, opt.tol.distance);
  if (!ok0) return Status(ErrorCode::kUnsupported, "pcurve seam: the distance bound could not be closed");
  std::pair<int, double> unclosed{-1, 0.0};
  const double g1b = certifyMax(pieces, detail::g1Bound, detail::g1Value, g1Best, g1x, g1p, kAngleBoundFloor, opt,
                                ok1, nullptr, &unclosed, opt.tol.angleDeg / kRadToDeg);
  out.g0Sampled = g0Best;
  out.g0At = pieces[static_cast<size_t>(g0p)].tOf.scalar(g0x);
  out.g1SampledDeg = g1Best * kRadToDeg;
  out.g1At = pieces[static_cast<size_t>(g1p)].tOf.scalar(g1x);
  // Where the angle bound cannot close (a normal vanishing inside the edge, no end root to divide out), the angle
  // measured where both normals are defined stands in (as analyzeSeam's certifyG1) and g1PoleT says where.
  out.g1BoundDeg = ok1 ? g1b * kRadToDeg : out.g1SampledDeg;
  out.g1Identity = detail::g1IdentityOf(pieces, ok1, out.g1BoundDeg);
  // The excess is made closer where it exceeds the bound's own certification gap (boundRelGap).
  if (opt.closestPointsOn != ClosestPoints::kNone)
    out.g1ClosestExcessDeg =
        closestExcess(std::max(kAngleBoundFloor, opt.boundRelGap * out.g1BoundDeg / kRadToDeg)) * kRadToDeg;
  if (!ok1 && !out.g1Identity)
    out.g1PoleT = unclosed.first >= 0 ? pieces[static_cast<size_t>(unclosed.first)].tOf.scalar(unclosed.second)
                                      : out.g1At;
  return Status::ok();
}

/// The excess (radians) of each of `cells` (in edge order): see PCurveSeam::closestExcess; infinite where a cell's
/// excess cannot be bounded.
std::vector<double> excessOfCells(const std::vector<ClosestCell>& cells) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  std::vector<double> out(cells.size(), kInf);
  const auto len = [&](size_t j) { return cells[j].t1 - cells[j].t0; };
  for (size_t i = 0; i < cells.size(); ++i) {
    const double f = cells[i].d.f / len(i);  // per unit of t
    size_t lo = i, hi = i;
    for (;;) {
      double m = kInf, M = 0.0, S = 0.0, K = 0.0;
      for (size_t j = lo; j <= hi; ++j) {
        const ClosestData& c = cells[j].d;
        const double h = len(j);
        m = std::min(m, c.speedLo / h);
        M = std::max(M, c.accelHi / (h * h));
        S = std::max(S, c.speedHi / h);
        K = std::max(K, c.turnHi / h);
      }
      const double d0 = 2.0 * f / (m * m);
      if (!(m > 0.0) || !std::isfinite(M) || !std::isfinite(S) || !std::isfinite(d0)) break;
      // The cells that [t0 - d0, t1 + d0] reaches: any new one may lower m or raise M, S, K.
      size_t nlo = lo, nhi = hi;
      while (nlo > 0 && cells[nlo].t0 > cells[i].t0 - d0) --nlo;
      while (nhi + 1 < cells.size() && cells[nhi].t1 < cells[i].t1 + d0) ++nhi;
      if (nlo == lo && nhi == hi) {
        const double c = m * m - (cells[i].d.gapHi + d0 * S) * M;
        const double e = f / c * K;
        if (c >= 0.5 * m * m && e >= 0.0) out[i] = e;  // else (or NaN: 0 / 0, inf * 0) not bounded
        break;
      }
      lo = nlo;
      hi = nhi;
    }
  }
  return out;
}

// How much the angle between A's normal and B's at B's (local) closest point can exceed the angle at the paired
// points, in radians (SeamOptions::closestPointsOn; kOnA: A and B exchanged in what follows; infinite where it cannot
// be bounded): first over each leaf as a whole, then with the cells above `target` halved (kClosestRefineRounds).
// In A's edge parameter t, at a point t of a cell, g(s) = (A(t) - B(s)) . B'(s) vanishes at B's closest point and
// g(t) = (A - B) . B' = f. With |B'| >= m, |B''| <= M and |A(t) - B(s)| <= G over the cells within d0 of the cell,
// g'(s) = -|B'|^2 + (A(t) - B(s)) . B'' <= -(m^2 - G M) =: -c < 0 there: |A(t) - B(s)|^2 is strictly convex in s
// and its least value on B's range lies within |f| / c of t (clamped at an end of the range likewise). Taking
// d0 = 2 |f| / m^2 and G = |A - B|(cell) + d0 max|B'|, c >= m^2 / 2 makes |f| / c <= d0 consistent. B's unit normal
// turns by at most K |s - t| (K = max |d(N_B / |N_B|) / dt| there). Local: a closest point elsewhere would need B's
// edge to come back within the gap of itself.
double PCurveSeam::closestExcess(double target) {
  std::vector<ClosestCell> cells;
  for (const ClosestLeaf& c : closest) cells.push_back(c.whole);
  double previous = std::numeric_limits<double>::infinity();
  for (int round = 0;; ++round) {
    const std::vector<double> e = excessOfCells(cells);
    const double worst = e.empty() ? 0.0 : *std::max_element(e.begin(), e.end());
    // (An excess that cannot be bounded over a whole leaf may be over its halves: the first round always halves.)
    if (worst <= target || round >= kClosestRefineRounds || (round > 0 && !(worst < kClosestRefineGain * previous)))
      return worst;
    previous = worst;
    std::vector<size_t> split;
    for (size_t i = 0; i < cells.size(); ++i)
      if (!(e[i] <= target)) split.push_back(i);
    std::vector<std::array<ClosestCell, 2>> halves(split.size());
    tbb::parallel_for(size_t{0}, split.size(), [&](size_t k) {
      const ClosestCell& c = cells[split[k]];
      const double xm = 0.5 * (c.x0 + c.x1), tm = 0.5 * (c.t0 + c.t1);
      const ClosestLeaf& L = closest[c.leaf];
      halves[k] = {ClosestCell{c.leaf, c.x0, xm, c.t0, tm, closestData(L, c.x0, xm, true)},
                   ClosestCell{c.leaf, xm, c.x1, tm, c.t1, closestData(L, xm, c.x1, true)}};
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

// A leaf's G2 data (a pure function of the leaf, as composeLeaf).
G2Leaf PCurveSeam::buildG2Leaf(size_t li) const {
  const PCurveLeaf& L = leaves[li];
  G2Leaf g;
  const std::array<BernsteinPoly, 3> XA = chartRows(spA, L.aiu, L.aiv, L.ca, a.surface->isRational(),
                                                    composed[li][0]),
                                     XB = chartRows(spB, L.biu, L.biv, L.cb, b.surface->isRational(),
                                                    composed[li][1]);
  const CartesianSide CA = detail::cartesian(XA[0], XA[1], XA[2], ra, 0),
                      CB = detail::cartesian(XB[0], XB[1], XB[2], rb, 1);
  // Checked before building anything: a piece above the limit would cost products of polynomials of degree
  // several hundred for nothing.
  if (detail::lemma2Degree(CA, CB, ra ? XA[0].degree() : 0, rb ? XB[0].degree() : 0) > g2MaxDegree()) {
    g.tooHigh = true;
    return g;
  }
  // The G2 data only (the G1 bound came from the composed normals above), from the Cartesian sides just formed.
  g.pc = detail::buildPiece(CA, CB, ra ? XA[0].component(XA[0].dim() - 1) : BernsteinPoly::constant(1.0),
                            rb ? XB[0].component(XB[0].dim() - 1) : BernsteinPoly::constant(1.0),
                            BernsteinPoly::linear(L.t0, L.t1), BernsteinPoly::linear(toB(L.t0), toB(L.t1)),
                            g2MaxDegree(), PieceData::kG2Only);
  for (int k = 0; k <= kPCurveSamplesPerPiece; ++k) {
    const double x = static_cast<double>(k) / kPCurveSamplesPerPiece;
    g.curvature[static_cast<size_t>(k)] = chartCurvature(CA, CB, g.pc, x, flatCurvature());
    if (g.curvature[static_cast<size_t>(k)] && g.pc.g2Available)
      g.jump[static_cast<size_t>(k)] = detail::g2Value(g.pc, x);
  }
  return g;
}

// The G2 pieces of all leaves, per leaf on the arena as the G1 data (pure functions of the leaf), then taken in
// leaf order: the first leaf above the degree limit ends the G2 route as the loop did, the samples are replayed in
// their order. False when some piece's G2 polynomials exceed the degree limit.
bool PCurveSeam::buildG2Pieces() {
  bool built = true;
  std::vector<G2Leaf> g2Leaves(leaves.size());
  bool tooHigh = false;
  for (size_t first = 0; first < leaves.size() && !tooHigh; first += batch) {  // in batches, as the G1 data
    const size_t last = std::min(leaves.size(), first + batch);
    if (last - first > 1) tbb::parallel_for(first, last, [&](size_t li) { g2Leaves[li] = buildG2Leaf(li); });
    else g2Leaves[first] = buildG2Leaf(first);
    for (size_t li = first; li < last; ++li) {
      G2Leaf& g = g2Leaves[li];
      if (g.tooHigh) {
        built = false;
        tooHigh = true;
        break;
      }
      for (size_t k = 0; k < g.curvature.size(); ++k)
        if (const auto& c = g.curvature[k]) {
          curvMax = std::max(curvMax, *c);
          if (g.pc.g2Available) regular.push_back({g.jump[k], *c});
        }
      if (!g.pc.g2Available) built = false;
      else out.maxDegreeG2 = std::max(out.maxDegreeG2, g.pc.rho.num.degree());
      g2Pieces.push_back(std::move(g.pc));
    }
  }
  return built;
}

// The G2 identity and the certified bound of the jump over the G2 pieces (`flat`: the curvature of a plane).
void PCurveSeam::boundG2(double flat) {
  const double curvRef = std::max(curvMax, flat);
  auto [g2Best, g2x, g2p] = bestSample(g2Pieces, detail::g2Value);
  bool rhoIdentity = true;
  for (const Piece& pc : g2Pieces)
    if (pc.rho.num.maxAbsCoeff() > kIdentityRelTol * pc.rhoScale) rhoIdentity = false;
  // The coefficient test compares with the largest term anywhere on the piece; where the terms' sizes vary by
  // many orders (a pole at one end) it can pass on a real jump. A well-conditioned sample whose relative jump
  // exceeds the classification tolerance refutes the identity.
  for (const auto& [jump, curv] : regular)
    if (jump > opt.tol.curvatureRel * std::max(curv, flat)) rhoIdentity = false;
  out.g2Identity = rhoIdentity;  // the Lemma 2 residual vanishes identically: G2 wherever the normal is defined
  bool ok2 = true;
  const double floor = kIdentityRelTol * curvRef;
  bool illConditioned = false;  // as in analyzeSeam: a midpoint next to a pole stops the subdivision
  const auto g2Checked = [&illConditioned](const Piece& pc, double x) {
    const auto v = detail::g2ValueIfDefined(pc, x);
    if (!v) illConditioned = true;
    return v.value_or(0.0);
  };
  const double g2b =
      certifyMax(g2Pieces, detail::g2Bound, g2Checked, g2Best, g2x, g2p, floor, opt, ok2, &illConditioned);
  // Near a vanishing normal the quotient bound cannot close: it ends above the sampled maximum by more than the
  // subdivision's target gap (or infinite). Such a bound says nothing useful and is not reported.
  if (!ok2 || !(g2b <= (1.0 + opt.boundRelGap) * g2Best + floor)) {
    out.g2Why = "the G2 bound could not be closed (vanishing normal)";
    return;
  }
  out.g2Certified = true;
  out.g2Bound = std::max(g2b, g2Best);
  out.g2Sampled = g2Best;
  out.g2At = g2Pieces[static_cast<size_t>(g2p)].tOf.scalar(g2x);
  out.g2Identity = rhoIdentity || out.g2Bound <= kIdentityBoundFactor * floor;
}

// G2 through the charts S(c(t) + s d(t)) of both faces: the same Lemma 2 polynomials as for patch seams.
void PCurveSeam::certifyG2() {
  if (!out.g1Identity) {
    out.g2Why = "not exactly G1";
    return;
  }
  const bool built = buildG2Pieces();
  out.curvatureMax = curvMax;
  if (!built) {
    out.g2Why = fmt::format("the G2 polynomials exceed degree {}", g2MaxDegree());
    return;
  }
  boundG2(flatCurvature());
}

}  // namespace

struct SurfaceSpans {
  const BSplineSurface* surface = nullptr;
  SpanPatches patches;
};

std::shared_ptr<const SurfaceSpans> surfaceSpans(const BSplineSurface& surface) {
  auto out = std::make_shared<SurfaceSpans>();
  out->surface = &surface;
  out->patches = spanPatches(surface);
  return out;
}

Result<PCurveSeamBounds> certifyPCurveSeam(const PCurveSide& a, const PCurveSide& b, const SeamOptions& opt) {
  return certifyPCurveSeam(a, b, opt, nullptr, nullptr);
}

Result<PCurveSeamBounds> certifyPCurveSeam(const PCurveSide& a, const PCurveSide& b, const SeamOptions& opt,
                                           const SurfaceSpans* spansA, const SurfaceSpans* spansB) {
  for (const PCurveSide* s : {&a, &b}) {
    if (!s->surface || s->surface->dim() != 3) return invalidInput("pcurve seam: a side has no 3-D surface");
    if (s->pcurve.dim() != 2) return invalidInput("pcurve seam: the parameter curve is not 2-D");
    if (!(s->range.length() > 0.0)) return invalidInput("pcurve seam: empty parameter range");
    if (!(s->domainSlackRel >= 0.0 && std::isfinite(s->domainSlackRel)))
      return invalidInput("pcurve seam: the domain slack is negative or not finite");
  }
  // Each side's spans: the shared ones when given for its surface, else built here.
  std::optional<SpanPatches> ownA, ownB;
  if (!spansA || spansA->surface != a.surface) ownA.emplace(spanPatches(*a.surface));
  if (!spansB || spansB->surface != b.surface) ownB.emplace(spanPatches(*b.surface));
  PCurveSeam route(a, b, opt, ownA ? *ownA : spansA->patches, ownB ? *ownB : spansB->patches);
  if (Status s = route.splitIntoLeaves(); !s.isOk()) return s;
  if (Status s = route.composeG1Pieces(); !s.isOk()) return s;
  if (Status s = route.certifyG0G1(); !s.isOk()) return s;
  route.certifyG2();
  return route.out;
}

}  // namespace seam
