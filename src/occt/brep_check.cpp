// OCC_CATCH_SIGNALS converts a signal raised inside OpenCASCADE into a Standard_Failure only when this macro is set
// (as in cad_io.cpp; see docs/reliability.md, "OpenCASCADE guards").
#ifndef OCC_CONVERT_SIGNALS
#define OCC_CONVERT_SIGNALS
#endif
#include "seam/occt/brep_check.h"

#include <fmt/format.h>

#include <BRepAdaptor_Curve.hxx>
#include <BRepBndLib.hxx>
#include <BRepBuilderAPI_Sewing.hxx>
#include <BRepLib.hxx>
#include <BRepTools.hxx>
#include <BRep_Tool.hxx>
#include <Bnd_Box.hxx>
#include <Geom2dConvert.hxx>
#include <Geom2dAdaptor_Curve.hxx>
#include <GeomAdaptor_Surface.hxx>
#include <Geom2d_BSplineCurve.hxx>
#include <Geom2d_Curve.hxx>
#include <Geom2d_TrimmedCurve.hxx>
#include <Geom_RectangularTrimmedSurface.hxx>
#include <Geom_Surface.hxx>
#include <OSD_Signal.hxx>
#include <Standard_ErrorHandler.hxx>
#include <Standard_Failure.hxx>
#include <TColStd_Array1OfReal.hxx>
#include <TopExp.hxx>
#include <TopExp_Explorer.hxx>
#include <TopTools_DataMapOfShapeInteger.hxx>
#include <TopTools_IndexedDataMapOfShapeListOfShape.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopTools_ListOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Edge.hxx>
#include <TopoDS_Face.hxx>
#include <algorithm>
#include <chrono>
#include <array>
#include <bit>
#include <cstdint>
#include <cmath>
#include <exception>
#include <map>
#include <memory>
#include <mutex>
#include <numbers>

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>
#include <tbb/task_group.h>

#include "continuity/sampling.h"
#include "occt/brep_check_internal.h"
#include "occt/brep_model.h"
#include "occt/cad_internal.h"
#include "occt/face_mesh.h"
#include "occt/pcurve_correspondence.h"

namespace seam::occt {

namespace fs = std::filesystem;

namespace {

/// Minimum samples along a sampled edge (issue: >= 64 per span).
constexpr int kMinSamples = 64;
/// Normal curvatures below this / (model size) count as flat when forming relative jumps (as in analyzeSeam).
constexpr double kFlatCurvatureRatio = 1e-3;
constexpr double kRadToDeg = 180.0 / std::numbers::pi;
/// The certified pcurve route is taken only where the converted patch reproduces the face's OpenCASCADE surface
/// along the pcurve (same parametrisation) within this fraction of the model size, at kParamCheckPoints points.
constexpr double kSameParametrisationRel = 1e-9;
constexpr int kParamCheckPoints = 16;
/// The note of a seam sampled through the pcurves (replaced when G0 and G1 are certified afterwards).
constexpr const char* kSampledNote =
    "sampled through the pcurves of the shared B-rep edge (trimmed faces): not certified";
/// Gauss-Newton steps, and the step relative to the domain at which they stop, of the projection of a face's point
/// onto its converted patch (isoLineInPatch).
constexpr int kProjectIterations = 30;
constexpr double kProjectStepRel = 1e-15;
/// Intervals at which an edge re-expressed as an iso-line of a converted patch is checked against the face's points.
constexpr int kReparamCheckPoints = 32;
/// A parameter that changes by less than this fraction of the domain along an edge is constant there (iso-lines).
constexpr double kIsoLineRel = 1e-9;
/// Points per edge polyline (drawings in reports).
constexpr int kPolylinePoints = 24;
/// Gauss-Newton steps that move B's partner point to the point of B's edge closest to A's (sampled route), and the
/// step, relative to B's parameter range, below which the iteration has converged.
constexpr int kPartnerIterations = 12;
constexpr double kPartnerStepRel = 1e-15;

/// True when the failure is a signal caught inside OpenCASCADE (a crash, converted by detail::OcctSignalGuard).
using detail::isSignal;

Vec3 toVec(const gp_Vec& v) { return {v.X(), v.Y(), v.Z()}; }
Vec3 toVec(const gp_Pnt& p) { return {p.X(), p.Y(), p.Z()}; }

std::string continuityName(GeomAbs_Shape s) {
  switch (s) {
    case GeomAbs_C0: return "C0";
    case GeomAbs_G1: return "G1";
    case GeomAbs_C1: return "C1";
    case GeomAbs_G2: return "G2";
    case GeomAbs_C2: return "C2";
    case GeomAbs_C3: return "C3";
    case GeomAbs_CN: return "CN";
  }
  return "?";
}

/// The type name of a pcurve under its trims ("Geom2d_Circle", ...).
std::string basisName(Handle(Geom2d_Curve) c) {
  while (const auto t = Handle(Geom2d_TrimmedCurve)::DownCast(c)) c = t->BasisCurve();
  return c->DynamicType()->Name();
}

/// Per face of the check, its parameter box (BRepTools::UVBounds, which bounds the pcurves of all the face's edges,
/// projecting a plane's edges onto it afresh each time: ~3 % of a check when it was called per edge and side):
/// computed once, on first use, by whichever thread needs it first (std::call_once per face, as SpansCache), then
/// shared read-only by the face's edges. UVBounds looks at the face FORWARD, so the box does not depend on the
/// orientation in which an edge's ancestor list holds the face.
class FaceBoxCache {
 public:
  explicit FaceBoxCache(const TopTools_IndexedMapOfShape& faces)
      : faces_(faces), once_(static_cast<size_t>(faces.Extent())), boxes_(static_cast<size_t>(faces.Extent())) {}
  /// The box of face `index` (1-based, as in the map). A Standard_Failure of UVBounds reaches the caller (and the
  /// next caller tries again: std::call_once sets nothing when its function throws).
  [[nodiscard]] const detail::ParamBox& at(int index) const {
    const size_t k = static_cast<size_t>(index - 1);
    std::call_once(once_[k], [&] {
      detail::ParamBox& b = boxes_[k];
      BRepTools::UVBounds(TopoDS::Face(faces_(index)), b.u0, b.u1, b.v0, b.v1);
    });
    return boxes_[k];
  }

 private:
  const TopTools_IndexedMapOfShape& faces_;
  mutable std::vector<std::once_flag> once_;
  mutable std::vector<detail::ParamBox> boxes_;
};

/// The side of the face's parameter box that the edge's pcurve runs along from corner to corner, if any.
std::optional<Edge> naturalSide(const TopoDS_Edge& e, const TopoDS_Face& f, const detail::ParamBox& box) {
  return detail::boxSideOf(e, f, box, true);
}

/// One face seen from the shared edge: its surface, the edge's pcurve on it and the sense of its normal.
struct FaceSide {
  Handle(Geom_Surface) surface;
  Handle(Geom2d_Curve) pcurve;
  double first = 0, last = 0;  // pcurve parameter range
  double sign = 1.0;           // -1 for a reversed face
  GeomAdaptor_Surface surfaceEval;  // the surface through its span cache (the sampled route's evaluations)
  Geom2dAdaptor_Curve pcurveEval;   // the pcurve through its span cache
};

struct PointData {
  Vec3 point = Vec3::Zero();
  double g0 = 0, g1 = 0, g2 = 0, curvature = 0;
  bool normalsOk = true;    // G1 measured (normals or their one-sided limits)
  bool curvatureOk = true;  // curvatures measured (well-conditioned charts)
};

/// B's edge parameter of the point of B's edge closest to A's edge point at t (A's pcurve parameter): from the
/// affine map of the two pcurve ranges (exact where the edge has SameParameter pcurves), refined by Gauss-Newton
/// steps on |S_B(c_B(s)) - S_A(c_A(t))|^2 so that the correspondence comes from the geometry, never from the
/// assumption that both pcurves share the edge's parameter.
double partnerParameter(const FaceSide& A, const FaceSide& B, double t) {
  double s = B.first + (t - A.first) / (A.last - A.first) * (B.last - B.first);
  const gp_Pnt2d uvA = A.pcurveEval.Value(t);
  const gp_Pnt p = A.surfaceEval.Value(uvA.X(), uvA.Y());
  const double range = B.last - B.first;
  for (int it = 0; it < kPartnerIterations; ++it) {
    gp_Pnt2d uv;
    gp_Vec2d d;
    B.pcurveEval.D1(s, uv, d);
    gp_Pnt q;
    gp_Vec su, sv;
    B.surfaceEval.D1(uv.X(), uv.Y(), q, su, sv);
    const Vec3 c1 = toVec(su) * d.X() + toVec(sv) * d.Y();
    const double c1n2 = c1.squaredNorm();
    if (!(c1n2 > 0.0)) break;  // a pole of B's edge: keep the affine partner
    const double step = (toVec(p) - toVec(q)).dot(c1) / c1n2;
    const double next = std::clamp(s + step, B.first, B.last);
    if (!std::isfinite(next)) break;
    const bool done = std::abs(next - s) <= kPartnerStepRel * range;
    s = next;
    if (done) break;
  }
  return s;
}

/// Measures at edge parameter t (A's pcurve parameter; B's partner point by partnerParameter).
PointData measure(const FaceSide& A, const FaceSide& B, double t) {
  PointData m;
  const double s = partnerParameter(A, B, t);
  gp_Pnt2d uvA, uvB;
  gp_Vec2d dA, dB;
  A.pcurveEval.D1(t, uvA, dA);
  B.pcurveEval.D1(s, uvB, dB);
  gp_Pnt pa, pb;
  gp_Vec au, av, auu, avv, auv, bu, bv, buu, bvv, buv;
  A.surfaceEval.D2(uvA.X(), uvA.Y(), pa, au, av, auu, avv, auv);
  B.surfaceEval.D2(uvB.X(), uvB.Y(), pb, bu, bv, buu, bvv, buv);
  m.point = toVec(pa);
  m.g0 = (toVec(pa) - toVec(pb)).norm();
  const Vec3 Au = toVec(au), Av = toVec(av), Bu = toVec(bu), Bv = toVec(bv);
  // Unit normals, or next to a pole their one-sided limits along the edge (derivatives of S_u, S_v along it).
  auto sideOf = [](double lo, double hi, double x) { return x - lo <= hi - x ? 1.0 : -1.0; };
  const std::optional<Vec3> uA = seam::detail::limitNormal(
      Au, Av, toVec(auu) * dA.X() + toVec(auv) * dA.Y(), toVec(auv) * dA.X() + toVec(avv) * dA.Y(),
      sideOf(A.first, A.last, t));
  const std::optional<Vec3> uB = seam::detail::limitNormal(
      Bu, Bv, toVec(buu) * dB.X() + toVec(buv) * dB.Y(), toVec(buv) * dB.X() + toVec(bvv) * dB.Y(),
      sideOf(B.first, B.last, s));
  const Vec3 T = Au * dA.X() + Av * dA.Y();
  if (!uA || !uB || !(T.norm() > 0.0)) {
    m.normalsOk = m.curvatureOk = false;
    return m;
  }
  const Vec3 nhA = A.sign * *uA, nhB = B.sign * *uB;
  m.g1 = std::atan2(nhA.cross(nhB).norm(), nhA.dot(nhB));
  if (seam::detail::chartConditioning(Au, Av) < seam::detail::kCurvatureChartRel ||
      seam::detail::chartConditioning(Bu, Bv) < seam::detail::kCurvatureChartRel) {
    m.curvatureOk = false;  // next to a pole: curvatures are round-off over a vanishing normal
    return m;
  }
  const Vec3 e1 = T.normalized(), e2 = nhA.cross(e1);
  const Eigen::Matrix2d SA = seam::detail::shapeInFrame(Au, Av, toVec(auu), toVec(auv), toVec(avv), nhA, e1, e2);
  const Eigen::Matrix2d SB = seam::detail::shapeInFrame(Bu, Bv, toVec(buu), toVec(buv), toVec(bvv), nhB, e1, e2);
  m.g2 = seam::detail::spectralNorm(SB - SA);
  m.curvature = std::max(seam::detail::spectralNorm(SA), seam::detail::spectralNorm(SB));
  return m;
}

/// The samples of an edge's measures through the pcurves: kMinSamples + 1 or more evenly spaced points (A's
/// parameter), the curvature reference and whether a normal vanishes at one of them.
struct EdgeSamples {
  std::vector<double> ts;
  std::vector<PointData> ms;
  double curvRef = 0.0;
  bool degenerate = false;
};

EdgeSamples sampleEdge(const TopoDS_Edge& edge, const FaceSide& A, const FaceSide& B, const SeamOptions& opt,
                       double modelSize) {
  int spans = 1;
  try {
    spans = std::max(1, BRepAdaptor_Curve(edge).NbIntervals(GeomAbs_C2));
  } catch (const Standard_Failure&) {
  }
  const int n = std::max(kMinSamples, std::max(opt.samplesPerSpan, 2) * spans);
  EdgeSamples s;
  s.ts.resize(static_cast<size_t>(n) + 1);
  s.ms.resize(s.ts.size());
  for (int i = 0; i <= n; ++i) {
    s.ts[static_cast<size_t>(i)] = A.first + (A.last - A.first) * i / n;
    s.ms[static_cast<size_t>(i)] = measure(A, B, s.ts[static_cast<size_t>(i)]);
  }
  const double flat = kFlatCurvatureRatio / std::max(modelSize, std::numeric_limits<double>::min());
  s.curvRef = flat;
  for (const PointData& m : s.ms) {
    s.curvRef = std::max(s.curvRef, m.curvature);
    s.degenerate |= !m.curvatureOk;
  }
  return s;
}

/// The sampled seam report through the pcurves (certified = false). The maxima are refined (Brent's parabolic
/// steps, detail::refinedMaximum) where `refineG0G1` / `refineG2` ask for it; where the certified route replaces
/// a measure's values afterwards (certifyThroughPCurves) its refinement is skipped and the best sample stands in
/// (the report does not keep it).
SeamReport sampledSeam(const EdgeSamples& s, const FaceSide& A, const FaceSide& B, const std::string& a,
                       const std::string& b, const SeamOptions& opt, bool refineG0G1 = true, bool refineG2 = true) {
  SeamReport rep;
  rep.a = a;
  rep.b = b;
  rep.overlapA = {A.first, A.last};
  rep.overlapB = {B.first, B.last};
  rep.correspondence = Correspondence::kProjection;
  const std::vector<double>& ts = s.ts;
  const std::vector<PointData>& ms = s.ms;
  const double curvRef = s.curvRef;
  // The measures made by the refinements, by parameter (bit pattern): the refinements of G0, G1 and G2 often
  // bracket the same sample, so that their refinements begin at the same point, and the worst location's
  // point is that of a measure already made. measure is a function of t alone up to round-off (the span caches of
  // the adaptors it evaluates through pick a parameter's span by its value, half-open; only a parameter within an
  // ulp of a knot may keep the neighbouring span's cache, whose value there agrees to round-off), so a kept measure
  // is the one a new call would make. The order of the calls is fixed per edge: the report does not depend on the
  // number of threads.
  std::vector<std::pair<std::uint64_t, PointData>> tried;
  auto measured = [&](double x) -> PointData {
    const auto key = std::bit_cast<std::uint64_t>(x);
    for (const auto& [k, m] : tried)
      if (k == key) return m;
    tried.emplace_back(key, measure(A, B, x));
    return tried.back().second;
  };
  // Parameter intervals between a sample where the curvature is not measured (a pole) and its neighbour where it
  // is: the G2 jump is undefined at the pole and round-off over the vanishing normal next to it (2e-4 mm from a
  // pole of trj3's F22/F23, two flat faces, it measured 0.75 of the flat curvature reference). Its maximum is not
  // refined into them, as on the patch route (analyzeSeam; issue 35 §2).
  std::vector<std::pair<double, double>> poleIntervals;
  for (size_t i = 0; i + 1 < ms.size(); ++i)
    if (ms[i].curvatureOk != ms[i + 1].curvatureOk) poleIntervals.emplace_back(ts[i], ts[i + 1]);
  const auto nearPole = [&](double x) {
    return std::any_of(poleIntervals.begin(), poleIntervals.end(),
                       [x](const auto& iv) { return x > iv.first && x < iv.second; });
  };
  // (t, value) of the refined maximum and its point, or of the best sample when not refined.
  auto best = [&](auto get, bool refine, bool awayFromPoles = false) -> std::pair<WorstLocation, double> {
    std::vector<double> v(ms.size());
    for (size_t i = 0; i < v.size(); ++i) v[i] = get(ms[i]);
    if (!refine) {
      const size_t i = static_cast<size_t>(std::max_element(v.begin(), v.end()) - v.begin());
      return {WorstLocation{ts[i], ms[i].point}, v[i]};
    }
    const auto [t, value] = seam::detail::refinedMaximum(
        ts, v, [&](double x) { return awayFromPoles && nearPole(x) ? 0.0 : get(measured(x)); });
    return {WorstLocation{t, measured(t).point}, value};
  };
  {
    const auto [at, v] = best([](const PointData& m) { return m.g0; }, refineG0G1);
    rep.g0Max = rep.g0Sampled = v;
    rep.g0Worst = at;
  }
  {
    const auto [at, v] = best([](const PointData& m) { return m.normalsOk ? m.g1 : 0.0; }, refineG0G1);
    rep.g1MaxDeg = rep.g1SampledDeg = v * kRadToDeg;
    rep.g1Worst = at;
  }
  {
    const auto [at, v] = best([](const PointData& m) { return m.curvatureOk ? m.g2 : 0.0; }, refineG2, true);
    rep.g2Max = rep.g2Sampled = v;
    rep.g2RelMax = rep.g2RelSampled = v / curvRef;
    rep.g2Worst = at;
  }
  if (opt.keepSamples)
    for (size_t i = 0; i < ts.size(); ++i)
      rep.samples.push_back({ts[i], ms[i].g0, ms[i].g1 * kRadToDeg, ms[i].g2, ms[i].g2 / curvRef});
  rep.certified = false;
  rep.notes.push_back(kSampledNote);
  rep.notes.push_back("faces of a B-rep have unrelated parametrisations: no C^k");
  if (s.degenerate) rep.notes.push_back("the normal vanishes somewhere on the edge (pole or degenerate edge)");
  rep.geometric = classifyGeometric(rep, opt.tol);  // sampled: no identities
  return rep;
}

/// A face's edge for the certified route: an exact curve in the patch's parameters, either in the edge's own
/// parameter (`ownParameter` false: the pcurve's B-spline form over [first, last]) or in a parameter of its own
/// (`ownParameter` true: the rational B-spline form of a circle or ellipse, whose parameter is not the angle; or an
/// iso-line of a converted analytic surface, whose patch parameter along a circle is not the angle). A side with
/// its own parameter is paired with the other face's edge by detail::correspondInParameterOf.
struct FacePCurve {
  PCurveSide side;
  bool ownParameter = false;
  std::string how;  ///< for the seam's notes, when ownParameter
};

/// The point of a converted (3-D) patch at (u, v), without the heap allocations of BSplineSurface::evaluate (~20
/// per call): pointAndFirstDerivatives forms the same basis values, sums them in the same order and divides by the
/// same weight, so the point is evaluate's bit for bit (OcctBRep.PatchPointIsTheSurfaceValueBitForBit).
Vec3 patchPoint(const BSplineSurface& patch, double u, double v) {
  Vec3 p, su, sv;
  patch.pointAndFirstDerivatives(u, v, p, su, sv);
  return p;
}

/// The patch parameters of the point of `patch` closest to x, by Gauss-Newton steps on |P(u, v) - x|^2 from `uv`
/// (clamped to the domain); x is expected on the patch (a point of the surface the patch converts).
std::array<double, 2> projectOntoPatch(const BSplineSurface& patch, const Vec3& x, std::array<double, 2> uv) {
  const Interval du = patch.domainU(), dv = patch.domainV();
  uv = {std::clamp(uv[0], du.lo, du.hi), std::clamp(uv[1], dv.lo, dv.hi)};
  for (int it = 0; it < kProjectIterations; ++it) {
    Vec3 p, su, sv;
    patch.pointAndFirstDerivatives(uv[0], uv[1], p, su, sv);
    const Vec3 r = x - p;
    const double a = su.dot(su), b = su.dot(sv), c = sv.dot(sv), det = a * c - b * b;
    if (!(det > 0.0)) break;  // a pole of the patch: keep the point reached
    const double ru = su.dot(r), rv = sv.dot(r);
    const double nu = std::clamp(uv[0] + (c * ru - b * rv) / det, du.lo, du.hi);
    const double nv = std::clamp(uv[1] + (a * rv - b * ru) / det, dv.lo, dv.hi);
    if (!std::isfinite(nu) || !std::isfinite(nv)) break;
    const bool done = std::abs(nu - uv[0]) <= kProjectStepRel * du.length() &&
                      std::abs(nv - uv[1]) <= kProjectStepRel * dv.length();
    uv = {nu, nv};
    if (done) break;
  }
  return uv;
}

/// For a face whose converted patch has other parameters than the face (a cylinder, cone, sphere, torus or surface
/// of revolution: along a circle the patch parameter is a rational function of tan(angle / 2), not the angle):
/// the edge as an iso-line of the patch, when it is an iso-line of the face (a tensor-product conversion maps the
/// face's iso-lines to the patch's, each direction on its own). The line runs in a parameter of its own, [0, 1],
/// from the projection onto the patch of the edge's first face point to that of its last; it is kept only when the
/// projections of the face's points at kReparamCheckPoints + 1 parameters lie on it and the patch reproduces them
/// within kSameParametrisationRel of the model size.
Result<BSplineCurve> isoLineInPatch(const FaceSide& f, const BSplineCurve& facePCurve, const BSplineSurface& patch,
                                    double modelSize) {
  const Interval dom[2] = {patch.domainU(), patch.domainV()};
  const Matrix& cp = facePCurve.points();
  int fixed = -1;  // the face parameter that is constant along the edge
  for (int k = 0; k < 2; ++k)
    if (cp.col(k).maxCoeff() - cp.col(k).minCoeff() <= kIsoLineRel * dom[k].length()) fixed = k;
  if (fixed < 0)
    return Status(ErrorCode::kUnsupported,
                  "the patch does not reproduce the face's surface in its own parameters (a converted analytic "
                  "surface), and the edge is no iso-line of the face");
  const size_t n = kReparamCheckPoints + 1;
  std::vector<Vec3> x(n);
  std::vector<std::array<double, 2>> uv(n);
  for (size_t i = 0; i < n; ++i) {
    const double t = f.first + (f.last - f.first) * static_cast<double>(i) / kReparamCheckPoints;
    const VecX o = facePCurve.evaluate(t);
    const gp_Pnt2d q = f.pcurve->Value(t);
    x[i] = toVec(f.surface->Value(q.X(), q.Y()));
    uv[i] = projectOntoPatch(patch, x[i], {o[0], o[1]});
  }
  const int moving = 1 - fixed;
  const double level = uv[n / 2][static_cast<size_t>(fixed)];
  for (size_t i = 0; i < n; ++i) {
    const bool onLine = std::abs(uv[i][static_cast<size_t>(fixed)] - level) <= kIsoLineRel * dom[fixed].length();
    const Vec3 y = patchPoint(patch, uv[i][0], uv[i][1]);
    if (!onLine || !((y - x[i]).norm() <= kSameParametrisationRel * modelSize))
      return Status(ErrorCode::kUnsupported,
                    "the patch does not reproduce the face's surface in its own parameters (a converted analytic "
                    "surface), and its edge is no iso-line of the patch");
  }
  const double m0 = uv.front()[static_cast<size_t>(moving)], m1 = uv.back()[static_cast<size_t>(moving)];
  if (!(std::abs(m1 - m0) > kIsoLineRel * dom[moving].length()))
    return Status(ErrorCode::kUnsupported, "the edge is a single point of the converted patch");
  Matrix pts(2, 2);
  pts(0, fixed) = pts(1, fixed) = level;
  pts(0, moving) = m0;
  pts(1, moving) = m1;
  return BSplineCurve::create(1, std::vector<double>{0.0, 0.0, 1.0, 1.0}, std::move(pts), VecX());
}

/// kUnsupported, with the reason, when OpenCASCADE cannot convert the pcurve, when it leaves the patch's domain, or
/// when the patch made from the face reproduces the face's edge neither along the pcurve nor as an iso-line.
Result<FacePCurve> pcurveSide(const FaceSide& f, const FaceBoxCache& boxes, int face, const BSplineSurface& patch,
                              double modelSize) {
  auto why = [&](std::string_view reason) {
    std::string type = "?";
    try {
      Handle(Geom_Surface) base = f.surface;
      while (const auto rts = Handle(Geom_RectangularTrimmedSurface)::DownCast(base)) base = rts->BasisSurface();
      type = base->DynamicType()->Name();
    } catch (const Standard_Failure&) {
    }
    return Status(ErrorCode::kUnsupported, fmt::format("{} (face surface {})", reason, type));
  };
  try {
    const Handle(Geom2d_TrimmedCurve) trimmed = new Geom2d_TrimmedCurve(f.pcurve, f.first, f.last);
    const Handle(Geom2d_BSplineCurve) bs = Geom2dConvert::CurveToBSplineCurve(trimmed);
    if (bs.IsNull()) return why("OpenCASCADE cannot convert the pcurve to a B-spline");

    TColStd_Array1OfReal knots(1, bs->NbPoles() + bs->Degree() + 1);
    bs->KnotSequence(knots);
    Matrix pts(bs->NbPoles(), 2);
    for (int i = 1; i <= bs->NbPoles(); ++i) pts.row(i - 1) << bs->Pole(i).X(), bs->Pole(i).Y();
    // On a periodic surface a pcurve may use another period than the patch's domain: shift it by whole periods so
    // that its middle lies in the domain (the surface is the same there). A pcurve already in the domain stays:
    // the two pcurves of a closed seam lie on its two ends (v = 0 and v = 1), and on a surface that is only C0
    // across its period (OCC17026-2.igs: a 90-degree crease) the two ends are two different one-sided surfaces.
    {
      const gp_Pnt2d mid = f.pcurve->Value(0.5 * (f.first + f.last));
      const Interval dom[2] = {patch.domainU(), patch.domainV()};
      const bool periodic[2] = {f.surface->IsUPeriodic(), f.surface->IsVPeriodic()};
      const double at[2] = {mid.X(), mid.Y()};
      for (int k = 0; k < 2; ++k) {
        if (!periodic[k] || (at[k] >= dom[k].lo && at[k] <= dom[k].hi)) continue;
        const double period = k == 0 ? f.surface->UPeriod() : f.surface->VPeriod();
        if (!(period > 0.0)) continue;
        // The whole periods that bring the middle nearest the domain's centre: a pcurve on the domain's side (u = 2
        // on a patch converted over [10, 14], period 8, trj3_s1-al-214.stp F33/F52) lands on it within round-off,
        // which the pcurve's domain slack covers (floor((hi - at) / period) missed it when hi was 14 less an ulp).
        const double shift = period * std::round((0.5 * (dom[k].lo + dom[k].hi) - at[k]) / period);
        const double moved = at[k] + shift, slack = kBRepDomainRelTol * dom[k].length();
        if (shift != 0.0 && moved >= dom[k].lo - slack && moved <= dom[k].hi + slack) pts.col(k).array() += shift;
      }
    }
    VecX weights;
    if (bs->IsRational()) {
      weights.resize(bs->NbPoles());
      for (int i = 1; i <= bs->NbPoles(); ++i) weights[i - 1] = bs->Weight(i);
    }
    Result<BSplineCurve> c = BSplineCurve::create(bs->Degree(), std::vector<double>(knots.begin(), knots.end()),
                                                  std::move(pts), std::move(weights));
    if (!c) return why("the pcurve's B-spline data are invalid: " + c.status().message());
    PCurveSide side;
    side.surface = &patch;
    side.pcurve = std::move(c).value();
    side.range = {f.first, f.last};
    const detail::ParamBox& box = boxes.at(face);
    side.faceU = {box.u0, box.u1};
    side.faceV = {box.v0, box.v1};
    side.normalSign = f.sign;
    const Interval pd = patch.domainU(), qd = patch.domainV();
    // A pcurve may overshoot its bounded surface by up to its edge's tolerance (trj3_s1-al-214.stp: 4e-4 of the
    // domain): the face's boundary there is the surface's end-span polynomial continued, as OpenCASCADE evaluates
    // it, and the certified route composes that same polynomial (PCurveSide::domainSlackRel).
    side.domainSlackRel = kBRepDomainRelTol;
    const double slackU = kBRepDomainRelTol * pd.length(), slackV = kBRepDomainRelTol * qd.length();
    for (int i = 0; i <= kParamCheckPoints; ++i) {
      const double t = f.first + (f.last - f.first) * i / kParamCheckPoints;
      const VecX uv = side.pcurve.evaluate(t);
      if (uv[0] < pd.lo - slackU || uv[0] > pd.hi + slackU || uv[1] < qd.lo - slackV || uv[1] > qd.hi + slackV)
        return why(fmt::format("the pcurve leaves the patch's parameter domain: ({:.9g}, {:.9g}) outside [{:.9g}, "
                               "{:.9g}] x [{:.9g}, {:.9g}]",
                               uv[0], uv[1], pd.lo, pd.hi, qd.lo, qd.hi));
      // Does the patch reproduce the face's surface in its own parameters? Compared inside the domain (the patch's
      // evaluator clamps; OpenCASCADE's continues the end span).
      const double cu = std::clamp(uv[0], pd.lo, pd.hi), cv = std::clamp(uv[1], qd.lo, qd.hi);
      const Vec3 x = patchPoint(patch, cu, cv);
      if ((x - toVec(f.surface->Value(cu, cv))).norm() > kSameParametrisationRel * modelSize) {
        // A converted analytic surface: the edge as an iso-line of the patch, in a parameter of its own.
        Result<BSplineCurve> line = isoLineInPatch(f, side.pcurve, patch, modelSize);
        if (!line) return why(line.status().message());
        side.pcurve = std::move(line).value();
        side.range = {0.0, 1.0};
        side.faceU = pd;  // the patch converts the face's surface over the face's box
        side.faceV = qd;
        return FacePCurve{std::move(side), true,
                          "an iso-line of its converted patch (whose parameter is not the angle)"};
      }
      // The B-spline form of the pcurve must keep the pcurve's own parameter (the edge's) for the two faces to be
      // paired by parameter: a circle or ellipse becomes a rational B-spline whose parameter differs from the
      // angle by up to ~0.016 rad (evaluating the other face at the same parameter would measure a gap of
      // 2 R sin(error / 2) that is not there). Such a form is exact in a parameter of its own: the other face is
      // paired with it by correspondence.
      const gp_Pnt2d o = f.pcurve->Value(t);
      if ((toVec(f.surface->Value(uv[0], uv[1])) - toVec(f.surface->Value(o.X(), o.Y()))).norm() >
          kSameParametrisationRel * modelSize) {
        side.range = side.pcurve.domain();
        return FacePCurve{std::move(side), true,
                          fmt::format("the rational B-spline form of its {} pcurve (whose parameter is not the angle)",
                                      basisName(f.pcurve))};
      }
    }
    return FacePCurve{std::move(side), false, {}};
  } catch (const Standard_Failure& e) {
    return why(std::string("OpenCASCADE failed on the pcurve: ") + e.GetMessageString());
  }
}

/// Replaces the sampled G0 / G1 (and, on G1 identities, G2) values by certified ones where the pcurves and surfaces
/// compose exactly.
/// `r` = certifyPCurveSeam(a, b, opt), computed before the sampled report (EdgeCertificate).
void certifyThroughPCurves(SeamReport& rep, const Result<PCurveSeamBounds>& r, const PCurveSide& a,
                           const SeamOptions& opt, double modelSize) {
  if (!r) {
    rep.notes.push_back(fmt::format("not certified: {}", r.status().message()));
    return;
  }
  // The composed route's own values replace the sampled ones for G0 and G1: the same surfaces, each face
  // evaluated on its own side of a knot line (OpenCASCADE evaluates a surface shared by two faces on one side
  // there), and no direction noise near poles, where the exact normal keeps its limit.
  auto pointAt = [&](double t) {
    const VecX uv = a.pcurve.evaluate(t);
    const Interval du = a.surface->domainU(), dv = a.surface->domainV();
    return Vec3(a.surface->evaluate(std::clamp(uv[0], du.lo, du.hi), std::clamp(uv[1], dv.lo, dv.hi)).head<3>());
  };
  rep.g0Sampled = r->g0Sampled;
  rep.g0Max = std::max(r->g0Bound, r->g0Sampled);
  rep.g0Worst = {r->g0At, pointAt(r->g0At)};
  rep.g1SampledDeg = r->g1SampledDeg;
  rep.g1MaxDeg = std::max(r->g1BoundDeg, r->g1SampledDeg);
  rep.g1Worst = {r->g1At, pointAt(r->g1At)};
  rep.g1Identity = r->g1Identity;
  rep.g1PoleT = r->g1PoleT;
  rep.certified = !r->g1PoleT;
  std::erase_if(rep.notes, [](const std::string& n) { return n.starts_with(kSampledNote); });
  std::string g2;
  if (r->g2Certified) {
    // Relative G2 against the composed route's own curvature reference (curvatures found on the seam: no larger
    // than the true maximum, so the relative bound stays an upper bound).
    const double flat = kFlatCurvatureRatio / std::max(modelSize, std::numeric_limits<double>::min());
    const double curvRef = std::max(flat, r->curvatureMax);
    rep.g2Sampled = r->g2Sampled;
    rep.g2Max = std::max(r->g2Bound, r->g2Sampled);
    rep.g2RelSampled = rep.g2Sampled / curvRef;
    rep.g2RelMax = rep.g2Max / curvRef;
    rep.g2Worst = {r->g2At, pointAt(r->g2At)};
    rep.g2Identity = r->g2Identity;
    g2 = fmt::format("G2 certified too (degree <= {})", r->maxDegreeG2);
  } else if (r->g2Identity) {
    // The Lemma 2 residual vanishes as a polynomial (G2 wherever the normal is defined); the values stay sampled.
    rep.g2Identity = true;
    g2 = fmt::format("G2 proved as an identity (Lemma 2 residual zero), its values sampled ({})", r->g2Why);
  } else {
    g2 = fmt::format("G2 sampled through the pcurves ({})", r->g2Why);
  }
  if (r->g1PoleT) {
    // No bound through the vanishing normal, no identity: the angle is measured (issue 35 section 2), as on patch
    // seams (analyzeSeam).
    rep.notes.insert(rep.notes.begin(),
                     fmt::format("not certified: a normal vanishes at t = {:.6g}, where the G1 bound cannot close; the "
                                 "angle shown ({:.6g} deg) is measured where both normals are defined; G0 certified "
                                 "through the pcurves composed with the surfaces ({} pieces, degree <= {})",
                                 *r->g1PoleT, r->g1SampledDeg, r->pieces, r->maxDegree));
  } else {
    rep.notes.insert(rep.notes.begin(),
                     fmt::format("G0 and G1 certified through the pcurves composed with the surfaces in Bernstein "
                                 "form ({} pieces, degree <= {}); {}",
                                 r->pieces, r->maxDegree, g2));
  }
  reconcileVerdict(rep, opt.tol);
}

/// An equal-parameter gap bound above this fraction of the distance tolerance is measured again between the
/// boundaries (tryCertificate). At 1 (the tolerance itself) a 1e-3 mm model whose pcurve drifts by 5e-5 kept that as
/// its gap where the boundaries coincide (OcctTruth.SeamGapsAreBetweenTheBoundariesWhenPCurvesDriftOrOverhang).
constexpr double kDriftRetryFraction = 0.01;

/// Per converted patch, its spans for certifyPCurveSeam (surfaceSpans): built once, on first use, by
/// whichever thread needs them first (std::call_once per patch, no global lock), then shared read-only by all
/// its seams.
class SpansCache {
 public:
  explicit SpansCache(const std::vector<Patch>& patches)
      : patches_(patches), once_(patches.size()), spans_(patches.size()) {}
  [[nodiscard]] const SurfaceSpans* at(size_t k) const {
    std::call_once(once_[k], [&] { spans_[k] = surfaceSpans(patches_[k].surface); });
    return spans_[k].get();
  }

 private:
  const std::vector<Patch>& patches_;
  mutable std::vector<std::once_flag> once_;
  mutable std::vector<std::shared_ptr<const SurfaceSpans>> spans_;
};

/// The certified route of an edge, tried before its sampled report is made (the sampled values the certified ones
/// replace are then not refined): both sides' exact pcurves (pcurveSide), and when the two faces' edges do not
/// share a parameter, B's side (or A's, when only B has a parameter of its own, or when B's pcurve has the higher
/// degree) re-expressed in the other's parameter by a monotone piecewise-cubic correspondence
/// (detail::correspondInParameterOf); then certifyPCurveSeam. Filled in place (a and b point into it).
struct EdgeCertificate {
  std::optional<Result<FacePCurve>> sideA, sideB;
  std::optional<Result<detail::Correspondence>> correspondence;
  bool byCorrespondence = false, masterA = true, sameParameter = false;
  SeamOptions opt;
  const PCurveSide *a = nullptr, *b = nullptr;           ///< the sides composed, when the route was tried
  std::optional<Result<PCurveSeamBounds>> bounds;        ///< certifyPCurveSeam(*a, *b, opt), when tried
  std::string failure;                                   ///< the note when the route could not be tried
  /// The certified gap at equal edge parameters, when it was above the tolerance and the closest-point pairing
  /// certified a smaller one (which replaced it); 0 otherwise.
  double equalParameterGap = 0.0;
  /// The certified angle at equal edge parameters (degrees), when samples between closest points lay above it and
  /// the closest-point pairing certified the edge instead (retryAngleByClosestPoints); 0 otherwise.
  double equalParameterAngleDeg = 0.0;
  /// The largest angle of the sampled route (A's edge points and the closest points of B's edge), degrees.
  double closestSampleAngleDeg = 0.0;
  /// The certified angle lies above seam's strict angle (kStrictAngleDeg, or the tolerance when smaller), the samples
  /// between closest points do not, the pcurves drift and the closest-point pairing could not be certified
  /// (retryAngleByClosestPoints): the angle is the pairing's, and the samples' angle is shown.
  bool angleFromPairing = false;
  /// G0 and G1 (g2: and G2) values will come from the certified route (unless reconcileVerdict withdraws them).
  [[nodiscard]] bool certifies() const { return bounds && bounds->isOk(); }
  [[nodiscard]] bool certifiesG2() const { return certifies() && (*bounds)->g2Certified; }
};

/// Pairs the two sides of `c` by a monotone piecewise-cubic correspondence: the master keeps its parameter; the
/// other is composed with a cubic (its degree triples): master = the side with its own parameter, or of the higher
/// pcurve degree. Sets c.a and c.b, or c.failure (c.a stays null).
void pairByCorrespondence(EdgeCertificate& c) {
  const FacePCurve& sa = **c.sideA;
  const FacePCurve& sb = **c.sideB;
  c.byCorrespondence = true;
  c.masterA = sa.ownParameter != sb.ownParameter ? sa.ownParameter : sa.side.pcurve.degree() >= sb.side.pcurve.degree();
  const FacePCurve& master = c.masterA ? sa : sb;
  const FacePCurve& other = c.masterA ? sb : sa;
  c.correspondence.emplace(detail::correspondInParameterOf(master.side, other.side, c.opt.tol.distance));
  if (!*c.correspondence) {
    c.failure = fmt::format("not certified: no common parameter for the two edges: {}",
                            c.correspondence->status().message());
    return;
  }
  c.opt.maxBoundWork = std::min(c.opt.maxBoundWork, detail::kCorrespondenceBoundWork);
  c.a = c.masterA ? &master.side : &(*c.correspondence)->b;
  c.b = c.masterA ? &(*c.correspondence)->b : &master.side;
}

/// a and b point into c's own optionals: point them again after c was moved or copied.
void repoint(EdgeCertificate& c) {
  c.a = c.masterA ? &(*c.sideA)->side : &(*c.correspondence)->b;
  c.b = c.masterA ? &(*c.correspondence)->b : &(*c.sideB)->side;
}

/// The certificate of c's two sides paired by the closest-point correspondence (pairByCorrespondence) instead of
/// their equal edge parameters, when it certifies: the retry of a SameParameter edge whose pcurves drift.
std::optional<EdgeCertificate> closestPointCertificate(const EdgeCertificate& c, const SpansCache& spans,
                                                       size_t patchA, size_t patchB) {
  EdgeCertificate closest;
  closest.sideA = c.sideA;
  closest.sideB = c.sideB;
  closest.sameParameter = true;
  closest.opt = c.opt;
  pairByCorrespondence(closest);
  if (closest.a == nullptr) return std::nullopt;
  closest.bounds.emplace(certifyPCurveSeam(*closest.a, *closest.b, closest.opt, spans.at(patchA), spans.at(patchB)));
  if (!closest.certifies()) return std::nullopt;
  return closest;
}

/// c becomes `closest` (its pointers into its own data renewed).
void adopt(EdgeCertificate& c, EdgeCertificate&& closest) {
  c = std::move(closest);
  repoint(c);
}

void tryCertificate(EdgeCertificate& c, const FaceSide& A, const FaceSide& B, const FaceBoxCache& boxes, int fa,
                    int fb, const BSplineSurface& pa, const BSplineSurface& pb,
                    const TopoDS_Edge& edge, const std::string& nameA, const std::string& nameB,
                    const SeamOptions& opt, double modelSize, const SpansCache& spans, size_t patchA,
                    size_t patchB) {
  c.sideA.emplace(pcurveSide(A, boxes, fa, pa, modelSize));
  c.sideB.emplace(pcurveSide(B, boxes, fb, pb, modelSize));
  c.sameParameter = BRep_Tool::SameParameter(edge) && BRep_Tool::SameRange(edge);
  c.opt = opt;
  const Result<FacePCurve>& sa = *c.sideA;
  const Result<FacePCurve>& sb = *c.sideB;
  if (!sa || !sb) {
    c.failure = fmt::format("not certified: on {}, {}", sa ? nameB : nameA, (sa ? sb : sa).status().message());
    return;
  }
  if (c.sameParameter && !sa->ownParameter && !sb->ownParameter) {
    c.a = &sa->side;
    c.b = &sb->side;
    c.bounds.emplace(certifyPCurveSeam(*c.a, *c.b, c.opt, spans.at(patchA), spans.at(patchB)));
    // Equal edge parameters pair points that a drifting SameParameter pcurve puts apart (issue 35 §1: certified
    // gaps of 0.0138 where the boundaries are 5e-6 apart): a gap above kDriftRetryFraction of the tolerance is
    // measured again between the boundaries themselves, through the closest-point correspondence, and the smaller
    // certified bound is kept (below that fraction the equal-parameter bound stands: it changes no verdict, and
    // the retry costs a correspondence per seam).
    if (!c.certifies() || (*c.bounds)->g0Bound <= kDriftRetryFraction * opt.tol.distance) return;
    std::optional<EdgeCertificate> closest = closestPointCertificate(c, spans, patchA, patchB);
    if (!closest || !((*closest->bounds)->g0Bound < (*c.bounds)->g0Bound)) return;
    closest->equalParameterGap = (*c.bounds)->g0Bound;
    adopt(c, std::move(*closest));
    return;
  } else {
    pairByCorrespondence(c);
    if (c.a == nullptr) return;
  }
  // A's side is on pa and B's on pb (the correspondence keeps the other side's surface); spans of another
  // surface would be ignored by certifyPCurveSeam.
  c.bounds.emplace(certifyPCurveSeam(*c.a, *c.b, c.opt, spans.at(patchA), spans.at(patchB)));
}

/// A sample of the closest-point route above the certified angle by more than this (degrees, plus
/// kAngleRetryRelSlack of the bound) makes retryAngleByClosestPoints certify the edge again. Both routes evaluate the
/// same surfaces; their angles differ by round-off (1e-13 deg on bearing.iges) unless they pair different points.
constexpr double kAngleRetrySlackDeg = 1e-9;
constexpr double kAngleRetryRelSlack = 1e-9;
/// retryAngleByClosestPoints certifies an edge again through closest points where the equal-parameter bound exceeds
/// their sampled angle by more than this fraction: the pcurve route's own certification slack (1 %,
/// docs/algorithms/seam-measures.md), beyond which the bound measures the pairing's drift rather than the seam.
constexpr double kLooseAngleRelSlack = 0.01;
/// The refinement of the largest angle between closest points (closestAngleOfEdgeDeg, closestAnglesAboveDeg) runs only
/// where the samples reach this fraction of the certified angle: far below it a drift of the pairing (1e-6 of the
/// model on bearing.iges) cannot lift the angle past the bound, and each refinement costs 8-15 evaluations through
/// OpenCASCADE's span caches.
constexpr double kAngleSearchFraction = 0.9;

/// The angle between A's normal at its edge point t and B's at the closest point of B's edge (measure), in
/// degrees; 0 where a normal is not defined.
double closestAngleDeg(const FaceSide& A, const FaceSide& B, double t) {
  const PointData m = measure(A, B, t);
  return m.normalsOk && std::isfinite(m.g1) ? m.g1 * kRadToDeg : 0.0;
}

/// The largest angle between closest points of an edge whose equal-parameter route certified `c`: the samples' (A's
/// edge points and the closest points of B's edge), refined within a sample spacing of the certified worst point
/// (Brent's steps, detail::refineMaxParabolic) when the samples reach kAngleSearchFraction of the bound, in degrees.
/// 0 next to a pole (the samples' normals there are limits, the certified route's exact) and where the certified
/// route proved G1 as an identity: no retry there.
double closestAngleOfEdgeDeg(const EdgeSamples& s, const EdgeCertificate& c, const FaceSide& A, const FaceSide& B) {
  if (s.degenerate || !c.certifies() || (*c.bounds)->g1Identity) return 0.0;
  double best = 0.0;
  for (const PointData& m : s.ms)
    if (m.normalsOk && std::isfinite(m.g1)) best = std::max(best, m.g1 * kRadToDeg);
  const PCurveSeamBounds& b = **c.bounds;
  if (c.byCorrespondence || s.ts.size() < 2 || best < kAngleSearchFraction * b.g1BoundDeg) return best;
  const double h = s.ts[1] - s.ts[0];
  const auto f = [&](double t) { return closestAngleDeg(A, B, t); };
  const double lo = std::max(A.first, b.g1At - h), hi = std::min(A.last, b.g1At + h);
  best = std::max(best, f(std::clamp(b.g1At, A.first, A.last)));
  return hi > lo ? std::max(best, seam::detail::refineMaxParabolic(f, lo, hi).second) : best;
}

/// Whether an angle between closest points exceeds `boundDeg` beyond the retry slack: at kMinSamples + 1 evenly
/// spaced points of A's edge, their largest maxima refined (detail::refinedMaximum) when they reach
/// kAngleSearchFraction of the bound. False next to a pole (the sampled normals there are limits).
bool closestAnglesAboveDeg(const FaceSide& A, const FaceSide& B, double boundDeg) {
  const double limit = boundDeg * (1.0 + kAngleRetryRelSlack) + kAngleRetrySlackDeg;
  std::vector<double> ts(kMinSamples + 1), values(ts.size());
  for (size_t i = 0; i < ts.size(); ++i) {
    ts[i] = A.first + (A.last - A.first) * static_cast<double>(i) / kMinSamples;
    const PointData m = measure(A, B, ts[i]);
    if (!m.curvatureOk) return false;
    values[i] = m.normalsOk && std::isfinite(m.g1) ? m.g1 * kRadToDeg : 0.0;
  }
  const double best = *std::max_element(values.begin(), values.end());
  if (best > limit) return true;
  return best >= kAngleSearchFraction * boundDeg &&
         seam::detail::refinedMaximum(ts, values, [&](double t) { return closestAngleDeg(A, B, t); }).second > limit;
}

/// Issue 35 §1 for angles: the equal-parameter route compares the normals at equal edge parameters. Where a
/// SameParameter pcurve drifts along the edge those points are not the closest ones, and on a strongly curved seam
/// the angle between them can stay below the angle between closest points (bearing.iges, a model 0.1 mm across
/// whose pcurves drift by 1e-6: 0.0229 deg certified, 0.0253 deg between closest points). When a sample of the
/// closest-point route lies above the certified angle, the edge is certified again through the closest-point
/// correspondence, whose bounds then stand (its G0 bound too: closest points are never farther apart).
void retryAngleByClosestPoints(EdgeCertificate& c, const SpansCache& spans, size_t patchA, size_t patchB) {
  if (!c.certifies() || c.byCorrespondence) return;
  const PCurveSeamBounds& b = **c.bounds;
  const double bound = b.g1BoundDeg, sample = c.closestSampleAngleDeg;
  // The bound is below a sample between closest points (it may not stand), or it lies above seam's strict angle
  // (kStrictAngleDeg, or the tolerance when smaller) where every sample between closest points is below it and the
  // pcurves drift (it may be too loose: bearing.iges, 0.0257 deg at equal parameters, 0.0025 deg between closest
  // points, edge 105). The numbers shown, and whether they are certified, do not depend on the tolerance.
  const double strict = c.opt.tol.strictAngleDeg();
  const bool belowSamples = sample > bound * (1.0 + kAngleRetryRelSlack) + kAngleRetrySlackDeg;
  const bool looseBound = bound > strict && sample <= strict && b.g0Bound > 0.0;
  // Above the strict angle, a bound more than kLooseAngleRelSlack over the closest points' angle is tried again
  // through them too (linkrods.step edge 75: 0.5016 deg certified between equal parameters, a kink at the CAD
  // default of 0.5, where the boundaries meet at 0.495 deg); the bound stands where that route does not certify.
  const bool aboveSamples = bound > strict && bound > sample * (1.0 + kLooseAngleRelSlack) && b.g0Bound > 0.0;
  if (!belowSamples && !looseBound && !aboveSamples) return;
  std::optional<EdgeCertificate> closest = closestPointCertificate(c, spans, patchA, patchB);
  if (!closest) {
    // No certified closest-point pairing: an angle made by the pairing alone is not shown as certified.
    c.angleFromPairing = looseBound;
    return;
  }
  const double closestBound = (*closest->bounds)->g1BoundDeg;
  if (!belowSamples && !(closestBound < bound)) return;
  // Tried for a loose bound only: the equal-parameter bound stands where the closest-point route's own bound lies
  // below the closest points' samples (its pairing is certified to within its slack only, and applyCertificate would
  // withdraw the certificate: bearing.iges, 11 edges).
  if (!belowSamples && !looseBound && sample > closestBound * (1.0 + kAngleRetryRelSlack) + kAngleRetrySlackDeg)
    return;
  closest->equalParameterAngleDeg = bound;
  closest->closestSampleAngleDeg = sample;
  adopt(c, std::move(*closest));
}

/// Applies the certified route (tryCertificate) to the edge's sampled report.
void applyCertificate(SeamReport& rep, const EdgeCertificate& c, const std::string& nameA, const std::string& nameB,
                      double modelSize) {
  if (!c.bounds) {
    rep.notes.push_back(c.failure);
    return;
  }
  const double sampledG0 = rep.g0Sampled, sampledG0Max = rep.g0Max;
  const WorstLocation sampledG0Worst = rep.g0Worst;
  certifyThroughPCurves(rep, *c.bounds, *c.a, c.opt, modelSize);
  // The bound holds for the points the certified route pairs, not for closest points: a kink made by that pairing
  // alone (the closest-point pairing could not be certified), or a sample between closest points above the bound
  // (its pairing error shows). The sampled angle and gap (between closest points) are shown, and the seam is not
  // called certified: the paired points' distance bounds the gap, but a drift makes it larger than the gap.
  const bool belowSamples =
      c.closestSampleAngleDeg > rep.g1MaxDeg * (1.0 + kAngleRetryRelSlack) + kAngleRetrySlackDeg;
  if (rep.certified && (c.angleFromPairing || belowSamples)) {
    rep.notes.push_back(fmt::format(
        "not certified: at the points the certified route pairs the normals make up to {:.4g} deg, between the "
        "sampled closest points {:.4g} deg (the SameParameter pcurves drift along the edge, the paired points are up "
        "to {:.3g} apart, and the closest-point pairing could not be certified closer): the sampled angle is shown",
        rep.g1MaxDeg, c.closestSampleAngleDeg, rep.g0Max));
    rep.g1MaxDeg = rep.g1SampledDeg = c.closestSampleAngleDeg;
    rep.g0Sampled = sampledG0;
    rep.g0Max = sampledG0Max;
    rep.g0Worst = sampledG0Worst;
    rep.certified = false;
    reconcileVerdict(rep, c.opt.tol);
  }
  if (!c.byCorrespondence || !rep.certified) return;
  const FacePCurve& a = **c.sideA;
  const FacePCurve& b = **c.sideB;
  const detail::Correspondence& corr = **c.correspondence;
  const bool masterA = c.masterA;
  std::string why = !c.sameParameter ? "the edge's pcurves do not share its parameter (no SameParameter / SameRange)"
                     : c.equalParameterGap > 0.0
                         ? fmt::format("at equal edge parameters the pcurves' images are up to {:.4g} apart, a drift "
                                       "of the SameParameter pcurves, not a gap between the boundaries",
                                       c.equalParameterGap)
                     : c.equalParameterAngleDeg > 0.0
                         ? fmt::format("the SameParameter pcurves drift along the edge: at equal edge parameters the "
                                       "normals make up to {:.4g} deg, between the sampled closest points {:.4g} deg, "
                                       "so the normals are compared between closest points",
                                       c.equalParameterAngleDeg, c.closestSampleAngleDeg)
                         : "";
  for (const auto& [s, name] : {std::pair{&a, &nameA}, std::pair{&b, &nameB}})
    if (s->ownParameter)
      why += fmt::format("{}{}'s edge is {}", why.empty() ? "" : "; ", *name, s->how);
  rep.notes.push_back(fmt::format(
      "no common parameter ({}): {}'s edge was paired with {}'s by a monotone piecewise-cubic correspondence ({} "
      "pieces, within {:.3g} of the closest points) composed exactly; the bounds hold for the edges themselves",
      why, masterA ? nameB : nameA, masterA ? nameA : nameB, corr.pieces, corr.pairingError));
}

Vec3 edgeMidpoint(const TopoDS_Edge& e) {
  try {
    BRepAdaptor_Curve c(e);
    return toVec(c.Value(0.5 * (c.FirstParameter() + c.LastParameter())));
  } catch (const Standard_Failure&) {
    return Vec3::Zero();
  }
}

/// Points along the edge's 3-D curve (empty when it has none).
std::vector<Vec3> edgePolyline(const TopoDS_Edge& e) {
  std::vector<Vec3> out;
  try {
    BRepAdaptor_Curve c(e);
    const double a = c.FirstParameter(), b = c.LastParameter();
    for (int i = 0; i <= kPolylinePoints; ++i) out.push_back(toVec(c.Value(a + (b - a) * i / kPolylinePoints)));
  } catch (const Standard_Failure&) {
    out.clear();
  }
  return out;
}

int countFreeEdges(const TopoDS_Shape& s) {
  TopTools_IndexedDataMapOfShapeListOfShape m;
  TopExp::MapShapesAndAncestors(s, TopAbs_EDGE, TopAbs_FACE, m);
  int n = 0;
  for (int i = 1; i <= m.Extent(); ++i)
    if (m.FindFromIndex(i).Extent() == 1 && !BRep_Tool::Degenerated(TopoDS::Edge(m.FindKey(i))) &&
        !BRep_Tool::IsClosed(TopoDS::Edge(m.FindKey(i)), TopoDS::Face(m.FindFromIndex(i).First())))
      ++n;
  return n;
}

/// What one edge of the model contributes to the report (checkBRepFile's edge loop).
struct EdgeOutcome {
  enum Kind { kNone, kDegenerate, kLoose, kNonManifold, kFree, kSeam, kUnanalysed } kind = kNone;
  BRepSeam seam;
  BRepFreeEdge free;
  BRepNonManifoldEdge nonManifold;
  std::string warning;  ///< kUnanalysed: why
};

}  // namespace

Result<BRepCheckReport> checkBRepFile(const fs::path& file, const BRepCheckOptions& options) {
  const std::optional<CadFormat> format = cadFormatOf(file);
  if (!format)
    return invalidInput(fmt::format("{}: not a STEP (.step/.stp) or IGES (.iges/.igs) file name", file.string()));
  std::vector<std::string> readWarnings;
  detail::FaceLabels labels;
  detail::FileUnits units;
  units.statedUnitMm = options.read.statedUnitMm;
  if (options.tolerances.units) units.statedUnitMm = lengthUnitInfo(*options.tolerances.units).millimetres;
  Result<TopoDS_Shape> read =
      detail::readShape(file, *format, &readWarnings, detail::kTransferTimeLimit, &labels, &units);
  if (!read) return read.status();
  return detail::checkBRepShape(*read, file, std::move(labels), units, readWarnings, options);
}

namespace detail {

Result<BRepCheckReport> checkBRepShape(const TopoDS_Shape& input, const fs::path& file, FaceLabels labels,
                                       const FileUnits& units, const std::vector<std::string>& readWarnings,
                                       const BRepCheckOptions& options, const EdgeFilter& onlyEdges) {
  const auto started = std::chrono::steady_clock::now();  // the view's meshing budget scales with the check's time
  BRepCheckReport out;
  // Every OpenCASCADE call of the check (bounding box, sewing, BRepLib::ContinuityOfFaces, pcurves, evaluation of
  // the faces' surfaces) runs under the guard: a signal inside it comes back as a Standard_Failure of kind
  // OSD_Signal and ends the check with an error (the state a crash leaves is not trusted); any other
  // Standard_Failure on one edge leaves that edge "not analysed", with a warning, and the check goes on.
  detail::OcctSignalGuard guard;
  try {
    OCC_CATCH_SIGNALS
    TopoDS_Shape shape = input;
    Bnd_Box box;
    BRepBndLib::Add(shape, box);
    const double diag = box.IsVoid() ? 1.0 : std::sqrt(box.SquareExtent());
    TopTools_IndexedMapOfShape faceMap;
    TopExp::MapShapes(shape, TopAbs_FACE, faceMap);
    // The solid of each face of the input (1-based, TopExp::MapShapes order; for the overlap search's pairs),
    // carried over to the sewn faces below: the sewn shape has no solids.
    TopTools_DataMapOfShapeInteger solidOfFace;
    {
      TopTools_IndexedMapOfShape solids;
      TopExp::MapShapes(input, TopAbs_SOLID, solids);
      for (int k = 1; k <= solids.Extent(); ++k)
        for (TopExp_Explorer ex(solids(k), TopAbs_FACE); ex.More(); ex.Next())
          if (!solidOfFace.IsBound(ex.Current())) solidOfFace.Bind(ex.Current(), k);
    }
    if (options.sewFreeEdges && faceMap.Extent() > 1 && countFreeEdges(shape) > 0) {
      BRepBuilderAPI_Sewing sewing(options.sewingRelTol * diag);
      sewing.Add(shape);
      sewing.Perform();
      if (!sewing.SewedShape().IsNull()) {
        shape = sewing.SewedShape();
        out.sewn = true;
        // The sewn faces keep the entities of the faces they were made from. The faces are sub-shapes of what was
        // added (the file's one shape): their history is ModifiedSubShape; Modified knows only the added shape
        // itself, and missed every face sewing rebuilt (issue 17 §3: all of bearing.iges, the fuselage, ...).
        detail::FaceLabels sewn;
        for (int i = 1; i <= labels.faces.Extent(); ++i) {
          const TopoDS_Shape& original = labels.faces(i);
          const TopoDS_Shape now =
              sewing.IsModifiedSubShape(original) ? sewing.ModifiedSubShape(original) : original;
          if (!sewn.faces.Contains(now)) {
            sewn.faces.Add(now);
            sewn.labels.push_back(labels.labels[static_cast<size_t>(i - 1)]);
          }
        }
        labels = std::move(sewn);
        TopTools_DataMapOfShapeInteger sewnSolid;
        for (TopTools_DataMapIteratorOfDataMapOfShapeInteger it(solidOfFace); it.More(); it.Next()) {
          const TopoDS_Shape& original = it.Key();
          const TopoDS_Shape now =
              sewing.IsModifiedSubShape(original) ? sewing.ModifiedSubShape(original) : original;
          if (!sewnSolid.IsBound(now)) sewnSolid.Bind(now, it.Value());
        }
        solidOfFace.Exchange(sewnSolid);
      }
      faceMap.Clear();
      TopExp::MapShapes(shape, TopAbs_FACE, faceMap);
    }
    std::vector<TopoDS_Face> faces;
    for (int i = 1; i <= faceMap.Extent(); ++i) faces.push_back(TopoDS::Face(faceMap(i)));
    Result<CadImport> imported = detail::convertFaces(file, faces, options.read);
    if (!imported) return imported.status();
    out.import = std::move(imported).value();
    detail::applyFaceLabels(out.import, faces, labels);
    out.import.warnings.insert(out.import.warnings.begin(), readWarnings.begin(), readWarnings.end());
    std::map<int, size_t> patchOfFace;  // 1-based face index -> patch index
    for (size_t k = 0; k < out.import.faces.size(); ++k) patchOfFace[out.import.faces[k].faceIndex] = k;
    out.import.units = units.units;
    out.units = cadModelUnits(out.import, options.tolerances);
    const ResolvedTolerances resolved =
        resolveTolerances(options.tolerances, out.units, out.import.model.boundingBox().diagonal());
    out.tolerances = resolved.tolerances;
    out.distanceSource = resolved.distanceSource;
    out.angleSource = resolved.angleSource;
    SeamOptions seamOpt = options.seam;
    seamOpt.tol = out.tolerances;
    const double size = out.import.model.boundingBox().diagonal();
    auto faceName = [&](int fi) { return fmt::format("F{}", fi); };
    const SpansCache spansCache(out.import.model.patches);
    const FaceBoxCache faceBoxes(faceMap);

    TopTools_IndexedDataMapOfShapeListOfShape edgeFaces;
    TopExp::MapShapesAndAncestors(shape, TopAbs_EDGE, TopAbs_FACE, edgeFaces);
    const int nEdges = edgeFaces.Extent(), nFaces = faceMap.Extent();
    // One edge: everything it contributes to the report, computed from read-only state (the shape, the maps, the
    // converted patches), so that edges can be analysed on several threads and merged in edge order.
    auto analyseEdge = [&](int i) {
      EdgeOutcome o;
      OCC_CATCH_SIGNALS  // this thread's handler: a signal here comes back as an OSD_Signal failure
      try {
        const TopoDS_Edge edge = TopoDS::Edge(edgeFaces.FindKey(i));
        if (onlyEdges && !onlyEdges(edge)) return o;  // not asked for
        if (BRep_Tool::Degenerated(edge)) {
          o.kind = EdgeOutcome::kDegenerate;
          return o;
        }
        // Distinct faces around the edge (a periodic face's seam edge lists its face twice, or once when closed).
        std::vector<TopoDS_Face> around;
        for (TopTools_ListOfShape::Iterator it(edgeFaces.FindFromIndex(i)); it.More(); it.Next()) {
          const TopoDS_Face f = TopoDS::Face(it.Value());
          if (std::none_of(around.begin(), around.end(), [&](const TopoDS_Face& g) { return g.IsSame(f); }))
            around.push_back(f);
        }
        if (around.empty()) {  // a loose edge: a 3-D curve of the file that bounds no face
          o.kind = EdgeOutcome::kLoose;
          return o;
        }
        if (around.size() > 2) {
          BRepNonManifoldEdge nm{i, {}, edgeMidpoint(edge)};
          for (const TopoDS_Face& f : around) nm.faces.push_back(faceName(faceMap.FindIndex(f)));
          o.kind = EdgeOutcome::kNonManifold;
          o.nonManifold = std::move(nm);
          return o;
        }
        FaceSide A, B;
        TopoDS_Face fa = around[0], fb;
        TopoDS_Edge ea = edge, eb = edge;
        if (around.size() == 1) {
          if (!BRep_Tool::IsClosed(edge, fa)) {
            o.kind = EdgeOutcome::kFree;
            o.free = {i, faceName(faceMap.FindIndex(fa)), edgeMidpoint(edge), edgePolyline(edge)};
            return o;
          }
          fb = fa;  // the seam of a closed (periodic) face: its two pcurves
          ea = TopoDS::Edge(edge.Oriented(TopAbs_FORWARD));
          eb = TopoDS::Edge(edge.Oriented(TopAbs_REVERSED));
        } else {
          fb = around[1];
        }
        const int ia = faceMap.FindIndex(fa), ib = faceMap.FindIndex(fb);
        BRepSeam seam;
        seam.edge = i;
        seam.a = faceName(ia);
        seam.b = faceName(ib);
        if (!patchOfFace.count(ia) || !patchOfFace.count(ib)) return o;  // a face that could not be read (warned)
        const size_t pa = patchOfFace.at(ia), pb = patchOfFace.at(ib);
        try {
          seam.occtContinuity = continuityName(
              BRepLib::ContinuityOfFaces(edge, fa, fb, out.tolerances.angleDeg * std::numbers::pi / 180.0));
        } catch (const Standard_Failure&) {
          seam.occtContinuity = "?";
        }
        // Certified route: both faces untrimmed and the edge a whole side of each.
        const std::optional<Edge> sa =
            out.import.faces[pa].trimmed || ia == ib ? std::nullopt : naturalSide(ea, fa, faceBoxes.at(ia));
        const std::optional<Edge> sb =
            out.import.faces[pb].trimmed || ia == ib ? std::nullopt : naturalSide(eb, fb, faceBoxes.at(ib));
        // Both faces' sides of the edge through OpenCASCADE (the pcurve route, and the patch-edge route's check);
        // false when the edge is not on both faces.
        auto loadSides = [&] {
          A.surface = BRep_Tool::Surface(fa);
          B.surface = BRep_Tool::Surface(fb);
          A.pcurve = BRep_Tool::CurveOnSurface(ea, fa, A.first, A.last);
          B.pcurve = BRep_Tool::CurveOnSurface(eb, fb, B.first, B.last);
          if (A.surface.IsNull() || B.surface.IsNull() || A.pcurve.IsNull() || B.pcurve.IsNull() ||
              !(A.last > A.first) || !(B.last > B.first))
            return false;
          A.surfaceEval.Load(A.surface);
          B.surfaceEval.Load(B.surface);
          A.pcurveEval.Load(A.pcurve, A.first, A.last);
          B.pcurveEval.Load(B.pcurve, B.first, B.last);
          A.sign = fa.Orientation() == TopAbs_REVERSED ? -1.0 : 1.0;
          B.sign = fb.Orientation() == TopAbs_REVERSED ? -1.0 : 1.0;
          return true;
        };
        bool done = false;
        if (sa && sb) {
          Result<SeamReport> r =
              analyzeSeam(out.import.model.patches[pa], *sa, out.import.model.patches[pb], *sb, seamOpt);
          if (r) {
            seam.report = std::move(r).value();
            seam.viaPatchEdges = true;
            done = true;
            // The patch-edge route pairs the two sides by an affine map of their parameters. Where the sides'
            // parametrisations drift apart along the edge, its certified angle can stay below the angle between
            // closest points (bearing.iges: 0.00883 deg certified, 0.00910 between closest points): checked at
            // the pcurve route's sample count; past it the edge takes the pcurve route, which pairs closest points.
            if (seam.report.certified && !seam.report.g1Identity && loadSides() &&
                closestAnglesAboveDeg(A, B, seam.report.g1MaxDeg)) {
              done = false;
              seam.report = SeamReport{};
              seam.viaPatchEdges = false;
            }
          }
        }
        if (!done) {
          if (!loadSides()) {
            o.kind = EdgeOutcome::kFree;  // not on both faces
            o.free = {i, seam.a, edgeMidpoint(edge), edgePolyline(edge)};
            return o;
          }
          const bool exact = out.import.faces[pa].exact && out.import.faces[pb].exact;
          EdgeSamples samples;
          EdgeCertificate cert;
          auto certify = [&] {
            if (exact)
              tryCertificate(cert, A, B, faceBoxes, ia, ib, out.import.model.patches[pa].surface,
                             out.import.model.patches[pb].surface, edge, seam.a, seam.b, seamOpt, size,
                             spansCache, pa, pb);
          };
          if (options.threads == 1) {
            samples = sampleEdge(edge, A, B, seamOpt, size);
            certify();
          } else {
            // The samples (OpenCASCADE's evaluators through A's and B's adaptors) and the certificate (the
            // faces' Geom objects, the converted patches, seam's own polynomials: no state shared with the
            // samples) as two tasks, so that one heavy edge does not hold the last block on one core. Each
            // computes what it computes serially; a failure is raised as the serial order would raise it (the
            // samples' first).
            std::exception_ptr sampleError, certError;
            tbb::task_group tasks;
            tasks.run([&] {
              OCC_CATCH_SIGNALS  // the thread that runs the task: its own handler
              try {
                samples = sampleEdge(edge, A, B, seamOpt, size);
              } catch (...) {
                sampleError = std::current_exception();
              }
            });
            try {
              certify();
            } catch (...) {
              certError = std::current_exception();
            }
            tasks.wait();
            if (sampleError) std::rethrow_exception(sampleError);
            if (certError) std::rethrow_exception(certError);
          }
          if (exact) {
            cert.closestSampleAngleDeg = closestAngleOfEdgeDeg(samples, cert, A, B);
            retryAngleByClosestPoints(cert, spansCache, pa, pb);
          }
          seam.report = sampledSeam(samples, A, B, seam.a, seam.b, seamOpt, !cert.certifies(), !cert.certifiesG2());
          if (exact) {
            applyCertificate(seam.report, cert, seam.a, seam.b, size);
          } else {
            seam.report.notes.push_back(
                fmt::format("not certified: {} was approximated, not converted exactly (see the import warnings)",
                            out.import.faces[pa].exact ? seam.b : seam.a));
          }
        }
        seam.curve = edgePolyline(edge);
        o.kind = EdgeOutcome::kSeam;
        o.seam = std::move(seam);
      } catch (const Standard_Failure& f) {
        if (isSignal(f)) throw;
        o = EdgeOutcome{};
        o.kind = EdgeOutcome::kUnanalysed;
        o.warning = fmt::format("{}: edge {} not analysed: OpenCASCADE failed on it: {}", file.string(), i,
                                f.GetMessageString());
      }
      return o;
    };
    // The edges in blocks of kProgressEdgeStep: each block on options.threads threads, then merged in edge order
    // (the report does not depend on the number of threads) and reported to the progress callback on this thread.
    if (options.progress) options.progress(nFaces, 0, nEdges);
    tbb::task_arena arena(options.threads > 0 ? options.threads : tbb::task_arena::automatic);
    std::vector<EdgeOutcome> block;
    for (int first = 1; first <= nEdges; first += kProgressEdgeStep) {
      if (options.progress && first > 1) options.progress(nFaces, first - 1, nEdges);
      const int n = std::min(kProgressEdgeStep, nEdges - first + 1);
      block.assign(static_cast<size_t>(n), EdgeOutcome{});
      if (options.threads == 1) {
        // In the one-thread arena: the nested parallel loops of an edge (certifyPCurveSeam's leaves) run here too.
        arena.execute([&] {
          for (int k = 0; k < n; ++k) block[static_cast<size_t>(k)] = analyseEdge(first + k);
        });
      } else {
        arena.execute([&] {
          tbb::parallel_for(0, n, [&](int k) { block[static_cast<size_t>(k)] = analyseEdge(first + k); });
        });
      }
      for (EdgeOutcome& o : block) {
        switch (o.kind) {
          case EdgeOutcome::kNone: break;
          case EdgeOutcome::kDegenerate: ++out.degenerateEdges; break;
          case EdgeOutcome::kLoose: ++out.looseEdges; break;
          case EdgeOutcome::kNonManifold: out.nonManifoldEdges.push_back(std::move(o.nonManifold)); break;
          case EdgeOutcome::kFree: out.freeEdges.push_back(std::move(o.free)); break;
          case EdgeOutcome::kSeam: out.seams.push_back(std::move(o.seam)); break;
          case EdgeOutcome::kUnanalysed:
            out.import.warnings.push_back(std::move(o.warning));
            ++out.unanalysedEdges;
            break;
        }
      }
    }
    if (options.progress) options.progress(nFaces, nEdges, nEdges);
    if (options.findOverlaps && !onlyEdges) {  // faces lying on each other, inside their trims (issue 38 §11)
      OverlapOptions oo = options.overlap;
      oo.threads = options.threads;
      detail::BRepOverlapSearch found = detail::findBRepOverlaps(faceMap, out.tolerances.distance, oo);
      out.overlaps = std::move(found.overlaps);
      out.overlapFacesSkipped = found.skippedFaces;
      out.overlapsSearched = true;
      auto solidOf = [&](int face) {
        const TopoDS_Shape& f = faceMap(face + 1);
        return solidOfFace.IsBound(f) ? solidOfFace.Find(f) : 0;
      };
      for (const FaceOverlap& o : out.overlaps) out.overlapSolids.emplace_back(solidOf(o.a), solidOf(o.b));
    }
    if (options.meshFaces) {
      // The view's meshes: kFaceMeshDeflectionRel x the diagonal, doubled (after removing the triangulation) while
      // the meshes exceed the vertex budget, at most kFaceMeshCoarsenings times.
      std::vector<bool> wanted;
      if (options.meshTrimmedOnly)
        for (const CadFace& f : out.import.faces) {
          if (f.faceIndex < 1) continue;  // 1-based; 0 = not traced to a face of the file
          if (wanted.size() < static_cast<size_t>(f.faceIndex)) wanted.resize(static_cast<size_t>(f.faceIndex), false);
          wanted[static_cast<size_t>(f.faceIndex - 1)] = f.trimmed;
        }
      out.meshDeflection = options.meshDeflectionRel * diag;
      const double checkSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
      const double budget = options.meshBudgetFactor > 0.0
                                ? std::max(options.meshBudgetMinSeconds, options.meshBudgetFactor * checkSeconds)
                                : 0.0;
      const Handle(detail::DeadlineIndicator) deadline = new detail::DeadlineIndicator(budget);  // over all attempts
      for (int attempt = 0;; ++attempt) {
        out.faceMeshes = detail::meshFaces(shape, faces, out.meshDeflection, wanted, deadline);
        if (deadline->expired()) {
          out.meshStoppedAfterSeconds = budget;
          break;
        }
        size_t vertices = 0;
        for (const BRepFaceMesh& m : out.faceMeshes) vertices += m.points.size();
        if (options.meshVertexBudget <= 0 || vertices <= static_cast<size_t>(options.meshVertexBudget) ||
            attempt == kFaceMeshCoarsenings)
          break;
        BRepTools::Clean(shape);
        out.meshDeflection *= 2.0;
      }
    }
  } catch (const Standard_Failure& f) {
    return Status(ErrorCode::kInvalidInput,
                  fmt::format("{}: OpenCASCADE {} during the B-rep check: {}", file.string(),
                              isSignal(f) ? "crashed (the file is corrupt)" : "failed", f.GetMessageString()));
  }
  for (const BRepSeam& s : out.seams) {
    ++out.geometric[static_cast<size_t>(s.report.geometric)];
    out.worstGeometric = std::min(out.worstGeometric, s.report.geometric);
    if (s.report.certified) ++out.certifiedSeams;
    const bool seamSmooth = s.report.geometric >= GeometricClass::kG1;
    const bool occtSmooth = s.occtContinuity != "C0" && s.occtContinuity != "?";
    if (seamSmooth == occtSmooth) ++out.occtAgreement;
  }
  return out;
}

std::string seamWorseThan(const SeamReport& after, const SeamReport& before, const Tolerances& tol, double creaseDeg,
                          const ModelUnits& units) {
  const double gapLimit = std::max(before.g0Max, tol.distance) + kWorseSlackRel * tol.distance;
  const std::optional<LengthUnit> shown = units.shownUnit();
  const std::string unit = shown ? std::string(" ") + lengthUnitInfo(*shown).name : std::string();
  // Angles are judged on seam's strict scale whatever the verdict's tolerance: with the CAD default (0.5 deg) a kink
  // of 0.62 deg could otherwise grow to 0.66 and a 0.1-degree seam to 0.5 without counting as worse.
  const double strict = tol.strictAngleDeg();
  if (after.g0Max > gapLimit)
    return fmt::format("its gap would grow from {:.3g} to {:.3g}{}", before.g0Max * units.displayScale(),
                       after.g0Max * units.displayScale(), unit);
  if (before.g1MaxDeg > creaseDeg) {
    if (std::abs(after.g1MaxDeg - before.g1MaxDeg) > strict)
      return fmt::format("its crease angle would change from {:.4g} to {:.4g} deg", before.g1MaxDeg, after.g1MaxDeg);
    return {};
  }
  const double angleLimit = std::max(before.g1MaxDeg, strict) + kWorseSlackRel * strict;
  if (after.g1MaxDeg > angleLimit)
    return fmt::format("its angle would grow from {:.3g} to {:.3g} deg", before.g1MaxDeg, after.g1MaxDeg);
  return {};
}

std::vector<SeamWorse> seamsWorse(const std::vector<BRepSeam>& before, const std::vector<BRepSeam>& after,
                                  const Tolerances& tol, double creaseDeg, const ModelUnits& units) {
  std::vector<SeamWorse> worse;
  for (const BRepSeam& s : after) {
    if (s.curve.empty()) continue;
    SeamWorse w;
    for (const BRepSeam* b : nearestSeams(before, seamMidpoint(s), tol.distance, seamMidpoint)) {
      std::string why = seamWorseThan(s.report, b->report, tol, creaseDeg, units);
      if (why.empty()) {
        w.before = nullptr;
        break;
      }
      if (w.before == nullptr) w = {b, &s, std::move(why)};
    }
    if (w.before != nullptr) worse.push_back(std::move(w));
  }
  return worse;
}

}  // namespace detail

/// Here rather than in brep_model.cpp: the model's B-rep is built there (detail::shapeFromBRep), checked here, so
/// that brep_model.cpp needs no part of the check (the CAD fuzz harnesses link it alone).
Result<BRepCheckReport> checkBRepModel(const Model& model, const fs::path& file,
                                       const BRepCheckOptions& options) {
  Result<TopoDS_Shape> shape = detail::shapeFromBRep(model, file.string());
  if (!shape) return shape.status();
  detail::FileUnits units;
  units.units.fileUnit = "";
  units.units.millimetresPerFileUnit = 1.0;
  return detail::checkBRepShape(*shape, file, detail::FaceLabels{}, units, {}, options);
}

void scaleLengths(BRepCheckReport& r, double scale) {
  r.tolerances.distance *= scale;
  for (BRepSeam& s : r.seams) {
    scaleLengths(s.report, scale);
    for (Vec3& p : s.curve) p *= scale;
  }
  for (BRepFreeEdge& f : r.freeEdges) {
    f.midpoint *= scale;
    for (Vec3& p : f.curve) p *= scale;
  }
  for (BRepNonManifoldEdge& e : r.nonManifoldEdges) e.midpoint *= scale;
  for (FaceOverlap& o : r.overlaps) {
    o.maxDistance *= scale;
    o.point *= scale;
  }
  for (BRepFaceMesh& m : r.faceMeshes)
    for (Vec3& p : m.points) p *= scale;
  r.meshDeflection *= scale;
}

void toShownUnits(BRepCheckReport& r) {
  const double scale = r.units.displayScale();
  if (scale != 1.0) scaleLengths(r, scale);
  r.units = r.units.shown();
}

}  // namespace seam::occt
