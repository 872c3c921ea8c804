#pragma once
// Pointwise curvature comparison and 1-D maximum refinement shared by the seam analysis (continuity/seam.cpp) and
// the B-rep edge check (occt/brep_edge.cpp).
#include <Eigen/Dense>
#include <functional>
#include <optional>
#include <utility>
#include <vector>

#include "seam/core/types.h"

namespace seam::detail {

/// Local maxima of a sampled measure that are refined by golden-section search, and the iterations per maximum
/// (0.618^40 ~ 4e-9 of the bracketing interval).
inline constexpr int kRefinedMaxima = 3;
inline constexpr int kGoldenIterations = 40;

/// The shape operator (second fundamental form with respect to unit normal n) of a surface with first partials
/// su, sv and second partials suu, suv, svv, expressed in the orthonormal tangent frame (e1, e2).
Eigen::Matrix2d shapeInFrame(const Vec3& su, const Vec3& sv, const Vec3& suu, const Vec3& suv, const Vec3& svv,
                             const Vec3& n, const Vec3& e1, const Vec3& e2);

/// A normal N = a x b (a, b tangent vectors of a chart) shorter than this fraction of |a|^2 + |b|^2 is vanishing
/// (a pole, a collapsed edge): its direction is round-off there, and the sampled routes use its one-sided limit
/// along the edge instead (limitNormal). 1e-8 keeps the direction noise near 1e-8 rad.
inline constexpr double kNormalVanishRel = 1e-8;
/// A chart whose conditioning |a x b| / (|a|^2 + |b|^2) is below this gives curvatures with relative round-off
/// ~ 1e-16 / conditioning^2: the sampled routes do not measure curvature there (1e-6 relative at the threshold).
inline constexpr double kCurvatureChartRel = 1e-5;
/// Breakpoints of two edges' parameter curves closer than this fraction of the edge are one breakpoint written with
/// different digits in the two faces' pcurves (6e-13 apart in a real file): a piece between them would hold nothing
/// but round-off. Used by the pcurve route and the B-rep correspondence.
inline constexpr double kSameBreakpointRel = 1e-9;

/// |a x b| / (|a|^2 + |b|^2) (0 for a zero chart): 1/2 for an orthonormal chart, 0 for a degenerate one.
double chartConditioning(const Vec3& a, const Vec3& b);
/// chartConditioning from |a x b| and |a|^2 + |b|^2 already formed (the same value; inline: the per-sample path).
inline double chartConditioning(double crossNorm, double size) { return size > 0.0 ? crossNorm / size : 0.0; }
/// True when the normal a x b of a chart vanishes (kNormalVanishRel), from |a x b| and |a|^2 + |b|^2: where it does,
/// limitNormal takes the one-sided limit.
inline bool normalVanishes(double crossNorm, double size) { return !(crossNorm > kNormalVanishRel * size); }

/// The unit normal of the chart (a, b) along a curve on which a and b have derivatives da and db: (a x b)/|a x b|
/// where that is well defined (kNormalVanishRel), else the one-sided limit of the normalised cross product along
/// the curve, side * N'/|N'| with N' = da x b + a x db (side +1 when the curve leaves the vanishing point, -1 when
/// it arrives there). nullopt when the limit vanishes too.
std::optional<Vec3> limitNormal(const Vec3& a, const Vec3& b, const Vec3& da, const Vec3& db, double side);

/// Spectral norm of the symmetric part of m (largest |normal curvature| difference over all directions).
double spectralNorm(const Eigen::Matrix2d& m);

/// Golden-section refinement of a local maximum of f on [lo, hi]: (x, f(x)).
std::pair<double, double> refineMax(const std::function<double(double)>& f, double lo, double hi,
                                    int iterations = kGoldenIterations);

/// The refinement's resolution in x, as a fraction of the bracketing interval. Golden section's last bracket after
/// kGoldenIterations steps is 0.618^40 = 4.3e-9 of it; Brent's test stops with a bracket of up to 4 resolutions, so
/// 1e-9 keeps the point at least as close: a smooth maximum's value to round-off, a maximum at a kink (the
/// spectral norm of the curvature jump where its eigenvalues cross) to the same 1e-9-relative slope error.
inline constexpr double kRefineRelTol = 1e-9;
/// The resolution of the curvature-jump refinement of certified seams that are not exactly G1 (SeamAnalysis::refineG2,
/// issue 37 goal 1). That jump is a spectral norm, with a kink where its eigenvalues cross: there Brent's method falls
/// back to golden section, 28 evaluations per maximum at kRefineRelTol on the 6 000-patch kinked network. At 1e-6 of
/// the bracket a kinked maximum is found to 1e-6 x its slope x the bracket (a smooth one to ~1e-12 relative), far
/// below what separates a dense plot sample from it (1/64 of a span).
inline constexpr double kG2RefineRelTol = 1e-6;
/// Most evaluations of one parabolic refinement: golden-section steps alone (a kink, a plateau) reach
/// kRefineRelTol in 44; the rest is margin for steps of kRefineRelTol itself near the end.
inline constexpr int kParabolicMaxEvaluations = kGoldenIterations + 25;

/// Brent's parabolic refinement of a local maximum of f on [lo, hi] (R. P. Brent, Algorithms for Minimization
/// without Derivatives, 1973, ch. 5): parabolas through the three best points, golden-section steps where a parabola
/// is not trusted. (x, f(x)) of the best point seen, x within kRefineRelTol (hi - lo) of a local maximum: what
/// refineMax gives, in 8-15 evaluations on a smooth maximum instead of 42. NaN values count as worse than any.
/// `relTol`: the resolution in x instead of kRefineRelTol (kG2RefineRelTol).
std::pair<double, double> refineMaxParabolic(const std::function<double(double)>& f, double lo, double hi,
                                             double relTol = kRefineRelTol);

/// Refines the kRefinedMaxima largest local maxima of values[i] (sampled at xs[i], increasing) between their
/// neighbouring samples (refineMaxParabolic) and returns the best (x, value), never below the best sample.
std::pair<double, double> refinedMaximum(const std::vector<double>& xs, const std::vector<double>& values,
                                         const std::function<double(double)>& f, double relTol = kRefineRelTol);

}  // namespace seam::detail
