// G2 across whole quad networks (seam/repair/g2_network.h; derivation in docs/algorithms/thesis-abstract.md,
// "G2 across networks").
//
// Unknowns: the control points of every chosen patch (held as biquintic B-splines on [0, 1]^2 with the patch's own
// knots, see ownForm; where the two boundary rows of a seam have the same knots their points are one unknown, so G0
// holds by construction; the boundary rows of free edges are fixed), and per seam and per span of the edge (the
// merged breakpoints of both sides) the coefficients of lambda (linear) and kappa (quadratic) in the span's local
// parameter tau in [0, 1].
// Equations per seam and span: G0 where the boundary rows differ in knots (C - B = 0 at kColloc0 parameters, both
// quintic on the span), the G1 identity C_s + lambda B_s - kappa B_t = 0 at kColloc1 parameters (degree <= 6:
// exact when it holds there), and G2's normal component n . (C_ss - lambda^2 B_ss + 2 lambda kappa B_st -
// kappa^2 B_tt) = 0 at kColloc2 parameters (n the unit normal; N . (...) has degree <= 16). The tangential part of
// the G2 identity is taken by mu B_s + nu B_t with any mu, nu, so it is not an equation.
// Solve: Gauss-Newton steps of least weighted change (step = -W^-1 J^T (J W^-1 J^T)^-1 r, rows scaled to unit
// norm, taken from the sparse KKT system, with the fairness term in the first steps), with backtracking. Near the
// solution the n tangent-plane rows at a vertex of valence n express a condition of codimension n - 2 (coplanarity),
// so the last digits converge linearly; the iteration stops at options.residualRel or when four steps (eight while not yet acceptable) gain less than a factor 2.
#include "seam/repair/g2_network.h"

#include <fmt/format.h>

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <set>

#include "core/union_find.h"
#include "repair/network_internal.h"
#include "seam/continuity/corner.h"
#include "seam/continuity/model_check.h"
#include "seam/repair/join.h"

namespace seam {

namespace {

constexpr int kDeg = 5;
/// Least multiplicity of every interior knot of the output (C2: each patch stays curvature continuous there).
constexpr int kMinMult = 3;
/// Largest multiplicity accepted: kDeg, a C0 knot (a triple knot of a cubic). Every patch keeps the smoothness it has at
/// each knot of the common form (C2 at least: smoothness rows, see SmoothRow).
constexpr int kMaxMult = kDeg;
constexpr int kDegLambda = 1; // degrees of the blending functions per span
constexpr int kDegKappa = 2;
constexpr int kBlendPerSpan = (kDegLambda + 1) + (kDegKappa + 1);
/// Parameters per span: the G1 identity has degree <= 6 per span; the G2 condition's normal component
/// (B_s x B_t) . (...) degree <= 9 + 7 = 16.
constexpr int kColloc1 = 7;
/// G0 where the two boundary rows have different knots: both boundary curves are quintic on each span.
constexpr int kColloc0 = kDeg + 1;
constexpr int kColloc2 = 17;
/// Weight of a blending coefficient against a control-point coordinate in the least-change step (the blending
/// functions are free: a small weight lets them take the change).
constexpr double kBlendWeight = 1.0;
/// The fairness term is used while the largest residual is above this fraction of the model size: the large first
/// steps are where sharp bends would be bought; the last steps are small and take the plain least-change form
/// (measured: the same curvature and displacement, smaller final residuals).
constexpr double kFairPhaseRel = 1e-4;
/// Weight (against 1 for other control points) of the points of the row beside an edge that meets a patch outside
/// the solve, when the fairness term is on (G2NetworkOptions::fairness).
constexpr double kFacingRowWeight = 1e6;
/// Regularisation -gamma of the KKT system's equation block (redundant equations at the vertices make it singular;
/// the rows are scaled to unit norm).
constexpr double kRegularisationRel = 1e-14;
/// Steps over which the largest residual must halve for the iteration to go on (doubled while it is not acceptable).
constexpr size_t kStagnationSteps = 4;
/// Step halvings of the backtracking line search before the iteration stops.
constexpr int kMaxHalvings = 12;

/// Eigen's sparse LDL^T, with the size of its factor after the symbolic analysis (the column counts it keeps).
class SizedLDLT : public Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> {
 public:
  /// Multiply-adds of a numeric factorisation of the analysed pattern (0 before analyzePattern).
  [[nodiscard]] double factorOperations() const {
    double ops = 0.0;
    for (Eigen::Index j = 0; j < m_nonZerosPerCol.size(); ++j)
      ops += static_cast<double>(m_nonZerosPerCol[j]) * static_cast<double>(m_nonZerosPerCol[j]);
    return ops;
  }
};

Status unsupported(std::string m) { return {ErrorCode::kUnsupported, std::move(m)}; }

/// The form of a patch in one direction: a clamped quintic knot vector with the patch's own interior knots (issue 36
/// goal 4: no knot of another patch is inserted, so uneven knots cost what the Bezier network of the same seams
/// costs), each of multiplicity at least kMinMult; the middle 1/2 when the patch has none there.
struct Form {
  KnotVector knots;
  int grid = 0;                 // control points in this direction
  std::vector<double> breaks;   // 0, the interior knots, 1
};

/// A region patch's two forms and the place of its control points (index offset + i * v.grid + j).
struct PatchGrid {
  Form u, v;
  int offset = 0;
  [[nodiscard]] int count() const { return u.grid * v.grid; }
  [[nodiscard]] int at(int i, int j) const { return offset + i * v.grid + j; }
  /// The form along edge e (U0/U1 run along v).
  [[nodiscard]] const Form& along(Edge e) const { return isUEdge(e) ? v : u; }
};

/// The patch raised to degree 5 and reparametrised onto [0, 1]^2 (exact), or why not.
Result<BSplineSurface> raised(const BSplineSurface& s0, const std::string& name) {
  if (s0.isRational()) return unsupported(fmt::format("patch \"{}\" is rational", name));
  if (s0.degreeU() > kDeg || s0.degreeV() > kDeg)
    return unsupported(fmt::format("patch \"{}\" has degree ({}, {}) above {}", name, s0.degreeU(), s0.degreeV(), kDeg));
  BSplineSurface s = s0.degreeElevated(kDeg - s0.degreeU(), kDeg - s0.degreeV()).reparametrized({0.0, 1.0}, {0.0, 1.0});
  for (int dir = 0; dir < 2; ++dir) {
    const KnotVector& kv = dir == 0 ? s.knotsU() : s.knotsV();
    if (kv.multiplicity(0.0) != kDeg + 1 || kv.multiplicity(1.0) != kDeg + 1)
      return unsupported(fmt::format("patch \"{}\": its knots are not clamped", name));
    for (double t : kv.interiorBreakpoints(kDeg))
      if (kv.multiplicity(t) > kMaxMult)
        return unsupported(fmt::format("patch \"{}\": the interior knot {} in {} has multiplicity {} at degree 5 (the "
                                       "patch is discontinuous there)",
                                       name, t, dir == 0 ? "u" : "v", kv.multiplicity(t)));
  }
  return s;
}

/// The form of a raised patch in one direction (see Form).
Form ownForm(const KnotVector& kv) {
  std::vector<double> k(kDeg + 1, 0.0);
  Form f;
  f.breaks.push_back(0.0);
  const std::vector<double> own = kv.interiorBreakpoints(kDeg);
  if (own.empty()) {
    k.insert(k.end(), kMinMult, 0.5);
    f.breaks.push_back(0.5);
  }
  for (double t : own) {
    k.insert(k.end(), static_cast<size_t>(std::max(kv.multiplicity(t), kMinMult)), t);
    f.breaks.push_back(t);
  }
  f.breaks.push_back(1.0);
  k.insert(k.end(), kDeg + 1, 1.0);
  f.grid = static_cast<int>(k.size()) - kDeg - 1;
  f.knots = KnotVector(std::move(k));
  return f;
}

/// The raised patch refined to its forms (exact knot insertion).
BSplineSurface toForm(BSplineSurface s, const PatchGrid& g) {
  for (int dir = 0; dir < 2; ++dir) {
    const Form& f = dir == 0 ? g.u : g.v;
    const KnotVector& kv = dir == 0 ? s.knotsU() : s.knotsV();
    std::vector<double> ins;
    for (size_t b = 1; b + 1 < f.breaks.size(); ++b) {
      const double t = f.breaks[b];
      for (int i = kv.multiplicity(t); i < f.knots.multiplicity(t); ++i) ins.push_back(t);
    }
    if (!ins.empty()) s = dir == 0 ? s.refinedU(ins) : s.refinedV(ins);
  }
  return s;
}

/// Control-point index (i, j) of point k (increasing edge parameter) of row r (0: the edge) of edge e.
std::pair<int, int> rowIndex(const PatchGrid& g, Edge e, int r, int k) {
  switch (e) {
    case Edge::U0: return {r, k};
    case Edge::U1: return {g.u.grid - 1 - r, k};
    case Edge::V0: return {k, r};
    case Edge::V1: return {k, g.v.grid - 1 - r};
  }
  return {0, 0};
}

/// One side of a seam seen at the common edge parameter t: for every derivative d^{i+j}/ds^i dt^j (s into the
/// patch, t along the common parameter), i + j <= 2, the 36 weights of the patch's control points that carry it.
struct SideJet {
  // order index: 0 S_s, 1 S_t, 2 S_ss, 3 S_st, 4 S_tt, 5 S
  std::array<std::array<double, 36>, 6> w{};
  std::array<int, 36> point{};  // row of the control point in the matrix of all points (PatchGrid::at)
  std::array<Vec3, 6> value{};
};

SideJet sideJet(const PatchGrid& g, const Matrix& q, Edge e, bool reversed, double t) {
  const double te = reversed ? 1.0 - t : t;
  const double st = reversed ? -1.0 : 1.0;
  const bool uEdge = isUEdge(e);
  const double n0 = (e == Edge::U0 || e == Edge::V0) ? 0.0 : 1.0;
  const double sn = (e == Edge::U0 || e == Edge::V0) ? 1.0 : -1.0;
  const double a = uEdge ? n0 : te, b = uEdge ? te : n0;
  const int spa = g.u.knots.findSpan(kDeg, a), spb = g.v.knots.findSpan(kDeg, b);
  const Matrix Na = basisFunctionDerivatives(g.u.knots, kDeg, spa, a, 2);
  const Matrix Nb = basisFunctionDerivatives(g.v.knots, kDeg, spb, b, 2);
  // (i, j) = derivative orders in (s, t); in the patch's own parameters: normal order i, along order j.
  static constexpr std::array<std::array<int, 2>, 6> orders{{{1, 0}, {0, 1}, {2, 0}, {1, 1}, {0, 2}, {0, 0}}};
  SideJet jet;
  for (int o = 0; o < 6; ++o) {
    const int i = orders[static_cast<size_t>(o)][0], j = orders[static_cast<size_t>(o)][1];
    const double sign = std::pow(sn, i) * std::pow(st, j);
    const int du = uEdge ? i : j, dv = uEdge ? j : i;
    Vec3 v = Vec3::Zero();
    int c = 0;
    for (int ra = 0; ra <= kDeg; ++ra)
      for (int rb = 0; rb <= kDeg; ++rb, ++c) {
        const int pi = spa - kDeg + ra, pj = spb - kDeg + rb;
        const double wgt = sign * Na(du, ra) * Nb(dv, rb);
        jet.w[static_cast<size_t>(o)][static_cast<size_t>(c)] = wgt;
        jet.point[static_cast<size_t>(c)] = g.at(pi, pj);
        v += wgt * q.row(g.at(pi, pj)).transpose();
      }
    jet.value[static_cast<size_t>(o)] = v;
  }
  return jet;
}

struct NetSeam {
  int pa = -1, pb = -1;  // region patch indices (B = pa, C = pb)
  Edge ea = Edge::U0, eb = Edge::U0;
  bool reversed = false;
  int blend = 0;  // offset of the seam's blending coefficients in the unknown vector
  /// Spans of the common edge parameter: both sides' breakpoints along the edge (B's mirrored when reversed), so
  /// that both sides are polynomials on each span.
  std::vector<double> breaks;
  /// The two boundary rows have the same knots (mirrored when reversed): they are one set of unknowns (G0 by
  /// construction). Otherwise G0 is a set of equations: the two boundary curves agree on every span.
  bool sharedRow = false;
  [[nodiscard]] int spans() const { return static_cast<int>(breaks.size()) - 1; }
  bool g1Only = false;  // G2 is impossible at one of its ends with the free edges kept (straight free boundary)
};

/// Sine of the angle below which the two free edges at a boundary vertex count as one straight boundary line.
constexpr double kStraightBoundarySin = 0.17;  // ~10 degrees
/// Relative difference of the two free edges' normal curvatures at a straight boundary vertex above which G2 at
/// that vertex is impossible (the second fundamental form takes one value per direction).
constexpr double kCurvatureMismatchRel = 1e-9;

/// Corner id (patch * 4 + cu * 2 + cv) at an end of an edge.
int cornerId(int patch, Edge e, int end) {
  const auto [cu, cv] = cornerOf(e, end);
  return patch * 4 + cu * 2 + cv;
}

double powi(double x, int k) {
  double r = 1.0;
  for (int i = 0; i < k; ++i) r *= x;
  return r;
}

/// Collocation parameters inside span sp of [0, 1] (Chebyshev points of the span).
template <int K>
std::array<double, K> collocation(const std::vector<double>& breaks, int sp) {
  std::array<double, K> t{};
  const double a = breaks[static_cast<size_t>(sp)], b = breaks[static_cast<size_t>(sp) + 1];
  for (int k = 0; k < K; ++k) {
    const double tau = 0.5 - 0.5 * std::cos(std::numbers::pi * (k + 0.5) / K);
    t[static_cast<size_t>(k)] = a + tau * (b - a);
  }
  return t;
}

/// The curvature spread (analyzeCorner) of every interior vertex in the input and in the output, with a note for
/// each vertex of valence 5 or more (the issue: report the remaining mismatch there).
template <class Groups>
void reportVertices(const Model& before, const Model& after, const std::vector<int>& chosen,
                    const std::vector<NetSeam>& seams, UnionFind& vertexOf, const Groups& groups,
                    G2NetworkReport& rep) {
  std::map<int, std::vector<int>> cornersOf;  // vertex -> corner ids
  for (int c = 0; c < static_cast<int>(chosen.size()) * 4; ++c) cornersOf[vertexOf.find(c)].push_back(c);
  std::map<int, std::vector<std::pair<int, int>>> seamEndsOf;  // vertex -> (seam, end)
  for (int k = 0; k < static_cast<int>(seams.size()); ++k)
    for (int end = 0; end < 2; ++end)
      seamEndsOf[vertexOf.find(cornerId(seams[static_cast<size_t>(k)].pa, seams[static_cast<size_t>(k)].ea, end))]
          .emplace_back(k, end);
  for (const auto& [vr, g] : groups) {
    if (g.boundary || g.corners < 3) continue;
    std::vector<PatchCorner> corners;
    std::map<int, int> indexOf;  // corner id -> index in `corners`
    for (int c : cornersOf[vr]) {
      indexOf[c] = static_cast<int>(corners.size());
      corners.push_back({chosen[static_cast<size_t>(c / 4)], (c / 2) % 2 == 1, c % 2 == 1});
    }
    std::vector<CornerLink> links;
    for (const auto& [k, end] : seamEndsOf[vr]) {
      const NetSeam& s = seams[static_cast<size_t>(k)];
      const int ca = cornerId(s.pa, s.ea, end), cb = cornerId(s.pb, s.eb, s.reversed ? 1 - end : end);
      links.push_back({indexOf.at(ca), s.ea, indexOf.at(cb), s.eb});
    }
    G2NetworkVertex v;
    v.valence = g.corners;
    for (int pass = 0; pass < 2; ++pass) {
      const Model& m = pass == 0 ? before : after;
      auto r = analyzeCorner(m.patches, corners, links);
      if (!r) continue;
      (pass == 0 ? v.spreadBefore : v.spreadAfter) = r->curvatureSpreadRel;
      if (pass == 1) {
        v.point = r->point;
        if (r->fourPatch) v.theorem2After = r->fourPatch->g2Residual;
      }
    }
    if (v.spreadAfter) rep.maxSpreadAfter = std::max(rep.maxSpreadAfter.value_or(0.0), *v.spreadAfter);
    if (v.valence >= 5 && v.spreadAfter)
      rep.notes.push_back(fmt::format(
          "vertex ({:.6g}, {:.6g}, {:.6g}) where {} patches meet: curvature mismatch {:.3g} % before, {:.3g} % after",
          v.point.x(), v.point.y(), v.point.z(), v.valence, 100.0 * v.spreadBefore.value_or(0.0),
          100.0 * *v.spreadAfter));
    rep.vertices.push_back(v);
  }
}

}  // namespace

Result<G2NetworkResult> g2NetworkScheme(const Model& model, const G2NetworkOptions& opt) {
  if (!(opt.fairness >= 0.0) || !std::isfinite(opt.fairness))
    return invalidInput(fmt::format("the fairness weight must be finite and >= 0 (got {})", opt.fairness));
  if (!(opt.maxFairFactorOperations >= 0.0))
    return invalidInput(fmt::format("the fairness term's factorisation limit must be >= 0 (got {})",
                                    opt.maxFairFactorOperations));
  if (opt.continuity != GeometricClass::kG1 && opt.continuity != GeometricClass::kG2)
    return invalidInput(fmt::format("the network solve makes seams G1 or G2 (asked: {})", toString(opt.continuity)));
  const bool g2 = opt.continuity == GeometricClass::kG2;
  const std::string solveName = g2 ? "G2 network" : "G1 network";
  auto setup = networkSetup(model, opt.patches, opt.tolerances, opt.maxGap);
  if (!setup) return setup.status();
  const std::vector<int>& chosen = setup->chosen;
  const double diag = setup->diagonal;
  const Tolerances& tol = setup->tol;
  const double maxGap = setup->maxGap;

  G2NetworkResult res;
  res.model = model;
  res.model.brep.reset();  // the patches change: the trims would not follow (Model::brep)
  G2NetworkReport& rep = res.report;

  const int np = static_cast<int>(chosen.size());
  std::map<int, int> local;
  for (int r = 0; r < np; ++r) local[chosen[static_cast<size_t>(r)]] = r;
  std::vector<BSplineSurface> form(static_cast<size_t>(np));
  bool raisedAny = false, refined = false;
  for (int r = 0; r < np; ++r) {
    const Patch& p = model.patches[static_cast<size_t>(chosen[static_cast<size_t>(r)])];
    auto f = raised(p.surface, p.name);
    if (!f) return f.status();
    raisedAny = raisedAny || p.surface.degreeU() < kDeg || p.surface.degreeV() < kDeg;
    form[static_cast<size_t>(r)] = *f;
  }
  std::vector<PatchGrid> pg(static_cast<size_t>(np));
  int nPoints = 0;
  for (int ri = 0; ri < np; ++ri) {
    PatchGrid& g = pg[static_cast<size_t>(ri)];
    BSplineSurface& f = form[static_cast<size_t>(ri)];
    g.u = ownForm(f.knotsU());
    g.v = ownForm(f.knotsV());
    g.offset = nPoints;
    nPoints += g.count();
    const int before = f.numU() * f.numV();
    f = toForm(f, g);
    refined = refined || f.numU() * f.numV() != before;
    if (f.numU() != g.u.grid || f.numV() != g.v.grid) return unsupported("internal: a patch did not reach its form");
  }
  auto localTau = [&](const NetSeam& s, int sp, double t) {
    const double a = s.breaks[static_cast<size_t>(sp)], b = s.breaks[static_cast<size_t>(sp) + 1];
    return (t - a) / (b - a);
  };

  // ---- topology.
  auto pairing = pairEdgesWithin(model, tol, maxGap, diag);
  if (!pairing) return pairing.status();
  for (const DegenerateEdge& d : pairing->degenerateEdges)
    if (local.count(d.edge.patch))
      return unsupported(fmt::format("patch \"{}\" has a collapsed edge {} (a pole)",
                                     model.patches[static_cast<size_t>(d.edge.patch)].name, edgeName(d.edge.edge)));
  std::vector<NetSeam> seams;
  std::set<std::pair<int, int>> paired;  // (region patch, edge) of interior seams
  const auto kept = [&](int patch, Edge e) {
    return std::find(opt.keepEdges.begin(), opt.keepEdges.end(), std::make_pair(patch, e)) != opt.keepEdges.end();
  };
  std::set<std::pair<int, int>> facing;  // (region patch, edge) of edges that meet a patch but are not solved: kept
                                         // seams, seams to patches outside the chosen set
  for (const EdgePair& pr : pairing->pairs) {
    const bool inA = local.count(pr.a.patch) > 0, inB = local.count(pr.b.patch) > 0;
    const bool keptPair = kept(pr.a.patch, pr.a.edge) || kept(pr.b.patch, pr.b.edge);
    if ((inA != inB) || (inA && keptPair)) {
      if (inA) facing.insert({local[pr.a.patch], static_cast<int>(pr.a.edge)});
      if (inB) facing.insert({local[pr.b.patch], static_cast<int>(pr.b.edge)});
    }
    if (!inA || !inB) continue;
    if (keptPair) continue;
    const std::string& na = model.patches[static_cast<size_t>(pr.a.patch)].name;
    const std::string& nb = model.patches[static_cast<size_t>(pr.b.patch)].name;
    if (!pr.fullA || !pr.fullB)
      return unsupported(fmt::format("the seam {}:{} / {}:{} covers only part of an edge (a T-junction)", na,
                                     edgeName(pr.a.edge), nb, edgeName(pr.b.edge)));
    NetSeam s;
    s.pa = local[pr.a.patch];
    s.pb = local[pr.b.patch];
    s.ea = pr.a.edge;
    s.eb = pr.b.edge;
    s.reversed = pr.reversed;
    for (const auto& key : {std::make_pair(s.pa, static_cast<int>(s.ea)), std::make_pair(s.pb, static_cast<int>(s.eb))})
      if (!paired.insert(key).second)
        return unsupported(fmt::format("edge {}:{} or {}:{} is shared by more than two patches", na,
                                       edgeName(pr.a.edge), nb, edgeName(pr.b.edge)));
    // The spans of the common parameter, and whether the two boundary rows have the same knots.
    const Form& fa = pg[static_cast<size_t>(s.pa)].along(s.ea);
    const Form& fb = pg[static_cast<size_t>(s.pb)].along(s.eb);
    s.breaks = fa.breaks;
    for (double t : fb.breaks) s.breaks.push_back(s.reversed ? 1.0 - t : t);
    std::sort(s.breaks.begin(), s.breaks.end());
    s.breaks.erase(std::unique(s.breaks.begin(), s.breaks.end(),
                               [](double x, double y) { return std::abs(x - y) <= kKnotRelTol; }),
                   s.breaks.end());
    s.sharedRow = fa.knots.size() == fb.knots.size();
    for (int k = 0; s.sharedRow && k < fa.knots.size(); ++k) {
      const double tb = s.reversed ? 1.0 - fb.knots[fb.knots.size() - 1 - k] : fb.knots[k];
      s.sharedRow = std::abs(fa.knots[k] - tb) <= kKnotRelTol;
    }
    seams.push_back(s);
  }
  rep.interiorSeams = static_cast<int>(seams.size());

  // ---- vertices: corners linked through seams (union-find). At a boundary vertex whose two free edges form one
  // straight line, the second fundamental form would have to take both free edges' normal curvatures in the same
  // direction: where they differ, G2 is impossible with the free edges kept, and the seams ending there are made
  // G1 only (and reported).
  UnionFind vertexOf(np * 4);
  for (const NetSeam& s : seams)
    for (int end = 0; end < 2; ++end)
      vertexOf.unite(cornerId(s.pa, s.ea, end), cornerId(s.pb, s.eb, s.reversed ? 1 - end : end));
  struct VertexGroup {
    int corners = 0;
    bool boundary = false;
    std::vector<std::pair<int, std::pair<Edge, int>>> freeEnds;  // (patch, (edge, end))
  };
  std::map<int, VertexGroup> vertexGroups;
  for (int c = 0; c < np * 4; ++c) ++vertexGroups[vertexOf.find(c)].corners;
  for (int ri = 0; ri < np; ++ri)
    for (Edge e : {Edge::U0, Edge::U1, Edge::V0, Edge::V1})
      if (!paired.count({ri, static_cast<int>(e)}))
        for (int end = 0; end < 2; ++end) {
          VertexGroup& g = vertexGroups[vertexOf.find(cornerId(ri, e, end))];
          g.boundary = true;
          g.freeEnds.push_back({ri, {e, end}});
        }
  std::set<int> straightMismatch;
  for (const auto& [vr, g] : vertexGroups) {
    if (!g2 || g.freeEnds.size() != 2) continue;  // G1 only: no curvature condition at any vertex
    std::array<Vec3, 2> d1, d2, nrm;
    for (int k = 0; k < 2; ++k) {
      const auto& [ri, ee] = g.freeEnds[static_cast<size_t>(k)];
      const auto [e, end] = ee;
      const BSplineSurface& f = form[static_cast<size_t>(ri)];
      const auto [cu, cv] = cornerOf(e, end);
      const double a = cu, b = cv;
      const auto der = f.derivatives(a, b, 2);
      const Vec3 su = der[1][0].head<3>(), sv = der[0][1].head<3>();
      const double sgn = end == 0 ? 1.0 : -1.0;  // away from the vertex
      d1[static_cast<size_t>(k)] = sgn * (isUEdge(e) ? sv : su);
      d2[static_cast<size_t>(k)] = isUEdge(e) ? Vec3(der[0][2].head<3>()) : Vec3(der[2][0].head<3>());
      nrm[static_cast<size_t>(k)] = su.cross(sv).normalized();
    }
    const double sine = d1[0].cross(d1[1]).norm() / (d1[0].norm() * d1[1].norm());
    if (!(sine < kStraightBoundarySin) || d1[0].dot(d1[1]) > 0.0) continue;
    const double k0 = nrm[0].dot(d2[0]) / d1[0].squaredNorm(), k1 = nrm[0].dot(d2[1]) / d1[1].squaredNorm();
    if (std::abs(k0 - k1) > kCurvatureMismatchRel * std::max({std::abs(k0), std::abs(k1), 1.0 / diag})) {
      straightMismatch.insert(vr);
      const auto [fp, fe] = g.freeEnds[0];
      const auto [cu, cv] = cornerOf(fe.first, fe.second);
      const Vec3 pt = form[static_cast<size_t>(fp)].evaluate(cu, cv).head<3>();
      rep.notes.push_back(fmt::format(
          "boundary vertex ({:.6g}, {:.6g}, {:.6g}): the free boundary runs straight through it with normal curvature "
          "{:.4g} on one side and {:.4g} on the other; curvature continuity there would move the free edges, so the "
          "seams ending there are made G1 only",
          pt.x(), pt.y(), pt.z(), k0, k1));
    }
  }
  for (NetSeam& s : seams)
    for (int end = 0; end < 2; ++end)
      if (straightMismatch.count(vertexOf.find(cornerId(s.pa, s.ea, end)))) s.g1Only = true;
  rep.g1OnlySeams = static_cast<int>(std::count_if(seams.begin(), seams.end(), [](const NetSeam& s) { return s.g1Only; }));
  if (seams.empty()) {
    rep.notes.push_back("no interior seam between the chosen patches: nothing to do");
    return res;
  }

  // ---- unknowns: control points (3 per point, minus the fixed ones), then blending coefficients.
  std::vector<char> fixedPoint(static_cast<size_t>(nPoints), 0);
  for (int r = 0; r < np; ++r)
    for (Edge e : {Edge::U0, Edge::U1, Edge::V0, Edge::V1}) {
      if (paired.count({r, static_cast<int>(e)})) continue;
      const PatchGrid& g = pg[static_cast<size_t>(r)];
      for (int k = 0; k < g.along(e).grid; ++k) {
        const auto [i, j] = rowIndex(g, e, 0, k);
        fixedPoint[static_cast<size_t>(g.at(i, j))] = 1;
      }
    }
  // G0 by construction where the two boundary rows have the same knots: their points are one unknown (union-find;
  // a class with a fixed member is fixed). Other seams share their end points and get G0 equations (below).
  UnionFind shared(nPoints);
  auto root = [&](int x) { return shared.find(x); };
  for (const NetSeam& s : seams) {
    const PatchGrid &ga = pg[static_cast<size_t>(s.pa)], &gb = pg[static_cast<size_t>(s.pb)];
    const int na = ga.along(s.ea).grid, nb = gb.along(s.eb).grid;
    for (int k = 0; k < na; ++k) {
      // Rows with other knots share their end points (the corners of the patches: the same point, G0).
      if (!s.sharedRow && k != 0 && k != na - 1) continue;
      const int kb = k == 0 ? 0 : k == na - 1 ? nb - 1 : k;
      const auto [ia, ja] = rowIndex(ga, s.ea, 0, k);
      const auto [ib, jb] = rowIndex(gb, s.eb, 0, s.reversed ? nb - 1 - kb : kb);
      shared.unite(ga.at(ia, ja), gb.at(ib, jb));
    }
  }
  const std::vector<char> fixedInInput = fixedPoint;
  for (int g = 0; g < nPoints; ++g)
    if (fixedInInput[static_cast<size_t>(g)]) fixedPoint[static_cast<size_t>(root(g))] = 1;
  std::vector<int> varOf(static_cast<size_t>(nPoints), -1);  // first of the 3 unknowns of a point
  int nv = 0;
  for (int g = 0; g < nPoints; ++g)
    if (root(g) == g && !fixedPoint[static_cast<size_t>(g)]) {
      varOf[static_cast<size_t>(g)] = nv;
      nv += 3;
    }
  for (int g = 0; g < nPoints; ++g) varOf[static_cast<size_t>(g)] = varOf[static_cast<size_t>(root(g))];
  const int nPointVars = nv;
  for (NetSeam& s : seams) {
    s.blend = nv;
    nv += s.spans() * kBlendPerSpan;
  }

  // Current control points (all patches, fixed ones included) and blending coefficients.
  Matrix q(nPoints, 3);
  for (int r = 0; r < np; ++r)
    q.middleRows(pg[static_cast<size_t>(r)].offset, pg[static_cast<size_t>(r)].count()) = form[static_cast<size_t>(r)].points();
  VecX blend = VecX::Zero(nv - nPointVars);

  // G0 first: every class of shared boundary points to its fixed member or to its mean.
  {
    std::vector<Vec3> sum(static_cast<size_t>(nPoints), Vec3::Zero());
    std::vector<int> count(static_cast<size_t>(nPoints), 0);
    std::vector<int> fixedMember(static_cast<size_t>(nPoints), -1);
    for (int g = 0; g < nPoints; ++g) {
      const auto c = static_cast<size_t>(root(g));
      sum[c] += q.row(g).transpose();
      ++count[c];
      if (fixedInInput[static_cast<size_t>(g)] && fixedMember[c] < 0) fixedMember[c] = g;
    }
    for (int g = 0; g < nPoints; ++g) {
      const auto c = static_cast<size_t>(root(g));
      if (count[c] < 2) continue;
      q.row(g) = (fixedMember[c] >= 0 ? Vec3(q.row(fixedMember[c]).transpose()) : Vec3(sum[c] / count[c])).transpose();
    }
  }

  // Blending offsets within a span block.
  const int offL = 0, offK = kDegLambda + 1;
  auto evalPoly = [&](const NetSeam& s, int sp, int off, int deg, double tau) {
    double v = 0.0;
    for (int k = deg; k >= 0; --k) v = v * tau + blend[s.blend - nPointVars + sp * kBlendPerSpan + off + k];
    return v;
  };
  auto sides = [&](const NetSeam& s, double t) {
    return std::make_pair(sideJet(pg[static_cast<size_t>(s.pa)], q, s.ea, false, t),
                          sideJet(pg[static_cast<size_t>(s.pb)], q, s.eb, s.reversed, t));
  };

  // Initial blending functions: per seam and span, lambda and kappa by least squares on the G1 identity.
  for (const NetSeam& s : seams)
    for (int sp = 0; sp < s.spans(); ++sp) {
      const auto ts = collocation<kColloc1>(s.breaks, sp);
      Matrix a1(3 * kColloc1, kBlendPerSpan);
      VecX b1(3 * kColloc1);
      for (int c = 0; c < kColloc1; ++c) {
        const double t = ts[static_cast<size_t>(c)], tau = localTau(s, sp, t);
        const auto [jb, jc] = sides(s, t);
        for (int d = 0; d < 3; ++d) {
          const int row = 3 * c + d;
          for (int k = 0; k <= kDegLambda; ++k) a1(row, offL + k) = -jb.value[0][d] * powi(tau, k);
          for (int k = 0; k <= kDegKappa; ++k) a1(row, offK + k) = jb.value[1][d] * powi(tau, k);
          b1[row] = jc.value[0][d];
        }
      }
      const VecX x1 = a1.colPivHouseholderQr().solve(b1);
      for (int k = 0; k < kBlendPerSpan; ++k) blend[s.blend - nPointVars + sp * kBlendPerSpan + k] = x1[k];
    }

  // ---- Gauss-Newton. Rows per seam and span: G0 where the boundary rows are not shared (3 per G0 parameter), G1
  // (3 per G1 parameter), G2 (1 per G2 parameter).
  int m = 0;
  for (const NetSeam& s : seams)
    m += s.spans() * ((s.sharedRow ? 0 : 3 * kColloc0) + 3 * kColloc1 + (g2 ? kColloc2 : 0));
  double residual = 0.0;
  auto assemble = [&](std::vector<Eigen::Triplet<double>>* trip, VecX& r) {
    r.setZero(m);
    int row = 0;
    auto addPoint = [&](int rowIdx, int point, const Vec3& g) {
      const int v = varOf[static_cast<size_t>(point)];
      if (v < 0) return;
      for (int d = 0; d < 3; ++d)
        if (g[d] != 0.0) trip->emplace_back(rowIdx, v + d, g[d]);
    };
    for (const NetSeam& s : seams) {
      for (int sp = 0; sp < s.spans(); ++sp) {
        const int bo = s.blend + sp * kBlendPerSpan;
        // G0 where the rows are not shared: C - B = 0 (both quintic on the span: exact at kColloc0 parameters).
        if (!s.sharedRow)
          for (double t : collocation<kColloc0>(s.breaks, sp)) {
            const auto [jb, jc] = sides(s, t);
            const Vec3 r0 = jc.value[5] - jb.value[5];
            for (int d = 0; d < 3; ++d) r[row + d] = r0[d];
            if (trip)
              for (size_t c2 = 0; c2 < 36; ++c2) {
                for (int d = 0; d < 3; ++d) {
                  const int vc = varOf[static_cast<size_t>(jc.point[c2])], vb = varOf[static_cast<size_t>(jb.point[c2])];
                  if (vc >= 0 && jc.w[5][c2] != 0.0) trip->emplace_back(row + d, vc + d, jc.w[5][c2]);
                  if (vb >= 0 && jb.w[5][c2] != 0.0) trip->emplace_back(row + d, vb + d, -jb.w[5][c2]);
                }
              }
            row += 3;
          }
        // G1: C_s + lambda B_s - kappa B_t = 0 (vector).
        const auto t1 = collocation<kColloc1>(s.breaks, sp);
        for (int c = 0; c < kColloc1; ++c, row += 3) {
          const double t = t1[static_cast<size_t>(c)], tau = localTau(s, sp, t);
          const auto [jb, jc] = sides(s, t);
          const double l = evalPoly(s, sp, offL, kDegLambda, tau), kk = evalPoly(s, sp, offK, kDegKappa, tau);
          const Vec3 r1 = jc.value[0] + l * jb.value[0] - kk * jb.value[1];
          for (int d = 0; d < 3; ++d) r[row + d] = r1[d];
          if (!trip) continue;
          for (size_t c2 = 0; c2 < 36; ++c2) {
            const int vc = varOf[static_cast<size_t>(jc.point[c2])];
            if (vc >= 0 && jc.w[0][c2] != 0.0)
              for (int d = 0; d < 3; ++d) trip->emplace_back(row + d, vc + d, jc.w[0][c2]);
            const int vb = varOf[static_cast<size_t>(jb.point[c2])];
            const double w1 = l * jb.w[0][c2] - kk * jb.w[1][c2];
            if (vb >= 0 && w1 != 0.0)
              for (int d = 0; d < 3; ++d) trip->emplace_back(row + d, vb + d, w1);
          }
          for (int d = 0; d < 3; ++d) {
            for (int k = 0; k <= kDegLambda; ++k) trip->emplace_back(row + d, bo + offL + k, jb.value[0][d] * powi(tau, k));
            for (int k = 0; k <= kDegKappa; ++k) trip->emplace_back(row + d, bo + offK + k, -jb.value[1][d] * powi(tau, k));
          }
        }
        // G2, normal component: n . (C_ss - lambda^2 B_ss + 2 lambda kappa B_st - kappa^2 B_tt) = 0 with the unit
        // normal n = N / |N|, N = B_s x B_t (the unit normal, not N: N . D also vanishes where the patch degenerates,
        // N = 0, which would attract the iteration to singular patches). Zero at kColloc2 parameters makes the
        // polynomial N . D (degree <= 16 per span) vanish identically.
        if (!g2) continue;  // the G1 network solve: no G2 rows
        const auto t2 = collocation<kColloc2>(s.breaks, sp);
        if (s.g1Only) {
          row += kColloc2;  // zero rows: the seam is G1 only
          continue;
        }
        for (int c = 0; c < kColloc2; ++c, ++row) {
          const double t = t2[static_cast<size_t>(c)], tau = localTau(s, sp, t);
          const auto [jb, jc] = sides(s, t);
          const double l = evalPoly(s, sp, offL, kDegLambda, tau), kk = evalPoly(s, sp, offK, kDegKappa, tau);
          const Vec3 N = jb.value[0].cross(jb.value[1]);
          const double nn = std::max(N.norm(), std::numeric_limits<double>::min());
          const Vec3 D = jc.value[2] - l * l * jb.value[2] + 2 * l * kk * jb.value[3] - kk * kk * jb.value[4];
          const double e = N.dot(D);
          r[row] = e / nn;
          if (!trip) continue;
          const Vec3 gs = jb.value[1].cross(D), gt = D.cross(jb.value[0]);
          const Vec3 hs = jb.value[1].cross(N), ht = N.cross(jb.value[0]);  // d|N|^2 / 2 per unit of B_s, B_t
          const double inv = 1.0 / nn, inv3 = e / (nn * nn * nn);
          for (size_t c2 = 0; c2 < 36; ++c2) {
            addPoint(row, jc.point[c2], (jc.w[2][c2] * inv) * N);
            const double wd = -l * l * jb.w[2][c2] + 2 * l * kk * jb.w[3][c2] - kk * kk * jb.w[4][c2];
            addPoint(row, jb.point[c2],
                     inv * (jb.w[0][c2] * gs + jb.w[1][c2] * gt + wd * N) - inv3 * (jb.w[0][c2] * hs + jb.w[1][c2] * ht));
          }
          const double dl = N.dot(-2 * l * jb.value[2] + 2 * kk * jb.value[3]) * inv;
          const double dk = N.dot(2 * l * jb.value[3] - 2 * kk * jb.value[4]) * inv;
          for (int k = 0; k <= kDegLambda; ++k) trip->emplace_back(row, bo + offL + k, dl * powi(tau, k));
          for (int k = 0; k <= kDegKappa; ++k) trip->emplace_back(row, bo + offK + k, dk * powi(tau, k));
        }
      }
    }
  };

  // Weights: control-point coordinates 1, blending coefficients kBlendWeight h^2, h the mean size of the patches'
  // control nets. A blending coefficient is dimensionless and multiplies a derivative of about the patch's size, so
  // a change of it moves the conditions as a point move of about its size times h: with h^2 the step is the same
  // whatever the model's scale (issue 36: with a fixed weight, network_fan5.json scaled by 1e-3 moved only points
  // and stopped at a residual of 0.12 x its size, 0 of 25 seams G2; scaled by 1e4 it moved only the blends).
  double netSize = 0.0;
  for (const BSplineSurface& f : form)
    netSize += (f.points().colwise().maxCoeff() - f.points().colwise().minCoeff()).norm() / static_cast<double>(np);
  VecX winv(nv);
  winv.head(nPointVars).setOnes();
  winv.tail(nv - nPointVars).setConstant(1.0 / (kBlendWeight * netSize * netSize));
  // With the fairness term, the row beside every edge that meets a patch outside the solve (a kept design crease, a
  // seam to another region) is stiff: the fairness coupling would otherwise spread changes into it and turn the angle
  // across that seam (heal refuses any change of it); it moves only where the conditions need it (near the vertices),
  // as it does without the term. Rows beside true free boundaries stay ordinary.
  if (opt.fairness > 0.0)
    for (const auto& [ri, ei] : facing)
      for (int k = 0; k < pg[static_cast<size_t>(ri)].along(static_cast<Edge>(ei)).grid; ++k) {
        const auto [i, j] = rowIndex(pg[static_cast<size_t>(ri)], static_cast<Edge>(ei), 1, k);
        const int v = varOf[static_cast<size_t>(pg[static_cast<size_t>(ri)].at(i, j))];
        if (v >= 0) winv.segment<3>(v).setConstant(1.0 / kFacingRowWeight);
      }
  const double target = opt.residualRel * diag;
  VecX r;
  int it = 0;
  std::vector<double> history;
  // Fairness (options.fairness > 0): the step minimises |delta|_W^2 + fairness * (sum of the squared second
  // differences of the control-point changes along both directions of every patch, and twice the squared mixed
  // differences) subject to J delta = -r: the KKT system [W + f K, J^T; J, -gamma I] (quasi-definite, LDL^T; the
  // symbolic analysis is redone only when the pattern changes).
  Eigen::SparseMatrix<double> fairK;
  if (opt.fairness > 0.0) {
    std::vector<Eigen::Triplet<double>> kt;
    size_t stencils = 0;  // at most 3 + 3 + 4 taps per grid point: 9 + 9 + 16 blocks of 3 entries
    for (const PatchGrid& g : pg) stencils += static_cast<size_t>(g.u.grid) * static_cast<size_t>(g.v.grid);
    kt.reserve(stencils * 34 * 3);
    // w * (sum g_i delta_i)^2 over a fixed-size stencil (a std::array: no allocation per call, which took about a
    // tenth of a strict G2 heal of sunglasses_lens.igs when each stencil was a std::vector).
    auto addDiff = [&](const auto& g, double w) {
      for (const auto& [a, ga] : g) {
        const int va = varOf[static_cast<size_t>(a)];
        if (va < 0) continue;
        for (const auto& [b, gb] : g) {
          const int vb = varOf[static_cast<size_t>(b)];
          if (vb < 0) continue;
          for (int d = 0; d < 3; ++d) kt.emplace_back(va + d, vb + d, w * ga * gb);
        }
      }
    };
    for (int ri = 0; ri < np; ++ri) {
      const PatchGrid& g = pg[static_cast<size_t>(ri)];
      auto at = [&](int i, int j) { return g.at(i, j); };
      const int nu = g.u.grid, nvv = g.v.grid;
      for (int i = 0; i < nu; ++i)
        for (int j = 0; j < nvv; ++j) {
          using Tap = std::pair<int, double>;
          using Three = std::array<Tap, 3>;
          using Four = std::array<Tap, 4>;
          if (i + 2 < nu) addDiff(Three{{{at(i, j), 1.0}, {at(i + 1, j), -2.0}, {at(i + 2, j), 1.0}}}, 1.0);
          if (j + 2 < nvv) addDiff(Three{{{at(i, j), 1.0}, {at(i, j + 1), -2.0}, {at(i, j + 2), 1.0}}}, 1.0);
          if (i + 1 < nu && j + 1 < nvv)
            addDiff(Four{{{at(i, j), 1.0}, {at(i + 1, j), -1.0}, {at(i, j + 1), -1.0}, {at(i + 1, j + 1), 1.0}}}, 2.0);
        }
    }
    fairK.resize(nv, nv);
    fairK.setFromTriplets(kt.begin(), kt.end());
    fairK *= opt.fairness;
  }
  SizedLDLT kkt;
  std::vector<int> kktOuter, kktInner;
  bool fairTooDear = false;  // the fairness term's factorisation is above maxFairFactorOperations: not used
  for (;; ++it) {
    std::vector<Eigen::Triplet<double>> trip;
    assemble(&trip, r);
    residual = r.cwiseAbs().maxCoeff();
    if (residual <= target || it >= opt.maxIterations) break;
    // Stagnation: the vertex conditions make the system degenerate there (n tangent-plane equations for a
    // condition of codimension n - 2), so the last digits come linearly; stop when kStagnationSteps steps gain less
    // than 2x once the result is acceptable, twice as many before (the largest residual is not monotone: the line
    // search decreases the 2-norm, and a crease inside a patch slows the middle phase).
    history.push_back(residual);
    const size_t window = residual <= opt.acceptRel * diag ? kStagnationSteps : 2 * kStagnationSteps;
    if (history.size() > window && residual > 0.5 * history[history.size() - 1 - window]) break;
    Eigen::SparseMatrix<double> J(m, nv);
    J.setFromTriplets(trip.begin(), trip.end());
    // Rows scaled to unit norm (the G2 rows carry second derivatives, ~25 x the first): the same solutions, a
    // better-conditioned normal matrix.
    VecX rowScale = VecX::Zero(m);
    for (int k = 0; k < J.outerSize(); ++k)
      for (Eigen::SparseMatrix<double>::InnerIterator itr(J, k); itr; ++itr)
        rowScale[itr.row()] += itr.value() * itr.value() * winv[itr.col()];
    for (int i = 0; i < m; ++i) rowScale[i] = rowScale[i] > 0.0 ? 1.0 / std::sqrt(rowScale[i]) : 1.0;
    J = rowScale.asDiagonal() * J;
    r = rowScale.asDiagonal() * r;
    const double r2 = r.squaredNorm();
    VecX step;
    bool fairPhase = opt.fairness > 0.0 && !fairTooDear && residual > kFairPhaseRel * diag;
    // The step of least weighted change (with the fairness term while fairPhase): the KKT system
    // [W + f K, J^T; J, -gamma I] (delta, y) = (0, -r), one sparse LDL^T. The fairness-free steps are the same
    // least-change step as -W^-1 J^T (J W^-1 J^T)^-1 r, but the KKT matrix keeps J's sparsity where J W^-1 J^T couples
    // every row of a seam with every other (measured 2026-11-30: a fan of 5 with uneven knots 10.5 -> 3.7 s, the
    // Bezier fan 1.4 -> 0.9 s, final residuals alike).
    {
      const auto kktMatrix = [&](bool withFairness) {
        std::vector<Eigen::Triplet<double>> t;
        t.reserve(static_cast<size_t>(fairK.nonZeros() + 2 * J.nonZeros() + nv + m));
        for (int k = 0; withFairness && k < fairK.outerSize(); ++k)
          for (Eigen::SparseMatrix<double>::InnerIterator itr(fairK, k); itr; ++itr)
            t.emplace_back(itr.row(), itr.col(), itr.value());
        for (int i = 0; i < nv; ++i) t.emplace_back(i, i, 1.0 / winv[i]);
        for (int k = 0; k < J.outerSize(); ++k)
          for (Eigen::SparseMatrix<double>::InnerIterator itr(J, k); itr; ++itr) {
            t.emplace_back(nv + itr.row(), itr.col(), itr.value());
            t.emplace_back(itr.col(), nv + itr.row(), itr.value());
          }
        for (int i = 0; i < m; ++i) t.emplace_back(nv + i, nv + i, -kRegularisationRel);
        Eigen::SparseMatrix<double> out(nv + m, nv + m);
        out.setFromTriplets(t.begin(), t.end());
        out.makeCompressed();
        return out;
      };
      Eigen::SparseMatrix<double> K = kktMatrix(fairPhase);
      const auto analyseIfNew = [&] {
        const std::vector<int> outer(K.outerIndexPtr(), K.outerIndexPtr() + K.outerSize() + 1);
        const std::vector<int> inner(K.innerIndexPtr(), K.innerIndexPtr() + K.nonZeros());
        if (outer == kktOuter && inner == kktInner) return;
        kkt.analyzePattern(K);
        kktOuter = outer;
        kktInner = inner;
      };
      analyseIfNew();
      if (fairPhase && kkt.factorOperations() > opt.maxFairFactorOperations) {
        // The fairness term would fill the factor in (maxFairFactorOperations): plain least-change steps instead.
        rep.notes.push_back(fmt::format(
            "fairness term not used: with it one step's factorisation takes about {:.2g} multiply-adds (limit {:.2g}; "
            "{} unknowns, {} equations); the steps are of least control-point change",
            kkt.factorOperations(), opt.maxFairFactorOperations, nv, m));
        fairTooDear = true;
        fairPhase = false;
        K = kktMatrix(false);
        analyseIfNew();
      }
      kkt.factorize(K);
      if (kkt.info() != Eigen::Success)
        return Status(ErrorCode::kNoSolution, "the " + solveName + " system could not be factorised");
      VecX rhs = VecX::Zero(nv + m);
      rhs.tail(m) = -r;
      VecX sol = kkt.solve(rhs);
      sol += kkt.solve(rhs - K * sol);  // one step of iterative refinement
      step = sol.head(nv);
    }
    // Backtracking on the residual's 2-norm (the identities are bilinear in points and blending coefficients).
    const Matrix qPrev = q;
    const VecX blendPrev = blend;
    double alpha = 1.0;
    bool decreased = false;
    for (int bt = 0; bt < kMaxHalvings; ++bt, alpha *= 0.5) {
      q = qPrev;
      blend = blendPrev;
      for (int g = 0; g < nPoints; ++g) {
        const int v = varOf[static_cast<size_t>(g)];
        if (v >= 0) q.row(g) += alpha * step.segment<3>(v).transpose();
      }
      blend += alpha * step.tail(nv - nPointVars);
      VecX rTry;
      assemble(nullptr, rTry);
      if ((rowScale.asDiagonal() * rTry).squaredNorm() < r2) {
        decreased = true;
        break;
      }
    }
    if (!decreased) {  // no descent along the step: keep the last iterate and stop
      q = qPrev;
      blend = blendPrev;
      break;
    }
  }
  rep.iterations = it;
  rep.residualRel = residual / diag;
  // ---- lambda > 0 everywhere (linear per span: its end values), and the result.
  double minLambda = std::numeric_limits<double>::infinity();
  for (const NetSeam& s : seams)
    for (int sp = 0; sp < s.spans(); ++sp)
      for (double tau : {0.0, 1.0}) minLambda = std::min(minLambda, evalPoly(s, sp, offL, kDegLambda, tau));
  rep.minLambda = minLambda;
  if (residual > opt.acceptRel * diag)
    return Status(ErrorCode::kNoSolution,
                  fmt::format("the {} solve stopped after {} iterations with a residual of {:.3g} x the model "
                              "size (wanted {:.1g})",
                              solveName, it, rep.residualRel, opt.acceptRel));
  if (!(minLambda > 0.0))
    return Status(ErrorCode::kNoSolution,
                  fmt::format("the {} solution folds a seam (lambda down to {:.3g})", solveName, minLambda));

  for (int ri = 0; ri < np; ++ri) {
    const int mi = chosen[static_cast<size_t>(ri)];
    Patch& p = res.model.patches[static_cast<size_t>(mi)];
    const BSplineSurface& orig = p.surface;
    const PatchGrid& g = pg[static_cast<size_t>(ri)];
    BSplineSurface out(kDeg, kDeg, g.u.knots, g.v.knots, g.u.grid, g.v.grid, q.middleRows(g.offset, g.count()));
    out = out.reparametrized(orig.domainU(), orig.domainV());
    const BSplineSurface& f = form[static_cast<size_t>(ri)];
    double size = 0.0;
    {
      const Matrix& pts = f.points();
      size = (pts.colwise().maxCoeff() - pts.colwise().minCoeff()).norm();
    }
    const double disp = (q.middleRows(g.offset, g.count()) - f.points()).rowwise().norm().maxCoeff();
    if (disp > rep.maxDisplacement) {
      rep.maxDisplacement = disp;
      rep.maxDisplacementRel = size > 0.0 ? disp / size : 0.0;
    }
    p.surface = std::move(out);
    rep.patchesChanged.push_back(p.name);
  }
  std::set<int> val;
  for (const auto& [vr, g] : vertexGroups)
    if (!g.boundary && g.corners > 1) val.insert(g.corners);
  rep.valences.assign(val.begin(), val.end());
  reportVertices(model, res.model, chosen, seams, vertexOf, vertexGroups, rep);
  if (raisedAny) rep.notes.push_back("degree raised to 5 x 5 (exact) for the " + solveName + " solve");
  if (refined)
    rep.notes.push_back(fmt::format("knots inserted (exact): the middle 1/2 where a patch had no interior knot, every "
                                    "interior knot to multiplicity {} at least; no patch takes another's knots",
                                    kMinMult));
  const int g0Seams = static_cast<int>(std::count_if(seams.begin(), seams.end(), [](const NetSeam& s) { return !s.sharedRow; }));
  if (g0Seams > 0)
    rep.notes.push_back(fmt::format("{} seam(s) between boundary rows of different knots: G0 held by equations on the "
                                    "merged spans",
                                    g0Seams));
  rep.notes.push_back(fmt::format("output patches are biquintic B-splines, C2 inside except where the input is only C1 or C0 "
                                  "(it keeps that smoothness at every knot); {} Gauss-Newton "
                                  "steps, identity residual {:.2g} x the model size",
                                  rep.iterations, rep.residualRel));
  return res;
}

}  // namespace seam
