// Model::brep <-> OpenCASCADE shapes (issue 34 §1): the topology of a STEP/IGES file kept in the JSON model
// format, and made into a shape again for STEP/IGES output and the B-rep check.
#ifndef OCC_CONVERT_SIGNALS
#define OCC_CONVERT_SIGNALS
#endif
#include "occt/brep_model.h"

#include <fmt/format.h>

#include <BRepBuilderAPI_Sewing.hxx>
#include <BRepCheck_Analyzer.hxx>
#include <BRepCheck_Wire.hxx>
#include <BRepLib.hxx>
#include <BRepTools.hxx>
#include <BRepTools_WireExplorer.hxx>
#include <BRep_Builder.hxx>
#include <BRep_Tool.hxx>
#include <Geom2dAPI_Interpolate.hxx>
#include <Geom2dConvert.hxx>
#include <Geom2d_BSplineCurve.hxx>
#include <Geom2d_TrimmedCurve.hxx>
#include <GeomAPI_Interpolate.hxx>
#include <GeomConvert.hxx>
#include <Geom_BSplineCurve.hxx>
#include <Geom_BSplineSurface.hxx>
#include <Geom_BezierSurface.hxx>
#include <Geom_TrimmedCurve.hxx>
#include <OSD_Signal.hxx>
#include <Precision.hxx>
#include <Standard_ErrorHandler.hxx>
#include <Standard_Failure.hxx>
#include <TColStd_Array1OfInteger.hxx>
#include <TColStd_Array1OfReal.hxx>
#include <TColStd_HArray1OfReal.hxx>
#include <TColgp_Array1OfPnt.hxx>
#include <TColgp_Array1OfPnt2d.hxx>
#include <TColgp_HArray1OfPnt.hxx>
#include <TColgp_HArray1OfPnt2d.hxx>
#include <TopExp.hxx>
#include <TopExp_Explorer.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Compound.hxx>
#include <TopoDS_Edge.hxx>
#include <TopoDS_Iterator.hxx>
#include <TopoDS_Shell.hxx>
#include <TopoDS_Solid.hxx>
#include <TopoDS_Vertex.hxx>
#include <TopoDS_Wire.hxx>
#include <XCAFDoc_DocumentTool.hxx>
#include <XCAFDoc_ShapeTool.hxx>
#include <gp_Vec2d.hxx>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <optional>
#include <type_traits>

#include "occt/brep_check_internal.h"
#include "occt/cad_internal.h"
#include "seam/occt/brep_model.h"
#include "spline/spline_internal.h"

namespace seam::occt {

namespace fs = std::filesystem;

namespace {

/// A converted curve or patch keeps the source's parameterisation when they agree within this fraction of the
/// model diagonal at every sample (a conversion that keeps it is exact up to rounding).
constexpr double kSameParamRelTol = 1e-10;
/// Samples per curve for that test and for the fits' error.
constexpr int kParamSamples = 17;
/// Samples per pcurve when looking for pcurves that run past their surface's bounds (extendPatchToPcurves).
constexpr int kOverhangSamples = 256;
/// Points of a fit (cubic interpolation at the edge's own parameters, GeomAPI_Interpolate): first try, then
/// four times as many up to the last.
constexpr int kFitPointsFirst = 33;
constexpr int kFitPointsLast = 2049;
/// A fitted 3-D curve or pcurve is kept when its error is at most this fraction of its edge's tolerance.
constexpr double kFitErrorOfTolerance = 0.1;
/// The 2-D fits aim at this fraction of the patch's parameter range (their error is then measured in 3-D).
constexpr double kFitParamRelTol = 1e-9;
/// The area a STEP/IGES file written from a topology may lose or gain, read back (relative): the reader
/// rebuilds the trims from the 3-D curves, which the fitted pcurves match within a tenth of their tolerances
/// (occ22470.igs: 3e-8).
constexpr double kBRepWrittenAreaRelTol = 1e-6;
/// The edges of an approximated face get at least this multiple of its approximation error as tolerance.
constexpr double kApproxToleranceFactor = 4.0;
/// Projection onto a patch: Gauss-Newton steps at most, and the step (relative to the domain) that ends it.
constexpr int kProjectionSteps = 30;
constexpr double kProjectionStepRel = 1e-14;

using detail::isSignal;

/// Flat knot vector of an OpenCASCADE B-spline curve (2-D or 3-D).
template <class C>
std::vector<double> flatKnots(const C& c) {
  TColStd_Array1OfReal k(1, c->NbPoles() + c->Degree() + 1);
  c->KnotSequence(k);
  return {k.begin(), k.end()};
}

/// A seam curve from an OpenCASCADE B-spline curve, 3-D (Geom_BSplineCurve) or 2-D (Geom2d_BSplineCurve, a
/// pcurve): the same poles, weights and knots; a periodic curve as its non-periodic form.
template <typename CurveT>
Result<BSplineCurve> fromOcct(opencascade::handle<CurveT> c) {
  constexpr bool k3d = std::is_same_v<CurveT, Geom_BSplineCurve>;
  if (c->IsPeriodic()) {
    c = opencascade::handle<CurveT>::DownCast(c->Copy());
    c->SetNotPeriodic();
  }
  Matrix pts(c->NbPoles(), k3d ? 3 : 2);
  VecX w = c->IsRational() ? VecX(c->NbPoles()) : VecX();
  for (int i = 1; i <= c->NbPoles(); ++i) {
    const auto p = c->Pole(i);
    pts(i - 1, 0) = p.X();
    pts(i - 1, 1) = p.Y();
    if constexpr (k3d) pts(i - 1, 2) = p.Z();
    if (c->IsRational()) w[i - 1] = c->Weight(i);
  }
  return BSplineCurve::create(c->Degree(), flatKnots(c), std::move(pts), std::move(w));
}

void distinct(const std::vector<double>& flat, TColStd_Array1OfReal& knots, TColStd_Array1OfInteger& mults) {
  std::vector<double> k;
  std::vector<int> m;
  for (double x : flat) {
    if (!k.empty() && x == k.back()) {
      ++m.back();
    } else {
      k.push_back(x);
      m.push_back(1);
    }
  }
  knots.Resize(1, static_cast<int>(k.size()), false);
  mults.Resize(1, static_cast<int>(m.size()), false);
  for (size_t i = 0; i < k.size(); ++i) {
    knots.SetValue(static_cast<int>(i) + 1, k[i]);
    mults.SetValue(static_cast<int>(i) + 1, m[i]);
  }
}

/// An OpenCASCADE B-spline curve from a seam curve: 3-D (CurveT = Geom_BSplineCurve) or 2-D (Geom2d_BSplineCurve).
template <typename CurveT>
opencascade::handle<CurveT> toOcct(const BSplineCurve& c) {
  constexpr bool k3d = std::is_same_v<CurveT, Geom_BSplineCurve>;
  using Poles = std::conditional_t<k3d, TColgp_Array1OfPnt, TColgp_Array1OfPnt2d>;
  Poles poles(1, c.numPoints());
  TColStd_Array1OfReal weights(1, c.numPoints());
  for (int i = 0; i < c.numPoints(); ++i) {
    if constexpr (k3d)
      poles.SetValue(i + 1, gp_Pnt(c.points()(i, 0), c.points()(i, 1), c.points()(i, 2)));
    else
      poles.SetValue(i + 1, gp_Pnt2d(c.points()(i, 0), c.points()(i, 1)));
    weights.SetValue(i + 1, c.isRational() ? c.weights()[i] : 1.0);
  }
  TColStd_Array1OfReal k;
  TColStd_Array1OfInteger m;
  distinct(c.knots().values(), k, m);
  if (c.isRational()) return new CurveT(poles, weights, k, m, c.degree());
  return new CurveT(poles, k, m, c.degree());
}

/// The point of `s` nearest to `p`, from (u, v) (Gauss-Newton, kept inside the domain; a direction in which
/// the surface does not move, a pole, keeps its start value).
gp_Pnt2d project(const Handle(Geom_BSplineSurface) & s, const gp_Pnt& p, double u, double v) {
  double u0 = 0, u1 = 0, v0 = 0, v1 = 0;
  s->Bounds(u0, u1, v0, v1);
  {  // pcurves may overshoot the patch's domain a little (their tolerance): the patch is extended, not
     // clamped
    const double eu = kBRepDomainRelTol * (u1 - u0), ev = kBRepDomainRelTol * (v1 - v0);
    u0 -= eu;
    u1 += eu;
    v0 -= ev;
    v1 += ev;
  }
  u = std::clamp(u, u0, u1);
  v = std::clamp(v, v0, v1);
  for (int it = 0; it < kProjectionSteps; ++it) {
    gp_Pnt q;
    gp_Vec su, sv;
    s->D1(u, v, q, su, sv);
    const gp_Vec r(q, p);
    const double a = su.Dot(su), b = su.Dot(sv), c = sv.Dot(sv), ru = su.Dot(r), rv = sv.Dot(r);
    const double reg = 1e-12 * (a + c) + 1e-300;
    const double det = (a + reg) * (c + reg) - b * b;
    if (!(std::abs(det) > 0)) break;
    const double du = ((c + reg) * ru - b * rv) / det, dv = ((a + reg) * rv - b * ru) / det;
    const double nu = std::clamp(u + du, u0, u1), nv = std::clamp(v + dv, v0, v1);
    const bool small = std::abs(nu - u) <= kProjectionStepRel * (u1 - u0) &&
                       std::abs(nv - v) <= kProjectionStepRel * (v1 - v0);
    u = nu;
    v = nv;
    if (small) break;
  }
  return {u, v};
}

/// Converts or fits one edge's geometry; `worst` collects the largest fit error.
struct FitStats {
  int curves = 0, pcurves = 0;
  double worst = 0.0;
};

/// The 3-D curve of an edge over [f, l] as a B-spline with the same parameterisation: converted where that
/// keeps it, else fitted through points within `allowed`; null when neither works.
std::optional<BSplineCurve> curve3d(const Handle(Geom_Curve) & c, double f, double l, double same,
                                    double allowed, FitStats& stats) {
  Handle(Geom_BSplineCurve) bs;
  try {
    OCC_CATCH_SIGNALS
    bs = GeomConvert::CurveToBSplineCurve(new Geom_TrimmedCurve(c, f, l));
  } catch (const Standard_Failure& e) {
    if (isSignal(e)) throw;
    bs.Nullify();
  }
  auto error = [&](const Handle(Geom_BSplineCurve) & b, bool mid) {
    double worst = 0;
    for (int i = 0; i < kParamSamples; ++i) {
      const double t = f + (l - f) * (i + (mid ? 0.5 : 0.0)) / (kParamSamples - (mid ? 0 : 1));
      worst = std::max(
          worst, c->Value(t).Distance(b->Value(std::clamp(t, b->FirstParameter(), b->LastParameter()))));
    }
    return worst;
  };
  if (!bs.IsNull() && std::abs(bs->FirstParameter() - f) <= Precision::PConfusion() &&
      std::abs(bs->LastParameter() - l) <= Precision::PConfusion() && error(bs, false) <= same &&
      error(bs, true) <= same) {
    Result<BSplineCurve> r = fromOcct(bs);
    if (r) return std::move(r).value();
  }
  for (int n = kFitPointsFirst; n <= kFitPointsLast; n = 4 * n - 3) {
    TColgp_Array1OfPnt pts(1, n);
    TColStd_Array1OfReal params(1, n);
    for (int i = 0; i < n; ++i) {
      const double t = i + 1 == n ? l : f + (l - f) * i / (n - 1);
      params.SetValue(i + 1, t);
      pts.SetValue(i + 1, c->Value(t));
    }
    const Handle(TColgp_HArray1OfPnt) hp = new TColgp_HArray1OfPnt(pts);
    const Handle(TColStd_HArray1OfReal) ht = new TColStd_HArray1OfReal(params);
    GeomAPI_Interpolate fit(hp, ht, false, Precision::Confusion() * 1e-3);
    fit.Perform();
    if (!fit.IsDone()) continue;
    const Handle(Geom_BSplineCurve) b = fit.Curve();
    const double err = std::max(error(b, false), error(b, true));
    if (err <= allowed && c->Value(f).Distance(b->Value(f)) <= allowed &&
        c->Value(l).Distance(b->Value(l)) <= allowed) {
      Result<BSplineCurve> r = fromOcct(b);
      if (!r) return std::nullopt;
      ++stats.curves;
      stats.worst = std::max(stats.worst, err);
      return std::move(r).value();
    }
  }
  return std::nullopt;
}

/// An edge's pcurve on a face as a B-spline in the face patch's parameters over [f, l]. `surf` is the face's
/// own surface; `patch` the converted patch. Where they share the parameterisation along the pcurve, the
/// pcurve is converted (or fitted in 2-D); elsewhere the surface's points along it are projected onto the
/// patch and fitted. The shift by whole periods that brings `x` into [lo, hi] (or nearest to it): a periodic
/// face's pcurves may lie one period away from the parameter box of its patch (Geom_RectangularTrimmedSurface
/// moves the box into its period).
double periodShift(double x, double lo, double hi, double period) {
  if (!(period > 0)) return 0.0;
  const double k0 = std::floor((x - lo) / period);
  double best = 0.0, bestDistance = std::numeric_limits<double>::infinity();
  for (double k : {0.0, k0, k0 - 1, k0 + 1}) {  // no shift first: a seam pcurve on the box side stays there
    const double y = x - k * period;
    const double d = y < lo ? lo - y : y > hi ? y - hi : 0.0;
    if (d < bestDistance - 1e-12 * period) {
      bestDistance = d;
      best = -k * period;
    }
  }
  return best;
}

std::optional<BSplineCurve> pcurve2d(Handle(Geom2d_Curve) c, double f, double l,
                                     const Handle(Geom_Surface) & surf,
                                     const Handle(Geom_BSplineSurface) & patch, double same, double allowed,
                                     FitStats& stats, double& best) {
  best = std::numeric_limits<double>::infinity();
  double u0 = 0, u1 = 0, v0 = 0, v1 = 0;
  patch->Bounds(u0, u1, v0, v1);
  const double pu = kBRepDomainRelTol * (u1 - u0), pv = kBRepDomainRelTol * (v1 - v0);
  {
    const gp_Pnt2d mid = c->Value(0.5 * (f + l));
    const double su = surf->IsUPeriodic() ? periodShift(mid.X(), u0, u1, surf->UPeriod()) : 0.0;
    const double sv = surf->IsVPeriodic() ? periodShift(mid.Y(), v0, v1, surf->VPeriod()) : 0.0;
    if (su != 0.0 || sv != 0.0) c = Handle(Geom2d_Curve)::DownCast(c->Translated(gp_Vec2d(su, sv)));
  }
  auto target = [&](double t) {
    const gp_Pnt2d q = c->Value(t);
    return surf->Value(q.X(), q.Y());
  };
  auto onPatch = [&](const gp_Pnt2d& q) {
    return patch->Value(std::clamp(q.X(), u0 - pu, u1 + pu), std::clamp(q.Y(), v0 - pv, v1 + pv));
  };
  // Does the patch reproduce the surface at the pcurve's own (u, v)?
  bool sameParam = true;
  for (int i = 0; i < kParamSamples && sameParam; ++i) {
    const double t = f + (l - f) * i / (kParamSamples - 1);
    const gp_Pnt2d q = c->Value(t);
    if (q.X() < u0 - pu || q.X() > u1 + pu || q.Y() < v0 - pv || q.Y() > v1 + pv)
      sameParam = false;
    else if (onPatch(q).Distance(target(t)) > same)
      sameParam = false;
  }
  auto error = [&](const Handle(Geom2d_BSplineCurve) & b) {
    double worst = 0;
    for (int i = 0; i < 2 * kParamSamples; ++i) {
      const double t = f + (l - f) * (i + 0.5) / (2 * kParamSamples);
      worst = std::max(
          worst,
          onPatch(b->Value(std::clamp(t, b->FirstParameter(), b->LastParameter()))).Distance(target(t)));
    }
    for (double t : {f, l}) worst = std::max(worst, onPatch(b->Value(t)).Distance(target(t)));
    return worst;
  };
  if (sameParam) {
    Handle(Geom2d_BSplineCurve) bs;
    try {
      OCC_CATCH_SIGNALS
      bs = Geom2dConvert::CurveToBSplineCurve(new Geom2d_TrimmedCurve(c, f, l));
    } catch (const Standard_Failure& e) {
      if (isSignal(e)) throw;
      bs.Nullify();
    }
    if (!bs.IsNull() && std::abs(bs->FirstParameter() - f) <= Precision::PConfusion() &&
        std::abs(bs->LastParameter() - l) <= Precision::PConfusion()) {
      double d2 = 0;  // the same (u, v) at the same parameter?
      for (int i = 0; i <= 2 * kParamSamples; ++i) {
        const double t = f + (l - f) * i / (2 * kParamSamples);
        d2 = std::max(d2, c->Value(t).Distance(bs->Value(t)));
      }
      if (d2 <= 1e-12 * std::max({u1 - u0, v1 - v0, 1.0})) {
        Result<BSplineCurve> r = fromOcct(bs);
        if (r) return std::move(r).value();
      }
    }
  }
  for (int n = kFitPointsFirst; n <= kFitPointsLast; n = 4 * n - 3) {
    TColgp_Array1OfPnt2d pts(1, n);
    TColStd_Array1OfReal params(1, n);
    for (int i = 0; i < n; ++i) {
      const double t = i + 1 == n ? l : f + (l - f) * i / (n - 1);
      params.SetValue(i + 1, t);
      const gp_Pnt2d q = c->Value(t);
      pts.SetValue(i + 1, sameParam ? q : project(patch, target(t), q.X(), q.Y()));
    }
    const Handle(TColgp_HArray1OfPnt2d) hp = new TColgp_HArray1OfPnt2d(pts);
    const Handle(TColStd_HArray1OfReal) ht = new TColStd_HArray1OfReal(params);
    Geom2dAPI_Interpolate fit(hp, ht, false, kFitParamRelTol * std::max(u1 - u0, v1 - v0));
    fit.Perform();
    if (!fit.IsDone()) continue;
    const Handle(Geom2d_BSplineCurve) b = fit.Curve();
    const double err = error(b);
    best = std::min(best, err);
    if (err <= allowed) {
      Result<BSplineCurve> r = fromOcct(b);
      if (!r) return std::nullopt;
      ++stats.pcurves;
      stats.worst = std::max(stats.worst, err);
      return std::move(r).value();
    }
  }
  return std::nullopt;
}

/// The pcurves of a face may run a little past its surface's bounds (trj3_s1-al-214.stp: 0.33 % of the v range on
/// face 22, within the edges' tolerances as OpenCASCADE evaluates the surface there). When the face's patch is its
/// B-spline or Bezier surface itself (an exact conversion), the patch is continued exactly over the pcurves' box
/// on each side that is not periodic (detail::extendedSurface: the end pieces' polynomials, as OpenCASCADE extends
/// them), so that the pcurves fit inside its domain. Returns a note ("" when nothing changed).
std::string extendPatchToPcurves(const TopoDS_Face& fwd, const Handle(Geom_Surface) & surf, const CadFace& info,
                                 Patch& patch) {
  if (!info.exact || !(surf->IsKind(STANDARD_TYPE(Geom_BSplineSurface)) ||
                       surf->IsKind(STANDARD_TYPE(Geom_BezierSurface))))
    return "";
  const Interval du = patch.surface.domainU(), dv = patch.surface.domainV();
  double ulo = du.lo, uhi = du.hi, vlo = dv.lo, vhi = dv.hi;
  auto add = [&](const gp_Pnt2d& q) {
    ulo = std::min(ulo, q.X());
    uhi = std::max(uhi, q.X());
    vlo = std::min(vlo, q.Y());
    vhi = std::max(vhi, q.Y());
  };
  for (TopExp_Explorer ex(fwd, TopAbs_EDGE); ex.More(); ex.Next()) {
    double f = 0, l = 0;
    const Handle(Geom2d_Curve) pc = BRep_Tool::CurveOnSurface(TopoDS::Edge(ex.Current()), fwd, f, l);
    if (pc.IsNull() || !(f < l)) continue;
    // Dense samples: the continuation is made only where a pcurve really runs past the bounds (the box of a
    // curved pcurve's poles is much larger than the curve), and its margin below covers what lies between them.
    for (int i = 0; i <= kOverhangSamples; ++i) add(pc->Value(f + (l - f) * i / kOverhangSamples));
  }
  // Sides past the domain check's slack (kBRepDomainRelTol) are continued to the samples' box plus that slack.
  const double su = kBRepDomainRelTol * du.length(), sv = kBRepDomainRelTol * dv.length();
  const bool uPer = surf->IsUPeriodic(), vPer = surf->IsVPeriodic();
  const Interval U{!uPer && ulo < du.lo - su ? ulo - su : du.lo, !uPer && uhi > du.hi + su ? uhi + su : du.hi};
  const Interval V{!vPer && vlo < dv.lo - sv ? vlo - sv : dv.lo, !vPer && vhi > dv.hi + sv ? vhi + sv : dv.hi};
  if (U == du && V == dv) return "";
  if (!std::isfinite(U.lo) || !std::isfinite(U.hi) || !std::isfinite(V.lo) || !std::isfinite(V.hi)) return "";
  Result<BSplineSurface> e = seam::detail::extendedSurface(patch.surface, U, V);
  if (!e) return "";  // left as it is: the pcurve fit below then says what does not fit
  patch.surface = std::move(e).value();
  const double most = std::max({(du.lo - U.lo) / du.length(), (U.hi - du.hi) / du.length(),
                                (dv.lo - V.lo) / dv.length(), (V.hi - dv.hi) / dv.length()});
  return fmt::format("the pcurves of face {} run up to {:.2g} % of its surface's parameter range past its bounds: "
                     "its patch is the surface continued exactly over [{:.6g}, {:.6g}] x [{:.6g}, {:.6g}], as "
                     "OpenCASCADE evaluates it there",
                     info.faceIndex, 100.0 * most, U.lo, U.hi, V.lo, V.hi);
}

}  // namespace

namespace detail {

std::shared_ptr<const BRepTopology> brepFromFaces(const TopoDS_Shape& shape,
                                                  const std::vector<TopoDS_Face>& faces,
                                                  CadImport& import, std::string& whyNot,
                                                  std::vector<std::string>& notes,
                                                  std::vector<int>* invalidInputFaces) {
  OcctSignalGuard guard;
  try {
    OCC_CATCH_SIGNALS
    TopTools_IndexedMapOfShape faceMap;
    for (const TopoDS_Face& f : faces) faceMap.Add(f);
    if (faceMap.Extent() != static_cast<int>(faces.size())) {
      whyNot = "a face is used more than once in the file's shape";
      return nullptr;
    }
    if (import.faces.size() != faces.size() || import.model.patches.size() != faces.size()) {
      whyNot = "the reader skipped a face (see its warnings)";
      return nullptr;
    }
    const double diag = std::max(import.model.boundingBox().diagonal(), 1e-300);
    const double same = kSameParamRelTol * diag;
    auto topo = std::make_shared<BRepTopology>();
    TopTools_IndexedMapOfShape vertexMap, edgeMap;
    FitStats stats;
    auto vertexId = [&](const TopoDS_Vertex& v) {
      const int before = vertexMap.Extent();
      const int k = vertexMap.Add(v);
      if (k > before) {
        const gp_Pnt p = BRep_Tool::Pnt(v);
        topo->vertices.push_back({Vec3(p.X(), p.Y(), p.Z()), BRep_Tool::Tolerance(v)});
      }
      return k - 1;
    };
    auto edgeId = [&](const TopoDS_Edge& e) -> int {
      const int before = edgeMap.Extent();
      const int k = edgeMap.Add(e);
      if (k <= before) return k - 1;
      const TopoDS_Edge fwd = TopoDS::Edge(e.Oriented(TopAbs_FORWARD));
      BRepEdge edge;
      TopoDS_Vertex a, b;
      TopExp::Vertices(fwd, a, b);
      if (a.IsNull() || b.IsNull()) {
        whyNot = fmt::format("edge {} has no vertex at one end", k);
        return -1;
      }
      edge.v0 = vertexId(a);
      edge.v1 = vertexId(b);
      edge.tolerance = BRep_Tool::Tolerance(fwd);
      BRep_Tool::Range(fwd, edge.t0, edge.t1);
      edge.degenerate = BRep_Tool::Degenerated(fwd);
      if (!edge.degenerate) {
        double f = 0, l = 0;
        const Handle(Geom_Curve) c = BRep_Tool::Curve(fwd, f, l);
        if (c.IsNull()) {
          whyNot = fmt::format("edge {} has no 3-D curve", k);
          return -1;
        }
        edge.t0 = f;
        edge.t1 = l;
        std::optional<BSplineCurve> bs =
            curve3d(c, f, l, same, std::max(kFitErrorOfTolerance * edge.tolerance, same), stats);
        if (!bs) {
          whyNot = fmt::format("the 3-D curve of edge {} ({}) cannot be made a B-spline within {:.3g}", k,
                               c->DynamicType()->Name(), kFitErrorOfTolerance * edge.tolerance);
          return -1;
        }
        edge.curve = std::move(*bs);
      }
      topo->edges.push_back(std::move(edge));
      return k - 1;
    };
    for (size_t fi = 0; fi < faces.size(); ++fi) {
      const TopoDS_Face& face = faces[fi];
      const TopoDS_Face fwd = TopoDS::Face(face.Oriented(TopAbs_FORWARD));
      const Handle(Geom_Surface) surf = BRep_Tool::Surface(fwd);
      const CadFace& info = import.faces[fi];
      if (std::string note = extendPatchToPcurves(fwd, surf, info, import.model.patches[fi]); !note.empty())
        notes.push_back(std::move(note));
      const Handle(Geom_BSplineSurface) patch = toOcctSurface(import.model.patches[fi].surface);
      BRepFace bf;
      bf.patch = static_cast<int>(fi);
      bf.reversed = face.Orientation() == TopAbs_REVERSED;
      bf.tolerance = BRep_Tool::Tolerance(fwd);
      // The outer wire first.
      const TopoDS_Wire outer = BRepTools::OuterWire(fwd);
      std::vector<TopoDS_Wire> wires;
      if (!outer.IsNull()) wires.push_back(outer);
      for (TopoDS_Iterator it(fwd); it.More(); it.Next())
        if (it.Value().ShapeType() == TopAbs_WIRE && !it.Value().IsSame(outer))
          wires.push_back(TopoDS::Wire(it.Value()));
      if (wires.empty()) {
        whyNot = fmt::format("face {} has no wire", fi + 1);
        return nullptr;
      }
      for (const TopoDS_Wire& w : wires) {
        int stored = 0;
        for (TopoDS_Iterator it(w); it.More(); it.Next()) ++stored;
        std::vector<TopoDS_Edge> ordered;
        for (BRepTools_WireExplorer ex(w, fwd); ex.More(); ex.Next()) ordered.push_back(ex.Current());
        const bool explored = static_cast<int>(ordered.size()) == stored;
        BRepCheck_Wire closure(w);
        // A wire that does not close (trj3's F30: one open edge), or that BRepTools_WireExplorer gives up on (two
        // edges meeting at both ends, gaps beyond the vertex tolerances): when OpenCASCADE's own check finds the
        // face invalid, the input is at fault, and the face is kept as it was read, open (BRepFace::openAsRead;
        // said in a warning, cad_io.cpp). Otherwise validateBRep checks the loop's closure.
        if (!bf.openAsRead &&
            (!explored || closure.Closed() != BRepCheck_NoError || closure.Closed2d(fwd) != BRepCheck_NoError) &&
            BRepCheck_Analyzer(face, false).IsValid() == Standard_False) {
          bf.openAsRead = true;
          if (invalidInputFaces != nullptr) invalidInputFaces->push_back(info.faceIndex);
        }
        if (!explored) {  // the wire's stored order
          ordered.clear();
          for (TopoDS_Iterator it(w); it.More(); it.Next())
            if (it.Value().ShapeType() == TopAbs_EDGE) ordered.push_back(TopoDS::Edge(it.Value()));
        }
        std::vector<BRepCoedge> loop;
        for (const TopoDS_Edge& e : ordered) {
          const int id = edgeId(e);
          if (id < 0) return nullptr;
          BRepCoedge c;
          c.edge = id;
          c.reversed = e.Orientation() == TopAbs_REVERSED;
          double f = 0, l = 0;
          const Handle(Geom2d_Curve) pc = BRep_Tool::CurveOnSurface(e, fwd, f, l);
          if (pc.IsNull()) {
            whyNot = fmt::format("edge {} has no pcurve on face {}", id + 1, fi + 1);
            return nullptr;
          }
          c.t0 = f;
          c.t1 = l;
          const double edgeTol = topo->edges[static_cast<size_t>(id)].tolerance;
          const double allowed =
              kFitErrorOfTolerance * std::max(edgeTol, bf.tolerance) + 2.0 * info.approximationError + same;
          double best = 0.0;
          std::optional<BSplineCurve> bs = pcurve2d(pc, f, l, surf, patch, same, allowed, stats, best);
          if (!bs) {
            whyNot = fmt::format(
                "the pcurve of edge {} on face {} ({}) cannot be carried onto the face's patch within "
                "{:.3g} (the closest fit is {:.3g} off)",
                id + 1, fi + 1, info.surfaceType, allowed, best);
            return nullptr;
          }
          c.pcurve = std::move(*bs);
          if (!info.exact) {
            // The patch of an approximated face is up to its approximation error off the face's surface, and
            // so are its edges' 3-D curves from the patch at their pcurves: their tolerances (and their
            // vertices') cover that, as OpenCASCADE's own approximations do.
            BRepEdge& edge = topo->edges[static_cast<size_t>(id)];
            const double tol = std::max(edge.tolerance, kApproxToleranceFactor * info.approximationError);
            edge.tolerance = tol;
            for (int v : {edge.v0, edge.v1})
              topo->vertices[static_cast<size_t>(v)].tolerance =
                  std::max(topo->vertices[static_cast<size_t>(v)].tolerance, tol);
          }
          loop.push_back(std::move(c));
        }
        bf.loops.push_back(std::move(loop));
      }
      topo->faces.push_back(std::move(bf));
    }
    // Shells, solids and the roots, in the order of a depth-first walk of the shape.
    TopTools_IndexedMapOfShape shellMap, solidMap;
    std::function<void(const TopoDS_Shape&)> walk = [&](const TopoDS_Shape& s) {
      switch (s.ShapeType()) {
        case TopAbs_COMPOUND:
        case TopAbs_COMPSOLID:
          for (TopoDS_Iterator it(s); it.More(); it.Next()) walk(it.Value());
          return;
        case TopAbs_SOLID: {
          if (solidMap.Contains(s)) return;
          BRepSolid solid;
          // Orientations relative to the parent (a shell in its solid, a face in its shell); locations
          // composed (the maps are keyed by the located shapes).
          for (TopoDS_Iterator it(s, false, true); it.More(); it.Next()) {
            if (it.Value().ShapeType() != TopAbs_SHELL) continue;
            const TopoDS_Shape& sh = it.Value();
            if (!shellMap.Contains(sh)) {
              BRepShell shell;
              for (TopoDS_Iterator jt(sh, false, true); jt.More(); jt.Next())
                if (const int k = faceMap.FindIndex(jt.Value()); k > 0)
                  shell.faces.push_back({k - 1, jt.Value().Orientation() == TopAbs_REVERSED});
              shellMap.Add(sh);
              topo->shells.push_back(std::move(shell));
            }
            solid.shells.push_back({shellMap.FindIndex(sh) - 1, sh.Orientation() == TopAbs_REVERSED});
          }
          solidMap.Add(s);
          topo->solids.push_back(std::move(solid));
          topo->roots.push_back(
              {BRepRoot::Kind::kSolid, {solidMap.Extent() - 1, s.Orientation() == TopAbs_REVERSED}});
          return;
        }
        case TopAbs_SHELL: {
          if (shellMap.Contains(s)) return;
          BRepShell shell;
          for (TopoDS_Iterator jt(s, false, true); jt.More(); jt.Next())
            if (const int k = faceMap.FindIndex(jt.Value()); k > 0)
              shell.faces.push_back({k - 1, jt.Value().Orientation() == TopAbs_REVERSED});
          shellMap.Add(s);
          topo->shells.push_back(std::move(shell));
          topo->roots.push_back(
              {BRepRoot::Kind::kShell, {shellMap.Extent() - 1, s.Orientation() == TopAbs_REVERSED}});
          return;
        }
        case TopAbs_FACE:
          if (const int k = faceMap.FindIndex(s); k > 0)
            topo->roots.push_back({BRepRoot::Kind::kFace, {k - 1, s.Orientation() == TopAbs_REVERSED}});
          return;
        default:
          return;  // wires, edges, vertices outside faces are not kept (docs/format.md)
      }
    };
    walk(shape);
    if (stats.curves + stats.pcurves > 0)
      notes.push_back(
          fmt::format("{} 3-D curves and {} pcurves fitted to keep the parameterisation of the converted "
                      "patches (each within a tenth of its edge's tolerance; largest error {:.3g} mm)",
                      stats.curves, stats.pcurves, stats.worst));
    return topo;
  } catch (const Standard_Failure& f) {
    whyNot = fmt::format("OpenCASCADE {}: {}", isSignal(f) ? "crashed" : "failed", f.GetMessageString());
    return nullptr;
  }
}

Result<TopoDS_Shape> shapeFromBRep(const Model& model, const std::string& source) {
  if (!model.brep) return invalidInput(source + ": the model has no B-rep topology");
  const BRepTopology& t = *model.brep;
  // Every id is used as an index below: a topology made in code (not read) is checked like a file's.
  if (Status st = validateBRep(model, t, source); !st) return st;
  OcctSignalGuard guard;
  std::string where = "the topology";
  try {
    OCC_CATCH_SIGNALS
    BRep_Builder b;
    std::vector<TopoDS_Vertex> vertices;
    for (const BRepVertex& v : t.vertices) {
      TopoDS_Vertex x;
      b.MakeVertex(x, gp_Pnt(v.point[0], v.point[1], v.point[2]),
                   std::max(v.tolerance, Precision::Confusion()));
      vertices.push_back(x);
    }
    std::vector<TopoDS_Edge> edges;
    for (size_t i = 0; i < t.edges.size(); ++i) {
      where = fmt::format("edge {}", i);
      const BRepEdge& e = t.edges[i];
      TopoDS_Edge x;
      const double tol = std::max(e.tolerance, Precision::Confusion());
      if (e.degenerate) {
        b.MakeEdge(x);
        b.Degenerated(x, true);
      } else {
        b.MakeEdge(x, toOcct<Geom_BSplineCurve>(e.curve), tol);
      }
      b.UpdateEdge(x, tol);
      b.Add(x, vertices[static_cast<size_t>(e.v0)].Oriented(TopAbs_FORWARD));
      b.Add(x, vertices[static_cast<size_t>(e.v1)].Oriented(TopAbs_REVERSED));
      b.Range(x, e.t0, e.t1);
      edges.push_back(x);
    }
    std::vector<TopoDS_Face> faces;
    for (size_t i = 0; i < t.faces.size(); ++i) {
      where = fmt::format("face {}", i);
      const BRepFace& f = t.faces[i];
      TopoDS_Face face;
      b.MakeFace(face, toOcctSurface(model.patches[static_cast<size_t>(f.patch)].surface),
                 std::max(f.tolerance, Precision::Confusion()));
      // Pcurves first (a seam edge gets both of its pcurves at once), then the wires.
      std::vector<std::vector<const BRepCoedge*>> byEdge(t.edges.size());
      for (const auto& loop : f.loops)
        for (const BRepCoedge& c : loop) byEdge[static_cast<size_t>(c.edge)].push_back(&c);
      for (size_t e = 0; e < byEdge.size(); ++e) {
        if (byEdge[e].empty()) continue;
        TopoDS_Edge& x = edges[e];
        const double tol = std::max(t.edges[e].tolerance, Precision::Confusion());
        const BRepCoedge* fwd = nullptr;
        const BRepCoedge* rev = nullptr;
        for (const BRepCoedge* c : byEdge[e]) (c->reversed ? rev : fwd) = c;
        if (fwd != nullptr && rev != nullptr) {
          b.UpdateEdge(x, toOcct<Geom2d_BSplineCurve>(fwd->pcurve), toOcct<Geom2d_BSplineCurve>(rev->pcurve), face,
                       tol);
        } else {
          const BRepCoedge* c = fwd != nullptr ? fwd : rev;
          b.UpdateEdge(x, toOcct<Geom2d_BSplineCurve>(c->pcurve), face, tol);
        }
        const BRepCoedge* c = fwd != nullptr ? fwd : rev;
        b.Range(x, face, c->t0, c->t1);
      }
      for (const auto& loop : f.loops) {
        TopoDS_Wire w;
        b.MakeWire(w);
        for (const BRepCoedge& c : loop)
          b.Add(w,
                edges[static_cast<size_t>(c.edge)].Oriented(c.reversed ? TopAbs_REVERSED : TopAbs_FORWARD));
        w.Closed(true);
        b.Add(face, w);
      }
      faces.push_back(face);
    }
    for (TopoDS_Edge& x : edges) {
      x.Closed(false);
      TopoDS_Vertex a, c;
      TopExp::Vertices(x, a, c);
      if (!a.IsNull() && a.IsSame(c)) x.Closed(true);
    }
    std::vector<TopoDS_Shell> shells;
    for (size_t i = 0; i < t.shells.size(); ++i) {
      TopoDS_Shell s;
      b.MakeShell(s);
      for (const BRepUse& u : t.shells[i].faces)
        b.Add(s, faces[static_cast<size_t>(u.id)].Oriented(u.reversed ? TopAbs_REVERSED : TopAbs_FORWARD));
      shells.push_back(s);
    }
    std::vector<TopoDS_Solid> solids;
    for (size_t i = 0; i < t.solids.size(); ++i) {
      TopoDS_Solid s;
      b.MakeSolid(s);
      for (const BRepUse& u : t.solids[i].shells)
        b.Add(s, shells[static_cast<size_t>(u.id)].Oriented(u.reversed ? TopAbs_REVERSED : TopAbs_FORWARD));
      solids.push_back(s);
    }
    TopoDS_Compound all;
    b.MakeCompound(all);
    for (const BRepRoot& r : t.roots) {
      const TopAbs_Orientation o = r.use.reversed ? TopAbs_REVERSED : TopAbs_FORWARD;
      const size_t k = static_cast<size_t>(r.use.id);
      if (r.kind == BRepRoot::Kind::kSolid)
        b.Add(all, solids[k].Oriented(o));
      else if (r.kind == BRepRoot::Kind::kShell)
        b.Add(all, shells[k].Oriented(o));
      else
        b.Add(all, faces[k].Oriented(o));
    }
    // The edges' SameParameter/SameRange flags: set by the builder; BRepLib::SameParameter checks them with
    // each edge's tolerance and only raises a tolerance where a pcurve is further off than it (none, for a
    // topology read from a valid file).
    BRepLib::SameParameter(all, Precision::Confusion(), false);
    return TopoDS_Shape(all);
  } catch (const Standard_Failure& f) {
    return invalidInput(fmt::format("{}: brep {}: OpenCASCADE {} making the shape: {}", source, where,
                                    isSignal(f) ? "crashed" : "failed", f.GetMessageString()));
  }
}

}  // namespace detail

Result<BRepWriteReport> writeBRepCadFile(const Model& model, const fs::path& file, CadFormat format) {
  Result<TopoDS_Shape> shape = detail::shapeFromBRep(model, file.string());
  if (!shape) return shape.status();
  BRepWriteReport report;
  detail::ShapeCounts counts;
  {
    detail::OcctSignalGuard guard;
    try {
      OCC_CATCH_SIGNALS
      counts = detail::countShape(*shape, detail::kPreciseAreaRelEps);
      report.valid = BRepCheck_Analyzer(*shape).IsValid();
    } catch (const Standard_Failure& f) {
      return invalidInput(
          fmt::format("{}: OpenCASCADE failed measuring the shape: {}", file.string(), f.GetMessageString()));
    }
  }
  detail::setCounts(report, counts);
  if (counts.faces == 0)
    return invalidInput(fmt::format("{}: the model's topology has no face to write", file.string()));
  const Handle(TDocStd_Document) doc = detail::newCadDocument();
  XCAFDoc_DocumentTool::ShapeTool(doc->Main())->AddShape(*shape, false);
  if (Status st = detail::writeCadDocument(doc, file, format, "MM", counts, &report.warnings,
                                           kBRepWrittenAreaRelTol, detail::kPreciseAreaRelEps);
      !st)
    return st;
  return report;
}


}  // namespace seam::occt
