// `seam heal`: pair the seams, join the open ones by successive least-squares joins in breadth-first order.
#include "seam/repair/heal.h"

#include <fmt/format.h>

#include <algorithm>
#include <deque>
#include <map>

#include "repair/frame_internal.h"
#include "repair/join_internal.h"
#include "seam/continuity/model_check.h"
#include "seam/repair/join.h"

namespace seam {

namespace {

enum class SeamState { kKept, kToJoin, kSkipped };

struct Work {
  EdgePair pair;
  SeamReport before;
  SeamState state = SeamState::kKept;
  int mover = -1;  // the patch index that moved for it
  std::vector<std::string> notes;
};

std::optional<Interval> rangeOf(const EdgePair& p, bool sideA) {
  if (sideA) return p.fullA ? std::nullopt : std::optional<Interval>(p.overlapA);
  return p.fullB ? std::nullopt : std::optional<Interval>(p.overlapB);
}

}  // namespace

Result<HealResult> healModel(const Model& model, const HealOptions& opt) {
  if (model.patches.empty()) return invalidInput("the model has no patches");
  if (opt.continuity != GeometricClass::kG0 && opt.continuity != GeometricClass::kG1)
    return invalidInput("heal joins G0 or G1 (use `seam join` for G2, seam by seam)");
  for (const Patch& p : model.patches)
    if (p.surface.dim() != 3) return invalidInput(fmt::format("patch \"{}\" is not 3-D", p.name));
  double diag = model.boundingBox().diagonal();
  if (!(diag > 0.0)) diag = 1.0;
  const Tolerances tol = opt.tolerances ? *opt.tolerances : Tolerances::forModelSize(diag);
  const double maxGap = opt.maxGap ? *opt.maxGap : kDefaultMaxGapRel * diag;
  SeamOptions so = opt.seam;
  so.tol = tol;

  ModelCheckOptions mco;
  mco.tolerances = tol;
  mco.pairingRelTol = std::max(maxGap, tol.distance) / diag;
  mco.analyzeSeams = false;
  mco.analyzeCorners = false;
  auto pairing = pairEdges(model, mco);
  if (!pairing) return pairing.status();

  HealResult res;
  res.model = model;
  HealReport& rep = res.report;
  rep.requested = opt.continuity;
  rep.maxGap = maxGap;

  const int np = static_cast<int>(model.patches.size());
  std::vector<Work> work;
  for (const EdgePair& p : pairing->pairs) {
    Work w;
    w.pair = p;
    const Patch& A = model.patches[static_cast<size_t>(p.a.patch)];
    const Patch& B = model.patches[static_cast<size_t>(p.b.patch)];
    auto r = analyzeSeam(A, p.a.edge, B, p.b.edge, so, rangeOf(p, true));
    if (!r) {
      rep.notes.push_back(fmt::format("seam {}:{} / {}:{} could not be analysed: {}", A.name, edgeName(p.a.edge),
                                      B.name, edgeName(p.b.edge), r.status().message()));
      continue;
    }
    w.before = *r;
    if (w.before.g0Max > maxGap) w.state = SeamState::kSkipped;
    else if (meets(w.before.geometric, opt.continuity)) w.state = SeamState::kKept;
    else w.state = SeamState::kToJoin;
    work.push_back(std::move(w));
  }

  // Vertices: the corner points of every patch, clustered within the gap limit; a seam end at a vertex where three
  // or more patches have a corner is "interior" (a later patch may have to close it).
  struct CornerAt {
    Vec3 p;
    int patch;
  };
  std::vector<CornerAt> corners;
  for (int i = 0; i < np; ++i) {
    const BSplineSurface& s = model.patches[static_cast<size_t>(i)].surface;
    const Interval du = s.domainU(), dv = s.domainV();
    for (double u : {du.lo, du.hi})
      for (double v : {dv.lo, dv.hi}) corners.push_back({s.evaluate(u, v).head<3>(), i});
  }
  const double vertexTol = std::max(maxGap, tol.distance);
  auto patchesAt = [&](const Vec3& p) {
    std::vector<int> out;
    for (const CornerAt& c : corners)
      if ((c.p - p).norm() <= vertexTol && std::find(out.begin(), out.end(), c.patch) == out.end())
        out.push_back(c.patch);
    return out;
  };

  // Order: breadth-first from the roots of each group of seams to join. Roots stay: patches already joined to a
  // neighbour outside the work (anchored), or else the first patch of the group; of two roots with a seam to join
  // between them the later one moves.
  std::vector<std::vector<int>> adj(static_cast<size_t>(np));
  std::vector<char> anchored(static_cast<size_t>(np), 0);
  for (size_t k = 0; k < work.size(); ++k) {
    const Work& w = work[k];
    if (w.state == SeamState::kToJoin) {
      adj[static_cast<size_t>(w.pair.a.patch)].push_back(static_cast<int>(k));
      adj[static_cast<size_t>(w.pair.b.patch)].push_back(static_cast<int>(k));
    } else if (w.state == SeamState::kKept) {
      anchored[static_cast<size_t>(w.pair.a.patch)] = 1;
      anchored[static_cast<size_t>(w.pair.b.patch)] = 1;
    }
  }
  auto otherOf = [&](int k, int i) {
    const Work& w = work[static_cast<size_t>(k)];
    return w.pair.a.patch == i ? w.pair.b.patch : w.pair.a.patch;
  };
  std::vector<char> settled(static_cast<size_t>(np), 1), visited(static_cast<size_t>(np), 0);
  std::vector<int> order;
  for (int i = 0; i < np; ++i)
    if (!adj[static_cast<size_t>(i)].empty()) settled[static_cast<size_t>(i)] = 0;
  for (int seed = 0; seed < np; ++seed) {
    if (adj[static_cast<size_t>(seed)].empty() || visited[static_cast<size_t>(seed)]) continue;
    // The group of `seed`.
    std::vector<int> group{seed};
    visited[static_cast<size_t>(seed)] = 1;
    for (size_t g = 0; g < group.size(); ++g)
      for (int k : adj[static_cast<size_t>(group[g])]) {
        const int j = otherOf(k, group[g]);
        if (!visited[static_cast<size_t>(j)]) {
          visited[static_cast<size_t>(j)] = 1;
          group.push_back(j);
        }
      }
    std::sort(group.begin(), group.end());
    std::vector<int> roots;
    for (int i : group) {
      if (!anchored[static_cast<size_t>(i)]) continue;
      bool clash = false;
      for (int k : adj[static_cast<size_t>(i)])
        clash = clash || std::find(roots.begin(), roots.end(), otherOf(k, i)) != roots.end();
      if (!clash) roots.push_back(i);
    }
    if (roots.empty()) roots.push_back(group.front());
    std::vector<char> queued(static_cast<size_t>(np), 0);
    std::deque<int> queue;
    for (int r : roots) {
      settled[static_cast<size_t>(r)] = 1;
      queued[static_cast<size_t>(r)] = 1;
      queue.push_back(r);
    }
    while (!queue.empty()) {
      const int i = queue.front();
      queue.pop_front();
      if (!settled[static_cast<size_t>(i)]) order.push_back(i);
      std::vector<int> next;
      for (int k : adj[static_cast<size_t>(i)]) {
        const int j = otherOf(k, i);
        if (!queued[static_cast<size_t>(j)]) next.push_back(j);
      }
      std::sort(next.begin(), next.end());
      next.erase(std::unique(next.begin(), next.end()), next.end());
      for (int j : next) {
        queued[static_cast<size_t>(j)] = 1;
        queue.push_back(j);
      }
    }
  }

  // Move each patch once, onto every settled neighbour.
  for (int s : order) {
    Patch& S = res.model.patches[static_cast<size_t>(s)];
    std::vector<detail::EdgeConstraint> cons;
    std::vector<int> consWork;
    std::vector<Edge> locked;
    for (size_t k = 0; k < work.size(); ++k) {
      Work& w = work[k];
      if (w.state == SeamState::kSkipped) continue;
      const bool sIsA = w.pair.a.patch == s, sIsB = w.pair.b.patch == s;
      if (!sIsA && !sIsB) continue;
      const EdgeRef me = sIsA ? w.pair.a : w.pair.b, other = sIsA ? w.pair.b : w.pair.a;
      if (other.patch == s) continue;  // a seam of the patch with itself: left alone
      if (!settled[static_cast<size_t>(other.patch)]) {
        if (w.state == SeamState::kKept) locked.push_back(me.edge);
        continue;
      }
      const Patch& X = res.model.patches[static_cast<size_t>(other.patch)];
      auto cur = analyzeSeam(S, me.edge, X, other.edge, so, rangeOf(w.pair, sIsA));
      if (!cur) {
        w.notes.push_back("analysis before the join failed: " + cur.status().message());
        continue;
      }
      Interval oA = cur->overlapA, oB = cur->overlapB;
      if (w.pair.fullA && w.pair.fullB) {  // whole edge against whole edge: corners within the gap limit meet
        const detail::JoinOverlap ov = detail::cornerSnappedOverlap(S.surface, me.edge, X.surface, other.edge, oA, oB,
                                                                    cur->reversed, maxGap);
        oA = ov.s;
        oB = ov.t;
      }
      detail::EdgeConstraint c;
      c.edge = me.edge;
      const BSplineSurface Xf = detail::toEdgeFrame(X.surface, other.edge, cur->reversed);
      c.target = detail::targetFromFrame(Xf, oA, cur->reversed ? -oB.hi : oB.lo, oB.length() / oA.length(), 1);
      // Straight seam lines through the vertices that later patches close (docs: §4.1 and the vertex condition).
      const BSplineSurface& ss = S.surface;
      auto endPoint = [&](double t) -> Vec3 {
        const Interval du = ss.domainU(), dv = ss.domainV();
        switch (me.edge) {
          case Edge::U0: return ss.evaluate(du.lo, t).head<3>();
          case Edge::U1: return ss.evaluate(du.hi, t).head<3>();
          case Edge::V0: return ss.evaluate(t, dv.lo).head<3>();
          case Edge::V1: return ss.evaluate(t, dv.hi).head<3>();
        }
        return Vec3::Zero();
      };
      auto laterPatchAt = [&](double t) {
        const std::vector<int> at = patchesAt(endPoint(t));
        if (at.size() < 3) return false;
        for (int q : at)
          if (q != s && !settled[static_cast<size_t>(q)]) return true;
        return false;
      };
      c.kappaZeroAtStart = laterPatchAt(oA.lo);
      c.kappaZeroAtEnd = laterPatchAt(oA.hi);
      cons.push_back(std::move(c));
      consWork.push_back(static_cast<int>(k));
    }
    if (cons.empty()) {
      settled[static_cast<size_t>(s)] = 1;
      continue;
    }
    detail::LsJoinOptions lo;
    lo.continuity = opt.continuity;
    lo.scale = diag;
    lo.lockedEdges = locked;
    lo.lockedRows = opt.continuity == GeometricClass::kG0 ? 1 : 2;
    // First as it is; if the rows cannot carry all the conditions (typically the corner where this patch closes a
    // vertex of four), raise the degree (exact) by 1, then 2; only then unlock the edges kept for unsettled
    // neighbours (they will join this patch when their turn comes).
    Result<detail::LsJoinOutcome> r = Status(ErrorCode::kNoSolution, "not run");
    std::vector<std::string> tries;
    for (int attempt = 0; attempt < 6; ++attempt) {
      const bool unlock = attempt >= 3;
      if (unlock && locked.empty()) break;
      detail::LsJoinOptions a = lo;
      if (unlock) a.lockedEdges.clear();
      a.elevate = attempt % 3;
      auto t = detail::leastSquaresJoin(S.surface, cons, a);
      if (!t) {
        if (attempt == 0) r = t;
        break;
      }
      if (!r || t->residual < r->residual) r = t;
      if (t->feasible) {
        if (unlock) tries.push_back("edges joined before were unlocked to meet every neighbour");
        if (a.elevate > 0) tries.push_back(fmt::format("degree raised by {} (exact) for enough freedom", a.elevate));
        break;
      }
    }
    if (!r) {
      for (int k : consWork) work[static_cast<size_t>(k)].notes.push_back("join failed: " + r.status().message());
    } else {
      const bool sameKnots = r->surface.knotsU().values() == S.surface.knotsU().values() &&
                             r->surface.knotsV().values() == S.surface.knotsV().values() &&
                             r->surface.degreeU() == S.surface.degreeU() && r->surface.degreeV() == S.surface.degreeV();
      if (!sameKnots) S.kind = PatchKind::kBSpline;
      S.surface = r->surface;
      rep.order.push_back(S.name);
      for (int k : consWork) {
        Work& w = work[static_cast<size_t>(k)];
        if (w.state == SeamState::kToJoin) w.mover = s;
        for (const std::string& n : tries) w.notes.push_back(S.name + ": " + n);
        if (!r->feasible)
          w.notes.push_back(fmt::format("{}: constraints not met exactly (residual {:.3g})", S.name, r->residual));
      }
    }
    settled[static_cast<size_t>(s)] = 1;
  }

  // Displacements and the after-analysis.
  for (int i = 0; i < np; ++i) {
    const Patch& b = model.patches[static_cast<size_t>(i)];
    const Patch& a = res.model.patches[static_cast<size_t>(i)];
    if (a.surface.points() == b.surface.points() && a.surface.knotsU().values() == b.surface.knotsU().values() &&
        a.surface.knotsV().values() == b.surface.knotsV().values())
      continue;
    const Displacement d = controlPointDisplacement(b.surface, a.surface, kRoundoff * diag);
    rep.patchesChanged.push_back(a.name);
    rep.maxDisplacement = std::max(rep.maxDisplacement, d.max);
    rep.movedPoints += d.moved;
  }
  rep.achieved = true;
  for (Work& w : work) {
    HealSeam hs;
    const Patch& A = res.model.patches[static_cast<size_t>(w.pair.a.patch)];
    const Patch& B = res.model.patches[static_cast<size_t>(w.pair.b.patch)];
    hs.a = A.name;
    hs.b = B.name;
    hs.aEdge = w.pair.a.edge;
    hs.bEdge = w.pair.b.edge;
    hs.before = w.before;
    hs.notes = w.notes;
    hs.action = w.state == SeamState::kSkipped ? "skipped" : (w.state == SeamState::kKept ? "kept" : "joined");
    if (w.mover >= 0) hs.moved = res.model.patches[static_cast<size_t>(w.mover)].name;
    auto r = analyzeSeam(A, w.pair.a.edge, B, w.pair.b.edge, so, rangeOf(w.pair, true));
    if (r) {
      hs.after = *r;
      hs.achieved = meets(r->geometric, opt.continuity);
      if (w.state != SeamState::kSkipped) {
        rep.worst = static_cast<GeometricClass>(std::min(static_cast<int>(rep.worst), static_cast<int>(r->geometric)));
        rep.worstG0 = std::max(rep.worstG0, r->g0Max);
        rep.worstG1Deg = std::max(rep.worstG1Deg, r->g1MaxDeg);
      }
    } else {
      hs.notes.push_back("analysis after healing failed: " + r.status().message());
    }
    if (w.state != SeamState::kSkipped && !hs.achieved) {
      rep.achieved = false;
      if (w.state == SeamState::kToJoin) hs.action = "failed";
    }
    rep.seams.push_back(std::move(hs));
  }
  return res;
}

}  // namespace seam
