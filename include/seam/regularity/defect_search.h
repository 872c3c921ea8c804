#pragma once
// A search for the defects that the regularity certificates exclude, for any knots and for rational splines:
// critical points (C'(t) = 0 on curves, S_u x S_v = 0 on surfaces) and self-intersections. Bezier subdivision with
// hull pruning: a parameter region is discarded when the convex hull of the Bernstein coefficients of the
// derivative (cross product) excludes 0, or when its derivative cones prove it injective (the Bezier-level analogue
// of Lau's condition / Theorem 3.7, see docs/algorithms/dyn-levin-yadshalom.md); pairs of regions are discarded when
// their control boxes are disjoint or when they lie in one injective region. Newton refinement turns the remaining
// small regions into points. What neither pruning nor Newton settles down to the stated resolution is reported as
// unresolved, so "no defect" is a statement with a resolution, never a guess from sampling.
#include <functional>
#include <optional>
#include <string_view>
#include <vector>

#include "seam/core/result.h"
#include "seam/core/types.h"
#include "seam/spline/bspline_curve.h"
#include "seam/spline/bspline_surface.h"

namespace seam::regularity {

/// Largest Bezier degree (per direction) the surface search takes: S_u x S_v has about twice the degree, its
/// Bernstein product costs O(degree^4), and beyond ~500 the binomial coefficients of the product overflow doubles.
/// A 200 x 200 Bezier net (degree 199) is refused with a message instead of running for minutes.
inline constexpr int kMaxSearchSurfaceDegree = 64;
/// Largest degree of a curve the search takes (rational curves: half of it, for the product A'w - Aw').
inline constexpr int kMaxSearchCurveDegree = 1024;

/// Progress of a long analysis: (stage, done, total), e.g. ("search", pieces settled, pieces). Called often (the
/// callee decides what to print and when); never called when empty.
using ProgressCallback = std::function<void(std::string_view stage, long done, long total)>;

struct SearchOptions {
  /// Regions are not split below this fraction of their knot span (per direction); what is left there unsettled is
  /// reported as unresolved.
  double resolution = 1e-6;
  /// Newton refinement starts once a region (both regions of a pair) is at most this fraction of its knot span.
  double newtonWidth = 1.0 / 16.0;
  /// Two points of the curve/surface closer than this are the same point (self-intersection). Default (nullopt):
  /// Tolerances::forModelSize(control-box diagonal).distance, i.e. 1e-6 x the diagonal.
  std::optional<double> distance;
  /// |C'| (curves) or |S_u x S_v| (surfaces) at or below criticalRelTol x its scale on the Bezier piece (largest
  /// Bernstein coefficient norm) counts as zero: a critical point.
  double criticalRelTol = 1e-9;
  /// At most this many critical points and self-intersection points are reported (then `truncated`).
  int maxReported = 64;
  /// Region and region-pair visits before the search gives up (then `complete` is false): at least maxWork, and at
  /// least maxWorkPerPiece per Bezier piece, so that the budget grows with the model (a clean curve needs a few
  /// visits per piece; a fixed total would leave every curve of more than ~100 000 segments unsettled).
  long maxWork = 300'000;
  long maxWorkPerPiece = 64;
  /// Called as ("search", pieces settled, pieces) while the self-intersection search runs.
  ProgressCallback progress;
};

struct CurveCriticalPoint {
  double t = 0.0;
  Vec3 point = Vec3::Zero();  ///< C(t) (embedded in R^3)
  double speed = 0.0;         ///< |C'(t)|
};

struct CurveSelfIntersection {
  double t1 = 0.0;  ///< t1 < t2
  double t2 = 0.0;
  Vec3 point = Vec3::Zero();
  double distance = 0.0;  ///< |C(t1) - C(t2)| after Newton
};

struct SurfaceCriticalPoint {
  double u = 0.0;
  double v = 0.0;
  Vec3 point = Vec3::Zero();
  double normalNorm = 0.0;  ///< |S_u x S_v|
};

struct SurfaceSelfIntersection {
  double u1 = 0.0, v1 = 0.0, u2 = 0.0, v2 = 0.0;
  Vec3 point = Vec3::Zero();
  double distance = 0.0;
};

/// What the search settled, for either kind of object.
struct SearchSummary {
  double resolution = 0.0;  ///< the relative resolution used (SearchOptions::resolution)
  double distance = 0.0;    ///< the distance tolerance used
  int unresolved = 0;       ///< regions or pairs left unsettled at the resolution (near a defect, or budget)
  bool truncated = false;   ///< more defects than maxReported
  bool complete = true;     ///< false when the work budget ran out
  long work = 0;            ///< region / pair visits
  /// True when nothing was found and everything was settled: no critical point and no self-intersection exist
  /// (down to the resolution; a near-miss closer than `distance` would have been reported).
  [[nodiscard]] bool provedClean(bool anyFound) const { return !anyFound && unresolved == 0 && complete; }
};

struct CurveSearchResult {
  std::vector<CurveCriticalPoint> criticalPoints;
  std::vector<CurveSelfIntersection> selfIntersections;
  SearchSummary summary;
  [[nodiscard]] bool defectFound() const { return !criticalPoints.empty() || !selfIntersections.empty(); }
};

struct SurfaceSearchResult {
  std::vector<SurfaceCriticalPoint> criticalPoints;
  std::vector<SurfaceSelfIntersection> selfIntersections;
  SearchSummary summary;
  [[nodiscard]] bool defectFound() const { return !criticalPoints.empty() || !selfIntersections.empty(); }
};

/// Searches a curve (any knots, polynomial or rational, 1..3 coordinates) for critical points and
/// self-intersections. Errors: kUnsupported for more than 3 coordinates or a degree above kMaxSearchCurveDegree
/// (rational: above half of it), kInvalidInput for a bad resolution.
Result<CurveSearchResult> searchCurveDefects(const BSplineCurve& curve, const SearchOptions& options = {});

/// Searches a surface (any knots, polynomial or rational, 2 or 3 coordinates) for points where S_u x S_v = 0 and
/// for self-intersections. Errors as searchCurveDefects; kUnsupported for a degree above kMaxSearchSurfaceDegree.
Result<SurfaceSearchResult> searchSurfaceDefects(const BSplineSurface& surface, const SearchOptions& options = {});

}  // namespace seam::regularity
