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
#include <numbers>
#include <memory>
#include <optional>
#include <vector>

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "continuity/closest_excess.h"
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
/// The closest-point excess bounds the curvature of a leaf shorter than kClosestWindowRel of its side's range from
/// derivatives that keep their size (detail::ClosestWindow): for a polynomial pcurve, from its derivatives at the
/// leaf's middle (PCurveSeam::closestTaylor); for a rational one, from a window around the leaf: the side's pcurve
/// piece holding the leaf, narrowed by
/// kClosestWindowShrink at a time (at most kClosestWindowTries times) until its pcurve stays within one span's width
/// of the leaf's span (the span's polynomial continued that far grows its coefficients by a small factor only), and
/// taken only while it is at least kClosestWindowGain times as long as the leaf. At 1e-3 of the range the leaf's own
/// bound carries round-off of about 1e-10 of the model's size per length squared, below any curvature that matters;
/// the slivers that need the window are 1e-9 to 2e-6 of their edge (linkrods.step, trj3, boxed_sphere).
constexpr double kClosestWindowRel = 1e-3;
constexpr double kClosestWindowShrink = 0.25;
constexpr int kClosestWindowTries = 12;
constexpr double kClosestWindowGain = 16.0;

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

/// The Cartesian part (first three coordinates) of a homogeneous polynomial.
BernsteinPoly xyz(const BernsteinPoly& p) { return BernsteinPoly(Matrix(p.coeffs().leftCols(3))); }

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
  out.x = xyz(X);
  out.w = X.component(3);
  // S = x / w: S_u = (w x_u - w_u x) / w^2; the normal direction is that of the product of the numerators (the
  // homogenising powers of a rational pcurve's weight are positive factors too).
  const BernsteinPoly Nu = product(out.w, xyz(Xu)) - product(Xu.component(3), out.x);
  const BernsteinPoly Nv = product(out.w, xyz(Xv)) - product(Xv.component(3), out.x);
  out.normal = cross(Nu, Nv) * sign;
  return out;
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
  // Per leaf, with SeamOptions::closestPointsOn: [0] A's points and their closest points on B, [1] B's on A.
  std::array<std::vector<detail::ClosestLeaf>, 2> closest;
  /// Whether the angle bound covers the closest points on B (onB) or on A of the other side's points.
  bool closesOn(bool onB) const {
    return opt.closestPointsOn == ClosestPoints::kBoth ||
           opt.closestPointsOn == (onB ? ClosestPoints::kOnB : ClosestPoints::kOnA);
  }
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
  std::optional<detail::ClosestWindow> closestWindow(size_t li, bool onB) const;
  std::optional<detail::ClosestWindow> closestTaylor(size_t li, bool onB, const ComposedSide& side) const;
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
    if (!idx) {
      // The control hull of a rational pcurve (a conic) reaches past the domain where the curve need not: where
      // both of the piece's end points lie in the domain, the piece is halved (the hulls close in on the curve);
      // where an end point is outside, the pcurve leaves the domain.
      const double d = spans.back().hi - spans.front().lo, slack = side.domainSlackRel * d;
      bool endsInside = c.rational;
      for (const double x : {0.0, 1.0}) {
        const double y = c.num(k).scalar(x) / c.w.scalar(x);
        endsInside = endsInside && y >= spans.front().lo - slack && y <= spans.back().hi + slack;
      }
      if (!endsInside) return false;
      ok = false;
      continue;
    }
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
  for (const bool onB : {true, false}) {
    if (!closesOn(onB)) continue;
    const ComposedSide &from = onB ? A : B, &to = onB ? B : A;
    const bool taylor = !(onB ? b : a).pcurve.isRational();
    closest[onB ? 0 : 1][li] =
        detail::closestLeaf(from.x, from.w, to.x, to.w, onB ? NA : NB, onB ? NB : NA, li, L.t0, L.t1,
                            taylor ? closestTaylor(li, onB, to) : closestWindow(li, onB));
  }
  composed[li] = {std::move(A.h), std::move(B.h)};
}

// The window of leaf li's closest-point side (B with onB, else A) for its curvature bound (kClosestWindowRel). The
// leaf's B is the span's polynomial composed with the pcurve piece's: the same composition over a longer window of
// the piece (both polynomials continued where the window crosses the span's knot line: a sliver is mostly a leaf cut
// at a knot-line crossing next to the piece's end) is the same polynomial, restricted to the leaf.
std::optional<detail::ClosestWindow> PCurveSeam::closestWindow(size_t li, bool onB) const {
  const PCurveLeaf& L = leaves[li];
  const PCurveSide& side = onB ? b : a;
  const std::vector<BezierCurvePiece>& pcs = onB ? pcB : pcA;
  const SpanPatches& sp = onB ? spB : spA;
  const double s0 = onB ? toB(L.t0) : L.t0, s1 = onB ? toB(L.t1) : L.t1;
  if (!(s1 - s0 < kClosestWindowRel * side.range.length()) || pcs.empty()) return std::nullopt;
  const size_t iu = onB ? L.biu : L.aiu, iv = onB ? L.biv : L.aiv;
  const std::array<Interval, 2> span{sp.us[iu], sp.vs[iv]};
  // The piece pcurveOn takes for the leaf (by its middle); the window never leaves it, except by the leaf itself
  // where a breakpoint within kSameBreakpointRel of the leaf's end was merged with it.
  size_t k = 0;
  while (k + 1 < pcs.size() && 0.5 * (s0 + s1) > pcs[k].interval.hi) ++k;
  const Interval P = pcs[k].interval;
  double reach = P.length();
  for (int i = 0; i < kClosestWindowTries; ++i, reach *= kClosestWindowShrink) {
    const double w0 = std::min(s0, std::max(P.lo, s0 - reach)), w1 = std::max(s1, std::min(P.hi, s1 + reach));
    if (!(w1 - w0 >= kClosestWindowGain * (s1 - s0))) return std::nullopt;
    const PCurvePiece c = pcurveOn(pcs, w0, w1);
    bool near = true;
    for (int j = 0; j < 2; ++j) {
      const auto [lo, hi] = c.hull(j);
      near = near && lo >= span[j].lo - span[j].length() && hi <= span[j].hi + span[j].length();
    }
    if (!near) continue;
    const ComposedSide W = composeSide(sp, iu, iv, c, side.surface->isRational(), side.normalSign);
    return detail::closestWindow(W.x, W.w, (s0 - w0) / (w1 - w0), (s1 - w0) / (w1 - w0));
  }
  return std::nullopt;
}

/// sum_j d_j (h (x - 1/2))^j / j! as a polynomial of x in [0, 1]: a Taylor series about the middle of a leaf of
/// length h.
BernsteinPoly taylorOnLeaf(const std::vector<double>& d, double h) {
  VecX a = VecX::Zero(static_cast<Eigen::Index>(std::max<size_t>(d.size(), 1)));
  double scale = 1.0;  // h^j / j!
  for (size_t j = 0; j < d.size(); ++j) {
    if (j > 0) scale *= h / static_cast<double>(j);
    double binom = 1.0;  // C(j, i)
    for (size_t i = 0; i <= j; ++i) {
      a[static_cast<Eigen::Index>(i)] += d[j] * scale * binom * std::pow(-0.5, static_cast<double>(j - i));
      binom = binom * static_cast<double>(j - i) / static_cast<double>(i + 1);
    }
  }
  return BernsteinPoly::fromPowerBasis(a);
}

// Leaf li's closest-point side (B with onB, else A), `side` its composition on the leaf, from its polynomial
// pcurve's derivatives (kClosestWindowRel). A short leaf often lies in a piece of the pcurve that is as short (B-spline
// pcurves with knots 1e-10 apart: occ22470.igs, linkrods.step), whose own Bezier points agree to all but a few
// digits: differenced twice, they are round-off. The B-spline's derivatives at the leaf's middle (from its de Boor
// points, differenced over knot intervals that are not all short) give c', c'' on the leaf exactly as Taylor
// polynomials (the leaf lies in one piece); the surface's partials come from its differenced net (spanPatches):
// X_t = H_u u' + H_v v', X_tt = H_uu u'^2 + 2 H_uv u' v' + H_vv v'^2 + H_u u'' + H_v v'' (span-local u, v), and
// with X = (x, w): T = x_t w - x w_t, T' = x_tt w - x w_tt.
std::optional<detail::ClosestWindow> PCurveSeam::closestTaylor(size_t li, bool onB, const ComposedSide& side) const {
  const PCurveLeaf& L = leaves[li];
  const PCurveSide& ps = onB ? b : a;
  const double s0 = onB ? toB(L.t0) : L.t0, s1 = onB ? toB(L.t1) : L.t1, h = s1 - s0;
  if (!(h < kClosestWindowRel * ps.range.length()) || ps.pcurve.dim() != 2) return std::nullopt;
  const SpanPatches& sp = onB ? spB : spA;
  const size_t iu = onB ? L.biu : L.aiu, iv = onB ? L.biv : L.aiv;
  const Interval U = sp.us[iu], V = sp.vs[iv];
  const int p = ps.pcurve.degree();
  if (p < 1) return std::nullopt;
  const Matrix D = ps.pcurve.derivatives(0.5 * (s0 + s1), p);  // rows 0..p
  if (!D.allFinite()) return std::nullopt;
  // u', v' (from row 1) and u'', v'' (from row 2) per unit of the span's local parameters.
  const auto series = [&](int from, int k, double len) {
    std::vector<double> d;
    for (int r = from; r <= p; ++r) d.push_back(D(r, k) / len);
    return taylorOnLeaf(d, h);
  };
  const BernsteinPoly du = series(1, 0, U.length()), dv = series(1, 1, V.length());
  const BernsteinPoly ddu = p >= 2 ? series(2, 0, U.length()) : BernsteinPoly::constant(0.0);
  const BernsteinPoly ddv = p >= 2 ? series(2, 1, V.length()) : BernsteinPoly::constant(0.0);
  const LocalPCurve lc(onB ? L.cb : L.ca, U, V, ps.surface->isRational());
  const auto& H = sp.at(iu, iv);
  const BernsteinPoly &X = side.h[0], &Hu = side.h[1], &Hv = side.h[2];
  const BernsteinPoly Huu = lc.compose(H[3], 2), Huv = lc.compose(H[4], 2), Hvv = lc.compose(H[5], 2);
  const BernsteinPoly Xt = product(du, Hu) + product(dv, Hv);
  const BernsteinPoly Xtt = product(product(du, du), Huu) + 2.0 * product(product(du, dv), Huv) +
                            product(product(dv, dv), Hvv) + product(ddu, Hu) + product(ddv, Hv);
  if (X.dim() == 3) return detail::ClosestWindow{Xt, Xtt, Xtt, BernsteinPoly::constant(1.0), 0.0, 1.0};
  const BernsteinPoly x = xyz(X), w = X.component(3), xt = xyz(Xt), wt = Xt.component(3);
  const BernsteinPoly T = product(xt, w) - product(x, wt);
  const BernsteinPoly T1 = product(xyz(Xtt), w) - product(x, Xtt.component(3));
  return detail::ClosestWindow{T, T1, product(T1, w) - 2.0 * product(T, wt), w, 0.0, 1.0};
}

// The leaves are composed on the calling thread's arena (each leaf a pure function of its own data: the same
// values on any number of threads, so that one heavy seam does not hold a core alone), then taken in leaf order:
// each batch checked in leaf order before the next is composed, so a degree above the limit ends the route after
// at most a batch of leaves, as the serial loop ended it after one.
Status PCurveSeam::composeG1Pieces() {
  pieces.resize(leaves.size());
  composed.resize(leaves.size());
  for (const bool onB : {true, false})
    if (closesOn(onB)) closest[onB ? 0 : 1].resize(leaves.size());
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
  out.g0Bound += a.surfaceError + b.surfaceError;  // stand-in surfaces (PCurveSide::surfaceError)
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
  // The excess is made closer where it exceeds the bound's own certification gap (boundRelGap). Its split bound
  // rests on the paired angle's bound: a sampled stand-in is not one, and 180 deg leaves the whole-turning excess.
  const double excessGap = std::max(kAngleBoundFloor, opt.boundRelGap * out.g1BoundDeg / kRadToDeg);
  for (const bool onB : {true, false})
    if (closesOn(onB)) {
      double& e = onB ? out.g1ClosestExcessOnBDeg : out.g1ClosestExcessOnADeg;
      e = detail::closestExcess(closest[onB ? 0 : 1], excessGap, ok1 ? out.g1BoundDeg / kRadToDeg : std::numbers::pi) *
          kRadToDeg;
      out.g1ClosestExcessDeg = std::max(out.g1ClosestExcessDeg, e);
    }
  if (!ok1 && !out.g1Identity)
    out.g1PoleT = unclosed.first >= 0 ? pieces[static_cast<size_t>(unclosed.first)].tOf.scalar(unclosed.second)
                                      : out.g1At;
  return Status::ok();
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
    if (!(s->surfaceError >= 0.0 && std::isfinite(s->surfaceError)))
      return invalidInput("pcurve seam: the surface's error bound is negative or not finite");
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
