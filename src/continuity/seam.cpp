// Certified seam analysis. See include/seam/continuity/seam.h for conventions and docs/algorithms/johansson.md for
// the derivations (Lemma 1, Lemma 2, the shape-operator jump of a G1 seam and the Bernstein bounds).
#include "seam/continuity/seam.h"

#include <fmt/format.h>

#include <cassert>

#include <Eigen/Dense>
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <numbers>
#include <optional>
#include <tuple>

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "continuity/curve_projection.h"
#include "continuity/rational_poly.h"
#include "continuity/sampling.h"
#include "continuity/seam_internal.h"
#include "core/bernstein_internal.h"
#include "spline/spline_internal.h"
#include "seam/core/bernstein.h"

namespace seam {

std::string_view toString(GeometricClass c) {
  switch (c) {
    case GeometricClass::kNone: return "none";
    case GeometricClass::kG0: return "G0";
    case GeometricClass::kG1: return "G1";
    case GeometricClass::kG2: return "G2";
  }
  return "?";
}
std::string_view toString(ParametricClass c) {
  switch (c) {
    case ParametricClass::kNone: return "none";
    case ParametricClass::kC0: return "C0";
    case ParametricClass::kC1: return "C1";
    case ParametricClass::kC2: return "C2";
  }
  return "?";
}
std::string_view toString(Correspondence c) {
  switch (c) {
    case Correspondence::kAffine: return "affine";
    case Correspondence::kPolynomial: return "polynomial";
    case Correspondence::kProjection: return "projection";
  }
  return "?";
}

namespace {

using detail::RationalPoly;
using detail::refinedMaximum;
using detail::refineMax;
using detail::shapeInFrame;
using detail::spectralNorm;
using detail::WeightContext;
using detail::chartConditioning;
using detail::kCurvatureChartRel;
using detail::limitNormal;

/// A correspondence whose certified distance bound is below this fraction of the edge size is exact.
constexpr double kExactCorrespondenceRel = 1e-9;
/// Normal curvatures below kFlatCurvatureRatio / (patch size) are treated as flat when forming relative jumps:
/// a radius of curvature a thousand times the patch size is indistinguishable from a plane.
constexpr double kFlatCurvatureRatio = 1e-3;
/// |slope| of an affine correspondence within this of 1 means the edge parametrisations match (parametric C^k).
constexpr double kMatchingSlopeTol = 1e-9;
/// Samples per span used to fit a polynomial correspondence (over-determined least squares, then verified exactly).
constexpr int kFitSamplesFactor = 3;

/// An edge end point is matched to the other edge's end point when that end is within this factor of the distance
/// to the other curve (gaps), rather than to its closest point (T-junctions).
constexpr double kOverlapSnapFactor = 2.0;
/// Absolute slack (radians) of the certified angle bound: far below any angle tolerance, above the round-off of
/// normal directions.
constexpr double kAngleBoundFloor = 1e-9;
/// A closed certified bound within this factor of its round-off floor (kAngleBoundFloor for angles,
/// kIdentityRelTol x curvature for G2) makes the condition an identity, as the coefficient tests do.
constexpr double kIdentityBoundFactor = 2.0;

constexpr double kRadToDeg = 180.0 / std::numbers::pi;
/// Samples per piece for the ranges of Johansson's connecting functions lambda, kappa on certified seams.
constexpr int kLemma1Samples = 16;
/// Golden-section steps per interior extreme: the bracket (1/16) shrinks to 4e-5 of the piece; at a smooth extreme
/// the value error is quadratic in that (~1e-9 relative).
constexpr int kLemma1GoldenIterations = 16;
/// lambda or kappa varying by less than this (relative) over a piece is constant to round-off: not refined.
constexpr double kLemma1ConstantRel = 1e-9;

// ------------------------------------------------------------------------------------------------------------
// One side of the seam, seen from its edge as by BSplineSurface::orientedFrom (the edge becomes u = 0, v runs along
// it, u into the surface).
struct Side {
  const Patch* patch = nullptr;
  Edge edge = Edge::U0;
  bool rational = false;
  int degree = 0;                               // degree along the edge
  Interval dom;                                 // parameter domain along the edge
  BSplineCurve curve;                           // Cartesian boundary curve
  std::vector<Interval> spans;                  // Bezier spans along the edge
  // Homogeneous k-th cross derivatives (k = 0, 1, 2), all spans in one matrix (no allocation per span): span i,
  // order k is the block of rows i * degree .. i * degree + degree, columns k * hd .. k * hd + hd - 1.
  Matrix rows;
  int hd = 0;  // homogeneous dimension (3, or 4 when rational)
  [[nodiscard]] Interval domain() const { return dom; }
  /// Coefficient j of span i of the k-th cross derivative: hd values; coefficient j + 1 is rowStride() further.
  [[nodiscard]] const double* coeff(size_t k, size_t i, int j) const {
    return rows.data() + (static_cast<Eigen::Index>(i) * degree + j) * rows.cols() + static_cast<Eigen::Index>(k) * hd;
  }
  [[nodiscard]] Eigen::Index rowStride() const { return rows.cols(); }
  /// The k-th cross derivative on span i as a polynomial (a copy; the general route's products and restrictions).
  [[nodiscard]] BernsteinPoly poly(size_t k, size_t i) const {
    return BernsteinPoly(Matrix(rows.block(static_cast<Eigen::Index>(i) * degree, static_cast<Eigen::Index>(k) * hd,
                                           degree + 1, hd)));
  }
};

/// BSplineSurface::crossDerivativeRows(e, 2) written into `out`, whose storage is reused when its size does not
/// change: the same basis values (detail::basisUpTo2), the same zero start and the same products and sums in the same
/// order as the surface's function, so the same bits (test SideRows.ReusedStorageGivesTheSurfaceRows). Surfaces that
/// are not 3-D or whose degree across the edge exceeds the fast basis path take the surface's own function.
void crossDerivativeRowsInto(const BSplineSurface& surf, Edge e, Matrix& out) {
  constexpr int kMaxOrder = 2;
  const bool uEdge = isUEdge(e), atEnd = e == Edge::U1 || e == Edge::V1;
  const int p = uEdge ? surf.degreeU() : surf.degreeV(), nAlong = uEdge ? surf.numV() : surf.numU();
  if (surf.dim() != 3 || p > detail::kMaxFastBasisDegree) {
    out = surf.crossDerivativeRows(e, kMaxOrder);
    return;
  }
  const KnotVector& kc = uEdge ? surf.knotsU() : surf.knotsV();
  const double c = atEnd ? kc.domain(p).hi : kc.domain(p).lo;
  const bool rational = surf.isRational();
  const int hd = rational ? 4 : 3, nv = surf.numV();
  out.setZero(nAlong, static_cast<Eigen::Index>(kMaxOrder + 1) * hd);
  const int top = std::min(kMaxOrder, p);
  const int span = kc.findSpan(p, c);
  double basis[3][detail::kMaxFastBasisDegree + 1];
  detail::basisUpTo2(kc.values(), p, span, c, basis);
  const double* pts = surf.points().data();
  const double* weights = surf.weights().data();
  const Eigen::Index cols = out.cols();
  // The points (and weights) of row `across` walked by pointer; the weight lane only for rational surfaces.
  const Eigen::Index step = uEdge ? 1 : static_cast<Eigen::Index>(nv);  // from point j to point j + 1, in points
  for (int r = 0; r <= p; ++r) {
    const int across = span - p + r;
    const Eigen::Index first = uEdge ? static_cast<Eigen::Index>(across) * nv : across;
    for (int k = 0; k <= top; ++k) {
      const double nkr = basis[k][r];
      // Reversed cross direction at the far edge: d/dn = -d/du there.
      const double coef = (atEnd && k % 2 == 1) ? -nkr : nkr;
      if (coef == 0.0) continue;
      double* o = out.data() + static_cast<Eigen::Index>(k) * hd;
      const double* x = pts + 3 * first;
      const double* w = rational ? weights + first : nullptr;  // a polynomial surface may have no weights at all
      for (int j = 0; j < nAlong; ++j, o += cols, x += 3 * step) {
        const double cw = coef * (rational ? w[j * step] : 1.0);  // the surface function's factor
        o[0] += cw * x[0];
        o[1] += cw * x[1];
        o[2] += cw * x[2];
        if (rational) o[3] += cw;
      }
    }
  }
}

/// Makes `s` the side of patch p seen from edge e, reusing the storage of its rows and spans.
void makeSideInto(Side& s, const Patch& p, Edge e) {
  s.patch = &p;
  s.edge = e;
  const BSplineSurface& surf = p.surface;
  s.rational = surf.isRational();
  const bool uEdge = isUEdge(e);
  s.degree = uEdge ? surf.degreeV() : surf.degreeU();
  const KnotVector& along = uEdge ? surf.knotsV() : surf.knotsU();
  s.dom = along.domain(s.degree);
  // All three cross-derivative rows at once, decomposed into Bezier pieces in one pass.
  crossDerivativeRowsInto(surf, e, s.rows);
  s.hd = static_cast<int>(s.rows.cols() / 3);
  // A polynomial side's curve takes a copy of row 0 as its points (fromHomogeneous would copy it twice: into the
  // temporary its const Matrix& binds, then into the curve).
  s.curve = s.rational ? BSplineCurve::fromHomogeneous(s.degree, along, s.rows.leftCols(s.hd), true)
                       : BSplineCurve(s.degree, along, Matrix(s.rows.leftCols(s.hd)));
  // One clamped Bezier span along the edge (every Bezier patch): decompose's own fast path (the same span, rows
  // untouched) without copying the knots.
  const std::vector<double>& kv = along.values();
  const size_t p1 = static_cast<size_t>(s.degree) + 1;
  if (s.degree >= 1 && kv.size() == 2 * p1 && s.rows.rows() == static_cast<Eigen::Index>(p1) &&
      kv[p1 - 1] < kv[p1] && std::all_of(kv.begin(), kv.begin() + static_cast<std::ptrdiff_t>(p1),
                                         [&](double k) { return k == kv.front(); }) &&
      std::all_of(kv.begin() + static_cast<std::ptrdiff_t>(p1), kv.end(), [&](double k) { return k == kv.back(); })) {
    s.spans.assign(1, Interval{kv[p1 - 1], kv[p1]});
    return;
  }
  std::vector<double> knots = kv;
  s.spans = detail::decompose(s.degree, knots, s.rows);
}

Side makeSide(const Patch& p, Edge e) {
  Side s;
  makeSideInto(s, p, e);
  return s;
}

int spanIndex(const Side& s, double t) {
  const auto& sp = s.spans;
  const auto it = std::lower_bound(sp.begin(), sp.end(), t, [](const Interval& i, double x) { return i.hi < x; });
  return it == sp.end() ? static_cast<int>(sp.size()) - 1 : static_cast<int>(it - sp.begin());
}

/// Largest Bezier degree evaluated by edgeJet on the stack (higher degrees use a heap buffer).
constexpr int kJetStackDegree = 15;

/// kN < 0: the degree n is known at run time only. Four components per point in plain arrays: the same
/// per-component arithmetic as Vector4d expressions (so the same bits), which the compiler unrolls for a fixed degree.
/// kD == 3: exactly three components (dim == 3, polynomial sides): the same operations on components 0..2, the
/// fourth left out (its outputs are 0, as the zero padding gives them).
template <int kN, int kD = 0>
void bernsteinJetImpl(const double* src, int n, int dim, Eigen::Index stride, double x, int order, double* b,
                      std::array<Eigen::Vector4d, 3>& out) {
  if constexpr (kN >= 0) n = kN;
  constexpr int kC = kD == 3 ? 3 : 4;  // components computed
  for (int i = 0; i <= n; ++i, src += stride) {  // coefficient i: dim consecutive values, the next stride further
    double* bi = b + 4 * i;
    if constexpr (kD == 3) {
      for (int k = 0; k < 3; ++k) bi[k] = src[k];
    } else {
      for (int k = 0; k < 4; ++k) bi[k] = k < dim ? src[k] : 0.0;
    }
  }
  const double y = 1.0 - x;
  const int keep = std::min(n, 2);  // stop with keep + 1 points: the last de Casteljau levels give the derivatives
  for (int r = 1; r <= n - keep; ++r)
    for (int i = 0; i <= n - r; ++i) {
      double* bi = b + 4 * i;
      for (int k = 0; k < kC; ++k) bi[k] = y * bi[k] + x * bi[k + 4];
    }
  out[1].setZero();
  out[2].setZero();
  if constexpr (kD == 3) out[0][3] = 0.0;
  const double* b0 = b;
  const double* b1 = b + 4;
  const double* b2 = b + 8;
  if (keep == 0) {
    for (int k = 0; k < kC; ++k) out[0][k] = b0[k];
  } else if (keep == 1) {
    for (int k = 0; k < kC; ++k) {
      out[0][k] = y * b0[k] + x * b1[k];
      out[1][k] = n * (b1[k] - b0[k]);
    }
  } else {
    const double nn = n, nn1 = n * (n - 1);
    for (int k = 0; k < kC; ++k) {
      const double q0 = y * b0[k] + x * b1[k], q1 = y * b1[k] + x * b2[k];
      out[0][k] = y * q0 + x * q1;
      if (order >= 1) out[1][k] = nn * (q1 - q0);
      if (order >= 2) out[2][k] = nn1 * (b2[k] - 2.0 * b1[k] + b0[k]);
    }
  }
}

/// Value and first two derivatives (order <= 2) with respect to x of a Bernstein polynomial of degree n with up to
/// 4 components (coefficient i at src + i * stride), by de Casteljau down to the last three points.
void bernsteinJet(const double* src, int n, int dim, Eigen::Index stride, double x, int order,
                  std::array<Eigen::Vector4d, 3>& out) {
  double stack[4 * (kJetStackDegree + 1)];
  if (dim == 3) {
    switch (n) {  // polynomial sides of the common degrees: three components, unrolled
      case 1: return bernsteinJetImpl<1, 3>(src, n, dim, stride, x, order, stack, out);
      case 2: return bernsteinJetImpl<2, 3>(src, n, dim, stride, x, order, stack, out);
      case 3: return bernsteinJetImpl<3, 3>(src, n, dim, stride, x, order, stack, out);
      case 4: return bernsteinJetImpl<4, 3>(src, n, dim, stride, x, order, stack, out);
      case 5: return bernsteinJetImpl<5, 3>(src, n, dim, stride, x, order, stack, out);
      default: break;
    }
  }
  switch (n) {  // the common degrees unrolled
    case 1: return bernsteinJetImpl<1>(src, n, dim, stride, x, order, stack, out);
    case 2: return bernsteinJetImpl<2>(src, n, dim, stride, x, order, stack, out);
    case 3: return bernsteinJetImpl<3>(src, n, dim, stride, x, order, stack, out);
    case 4: return bernsteinJetImpl<4>(src, n, dim, stride, x, order, stack, out);
    case 5: return bernsteinJetImpl<5>(src, n, dim, stride, x, order, stack, out);
    default: break;
  }
  if (n <= kJetStackDegree) return bernsteinJetImpl<-1>(src, n, dim, stride, x, order, stack, out);
  std::vector<double> heap(4 * (static_cast<size_t>(n) + 1));
  bernsteinJetImpl<-1>(src, n, dim, stride, x, order, heap.data(), out);
}

/// edgeJet on span k of a polynomial side (three coordinates) of degree kN >= 2, at local parameter x with
/// dx = 1 / span length: the three bernsteinJetImpl<kN, 3> evaluations that edgeJet makes (rows 0, 1, 2 to orders 2,
/// 1, 0) and edgeJet's scaling, operation for operation in the same order on each coordinate, without the Vector4d
/// temporaries: the same bits (test SideJet.FusedPassGivesTheGenericBits). Coefficient j of the span holds the
/// three rows' coordinates in 9 consecutive doubles, so each de Casteljau step runs over those 9 lanes at once.
template <int kN>
void polynomialEdgeJet(const Side& s, size_t k, double x, double dx, std::array<Vec3, 6>& out) {
  static_assert(kN >= 2);
  constexpr int kLanes = 9;  // rows 0, 1, 2 x coordinates 0, 1, 2
  assert(s.hd == 3 && s.rowStride() == kLanes);
  constexpr double nn = kN, nn1 = kN * (kN - 1);
  const double y = 1.0 - x;
  const double* src = s.coeff(0, k, 0);
  double b[kN + 1][kLanes];
  for (int i = 0; i <= kN; ++i)
    for (int l = 0; l < kLanes; ++l) b[i][l] = src[i * kLanes + l];
  for (int level = 1; level <= kN - 2; ++level)
    for (int i = 0; i <= kN - level; ++i)
      for (int l = 0; l < kLanes; ++l) b[i][l] = y * b[i][l] + x * b[i + 1][l];
  double q0[kLanes], q1[kLanes], v[kLanes];
  for (int l = 0; l < kLanes; ++l) {
    q0[l] = y * b[0][l] + x * b[1][l];
    q1[l] = y * b[1][l] + x * b[2][l];
    v[l] = y * q0[l] + x * q1[l];
  }
  for (int c = 0; c < 3; ++c) {
    out[0][c] = v[c];
    out[1][c] = v[3 + c];
    out[2][c] = dx * (nn * (q1[c] - q0[c]));
    out[3][c] = v[6 + c];
    out[4][c] = dx * (nn * (q1[3 + c] - q0[3 + c]));
    out[5][c] = dx * dx * (nn1 * (b[2][c] - 2.0 * b[1][c] + b[0][c]));
  }
}

/// edgeJet on span k at local parameter x (dx = 1 / span length) by three Bernstein jets of any degree and
/// dimension (homogeneous; the quotient rule for rational sides).
void genericEdgeJet(const Side& s, size_t k, double x, double dx, std::array<Vec3, 6>& out) {
  std::array<Eigen::Vector4d, 3> j0, j1, j2;
  bernsteinJet(s.coeff(0, k, 0), s.degree, s.hd, s.rowStride(), x, 2, j0);
  bernsteinJet(s.coeff(1, k, 0), s.degree, s.hd, s.rowStride(), x, 1, j1);
  bernsteinJet(s.coeff(2, k, 0), s.degree, s.hd, s.rowStride(), x, 0, j2);
  // Homogeneous (x, w): value, d/du, d/dv, d2/du2, d2/dudv, d2/dv2.
  const std::array<Eigen::Vector4d, 6> H{j0[0], j1[0], dx * j0[1], j2[0], dx * j1[1], dx * dx * j0[2]};
  if (!s.rational) {
    for (size_t i = 0; i < 6; ++i) out[i] = H[i].head<3>();
    return;
  }
  // x = w S differentiated: S_a = (x_a - w_a S) / w, S_ab = (x_ab - w_ab S - w_a S_b - w_b S_a) / w.
  const double w = H[0][3];
  const Vec3 S = H[0].head<3>() / w;
  const Vec3 Su = (H[1].head<3>() - H[1][3] * S) / w, Sv = (H[2].head<3>() - H[2][3] * S) / w;
  out[0] = S;
  out[1] = Su;
  out[2] = Sv;
  out[3] = (H[3].head<3>() - H[3][3] * S - 2.0 * H[1][3] * Su) / w;
  out[4] = (H[4].head<3>() - H[4][3] * S - H[1][3] * Sv - H[2][3] * Su) / w;
  out[5] = (H[5].head<3>() - H[5][3] * S - 2.0 * H[2][3] * Sv) / w;
}

/// The span of side s at t and the local parameter there, as edgeJet and edgePoint choose them.
struct SpanPoint {
  size_t k = 0;
  double x = 0.0, dx = 0.0;
};
SpanPoint spanPoint(const Side& s, double t, bool fromRight) {
  size_t k = static_cast<size_t>(spanIndex(s, t));
  // At a breakpoint (to kKnotRelTol: a parameter mapped from the other side carries round-off) the span that ends
  // there gives the limit from the left, the span that starts there the limit from the right. They differ where the
  // edge is only C0 or C1 (double or triple knots), so the caller chooses.
  const double snap = kKnotRelTol * s.dom.length();
  if (fromRight && k + 1 < s.spans.size() && t >= s.spans[k].hi - snap) ++k;
  if (!fromRight && k > 0 && t <= s.spans[k].lo + snap) --k;
  const Interval span = s.spans[k];
  return {k, (t - span.lo) / span.length(), 1.0 / span.length()};
}

/// S, S_u, S_v, S_uu, S_uv, S_vv of the oriented surface at (u = edge, v = t) from the cross-derivative Bezier pieces
/// of the side (homogeneous; the quotient rule for rational sides). The same values as the surface's own evaluator
/// to round-off, at a fraction of its cost. Spans are non-empty (decompose drops empty ones). `fused` false: always
/// the generic route (the test hook detail::sideJet compares the two).
void edgeJet(const Side& s, double t, std::array<Vec3, 6>& out, bool fromRight = false, bool fused = true) {
  const SpanPoint sp = spanPoint(s, t, fromRight);
  if (fused && !s.rational && s.hd == 3) {  // polynomial sides of the common degrees: one fused pass
    switch (s.degree) {
      case 2: return polynomialEdgeJet<2>(s, sp.k, sp.x, sp.dx, out);
      case 3: return polynomialEdgeJet<3>(s, sp.k, sp.x, sp.dx, out);
      case 4: return polynomialEdgeJet<4>(s, sp.k, sp.x, sp.dx, out);
      case 5: return polynomialEdgeJet<5>(s, sp.k, sp.x, sp.dx, out);
      default: break;
    }
  }
  genericEdgeJet(s, sp.k, sp.x, sp.dx, out);
}

// ------------------------------------------------------------------------------------------------------------
// Pointwise measures from the surfaces' own derivatives (the sampled route).
struct PointMeasures {
  double g0 = 0.0;        // |a(t) - b(s)|
  double g1 = 0.0;        // radians
  double g2 = 0.0;        // spectral norm of the shape-operator difference
  double curvature = 0.0; // larger curvature of the two sides (spectral norms)
  double lambda = 0.0, kappa = 0.0;
  double residual = 0.0;  // normal component of the Lemma 2 residual
  double c1 = 0.0, c2 = 0.0, c1Scale = 0.0, c2Scale = 0.0;
  Vec3 point = Vec3::Zero();
  bool normalsOk = true;    // the G1 angle was measured (normals or their one-sided limits exist)
  bool curvatureOk = true;  // the chart is well conditioned: curvatures, lambda, kappa were measured
};

// sgn = +1 when B's edge parameter s increases with A's t, -1 otherwise. (Seams that share their control rows take
// measureSharedAt instead, except for the plots' dense samples.)
PointMeasures measureAt(const Side& A, double t, const Side& B, double s, double sgn) {
  std::array<Vec3, 6> da, db;  // S, S_u, S_v, S_uu, S_uv, S_vv
  // The same one-sided limit on both sides at a breakpoint: from the left along A's edge, which is from the right
  // along B's when B runs the other way (a mirrored neighbour).
  edgeJet(A, t, da);
  edgeJet(B, s, db, sgn < 0.0);
  PointMeasures m;
  const Vec3 a = da[0], T = da[2], O = -da[1];
  const Vec3 Aoo = da[3], Aot = -da[4], Att = da[5];
  const Vec3 b = db[0], Bc = db[1], Bt = sgn * db[2];
  const Vec3 Bcc = db[3];
  m.point = a;
  m.g0 = (a - b).norm();
  const Vec3 nA = T.cross(O), nB = Bt.cross(Bc);
  m.c1 = (Bc - O).norm();
  m.c2 = (Bcc - Aoo).norm();
  m.c1Scale = std::max(O.norm(), Bc.norm());
  m.c2Scale = std::max(Aoo.norm(), Bcc.norm());
  // Unit normals, or at a pole their one-sided limits along the edge (the edge leaves a vanishing point at the
  // start of its domain and arrives at one at its end).
  auto sideOf = [](const Interval& d, double x) { return x - d.lo <= d.hi - x ? 1.0 : -1.0; };
  const std::optional<Vec3> uA = limitNormal(T, O, Att, Aot, sideOf(A.dom, t));
  const std::optional<Vec3> uB = limitNormal(Bt, Bc, sgn * db[5], db[4], sideOf(B.dom, s));
  const double la = nA.norm(), lb = nB.norm();
  if (!uA || !uB || !(T.norm() > 0.0)) {
    m.normalsOk = m.curvatureOk = false;
    return m;
  }
  m.g1 = std::atan2(uA->cross(*uB).norm(), uA->dot(*uB));
  if (!(la > 0.0) || !(lb > 0.0) || chartConditioning(T, O) < kCurvatureChartRel ||
      chartConditioning(Bt, Bc) < kCurvatureChartRel) {
    m.curvatureOk = false;  // next to a pole: the direction is its limit, curvatures are not measured here
    return m;
  }
  // Lemma 1 connecting functions by least squares: Bc = lambda O + kappa T.
  Eigen::Matrix<double, 3, 2> M;
  M << O, T;
  const Eigen::Vector2d lk = (M.transpose() * M).ldlt().solve(M.transpose() * Bc);
  m.lambda = lk[0];
  m.kappa = lk[1];
  const Vec3 nhA = nA / la, nhB = nB / lb;
  m.residual = nhA.dot(Bcc - m.lambda * m.lambda * Aoo - 2.0 * m.lambda * m.kappa * Aot - m.kappa * m.kappa * Att);
  // Shape operators in A's frame (e1 along the seam, e2 = n x e1), each side with its consistently oriented normal.
  const Vec3 e1 = T.normalized(), e2 = nhA.cross(e1);
  const Eigen::Matrix2d SA = shapeInFrame(da[1], da[2], da[3], da[4], da[5], nhA, e1, e2);
  const Eigen::Matrix2d SB = shapeInFrame(db[1], db[2], db[3], db[4], db[5], nhB, e1, e2);
  m.g2 = spectralNorm(SB - SA);
  m.curvature = std::max(spectralNorm(SA), spectralNorm(SB));
  return m;
}

/// The boundary point of a side at t (row 0 only), with the span chosen as edgeJet chooses it: the same bits as
/// edgeJet's value.
Vec3 edgePoint(const Side& s, double t, bool fromRight) {
  const SpanPoint sp = spanPoint(s, t, fromRight);
  std::array<Eigen::Vector4d, 3> j0;
  bernsteinJet(s.coeff(0, sp.k, 0), s.degree, s.hd, s.rowStride(), sp.x, 0, j0);
  if (!s.rational) return j0[0].head<3>();
  return Vec3(j0[0].head<3>() / j0[0][3]);
}

/// measureAt on a seam whose rows sharedRowBounds certified (B_0 = A_0, B_1 = lambda A_out, B_2 = lambda^2 A_oo up
/// to rounding, one constant lambda): B's derivatives are not evaluated. The gap is measured (B's boundary point
/// from its own row); lambda, kappa = 0, the Lemma 2 residual = 0 and the C1/C2 mismatches |lambda - 1| |A_out|,
/// |lambda^2 - 1| |A_oo| are the identities' exact values (docs/algorithms/seam-measures.md, "Seams that share their
/// control rows"); the angle and the curvature jump, zero in exact arithmetic, are 0 (not their round-off) and the
/// curvature is A's (B's equals it up to rounding).
///
/// `sameBoundary` (identicalBoundaryRows, and s == t): B's boundary point is A's, bit for bit, so the gap is 0 as
/// edgePoint would give it, without evaluating B.
PointMeasures measureSharedAt(const Side& A, double t, const Side& B, double s, double sgn, double lambda,
                              bool sameBoundary) {
  std::array<Vec3, 6> da;
  edgeJet(A, t, da);
  PointMeasures m;
  const Vec3 a = da[0], T = da[2], O = -da[1];
  const Vec3 Aoo = da[3], Aot = -da[4], Att = da[5];
  m.point = a;
  m.g0 = sameBoundary && s == t && a.allFinite() ? 0.0 : (a - edgePoint(B, s, sgn < 0.0)).norm();
  const double oNorm = O.norm(), aooNorm = Aoo.norm();
  m.c1 = std::abs(lambda - 1.0) * oNorm;
  m.c2 = std::abs(lambda * lambda - 1.0) * aooNorm;
  m.c1Scale = std::max(1.0, lambda) * oNorm;
  m.c2Scale = std::max(1.0, lambda * lambda) * aooNorm;
  auto sideOf = [](const Interval& d, double x) { return x - d.lo <= d.hi - x ? 1.0 : -1.0; };
  // limitNormal's test and chartConditioning from this one cross product (the same values, so the same decisions;
  // the one-sided limit only where the normal vanishes).
  const Vec3 nA = T.cross(O);
  const double la = nA.norm();
  const double size = T.squaredNorm() + O.squaredNorm();
  const bool normalExists =
      !detail::normalVanishes(la, size) || limitNormal(T, O, Att, Aot, sideOf(A.dom, t)).has_value();
  if (!normalExists || !(T.norm() > 0.0)) {
    m.normalsOk = m.curvatureOk = false;
    return m;
  }
  if (!(la > 0.0) || detail::chartConditioning(la, size) < kCurvatureChartRel) {
    m.curvatureOk = false;
    return m;
  }
  m.lambda = lambda;
  m.kappa = 0.0;
  const Vec3 nhA = nA / la;
  const Vec3 e1 = T.normalized(), e2 = nhA.cross(e1);
  m.curvature = spectralNorm(shapeInFrame(da[1], da[2], da[3], da[4], da[5], nhA, e1, e2));
  return m;
}

/// True when B's boundary rows are A's, value for value, in the same direction: the same degree, homogeneous
/// dimension, domain and spans, and row 0 of every span equal. Then edgePoint(B, s) at s == t takes the same span,
/// the same local parameter and the same coefficients as edgeJet(A, t): the same point, bit for bit (up to the sign
/// of a zero coordinate), so the sampled gap there is exactly 0.
bool identicalBoundaryRows(const Side& A, const Side& B, bool reversed) {
  if (reversed || A.degree != B.degree || A.hd != B.hd || A.rational != B.rational || !(A.dom.lo == B.dom.lo) ||
      !(A.dom.hi == B.dom.hi) || A.spans.size() != B.spans.size())
    return false;
  for (size_t k = 0; k < A.spans.size(); ++k) {
    if (!(A.spans[k].lo == B.spans[k].lo) || !(A.spans[k].hi == B.spans[k].hi)) return false;
    for (int j = 0; j <= A.degree; ++j) {
      const double* a = A.coeff(0, k, j);
      const double* b = B.coeff(0, k, j);
      for (int c = 0; c < A.hd; ++c)
        if (!(a[c] == b[c])) return false;
    }
  }
  return true;
}

// ------------------------------------------------------------------------------------------------------------
// Exact piece data along the seam: everything as (rational) polynomials of a local parameter tau in [0,1].
struct CartesianSide {
  RationalPoly S, Su, Sv, Suu, Suv, Svv;
};

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

struct Piece {
  BernsteinPoly tOf, sOf;  // A's and B's edge parameters as functions of tau
  BernsteinPoly wa, wb;
  RationalPoly g0;          // a - b
  BernsteinPoly P, Q, R;    // G1: NA.NB, |NA x NB|^2, |NA|^2 |NB|^2 (normal numerators, end roots stripped)
  BernsteinPoly cross;      // NA x NB
  double crossScale = 0.0;  // |NA| |NB| scale for the identity test
  bool g2Available = false;
  RationalPoly rho, T2, nA2, BcT2, O2;  // O2 = |O|^2 (chart conditioning next to poles)
  double rhoScale = 0.0;
  RationalPoly c1, c2, O, Aoo;
  RationalPoly L, K, D;     // Lemma 1: lambda = L / D, kappa = K / D (kappa per unit of the piece parameter)
};

/// Degree of the Lemma 2 residual buildPiece forms from these sides: 2 deg D + deg B_cc + deg n_A + 2 (deg w_A +
/// deg w_B), with n_A = A_t x A_o and D = -|n_A|^2. Known before any product is formed.
int lemma2Degree(const CartesianSide& A, const CartesianSide& B, int waDegree, int wbDegree) {
  const int nA = A.Su.num.degree() + A.Sv.num.degree();
  return 2 * (2 * nA) + B.Suu.num.degree() + nA + 2 * (waDegree + wbDegree);
}

/// What buildPiece forms: everything (patch seams), or only what the G2 bound and samples read (the pcurve route's
/// G2 pieces: wa, wb, rho, T2, nA2, BcT2, O2, tOf; its G1 comes from the composed normals, ComposedSide).
enum class PieceData { kAll, kG2Only };

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
    pc.c1 = ctx.add(Bc, O, -1.0);
    pc.c2 = ctx.add(Bcc, Aoo, -1.0);
    pc.O = O;
    pc.Aoo = Aoo;
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

struct SubPiece {
  double waLo, waHi, wbLo, wbHi;  // coefficient bounds of the weights restricted to [x0, x1]
  SubPiece(const Piece& p, double x0, double x1) {
    const CoeffView wa = restrictedView(p.wa, x0, x1);
    waLo = lowerBoundOf(wa);
    waHi = upperBoundOf(wa);
    const CoeffView wb = restrictedView(p.wb, x0, x1);
    wbLo = lowerBoundOf(wb);
    wbHi = upperBoundOf(wb);
  }
  // As detail::denominatorLower / denominatorUpper of the restricted weights.
  [[nodiscard]] double denLower(const RationalPoly& r) const { return std::pow(waLo, r.ea) * std::pow(wbLo, r.eb); }
  [[nodiscard]] double denUpper(const RationalPoly& r) const { return std::pow(waHi, r.ea) * std::pow(wbHi, r.eb); }
};

double evalRational(const RationalPoly& r, const Piece& pc, double x, VecX* vec = nullptr) {
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

/// g1Bound adds the cosine's bound where the sine's bound reaches this sin^2 (45 degrees): above it the arcsine is
/// the worse conditioned of the two (at 45 degrees both have slope 1 / cos = 1 / sin = sqrt 2).
constexpr double kG1CosineBoundMinSin2 = 0.5;
double g1Bound(const Piece& pc, double x0, double x1) {
  double rLo = 0.0, rHi = 0.0;
  {
    const CoeffView r = restrictedView(pc.R, x0, x1);
    rLo = lowerBoundOf(r);
    rHi = upperBoundOf(r);
  }
  if (!(rLo > 0.0)) return std::numbers::pi;
  const double pLo = lowerBoundOf(restrictedView(pc.P, x0, x1));
  if (pLo > 0.0) {
    // Below 90 degrees two bounds hold: sin(angle) <= sqrt(Q_hi / R_lo), and cos(angle) = P / sqrt(R) >=
    // P_lo / sqrt(R_hi). The sine's is the sharp one at small angles; next to 90 degrees (a crease) the arcsine of
    // a value close to 1 is ill-conditioned (a 0.06 % overestimate of Q / R moves an 88.5-degree bound by 0.9
    // degrees) and the cosine's is the sharp one. Above 45 degrees (sin^2 > 1/2) the smaller of the two.
    const double qHi = std::max(0.0, upperBoundOf(restrictedView(pc.Q, x0, x1)));
    const double sin2 = std::min(1.0, qHi / rLo);
    const double bySine = std::asin(std::sqrt(sin2));
    if (!(sin2 > kG1CosineBoundMinSin2)) return bySine;
    return std::min(bySine, std::acos(std::min(1.0, pLo / std::sqrt(rHi))));
  }
  return std::acos(std::clamp(pLo / std::sqrt(rLo), -1.0, 1.0));
}
double scalarAt(const BernsteinPoly& p, double x);
// A sample, never a bound: from degree kSampleHornerDegree (the pcurve route's composed P, Q, rho, ..., degree
// ~40-500) in O(n) by scalarAt instead of de Casteljau's O(n^2), which differs in the last bits only (issue 16 goal
// 6). Below it (every quantity of a bicubic or biquartic seam: rho of a bicubic one has degree 28) de Casteljau, as
// before. Above degree 512 the binomial factors of scalarAt may overflow: de Casteljau again.
constexpr int kSampleHornerDegree = 32;
double sampleAt(const BernsteinPoly& p, double x) {
  if (p.degree() < kSampleHornerDegree || p.degree() > 512) return p.scalar(x);
  const double v = scalarAt(p, x);
  return std::isfinite(v) ? v : p.scalar(x);
}
double g1Value(const Piece& pc, double x) {
  return std::atan2(std::sqrt(std::max(0.0, sampleAt(pc.Q, x))), sampleAt(pc.P, x));
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

// Scalar Bernstein polynomial at x in [0, 1] (coefficient column 0) in O(n), no allocation: Horner's scheme in
// s = x / (1 - x) (or, mirrored, in (1 - x) / x for x > 1/2, so that |s| <= 1), times (1 - x)^n. For the samples
// of the connecting functions only (bounds never use it).
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
  for (int i = n; i >= 1; --i) {
    binom = binom * i / (n - i + 1);
    acc = acc * s + binom * (mirror ? c[n - i + 1] : c[i - 1]);
  }
  return acc * std::pow(1.0 - y, n);
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
                  int& bestPiece, double floor, const SeamOptions& opt, bool& ok, const bool* stop = nullptr) {
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
    if (ub <= (1.0 + opt.boundRelGap) * best + floor) {
      result = std::max(result, ub);
      tree.release(node);
      continue;
    }
    if (it.depth >= opt.maxSubdivisionDepth || work >= opt.maxBoundWork) {
      if (!std::isfinite(ub)) ok = false;
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

// ------------------------------------------------------------------------------------------------------------
// Correspondence: a master side parametrises the seam; per master span a polynomial map m(sigma) (sigma local in
// the span) gives the other side's global edge parameter.
struct MapSpan {
  int span;             // master span index
  double sig0, sig1;    // local interval inside the span that belongs to the overlap
  BernsteinPoly m;      // slave global parameter as a function of sigma in [0,1] (whole span)
};

// Finds sigma in [lo, hi] with m(sigma) = target, m monotone on it (bisection to round-off).
double solveMonotone(const BernsteinPoly& m, double target, double lo, double hi) {
  const bool increasing = m.scalar(hi) >= m.scalar(lo);
  for (int i = 0; i < 200 && hi - lo > 1e-16; ++i) {
    const double mid = 0.5 * (lo + hi);
    const double v = m.scalar(mid);
    if ((v < target) == increasing)
      lo = mid;
    else
      hi = mid;
  }
  return 0.5 * (lo + hi);
}

std::vector<Piece> buildPieces(const Side& master, const Side& slave, bool masterIsA,
                               const std::vector<MapSpan>& maps, const SeamOptions& opt) {
  std::vector<Piece> out;
  for (const MapSpan& ms : maps) {
    const Interval msp = master.spans[static_cast<size_t>(ms.span)];
    // Split the local interval where the slave parameter crosses one of the slave's breakpoints.
    std::vector<double> cuts{ms.sig0};
    const double m0 = ms.m.scalar(ms.sig0), m1 = ms.m.scalar(ms.sig1);
    for (size_t k = 0; k + 1 < slave.spans.size(); ++k) {
      const double b = slave.spans[k].hi;
      if (b > std::min(m0, m1) && b < std::max(m0, m1)) cuts.push_back(solveMonotone(ms.m, b, ms.sig0, ms.sig1));
    }
    cuts.push_back(ms.sig1);
    std::sort(cuts.begin(), cuts.end());
    // Knots of the two edges that agree to round-off (the same knot value seen through an affine map) must not
    // leave a sliver piece: its polynomials vanish to round-off and no bound closes on it.
    const double sliver = kKnotRelTol * master.domain().length() / msp.length();
    std::vector<double> kept{cuts.front()};
    for (size_t c = 1; c + 1 < cuts.size(); ++c)
      if (cuts[c] - kept.back() > sliver && cuts.back() - cuts[c] > sliver) kept.push_back(cuts[c]);
    kept.push_back(cuts.back());
    cuts = std::move(kept);
    for (size_t c = 0; c + 1 < cuts.size(); ++c) {
      const double sa = cuts[c], sb = cuts[c + 1];
      if (!(sb - sa > sliver)) continue;
      // Master data restricted to [sa, sb] of its span.
      std::array<BernsteinPoly, 3> XM, XS;
      for (size_t k = 0; k < 3; ++k) XM[k] = master.poly(k, static_cast<size_t>(ms.span)).restricted(sa, sb);
      // Slave: the span containing the middle, and the map in its local coordinates.
      const BernsteinPoly mr = ms.m.restricted(sa, sb);
      const int sspan = spanIndex(slave, mr.scalar(0.5));
      const Interval ssp = slave.spans[static_cast<size_t>(sspan)];
      BernsteinPoly local = mr;
      local.coeffs().array() -= ssp.lo;
      local *= 1.0 / ssp.length();
      for (size_t k = 0; k < 3; ++k) {
        const BernsteinPoly hs = slave.poly(k, static_cast<size_t>(sspan));
        XS[k] = local.degree() <= 1 ? hs.restricted(local.coeffs()(0, 0), local.coeffs()(local.degree(), 0))
                                    : hs.composed(local);
      }
      const BernsteinPoly masterParam = BernsteinPoly::linear(msp.lo + msp.length() * sa, msp.lo + msp.length() * sb);
      // Without the G2 certificate (SeamOptions::certifyG2 = false) the Lemma 2 polynomials are not formed: nothing
      // reads them then (g2Available only gates the G2 subdivision), and on biquintic seams they are most of the
      // piece's products.
      const int g2Degree = opt.certifyG2 ? opt.maxCertifiedDegree : -1;
      if (masterIsA)
        out.push_back(buildPiece(XM, XS, master.rational, slave.rational, masterParam, mr, g2Degree));
      else
        out.push_back(buildPiece(XS, XM, slave.rational, master.rational, mr, masterParam, g2Degree));
    }
  }
  return out;
}

// Affine map from A's overlap onto B's overlap.
std::vector<MapSpan> affineMaps(const Side& A, Interval oa, Interval ob, bool reversed) {
  std::vector<MapSpan> maps;
  const double slope = (reversed ? -1.0 : 1.0) * ob.length() / oa.length();
  const double s0 = reversed ? ob.hi : ob.lo;
  for (size_t k = 0; k < A.spans.size(); ++k) {
    const Interval sp = A.spans[k];
    const double lo = std::max(sp.lo, oa.lo), hi = std::min(sp.hi, oa.hi);
    if (!(hi - lo > kKnotRelTol * A.domain().length())) continue;  // no sliver spans (see buildPieces)
    const auto sOf = [&](double t) { return s0 + slope * (t - oa.lo); };
    maps.push_back({static_cast<int>(k), (lo - sp.lo) / sp.length(), (hi - sp.lo) / sp.length(),
                    BernsteinPoly::linear(sOf(sp.lo), sOf(sp.hi))});
  }
  return maps;
}

// Polynomial map of degree r from the master's parameter to the slave's, fitted per master span by least squares
// on closest-point projections (it is verified afterwards by the exact distance bound).
std::vector<MapSpan> fittedMaps(const Side& master, const Side& slave, Interval om, int r) {
  std::vector<MapSpan> maps;
  const int n = kFitSamplesFactor * (r + 1);
  double guess = slave.domain().lo;
  bool first = true;
  for (size_t k = 0; k < master.spans.size(); ++k) {
    const Interval sp = master.spans[k];
    const double lo = std::max(sp.lo, om.lo), hi = std::min(sp.hi, om.hi);
    if (!(hi - lo > kKnotRelTol * master.domain().length())) continue;  // no sliver spans (see buildPieces)
    Eigen::MatrixXd V(n, r + 1);
    Eigen::VectorXd y(n);
    for (int i = 0; i < n; ++i) {
      const double sigma = (static_cast<double>(i) + 0.5) / n;
      const double tm = sp.lo + sp.length() * sigma;
      const Vec3 p = master.curve.point3(tm);
      const auto cp = first ? detail::closestPoint(slave.curve, p) : detail::closestPoint(slave.curve, p, {}, guess);
      first = false;
      guess = cp.t;
      y[i] = cp.t;
      for (int j = 0; j <= r; ++j) V(i, j) = binomial(r, j) * std::pow(sigma, j) * std::pow(1.0 - sigma, r - j);
    }
    const Eigen::VectorXd c = V.colPivHouseholderQr().solve(y);
    maps.push_back({static_cast<int>(k), (lo - sp.lo) / sp.length(), (hi - sp.lo) / sp.length(),
                    BernsteinPoly(Matrix(c))});
  }
  return maps;
}

// ------------------------------------------------------------------------------------------------------------
struct SampleSet {
  std::vector<double> t, s;
  std::vector<PointMeasures> m;
};

double controlDiagonal(const BSplineSurface& s) { return controlBox(s).diagonal(); }

// ------------------------------------------------------------------------------------------------------------
// Seams that share their control rows (C^k splits: two patches cut from one surface at a knot line, issue 16 goal
// 2). docs/algorithms/seam-measures.md, "Seams that share their control rows", derives the bounds.

/// Rounding allowance of the shared-row test, in units of the machine epsilon times (degree + 1) times the magnitude
/// of the coordinates the rows were computed from: rows that differ by more are not "the same row up to rounding"
/// (a perturbation of 1e-12 of the coordinates is 70 times above it for cubics) and take the general route.
constexpr double kSharedRowUlps = 16.0;
/// Relative inflation of the shared-row bounds: covers the rounding of the few dozen operations that form them.
constexpr double kSharedRowSafety = 1.0 + 1e-12;

/// Factors d/du and d^2/du^2 of the cross-derivative rows at edge e per unit of the control points' coordinates:
/// p / h and p (p - 1) / h^2 with h the knot span next to the edge (the rows are differences of control points
/// scaled by them, so their rounding is epsilon x coordinates x these factors).
std::pair<double, double> crossRowFactors(const BSplineSurface& surf, Edge e) {
  const bool uEdge = isUEdge(e);
  const int p = uEdge ? surf.degreeU() : surf.degreeV();
  const KnotVector& kv = uEdge ? surf.knotsU() : surf.knotsV();
  const Interval dom = kv.domain(p);
  const bool atStart = e == Edge::U0 || e == Edge::V0;
  double h = dom.length();
  for (int i = 0; i < kv.size(); ++i) {
    const double k = kv[i];
    const double d = atStart ? k - dom.lo : dom.hi - k;
    if (d > kKnotRelTol * dom.length()) h = std::min(h, d);
  }
  if (!(h > 0.0)) return {0.0, 0.0};
  return {p / h, p * (p - 1) / (h * h)};
}

/// The Bernstein weights of sharedRowBounds' product n_A = A_t x A_out for each degree n <= kJetStackDegree, computed
/// once: product[n][i][j] = C(n-1, i) C(n, j) / C(2n-1, i+j) and binomial[n][l] = C(2n-1, l), the same expressions
/// (so the same doubles) that were evaluated per coefficient.
struct ProductWeights {
  std::array<std::array<std::array<double, kJetStackDegree + 1>, kJetStackDegree>, kJetStackDegree + 1> product{};
  std::array<std::array<double, 2 * kJetStackDegree>, kJetStackDegree + 1> binomial{};
};

const ProductWeights& productWeights() {
  static const ProductWeights w = [] {
    ProductWeights r;
    for (int n = 1; n <= kJetStackDegree; ++n) {
      const int dn = 2 * n - 1;
      for (int i = 0; i < n; ++i)
        for (int j = 0; j <= n; ++j)
          r.product[static_cast<size_t>(n)][static_cast<size_t>(i)][static_cast<size_t>(j)] =
              binomial(n - 1, i) * binomial(n, j) / binomial(dn, i + j);
      for (int l = 0; l <= dn; ++l) r.binomial[static_cast<size_t>(n)][static_cast<size_t>(l)] = binomial(dn, l);
    }
    return r;
  }();
  return w;
}

struct SharedRowBounds {
  double g0 = 0.0;  // certified gap bound (the largest control-point difference of the boundary rows)
  double g1 = 0.0;  // certified angle bound, radians
  double g2 = 0.0;  // certified bound of the G2 quotient (as g2Bound)
  double c1 = 0.0, c2 = 0.0;  // largest coefficient of B'_u - A_out and B'_uu - A'_uu (parametric identities)
  double lambda = 1.0;        // the constant of B_1 = lambda A_out (least squares over the first rows)
};

/// Bounds of a seam whose two sides are polynomial, share their Bezier spans along the edge (same degree, same
/// normalised breakpoints, the overlap being both whole edges) and whose rows satisfy, up to rounding,
/// B_0 = A_0, B_1 = lambda A_out (one constant lambda > 0) and B_2 = lambda^2 A_oo (the C2 relation for the
/// cross-derivative scale lambda). nullopt when any of that fails or the bounds are not at round-off level: the
/// caller then takes the general route. No allocation.
std::optional<SharedRowBounds> sharedRowBounds(const Side& A, const Side& B, bool reversed) {
  if (A.rational || B.rational || A.degree != B.degree || A.spans.size() != B.spans.size() || A.degree < 1)
    return std::nullopt;
  const int n = A.degree;
  const size_t m = A.spans.size();
  // The spans correspond one to one: same normalised breakpoints (B's mirrored when reversed).
  for (size_t k = 0; k < m; ++k) {
    const size_t kb = reversed ? m - 1 - k : k;
    const double na = (A.spans[k].lo - A.dom.lo) / A.dom.length();
    const double nb = reversed ? (B.dom.hi - B.spans[kb].hi) / B.dom.length()
                               : (B.spans[kb].lo - B.dom.lo) / B.dom.length();
    if (!(std::abs(na - nb) <= kKnotRelTol)) return std::nullopt;
  }
  // Coefficient j of span i of the k-th cross derivative of a side (polynomial: three coordinates).
  auto row = [](const Side& s, size_t k, size_t i, int j) { return Vec3(Eigen::Map<const Vec3>(s.coeff(k, i, j))); };
  // lambda by least squares over all coefficients of the first rows: B_1 = lambda A_out = -lambda A_1.
  double num = 0.0, den = 0.0, mag0 = 0.0;
  for (size_t k = 0; k < m; ++k) {
    const size_t kb = reversed ? m - 1 - k : k;
    for (int j = 0; j <= n; ++j) {
      const int jb = reversed ? n - j : j;
      const Vec3 o = -row(A, 1, k, j), b1 = row(B, 1, kb, jb);
      num += b1.dot(o);
      den += o.squaredNorm();
      mag0 = std::max({mag0, row(A, 0, k, j).cwiseAbs().maxCoeff(), row(B, 0, kb, jb).cwiseAbs().maxCoeff()});
    }
  }
  if (!(den > 0.0)) return std::nullopt;
  const double lambda = num / den;
  if (!(lambda > 0.0) || !std::isfinite(lambda)) return std::nullopt;
  // Rounding allowances from the coordinates' magnitude.
  const auto [fa1, fa2] = crossRowFactors(A.patch->surface, A.edge);
  const auto [fb1, fb2] = crossRowFactors(B.patch->surface, B.edge);
  const double ulp = kSharedRowUlps * (n + 1) * std::numeric_limits<double>::epsilon() * mag0;
  const double eps0 = ulp, eps1 = ulp * (lambda * fa1 + fb1), eps2 = ulp * (lambda * lambda * fa2 + fb2);

  double d0 = 0.0, d1 = 0.0, d2 = 0.0, dT = 0.0, c1 = 0.0, c2 = 0.0;
  double tMax = 0.0, oMax = 0.0, aooMax = 0.0, aotMax = 0.0, attMax = 0.0;
  double nMin = std::numeric_limits<double>::infinity();
  constexpr int kMaxDegree = kJetStackDegree;
  if (n > kMaxDegree) return std::nullopt;
  std::array<Vec3, kMaxDegree + 1> diff;
  std::array<Vec3, kMaxDegree> T, O1;          // A_t and the along-edge derivative of A_1 (coefficients)
  std::array<Vec3, 2 * kMaxDegree> NA;         // n_A = A_t x A_out, degree 2n - 1
  std::array<Vec3, kMaxDegree + 1> O;          // A_out = -A_1 (coefficients)
  for (size_t k = 0; k < m; ++k) {
    const size_t kb = reversed ? m - 1 - k : k;
    for (int j = 0; j <= n; ++j) {
      const int jb = reversed ? n - j : j;
      const Vec3 pa = row(A, 0, k, j), pb = row(B, 0, kb, jb);
      const Vec3 ra1 = row(A, 1, k, j), rb1 = row(B, 1, kb, jb);
      const Vec3 ra2 = row(A, 2, k, j), rb2 = row(B, 2, kb, jb);
      diff[static_cast<size_t>(j)] = pb - pa;
      d0 = std::max(d0, (pb - pa).norm());
      d1 = std::max(d1, (rb1 + lambda * ra1).norm());
      d2 = std::max(d2, (rb2 - lambda * lambda * ra2).norm());
      c1 = std::max(c1, (rb1 + ra1).norm());
      c2 = std::max(c2, (rb2 - ra2).norm());
      oMax = std::max(oMax, ra1.norm());
      aooMax = std::max(aooMax, ra2.norm());
      if (j >= 2) {
        const Vec3 att = n * (n - 1) * (pa - 2.0 * row(A, 0, k, j - 1) + row(A, 0, k, j - 2));
        attMax = std::max(attMax, att.norm());
      }
    }
    if (!(d0 <= eps0) || !(d1 <= eps1) || !(d2 <= eps2)) return std::nullopt;
    for (int j = 0; j < n; ++j) {
      const size_t u = static_cast<size_t>(j);
      T[u] = n * (row(A, 0, k, j + 1) - row(A, 0, k, j));
      O1[u] = n * (row(A, 1, k, j + 1) - row(A, 1, k, j));
      tMax = std::max(tMax, T[u].norm());
      aotMax = std::max(aotMax, O1[u].norm());
      dT = std::max(dT, (n * (diff[u + 1] - diff[u])).norm());
    }
    // n_A = A_t x A_out in Bernstein form of degree 2n - 1: sum over i + j = l of C(n-1, i) C(n, j) / C(2n-1, l).
    const int dn = 2 * n - 1;
    const ProductWeights& weights = productWeights();
    for (int j = 0; j <= n; ++j) O[static_cast<size_t>(j)] = -row(A, 1, k, j);
    for (int l = 0; l <= dn; ++l) NA[static_cast<size_t>(l)].setZero();
    for (int i = 0; i < n; ++i)
      for (int j = 0; j <= n; ++j)
        NA[static_cast<size_t>(i + j)] += weights.product[static_cast<size_t>(n)][static_cast<size_t>(i)]
                                                         [static_cast<size_t>(j)] *
                                          T[static_cast<size_t>(i)].cross(O[static_cast<size_t>(j)]);
    // |n_A| >= min_l <m, N_l> for the unit direction m of n_A at the middle (the hull of a scalar polynomial).
    Vec3 mid = Vec3::Zero();
    for (int l = 0; l <= dn; ++l)  // 2^dn n_A(1/2)
      mid += weights.binomial[static_cast<size_t>(n)][static_cast<size_t>(l)] * NA[static_cast<size_t>(l)];
    if (!(mid.norm() > 0.0)) return std::nullopt;
    mid.normalize();
    for (int l = 0; l <= dn; ++l) {
      nMin = std::min(nMin, mid.dot(NA[static_cast<size_t>(l)]));
    }
  }
  if (!(nMin > 0.0)) return std::nullopt;
  SharedRowBounds r;
  r.lambda = lambda;
  r.g0 = d0 * kSharedRowSafety;
  r.c1 = c1;
  r.c2 = c2;
  // G1: n_B = lambda n_A + e with |e| <= lambda dT |O| + |T| d1 + dT d1; sin(angle) <= |e| / (lambda |n_A|).
  const double e = lambda * dT * oMax + tMax * d1 + dT * d1;
  const double sinBound = kSharedRowSafety * e / (lambda * nMin);
  if (!(sinBound < 1.0)) return std::nullopt;
  r.g1 = std::asin(sinBound) * kSharedRowSafety;
  // G2 (the quotient of g2Bound, pointwise): with L = lambda D + e_L', |e_L'| <= d1 |T| |n_A|, |K| <= |O| d1 |n_A|,
  // D = -|n_A|^2 and B_cc = lambda^2 A_oo + e2, |V| / |n_A|^4 <= d2 + d1 |T| (2 lambda |n_A| + d1 |T|) |A_oo| / |n_A|^2
  // + 2 (lambda |n_A| + d1 |T|) |O| d1 |A_ot| / |n_A|^2 + |O|^2 d1^2 |A_tt| / |n_A|^2 and |y| <= that x |T|^2 /
  // |B_c x T|^2, |B_c x T| >= lambda |n_A| - d1 |T|: every term decreases with |n_A|, so |n_A| = nMin bounds it.
  const double bLow = lambda * nMin - d1 * tMax;
  if (!(bLow > 0.0)) return std::nullopt;
  const double n2 = nMin * nMin, dt = d1 * tMax;
  const double V = d2 + dt * (2.0 * lambda * nMin + dt) * aooMax / n2 +
                   2.0 * (lambda * nMin + dt) * oMax * d1 * aotMax / n2 + oMax * oMax * d1 * d1 * attMax / n2;
  r.g2 = kSharedRowSafety * V * tMax * tMax / (bLow * bLow);
  if (!(r.g1 <= kIdentityBoundFactor * kAngleBoundFloor) || !std::isfinite(r.g2)) return std::nullopt;
  return r;
}

}  // namespace

// ---------------------------------------------------------------------------------------------------------------
GeometricClass classifyGeometric(const SeamReport& r, const Tolerances& tol) {
  if (!(r.g0Max <= tol.distance)) return GeometricClass::kNone;
  if (!(r.g1MaxDeg <= tol.angleDeg || r.g1Identity)) return GeometricClass::kG0;
  if (!(r.g2Identity || r.g2RelMax <= tol.curvatureRel)) return GeometricClass::kG1;
  return GeometricClass::kG2;
}

void reconcileVerdict(SeamReport& r, const Tolerances& tol) {
  if (r.g1Identity && !(r.g1MaxDeg <= tol.angleDeg)) {
    if (r.g1SampledDeg <= tol.angleDeg) {
      r.g1MaxDeg = r.g1SampledDeg;
      r.notes.push_back("G1 proved as an identity (N_A x N_B = 0); its bound did not close next to a vanishing "
                        "normal: the angle shown is sampled");
    } else {
      r.g1Identity = false;
      r.certified = false;
      r.notes.push_back(fmt::format("not certified: the G1 identity test and the sampled angle ({:.6g} deg) "
                                    "disagree next to a vanishing normal",
                                    r.g1SampledDeg));
    }
  }
  if (r.g2Identity && !(r.g2RelMax <= tol.curvatureRel)) {
    if (r.g2RelSampled <= tol.curvatureRel) {
      r.g2Max = r.g2Sampled;
      r.g2RelMax = r.g2RelSampled;
      r.notes.push_back("G2 proved as an identity (Lemma 2 residual zero); its bound did not close next to a "
                        "vanishing normal: the jump shown is sampled");
    } else {
      r.g2Identity = false;
      r.notes.push_back("the G2 identity test and the sampled jump disagree: G2 not certified");
    }
  }
  r.geometric = classifyGeometric(r, tol);
}

Result<SeamReport> analyzeSeam(const Patch& a, Edge ea, const Patch& b, Edge eb, const SeamOptions& options) {
  return analyzeSeam(a, ea, b, eb, options, std::nullopt);
}

Result<SeamReport> analyzeSeam(const Patch& pa, Edge ea, const Patch& pb, Edge eb, const SeamOptions& opt,
                               std::optional<Interval> aRange) {
  if (pa.surface.dim() != 3 || pb.surface.dim() != 3)
    return invalidInput(fmt::format("seam {}:{} / {}:{}: patches must have 3-D control points", pa.name,
                                    edgeName(ea), pb.name, edgeName(eb)));
  return detail::analyzeSeamScaled(pa, ea, pb, eb, opt, aRange, controlDiagonal(pa.surface),
                                   controlDiagonal(pb.surface));
}

namespace detail {

void sideCrossRows(const BSplineSurface& s, Edge e, Matrix& rows) { crossDerivativeRowsInto(s, e, rows); }

std::array<Vec3, 6> sideJet(const Patch& p, Edge e, double t, bool fromRight, bool fused) {
  const Side s = makeSide(p, e);
  std::array<Vec3, 6> out;
  edgeJet(s, t, out, fromRight, fused);
  return out;
}

Result<SeamReport> analyzeSeamScaled(const Patch& pa, Edge ea, const Patch& pb, Edge eb, const SeamOptions& opt,
                                     std::optional<Interval> aRange, double patchDiagA, double patchDiagB) {
  if (pa.surface.dim() != 3 || pb.surface.dim() != 3)
    return invalidInput(fmt::format("seam {}:{} / {}:{}: patches must have 3-D control points", pa.name,
                                    edgeName(ea), pb.name, edgeName(eb)));
  // Formatted only for an error (not on the per-seam path).
  const auto label = [&] {
    return fmt::format("seam {}:{} / {}:{}", pa.name, edgeName(ea), pb.name, edgeName(eb));
  };
  // Per-thread sides reused from seam to seam (their rows and spans keep their storage). The one nested analysis
  // (the general route below) rebuilds them and its report is returned directly: these are not used after it.
  thread_local Side sideA, sideB;
  makeSideInto(sideA, pa, ea);
  makeSideInto(sideB, pb, eb);
  const Side& A = sideA;
  const Side& B = sideB;
  const double scale = std::max(patchDiagA, patchDiagB);
  // The edges' control box diagonals, also the overlap projections' scale below.
  const double diagA = controlBox(A.curve).diagonal(), diagB = controlBox(B.curve).diagonal();
  for (const auto& [s, diag] : {std::pair{&A, diagA}, std::pair{&B, diagB}}) {
    if (!(diag > kRoundoff * scale))
      return Status(ErrorCode::kDegenerate, fmt::format("{}: edge {} of patch \"{}\" collapses to a point", label(),
                                                        edgeName(s->edge), s->patch->name));
  }
  SeamReport rep;
  rep.a = pa.name;
  rep.b = pb.name;
  rep.aEdge = ea;
  rep.bEdge = eb;

  // ---- overlap: project each edge's end points onto the other edge.
  Interval da = A.domain(), db = B.domain();
  if (aRange) da = {std::max(da.lo, aRange->lo), std::min(da.hi, aRange->hi)};
  const Vec3 a0 = A.curve.point3(da.lo), a1 = A.curve.point3(da.hi);
  const Vec3 b0 = B.curve.point3(db.lo), b1 = B.curve.point3(db.hi);
  // A's point at t for the reported worst points: a0 or a1 when t is that end of the range, bit for bit (the same
  // call on the same argument; the sign of a zero compared too), else evaluated.
  const auto sameBits = [](double x, double y) {
    return std::bit_cast<std::uint64_t>(x) == std::bit_cast<std::uint64_t>(y);
  };
  const auto pointOnA = [&](double t) {
    if (sameBits(t, da.lo)) return a0;
    if (sameBits(t, da.hi)) return a1;
    return A.curve.point3(t);
  };
  // An end point whose partner edge's end is about as close as the partner curve itself (a gap, not a
  // T-junction) is snapped to that end, so that offset seams keep their exact end-to-end correspondence.
  // `lo`, `hi`: the curve's points at the range ends (computed once above); `diag`: its control box diagonal.
  auto project = [](const BSplineCurve& c, const Vec3& lo, const Vec3& hi, double diag, const Vec3& p,
                    Interval range) {
    const double dLo = (lo - p).norm(), dHi = (hi - p).norm();
    const double roundoff = kRoundoff * diag;
    if (std::min(dLo, dHi) <= roundoff) return dLo <= dHi ? range.lo : range.hi;  // shared end point
    const detail::CurvePoint cp = detail::closestPoint(c, p, range);
    const double slack = kOverlapSnapFactor * cp.distance + roundoff;
    if (std::min(dLo, dHi) <= slack) return dLo <= dHi ? range.lo : range.hi;
    return cp.t;
  };
  const double tb0 = project(A.curve, a0, a1, diagA, b0, da), tb1 = project(A.curve, a0, a1, diagA, b1, da);
  const double sa0 = project(B.curve, b0, b1, diagB, a0, db), sa1 = project(B.curve, b0, b1, diagB, a1, db);
  rep.reversed = tb0 > tb1 || (tb0 == tb1 && sa0 > sa1);
  // End mismatch (issue 15 §4): an end point of A and an end point of B matched to each other both ways (each is
  // the other's partner end) are the same end of the seam, so the gap there is their distance, also where one edge
  // runs a little past the other (an overhang within the snap distance, which the pairing does not report as a free
  // part). An end matched only one way (T-junctions, edges that go on past the other) is not a seam end.
  double endMismatch = 0.0, endMismatchT = da.lo;
  Vec3 endMismatchPoint = a0;
  for (const auto& [aT, aP, sa] : {std::tuple{da.lo, a0, sa0}, std::tuple{da.hi, a1, sa1}}) {
    for (const auto& [bS, bP, tb] : {std::tuple{db.lo, b0, tb0}, std::tuple{db.hi, b1, tb1}}) {
      if (sa != bS || tb != aT) continue;
      const double d = (aP - bP).norm();
      if (d > endMismatch) endMismatch = d, endMismatchT = aT, endMismatchPoint = aP;
    }
  }
  rep.overlapA = {std::min(tb0, tb1), std::max(tb0, tb1)};
  rep.overlapB = {std::min(sa0, sa1), std::max(sa0, sa1)};
  const double minOverlap = kKnotRelTol * 1e3;
  if (!(rep.overlapA.length() > minOverlap * da.length()) || !(rep.overlapB.length() > minOverlap * db.length()))
    return Status(ErrorCode::kNotFound, fmt::format("{}: the edges do not overlap", label()));
  const double sgn = rep.reversed ? -1.0 : 1.0;
  const double edgeScale = std::max(diagA, diagB);
  const double exactFloor = kExactCorrespondenceRel * edgeScale;

  // ---- correspondence: shared control rows, affine, then polynomial, else closest-point projection.
  std::vector<Piece> pieces;
  bool certified = false;
  double corrBound = std::numeric_limits<double>::infinity();  // certified bound of |a - b o phi| when certified
  // Both whole edges, the same spans and rows equal up to rounding (C^k splits): bounds straight from the rows.
  std::optional<SharedRowBounds> shared;
  if (opt.sharedRows && rep.overlapA.lo == A.dom.lo && rep.overlapA.hi == A.dom.hi && rep.overlapB.lo == B.dom.lo &&
      rep.overlapB.hi == B.dom.hi)
    shared = sharedRowBounds(A, B, rep.reversed);
  if (shared) {
    rep.correspondence = Correspondence::kAffine;
    rep.sharedRows = true;
    certified = true;
    corrBound = shared->g0;
  } else {
  auto tryMaps = [&](const Side& master, const Side& slave, bool masterIsA, const std::vector<MapSpan>& maps) {
    std::vector<Piece> pcs = buildPieces(master, slave, masterIsA, maps, opt);
    double best = 0.0, bx = 0.0;
    int bp = 0;
    bool ok = true;
    for (size_t i = 0; i < pcs.size(); ++i)
      for (int k = 0; k <= 4; ++k) best = std::max(best, g0Value(pcs[i], k / 4.0));
    const double bound = certifyMax(pcs, g0Bound, g0Value, best, bx, bp, exactFloor, opt, ok);
    return std::pair{std::move(pcs), bound};
  };
  {
    auto [pcs, bound] = tryMaps(A, B, true, affineMaps(A, rep.overlapA, rep.overlapB, rep.reversed));
    if (bound <= exactFloor) {
      pieces = std::move(pcs);
      rep.correspondence = Correspondence::kAffine;
      certified = true;
      corrBound = bound;
    } else {
      const int pA = A.degree, pB = B.degree;
      bool found = false;
      {  // homogeneous degrees: b = a o psi holds for (wP, w) as well, up to a common factor that is not sought
        if (pB % pA == 0 && pB / pA > 1) {
          auto [pc2, b2] = tryMaps(B, A, false, fittedMaps(B, A, rep.overlapB, pB / pA));
          if (b2 <= exactFloor) {
            pieces = std::move(pc2);
            rep.correspondenceDegree = pB / pA;
            found = true;
            corrBound = b2;
          }
        } else if (pA % pB == 0 && pA / pB > 1) {
          auto [pc2, b2] = tryMaps(A, B, true, fittedMaps(A, B, rep.overlapA, pA / pB));
          if (b2 <= exactFloor) {
            pieces = std::move(pc2);
            rep.correspondenceDegree = pA / pB;
            found = true;
            corrBound = b2;
          }
        }
      }
      if (found) {
        rep.correspondence = Correspondence::kPolynomial;
        certified = true;
      } else {
        // A gap: keep the affine map when it is as good as closest-point matching (offset seams), else project.
        // haus only grows, so the loop stops as soon as it decides the test (the same decision as the whole loop).
        double haus = 0.0;
        const auto affineAsGood = [&] { return bound <= (1.0 + opt.boundRelGap) * haus + exactFloor; };
        const int n = std::max(opt.samplesPerSpan, 8) * static_cast<int>(A.spans.size());
        for (int i = 0; i <= n && !affineAsGood(); ++i) {
          const double t = rep.overlapA.lo + rep.overlapA.length() * i / n;
          haus = std::max(haus, detail::closestPoint(B.curve, A.curve.point3(t), rep.overlapB).distance);
        }
        if (affineAsGood()) {
          pieces = std::move(pcs);
          rep.correspondence = Correspondence::kAffine;
          certified = true;
          corrBound = bound;
        } else {
          rep.correspondence = Correspondence::kProjection;
          rep.notes.push_back("no polynomial correspondence between the edges: measures are sampled");
        }
      }
    }
  }
  }
  for (const Piece& pc : pieces)
    if (pc.P.degree() > opt.maxCertifiedDegree) {
      certified = false;
      pieces.clear();
      rep.notes.push_back("seam polynomials exceed the certified degree limit: measures are sampled");
      break;
    }

  // ---- dense sampling (the sampled worst values, and the whole story when not certified).
  // Per-thread storage reused from seam to seam (no allocation once grown). Nothing else on this thread uses it
  // while the seam is analysed: the one nested analysis (the general route below) returns its report directly.
  thread_local SampleSet sampleScratch;
  SampleSet& S = sampleScratch;
  S.t.clear();
  S.s.clear();
  S.m.clear();
  const auto sOfT = [&](double t, double guess) {
    return detail::closestPoint(B.curve, A.curve.point3(t), rep.overlapB, guess).t;
  };
  const int perSpan = std::max(opt.samplesPerSpan, 2);
  if (certified) {
    // Plots (keepSamples) get the dense sampling; otherwise the bound subdivision does the refining.
    const int start = corrBound <= exactFloor ? opt.certifiedSamplesPerPiece : 2 * opt.certifiedSamplesPerPiece;
    const int perPiece = std::max(opt.keepSamples ? opt.samplesPerSpan : start, 2);
    // Shared rows: half as many samples per span (issue 16 goal 2). The gap, angle and curvature jump there are
    // identities (sharedRowBounds); the samples give only the curvature reference of the relative G2 values (whose
    // numerators are round-off bounds: dividing an upper bound by a curvature <= the seam's largest keeps it an
    // upper bound) and the sampled C1/C2 mismatch |lambda - 1| |A_out| of a constant lambda. The plots keep all.
    const int perShared = opt.keepSamples ? perPiece : std::max(perPiece / 2, 2);
    const size_t m = A.spans.size();
    const size_t count = ((shared ? m : 0) + pieces.size()) * static_cast<size_t>(perPiece + 1);
    S.t.reserve(count);
    S.s.reserve(count);
    if (shared)  // the spans correspond one to one, each by the identity of its local parameter
      for (size_t k = 0; k < m; ++k) {
        const Interval sa = A.spans[k], sb = B.spans[rep.reversed ? m - 1 - k : k];
        for (int i = 0; i <= perShared; ++i) {
          const double x = static_cast<double>(i) / perShared;
          S.t.push_back((1.0 - x) * sa.lo + x * sa.hi);
          S.s.push_back(rep.reversed ? x * sb.lo + (1.0 - x) * sb.hi : (1.0 - x) * sb.lo + x * sb.hi);
        }
      }
    for (const Piece& pc : pieces)
      for (int i = 0; i <= perPiece; ++i) {
        const double x = static_cast<double>(i) / perPiece;
        S.t.push_back(pc.tOf.scalar(x));
        S.s.push_back(pc.sOf.scalar(x));
      }
  } else {
    double guess = rep.reversed ? rep.overlapB.hi : rep.overlapB.lo;
    for (size_t k = 0; k < A.spans.size(); ++k) {
      const double lo = std::max(A.spans[k].lo, rep.overlapA.lo), hi = std::min(A.spans[k].hi, rep.overlapA.hi);
      if (!(hi > lo)) continue;
      for (int i = 0; i <= perSpan; ++i) {
        const double t = lo + (hi - lo) * i / perSpan;
        const double s = sOfT(t, guess);
        guess = s;
        S.t.push_back(t);
        S.s.push_back(s);
      }
    }
  }
  // Sort by t (pieces may come in B's order when B is the master).
  if (!std::is_sorted(S.t.begin(), S.t.end())) {
    std::vector<size_t> idx(S.t.size());
    for (size_t i = 0; i < idx.size(); ++i) idx[i] = i;
    std::sort(idx.begin(), idx.end(), [&](size_t x, size_t y) { return S.t[x] < S.t[y]; });
    SampleSet sorted;
    for (size_t i : idx) {
      sorted.t.push_back(S.t[i]);
      sorted.s.push_back(S.s[i]);
    }
    S = std::move(sorted);
  }
  S.m.reserve(S.t.size());
  // Shared rows: the angle and the curvature jump are not sampled, but the plots (keepSamples) get every measure.
  const bool sharedSamples = shared && !opt.keepSamples;
  const bool sameBoundary = sharedSamples && identicalBoundaryRows(A, B, rep.reversed);
  for (size_t i = 0; i < S.t.size(); ++i)
    S.m.push_back(sharedSamples ? measureSharedAt(A, S.t[i], B, S.s[i], sgn, shared->lambda, sameBoundary)
                                : measureAt(A, S.t[i], B, S.s[i], sgn));

  // Curvature reference for relative G2 values: the largest curvature on the seam, floored at "flat".
  const double flat = kFlatCurvatureRatio / std::max(scale, std::numeric_limits<double>::min());
  double curvRef = flat;
  for (const auto& m : S.m) curvRef = std::max(curvRef, m.curvature);

  // Sampled maxima, refined (detail::refineMaxParabolic) (s follows t through the correspondence or projection).
  auto sAt = [&](double t) {
    // Start from the nearest sample's partner and project (on an exact correspondence this is phi(t) to round-off).
    const auto it = std::lower_bound(S.t.begin(), S.t.end(), t);
    const size_t i = std::min<size_t>(static_cast<size_t>(it - S.t.begin()), S.t.size() - 1);
    return sOfT(t, S.s[i]);
  };
  auto pointMeasure = [&](double t) { return measureAt(A, t, B, sAt(t), sgn); };
  // Sampled maxima follow the correspondence; the refinement (which re-projects) only where the
  // correspondence is itself a projection. Certified seams are refined by the subdivision of the bounds instead.
  auto refined = [&](auto get) {
    if (certified && !S.m.empty()) {  // std::max_element's choice (the first maximum), without a vector
      size_t best = 0;
      double value = get(S.m[0]);
      for (size_t i = 1; i < S.m.size(); ++i) {
        const double vi = get(S.m[i]);
        if (value < vi) value = vi, best = i;
      }
      return std::pair{S.t[best], value};
    }
    std::vector<double> v(S.m.size());
    for (size_t i = 0; i < v.size(); ++i) v[i] = get(S.m[i]);
    if (certified) {
      const auto it = std::max_element(v.begin(), v.end());
      const size_t i = static_cast<size_t>(it - v.begin());
      return std::pair{S.t[i], *it};
    }
    return refinedMaximum(S.t, v, [&](double t) { return get(pointMeasure(t)); });
  };
  bool anyDegenerate = false;
  for (const auto& m : S.m) anyDegenerate |= !m.curvatureOk;
  if (anyDegenerate) rep.notes.push_back("the normal vanishes somewhere on the seam (pole or degenerate edge)");

  // G0 sampled: closest-point distance both ways (parametrisation independent). On an exact correspondence the
  // distance is below the certified round-off bound already, and the projections are skipped.
  if (corrBound <= exactFloor) {
    const auto it = std::max_element(S.m.begin(), S.m.end(), [](auto& x, auto& y) { return x.g0 < y.g0; });
    rep.g0Sampled = it->g0;
    rep.g0Worst = {S.t[static_cast<size_t>(it - S.m.begin())], it->point};
  } else {
    std::vector<double> d1(S.t.size());
    for (size_t i = 0; i < S.t.size(); ++i)
      d1[i] = detail::closestPoint(B.curve, S.m[i].point, rep.overlapB, S.s[i]).distance;
    auto f = [&](double t) {
      return detail::closestPoint(B.curve, A.curve.point3(t), rep.overlapB, sAt(t)).distance;
    };
    auto [tw, w] = refinedMaximum(S.t, d1, f);
    double other = 0.0;
    for (size_t i = 0; i < S.s.size(); ++i)
      other = std::max(other, detail::closestPoint(A.curve, B.curve.point3(S.s[i]), rep.overlapA,
                                                   S.t[i]).distance);
    rep.g0Sampled = std::max(w, other);
    rep.g0Worst = {tw, pointOnA(tw)};
  }
  {
    auto [tw, w] = refined([](const PointMeasures& m) { return m.normalsOk ? m.g1 : 0.0; });
    rep.g1SampledDeg = w * kRadToDeg;
    rep.g1Worst = {tw, pointOnA(tw)};
  }
  {
    auto [tw, w] = refined([](const PointMeasures& m) { return m.curvatureOk ? m.g2 : 0.0; });
    rep.g2Sampled = w;
    rep.g2RelSampled = w / curvRef;
    rep.g2Worst = {tw, pointOnA(tw)};
  }
  double lamLo = std::numeric_limits<double>::infinity(), lamHi = -lamLo, kapLo = lamLo, kapHi = -lamLo;
  double c1 = 0.0, c1s = 0.0, c2 = 0.0, c2s = 0.0;
  for (const auto& m : S.m) {
    if (m.curvatureOk) {
      lamLo = std::min(lamLo, m.lambda);
      lamHi = std::max(lamHi, m.lambda);
      kapLo = std::min(kapLo, m.kappa);
      kapHi = std::max(kapHi, m.kappa);
      rep.g2ResidualMax = std::max(rep.g2ResidualMax, std::abs(m.residual));
    }
    c1 = std::max(c1, m.c1);
    c1s = std::max(c1s, m.c1Scale);
    c2 = std::max(c2, m.c2);
    c2s = std::max(c2s, m.c2Scale);
  }
  if (lamLo <= lamHi) {
    rep.lambdaRange = {lamLo, lamHi};
    rep.kappaRange = {kapLo, kapHi};
  }
  rep.c1Mismatch = c1s > 0.0 ? c1 / c1s : 0.0;
  rep.c2Mismatch = c2s > 0.0 ? c2 / c2s : 0.0;
  if (opt.keepSamples)
    for (size_t i = 0; i < S.t.size(); ++i)
      rep.samples.push_back({S.t[i], S.m[i].g0, S.m[i].g1 * kRadToDeg, S.m[i].g2, S.m[i].g2 / curvRef});

  // ---- certified bounds and identities.
  rep.certified = certified;
  rep.g0Max = rep.g0Sampled;
  rep.g1MaxDeg = rep.g1SampledDeg;
  rep.g2Max = rep.g2Sampled;
  bool c1Identity = false, c2Identity = false;
  if (certified && shared) {
    // Bounds from the rows (sharedRowBounds): G1 and G2 hold as identities up to rounding, with these bounds. A G2
    // bound above the identity floor of this seam's curvature, or samples that contradict the identities, send the
    // seam to the general route (rare: the rows agree to rounding).
    if (!(shared->g2 <= kIdentityBoundFactor * kIdentityRelTol * curvRef) || !(rep.g1SampledDeg <= opt.tol.angleDeg) ||
        !(rep.g2Sampled <= opt.tol.curvatureRel * curvRef)) {
      SeamOptions general = opt;
      general.sharedRows = false;
      return analyzeSeamScaled(pa, ea, pb, eb, general, aRange, patchDiagA, patchDiagB);
    }
    rep.g0Max = std::max(corrBound, rep.g0Sampled);
    rep.g1MaxDeg = std::max(shared->g1 * kRadToDeg, rep.g1SampledDeg);
    rep.g1Identity = true;
    if (!opt.certifyG2) {
      rep.notes.push_back("G2 not certified (not requested): the G2 values are samples");
    } else {
      rep.g2Identity = true;
      rep.g2Max = std::max(shared->g2, rep.g2Sampled);
    }
    c1Identity = shared->c1 <= kIdentityRelTol * c1s;
    c2Identity = shared->c2 <= kIdentityRelTol * std::max(c2s, c1s);
  } else if (certified) {
    auto tAt = [&](int piece, double x) { return pieces[static_cast<size_t>(piece)].tOf.scalar(x); };
    // G2 values that are not bounded: the sampled maximum refined by golden section, as for uncertified seams.
    auto refineG2 = [&] {
      std::vector<double> v(S.m.size());
      for (size_t i = 0; i < v.size(); ++i) v[i] = S.m[i].curvatureOk ? S.m[i].g2 : 0.0;
      auto [tw, w] = refinedMaximum(S.t, v, [&](double t) {
        const PointMeasures m = pointMeasure(t);
        return m.curvatureOk ? m.g2 : 0.0;
      });
      if (w > rep.g2Sampled) {
        rep.g2Sampled = w;
        rep.g2Worst = {tw, pointOnA(tw)};
      }
      rep.g2Max = std::max(rep.g2Max, rep.g2Sampled);
    };
    bool ok = true;
    {
      // The correspondence search already certified the distance bound on these very pieces.
      rep.g0Max = std::max(corrBound, rep.g0Sampled);
    }
    {
      double best = rep.g1SampledDeg / kRadToDeg, bx = 0.0;
      int bp = -1;
      const double bound = certifyMax(pieces, g1Bound, g1Value, best, bx, bp, kAngleBoundFloor, opt, ok);
      rep.g1MaxDeg = bound * kRadToDeg;
      if (bp >= 0 && best * kRadToDeg > rep.g1SampledDeg) {
        rep.g1SampledDeg = best * kRadToDeg;
        const double t = tAt(bp, bx);
        rep.g1Worst = {t, pointOnA(t)};
      }
      if (!ok) {
        rep.notes.push_back("the G1 bound could not be closed near a vanishing normal");
        rep.g1MaxDeg = std::max(rep.g1SampledDeg, rep.g1MaxDeg);
      }
    }
    // G1 identity: NA x NB == 0 and no fold; or, where composition and elevation cost more digits than the
    // coefficient test allows, a closed certified angle bound at the round-off floor of the subdivision.
    bool coeffIdentity = true, fold = false;
    for (const Piece& pc : pieces) {
      if (pc.cross.maxAbsCoeff() > kIdentityRelTol * pc.crossScale) coeffIdentity = false;
      if (detail::lowerBound(pc.P) < 0.0) fold = true;
    }
    for (const auto& m : S.m)
      if (m.normalsOk && m.g1 > std::numbers::pi / 2) fold = true;
    const bool angleAtRoundoff = ok && rep.g1MaxDeg <= kIdentityBoundFactor * kAngleBoundFloor * kRadToDeg;
    rep.g1Identity = (coeffIdentity && !fold) || angleAtRoundoff;
    if (rep.g1Identity && !ok) {
      // N_A x N_B vanishes as a polynomial: tangent planes agree wherever the normals are defined. The quotient
      // bound cannot close at the pole itself, so the angle shown is the sampled one (one-sided limits there).
      rep.g1MaxDeg = rep.g1SampledDeg;
      rep.notes.push_back("G1 proved as an identity (N_A x N_B = 0); the angle shown is sampled (one-sided limits "
                          "of the normal at the pole)");
    }
    if (rep.g1Identity && !(rep.g1SampledDeg <= opt.tol.angleDeg)) {
      // Never a class that contradicts its own numbers: samples above tolerance overrule a coefficient test.
      rep.g1Identity = false;
      rep.certified = certified = false;
      rep.notes.push_back(fmt::format("not certified: the G1 identity test and the sampled angle ({:.6g} deg) "
                                      "disagree next to a vanishing normal",
                                      rep.g1SampledDeg));
    }
    // G2: only meaningful for a G1 seam.
    bool g2Ready = rep.g1Identity;
    for (const Piece& pc : pieces) g2Ready = g2Ready && pc.g2Available;
    if (!opt.certifyG2) {
      rep.notes.push_back("G2 not certified (not requested): the G2 values are samples");
    } else if (g2Ready) {
      rep.g2Identity = true;
      for (const Piece& pc : pieces)
        if (pc.rho.num.maxAbsCoeff() > kIdentityRelTol * pc.rhoScale) rep.g2Identity = false;
      double best = rep.g2Sampled, bx = 0.0;
      int bp = -1;
      bool g2ok = true;
      // A midpoint whose chart is too ill-conditioned for curvature (next to a pole) means the quotient bound
      // cannot close there (it divides by the vanishing normal): stop at once instead of spending maxBoundWork.
      bool illConditioned = false;
      const auto g2Checked = [&illConditioned](const Piece& pc, double x) {
        const auto v = g2ValueIfDefined(pc, x);
        if (!v) illConditioned = true;
        return v.value_or(0.0);
      };
      const double bound =
          certifyMax(pieces, g2Bound, g2Checked, best, bx, bp, kIdentityRelTol * curvRef, opt, g2ok, &illConditioned);
      if (bp >= 0 && best > rep.g2Sampled) {
        rep.g2Sampled = best;
        const double t = tAt(bp, bx);
        rep.g2Worst = {t, pointOnA(t)};
      }
      if (g2ok) {
        rep.g2Max = std::max(bound, rep.g2Sampled);
        if (rep.g2Max <= kIdentityBoundFactor * kIdentityRelTol * curvRef) rep.g2Identity = true;
      }
      if (rep.g2Identity && (!g2ok || rep.g2Max > opt.tol.curvatureRel * curvRef)) {
        // The Lemma 2 residual vanishes as a polynomial (G2 wherever the normal is defined) but the quotient bound
        // divides by a normal that vanishes at a pole: the jump shown is the sampled one, never the bound.
        rep.notes.push_back("G2 proved as an identity (Lemma 2 residual zero); its bound does not close next to a "
                            "vanishing normal: the jump shown is sampled");
        refineG2();
        rep.g2Max = rep.g2Sampled;
        if (!(rep.g2Sampled <= opt.tol.curvatureRel * curvRef)) {
          rep.g2Identity = false;
          rep.notes.push_back("the G2 identity test and the sampled jump disagree: G2 not certified");
        }
      } else if (!g2ok) {
        rep.notes.push_back("G2 bound not closed near a vanishing normal: G2 values are sampled");
        refineG2();
      }
    } else {
      if (!rep.g1Identity)
        rep.notes.push_back("not exactly G1: the G2 jump is sampled (refined maximum)");
      else
        rep.notes.push_back(fmt::format("the G2 polynomial exceeds degree {} (maxCertifiedDegree): G2 is sampled",
                                        opt.maxCertifiedDegree));
      refineG2();
    }
    // Connecting functions: from the exact Lemma 1 polynomials instead of the start samples.
    if (rep.g1Identity) lemma1Ranges(pieces, rep.lambdaRange, rep.kappaRange);
    // Parametric identities: certified bounds of |B'_u - A_out| and |B'_uu - A'_uu| at round-off level.
    c1Identity = c2Identity = true;
    for (const Piece& pc : pieces) {
      const SubPiece sp(pc, 0.0, 1.0);
      if (pc.c1.num.maxCoeffNorm() / sp.denLower(pc.c1) > kIdentityRelTol * c1s) c1Identity = false;
      if (pc.c2.num.maxCoeffNorm() / sp.denLower(pc.c2) > kIdentityRelTol * std::max(c2s, c1s)) c2Identity = false;
    }
  }
  rep.g2RelMax = rep.g2Max / curvRef;
  rep.g2RelSampled = rep.g2Sampled / curvRef;

  // ---- the ends: the gap of a seam includes the distance between its matched end points.
  rep.endMismatch = endMismatch;
  if (endMismatch > rep.g0Max) {
    rep.notes.push_back(fmt::format("the edges' end points are {:.6g} apart at t = {:.6g}, more than the gap of {:.6g} "
                                    "between the edges elsewhere: one edge runs past the other; the gap shown "
                                    "includes the ends",
                                    endMismatch, endMismatchT, rep.g0Max));
    rep.g0Max = endMismatch;
    rep.g0Worst = {endMismatchT, endMismatchPoint};
  }
  rep.g0Sampled = std::max(rep.g0Sampled, endMismatch);

  // ---- classification.
  const auto& tol = opt.tol;
  reconcileVerdict(rep, tol);
  // Without the G2 certificate a certified seam is claimed G1 at most (G2 from samples alone is not a verdict).
  if (!opt.certifyG2 && rep.certified && rep.geometric == GeometricClass::kG2) rep.geometric = GeometricClass::kG1;
  // Parametric continuity only where the parametrisations match: affine correspondence with |slope| = 1.
  const double slope = rep.overlapB.length() / rep.overlapA.length();
  const bool matching = rep.correspondence == Correspondence::kAffine && std::abs(slope - 1.0) <= kMatchingSlopeTol;
  if (!matching) {
    rep.notes.push_back(fmt::format("edge parametrisations differ (correspondence {}, slope {:.6g}): no C^k",
                                    toString(rep.correspondence), slope));
  } else if (rep.g0Max <= tol.distance) {
    rep.parametric = ParametricClass::kC0;
    if (c1Identity || rep.c1Mismatch <= tol.parametric) {
      rep.parametric = ParametricClass::kC1;
      if (c2Identity || rep.c2Mismatch <= tol.parametric) rep.parametric = ParametricClass::kC2;
    }
  }
  return rep;
}

}  // namespace detail


// ---------------------------------------------------------------------------------------------------------------
// Seams along parameter curves (trimmed B-rep edges): certified G0 / G1 by composition.

namespace {

/// Deepest bisection while isolating the knot-line crossings of a pcurve (2^-60 of a pcurve piece).
constexpr int kPCurveSplitDepth = 60;
/// Bisection steps for a crossing of a monotone pcurve coordinate with a knot line (to the last bit).
constexpr int kCrossingBisections = 80;
/// Start samples per composed piece (the bound subdivision refines).
constexpr int kPCurveSamplesPerPiece = 8;
/// A chart whose two directions make an angle with sine below this is ill-conditioned at that point (a pole):
/// its curvature samples are skipped, for the curvature reference and for refuting a G2 identity.
constexpr double kChartRegularSin = 1e-3;

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
std::optional<size_t> spanOf(const std::vector<Interval>& spans, double lo, double hi, Interval face) {
  const double range = spans.back().hi - spans.front().lo;
  const double slack = kKnotRelTol * range, endSlack = kPCurveDomainSlackRel * range;
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
/// next to a pole the curvature of a chart is round-off divided by a vanishing normal).
std::optional<double> chartCurvature(const CartesianSide& A, const CartesianSide& B, const Piece& pc, double x) {
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
    out = std::max(out, spectralNorm(shapeInFrame(a, t, suu, suv, svv, nh, e1, e2)));
  }
  return out;
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
  }
  // A side is rational when its surface or its pcurve is (x / w after composition).
  const bool ra = a.surface->isRational() || a.pcurve.isRational(), rb = b.surface->isRational() || b.pcurve.isRational();
  // Each side's spans: the shared ones when given for its surface, else built here.
  std::optional<SpanPatches> ownA, ownB;
  if (!spansA || spansA->surface != a.surface) ownA.emplace(spanPatches(*a.surface));
  if (!spansB || spansB->surface != b.surface) ownB.emplace(spanPatches(*b.surface));
  const SpanPatches& spA = ownA ? *ownA : spansA->patches;
  const SpanPatches& spB = ownB ? *ownB : spansB->patches;
  const std::vector<BezierCurvePiece> pcA = a.pcurve.bezierPieces(), pcB = b.pcurve.bezierPieces();
  auto toB = [&](double t) { return b.range.lo + (t - a.range.lo) / a.range.length() * b.range.length(); };
  // Cuts: the range ends and both pcurves' breakpoints (B's mapped into A's parameter).
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
  {
    const double minGap = detail::kSameBreakpointRel * a.range.length();
    std::vector<double> kept{cuts.front()};
    for (size_t i = 1; i + 1 < cuts.size(); ++i)
      if (cuts[i] - kept.back() > minGap && a.range.hi - cuts[i] > minGap) kept.push_back(cuts[i]);
    kept.push_back(a.range.hi);
    cuts = std::move(kept);
  }

  std::vector<PCurveLeaf> leaves;
  // Splits [t0, t1] until each side's pcurve lies in one span of its surface; at an exact crossing where the
  // coordinate is monotone, else in the middle.
  std::function<bool(double, double, int)> split = [&](double t0, double t1, int depth) -> bool {
    PCurveLeaf L;
    L.t0 = t0;
    L.t1 = t1;
    L.ca = pcurveOn(pcA, t0, t1);
    L.cb = pcurveOn(pcB, toB(t0), toB(t1));
    double cutAt = -1.0;
    bool ok = true;
    auto place = [&](const PCurvePiece& c, const SpanPatches& sp, const PCurveSide& side, size_t& iu, size_t& iv) {
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
        const auto idx = spanOf(spans, lo, hi, k == 0 ? side.faceU : side.faceV);
        if (!idx) return false;
        (k == 0 ? iu : iv) = *idx;
      }
      return true;
    };
    if (!place(L.ca, spA, a, L.aiu, L.aiv) || !place(L.cb, spB, b, L.biu, L.biv)) return false;
    if (ok) {
      leaves.push_back(std::move(L));
      return true;
    }
    if (depth >= kPCurveSplitDepth) return false;
    const double x = cutAt > 0.0 && cutAt < 1.0 ? cutAt : 0.5;
    const double tm = t0 + x * (t1 - t0);
    if (!(tm > t0 && tm < t1)) return false;
    return split(t0, tm, depth + 1) && split(tm, t1, depth + 1);
  };
  for (size_t i = 0; i + 1 < cuts.size(); ++i)
    if (!split(cuts[i], cuts[i + 1], 0))
      return Status(ErrorCode::kUnsupported,
                    "pcurve seam: a pcurve leaves its surface's domain or its knot-line crossings cannot be isolated");

  // Exact data per leaf, in the same form as the patch seams (g0 and G1 only). The leaves are composed on the
  // calling thread's arena (each leaf a pure function of its own data: the same values on any number of threads,
  // so that one heavy seam does not hold a core alone), then taken in leaf order.
  std::vector<Piece> pieces(leaves.size());
  std::vector<std::array<std::array<BernsteinPoly, 3>, 2>> composed(leaves.size());  // A's and B's ComposedSide::h
  auto composeLeaf = [&](size_t li) {
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
    composed[li] = {std::move(A.h), std::move(B.h)};
  };
  // As many leaves at a time as the arena has threads (one: the loop of one leaf after the other), each batch
  // checked in leaf order before the next is composed: a degree above the limit ends the route after at most a
  // batch of leaves, as the serial loop ended it after one.
  const size_t batch = static_cast<size_t>(std::max(1, tbb::this_task_arena::max_concurrency()));
  PCurveSeamBounds out;
  for (size_t first = 0; first < leaves.size(); first += batch) {
    const size_t last = std::min(leaves.size(), first + batch);
    if (last - first > 1) tbb::parallel_for(first, last, composeLeaf);
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
  const double edgeScale = std::max(controlDiagonal(*a.surface), controlDiagonal(*b.surface));
  // Start samples, then the certified maxima (the subdivision raises the best values it meets).
  auto [g0Best, g0x, g0p] = bestSample(pieces, g0Value);
  auto [g1Best, g1x, g1p] = bestSample(pieces, g1Value);
  bool ok0 = true, ok1 = true;
  out.g0Bound = certifyMax(pieces, g0Bound, g0Value, g0Best, g0x, g0p, kRoundoff * edgeScale, opt, ok0);
  const double g1b = certifyMax(pieces, g1Bound, g1Value, g1Best, g1x, g1p, kAngleBoundFloor, opt, ok1);
  if (!ok0 || !ok1)
    return Status(ErrorCode::kUnsupported, "pcurve seam: a bound could not be closed (vanishing normal)");
  out.g0Sampled = g0Best;
  out.g0At = pieces[static_cast<size_t>(g0p)].tOf.scalar(g0x);
  out.g1BoundDeg = g1b * kRadToDeg;
  out.g1SampledDeg = g1Best * kRadToDeg;
  out.g1At = pieces[static_cast<size_t>(g1p)].tOf.scalar(g1x);
  bool coeffIdentity = true, fold = false;
  for (const Piece& pc : pieces) {
    if (pc.cross.maxAbsCoeff() > kIdentityRelTol * pc.crossScale) coeffIdentity = false;
    if (detail::lowerBound(pc.P) < 0.0) fold = true;
  }
  out.g1Identity =
      (coeffIdentity && !fold) || out.g1BoundDeg <= kIdentityBoundFactor * kAngleBoundFloor * kRadToDeg;
  if (!out.g1Identity) {
    out.g2Why = "not exactly G1";
    return out;
  }

  // G2 through the charts S(c(t) + s d(t)) of both faces: the same Lemma 2 polynomials as for patch seams.
  std::vector<Piece> g2Pieces;
  double curvMax = 0.0;
  std::vector<std::array<double, 2>> regular;  // (jump, curvature) at the well-conditioned start samples
  bool built = true;
  // Per leaf on the arena as the G1 data above (pure functions of the leaf), then taken in leaf order: the first
  // leaf above the degree limit ends the G2 route as the loop did, the samples are replayed in their order.
  struct G2Leaf {
    bool tooHigh = false;
    Piece pc;
    std::array<std::optional<double>, kPCurveSamplesPerPiece + 1> curvature;  // chartCurvature at the samples
    std::array<double, kPCurveSamplesPerPiece + 1> jump{};                      // g2Value there (g2Available)
  };
  std::vector<G2Leaf> g2Leaves(leaves.size());
  auto buildG2Leaf = [&](size_t li) {
    const PCurveLeaf& L = leaves[li];
    G2Leaf& g = g2Leaves[li];
    const std::array<BernsteinPoly, 3> XA = chartRows(spA, L.aiu, L.aiv, L.ca, a.surface->isRational(),
                                                      composed[li][0]),
                                       XB = chartRows(spB, L.biu, L.biv, L.cb, b.surface->isRational(),
                                                      composed[li][1]);
    const CartesianSide CA = cartesian(XA[0], XA[1], XA[2], ra, 0), CB = cartesian(XB[0], XB[1], XB[2], rb, 1);
    // Checked before building anything: a piece above the limit would cost products of polynomials of degree
    // several hundred for nothing.
    if (lemma2Degree(CA, CB, ra ? XA[0].degree() : 0, rb ? XB[0].degree() : 0) > opt.maxCertifiedDegree) {
      g.tooHigh = true;
      return;
    }
    // The G2 data only (the G1 bound came from the composed normals above), from the Cartesian sides just formed.
    g.pc = buildPiece(CA, CB, ra ? XA[0].component(XA[0].dim() - 1) : BernsteinPoly::constant(1.0),
                      rb ? XB[0].component(XB[0].dim() - 1) : BernsteinPoly::constant(1.0),
                      BernsteinPoly::linear(L.t0, L.t1), BernsteinPoly::linear(toB(L.t0), toB(L.t1)),
                      opt.maxCertifiedDegree, PieceData::kG2Only);
    for (int k = 0; k <= kPCurveSamplesPerPiece; ++k) {
      const double x = static_cast<double>(k) / kPCurveSamplesPerPiece;
      g.curvature[static_cast<size_t>(k)] = chartCurvature(CA, CB, g.pc, x);
      if (g.curvature[static_cast<size_t>(k)] && g.pc.g2Available) g.jump[static_cast<size_t>(k)] = g2Value(g.pc, x);
    }
  };
  bool tooHigh = false;
  for (size_t first = 0; first < leaves.size() && !tooHigh; first += batch) {  // in batches, as the G1 data
    const size_t last = std::min(leaves.size(), first + batch);
    if (last - first > 1) tbb::parallel_for(first, last, buildG2Leaf);
    else buildG2Leaf(first);
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
  out.curvatureMax = curvMax;
  if (!built) {
    out.g2Why = fmt::format("the G2 polynomials exceed degree {} (maxCertifiedDegree)", opt.maxCertifiedDegree);
    return out;
  }
  const double flat = kFlatCurvatureRatio / std::max(edgeScale, std::numeric_limits<double>::min());
  const double curvRef = std::max(curvMax, flat);
  auto [g2Best, g2x, g2p] = bestSample(g2Pieces, g2Value);
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
    const auto v = g2ValueIfDefined(pc, x);
    if (!v) illConditioned = true;
    return v.value_or(0.0);
  };
  const double g2b = certifyMax(g2Pieces, g2Bound, g2Checked, g2Best, g2x, g2p, floor, opt, ok2, &illConditioned);
  // Near a vanishing normal the quotient bound cannot close: it ends above the sampled maximum by more than the
  // subdivision's target gap (or infinite). Such a bound says nothing useful and is not reported.
  if (!ok2 || !(g2b <= (1.0 + opt.boundRelGap) * g2Best + floor)) {
    out.g2Why = "the G2 bound could not be closed (vanishing normal)";
    return out;
  }
  out.g2Certified = true;
  out.g2Bound = std::max(g2b, g2Best);
  out.g2Sampled = g2Best;
  out.g2At = g2Pieces[static_cast<size_t>(g2p)].tOf.scalar(g2x);
  out.g2Identity = rhoIdentity || out.g2Bound <= kIdentityBoundFactor * floor;
  return out;
}

}  // namespace seam
