// OCC_CATCH_SIGNALS converts a signal raised inside OpenCASCADE into a Standard_Failure only when this macro is set
// (as in brep_check.cpp; see docs/reliability.md, "OpenCASCADE guards").
#ifndef OCC_CONVERT_SIGNALS
#define OCC_CONVERT_SIGNALS
#endif
#include "occt/brep_edge.h"
#include "occt/analytic_patch.h"

#include <fmt/format.h>

#include <BRepAdaptor_Curve.hxx>
#include <BRepLib.hxx>
#include <BRep_Tool.hxx>
#include <OSD_Signal.hxx>
#include <Standard_ErrorHandler.hxx>
#include <Standard_Failure.hxx>
#include <TopTools_ListOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Face.hxx>
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <exception>
#include <limits>

#include <tbb/task_group.h>

#include "continuity/sampling.h"

namespace seam::occt::detail {

namespace {

/// Points per edge polyline (drawings in reports).
constexpr int kPolylinePoints = 24;
/// Gauss-Newton steps that move B's partner point to the point of B's edge closest to A's (sampled route), and the
/// step, relative to B's parameter range, below which the iteration has converged.
constexpr int kPartnerIterations = 12;
constexpr double kPartnerStepRel = 1e-15;

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

/// The side of the face's parameter box that the edge's pcurve runs along from corner to corner, if any.
std::optional<Edge> naturalSide(const TopoDS_Edge& e, const TopoDS_Face& f, const detail::ParamBox& box) {
  return detail::boxSideOf(e, f, box, true);
}

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

/// The seam through the pcurves: sampled, with the certified route where both faces' patches are exact conversions
/// (or the face's surface has its own polynomial patch: a cylinder, cone, sphere or torus)
/// (patches pa and pb of faces ia and ib). The samples and the certificate run as two tasks when ctx.threads != 1.
SeamReport pcurveRouteReport(const EdgeCheckContext& ctx, const TopoDS_Edge& edge, const FaceSide& A,
                             const FaceSide& B, int ia, int ib, size_t pa, size_t pb, const std::string& nameA,
                             const std::string& nameB) {
  const SeamOptions& seamOpt = ctx.seamOpt;
  const double size = ctx.modelSize;
  SeamReport report;
  // A face whose patch approximates its surface is certified only where that surface has its own polynomial patch
  // (a cylinder, cone, sphere or torus: analyticSide, which the approximated patch's check sends it to).
  const bool exactA = ctx.import.faces[pa].exact, exactB = ctx.import.faces[pb].exact;
  const bool certifiable = (exactA || hasAnalyticPatch(A.surface)) && (exactB || hasAnalyticPatch(B.surface));
  EdgeSamples samples;
  EdgeCertificate cert;
  auto certify = [&] {
    if (certifiable)
      tryCertificate(cert, A, B, ctx.faceBoxes, ia, ib, ctx.import.model.patches[pa].surface,
                     ctx.import.model.patches[pb].surface, edge, nameA, nameB, seamOpt, size,
                     ctx.spans, pa, pb, exactA, exactB);
  };
  if (ctx.threads == 1) {
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
      try {
        OCC_CATCH_SIGNALS  // the thread that runs the task: its own handler (inside the try, which catches it)
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
  if (certifiable) {
    cert.closestSampleAngleDeg = closestAngleOfEdgeDeg(samples, cert, A, B);
    retryAngleByClosestPoints(cert, ctx.spans, pa, pb);
    sharpenReverseDirection(cert, A, B, ctx.spans, pa, pb);
  }
  report = sampledSeam(samples, A, B, nameA, nameB, seamOpt, !cert.certifies(), !cert.certifiesG2());
  if (certifiable) {
    applyCertificate(report, cert, nameA, nameB, size);
  } else {
    report.notes.push_back(
        fmt::format("not certified: {} was approximated, not converted exactly (see the import warnings)",
                    ctx.import.faces[pa].exact ? nameB : nameA));
  }
  return report;
}

}  // namespace

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
                       const std::string& b, const SeamOptions& opt, bool refineG0G1, bool refineG2) {
  SeamReport rep;
  rep.a = a;
  rep.b = b;
  rep.overlapA = {A.first, A.last};
  rep.overlapB = {B.first, B.last};
  rep.correspondence = seam::Correspondence::kProjection;
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

EdgeOutcome analyseEdge(const EdgeCheckContext& ctx, int i) {
  const TopTools_IndexedMapOfShape& faceMap = ctx.faceMap;
  const TopTools_IndexedDataMapOfShapeListOfShape& edgeFaces = ctx.edgeFaces;
  const EdgeFilter& onlyEdges = ctx.onlyEdges;
  const std::map<int, size_t>& patchOfFace = ctx.patchOfFace;
  const SeamOptions& seamOpt = ctx.seamOpt;
  const std::filesystem::path& file = ctx.file;
  auto faceName = [&](int fi) { return fmt::format("F{}", fi); };
  EdgeOutcome o;
  try {
    OCC_CATCH_SIGNALS  // this thread's handler: a signal here comes back as an OSD_Signal failure, caught below
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
          BRepLib::ContinuityOfFaces(edge, fa, fb, ctx.tolerances.angleDeg * std::numbers::pi / 180.0));
    } catch (const Standard_Failure&) {
      seam.occtContinuity = "?";
    }
    // Certified route: both faces untrimmed and the edge a whole side of each.
    const std::optional<Edge> sa =
        ctx.import.faces[pa].trimmed || ia == ib ? std::nullopt : naturalSide(ea, fa, ctx.faceBoxes.at(ia));
    const std::optional<Edge> sb =
        ctx.import.faces[pb].trimmed || ia == ib ? std::nullopt : naturalSide(eb, fb, ctx.faceBoxes.at(ib));
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
          analyzeSeam(ctx.import.model.patches[pa], *sa, ctx.import.model.patches[pb], *sb, seamOpt);
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
        } else if (!seam.report.certified && loadSides()) {
          // Where the patch-edge route finds no polynomial correspondence (one edge running past the other by more
          // than the gap: bearing.iges, BUC50025.igs), the pcurve route pairs the edges by its own monotone
          // correspondence and may certify them: its report is taken where it does, the sampled one kept otherwise.
          SeamReport viaPCurves = pcurveRouteReport(ctx, edge, A, B, ia, ib, pa, pb, seam.a, seam.b);
          if (viaPCurves.certified) {
            seam.report = std::move(viaPCurves);
            seam.viaPatchEdges = false;
          }
        }
      }
    }
    if (!done) {
      if (!loadSides()) {
        o.kind = EdgeOutcome::kFree;  // not on both faces
        o.free = {i, seam.a, edgeMidpoint(edge), edgePolyline(edge)};
        return o;
      }
      seam.report = pcurveRouteReport(ctx, edge, A, B, ia, ib, pa, pb, seam.a, seam.b);
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
}

}  // namespace seam::occt::detail
