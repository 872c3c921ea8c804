// The certified route of a shared B-rep edge (issue 35): both faces' pcurves in exact B-spline form on the faces'
// converted patches, paired at equal edge parameters or by a closest-point correspondence, composed with the
// patches in Bernstein form by certifyPCurveSeam; the retries between closest points where SameParameter pcurves
// drift; and what the certificate changes in the edge's sampled report (docs/algorithms/seam-measures.md).
#include "occt/brep_edge.h"

#include <fmt/format.h>

#include <BRep_Tool.hxx>
#include <Geom2dConvert.hxx>
#include <Geom2d_BSplineCurve.hxx>
#include <Geom2d_TrimmedCurve.hxx>
#include <Geom_RectangularTrimmedSurface.hxx>
#include <Standard_Failure.hxx>
#include <TColStd_Array1OfReal.hxx>
#include <algorithm>
#include <array>
#include <cmath>

#include "continuity/sampling.h"
#include "occt/analytic_patch.h"

namespace seam::occt::detail {

namespace {

/// The certified pcurve route is taken only where the converted patch reproduces the face's OpenCASCADE surface
/// along the pcurve (same parametrisation) within this fraction of the model size, at kParamCheckPoints points.
constexpr double kSameParametrisationRel = 1e-9;
constexpr int kParamCheckPoints = 16;
/// A pcurve past kBRepDomainRelTol, within its edge's tolerance in 3-D (pcurveSide), may run this many times its
/// largest overshoot at the check points past the domain.
constexpr double kOvershootSlackFactor = 2.0;
/// Gauss-Newton steps, and the step relative to the domain at which they stop, of the projection of a face's point
/// onto its converted patch (isoLineInPatch).
constexpr int kProjectIterations = 30;
constexpr double kProjectStepRel = 1e-15;
/// Intervals at which an edge re-expressed as an iso-line of a converted patch is checked against the face's points.
constexpr int kReparamCheckPoints = 32;
/// A parameter that changes by less than this fraction of the domain along an edge is constant there (iso-lines).
constexpr double kIsoLineRel = 1e-9;
/// The polynomial patch of an analytic face (analyticSide) covers its parameter box widened by this fraction of the
/// box's size on each side.
constexpr double kAnalyticBoxMargin = 0.01;

/// The type name of a pcurve under its trims ("Geom2d_Circle", ...).
std::string basisName(Handle(Geom2d_Curve) c) {
  while (const auto t = Handle(Geom2d_TrimmedCurve)::DownCast(c)) c = t->BasisCurve();
  return c->DynamicType()->Name();
}

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

/// The type name of a face's surface under its trims ("Geom_CylindricalSurface", ...), "?" where OpenCASCADE fails.
std::string surfaceTypeName(const FaceSide& f) {
  std::string type = "?";
  try {
    Handle(Geom_Surface) base = f.surface;
    while (const auto rts = Handle(Geom_RectangularTrimmedSurface)::DownCast(base)) base = rts->BasisSurface();
    type = base->DynamicType()->Name();
  } catch (const Standard_Failure&) {
  }
  return type;
}

Result<FacePCurve> pcurveSide(const FaceSide& f, const FaceBoxCache& boxes, int face, const BSplineSurface& patch,
                              double modelSize, double edgeTol, bool standIn);

/// A face on an analytic surface whose converted patch runs in other parameters, with an edge that is no iso-line:
/// the pcurve composed with the surface's polynomial patch in the face's own parameters (analyticPatch, over the
/// face's parameter box), checked against the face like a converted patch (pcurveSide). `isoLineWhy`: the reason the
/// iso-line route failed, the error where the surface has no such patch.
Result<FacePCurve> analyticSide(const FaceSide& f, const FaceBoxCache& boxes, int face, double modelSize,
                                double edgeTol, const std::string& isoLineWhy) {
  // Over the face's parameter box widened by kAnalyticBoxMargin of its size each way: the surface is the same there,
  // and a pcurve that overshoots the box (by its edge's tolerance: 1e-7 absolute on a 0.5 mm cylinder cut by
  // OpenCASCADE's Boolean operations) stays inside the patch's domain.
  const detail::ParamBox& box = boxes.at(face);
  const double mu = kAnalyticBoxMargin * (box.u1 - box.u0), mv = kAnalyticBoxMargin * (box.v1 - box.v0);
  Result<AnalyticPatch> ap = analyticPatch(f.surface, box.u0 - mu, box.u1 + mu, box.v0 - mv, box.v1 + mv);
  if (!ap)
    return Status(ErrorCode::kUnsupported, fmt::format("{} (face surface {})", isoLineWhy, surfaceTypeName(f)));
  auto own = std::make_shared<const AnalyticPatch>(std::move(ap).value());
  Result<FacePCurve> out = pcurveSide(f, boxes, face, own->surface, modelSize, edgeTol, true);
  if (!out) return out;
  out->side.surfaceError = own->positionError;
  out->ownSurface = std::shared_ptr<const BSplineSurface>(own, &own->surface);
  out->surfaceNote = fmt::format("its {} composed as a polynomial patch in the face's own (angle) parameters, within "
                                 "{:.2g} of the surface",
                                 own->kind, own->positionError);
  return out;
}

/// kUnsupported, with the reason, when OpenCASCADE cannot convert the pcurve, when it leaves the patch's domain, or
/// when the patch made from the face reproduces the face's edge neither along the pcurve nor as an iso-line.
/// `standIn`: `patch` is the face's analytic surface's polynomial patch in its own parameters (analyticSide).
Result<FacePCurve> pcurveSide(const FaceSide& f, const FaceBoxCache& boxes, int face, const BSplineSurface& patch,
                              double modelSize, double edgeTol, bool standIn = false) {
  auto why = [&](std::string_view reason) {
    return Status(ErrorCode::kUnsupported, fmt::format("{} (face surface {})", reason, surfaceTypeName(f)));
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
    // Farther out, the overshoot is accepted where the surface continued there lies within the edge's own tolerance
    // (BRep_Tool::Tolerance) of the surface at the bound: the slack is then kOvershootSlackFactor times the largest
    // overshoot at the check points, and a pcurve piece past that slack is not certified (PCurveSeam::place finds no
    // span for it). trj3_s1-al-214.stp F21/F22 stay refused: 1.4e-3 of the domain out, 0.024 mm from the surface at
    // its bound where the edge's tolerance is 0.0136 mm.
    side.domainSlackRel = kBRepDomainRelTol;
    for (int i = 0; i <= kParamCheckPoints; ++i) {
      const double t = f.first + (f.last - f.first) * i / kParamCheckPoints;
      const VecX uv = side.pcurve.evaluate(t);
      const double cu = std::clamp(uv[0], pd.lo, pd.hi), cv = std::clamp(uv[1], qd.lo, qd.hi);
      const double out = std::max(std::abs(uv[0] - cu) / pd.length(), std::abs(uv[1] - cv) / qd.length());
      if (!(out <= kBRepDomainRelTol)) {
        const double extent = (toVec(f.surface->Value(uv[0], uv[1])) - toVec(f.surface->Value(cu, cv))).norm();
        if (!(extent <= edgeTol))
          return why(fmt::format("the pcurve leaves the patch's parameter domain: ({:.9g}, {:.9g}) outside [{:.9g}, "
                                 "{:.9g}] x [{:.9g}, {:.9g}], {:.3g} from the surface at its bound (the edge's "
                                 "tolerance: {:.3g})",
                                 uv[0], uv[1], pd.lo, pd.hi, qd.lo, qd.hi, extent, edgeTol));
        side.domainSlackRel = std::max(side.domainSlackRel, kOvershootSlackFactor * out);
      }
      // Does the patch reproduce the face's surface in its own parameters? Compared inside the domain (the patch's
      // evaluator clamps; OpenCASCADE's continues the end span).
      const Vec3 x = patchPoint(patch, cu, cv);
      if ((x - toVec(f.surface->Value(cu, cv))).norm() > kSameParametrisationRel * modelSize) {
        if (standIn) return why("the polynomial patch of the analytic surface does not reproduce it");
        // A converted analytic surface: the edge as an iso-line of the patch, in a parameter of its own.
        Result<BSplineCurve> line = isoLineInPatch(f, side.pcurve, patch, modelSize);
        if (!line) return analyticSide(f, boxes, face, modelSize, edgeTol, line.status().message());
        side.pcurve = std::move(line).value();
        side.range = {0.0, 1.0};
        side.faceU = pd;  // the patch converts the face's surface over the face's box
        side.faceV = qd;
        return FacePCurve{std::move(side), true,
                          "an iso-line of its converted patch (whose parameter is not the angle)", nullptr, {}};
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
                                      basisName(f.pcurve)),
                          nullptr,
                          {}};
      }
    }
    return FacePCurve{std::move(side), false, {}, nullptr, {}};
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
  // The angle between closest points: the paired points' bound plus the excess, where that is bounded. Where it is
  // not (the other edge's second derivative on a sliver leaf is round-off over the leaf's length squared), the bound
  // holds at the paired points, and the samples between closest points still withdraw it when above it.
  const bool excessBounded = std::isfinite(r->g1ClosestExcessDeg);
  const double excess = closestExcessDeg(*r);
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
  rep.g1MaxDeg = std::max(r->g1BoundDeg + excess, r->g1SampledDeg);
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
    const std::string closest =
        !excessBounded ? "; the angle bound holds at the points paired (how far the closest points' angle may exceed "
                         "it could not be bounded: a leaf too short for its second derivative's round-off)"
        : excess > 0.0 ? fmt::format("; the angle between closest points exceeds the paired points' ({:.6g} deg) by "
                                     "at most {:.3g} deg, included",
                                     r->g1BoundDeg, excess)
                       : "";
    rep.notes.insert(rep.notes.begin(),
                     fmt::format("G0 and G1 certified through the pcurves composed with the surfaces in Bernstein "
                                 "form ({} pieces, degree <= {}){}; {}",
                                 r->pieces, r->maxDegree, closest, g2));
  }
  reconcileVerdict(rep, opt.tol);
}

/// An equal-parameter gap bound above this fraction of the distance tolerance is measured again between the
/// boundaries (tryCertificate). At 1 (the tolerance itself) a 1e-3 mm model whose pcurve drifts by 5e-5 kept that as
/// its gap where the boundaries coincide (OcctTruth.SeamGapsAreBetweenTheBoundariesWhenPCurvesDriftOrOverhang).
constexpr double kDriftRetryFraction = 0.01;

/// Pairs the two sides of `c` by a monotone piecewise-cubic correspondence: the master keeps its parameter; the
/// other is composed with a cubic (its degree triples): master = the side with its own parameter, or of the higher
/// pcurve degree. Sets c.a and c.b, or c.failure (c.a stays null).
/// `masterA`: the master chosen by the caller (sharpenReverseDirection), else by the rule above.
void pairByCorrespondence(EdgeCertificate& c, double pairFraction = detail::kCorrespondenceTolFraction,
                          std::optional<bool> masterA = std::nullopt) {
  const FacePCurve& sa = **c.sideA;
  const FacePCurve& sb = **c.sideB;
  c.byCorrespondence = true;
  c.masterA = masterA ? *masterA
              : sa.ownParameter != sb.ownParameter ? sa.ownParameter
                                                   : sa.side.pcurve.degree() >= sb.side.pcurve.degree();
  const FacePCurve& master = c.masterA ? sa : sb;
  const FacePCurve& other = c.masterA ? sb : sa;
  c.correspondence.emplace(detail::correspondInParameterOf(master.side, other.side, c.opt.tol.distance, pairFraction));
  if (!*c.correspondence) {
    c.failure = fmt::format("not certified: no common parameter for the two edges: {}",
                            c.correspondence->status().message());
    return;
  }
  c.opt.maxBoundWork = std::min(c.opt.maxBoundWork, detail::kCorrespondenceBoundWork);
  // The master's points are paired with their closest points on the other side: the angle bound covers those, and
  // the other side's points with theirs on the master (as tryCertificate).
  c.opt.closestPointsOn = ClosestPoints::kBoth;
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
                                                       size_t patchA, size_t patchB,
                                                       double pairFraction = detail::kCorrespondenceTolFraction,
                                                       std::optional<bool> masterA = std::nullopt) {
  EdgeCertificate closest;
  closest.sideA = c.sideA;
  closest.sideB = c.sideB;
  closest.sameParameter = true;
  closest.opt = c.opt;
  pairByCorrespondence(closest, pairFraction, masterA);
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

}  // namespace

void tryCertificate(EdgeCertificate& c, const FaceSide& A, const FaceSide& B, const FaceBoxCache& boxes, int fa,
                    int fb, const BSplineSurface& pa, const BSplineSurface& pb,
                    const TopoDS_Edge& edge, const std::string& nameA, const std::string& nameB,
                    const SeamOptions& opt, double modelSize, const SpansCache& spans, size_t patchA,
                    size_t patchB, bool exactA, bool exactB) {
  const double edgeTol = BRep_Tool::Tolerance(edge);
  const std::string approximated = "its patch approximates the face's surface";
  c.sideA.emplace(exactA ? pcurveSide(A, boxes, fa, pa, modelSize, edgeTol)
                         : analyticSide(A, boxes, fa, modelSize, edgeTol, approximated));
  c.sideB.emplace(exactB ? pcurveSide(B, boxes, fb, pb, modelSize, edgeTol)
                         : analyticSide(B, boxes, fb, modelSize, edgeTol, approximated));
  c.sameParameter = BRep_Tool::SameParameter(edge) && BRep_Tool::SameRange(edge);
  c.opt = opt;
  // Angles between closest points (PCurveSeamBounds::g1ClosestExcessDeg) both ways: A's edge points and their
  // closest points on B (as the sampled route takes them), and B's and theirs on A. One way alone fell below the
  // OpenCASCADE probe's two-sided boundary angle by 1.5 % across a 0.02 mm gap (boxed_sphere.step edge 9: 4.272 deg
  // certified, 4.337 deg measured from B's side).
  c.opt.closestPointsOn = ClosestPoints::kBoth;
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
  if (c.byCorrespondence || s.ts.size() < 2 || best < kAngleSearchFraction * c.angleBoundDeg()) return best;
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
  const double bound = c.angleBoundDeg(), sample = c.closestSampleAngleDeg;
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
  // The excess of the closest points' angle over the paired points' (g1ClosestExcessDeg) is more than the
  // certification gap: the pcurves drift, and the closest-point pairing, whose excess is at the pairing's accuracy,
  // may give the closer bound (trj3_s1-al-214.stp edge 96: 0.0369 deg at equal parameters plus 0.0443 of excess).
  const auto excessLoose = [](const EdgeCertificate& e) {
    return e.forwardExcessDeg() > kLooseAngleRelSlack * (*e.bounds)->g1BoundDeg + kAngleRetrySlackDeg;
  };
  const bool looseExcess = excessLoose(c);
  if (!belowSamples && !looseBound && !aboveSamples && !looseExcess) return;
  std::optional<EdgeCertificate> closest = closestPointCertificate(c, spans, patchA, patchB);
  // Below a sample, the closest-point pairing is made finer (kFinerPairingFractions) while its bound stays below the
  // sample or it cannot be formed at the default accuracy (an end overhang beyond it: bearing.iges edge 111, 1.9e-6
  // against 1e-6; a finer pairing holds its end pieces to the overhang); where the excess is loose and the default
  // pairing cannot be formed, likewise.
  const auto belowSample = [&](const EdgeCertificate& e) {
    return sample > e.angleBoundDeg() * (1.0 + kAngleRetryRelSlack) + kAngleRetrySlackDeg;
  };
  double pairing = detail::kCorrespondenceTolFraction;
  if (belowSamples || (looseExcess && !closest))
    for (const double fraction : detail::kFinerPairingFractions) {
      if (closest && !belowSample(*closest)) break;
      std::optional<EdgeCertificate> finer = closestPointCertificate(c, spans, patchA, patchB, fraction);
      if (!finer) break;
      closest = std::move(finer);
      repoint(*closest);
      pairing = fraction;
    }
  // Where the pairing's own excess is still more than the certification gap of its bound, the pairing is made finer
  // once, to the accuracy at which the excess (the pairing's distance from the closest points times the normal's
  // turning) would shrink to that gap (bearing.iges edge 105: 0.0041 deg paired plus 0.0020 of excess at 6.4e-7 mm;
  // the OCCT probe measures 0.0025 deg).
  if (closest && excessLoose(*closest)) {
    const PCurveSeamBounds& cb = **closest->bounds;
    const double fraction = std::max(detail::kFinerPairingFractions.back(),
                                     pairing * kLooseAngleRelSlack * cb.g1BoundDeg / closest->forwardExcessDeg());
    if (fraction < pairing)
      if (std::optional<EdgeCertificate> finer = closestPointCertificate(c, spans, patchA, patchB, fraction);
          finer && finer->angleBoundDeg() < closest->angleBoundDeg()) {
        closest = std::move(finer);
        repoint(*closest);
      }
  }
  if (!closest) {
    // No certified closest-point pairing: an angle made by the pairing alone is not shown as certified.
    c.angleFromPairing = looseBound;
    return;
  }
  const double closestBound = closest->angleBoundDeg();
  if (!belowSamples && !(closestBound < bound)) return;
  // Tried for a loose bound only: the equal-parameter bound stands where the closest-point route's own bound lies
  // below the closest points' samples (its pairing is certified to within its slack only, and applyCertificate would
  // withdraw the certificate: bearing.iges, 11 edges).
  if (!belowSamples && !looseBound && !looseExcess &&
      sample > closestBound * (1.0 + kAngleRetryRelSlack) + kAngleRetrySlackDeg)
    return;
  closest->equalParameterAngleDeg = bound;
  closest->closestSampleAngleDeg = sample;
  adopt(c, std::move(*closest));
}

void sharpenReverseDirection(EdgeCertificate& c, const FaceSide& A, const FaceSide& B, const SpansCache& spans,
                             size_t patchA, size_t patchB) {
  if (!c.certifies()) return;
  PCurveSeamBounds& b = **c.bounds;
  if (b.g1PoleT) return;
  const bool fromA = c.pairedFromA();
  const double forward = fromA ? b.g1ClosestExcessOnBDeg : b.g1ClosestExcessOnADeg;
  const double reverse = fromA ? b.g1ClosestExcessOnADeg : b.g1ClosestExcessOnBDeg;
  if (!std::isfinite(forward)) return;  // the paired points' bound stands (certifyThroughPCurves), as before
  const double own = b.g1BoundDeg + forward;
  // The reverse direction's excess within the certification gap of the pairing's own: the two-sided bound stands.
  if (reverse <= forward + kLooseAngleRelSlack * own + kAngleRetrySlackDeg) return;
  // The other side's points paired with their closest points (a correspondence with that side as the master): its
  // own direction is the sharp one.
  if (std::optional<EdgeCertificate> other =
          closestPointCertificate(c, spans, patchA, patchB, detail::kCorrespondenceTolFraction, !fromA)) {
    const PCurveSeamBounds& ob = **other->bounds;
    const double e = fromA ? ob.g1ClosestExcessOnADeg : ob.g1ClosestExcessOnBDeg;
    if (!ob.g1PoleT && std::isfinite(e) && !(ob.g1BoundDeg + e >= b.g1BoundDeg + reverse)) {
      c.reverseAngleDeg = ob.g1BoundDeg + e;
      b.g1ClosestExcessDeg = std::max(own, c.reverseAngleDeg) - b.g1BoundDeg;
      return;
    }
  }
  // No sharper pairing from the other side (its correspondence cannot be formed or certified: trj3_s1-al-214.stp
  // edge 81, whose loose reverse excess of 0.25 deg would multiply a 0.037 deg angle by 8): the other side's edge
  // points at kMinSamples + 1 evenly spaced parameters, with the normal at their closest points. Where they stay
  // within the pairing's own bound, that bound is shown (its direction certified, the other held to the samples, as
  // before the two-sided angle); above it, the loose two-sided bound where it is finite, else the samples withdraw
  // the certificate (applyCertificate).
  const FaceSide& from = fromA ? B : A;
  const FaceSide& to = fromA ? A : B;
  double sampled = 0.0;
  for (int i = 0; i <= kMinSamples; ++i)
    sampled = std::max(sampled, closestAngleDeg(from, to, from.first + (from.last - from.first) * i / kMinSamples));
  c.reverseSampleAngleDeg = sampled;
  if (sampled <= own * (1.0 + kAngleRetryRelSlack) + kAngleRetrySlackDeg) {
    b.g1ClosestExcessDeg = forward;
  } else if (!std::isfinite(reverse)) {
    b.g1ClosestExcessDeg = forward;
    c.closestSampleAngleDeg = std::max(c.closestSampleAngleDeg, sampled);
  }
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
  // The excess of the closest points' angle over the paired points' (PCurveSeamBounds::g1ClosestExcessDeg) alone
  // changes the class (linkrods.step edge 75: 0.4999 deg between paired points, 2.95 deg with the excess of a drift
  // of 1.7e-4 mm where the normals turn by 150 rad/mm, 0.4967 deg between the sampled closest points): neither class
  // is proved, and the sampled one is shown.
  bool excessDecides = false;
  if (rep.certified && c.certifies() && closestExcessDeg(**c.bounds) > 0.0) {
    SeamReport paired = rep;
    paired.g1MaxDeg = std::max((*c.bounds)->g1BoundDeg, (*c.bounds)->g1SampledDeg);
    reconcileVerdict(paired, c.opt.tol);
    excessDecides = paired.geometric != rep.geometric;
  }
  if (rep.certified && excessDecides) {
    rep.notes.push_back(fmt::format(
        "not certified: between the points the certified route pairs the normals make up to {:.4g} deg, and between "
        "closest points at most {:.3g} deg more (the pcurves drift along the edge, the normals turn); the sampled "
        "angle between closest points ({:.4g} deg) is shown, since the bound alone would change the class",
        (*c.bounds)->g1BoundDeg, (*c.bounds)->g1ClosestExcessDeg, c.closestSampleAngleDeg));
  } else if (rep.certified && (c.angleFromPairing || belowSamples)) {
    rep.notes.push_back(fmt::format(
        "not certified: at the points the certified route pairs the normals make up to {:.4g} deg, between the "
        "sampled closest points {:.4g} deg (the SameParameter pcurves drift along the edge, the paired points are up "
        "to {:.3g} apart, and the closest-point pairing could not be certified closer): the sampled angle is shown",
        rep.g1MaxDeg, c.closestSampleAngleDeg, rep.g0Max));
  }
  if (rep.certified && (excessDecides || c.angleFromPairing || belowSamples)) {
    rep.g1MaxDeg = rep.g1SampledDeg = c.closestSampleAngleDeg;
    rep.g0Sampled = sampledG0;
    rep.g0Max = sampledG0Max;
    rep.g0Worst = sampledG0Worst;
    rep.certified = false;
    reconcileVerdict(rep, c.opt.tol);
  }
  if (!rep.certified) return;
  const FacePCurve& a = **c.sideA;
  const FacePCurve& b = **c.sideB;
  for (const auto& [s, name] : {std::pair{&a, &nameA}, std::pair{&b, &nameB}})
    if (s->ownSurface) rep.notes.push_back(fmt::format("{}: {}", *name, s->surfaceNote));
  const std::string& from = c.pairedFromA() ? nameB : nameA;
  const std::string& to = c.pairedFromA() ? nameA : nameB;
  if (c.reverseAngleDeg > 0.0)
    rep.notes.push_back(fmt::format("between {}'s edge points and their closest points on {}'s edge the angle is "
                                    "bounded by a second pairing, made from {}'s side ({:.6g} deg)",
                                    from, to, from, c.reverseAngleDeg));
  else if (c.reverseSampleAngleDeg > 0.0 && (*c.bounds)->g1ClosestExcessDeg == c.forwardExcessDeg())
    rep.notes.push_back(fmt::format("between {}'s edge points and their closest points on {}'s edge the angle is "
                                    "sampled ({:.6g} deg at {} points, within the bound): the bound of that direction "
                                    "through the pairing from {}'s side is loose, and no pairing from {}'s side "
                                    "certifies",
                                    from, to, c.reverseSampleAngleDeg, kMinSamples + 1, to, from));
  if (!c.byCorrespondence) return;
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

}  // namespace seam::occt::detail
