// The local G1 scheme for quad networks (seam/repair/local_scheme.h; derivation in
// docs/algorithms/thesis-abstract.md, "The local scheme").
//
// Notation. Every chosen patch is held as a biquintic B-spline with the knot 1/2 (of its domain) of multiplicity 4 in
// both directions: a 10 x 10 control grid Q(i, j), four C1-joined quintic Bezier pieces. Seen from one of its corners
// the corner piece has "composite" points L(x, y), x, y = 0..5, where index 5 is the (implicit) knot point
// (L(4) + L(6)) / 2. A half-edge is the half of a patch edge next to one corner; its row k (k = 0: the edge, k = 1:
// the row beside it) has points x = 0..4 from the corner outwards. All derivatives are taken in the pieces' local
// parameters w in [0, 1] (w = 0 at the vertex, w = 1 at the middle of the edge); both sides of a seam use the same
// scaling, so the G1 identity below is the same in global parameters.
//
// The G1 identity along a seam between patches B and C (cross derivatives B_u, C_s into each patch, edge Phi):
//     B_u + C_s = gamma(w) Phi'(w)            (alpha = beta = 1, lambda = 1 in Johansson's notation)
// on each half, with gamma a cubic, gamma(1) = 0 at the middle, gamma C1 there. Coefficient k of this degree-5
// identity is: k = 0 the tangent condition at the vertex, k = 1 the twist condition, k = 2..5 the rows beside the
// edge.
#include "seam/repair/local_scheme.h"

#include <fmt/format.h>

#include <Eigen/QR>
#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numbers>
#include <numeric>
#include <set>

#include "repair/join_internal.h"
#include "repair/network_internal.h"
#include "seam/continuity/model_check.h"
#include "seam/core/bernstein.h"
#include "seam/repair/join.h"

namespace seam {

namespace {

constexpr int kDeg = 5;    // degree of the output patches
constexpr int kGrid = 10;  // control points per direction: knots {0^6, 1/2^4, 1^6}
constexpr int kMidMult = 4;
/// A tangent fit that moves a tangent vector by more than this fraction of the longest tangent at the vertex is
/// refused (the vertex's fan is too far from any affine image of a regular fan for the symmetric scheme).
constexpr double kMaxTangentFitRel = 1.0;
/// |sin(Theta)| below which a boundary fan of total angle Theta counts as straight (Theta = pi within ~1.1 degrees).
constexpr double kStraightFanSin = 0.02;

/// A boundary edge of a patch seen from one of its ends (end 0: the low parameter end).
struct Slot {
  int patch = -1;  // index into the region's patch list
  Edge edge = Edge::U0;
  int end = 0;
  friend auto operator<=>(const Slot&, const Slot&) = default;
};

/// Grid index (i, j) of point x (0..4, from the end's corner outwards) of row k of a slot.
std::pair<int, int> slotIndex(const Slot& s, int k, int x) {
  const int along = s.end == 0 ? x : kGrid - 1 - x;
  switch (s.edge) {
    case Edge::U0: return {k, along};
    case Edge::U1: return {kGrid - 1 - k, along};
    case Edge::V0: return {along, k};
    case Edge::V1: return {along, kGrid - 1 - k};
  }
  return {0, 0};
}

/// The two slots at a corner.
std::array<Slot, 2> slotsAt(int patch, int cu, int cv) {
  return {Slot{patch, cv == 0 ? Edge::V0 : Edge::V1, cu}, Slot{patch, cu == 0 ? Edge::U0 : Edge::U1, cv}};
}

struct Grid {
  Matrix q;  // kGrid * kGrid x 3, row i * kGrid + j
  Vec3 at(int i, int j) const { return q.row(i * kGrid + j).transpose(); }
  void set(int i, int j, const Vec3& p) { q.row(i * kGrid + j) = p.transpose(); }
  Vec3 at(const Slot& s, int k, int x) const {
    const auto [i, j] = slotIndex(s, k, x);
    return at(i, j);
  }
  void set(const Slot& s, int k, int x, const Vec3& p) {
    const auto [i, j] = slotIndex(s, k, x);
    set(i, j, p);
  }
};

/// Composite points 0..5 of row k of a half-edge and of the opposite half (sharing the middle point).
using HalfRow = Eigen::Matrix<double, kDeg + 1, 3, Eigen::RowMajor>;  // six points, no heap

HalfRow halfRow(const Grid& g, const Slot& s, int k) {
  Slot other = s;
  other.end = 1 - s.end;
  HalfRow r;
  for (int x = 0; x <= 4; ++x) r.row(x) = g.at(s, k, x).transpose();
  r.row(5) = 0.5 * (g.at(s, k, 4) + g.at(other, k, 4)).transpose();
  return r;
}



/// One edge at a vertex, in the cyclic order around it.
struct VertexEdge {
  int netEdge = -1;             // index into the interior edges, -1 for a free edge
  std::vector<Slot> slots;      // the half-edges at this vertex (1 for a free edge, 2 for a seam)
  Vec3 tOld = Vec3::Zero(), t = Vec3::Zero();
  double gamma0 = 0.0, gamma1 = 0.0;  // gamma(0) and gamma'(0) on this half
  Vec3 curvature = Vec3::Zero();      // curvature point C of the half's cubic
};

struct Vertex {
  Vec3 p = Vec3::Zero();
  bool boundary = false;
  std::vector<std::array<int, 3>> corners;  // (patch, cu, cv), patch j between edges j and j+1
  std::vector<VertexEdge> edges;            // n (interior) or k + 1 (boundary)
  Vec3 normal = Vec3::Zero();
};

struct NetEdge {
  std::array<Slot, 2> side;   // side[s] seen from end P (the vertex vtx[0]); the Q end is end 1 - side[s].end
  std::array<int, 2> vtx{-1, -1};
  std::array<int, 2> vtxEdge{-1, -1};  // index into Vertex::edges at each end
};

Status unsupported(std::string m) { return {ErrorCode::kUnsupported, std::move(m)}; }

/// A clamped Bezier knot vector of `degree` (one span: degree + 1 equal knots at each end).
bool isBezierKnots(const KnotVector& kv, int degree) {
  const std::vector<double>& t = kv.values();
  if (static_cast<int>(t.size()) != 2 * (degree + 1)) return false;
  for (int i = 1; i <= degree; ++i)
    if (t[static_cast<size_t>(i)] != t[0] ||
        t[static_cast<size_t>(degree + 1 + i)] != t[static_cast<size_t>(degree + 1)])
      return false;
  return t[0] < t[static_cast<size_t>(degree + 1)];
}

/// One direction of the scheme form of a Bezier row: `in` (degree + 1 values, `stride` apart) raised to degree 5,
/// then split at 1/2 by de Casteljau; the knot 1/2 of multiplicity 4 keeps both halves' points but the junction
/// (out: the left half's points 0..4, the right half's 1..5).
void bezierRowToSchemeForm(const double* in, int degree, Eigen::Index stride, double* out) {
  // Degree elevation factors C(p, i) C(5 - p, j - i) / C(5, j), per p = 0..5 (zero outside the valid i).
  static const auto factors = [] {
    std::array<std::array<std::array<double, kDeg + 1>, kDeg + 1>, kDeg + 1> f{};
    for (int p = 0; p <= kDeg; ++p)
      for (int j = 0; j <= kDeg; ++j)
        for (int i = std::max(0, j - (kDeg - p)); i <= std::min(p, j); ++i)
          f[static_cast<size_t>(p)][static_cast<size_t>(j)][static_cast<size_t>(i)] =
              binomial(p, i) * binomial(kDeg - p, j - i) / binomial(kDeg, j);
    return f;
  }();
  const auto& fp = factors[static_cast<size_t>(degree)];
  double e[kDeg + 1];
  for (int j = 0; j <= kDeg; ++j) {
    double v = 0.0;
    for (int i = std::max(0, j - (kDeg - degree)); i <= std::min(degree, j); ++i)
      v += fp[static_cast<size_t>(j)][static_cast<size_t>(i)] * in[i * stride];
    e[j] = v;
  }
  double right[kDeg + 1];
  out[0] = e[0];
  right[kDeg] = e[kDeg];
  for (int r = 1; r <= kDeg; ++r) {
    for (int i = 0; i + r <= kDeg; ++i) e[i] = 0.5 * (e[i] + e[i + 1]);
    if (r < kDeg) out[r] = e[0];
    right[kDeg - r] = e[kDeg - r];
  }
  for (int i = 1; i <= kDeg; ++i) out[kDeg - 1 + i] = right[i];
}

/// The scheme form of a polynomial Bezier patch (one span each way, degrees <= 5) directly: the same surface,
/// knots and control-point layout as the general route (degreeElevated, then the knot 1/2 inserted 4 times), with
/// the control points formed by Bezier degree elevation and de Casteljau subdivision (round-off differs).
BSplineSurface bezierToSchemeForm(const BSplineSurface& s0) {
  const int p = s0.degreeU(), q = s0.degreeV(), nv = s0.numV();
  const Matrix& P = s0.points();
  // u first: (p + 1) x nv x 3 -> kGrid x nv x 3, then v: kGrid x kGrid x 3 (row i * kGrid + j).
  Matrix mid(kGrid * nv, 3);
  double col[kGrid];
  for (int j = 0; j < nv; ++j)
    for (int c = 0; c < 3; ++c) {
      bezierRowToSchemeForm(&P(j, c), p, nv * 3, col);
      for (int i = 0; i < kGrid; ++i) mid(i * nv + j, c) = col[i];
    }
  Matrix out(kGrid * kGrid, 3);
  for (int i = 0; i < kGrid; ++i)
    for (int c = 0; c < 3; ++c) {
      bezierRowToSchemeForm(&mid(i * nv, c), q, 3, col);
      for (int j = 0; j < kGrid; ++j) out(i * kGrid + j, c) = col[j];
    }
  auto knots = [](const KnotVector& kv, int degree) {
    const double lo = kv[0], hi = kv[degree + 1], m = 0.5 * (lo + hi);
    std::vector<double> t(static_cast<size_t>(kDeg + 1), lo);
    t.insert(t.end(), static_cast<size_t>(kMidMult), m);
    t.insert(t.end(), static_cast<size_t>(kDeg + 1), hi);
    return KnotVector(std::move(t));
  };
  return BSplineSurface(kDeg, kDeg, knots(s0.knotsU(), p), knots(s0.knotsV(), q), kGrid, kGrid, std::move(out));
}

/// The patch written as a biquintic B-spline with the knot 1/2 of multiplicity 4 (exact), or why not.
Result<BSplineSurface> toSchemeForm(const BSplineSurface& s0, const std::string& name) {
  if (s0.isRational()) return unsupported(fmt::format("patch \"{}\" is rational", name));
  if (s0.degreeU() > kDeg || s0.degreeV() > kDeg)
    return unsupported(fmt::format("patch \"{}\" has degree ({}, {}) above {}", name, s0.degreeU(), s0.degreeV(), kDeg));
  if (s0.dim() == 3 && s0.numU() == s0.degreeU() + 1 && s0.numV() == s0.degreeV() + 1 &&
      isBezierKnots(s0.knotsU(), s0.degreeU()) && isBezierKnots(s0.knotsV(), s0.degreeV()))
    return bezierToSchemeForm(s0);
  BSplineSurface s = s0.degreeElevated(kDeg - s0.degreeU(), kDeg - s0.degreeV());
  for (int dir = 0; dir < 2; ++dir) {
    const KnotVector& kv = dir == 0 ? s.knotsU() : s.knotsV();
    const Interval dom = kv.domain(kDeg);
    const double mid = 0.5 * (dom.lo + dom.hi);
    if (kv.multiplicity(dom.lo) != kDeg + 1 || kv.multiplicity(dom.hi) != kDeg + 1)
      return unsupported(fmt::format("patch \"{}\": its knots are not clamped", name));
    int have = 0;
    for (double t : kv.interiorBreakpoints(kDeg)) {
      if (std::abs(t - mid) > kKnotRelTol * dom.length())
        return unsupported(fmt::format(
            "patch \"{}\": interior knot {} in {}; the scheme takes Bezier patches or B-splines whose only interior "
            "knot is the middle of the domain",
            name, t, dir == 0 ? "u" : "v"));
      have = kv.multiplicity(t);
    }
    if (have < kMidMult) {
      std::vector<double> ins(static_cast<size_t>(kMidMult - have), mid);
      s = dir == 0 ? s.refinedU(ins) : s.refinedV(ins);
    }
  }
  if (s.numU() != kGrid || s.numV() != kGrid) return unsupported(fmt::format("patch \"{}\": unexpected knots", name));
  return s;
}

/// The half-edge cubic (P, A, C, M) in Bernstein form.
BernsteinPoly cubicHalf(const Vec3& P, const Vec3& A, const Vec3& C, const Vec3& M) {
  Matrix phi(4, 3);
  phi << P.transpose(), A.transpose(), C.transpose(), M.transpose();
  return BernsteinPoly(std::move(phi));
}

/// Degree-5 coefficients of gamma * Phi' on a half: gamma cubic with gamma(0) = g0, gamma'(0) = g1, gamma(1) = 0,
/// gamma'(1) = g; Phi the cubic (P, A, C, M). Returns (known part, coefficient of g). The Bernstein product written
/// out: gamma's coefficients are (g0, g0 + g1 / 3, 0, 0) + g (0, 0, -1/3, 0), Phi''s d = 3 (A - P, C - A, M - C), and
/// coefficient k of the product is sum_{i + j = k} C(3, i) C(2, j) / C(5, k) gamma_i d_j.
std::pair<HalfRow, HalfRow> gammaPhiPrime(double g0, double g1, const Vec3& P, const Vec3& A, const Vec3& C,
                                          const Vec3& M) {
  const Vec3 d0 = 3.0 * (A - P), d1 = 3.0 * (C - A), d2 = 3.0 * (M - C);
  const double c0 = g0, c1 = g0 + g1 / 3.0;
  HalfRow gk = HalfRow::Zero(), gg = HalfRow::Zero();
  gk.row(0) = (c0 * d0).transpose();
  gk.row(1) = (0.6 * c1 * d0 + 0.4 * c0 * d1).transpose();
  gk.row(2) = (0.6 * c1 * d1 + 0.1 * c0 * d2).transpose();
  gk.row(3) = (0.3 * c1 * d2).transpose();
  gg.row(2) = (-0.1 * d0).transpose();
  gg.row(3) = (-0.2 * d1).transpose();
  gg.row(4) = (-0.2 * d2).transpose();
  return {gk, gg};
}

Matrix elevatedCubic(const Vec3& P, const Vec3& A, const Vec3& C, const Vec3& M) {
  return cubicHalf(P, A, C, M).elevatedTo(kDeg).coeffs();
}

}  // namespace

Result<LocalSchemeResult> localG1Scheme(const Model& model, const LocalSchemeOptions& opt) {
  return detail::localG1Scheme(model, opt, nullptr);
}

Result<LocalSchemeResult> detail::localG1Scheme(const Model& model, const LocalSchemeOptions& opt,
                                                std::vector<std::pair<int, BSplineSurface>>* inputForms) {
  if (inputForms) inputForms->clear();
  auto setup = networkSetup(model, opt.patches, opt.tolerances, opt.maxGap);
  if (!setup) return setup.status();
  const std::vector<int>& chosen = setup->chosen;
  const double diag = setup->diagonal;
  const Tolerances& tol = setup->tol;
  const double maxGap = setup->maxGap;

  LocalSchemeResult res;
  res.model = model;
  res.model.brep.reset();  // the patches change: the trims would not follow (Model::brep)
  LocalSchemeReport& rep = res.report;

  // ---- 1. the patches in scheme form.
  const int np = static_cast<int>(chosen.size());
  std::map<int, int> local;  // model index -> region index
  for (int r = 0; r < np; ++r) local[chosen[static_cast<size_t>(r)]] = r;
  std::vector<BSplineSurface> form(static_cast<size_t>(np));
  std::vector<Grid> grid(static_cast<size_t>(np)), old(static_cast<size_t>(np));
  bool raised = false;
  for (int r = 0; r < np; ++r) {
    const Patch& p = model.patches[static_cast<size_t>(chosen[static_cast<size_t>(r)])];
    auto f = toSchemeForm(p.surface, p.name);
    if (!f) return f.status();
    raised = raised || p.surface.degreeU() < kDeg || p.surface.degreeV() < kDeg;
    form[static_cast<size_t>(r)] = *f;
    grid[static_cast<size_t>(r)].q = f->points();
    old[static_cast<size_t>(r)].q = f->points();
  }

  // ---- 2. topology: seams between chosen patches, vertices with their cyclic order.
  std::optional<EdgePairing> own;
  if (!opt.pairing) {
    auto paired = pairEdgesWithin(model, tol, maxGap, diag);
    if (!paired) return paired.status();
    own = std::move(*paired);
  }
  const EdgePairing* pairing = opt.pairing ? opt.pairing : &*own;
  for (const DegenerateEdge& d : pairing->degenerateEdges)
    if (local.count(d.edge.patch))
      return unsupported(fmt::format("patch \"{}\" has a collapsed edge {} (a pole)",
                                     model.patches[static_cast<size_t>(d.edge.patch)].name, edgeName(d.edge.edge)));
  std::map<Slot, Slot> partner, keptPartner;
  std::vector<NetEdge> edges;
  for (const EdgePair& pr : pairing->pairs) {
    const bool ina = local.count(pr.a.patch) > 0, inb = local.count(pr.b.patch) > 0;
    if (!ina || !inb) continue;
    const auto kept = [&](int patch, Edge e) {
      return std::find(opt.keepEdges.begin(), opt.keepEdges.end(), std::make_pair(patch, e)) != opt.keepEdges.end();
    };
    if (kept(pr.a.patch, pr.a.edge) || kept(pr.b.patch, pr.b.edge)) {
      // A kept seam: both sides stay free edges; remember the pairing to find creases that end at a vertex.
      for (int end = 0; end < 2; ++end) {
        Slot a{local[pr.a.patch], pr.a.edge, end};
        Slot b{local[pr.b.patch], pr.b.edge, pr.reversed ? 1 - end : end};
        keptPartner[a] = b;
        keptPartner[b] = a;
      }
      continue;
    }
    const std::string& na = model.patches[static_cast<size_t>(pr.a.patch)].name;
    const std::string& nb = model.patches[static_cast<size_t>(pr.b.patch)].name;
    if (!pr.fullA || !pr.fullB)
      return unsupported(fmt::format("the seam {}:{} / {}:{} covers only part of an edge (a T-junction)", na,
                                     edgeName(pr.a.edge), nb, edgeName(pr.b.edge)));
    NetEdge e;
    e.side[0] = Slot{local[pr.a.patch], pr.a.edge, 0};
    e.side[1] = Slot{local[pr.b.patch], pr.b.edge, pr.reversed ? 1 : 0};
    for (int end = 0; end < 2; ++end) {
      Slot a = e.side[0], b = e.side[1];
      if (end == 1) {
        a.end = 1 - a.end;
        b.end = 1 - b.end;
      }
      if (partner.count(a) || partner.count(b))
        return unsupported(fmt::format("edge {}:{} or {}:{} is shared by more than two patches", na,
                                       edgeName(pr.a.edge), nb, edgeName(pr.b.edge)));
      partner[a] = b;
      partner[b] = a;
    }
    edges.push_back(e);
  }
  rep.interiorSeams = static_cast<int>(edges.size());

  // Corners linked through seams form the vertices (union-find over np * 4 corners).
  std::vector<int> parent(static_cast<size_t>(np) * 4);
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&](int x) {
    while (parent[static_cast<size_t>(x)] != x) x = parent[static_cast<size_t>(x)] = parent[static_cast<size_t>(parent[static_cast<size_t>(x)])];
    return x;
  };
  auto cornerId = [](const Slot& s) {
    const auto [cu, cv] = cornerOf(s.edge, s.end);
    return s.patch * 4 + cu * 2 + cv;
  };
  for (const auto& [a, b] : partner) parent[static_cast<size_t>(find(cornerId(a)))] = find(cornerId(b));
  std::map<int, std::vector<int>> groups;
  for (int c = 0; c < np * 4; ++c) groups[find(c)].push_back(c);

  std::vector<Vertex> vertices;
  std::map<Slot, std::pair<int, int>> slotVertexEdge;  // slot -> (vertex, index in Vertex::edges)
  for (const auto& [root, members] : groups) {
    (void)root;
    auto cornerSlots = [&](int c) { return slotsAt(c / 4, (c % 4) / 2, c % 2); };
    // Start: a corner with a free slot (boundary vertex), else any corner.
    int start = members.front();
    int startSlot = 0;
    bool boundary = false;
    for (int c : members) {
      const auto ss = cornerSlots(c);
      for (int k = 0; k < 2; ++k)
        if (!partner.count(ss[static_cast<size_t>(k)])) {
          start = c;
          startSlot = k;
          boundary = true;
        }
      if (boundary) break;
    }
    if (members.size() == 1 && boundary) {
      // A corner of one patch only: no seam there, nothing to do.
      const auto ss = cornerSlots(start);
      if (!partner.count(ss[0]) && !partner.count(ss[1])) continue;
    }
    Vertex v;
    v.boundary = boundary;
    // Walk: enter the corner through slot `in`, leave through the other one.
    int c = start;
    int in = startSlot;
    std::set<int> seen;
    {
      VertexEdge first;
      const auto ss = cornerSlots(c);
      first.slots.push_back(ss[static_cast<size_t>(in)]);
      if (!boundary) first.slots.push_back(partner[ss[static_cast<size_t>(in)]]);
      v.edges.push_back(first);
    }
    while (true) {
      if (seen.count(c)) break;
      seen.insert(c);
      const auto ss = cornerSlots(c);
      v.corners.push_back({c / 4, (c % 4) / 2, c % 2});
      const Slot out = ss[static_cast<size_t>(1 - in)];
      VertexEdge ve;
      ve.slots.push_back(out);
      auto it = partner.find(out);
      if (it == partner.end()) {
        v.edges.push_back(ve);
        break;  // boundary: the fan ends here
      }
      ve.slots.push_back(it->second);
      const int next = cornerId(it->second);
      if (next == start && !boundary) break;  // closed: edge 0 is this one
      v.edges.push_back(ve);
      const auto ns = cornerSlots(next);
      in = ns[0] == it->second ? 0 : 1;
      c = next;
    }
    if (seen.size() != members.size()) {
      const Patch& p = model.patches[static_cast<size_t>(chosen[static_cast<size_t>(members.front() / 4)])];
      return unsupported(fmt::format("the corners at the vertex of patch \"{}\" do not form one fan (a non-manifold vertex)",
                                     p.name));
    }
    const int n = static_cast<int>(v.corners.size());
    if (!boundary && n < 3) {
      const Patch& p = model.patches[static_cast<size_t>(chosen[static_cast<size_t>(members.front() / 4)])];
      return unsupported(fmt::format("an interior vertex of patch \"{}\" where only {} patches meet", p.name, n));
    }
    // Vertex point: mean of the corners (they agree within the gap).
    Vec3 sum = Vec3::Zero();
    for (const auto& cr : v.corners) sum += grid[static_cast<size_t>(cr[0])].at(cr[1] ? kGrid - 1 : 0, cr[2] ? kGrid - 1 : 0);
    v.p = sum / n;
    if (boundary) v.p = grid[static_cast<size_t>(v.edges.front().slots[0].patch)].at(v.edges.front().slots[0], 0, 0);
    if (boundary && v.edges.size() >= 3) {
      // A kept seam (design crease) that ends here: its two sides open the fan. G1 on every other seam of the fan
      // would put all its patches in one tangent plane at the vertex and flatten the crease there: refused.
      auto kp = keptPartner.find(v.edges.front().slots.front());
      if (kp != keptPartner.end() && kp->second == v.edges.back().slots.front())
        return unsupported(fmt::format(
            "a kept crease ends at the vertex ({:.6g}, {:.6g}, {:.6g}): making the other {} seams there G1 would "
            "flatten the crease at that vertex",
            v.p.x(), v.p.y(), v.p.z(), v.edges.size() - 2));
    }
    const int vid = static_cast<int>(vertices.size());
    for (int i = 0; i < static_cast<int>(v.edges.size()); ++i)
      for (const Slot& s : v.edges[static_cast<size_t>(i)].slots) slotVertexEdge[s] = {vid, i};
    vertices.push_back(std::move(v));
  }
  // Interior edges know their vertices.
  for (int e = 0; e < static_cast<int>(edges.size()); ++e) {
    NetEdge& ne = edges[static_cast<size_t>(e)];
    for (int end = 0; end < 2; ++end) {
      Slot s = ne.side[0];
      if (end == 1) s.end = 1 - s.end;
      const auto [vid, ei] = slotVertexEdge.at(s);
      ne.vtx[static_cast<size_t>(end)] = vid;
      ne.vtxEdge[static_cast<size_t>(end)] = ei;
      vertices[static_cast<size_t>(vid)].edges[static_cast<size_t>(ei)].netEdge = e;
    }
  }

  // ---- 3. tangent fit per vertex.
  const double pi = std::numbers::pi;
  for (Vertex& v : vertices) {
    const int m = static_cast<int>(v.edges.size());
    for (VertexEdge& ve : v.edges) {
      Vec3 t = Vec3::Zero();
      for (const Slot& s : ve.slots) {
        const Grid& g = grid[static_cast<size_t>(s.patch)];
        t += kDeg * (g.at(s, 0, 1) - g.at(s, 0, 0));
      }
      ve.tOld = t / static_cast<double>(ve.slots.size());
      ve.t = ve.tOld;
    }
    double tmax = 0.0;
    for (const VertexEdge& ve : v.edges) tmax = std::max(tmax, ve.tOld.norm());
    if (!(tmax > 0.0)) return Status(ErrorCode::kDegenerate, "a vertex whose edges have zero tangents");
    // Orientation reference: the corner normals of the input.
    Vec3 nsum = Vec3::Zero();
    const int sectors = v.boundary ? m - 1 : m;
    for (int j = 0; j < sectors; ++j) {
      const Vec3 a = v.edges[static_cast<size_t>(j)].tOld, b = v.edges[static_cast<size_t>((j + 1) % m)].tOld;
      nsum += a.cross(b).normalized();
    }
    if (!v.boundary) {
      const int n = m;
      Vec3 a = Vec3::Zero(), b = Vec3::Zero();
      for (int i = 0; i < n; ++i) {
        const double th = 2.0 * pi * i / n;
        a += (2.0 / n) * std::cos(th) * v.edges[static_cast<size_t>(i)].tOld;
        b += (2.0 / n) * std::sin(th) * v.edges[static_cast<size_t>(i)].tOld;
      }
      const Vec3 nrm = a.cross(b);
      if (!(nrm.norm() > 1e-3 * a.norm() * b.norm()) || nrm.dot(nsum) <= 0.0)
        return Status(ErrorCode::kNoSolution,
                      fmt::format("the tangent fit at the vertex ({:.6g}, {:.6g}, {:.6g}) of valence {} degenerates or folds",
                                  v.p.x(), v.p.y(), v.p.z(), n));
      v.normal = nrm.normalized();
      for (int i = 0; i < n; ++i) {
        const double th = 2.0 * pi * i / n;
        VertexEdge& ve = v.edges[static_cast<size_t>(i)];
        ve.t = std::cos(th) * a + std::sin(th) * b;
        ve.gamma0 = 2.0 * std::cos(2.0 * pi / n);
      }
    } else if (m >= 3) {
      const int k = m - 1;  // patches in the fan
      const Vec3 N = nsum.normalized();
      auto proj = [&](const Vec3& x) { return Vec3(x - x.dot(N) * N); };
      double Theta = 0.0;
      for (int j = 0; j < k; ++j) {
        const Vec3 a = proj(v.edges[static_cast<size_t>(j)].tOld), b = proj(v.edges[static_cast<size_t>(j + 1)].tOld);
        Theta += std::atan2(a.cross(b).dot(N), a.dot(b));
      }
      if (!(Theta > 0.0 && Theta < 2.0 * pi))
        return Status(ErrorCode::kNoSolution, fmt::format("a boundary vertex ({:.6g}, {:.6g}, {:.6g}) whose fan folds",
                                                          v.p.x(), v.p.y(), v.p.z()));
      const Vec3 a = v.edges.front().tOld, tk = v.edges.back().tOld;
      Vec3 b;
      if (std::abs(std::sin(Theta)) > kStraightFanSin) {
        b = (tk - a * std::cos(Theta)) / std::sin(Theta);
      } else {
        b = Vec3::Zero();
        double den = 0.0;
        for (int i = 1; i < k; ++i) {
          const double th = i * Theta / k;
          b += std::sin(th) * (v.edges[static_cast<size_t>(i)].tOld - std::cos(th) * a);
          den += std::sin(th) * std::sin(th);
        }
        b /= den;
        if ((a * std::cos(Theta) + b * std::sin(Theta) - tk).norm() > 1e-9 * tmax)
          return Status(ErrorCode::kNoSolution,
                        fmt::format("the boundary vertex ({:.6g}, {:.6g}, {:.6g}) has nearly opposite free edges of "
                                    "different tangent lengths: no symmetric fan fits them",
                                    v.p.x(), v.p.y(), v.p.z()));
      }
      v.normal = a.cross(b).normalized();
      if (v.normal.dot(N) < 0.0) v.normal = -v.normal;
      for (int i = 1; i < k; ++i) {
        const double th = i * Theta / k;
        VertexEdge& ve = v.edges[static_cast<size_t>(i)];
        ve.t = std::cos(th) * a + std::sin(th) * b;
        ve.gamma0 = 2.0 * std::cos(Theta / k);
      }
    }
    // No sector may degenerate or turn over.
    for (int j = 0; j < sectors; ++j) {
      const Vec3 a = v.edges[static_cast<size_t>(j)].t, b = v.edges[static_cast<size_t>((j + 1) % m)].t;
      const Vec3 a0 = v.edges[static_cast<size_t>(j)].tOld, b0 = v.edges[static_cast<size_t>((j + 1) % m)].tOld;
      if (!(a.cross(b).dot(a0.cross(b0)) > 0.0) || a.cross(b).norm() < 1e-3 * a.norm() * b.norm())
        return Status(ErrorCode::kNoSolution,
                      fmt::format("the tangent fit at the vertex ({:.6g}, {:.6g}, {:.6g}) folds a patch corner",
                                  v.p.x(), v.p.y(), v.p.z()));
    }
    LocalSchemeVertex lv;
    lv.point = v.p;
    lv.valence = static_cast<int>(v.corners.size());
    lv.boundary = v.boundary;
    for (const VertexEdge& ve : v.edges) lv.tangentFitRel = std::max(lv.tangentFitRel, (ve.t - ve.tOld).norm() / tmax);
    if (!(lv.tangentFitRel <= kMaxTangentFitRel))
      return Status(ErrorCode::kNoSolution,
                    fmt::format("the tangent fit at the vertex ({:.6g}, {:.6g}, {:.6g}) of valence {} would move a "
                                "tangent by {:.3g} x its length",
                                v.p.x(), v.p.y(), v.p.z(), lv.valence, lv.tangentFitRel));
    rep.vertices.push_back(lv);
  }

  // ---- 4. edge curves: two cubic halves (P, A, C, M), C1 at M = (C_P + C_Q) / 2, fitted to the old edge.
  for (NetEdge& ne : edges) {
    std::array<Vec3, 2> P, A;
    std::array<HalfRow, 2> oldHalf;
    for (int end = 0; end < 2; ++end) {
      const Vertex& v = vertices[static_cast<size_t>(ne.vtx[static_cast<size_t>(end)])];
      const VertexEdge& ve = v.edges[static_cast<size_t>(ne.vtxEdge[static_cast<size_t>(end)])];
      P[static_cast<size_t>(end)] = v.p;
      A[static_cast<size_t>(end)] = v.p + ve.t / 3.0;
      HalfRow h = HalfRow::Zero();
      for (const Slot& s0 : ne.side) {
        Slot s = s0;
        if (end == 1) s.end = 1 - s.end;
        h += halfRow(old[static_cast<size_t>(s.patch)], s, 0);
      }
      oldHalf[static_cast<size_t>(end)] = 0.5 * h;
    }
    // Least squares on samples w = 1/8 .. 7/8 of both halves; unknowns C_P, C_Q (coordinates separate).
    Eigen::Matrix2d NtN = Eigen::Matrix2d::Zero();
    Eigen::Matrix<double, 2, 3> Ntb = Eigen::Matrix<double, 2, 3>::Zero();
    for (int end = 0; end < 2; ++end) {
      const BernsteinPoly target(oldHalf[static_cast<size_t>(end)]);
      for (int s = 1; s <= 7; ++s) {
        const double w = s / 8.0, u = 1.0 - w;
        const double b0 = u * u * u, b1 = 3 * u * u * w, b2 = 3 * u * w * w, b3 = w * w * w;
        // Phi = b0 P + b1 A + b2 C_end + b3 (C_P + C_Q) / 2
        Eigen::Vector2d row;
        row[end] = b2 + 0.5 * b3;
        row[1 - end] = 0.5 * b3;
        const Vec3 rhs = target(w).head<3>() - b0 * P[static_cast<size_t>(end)] - b1 * A[static_cast<size_t>(end)];
        NtN += row * row.transpose();
        Ntb += row * rhs.transpose();
      }
    }
    const Eigen::Matrix<double, 2, 3> Cs = NtN.ldlt().solve(Ntb);
    for (int end = 0; end < 2; ++end) {
      Vertex& v = vertices[static_cast<size_t>(ne.vtx[static_cast<size_t>(end)])];
      v.edges[static_cast<size_t>(ne.vtxEdge[static_cast<size_t>(end)])].curvature = Cs.row(end).transpose();
    }
  }

  // ---- 5. corner systems per vertex: twist points, gamma'(0), and (even n >= 6) curvature corrections.
  for (size_t vi = 0; vi < vertices.size(); ++vi) {
    Vertex& v = vertices[vi];
    const int m = static_cast<int>(v.edges.size());
    const int nc = static_cast<int>(v.corners.size());
    std::vector<int> interior;
    for (int i = 0; i < m; ++i)
      if (v.edges[static_cast<size_t>(i)].netEdge >= 0) interior.push_back(i);
    if (interior.empty()) continue;
    const bool evenCorrection = !v.boundary && nc % 2 == 0 && nc >= 6;
    // Unknowns: D_j (3 per corner), gamma'_i (1 per interior edge), s_i (even correction).
    const int ni = static_cast<int>(interior.size());
    const int nUnk = 3 * nc + ni + (evenCorrection ? ni : 0);
    Eigen::MatrixXd C = Eigen::MatrixXd::Zero(3 * ni, nUnk);
    Eigen::VectorXd d = Eigen::VectorXd::Zero(3 * ni), x0 = Eigen::VectorXd::Zero(nUnk), w = Eigen::VectorXd::Zero(nUnk);
    // Corner j lies between edges j and j+1 (mod m for a closed fan).
    for (int j = 0; j < nc; ++j) {
      const auto& cr = v.corners[static_cast<size_t>(j)];
      const Grid& g = old[static_cast<size_t>(cr[0])];
      const int i1 = cr[1] ? kGrid - 2 : 1, i0 = cr[1] ? kGrid - 1 : 0;
      const int j1 = cr[2] ? kGrid - 2 : 1, j0 = cr[2] ? kGrid - 1 : 0;
      const Vec3 D0 = g.at(i1, j1) - g.at(i1, j0) - g.at(i0, j1) + g.at(i0, j0);
      for (int c = 0; c < 3; ++c) {
        x0[3 * j + c] = D0[c];
        w[3 * j + c] = 1.0;
      }
    }
    for (int r = 0; r < ni; ++r) {
      const int i = interior[static_cast<size_t>(r)];
      const VertexEdge& ve = v.edges[static_cast<size_t>(i)];
      const int jm = (i - 1 + nc) % nc, jp = i % nc;  // corners beside edge i
      const Vec3 A = v.p + ve.t / 3.0;
      const Vec3 phi2 = 6.0 * (v.p - 2.0 * A + ve.curvature);
      for (int c = 0; c < 3; ++c) {
        const int row = 3 * r + c;
        C(row, 3 * jm + c) += 25.0;
        C(row, 3 * jp + c) += 25.0;
        C(row, 3 * nc + r) = -ve.t[c];
        d[row] = ve.gamma0 * phi2[c];
        if (evenCorrection) C(row, 3 * nc + ni + r) = -6.0 * ve.gamma0 * v.normal[c];
      }
      if (evenCorrection) w[3 * nc + ni + r] = opt.curvatureWeight;
    }
    double resid = 0.0;
    const Eigen::VectorXd x = detail::constrainedLeastSquaresQR(C, d, x0, w, &resid);
    double scale = d.cwiseAbs().maxCoeff();
    for (const VertexEdge& ve : v.edges) scale = std::max(scale, ve.t.norm());
    const double rel = resid / std::max(scale, std::numeric_limits<double>::min());
    rep.vertices[vi].cornerResidual = rel;
    if (!(rel <= detail::kConstraintRelTol))
      return Status(ErrorCode::kNoSolution,
                    fmt::format("the corner system at the vertex ({:.6g}, {:.6g}, {:.6g}) of valence {} has no solution "
                                "(residual {:.3g})",
                                v.p.x(), v.p.y(), v.p.z(), nc, rel));
    for (int r = 0; r < ni; ++r) {
      VertexEdge& ve = v.edges[static_cast<size_t>(interior[static_cast<size_t>(r)])];
      ve.gamma1 = x[3 * nc + r];
      if (evenCorrection) {
        const double s = x[3 * nc + ni + r];
        ve.curvature += s * v.normal;
        rep.vertices[vi].curvatureCorrection = std::max(rep.vertices[vi].curvatureCorrection, std::abs(s));
      }
    }
    // Corner blocks: vertex, the two tangent points, the twist point.
    for (int j = 0; j < nc; ++j) {
      const auto& cr = v.corners[static_cast<size_t>(j)];
      Grid& g = grid[static_cast<size_t>(cr[0])];
      const auto ss = slotsAt(cr[0], cr[1], cr[2]);
      // The edges of this corner in the vertex's order: j and j+1; find which slot is which.
      const VertexEdge& ea = v.edges[static_cast<size_t>(j)];
      const VertexEdge& eb = v.edges[static_cast<size_t>((j + 1) % m)];
      auto tangentOf = [&](const Slot& s) -> Vec3 {
        for (const Slot& q : ea.slots)
          if (q == s) return ea.t;
        for (const Slot& q : eb.slots)
          if (q == s) return eb.t;
        return Vec3::Constant(std::numeric_limits<double>::quiet_NaN());
      };
      const Vec3 t0 = tangentOf(ss[0]), t1 = tangentOf(ss[1]);
      if (!t0.allFinite() || !t1.allFinite()) return Status(ErrorCode::kNoSolution, "internal: corner slots not found");
      g.set(ss[0], 0, 0, v.p);
      g.set(ss[0], 0, 1, v.p + t0 / kDeg);  // along slot 0's edge
      g.set(ss[1], 0, 1, v.p + t1 / kDeg);  // along slot 1's edge
      const Vec3 D = x.segment<3>(3 * j);
      g.set(ss[0], 1, 1, v.p + t0 / kDeg + t1 / kDeg + D);  // P11 = P10 + P01 - P00 + D
    }
  }

  // ---- 6. the rows beside every interior edge.
  double edgeResidualMax = 0.0;
  for (const NetEdge& ne : edges) {
    // Per end: the cubic (P, A, C, M) and gamma data.
    std::array<Vec3, 2> P, A, Cc;
    std::array<double, 2> g0{}, g1{};
    for (int end = 0; end < 2; ++end) {
      const Vertex& v = vertices[static_cast<size_t>(ne.vtx[static_cast<size_t>(end)])];
      const VertexEdge& ve = v.edges[static_cast<size_t>(ne.vtxEdge[static_cast<size_t>(end)])];
      P[static_cast<size_t>(end)] = v.p;
      A[static_cast<size_t>(end)] = v.p + ve.t / 3.0;
      Cc[static_cast<size_t>(end)] = ve.curvature;
      g0[static_cast<size_t>(end)] = ve.gamma0;
      g1[static_cast<size_t>(end)] = ve.gamma1;
    }
    const Vec3 M = 0.5 * (Cc[0] + Cc[1]);
    std::array<Matrix, 2> row0;
    std::array<HalfRow, 2> gk, gg;
    for (int end = 0; end < 2; ++end) {
      const size_t e = static_cast<size_t>(end);
      row0[e] = elevatedCubic(P[e], A[e], Cc[e], M);
      std::tie(gk[e], gg[e]) = gammaPhiPrime(g0[e], g1[e], P[e], A[e], Cc[e], M);
    }
    // Row 0 of both sides.
    for (const Slot& s0 : ne.side)
      for (int end = 0; end < 2; ++end) {
        Slot s = s0;
        if (end == 1) s.end = 1 - s.end;
        Grid& g = grid[static_cast<size_t>(s.patch)];
        for (int x = 0; x <= 4; ++x) g.set(s, 0, x, row0[static_cast<size_t>(end)].row(x).transpose());
      }
    // Unknowns: row-1 points x = 2, 3, 4 of side s at end e, b(s, e, x), and g, with the smallest change
    // sum |b(s, e, x) - t(s, e, x)|^2 of the cross-boundary vectors (targets t). Every equation reads the two sides
    // through their sum sigma(e, x) = b(0, e, x) + b(1, e, x) only, and for a given sum that change is smallest at
    // b(s) = t(s) + (sigma - t(0) - t(1)) / 2 (it is then |sigma - t(0) - t(1)|^2 / 2): the system is solved for
    // sigma (index (e * 3 + (x - 2)) * 3 + c) and g, half the unknowns.
    //
    // The system, row (e, k, c): k = 2..4: 5 sigma(e, k) - gg_e(k) g = d(e, k); k = 5:
    // 5/2 (sigma(0, 4) + sigma(1, 4)) = d(e, 5), with gg_e(k) the coefficients of g in gamma Phi' (gg_e(5) = 0:
    // gamma's part in g, (0, 0, -1/3, 0), times Phi''s (3 (A - P), 3 (C - A), 3 (M - C)) has no degree-5 term).
    // The k = 5 rows do not involve g, and the sum of the k = 4 rows, 5 (sigma(0, 4) + sigma(1, 4)) +
    // (3/5) (2 M - C_P - C_Q) g, is g-free too (M = (C_P + C_Q) / 2). They hold by construction (the common middle
    // point M makes d(0, 5) = d(1, 5) = 10 M and sigma(0, 4) + sigma(1, 4) = 4 M), and the residual below checks
    // them. So sigma(e, k) = (d(e, k) + gg_e(k) g) / 5 with one free parameter g, chosen for the smallest change
    // sum |sigma(e, k) - t(0, e, k) - t(1, e, k)|^2: with u = gg / 5 and v = d / 5 - (t(0) + t(1)),
    // g = -sum u v / sum u^2 (0 where every u vanishes). This is the solution of detail::constrainedLeastSquaresQR on
    // the same rows (rank 18 of 19 unknowns, nullspace direction (gg / 5, 1), weight 1 on sigma and 0 on g) in
    // closed form: the same up to round-off.
    std::array<std::array<std::array<Vec3, 3>, 2>, 2> target;  // [s][e][x - 2]
    std::array<std::array<Vec3, 3>, 2> sum0;                   // [e][x - 2]: t(0) + t(1)
    for (int s = 0; s < 2; ++s)
      for (int e = 0; e < 2; ++e) {
        Slot sl = ne.side[static_cast<size_t>(s)];
        if (e == 1) sl.end = 1 - sl.end;
        const Grid& go = old[static_cast<size_t>(sl.patch)];
        for (int x = 2; x <= 4; ++x) {
          // Keep the cross-boundary vector: target = new row 0 + (old row 1 - old row 0).
          const Vec3 t = row0[static_cast<size_t>(e)].row(x).transpose() + go.at(sl, 1, x) - go.at(sl, 0, x);
          target[static_cast<size_t>(s)][static_cast<size_t>(e)][static_cast<size_t>(x - 2)] = t;
          Vec3& sm = sum0[static_cast<size_t>(e)][static_cast<size_t>(x - 2)];
          sm = s == 0 ? t : Vec3(sm + t);
        }
      }
    // Right-hand sides d(e, k, c) (k = 2..5) and the coefficients of g, -gg_e(k, c), as the rows of the system.
    std::array<std::array<Vec3, 4>, 2> d, cg;  // [e][k - 2]
    for (int e = 0; e < 2; ++e)
      for (int k = 2; k <= 5; ++k)
        for (int c = 0; c < 3; ++c) {
          double rhs = gk[static_cast<size_t>(e)](k, c);
          for (int s = 0; s < 2; ++s) rhs += kDeg * row0[static_cast<size_t>(e)](k, c);
          d[static_cast<size_t>(e)][static_cast<size_t>(k - 2)][c] = rhs;
          cg[static_cast<size_t>(e)][static_cast<size_t>(k - 2)][c] = -gg[static_cast<size_t>(e)](k, c);
        }
    double uv = 0.0, uu = 0.0;
    for (size_t e = 0; e < 2; ++e)
      for (size_t k = 0; k < 3; ++k)
        for (int c = 0; c < 3; ++c) {
          const double u = -cg[e][k][c] / kDeg, v = d[e][k][c] / kDeg - sum0[e][k][c];
          uv += u * v;
          uu += u * u;
        }
    const double gFree = uu > 0.0 ? -uv / uu : 0.0;
    std::array<std::array<std::array<Vec3, 3>, 2>, 2> b;  // [s][e][x - 2]
    for (size_t e = 0; e < 2; ++e)
      for (size_t ux = 0; ux < 3; ++ux) {
        const Vec3 sigma = (d[e][ux] - cg[e][ux] * gFree) / kDeg;
        const Vec3 half = 0.5 * (sigma - target[0][e][ux] - target[1][e][ux]);
        for (size_t s = 0; s < 2; ++s) b[s][e][ux] = target[s][e][ux] + half;
      }
    // The residual of the equations in the points themselves (as written to the grids).
    double resid = 0.0, dMax = 0.0;
    for (int e = 0; e < 2; ++e)
      for (int k = 2; k <= 5; ++k)
        for (int c = 0; c < 3; ++c) {
          const size_t ue = static_cast<size_t>(e), uo = static_cast<size_t>(1 - e), uk = static_cast<size_t>(k - 2);
          double lhs = cg[ue][uk][c] * gFree;
          for (size_t s = 0; s < 2; ++s) {
            if (k <= 4) lhs += kDeg * b[s][ue][uk][c];
            else lhs += 0.5 * kDeg * b[s][ue][2][c] + 0.5 * kDeg * b[s][uo][2][c];
          }
          resid = std::max(resid, std::abs(lhs - d[ue][uk][c]));
          dMax = std::max(dMax, std::abs(d[ue][uk][c]));
        }
    const double scale = std::max(dMax, (P[1] - P[0]).norm());
    edgeResidualMax = std::max(edgeResidualMax, resid / std::max(scale, std::numeric_limits<double>::min()));
    for (int s = 0; s < 2; ++s)
      for (int e = 0; e < 2; ++e) {
        Slot sl = ne.side[static_cast<size_t>(s)];
        if (e == 1) sl.end = 1 - sl.end;
        Grid& g = grid[static_cast<size_t>(sl.patch)];
        for (int xx = 2; xx <= 4; ++xx)
          g.set(sl, 1, xx, b[static_cast<size_t>(s)][static_cast<size_t>(e)][static_cast<size_t>(xx - 2)]);
      }
  }
  if (!(edgeResidualMax <= detail::kConstraintRelTol))
    return Status(ErrorCode::kNoSolution,
                  fmt::format("the rows beside the edges cannot meet the G1 identity (residual {:.3g})", edgeResidualMax));

  // ---- 7. verify the vertex and middle coefficients of the identity on every half from the final grids.
  double identityMax = 0.0;
  for (const NetEdge& ne : edges)
    for (int end = 0; end < 2; ++end) {
      const Vertex& v = vertices[static_cast<size_t>(ne.vtx[static_cast<size_t>(end)])];
      const VertexEdge& ve = v.edges[static_cast<size_t>(ne.vtxEdge[static_cast<size_t>(end)])];
      std::array<HalfRow, 2> r0, r1;
      for (int s = 0; s < 2; ++s) {
        Slot sl = ne.side[static_cast<size_t>(s)];
        if (end == 1) sl.end = 1 - sl.end;
        r0[static_cast<size_t>(s)] = halfRow(grid[static_cast<size_t>(sl.patch)], sl, 0);
        r1[static_cast<size_t>(s)] = halfRow(grid[static_cast<size_t>(sl.patch)], sl, 1);
      }
      const Vertex& vq = vertices[static_cast<size_t>(ne.vtx[static_cast<size_t>(1 - end)])];
      const VertexEdge& vqe = vq.edges[static_cast<size_t>(ne.vtxEdge[static_cast<size_t>(1 - end)])];
      const Vec3 M = 0.5 * (ve.curvature + vqe.curvature);
      const HalfRow gk = gammaPhiPrime(ve.gamma0, ve.gamma1, v.p, v.p + ve.t / 3.0, ve.curvature, M).first;
      // Coefficients 0, 1 (the vertex's tangent and twist conditions) and 5 (the middle) do not depend on
      // g = gamma'(1); coefficients 2..4 were checked by the edge solve's residual.
      const Matrix lhs = kDeg * (r1[0] - r0[0]) + kDeg * (r1[1] - r0[1]);
      for (int k : {0, 1, 5}) {
        const double err = (lhs.row(k) - gk.row(k)).norm();
        const double sc = std::max(lhs.row(k).norm(), ve.t.norm());
        identityMax = std::max(identityMax, err / std::max(sc, std::numeric_limits<double>::min()));
      }
    }
  if (!(identityMax <= detail::kConstraintRelTol))
    return Status(ErrorCode::kNoSolution, fmt::format("internal: the G1 identity fails at a vertex (residual {:.3g})", identityMax));

  // ---- 8. write the patches, displacement.
  for (int r = 0; r < np; ++r) {
    const int mi = chosen[static_cast<size_t>(r)];
    const BSplineSurface& f = form[static_cast<size_t>(r)];
    BSplineSurface ns(kDeg, kDeg, f.knotsU(), f.knotsV(), kGrid, kGrid, grid[static_cast<size_t>(r)].q);
    Patch& out = res.model.patches[static_cast<size_t>(mi)];
    const Patch& in = model.patches[static_cast<size_t>(mi)];
    // The input in the output's knots and degrees is its scheme form (toSchemeForm raises and refines exactly as
    // detail::expressedLike(in.surface, ns) does: the same bits).
    const double disp = (f.points() - ns.points()).rowwise().norm().maxCoeff();
    const double size = std::max(controlBox(in.surface).diagonal(), std::numeric_limits<double>::min());
    if (disp > rep.maxDisplacement) rep.maxDisplacement = disp;
    rep.maxDisplacementRel = std::max(rep.maxDisplacementRel, disp / size);
    out = detail::replacedSurface(in, std::move(ns));
    rep.patchesChanged.push_back(in.name);
    if (inputForms) inputForms->emplace_back(mi, std::move(form[static_cast<size_t>(r)]));
  }
  std::set<int> val;
  for (const Vertex& v : vertices)
    if (!v.boundary) val.insert(static_cast<int>(v.corners.size()));
  rep.valences.assign(val.begin(), val.end());
  if (raised)
    rep.notes.push_back("patches written as biquintic B-splines with the knot 1/2 of multiplicity 4 (degree raised and "
                        "knots inserted exactly before the scheme)");
  int corrected = 0;
  for (const LocalSchemeVertex& lv : rep.vertices)
    if (lv.curvatureCorrection > 0.0) ++corrected;
  if (corrected)
    rep.notes.push_back(fmt::format("{} vertices of even valence >= 6: curvature points moved along the normal onto "
                                    "the even-valence restriction",
                                    corrected));
  return res;
}

}  // namespace seam
