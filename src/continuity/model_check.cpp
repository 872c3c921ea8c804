#include "seam/continuity/model_check.h"

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <bit>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <numeric>
#include <span>
#include <tuple>
#include <utility>

#include "core/union_find.h"
#include "continuity/model_check_internal.h"
#include "continuity/one_span_curve.h"
#include "continuity/seam_internal.h"

namespace seam {

// ---------------------------------------------------------------------------------------------------------------
// Edge geometry helpers (model_check_internal.h)

namespace detail {

namespace {
/// Coarse samples per knot span before Newton (the distance function of a cubic/quintic edge has at most a few
/// minima per span; 8 separates them in practice, as in the seam analysis).
constexpr int kProjectionSamplesPerSpan = 8;
constexpr int kProjectionNewtonIterations = 20;
}  // namespace

EdgeProjection projectOntoCurve(const BSplineCurve& curve, const Vec3& p, std::optional<Interval> range) {
  const Interval r = range.value_or(curve.domain());
  std::vector<double> cuts{r.lo};
  for (double b : curve.knots().interiorBreakpoints(curve.degree()))
    if (b > r.lo && b < r.hi) cuts.push_back(b);
  cuts.push_back(r.hi);
  const OneSpanCurve ev(curve);  // the curve's own values, without the span search on Bezier edges
  auto dist2 = [&](double t) { return (ev.point3(t) - p).squaredNorm(); };
  double bestT = r.lo, bestD = dist2(r.lo);
  for (size_t k = 0; k + 1 < cuts.size(); ++k) {
    for (int i = 1; i <= kProjectionSamplesPerSpan; ++i) {
      const double t = cuts[k] + (cuts[k + 1] - cuts[k]) * i / kProjectionSamplesPerSpan;
      const double d = dist2(t);
      if (d < bestD) {
        bestD = d;
        bestT = t;
      }
    }
  }
  // Safeguarded Newton on f(t) = (C - p) . C'; accept only steps that do not increase the distance.
  double t = bestT;
  for (int it = 0; it < kProjectionNewtonIterations; ++it) {
    Vec3 x, d1, d2;
    ev.derivatives2(t, x, d1, d2);
    const Vec3 diff = x - p;
    const double f = diff.dot(d1);
    const double fp = d1.squaredNorm() + diff.dot(d2);
    if (!(fp > 0.0)) break;
    double next = std::clamp(t - f / fp, r.lo, r.hi);
    double dn = dist2(next);
    int halvings = 0;
    while (dn > bestD && halvings < 30) {
      next = 0.5 * (next + t);
      dn = dist2(next);
      ++halvings;
    }
    if (dn > bestD) break;
    const bool converged = std::abs(next - t) <= kRoundoff * r.length();
    t = next;
    bestD = dn;
    if (converged) break;
  }
  return {t, std::sqrt(bestD)};
}

double controlExtent(const BSplineCurve& curve) {
  const Matrix& P = curve.points();
  double extent = 0.0;
  for (Eigen::Index i = 1; i < P.rows(); ++i) extent = std::max(extent, (P.row(i) - P.row(0)).head<3>().norm());
  return extent;
}

Interval edgeDomain(const BSplineSurface& s, Edge e) { return isUEdge(e) ? s.domainV() : s.domainU(); }

Vec2 edgePointUV(const BSplineSurface& s, Edge e, double t) {
  switch (e) {
    case Edge::U0: return {s.domainU().lo, t};
    case Edge::U1: return {s.domainU().hi, t};
    case Edge::V0: return {t, s.domainV().lo};
    case Edge::V1: return {t, s.domainV().hi};
  }
  return {0.0, 0.0};
}

double boxDistance(const BoundingBox& b, const Vec3& p) { return (p.cwiseMax(b.min).cwiseMin(b.max) - p).norm(); }

}  // namespace detail

namespace {

/// Samples per Bezier span of an edge for the pairing's overlap test (at least kMinPairSamples in all).
constexpr int kPairSamplesPerSpan = 8;
constexpr int kMinPairSamples = 16;
/// The departure directions of an edge are chords to the points at 1/kDepartureDivisor of its domain from each end.
constexpr double kDepartureDivisor = 64.0;
/// Two edges meeting at a common end point can only share a part that starts there when they leave it in nearly the
/// same direction: cos(angle) above this (60 degrees; a real seam with a gap d shared over a length >= 2d leaves at
/// most ~30 degrees apart). Edges meeting at a corner at any larger angle, or continuing each other, are not tested
/// further.
constexpr double kDepartureCos = 0.5;
/// Polyline points per Bezier span for the approximate first pass of the overlap test.
constexpr int kPolylinePerSpan = 32;
/// Polyline segments per box of the projection's cut-off (polylineProjectionWithin).
constexpr size_t kPolylineGroup = 8;
/// A candidate pair is rejected when more than this fraction of its shared part is already claimed, on either edge,
/// by a closer partner.
constexpr double kMaxClaimedFraction = 0.5;
/// An edge whose bounding box covers more grid cells than this is tested against every edge by bounding boxes
/// instead (a few very long edges must not blow up the index).
constexpr long kMaxCellsPerEdge = 4096;
/// Doubles below this magnitude that are integers are exact (2^52): quantised keys are compared exactly.
constexpr double kExactIntegerDouble = 4503599627370496.0;
/// Largest cell index per axis of the corner-proximity grid (keys stay far from overflowing a long when a neighbour
/// offset is added; a wider model gets coarser cells, same result).
constexpr double kMaxCornerCells = 1e12;
/// Relative slack on parameters: an overlap reaching within this fraction of an edge's domain length (plus the
/// pair's distance) of its end covers that end.
constexpr double kParamRelSlack = 1e-9;

/// Runs body(k) for k in [0, n): serially on the calling thread when threads == 1 (or n is small), else in a TBB arena
/// of `threads` threads (0 = all). Every body writes only its own slot, so the result does not depend on the threads.
template <class Body>
void forEachIndex(size_t n, int threads, const Body& body) {
  constexpr size_t kMinParallel = 64;  // below this, a task arena costs more than it saves
  if (threads == 1 || n < kMinParallel) {
    for (size_t k = 0; k < n; ++k) body(k);
    return;
  }
  tbb::task_arena arena(threads > 0 ? threads : tbb::task_arena::automatic);
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t k = r.begin(); k != r.end(); ++k) body(k);
    });
  });
}

/// Open-addressing hash index from 64-bit keys to a range [first, last) of a sorted array (the cells of the spatial
/// grids): O(1) look-ups where a binary search over all keys cost ~log2(4 N) comparisons per neighbour cell.
class RangeIndex {
 public:
  explicit RangeIndex(size_t count) {
    size_t cap = 16;
    while (cap < 2 * count) cap *= 2;
    slots_.assign(cap, Slot{});
    mask_ = cap - 1;
  }
  void insert(std::uint64_t key, size_t first, size_t last) {
    size_t h = hash(key);
    while (slots_[h].last != 0) h = (h + 1) & mask_;
    slots_[h] = {key, first, last};
  }
  /// The range of `key`, or an empty one.
  [[nodiscard]] std::pair<size_t, size_t> find(std::uint64_t key) const {
    for (size_t h = hash(key);; h = (h + 1) & mask_) {
      const Slot& s = slots_[h];
      if (s.last == 0) return {0, 0};
      if (s.key == key) return {s.first, s.last};
    }
  }

 private:
  struct Slot {
    std::uint64_t key = 0;
    size_t first = 0, last = 0;  ///< last == 0: empty (a stored range is never empty)
  };
  [[nodiscard]] size_t hash(std::uint64_t key) const {
    key ^= key >> 33;
    key *= 0xff51afd7ed558ccdULL;  // MurmurHash3's 64-bit finaliser
    key ^= key >> 33;
    return static_cast<size_t>(key) & mask_;
  }
  std::vector<Slot> slots_;
  size_t mask_ = 0;
};

/// Stable sort of (key, index) pairs by key alone, least significant 16 bits first (`bits`: how many low bits of the
/// keys are used; a pass whose digit is the same for every entry is skipped): linear time where std::sort of the
/// pairs was a third of the candidate search. Entries made in increasing index order come out ordered by (key, index).
void radixSortByKey(std::vector<std::pair<std::uint64_t, int>>& v, int bits) {
  constexpr int kDigitBits = 16;
  constexpr size_t kBuckets = size_t{1} << kDigitBits;
  if (v.size() < 2) return;
  std::vector<std::pair<std::uint64_t, int>> buffer(v.size());
  std::vector<size_t> count(kBuckets);
  for (int shift = 0; shift < bits; shift += kDigitBits) {
    std::fill(count.begin(), count.end(), size_t{0});
    for (const auto& k : v) ++count[(k.first >> shift) & (kBuckets - 1)];
    if (count[(v.front().first >> shift) & (kBuckets - 1)] == v.size()) continue;
    size_t sum = 0;
    for (size_t& c : count) sum += std::exchange(c, sum);
    for (const auto& k : v) buffer[count[(k.first >> shift) & (kBuckets - 1)]++] = k;
    v.swap(buffer);
  }
}

/// A 64-bit hash of doubles by their bits (-0 taken as +0, so that values that compare equal hash equally).
std::uint64_t hashDoubles(std::span<const double> x) {
  std::uint64_t h = 0x9e3779b97f4a7c15ULL;
  for (const double v : x) {
    std::uint64_t bits = 0;
    const double w = v + 0.0;  // -0.0 + 0.0 = +0.0
    std::memcpy(&bits, &w, sizeof bits);
    h ^= bits + 0x9e3779b97f4a7c15ULL + (h << 6) + (h >> 2);
    h *= 0xff51afd7ed558ccdULL;
    h ^= h >> 32;
  }
  return h;
}

struct EdgeInfo {
  EdgeRef ref;
  BSplineCurve curve;
  Interval domain;
  BoundingBox box;
  double length = 0.0;  ///< control-polygon length (>= arc length)
  double width = 0.0;   ///< extent of the patch across the edge
  bool collapsed = false;
  bool coincidentExtra = false;  ///< a third or later copy of a coincident edge: left out of the pairing
  Vec3 start = Vec3::Zero(), end = Vec3::Zero();
  /// The first and last control points (3 coordinates; the stage-1 test reads them for every candidate).
  Vec3 firstPoint = Vec3::Zero(), lastPoint = Vec3::Zero();
  /// Unit directions in which the edge leaves its start and its end point (chords to the points at 1/64 of the
  /// domain from each end, robust where the first derivative vanishes).
  Vec3 startDir = Vec3::Zero(), endDir = Vec3::Zero();
  std::span<const double> unitKnots;  ///< the curve's knots mapped affinely onto [0, 1] (in Pairing::unitKnotPool)
  // Samples for the general overlap test (filled on demand).
  std::vector<double> sampleT;
  std::vector<Vec3> sampleP;
  // Dense polyline for the fast approximate projection of the first pass (filled on demand).
  std::vector<double> polyT;
  std::vector<Vec3> polyP;
  /// Boxes of kPolylineGroup consecutive polyline segments (group g: points g * kPolylineGroup ... + kPolylineGroup).
  std::vector<BoundingBox> polyGroups;
};

/// Knot vector of the curve mapped affinely onto [0, 1], written into `out` (as many values as the curve has knots).
void normalizedKnots(const BSplineCurve& c, std::span<double> out) {
  const std::vector<double>& k = c.knots().values();
  assert(out.size() == k.size());
  const Interval d = c.domain();
  for (size_t i = 0; i < k.size(); ++i) out[i] = (k[i] - d.lo) / d.length();
}

/// |d|, without overflowing in the squares when the coordinates are near 1e300 (the scaled norm only then).
double safeNorm(const Vec3& d) {
  const double n = d.norm();
  return std::isfinite(n) ? n : d.stableNorm();
}

/// `unitKnots`: where the edge's normalised knots go (as many values as the surface has knots along the edge).
/// Fills `info` (a default-constructed slot, filled in place).
void makeEdge(EdgeInfo& info, const Patch& patch, int index, Edge e, double collapseTol, std::span<double> unitKnots) {
  info.ref = {index, e};
  const BSplineSurface& s = patch.surface;
  info.curve = s.boundaryCurve(e);
  info.domain = info.curve.domain();
  info.box = controlBox(info.curve);
  normalizedKnots(info.curve, unitKnots);
  info.unitKnots = unitKnots;
  const Matrix& P = info.curve.points();
  for (Eigen::Index i = 1; i < P.rows(); ++i) info.length += safeNorm((P.row(i) - P.row(i - 1)).head<3>().transpose());
  info.collapsed = detail::controlExtent(info.curve) <= collapseTol;
  // The end points: at a clamped end the end control point itself (exactly the curve's value there), else evaluated.
  const std::vector<double>& kn = info.curve.knots().values();
  const int p = info.curve.degree();
  bool clampedLo = true, clampedHi = true;
  for (int i = 1; i <= p; ++i) {
    clampedLo = clampedLo && kn[static_cast<size_t>(i)] == kn.front();
    clampedHi = clampedHi && kn[kn.size() - 1 - static_cast<size_t>(i)] == kn.back();
  }
  const detail::OneSpanCurve ev(info.curve);
  info.firstPoint = P.row(0).head<3>().transpose();
  info.lastPoint = P.row(P.rows() - 1).head<3>().transpose();
  info.start = clampedLo ? info.firstPoint : ev.point3(info.domain.lo);
  info.end = clampedHi ? info.lastPoint : ev.point3(info.domain.hi);
  const double step = info.domain.length() / kDepartureDivisor;
  info.startDir = (ev.point3(info.domain.lo + step) - info.start).normalized();
  info.endDir = (ev.point3(info.domain.hi - step) - info.end).normalized();
}

/// Width of a patch across two opposite edges (U0/U1 or V0/V1, whose curves share one parameter domain): the largest
/// of the distances between them at 1/4, 1/2 and 3/4 of the edge parameter.
void setWidths(EdgeInfo& e0, EdgeInfo& e1) {
  const detail::OneSpanCurve ev0(e0.curve), ev1(e1.curve);
  double w = 0.0;
  for (double f : {0.25, 0.5, 0.75}) {
    const double t = e0.domain.lo + f * e0.domain.length();
    w = std::max(w, safeNorm(ev0.point3(t) - ev1.point3(t)));
  }
  e0.width = e1.width = w;
}

void ensureSamples(EdgeInfo& e) {
  if (!e.sampleT.empty()) return;
  std::vector<double> cuts{e.domain.lo};
  for (double b : e.curve.knots().interiorBreakpoints(e.curve.degree())) cuts.push_back(b);
  cuts.push_back(e.domain.hi);
  const int spans = static_cast<int>(cuts.size()) - 1;
  const int perSpan = std::max(kPairSamplesPerSpan, (kMinPairSamples + spans - 1) / spans);
  const auto samples = static_cast<size_t>(spans * perSpan + 1);
  const auto poly = static_cast<size_t>(spans * kPolylinePerSpan + 1);
  e.sampleT.reserve(samples);
  e.sampleP.reserve(samples);
  e.polyT.reserve(poly);
  e.polyP.reserve(poly);
  e.polyGroups.reserve((poly - 1 + kPolylineGroup - 1) / kPolylineGroup);
  for (int k = 0; k < spans; ++k)
    for (int i = (k == 0 ? 0 : 1); i <= perSpan; ++i)
      e.sampleT.push_back(cuts[static_cast<size_t>(k)] + (cuts[static_cast<size_t>(k) + 1] - cuts[static_cast<size_t>(k)]) * i / perSpan);
  const detail::OneSpanCurve ev(e.curve);
  for (double t : e.sampleT) e.sampleP.push_back(ev.point3(t));
  for (int k = 0; k < spans; ++k)
    for (int i = (k == 0 ? 0 : 1); i <= kPolylinePerSpan; ++i)
      e.polyT.push_back(cuts[static_cast<size_t>(k)] +
                        (cuts[static_cast<size_t>(k) + 1] - cuts[static_cast<size_t>(k)]) * i / kPolylinePerSpan);
  for (double t : e.polyT) e.polyP.push_back(ev.point3(t));
  for (size_t first = 0; first + 1 < e.polyP.size(); first += kPolylineGroup) {
    BoundingBox g;
    for (size_t k = first; k <= std::min(first + kPolylineGroup, e.polyP.size() - 1); ++k) g.add(e.polyP[k]);
    e.polyGroups.push_back(g);
  }
}

/// The closest point on the polyline where only a distance within `cutoff` matters (infinite: the closest point): a
/// group of segments whose box is farther from p than the best distance so far or than the cut-off is skipped (its
/// segments are at least that far). The result is the full scan's, bit for bit, whenever that is within the
/// cut-off (a skipped segment is farther than the result, so it was never the first closest); otherwise it is some
/// distance above the cut-off.
detail::EdgeProjection polylineProjectionWithin(const EdgeInfo& e, const Vec3& p, double cutoff) {
  detail::EdgeProjection best{e.polyT[0], (e.polyP[0] - p).norm()};
  for (size_t g = 0; g < e.polyGroups.size(); ++g) {
    if (detail::boxDistance(e.polyGroups[g], p) > std::min(best.distance, cutoff)) continue;
    const size_t last = std::min((g + 1) * kPolylineGroup, e.polyP.size() - 1);
    for (size_t k = g * kPolylineGroup; k < last; ++k) {
      const Vec3 d = e.polyP[k + 1] - e.polyP[k];
      const double len2 = d.squaredNorm();
      const double f = len2 > 0.0 ? std::clamp((p - e.polyP[k]).dot(d) / len2, 0.0, 1.0) : 0.0;
      const double dist = (e.polyP[k] + f * d - p).norm();
      if (dist < best.distance) best = {e.polyT[k] + f * (e.polyT[k + 1] - e.polyT[k]), dist};
    }
  }
  return best;
}

/// Closest point on the polyline of `e` (parameter interpolated linearly on the closest segment): the cheap first
/// pass of the overlap test. Its error is the polyline's sag, ~(span length / kPolylinePerSpan)^2 x curvature / 8.
detail::EdgeProjection polylineProjection(const EdgeInfo& e, const Vec3& p) {
  return polylineProjectionWithin(e, p, std::numeric_limits<double>::infinity());
}

/// The pair identicalPolygons reports for polygons found to agree in the orientation `reversed` within `distance`
/// (before snapOverlap).
EdgePair identicalPair(const EdgeInfo& a, const EdgeInfo& b, bool reversed, double distance) {
  EdgePair p;
  p.a = a.ref;
  p.b = b.ref;
  p.overlapA = a.domain;
  p.overlapB = b.domain;
  p.reversed = reversed;
  p.distance = distance;
  p.identicalControlPolygons = true;
  return p;
}

/// Fast path: control polygons that agree point by point within `tol` (in the same or reversed order, the closer of
/// the two) with equivalent knots and weights. Then the edges are the same parametrised curve up to the largest
/// control-point distance (partition of unity).
std::optional<EdgePair> identicalPolygons(const EdgeInfo& a, const EdgeInfo& b, double tol) {
  const BSplineCurve& ca = a.curve;
  const BSplineCurve& cb = b.curve;
  if (ca.degree() != cb.degree() || ca.numPoints() != cb.numPoints() || ca.isRational() != cb.isRational())
    return std::nullopt;
  const std::span<const double> ka = a.unitKnots;
  const std::span<const double> kb = b.unitKnots;
  const size_t nk = ka.size();
  if (kb.size() != nk) return std::nullopt;
  const int n = ca.numPoints();
  const Matrix& pa = ca.points();
  const Matrix& pb = cb.points();
  const bool rational = ca.isRational();
  // Fast path: polynomial edges whose normalised knots and control points are equal value for value (neighbours cut
  // from one surface share their boundary rows exactly). The loops below would find the same: the knots match in the
  // same order, every point difference is +-0 (distance 0, within any tolerance), and the reversed order is ruled out
  // at its first point (no closer than 0).
  if (!rational && !(0.0 > tol) && pa.cols() == pb.cols() && std::equal(ka.begin(), ka.end(), kb.begin()) &&
      std::equal(pa.data(), pa.data() + pa.size(), pb.data()))
    return identicalPair(a, b, false, 0.0);
  // The best orientation so far: its distance, or none.
  bool found = false, bestReversed = false;
  double bestD = 0.0;
  for (const bool reversed : {false, true}) {
    bool knotsMatch = true;
    for (size_t i = 0; i < nk && knotsMatch; ++i) {
      const double other = reversed ? 1.0 - kb[nk - 1 - i] : kb[i];
      knotsMatch = std::abs(ka[i] - other) <= kKnotRelTol;
    }
    if (!knotsMatch) continue;
    // Stops at the first control point that rules this orientation out (too far, or no closer than the other one).
    double d = 0.0;
    bool ruledOut = false;
    for (int i = 0; i < n && !ruledOut; ++i) {
      const int j = reversed ? n - 1 - i : i;
      d = std::max(d, (pa.row(i) - pb.row(j)).head<3>().norm());
      if (rational && !(std::abs(ca.weights()[i] - cb.weights()[j]) <= kRoundoff * std::abs(ca.weights()[i])))
        ruledOut = true;
      ruledOut = ruledOut || d > tol || (found && d >= bestD);
    }
    if (ruledOut) continue;
    found = true;
    bestReversed = reversed;
    bestD = d;
  }
  if (!found) return std::nullopt;
  return identicalPair(a, b, bestReversed, bestD);
}

/// The longest run of consecutive samples within `tol` of the other edge; returns (first, last) indices.
std::optional<std::pair<size_t, size_t>> longestRun(const std::vector<detail::EdgeProjection>& proj, double tol) {
  std::optional<std::pair<size_t, size_t>> best;
  size_t i = 0;
  while (i < proj.size()) {
    if (proj[i].distance > tol) {
      ++i;
      continue;
    }
    size_t j = i;
    while (j + 1 < proj.size() && proj[j + 1].distance <= tol) ++j;
    if (j > i && (!best || j - i > best->second - best->first)) best = std::pair{i, j};
    i = j + 1;
  }
  return best;
}

/// Cheap necessary condition for a shared part (whose ends are always edge ends, see endsExplained): some end point
/// of one edge lies within tol of the other edge's control box, and where that end point coincides with an end point
/// of the other edge, both edges leave it in nearly the same direction.
bool mayOverlap(const EdgeInfo& a, const EdgeInfo& b, double tol) {
  auto check = [tol](const Vec3& E, const Vec3& dir, const EdgeInfo& o) {
    if (detail::boxDistance(o.box, E) > tol) return false;
    if ((E - o.start).norm() <= tol) return dir.dot(o.startDir) > kDepartureCos;
    if ((E - o.end).norm() <= tol) return dir.dot(o.endDir) > kDepartureCos;
    return true;  // near the other edge's interior: a T-junction is possible
  };
  return check(a.start, a.startDir, b) || check(a.end, a.endDir, b) || check(b.start, b.startDir, a) ||
         check(b.end, b.endDir, a);
}

/// General overlap test by sampling both edges and projecting onto the other (the samples are filled by
/// ensureSamples before: the test only reads the edges, so that candidates are tested in parallel). A candidate
/// shared part is built from the longest run of samples of A within `tol` of B and the longest such run of B (or from one of them alone), and
/// kept only when it verifies: every sample of A inside it lies within `tol` of B and every sample of B inside its
/// image lies within `tol` of A. (Without the check, two curves that meet only at both of their ends, like the
/// two halves of a closed loop, would combine their two end runs into a false full overlap.)
/// With `exact` false, every projection is onto the other edge's dense polyline (cheap; used to reject most
/// candidates); with `exact` true, onto the curve itself (Newton).
std::optional<EdgePair> sampledOverlap(const EdgeInfo& a, const EdgeInfo& b, double tol,
                                       const ModelCheckOptions& options, bool exact) {
  assert(!a.sampleT.empty() && !b.sampleT.empty());  // ensureSamples(a), ensureSamples(b) before
  auto project = [exact](const EdgeInfo& onto, const Vec3& p) {
    return exact ? detail::projectOntoCurve(onto.curve, p) : polylineProjection(onto, p);
  };
  // A sample farther than tol from the other edge's control box is farther than tol from its curve and polyline
  // (both lie in the box), and on the polyline groups of segments farther than tol are skipped the same way: such a
  // sample gets a distance above tol that is not its own (t = NaN marks it). The runs and the verification only ask
  // whether a distance is above tol; the one place that reads the value (the distance over the final shared part)
  // projects the marked samples properly (exactDistance). Edges that only share a corner skip most of the
  // projections this way (issue 37 goal 1).
  constexpr double kNotProjected = std::numeric_limits<double>::quiet_NaN();
  auto projectNear = [&](const EdgeInfo& onto, const Vec3& p) {
    const double boxD = detail::boxDistance(onto.box, p);
    if (boxD > tol) return detail::EdgeProjection{kNotProjected, boxD};
    if (exact) return project(onto, p);
    detail::EdgeProjection q = polylineProjectionWithin(onto, p, tol);
    if (q.distance > tol) q.t = kNotProjected;
    return q;
  };
  auto exactDistance = [&](const detail::EdgeProjection& q, const EdgeInfo& onto, const Vec3& p) {
    return std::isnan(q.t) ? project(onto, p).distance : q.distance;
  };
  std::vector<detail::EdgeProjection> pa, pb;  // a's samples onto b, b's samples onto a
  for (const Vec3& p : a.sampleP) pa.push_back(projectNear(b, p));
  for (const Vec3& p : b.sampleP) pb.push_back(projectNear(a, p));
  const auto ra = longestRun(pa, tol), rb = longestRun(pb, tol);
  if (!ra && !rb) return std::nullopt;

  struct Candidate {
    Interval oa, ob;
    double dist = 0.0, corr = 0.0;
  };
  auto build = [&](bool useA, bool useB) -> std::optional<Candidate> {
    Candidate c{{a.domain.hi, a.domain.lo}, {b.domain.hi, b.domain.lo}, 0.0, 0.0};
    if (useA) {
      c.oa.lo = std::min(c.oa.lo, a.sampleT[ra->first]);
      c.oa.hi = std::max(c.oa.hi, a.sampleT[ra->second]);
      for (size_t k = ra->first; k <= ra->second; ++k) {
        c.ob.lo = std::min(c.ob.lo, pa[k].t);
        c.ob.hi = std::max(c.ob.hi, pa[k].t);
      }
      c.corr += (pa[ra->second].t - pa[ra->first].t) / b.domain.length();
    }
    if (useB) {
      c.ob.lo = std::min(c.ob.lo, b.sampleT[rb->first]);
      c.ob.hi = std::max(c.ob.hi, b.sampleT[rb->second]);
      for (size_t k = rb->first; k <= rb->second; ++k) {
        c.oa.lo = std::min(c.oa.lo, pb[k].t);
        c.oa.hi = std::max(c.oa.hi, pb[k].t);
      }
      c.corr += (pb[rb->second].t - pb[rb->first].t) / a.domain.length();
    }
    if (!(c.oa.hi > c.oa.lo) || !(c.ob.hi > c.ob.lo)) return std::nullopt;
    // Verification over the whole candidate part.
    for (size_t k = 0; k < pa.size(); ++k) {
      if (a.sampleT[k] < c.oa.lo || a.sampleT[k] > c.oa.hi) continue;
      if (pa[k].distance > tol) return std::nullopt;
      c.dist = std::max(c.dist, pa[k].distance);
    }
    for (size_t k = 0; k < pb.size(); ++k) {
      if (b.sampleT[k] < c.ob.lo || b.sampleT[k] > c.ob.hi) continue;
      if (pb[k].distance > tol) return std::nullopt;
      c.dist = std::max(c.dist, pb[k].distance);
    }
    return c;
  };
  std::optional<Candidate> c;
  if (ra && rb) c = build(true, true);
  if (!c && ra) c = build(true, false);
  if (!c && rb) c = build(false, true);
  if (!c) return std::nullopt;

  // Refine the ends: a shared part ends where one of the edges ends, so each end of the sampled part is moved to the
  // nearest of: the edge's own domain end, or the projection of an end point of the other edge (when that end point
  // lies within tol of this edge). Runs overshoot by up to one sample spacing (samples just beyond the other edge's
  // end are still within tol of its end point); two edges that only touch at a corner collapse to a point here.
  const detail::EdgeProjection bs = project(a, b.start), be = project(a, b.end);
  const detail::EdgeProjection as = project(b, a.start), ae = project(b, a.end);
  auto refine = [tol](Interval& o, const EdgeInfo& e, const detail::EdgeProjection& p0, const detail::EdgeProjection& p1) {
    const double spacing = e.domain.length() / static_cast<double>(e.sampleT.size() - 1);
    const double slack = 1.5 * spacing + (e.length > 0.0 ? tol / e.length * e.domain.length() : 0.0);
    auto snapEnd = [&](double x) {
      double best = x, bestD = slack;
      for (const double cand : {e.domain.lo, e.domain.hi}) {
        if (std::abs(cand - x) <= bestD) best = cand, bestD = std::abs(cand - x);
      }
      for (const detail::EdgeProjection* q : {&p0, &p1}) {
        if (q->distance <= tol && std::abs(q->t - x) < bestD) best = q->t, bestD = std::abs(q->t - x);
      }
      return best;
    };
    o = {snapEnd(o.lo), snapEnd(o.hi)};
  };
  refine(c->oa, a, bs, be);
  refine(c->ob, b, as, ae);
  if (!(c->oa.hi > c->oa.lo) || !(c->ob.hi > c->ob.lo)) return std::nullopt;
  c->dist = 0.0;
  for (size_t k = 0; k < pa.size(); ++k)
    if (a.sampleT[k] >= c->oa.lo && a.sampleT[k] <= c->oa.hi)
      c->dist = std::max(c->dist, exactDistance(pa[k], b, a.sampleP[k]));
  for (size_t k = 0; k < pb.size(); ++k)
    if (b.sampleT[k] >= c->ob.lo && b.sampleT[k] <= c->ob.hi)
      c->dist = std::max(c->dist, exactDistance(pb[k], a, b.sampleP[k]));
  for (const auto* q : {&bs, &be}) {
    if (q->t >= c->oa.lo && q->t <= c->oa.hi && q->distance <= tol) c->dist = std::max(c->dist, q->distance);
  }
  for (const auto* q : {&as, &ae}) {
    if (q->t >= c->ob.lo && q->t <= c->ob.hi && q->distance <= tol) c->dist = std::max(c->dist, q->distance);
  }
  const double lenA = a.length * c->oa.length() / a.domain.length();
  const double lenB = b.length * c->ob.length() / b.domain.length();
  const double shorter = std::min(a.length, b.length);
  if (std::min(lenA, lenB) < options.minOverlapFraction * shorter) return std::nullopt;
  EdgePair p;
  p.a = a.ref;
  p.b = b.ref;
  p.overlapA = c->oa;
  p.overlapB = c->ob;
  p.reversed = c->corr < 0.0;
  p.distance = c->dist;
  return p;
}

/// Snaps overlap ends to the domain ends they reach (within the pair's distance) and sets fullA / fullB.
void snapOverlap(EdgePair& p, const EdgeInfo& a, const EdgeInfo& b) {
  auto snap = [&](Interval& o, const EdgeInfo& e) {
    const double slack = (e.length > 0.0 ? 2.0 * p.distance / e.length : 0.0) * e.domain.length() +
                         kParamRelSlack * e.domain.length();
    if (o.lo - e.domain.lo <= slack) o.lo = e.domain.lo;
    if (e.domain.hi - o.hi <= slack) o.hi = e.domain.hi;
    return o.lo == e.domain.lo && o.hi == e.domain.hi;
  };
  p.fullA = snap(p.overlapA, a);
  p.fullB = snap(p.overlapB, b);
}

/// A pair with a gap must share a part at least this many times longer than the gap (on both edges): two edges that
/// only touch at a common corner come within the gap of each other over a length of about gap / sin(angle), i.e. a
/// ratio near 1 for the usual angles, while a real near-coincident seam shares (almost) the whole edge.
constexpr double kMinOverlapToGap = 2.0;

/// A pair with a gap must share a part that is long compared with the gap (on both edges).
/// Note: two sheets whose free edges run side by side closer than the pairing tolerance (the tip of the teaspoon's
/// bowl, where the inner and outer surfaces end 0.0089 apart) are paired; the seam analysis then reports the gap and
/// the fold. shared/data/README.md counts that tip as a gap seam too.
bool plausibleGappedSeam(const EdgePair& p, const EdgeInfo& a, const EdgeInfo& b) {
  const double lenA = a.length * p.overlapA.length() / a.domain.length();
  const double lenB = b.length * p.overlapB.length() / b.domain.length();
  return std::min(lenA, lenB) >= kMinOverlapToGap * p.distance;
}

/// Every end of a shared part must be the end of one of the two edges (after snapping): a real seam, full, T-junction
/// or staggered, ends where an edge ends. Two edges that merely approach each other (e.g. the two halves of the
/// teapot's handle end, which meet in a cusp at their common corner) share a part that ends in the middle of both.
bool endsExplained(const EdgePair& p, const EdgeInfo& a, const EdgeInfo& b) {
  const bool aLo = p.overlapA.lo == a.domain.lo, aHi = p.overlapA.hi == a.domain.hi;
  const bool bLo = p.overlapB.lo == b.domain.lo, bHi = p.overlapB.hi == b.domain.hi;
  // A's lower end meets B's lower end unless the directions are opposite.
  const bool lowEnd = aLo || (p.reversed ? bHi : bLo);
  const bool highEnd = aHi || (p.reversed ? bLo : bHi);
  return lowEnd && highEnd;
}

/// Length of the part of `o` covered by the (possibly overlapping) intervals `claimed` (`cut`: working storage).
double claimedLength(std::span<const Interval> claimed, const Interval& o, std::vector<Interval>& cut) {
  cut.clear();
  for (const Interval& c : claimed) {
    const double lo = std::max(c.lo, o.lo), hi = std::min(c.hi, o.hi);
    if (hi > lo) cut.push_back({lo, hi});
  }
  std::sort(cut.begin(), cut.end(), [](const Interval& x, const Interval& y) { return x.lo < y.lo; });
  double total = 0.0, curLo = 0.0, curHi = -1.0;
  bool open = false;
  for (const Interval& c : cut) {
    if (!open || c.lo > curHi) {
      if (open) total += curHi - curLo;
      curLo = c.lo;
      curHi = c.hi;
      open = true;
    } else {
      curHi = std::max(curHi, c.hi);
    }
  }
  if (open) total += curHi - curLo;
  return total;
}

/// The parts of `domain` not covered by `c` (the claimed parts, sorted here in place) that are longer than
/// `minLength`.
std::vector<Interval> uncovered(std::vector<Interval>& c, const Interval& domain, double minLength) {
  std::sort(c.begin(), c.end(), [](const Interval& x, const Interval& y) { return x.lo < y.lo; });
  std::vector<Interval> out;
  double cur = domain.lo;
  for (const Interval& x : c) {
    if (x.lo - cur > minLength) out.push_back({cur, x.lo});
    cur = std::max(cur, x.hi);
  }
  if (domain.hi - cur > minLength) out.push_back({cur, domain.hi});
  return out;
}

/// The parts claimed on each edge: one singly linked list per edge in flat arrays (almost every edge is claimed once,
/// so a vector per edge would cost an allocation per edge).
class ClaimLists {
 public:
  explicit ClaimLists(size_t edges) : head_(edges, -1) {}
  void add(size_t edge, const Interval& part) {
    next_.push_back(head_[edge]);
    parts_.push_back(part);
    head_[edge] = static_cast<int>(parts_.size()) - 1;
  }
  /// The parts claimed on `edge` in the order they were claimed (out is cleared first).
  void get(size_t edge, std::vector<Interval>& out) const {
    out.clear();
    for (int c = head_[edge]; c >= 0; c = next_[static_cast<size_t>(c)]) out.push_back(parts_[static_cast<size_t>(c)]);
    std::reverse(out.begin(), out.end());
  }

 private:
  std::vector<int> head_;  ///< per edge: its last claim, or -1
  std::vector<int> next_;  ///< per claim: the same edge's previous claim, or -1
  std::vector<Interval> parts_;
};

/// True when every coordinate of the box is finite.
bool finiteBox(const BoundingBox& b) { return b.min.allFinite() && b.max.allFinite(); }

/// The first test of a candidate pair (runPairing's stage 1): rejected, identical control polygons (with the
/// orientation and distance identicalPolygons found), or to be sampled.
enum class Stage : char { kRejected, kIdentical, kSampled };
struct StageResult {
  Stage stage = Stage::kRejected;
  bool reversed = false;
  double distance = 0.0;
};
/// A candidate pair of edges (a < b) that its first test did not reject.
struct Candidate {
  int a = 0, b = 0;
  StageResult stage;
};

/// Candidate pairs from a uniform grid over the inflated edge boxes: sorted (cell, edge) keys, then every two edges
/// that share a cell. Edge i's box is inflated by inflate[i]; two edges within inflate[i] + inflate[j] of each other
/// always share a cell. Edges covering too many cells are compared with every edge by box.
/// Each pair (i, j), in increasing order, goes through `test(i, j)` (a StageResult; read-only, called in parallel) as
/// it is found, and only those not rejected are listed: the pairs that a list of every candidate followed by the test
/// of each would keep, in the same order, without that list.
template <class Test>
std::vector<Candidate> candidatePairs(const std::vector<EdgeInfo>& edges, const std::vector<double>& inflateOf,
                                      int threads, const Test& test) {
  std::vector<int> active;
  std::vector<double> sizes;
  for (int i = 0; i < static_cast<int>(edges.size()); ++i) {
    // Collapsed edges and extra copies of coincident edges pair with nothing; non-finite ones are refused by
    // runPairing (never keyed: no cell of NaN).
    const EdgeInfo& e = edges[static_cast<size_t>(i)];
    if (e.collapsed || e.coincidentExtra || !finiteBox(e.box) || !std::isfinite(inflateOf[static_cast<size_t>(i)]))
      continue;
    active.push_back(i);
    const BoundingBox& b = edges[static_cast<size_t>(i)].box;
    sizes.push_back((b.max - b.min).maxCoeff() + 2.0 * inflateOf[static_cast<size_t>(i)]);
  }
  std::vector<Candidate> out;
  if (active.size() < 2) return out;
  std::nth_element(sizes.begin(), sizes.begin() + static_cast<long>(sizes.size() / 2), sizes.end());
  // Cells are counted from the low corner of all inflated boxes, kCellBits per axis packed into one 64-bit code;
  // a model wider than 2^kCellBits cells gets coarser cells (more candidates, the same result).
  constexpr int kCellBits = 21;
  constexpr double kMaxCellsPerAxis = static_cast<double>((1L << kCellBits) - 2);
  Vec3 gmin = Vec3::Constant(std::numeric_limits<double>::infinity()), gmax = -gmin;
  for (int i : active) {
    const BoundingBox& b = edges[static_cast<size_t>(i)].box;
    const double inflate = inflateOf[static_cast<size_t>(i)];
    gmin = gmin.cwiseMin(b.min - Vec3::Constant(inflate));
    gmax = gmax.cwiseMax(b.max + Vec3::Constant(inflate));
  }
  // Cells are computed in a scaled frame (coordinates divided by the largest magnitude, so within [-1, 1]): no
  // difference of coordinates near +-1e308 overflows, no quotient by a subnormal cell size does; keys are clamped.
  double scale = std::max(gmin.cwiseAbs().maxCoeff(), gmax.cwiseAbs().maxCoeff());
  if (!(scale > 0.0) || !std::isfinite(scale)) scale = 1.0;
  const Vec3 smin = gmin / scale;
  const double extent = (gmax / scale - smin).maxCoeff();
  double h = sizes[sizes.size() / 2] / scale;
  if (!(h > 0.0) || !std::isfinite(h)) h = extent > 0.0 ? extent : 1.0;
  h = std::max(h, extent / kMaxCellsPerAxis);
  using Cell = std::array<std::uint64_t, 3>;
  std::vector<std::pair<std::uint64_t, int>> keys;  // (cell code, edge), sorted
  std::vector<int> oversize;
  std::vector<std::array<Cell, 2>> cellRange(edges.size());  // lo, hi cell of each keyed edge
  std::vector<char> keyed(edges.size(), 0);
  Cell maxCell{0, 0, 0};  // the largest cell index per axis of the keyed edges
  for (int i : active) {
    const BoundingBox& b = edges[static_cast<size_t>(i)].box;
    const double inflate = inflateOf[static_cast<size_t>(i)];
    Cell lo{}, hi{};
    long count = 1;
    for (int k = 0; k < 3; ++k) {
      const auto cellOf = [&](double x) {
        return static_cast<std::uint64_t>(std::clamp(std::floor((x / scale - smin[k]) / h), 0.0, kMaxCellsPerAxis));
      };
      lo[static_cast<size_t>(k)] = cellOf(b.min[k] - inflate);
      hi[static_cast<size_t>(k)] = cellOf(b.max[k] + inflate);
      count *= static_cast<long>(hi[static_cast<size_t>(k)] - lo[static_cast<size_t>(k)] + 1);
    }
    if (count > kMaxCellsPerEdge) {
      oversize.push_back(i);
      continue;
    }
    cellRange[static_cast<size_t>(i)] = {lo, hi};
    keyed[static_cast<size_t>(i)] = 1;
    for (size_t k = 0; k < 3; ++k) maxCell[k] = std::max(maxCell[k], hi[k]);
  }
  // Cell codes packed with as many bits per axis as the largest index needs (at most kCellBits): one code per cell,
  // and as few radix passes as the occupied cells need (2 of 16 bits for up to 128 cells per axis).
  const int bitsY = static_cast<int>(std::bit_width(maxCell[1])), bitsZ = static_cast<int>(std::bit_width(maxCell[2]));
  const int codeBits = static_cast<int>(std::bit_width(maxCell[0])) + bitsY + bitsZ;
  auto code = [bitsY, bitsZ](std::uint64_t x, std::uint64_t y, std::uint64_t z) {
    return (x << (bitsY + bitsZ)) | (y << bitsZ) | z;
  };
  for (int i : active) {
    if (!keyed[static_cast<size_t>(i)]) continue;
    const auto& [lo, hi] = cellRange[static_cast<size_t>(i)];
    for (std::uint64_t x = lo[0]; x <= hi[0]; ++x)
      for (std::uint64_t y = lo[1]; y <= hi[1]; ++y)
        for (std::uint64_t z = lo[2]; z <= hi[2]; ++z) keys.emplace_back(code(x, y, z), i);
  }
  // Sorted by (cell, edge): the keys were made in increasing edge order, so a stable sort by cell alone does it.
  radixSortByKey(keys, codeBits);
  // Each occupied cell's run of keys, found by a hash of its code.
  size_t cells = 0;
  for (size_t k = 0; k < keys.size(); ++k) cells += (k == 0 || keys[k].first != keys[k - 1].first) ? 1 : 0;
  RangeIndex cellIndex(cells);
  for (size_t k = 0; k < keys.size();) {
    size_t end = k + 1;
    while (end < keys.size() && keys[end].first == keys[k].first) ++end;
    cellIndex.insert(keys[k].first, k, end);
    k = end;
  }
  // Pairs (i, j), i < j, in increasing order without a global sort: each edge gathers the higher-numbered edges of
  // its own cells (plus the oversize ones), and only that short list is sorted. The active edges are cut into a fixed
  // number of chunks (independent of the thread count) whose pair lists are concatenated in order.
  std::vector<char> isOversize(edges.size(), 0);
  for (int i : oversize) isOversize[static_cast<size_t>(i)] = 1;
  auto boxesApart = [&](int i, int j) {  // the exact box test (both inflations)
    const BoundingBox& a = edges[static_cast<size_t>(i)].box;
    const BoundingBox& b = edges[static_cast<size_t>(j)].box;
    const double r = inflateOf[static_cast<size_t>(i)] + inflateOf[static_cast<size_t>(j)];
    return ((a.min.array() - r) > b.max.array()).any() || ((b.min.array() - r) > a.max.array()).any();
  };
  constexpr size_t kChunks = 64;
  std::vector<std::vector<Candidate>> chunkPairs(kChunks);
  forEachIndex(kChunks, threads, [&](size_t chunk) {
    const size_t first = active.size() * chunk / kChunks, last = active.size() * (chunk + 1) / kChunks;
    std::vector<Candidate>& local = chunkPairs[chunk];
    std::vector<int> partners;
    for (size_t a = first; a < last; ++a) {
      const int i = active[a];
      partners.clear();
      if (isOversize[static_cast<size_t>(i)]) {
        for (int j : active)
          if (j > i) partners.push_back(j);
      } else {
        const auto& [lo, hi] = cellRange[static_cast<size_t>(i)];
        for (std::uint64_t x = lo[0]; x <= hi[0]; ++x)
          for (std::uint64_t y = lo[1]; y <= hi[1]; ++y)
            for (std::uint64_t z = lo[2]; z <= hi[2]; ++z) {
              const std::uint64_t c = code(x, y, z);
              const auto [cellFirst, cellLast] = cellIndex.find(c);
              // This cell's edges above i, each taken in one cell only: the lowest of the cells it shares with i
              // (the componentwise larger of the two low cells; x >= both low cells here), so no duplicates.
              auto it = std::upper_bound(keys.begin() + cellFirst, keys.begin() + cellLast, std::pair{c, i});
              for (; it != keys.begin() + cellLast; ++it) {
                const Cell& loJ = cellRange[static_cast<size_t>(it->second)][0];
                if ((x == lo[0] || x == loJ[0]) && (y == lo[1] || y == loJ[1]) && (z == lo[2] || z == loJ[2]))
                  partners.push_back(it->second);
              }
            }
        for (int j : oversize)
          if (j > i) partners.push_back(j);
      }
      std::sort(partners.begin(), partners.end());
      for (int j : partners) {
        if (boxesApart(i, j)) continue;
        const StageResult r = test(i, j);
        if (r.stage != Stage::kRejected) local.push_back({i, j, r});
      }
    }
  });
  size_t total = 0;
  for (const auto& c : chunkPairs) total += c.size();
  out.reserve(total);
  for (const auto& c : chunkPairs) out.insert(out.end(), c.begin(), c.end());
  return out;
}

/// Groups of three or more coincident edges (same end points, either way round, and mid point within `tol`), found
/// by sorting quantised keys: O(N log N). All but the first two edges of each group are marked coincidentExtra.
/// The keys are made in two steps: the end points' six quantised coordinates for every edge, and the mid point's
/// three only for the edges that share their end-point key with two others or more (a group of three equal keys
/// needs three equal end-point keys: on a model of distinct seams no mid point is evaluated). The groups, their
/// members and the marks are those of the nine-coordinate keys.
std::vector<CoincidentEdges> markCoincidentEdges(std::vector<EdgeInfo>& edges, double tol, int threads) {
  const double q = tol > 0.0 ? tol : std::numeric_limits<double>::min();
  // Cell index of a coordinate (the coordinate itself when the index would not be an exact integer): identical
  // points always get identical keys; points within tol of each other usually do (the rest pair the usual way).
  auto quant = [q](double v) {
    const double r = std::floor(v / q);
    return std::isfinite(r) && std::abs(r) < kExactIntegerDouble ? r : v;
  };
  constexpr size_t kEndKeys = 6;  ///< the end points' quantised coordinates (the first six of the nine)
  struct Key {
    std::array<double, 9> k;  ///< end points (the lexicographically smaller first), then the mid point
    int edge;
  };
  auto endsEqual = [](const Key& x, const Key& y) {
    return std::equal(x.k.begin(), x.k.begin() + kEndKeys, y.k.begin());
  };
  auto endsLess = [](const Key& x, const Key& y) {
    return std::lexicographical_compare(x.k.begin(), x.k.begin() + kEndKeys, y.k.begin(), y.k.begin() + kEndKeys);
  };
  // End-point keys and their hashes per edge in parallel (each edge its own slot), then the non-collapsed ones in edge
  // order.
  std::vector<Key> all(edges.size());
  std::vector<std::uint64_t> hashes(edges.size());
  forEachIndex(edges.size(), threads, [&](size_t i) {
    const EdgeInfo& e = edges[i];
    if (e.collapsed) return;
    Vec3 a = e.start, b = e.end;
    if (std::lexicographical_compare(b.data(), b.data() + 3, a.data(), a.data() + 3)) std::swap(a, b);
    Key key{{}, static_cast<int>(i)};
    for (int c = 0; c < 3; ++c) {
      key.k[static_cast<size_t>(c)] = quant(a[c]);
      key.k[static_cast<size_t>(3 + c)] = quant(b[c]);
    }
    all[i] = key;
    hashes[i] = hashDoubles(std::span<const double>(key.k.data(), kEndKeys));
  });
  std::vector<Key> keys;
  std::vector<std::pair<std::uint64_t, int>> byHash;
  keys.reserve(edges.size());
  byHash.reserve(edges.size());
  for (size_t i = 0; i < edges.size(); ++i) {
    if (edges[i].collapsed) continue;
    byHash.emplace_back(hashes[i], static_cast<int>(keys.size()));
    keys.push_back(all[i]);
  }
  // Ordered so that equal end-point keys are contiguous, in increasing edge order: by a hash of the key (a stable
  // linear sort of keys made in edge order), runs of one hash holding different keys (collisions) then stably by the
  // key itself.
  {
    radixSortByKey(byHash, 64);
    std::vector<Key> sorted;
    sorted.reserve(keys.size());
    for (size_t r = 0; r < byHash.size();) {
      size_t end = r + 1;
      while (end < byHash.size() && byHash[end].first == byHash[r].first) ++end;
      const size_t first = sorted.size();
      bool mixed = false;
      for (size_t m = r; m < end; ++m) {
        sorted.push_back(keys[static_cast<size_t>(byHash[m].second)]);
        mixed = mixed || !endsEqual(sorted.back(), sorted[first]);
      }
      if (mixed)
        std::stable_sort(sorted.begin() + static_cast<std::ptrdiff_t>(first), sorted.end(), endsLess);
      r = end;
    }
    keys.swap(sorted);
  }
  std::vector<CoincidentEdges> out;
  std::vector<Vec3> mids;  // of the current end-point group's edges, by position in `keys`
  for (size_t h = 0; h < keys.size();) {
    size_t hEnd = h + 1;
    while (hEnd < keys.size() && endsEqual(keys[hEnd], keys[h])) ++hEnd;
    if (hEnd - h < 3) {
      h = hEnd;
      continue;
    }
    // Three or more equal end-point keys: the mid points' keys, then runs of equal nine-coordinate keys in edge order
    // (the run is in edge order; a stable sort by the whole key keeps it within equal keys).
    mids.assign(hEnd - h, Vec3::Zero());
    for (size_t m = h; m < hEnd; ++m) {
      const EdgeInfo& e = edges[static_cast<size_t>(keys[m].edge)];
      mids[m - h] = e.curve.point3(0.5 * (e.domain.lo + e.domain.hi));
      for (int c = 0; c < 3; ++c) keys[m].k[static_cast<size_t>(6 + c)] = quant(mids[m - h][c]);
    }
    std::vector<std::pair<Key, Vec3>> group;
    for (size_t m = h; m < hEnd; ++m) group.emplace_back(keys[m], mids[m - h]);
    std::stable_sort(group.begin(), group.end(), [](const auto& x, const auto& y) { return x.first.k < y.first.k; });
    for (size_t g = 0; g < group.size();) {
      size_t end = g + 1;
      while (end < group.size() && group[end].first.k == group[g].first.k) ++end;
      if (end - g >= 3) {
        const EdgeInfo& first = edges[static_cast<size_t>(group[g].first.edge)];
        const Vec3& firstMid = group[g].second;
        std::vector<int> members;
        for (size_t m = g; m < end; ++m) {
          const EdgeInfo& e = edges[static_cast<size_t>(group[m].first.edge)];
          const bool same = (e.start - first.start).norm() <= tol && (e.end - first.end).norm() <= tol;
          const bool flipped = (e.start - first.end).norm() <= tol && (e.end - first.start).norm() <= tol;
          if ((same || flipped) && (group[m].second - firstMid).norm() <= tol) members.push_back(group[m].first.edge);
        }
        if (members.size() >= 3) {  // keys sorted by edge within the group: members are in EdgeRef order
          CoincidentEdges c;
          for (int i : members) c.edges.push_back(edges[static_cast<size_t>(i)].ref);
          c.point = firstMid;
          for (size_t m = 2; m < members.size(); ++m) edges[static_cast<size_t>(members[m])].coincidentExtra = true;
          out.push_back(std::move(c));
        }
      }
      g = end;
    }
    h = hEnd;
  }
  std::sort(out.begin(), out.end(),
            [](const CoincidentEdges& x, const CoincidentEdges& y) { return x.edges.front() < y.edges.front(); });
  return out;
}

struct Pairing {
  std::vector<EdgeInfo> edges;  // 4 per patch, index 4 * patch + edge
  std::vector<double> unitKnotPool;  // every edge's normalised knots, one allocation (EdgeInfo::unitKnots views)
  EdgePairing result;
};

/// `diagonal`: the model's bounding-box diagonal (computed once by the caller).
Result<Pairing> runPairing(const Model& model, double diagonal, const Tolerances& tol,
                           const ModelCheckOptions& options) {
  Pairing P;
  const double tau = std::max(tol.distance, options.pairingRelTol * (std::isfinite(diagonal) ? diagonal : 0.0));
  P.result.pairingTolerance = tau;
  for (const Patch& patch : model.patches)
    if (patch.surface.dim() != 3) return invalidInput(fmt::format("patch \"{}\" is not 3-D", patch.name));
  // Edge data per patch, in parallel (each patch fills its own four slots: index 4 * patch + edge, kAllEdges order
  // U0, U1, V0, V1).
  P.edges.resize(model.patches.size() * 4);
  // Each edge's slice of the knot pool: its curve has the surface's knots along the edge.
  std::vector<size_t> knotStart(P.edges.size() + 1, 0);
  for (size_t i = 0; i < model.patches.size(); ++i)
    for (size_t k = 0; k < 4; ++k) {
      const BSplineSurface& s = model.patches[i].surface;
      knotStart[4 * i + k + 1] =
          knotStart[4 * i + k] + static_cast<size_t>(isUEdge(kAllEdges[k]) ? s.knotsV().size() : s.knotsU().size());
    }
  P.unitKnotPool.resize(knotStart.back());
  forEachIndex(model.patches.size(), options.threads, [&](size_t i) {
    const Patch& patch = model.patches[i];
    const size_t base = 4 * i;
    for (size_t k = 0; k < 4; ++k) {
      const std::span<double> slot(P.unitKnotPool.data() + knotStart[base + k],
                                   knotStart[base + k + 1] - knotStart[base + k]);
      makeEdge(P.edges[base + k], patch, static_cast<int>(i), kAllEdges[k], tol.distance, slot);
    }
    setWidths(P.edges[base], P.edges[base + 1]);
    setWidths(P.edges[base + 2], P.edges[base + 3]);
  });
  // Edges whose points overflow doubles (a weight near 1e308, coordinates near +-1e308) cannot be measured: refused
  // here, before they reach the spatial hash or the seam analysis.
  for (const EdgeInfo& e : P.edges)
    if (!finiteBox(e.box) || !e.start.allFinite() || !e.end.allFinite() || !std::isfinite(e.width) ||
        !std::isfinite(e.length))
      return invalidInput(fmt::format("patch \"{}\", edge {}: its points are not finite doubles (evaluating it "
                                      "overflows or divides by zero: coordinates or weights near 1e308, knot spans "
                                      "near 5e-324?); seam cannot check it",
                                      model.patches[static_cast<size_t>(e.ref.patch)].name, edgeName(e.ref.edge)));
  for (const EdgeInfo& e : P.edges)
    if (e.collapsed) P.result.degenerateEdges.push_back({e.ref, e.start});
  P.result.coincidentEdges = markCoincidentEdges(P.edges, tol.distance, options.threads);

  // A pair of different patches is kept only with a gap below min(tau, maxGapToWidth x both widths), a pair within one
  // patch only when exact: inflating each box by half of its own bound finds every such pair.
  std::vector<double> inflate(P.edges.size());
  for (size_t k = 0; k < P.edges.size(); ++k)
    inflate[k] = 0.5 * std::min(tau, std::max(tol.distance, options.maxGapToWidth * P.edges[k].width));
  // Gapped pairs must have a gap below maxGapToWidth x the patch widths, and a patch meets itself only exactly: the
  // sampled test never needs a larger tolerance than that.
  auto tauPairOf = [&](const EdgeInfo& a, const EdgeInfo& b) {
    return a.ref.patch == b.ref.patch
               ? tol.distance
               : std::min(tau, std::max(tol.distance, options.maxGapToWidth * std::min(a.width, b.width)));
  };
  // The gap rules every pair must meet (after the identical-polygon or the sampled test).
  auto keepPair = [&](const EdgePair& p, const EdgeInfo& a, const EdgeInfo& b) {
    if (p.distance <= tol.distance) return true;
    if (a.ref.patch == b.ref.patch) return false;  // a patch meets itself only exactly (closed surfaces)
    if (p.distance > options.maxGapToWidth * std::min(a.width, b.width)) return false;
    return plausibleGappedSeam(p, a, b);
  };
  // Stage 1 (parallel, read-only, on each candidate as the grid finds it): identical control polygons (within tau,
  // then the gap rules: small patches whose polygons all lie within tau of each other stop here), or else the cheap
  // necessary condition of the sampled test. An identical-polygon candidate keeps the orientation and distance
  // identicalPolygons found (stage 3 rebuilds the pair from them instead of comparing the polygons again).
  auto stageOne = [&](int i, int j) -> StageResult {
    const EdgeInfo& a = P.edges[static_cast<size_t>(i)];
    const EdgeInfo& b = P.edges[static_cast<size_t>(j)];
    // Shortcut with the same outcome: when the end control points rule out every identical-polygon pair that the gap
    // rules would keep (in both orientations the distance of the polygons, at least that of their end points, exceeds
    // the largest gap keepPair allows) and the sampled test's necessary condition fails, the candidate is rejected
    // whichever way identicalPolygons decides (edges that only share a corner).
    // (The end control points as Vec3: the same differences and sums of squares as the rows' first three columns.)
    if (a.curve.numPoints() == b.curve.numPoints() && a.curve.numPoints() > 0) {
      const double keptGap = a.ref.patch == b.ref.patch
                                 ? tol.distance
                                 : std::max(tol.distance, options.maxGapToWidth * std::min(a.width, b.width));
      const double sameWay = std::max((a.firstPoint - b.firstPoint).norm(), (a.lastPoint - b.lastPoint).norm());
      const double reversedWay = std::max((a.firstPoint - b.lastPoint).norm(), (a.lastPoint - b.firstPoint).norm());
      if (sameWay > keptGap && reversedWay > keptGap && !mayOverlap(a, b, tauPairOf(a, b))) return {};
    }
    if (std::optional<EdgePair> p = identicalPolygons(a, b, tau)) {
      snapOverlap(*p, a, b);
      if (keepPair(*p, a, b)) return {Stage::kIdentical, p->reversed, p->distance};
    } else if (mayOverlap(a, b, tauPairOf(a, b))) {
      return {Stage::kSampled, false, 0.0};
    }
    return {};
  };
  // The candidates that stage 1 keeps, in candidate order (by a, then b).
  const std::vector<Candidate> survivors = candidatePairs(P.edges, inflate, options.threads, stageOne);
  std::vector<char> needsSamples(P.edges.size(), 0);
  for (const Candidate& c : survivors)
    if (c.stage.stage == Stage::kSampled)
      needsSamples[static_cast<size_t>(c.a)] = needsSamples[static_cast<size_t>(c.b)] = 1;
  // Stage 2: the samples of the edges that need them, each edge once, in parallel.
  std::vector<size_t> sampledEdges;
  for (size_t e = 0; e < P.edges.size(); ++e)
    if (needsSamples[e]) sampledEdges.push_back(e);
  forEachIndex(sampledEdges.size(), options.threads, [&](size_t k) { ensureSamples(P.edges[sampledEdges[k]]); });
  // Stage 3 (parallel, read-only): the pair of each surviving candidate, or none.
  std::vector<std::optional<EdgePair>> found(survivors.size());
  forEachIndex(survivors.size(), options.threads, [&](size_t s) {
    const Candidate& cand = survivors[s];
    const EdgeInfo& a = P.edges[static_cast<size_t>(cand.a)];
    const EdgeInfo& b = P.edges[static_cast<size_t>(cand.b)];
    const bool samePatch = a.ref.patch == b.ref.patch;
    std::optional<EdgePair> p;
    if (cand.stage.stage == Stage::kIdentical) {
      p = identicalPair(a, b, cand.stage.reversed, cand.stage.distance);
      snapOverlap(*p, a, b);
    } else {
      // Two passes: the cheap polyline pass rejects most candidates (edges that only touch at a corner, parallel
      // edges across a patch), the exact pass (Newton projections) measures the survivors.
      auto accept = [&](EdgePair& q, bool exact) {
        snapOverlap(q, a, b);
        if (!endsExplained(q, a, b)) return false;
        // The polyline pass cannot tell an exact pair from one with a gap below the polyline's sag: it only rejects
        // what is far beyond the rules.
        if (!exact || q.distance > tol.distance) {
          if (samePatch && exact) return false;
          if (q.distance > options.maxGapToWidth * std::min(a.width, b.width)) return false;
          if (!plausibleGappedSeam(q, a, b)) return false;
        }
        return true;
      };
      const double tauPair = tauPairOf(a, b);
      p = sampledOverlap(a, b, tauPair, options, false);
      if (!p || !accept(*p, false)) return;
      p = sampledOverlap(a, b, tauPair, options, true);
      if (!p || !accept(*p, true)) return;
    }
    if (keepPair(*p, a, b)) found[s] = p;
  });
  std::vector<EdgePair> candidates;  // in candidate order, i.e. ordered by (a, b): each pair of edges comes once
  for (const std::optional<EdgePair>& p : found)
    if (p) candidates.push_back(*p);
  // Closest partners first; a candidate whose shared part is mostly claimed already (on either edge) is dropped. The
  // accepted ones are listed in candidate order (by a, then b).
  std::vector<size_t> byDistance(candidates.size());
  std::iota(byDistance.begin(), byDistance.end(), size_t{0});
  std::stable_sort(byDistance.begin(), byDistance.end(),
                   [&](size_t x, size_t y) { return candidates[x].distance < candidates[y].distance; });
  std::vector<char> isAccepted(candidates.size(), 0);
  ClaimLists claimed(P.edges.size());
  std::vector<Interval> claimedA, claimedB, cut;  // working storage
  for (size_t k : byDistance) {
    const EdgePair& c = candidates[k];
    const size_t ia = static_cast<size_t>(4 * c.a.patch + static_cast<int>(c.a.edge));
    const size_t ib = static_cast<size_t>(4 * c.b.patch + static_cast<int>(c.b.edge));
    claimed.get(ia, claimedA);
    claimed.get(ib, claimedB);
    const double fa = claimedLength(claimedA, c.overlapA, cut) / c.overlapA.length();
    const double fb = claimedLength(claimedB, c.overlapB, cut) / c.overlapB.length();
    if (fa > kMaxClaimedFraction || fb > kMaxClaimedFraction) continue;
    claimed.add(ia, c.overlapA);
    claimed.add(ib, c.overlapB);
    isAccepted[k] = 1;
  }
  for (size_t k = 0; k < candidates.size(); ++k)
    if (isAccepted[k]) P.result.pairs.push_back(candidates[k]);
  for (size_t k = 0; k < P.edges.size(); ++k) {
    const EdgeInfo& e = P.edges[k];
    if (e.collapsed || e.coincidentExtra) continue;
    const double minLength = options.minOverlapFraction * e.domain.length();
    claimed.get(k, claimedA);
    const std::vector<Interval> free = uncovered(claimedA, e.domain, minLength);
    for (const Interval& f : free)
      P.result.freeEdges.push_back({e.ref, f, !(f.lo == e.domain.lo && f.hi == e.domain.hi)});
  }
  return P;
}

// ---------------------------------------------------------------------------------------------------------------
// Corners

/// Corner id: 4 * patch + 2 * uMax + vMax.
int cornerId(int patch, bool uMax, bool vMax) { return 4 * patch + 2 * (uMax ? 1 : 0) + (vMax ? 1 : 0); }
PatchCorner cornerOf(int id) { return {id / 4, ((id % 4) / 2) == 1, (id % 2) == 1}; }

/// The corner at the start (t = lo) or end of edge e.
int edgeEndCorner(int patch, Edge e, bool atEnd) {
  switch (e) {
    case Edge::U0: return cornerId(patch, false, atEnd);
    case Edge::U1: return cornerId(patch, true, atEnd);
    case Edge::V0: return cornerId(patch, atEnd, false);
    case Edge::V1: return cornerId(patch, atEnd, true);
  }
  return 0;
}

struct CornerLinkGlobal {
  int a;
  Edge aEdge;
  int b;
  Edge bEdge;
};

std::vector<ModelCorner> findCorners(const Model& model, const std::vector<EdgeInfo>& edges,
                                     const std::vector<EdgePair>& pairs, double cornerTol,
                                     const CornerOptions& cornerOptions, bool analyze, int threads,
                                     const std::vector<double>& patchDiagonal) {
  const int np = static_cast<int>(model.patches.size());
  const int nc = 4 * np;
  std::vector<Vec3> points(static_cast<size_t>(nc));
  for (int p = 0; p < np; ++p) {
    // Corner points from the edges' end points (already evaluated).
    const EdgeInfo& u0 = edges[static_cast<size_t>(4 * p)];
    const EdgeInfo& u1 = edges[static_cast<size_t>(4 * p + 1)];
    points[static_cast<size_t>(cornerId(p, false, false))] = u0.start;
    points[static_cast<size_t>(cornerId(p, false, true))] = u0.end;
    points[static_cast<size_t>(cornerId(p, true, false))] = u1.start;
    points[static_cast<size_t>(cornerId(p, true, true))] = u1.end;
  }
  UnionFind uf(nc);
  std::vector<CornerLinkGlobal> links;
  // Collapsed edges join their two corners.
  for (const EdgeInfo& e : edges) {
    if (!e.collapsed) continue;
    const int a = edgeEndCorner(e.ref.patch, e.ref.edge, false), b = edgeEndCorner(e.ref.patch, e.ref.edge, true);
    uf.unite(a, b);
    links.push_back({a, e.ref.edge, b, e.ref.edge});
  }
  // Paired edges join the corners at the ends they share.
  for (const EdgePair& p : pairs) {
    const EdgeInfo& ea = edges[static_cast<size_t>(4 * p.a.patch + static_cast<int>(p.a.edge))];
    const EdgeInfo& eb = edges[static_cast<size_t>(4 * p.b.patch + static_cast<int>(p.b.edge))];
    for (bool aEnd : {false, true}) {
      const bool aAtEnd = aEnd ? p.overlapA.hi == ea.domain.hi : p.overlapA.lo == ea.domain.lo;
      const bool bEndSide = aEnd != p.reversed;  // the end of B that meets this end of A
      const bool bAtEnd = bEndSide ? p.overlapB.hi == eb.domain.hi : p.overlapB.lo == eb.domain.lo;
      if (!aAtEnd || !bAtEnd) continue;
      const int ca = edgeEndCorner(p.a.patch, p.a.edge, aEnd), cb = edgeEndCorner(p.b.patch, p.b.edge, bEndSide);
      if (ca == cb) continue;
      uf.unite(ca, cb);
      links.push_back({ca, p.a.edge, cb, p.b.edge});
    }
  }
  // Proximity: a uniform grid of cell cornerTol, each corner compared with the corners in its 27 neighbouring cells.
  if (cornerTol > 0.0) {
    struct Key {
      std::array<long, 3> cell;
      int corner;
      // Element-wise (std::array's operators go through memcmp, which dominated this loop).
      bool operator<(const Key& o) const {
        return std::tie(cell[0], cell[1], cell[2], corner) < std::tie(o.cell[0], o.cell[1], o.cell[2], o.corner);
      }
      [[nodiscard]] bool inCell(const std::array<long, 3>& c) const {
        return cell[0] == c[0] && cell[1] == c[1] && cell[2] == c[2];
      }
    };
    // Cells in a scaled frame (coordinates divided by the largest magnitude, counted from the low corner), at least
    // cornerTol wide and at most kMaxCornerCells per axis: keys neither overflow nor come from a non-finite quotient
    // (coordinates near 1e300, a tolerance near 5e-324). Corners that are not finite take part in no proximity.
    Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
    for (const Vec3& q : points)
      if (q.allFinite()) lo = lo.cwiseMin(q), hi = hi.cwiseMax(q);
    double scale = std::max(lo.cwiseAbs().maxCoeff(), hi.cwiseAbs().maxCoeff());
    if (!(scale > 0.0) || !std::isfinite(scale)) scale = 1.0;
    const Vec3 slo = lo / scale;
    const double extent = (hi / scale - slo).maxCoeff();
    double cellSize = std::max(cornerTol / scale, extent / kMaxCornerCells);
    if (!(cellSize > 0.0) || !std::isfinite(cellSize)) cellSize = 1.0;
    std::vector<Key> keys;
    keys.reserve(static_cast<size_t>(nc));
    for (int c = 0; c < nc; ++c) {
      const Vec3& q = points[static_cast<size_t>(c)];
      if (!q.allFinite()) continue;
      std::array<long, 3> k{};
      for (int a = 0; a < 3; ++a)
        k[static_cast<size_t>(a)] =
            static_cast<long>(std::clamp(std::floor((q[a] / scale - slo[a]) / cellSize), 0.0, kMaxCornerCells));
      keys.push_back({k, c});
    }
    // Keys grouped by cell (runs of one cell, corners in increasing order): sorted by a hash of the cell (a stable
    // linear sort of keys made in corner order), runs of one hash holding different cells (collisions) then by cell.
    // Each run is found again by its hash; the runs of one hash are contiguous.
    auto cellHash = [](const std::array<long, 3>& c) {
      const auto u = [](long x) { return static_cast<std::uint64_t>(x); };
      std::uint64_t h =
          u(c[0]) * 0x9e3779b97f4a7c15ULL ^ u(c[1]) * 0xc2b2ae3d27d4eb4fULL ^ u(c[2]) * 0x165667b19e3779f9ULL;
      h ^= h >> 29;
      return h;
    };
    std::vector<std::pair<std::uint64_t, int>> byHash(keys.size());
    for (size_t i = 0; i < keys.size(); ++i) byHash[i] = {cellHash(keys[i].cell), static_cast<int>(i)};
    radixSortByKey(byHash, 64);
    std::vector<Key> sorted;
    sorted.reserve(keys.size());
    std::vector<std::pair<size_t, size_t>> runs;  // [first, last) of each cell in keys
    RangeIndex cellIndex(keys.size());
    for (size_t r = 0; r < byHash.size();) {
      size_t end = r + 1;
      while (end < byHash.size() && byHash[end].first == byHash[r].first) ++end;
      const size_t first = sorted.size();
      bool mixed = false;
      for (size_t m = r; m < end; ++m) {
        sorted.push_back(keys[static_cast<size_t>(byHash[m].second)]);
        mixed = mixed || !sorted.back().inCell(sorted[first].cell);
      }
      if (mixed) std::sort(sorted.begin() + static_cast<std::ptrdiff_t>(first), sorted.end());
      const size_t firstRun = runs.size();
      for (size_t k = first; k < sorted.size();) {
        size_t runEnd = k + 1;
        while (runEnd < sorted.size() && sorted[runEnd].inCell(sorted[k].cell)) ++runEnd;
        runs.emplace_back(k, runEnd);
        k = runEnd;
      }
      cellIndex.insert(byHash[r].first, firstRun, runs.size());
      r = end;
    }
    keys.swap(sorted);
    auto findRun = [&](const std::array<long, 3>& cell) -> std::optional<std::pair<size_t, size_t>> {
      const auto [first, last] = cellIndex.find(cellHash(cell));
      for (size_t r = first; r < last; ++r)
        if (keys[runs[r].first].inCell(cell)) return runs[r];
      return std::nullopt;
    };
    auto near = [&](int a, int b) {
      const Vec3 d = points[static_cast<size_t>(b)] - points[static_cast<size_t>(a)];
      double dist = d.norm();
      if (!std::isfinite(dist)) dist = d.stableNorm();  // squares of coordinates near 1e300 overflow
      return dist <= cornerTol;
    };
    // Each pair of cells is visited once: the same cell (each pair of its corners), and the 13 neighbouring cells that
    // come after it in lexicographic order (all their corners). The order of the unions does not matter: a cluster's
    // root is always its smallest corner.
    for (const auto& [first, last] : runs) {
      const std::array<long, 3>& base = keys[first].cell;
      for (size_t m = first; m < last; ++m)
        for (size_t n = m + 1; n < last; ++n)
          if (near(keys[m].corner, keys[n].corner)) uf.unite(keys[m].corner, keys[n].corner);
      for (long dx = 0; dx <= 1; ++dx)
        for (long dy = dx == 0 ? 0 : -1; dy <= 1; ++dy)
          for (long dz = (dx == 0 && dy == 0) ? 1 : -1; dz <= 1; ++dz) {
            const auto other = findRun({base[0] + dx, base[1] + dy, base[2] + dz});
            if (!other) continue;
            for (size_t m = first; m < last; ++m)
              for (size_t n = other->first; n < other->second; ++n)
                if (near(keys[m].corner, keys[n].corner)) uf.unite(keys[m].corner, keys[n].corner);
          }
    }
  }
  // Clusters by root (the smallest member), in increasing order of root, members in increasing order; the links of
  // each cluster in the order they were made. Flat arrays (offsets per root) instead of one vector per corner.
  std::vector<int> rootOf(static_cast<size_t>(nc));
  for (int c = 0; c < nc; ++c) rootOf[static_cast<size_t>(c)] = uf.find(c);
  std::vector<size_t> memberStart(static_cast<size_t>(nc) + 1, 0), linkStart(static_cast<size_t>(nc) + 1, 0);
  for (int c = 0; c < nc; ++c) ++memberStart[static_cast<size_t>(rootOf[static_cast<size_t>(c)]) + 1];
  for (const CornerLinkGlobal& l : links) ++linkStart[static_cast<size_t>(rootOf[static_cast<size_t>(l.a)]) + 1];
  for (size_t r = 0; r < static_cast<size_t>(nc); ++r) {
    memberStart[r + 1] += memberStart[r];
    linkStart[r + 1] += linkStart[r];
  }
  std::vector<int> members(static_cast<size_t>(nc));
  std::vector<CornerLinkGlobal> clusterLinks(links.size());
  {
    std::vector<size_t> fill(memberStart.begin(), memberStart.end() - 1);
    for (int c = 0; c < nc; ++c) members[fill[static_cast<size_t>(rootOf[static_cast<size_t>(c)])]++] = c;
    fill.assign(linkStart.begin(), linkStart.end() - 1);
    for (const CornerLinkGlobal& l : links)
      clusterLinks[fill[static_cast<size_t>(rootOf[static_cast<size_t>(l.a)])]++] = l;
  }
  std::vector<size_t> vertexRoots;  // clusters of two or more corners
  for (size_t root = 0; root < static_cast<size_t>(nc); ++root)
    if (memberStart[root + 1] - memberStart[root] >= 2) vertexRoots.push_back(root);

  // The default length scale of analyzeCorner (the largest control-box diagonal of the patches at the vertex), from
  // each patch's diagonal computed once (checkModel) instead of once per corner.

  // The vertices are analysed in parallel, each into its own slot, and listed in order of root.
  std::vector<std::optional<ModelCorner>> analysed(vertexRoots.size());
  const std::span<const Patch> patches(model.patches);
  forEachIndex(vertexRoots.size(), threads, [&](size_t v) {
    const size_t root = vertexRoots[v];
    const std::span<const int> cluster(members.data() + memberStart[root], memberStart[root + 1] - memberStart[root]);
    // Per-thread lists reused from vertex to vertex (analyzeCorner copies what it reports).
    thread_local std::vector<PatchCorner> corners;
    thread_local std::vector<CornerLink> cl;
    corners.clear();
    cl.clear();
    double scale = 0.0;
    for (int c : cluster) {
      corners.push_back(cornerOf(c));
      scale = std::max(scale, patchDiagonal[static_cast<size_t>(c / 4)]);
    }
    // Members are sorted: a corner's index in the cluster by binary search.
    auto local = [&](int c) {
      return static_cast<int>(std::lower_bound(cluster.begin(), cluster.end(), c) - cluster.begin());
    };
    for (size_t l = linkStart[root]; l < linkStart[root + 1]; ++l) {
      const CornerLinkGlobal& g = clusterLinks[l];
      cl.push_back({local(g.a), g.aEdge, local(g.b), g.bEdge});
    }
    CornerOptions co = cornerOptions;
    if (!co.lengthScale) co.lengthScale = scale > 0.0 && std::isfinite(scale) ? scale : 1.0;
    Result<CornerReport> r = analyzeCorner(patches, corners, cl, co);
    if (!r) return;  // cannot happen for valid indices and 3-D patches (checked before)
    ModelCorner& mc = analysed[v].emplace(ModelCorner{std::move(r).value()});
    if (!analyze) mc.report.fourPatch.reset();
  });
  std::vector<ModelCorner> out;
  out.reserve(analysed.size());
  for (std::optional<ModelCorner>& c : analysed)
    if (c) out.push_back(std::move(*c));
  return out;
}

}  // namespace

Result<EdgePairing> pairEdges(const Model& model, const ModelCheckOptions& options) {
  if (model.patches.empty()) return invalidInput("the model has no patches");
  const double diagonal = model.boundingBox().diagonal();
  const Tolerances tol = options.tolerances.value_or(Tolerances::forModelSize(diagonal));
  Result<Pairing> p = runPairing(model, diagonal, tol, options);
  if (!p) return p.status();
  return std::move(p->result);
}

Result<ModelCheckReport> checkModel(const Model& model, const ModelCheckOptions& options) {
  if (model.patches.empty()) return invalidInput("the model has no patches");
  ModelCheckReport report;
  // Each patch's control box, computed once: the model's box (Model::boundingBox's union, the patches in order and
  // then the curves: the same box), the seams' scale (analyzeSeam computes it per seam) and the vertices' default
  // length scale.
  std::vector<BoundingBox> patchBox(model.patches.size());
  forEachIndex(model.patches.size(), options.threads,
               [&](size_t p) { patchBox[p] = controlBox(model.patches[p].surface); });
  BoundingBox modelBox;
  for (const BoundingBox& b : patchBox) modelBox.add(b);
  for (const Curve& c : model.curves) modelBox.add(controlBox(c.curve));
  const double diagonal = modelBox.diagonal();
  report.tolerances = options.tolerances.value_or(Tolerances::forModelSize(diagonal));
  const Tolerances& tol = report.tolerances;
  Result<Pairing> pairing = runPairing(model, diagonal, tol, options);
  if (!pairing) return pairing.status();
  Pairing& P = pairing.value();
  report.pairingTolerance = P.result.pairingTolerance;
  report.freeEdges = std::move(P.result.freeEdges);
  report.degenerateEdges = std::move(P.result.degenerateEdges);
  report.coincidentEdges = std::move(P.result.coincidentEdges);

  std::vector<double> patchDiagonal(model.patches.size());
  for (size_t p = 0; p < patchDiagonal.size(); ++p) patchDiagonal[p] = patchBox[p].diagonal();

  // Seams: independent analyses, in parallel (TBB), stored in pairing order.
  SeamOptions seamOptions = options.seam;
  seamOptions.tol = tol;
  ModelCheckSummary& S = report.summary;
  report.seams.resize(P.result.pairs.size());
  auto analyzeOne = [&](size_t k) {
    const EdgePair& p = P.result.pairs[k];
    ModelSeam& ms = report.seams[k];
    ms.pair = p;
    if (!options.analyzeSeams) return;
    const Patch& a = model.patches[static_cast<size_t>(p.a.patch)];
    const Patch& b = model.patches[static_cast<size_t>(p.b.patch)];
    const std::optional<Interval> range = p.fullA ? std::nullopt : std::optional<Interval>(p.overlapA);
    Result<SeamReport> r =
        detail::analyzeSeamScaled(a, p.a.edge, b, p.b.edge, seamOptions, range,
                                  patchDiagonal[static_cast<size_t>(p.a.patch)],
                                  patchDiagonal[static_cast<size_t>(p.b.patch)]);
    if (r)
      ms.report = std::move(r).value();
    else
      ms.error = r.status();
  };
  if (options.threads == 1 || P.result.pairs.size() < 2) {
    for (size_t k = 0; k < P.result.pairs.size(); ++k) analyzeOne(k);
  } else {
    tbb::task_arena arena(options.threads > 0 ? options.threads : tbb::task_arena::automatic);
    arena.execute([&] {
      tbb::parallel_for(tbb::blocked_range<size_t>(0, P.result.pairs.size()), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t k = r.begin(); k != r.end(); ++k) analyzeOne(k);
      });
    });
  }

  CornerOptions co;
  co.tol = tol;
  const double cornerTol = options.cornerTolerance.value_or(tol.distance);
  report.corners = findCorners(model, P.edges, P.result.pairs, cornerTol, co, options.analyzeCorners, options.threads,
                               patchDiagonal);  // the same corners in the same order, moved once

  // Summary.
  S.seams = static_cast<int>(report.seams.size());
  S.corners = static_cast<int>(report.corners.size());
  S.freeEdges = static_cast<int>(report.freeEdges.size());
  S.degenerateEdges = static_cast<int>(report.degenerateEdges.size());
  S.coincidentEdgeGroups = static_cast<int>(report.coincidentEdges.size());
  report.overlapsSearched = options.findOverlaps && model.trimmedFaces == 0 && !model.brep;
  if (report.overlapsSearched) {
    OverlapOptions oo = options.overlap;
    oo.threads = options.threads;
    report.overlaps = findOverlaps(model, tol.distance, oo);
  }
  S.overlaps = static_cast<int>(report.overlaps.size());
  for (int k = 0; k < S.seams; ++k) {
    const ModelSeam& ms = report.seams[static_cast<size_t>(k)];
    if (!ms.report) {
      if (options.analyzeSeams) {
        ++S.failedSeams;
        S.worstGeometric = GeometricClass::kNone;
        S.worstParametric = ParametricClass::kNone;
        if (options.require) ++S.belowRequired;
      }
      continue;
    }
    const SeamReport& r = *ms.report;
    ++S.geometric[static_cast<size_t>(r.geometric)];
    ++S.parametric[static_cast<size_t>(r.parametric)];
    if (r.certified) ++S.certifiedSeams;
    S.worstGeometric = std::min(S.worstGeometric, r.geometric);
    S.worstParametric = std::min(S.worstParametric, r.parametric);
    if (S.g0Seam < 0 || r.g0Max > S.g0Max) S.g0Max = r.g0Max, S.g0Seam = k;
    if (S.g1Seam < 0 || r.g1MaxDeg > S.g1MaxDeg) S.g1MaxDeg = r.g1MaxDeg, S.g1Seam = k;
    if (S.g2Seam < 0 || r.g2Max > S.g2Max) S.g2Max = r.g2Max, S.g2Seam = k;
    S.g2RelMax = std::max(S.g2RelMax, r.g2RelMax);
    if (options.require && !meets(r.geometric, *options.require)) ++S.belowRequired;
  }
  for (const ModelCorner& c : report.corners) {
    const CornerReport& r = c.report;
    if (r.degenerate) ++S.degenerateCorners;
    if (r.normalSpreadDeg) S.normalSpreadMaxDeg = std::max(S.normalSpreadMaxDeg, *r.normalSpreadDeg);
    if (r.curvatureSpreadRel)
      S.cornerCurvatureSpreadRelMax = std::max(S.cornerCurvatureSpreadRelMax.value_or(0.0), *r.curvatureSpreadRel);
    if (r.fourPatch) {
      ++S.fourValentCorners;
      S.cornerG1ResidualMax = std::max(S.cornerG1ResidualMax, r.fourPatch->g1Residual);
      if (r.fourPatch->g2Residual)
        S.cornerG2ResidualMax = std::max(S.cornerG2ResidualMax.value_or(0.0), *r.fourPatch->g2Residual);
    }
  }
  return report;
}

Result<EdgePairing> pairEdgesWithin(const Model& model, const Tolerances& tol, double maxGap, double diagonal) {
  ModelCheckOptions mco;
  mco.tolerances = tol;
  mco.pairingRelTol = std::max(maxGap, tol.distance) / diagonal;
  mco.analyzeSeams = false;
  mco.analyzeCorners = false;
  return pairEdges(model, mco);
}

void scaleLengths(ModelCheckReport& r, double scale) {
  r.tolerances.distance *= scale;
  r.pairingTolerance *= scale;
  for (ModelSeam& s : r.seams) {
    s.pair.distance *= scale;
    if (s.report) scaleLengths(*s.report, scale);
  }
  for (ModelCorner& c : r.corners) scaleLengths(c.report, scale);
  for (DegenerateEdge& d : r.degenerateEdges) d.point *= scale;
  for (CoincidentEdges& c : r.coincidentEdges) c.point *= scale;
  for (FaceOverlap& o : r.overlaps) {
    o.maxDistance *= scale;
    o.point *= scale;
  }
  r.summary.g0Max *= scale;
  r.summary.g2Max /= scale;  // 1/length
}

}  // namespace seam
