// `seam heal`: pair the seams, group them into regions, and per region take the best of the successive
// least-squares joins (each step accepted only if it makes no seam worse), the local G1 scheme and the input.
#include "seam/repair/heal.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <map>
#include <memory>

#include "repair/frame_internal.h"
#include "repair/join_internal.h"
#include "repair/network_internal.h"
#include "seam/repair/g2_network.h"
#include "seam/continuity/model_check.h"
#include "seam/repair/join.h"
#include "seam/regularity/defect_search.h"
#include "seam/repair/local_scheme.h"

namespace seam {

std::string_view toString(HealMethod m) {
  switch (m) {
    case HealMethod::kAuto: return "auto";
    case HealMethod::kSuccessive: return "successive";
    case HealMethod::kLocal: return "local";
  }
  return "?";
}

Result<HealMethod> parseHealMethod(std::string_view text) {
  for (HealMethod m : {HealMethod::kAuto, HealMethod::kSuccessive, HealMethod::kLocal})
    if (text == toString(m)) return m;
  return invalidInput(fmt::format("unknown heal method \"{}\" (expected auto, successive or local)", text));
}

namespace {

enum class SeamState { kKept, kToJoin, kSkipped };

struct Work {
  EdgePair pair;
  SeamReport before;
  SeamState state = SeamState::kKept;
  bool crease = false;  // skipped as a design crease (kink angle above maxAngleDeg), not for its gap
  int region = -1;
};

std::optional<Interval> rangeOf(const EdgePair& p, bool sideA) {
  if (sideA) return p.fullA ? std::nullopt : std::optional<Interval>(p.overlapA);
  return p.fullB ? std::nullopt : std::optional<Interval>(p.overlapB);
}

bool isFold(const SeamReport& r) {
  const bool lambdaKnown = !(r.lambdaRange.lo == 0.0 && r.lambdaRange.hi == 0.0);
  return r.g1SampledDeg >= kFoldAngleDeg || (lambdaKnown && r.lambdaRange.lo <= 0.0);
}

/// Why `now` is worse than `ref` ("" when it is not): the reported values (certified bounds when certified) must
/// not grow beyond the tolerances, the class must not drop, no fold may appear, a certified seam stays certified.
/// Angles on seam's strict scale (min(tolerance, kStrictAngleDeg)): a CAD tolerance of 0.5 deg must not let a seam's
/// angle grow by half a degree.
std::string worseThan(const SeamReport& now, const SeamReport& ref, const Tolerances& tol) {
  if (now.g0Max > ref.g0Max + tol.distance) return fmt::format("gap {:.3g} -> {:.3g}", ref.g0Max, now.g0Max);
  if (now.g1MaxDeg > ref.g1MaxDeg + tol.strictAngleDeg())
    return fmt::format("kink angle {:.3g} -> {:.3g} deg", ref.g1MaxDeg, now.g1MaxDeg);
  if (static_cast<int>(now.geometric) < static_cast<int>(ref.geometric))
    return fmt::format("class {} -> {}", toString(ref.geometric), toString(now.geometric));
  if (isFold(now) && !isFold(ref)) return "a fold (the tangent planes turn over, lambda <= 0)";
  if (ref.certified && !now.certified) return "no longer certified";
  return "";
}

double sizeOf(const BSplineSurface& s) {
  const double d = controlBox(s).diagonal();
  return d > 0.0 ? d : 1.0;
}

/// A point of `s` at the normalised parameters (a, b) in [0,1]^2.
Vec3 atNormalised(const BSplineSurface& s, double a, double b) {
  const Interval du = s.domainU(), dv = s.domainV();
  return s.evaluate(du.lo + a * du.length(), dv.lo + b * dv.length()).head<3>();
}

/// A point of edge `e` of `s` at the normalised edge parameter t in [0,1].
Vec3 edgeAt(const BSplineSurface& s, Edge e, double t) {
  switch (e) {
    case Edge::U0: return atNormalised(s, 0.0, t);
    case Edge::U1: return atNormalised(s, 1.0, t);
    case Edge::V0: return atNormalised(s, t, 0.0);
    case Edge::V1: return atNormalised(s, t, 1.0);
  }
  return Vec3::Zero();
}

/// Largest distance between edge `e` of two versions of a patch (33 samples at equal normalised parameters).
double edgeMovement(const BSplineSurface& before, const BSplineSurface& after, Edge e) {
  constexpr int kSamples = 33;
  double d = 0.0;
  for (int i = 0; i < kSamples; ++i) {
    const double t = static_cast<double>(i) / (kSamples - 1);
    d = std::max(d, (edgeAt(after, e, t) - edgeAt(before, e, t)).norm());
  }
  return d;
}

/// How far seam `pair`'s two boundary curves moved from `before` to `after` (the larger of the two).
double seamEdgeMovement(const Model& before, const Model& after, const EdgePair& pair) {
  double d = 0.0;
  for (const EdgeRef& e : {pair.a, pair.b})
    d = std::max(d, edgeMovement(before.patches[static_cast<size_t>(e.patch)].surface,
                                 after.patches[static_cast<size_t>(e.patch)].surface, e.edge));
  return d;
}

/// The report's totals over its changed patches (rep.patches).
void sumPatchDisplacements(HealReport& rep) {
  rep.maxDisplacement = rep.maxSurfaceDisplacement = rep.maxSurfaceDisplacementRel = 0.0;
  rep.movedPoints = 0;
  rep.surfaceDisplacementCertified = true;
  for (const HealPatch& hp : rep.patches) {
    rep.maxDisplacement = std::max(rep.maxDisplacement, hp.maxDisplacement);
    rep.movedPoints += hp.movedPoints;
    rep.maxSurfaceDisplacement = std::max(rep.maxSurfaceDisplacement, hp.maxSurfaceDisplacement);
    rep.maxSurfaceDisplacementRel = std::max(rep.maxSurfaceDisplacementRel, hp.maxSurfaceDisplacementRel);
    rep.surfaceDisplacementCertified = rep.surfaceDisplacementCertified && hp.surfaceDisplacementCertified;
  }
}

/// Basis values of one direction of a polynomial B-spline at the lattice of `grid` equally spaced parameters of its
/// domain (sampledSurfaceDistance's lattice): per lattice line the first non-zero function and the p + 1 values.
struct LatticeBasis {
  std::vector<double> knots;
  int degree = -1;
  std::vector<int> first;
  Matrix values;
};

/// The lattice basis of (knots, degree), computed once per distinct knot vector and degree (a heal's patches share a
/// few: the scheme's output all have {0^6, 1/2^4, 1^6}); a small per-thread cache of the last ones.
const LatticeBasis& latticeBasis(const KnotVector& kv, int p, int grid) {
  thread_local std::vector<LatticeBasis> cache;
  for (const LatticeBasis& b : cache)
    if (b.degree == p && static_cast<Eigen::Index>(b.first.size()) == grid && b.knots == kv.values()) return b;
  if (cache.size() >= 8) cache.erase(cache.begin());
  LatticeBasis b;
  b.knots = kv.values();
  b.degree = p;
  b.first.resize(static_cast<size_t>(grid));
  b.values.resize(grid, p + 1);
  const Interval iv = kv.domain(p);
  for (int a = 0; a < grid; ++a) {
    const double t = a + 1 == grid ? iv.hi : iv.lo + iv.length() * a / (grid - 1);
    const int span = kv.findSpan(p, t);
    b.values.row(a) = basisFunctionDerivatives(kv, p, span, t, 0).row(0);
    b.first[static_cast<size_t>(a)] = span - p;
  }
  cache.push_back(std::move(b));
  return cache.back();
}

/// Largest |D(u, v)| over the grid x grid lattice of D's domain, D the polynomial B-spline (degrees p, q, knots ku,
/// kv, nv control points per u-row, row i * nv + j of `points`): per lattice u-line the blend of the p + 1 control
/// rows, then per lattice point the q + 1 values of it.
double latticeMaxNorm(const KnotVector& ku, const KnotVector& kv, int p, int q, int nv, const Matrix& points,
                      int grid) {
  // The basis values are copied into fixed arrays (the second look-up may grow the cache); the sums are formed in
  // the order of the Eigen expressions they replace (row += N * rows; v += N * row), so the values keep their bits.
  constexpr int kMaxGrid = 64, kMaxOrder = 16, kMaxRow = 64;
  if (grid > kMaxGrid || p + 1 > kMaxOrder || q + 1 > kMaxOrder || nv > kMaxRow || points.cols() != 3) {
    const LatticeBasis bu = latticeBasis(ku, p, grid);
    const LatticeBasis bv = latticeBasis(kv, q, grid);
    Eigen::Matrix<double, Eigen::Dynamic, 3> row(nv, 3);
    double best = 0.0;
    for (int a = 0; a < grid; ++a) {
      row.setZero();
      for (int r = 0; r <= p; ++r)
        row += bu.values(a, r) * points.middleRows((bu.first[static_cast<size_t>(a)] + r) * nv, nv);
      for (int b = 0; b < grid; ++b) {
        Vec3 v = Vec3::Zero();
        for (int c = 0; c <= q; ++c) v += bv.values(b, c) * row.row(bv.first[static_cast<size_t>(b)] + c).transpose();
        best = std::max(best, v.norm());
      }
    }
    return best;
  }
  double uVal[kMaxGrid][kMaxOrder], vVal[kMaxGrid][kMaxOrder];
  int uFirst[kMaxGrid], vFirst[kMaxGrid];
  {
    const LatticeBasis& bu = latticeBasis(ku, p, grid);
    for (int a = 0; a < grid; ++a) {
      uFirst[a] = bu.first[static_cast<size_t>(a)];
      for (int r = 0; r <= p; ++r) uVal[a][r] = bu.values(a, r);
    }
    const LatticeBasis& bv = latticeBasis(kv, q, grid);
    for (int b = 0; b < grid; ++b) {
      vFirst[b] = bv.first[static_cast<size_t>(b)];
      for (int c = 0; c <= q; ++c) vVal[b][c] = bv.values(b, c);
    }
  }
  double row[kMaxRow][3];
  double best = 0.0;
  for (int a = 0; a < grid; ++a) {
    for (int j = 0; j < nv; ++j) row[j][0] = row[j][1] = row[j][2] = 0.0;
    for (int r = 0; r <= p; ++r) {
      const double n = uVal[a][r];
      const Eigen::Index base = static_cast<Eigen::Index>(uFirst[a] + r) * nv;
      for (int j = 0; j < nv; ++j)
        for (int k = 0; k < 3; ++k) row[j][k] = row[j][k] + n * points(base + j, k);
    }
    for (int b = 0; b < grid; ++b) {
      Vec3 v = Vec3::Zero();
      for (int c = 0; c <= q; ++c) {
        const double n = vVal[b][c];
        const double* rr = row[vFirst[b] + c];
        v = Vec3(v[0] + n * rr[0], v[1] + n * rr[1], v[2] + n * rr[2]);
      }
      best = std::max(best, v.norm());
    }
  }
  return best;
}

/// How far `after` moved from `before` (see HealPatch). `beforeLikeAfter`: `before` already expressed in `after`'s
/// knots and degrees (detail::expressedLike(before, after), e.g. the local scheme's exact form of its input), or
/// nullptr.
HealPatch displacementOf(const Patch& before, const Patch& after, double threshold,
                         const BSplineSurface* beforeLikeAfter = nullptr) {
  HealPatch hp;
  hp.name = after.name;
  hp.size = sizeOf(before.surface);
  const BSplineSurface& b = before.surface;
  const BSplineSurface& a = after.surface;
  const double kt = kKnotRelTol * std::max(1.0, std::max(b.domainU().length(), b.domainV().length()));
  const bool sameDomain = std::abs(a.domainU().lo - b.domainU().lo) <= kt &&
                          std::abs(a.domainU().hi - b.domainU().hi) <= kt &&
                          std::abs(a.domainV().lo - b.domainV().lo) <= kt &&
                          std::abs(a.domainV().hi - b.domainV().hi) <= kt;
  bool bound = false;
  constexpr int kGrid = 21;
  bool sampled = false;
  if (sameDomain && a.degreeU() >= b.degreeU() && a.degreeV() >= b.degreeV()) {
    if (!a.isRational() && !b.isRational()) {
      // controlPointDisplacement's measures from one expression of `before` in `after`'s basis, which also gives the
      // difference surface after - before: sampled once on the grid instead of sampling both surfaces.
      const bool given = beforeLikeAfter != nullptr && beforeLikeAfter->degreeU() == a.degreeU() &&
                         beforeLikeAfter->degreeV() == a.degreeV() &&
                         beforeLikeAfter->knotsU().values() == a.knotsU().values() &&
                         beforeLikeAfter->knotsV().values() == a.knotsV().values();
      const BSplineSurface computed = given ? BSplineSurface() : detail::expressedLike(b, a);
      const BSplineSurface& ref = given ? *beforeLikeAfter : computed;
      if (ref.numU() == a.numU() && ref.numV() == a.numV() && !ref.isRational()) {
        const Matrix diff = a.points() - ref.points();
        hp.maxDisplacement = 0.0;
        hp.movedPoints = 0;
        for (Eigen::Index r = 0; r < diff.rows(); ++r) {
          const double dist = diff.row(r).norm();
          hp.maxDisplacement = std::max(hp.maxDisplacement, dist);
          if (dist > threshold) ++hp.movedPoints;  // polynomial: every weight is 1 on both sides
        }
        bound = std::isfinite(hp.maxDisplacement);
        if (a.domainU() == b.domainU() && a.domainV() == b.domainV() && diff.cols() == 3) {
          hp.maxSurfaceDisplacementSampled =
              latticeMaxNorm(a.knotsU(), a.knotsV(), a.degreeU(), a.degreeV(), a.numV(), diff, kGrid);
          sampled = true;
        }
      } else {
        hp.maxDisplacement = std::numeric_limits<double>::infinity();
        hp.movedPoints = static_cast<int>(a.points().rows());
      }
    } else {
      const Displacement d = controlPointDisplacement(b, a, threshold);
      hp.maxDisplacement = d.max;
      hp.movedPoints = d.moved;
    }
  } else {
    hp.maxDisplacement = std::numeric_limits<double>::infinity();
    hp.movedPoints = static_cast<int>(a.points().rows());
  }
  if (!sampled) hp.maxSurfaceDisplacementSampled = sampledSurfaceDistance(b, a, kGrid);
  hp.surfaceDisplacementCertified = bound;
  hp.maxSurfaceDisplacement = bound ? hp.maxDisplacement : hp.maxSurfaceDisplacementSampled;
  hp.maxSurfaceDisplacementRel = hp.maxSurfaceDisplacement / hp.size;
  return hp;
}

/// One way of healing, judged region by region.
struct Candidate {
  std::string method;  // "successive", "local", "none"
  /// What produced a "local" candidate, for the notes: "local scheme", or "G1 network solve" where the local scheme
  /// did not apply.
  std::string solver = "local scheme";
  const Model* model = nullptr;
  bool acceptable = false;
  int achieved = 0, moved = 0;
  bool changed = false;          // some patch of the region differs from the input
  double displacement = 0.0;     // largest surface displacement
  double displacementRel = 0.0;  // largest surface displacement relative to its patch's size
  std::vector<std::optional<SeamReport>> after;  // per seam of the region
  /// The displacement of every patch of the region that differs from the input (model patch index, as
  /// displacementOf gives it): the report's displacements of the chosen candidate, not computed a second time.
  std::vector<std::pair<int, HealPatch>> displaced;
  std::string note;                              // why it is not acceptable, or the region's shortfall
};

/// The gaps of design creases, closed before the heal proper (issue 38 goal 4): a crease keeps its angle, but its gap
/// is a defect. Per crease seam with a gap above the distance tolerance (and within maxGap), one side moves: the G0
/// least-squares join (detail::leastSquaresJoin) moves its boundary row onto the other side's boundary, and the row
/// next to it moves by the same displacement, so that the cross-boundary derivative S_n = p (P_1 - P_0) / h along
/// the edge is unchanged (exactly for polynomial patches) and the normal turns only as much as the boundary's
/// tangent does. The move is kept when the crease's gap shrinks, its angle stays within the angle tolerance, no
/// other seam of the patch is worse (worseThan) and the patch does not fold; of the two sides the one that moves
/// least. The heal proper then runs on the result, with the crease left alone as before.
struct CreaseOutcome {
  int work = -1;              // index into the first Healer's work_
  std::string action;         // "crease: gap closed", "crease: gap narrowed" or "crease: gap not closed"
  std::string mover;          // the patch that moved ("" when none did)
  std::string note;
};
struct CreaseGapPass {
  Model model;
  bool changed = false;
  std::vector<CreaseOutcome> outcomes;
  std::vector<int> movedPatches;
};

/// The constraint that joins edge `se` of the moving patch S to edge `xe` of the fixed patch X (`cur`: their seam as
/// analysed now, S as side A), with the targets' cross derivatives up to `order`. Whole edge against whole edge:
/// corners within the gap limit meet (detail::cornerSnappedOverlap). `overlapS` (if given): the part of S's edge joined.
detail::EdgeConstraint seamConstraint(const Patch& S, Edge se, const Patch& X, Edge xe, const SeamReport& cur,
                                      const EdgePair& pair, double maxGap, int order, Interval* overlapS = nullptr) {
  Interval oA = cur.overlapA, oB = cur.overlapB;
  if (pair.fullA && pair.fullB) {
    const detail::JoinOverlap ov =
        detail::cornerSnappedOverlap(S.surface, se, X.surface, xe, oA, oB, cur.reversed, maxGap);
    oA = ov.s;
    oB = ov.t;
  }
  detail::EdgeConstraint c;
  c.edge = se;
  const BSplineSurface Xf = detail::toEdgeFrame(X.surface, xe, cur.reversed);
  c.target = detail::targetFromFrame(Xf, oA, cur.reversed ? -oB.hi : oB.lo, oB.length() / oA.length(), order);
  if (overlapS) *overlapS = oA;
  return c;
}

struct SuccessiveRun {
  Model model;
  std::vector<HealStep> steps;
  std::vector<int> mover;                         // per work item
  std::vector<std::vector<std::string>> notes;    // per work item
};

class Healer {
 public:
  Healer(const Model& input, const HealOptions& opt) : in_(input), opt_(opt) {}

  /// Checks the options, pairs the edges and analyses every seam of the input.
  Status prepare();
  /// The heal proper (after prepare).
  Result<HealResult> finish();
  /// Closes the gaps of design creases (issue 38 goal 4, after prepare): see CreaseGapPass.
  CreaseGapPass closeCreaseGaps() const;
  /// The report of a heal of `pass.model` (a second Healer's finish) told against this Healer's input: seams before
  /// as in the input, the creases' actions, the displacements against the input patches.
  void mergeCreasePass(HealResult& res, const CreaseGapPass& pass) const;
  [[nodiscard]] const Tolerances& tolerances() const { return tol_; }
  [[nodiscard]] double maxGap() const { return maxGap_; }

 private:
  std::string seamName(const EdgePair& p) const {
    return fmt::format("{}:{} / {}:{}", in_.patches[static_cast<size_t>(p.a.patch)].name, edgeName(p.a.edge),
                       in_.patches[static_cast<size_t>(p.b.patch)].name, edgeName(p.b.edge));
  }
  Result<SeamReport> analyse(const Model& m, const EdgePair& p) const {
    return analyzeSeam(m.patches[static_cast<size_t>(p.a.patch)], p.a.edge, m.patches[static_cast<size_t>(p.b.patch)],
                       p.b.edge, so_, rangeOf(p, true));
  }
  void buildOrder();
  SuccessiveRun successive(bool strict) const;
  /// `inputForms`: per model patch index the input patch in the candidate's knots and degrees where known
  /// (nullptr entries, or no vector at all: computed by displacementOf).
  Candidate judge(const Model& m, std::string method, int region,
                  const std::vector<const BSplineSurface*>* inputForms = nullptr) const;
  bool freeEdgesKept(const Model& m, int region, std::string* why) const;
  /// Why moving patch `i` to `cand` is worse inside the patch ("" when it is not), issue 36 goal 2: a fold (S_u x S_v
  /// vanishes at a point where the input patch is regular: the surface turns back over itself there), a normal that
  /// turns against the input's by more than 90 degrees and more than the crease angle (no seam the heal joins
  /// asks for that), or more self-intersections than the input patch.
  std::string foldOf(int i, const BSplineSurface& cand) const;
  std::string leftAloneBroken(const Model& m, int k, const SeamReport& now, int region) const;
  /// Patch `me.patch` of `m` with the gap of crease seam `pair` closed by moving it (see CreaseGapPass);
  /// `lockOthers`: the positions along its other three edges stay.
  Result<BSplineSurface> creaseGapMove(const Model& m, const EdgePair& pair, bool moverIsA, bool lockOthers) const;

  const Model& in_;
  HealOptions opt_;
  double diag_ = 1.0, maxGap_ = 0.0, maxAngle_ = kDefaultMaxHealAngleDeg;
  Tolerances tol_;
  SeamOptions so_;
  EdgePairing pairing_;
  int np_ = 0;
  std::vector<Work> work_;
  std::vector<std::vector<int>> regionPatches_, regionSeams_;
  std::vector<std::vector<int>> regionFrozen_;  // skipped seams (gaps, creases) with a side in the region
  std::vector<int> patchRegion_;
  std::vector<int> order_;          // patches in the order they move
  /// Regions the successive runs leave out (auto: the local scheme already reached G1 there and the region has
  /// vertices of valence other than 4, which successive joins cannot close).
  std::vector<char> skipSuccessive_;
  std::vector<char> initialSettled_;
  struct CornerAt {
    Vec3 p;
    int patch;
  };
  std::vector<CornerAt> corners_;
  std::vector<std::shared_ptr<Model>> localModels_;  // the local scheme's results (candidates point into them)
  /// Self-intersections found in each input patch (-1: not searched yet; foldOf searches on demand).
  mutable std::vector<int> inputSelfIntersections_;
  /// The joins of the successive runs by their exact inputs (joinKey): the strict run repeats the relaxed run's
  /// steps until the first verdict that differs, and each of those joins (a sparse least-squares solve) is the same
  /// computation (sunglasses_lens.igs at --tol-angle 0.01: 110 solves, every one twice).
  mutable std::map<std::string, Result<detail::LsJoinOutcome>> joinMemo_;
  Result<detail::LsJoinOutcome> memoJoin(const BSplineSurface& s, const std::vector<detail::EdgeConstraint>& cons,
                                         const detail::LsJoinOptions& lo) const;
  std::vector<std::string> prepareNotes_;  // seams that could not be analysed
};

namespace {

/// The bytes of every input of a join (the surface, the constraints with their targets, the options): equal keys,
/// the same join. Doubles are taken bit for bit (a -0.0 and a 0.0 differ: a miss, never a wrong hit).
std::string joinKey(const BSplineSurface& s, const std::vector<detail::EdgeConstraint>& cons,
                    const detail::LsJoinOptions& lo) {
  std::string key;
  const auto put = [&key](const auto& x) { key.append(reinterpret_cast<const char*>(&x), sizeof x); };
  const auto putDoubles = [&key, &put](const double* p, Eigen::Index n) {
    put(n);
    key.append(reinterpret_cast<const char*>(p), static_cast<size_t>(n) * sizeof(double));
  };
  const auto putMatrix = [&](const Matrix& m) {
    put(m.rows());
    putDoubles(m.data(), m.size());
  };
  put(s.degreeU());
  put(s.degreeV());
  put(s.numU());
  put(s.numV());
  putDoubles(s.knotsU().values().data(), static_cast<Eigen::Index>(s.knotsU().values().size()));
  putDoubles(s.knotsV().values().data(), static_cast<Eigen::Index>(s.knotsV().values().size()));
  putMatrix(s.points());
  putDoubles(s.weights().data(), s.weights().size());
  put(cons.size());
  for (const detail::EdgeConstraint& c : cons) {
    put(c.edge);
    put(c.kappaZeroAtStart);
    put(c.kappaZeroAtEnd);
    put(c.target.rational);
    put(c.target.dimH);
    put(c.target.breaks.size());
    for (const auto& [u, k] : c.target.breaks) {
      put(u);
      put(k);
    }
    put(c.target.pieces.size());
    for (const detail::TargetPiece& p : c.target.pieces) {
      put(p.u.lo);
      put(p.u.hi);
      putMatrix(p.point.coeffs());
      putMatrix(p.cross1.coeffs());
      putMatrix(p.cross2.coeffs());
    }
  }
  put(lo.continuity);
  put(lo.scale);
  put(lo.lockedEdges.size());
  for (Edge e : lo.lockedEdges) put(e);
  put(lo.lockedRows);
  put(lo.elevate);
  return key;
}

}  // namespace

Result<detail::LsJoinOutcome> Healer::memoJoin(const BSplineSurface& s, const std::vector<detail::EdgeConstraint>& cons,
                                               const detail::LsJoinOptions& lo) const {
  std::string key = joinKey(s, cons, lo);
  if (const auto it = joinMemo_.find(key); it != joinMemo_.end()) return it->second;
  Result<detail::LsJoinOutcome> out = detail::leastSquaresJoin(s, cons, lo);
  joinMemo_.emplace(std::move(key), out);
  return out;
}

std::string Healer::foldOf(int i, const BSplineSurface& cand) const {
  const Patch& in = in_.patches[static_cast<size_t>(i)];
  auto found = searchMovedPatch(cand);  // one search for the fold points and the self-intersections
  // A heal joins seams up to the crease angle: the normal may turn by that much (and always by up to 90 degrees).
  const std::string why = seam::foldOf(in.surface, cand, std::max(90.0, maxAngle_), found ? &*found : nullptr);
  if (!why.empty()) return fmt::format("patch {} {}", in.name, why);
  if (!found) return "";
  if (inputSelfIntersections_.empty()) inputSelfIntersections_.assign(in_.patches.size(), -1);
  const int after = static_cast<int>(found->selfIntersections.size());
  if (after == 0) return "";
  int& before = inputSelfIntersections_[static_cast<size_t>(i)];
  if (before < 0) {
    auto r = searchMovedPatch(in.surface);
    before = r ? static_cast<int>(r->selfIntersections.size()) : 0;
  }
  if (after > before)
    return fmt::format("patch {} would intersect itself ({} self-intersection(s), {} in the input)", in.name, after,
                       before);
  return "";
}

// Order: breadth-first from the roots of each group of seams to join. Roots stay: patches already joined to a
// neighbour outside the work (anchored), or else the first patch of the group; of two roots with a seam to join
// between them the later one moves.
void Healer::buildOrder() {
  std::vector<std::vector<int>> adj(static_cast<size_t>(np_));
  std::vector<char> anchored(static_cast<size_t>(np_), 0);
  for (size_t k = 0; k < work_.size(); ++k) {
    const Work& w = work_[k];
    if (w.state == SeamState::kToJoin) {
      adj[static_cast<size_t>(w.pair.a.patch)].push_back(static_cast<int>(k));
      adj[static_cast<size_t>(w.pair.b.patch)].push_back(static_cast<int>(k));
    } else if (w.state == SeamState::kKept) {
      anchored[static_cast<size_t>(w.pair.a.patch)] = 1;
      anchored[static_cast<size_t>(w.pair.b.patch)] = 1;
    }
  }
  auto otherOf = [&](int k, int i) {
    const Work& w = work_[static_cast<size_t>(k)];
    return w.pair.a.patch == i ? w.pair.b.patch : w.pair.a.patch;
  };
  initialSettled_.assign(static_cast<size_t>(np_), 1);
  std::vector<char> visited(static_cast<size_t>(np_), 0);
  for (int i = 0; i < np_; ++i)
    if (!adj[static_cast<size_t>(i)].empty()) initialSettled_[static_cast<size_t>(i)] = 0;
  std::vector<char> settled = initialSettled_;
  for (int seed = 0; seed < np_; ++seed) {
    if (adj[static_cast<size_t>(seed)].empty() || visited[static_cast<size_t>(seed)]) continue;
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
    std::vector<char> queued(static_cast<size_t>(np_), 0);
    std::deque<int> queue;
    for (int r : roots) {
      settled[static_cast<size_t>(r)] = 1;
      initialSettled_[static_cast<size_t>(r)] = 1;
      queued[static_cast<size_t>(r)] = 1;
      queue.push_back(r);
    }
    while (!queue.empty()) {
      const int i = queue.front();
      queue.pop_front();
      if (!settled[static_cast<size_t>(i)]) order_.push_back(i);
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
}

// The successive joins. Each step (one patch move) is accepted only if no seam touching the patch gets worse than
// before the step or than in the input. `strict` = false defers the verdict on a seam whose other patch moves later
// (that patch's step must then leave it no worse than in the input); the caller re-checks every region at the end
// and falls back to the strict run when a deferred seam stayed worse.
SuccessiveRun Healer::successive(bool strict) const {
  SuccessiveRun run;
  run.model = in_;
  run.mover.assign(work_.size(), -1);
  run.notes.assign(work_.size(), {});
  std::vector<std::optional<SeamReport>> current(work_.size());
  for (size_t k = 0; k < work_.size(); ++k) current[k] = work_[k].before;
  std::vector<char> settled = initialSettled_;
  std::vector<int> position(static_cast<size_t>(np_), -1);
  for (size_t i = 0; i < order_.size(); ++i) position[static_cast<size_t>(order_[i])] = static_cast<int>(i);
  const double vertexTol = std::max(maxGap_, tol_.distance);
  auto patchesAt = [&](const Vec3& p) {  // corners_ is sorted by x: only the slab |x - p.x| <= vertexTol is scanned
    std::vector<int> out;
    auto it = std::lower_bound(corners_.begin(), corners_.end(), p.x() - vertexTol,
                               [](const CornerAt& c, double x) { return c.p.x() < x; });
    for (; it != corners_.end() && it->p.x() <= p.x() + vertexTol; ++it)
      if ((it->p - p).norm() <= vertexTol && std::find(out.begin(), out.end(), it->patch) == out.end())
        out.push_back(it->patch);
    return out;
  };
  const bool g1 = opt_.continuity == GeometricClass::kG1;

  for (size_t step = 0; step < order_.size(); ++step) {
    const int s = order_[step];
    if (!skipSuccessive_.empty() && skipSuccessive_[static_cast<size_t>(patchRegion_[static_cast<size_t>(s)])]) continue;
    Patch& S = run.model.patches[static_cast<size_t>(s)];
    HealStep hs;
    hs.patch = S.name;
    hs.region = patchRegion_[static_cast<size_t>(s)];
    std::vector<detail::EdgeConstraint> cons;
    std::vector<int> consWork, touching;
    std::vector<Edge> lockedKept, lockedG0, frozen;
    for (size_t k = 0; k < work_.size(); ++k) {
      const Work& w = work_[k];
      const bool sIsA = w.pair.a.patch == s, sIsB = w.pair.b.patch == s;
      if (!sIsA && !sIsB) continue;
      touching.push_back(static_cast<int>(k));
      if (w.state == SeamState::kSkipped) {  // left alone (design crease, wide gap): its side never moves
        if (sIsA) frozen.push_back(w.pair.a.edge);
        if (sIsB) frozen.push_back(w.pair.b.edge);
        continue;
      }
      const EdgeRef me = sIsA ? w.pair.a : w.pair.b, other = sIsA ? w.pair.b : w.pair.a;
      if (other.patch == s) continue;  // a seam of the patch with itself: left alone (but checked)
      if (!settled[static_cast<size_t>(other.patch)]) {
        // Not moved yet (this seam is still as in the input): keep what holds already.
        if (w.state == SeamState::kKept) lockedKept.push_back(me.edge);
        else if (meets(w.before.geometric, GeometricClass::kG0)) lockedG0.push_back(me.edge);
        continue;
      }
      const Patch& X = run.model.patches[static_cast<size_t>(other.patch)];
      auto cur = analyzeSeam(S, me.edge, X, other.edge, so_, rangeOf(w.pair, sIsA));
      if (!cur) {
        run.notes[k].push_back("analysis before the join failed: " + cur.status().message());
        continue;
      }
      Interval oA;
      detail::EdgeConstraint c = seamConstraint(S, me.edge, X, other.edge, *cur, w.pair, maxGap_, 1, &oA);
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
    settled[static_cast<size_t>(s)] = 1;
    if (cons.empty()) continue;

    // The acceptance test: every seam touching the moved patch against its state before the step and the input.
    std::vector<std::pair<int, SeamReport>> checked;
    auto rejection = [&](const BSplineSurface& cand) -> std::string {
      checked.clear();
      Model& m = run.model;
      const BSplineSurface keep = m.patches[static_cast<size_t>(s)].surface;
      m.patches[static_cast<size_t>(s)].surface = cand;
      std::string why = foldOf(s, cand);
      if (!why.empty()) {
        m.patches[static_cast<size_t>(s)].surface = keep;
        return why;
      }
      for (int k : touching) {
        const Work& w = work_[static_cast<size_t>(k)];
        const int other = w.pair.a.patch == s ? w.pair.b.patch : w.pair.a.patch;
        const bool deferred = !strict && other != s && w.state != SeamState::kSkipped &&
                              position[static_cast<size_t>(other)] > static_cast<int>(step);
        if (deferred) continue;
        auto now = analyse(m, w.pair);
        if (!now) {
          why = fmt::format("{}: no longer analysable ({})", seamName(w.pair), now.status().message());
          break;
        }
        if (current[static_cast<size_t>(k)]) {
          const std::string r = worseThan(*now, *current[static_cast<size_t>(k)], tol_);
          if (!r.empty()) {
            why = fmt::format("{}: {} (worse than before the step)", seamName(w.pair), r);
            break;
          }
        }
        const std::string r = worseThan(*now, w.before, tol_);
        if (!r.empty()) {
          why = fmt::format("{}: {} (worse than in the input)", seamName(w.pair), r);
          break;
        }
        if (w.state == SeamState::kSkipped) {
          const std::string moved = leftAloneBroken(m, k, *now, -1);
          if (!moved.empty()) {
            why = moved;
            break;
          }
        }
        checked.emplace_back(k, *now);
      }
      m.patches[static_cast<size_t>(s)].surface = keep;
      return why;
    };

    // Variants, most conservative first: edges towards patches that have not moved yet locked (rows 0-1 when G1
    // holds or G0 holds there, as the request needs), then positions only, then nothing locked; each as it is, then
    // with the degree raised by 1 and 2 (exact) for enough freedom.
    struct Variant {
      std::vector<Edge> locked;
      int rows;
      std::string note;
    };
    // The sides of seams left alone (design creases, wide gaps) are locked in every variant (rows 0-1 where the
    // variant allows; the acceptance test rejects any change of their boundary curve or kink angle).
    std::vector<Variant> variants;
    std::vector<Edge> lockAll = lockedKept;
    lockAll.insert(lockAll.end(), lockedG0.begin(), lockedG0.end());
    const bool anyLocked = !lockAll.empty();
    lockAll.insert(lockAll.end(), frozen.begin(), frozen.end());
    if (g1 || !frozen.empty()) {
      variants.push_back({lockAll, 2, ""});
      if (anyLocked || !g1)
        variants.push_back({lockAll, 1, g1 ? "only the positions of edges towards unmoved neighbours kept" : ""});
    } else {
      variants.push_back({lockAll, 1, ""});
    }
    if (anyLocked) variants.push_back({frozen, frozen.empty() ? 1 : 2, "edges towards unmoved neighbours unlocked"});
    if (anyLocked && !frozen.empty()) variants.push_back({frozen, 1, "edges towards unmoved neighbours unlocked"});

    struct Tried {
      BSplineSurface surface;
      double residual;
      std::vector<std::string> notes;
    };
    std::optional<Tried> chosen;
    std::vector<Tried> inexact;
    std::string lastWhy, error, unchangedWhy;
    for (const Variant& v : variants) {
      for (int elevate = 0; elevate < 3 && !chosen; ++elevate) {
        detail::LsJoinOptions lo;
        lo.continuity = opt_.continuity;
        lo.scale = diag_;
        lo.lockedEdges = v.locked;
        lo.lockedRows = v.rows;
        lo.elevate = elevate;
        auto t = memoJoin(S.surface, cons, lo);
        if (!t) {
          if (error.empty()) error = t.status().message();
          break;
        }
        if (t->unchanged) {
          // The solver left the patch as it was (the constraints cannot be met without a fold): no move, whatever
          // the residual; a higher degree may still help.
          if (unchangedWhy.empty()) {
            unchangedWhy = "the join leaves the patch as it was";
            for (const std::string& n : t->notes) unchangedWhy += ": " + n;
          }
          continue;
        }
        Tried tr{t->surface, t->residual, {}};
        if (!v.note.empty()) tr.notes.push_back(v.note);
        if (elevate > 0) tr.notes.push_back(fmt::format("degree raised by {} (exact) for enough freedom", elevate));
        if (!t->feasible) {
          tr.notes.push_back(fmt::format("constraints not met exactly (residual {:.3g})", t->residual));
          inexact.push_back(std::move(tr));
          continue;
        }
        const std::string why = rejection(tr.surface);
        if (why.empty()) {
          chosen = std::move(tr);
        } else {
          lastWhy = why;
          break;  // a larger degree would move the same way: try the next variant
        }
      }
      if (chosen) break;
    }
    if (!chosen) {
      // Inexact joins that still make nothing worse are progress too (smallest residual first, two at most).
      std::sort(inexact.begin(), inexact.end(), [](const Tried& a, const Tried& b) { return a.residual < b.residual; });
      for (size_t i = 0; i < std::min<size_t>(2, inexact.size()) && !chosen; ++i) {
        const std::string why = rejection(inexact[i].surface);
        if (why.empty()) chosen = std::move(inexact[i]);
        else if (lastWhy.empty()) lastWhy = why;
      }
    }
    if (chosen && chosen->surface.degreeU() == S.surface.degreeU() &&
        chosen->surface.degreeV() == S.surface.degreeV() &&
        chosen->surface.knotsU().values() == S.surface.knotsU().values() &&
        chosen->surface.knotsV().values() == S.surface.knotsV().values() &&
        chosen->surface.points() == S.surface.points() && chosen->surface.weights() == S.surface.weights()) {
      chosen.reset();  // bit for bit the patch it was: not a move
      if (lastWhy.empty()) lastWhy = "the join leaves the patch as it was";
    }
    if (chosen) {
      S = detail::replacedSurface(S, chosen->surface);
      for (auto& [k, r] : checked) current[static_cast<size_t>(k)] = r;
      // Seams deferred above now differ from their last analysis.
      for (int k : touching) {
        const bool fresh = std::any_of(checked.begin(), checked.end(), [&](const auto& c) { return c.first == k; });
        if (!fresh) current[static_cast<size_t>(k)].reset();
      }
      hs.accepted = true;
      hs.notes = chosen->notes;
      for (int k : consWork) {
        if (work_[static_cast<size_t>(k)].state == SeamState::kToJoin) run.mover[static_cast<size_t>(k)] = s;
        for (const std::string& n : chosen->notes) run.notes[static_cast<size_t>(k)].push_back(S.name + ": " + n);
      }
    } else {
      hs.accepted = false;
      hs.reason = !lastWhy.empty()        ? lastWhy
                  : !unchangedWhy.empty() ? unchangedWhy
                  : !error.empty()        ? "join failed: " + error
                                          : "no join found";
      for (int k : consWork)
        run.notes[static_cast<size_t>(k)].push_back(fmt::format("{} not moved: {}", S.name, hs.reason));
    }
    run.steps.push_back(std::move(hs));
  }
  return run;
}

// Every seam of the region analysed in `m`, compared with the input.
Candidate Healer::judge(const Model& m, std::string method, int region,
                        const std::vector<const BSplineSurface*>* inputForms) const {
  Candidate c;
  c.method = std::move(method);
  c.model = &m;
  c.acceptable = true;
  for (int k : regionSeams_[static_cast<size_t>(region)]) {
    const Work& w = work_[static_cast<size_t>(k)];
    auto r = &m == &in_ ? Result<SeamReport>(w.before) : analyse(m, w.pair);
    if (!r) {
      c.after.emplace_back(std::nullopt);
      if (c.acceptable) c.note = fmt::format("{}: not analysable ({})", seamName(w.pair), r.status().message());
      c.acceptable = false;
      continue;
    }
    const std::string why = worseThan(*r, w.before, tol_);
    if (!why.empty() && c.acceptable) {
      c.acceptable = false;
      c.note = fmt::format("{}: {} (worse than in the input)", seamName(w.pair), why);
    }
    if (w.state != SeamState::kSkipped && meets(r->geometric, opt_.continuity)) ++c.achieved;
    c.after.emplace_back(std::move(*r));
  }
  for (int i : regionPatches_[static_cast<size_t>(region)]) {
    const Patch& b = in_.patches[static_cast<size_t>(i)];
    const Patch& a = m.patches[static_cast<size_t>(i)];
    if (a.surface.points() == b.surface.points() && a.surface.knotsU().values() == b.surface.knotsU().values() &&
        a.surface.knotsV().values() == b.surface.knotsV().values())
      continue;
    if (c.acceptable) {
      const std::string fold = foldOf(i, a.surface);
      if (!fold.empty()) {
        c.acceptable = false;
        c.note = fold;
      }
    }
    HealPatch d = displacementOf(b, a, kRoundoff * diag_, inputForms ? (*inputForms)[static_cast<size_t>(i)] : nullptr);
    c.changed = true;
    c.moved += d.movedPoints;
    c.displacement = std::max(c.displacement, d.maxSurfaceDisplacement);
    c.displacementRel = std::max(c.displacementRel, d.maxSurfaceDisplacementRel);
    c.displaced.emplace_back(i, std::move(d));
  }
  // Seams left alone (design creases, wide gaps) with a side in the region: that side must not have moved.
  if (c.changed)
    for (int k : regionFrozen_[static_cast<size_t>(region)]) {
      const Work& w = work_[static_cast<size_t>(k)];
      auto r = analyse(m, w.pair);
      std::string why = r ? leftAloneBroken(m, k, *r, region) : "not analysable: " + r.status().message();
      if (r && why.empty()) why = worseThan(*r, w.before, tol_);
      if (!why.empty() && c.acceptable) {
        c.acceptable = false;
        c.note = fmt::format("{} (left alone): {}", seamName(w.pair), why);
      }
    }
  return c;
}

// Why a seam that is left alone (skipped: design crease or wide gap) is no longer as in the input ("" when it is):
// the sides in `region` (every side when region < 0) keep their boundary curve, the kink angle and the gap stay.
std::string Healer::leftAloneBroken(const Model& m, int k, const SeamReport& now, int region) const {
  const Work& w = work_[static_cast<size_t>(k)];
  const std::string what = w.crease ? "design crease" : "seam above the gap limit";
  if (std::abs(now.g1MaxDeg - w.before.g1MaxDeg) > tol_.strictAngleDeg())
    return fmt::format("{} {}: kink angle {:.6g} -> {:.6g} deg", what, seamName(w.pair), w.before.g1MaxDeg,
                       now.g1MaxDeg);
  if (std::abs(now.g0Max - w.before.g0Max) > tol_.distance)
    return fmt::format("{} {}: gap {:.3g} -> {:.3g}", what, seamName(w.pair), w.before.g0Max, now.g0Max);
  for (const EdgeRef& e : {w.pair.a, w.pair.b}) {
    if (region >= 0 && patchRegion_[static_cast<size_t>(e.patch)] != region) continue;
    const double d = edgeMovement(in_.patches[static_cast<size_t>(e.patch)].surface,
                                  m.patches[static_cast<size_t>(e.patch)].surface, e.edge);
    if (d > tol_.distance)
      return fmt::format("{} {}: edge {}:{} moved by {:.3g}", what, seamName(w.pair),
                         in_.patches[static_cast<size_t>(e.patch)].name, edgeName(e.edge), d);
  }
  return "";
}

// The region's free edges (and the sides of seams left alone, gap above maxGap) are where they were in the input.
bool Healer::freeEdgesKept(const Model& m, int region, std::string* why) const {
  std::vector<EdgeRef> edges;
  for (const FreeEdge& f : pairing_.freeEdges)
    if (patchRegion_[static_cast<size_t>(f.edge.patch)] == region) edges.push_back(f.edge);
  for (int k : regionSeams_[static_cast<size_t>(region)]) {
    const Work& w = work_[static_cast<size_t>(k)];
    if (w.state != SeamState::kSkipped) continue;
    edges.push_back(w.pair.a);
    edges.push_back(w.pair.b);
  }
  for (const EdgeRef& e : edges) {
    const double d = edgeMovement(in_.patches[static_cast<size_t>(e.patch)].surface,
                                  m.patches[static_cast<size_t>(e.patch)].surface, e.edge);
    if (d > tol_.distance) {
      *why = fmt::format("free edge {}:{} moved by {:.3g}", in_.patches[static_cast<size_t>(e.patch)].name,
                         edgeName(e.edge), d);
      return false;
    }
  }
  return true;
}

Status Healer::prepare() {
  const Model& model = in_;
  if (model.patches.empty()) return invalidInput("the model has no patches");
  if (opt_.continuity == GeometricClass::kNone) return invalidInput("heal joins G0, G1 or G2");
  if (opt_.method == HealMethod::kLocal && opt_.continuity == GeometricClass::kG0)
    return invalidInput("the local scheme makes G1 or G2 joins of a G0 network: use --method successive or auto for G0");
  if (opt_.method == HealMethod::kSuccessive && opt_.continuity == GeometricClass::kG2)
    return invalidInput("G2 across a network is made by the network solve, not by successive joins: use --method "
                        "auto or local (or `seam join --continuity G2` seam by seam)");
  for (const Patch& p : model.patches)
    if (p.surface.dim() != 3) return invalidInput(fmt::format("patch \"{}\" is not 3-D", p.name));
  const double maxAngle = opt_.maxAngleDeg ? *opt_.maxAngleDeg : kDefaultMaxHealAngleDeg;
  if (!(maxAngle > 0.0 && maxAngle <= 180.0))
    return invalidInput(fmt::format("the crease angle must be in (0, 180] degrees (got {})", maxAngle));
  if (!(opt_.g2Fairness >= 0.0 && std::isfinite(opt_.g2Fairness)))
    return invalidInput(fmt::format("the G2 fairness weight must be finite and >= 0 (got {})", opt_.g2Fairness));
  diag_ = model.boundingBox().diagonal();
  if (!(diag_ > 0.0)) diag_ = 1.0;
  tol_ = opt_.tolerances ? *opt_.tolerances : Tolerances::forModelSize(diag_);
  maxGap_ = opt_.maxGap ? *opt_.maxGap : kDefaultMaxGapRel * diag_;
  so_ = opt_.seam;
  so_.tol = tol_;
  // Below G2, heal decides on G0/G1 only: the G2 subdivision of every seam (most of the cost on biquintic seams) is
  // skipped.
  so_.certifyG2 = opt_.continuity == GeometricClass::kG2;

  auto pairing = pairEdgesWithin(model, tol_, maxGap_, diag_);
  if (!pairing) return pairing.status();
  pairing_ = std::move(*pairing);
  maxAngle_ = maxAngle;
  np_ = static_cast<int>(model.patches.size());

  for (const EdgePair& p : pairing_.pairs) {
    Work w;
    w.pair = p;
    auto r = analyse(model, p);
    if (!r) {
      prepareNotes_.push_back(fmt::format("seam {} could not be analysed: {}", seamName(p), r.status().message()));
      continue;
    }
    w.before = *r;
    if (w.before.g0Max > maxGap_) {
      w.state = SeamState::kSkipped;
    } else if (w.before.g1MaxDeg > maxAngle) {  // a design crease: left alone (180: heal every seam)
      w.state = SeamState::kSkipped;
      w.crease = true;
    } else if (meets(w.before.geometric, opt_.continuity)) w.state = SeamState::kKept;
    else w.state = SeamState::kToJoin;
    work_.push_back(std::move(w));
  }
  return Status::ok();
}

Result<HealResult> Healer::finish() {
  const Model& model = in_;
  const double maxAngle = maxAngle_;
  HealResult res;
  HealReport& rep = res.report;
  rep.requested = opt_.continuity;
  rep.method = opt_.method;
  rep.maxGap = maxGap_;
  rep.maxAngleDeg = maxAngle;
  rep.notes = prepareNotes_;

  // Regions: connected components of the graph of seams within maxGap (seams of one patch with itself included).
  patchRegion_.assign(static_cast<size_t>(np_), -1);
  {
    std::vector<int> parent(static_cast<size_t>(np_));
    for (int i = 0; i < np_; ++i) parent[static_cast<size_t>(i)] = i;
    auto find = [&](int i) {
      while (parent[static_cast<size_t>(i)] != i) i = parent[static_cast<size_t>(i)] = parent[static_cast<size_t>(parent[static_cast<size_t>(i)])];
      return i;
    };
    std::vector<char> inSeam(static_cast<size_t>(np_), 0);
    for (const Work& w : work_) {
      inSeam[static_cast<size_t>(w.pair.a.patch)] = inSeam[static_cast<size_t>(w.pair.b.patch)] = 1;
      if (w.state == SeamState::kSkipped) continue;
      parent[static_cast<size_t>(find(w.pair.a.patch))] = find(w.pair.b.patch);
    }
    std::map<int, int> index;
    for (int i = 0; i < np_; ++i) {
      if (!inSeam[static_cast<size_t>(i)]) continue;
      const int root = find(i);
      auto [it, fresh] = index.emplace(root, static_cast<int>(regionPatches_.size()));
      if (fresh) regionPatches_.emplace_back();
      regionPatches_[static_cast<size_t>(it->second)].push_back(i);
      patchRegion_[static_cast<size_t>(i)] = it->second;
    }
    regionSeams_.assign(regionPatches_.size(), {});
    for (size_t k = 0; k < work_.size(); ++k) {
      Work& w = work_[k];
      w.region = patchRegion_[static_cast<size_t>(w.pair.a.patch)];
      regionSeams_[static_cast<size_t>(w.region)].push_back(static_cast<int>(k));
    }
    regionFrozen_.assign(regionPatches_.size(), {});
    for (size_t k = 0; k < work_.size(); ++k) {
      const Work& w = work_[k];
      if (w.state != SeamState::kSkipped) continue;
      const int ra = patchRegion_[static_cast<size_t>(w.pair.a.patch)];
      const int rb = patchRegion_[static_cast<size_t>(w.pair.b.patch)];
      regionFrozen_[static_cast<size_t>(ra)].push_back(static_cast<int>(k));
      if (rb != ra) regionFrozen_[static_cast<size_t>(rb)].push_back(static_cast<int>(k));
    }
  }
  const int nr = static_cast<int>(regionPatches_.size());

  buildOrder();

  auto regionAchieved = [&](int g, const Candidate& c) {
    int need = 0;
    for (int k : regionSeams_[static_cast<size_t>(g)])
      if (work_[static_cast<size_t>(k)].state != SeamState::kSkipped) ++need;
    return c.achieved == need;
  };
  auto better = [](const Candidate& a, const Candidate& b) {  // a strictly preferred to b
    if (a.acceptable != b.acceptable) return a.acceptable;
    if (a.achieved != b.achieved) return a.achieved > b.achieved;
    // A candidate that changed nothing is the input ("none").
    const bool aNone = a.method == "none" || !a.changed, bNone = b.method == "none" || !b.changed;
    if (aNone != bNone) return !aNone;  // partial improvements that make nothing worse are kept
    if (a.displacementRel != b.displacementRel) return a.displacementRel < b.displacementRel;
    if (a.moved != b.moved) return a.moved < b.moved;
    return a.displacement < b.displacement;
  };

  // The successive runs: relaxed first (a seam towards a patch that moves later is judged at that patch's step),
  // strict for the regions where the relaxed run left a seam worse than in the input or fell short.
  std::vector<Candidate> best(static_cast<size_t>(nr));
  for (int g = 0; g < nr; ++g) best[static_cast<size_t>(g)] = judge(model, "none", g);
  // The local scheme per region (G1; method local or auto), before the successive runs: auto leaves the successive
  // joins out of a region where the local scheme reached G1 and some vertex has a valence other than 4 (successive
  // joins cannot close such vertices; on large networks they would only cost time).
  // G2: the network solve (g2_network.h) in the place of the local scheme, and no successive joins.
  const bool g2 = opt_.continuity == GeometricClass::kG2;
  const bool tryLocal = (opt_.continuity == GeometricClass::kG1 || g2) &&
                        (opt_.method == HealMethod::kLocal || opt_.method == HealMethod::kAuto);
  std::vector<std::optional<Candidate>> localCand(static_cast<size_t>(nr));
  std::vector<std::string> localNote(static_cast<size_t>(nr));
  std::vector<std::vector<std::string>> regionG2Notes(static_cast<size_t>(nr));
  skipSuccessive_.assign(static_cast<size_t>(nr), 0);
  for (int g = 0; g < nr && tryLocal; ++g) {
    if (regionAchieved(g, best[static_cast<size_t>(g)])) continue;
    std::vector<std::pair<int, Edge>> keepEdges;
    // Seams left alone (design creases, gaps above maxGap) stay free edges: both sides keep their boundary curves.
    for (int k : regionFrozen_[static_cast<size_t>(g)]) {
      const Work& w = work_[static_cast<size_t>(k)];
      keepEdges.emplace_back(w.pair.a.patch, w.pair.a.edge);
      keepEdges.emplace_back(w.pair.b.patch, w.pair.b.edge);
    }
    Result<LocalSchemeResult> l = Status(ErrorCode::kUnsupported, "");
    std::vector<std::pair<int, BSplineSurface>> inputForms;  // the scheme's exact forms of its input patches
    bool networkG1 = false;                                   // the G1 network solve ran in the local scheme's place
    // The network solve on the region (G2, or G1 where the local scheme does not apply), its result in the local
    // scheme's form.
    auto network = [&](GeometricClass continuity) -> Result<LocalSchemeResult> {
      G2NetworkOptions go;
      go.patches = regionPatches_[static_cast<size_t>(g)];
      go.maxGap = maxGap_;
      go.tolerances = tol_;
      go.keepEdges = keepEdges;
      go.fairness = opt_.g2Fairness;
      go.continuity = continuity;
      auto n = g2NetworkScheme(model, go);
      if (!n) return n.status();
      LocalSchemeResult lr;
      lr.model = std::move(n->model);
      lr.report.valences = std::move(n->report.valences);
      lr.report.notes = std::move(n->report.notes);
      return lr;
    };
    if (g2) {
      l = network(GeometricClass::kG2);
      if (!l) {
        // Refused input (kUnsupported, kInvalidInput) is "not applicable"; a solve that ran and found nothing (no
        // convergence, a fold) says so (issue 38 goal 6).
        localNote[static_cast<size_t>(g)] =
            (l.status().code() == ErrorCode::kNoSolution ? "G2 network solve found no solution: "
                                                         : "G2 network solve not applicable: ") +
            l.status().message();
        continue;
      }
    } else {
      LocalSchemeOptions lo;
      lo.patches = regionPatches_[static_cast<size_t>(g)];
      lo.maxGap = maxGap_;
      lo.tolerances = tol_;
      lo.keepEdges = keepEdges;
      lo.pairing = &pairing_;  // the same tolerances, gap limit and diagonal: not paired a second time
      l = detail::localG1Scheme(model, lo, &inputForms);
      // Issue 36 goal 1: where the local scheme has no solution or does not apply (a boundary vertex whose straight
      // free edges have unequal tangent lengths: no symmetric fan; interior knots off the middle), the network solve
      // with the G1 identities only (free blending functions per span) takes the region, up to its size limit.
      if (!l && l.status().code() != ErrorCode::kInvalidInput) {
        const std::string localWhy = l.status().message();
        if (static_cast<int>(lo.patches.size()) > kMaxG1NetworkPatches) {
          l = Status(l.status().code(),
                     fmt::format("{}; the G1 network solve is not tried on a region of more than {} patches ({})",
                                 localWhy, kMaxG1NetworkPatches, lo.patches.size()));
        } else if (auto n = network(GeometricClass::kG1)) {
          n->report.notes.insert(n->report.notes.begin(), "the local scheme does not apply (" + localWhy +
                                                              "); the G1 network solve ran in its place");
          l = std::move(n);
          networkG1 = true;
        } else {
          l = Status(l.status().code(), localWhy + "; G1 network solve: " + n.status().message());
        }
      }
    }
    if (!l) {
      localNote[static_cast<size_t>(g)] =
          (l.status().code() == ErrorCode::kNoSolution ? "local scheme found no solution: "
                                                       : "local scheme not applicable: ") +
          l.status().message();
      continue;
    }
    const std::vector<int> valences = l->report.valences;
    auto keep = std::make_shared<Model>(std::move(l->model));
    std::vector<const BSplineSurface*> formOf;
    if (!inputForms.empty()) {
      formOf.assign(static_cast<size_t>(np_), nullptr);
      for (const auto& [i, f] : inputForms) formOf[static_cast<size_t>(i)] = &f;
    }
    Candidate c = judge(*keep, "local", g, formOf.empty() ? nullptr : &formOf);
    if (networkG1) c.solver = "G1 network solve";
    std::string why;
    // G1: all or nothing. G2: a partial result that makes nothing worse is kept (seams ending where a straight free
    // boundary has a curvature jump cannot be G2 with the free edges kept; the solve's notes say where).
    if (c.acceptable && !regionAchieved(g, c) && !g2) {
      c.acceptable = false;
      c.note = fmt::format("{} of {} seams reach G1", c.achieved, regionSeams_[static_cast<size_t>(g)].size());
    }
    if (g2 || networkG1)
      for (const std::string& n : l->report.notes) regionG2Notes[static_cast<size_t>(g)].push_back(n);
    if (c.acceptable) {
      for (const auto& a : c.after)
        if (a && !a->certified) {
          c.acceptable = false;
          c.note = fmt::format("{} / {} not certified after", a->a, a->b);
          break;
        }
    }
    if (c.acceptable && !freeEdgesKept(*keep, g, &why)) {
      c.acceptable = false;
      c.note = why;
    }
    localModels_.push_back(keep);
    const bool irregular = std::any_of(valences.begin(), valences.end(), [](int n) { return n != 4; });
    if (opt_.method == HealMethod::kAuto && c.acceptable && irregular) skipSuccessive_[static_cast<size_t>(g)] = 1;
    if (g2) skipSuccessive_[static_cast<size_t>(g)] = 1;
    localCand[static_cast<size_t>(g)] = std::move(c);
  }
  bool anySuccessive = false;
  for (int g = 0; g < nr; ++g) anySuccessive = anySuccessive || !skipSuccessive_[static_cast<size_t>(g)];
  const bool trySuccessive = opt_.method != HealMethod::kLocal && !order_.empty() && anySuccessive && !g2;
  std::optional<SuccessiveRun> relaxed, strict;
  if (trySuccessive) {
    // Vertices (the successive runs only need them): the corner points of every patch, clustered within the gap
    // limit; a seam end at a vertex where three or more patches have a corner is "interior" (a later patch may have
    // to close it).
    for (int i = 0; i < np_; ++i) {
      const BSplineSurface& s = model.patches[static_cast<size_t>(i)].surface;
      const Interval du = s.domainU(), dv = s.domainV();
      for (double u : {du.lo, du.hi})
        for (double v : {dv.lo, dv.hi}) corners_.push_back({s.evaluate(u, v).head<3>(), i});
    }
    std::sort(corners_.begin(), corners_.end(), [](const CornerAt& a, const CornerAt& b) { return a.p.x() < b.p.x(); });
    relaxed = successive(false);
  }
  std::vector<std::vector<std::string>> regionNotes(static_cast<size_t>(nr));
  std::vector<const SuccessiveRun*> stepsFrom(static_cast<size_t>(nr), nullptr);
  std::vector<std::string> comparison(static_cast<size_t>(nr));        // auto: successive against local
  std::vector<double> succRel(static_cast<size_t>(nr), -1.0), localRel(static_cast<size_t>(nr), -1.0);
  bool needStrict = false;
  std::vector<Candidate> fromRelaxed(static_cast<size_t>(nr));
  if (relaxed) {
    for (int g = 0; g < nr; ++g) {
      if (regionAchieved(g, best[static_cast<size_t>(g)]) || skipSuccessive_[static_cast<size_t>(g)]) continue;
      Candidate c = judge(relaxed->model, "successive", g);
      if (!c.acceptable || !regionAchieved(g, c)) needStrict = true;
      fromRelaxed[static_cast<size_t>(g)] = std::move(c);
    }
    if (needStrict) strict = successive(true);
  }
  for (int g = 0; g < nr; ++g) {
    Candidate& b = best[static_cast<size_t>(g)];
    if (regionAchieved(g, b)) {
      b.note = "";
      continue;
    }
    auto consider = [&](Candidate c, const SuccessiveRun* from) {
      if (!c.acceptable && !c.note.empty()) regionNotes[static_cast<size_t>(g)].push_back(
          (c.method == "local" ? c.solver + " rejected: " : c.method + " joins rejected: ") + c.note);
      if (from && !stepsFrom[static_cast<size_t>(g)]) stepsFrom[static_cast<size_t>(g)] = from;
      if (better(c, b)) {
        b = std::move(c);
        if (from) stepsFrom[static_cast<size_t>(g)] = from;
      }
    };
    if (relaxed && !skipSuccessive_[static_cast<size_t>(g)]) {
      Candidate c = std::move(fromRelaxed[static_cast<size_t>(g)]);
      const bool enough = c.acceptable && regionAchieved(g, c);
      if (!enough && strict) {
        // Keep the relaxed run's note only when the strict run is not better.
        Candidate s = judge(strict->model, "successive", g);
        if (c.acceptable) consider(std::move(c), &*relaxed);
        else if (!c.note.empty()) regionNotes[static_cast<size_t>(g)].push_back("successive joins rejected: " + c.note);
        consider(std::move(s), &*strict);
      } else {
        consider(std::move(c), &*relaxed);
      }
    }
    // auto: the local scheme too (G1), also where the successive joins reach the request: the smaller displacement
    // wins between two that achieve as much.
    const bool compare = opt_.method == HealMethod::kAuto && b.method == "successive" && b.changed && b.acceptable;
    const double successiveRel = compare ? b.displacementRel : -1.0;
    const int successiveAchieved = b.achieved;
    if (tryLocal && localCand[static_cast<size_t>(g)]) {
      Candidate c = std::move(*localCand[static_cast<size_t>(g)]);  // read once: no copy of every seam's report
      if (c.acceptable) localRel[static_cast<size_t>(g)] = c.displacementRel;
      if (compare && c.acceptable) {
        const bool localWins = better(c, b);
        std::string how = fmt::format("successive moved {:.3g} % of a patch, local {:.3g} %",
                                      100.0 * successiveRel, 100.0 * c.displacementRel);
        if (c.achieved != successiveAchieved)
          how = fmt::format("successive reaches {} seams, local {}; ", successiveAchieved, c.achieved) + how;
        comparison[static_cast<size_t>(g)] = how + (localWins ? ": local kept" : ": successive kept");
      }
      consider(std::move(c), nullptr);
    } else if (tryLocal && !localNote[static_cast<size_t>(g)].empty()) {
      regionNotes[static_cast<size_t>(g)].push_back(localNote[static_cast<size_t>(g)]);
    }
    for (const std::string& n : regionG2Notes[static_cast<size_t>(g)]) regionNotes[static_cast<size_t>(g)].push_back(n);
    if (skipSuccessive_[static_cast<size_t>(g)] && !g2)
      regionNotes[static_cast<size_t>(g)].push_back(
          "successive joins not tried: the local scheme reached G1 and the region has vertices where other than 4 "
          "patches meet, which successive joins cannot close");
    if (compare) succRel[static_cast<size_t>(g)] = successiveRel;
  }

  // A candidate that changed nothing is the input: the region's method is "none".
  for (int g = 0; g < nr; ++g) {
    Candidate& c = best[static_cast<size_t>(g)];
    if (c.method != "none" && !c.changed) {
      regionNotes[static_cast<size_t>(g)].push_back(c.method + " joins left every patch as it was");
      c.method = "none";
      c.model = &model;
    }
  }

  // The output: every region from the model of its chosen candidate.
  res.model = model;
  res.model.brep.reset();  // the patches change: the trims would not follow (Model::brep)
  for (int g = 0; g < nr; ++g) {
    const Candidate& c = best[static_cast<size_t>(g)];
    if (c.method == "none") continue;
    for (int i : regionPatches_[static_cast<size_t>(g)])
      res.model.patches[static_cast<size_t>(i)] = c.model->patches[static_cast<size_t>(i)];
  }

  // The report.
  for (int g = 0; g < nr; ++g) {
    const Candidate& c = best[static_cast<size_t>(g)];
    HealRegion hr;
    for (int i : regionPatches_[static_cast<size_t>(g)]) hr.patches.push_back(model.patches[static_cast<size_t>(i)].name);
    for (int k : regionSeams_[static_cast<size_t>(g)])
      if (work_[static_cast<size_t>(k)].state != SeamState::kSkipped) ++hr.seams;
    hr.seamsAchieved = c.achieved;
    hr.method = c.method;
    hr.achieved = regionAchieved(g, c);
    hr.successiveDisplacementRel = succRel[static_cast<size_t>(g)];
    hr.localDisplacementRel = localRel[static_cast<size_t>(g)];
    std::vector<std::string> notes = regionNotes[static_cast<size_t>(g)];
    if (!comparison[static_cast<size_t>(g)].empty()) notes.insert(notes.begin(), comparison[static_cast<size_t>(g)]);
    if (!hr.achieved)
      notes.insert(notes.begin(), fmt::format("{} of {} seams reach {}; the rest is left as good as it was", c.achieved,
                                              hr.seams, toString(opt_.continuity)));
    for (const std::string& n : notes) hr.note += (hr.note.empty() ? "" : "; ") + n;
    rep.regions.push_back(std::move(hr));
    // The successive steps behind the region's result (or the reasons it is left as it was); kept only when the
    // region's result is that run.
    if (const SuccessiveRun* from = stepsFrom[static_cast<size_t>(g)])
      for (const HealStep& st : from->steps)
        if (st.region == g) {
          rep.steps.push_back(st);
          rep.steps.back().kept = st.accepted && c.method == "successive" && c.model == &from->model;
        }
  }
  for (const HealStep& st : rep.steps) {
    if (!st.accepted) ++rep.stepsReverted;
    if (st.kept) rep.order.push_back(st.patch);
  }

  rep.achieved = true;
  std::vector<size_t> slot(static_cast<size_t>(nr), 0);
  std::vector<HealSeam> seams(work_.size());
  for (int g = 0; g < nr; ++g) {
    const Candidate& c = best[static_cast<size_t>(g)];
    const SuccessiveRun* from =
        c.method == "successive" && stepsFrom[static_cast<size_t>(g)] &&
                c.model == &stepsFrom[static_cast<size_t>(g)]->model
            ? stepsFrom[static_cast<size_t>(g)]
            : nullptr;
    const auto& ks = regionSeams_[static_cast<size_t>(g)];
    for (size_t q = 0; q < ks.size(); ++q) {
      const int k = ks[q];
      const Work& w = work_[static_cast<size_t>(k)];
      HealSeam& hs = seams[static_cast<size_t>(k)];
      hs.a = model.patches[static_cast<size_t>(w.pair.a.patch)].name;
      hs.b = model.patches[static_cast<size_t>(w.pair.b.patch)].name;
      hs.aEdge = w.pair.a.edge;
      hs.bEdge = w.pair.b.edge;
      hs.region = g;
      hs.before = w.before;
      hs.edgeMoved = seamEdgeMovement(model, res.model, w.pair);
      if (from) {
        hs.notes = from->notes[static_cast<size_t>(k)];
        if (from->mover[static_cast<size_t>(k)] >= 0)
          hs.moved = model.patches[static_cast<size_t>(from->mover[static_cast<size_t>(k)])].name;
      }
      hs.action = w.state == SeamState::kSkipped ? (w.crease ? "crease kept" : "skipped")
                                                 : (w.state == SeamState::kKept ? "kept" : "joined");
      if (w.crease) {
        ++rep.creasesKept;
        hs.notes.push_back(fmt::format("crease, left as designed: angle {:.4g} deg, above the crease angle {:.4g} deg",
                                       w.before.g1MaxDeg, maxAngle));
      }
      if (c.method == "local" && w.state == SeamState::kToJoin) hs.notes.push_back("local G1 scheme");
      std::optional<SeamReport> r = c.after[q];
      // A seam between two regions: both sides as they are in the output.
      if (patchRegion_[static_cast<size_t>(w.pair.b.patch)] != g) {
        auto fin = analyse(res.model, w.pair);
        r = fin ? std::optional<SeamReport>(*fin) : std::nullopt;
      }
      if (r) {
        hs.after = *r;
        hs.achieved = meets(r->geometric, opt_.continuity);
        hs.worse = !worseThan(*r, w.before, tol_).empty();
        if (w.state != SeamState::kSkipped) {
          rep.worst = static_cast<GeometricClass>(std::min(static_cast<int>(rep.worst), static_cast<int>(r->geometric)));
          rep.worstG0 = std::max(rep.worstG0, r->g0Max);
          rep.worstG1Deg = std::max(rep.worstG1Deg, r->g1MaxDeg);
        }
      } else {
        hs.notes.push_back("analysis after healing failed");
        hs.worse = true;
      }
      if (w.state != SeamState::kSkipped) {
        ++rep.seamsToReach;
        if (hs.achieved) ++rep.seamsAchieved;
        else {
          rep.achieved = false;
          if (w.state == SeamState::kToJoin) hs.action = "failed";
        }
      }
      if (hs.worse) ++rep.seamsWorse;
    }
  }
  for (HealSeam& s : seams) rep.seams.push_back(std::move(s));

  // Displacements: a patch of the output is its region's chosen candidate's patch, whose displacement judge()
  // measured already (the same two surfaces); computed here only where no candidate has it.
  std::vector<HealPatch*> measured(static_cast<size_t>(np_), nullptr);
  for (int g = 0; g < nr; ++g) {
    Candidate& c = best[static_cast<size_t>(g)];
    if (c.method == "none") continue;
    for (auto& [i, hp] : c.displaced)
      if (patchRegion_[static_cast<size_t>(i)] == g) measured[static_cast<size_t>(i)] = &hp;
  }
  for (int i = 0; i < np_; ++i) {
    const Patch& b = model.patches[static_cast<size_t>(i)];
    const Patch& a = res.model.patches[static_cast<size_t>(i)];
    if (a.surface.points() == b.surface.points() && a.surface.knotsU().values() == b.surface.knotsU().values() &&
        a.surface.knotsV().values() == b.surface.knotsV().values())
      continue;
    HealPatch hp = measured[static_cast<size_t>(i)] ? std::move(*measured[static_cast<size_t>(i)])
                                                    : displacementOf(b, a, kRoundoff * diag_);
    hp.region = patchRegion_[static_cast<size_t>(i)];
    rep.patchesChanged.push_back(a.name);
    rep.patches.push_back(std::move(hp));
  }
  sumPatchDisplacements(rep);
  if (rep.stepsReverted > 0)
    rep.notes.push_back(fmt::format("{} join step(s) reverted: each would have made a seam worse or could not move "
                                    "the patch without a fold (the reason is given per step)",
                                    rep.stepsReverted));
  return res;
}

Result<BSplineSurface> Healer::creaseGapMove(const Model& m, const EdgePair& pair, bool moverIsA,
                                             bool lockOthers) const {
  const EdgeRef me = moverIsA ? pair.a : pair.b, other = moverIsA ? pair.b : pair.a;
  const Patch& S = m.patches[static_cast<size_t>(me.patch)];
  const Patch& X = m.patches[static_cast<size_t>(other.patch)];
  auto cur = analyzeSeam(S, me.edge, X, other.edge, so_, rangeOf(pair, moverIsA));
  if (!cur) return cur.status();
  const detail::EdgeConstraint c = seamConstraint(S, me.edge, X, other.edge, *cur, pair, maxGap_, 0);
  detail::LsJoinOptions lo;
  lo.continuity = GeometricClass::kG0;
  lo.scale = diag_;
  lo.lockedRows = 1;
  if (lockOthers)
    for (Edge e : {Edge::U0, Edge::U1, Edge::V0, Edge::V1})
      if (e != me.edge) lo.lockedEdges.push_back(e);
  auto out = detail::leastSquaresJoin(S.surface, {c}, lo);
  if (!out) return out.status();
  if (out->unchanged) return Status(ErrorCode::kNoSolution, "the G0 join found no solution");
  // The row next to the edge moves with the boundary row: S_n along the edge stays (see CreaseGapPass).
  const BSplineSurface old = detail::expressedLike(S.surface, out->surface);
  if (old.numU() != out->surface.numU() || old.numV() != out->surface.numV() ||
      old.isRational() != out->surface.isRational())
    return Status(ErrorCode::kUnsupported, "the join changed the patch's form");
  BSplineSurface fo = detail::toEdgeFrame(old, me.edge, false);
  BSplineSurface fn = detail::toEdgeFrame(out->surface, me.edge, false);
  if (lockOthers && fn.numV() == 2)
    return Status(ErrorCode::kUnsupported, "the row next to the edge is the opposite edge, which stays");
  Matrix pts = fn.points();
  for (int a = 0; a < fn.numU(); ++a) {
    const Eigen::Index r0 = static_cast<Eigen::Index>(a) * fn.numV(), r1 = r0 + 1;
    pts.row(r1) += fn.points().row(r0) - fo.points().row(r0);
  }
  const BSplineSurface moved(fn.degreeU(), fn.degreeV(), fn.knotsU(), fn.knotsV(), fn.numU(), fn.numV(),
                             std::move(pts), fn.weights());
  return detail::fromEdgeFrame(moved, me.edge, false);
}

CreaseGapPass Healer::closeCreaseGaps() const {
  CreaseGapPass pass;
  pass.model = in_;
  std::vector<SeamReport> current(work_.size());
  for (size_t k = 0; k < work_.size(); ++k) current[k] = work_[k].before;
  for (size_t k = 0; k < work_.size(); ++k) {
    const Work& w = work_[k];
    if (!w.crease || !(w.before.g0Max > tol_.distance)) continue;
    CreaseOutcome oc;
    oc.work = static_cast<int>(k);
    struct Best {
      BSplineSurface surface;
      int patch = -1;
      double displacement = 0.0;
      SeamReport after;
      std::vector<std::pair<int, SeamReport>> touched;
    };
    std::optional<Best> best;
    std::vector<std::string> why;
    for (bool moverIsA : {true, false}) {
      const EdgeRef me = moverIsA ? w.pair.a : w.pair.b, other = moverIsA ? w.pair.b : w.pair.a;
      if (me.patch == other.patch) {
        why.push_back("a seam of a patch with itself");
        break;
      }
      const std::string& name = in_.patches[static_cast<size_t>(me.patch)].name;
      for (bool lockOthers : {true, false}) {
        auto cand = creaseGapMove(pass.model, w.pair, moverIsA, lockOthers);
        if (!cand) {
          why.push_back(fmt::format("moving {}: {}", name, cand.status().message()));
          continue;
        }
        std::string reason = foldOf(me.patch, *cand);
        Model& m = pass.model;
        const BSplineSurface keep = m.patches[static_cast<size_t>(me.patch)].surface;
        m.patches[static_cast<size_t>(me.patch)].surface = *cand;
        std::optional<SeamReport> crease;
        std::vector<std::pair<int, SeamReport>> touched;
        for (size_t q = 0; q < work_.size() && reason.empty(); ++q) {
          const Work& u = work_[q];
          if (u.pair.a.patch != me.patch && u.pair.b.patch != me.patch) continue;
          auto now = analyse(m, u.pair);
          if (!now) {
            reason = fmt::format("{} no longer analysable ({})", seamName(u.pair), now.status().message());
            break;
          }
          if (q == k) {
            if (!(now->g0Max < current[k].g0Max))
              reason = fmt::format("the gap would not shrink ({:.4g} -> {:.4g})", current[k].g0Max, now->g0Max);
            else if (std::abs(now->g1MaxDeg - w.before.g1MaxDeg) > tol_.strictAngleDeg())
              reason = fmt::format("the crease angle would change from {:.6g} to {:.6g} deg", w.before.g1MaxDeg,
                                   now->g1MaxDeg);
            crease = *now;
          } else if (std::string r = worseThan(*now, current[q], tol_); !r.empty()) {
            reason = fmt::format("{}: {}", seamName(u.pair), r);
          }
          touched.emplace_back(static_cast<int>(q), *now);
        }
        m.patches[static_cast<size_t>(me.patch)].surface = keep;
        if (!reason.empty() || !crease) {
          why.push_back(fmt::format("moving {}{}: {}", name, lockOthers ? "" : " (its other edges free)",
                                    reason.empty() ? "not analysed" : reason));
          continue;
        }
        const HealPatch d = displacementOf(in_.patches[static_cast<size_t>(me.patch)],
                                           Patch{name, PatchKind::kBSpline, *cand}, kRoundoff * diag_);
        if (!best || d.maxSurfaceDisplacement < best->displacement)
          best = Best{*cand, me.patch, d.maxSurfaceDisplacement, *crease, std::move(touched)};
        break;  // the other edges locked is preferred when it works
      }
    }
    if (!best) {
      oc.action = "crease: gap not closed";
      for (const std::string& r : why) oc.note += (oc.note.empty() ? "" : "; ") + r;
      pass.outcomes.push_back(std::move(oc));
      continue;
    }
    Patch& moved = pass.model.patches[static_cast<size_t>(best->patch)];
    moved = detail::replacedSurface(moved, best->surface);
    for (auto& [q, r] : best->touched) current[static_cast<size_t>(q)] = r;
    pass.changed = true;
    if (std::find(pass.movedPatches.begin(), pass.movedPatches.end(), best->patch) == pass.movedPatches.end())
      pass.movedPatches.push_back(best->patch);
    oc.mover = in_.patches[static_cast<size_t>(best->patch)].name;
    const bool closed = best->after.g0Max <= tol_.distance;
    oc.action = closed ? "crease: gap closed" : "crease: gap narrowed";
    oc.note = fmt::format("crease gap {:.4g} -> {:.4g} by moving {} (its edge and the next row by the same amount, so "
                          "the angle stays: {:.6g} -> {:.6g} deg)",
                          w.before.g0Max, best->after.g0Max, oc.mover, w.before.g1MaxDeg, best->after.g1MaxDeg);
    pass.outcomes.push_back(std::move(oc));
  }
  return pass;
}

/// Two reports of one seam cover the same stretch of both edges (their overlaps agree to the knot tolerance).
bool sameOverlap(const SeamReport& x, const SeamReport& y) {
  auto same = [](const Interval& a, const Interval& b) {
    const double scale = std::max({1.0, std::abs(a.lo), std::abs(a.hi)});
    return std::abs(a.lo - b.lo) <= kKnotRelTol * scale && std::abs(a.hi - b.hi) <= kKnotRelTol * scale;
  };
  return same(x.overlapA, y.overlapA) && same(x.overlapB, y.overlapB);
}

void Healer::mergeCreasePass(HealResult& res, const CreaseGapPass& pass) const {
  HealReport& rep = res.report;
  const auto key = [](const std::string& a, Edge ea, const std::string& b, Edge eb) {
    return fmt::format("{}:{}/{}:{}", a, edgeName(ea), b, edgeName(eb));
  };
  std::map<std::string, int> workOf;
  for (size_t k = 0; k < work_.size(); ++k) {
    const Work& w = work_[k];
    const std::string& a = in_.patches[static_cast<size_t>(w.pair.a.patch)].name;
    const std::string& b = in_.patches[static_cast<size_t>(w.pair.b.patch)].name;
    workOf[key(a, w.pair.a.edge, b, w.pair.b.edge)] = static_cast<int>(k);
    workOf[key(b, w.pair.b.edge, a, w.pair.a.edge)] = static_cast<int>(k);
  }
  std::map<int, const CreaseOutcome*> outcomeOf;
  for (const CreaseOutcome& o : pass.outcomes) outcomeOf[o.work] = &o;
  rep.seamsWorse = 0;
  for (HealSeam& hs : rep.seams) {
    const auto it = workOf.find(key(hs.a, hs.aEdge, hs.b, hs.bEdge));
    if (it != workOf.end()) {
      const Work& w = work_[static_cast<size_t>(it->second)];
      hs.before = w.before;
      if (pass.changed) {  // against the input, not the crease pass's model
        hs.edgeMoved = seamEdgeMovement(in_, res.model, w.pair);
        // The heal proper paired the crease pass's model again; where a moved edge changed how much of the two
        // edges overlap, its "after" measured another stretch of the seam than "before" (a gap that includes an end
        // the input's pairing left out as an overhang). Measure the output with the input's pairing instead.
        if (hs.after && !sameOverlap(*hs.after, w.before))
          if (auto now = analyse(res.model, w.pair)) {
            hs.after = std::move(*now);
            hs.achieved = meets(hs.after->geometric, opt_.continuity);
          }
      }
      if (const auto o = outcomeOf.find(it->second); o != outcomeOf.end()) {
        hs.action = o->second->action;
        if (!o->second->mover.empty()) hs.moved = o->second->mover;
        hs.notes.push_back(o->second->note);
        if (o->second->action != "crease: gap not closed") ++rep.creaseGapsClosed;
      }
      if (hs.after) hs.worse = !worseThan(*hs.after, hs.before, tol_).empty();
    }
    if (hs.worse) ++rep.seamsWorse;
  }
  if (!pass.changed) return;
  // The displacements against the input.
  for (int i : pass.movedPatches) {
    const Patch& before = in_.patches[static_cast<size_t>(i)];
    const Patch& after = res.model.patches[static_cast<size_t>(i)];
    HealPatch hp = displacementOf(before, after, kRoundoff * diag_);
    const auto same = [&](const HealPatch& p) { return p.name == before.name; };
    if (auto it = std::find_if(rep.patches.begin(), rep.patches.end(), same); it != rep.patches.end()) {
      hp.region = it->region;
      *it = std::move(hp);
    } else {
      hp.region = -1;
      for (const HealSeam& s : rep.seams)
        if (s.a == before.name || s.b == before.name) hp.region = s.region;
      rep.patches.push_back(std::move(hp));
      rep.patchesChanged.push_back(before.name);
    }
  }
  sumPatchDisplacements(rep);
}

}  // namespace

Result<HealResult> healModel(const Model& model, const HealOptions& options) {
  Healer first(model, options);
  if (Status st = first.prepare(); !st.isOk()) return st;
  const CreaseGapPass pass = first.closeCreaseGaps();
  if (!pass.changed) {
    auto res = first.finish();
    if (res) first.mergeCreasePass(*res, pass);
    return res;
  }
  // The heal proper of the model with the creases closed, with the first heal's tolerances and gap limit (the
  // bounding box moved by the gaps at most).
  HealOptions again = options;
  again.tolerances = first.tolerances();
  again.maxGap = first.maxGap();
  Healer second(pass.model, again);
  if (Status st = second.prepare(); !st.isOk()) return st;
  auto res = second.finish();
  if (res) first.mergeCreasePass(*res, pass);
  return res;
}

}  // namespace seam
