// GC^n of patch seams (Zheng-Wang-Liang): the exact route (Theorem 5 per Bezier piece) and the sampled route (3.8).
// See include/seam/rational/gcn.h and docs/algorithms/zheng-wang-liang.md.
#include "seam/rational/gcn.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "seam/core/tolerances.h"

namespace seam::rational {

namespace {

/// |slope| of the edge correspondence within this of 1: the edge parametrisations match (parametric C^k), as in
/// seam::analyzeSeam.
constexpr double kMatchingSlopeTol = 1e-9;
/// Grid used to size expression surfaces for the normalisation of coordinates.
constexpr int kSizingGrid = 9;

std::string seamLabel(const std::string& a, Edge ea, const std::string& b, Edge eb) {
  return fmt::format("seam {}:{} / {}:{}", a, edgeName(ea), b, edgeName(eb));
}

/// Homogeneous Bezier patch (w P, w) with R -> (R - c w) / L; 3-D points (P - c) / L when `integral`.
BernsteinPatch homogeneousPiece(const BezierPatch& bp, bool integral, const Vec3& c, double L) {
  const int du = bp.degreeU(), dv = bp.degreeV();
  Matrix h(bp.points().rows(), integral ? 3 : 4);
  for (int i = 0; i <= du; ++i)
    for (int j = 0; j <= dv; ++j) {
      const int row = i * (dv + 1) + j;
      const double w = bp.weight(i, j);
      const Vec3 p = (bp.point(i, j).head(3).transpose() - c) / L;
      if (integral) {
        h.row(row) = p.transpose();
      } else {
        h.row(row).head(3) = (w * p).transpose();
        h(row, 3) = w;
      }
    }
  return BernsteinPatch(du, dv, std::move(h));
}

std::vector<BezierPatchPiece> edgePieces(const BSplineSurface& oriented) {
  std::vector<BezierPatchPiece> out;
  for (BezierPatchPiece& p : oriented.bezierPatches())
    if (p.spanU == 0) out.push_back(std::move(p));
  std::sort(out.begin(), out.end(), [](const auto& x, const auto& y) { return x.v.lo < y.v.lo; });
  return out;
}

const BezierPatchPiece* pieceAt(const std::vector<BezierPatchPiece>& pieces, double v) {
  for (const BezierPatchPiece& p : pieces)
    if (v >= p.v.lo && v <= p.v.hi) return &p;
  return nullptr;
}

/// The exact route on every Bezier piece of the seam. Returns false (with a note) when it cannot be applied.
bool exactRoute(const Patch& pa, Edge ea, const Patch& pb, Edge eb, GcnReport& rep, const Vec3& c, double L,
                const GcnOptions& opt) {
  const int n = opt.order;
  const BSplineSurface Ao = pa.surface.orientedFrom(ea), Bo = pb.surface.orientedFrom(eb);
  const std::vector<BezierPatchPiece> Ap = edgePieces(Ao), Bp = edgePieces(Bo);
  const bool integral = !Ao.isRational() && !Bo.isRational();
  const Interval oA = rep.overlapA;
  const double tol = kKnotRelTol * oA.length();
  std::vector<double> ts{oA.lo, oA.hi};
  for (const auto& p : Ap)
    for (double t : {p.v.lo, p.v.hi})
      if (t > oA.lo + tol && t < oA.hi - tol) ts.push_back(t);
  for (const auto& p : Bp)
    for (double s : {p.v.lo, p.v.hi}) {
      const double t = (s - rep.offset) / rep.slope;
      if (t > oA.lo + tol && t < oA.hi - tol) ts.push_back(t);
    }
  std::sort(ts.begin(), ts.end());
  ExactGcnOptions eo = opt.exact;
  eo.order = n;
  for (size_t k = 0; k + 1 < ts.size(); ++k) {
    const double t0 = ts[k], t1 = ts[k + 1];
    if (!(t1 - t0 > tol)) continue;
    const double mid = 0.5 * (t0 + t1);
    const BezierPatchPiece* A = pieceAt(Ap, mid);
    const BezierPatchPiece* B = pieceAt(Bp, rep.slope * mid + rep.offset);
    if (A == nullptr || B == nullptr) {
      rep.notes.push_back("exact route: no Bezier piece at a seam parameter (sampled route used)");
      rep.exact.clear();
      return false;
    }
    const double s0 = rep.slope * t0 + rep.offset, s1 = rep.slope * t1 + rep.offset;
    const double hA = A->u.length(), hB = B->u.length(), ht = t1 - t0;
    const BernsteinPatch PA = homogeneousPiece(A->patch, integral, c, L)
                                  .restricted(0.0, 1.0, (t0 - A->v.lo) / A->v.length(), (t1 - A->v.lo) / A->v.length())
                                  .reversedU();
    const BernsteinPatch PB = homogeneousPiece(B->patch, integral, c, L)
                                  .restricted(0.0, 1.0, (s0 - B->v.lo) / B->v.length(), (s1 - B->v.lo) / B->v.length());
    std::vector<std::vector<BernsteinPoly>> X(static_cast<size_t>(n + 1));
    std::vector<BernsteinPoly> Y;
    for (int a = 0; a <= n; ++a) {
      for (int b = 0; a + b <= n; ++b)
        X[static_cast<size_t>(a)].push_back(PA.derivative(a, b).isoU(1.0) * (1.0 / (std::pow(hA, a) * std::pow(ht, b))));
      Y.push_back(PB.derivative(a, 0).isoU(0.0) * (1.0 / std::pow(hB, a)));
    }
    auto r = exactGcnFromBoundary(X, Y, eo);
    if (!r) {
      rep.notes.push_back("exact route not applied: " + r.status().message());
      rep.exact.clear();
      return false;
    }
    rep.exact.push_back({{t0, t1}, std::move(r).value()});
  }
  return !rep.exact.empty();
}

std::vector<double> spanSamples(const std::vector<double>& breaks, Interval overlap, int perSpan) {
  std::vector<double> s;
  std::vector<double> b{overlap.lo};
  for (double x : breaks)
    if (x > overlap.lo && x < overlap.hi) b.push_back(x);
  b.push_back(overlap.hi);
  for (size_t k = 0; k + 1 < b.size(); ++k)
    for (int i = 0; i < perSpan; ++i) s.push_back(b[k] + (b[k + 1] - b[k]) * (i + 0.5) / perSpan);
  return s;
}

/// Fills the verdict from the sampled route (when the exact route is not used) and applies the slope rule for C^k.
void finish(GcnReport& rep, const GcnOptions& opt) {
  const int n = opt.order;
  if (rep.exact.empty()) {
    rep.certified = false;
    rep.gcOrder = rep.sampled.gcOrder;
    rep.cOrder = rep.sampled.cOrder;
    const int len = std::min(n + 1, rep.gcOrder + 2);
    rep.residuals.assign(rep.sampled.residuals.begin(), rep.sampled.residuals.begin() + len);
    for (const std::string& note : rep.sampled.notes) rep.notes.push_back(note);
  } else {
    rep.certified = true;
    rep.gcOrder = n;
    rep.cOrder = n;
    rep.gcnCase = rep.exact.front().result.gcnCase;
    for (const GcnExactPiece& p : rep.exact) {
      rep.gcOrder = std::min(rep.gcOrder, p.result.gcOrder);
      rep.cOrder = std::min(rep.cOrder, p.result.cOrder);
      rep.certified = rep.certified && p.result.certified;
      for (size_t m = 0; m < p.result.residuals.size(); ++m) {
        if (rep.residuals.size() <= m) rep.residuals.push_back(0.0);
        rep.residuals[m] = std::max(rep.residuals[m], p.result.residuals[m]);
      }
      for (const std::string& note : p.result.notes)
        if (std::find(rep.notes.begin(), rep.notes.end(), note) == rep.notes.end()) rep.notes.push_back(note);
    }
    rep.residuals.resize(static_cast<size_t>(std::min(n + 1, rep.gcOrder + 2)));
    if (rep.sampled.gcOrder != rep.gcOrder)
      rep.notes.push_back(fmt::format("the sampled route finds GC^{} (the exact verdict GC^{} is reported)",
                                      rep.sampled.gcOrder, rep.gcOrder));
  }
  if (rep.gcOrder >= 0 && std::abs(std::abs(rep.slope) - 1.0) > kMatchingSlopeTol) {
    rep.notes.push_back(fmt::format("edge parametrisations differ (slope {:.6g}): no parametric C^k", rep.slope));
    rep.cOrder = -1;
  }
}

Status checkOrder(int n) {
  if (n < 0 || n > kMaxGcnOrder) return invalidInput(fmt::format("GC^n order {} out of range [0, {}]", n, kMaxGcnOrder));
  return Status::ok();
}

ConnectingOptions connectingOptions(const GcnOptions& opt) {
  ConnectingOptions co = opt.connecting;
  co.order = opt.order;
  co.pbar = {1.0};
  co.qbar = {};
  co.requirePositiveJacobian = true;
  return co;
}

}  // namespace

Result<GcnReport> analyzeGcn(const Patch& pa, Edge ea, const Patch& pb, Edge eb, const GcnOptions& opt) {
  if (Status s = checkOrder(opt.order); !s) return s;
  const std::string label = seamLabel(pa.name, ea, pb.name, eb);
  auto seam = analyzeSeam(pa, ea, pb, eb, opt.seam);
  if (!seam) return seam.status();
  GcnReport rep;
  rep.a = pa.name;
  rep.b = pb.name;
  rep.aEdge = ea;
  rep.bEdge = eb;
  rep.overlapA = seam->overlapA;
  rep.overlapB = seam->overlapB;
  const double k = rep.overlapB.length() / rep.overlapA.length();
  rep.slope = seam->reversed ? -k : k;
  rep.offset = seam->reversed ? rep.overlapB.hi + k * rep.overlapA.lo : rep.overlapB.lo - k * rep.overlapA.lo;
  if (seam->correspondence != Correspondence::kAffine) {
    if (seam->geometric == GeometricClass::kNone) {
      rep.notes.push_back(fmt::format("the edges do not meet (gap up to {:.3g}): no GC^0", seam->g0Max));
      return rep;
    }
    return Status(ErrorCode::kUnsupported,
                  fmt::format("{}: the edges correspond by a {} map, GC^n needs an affine edge correspondence", label,
                              toString(seam->correspondence)));
  }
  BoundingBox box = controlBox(pa.surface);
  box.add(controlBox(pb.surface));
  const Vec3 c = 0.5 * (box.min + box.max);
  const double L = std::max(0.5 * box.diagonal(), std::numeric_limits<double>::min());

  // Sampled route.
  const HomogeneousSurface A = homogeneousSurface(pa.surface, pa.name).normalized(c, L).edgeFrame(ea, true);
  const HomogeneousSurface B = homogeneousSurface(pb.surface, pb.name).normalized(c, L).edgeFrame(eb, false);
  const ParameterLine e1{Vec2(0.0, 0.0), Vec2(0.0, 1.0)}, e2{Vec2(0.0, rep.offset), Vec2(0.0, rep.slope)};
  const std::vector<double> breaks = isUEdge(ea) ? pa.surface.knotsV().breakpoints() : pa.surface.knotsU().breakpoints();
  const std::vector<double> samples = spanSamples(breaks, rep.overlapA, std::max(opt.samplesPerSpan, 2));
  auto sampled = solveConnectingFunctions(A, e1, B, e2, samples, connectingOptions(opt));
  if (!sampled) return sampled.status().withContext(label);
  rep.sampled = std::move(sampled).value();

  if (opt.exactRoute) exactRoute(pa, ea, pb, eb, rep, c, L, opt);
  finish(rep, opt);
  return rep;
}

Result<GcnReport> analyzeGcn(const HomogeneousSurface& a, Edge ea, const HomogeneousSurface& b, Edge eb,
                             const GcnOptions& opt) {
  if (Status s = checkOrder(opt.order); !s) return s;
  const std::string label = seamLabel(a.name(), ea, b.name(), eb);
  GcnReport rep;
  rep.a = a.name();
  rep.b = b.name();
  rep.aEdge = ea;
  rep.bEdge = eb;
  const HomogeneousSurface fa = a.edgeFrame(ea, true), fb = b.edgeFrame(eb, false);
  rep.overlapA = fa.domainV();
  rep.overlapB = fb.domainV();
  // End-to-end matching: the orientation whose end points are closer.
  Vec3 ends[4];
  {
    const double params[4] = {rep.overlapA.lo, rep.overlapA.hi, rep.overlapB.lo, rep.overlapB.hi};
    for (int i = 0; i < 4; ++i) {
      auto p = (i < 2 ? fa : fb).point(0.0, params[i]);
      if (!p) return p.status().withContext(label);
      ends[i] = *p;
    }
  }
  const bool reversed = (ends[0] - ends[3]).norm() + (ends[1] - ends[2]).norm() <
                        (ends[0] - ends[2]).norm() + (ends[1] - ends[3]).norm();
  const double k = rep.overlapB.length() / rep.overlapA.length();
  rep.slope = reversed ? -k : k;
  rep.offset = reversed ? rep.overlapB.hi + k * rep.overlapA.lo : rep.overlapB.lo - k * rep.overlapA.lo;
  // Normalisation of coordinates from a grid of points of both surfaces.
  BoundingBox box;
  for (const HomogeneousSurface* s : {&a, &b})
    for (int i = 0; i <= kSizingGrid; ++i)
      for (int j = 0; j <= kSizingGrid; ++j) {
        const double u = s->domainU().lo + s->domainU().length() * i / kSizingGrid;
        const double v = s->domainV().lo + s->domainV().length() * j / kSizingGrid;
        if (auto p = s->point(u, v); p && p->allFinite()) box.add(*p);
      }
  const Vec3 c = box.empty() ? Vec3::Zero() : Vec3(0.5 * (box.min + box.max));
  const double L = box.empty() || !(box.diagonal() > 0.0) ? 1.0 : 0.5 * box.diagonal();
  const HomogeneousSurface A = a.normalized(c, L).edgeFrame(ea, true);
  const HomogeneousSurface B = b.normalized(c, L).edgeFrame(eb, false);
  const ParameterLine e1{Vec2(0.0, 0.0), Vec2(0.0, 1.0)}, e2{Vec2(0.0, rep.offset), Vec2(0.0, rep.slope)};
  const int count = std::max(opt.surfaceSamples, 2);
  std::vector<double> samples;
  for (int i = 0; i < count; ++i) samples.push_back(rep.overlapA.lo + rep.overlapA.length() * (i + 0.5) / count);
  auto sampled = solveConnectingFunctions(A, e1, B, e2, samples, connectingOptions(opt));
  if (!sampled) return sampled.status().withContext(label);
  rep.sampled = std::move(sampled).value();
  finish(rep, opt);
  return rep;
}

}  // namespace seam::rational
