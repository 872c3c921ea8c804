#pragma once
// Regularity certificates for B-spline curves and tensor-product surfaces (N. Dyn, D. Levin, I. Yad-Shalom,
// "Conditions for regular B-spline curves and surfaces", M2AN 26(1), 1992), per segment / per sub-net, with the
// defect search of defect_search.h as an independent check. See docs/algorithms/dyn-levin-yadshalom.md for which
// theorem backs which verdict and for the extensions to non-uniform knots and rational curves.
//
//   auto report = seam::regularity::analyzeCurve(curve);
//   for (const auto& s : report->segments) if (s.verdict == Verdict::kFails) ... s.result.failure()->separation.witness
#include <functional>
#include <optional>
#include <string_view>
#include <vector>

#include "seam/core/result.h"
#include "seam/core/types.h"
#include "seam/regularity/conditions.h"
#include "seam/regularity/defect_search.h"
#include "seam/regularity/separation.h"
#include "seam/spline/bspline_curve.h"
#include "seam/spline/bspline_surface.h"

namespace seam::regularity {

/// Knot gaps that differ from the span length h by at most kUniformKnotRelTol * h count as equal (knots read from
/// decimal text are rarely exactly uniform in binary).
inline constexpr double kUniformKnotRelTol = 1e-9;

enum class Verdict {
  kCertified,      ///< a sufficient condition holds: no critical point and no self-intersection (proof in `result`)
  kFails,          ///< uniform knots and Definition 1.1 / 1.2 fails: `result` ends with the witness
  kNotApplicable,  ///< the paper's theorems do not apply (non-uniform knots, rational) and no extension certified
};

enum class Condition {
  kNone,
  kLau,         ///< Lau's condition (curves) / Theorem 3.7 (surfaces): valid for any knots
  kRegularity,  ///< Definition 1.1 / 1.2 with the paper's splits W_k (uniform) or all splits (otherwise)
};

std::string_view verdictName(Verdict v);      ///< "certified", "fails", "not-applicable"
std::string_view conditionName(Condition c);  ///< "none", "lau", "regularity"
std::string_view checkKindName(CheckKind k);  ///< "lau", "split", "(1.7)", "(1.8)", "(1.9)+", "(1.9)-", ...

struct RegularityOptions {
  /// Theorems 2.7 / 3.5 are tried for orders k+1 .. k+maxEll (and never beyond the number of control points).
  int maxEll = 2;
  /// Relative tolerance of the uniform-knot test (see kUniformKnotRelTol).
  double uniformKnotRelTol = kUniformKnotRelTol;
  /// Beyond the paper: certify non-uniform (and rational) segments with Definition 1.1 for all splits 1..k-1
  /// (proved in the docs). False: such segments are not-applicable unless Lau's condition holds.
  bool allSplitsForNonUniform = true;
  /// Run the subdivision search (critical points, self-intersections) as well.
  bool runSearch = true;
  SearchOptions search;
  SeparationOptions separation;
  /// Called as ("certificates", segments / sub-nets done, all), ("ell", windows done, all) and, unless
  /// search.progress is set, ("search", pieces settled, pieces) during long runs (the CLI prints a line a second
  /// after the first second).
  ProgressCallback progress;
};

/// The verdict on one curve segment (one non-empty knot span).
struct SegmentVerdict {
  int index = 0;        ///< first control point: the segment depends on points index .. index + k - 1
  Interval interval;    ///< its parameter interval
  bool uniform = false;  ///< the 2k knots around the span are uniform (and the curve is polynomial)
  Verdict verdict = Verdict::kNotApplicable;
  Condition condition = Condition::kNone;  ///< the condition that certified, or that failed (kRegularity)
  std::vector<int> splits;                 ///< the splits r used by Definition 1.1
  ConditionResult result;                  ///< the certificate, or the failing check with its witness
  /// From the search: a critical point or self-intersection parameter lies in this segment's interval.
  bool defectNearby = false;
};

/// The window that stopped the Theorem 2.7 / 3.5 search (orders beyond ell_certified).
struct EllLimit {
  int order1 = 0;  ///< k + l (curves) / k1 + l1 (surfaces)
  int order2 = 0;  ///< k2 + l2 (surfaces)
  int first1 = 0;  ///< first control point (row) of the window
  int first2 = 0;  ///< first column (surfaces)
  ConditionResult lau;
  ConditionResult regularity;
};

struct CurveRegularity {
  int order = 0;  ///< k = degree + 1
  int dim = 0;
  bool rational = false;
  std::vector<SegmentVerdict> segments;
  /// Theorem 2.7: S(t1) = S(t2), t1 != t2, implies |t1 - t2| > ell knot spans. nullopt when some segment is not
  /// certified. ellCertified == number of segments - 1 means the whole curve is injective.
  std::optional<int> ellCertified;
  std::optional<EllLimit> ellLimit;  ///< why ell is not larger (absent when maxEll or the curve's end was reached)
  std::optional<CurveSearchResult> search;
  [[nodiscard]] bool anyFails() const;
};

/// The verdict on one k1 x k2 sub-net (one non-empty knot rectangle).
struct SubnetVerdict {
  int indexU = 0;  ///< first control row (u) and column (v) of the sub-net
  int indexV = 0;
  Interval u, v;
  bool uniformU = false;
  bool uniformV = false;
  Verdict verdict = Verdict::kNotApplicable;
  Condition condition = Condition::kNone;
  std::vector<int> splitsU, splitsV;
  ConditionResult result;
  bool defectNearby = false;
};

struct SurfaceRegularity {
  int orderU = 0;
  int orderV = 0;
  int dim = 0;
  bool rational = false;
  std::vector<SubnetVerdict> subnets;  ///< ordered by indexU, then indexV
  /// Theorem 3.5: S(u1,v1) = S(u2,v2) at different parameters implies |u1-u2| > ellU or |v1-v2| > ellV (in
  /// knot spans). nullopt when some sub-net is not certified.
  std::optional<int> ellU;
  std::optional<int> ellV;
  std::optional<EllLimit> ellLimit;
  std::optional<SurfaceSearchResult> search;
  [[nodiscard]] bool anyFails() const;
};

/// Certificates for every segment of a curve (1..3 coordinates, degree >= 1), Theorem 2.7 up to maxEll, and the
/// search. Errors: kUnsupported (more than 3 coordinates), kInvalidInput (bad options).
Result<CurveRegularity> analyzeCurve(const BSplineCurve& curve, const RegularityOptions& options = {});

/// Certificates for every sub-net of a surface (2 or 3 coordinates), Theorem 3.5 up to maxEll, and the search.
/// Rational surfaces get not-applicable verdicts (search only). Errors as analyzeCurve.
Result<SurfaceRegularity> analyzeSurface(const BSplineSurface& surface, const RegularityOptions& options = {});

/// The progress callback of the i-th object of analyzeCurves / analyzeSurfaces (called from the thread analysing it).
using ProgressOf = std::function<ProgressCallback(size_t)>;
/// analyzeCurve / analyzeSurface of every object on TBB's threads (each analysis is serial and independent of the
/// others; GLPK keeps its environment per thread): the results in the objects' order. `progressOf` (if set) gives
/// object i's options.progress; it may be called from several threads at once.
std::vector<Result<CurveRegularity>> analyzeCurves(const std::vector<const BSplineCurve*>& curves,
                                                   const RegularityOptions& options = {},
                                                   const ProgressOf& progressOf = {});
std::vector<Result<SurfaceRegularity>> analyzeSurfaces(const std::vector<const BSplineSurface*>& surfaces,
                                                       const RegularityOptions& options = {},
                                                       const ProgressOf& progressOf = {});

/// Are the knots t_first .. t_last equally spaced up to relTol * (their mean gap)? (An empty gap is never uniform.)
bool uniformKnots(const std::vector<double>& knots, int first, int last, double relTol = kUniformKnotRelTol);

}  // namespace seam::regularity
