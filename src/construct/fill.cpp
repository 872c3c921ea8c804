// Johansson Section 4 on a model: the 4th patch at a vertex, hole filling, fillets, and their verification.
#include "seam/construct/fill.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include "construct/construct_internal.h"

namespace seam {

namespace ci = construct_internal;

namespace {

/// Samples of an edge used to decide whether two edges coincide (ends, quarter points and middle): a topology
/// test, not a certification (analyzeSeam certifies the seams).
constexpr std::array<double, 5> kEdgeMatchParams = {0.0, 0.25, 0.5, 0.75, 1.0};

bool atLeastG1(GeometricClass c) { return static_cast<int>(c) >= static_cast<int>(GeometricClass::kG1); }

Tolerances tolerancesFor(const Model& model, const FillOptions& options) {
  return options.tolerances.value_or(Tolerances::forModelSize(model.boundingBox().diagonal()));
}

Result<int> patchIndex(const Model& model, const std::string& name) {
  for (size_t i = 0; i < model.patches.size(); ++i) {
    if (model.patches[i].name == name) return static_cast<int>(i);
  }
  return Status(ErrorCode::kNotFound, fmt::format("no patch named \"{}\"", name));
}

/// Points of a model patch's edge at kEdgeMatchParams (fractions of the edge's parameter range).
std::array<Vec3, kEdgeMatchParams.size()> edgeSamples(const Patch& p, Edge e) {
  const BSplineCurve c = p.surface.boundaryCurve(e);
  const Interval d = c.domain();
  std::array<Vec3, kEdgeMatchParams.size()> out;
  for (size_t k = 0; k < kEdgeMatchParams.size(); ++k)
    out[k] = c.evaluate(d.lo + kEdgeMatchParams[k] * d.length()).head<3>();
  return out;
}

struct EdgeGeom {
  int patch = 0;
  Edge edge = Edge::U0;
  std::array<Vec3, kEdgeMatchParams.size()> pts;
  [[nodiscard]] const Vec3& start() const { return pts.front(); }
  [[nodiscard]] const Vec3& end() const { return pts.back(); }
};

/// True when the two edges coincide within `tol` at every sample (same or opposite direction).
bool sameEdge(const EdgeGeom& a, const EdgeGeom& b, double tol, bool* reversed = nullptr) {
  const size_t n = a.pts.size();
  bool fwd = true, rev = true;
  for (size_t k = 0; k < n; ++k) {
    fwd = fwd && (a.pts[k] - b.pts[k]).norm() <= tol;
    rev = rev && (a.pts[k] - b.pts[n - 1 - k]).norm() <= tol;
  }
  if (reversed) *reversed = !fwd && rev;
  return fwd || rev;
}

std::vector<EdgeGeom> edgesOf(const Model& model, std::span<const int> patches) {
  std::vector<EdgeGeom> out;
  for (int p : patches) {
    for (Edge e : kAllEdges) out.push_back({p, e, edgeSamples(model.patches[static_cast<size_t>(p)], e)});
  }
  return out;
}

/// Pairs of coinciding edges of different patches (sweep over the middle point's x coordinate).
std::vector<std::pair<int, int>> matchEdges(const std::vector<EdgeGeom>& edges, double tol) {
  std::vector<int> order(edges.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
  auto midX = [&](int i) { return edges[static_cast<size_t>(i)].pts[2].x(); };
  std::sort(order.begin(), order.end(), [&](int a, int b) { return midX(a) < midX(b); });
  std::vector<std::pair<int, int>> pairs;
  for (size_t a = 0; a < order.size(); ++a) {
    for (size_t b = a + 1; b < order.size() && midX(order[b]) - midX(order[a]) <= tol; ++b) {
      const EdgeGeom& ea = edges[static_cast<size_t>(order[a])];
      const EdgeGeom& eb = edges[static_cast<size_t>(order[b])];
      if (ea.patch == eb.patch) continue;
      if (sameEdge(ea, eb, tol))
        pairs.emplace_back(std::min(order[a], order[b]), std::max(order[a], order[b]));
    }
  }
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

std::vector<int> allPatches(const Model& model) {
  std::vector<int> all(model.patches.size());
  for (size_t i = 0; i < all.size(); ++i) all[i] = static_cast<int>(i);
  return all;
}

/// Transposes the new patch (u <-> v) of a construction and the edges of its seams: used to orient a new
/// patch like its neighbours.
void transposeNew(G1PatchResult& r, std::vector<FillSeam>& seams) {
  const BezierPatch& p = r.patch;
  Matrix pts(p.points().rows(), p.points().cols());
  for (int i = 0; i <= p.degreeU(); ++i)
    for (int j = 0; j <= p.degreeV(); ++j) pts.row(j * (p.degreeU() + 1) + i) = p.point(i, j);
  r.patch = BezierPatch(p.degreeV(), p.degreeU(), std::move(pts));
  auto swapEdge = [](Edge e) {
    switch (e) {
      case Edge::U0:
        return Edge::V0;
      case Edge::U1:
        return Edge::V1;
      case Edge::V0:
        return Edge::U0;
      case Edge::V1:
        return Edge::U1;
    }
    return e;
  };
  for (FillSeam& s : seams) s.newEdge = swapEdge(s.newEdge);
  for (CornerCompatibility& c : r.corners) {
    if (c.corner == 1 || c.corner == 2) c.corner = 3 - c.corner;
    std::swap(c.seamU, c.seamV);
  }
  for (G1Attempt& a : r.attempts) std::swap(a.degreeU, a.degreeV);
}

/// Normal (S_u x S_v, not normalised) of a Bezier patch at a corner.
Vec3 cornerNormal(const BezierPatch& b, int corner) {
  const double u = (corner & 1) ? 1.0 : 0.0, v = (corner & 2) ? 1.0 : 0.0;
  const auto d = b.derivatives(u, v, 1);
  return Vec3(d[1][0].head<3>()).cross(Vec3(d[0][1].head<3>()));
}

/// One seam of a new patch to build: the neighbour (model index or earlier new patch), its edge, N's edge.
struct SeamPlan {
  std::string neighbourName;
  BezierPatch neighbour;
  Edge neighbourEdge = Edge::U0;
  Edge newEdge = Edge::U0;
  bool reversed = false;
};

/// Builds one new patch from its seam plan, orients it like the first neighbour, and appends it to `out`.
Status buildOne(const std::vector<SeamPlan>& plan, const G1PatchOptions& options, const std::string& name,
                const std::string& role, FillResult& out) {
  std::vector<G1SeamSpec> specs;
  for (const SeamPlan& s : plan) {
    G1SeamSpec spec;
    spec.neighbour = s.neighbour;
    spec.neighbourEdge = s.neighbourEdge;
    spec.newEdge = s.newEdge;
    spec.reversed = s.reversed;
    specs.push_back(std::move(spec));
  }
  Result<G1PatchResult> built = buildG1Patch(specs, options);
  if (!built) return built.status().withContext(fmt::format("new patch \"{}\"", name));
  G1PatchResult r = std::move(built).value();
  std::vector<FillSeam> seams;
  for (size_t s = 0; s < plan.size(); ++s) {
    seams.push_back({name, plan[s].newEdge, plan[s].neighbourName, plan[s].neighbourEdge, plan[s].reversed,
                     r.functions[s]});
  }
  // Orientation: N's normal at a corner on the first seam should agree with the neighbour's normal there.
  const SeamPlan& first = plan.front();
  const int nCorner = ci::edgeCorner(first.newEdge, false);
  const int aCorner = ci::edgeCorner(first.neighbourEdge, first.reversed);
  if (cornerNormal(r.patch, nCorner).dot(cornerNormal(first.neighbour, aCorner)) < 0.0) {
    transposeNew(r, seams);
    r.notes.push_back(
        fmt::format("u and v swapped so that the normal agrees with \"{}\"", first.neighbourName));
  }
  for (const std::string& n : r.notes) out.notes.push_back(fmt::format("{}: {}", name, n));
  FilledPatch fp{ci::bezierModelPatch(name, r.patch), role, std::move(r)};
  out.patches.push_back(std::move(fp));
  out.seams.insert(out.seams.end(), seams.begin(), seams.end());
  return Status::ok();
}

std::vector<std::string> takenNames(const Model& model, const FillResult& out) {
  std::vector<std::string> names;
  for (const Patch& p : model.patches) names.push_back(p.name);
  for (const FilledPatch& p : out.patches) names.push_back(p.patch.name);
  return names;
}

/// Seam reports among the patches `around` (every pair of coinciding edges).
std::vector<SeamReport> analyzeAmong(const Model& model, std::span<const int> around, const Tolerances& tol,
                                     SeamOptions seamOptions, std::vector<std::string>& notes) {
  seamOptions.tol = tol;
  const std::vector<EdgeGeom> edges = edgesOf(model, around);
  std::vector<SeamReport> out;
  for (const auto& [i, j] : matchEdges(edges, tol.distance)) {
    const EdgeGeom& a = edges[static_cast<size_t>(i)];
    const EdgeGeom& b = edges[static_cast<size_t>(j)];
    const Patch& pa = model.patches[static_cast<size_t>(a.patch)];
    const Patch& pb = model.patches[static_cast<size_t>(b.patch)];
    Result<SeamReport> rep = analyzeSeam(pa, a.edge, pb, b.edge, seamOptions);
    if (!rep) {
      notes.push_back(fmt::format("seam {}.{} / {}.{} could not be analysed: {}", pa.name, edgeName(a.edge),
                                  pb.name, edgeName(b.edge), rep.status().message()));
      SeamReport bad;
      bad.a = pa.name;
      bad.b = pb.name;
      bad.aEdge = a.edge;
      bad.bEdge = b.edge;
      bad.notes.push_back(rep.status().message());
      out.push_back(std::move(bad));
      continue;
    }
    out.push_back(std::move(rep).value());
  }
  return out;
}

}  // namespace

// ---------------------------------------------------------------------------------------------------------------

Result<FillResult> fillQuad(const Model& model, const std::string& cornerName, const std::string& bName,
                            const std::string& cName, const FillOptions& options) {
  const Tolerances tol = tolerancesFor(model, options);
  std::array<int, 3> idx{};
  std::array<BezierPatch, 3> bz;
  const std::array<const std::string*, 3> names = {&cornerName, &bName, &cName};
  for (size_t k = 0; k < 3; ++k) {
    Result<int> i = patchIndex(model, *names[k]);
    if (!i) return i.status();
    idx[k] = *i;
    Result<BezierPatch> b = ci::singleBezier(model.patches[static_cast<size_t>(*i)]);
    if (!b) return b.status();
    bz[k] = std::move(b).value();
  }
  if (idx[0] == idx[1] || idx[0] == idx[2] || idx[1] == idx[2]) {
    return invalidInput("fill --quad: the three patches must be different");
  }
  // The vertex: a corner of each of the three patches at one point.
  std::optional<std::array<int, 3>> vertex;
  for (int a = 0; a < 4 && !vertex; ++a)
    for (int b = 0; b < 4 && !vertex; ++b)
      for (int c = 0; c < 4 && !vertex; ++c) {
        const Vec3 pa = ci::cornerPoint(bz[0], a), pb = ci::cornerPoint(bz[1], b),
                   pc = ci::cornerPoint(bz[2], c);
        if ((pa - pb).norm() <= tol.distance && (pa - pc).norm() <= tol.distance)
          vertex = std::array<int, 3>{a, b, c};
      }
  if (!vertex) {
    return Status(
        ErrorCode::kNotFound,
        fmt::format("patches \"{}\", \"{}\", \"{}\" have no common corner point", cornerName, bName, cName));
  }
  // For the neighbour k (1 = b, 2 = c): its edge through the vertex shared with the corner patch, and the
  // other one.
  auto freeEdgeOf =
      [&](size_t k) -> Result<std::pair<Edge, Edge>> {  // (corner patch's shared edge, k's free edge)
    for (Edge ea : kAllEdges) {
      if (!ci::cornerOnEdge((*vertex)[0], ea)) continue;
      for (Edge ek : kAllEdges) {
        if (!ci::cornerOnEdge((*vertex)[k], ek)) continue;
        const bool rev = ci::edgeCorner(ea, false) == (*vertex)[0] ? ci::edgeCorner(ek, false) != (*vertex)[k]
                                                                   : ci::edgeCorner(ek, true) != (*vertex)[k];
        if (ci::edgeDistance(bz[0], ea, bz[k], ek, rev) > tol.distance) continue;
        for (Edge other : kAllEdges) {
          if (other != ek && ci::cornerOnEdge((*vertex)[k], other)) return std::make_pair(ea, other);
        }
      }
    }
    return Status(ErrorCode::kNotFound,
                  fmt::format("patch \"{}\" shares no edge with \"{}\" through their common corner",
                              *names[k], cornerName));
  };
  Result<std::pair<Edge, Edge>> eb = freeEdgeOf(1);
  if (!eb) return eb.status();
  Result<std::pair<Edge, Edge>> ec = freeEdgeOf(2);
  if (!ec) return ec.status();
  if (eb->first == ec->first) {
    return invalidInput(
        fmt::format("\"{}\" and \"{}\" share the same edge of \"{}\"", bName, cName, cornerName));
  }
  // N: corner (0,0) at the vertex, N(u,0) along b's free edge, N(0,v) along c's free edge (Figure 2: r3
  // against r2, r4).
  std::vector<SeamPlan> plan;
  plan.push_back({bName, bz[1], eb->second, Edge::V0, ci::edgeCorner(eb->second, false) != (*vertex)[1]});
  plan.push_back({cName, bz[2], ec->second, Edge::U0, ci::edgeCorner(ec->second, false) != (*vertex)[2]});
  FillResult out;
  const std::string name =
      ci::uniqueName(options.name.empty() ? "fill" : options.name, takenNames(model, out));
  if (Status s = buildOne(plan, options.patch, name, "quad", out); !s) return s;
  return out;
}

// ---------------------------------------------------------------------------------------------------------------

std::vector<Hole> findHoles(const Model& model, std::span<const int> candidates, double distance) {
  const std::vector<int> all = allPatches(model);
  const std::span<const int> pool = candidates.empty() ? std::span<const int>(all) : candidates;
  const std::vector<EdgeGeom> edges = edgesOf(model, pool);
  std::vector<bool> paired(edges.size(), false);
  for (const auto& [i, j] : matchEdges(edges, distance)) {
    paired[static_cast<size_t>(i)] = paired[static_cast<size_t>(j)] = true;
  }
  // Vertices: end points of free edges, merged within `distance`.
  std::vector<Vec3> verts;
  auto vertexOf = [&](const Vec3& p) {
    for (size_t v = 0; v < verts.size(); ++v)
      if ((verts[v] - p).norm() <= distance) return static_cast<int>(v);
    verts.push_back(p);
    return static_cast<int>(verts.size() - 1);
  };
  struct FreeEdge {
    int edge, v0, v1;
  };
  std::vector<FreeEdge> free;
  for (size_t e = 0; e < edges.size(); ++e) {
    if (paired[e]) continue;
    const int v0 = vertexOf(edges[e].start()), v1 = vertexOf(edges[e].end());
    if (v0 != v1) free.push_back({static_cast<int>(e), v0, v1});
  }
  std::map<int, std::vector<int>> atVertex;  // vertex -> free edges (index into `free`)
  for (size_t f = 0; f < free.size(); ++f) {
    atVertex[free[f].v0].push_back(static_cast<int>(f));
    atVertex[free[f].v1].push_back(static_cast<int>(f));
  }
  auto other = [&](int f, int v) {
    return free[static_cast<size_t>(f)].v0 == v ? free[static_cast<size_t>(f)].v1
                                                : free[static_cast<size_t>(f)].v0;
  };
  auto patchOf = [&](int f) { return edges[static_cast<size_t>(free[static_cast<size_t>(f)].edge)].patch; };
  std::set<std::array<int, 4>> seen;
  std::vector<Hole> holes;
  for (size_t f0 = 0; f0 < free.size(); ++f0) {
    const int c0 = free[f0].v0, c1 = free[f0].v1;
    for (int f1 : atVertex[c1]) {
      if (f1 == static_cast<int>(f0)) continue;
      const int c2 = other(f1, c1);
      for (int f2 : atVertex[c2]) {
        if (f2 == f1) continue;
        const int c3 = other(f2, c2);
        for (int f3 : atVertex[c3]) {
          if (f3 == f2 || other(f3, c3) != c0) continue;
          const std::array<int, 4> fs = {static_cast<int>(f0), f1, f2, f3};
          const std::array<int, 4> cs = {c0, c1, c2, c3};
          std::set<int> patches, corners(cs.begin(), cs.end());
          for (int f : fs) patches.insert(patchOf(f));
          if (patches.size() != 4 || corners.size() != 4) continue;
          std::array<int, 4> key = fs;
          std::sort(key.begin(), key.end());
          if (!seen.insert(key).second) continue;
          Hole h;
          std::set<int> around;
          for (int k = 0; k < 4; ++k) {
            const EdgeGeom& g =
                edges[static_cast<size_t>(free[static_cast<size_t>(fs[static_cast<size_t>(k)])].edge)];
            h.sidePatch[static_cast<size_t>(k)] = g.patch;
            h.sideEdge[static_cast<size_t>(k)] = g.edge;
            h.corners[static_cast<size_t>(k)] = verts[static_cast<size_t>(cs[static_cast<size_t>(k)])];
            around.insert(g.patch);
          }
          for (int p : pool) {  // patches with a corner at a hole corner (the diagonal ones)
            const Patch& mp = model.patches[static_cast<size_t>(p)];
            for (Edge e : kAllEdges) {
              const auto s = edgeSamples(mp, e);
              for (const Vec3& c : h.corners)
                if ((s.front() - c).norm() <= distance || (s.back() - c).norm() <= distance) around.insert(p);
            }
          }
          h.around.assign(around.begin(), around.end());
          holes.push_back(std::move(h));
        }
      }
    }
  }
  return holes;
}

Result<FillResult> fillHole(const Model& model, const std::vector<std::string>& aroundNames,
                            const FillOptions& options) {
  const Tolerances tol = tolerancesFor(model, options);
  std::vector<int> candidates;
  for (const std::string& n : aroundNames) {
    Result<int> i = patchIndex(model, n);
    if (!i) return i.status();
    candidates.push_back(*i);
  }
  const std::vector<Hole> holes = findHoles(model, candidates, tol.distance);
  if (holes.empty()) {
    return Status(ErrorCode::kNotFound,
                  aroundNames.empty()
                      ? std::string("no four-sided hole bounded by free edges in the model")
                      : fmt::format("no four-sided hole bounded by free edges of the {} given patches",
                                    aroundNames.size()));
  }
  FillResult out;
  if (options.checkSurrounding) {
    std::set<int> around;
    for (const Hole& h : holes) around.insert(h.around.begin(), h.around.end());
    const std::vector<int> aroundList(around.begin(), around.end());
    out.surrounding = analyzeAmong(model, aroundList, tol, options.seam, out.notes);
    for (const SeamReport& r : out.surrounding) {
      if (!atLeastG1(r.geometric)) {
        out.surroundingG1 = false;
        out.notes.push_back(fmt::format(
            "the surrounding surface is not G1 at seam {}.{} / {}.{}: {} (G0 gap {:.3g}, "
            "tangent-plane angle {:.4g} deg)",
            r.a, edgeName(r.aEdge), r.b, edgeName(r.bEdge), toString(r.geometric), r.g0Max, r.g1MaxDeg));
      }
    }
    if (!out.surroundingG1) return out;
  }
  for (const Hole& h : holes) {
    // N: side 0 -> V0 (u from c0 to c1), side 1 -> U1 (v from c1 to c2), side 2 -> V1 (u from c3 to c2),
    // side 3 -> U0 (v from c0 to c3).
    constexpr std::array<Edge, 4> kNewEdge = {Edge::V0, Edge::U1, Edge::V1, Edge::U0};
    constexpr std::array<int, 4> kNewStart = {0, 1, 3,
                                              0};  // corner of the hole where N's edge parameter starts
    std::vector<SeamPlan> plan;
    for (size_t k = 0; k < 4; ++k) {
      const Patch& mp = model.patches[static_cast<size_t>(h.sidePatch[k])];
      Result<BezierPatch> b = ci::singleBezier(mp);
      if (!b) return b.status();
      const Vec3 start = ci::edgeEnds(*b, h.sideEdge[k]).first;
      const bool reversed = (start - h.corners[static_cast<size_t>(kNewStart[k])]).norm() > tol.distance;
      plan.push_back({mp.name, std::move(b).value(), h.sideEdge[k], kNewEdge[k], reversed});
    }
    const std::string name =
        ci::uniqueName(options.name.empty() ? "fill" : options.name, takenNames(model, out));
    if (Status s = buildOne(plan, options.patch, name, "hole", out); !s) return s;
  }
  return out;
}

// ---------------------------------------------------------------------------------------------------------------

Result<FillResult> fillFillet(const Model& model, const std::vector<std::string>& strip1,
                              const std::vector<std::string>& strip2, const FillOptions& options) {
  if (strip1.empty() || strip1.size() != strip2.size()) {
    return invalidInput(
        fmt::format("fill --fillet: the strips must be non-empty and of equal length ({} and {} patches)",
                    strip1.size(), strip2.size()));
  }
  const Tolerances tol = tolerancesFor(model, options);
  const size_t n = strip1.size();
  std::array<std::vector<int>, 2> idx;
  std::array<std::vector<BezierPatch>, 2> bz;
  for (size_t s = 0; s < 2; ++s) {
    for (const std::string& name : s == 0 ? strip1 : strip2) {
      Result<int> i = patchIndex(model, name);
      if (!i) return i.status();
      Result<BezierPatch> b = ci::singleBezier(model.patches[static_cast<size_t>(*i)]);
      if (!b) return b.status();
      idx[s].push_back(*i);
      bz[s].push_back(std::move(b).value());
    }
  }
  // A patch in both strips (or twice in one) would face itself: the fillet between them is degenerate.
  for (size_t s = 0; s < 2; ++s) {
    for (size_t k = 0; k < n; ++k) {
      for (size_t t = s; t < 2; ++t) {
        for (size_t j = t == s ? k + 1 : 0; j < n; ++j) {
          if (idx[s][k] != idx[t][j]) continue;
          return invalidInput(fmt::format(
              "fill --fillet: patch \"{}\" is given twice ({} of strip {} and {} of strip {}); the two strips must "
              "be different patches facing each other",
              model.patches[static_cast<size_t>(idx[s][k])].name, k + 1, s + 1, j + 1, t + 1));
        }
      }
    }
  }
  // The facing edges: for each k, the edges of strip1[k] and strip2[k] not shared with their strip
  // neighbours, the pair with the closest middle points.
  auto candidateEdges = [&](size_t s, size_t k) {
    std::vector<Edge> out;
    for (Edge e : kAllEdges) {
      const EdgeGeom g{idx[s][k], e, edgeSamples(model.patches[static_cast<size_t>(idx[s][k])], e)};
      bool shared = false;
      for (size_t j : {k - 1, k + 1}) {
        if (j >= n) continue;  // k - 1 wraps to a huge value for k == 0
        for (Edge f : kAllEdges) {
          const EdgeGeom h{idx[s][j], f, edgeSamples(model.patches[static_cast<size_t>(idx[s][j])], f)};
          shared = shared || sameEdge(g, h, tol.distance);
        }
      }
      if (!shared) out.push_back(e);
    }
    return out;
  };
  struct Facing {
    Edge e1 = Edge::U0, e2 = Edge::U0;
    bool reversed = false;  // strip2's edge runs against strip1's
  };
  std::vector<Facing> facing(n);
  for (size_t k = 0; k < n; ++k) {
    double best = std::numeric_limits<double>::infinity();
    for (Edge e1 : candidateEdges(0, k)) {
      for (Edge e2 : candidateEdges(1, k)) {
        const auto [a0, a1] = ci::edgeEnds(bz[0][k], e1);
        const auto [b0, b1] = ci::edgeEnds(bz[1][k], e2);
        const double fwd = (a0 - b0).norm() + (a1 - b1).norm(), rev = (a0 - b1).norm() + (a1 - b0).norm();
        const BernsteinPoly c1 = ci::edgeJet(bz[0][k].numerator(), e1).curve;
        const BernsteinPoly c2 = ci::edgeJet(bz[1][k].numerator(), e2).curve;
        const double mid = (c1(0.5) - c2(0.5)).norm();
        const double score = mid + std::min(fwd, rev);
        if (score < best) {
          best = score;
          facing[k] = {e1, e2, rev < fwd};
        }
      }
    }
    if (!std::isfinite(best)) {
      return Status(ErrorCode::kNotFound,
                    fmt::format("fill --fillet: \"{}\" and \"{}\" have no free edges facing each "
                                "other",
                                strip1[k], strip2[k]));
    }
  }
  FillResult out;
  const std::string base = options.name.empty() ? "fillet" : options.name;
  std::map<size_t, size_t> bridgeOf;  // k -> index into out.patches
  // Bridges (k even): rows 0,1 from strip1[k], rows 2,3 from strip2[k], kappa = 0, constant lambdas by
  // fairness.
  for (size_t k = 0; k < n; k += 2) {
    const int across = 3;
    const int along = std::max(ci::edgeJet(bz[0][k].numerator(), facing[k].e1).curve.degree(),
                               ci::edgeJet(bz[1][k].numerator(), facing[k].e2).curve.degree());
    std::vector<SeamPlan> plan;
    plan.push_back({strip1[k], bz[0][k], facing[k].e1, Edge::V0, false});
    plan.push_back({strip2[k], bz[1][k], facing[k].e2, Edge::V1, facing[k].reversed});
    G1PatchOptions bridge = options.patch;
    bridge.degreeU = along;
    bridge.degreeV = across;
    bridge.maxDegree = std::max(along, across);
    bridge.kappaZero = true;
    bridge.interior = InteriorRule::kFairness;
    const std::string name = ci::uniqueName(base, takenNames(model, out));
    if (Status s = buildOne(plan, bridge, name, "fillet-bridge", out); !s) return s;
    bridgeOf[k] = out.patches.size() - 1;
  }
  // Fills (k odd): against strip1[k], strip2[k] and the bridges k - 1 and k + 1 (when present).
  for (size_t k = 1; k < n; k += 2) {
    const auto [c0, c1] = ci::edgeEnds(bz[0][k], facing[k].e1);
    std::vector<SeamPlan> plan;
    plan.push_back({strip1[k], bz[0][k], facing[k].e1, Edge::V0, false});
    plan.push_back({strip2[k], bz[1][k], facing[k].e2, Edge::V1, facing[k].reversed});
    for (size_t j : {k - 1, k + 1}) {
      if (!bridgeOf.count(j)) continue;
      const FilledPatch& bp = out.patches[bridgeOf[j]];
      const BezierPatch& b = bp.construction.patch;
      for (Edge e : {Edge::U0, Edge::U1, Edge::V0, Edge::V1}) {
        const auto [s0, s1] = ci::edgeEnds(b, e);
        // N's U0 runs from c0 (v = 0) to strip2, N's U1 from c1.
        for (const auto& [corner, newEdge] : {std::pair{c0, Edge::U0}, std::pair{c1, Edge::U1}}) {
          if ((s0 - corner).norm() <= tol.distance)
            plan.push_back({bp.patch.name, b, e, newEdge, false});
          else if ((s1 - corner).norm() <= tol.distance)
            plan.push_back({bp.patch.name, b, e, newEdge, true});
        }
      }
    }
    // Keep only the bridge edges that run across (from strip1 to strip2): the ones whose far end is on
    // strip2[k].
    std::vector<SeamPlan> kept;
    const auto [d0, d1] = ci::edgeEnds(bz[1][k], facing[k].e2);
    for (SeamPlan& p : plan) {
      if (p.newEdge == Edge::V0 || p.newEdge == Edge::V1) {
        kept.push_back(std::move(p));
        continue;
      }
      const auto [s0, s1] = ci::edgeEnds(p.neighbour, p.neighbourEdge);
      const Vec3 far = p.reversed ? s0 : s1;
      if ((far - d0).norm() <= tol.distance || (far - d1).norm() <= tol.distance)
        kept.push_back(std::move(p));
    }
    const std::string name = ci::uniqueName(base, takenNames(model, out));
    if (Status s = buildOne(kept, options.patch, name, "fillet-fill", out); !s) return s;
  }
  return out;
}

// ---------------------------------------------------------------------------------------------------------------

Model withFill(const Model& model, const FillResult& fill) {
  Model m = model;
  for (const FilledPatch& p : fill.patches) m.patches.push_back(p.patch);
  return m;
}

Result<FillCheck> checkFill(const Model& model, const FillResult& fill, const FillOptions& options) {
  const Model full = withFill(model, fill);
  const Tolerances tol = tolerancesFor(full, options);
  SeamOptions so = options.seam;
  so.tol = tol;
  FillCheck check;
  for (const FillSeam& s : fill.seams) {
    Result<int> a = patchIndex(full, s.neighbour);
    Result<int> b = patchIndex(full, s.newPatch);
    if (!a || !b) return Status(ErrorCode::kNotFound, "checkFill: a seam names an unknown patch");
    Result<SeamReport> rep = analyzeSeam(full.patches[static_cast<size_t>(*a)], s.neighbourEdge,
                                         full.patches[static_cast<size_t>(*b)], s.newEdge, so);
    if (!rep)
      return rep.status().withContext(fmt::format(
          "seam {}.{} / {}.{}", s.neighbour, edgeName(s.neighbourEdge), s.newPatch, edgeName(s.newEdge)));
    if (!atLeastG1(rep->geometric)) {
      check.g1 = false;
      check.problems.push_back(
          fmt::format("seam {}.{} / {}.{} is {} (tangent-plane angle {:.4g} deg, gap {:.3g})", s.neighbour,
                      edgeName(s.neighbourEdge), s.newPatch, edgeName(s.newEdge), toString(rep->geometric),
                      rep->g1MaxDeg, rep->g0Max));
    }
    check.seams.push_back(std::move(rep).value());
  }
  // Corners: every distinct corner point of the new patches, with every patch corner of the full model there.
  std::vector<Vec3> points;
  for (const FilledPatch& p : fill.patches) {
    for (int c = 0; c < 4; ++c) {
      const Vec3 x = ci::cornerPoint(p.construction.patch, c);
      bool known = false;
      for (const Vec3& y : points) known = known || (x - y).norm() <= tol.distance;
      if (!known) points.push_back(x);
    }
  }
  CornerOptions co;
  co.tol = tol;
  for (const Vec3& x : points) {
    std::vector<PatchCorner> corners;
    for (size_t i = 0; i < full.patches.size(); ++i) {
      const BSplineSurface& s = full.patches[i].surface;
      const Interval du = s.domainU(), dv = s.domainV();
      for (int c = 0; c < 4; ++c) {
        const bool uMax = (c & 1) != 0, vMax = (c & 2) != 0;
        const Vec3 y = s.evaluate(uMax ? du.hi : du.lo, vMax ? dv.hi : dv.lo).head<3>();
        if ((x - y).norm() <= tol.distance) corners.push_back({static_cast<int>(i), uMax, vMax});
      }
    }
    Result<CornerReport> rep = analyzeCorner(full.patches, corners, co);
    if (!rep) return rep.status().withContext("checkFill: corner analysis");
    if (rep->normalSpreadDeg && *rep->normalSpreadDeg > tol.angleDeg) {
      check.g1 = false;
      check.problems.push_back(
          fmt::format("vertex ({:.6g}, {:.6g}, {:.6g}): the normals of the {} patches there spread "
                      "by {:.4g} deg",
                      x.x(), x.y(), x.z(), rep->corners.size(), *rep->normalSpreadDeg));
    }
    check.corners.push_back(std::move(rep).value());
  }
  return check;
}

}  // namespace seam
