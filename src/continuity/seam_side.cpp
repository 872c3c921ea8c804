// One side of a patch seam seen from its edge: its cross-derivative rows, the derivative jets along the edge and the
// pointwise measures of the sampled route (continuity/seam_side.h).
#include "continuity/seam_side.h"

#include <cassert>

#include <algorithm>
#include <cmath>
#include <optional>

#include "continuity/sampling.h"
#include "continuity/seam_internal.h"
#include "spline/spline_internal.h"
#include "seam/core/tolerances.h"

namespace seam::detail {

namespace {

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

}  // namespace

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

/// S, S_u, S_v, S_uu, S_uv, S_vv of the oriented surface at (u = edge, v = t) from the cross-derivative Bezier pieces
/// of the side (homogeneous; the quotient rule for rational sides). The same values as the surface's own evaluator
/// to round-off, at a fraction of its cost. Spans are non-empty (decompose drops empty ones). `fused` false: always
/// the generic route (the test hook detail::sideJet compares the two).
void edgeJet(const Side& s, double t, std::array<Vec3, 6>& out, bool fromRight, bool fused) {
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

// sgn = +1 when B's edge parameter s increases with A's t, -1 otherwise. (Seams that share their control rows take
// measureSharedAt instead, except for the plots' dense samples.)
PointMeasures measureAt(const Side& A, double t, const Side& B, double s, double sgn, bool g2Only) {
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
  const Vec3 nA = T.cross(O), nB = Bt.cross(Bc);
  if (g2Only) {
    // The full measure's curvature branch: a vanishing normal (or tangent: then nA = 0) or an ill-conditioned chart
    // leaves the curvature unmeasured, as the limit normals' test below and the one after it do.
    const double la = nA.norm(), lb = nB.norm();
    if (!(la > 0.0) || !(lb > 0.0) || chartConditioning(T, O) < kCurvatureChartRel ||
        chartConditioning(Bt, Bc) < kCurvatureChartRel) {
      m.normalsOk = la > 0.0 && lb > 0.0;
      m.curvatureOk = false;
      return m;
    }
    const Vec3 nhA = nA / la, nhB = nB / lb;
    const Vec3 e1 = T.normalized(), e2 = nhA.cross(e1);
    m.g2 = spectralNorm(shapeInFrame(db[1], db[2], db[3], db[4], db[5], nhB, e1, e2) -
                        shapeInFrame(da[1], da[2], da[3], da[4], da[5], nhA, e1, e2));
    return m;
  }
  m.g0 = (a - b).norm();
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

double controlDiagonal(const BSplineSurface& s) { return controlBox(s).diagonal(); }

void sideCrossRows(const BSplineSurface& s, Edge e, Matrix& rows) { crossDerivativeRowsInto(s, e, rows); }

std::array<Vec3, 6> sideJet(const Patch& p, Edge e, double t, bool fromRight, bool fused) {
  const Side s = makeSide(p, e);
  std::array<Vec3, 6> out;
  edgeJet(s, t, out, fromRight, fused);
  return out;
}

}  // namespace seam::detail
