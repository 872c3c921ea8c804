#pragma once
// Helpers for seam_test.cpp: exact constructions of patch pairs whose seam answers are known by construction, and
// an INDEPENDENT dense reference for the seam measures.
//
// Independence rule: nothing here calls analyzeSeam (or anything in seam/continuity). The reference measures use
// only the kernel's surface evaluation and derivatives (BSplineSurface::derivatives, boundaryCurve, orientedFrom),
// which the kernel tests verify against Cox-de Boor / explicit Bernstein sums. Constructions use only knot
// insertion, Bernstein products / elevation / composition and plain control-point arithmetic.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <numbers>
#include <optional>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "seam/continuity/seam.h"
#include "seam/core/bernstein.h"
#include "seam/core/types.h"
#include "seam/model/model.h"
#include "seam/repair/bicubic.h"
#include "seam/spline/bezier.h"
#include "seam/spline/bspline_surface.h"

namespace seam::seamtest {

using Rng = std::mt19937_64;

inline double urand(Rng& rng, double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); }
inline int irand(Rng& rng, int a, int b) { return std::uniform_int_distribution<int>(a, b)(rng); }
/// A point with coordinates uniform in [a, b], drawn z, y, x (test_helpers.h, "Random draws and argument order": the
/// order GCC evaluated Vec3(urand(..), urand(..), urand(..)) in, which this replaces).
inline Vec3 randomVec3(Rng& rng, double a, double b) {
  const double z = urand(rng, a, b), y = urand(rng, a, b), x = urand(rng, a, b);
  return {x, y, z};
}
/// Uniform in [lo, hi] but never in the open band (1/away, away) around 1 (so a random factor is clearly not 1).
inline double factorAwayFromOne(Rng& rng, double lo, double hi, double away) {
  for (;;) {
    const double f = urand(rng, lo, hi);
    if (f <= 1.0 / away || f >= away) return f;
  }
}

inline constexpr double kPi = std::numbers::pi;
inline double degrees(double rad) { return rad * 180.0 / kPi; }
inline double radians(double deg) { return deg * kPi / 180.0; }

/// Angle between two vectors in degrees, accurate near 0 and 180 (atan2 of |a x b| and a.b).
inline double angleDeg(const Vec3& a, const Vec3& b) { return degrees(std::atan2(a.cross(b).norm(), a.dot(b))); }

inline Vec3 v3(const VecX& v) { return Vec3(v[0], v[1], v[2]); }

/// A rotation from a normalised random quaternion (own generator: no global RNG state).
inline Eigen::Matrix3d randomRotation(Rng& rng) {
  std::normal_distribution<double> g;
  // (Drawn last argument first: test_helpers.h, "Random draws and argument order".)
  const double z = g(rng), y = g(rng), x = g(rng), w = g(rng);
  Eigen::Quaterniond q(w, x, y, z);
  q.normalize();
  return q.toRotationMatrix();
}

/// Applies x -> R x + c to every control point (rigid motion: geometry, angles and curvatures unchanged).
inline BSplineSurface transformed(const BSplineSurface& s, const Eigen::Matrix3d& r, const Vec3& c) {
  Matrix p = s.points();
  for (Eigen::Index i = 0; i < p.rows(); ++i) p.row(i) = (r * p.row(i).transpose() + c).transpose();
  return BSplineSurface(s.degreeU(), s.degreeV(), s.knotsU(), s.knotsV(), s.numU(), s.numV(), std::move(p),
                        s.weights());
}
inline BSplineSurface translated(const BSplineSurface& s, const Vec3& d) {
  return transformed(s, Eigen::Matrix3d::Identity(), d);
}
/// The same surface with every weight multiplied by `factor` (rational surfaces only): identical geometry.
inline BSplineSurface weightsScaled(const BSplineSurface& s, double factor) {
  return BSplineSurface(s.degreeU(), s.degreeV(), s.knotsU(), s.knotsV(), s.numU(), s.numV(), s.points(),
                        s.weights() * factor);
}

inline Patch makePatch(std::string name, BSplineSurface s) {
  return Patch{std::move(name), PatchKind::kBSpline, std::move(s)};
}

/// Clamped knot vector on [lo, hi] for `numPoints` points of degree p, interior knots simple and at random
/// positions (span lengths in a ratio of at most 1:3).
inline std::vector<double> randomClampedKnots(Rng& rng, int p, int numPoints, double lo = 0.0, double hi = 1.0) {
  const int spans = numPoints - p;
  std::vector<double> len(static_cast<size_t>(spans));
  double total = 0.0;
  for (auto& l : len) total += (l = urand(rng, 1.0, 3.0));
  std::vector<double> k(static_cast<size_t>(p + 1), lo);
  double acc = 0.0;
  for (int i = 0; i + 1 < spans; ++i) {
    acc += len[static_cast<size_t>(i)];
    k.push_back(lo + (hi - lo) * acc / total);
  }
  for (int i = 0; i <= p; ++i) k.push_back(hi);
  return k;
}

/// Control net of a regular "graph" surface: P_ij = (X_i, Y_j, Z_ij) with X, Y strictly increasing (so the surface
/// is a graph over its (x,y) footprint and its normal never vanishes), heights random in [-amp, amp].
inline Matrix graphNet(Rng& rng, int nu, int nv, double amp) {
  std::vector<double> x(static_cast<size_t>(nu)), y(static_cast<size_t>(nv));
  double a = 0.0;
  for (auto& xi : x) xi = (a += urand(rng, 0.6, 1.4) / nu);
  a = 0.0;
  for (auto& yj : y) yj = (a += urand(rng, 0.6, 1.4) / nv);
  Matrix p(nu * nv, 3);
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j)
      p.row(i * nv + j) << x[static_cast<size_t>(i)], y[static_cast<size_t>(j)], urand(rng, -amp, amp);
  return p;
}

inline VecX randomWeights(Rng& rng, int n, double lo = 0.5, double hi = 2.0) {
  VecX w(n);
  for (int i = 0; i < n; ++i) w[i] = urand(rng, lo, hi);
  return w;
}

/// A random regular B-spline (or NURBS) graph surface of bi-degree (pu, pv) with nu x nv points, clamped knots on
/// [0,1]^2 with random simple interior knots, then moved by a random rigid motion.
inline BSplineSurface randomGraphSurface(Rng& rng, int pu, int pv, int nu, int nv, bool rational, double amp = 0.25) {
  Matrix p = graphNet(rng, nu, nv, amp);
  VecX w = rational ? randomWeights(rng, nu * nv) : VecX();
  KnotVector kv(randomClampedKnots(rng, pv, nv));  // drawn last argument first (test_helpers.h)
  BSplineSurface s(pu, pv, KnotVector(randomClampedKnots(rng, pu, nu)), std::move(kv), nu, nv, std::move(p),
                   std::move(w));
  const Vec3 shift = randomVec3(rng, -2, 2);
  return transformed(s, randomRotation(rng), shift);
}

/// The referee's settings in the repair tests: certified bounds, subdivided only until within 25 % of the sampled
/// worst value (the curvature bounds of G1-but-not-G2 seams are the expensive part and are not under test there).
inline SeamOptions refereeOptions() {
  SeamOptions o;
  o.boundRelGap = 0.25;
  o.maxSubdivisionDepth = 12;
  return o;
}

/// A C1 bicubic graph surface over the given breakpoints: d_ij = (G_i, H_j, z_ij) at the Greville abscissae,
/// heights random in [-amp, amp] (a regular surface, normal never vanishing).
inline BSplineSurface c1Graph(Rng& rng, const std::vector<double>& bu, const std::vector<double>& bv, double amp) {
  const KnotVector ku = c1CubicKnots(bu), kv = c1CubicKnots(bv);
  const int nu = ku.size() - 4, nv = kv.size() - 4;
  Matrix pts(nu * nv, 3);
  auto greville = [](const KnotVector& k, int i) { return (k[i + 1] + k[i + 2] + k[i + 3]) / 3.0; };
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) pts.row(i * nv + j) << greville(ku, i), greville(kv, j), urand(rng, -amp, amp);
  return BSplineSurface(3, 3, ku, kv, nu, nv, std::move(pts));
}

// =====================================================================================================================
// Splitting a B-spline surface at a parameter (written here: knot insertion to full multiplicity, then slicing).
// =====================================================================================================================

/// Splits at u = k (strictly inside the domain) into the parts on [u_min, k] and [k, u_max]. Both keep the original
/// knot values, so together they are the original surface, parametrisation included.
inline std::pair<BSplineSurface, BSplineSurface> splitU(const BSplineSurface& s, double k) {
  const int p = s.degreeU();
  int mult = 0;
  for (double x : s.knotsU().values()) mult += (x == k) ? 1 : 0;
  const BSplineSurface t = (mult < p) ? s.withKnotInsertedU(k, p - mult) : s;
  const std::vector<double>& kn = t.knotsU().values();
  int r = 0;  // first index of the knot k
  while (kn[static_cast<size_t>(r)] != k) {
    ++r;
    if (r >= static_cast<int>(kn.size())) ADD_FAILURE() << "splitU: knot " << k << " not found after insertion";
  }
  // After insertion k has multiplicity p at indices r..r+p-1; the point P_{r-1} lies on the surface at u = k.
  std::vector<double> kl(kn.begin(), kn.begin() + r + p);
  kl.push_back(k);
  std::vector<double> kr{k};
  kr.insert(kr.end(), kn.begin() + r, kn.end());
  const int nv = t.numV();
  const int nl = r, nr = t.numU() - r + 1;
  Matrix pl = t.points().topRows(static_cast<Eigen::Index>(nl) * nv);
  Matrix pr = t.points().bottomRows(static_cast<Eigen::Index>(nr) * nv);
  VecX wl, wr;
  if (t.isRational()) {
    wl = t.weights().head(static_cast<Eigen::Index>(nl) * nv);
    wr = t.weights().tail(static_cast<Eigen::Index>(nr) * nv);
  }
  return {BSplineSurface(p, t.degreeV(), KnotVector(std::move(kl)), t.knotsV(), nl, nv, std::move(pl), std::move(wl)),
          BSplineSurface(p, t.degreeV(), KnotVector(std::move(kr)), t.knotsV(), nr, nv, std::move(pr), std::move(wr))};
}

inline std::pair<BSplineSurface, BSplineSurface> splitV(const BSplineSurface& s, double k) {
  auto [a, b] = splitU(s.swappedUV(), k);
  return {a.swappedUV(), b.swappedUV()};
}

/// The interior knot values of a clamped knot vector of degree p (distinct, increasing).
inline std::vector<double> interiorKnots(const KnotVector& k, int p) {
  std::vector<double> r;
  const auto& v = k.values();
  for (size_t i = static_cast<size_t>(p) + 1; i + static_cast<size_t>(p) + 1 < v.size(); ++i)
    if (r.empty() || r.back() != v[i]) r.push_back(v[i]);
  return r;
}

// =====================================================================================================================
// Bezier constructions.
// =====================================================================================================================

/// Row i of a Bezier patch (the curve v -> sum_j P_ij B_j(v)) as a Bernstein polynomial, homogeneous when rational.
inline BernsteinPoly bezierRow(const BernsteinPatch& h, int i) {
  const int m = h.degreeV();
  return BernsteinPoly(h.coeffs().middleRows(static_cast<Eigen::Index>(i) * (m + 1), m + 1));
}

inline BernsteinPatch patchFromRows(const std::vector<BernsteinPoly>& rows) {
  const int n = static_cast<int>(rows.size()) - 1;
  int m = 0;
  for (const auto& r : rows) m = std::max(m, r.degree());
  Matrix c(static_cast<Eigen::Index>(n + 1) * (m + 1), rows.front().dim());
  for (int i = 0; i <= n; ++i)
    c.middleRows(static_cast<Eigen::Index>(i) * (m + 1), m + 1) = rows[static_cast<size_t>(i)].elevatedTo(m).coeffs();
  return BernsteinPatch(n, m, std::move(c));
}

inline BezierPatch bezierFromHomogeneous(const BernsteinPatch& h, bool rational) {
  return rational ? BezierPatch::fromHomogeneous(h) : BezierPatch(h.degreeU(), h.degreeV(), h.coeffs());
}

/// B(u, w(s)): every row (along v) composed with the scalar polynomial w (exact; degree along v multiplies by
/// deg w). Rational patches are composed in homogeneous coordinates, which is exact for the rational surface too.
inline BezierPatch composedAlongV(const BezierPatch& b, const BernsteinPoly& w) {
  const BernsteinPatch h = b.homogeneous();
  std::vector<BernsteinPoly> rows;
  for (int i = 0; i <= b.degreeU(); ++i) rows.push_back(bezierRow(h, i).composed(w));
  return bezierFromHomogeneous(patchFromRows(rows), b.isRational());
}

/// A random strictly increasing polynomial w: [0,1] -> [0,1] with w(0) = 0, w(1) = 1: Bernstein coefficients
/// 0 = c_0 < c_1 < ... < c_d = 1 make w' a positive combination of Bernstein polynomials. Steps in a ratio <= 1:8
/// keep w' well away from 0 (a clearly regular reparametrisation) and clearly non-affine.
inline BernsteinPoly randomMonotone(Rng& rng, int degree) {
  std::vector<double> step(static_cast<size_t>(degree));
  double total = 0.0;
  for (auto& s : step) total += (s = urand(rng, 0.25, 2.0));
  Matrix c(degree + 1, 1);
  c(0, 0) = 0.0;
  for (int i = 1; i <= degree; ++i) c(i, 0) = c(i - 1, 0) + step[static_cast<size_t>(i - 1)] / total;
  c(degree, 0) = 1.0;
  return BernsteinPoly(std::move(c));
}

/// A random regular graph Bezier patch of bi-degree (n, m), optionally rational, moved by a random rigid motion.
inline BezierPatch randomGraphBezier(Rng& rng, int n, int m, bool rational, double amp = 0.25) {
  const BSplineSurface s = randomGraphSurface(rng, n, m, n + 1, m + 1, rational, amp);
  return BezierPatch(n, m, s.points(), s.weights());
}

// =====================================================================================================================
// Johansson Lemma 1 / Lemma 2 construction (exact, polynomial Bezier).
//
// Both patches are seen from their edge U0 (edge u = 0, parameter t = v along it), as in seam.h:
//   A_out = -A_u(0,t), A_t = A_v(0,t);  B_cross = B_u(0,t).
// B is built so that, exactly as polynomials in t,
//   B_cross = lambda A_out + kappa A_t                                              (Lemma 1, eq. 2.1)
// and, when `g2`,
//   B_uu = lambda^2 A_oo + 2 lambda kappa A_ot + kappa^2 A_tt + mu A_out + nu A_t  (Lemma 2, eq. 3.10)
// with A_oo = A_uu, A_ot = d/dt A_out = -A_uv, A_tt = A_vv (the paper's r^(1)(u, v) is A(1 - u, v)).
// Bezier rows of B (degree nB across, M along):  B_u(0,t) = nB (b_1 - b_0),  B_uu(0,t) = nB (nB-1) (b_2 - 2 b_1 + b_0),
// so b_0 = A's edge row, b_1 = b_0 + target1 / nB, b_2 = 2 b_1 - b_0 + target2 / (nB (nB-1)).
// =====================================================================================================================

struct Lemma1Pair {
  BezierPatch a;  ///< edge U0; along-degree elevated to B's when `elevateA`, else the original
  BezierPatch b;  ///< edge U0
  BernsteinPoly lambda, kappa;
};

inline Lemma1Pair lemma1Pair(Rng& rng, const BezierPatch& a0, const BernsteinPoly& lambda,
                             const BernsteinPoly& kappa, int nB, bool g2, bool elevateA,
                             const BernsteinPoly& mu = BernsteinPoly::constant(0.0),
                             const BernsteinPoly& nu = BernsteinPoly::constant(0.0)) {
  const int n = a0.degreeU();
  const BernsteinPatch h = a0.numerator();  // polynomial patch: the points themselves
  const BernsteinPoly r0 = bezierRow(h, 0), r1 = bezierRow(h, 1);
  const BernsteinPoly aOut = -1.0 * (static_cast<double>(n) * (r1 - r0));
  const BernsteinPoly aT = r0.derivative();
  BernsteinPoly target1 = product(lambda, aOut) + product(kappa, aT);
  std::optional<BernsteinPoly> target2;
  if (g2) {
    const BernsteinPoly r2 = n >= 2 ? bezierRow(h, 2) : BernsteinPoly::zero(r0.degree(), 3);
    const BernsteinPoly aUU = static_cast<double>(n * (n - 1)) * (r2 - 2.0 * r1 + r0);
    const BernsteinPoly aOT = aOut.derivative();  // = -A_uv
    const BernsteinPoly aTT = r0.derivative(2);
    target2 = product(product(lambda, lambda), aUU) + 2.0 * product(product(lambda, kappa), aOT) +
              product(product(kappa, kappa), aTT) + product(mu, aOut) + product(nu, aT);
  }
  int M = std::max(r0.degree(), target1.degree());
  if (target2) M = std::max(M, target2->degree());
  const BernsteinPoly b0 = r0.elevatedTo(M);
  const BernsteinPoly b1 = b0 + (1.0 / nB) * target1.elevatedTo(M);
  std::vector<BernsteinPoly> rows{b0, b1};
  const BernsteinPoly step = b1 - b0;
  for (int i = 2; i <= nB; ++i) {
    BernsteinPoly bi;
    if (i == 2 && target2) {
      bi = 2.0 * b1 - b0 + (1.0 / (nB * (nB - 1))) * target2->elevatedTo(M);
    } else {
      bi = rows.back() + step;  // continue the cross direction, then perturb (generic curvature, so not G2)
      for (Eigen::Index r = 0; r < bi.coeffs().rows(); ++r)
        for (int c = 0; c < 3; ++c) bi.coeffs()(r, c) += urand(rng, -0.3, 0.3);
    }
    rows.push_back(bi);
  }
  const BernsteinPatch hb = patchFromRows(rows);
  BezierPatch a = a0;
  if (elevateA) a = BezierPatch(n, M, h.elevatedTo(n, M).coeffs());
  return {a, BezierPatch(nB, M, hb.coeffs()), lambda, kappa};
}

// =====================================================================================================================
// Independent dense reference for the seam measures.
// =====================================================================================================================

/// One side of a seam seen from its edge (A' = A.orientedFrom(e)): edge u = u0, along parameter t on `along`.
struct SeamSide {
  BSplineSurface s;
  double u0 = 0.0;
  Interval along;
  explicit SeamSide(const BSplineSurface& surf, Edge e)
      : s(surf.orientedFrom(e)), u0(s.domainU().lo), along(s.domainV()) {}
  /// d[k][l] = d^{k+l} / du^k dt^l of the oriented surface on the edge.
  [[nodiscard]] std::vector<std::vector<VecX>> derivs(double t, int order) const { return s.derivatives(u0, t, order); }
};

/// Closest point on the boundary curve `c` (restricted to [lo, hi]) to p: coarse search on `coarse` precomputed
/// points, then safeguarded Newton on f(s) = (c(s) - p) . c'(s). Returns the distance.
class CurveDistance {
 public:
  CurveDistance(BSplineCurve c, Interval range, int coarse = 512) : c_(std::move(c)), r_(range) {
    for (int i = 0; i <= coarse; ++i) {
      const double s = r_.lo + (r_.hi - r_.lo) * i / coarse;
      ss_.push_back(s);
      pts_.push_back(v3(c_.evaluate(s)));
    }
  }
  [[nodiscard]] double distance(const Vec3& p, double* at = nullptr) const {
    size_t best = 0;
    double bd = std::numeric_limits<double>::infinity();
    for (size_t i = 0; i < pts_.size(); ++i) {
      const double d = (pts_[i] - p).squaredNorm();
      if (d < bd) { bd = d; best = i; }
    }
    double s = ss_[best];
    double dist = std::sqrt(bd);
    const double h = (r_.hi - r_.lo) / static_cast<double>(ss_.size() - 1);
    double lo = std::max(r_.lo, s - h), hi = std::min(r_.hi, s + h);
    for (int it = 0; it < 30; ++it) {
      const Matrix d = c_.derivatives(s, 2);
      const Vec3 q = v3(d.row(0).transpose()) - p, d1 = v3(d.row(1).transpose()), d2 = v3(d.row(2).transpose());
      dist = std::min(dist, q.norm());
      const double f = q.dot(d1), fp = d1.squaredNorm() + q.dot(d2);
      double sn = (fp > 0.0) ? s - f / fp : 0.5 * (lo + hi);
      if (!(sn > lo && sn < hi)) sn = std::clamp(sn, lo, hi);
      if (std::abs(sn - s) <= 1e-15 * (1.0 + std::abs(s))) { s = sn; break; }
      s = sn;
    }
    dist = std::min(dist, (v3(c_.evaluate(s)) - p).norm());
    for (double e : {lo, hi}) dist = std::min(dist, (v3(c_.evaluate(e)) - p).norm());
    if (at) *at = s;
    return dist;
  }

 private:
  BSplineCurve c_;
  Interval r_;
  std::vector<double> ss_;
  std::vector<Vec3> pts_;
};

struct RefMeasures {
  double g0 = 0.0;           ///< two-way closest-point distance between the edge curves (over the overlaps)
  double g1Deg = 0.0;        ///< angle between the consistently oriented normals
  double g2 = 0.0;           ///< spectral norm of the shape-operator jump in A's tangent frame
  double g2Rel = 0.0;        ///< g2 / curvScale: relative to the largest curvature on the seam (seam.h's reading)
  double g2RelPointwise = 0.0;  ///< max over t of jump(t) / (larger of the two curvatures at t)
  double curvScale = 0.0;    ///< max over the seam of the larger curvature (for round-off floors)
  double g2Residual = 0.0;   ///< max |n_A . (B_cc - lambda^2 A_oo - 2 lambda kappa A_ot - kappa^2 A_tt)| (Lemma 2)
  double secondScale = 0.0;  ///< max norm of the second partial derivatives of both sides (round-off scale)
  double lambdaMin = std::numeric_limits<double>::infinity(), lambdaMax = -lambdaMin;
  double kappaMin = lambdaMin, kappaMax = -lambdaMin;
  double g1At = 0.0, g2At = 0.0;  ///< A's edge parameter of the worst values
};

/// 2x2 matrix Q with w^T Q w = normal curvature (w.r.t. the unit normal n) in the direction x = F w, where F is an
/// orthonormal 3x2 frame of (nearly) the tangent plane of the surface with partials su, sv, suu, suv, svv at a point.
/// Directions are pulled back by least squares (exact when F spans the tangent plane).
inline Eigen::Matrix2d curvatureInFrame(const Vec3& su, const Vec3& sv, const Vec3& suu, const Vec3& suv,
                                        const Vec3& svv, const Vec3& n, const Eigen::Matrix<double, 3, 2>& frame) {
  Eigen::Matrix<double, 3, 2> j;
  j << su, sv;
  const Eigen::Matrix2d g = j.transpose() * j;
  const Eigen::Matrix2d t = g.ldlt().solve(j.transpose() * frame);  // parameter directions of the frame vectors
  Eigen::Matrix2d h;
  h << n.dot(suu), n.dot(suv), n.dot(suv), n.dot(svv);
  // Normal curvature of direction x = J a is (a^T h a) / (a^T g a); for unit x = F w, a = T w and a^T g a = 1.
  return t.transpose() * h * t;
}
/// Spectral norm of the symmetric part [[a, b], [b, c]]: eigenvalues (a+c)/2 +/- hypot((a-c)/2, b).
inline double spectralNorm(const Eigen::Matrix2d& m) {
  const double a = m(0, 0), c = m(1, 1), b = 0.5 * (m(0, 1) + m(1, 0));
  return std::abs(0.5 * (a + c)) + std::hypot(0.5 * (a - c), b);
}

struct RefOptions {
  int samples = 10000;                        ///< points on A's overlap (both ends included)
  std::function<double(double)> phi;         ///< A's edge parameter -> B's; empty: closest point on B's edge
  Interval aRange{0.0, -1.0};                 ///< A's overlap (empty interval: A's whole edge)
  Interval bRange{0.0, -1.0};                 ///< B's overlap (empty interval: B's whole edge)
  bool g0 = true;                             ///< compute the two-way closest-point distance
  bool g2 = true;                             ///< compute curvature measures
};

inline double identityMap(double t) { return t; }

/// Reference options: `samples` points, correspondence `phi` (empty: closest point), with or without the gap.
inline RefOptions refOpts(int samples, std::function<double(double)> phi, bool g0,
                          Interval aRange = Interval{0.0, -1.0}) {
  RefOptions o;
  o.samples = samples;
  o.phi = std::move(phi);
  o.g0 = g0;
  o.aRange = aRange;
  return o;
}

/// Dense reference of the seam measures between edge ea of A and edge eb of B, from kernel derivatives only.
/// The correspondence is `phi` when given (known by construction), else the closest point on B's edge; B_t is
/// the derivative of b(phi(t)) in t (central difference of phi when phi is given, the projection's direction
/// otherwise), so normals are oriented as in seam.h: n_A = A_t x A_out, n_B = B_t x B_cross.
inline RefMeasures denseReference(const BSplineSurface& A, Edge ea, const BSplineSurface& B, Edge eb,
                                  const RefOptions& o = {}) {
  const SeamSide sa(A, ea), sb(B, eb);
  const Interval ar = o.aRange.lo <= o.aRange.hi ? o.aRange : sa.along;
  const Interval br = o.bRange.lo <= o.bRange.hi ? o.bRange : sb.along;
  const CurveDistance toB(sb.s.boundaryCurve(Edge::U0), br);
  RefMeasures r;
  // Orientation of the correspondence: +1 when B's parameter increases with A's (judged on A's range, or on A's
  // whole edge when the range is a single point).
  double orient = 1.0;
  const Interval judge = ar.hi > ar.lo ? ar : sa.along;
  if (o.phi) {
    orient = (o.phi(judge.hi) > o.phi(judge.lo)) ? 1.0 : -1.0;
  } else {
    double s0 = 0.0, s1 = 0.0;
    (void)toB.distance(v3(sa.derivs(judge.lo, 0)[0][0]), &s0);
    (void)toB.distance(v3(sa.derivs(judge.hi, 0)[0][0]), &s1);
    orient = (s1 > s0) ? 1.0 : -1.0;
  }
  const int order = o.g2 ? 2 : 1;
  for (int i = 0; i < o.samples; ++i) {
    const double t = ar.lo + (ar.hi - ar.lo) * i / (o.samples - 1);
    const auto da = sa.derivs(t, order);
    const Vec3 pa = v3(da[0][0]), aOut = -v3(da[1][0]), aT = v3(da[0][1]);
    double s = 0.0;
    double dist = 0.0;
    if (o.phi) {
      s = o.phi(t);
      if (o.g0) dist = toB.distance(pa);
    } else {
      dist = toB.distance(pa, &s);
    }
    r.g0 = std::max(r.g0, dist);
    const auto db = sb.derivs(s, order);
    const Vec3 bCross = v3(db[1][0]), bS = v3(db[0][1]);
    const Vec3 nA = aT.cross(aOut).normalized();
    const Vec3 nB = (orient * bS).cross(bCross).normalized();
    const double g1 = angleDeg(nA, nB);
    if (g1 > r.g1Deg) { r.g1Deg = g1; r.g1At = t; }
    // Lemma 1 connecting functions: least-squares solve of B_cross = lambda A_out + kappa A_t.
    Eigen::Matrix<double, 3, 2> m;
    m << aOut, aT;
    const Eigen::Vector2d lk = (m.transpose() * m).ldlt().solve(m.transpose() * bCross);
    r.lambdaMin = std::min(r.lambdaMin, lk[0]);
    r.lambdaMax = std::max(r.lambdaMax, lk[0]);
    r.kappaMin = std::min(r.kappaMin, lk[1]);
    r.kappaMax = std::max(r.kappaMax, lk[1]);
    if (o.g2) {
      Eigen::Matrix<double, 3, 2> frame;
      const Vec3 e1 = aT.normalized();
      frame << e1, nA.cross(e1);
      // Shape operators of A and B as quadratic forms in A's orthonormal tangent frame, each with its own oriented
      // normal (n_B = +/- B'_s x B'_u, consistent with n_A across the seam).
      const Eigen::Matrix2d qa = curvatureInFrame(v3(da[1][0]), v3(da[0][1]), v3(da[2][0]), v3(da[1][1]),
                                                  v3(da[0][2]), nA, frame);
      const Eigen::Matrix2d qb = curvatureInFrame(v3(db[1][0]), v3(db[0][1]), v3(db[2][0]), v3(db[1][1]),
                                                  v3(db[0][2]), nB, frame);
      const double jump = spectralNorm(qa - qb);
      const double scale = std::max(spectralNorm(qa), spectralNorm(qb));
      r.curvScale = std::max(r.curvScale, scale);
      if (jump > r.g2) { r.g2 = jump; r.g2At = t; }
      if (scale > 0.0) r.g2RelPointwise = std::max(r.g2RelPointwise, jump / scale);
      // Lemma 2 residual with A_oo = A'_uu, A_ot = d/dt A_out = -A'_ut, A_tt = A'_tt, B_cc = B'_uu.
      const Vec3 res = v3(db[2][0]) - lk[0] * lk[0] * v3(da[2][0]) + 2.0 * lk[0] * lk[1] * v3(da[1][1]) -
                       lk[1] * lk[1] * v3(da[0][2]);
      r.g2Residual = std::max(r.g2Residual, std::abs(nA.dot(res)));
      for (const Vec3& d2 : {v3(da[2][0]), v3(da[1][1]), v3(da[0][2]), v3(db[2][0]), v3(db[1][1]), v3(db[0][2])})
        r.secondScale = std::max(r.secondScale, d2.norm());
    }
  }
  if (r.curvScale > 0.0) r.g2Rel = r.g2 / r.curvScale;
  if (o.g0) {  // the other way: points of B's overlap against A's edge
    const CurveDistance toA(sa.s.boundaryCurve(Edge::U0), ar);
    for (int i = 0; i < o.samples; ++i) {
      const double s = br.lo + (br.hi - br.lo) * i / (o.samples - 1);
      r.g0 = std::max(r.g0, toA.distance(v3(sb.derivs(s, 0)[0][0])));
    }
  }
  return r;
}

/// A random pair for the bounds test (issue 7.ix) with its reference options (correspondence known by construction).
struct BoundsPair {
  BSplineSurface a, b;
  Edge ea = Edge::U1, eb = Edge::U0;
  RefOptions ref;
  bool exactG1 = false;  ///< B's first cross row untouched: G1 holds exactly (the G2 bound is then certified)
  std::string what;
};

/// `nearG1`: a split pair (exactly G0) with B's rows 1 and 2 from the edge moved -- row 1 by ~1e-6 (a tiny angle,
/// small enough that the choice of the common tangent frame for the curvature comparison does not matter at the
/// 1e-4 level) or not at all (exact G1), row 2 by ~0.03 (a curvature jump) -- then B reparametrised by a random
/// affine map along the edge (optionally reversed). The correspondence is known exactly.
/// Otherwise: a graph patch A whose edge row (u = 0) lies in the plane z = 0 and a patch B on the other side (x
/// decreasing) with the same edge row, knots and weights, each edge point then moved by eps * delta_j along z
/// (perpendicular to the edge plane): B's edge is A's edge plus a z-offset, so the closest-point gap is the offset up
/// to O(eps^2). The two patches meet at a random kink.
inline BoundsPair makeBoundsPair(Rng& rng, bool nearG1, bool rational, int variant) {
  const int pu = irand(rng, 2, 4), pv = irand(rng, 2, 4);
  BoundsPair bp;
  bp.what = std::string(nearG1 ? "near-G1" : "gap+kink") + (rational ? " rational" : " polynomial") + " degrees " +
            std::to_string(pu) + "x" + std::to_string(pv);
  bp.ref.samples = 10000;
  if (nearG1) {
    const BSplineSurface s = randomGraphSurface(rng, pu, pv, pu + 4, pv + 2, rational);
    const std::vector<double> ks = interiorKnots(s.knotsU(), pu);
    auto [a, b] = splitU(s, ks[ks.size() / 2]);
    bp.exactG1 = variant % 3 == 0;
    Matrix p = b.points();
    for (int j = 0; j < b.numV(); ++j)
      for (int c = 0; c < 3; ++c) {
        if (!bp.exactG1) p(1 * b.numV() + j, c) += urand(rng, -1e-6, 1e-6);
        p(2 * b.numV() + j, c) += urand(rng, -0.03, 0.03);
      }
    b = BSplineSurface(b.degreeU(), b.degreeV(), b.knotsU(), b.knotsV(), b.numU(), b.numV(), p, b.weights());
    const Interval dv = b.domainV();
    const double alpha = urand(rng, 0.5, 2.0), beta = urand(rng, -1.0, 1.0);
    const bool reverse = variant % 2 == 1;
    const BSplineSurface bb = reverse ? b.reversedV() : b;
    bp.a = a;
    bp.b = bb.reparametrized(b.domainU(), {beta, beta + alpha * dv.length()});
    bp.ref.phi = [=](double t) { return beta + alpha * (reverse ? dv.hi - t : t - dv.lo); };
    bp.ref.g0 = false;  // B's edge is A's edge: the gap is 0 by construction
    bp.what += bp.exactG1 ? " exact-G1" : " small-angle";
    bp.what += reverse ? " reversed" : "";
    return bp;
  }
  const int nu = pu + 2, nv = pv + 2, nbu = irand(rng, 2, 4) + 1;
  Matrix na = graphNet(rng, nu, nv, 0.25);
  for (int j = 0; j < nv; ++j) na(j, 2) = 0.0;
  Matrix nb = graphNet(rng, nbu, nv, 0.25);
  for (int i = 0; i < nbu; ++i)
    for (int j = 0; j < nv; ++j) {
      nb(i * nv + j, 0) = na(0, 0) - (nb(i * nv + j, 0) - nb(0, 0));  // mirrored across the edge: x decreasing
      nb(i * nv + j, 1) = na(j, 1);
    }
  const double eps = 1e-4;
  for (int j = 0; j < nv; ++j) nb.row(j) = na.row(j) + Vec3(0, 0, eps * urand(rng, -1, 1)).transpose();
  VecX wa, wb;
  if (rational) {
    wa = randomWeights(rng, nu * nv);
    wb = randomWeights(rng, nbu * nv);
    wb.head(nv) = wa.head(nv);
  }
  const std::vector<double> kv = randomClampedKnots(rng, pv, nv);
  const BSplineSurface a(pu, pv, KnotVector(randomClampedKnots(rng, pu, nu)), KnotVector(kv), nu, nv, na, wa);
  const int pbu = std::min(nbu - 1, irand(rng, 2, 4));
  const BSplineSurface b(pbu, pv, KnotVector(randomClampedKnots(rng, pbu, nbu)), KnotVector(kv), nbu, nv, nb, wb);
  const Eigen::Matrix3d rot = randomRotation(rng);
  const Vec3 shift = randomVec3(rng, -1, 1);
  bp.a = transformed(a, rot, shift);
  bp.b = transformed(b, rot, shift);
  bp.ea = Edge::U0;
  bp.eb = Edge::U0;
  bp.ref.g2 = false;  // a kink: no shared tangent plane, the curvature comparison is not defined
  return bp;
}

/// Largest |B'_u - lambda A_out - kappa A_t| over `n` points of A's edge (relative to max |A_out|), with phi = id:
/// the self-check of an exact Lemma 1 construction.
inline double lemma1Residual(const BSplineSurface& A, const BSplineSurface& B, const BernsteinPoly& lambda,
                             const BernsteinPoly& kappa, int n = 101) {
  double worst = 0.0, scale = 0.0;
  for (int i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) / (n - 1);
    const auto da = A.derivatives(0.0, t, 1);
    const auto db = B.derivatives(0.0, t, 1);
    const Vec3 aOut = -v3(da[1][0]);
    const Vec3 res = v3(db[1][0]) - lambda.scalar(t) * aOut - kappa.scalar(t) * v3(da[0][1]);
    worst = std::max(worst, res.norm());
    scale = std::max(scale, aOut.norm());
  }
  return worst / scale;
}

/// Size of a patch for relative floors: the diagonal of its control-point bounding box.
inline double patchScale(const BSplineSurface& s) {
  const Matrix& p = s.points();
  return (p.colwise().maxCoeff() - p.colwise().minCoeff()).norm();
}

/// Normals of a moved patch against the input at equal normalised parameters (issue 36 goal 2's independent
/// oracle): pointwise derivatives (NURBS Book A4.4), not the Bernstein products and subdivision of normalTurnover.
struct SampledTurn {
  double angleDeg = 0.0;    ///< the largest angle between the normals where both are defined
  double a = 0.0, b = 0.0;  ///< normalised parameters of that point
};

/// S_u x S_v at the normalised parameters (a, b) of the surface's domain.
inline Vec3 sampledNormal(const BSplineSurface& s, double a, double b) {
  const auto d = s.derivatives(s.domainU().lo + a * s.domainU().length(), s.domainV().lo + b * s.domainV().length(), 1);
  return Vec3(d[1][0].head<3>().cross(d[0][1].head<3>()));
}

/// The largest angle between the normals of two surfaces on an n x n lattice of normalised parameters, where both
/// are defined (|S_u x S_v| above 1e-9 of the lattice's largest on each surface: poles give no direction).
inline SampledTurn sampledTurn(const BSplineSurface& before, const BSplineSurface& after, int n) {
  std::vector<Vec3> n0, n1;
  double s0 = 0.0, s1 = 0.0;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const double a = static_cast<double>(i) / (n - 1), b = static_cast<double>(j) / (n - 1);
      n0.push_back(sampledNormal(before, a, b));
      n1.push_back(sampledNormal(after, a, b));
      s0 = std::max(s0, n0.back().norm());
      s1 = std::max(s1, n1.back().norm());
    }
  SampledTurn t;
  for (int k = 0; k < n * n; ++k) {
    const Vec3& x = n0[static_cast<size_t>(k)];
    const Vec3& y = n1[static_cast<size_t>(k)];
    if (x.norm() <= 1e-9 * s0 || y.norm() <= 1e-9 * s1) continue;
    const double deg = std::acos(std::clamp(x.dot(y) / (x.norm() * y.norm()), -1.0, 1.0)) * 180.0 / std::numbers::pi;
    if (deg > t.angleDeg) t = {deg, static_cast<double>(k / n) / (n - 1), static_cast<double>(k % n) / (n - 1)};
  }
  return t;
}

}  // namespace seam::seamtest
