// `seam join`: method selection, the paper's methods in edge frames, the least-squares join, before/after analysis.
#include "seam/repair/join.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <limits>
#include <optional>
#include <queue>
#include <utility>
#include <vector>

#include "repair/frame_internal.h"
#include "repair/join_internal.h"
#include "seam/continuity/model_check.h"
#include "seam/core/bernstein.h"
#include "seam/regularity/defect_search.h"
#include "seam/repair/bicubic.h"

namespace seam {

std::string_view toString(JoinMethod m) {
  switch (m) {
    case JoinMethod::kAuto: return "auto";
    case JoinMethod::kBSpline: return "bspline";
    case JoinMethod::kBezierStrip: return "bezier-strip";
    case JoinMethod::kLeastSquares: return "least-squares";
  }
  return "?";
}

Result<JoinMethod> parseJoinMethod(std::string_view name) {
  for (JoinMethod m : {JoinMethod::kAuto, JoinMethod::kBSpline, JoinMethod::kBezierStrip, JoinMethod::kLeastSquares})
    if (name == toString(m)) return m;
  return invalidInput(fmt::format("unknown method \"{}\" (expected auto, bspline, bezier-strip or least-squares)", name));
}

Result<GeometricClass> parseContinuity(std::string_view name) {
  std::string s(name);
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
  if (s == "G0") return GeometricClass::kG0;
  if (s == "G1") return GeometricClass::kG1;
  if (s == "G2") return GeometricClass::kG2;
  return invalidInput(fmt::format("unknown continuity \"{}\" (expected G0, G1 or G2)", name));
}

Displacement controlPointDisplacement(const BSplineSurface& before, const BSplineSurface& after, double threshold) {
  const BSplineSurface ref = detail::expressedLike(before, after);
  Displacement d;
  if (ref.numU() != after.numU() || ref.numV() != after.numV()) {
    d.max = std::numeric_limits<double>::infinity();
    d.moved = static_cast<int>(after.points().rows());
    return d;
  }
  for (Eigen::Index r = 0; r < after.points().rows(); ++r) {
    const double dist = (after.points().row(r) - ref.points().row(r)).norm();
    const double dw = std::abs(after.weight(static_cast<int>(r) / after.numV(), static_cast<int>(r) % after.numV()) -
                               ref.weight(static_cast<int>(r) / ref.numV(), static_cast<int>(r) % ref.numV()));
    d.max = std::max(d.max, dist);
    if (dist > threshold || dw > kRoundoff) ++d.moved;
  }
  return d;
}

SurfaceDisplacement surfaceDisplacement(const BSplineSurface& before, const BSplineSurface& after, int grid) {
  const BSplineSurface ref = detail::expressedLike(before, after);
  SurfaceDisplacement d;
  if (ref.numU() != after.numU() || ref.numV() != after.numV()) {
    d.bound = d.sampled = std::numeric_limits<double>::infinity();
    return d;
  }
  const int nv = after.numV();
  const int pu = after.degreeU(), pv = after.degreeV();
  const std::vector<double>& ku = after.knotsU().values();
  const std::vector<double>& kv = after.knotsV().values();
  auto pt = [](const BSplineSurface& s, int i, int j) -> Vec3 { return s.points().row(i * s.numV() + j).head<3>(); };
  // Certified bound, knot cell by knot cell: S1 - S0 = sum a1_i (P1_i - P0_i) + sum (a1_i - a0_i) (P0_i - c) with
  // the rational basis functions a = w N / W; a1_i / a0_i lies in [1/rho, rho], rho = max r / min r, so
  // sum |a1_i - a0_i| <= rho - 1, and |P0_i - c| <= half the box diagonal (c its centre).
  for (int a = pu; a < after.numU(); ++a) {
    if (!(ku[static_cast<size_t>(a + 1)] > ku[static_cast<size_t>(a)])) continue;
    for (int b = pv; b < nv; ++b) {
      if (!(kv[static_cast<size_t>(b + 1)] > kv[static_cast<size_t>(b)])) continue;
      double moved = 0.0, rLo = std::numeric_limits<double>::infinity(), rHi = 0.0;
      BoundingBox box;
      for (int i = a - pu; i <= a; ++i)
        for (int j = b - pv; j <= b; ++j) {
          moved = std::max(moved, (pt(after, i, j) - pt(ref, i, j)).norm());
          const double r = after.weight(i, j) / ref.weight(i, j);
          rLo = std::min(rLo, r);
          rHi = std::max(rHi, r);
          box.add(pt(ref, i, j));
        }
      d.bound = std::max(d.bound, moved + (rHi / rLo - 1.0) * 0.5 * box.diagonal());
    }
  }
  d.sampled = sampledSurfaceDistance(before, after, grid);
  return d;
}

namespace {

/// One region of a knot cell for surfaceDisplacementSharp: the difference after - before on it as E / Q (Bernstein
/// forms over the region; Q empty for polynomial patches), with the certified bound max |E_k| / min Q_k.
struct DifferenceRegion {
  BernsteinPatch e, q;
  double bound = 0.0;
  bool operator<(const DifferenceRegion& o) const { return bound < o.bound; }
};

double regionBound(const BernsteinPatch& e, const BernsteinPatch& q) {
  const double top = e.coeffs().rowwise().norm().maxCoeff();
  if (q.coeffs().size() == 0) return top;
  const double low = q.coeffs().minCoeff();
  return low > 0.0 ? top / low : std::numeric_limits<double>::infinity();
}

/// |E / Q| at the region's corners (their coefficients are values) and centre: values of the true difference.
double regionSample(const BernsteinPatch& e, const BernsteinPatch& q) {
  double best = 0.0;
  const int du = e.degreeU(), dv = e.degreeV();
  const bool rational = q.coeffs().size() > 0;
  for (const auto& [i, j] : {std::pair{0, 0}, std::pair{0, dv}, std::pair{du, 0}, std::pair{du, dv}}) {
    const double w = rational ? q.coeff(i, j)(0) : 1.0;  // E and Q have the same degrees
    if (w > 0.0) best = std::max(best, e.coeff(i, j).norm() / w);
  }
  const VecX mid = e(0.5, 0.5);
  const double w = rational ? q(0.5, 0.5)[0] : 1.0;
  if (w > 0.0) best = std::max(best, mid.norm() / w);
  return best;
}

/// The Bernstein forms of a Bezier piece: w P and w (BezierPatch::homogeneous), or P and nothing when polynomial.
std::pair<BernsteinPatch, BernsteinPatch> homogeneousOf(const BezierPatch& b, bool rational) {
  const BernsteinPatch h = b.homogeneous();  // columns x, y, z and, last, the weight (1 for a polynomial piece)
  const int w = h.dim() - 1;
  BernsteinPatch n(h.degreeU(), h.degreeV(), h.coeffs().leftCols(w));
  if (!rational) return {std::move(n), BernsteinPatch()};
  return {std::move(n), BernsteinPatch(h.degreeU(), h.degreeV(), h.coeffs().rightCols(1))};
}

}  // namespace

SurfaceDisplacement surfaceDisplacementSharp(const BSplineSurface& before, const BSplineSurface& after, double ratio,
                                             int maxSplits) {
  SurfaceDisplacement coarse = surfaceDisplacement(before, after);
  if (!std::isfinite(coarse.bound)) return coarse;
  const BSplineSurface ref = detail::expressedLike(before, after);
  const std::vector<BezierPatchPiece> p0 = ref.bezierPatches(), p1 = after.bezierPatches();
  if (p0.size() != p1.size()) return coarse;
  const bool rational = ref.isRational() || after.isRational();
  std::priority_queue<DifferenceRegion> open;
  double sampled = coarse.sampled;
  for (size_t k = 0; k < p0.size(); ++k) {
    const auto [n0, w0] = homogeneousOf(p0[k].patch, rational);
    const auto [n1, w1] = homogeneousOf(p1[k].patch, rational);
    DifferenceRegion r;
    if (rational) {
      BernsteinPatch e = product(n1, w0);
      e.coeffs() -= product(n0, w1).coeffs();
      r.e = std::move(e);
      r.q = product(w0, w1);
    } else {
      r.e = n1;
      r.e.coeffs() -= n0.coeffs();
    }
    r.bound = regionBound(r.e, r.q);
    sampled = std::max(sampled, regionSample(r.e, r.q));
    open.push(std::move(r));
  }
  int splits = 0;
  while (!open.empty() && open.top().bound > ratio * sampled && splits < maxSplits) {
    const DifferenceRegion top = open.top();
    open.pop();
    ++splits;
    for (const auto& [u0, u1, v0, v1] : {std::array{0.0, 0.5, 0.0, 0.5}, std::array{0.5, 1.0, 0.0, 0.5},
                                          std::array{0.0, 0.5, 0.5, 1.0}, std::array{0.5, 1.0, 0.5, 1.0}}) {
      DifferenceRegion c;
      c.e = top.e.restricted(u0, u1, v0, v1);
      if (rational) c.q = top.q.restricted(u0, u1, v0, v1);
      c.bound = regionBound(c.e, c.q);
      sampled = std::max(sampled, regionSample(c.e, c.q));
      open.push(std::move(c));
    }
  }
  SurfaceDisplacement d;
  d.sampled = sampled;
  d.bound = std::min(coarse.bound, open.empty() ? sampled : std::max(open.top().bound, sampled));
  return d;
}

namespace {

/// The normal numerator of a Bezier piece (normalTurnover): S_u x S_v, or w^4 S_u x S_v for a rational piece.
BernsteinPatch normalNumerator(const BezierPatch& b) {
  const auto [su, sv] = partialNumerators(b.homogeneous(), b.isRational());
  return cross(su, sv);
}

/// `a` and `b` in one spline space (the larger degrees, the union of their knots), or nothing when their domains
/// differ.
std::optional<std::pair<BSplineSurface, BSplineSurface>> commonForms(const BSplineSurface& a, const BSplineSurface& b) {
  const double kt =
      kKnotRelTol * std::max({1.0, a.domainU().length(), a.domainV().length(), b.domainU().length(), b.domainV().length()});
  if (std::abs(a.domainU().lo - b.domainU().lo) > kt || std::abs(a.domainU().hi - b.domainU().hi) > kt ||
      std::abs(a.domainV().lo - b.domainV().lo) > kt || std::abs(a.domainV().hi - b.domainV().hi) > kt)
    return std::nullopt;
  const int du = std::max(a.degreeU(), b.degreeU()), dv = std::max(a.degreeV(), b.degreeV());
  const BSplineSurface ae = a.degreeElevated(du - a.degreeU(), dv - a.degreeV());
  const BSplineSurface be = b.degreeElevated(du - b.degreeU(), dv - b.degreeV());
  BSplineSurface ac = detail::expressedLike(ae, be);  // a with b's knots added
  BSplineSurface bc = detail::expressedLike(be, ac);  // b with a's knots added
  if (ac.knotsU().values() != bc.knotsU().values() || ac.knotsV().values() != bc.knotsV().values()) return std::nullopt;
  return std::pair{std::move(ac), std::move(bc)};
}

/// The angle (degrees) between two normals and whether it counts (neither is a pole's vanishing normal).
struct NormalPair {
  double cosine = 1.0;
  bool defined = false;
};

NormalPair compareNormals(const VecX& n0, const VecX& n1, double scale0, double scale1) {
  NormalPair r;
  const double l0 = n0.norm(), l1 = n1.norm();
  if (!(l0 > kTurnoverPoleRel * scale0 && l1 > kTurnoverPoleRel * scale1)) return r;
  r.cosine = std::clamp(n0.dot(n1) / (l0 * l1), -1.0, 1.0);
  r.defined = true;
  return r;
}

constexpr double kRadToDeg = 57.29577951308232;

/// normalTurnover on a normalised lattice, for patches whose domains or knot structures do not correspond.
NormalTurnover sampledTurnover(const BSplineSurface& before, const BSplineSurface& after, double cosLimit) {
  constexpr int kLattice = 41;
  NormalTurnover t;
  std::vector<Vec3> n0, n1;
  std::vector<std::pair<double, double>> at;
  double s0 = 0.0, s1 = 0.0;
  for (int i = 0; i < kLattice; ++i)
    for (int j = 0; j < kLattice; ++j) {
      const double a = static_cast<double>(i) / (kLattice - 1), b = static_cast<double>(j) / (kLattice - 1);
      auto normalOf = [&](const BSplineSurface& s) {
        const auto d = s.derivatives(s.domainU().lo + a * s.domainU().length(), s.domainV().lo + b * s.domainV().length(), 1);
        return Vec3(d[1][0].head<3>().cross(d[0][1].head<3>()));
      };
      n0.push_back(normalOf(before));
      n1.push_back(normalOf(after));
      s0 = std::max(s0, n0.back().norm());
      s1 = std::max(s1, n1.back().norm());
      at.emplace_back(after.domainU().lo + a * after.domainU().length(), after.domainV().lo + b * after.domainV().length());
    }
  for (size_t k = 0; k < n0.size(); ++k) {
    const NormalPair c = compareNormals(n0[k], n1[k], s0, s1);
    if (c.defined && c.cosine < cosLimit && (!t.found || std::acos(c.cosine) * kRadToDeg > t.angleDeg)) {
      t.found = true;
      t.u = at[k].first;
      t.v = at[k].second;
      t.angleDeg = std::acos(c.cosine) * kRadToDeg;
    }
  }
  return t;
}

/// A region of a knot cell for normalTurnover: D = N_after . N_before restricted to [u0,u1] x [v0,v1] of the piece.
struct TurnoverRegion {
  BernsteinPatch d;
  int piece = 0;
  double u0 = 0.0, u1 = 1.0, v0 = 0.0, v1 = 1.0;
  double key = 0.0;  // the most negative coefficient of D relative to the piece's scale (most negative first)
  bool operator<(const TurnoverRegion& o) const { return key > o.key; }
};

}  // namespace

NormalTurnover normalTurnover(const BSplineSurface& before, const BSplineSurface& after, double minAngleDeg,
                              int maxSplits) {
  NormalTurnover t;
  const double cosLimit = std::cos(std::clamp(minAngleDeg, 90.0, 180.0) / kRadToDeg) - kTurnoverCosineSlack;
  if (before.dim() != 3 || after.dim() != 3 || before.degreeU() < 1 || before.degreeV() < 1) return t;
  const auto forms = commonForms(before, after);
  if (cosLimit < -1.0) return t;  // 180 degrees: nothing turns further
  if (!forms) return sampledTurnover(before, after, cosLimit);
  const std::vector<BezierPatchPiece> p0 = forms->first.bezierPatches(), p1 = forms->second.bezierPatches();
  if (p0.size() != p1.size()) return sampledTurnover(before, after, cosLimit);
  struct Piece {
    BernsteinPatch n0, n1;
    double s0 = 0.0, s1 = 0.0;  // largest coefficient norms of N_before, N_after
    Interval u, v;
  };
  std::vector<Piece> pieces;
  std::priority_queue<TurnoverRegion> open;
  auto settle = [&](TurnoverRegion r) {
    const Piece& pc = pieces[static_cast<size_t>(r.piece)];
    const double scale = pc.s0 * pc.s1;
    r.key = scale > 0.0 ? r.d.coeffs().minCoeff() / scale : 0.0;
    if (r.key >= -kIdentityRelTol) return;  // D >= 0 on the region up to round-off: no turnover there
    // Values of the true normals at the region's corners and centre.
    for (const auto& [a, b] : {std::pair{0.0, 0.0}, std::pair{0.0, 1.0}, std::pair{1.0, 0.0}, std::pair{1.0, 1.0},
                               std::pair{0.5, 0.5}}) {
      const double u = r.u0 + a * (r.u1 - r.u0), v = r.v0 + b * (r.v1 - r.v0);
      const NormalPair c = compareNormals(pc.n0(u, v), pc.n1(u, v), pc.s0, pc.s1);
      if (c.defined && c.cosine < cosLimit) {
        t.found = true;
        t.u = pc.u.lo + u * pc.u.length();
        t.v = pc.v.lo + v * pc.v.length();
        t.angleDeg = std::acos(c.cosine) * kRadToDeg;
        return;
      }
    }
    open.push(std::move(r));
  };
  for (size_t k = 0; k < p0.size() && !t.found; ++k) {
    Piece pc;
    pc.n0 = normalNumerator(p0[k].patch);
    pc.n1 = normalNumerator(p1[k].patch);
    pc.s0 = pc.n0.coeffs().rowwise().norm().maxCoeff();
    pc.s1 = pc.n1.coeffs().rowwise().norm().maxCoeff();
    pc.u = p0[k].u;
    pc.v = p0[k].v;
    TurnoverRegion r;
    r.d = dot(pc.n1, pc.n0);
    r.piece = static_cast<int>(k);
    pieces.push_back(std::move(pc));
    settle(std::move(r));
  }
  while (!t.found && !open.empty() && t.splits < maxSplits) {
    const TurnoverRegion top = open.top();
    open.pop();
    ++t.splits;
    const double um = 0.5 * (top.u0 + top.u1), vm = 0.5 * (top.v0 + top.v1);
    for (const auto& [a0, a1, b0, b1] : {std::array{0.0, 0.5, 0.0, 0.5}, std::array{0.5, 1.0, 0.0, 0.5},
                                         std::array{0.0, 0.5, 0.5, 1.0}, std::array{0.5, 1.0, 0.5, 1.0}}) {
      TurnoverRegion c;
      c.d = top.d.restricted(a0, a1, b0, b1);
      c.piece = top.piece;
      c.u0 = a0 == 0.0 ? top.u0 : um;
      c.u1 = a1 == 0.5 ? um : top.u1;
      c.v0 = b0 == 0.0 ? top.v0 : vm;
      c.v1 = b1 == 0.5 ? vm : top.v1;
      settle(std::move(c));
      if (t.found) break;
    }
  }
  t.certified = !t.found && open.empty();
  return t;
}

Result<regularity::SurfaceSearchResult> searchMovedPatch(const BSplineSurface& s) {
  regularity::SearchOptions so;
  so.maxWork = kFoldSearchWork;
  so.maxWorkPerPiece = 0;
  return regularity::searchSurfaceDefects(s, so);
}

std::optional<FoldPoint> newFoldPoint(const BSplineSurface& before, const BSplineSurface& after,
                                      const regularity::SurfaceSearchResult* searched) {
  if (after.dim() != 3) return std::nullopt;
  Result<regularity::SurfaceSearchResult> own = Status(ErrorCode::kUnsupported, "not searched");
  if (searched == nullptr) {
    own = searchMovedPatch(after);
    if (!own) return std::nullopt;
    searched = &*own;
  }
  for (const regularity::SurfaceCriticalPoint& c : searched->criticalPoints) {
    const double u = std::clamp(c.u, before.domainU().lo, before.domainU().hi);
    const double v = std::clamp(c.v, before.domainV().lo, before.domainV().hi);
    const auto d = before.derivatives(u, v, 1);
    const Vec3 su = d[1][0].head<3>(), sv = d[0][1].head<3>();
    const double lengths = su.norm() * sv.norm();
    if (lengths > 0.0 && su.cross(sv).norm() > kFoldRegularSine * lengths) return FoldPoint{c.u, c.v};
  }
  return std::nullopt;
}

std::string foldOf(const BSplineSurface& before, const BSplineSurface& after, double maxTurnDeg,
                   const regularity::SurfaceSearchResult* searched) {
  const NormalTurnover nt = normalTurnover(before, after, maxTurnDeg);
  if (nt.found)
    return fmt::format("would turn over: its normal turns by {:.4g} deg at (u, v) = ({:.6g}, {:.6g})", nt.angleDeg,
                       nt.u, nt.v);
  if (const auto f = newFoldPoint(before, after, searched))
    return fmt::format("would fold: S_u x S_v vanishes at (u, v) = ({:.6g}, {:.6g}), where the input is regular", f->u,
                       f->v);
  return "";
}

double sampledSurfaceDistance(const BSplineSurface& a, const BSplineSurface& b, int grid) {
  auto lattice = [grid](Interval iv) {
    std::vector<double> t(static_cast<size_t>(grid));
    for (int i = 0; i < grid; ++i) t[static_cast<size_t>(i)] = iv.lo + iv.length() * i / (grid - 1);
    t.back() = iv.hi;
    return t;
  };
  Matrix pa, pb;
  GridEvaluator(a, lattice(a.domainU()), lattice(a.domainV())).evaluate(&pa, nullptr, nullptr);
  GridEvaluator(b, lattice(b.domainU()), lattice(b.domainV())).evaluate(&pb, nullptr, nullptr);
  return (pa.leftCols(3) - pb.leftCols(3)).rowwise().norm().maxCoeff();
}

namespace {

SeamReport mergeReports(const std::vector<SeamReport>& parts) {
  SeamReport r = parts.front();
  r.notes.clear();
  bool certified = true, g1Id = true, g2Id = true;
  int geo = 3, par = 3;
  for (const SeamReport& p : parts) {
    r.overlapA.lo = std::min(r.overlapA.lo, p.overlapA.lo);
    r.overlapA.hi = std::max(r.overlapA.hi, p.overlapA.hi);
    r.overlapB.lo = std::min(r.overlapB.lo, p.overlapB.lo);
    r.overlapB.hi = std::max(r.overlapB.hi, p.overlapB.hi);
    if (p.g0Max > r.g0Max) { r.g0Max = p.g0Max; r.g0Worst = p.g0Worst; }
    if (p.g1MaxDeg > r.g1MaxDeg) { r.g1MaxDeg = p.g1MaxDeg; r.g1Worst = p.g1Worst; }
    if (p.g2Max > r.g2Max) { r.g2Max = p.g2Max; r.g2Worst = p.g2Worst; }
    r.g0Sampled = std::max(r.g0Sampled, p.g0Sampled);
    r.g1SampledDeg = std::max(r.g1SampledDeg, p.g1SampledDeg);
    r.g2Sampled = std::max(r.g2Sampled, p.g2Sampled);
    r.g2RelMax = std::max(r.g2RelMax, p.g2RelMax);
    r.g2RelSampled = std::max(r.g2RelSampled, p.g2RelSampled);
    r.g2ResidualMax = std::max(r.g2ResidualMax, p.g2ResidualMax);
    r.c1Mismatch = std::max(r.c1Mismatch, p.c1Mismatch);
    r.c2Mismatch = std::max(r.c2Mismatch, p.c2Mismatch);
    r.lambdaRange.lo = std::min(r.lambdaRange.lo, p.lambdaRange.lo);
    r.lambdaRange.hi = std::max(r.lambdaRange.hi, p.lambdaRange.hi);
    r.kappaRange.lo = std::min(r.kappaRange.lo, p.kappaRange.lo);
    r.kappaRange.hi = std::max(r.kappaRange.hi, p.kappaRange.hi);
    certified = certified && p.certified;
    g1Id = g1Id && p.g1Identity;
    g2Id = g2Id && p.g2Identity;
    geo = std::min(geo, static_cast<int>(p.geometric));
    par = std::min(par, static_cast<int>(p.parametric));
    if (p.correspondence == Correspondence::kProjection) r.correspondence = Correspondence::kProjection;
    for (const std::string& n : p.notes)
      if (std::find(r.notes.begin(), r.notes.end(), n) == r.notes.end()) r.notes.push_back(n);
    r.samples.insert(r.samples.end(), p.samples.begin(), p.samples.end());
  }
  r.certified = certified;
  r.g1Identity = g1Id;
  r.g2Identity = g2Id;
  r.geometric = static_cast<GeometricClass>(geo);
  r.parametric = static_cast<ParametricClass>(par);
  r.notes.push_back(fmt::format("analysed over {} sub-ranges of {}'s edge (correspondence affine on each)", parts.size(), r.a));
  return r;
}

}  // namespace

Result<SeamReport> analyzeSeamPiecewise(const Patch& a, Edge ea, const Patch& b, Edge eb, const SeamOptions& options,
                                        const std::vector<double>& breaks) {
  if (breaks.size() < 2) return analyzeSeam(a, ea, b, eb, options);
  std::vector<SeamReport> parts;
  for (size_t k = 0; k + 1 < breaks.size(); ++k) {
    auto r = analyzeSeam(a, ea, b, eb, options, Interval{breaks[k], breaks[k + 1]});
    if (!r) return r.status();
    parts.push_back(std::move(*r));
  }
  return mergeReports(parts);
}

namespace detail {
Patch replacedSurface(const Patch& p, BSplineSurface s) {
  Patch out = p;
  const bool sameKnots = s.knotsU().values() == p.surface.knotsU().values() &&
                         s.knotsV().values() == p.surface.knotsV().values() && s.degreeU() == p.surface.degreeU() &&
                         s.degreeV() == p.surface.degreeV();
  if (!sameKnots) out.kind = PatchKind::kBSpline;
  out.surface = std::move(s);
  return out;
}
}  // namespace detail

namespace {

// The seam seen from both sides in edge frames, and the affine correspondence.
struct SeamSetup {
  const Patch* S = nullptr;
  const Patch* T = nullptr;
  Edge es = Edge::V0, et = Edge::V0;
  SeamReport before;
  bool reversed = false;
  Interval rangeS;          // S's own edge parameter
  double c0 = 0.0, c1 = 1.0;  // T frame along = c0 + c1 (u - rangeS.lo)
  BSplineSurface Sf, Tf;    // edge frames (T flipped when reversed)
  double diag = 1.0;
  Tolerances tol;
  SeamOptions seamOpt;
};

// The paper's preconditions beyond C1 bicubic: the seam starts at both frames' first corner, and S's breakpoints
// b_0..b_m^ lie on T's breakpoints b~_0..b~_m^ (span i of S corresponds to span i of T) within maxGap.
Status paperCorrespondence(const SeamSetup& st, double maxGap) {
  const double tolU = 1e3 * kKnotRelTol;
  const Interval dS = st.Sf.domainU(), dT = st.Tf.domainU();
  const double tStart = st.c0;
  if (std::abs(st.rangeS.lo - dS.lo) > tolU * dS.length() || std::abs(tStart - dT.lo) > tolU * dT.length())
    return {ErrorCode::kUnsupported,
            "the paper's methods join edges from a common corner (span i of S against span i of S~); this seam "
            "starts inside an edge: use least-squares"};
  const std::vector<double> bS = st.Sf.knotsU().breakpoints(), bT = st.Tf.knotsU().breakpoints();
  const size_t mh = std::min(bS.size(), bT.size()) - 1;
  const double vS = st.Sf.domainV().lo, vT = st.Tf.domainV().lo;
  for (size_t i = 0; i <= mh; ++i) {
    const double d = (st.Sf.evaluate(bS[i], vS) - st.Tf.evaluate(bT[i], vT)).norm();
    if (d > maxGap)
      return {ErrorCode::kUnsupported,
              fmt::format("the paper's methods pair span i of S with span i of S~, but breakpoint {} of S and of S~ "
                          "are {:.6g} apart (above the gap limit {:.6g}): use least-squares",
                          i, d, maxGap)};
  }
  return Status::ok();
}


}  // namespace

Result<JoinResult> joinSeam(const Model& model, const std::string& moveName, Edge moveEdge, const std::string& toName,
                            Edge toEdge, const JoinOptions& opt) {
  const auto findIndex = [&](const std::string& name) -> int {
    for (size_t i = 0; i < model.patches.size(); ++i)
      if (model.patches[i].name == name) return static_cast<int>(i);
    return -1;
  };
  const int is = findIndex(moveName), it = findIndex(toName);
  if (is < 0) return Status(ErrorCode::kNotFound, fmt::format("no patch named \"{}\"", moveName));
  if (it < 0) return Status(ErrorCode::kNotFound, fmt::format("no patch named \"{}\"", toName));
  if (is == it && moveEdge == toEdge) return invalidInput("an edge cannot be joined to itself");
  if (opt.continuity == GeometricClass::kNone) return invalidInput("the requested continuity must be G0, G1 or G2");
  if (opt.ell && opt.method != JoinMethod::kBezierStrip)
    return invalidInput("--ell is the parameter of the Bezier strip (--method bezier-strip)");
  if (opt.average && (opt.method == JoinMethod::kBSpline || opt.method == JoinMethod::kBezierStrip))
    return invalidInput("--average moves both patches: only the least-squares method does that");
  if (opt.average && is == it) return invalidInput("--average needs two different patches");
  if (!(opt.maxDisplacementRel >= 0.0))
    return invalidInput(fmt::format("the largest displacement must be a non-negative multiple of the patch size, not "
                                    "{}",
                                    opt.maxDisplacementRel));
  if (opt.average && opt.continuity == GeometricClass::kG2)
    return Status(ErrorCode::kUnsupported, "--average is implemented for G0 and G1");

  if (opt.creaseAngleDeg && !validCreaseAngle(*opt.creaseAngleDeg))
    return invalidInput(fmt::format("the crease angle must be in (0, 180] degrees (got {})", *opt.creaseAngleDeg));

  SeamSetup st;
  st.S = &model.patches[static_cast<size_t>(is)];
  st.T = &model.patches[static_cast<size_t>(it)];
  st.es = moveEdge;
  st.et = toEdge;
  st.diag = model.boundingBox().diagonal();
  if (!(st.diag > 0.0)) st.diag = 1.0;
  st.tol = opt.tolerances ? *opt.tolerances : Tolerances::forModelSize(st.diag);
  st.seamOpt = opt.seam;
  st.seamOpt.tol = st.tol;
  const double maxGap = opt.maxGap ? *opt.maxGap : kDefaultMaxGapRel * st.diag;

  auto before = analyzeSeam(*st.S, moveEdge, *st.T, toEdge, st.seamOpt);
  if (!before) return before.status();
  st.before = *before;
  if (st.before.g0Max > maxGap)
    return invalidInput(fmt::format("the edges {}:{} and {}:{} are {:.6g} apart, above the gap limit {:.6g} "
                                    "(--max-gap)",
                                    moveName, edgeName(moveEdge), toName, edgeName(toEdge), st.before.g0Max, maxGap));
  if (opt.creaseAngleDeg && opt.continuity != GeometricClass::kG0 && st.before.g1MaxDeg >= *opt.creaseAngleDeg) {
    // a design crease: left alone
    JoinResult kept;
    kept.model = model;
    kept.model.brep.reset();  // as every repair result (Model::brep)
    JoinReport& rep = kept.report;
    rep.method = opt.method == JoinMethod::kAuto ? JoinMethod::kLeastSquares : opt.method;
    rep.reason = "none: the seam is a design crease";
    rep.before = rep.after = st.before;
    rep.requested = opt.continuity;
    rep.achieved = meets(st.before.geometric, opt.continuity);
    rep.creaseKept = true;
    rep.notes.push_back(fmt::format("crease, left as designed: angle {:.4g} deg, at or above the crease angle {:.4g} "
                                    "deg (--crease-angle 180 joins it)",
                                    st.before.g1MaxDeg, *opt.creaseAngleDeg));
    return kept;
  }
  st.reversed = st.before.reversed;
  const detail::JoinOverlap ov = detail::cornerSnappedOverlap(st.S->surface, moveEdge, st.T->surface, toEdge,
                                                             st.before.overlapA, st.before.overlapB, st.reversed,
                                                             maxGap);
  st.rangeS = ov.s;
  const Interval oB = ov.t;
  st.c1 = oB.length() / st.rangeS.length();
  st.c0 = st.reversed ? -oB.hi : oB.lo;
  st.Sf = detail::toEdgeFrame(st.S->surface, moveEdge, false);
  st.Tf = detail::toEdgeFrame(st.T->surface, toEdge, st.reversed);

  JoinResult res;
  res.model = model;
  res.model.brep.reset();  // the patches change: the trims would not follow (Model::brep)
  JoinReport& rep = res.report;
  rep.before = st.before;
  rep.requested = opt.continuity;

  // ---- method selection.
  const Status paperS = checkC1Bicubic(st.S->surface), paperT = checkC1Bicubic(st.T->surface);
  const bool paperClass = paperS.isOk() && paperT.isOk();
  std::optional<KnotProportionality> prop;
  if (paperClass) {
    auto pr = proportionalKnots(st.Sf.knotsU(), st.Tf.knotsU());
    if (pr) {
      prop = *pr;
      rep.proportionalKnots = pr->proportional;
    }
  }
  const Status corr = paperClass ? paperCorrespondence(st, maxGap) : Status::ok();
  JoinMethod method = opt.method;
  if (method == JoinMethod::kAuto) {
    if (opt.average) {
      method = JoinMethod::kLeastSquares;
      rep.reason = "auto: --average moves both patches, which only the least-squares join does";
    } else if (!paperClass) {
      method = JoinMethod::kLeastSquares;
      rep.reason = fmt::format("auto: not two C1 bicubic B-splines in the paper's sense ({}), so the general "
                               "least-squares join",
                               paperS.isOk() ? "S~: " + paperT.message() : "S: " + paperS.message());
    } else if (!corr.isOk()) {
      method = JoinMethod::kLeastSquares;
      rep.reason = "auto: C1 bicubic, but " + corr.message();
    } else if (opt.continuity == GeometricClass::kG2) {
      method = JoinMethod::kLeastSquares;
      rep.reason = "auto: G2 requested; the paper's methods give G1, so the least-squares join with second-order rows";
    } else if (prop && prop->proportional) {
      method = JoinMethod::kBSpline;
      rep.reason = "auto: C1 bicubic B-splines with proportional knots (Def. 3.1): Theorem 1 keeps the knots and gives "
                   "a C1 join after the reflection of v";
    } else {
      method = JoinMethod::kLeastSquares;
      rep.reason = "auto: C1 bicubic but the knots are not proportional; the least-squares join inserts the "
                   "neighbour's knots and keeps S a C1 B-spline (the Bezier strip of Algorithm 3.3, --method "
                   "bezier-strip, would leave S only G1 inside the strip)";
    }
  } else {
    rep.reason = fmt::format("requested with --method {}", toString(method));
  }
  if (method == JoinMethod::kBSpline || method == JoinMethod::kBezierStrip) {
    if (!paperClass)
      return Status(ErrorCode::kUnsupported,
                    fmt::format("--method {} needs two C1 bicubic B-splines (double interior knots, 4-fold ends): {}",
                                toString(method), paperS.isOk() ? "S~: " + paperT.message() : "S: " + paperS.message()));
    if (!corr) return corr;
    if (opt.continuity == GeometricClass::kG2)
      return Status(ErrorCode::kUnsupported, fmt::format("--method {} joins G1; use least-squares for G2", toString(method)));
  }
  rep.method = method;

  const double moveThreshold = kRoundoff * st.diag;
  std::vector<double> pieceBreaks;  // for the piecewise analysis of the strip
  if (method == JoinMethod::kBSpline) {
    auto r = theorem1Join(st.Sf, st.Tf);
    if (!r) return r.status();
    rep.reason += fmt::format(" [Theorem 1, case {}]", toString(r->spanCase));
    res.model.patches[static_cast<size_t>(is)] =
        detail::replacedSurface(*st.S, detail::fromEdgeFrame(r->surface, moveEdge, false));
  } else if (method == JoinMethod::kBezierStrip) {
    BezierStripOptions so;
    so.ell = opt.ell;
    auto r = bezierStripJoin(st.Sf, st.Tf, so);
    if (!r) return r.status();
    rep.junctions = r->junctions;
    for (const std::string& n : r->notes) rep.notes.push_back(n);
    rep.reason += fmt::format(" [Algorithm 3.3, case {}, {} wrinkled junction{}]", toString(r->spanCase),
                              r->raisedKnots.size(), r->raisedKnots.size() == 1 ? "" : "s");
    (isUEdge(moveEdge) ? rep.insertedKnotsV : rep.insertedKnotsU) = r->raisedKnots;
    res.model.patches[static_cast<size_t>(is)] = detail::replacedSurface(*st.S, detail::fromEdgeFrame(r->surface, moveEdge, false));
    const std::vector<double> bS = st.Sf.knotsU().breakpoints();
    for (size_t i = 0; i < bS.size() && i <= static_cast<size_t>(r->mHat); ++i) pieceBreaks.push_back(bS[i]);
    // Internal G1 of the strip across the wrinkled junctions: the two Bezier patches on either side, certified.
    const BSplineSurface& Sstar = r->surface;
    const std::vector<BezierPatchPiece> pcs = Sstar.bezierPatches();
    double worst = 0.0;
    bool allCert = true;
    for (const StripJunction& J : r->junctions) {
      if (!J.wrinkled) continue;
      const BezierPatchPiece *left = nullptr, *right = nullptr;
      for (const BezierPatchPiece& pc : pcs) {
        if (pc.spanV != 0) continue;
        if (std::abs(pc.u.hi - J.u) <= kKnotRelTol * st.Sf.domainU().length()) left = &pc;
        if (std::abs(pc.u.lo - J.u) <= kKnotRelTol * st.Sf.domainU().length()) right = &pc;
      }
      if (!left || !right) continue;
      const Patch L{"strip-left", PatchKind::kBezier, left->patch.toBSpline(left->u, left->v)};
      const Patch R{"strip-right", PatchKind::kBezier, right->patch.toBSpline(right->u, right->v)};
      auto a = analyzeSeam(L, Edge::U1, R, Edge::U0, st.seamOpt);
      if (!a) continue;
      worst = std::max(worst, a->g1MaxDeg);
      allCert = allCert && a->certified;
    }
    rep.stripInternalG1MaxDeg = worst;
    if (!allCert) rep.notes.push_back("the strip's internal G1 check was not certified at every junction");
  } else {
    // ---- least squares.
    detail::LsJoinOptions lo;
    lo.continuity = opt.continuity;
    lo.scale = st.diag;
    const int order = opt.continuity == GeometricClass::kG2 ? 2 : 1;
    if (!opt.average) {
      detail::EdgeConstraint c;
      c.edge = moveEdge;
      c.target = detail::targetFromFrame(st.Tf, st.rangeS, st.c0, st.c1, order);
      auto r = detail::leastSquaresJoin(st.S->surface, {c}, lo);
      if (!r) return r.status();
      // Rational sides: the connecting functions of the homogeneous equations need more degree than the patch's
      // own (the weight equation w_Sn = -lambda w_Tn + kappa w_Tt + nu w_T is solvable with lambda > 0 only when
      // kappa and nu may have about the degree of the edge's weights): raise the degree (exact) and try again.
      const bool rationalJoin = st.S->surface.isRational() || st.T->surface.isRational();
      const bool alreadyMet = meets(st.before.geometric, opt.continuity);  // nothing to gain from a higher degree
      for (int elevate = 1; rationalJoin && !alreadyMet && elevate <= kRationalJoinMaxElevation && (r->unchanged || !r->feasible);
           ++elevate) {
        detail::LsJoinOptions le = lo;
        le.elevate = elevate;
        auto re = detail::leastSquaresJoin(st.S->surface, {c}, le);
        if (!re) break;
        if (!re->unchanged && re->feasible) {
          re->notes.insert(re->notes.begin(),
                           fmt::format("rational join: degree raised by {} for the connecting functions", elevate));
          r = std::move(re);
        }
      }
      // A rational seam already at the requested class whose solve needed the weights as unknowns: that solve
      // reshapes the patch (JoinNeverFolds.RationalPairAlreadyG1ComesBackUnmoved: the displacement cap refused it
      // only while the cap's bound was loose); nothing is to be gained, so nothing moves.
      if (alreadyMet && rationalJoin && !r->unchanged && !r->weightsFixed) {
        r->unchanged = true;
        r->notes.push_back(fmt::format("the seam is already {} and the rational solve would have had to change the "
                                       "weights: left as it was",
                                       toString(st.before.geometric)));
      }
      for (const std::string& n : r->notes) rep.notes.push_back(n);
      if (!r->unchanged) {  // else the patch stays bit-identical (the fold test refused every solution)
        rep.insertedKnotsU = r->insertedKnotsU;
        rep.insertedKnotsV = r->insertedKnotsV;
        rep.elevatedU = r->elevatedU;
        rep.elevatedV = r->elevatedV;
        if (opt.continuity != GeometricClass::kG0 && !r->lambda.empty()) rep.lambdaMin = r->lambdaMin;
        for (size_t k = 0; k < r->lambdaFixed.size(); ++k)
          if (r->lambdaFixed[k]) {
            rep.lambdaFixed = true;
            rep.lambda0 = std::min(rep.lambda0.value_or(r->lambda0[k]), r->lambda0[k]);
          }
        rep.weightsFixed = r->weightsFixed;
        res.model.patches[static_cast<size_t>(is)] = detail::replacedSurface(*st.S, r->surface);
      }
    } else {
      // Both sides move onto the common middle: S's own data and T's data over S's edge parameter.
      const detail::SeamTarget own = detail::targetFromFrame(st.Sf, st.rangeS, st.rangeS.lo, 1.0, 1);
      const detail::SeamTarget other = detail::targetFromFrame(st.Tf, st.rangeS, st.c0, st.c1, 1);
      double ns = 0.0, nt = 0.0;
      for (int k = 0; k <= 32; ++k) {
        const double u = st.rangeS.lo + st.rangeS.length() * k / 32.0;
        auto val = [&](const detail::SeamTarget& t) {
          for (const detail::TargetPiece& p : t.pieces)
            if (u >= p.u.lo && u <= p.u.hi) {
              const VecX v = p.cross1((u - p.u.lo) / p.u.length());
              const VecX w = p.point((u - p.u.lo) / p.u.length());
              if (!t.rational) return v.norm();
              const int d = static_cast<int>(v.size()) - 1;
              return ((w[d] * v.head(d) - v[d] * w.head(d)) / (w[d] * w[d])).norm();
            }
          return 0.0;
        };
        ns += val(own);
        nt += val(other);
      }
      const double lambda0 = nt > 0.0 ? ns / nt : 1.0;
      detail::SeamTarget mid = detail::averagedTarget(own, other, lambda0);
      detail::EdgeConstraint cs;
      cs.edge = moveEdge;
      cs.target = mid;
      auto rs = detail::leastSquaresJoin(st.S->surface, {cs}, lo);
      if (!rs) return rs.status();
      // T's view: the middle lies on S's side; T's own edge parameter is oB.lo + c1 (u - lo) (or reversed).
      detail::SeamTarget midT = mid;
      for (detail::TargetPiece& p : midT.pieces) p.cross1 = -1.0 * p.cross1;
      const double a = st.reversed ? oB.hi + st.c1 * st.rangeS.lo : oB.lo - st.c1 * st.rangeS.lo;
      const double b = st.reversed ? -st.c1 : st.c1;
      detail::EdgeConstraint ct;
      ct.edge = toEdge;
      ct.target = detail::mappedTarget(midT, a, b);
      auto rt = detail::leastSquaresJoin(st.T->surface, {ct}, lo);
      if (!rt) return rt.status();
      for (const std::string& n : rs->notes) rep.notes.push_back(fmt::format("{}: {}", moveName, n));
      for (const std::string& n : rt->notes) rep.notes.push_back(fmt::format("{}: {}", toName, n));
      if (rs->unchanged || rt->unchanged) {
        rep.notes.push_back("average: one side cannot reach the middle without folding; both left as they were");
      } else {
        rep.insertedKnotsU = rs->insertedKnotsU;
        rep.insertedKnotsV = rs->insertedKnotsV;
        rep.elevatedU = rs->elevatedU;
        rep.elevatedV = rs->elevatedV;
        if (opt.continuity != GeometricClass::kG0) rep.lambdaMin = std::min(rs->lambdaMin, rt->lambdaMin);
        for (const detail::LsJoinOutcome* o : {&*rs, &*rt})
          for (size_t c = 0; c < o->lambdaFixed.size(); ++c)
            if (o->lambdaFixed[c]) {
              rep.lambdaFixed = true;
              rep.lambda0 = std::min(rep.lambda0.value_or(o->lambda0[c]), o->lambda0[c]);
            }
        rep.weightsFixed = rs->weightsFixed && rt->weightsFixed;
        rep.notes.push_back(fmt::format("average: both edges moved onto their middle; cross derivatives balanced "
                                        "with lambda0 = {:.6g}",
                                        lambda0));
        res.model.patches[static_cast<size_t>(is)] = detail::replacedSurface(*st.S, rs->surface);
        res.model.patches[static_cast<size_t>(it)] = detail::replacedSurface(*st.T, rt->surface);
      }
    }
  }

  // ---- the referee's verdict: never worse than before (else the input, unchanged).
  const auto samePatch = [](const Patch& a, const Patch& b) {
    return a.surface.knotsU().values() == b.surface.knotsU().values() &&
           a.surface.knotsV().values() == b.surface.knotsV().values() && a.surface.points() == b.surface.points() &&
           a.surface.weights() == b.surface.weights() && a.surface.degreeU() == b.surface.degreeU() &&
           a.surface.degreeV() == b.surface.degreeV();
  };
  const bool changed = !samePatch(model.patches[static_cast<size_t>(is)], res.model.patches[static_cast<size_t>(is)]) ||
                       !samePatch(model.patches[static_cast<size_t>(it)], res.model.patches[static_cast<size_t>(it)]);
  if (changed) {
    const Patch& Sa = res.model.patches[static_cast<size_t>(is)];
    const Patch& Ta = res.model.patches[static_cast<size_t>(it)];
    auto after = pieceBreaks.size() >= 3 ? analyzeSeamPiecewise(Sa, moveEdge, Ta, toEdge, st.seamOpt, pieceBreaks)
                                         : analyzeSeam(Sa, moveEdge, Ta, toEdge, st.seamOpt);
    if (!after) return after.status().withContext("after the join");
    rep.after = *after;
    const SeamReport& b = rep.before;
    const SeamReport& a = rep.after;
    std::vector<std::string> worse;
    // Certified after-bounds against the worst values found before (lower bounds of the before maxima): the seam's
    // true after-maximum is then at most its true before-maximum plus the tolerance.
    if (a.g1MaxDeg > b.g1SampledDeg + st.tol.angleDeg)
      worse.push_back(fmt::format("the G1 angle would grow from {:.6g} to {:.6g} degrees", b.g1SampledDeg, a.g1MaxDeg));
    if (a.g0Max > b.g0Sampled + st.tol.distance)
      worse.push_back(fmt::format("the gap would grow from {:.6g} to {:.6g}", b.g0Sampled, a.g0Max));
    if (static_cast<int>(a.geometric) < static_cast<int>(b.geometric))
      worse.push_back(fmt::format("the seam would drop from {} to {}", toString(b.geometric), toString(a.geometric)));
    if (opt.continuity != GeometricClass::kG0) {
      const bool sampledLambda = !(a.lambdaRange.lo == 0.0 && a.lambdaRange.hi == 0.0);  // set when normals exist
      if (rep.lambdaMin && !(*rep.lambdaMin > 0.0))
        worse.push_back(fmt::format("lambda would reach {:.4g} (a fold)", *rep.lambdaMin));
      else if (sampledLambda && !(a.lambdaRange.lo > 0.0))
        worse.push_back(fmt::format("lambda would reach {:.4g} on the seam (a fold)", a.lambdaRange.lo));
    }
    // Folds inside a moved patch (issue 36 goal 2): no new point where S_u x S_v vanishes, and no normal turned
    // against the input's by more than a right angle plus the seam's own angle (closing a crease of angle a turns
    // the tangent plane at the seam by up to a).
    if (opt.refuseFolds)
      for (int idx : {is, it}) {
        const Patch& p0 = model.patches[static_cast<size_t>(idx)];
        const Patch& p1 = res.model.patches[static_cast<size_t>(idx)];
        if (!samePatch(p0, p1)) {
          const double seamAngle = std::isfinite(b.g1MaxDeg) ? b.g1MaxDeg : 0.0;
          const std::string why = foldOf(p0.surface, p1.surface, std::min(180.0, 90.0 + seamAngle));
          if (!why.empty()) worse.push_back(fmt::format("patch \"{}\" {}", p1.name, why));
        }
        if (is == it) break;
      }
    // The displacement cap: a join may not move a patch by more than maxDisplacementRel x its own size (certified).
    double worstRel = 0.0;
    for (int idx : {is, it}) {
      const Patch& p0 = model.patches[static_cast<size_t>(idx)];
      const Patch& p1 = res.model.patches[static_cast<size_t>(idx)];
      if (!samePatch(p0, p1)) {
        const double size = controlBox(p0.surface).diagonal();
        double bound = surfaceDisplacement(p0.surface, p1.surface).bound;
        // A refusal must not rest on a loose bound (issue 36 goal 6): above the cap, the bound is sharpened by
        // subdividing the difference's Bernstein form until it is within 1.5x of the displacement sampled.
        if (size > 0.0 && bound > opt.maxDisplacementRel * size)
          bound = surfaceDisplacementSharp(p0.surface, p1.surface).bound;
        worstRel = std::max(worstRel, size > 0.0 ? bound / size : std::numeric_limits<double>::infinity());
      }
      if (is == it) break;
    }
    if (worstRel > opt.maxDisplacementRel) {
      rep.notes.push_back(fmt::format("the join would move the patch by {:.3g} x its size; left as it was (limit {:.3g} "
                                      "x, --max-displacement)",
                                      worstRel, opt.maxDisplacementRel));
      worse.push_back(fmt::format("the surface would move by {:.3g} x the patch size", worstRel));
    }
    // Never half-done (issue 13 §1): a join that does not reach the requested class leaves the patch as it was.
    if (worse.empty() && !meets(a.geometric, opt.continuity))
      worse.push_back(fmt::format("the seam would be {}, not the requested {}", toString(a.geometric),
                                  toString(opt.continuity)));
    if (!worse.empty()) {
      std::string why = worse.front();
      for (size_t k = 1; k < worse.size(); ++k) why += "; " + worse[k];
      rep.notes.push_back(fmt::format("join reverted, the input is returned unchanged: {}", why));
      res.model = model;
      res.model.brep.reset();  // the patches change: the trims would not follow (Model::brep)
      rep.reverted = true;
    }
  }
  if (!changed || rep.reverted) {
    rep.after = rep.before;
    rep.lambdaMin.reset();
    rep.lambdaFixed = false;
    rep.lambda0.reset();
    rep.weightsFixed = false;
    rep.insertedKnotsU.clear();
    rep.insertedKnotsV.clear();
    rep.elevatedU = rep.elevatedV = 0;
    rep.junctions.clear();
    rep.stripInternalG1MaxDeg.reset();
  }

  // ---- what changed.
  for (int idx : {is, it}) {
    const Patch& before0 = model.patches[static_cast<size_t>(idx)];
    const Patch& after0 = res.model.patches[static_cast<size_t>(idx)];
    if (!samePatch(before0, after0)) {
      const Displacement d = controlPointDisplacement(before0.surface, after0.surface, moveThreshold);
      const SurfaceDisplacement sd = surfaceDisplacement(before0.surface, after0.surface);
      if (std::find(rep.patchesChanged.begin(), rep.patchesChanged.end(), after0.name) == rep.patchesChanged.end())
        rep.patchesChanged.push_back(after0.name);
      rep.maxDisplacement = std::max(rep.maxDisplacement, d.max);
      rep.movedPoints += d.moved;
      rep.maxSurfaceDisplacement = std::max(rep.maxSurfaceDisplacement, sd.bound);
      rep.maxSurfaceDisplacementSampled = std::max(rep.maxSurfaceDisplacementSampled, sd.sampled);
      const double size = controlBox(before0.surface).diagonal();
      if (size > 0.0) rep.maxSurfaceDisplacementRel = std::max(rep.maxSurfaceDisplacementRel, sd.bound / size);
    }
    if (is == it) break;
  }
  rep.achieved = meets(rep.after.geometric, opt.continuity);
  if (!rep.achieved)
    rep.notes.push_back(fmt::format("requested {} not achieved: the seam is {} after the join{}",
                                    toString(opt.continuity), toString(rep.after.geometric),
                                    changed && !rep.reverted ? "" : " (left as it was)"));
  if (!rep.after.certified) rep.notes.push_back("the after-analysis is sampled, not certified");
  return res;
}

}  // namespace seam
