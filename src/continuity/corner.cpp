#include "seam/continuity/corner.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <set>
#include <type_traits>

#include "continuity/model_check_internal.h"

namespace seam {

namespace {

/// A corner whose |S_u x S_v| is below this fraction of max(|S_u|, |S_v|)^2 has no normal: the angle between S_u and
/// S_v is below ~1e-8 rad, or one of them is shorter than 1e-8 of the other (a collapsed edge, e.g. a pole). Above
/// it, the unit normal is computed to ~kRoundoff / 1e-8 = 1e-4 relative at worst, and far better at ordinary corners.
constexpr double kDegenerateNormalRel = 1e-8;

/// Where the geometric link test samples each edge: at this fraction of the edge's parameter range from the vertex.
constexpr double kLinkSampleFraction = 0.25;

/// Default link tolerance of the geometric overload, as a multiple of Tolerances::distance (small gaps still link).
constexpr double kDefaultLinkToleranceFactor = 100.0;

double degrees(double radians) { return radians * 180.0 / std::numbers::pi; }

/// Angle between two unit vectors in radians, accurate near 0 and pi.
double angleBetween(const Vec3& a, const Vec3& b) { return std::atan2(a.cross(b).norm(), a.dot(b)); }

/// A fan whose corner normals deviate more than this (radians, 10 degrees) from their mean has no common tangent plane
/// to compare curvatures in: no curvature spread is reported there.
constexpr double kCurvatureSpreadMaxTilt = 10.0 * std::numbers::pi / 180.0;

/// Spectral norm of a symmetric 2 x 2 matrix (its largest eigenvalue in absolute value).
double spectralNormSym(const Eigen::Matrix2d& m) {
  const double mid = 0.5 * (m(0, 0) + m(1, 1)), half = 0.5 * (m(0, 0) - m(1, 1));
  return std::abs(mid) + std::hypot(half, m(0, 1));
}

/// Value and partial derivatives up to order 2 at one point.
struct Jet {
  Vec3 p = Vec3::Zero(), u = Vec3::Zero(), v = Vec3::Zero(), uu = Vec3::Zero(), uv = Vec3::Zero(),
       vv = Vec3::Zero();
};

/// The integer k as a type (a loop bound or index known at compile time where a function template takes it).
template <int k>
constexpr std::integral_constant<int, k> kConst{};

Vec2 cornerUV(const BSplineSurface& s, const PatchCorner& c) {
  const Interval du = s.domainU(), dv = s.domainV();
  return {c.uMax ? du.hi : du.lo, c.vMax ? dv.hi : dv.lo};
}

/// Weights of the first three control points (counted from the corner's end of the knot vector) in the value and the
/// first two derivatives at that end of a B-spline of degree p whose knots are clamped there: w[k][i] is the weight
/// of point i in the k-th derivative (i = 0, 1, 2; derivative control points, The NURBS Book eq. 3.8, at a clamped
/// end). false when the end is not clamped (the caller evaluates instead).
bool clampedEndWeights(const KnotVector& kv, int p, bool atEnd, std::array<std::array<double, 3>, 3>& w) {
  const std::vector<double>& U = kv.values();
  const int m = static_cast<int>(U.size()) - 1;
  // Knot t_i counted from the corner's end, reflected at the far end (t -> -t) so that one formula serves both.
  auto t = [&](int i) { return atEnd ? -U[static_cast<size_t>(m - i)] : U[static_cast<size_t>(i)]; };
  for (int i = 1; i <= p; ++i)
    if (t(i) != t(0)) return false;
  if (p < 1 || m < 2 * p + 1) return false;
  w = {};
  w[0][0] = 1.0;
  const double a1 = p / (t(p + 1) - t(1));
  w[1][0] = -a1;
  w[1][1] = a1;
  if (p >= 2) {
    const double b1 = p / (t(p + 2) - t(2));  // Q_1 = b1 (P_2 - P_1), Q_0 = a1 (P_1 - P_0)
    const double c = (p - 1) / (t(p + 1) - t(2));  // R_0 = c (Q_1 - Q_0)
    w[2][0] = c * a1;
    w[2][1] = -c * (a1 + b1);
    w[2][2] = c * b1;
  }
  if (atEnd) {  // d/dt of the reflected parameter is -d/dt: the odd derivative changes sign
    for (double& x : w[1]) x = -x;
  }
  return true;
}

Jet cornerJet(const BSplineSurface& s, const PatchCorner& c) {
  // A polynomial patch clamped at the corner (every Bezier patch, almost every B-spline patch): the jet straight
  // from the 3 x 3 control points at the corner, without span search and basis functions.
  std::array<std::array<double, 3>, 3> wu{}, wv{};
  if (!s.isRational() && clampedEndWeights(s.knotsU(), s.degreeU(), c.uMax, wu) &&
      clampedEndWeights(s.knotsV(), s.degreeV(), c.vMax, wv)) {
    const int nu = s.numU(), nv = s.numV();
    const int ku = std::min(3, nu), kv = std::min(3, nv);
    std::array<std::array<Vec3, 3>, 3> P;
    for (auto& row : P) row.fill(Vec3::Zero());
    for (int a = 0; a < ku; ++a)
      for (int b = 0; b < kv; ++b)
        P[static_cast<size_t>(a)][static_cast<size_t>(b)] =
            s.point(c.uMax ? nu - 1 - a : a, c.vMax ? nv - 1 - b : b).transpose().head<3>();
    // clampedEndWeights leaves w[k][i] = +-0 for i > k: with finite weights those terms have f = +-0 and are skipped
    // below anyway, so the sums stop at i = k (the same terms in the same order). Non-finite weights take every term.
    bool finite = true;
    for (const auto* w : {&wu, &wv})
      for (const auto& row : *w)
        for (const double x : row) finite = finite && std::isfinite(x);
    // r = the sum over a < na, b < nb of wu[du][a] wv[dv][b] P[a][b], terms with f = 0 skipped. With int arguments
    // the bounds are known at run time; with std::integral_constant ones (kConst) at compile time.
    auto mix = [&](auto du, auto dv, auto na, auto nb) -> Vec3 {
      Vec3 r = Vec3::Zero();
      for (int a = 0; a < na; ++a)
        for (int b = 0; b < nb; ++b) {
          const double f = wu[static_cast<size_t>(du)][static_cast<size_t>(a)] *
                           wv[static_cast<size_t>(dv)][static_cast<size_t>(b)];
          if (f != 0.0) r += f * P[static_cast<size_t>(a)][static_cast<size_t>(b)];
        }
      return r;
    };
    Jet j;
    j.p = P[0][0];
    if (finite && ku == 3 && kv == 3) {  // 3 x 3 corner points, finite weights (every Bezier corner): a <= du, b <= dv
      j.u = mix(kConst<1>, kConst<0>, kConst<2>, kConst<1>);
      j.v = mix(kConst<0>, kConst<1>, kConst<1>, kConst<2>);
      j.uu = mix(kConst<2>, kConst<0>, kConst<3>, kConst<1>);
      j.uv = mix(kConst<1>, kConst<1>, kConst<2>, kConst<2>);
      j.vv = mix(kConst<0>, kConst<2>, kConst<1>, kConst<3>);
      return j;
    }
    auto na = [&](int du) { return finite ? std::min(ku, du + 1) : ku; };
    auto nb = [&](int dv) { return finite ? std::min(kv, dv + 1) : kv; };
    j.u = mix(1, 0, na(1), nb(0));
    j.v = mix(0, 1, na(0), nb(1));
    j.uu = mix(2, 0, na(2), nb(0));
    j.uv = mix(1, 1, na(1), nb(1));
    j.vv = mix(0, 2, na(0), nb(2));
    return j;
  }
  const Vec2 uv = cornerUV(s, c);
  std::array<Vec3, 6> d;
  s.secondOrderDerivatives(uv.x(), uv.y(), d);  // allocation-free (3-D surfaces are checked before)
  Jet j;
  j.p = d[0];
  j.u = d[1];
  j.v = d[2];
  j.uu = d[3];
  j.uv = d[4];
  j.vv = d[5];
  return j;
}

/// The jet of the reoriented patch (PatchLayout) at the same point.
Jet orient(Jet j, const PatchLayout& l) {
  if (l.swapUV) {
    std::swap(j.u, j.v);
    std::swap(j.uu, j.vv);
  }
  if (l.reverseU) {
    j.u = -j.u;
    j.uv = -j.uv;
  }
  if (l.reverseV) {
    j.v = -j.v;
    j.uv = -j.uv;
  }
  return j;
}

/// Where the corner lies after reorientation by `l`.
PatchCorner orientCorner(PatchCorner c, const PatchLayout& l) {
  if (l.swapUV) std::swap(c.uMax, c.vMax);
  if (l.reverseU) c.uMax = !c.uMax;
  if (l.reverseV) c.vMax = !c.vMax;
  return c;
}

/// First and second derivative of a separable reparametrisation u -> alpha(u) at V.
struct Map1 {
  double d1 = 1.0;
  double d2 = 0.0;
};

/// r~(u, v) = r(alpha(u), beta(v)): chain rule up to order 2.
Jet reparametrize(const Jet& j, const Map1& a, const Map1& b) {
  Jet r;
  r.p = j.p;
  r.u = a.d1 * j.u;
  r.v = b.d1 * j.v;
  r.uu = a.d1 * a.d1 * j.uu + a.d2 * j.u;
  r.uv = a.d1 * b.d1 * j.uv;
  r.vv = b.d1 * b.d1 * j.vv + b.d2 * j.v;
  return r;
}

/// The correspondence s = phi(t) between two parametrisations of one curve at a point, from c1(t) = c2(phi(t)):
/// c1' = c2' phi', c1'' = c2'' phi'^2 + c2' phi'' (least squares along c2').
Map1 correspondence(const Vec3& c1d, const Vec3& c1dd, const Vec3& c2d, const Vec3& c2dd) {
  const double n2 = c2d.squaredNorm();
  Map1 m;
  m.d1 = c1d.dot(c2d) / n2;
  m.d2 = (c1dd - m.d1 * m.d1 * c2dd).dot(c2d) / n2;
  return m;
}

/// Eq. 2.1 / 3.10 / 3.11 at V for one seam. a = A_cross, b = A_along (side A), da, db their derivatives along the seam,
/// B = B_cross and dB its derivative along the seam, Acc/Aca/Aaa the second derivatives of A (cross-cross,
/// cross-along, along-along), Bcc that of B. Written into `s` (a default-constructed VertexSeam, in its report slot).
void seamAtVertex(const Vec3& a, const Vec3& b, const Vec3& da, const Vec3& db, const Vec3& B, const Vec3& dB,
                  const Vec3& Acc, const Vec3& Aca, const Vec3& Aaa, const Vec3& Bcc, double lengthScale,
                  const Tolerances& tol, double sinTol, VertexSeam& s) {
  Eigen::Matrix2d G;
  G << a.dot(a), a.dot(b), a.dot(b), b.dot(b);
  const Eigen::Matrix2d Ginv = G.inverse();
  const Eigen::Vector2d x = Ginv * Eigen::Vector2d(a.dot(B), b.dot(B));
  s.lambda = x[0];
  s.kappa = x[1];
  const Vec3 res = B - s.lambda * a - s.kappa * b;
  s.g1Residual = res.norm() / B.norm();

  // d/ds of the least-squares solution: G x = c  =>  G' x + G x' = c'.
  Eigen::Matrix2d Gd;
  Gd << 2.0 * a.dot(da), da.dot(b) + a.dot(db), da.dot(b) + a.dot(db), 2.0 * b.dot(db);
  const Eigen::Vector2d cd(da.dot(B) + a.dot(dB), db.dot(B) + b.dot(dB));
  const Eigen::Vector2d xd = Ginv * (cd - Gd * x);
  s.dLambda = xd[0];
  s.dKappa = xd[1];
  const Vec3 n = a.cross(b).normalized();
  const Vec3 dres = dB - s.dLambda * a - s.lambda * da - s.dKappa * b - s.kappa * db;
  s.g1SlopeResidual = std::abs(n.dot(dres)) / B.norm() / b.norm() * lengthScale;

  // Lemma 2: B_cc = lambda^2 A_cc + 2 lambda kappa A_ca + kappa^2 A_aa + mu A_cross + nu A_along (+ normal residual).
  const Vec3 predicted = s.lambda * s.lambda * Acc + 2.0 * s.lambda * s.kappa * Aca + s.kappa * s.kappa * Aaa;
  const Vec3 r2 = Bcc - predicted;
  const Eigen::Vector2d mn = Ginv * Eigen::Vector2d(a.dot(r2), b.dot(r2));
  const double b2 = B.squaredNorm();
  s.g2Jump = n.dot(r2) / b2;
  const double kA = n.dot(predicted) / b2, kB = n.dot(Bcc) / b2;
  s.g2JumpRel = std::abs(s.g2Jump) / std::max({std::abs(kA), std::abs(kB), 1.0 / lengthScale});

  s.g1 = s.g1Residual <= sinTol && s.g1SlopeResidual <= sinTol;
  s.g2 = s.g1 && s.g2JumpRel <= tol.curvatureRel;
  if (s.g2) {
    s.mu = mn[0];
    s.nu = mn[1];
  }
}

/// Node of the fan walk: one of the two edges through a corner.
struct CornerEdge {
  int corner = 0;
  Edge edge = Edge::U0;
  friend bool operator==(const CornerEdge&, const CornerEdge&) = default;
};

/// The two edges through a corner in counter-clockwise order around the vertex (seen from the side S_u x S_v points
/// to): at (u_min, v_min) and (u_max, v_max) the v-edge comes first, at the two other corners the u-edge.
std::pair<Edge, Edge> ccwEdges(const PatchCorner& c, int orientation) {
  const bool vFirst = (c.uMax == c.vMax);
  std::pair<Edge, Edge> e = vFirst ? std::pair{c.vEdge(), c.uEdge()} : std::pair{c.uEdge(), c.vEdge()};
  if (orientation < 0) std::swap(e.first, e.second);
  return e;
}

struct Fan {
  std::vector<int> order;  // corners in walk order
  bool closed = false;
};

/// analyzeCorner's working storage, kept per thread and reused from vertex to vertex (checkModel analyses thousands
/// of vertices; a call uses it from start to end and calls nothing that uses it too): no allocation once grown.
struct CornerScratch {
  std::vector<std::array<std::optional<CornerEdge>, 2>> partner;
  std::vector<Jet> jets;
  std::vector<Vec3> normals, orientedNormal, oriented;
  std::vector<char> degenerate;
  std::vector<Fan> fans;  ///< the first fanCount are this call's (the rest keep their storage for later calls)
  size_t fanCount = 0;
  std::vector<Eigen::Matrix2d> shape;
};

CornerScratch& cornerScratch() {
  thread_local CornerScratch scratch;
  return scratch;
}

}  // namespace

BSplineSurface applyLayout(const BSplineSurface& s, const PatchLayout& layout) {
  BSplineSurface r = layout.swapUV ? s.swappedUV() : s;
  if (layout.reverseU) r = r.reversedU();
  if (layout.reverseV) r = r.reversedV();
  return r;
}

std::vector<CornerLink> findCornerLinks(std::span<const Patch> patches, std::span<const PatchCorner> corners,
                                        double tolerance) {
  std::vector<CornerLink> links;
  const int n = static_cast<int>(corners.size());
  // The point at kLinkSampleFraction of edge e from the corner, and the edge curve.
  struct EdgeSample {
    CornerEdge node;
    Vec3 point;
    BSplineCurve curve;
    bool valid = false;
  };
  std::vector<EdgeSample> samples;
  for (int i = 0; i < n; ++i) {
    const PatchCorner& c = corners[static_cast<size_t>(i)];
    if (c.patch < 0 || c.patch >= static_cast<int>(patches.size())) continue;
    const BSplineSurface& s = patches[static_cast<size_t>(c.patch)].surface;
    for (Edge e : {c.uEdge(), c.vEdge()}) {
      EdgeSample es;
      es.node = {i, e};
      es.curve = s.boundaryCurve(e);
      const Interval d = es.curve.domain();
      // The corner is at the start of the edge when the other parameter is at its minimum.
      const bool atStart = isUEdge(e) ? !c.vMax : !c.uMax;
      const double t = atStart ? d.lo + kLinkSampleFraction * d.length() : d.hi - kLinkSampleFraction * d.length();
      es.point = es.curve.point3(t);
      es.valid = true;
      samples.push_back(std::move(es));
    }
  }
  for (size_t x = 0; x < samples.size(); ++x) {
    for (size_t y = x + 1; y < samples.size(); ++y) {
      const EdgeSample& p = samples[x];
      const EdgeSample& q = samples[y];
      if (p.node.corner == q.node.corner) continue;  // the two edges of one corner are never one seam
      const PatchCorner& cp = corners[static_cast<size_t>(p.node.corner)];
      const PatchCorner& cq = corners[static_cast<size_t>(q.node.corner)];
      if (cp.patch == cq.patch && p.node.edge == q.node.edge) {
        // Both ends of one edge at the vertex: a collapsed edge when its middle is there too.
        const Interval d = p.curve.domain();
        const Vec3 mid = p.curve.point3(0.5 * (d.lo + d.hi));
        if ((mid - p.curve.point3(d.lo)).norm() <= tolerance &&
            detail::controlExtent(p.curve) <= tolerance) {
          links.push_back({p.node.corner, p.node.edge, q.node.corner, q.node.edge});
        }
        continue;
      }
      if (detail::projectOntoCurve(q.curve, p.point).distance <= tolerance &&
          detail::projectOntoCurve(p.curve, q.point).distance <= tolerance) {
        links.push_back({p.node.corner, p.node.edge, q.node.corner, q.node.edge});
      }
    }
  }
  return links;
}

Result<CornerReport> analyzeCorner(std::span<const Patch> patches, std::span<const PatchCorner> corners,
                                   const CornerOptions& options) {
  for (const PatchCorner& c : corners) {
    if (c.patch < 0 || c.patch >= static_cast<int>(patches.size()))
      return invalidInput(fmt::format("corner: patch index {} out of range (0..{})", c.patch, patches.size()));
  }
  const double tolerance = options.linkTolerance.value_or(kDefaultLinkToleranceFactor * options.tol.distance);
  const std::vector<CornerLink> links = findCornerLinks(patches, corners, tolerance);
  return analyzeCorner(patches, corners, links, options);
}

Result<CornerReport> analyzeCorner(std::span<const Patch> patches, std::span<const PatchCorner> corners,
                                   std::span<const CornerLink> links, const CornerOptions& options) {
  const int n = static_cast<int>(corners.size());
  if (n == 0) return invalidInput("corner: no patch corners given");
  for (const PatchCorner& c : corners) {
    if (c.patch < 0 || c.patch >= static_cast<int>(patches.size()))
      return invalidInput(fmt::format("corner: patch index {} out of range (0..{})", c.patch, patches.size()));
    if (patches[static_cast<size_t>(c.patch)].surface.dim() != 3)
      return invalidInput(fmt::format("corner: patch \"{}\" is not 3-D", patches[static_cast<size_t>(c.patch)].name));
  }
  CornerScratch& W = cornerScratch();
  // Links: validated, and at most one partner per corner edge.
  std::vector<std::array<std::optional<CornerEdge>, 2>>& partner = W.partner;
  partner.assign(static_cast<size_t>(n), {});
  auto slot = [&](int corner, Edge e) -> int {
    const PatchCorner& c = corners[static_cast<size_t>(corner)];
    return e == c.uEdge() ? 0 : (e == c.vEdge() ? 1 : -1);
  };
  std::vector<std::string> notes;
  std::set<std::pair<int, int>> collapsed;  // (corner, corner) pairs joined by a collapsed edge
  for (const CornerLink& l : links) {
    if (l.a < 0 || l.a >= n || l.b < 0 || l.b >= n)
      return invalidInput(fmt::format("corner: link refers to corner {} or {} (have {})", l.a, l.b, n));
    const int sa = slot(l.a, l.aEdge), sb = slot(l.b, l.bEdge);
    if (sa < 0 || sb < 0 || l.a == l.b)
      return invalidInput(fmt::format("corner: link {}:{} - {}:{} does not join edges through two corners", l.a,
                                      edgeName(l.aEdge), l.b, edgeName(l.bEdge)));
    auto& pa = partner[static_cast<size_t>(l.a)][static_cast<size_t>(sa)];
    auto& pb = partner[static_cast<size_t>(l.b)][static_cast<size_t>(sb)];
    if (pa || pb) {
      notes.push_back(fmt::format("non-manifold: corner edge {}:{} or {}:{} belongs to more than one seam; extra link "
                                  "ignored",
                                  l.a, edgeName(l.aEdge), l.b, edgeName(l.bEdge)));
      continue;
    }
    pa = CornerEdge{l.b, l.bEdge};
    pb = CornerEdge{l.a, l.aEdge};
    if (corners[static_cast<size_t>(l.a)].patch == corners[static_cast<size_t>(l.b)].patch && l.aEdge == l.bEdge)
      collapsed.insert({std::min(l.a, l.b), std::max(l.a, l.b)});
  }

  CornerReport report;
  report.corners.assign(corners.begin(), corners.end());
  report.notes = std::move(notes);

  // Corner data.
  std::vector<Jet>& jets = W.jets;
  jets.assign(static_cast<size_t>(n), Jet{});
  std::vector<Vec3>& normals = W.normals;
  normals.assign(static_cast<size_t>(n), Vec3::Zero());
  std::vector<char>& degenerate = W.degenerate;
  degenerate.assign(static_cast<size_t>(n), 0);
  double scale = 0.0;
  for (int i = 0; i < n; ++i) {
    const PatchCorner& c = corners[static_cast<size_t>(i)];
    const BSplineSurface& s = patches[static_cast<size_t>(c.patch)].surface;
    jets[static_cast<size_t>(i)] = cornerJet(s, c);
    const Jet& j = jets[static_cast<size_t>(i)];
    report.point += j.p;
    if (!options.lengthScale) scale = std::max(scale, controlBox(s).diagonal());  // only for the default below
    const Vec3 cr = j.u.cross(j.v);
    const double m = std::max(j.u.norm(), j.v.norm());
    if (!(cr.norm() > kDegenerateNormalRel * m * m)) {
      degenerate[static_cast<size_t>(i)] = 1;
      report.degenerateCorners.push_back(i);
    } else {
      normals[static_cast<size_t>(i)] = cr.normalized();
    }
  }
  report.point /= n;
  for (const Jet& j : jets) report.cornerGap = std::max(report.cornerGap, (j.p - report.point).norm());
  report.degenerate = !report.degenerateCorners.empty();
  const double lengthScale =
      options.lengthScale.value_or(scale > 0.0 && std::isfinite(scale) ? scale : 1.0);

  // Fans: walk from corner to corner across the linked edges, orienting each corner so that the seam edge we arrive
  // by is its first edge (counter-clockwise); start open fans at a corner with an unlinked edge.
  report.orientation.assign(static_cast<size_t>(n), 0);
  W.fanCount = 0;
  auto walk = [&](int start, int startOrientation) {
    if (W.fanCount == W.fans.size()) W.fans.emplace_back();
    Fan& fan = W.fans[W.fanCount++];
    fan.order.clear();
    fan.closed = false;
    int cur = start;
    report.orientation[static_cast<size_t>(cur)] = startOrientation;
    fan.order.push_back(cur);
    for (;;) {
      const PatchCorner& c = corners[static_cast<size_t>(cur)];
      const Edge second = ccwEdges(c, report.orientation[static_cast<size_t>(cur)]).second;
      const auto& next = partner[static_cast<size_t>(cur)][static_cast<size_t>(slot(cur, second))];
      if (!next) break;
      const int j = next->corner;
      if (j == start) {
        const Edge first = ccwEdges(corners[static_cast<size_t>(j)], report.orientation[static_cast<size_t>(j)]).first;
        if (first == next->edge) {
          fan.closed = true;
        } else {
          report.notes.push_back("the seams around the vertex cannot be oriented consistently (non-orientable)");
        }
        break;
      }
      if (report.orientation[static_cast<size_t>(j)] != 0) {
        report.notes.push_back("non-manifold vertex: a corner is reached twice around the vertex");
        break;
      }
      const int o = ccwEdges(corners[static_cast<size_t>(j)], 1).first == next->edge ? 1 : -1;
      report.orientation[static_cast<size_t>(j)] = o;
      fan.order.push_back(j);
      cur = j;
    }
  };
  // Open fans first: a corner with exactly one linked edge starts one, oriented so the unlinked edge comes first.
  for (int i = 0; i < n; ++i) {
    if (report.orientation[static_cast<size_t>(i)] != 0) continue;
    const auto& p = partner[static_cast<size_t>(i)];
    if (p[0].has_value() == p[1].has_value()) continue;
    const Edge unlinked = p[0] ? corners[static_cast<size_t>(i)].vEdge() : corners[static_cast<size_t>(i)].uEdge();
    walk(i, ccwEdges(corners[static_cast<size_t>(i)], 1).first == unlinked ? 1 : -1);
  }
  for (int i = 0; i < n; ++i)
    if (report.orientation[static_cast<size_t>(i)] == 0) walk(i, 1);
  const std::span<const Fan> fans(W.fans.data(), W.fanCount);
  if (fans.size() > 1) report.notes.push_back(fmt::format("{} separate fans meet at the vertex", fans.size()));

  // Sectors: consecutive corners of a fan joined by a collapsed edge are one sector.
  report.sectors.reserve(static_cast<size_t>(n));
  for (const Fan& fan : fans) {
    // This fan's sectors, made in place at the end of report.sectors (from index first).
    std::vector<std::vector<int>>& sectors = report.sectors;
    const size_t first = sectors.size();
    for (int c : fan.order) {
      if (sectors.size() > first &&
          collapsed.count({std::min(sectors.back().back(), c), std::max(sectors.back().back(), c)}))
        sectors.back().push_back(c);
      else
        sectors.push_back({c});
    }
    if (fan.closed && sectors.size() - first > 1 &&
        collapsed.count({std::min(sectors.back().back(), sectors[first].front()),
                         std::max(sectors.back().back(), sectors[first].front())})) {
      sectors[first].insert(sectors[first].begin(), sectors.back().begin(), sectors.back().end());
      sectors.pop_back();
    }
  }
  report.valence = static_cast<int>(report.sectors.size());
  report.closed = fans.size() == 1 && fans[0].closed;

  // The consistently oriented unit normals (zero at degenerate corners), once for the spreads below.
  std::vector<Vec3>& orientedNormal = W.orientedNormal;
  orientedNormal.resize(static_cast<size_t>(n));
  for (size_t i = 0; i < orientedNormal.size(); ++i)
    orientedNormal[i] = static_cast<double>(report.orientation[i]) * normals[i];

  // Normal spread over the consistently oriented normals, within each fan (the orientations of separate fans, e.g. a
  // handle touching a body at a vertex, are unrelated, so their normals are not compared).
  for (const Fan& fan : fans) {
    std::vector<Vec3>& oriented = W.oriented;
    oriented.clear();
    for (int i : fan.order)
      if (!degenerate[static_cast<size_t>(i)]) oriented.push_back(orientedNormal[static_cast<size_t>(i)]);
    if (oriented.size() < 2) continue;
    double spread = 0.0;
    for (size_t x = 0; x < oriented.size(); ++x)
      for (size_t y = x + 1; y < oriented.size(); ++y) spread = std::max(spread, angleBetween(oriented[x], oriented[y]));
    report.normalSpreadDeg = std::max(report.normalSpreadDeg.value_or(0.0), degrees(spread));
  }

  // Curvature spread within each fan: every corner's second fundamental form written as a symmetric 2 x 2 matrix
  // W_i in one orthonormal basis (e1, e2) of the fan's mean tangent plane (johansson.md, "The curvature spread at a
  // vertex"): W_i = P^-T H P^-1 with P = [e . S_u, e . S_v] and H = [S_uu, S_uv; S_uv, S_vv] . N_i. All seams at
  // the vertex G2 => all W_i equal; the spread is the largest normal-curvature difference between two corners over
  // every direction, max_ij ||W_i - W_j||_2.
  for (const Fan& fan : fans) {
    Vec3 mean = Vec3::Zero();
    for (int i : fan.order)
      if (!degenerate[static_cast<size_t>(i)]) mean += orientedNormal[static_cast<size_t>(i)];
    if (!(mean.norm() > 0.0)) continue;
    mean.normalize();
    // No common tangent plane (a crease at the vertex): curvatures are not compared.
    bool creased = false;
    for (int i : fan.order)
      if (!degenerate[static_cast<size_t>(i)])
        creased = creased || angleBetween(mean, orientedNormal[static_cast<size_t>(i)]) > kCurvatureSpreadMaxTilt;
    if (creased) continue;
    const Vec3 e1 = mean.unitOrthogonal(), e2 = mean.cross(e1);
    std::vector<Eigen::Matrix2d>& shape = W.shape;
    shape.clear();
    double largest = 0.0;
    for (int i : fan.order) {
      if (degenerate[static_cast<size_t>(i)]) continue;
      const Jet& j = jets[static_cast<size_t>(i)];
      const Vec3& nrm = orientedNormal[static_cast<size_t>(i)];
      Eigen::Matrix2d P, H;
      P << e1.dot(j.u), e1.dot(j.v), e2.dot(j.u), e2.dot(j.v);
      H << j.uu.dot(nrm), j.uv.dot(nrm), j.uv.dot(nrm), j.vv.dot(nrm);
      const Eigen::Matrix2d Pinv = P.inverse();
      shape.push_back(Pinv.transpose() * H * Pinv);
      largest = std::max(largest, spectralNormSym(shape.back()));
    }
    if (shape.size() < 2) continue;
    double spread = 0.0;
    for (size_t x = 0; x < shape.size(); ++x)
      for (size_t y = x + 1; y < shape.size(); ++y) spread = std::max(spread, spectralNormSym(shape[x] - shape[y]));
    report.curvatureSpread = std::max(report.curvatureSpread.value_or(0.0), spread);
    report.curvatureSpreadRel =
        std::max(report.curvatureSpreadRel.value_or(0.0), spread / std::max(largest, 1.0 / lengthScale));
  }

  // Four-patch analysis (Theorems 1 and 2).
  const bool fourPatch = report.closed && report.valence == 4 && n == 4 && !report.degenerate;
  if (!fourPatch) {
    if (report.closed && report.valence == 4 && report.degenerate)
      report.notes.push_back("4-valent vertex with a degenerate corner: Theorems 1 and 2 need S_u x S_v != 0");
    return report;
  }
  FourPatchVertex fp;
  // Patch 1: the corner listed first; patch 2 across its u-edge, patch 4 across its v-edge, patch 3 opposite.
  const int c1 = 0;
  const PatchCorner& k1 = corners[0];
  const CornerEdge to2 = *partner[0][0];
  const CornerEdge to4 = *partner[0][1];
  const int c2 = to2.corner, c4 = to4.corner;
  const PatchCorner& k2 = corners[static_cast<size_t>(c2)];
  const PatchCorner& k4 = corners[static_cast<size_t>(c4)];
  const Edge e2other = to2.edge == k2.uEdge() ? k2.vEdge() : k2.uEdge();
  const Edge e4other = to4.edge == k4.uEdge() ? k4.vEdge() : k4.uEdge();
  const CornerEdge from2 = *partner[static_cast<size_t>(c2)][static_cast<size_t>(slot(c2, e2other))];
  const CornerEdge from4 = *partner[static_cast<size_t>(c4)][static_cast<size_t>(slot(c4, e4other))];
  if (from2.corner != from4.corner || from2.corner == c1) {
    report.notes.push_back("4-valent vertex whose seams do not form the 2 x 2 layout of Figure 2");
    return report;
  }
  const int c3 = from2.corner;
  const PatchCorner& k3 = corners[static_cast<size_t>(c3)];
  fp.corner = {c1, c2, c3, c4};
  // Layouts: the oriented patch k has V at (max,max), (min,max), (min,min), (max,min) for k = 1, 2, 3, 4; the seam
  // (1,2) is u = max of 1 and u = min of 2, (1,4) is v = max of 1 and v = min of 4, (2,3) is v = max of 2 and
  // v = min of 3, (4,3) is u = max of 4 and u = min of 3.
  auto layoutFor = [](const PatchCorner& c, bool swap, bool wantUMax, bool wantVMax) {
    PatchLayout l;
    l.swapUV = swap;
    const PatchCorner s = orientCorner(c, {swap, false, false});
    l.reverseU = s.uMax != wantUMax;
    l.reverseV = s.vMax != wantVMax;
    return l;
  };
  fp.layout[0] = layoutFor(k1, false, true, true);
  fp.layout[1] = layoutFor(k2, !isUEdge(to2.edge), false, true);      // shared edge with 1 becomes u = min
  fp.layout[2] = layoutFor(k3, isUEdge(from2.edge), false, false);    // shared edge with 2 becomes v = min
  fp.layout[3] = layoutFor(k4, isUEdge(to4.edge), true, false);       // shared edge with 1 becomes v = min
  Jet D1 = orient(jets[static_cast<size_t>(c1)], fp.layout[0]);
  Jet D2 = orient(jets[static_cast<size_t>(c2)], fp.layout[1]);
  Jet D3 = orient(jets[static_cast<size_t>(c3)], fp.layout[2]);
  Jet D4 = orient(jets[static_cast<size_t>(c4)], fp.layout[3]);

  // Common parametrisation (johansson.md): patch 1 as it is; patch 2 keeps its u and takes v from patch 1 along seam
  // (1,2); patch 4 keeps its v and takes u from patch 1 along seam (1,4); patch 3 takes u from patch 2 along (2,3)
  // and v from patch 4 along (4,3).
  const Map1 id;
  const Map1 phi12 = correspondence(D1.v, D1.vv, D2.v, D2.vv);
  const Map1 phi14 = correspondence(D1.u, D1.uu, D4.u, D4.uu);
  const Map1 phi23 = correspondence(D2.u, D2.uu, D3.u, D3.uu);
  const Map1 phi43 = correspondence(D4.v, D4.vv, D3.v, D3.vv);
  const Jet R1 = D1;
  const Jet R2 = reparametrize(D2, id, phi12);
  const Jet R4 = reparametrize(D4, phi14, id);
  const Jet R3 = reparametrize(D3, phi23, phi43);

  const Tolerances& tol = options.tol;
  const double sinTol = std::sin(tol.angleDeg * std::numbers::pi / 180.0);  // of the G1 tolerance, once per vertex
  // (1,2): cross u, along v.   (4,3): cross u, along v.   (1,4): cross v, along u.   (2,3): cross v, along u.
  // Each seam written in its slot of fp.seams (s12, s23, s43, s14 in that order).
  VertexSeam& s12 = fp.seams[0];
  VertexSeam& s23 = fp.seams[1];
  VertexSeam& s43 = fp.seams[2];
  VertexSeam& s14 = fp.seams[3];
  seamAtVertex(R1.u, R1.v, R1.uv, R1.vv, R2.u, R2.uv, R1.uu, R1.uv, R1.vv, R2.uu, lengthScale, tol, sinTol, s12);
  seamAtVertex(R4.u, R4.v, R4.uv, R4.vv, R3.u, R3.uv, R4.uu, R4.uv, R4.vv, R3.uu, lengthScale, tol, sinTol, s43);
  seamAtVertex(R1.v, R1.u, R1.uv, R1.uu, R4.v, R4.uv, R1.vv, R1.uv, R1.uu, R4.vv, lengthScale, tol, sinTol, s14);
  seamAtVertex(R2.v, R2.u, R2.uv, R2.uu, R3.v, R3.uv, R2.vv, R2.uv, R2.uu, R3.vv, lengthScale, tol, sinTol, s23);
  s12.from = 1, s12.to = 2;
  s23.from = 2, s23.to = 3;
  s43.from = 4, s43.to = 3;
  s14.from = 1, s14.to = 4;

  const double l12 = s12.lambda, k12 = s12.kappa, l14 = s14.lambda, k14 = s14.kappa;
  const double l23 = s23.lambda, k23 = s23.kappa, l43 = s43.lambda, k43 = s43.kappa;
  const double au = R1.u.norm(), av = R1.v.norm();
  const double su = std::max(R2.u.norm(), R3.u.norm()), sv = std::max(R4.v.norm(), R3.v.norm());
  // Components of r3_u (2.6a, 2.7a) and r3_v (2.6b, 2.7b) predicted along the two routes around V.
  fp.g1Relations = {(k12 - l14 * k43) * av / su, (k14 - l12 * k23) * au / sv, (l12 - l43 - k14 * k43) * au / su,
                    (l14 - l23 - k12 * k23) * av / sv};
  for (double r : fp.g1Relations) fp.g1Residual = std::max(fp.g1Residual, std::abs(r));

  if (s12.g2 && s23.g2 && s43.g2 && s14.g2) {
    const double m12 = *s12.mu, n12 = *s12.nu, m14 = *s14.mu, n14 = *s14.nu;
    const double m23 = *s23.mu, n23 = *s23.nu, m43 = *s43.mu, n43 = *s43.nu;
    const double dl12 = s12.dLambda, dk12 = s12.dKappa, dl14 = s14.dLambda, dk14 = s14.dKappa;
    const double dl23 = s23.dLambda, dk23 = s23.dKappa, dl43 = s43.dLambda;
    const double dk43 = s43.dKappa;
    double M = std::max(au, av) * std::max(au, av) / lengthScale;
    for (const Jet* r : {&R1, &R2, &R3, &R4}) M = std::max({M, r->uu.norm(), r->uv.norm(), r->vv.norm()});
    std::array<double, 6> g2 = {
        // r3_uu along r1_v, r3_vv along r1_u, r3_uu along r1_u, r3_vv along r1_v, twist along r1_u, r1_v.
        (2.0 * l43 * dl14 * k43 - n12 + n43 * l14 + m14 * k43 * k43) * av / M,
        (2.0 * l23 * dl12 * k23 - n14 + n23 * l12 + m12 * k23 * k23) * au / M,
        (2.0 * l43 * k43 * dk14 - m12 + m43 + n43 * k14 + n14 * k43 * k43) * au / M,
        (2.0 * l23 * k23 * dk12 - m14 + m23 + n23 * k12 + n12 * k23 * k23) * av / M,
        (dl43 - l23 * dl12 + l43 * dk14 - l12 * dk23 + k14 * dk43 - m12 * k23 + n14 * k43) * au / M,
        (dl23 - l43 * dl14 + l23 * dk12 - l14 * dk43 + k12 * dk23 - m14 * k43 + n12 * k23) * av / M,
    };
    double worst = 0.0;
    for (double r : g2) worst = std::max(worst, std::abs(r));
    fp.g2Relations = g2;
    fp.g2Residual = worst;
  }
  report.fourPatch = fp;
  return report;
}

void scaleLengths(CornerReport& r, double scale) {
  r.point *= scale;
  r.cornerGap *= scale;
  if (r.curvatureSpread) *r.curvatureSpread /= scale;  // 1/length
}

}  // namespace seam
