#pragma once
// Continuity of two patches along a shared edge (a seam): certified G0/G1/G2 and C0/C1/C2 measures.
//
// Conventions (docs/algorithms/johansson.md has the derivation):
//  * Each side is seen from its edge: A' = A.orientedFrom(ea), B' = B.orientedFrom(eb), so the edge is u = 0 and
//    t (A) / s (B) run along it. A_out = -A'_u points out of A across the seam; B_cross = B'_u points into B.
//  * The correspondence s = phi(t) maps A's edge parameter to B's (affine, polynomial, or closest point).
//  * G1 connecting functions (Johansson Lemma 1): B_cross(phi(t)) = lambda(t) A_out(t) + kappa(t) A_t(t);
//    lambda > 0 for a proper join, lambda <= 0 is a fold. Normals n_A = A_t x A_out, n_B = B_t x B_cross (B_t the
//    derivative of b(phi(t)) in t) are oriented consistently, so a fold shows an angle near 180 degrees.
//  * G2: the jump of the shape operator in a common orthonormal frame of the tangent plane (spectral norm), and the
//    normal component of the Lemma 2 residual B_cc - lambda^2 A_oo - 2 lambda kappa A_ot - kappa^2 A_tt.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "seam/core/result.h"
#include "seam/core/tolerances.h"
#include "seam/core/types.h"
#include "seam/model/model.h"
#include "seam/spline/bspline_curve.h"
#include "seam/spline/bspline_surface.h"

namespace seam {

enum class GeometricClass { kNone, kG0, kG1, kG2 };
enum class ParametricClass { kNone, kC0, kC1, kC2 };
/// How points of B's edge were matched to points of A's edge.
enum class Correspondence {
  kAffine,      ///< s = alpha t + beta on the whole overlap (verified as a polynomial identity, or as the best map)
  kPolynomial,  ///< s = phi(t) (or t = psi(s)) polynomial per span, verified as an identity b(phi(t)) == a(t)
  kProjection,  ///< closest-point projection, sampled (measures not certified)
};
std::string_view toString(GeometricClass c);
std::string_view toString(ParametricClass c);
std::string_view toString(Correspondence c);

/// Where a worst value occurs: parameter on A's edge (A's own parameter, not the oriented one) and the 3-D point.
struct WorstLocation {
  double t = 0.0;
  Vec3 point = Vec3::Zero();
};

/// One sample along the seam (for plots and reports).
struct SeamSample {
  double t = 0.0;        ///< parameter on A's edge
  double g0 = 0.0;       ///< distance to B at the corresponding point
  double g1Deg = 0.0;    ///< tangent-plane angle, degrees
  double g2 = 0.0;       ///< shape-operator jump (1/length)
  double g2Rel = 0.0;    ///< relative to the larger curvature
};

/// Which closest points a pcurve seam's angle bound covers (SeamOptions::closestPointsOn).
/// kBoth: A's points paired with their closest points on B and B's with theirs on A (the two-sided angle, as the gap
/// is two-sided).
enum class ClosestPoints { kNone, kOnB, kOnA, kBoth };

struct SeamOptions {
  Tolerances tol;                 ///< classification thresholds (defaults: Tolerances{}; scale them to the model)
  int samplesPerSpan = 64;        ///< dense samples per Bezier span where the seam cannot be certified
  /// Start samples per piece of a certified seam whose edges coincide exactly (the bound subdivision refines);
  /// certified seams with a gap use twice as many, since their sampled distance comes from projections.
  int certifiedSamplesPerPiece = 8;
  double boundRelGap = 0.01;      ///< subdivide until a certified bound is within 1 % of the sampled worst value
  int maxSubdivisionDepth = 30;   ///< per piece; a bound that is not tight by then is reported as it is
  /// Interval bounds evaluated per measure (all pieces together). When the budget is spent, the intervals still
  /// open keep their (valid, looser) bounds instead of being split further: a bound that cannot close (a vanishing
  /// normal) costs this much, never 2^maxSubdivisionDepth.
  int maxBoundWork = 20000;
  int maxCertifiedDegree = 256;   ///< polynomial data above this degree are sampled instead (certified = false)
  bool keepSamples = false;       ///< fill SeamReport::samples (for reports and plots)
  /// Certify the G2 bound of G1 seams (subdivision of the Lemma 2 polynomials). false: the G2 values are the start
  /// samples only (a note says so) — for callers that need G0/G1 verdicts (heal of G0/G1 requests), where the G2
  /// subdivision of high-degree seams is most of the cost.
  bool certifyG2 = true;
  /// Seams whose sides share their control rows up to rounding (C^k splits: both whole edges, polynomial, the same
  /// Bezier spans, B_0 = A_0, B_1 = lambda A_out, B_2 = lambda^2 A_oo) get their G0/G1/G2 bounds straight from the
  /// row differences, without the exact piece data and the subdivision (docs/algorithms/seam-measures.md). The
  /// same classes; the bounds are rigorous and at round-off level. false: always the general route (tests).
  bool sharedRows = true;
  /// Pcurve seams (certifyPCurveSeam): also bound how much the angle between the normals at closest points can
  /// exceed the angle at the points the route pairs (PCurveSeamBounds::g1ClosestExcessDeg): kOnB for each point of
  /// A's edge and its closest point on B's, kOnA the other way, kBoth both ways. The B-rep check asks for both: its
  /// angles are between closest points, either way, as its gaps are two-sided (issue 35; the probe's boundary angle).
  ClosestPoints closestPointsOn = ClosestPoints::kNone;
};

struct SeamReport {
  std::string a, b;                   ///< patch names
  Edge aEdge = Edge::U0, bEdge = Edge::U0;
  Interval overlapA, overlapB;        ///< the shared part, in each patch's own edge parameter
  bool reversed = false;              ///< B's edge parameter decreases where A's increases
  Correspondence correspondence = Correspondence::kProjection;
  int correspondenceDegree = 1;       ///< degree of phi (1 = affine)

  // Worst values: *Max are certified upper bounds when `certified`, else the refined sampled maxima.
  double g0Max = 0.0, g0Sampled = 0.0;
  /// Largest distance between an end point of A's edge and the end point of B's edge matched to it (the ends of
  /// the seam; issue 15 §4). Included in g0Max / g0Sampled: where one edge overhangs the other by less than the
  /// overlap snap distance, the gap of the seam is this distance, not the gap over the common part alone.
  double endMismatch = 0.0;
  double g1MaxDeg = 0.0, g1SampledDeg = 0.0;
  /// Where the seam has a gap (its certified correspondence is not exact): the part of g1MaxDeg that covers the
  /// angle between A's normal at a point of A's edge and B's normal at the closest point of B's edge, beyond the
  /// angle at the points the correspondence pairs (a certified bound, degrees; issue 35). 0 where the
  /// correspondence is exact (the paired points are the closest points up to round-off) or not certified.
  double g1ClosestExcessDeg = 0.0;
  double g2Max = 0.0, g2Sampled = 0.0;          ///< absolute (1/length)
  /// g2Max / g2Sampled divided by the largest curvature (spectral norm of either shape operator) found anywhere on
  /// the seam, floored at "flat" (1e-3 / patch size): a seam-global ratio, not the pointwise maximum of
  /// jump(t) / curvature(t). Dividing by a value no larger than the true maximum keeps g2RelMax an upper bound.
  double g2RelMax = 0.0, g2RelSampled = 0.0;
  /// |normal component of the Lemma 2 residual|: sampled; on a certified G1 identity refined on the exact pieces
  double g2ResidualMax = 0.0;
  WorstLocation g0Worst, g1Worst, g2Worst;
  Interval lambdaRange{0.0, 0.0}, kappaRange{0.0, 0.0};  ///< sampled ranges of the G1 connecting functions
  double c1Mismatch = 0.0, c2Mismatch = 0.0;    ///< max |B'_u^k - (-1)^k A'_u^k| relative to max |A'_u^k|

  GeometricClass geometric = GeometricClass::kNone;
  ParametricClass parametric = ParametricClass::kNone;
  bool certified = false;             ///< bounds computed in Bernstein form over the whole overlap
  bool g1Identity = false;            ///< G1 proved as a polynomial identity (coefficients zero to round-off)
  bool g2Identity = false;            ///< G2 proved as a polynomial identity
  /// The bounds came from the sides' shared control rows (SeamOptions::sharedRows), not from the exact piece data.
  bool sharedRows = false;
  /// Set where the G1 bound could not close because a normal vanishes on the seam (a pole at an end, or a point
  /// inside where a side's cross-boundary derivative is tangent to the edge) and G1 was not proved as an identity:
  /// A's edge parameter there. g1MaxDeg is then the angle measured where the normals are defined (the limits along
  /// the edge from inside), never a bound from the vanishing point, and the seam is not certified (issue 35 §2).
  std::optional<double> g1PoleT;
  std::vector<std::string> notes;     ///< why something was not certified, degenerate normals, ...
  std::vector<SeamSample> samples;    ///< only with SeamOptions::keepSamples
};

/// The geometric class of a seam from its worst values (and exact identities, which override the tolerances):
/// G0 when the gap is within tol.distance, G1 when also the angle is within tol.angleDeg (or G1 is an identity),
/// G2 when also the relative curvature jump is within tol.curvatureRel (or G2 is an identity).
GeometricClass classifyGeometric(const SeamReport& report, const Tolerances& tol);

/// Makes a report's claims agree with its own numbers, then classifies it (issue 18: a class must never contradict
/// its numbers). An identity (G1: N_A x N_B = 0; G2: Lemma 2 residual = 0) whose bound did not close next to a
/// vanishing normal keeps the sampled value as the number shown, with a note; an identity that the samples
/// contradict (sampled angle or jump above tolerance) is dropped, and for G1 the seam is no longer certified.
void reconcileVerdict(SeamReport& report, const Tolerances& tol);

/// Analyses the seam between edge `ea` of `a` and edge `eb` of `b`. The edges must overlap (within
/// options.tol.distance, or with a gap: the overlap is found by closest-point projection of the end points).
/// Errors: kInvalidInput for non-3-D patches, kNotFound when the edges do not overlap at all, kDegenerate when an
/// edge collapses to a point.
Result<SeamReport> analyzeSeam(const Patch& a, Edge ea, const Patch& b, Edge eb, const SeamOptions& options = {});

/// Same, restricted to the part of A's edge with parameter in `aRange` (T-junctions: one long edge against several
/// short ones are analysed one short edge at a time).
Result<SeamReport> analyzeSeam(const Patch& a, Edge ea, const Patch& b, Edge eb, const SeamOptions& options,
                               std::optional<Interval> aRange);

/// Converts every length of `report` to another unit (issue 38 §1, display units): lengths (gaps, points) are
/// multiplied by `scale`, absolute curvatures (1/length) divided by it; angles, ratios and parameters are unchanged.
void scaleLengths(SeamReport& report, double scale);

/// One face's side of a seam along a curve in its parameter plane (an edge of a trimmed face): the face's surface,
/// the edge's parameter curve c(t) = (u(t), v(t)) (a 2-D B-spline, polynomial or rational: a rational one is composed
/// homogeneously, w^(p+q) S(u/w, v/w), which makes the side rational), the
/// parameter range of the edge on it, the face's parameter box (which side of a knot line the face lies on, where the
/// curve runs along one) and the sense of the face's normal (-1 for a reversed face).
/// A pcurve may run past its surface's parameter domain by this fraction of the domain (B-rep pcurves are only
/// accurate to the edge tolerance; real files overshoot by 1e-10..1e-7): the end span's polynomial is used there.
inline constexpr double kPCurveDomainSlackRel = 1e-6;

struct PCurveSide {
  const BSplineSurface* surface = nullptr;
  BSplineCurve pcurve;
  Interval range;
  Interval faceU, faceV;
  double normalSign = 1.0;
  /// How far the pcurve may run past its surface's parameter domain, as a fraction of the domain: the end span's
  /// polynomial continues the surface there (exactly as OpenCASCADE evaluates a bounded B-spline surface outside its
  /// bounds). The B-rep check sets kBRepDomainRelTol (model/brep.h) for the faces whose patch is their own surface.
  double domainSlackRel = kPCurveDomainSlackRel;
  /// A bound of how far `surface` lies from the face's own surface, where it is a polynomial stand-in for an analytic
  /// one (the B-rep check's patch of a cylinder in its angle parameter): added to the certified gap. 0 otherwise.
  double surfaceError = 0.0;
};

/// Certified values of a seam between two faces along their pcurves, which share the edge parameter (B's range
/// mapped affinely onto A's, as B-rep edges with SameParameter are). The edge is cut where a pcurve has a knot or
/// crosses a knot line of its surface (isolated exactly on the Bernstein coefficients), and on each piece S(c(t)),
/// the normal numerators (S_u x S_v)(c(t)) and the distance are composed exactly in Bernstein form
/// (BernsteinPatch::composed); the bounds are subdivided as in analyzeSeam. `t` values are A's pcurve parameter.
///
/// G2 (only when G1 holds as an identity): each face is seen through the local chart (s, t) -> S(c(t) + s d(t)),
/// d = (-v', u') the pcurve's normal in the parameter plane, whose rows H(c), dH/ds and d2H/ds2 along the edge are
/// composed polynomials too; the shape-operator jump is then bounded exactly as for patch seams (Lemma 2 residual,
/// docs/algorithms/johansson.md). The measure does not depend on the chart: any transversal d gives the same value.
struct PCurveSeamBounds {
  double g0Bound = 0.0, g0Sampled = 0.0, g0At = 0.0;        ///< distance: certified bound, best value, where
  double g1BoundDeg = 0.0, g1SampledDeg = 0.0, g1At = 0.0;  ///< normal angle (degrees), likewise
  bool g1Identity = false;  ///< the normals are parallel and agree as a polynomial identity (to round-off)
  /// Set where a normal vanishes inside the edge so that the angle bound cannot close there (and N_A x N_B is no
  /// identity): A's pcurve parameter of that point. g1BoundDeg is then the angle measured where both normals are
  /// defined, not a bound (SeamReport::g1PoleT; issue 35 section 2).
  std::optional<double> g1PoleT;
  /// G2 certified: g1Identity held, the Lemma 2 polynomials stayed within maxCertifiedDegree and the bound closed.
  bool g2Certified = false;
  double g2Bound = 0.0, g2Sampled = 0.0, g2At = 0.0;  ///< shape-operator jump (1/length), when g2Certified
  /// The Lemma 2 residual vanishes as a polynomial identity (or, when g2Certified, its bound is at round-off); may
  /// hold without g2Certified (a vanishing normal keeps the bound open): G2 wherever the normal is defined.
  bool g2Identity = false;
  /// Largest normal curvature (spectral norm of either shape operator) at the start samples: the reference for
  /// relative G2 values (no floor applied). Filled whenever G1 is an identity.
  double curvatureMax = 0.0;
  std::string g2Why;        ///< why G2 was not certified (empty when it was)
  int pieces = 0;           ///< polynomial pieces along the edge
  int maxDegree = 0;        ///< largest degree of the composed G1 polynomials
  int maxDegreeG2 = 0;      ///< largest degree of the Lemma 2 residual polynomials (0 when not built)
  /// With SeamOptions::closestPointsOn = kOnB: a certified bound of how much the angle between A's normal at a point
  /// of A's edge and B's normal at the (local) closest point of B's edge can exceed the angle between the normals at
  /// the points the route pairs, in degrees (g1BoundDeg + this bounds the angle between closest points); kOnA: the
  /// same with A and B exchanged; kBoth: the larger of the two. Infinite where it cannot be bounded (the other edge's
  /// tangent or normal not bounded away from zero near the pairing, or its curvature too large for the distance
  /// between the paired points). 0 with kNone.
  double g1ClosestExcessDeg = 0.0;
  /// The two directions of g1ClosestExcessDeg apart: A's points and their closest points on B (kOnB, kBoth), B's and
  /// theirs on A (kOnA, kBoth); 0 where not asked for. A pairing made from one side's closest points has the sharp
  /// excess in that direction; the other direction's may be loose (the B-rep check then pairs from the other side).
  double g1ClosestExcessOnBDeg = 0.0, g1ClosestExcessOnADeg = 0.0;
};
/// Errors (the caller samples instead): kInvalidInput (missing surface, pcurve not 2-D, empty ranges),
/// kUnsupported (a pcurve leaving its surface's domain, knot lines that cannot be isolated, degree
/// above SeamOptions::maxCertifiedDegree, a normal vanishing so that the distance bound cannot be closed). A normal
/// vanishing inside the edge, where the angle bound cannot close, is no error: g1PoleT says where.
Result<PCurveSeamBounds> certifyPCurveSeam(const PCurveSide& a, const PCurveSide& b, const SeamOptions& options = {});

/// A surface's Bezier span patches with their homogeneous partials up to order 2, as certifyPCurveSeam
/// composes them: built once per surface (surfaceSpans) and shared, read-only, by all the seams on it, on any
/// number of threads.
struct SurfaceSpans;
std::shared_ptr<const SurfaceSpans> surfaceSpans(const BSplineSurface& surface);
/// Same as certifyPCurveSeam(a, b, options), with each side's spans given: spansA / spansB from surfaceSpans
/// of that side's surface (nullptr, or the spans of another surface: built here). The result does not depend
/// on them.
Result<PCurveSeamBounds> certifyPCurveSeam(const PCurveSide& a, const PCurveSide& b,
                                           const SeamOptions& options, const SurfaceSpans* spansA,
                                           const SurfaceSpans* spansB);

}  // namespace seam
