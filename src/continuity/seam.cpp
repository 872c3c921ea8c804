// Certified seam analysis. See include/seam/continuity/seam.h for conventions and docs/algorithms/johansson.md for
// the derivations (Lemma 1, Lemma 2, the shape-operator jump of a G1 seam and the Bernstein bounds).
//
// The analysis of a patch seam, step by step (analyzeSeamScaled): the sides and their edge jets (seam_side.h), the
// overlap and the correspondence (seam_correspondence.h, seam_shared_rows.cpp), the samples and their maxima, the
// certified bounds on the exact pieces (seam_piece.h), the ends and the classes. Seams along parameter curves
// (trimmed B-rep edges) are in pcurve_seam.cpp.
#include "seam/continuity/seam.h"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <optional>
#include <utility>
#include <vector>

#include "continuity/closest_excess.h"
#include "continuity/curve_projection.h"
#include "continuity/sampling.h"
#include "continuity/seam_correspondence.h"
#include "continuity/seam_internal.h"
#include "continuity/seam_piece.h"
#include "continuity/seam_side.h"
#include "core/bernstein_internal.h"

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

using detail::kAngleBoundFloor;
using detail::kFlatCurvatureRatio;
using detail::kIdentityBoundFactor;
using detail::kRadToDeg;
using detail::Piece;
using detail::PointMeasures;
using detail::refinedMaximum;
using detail::SeamCorrespondence;
using detail::SeamOverlap;
using detail::Side;
// The steps' functions (seam_side.h, seam_piece.h, seam_correspondence.h).
using detail::certifyMax;
using detail::controlDiagonal;
using detail::identicalBoundaryRows;
using detail::measureAt;
using detail::measureSharedAt;

/// The largest angle between two directions, degrees.
constexpr double kStraightAngleDeg = 180.0;
/// |slope| of an affine correspondence within this of 1 means the edge parametrisations match (parametric C^k).
constexpr double kMatchingSlopeTol = 1e-9;

struct SampleSet {
  std::vector<double> t, s;
  std::vector<PointMeasures> m;
};

/// One patch seam's analysis after its correspondence is known: the samples, their maxima, the certified bounds
/// and the ends, each step filling its part of the report.
struct SeamAnalysis {
  SeamAnalysis(const Side& sideA, const Side& sideB, const SeamOptions& options, const SeamOverlap& overlap,
               SeamCorrespondence& correspondence, SeamReport& report, SampleSet& samples, double floor,
               double patchScale)
      : A(sideA), B(sideB), opt(options), ov(overlap), corr(correspondence), rep(report), S(samples),
        exactFloor(floor), scale(patchScale), sgn(report.reversed ? -1.0 : 1.0) {}

  void sample();
  void sampledMaxima();
  /// The shared-row route's bounds; false when the seam needs the general route instead.
  bool sharedRowBounds();
  void certifiedBounds();
  void includeEnds();
  void classify();

  const Side& A;
  const Side& B;
  const SeamOptions& opt;
  const SeamOverlap& ov;
  SeamCorrespondence& corr;
  SeamReport& rep;
  SampleSet& S;
  const double exactFloor, scale, sgn;
  double curvRef = 0.0;                  // curvature reference of the relative G2 values
  double c1s = 0.0, c2s = 0.0;           // the sampled derivative scales of the C1 / C2 mismatches
  bool c1Identity = false, c2Identity = false;
  /// Parameter intervals between a sample where the curvature is not measured (a pole: the chart is too
  /// ill-conditioned, the normal vanishes) and its neighbour where it is. The G2 jump is undefined at the pole and
  /// may grow without bound toward it: its maximum is not refined into these intervals (issue 35 §2).
  std::vector<Interval> poleIntervals;

  Vec3 pointOnA(double t) const;
  double sOfT(double t, double guess) const;
  double sAt(double t) const;
  /// B's parameter at t by projection from the nearest sample's partner (a starting guess for the gap's own
  /// closest-point search: the same guess as before sAt followed the correspondence, so that the worst point of a
  /// constant gap, decided by round-off, stays where it was at every scale).
  double sProjectedAt(double t) const;
  PointMeasures pointMeasure(double t) const { return measureAt(A, t, B, sAt(t), sgn); }
  template <class Get>
  std::pair<double, double> refined(Get get, bool awayFromPoles = false) const;
  bool nearPole(double t) const;
  std::optional<double> poleNextTo(double t) const;
  double tAt(int piece, double x) const { return corr.pieces[static_cast<size_t>(piece)].tOf.scalar(x); }

  void certifiedSampleParameters();
  void projectedSampleParameters();
  void sortSamples();
  void sampledGap();
  void sampledRanges();
  bool certifyG1();
  void g1IdentityFrom(bool ok);
  void closestPointAngles();
  void certifyG2();
  void g2Bounds();
  void refineG2();
  void parametricIdentities();
};

// A's point at t for the reported worst points: a0 or a1 when t is that end of the range, bit for bit (the same
// call on the same argument; the sign of a zero compared too), else evaluated.
Vec3 SeamAnalysis::pointOnA(double t) const {
  const auto sameBits = [](double x, double y) {
    return std::bit_cast<std::uint64_t>(x) == std::bit_cast<std::uint64_t>(y);
  };
  if (sameBits(t, ov.da.lo)) return ov.a0;
  if (sameBits(t, ov.da.hi)) return ov.a1;
  return A.curve.point3(t);
}

double SeamAnalysis::sOfT(double t, double guess) const {
  return detail::closestPoint(B.curve, A.curve.point3(t), rep.overlapB, guess).t;
}

double SeamAnalysis::sAt(double t) const {
  // A certified correspondence gives B's parameter itself (a projection would only reach it to round-off, at the
  // price of a Newton iteration on B's edge: a third of the check of a network whose seams are kinks, issue 37).
  if (corr.certified)
    if (const std::optional<double> s = detail::partnerThroughPieces(corr.pieces, t)) return *s;
  return sProjectedAt(t);
}

double SeamAnalysis::sProjectedAt(double t) const {
  // Start from the nearest sample's partner and project.
  const auto it = std::lower_bound(S.t.begin(), S.t.end(), t);
  const size_t i = std::min<size_t>(static_cast<size_t>(it - S.t.begin()), S.t.size() - 1);
  return sOfT(t, S.s[i]);
}

// Sampled maxima follow the correspondence; the refinement (which re-projects) only where the
// correspondence is itself a projection. Certified seams are refined by the subdivision of the bounds instead.
template <class Get>
std::pair<double, double> SeamAnalysis::refined(Get get, bool awayFromPoles) const {
  if (corr.certified && !S.m.empty()) {  // std::max_element's choice (the first maximum), without a vector
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
  if (corr.certified) {
    const auto it = std::max_element(v.begin(), v.end());
    const size_t i = static_cast<size_t>(it - v.begin());
    return std::pair{S.t[i], *it};
  }
  return refinedMaximum(S.t, v, [&](double t) { return awayFromPoles && nearPole(t) ? 0.0 : get(pointMeasure(t)); });
}

// Inside an interval between a pole sample and its neighbour.
bool SeamAnalysis::nearPole(double t) const {
  return std::any_of(poleIntervals.begin(), poleIntervals.end(),
                     [t](const Interval& iv) { return t > iv.lo && t < iv.hi; });
}

// The pole sample next to the sample at t, if any (t the other end of a pole interval).
std::optional<double> SeamAnalysis::poleNextTo(double t) const {
  for (const Interval& iv : poleIntervals) {
    if (t == iv.lo) return iv.hi;
    if (t == iv.hi) return iv.lo;
  }
  return std::nullopt;
}

// Certified seams: evenly spaced samples per piece (and per span of shared rows).
void SeamAnalysis::certifiedSampleParameters() {
  // Plots (keepSamples) get the dense sampling; otherwise the bound subdivision does the refining.
  const int start = corr.corrBound <= exactFloor ? opt.certifiedSamplesPerPiece : 2 * opt.certifiedSamplesPerPiece;
  const int perPiece = std::max(opt.keepSamples ? opt.samplesPerSpan : start, 2);
  // Shared rows: half as many samples per span (issue 16 goal 2). The gap, angle and curvature jump there are
  // identities (sharedRowBounds); the samples give only the curvature reference of the relative G2 values (whose
  // numerators are round-off bounds: dividing an upper bound by a curvature <= the seam's largest keeps it an
  // upper bound) and the sampled C1/C2 mismatch |lambda - 1| |A_out| of a constant lambda. The plots keep all.
  const int perShared = opt.keepSamples ? perPiece : std::max(perPiece / 2, 2);
  const size_t m = A.spans.size();
  const size_t count = ((corr.shared ? m : 0) + corr.pieces.size()) * static_cast<size_t>(perPiece + 1);
  S.t.reserve(count);
  S.s.reserve(count);
  if (corr.shared)  // the spans correspond one to one, each by the identity of its local parameter
    for (size_t k = 0; k < m; ++k) {
      const Interval sa = A.spans[k], sb = B.spans[rep.reversed ? m - 1 - k : k];
      for (int i = 0; i <= perShared; ++i) {
        const double x = static_cast<double>(i) / perShared;
        S.t.push_back((1.0 - x) * sa.lo + x * sa.hi);
        S.s.push_back(rep.reversed ? x * sb.lo + (1.0 - x) * sb.hi : (1.0 - x) * sb.lo + x * sb.hi);
      }
    }
  for (const Piece& pc : corr.pieces)
    for (int i = 0; i <= perPiece; ++i) {
      const double x = static_cast<double>(i) / perPiece;
      S.t.push_back(pc.tOf.scalar(x));
      S.s.push_back(pc.sOf.scalar(x));
    }
}

// Seams without a certified correspondence: samplesPerSpan per span of A, B's parameter by projection.
void SeamAnalysis::projectedSampleParameters() {
  const int perSpan = std::max(opt.samplesPerSpan, 2);
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
void SeamAnalysis::sortSamples() {
  if (std::is_sorted(S.t.begin(), S.t.end())) return;
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

// ---- dense sampling (the sampled worst values, and the whole story when not certified), then the curvature
// reference for relative G2 values: the largest curvature on the seam, floored at "flat".
void SeamAnalysis::sample() {
  S.t.clear();
  S.s.clear();
  S.m.clear();
  if (corr.certified)
    certifiedSampleParameters();
  else
    projectedSampleParameters();
  sortSamples();
  S.m.reserve(S.t.size());
  // Shared rows: the angle and the curvature jump are not sampled, but the plots (keepSamples) get every measure.
  const bool sharedSamples = corr.shared && !opt.keepSamples;
  const bool sameBoundary = sharedSamples && identicalBoundaryRows(A, B, rep.reversed);
  for (size_t i = 0; i < S.t.size(); ++i)
    S.m.push_back(sharedSamples ? measureSharedAt(A, S.t[i], B, S.s[i], sgn, corr.shared->lambda, sameBoundary)
                                : measureAt(A, S.t[i], B, S.s[i], sgn));
  const double flat = kFlatCurvatureRatio / std::max(scale, std::numeric_limits<double>::min());
  curvRef = flat;
  for (const auto& m : S.m) curvRef = std::max(curvRef, m.curvature);
  for (size_t i = 0; i + 1 < S.m.size(); ++i)
    if (S.m[i].curvatureOk != S.m[i + 1].curvatureOk) poleIntervals.push_back({S.t[i], S.t[i + 1]});
}

// G0 sampled: closest-point distance both ways (parametrisation independent). On an exact correspondence the
// distance is below the certified round-off bound already, and the projections are skipped.
void SeamAnalysis::sampledGap() {
  if (corr.corrBound <= exactFloor) {
    const auto it = std::max_element(S.m.begin(), S.m.end(), [](auto& x, auto& y) { return x.g0 < y.g0; });
    rep.g0Sampled = it->g0;
    rep.g0Worst = {S.t[static_cast<size_t>(it - S.m.begin())], it->point};
    return;
  }
  std::vector<double> d1(S.t.size());
  for (size_t i = 0; i < S.t.size(); ++i)
    d1[i] = detail::closestPoint(B.curve, S.m[i].point, rep.overlapB, S.s[i]).distance;
  auto f = [&](double t) {
    return detail::closestPoint(B.curve, A.curve.point3(t), rep.overlapB, sProjectedAt(t)).distance;
  };
  auto [tw, w] = refinedMaximum(S.t, d1, f);
  double other = 0.0;
  for (size_t i = 0; i < S.s.size(); ++i)
    other = std::max(other, detail::closestPoint(A.curve, B.curve.point3(S.s[i]), rep.overlapA,
                                                 S.t[i]).distance);
  rep.g0Sampled = std::max(w, other);
  rep.g0Worst = {tw, pointOnA(tw)};
}

// The sampled ranges of lambda and kappa, the largest Lemma 2 residual and the C1 / C2 mismatches.
void SeamAnalysis::sampledRanges() {
  double lamLo = std::numeric_limits<double>::infinity(), lamHi = -lamLo, kapLo = lamLo, kapHi = -lamLo;
  double c1 = 0.0, c2 = 0.0;
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
}

// Sampled maxima, refined (detail::refineMaxParabolic) (s follows t through the correspondence or projection).
void SeamAnalysis::sampledMaxima() {
  bool anyDegenerate = false;
  for (const auto& m : S.m) anyDegenerate |= !m.curvatureOk;
  if (anyDegenerate) rep.notes.push_back("the normal vanishes somewhere on the seam (pole or degenerate edge)");
  sampledGap();
  {
    auto [tw, w] = refined([](const PointMeasures& m) { return m.normalsOk ? m.g1 : 0.0; });
    rep.g1SampledDeg = w * kRadToDeg;
    rep.g1Worst = {tw, pointOnA(tw)};
  }
  {
    auto [tw, w] = refined([](const PointMeasures& m) { return m.curvatureOk ? m.g2 : 0.0; }, true);
    rep.g2Sampled = w;
    rep.g2RelSampled = w / curvRef;
    rep.g2Worst = {tw, pointOnA(tw)};
  }
  sampledRanges();
}

// Bounds from the rows (sharedRowBounds): G1 and G2 hold as identities up to rounding, with these bounds. A G2
// bound above the identity floor of this seam's curvature, or samples that contradict the identities, send the
// seam to the general route (rare: the rows agree to rounding): false then.
bool SeamAnalysis::sharedRowBounds() {
  const detail::SharedRowBounds& shared = *corr.shared;
  if (!(shared.g2 <= kIdentityBoundFactor * kIdentityRelTol * curvRef) || !(rep.g1SampledDeg <= opt.tol.angleDeg) ||
      !(rep.g2Sampled <= opt.tol.curvatureRel * curvRef))
    return false;
  rep.g0Max = std::max(corr.corrBound, rep.g0Sampled);
  rep.g1MaxDeg = std::max(shared.g1 * kRadToDeg, rep.g1SampledDeg);
  rep.g1Identity = true;
  if (!opt.certifyG2) {
    rep.notes.push_back("G2 not certified (not requested): the G2 values are samples");
  } else {
    rep.g2Identity = true;
    rep.g2Max = std::max(shared.g2, rep.g2Sampled);
  }
  c1Identity = shared.c1 <= kIdentityRelTol * c1s;
  c2Identity = shared.c2 <= kIdentityRelTol * std::max(c2s, c1s);
  return true;
}

// G2 values that are not bounded: the sampled maximum refined by golden section, as for uncertified seams.
void SeamAnalysis::refineG2() {
  std::vector<double> v(S.m.size());
  for (size_t i = 0; i < v.size(); ++i) v[i] = S.m[i].curvatureOk ? S.m[i].g2 : 0.0;
  auto [tw, w] = refinedMaximum(S.t, v, [&](double t) {
    if (nearPole(t)) return 0.0;
    const PointMeasures m = measureAt(A, t, B, sAt(t), sgn, true);  // the curvature jump alone
    return m.curvatureOk ? m.g2 : 0.0;
  }, detail::kG2RefineRelTol);  // every caller is on the certified route
  if (w > rep.g2Sampled) {
    rep.g2Sampled = w;
    rep.g2Worst = {tw, pointOnA(tw)};
  }
  rep.g2Max = std::max(rep.g2Max, rep.g2Sampled);
}

// The certified angle bound; false when some interval could not be bounded (a vanishing normal).
bool SeamAnalysis::certifyG1() {
  bool ok = true;
  double best = rep.g1SampledDeg / kRadToDeg, bx = 0.0;
  int bp = -1;
  std::pair<int, double> unclosed{-1, 0.0};
  const double bound = certifyMax(corr.pieces, detail::g1BoundByRatios, detail::g1Value, best, bx, bp, kAngleBoundFloor,
                                  opt, ok, nullptr, &unclosed, opt.tol.angleDeg / kRadToDeg);
  rep.g1MaxDeg = bound * kRadToDeg;
  if (bp >= 0 && best * kRadToDeg > rep.g1SampledDeg) {
    rep.g1SampledDeg = best * kRadToDeg;
    const double t = tAt(bp, bx);
    rep.g1Worst = {t, pointOnA(t)};
  }
  if (!ok) {
    // The angle measured where the normals are defined stands; g1IdentityFrom decides what the seam is.
    rep.g1PoleT = unclosed.first >= 0 ? tAt(unclosed.first, unclosed.second) : rep.g1Worst.t;
    rep.g1MaxDeg = rep.g1SampledDeg;
  }
  return ok;
}

// G1 identity: NA x NB == 0 and no fold; or, where composition and elevation cost more digits than the
// coefficient test allows, a closed certified angle bound at the round-off floor of the subdivision. `ok`: the
// angle bound closed.
void SeamAnalysis::g1IdentityFrom(bool ok) {
  // A sample with the normals more than 90 degrees apart is a fold too (besides N_A . N_B below zero on a piece).
  bool sampledFold = false;
  for (const auto& m : S.m)
    if (m.normalsOk && m.g1 > std::numbers::pi / 2) sampledFold = true;
  rep.g1Identity = detail::g1IdentityOf(corr.pieces, ok, rep.g1MaxDeg, sampledFold);
  if (!ok && !rep.g1Identity) {
    // No bound through the vanishing normal, no identity: the angle is measured (issue 35 §2), never certified.
    rep.certified = corr.certified = false;
    rep.notes.push_back(fmt::format("not certified: a normal vanishes at t = {:.6g}, where the G1 bound cannot close; "
                                    "the angle shown ({:.6g} deg) is measured where both normals are defined",
                                    *rep.g1PoleT, rep.g1SampledDeg));
  }
  if (rep.g1Identity) rep.g1PoleT.reset();
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
    rep.certified = corr.certified = false;
    rep.notes.push_back(fmt::format("not certified: the G1 identity test and the sampled angle ({:.6g} deg) "
                                    "disagree next to a vanishing normal",
                                    rep.g1SampledDeg));
  }
}

// Across a gap the correspondence pairs A(t) with B(phi(t)), which is not B's point closest to A(t): the angle
// between the faces is read at closest points (the dense references, OpenCASCADE's probes), and next to a corner
// the two differ by more than the bound's slack (CornerJoin3: 3.55 deg paired, 6.79 deg at closest points). The
// certified angle bound grows by the closest-point excess (closest_excess.h, as on the pcurve route) so that it
// bounds both; where that excess cannot be bounded (B's edge curving too much for the gap) the angle is not
// certified. An exact correspondence (gap bound at the round-off floor) pairs closest points up to round-off.
void SeamAnalysis::closestPointAngles() {
  if (!(corr.corrBound > exactFloor) || corr.pieces.empty()) return;
  std::vector<detail::ClosestLeaf> leaves;
  leaves.reserve(corr.pieces.size());
  for (size_t i = 0; i < corr.pieces.size(); ++i) {
    const Piece& pc = corr.pieces[i];
    leaves.push_back(
        detail::closestLeaf(pc.xa, pc.wa, pc.xb, pc.wb, pc.na, pc.nb, i, pc.tOf.scalar(0.0), pc.tOf.scalar(1.0)));
  }
  const double excess =
      detail::closestExcess(leaves, std::max(kAngleBoundFloor, opt.boundRelGap * rep.g1MaxDeg / kRadToDeg),
                            rep.g1MaxDeg / kRadToDeg, detail::kPatchClosestRefinement);
  // No angle exceeds 180 deg: a bound that reaches it holds, and where the paired points' normals are already
  // opposite to within the angle tolerance, 180 is the angle whatever the excess (teaspoon.bpt: a 180 deg crease
  // across a gap of 0.0089, next to a pole where B's normal turns without bound). A smaller paired angle with an
  // excess that cannot be bounded is not certified: 180 would hold but say nothing.
  if (rep.g1MaxDeg + excess * kRadToDeg >= kStraightAngleDeg &&
      (std::isfinite(excess) || rep.g1MaxDeg >= kStraightAngleDeg - opt.tol.angleDeg)) {
    rep.g1ClosestExcessDeg = kStraightAngleDeg - rep.g1MaxDeg;
    rep.g1MaxDeg = kStraightAngleDeg;
    return;
  }
  if (std::isfinite(excess)) {
    rep.g1ClosestExcessDeg = excess * kRadToDeg;
    if (rep.g1ClosestExcessDeg > 0.0)
      rep.notes.push_back(fmt::format("across the gap the angle between closest points exceeds the paired points' "
                                      "({:.6g} deg) by at most {:.3g} deg, included",
                                      rep.g1MaxDeg, rep.g1ClosestExcessDeg));
    rep.g1MaxDeg += rep.g1ClosestExcessDeg;
    // An identity along the pairing says nothing of the closest points once they differ.
    if (rep.g1Identity && rep.g1ClosestExcessDeg > kIdentityBoundFactor * kAngleBoundFloor * kRadToDeg)
      rep.g1Identity = false;
    return;
  }
  rep.certified = corr.certified = false;
  rep.notes.push_back(fmt::format("not certified: across the gap of {:.6g} the angle between closest points cannot "
                                  "be bounded from the angle between the points the correspondence pairs ({:.6g} deg); "
                                  "the angle shown is sampled",
                                  corr.corrBound, rep.g1MaxDeg));
  rep.g1MaxDeg = rep.g1SampledDeg;
}

// The G2 identity and bound of an exactly G1 seam whose Lemma 2 polynomials were formed.
void SeamAnalysis::g2Bounds() {
  rep.g2Identity = true;
  for (const Piece& pc : corr.pieces)
    if (pc.rho.num.maxAbsCoeff() > kIdentityRelTol * pc.rhoScale) rep.g2Identity = false;
  double best = rep.g2Sampled, bx = 0.0;
  int bp = -1;
  bool g2ok = true;
  // A midpoint whose chart is too ill-conditioned for curvature (next to a pole) means the quotient bound
  // cannot close there (it divides by the vanishing normal): stop at once instead of spending maxBoundWork. So does
  // a midpoint between a pole sample and its neighbour: the jump there is no value to print (issue 35 §2).
  bool illConditioned = false;
  const auto g2Checked = [this, &illConditioned](const Piece& pc, double x) {
    const auto v = nearPole(pc.tOf.scalar(x)) ? std::nullopt : detail::g2ValueIfDefined(pc, x);
    if (!v) illConditioned = true;
    return v.value_or(0.0);
  };
  const double bound = certifyMax(corr.pieces, detail::g2Bound, g2Checked, best, bx, bp, kIdentityRelTol * curvRef,
                                  opt, g2ok, &illConditioned);
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
}

// G2: only meaningful for a G1 seam (else sampled, with a note).
void SeamAnalysis::certifyG2() {
  bool g2Ready = rep.g1Identity;
  for (const Piece& pc : corr.pieces) g2Ready = g2Ready && pc.g2Available;
  if (!opt.certifyG2) {
    rep.notes.push_back("G2 not certified (not requested): the G2 values are samples");
  } else if (g2Ready) {
    g2Bounds();
  } else {
    if (!rep.g1Identity)
      rep.notes.push_back("not exactly G1: the G2 jump is sampled (refined maximum)");
    else
      rep.notes.push_back(fmt::format("the G2 polynomial exceeds degree {} (maxCertifiedDegree): G2 is sampled",
                                      opt.maxCertifiedDegree));
    refineG2();
  }
}

// Parametric identities: certified bounds of |B'_u - A_out| and |B'_uu - A'_uu| at round-off level.
void SeamAnalysis::parametricIdentities() {
  c1Identity = c2Identity = true;
  for (const Piece& pc : corr.pieces) {
    const detail::SubPiece sp(pc, 0.0, 1.0);
    if (pc.c1.num.maxCoeffNorm() / sp.denLower(pc.c1) > kIdentityRelTol * c1s) c1Identity = false;
    if (pc.c2.num.maxCoeffNorm() / sp.denLower(pc.c2) > kIdentityRelTol * std::max(c2s, c1s)) c2Identity = false;
  }
}

// ---- certified bounds and identities on the exact pieces (general route).
void SeamAnalysis::certifiedBounds() {
  // The correspondence search already certified the distance bound on these very pieces.
  rep.g0Max = std::max(corr.corrBound, rep.g0Sampled);
  const bool g1Closed = certifyG1();
  g1IdentityFrom(g1Closed);
  if (g1Closed) closestPointAngles();
  certifyG2();
  // Connecting functions: from the exact Lemma 1 polynomials instead of the start samples.
  if (rep.g1Identity) {
    detail::lemma1Ranges(corr.pieces, rep.lambdaRange, rep.kappaRange);
    // The Lemma 2 residual refined on the pieces as well: the start samples alone came 3.6 % below a dense
    // reference (SeamLemma1.G1NotG2WithRandomLambdaAndKappa, the case Clang's argument order draws).
    if (const auto res = detail::lemma2ResidualMax(corr.pieces))
      rep.g2ResidualMax = std::max(rep.g2ResidualMax, *res);
  }
  parametricIdentities();
}

// ---- the ends: the gap of a seam includes the distance between its matched end points.
void SeamAnalysis::includeEnds() {
  rep.g2RelMax = rep.g2Max / curvRef;
  rep.g2RelSampled = rep.g2Sampled / curvRef;
  rep.endMismatch = ov.endMismatch;
  if (ov.endMismatch > rep.g0Max) {
    rep.notes.push_back(fmt::format("the edges' end points are {:.6g} apart at t = {:.6g}, more than the gap of {:.6g} "
                                    "between the edges elsewhere: one edge runs past the other; the gap shown "
                                    "includes the ends",
                                    ov.endMismatch, ov.endMismatchT, rep.g0Max));
    rep.g0Max = ov.endMismatch;
    rep.g0Worst = {ov.endMismatchT, ov.endMismatchPoint};
  }
  rep.g0Sampled = std::max(rep.g0Sampled, ov.endMismatch);
}

// ---- classification.
void SeamAnalysis::classify() {
  const auto& tol = opt.tol;
  // The largest G2 jump is the sample next to a pole: it may grow toward the pole, where it is undefined.
  const std::optional<double> pole =
      rep.g2Identity || !(rep.g2Sampled > 0.0) ? std::nullopt : poleNextTo(rep.g2Worst.t);
  if (pole)
    rep.notes.push_back(fmt::format("the curvature jump is largest next to the pole at t = {:.6g} (at t = {:.6g}) "
                                    "and is undefined at the pole: the G2 values shown are those away from it",
                                    *pole, rep.g2Worst.t));
  reconcileVerdict(rep, tol);
  // G2 is never claimed on samples that stop short of a pole toward which the jump grows (issue 35 §2).
  if (pole && !rep.g2Identity && rep.geometric == GeometricClass::kG2) {
    rep.geometric = GeometricClass::kG1;
    rep.notes.push_back("G2 not claimed: the curvature jump grows toward a pole, where it is undefined");
  }
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
  SeamOverlap overlap;
  if (!findOverlap(A, B, aRange, diagA, diagB, rep, overlap))
    return Status(ErrorCode::kNotFound, fmt::format("{}: the edges do not overlap", label()));
  const double exactFloor = exactCorrespondenceFloor(std::max(diagA, diagB));
  SeamCorrespondence corr = findCorrespondence(A, B, opt, exactFloor, rep);
  // Per-thread storage reused from seam to seam (no allocation once grown). Nothing else on this thread uses it
  // while the seam is analysed: the one nested analysis (the general route below) returns its report directly.
  thread_local SampleSet sampleScratch;
  // The plots' dense samples (keepSamples) are measured apart, on a copy of the report, before the bounds refine the
  // correspondence: the values of the report's table are then those of `seam check`, bit for bit (issue 38 §5);
  // with the dense samples in the analysis the bounds started from other samples and differed by up to
  // boundRelGap (fan seam 11: 1.461 against 1.4575 degrees).
  std::vector<SeamSample> plotSamples;
  if (opt.keepSamples) {
    SeamReport scratch = rep;
    SampleSet dense;
    SeamAnalysis plot(A, B, opt, overlap, corr, scratch, dense, exactFloor, scale);
    plot.sample();
    plot.sampledRanges();
    plotSamples = std::move(scratch.samples);
  }
  SeamOptions base = opt;
  base.keepSamples = false;
  SeamAnalysis analysis(A, B, base, overlap, corr, rep, sampleScratch, exactFloor, scale);
  analysis.sample();
  analysis.sampledMaxima();
  rep.certified = corr.certified;
  rep.g0Max = rep.g0Sampled;
  rep.g1MaxDeg = rep.g1SampledDeg;
  rep.g2Max = rep.g2Sampled;
  if (corr.certified && corr.shared) {
    if (!analysis.sharedRowBounds()) {
      SeamOptions general = opt;
      general.sharedRows = false;
      return analyzeSeamScaled(pa, ea, pb, eb, general, aRange, patchDiagA, patchDiagB);
    }
  } else if (corr.certified) {
    analysis.certifiedBounds();
  }
  analysis.includeEnds();
  analysis.classify();
  // The curvature jump is not plotted where the table does not measure it: between a pole and the analysis' nearest
  // sample where the curvature is measured (poleIntervals). The denser plot gets closer to the pole, where the jump
  // is round-off over a vanishing normal and grows without bound (issue 35 §2).
  for (SeamSample& x : plotSamples)
    for (const Interval& iv : analysis.poleIntervals)
      if (x.t > std::min(iv.lo, iv.hi) && x.t < std::max(iv.lo, iv.hi)) {
        x.g2 = x.g2Rel = std::numeric_limits<double>::quiet_NaN();
        break;
      }
  rep.samples = std::move(plotSamples);
  return rep;
}

}  // namespace detail

void scaleLengths(SeamReport& r, double scale) {
  r.g0Max *= scale;
  r.g0Sampled *= scale;
  r.endMismatch *= scale;
  r.g2Max /= scale;  // 1/length
  r.g2Sampled /= scale;
  r.g2ResidualMax *= scale;  // a second derivative over squared parameters: a length
  for (WorstLocation* w : {&r.g0Worst, &r.g1Worst, &r.g2Worst}) w->point *= scale;
  for (SeamSample& x : r.samples) {
    x.g0 *= scale;
    x.g2 /= scale;
  }
}

}  // namespace seam
