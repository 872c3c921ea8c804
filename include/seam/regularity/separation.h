#pragma once
// Exact decisions about two finite point sets: are their convex hulls strictly separated by a hyperplane (and by
// which one), or do they meet (and where)? This is the primitive behind every regularity certificate
// (Dyn-Levin-Yad-Shalom, docs/algorithms/dyn-levin-yadshalom.md).
//
// Every answer is exact for the given double coordinates: a separating plane is checked point by point in exact
// arithmetic (a floating-point filter with a proven error bound, GMP rationals when the filter cannot decide), and a
// witness is a convex combination of both sets whose equality was checked in GMP rationals. Touching hulls (sharing
// only a boundary point) count as meeting.
//
// Points are rows of a Matrix with 1, 2 or 3 columns; sets of fewer than 3 columns are embedded in R^3 with zero
// coordinates (a separating plane of the embedded sets restricted to the first columns separates the originals).
#include <vector>

#include "seam/core/result.h"
#include "seam/core/types.h"

namespace seam::regularity {

/// The plane {x : normal . x = offset} (in R^3; for 1- or 2-dimensional data the extra coordinates are zero).
struct Hyperplane {
  Vec3 normal = Vec3::Zero();
  double offset = 0.0;
};

/// Which stage of the decision pipeline produced the (always exactly checked) answer.
enum class DecisionRoute {
  kQuickDirection,  ///< a cheap candidate direction (centroids, summed unit vectors) was checked exactly
  kMinNormPoint,    ///< Wolfe's minimum-norm-point algorithm on the Minkowski difference
  kGlpk,            ///< GLPK simplex (margin LP or feasibility LP), then the exact check
  kExactSimplex,    ///< the exact phase-1 simplex in GMP rationals (always decides)
};

/// The outcome of one "are conv(first) and conv(second) disjoint?" question.
struct Separation {
  bool separated = false;
  /// When separated: normal . x > offset for every point x of `first` and normal . y < offset for every point y of
  /// `second`, both verified exactly. |normal|_inf = 1.
  Hyperplane plane;
  /// False only in the pathological case where the exact rational plane separates but no plane with double
  /// coefficients near it does (separation margin below double resolution); `plane` is then the rounded plane.
  bool planeExact = true;
  /// When not separated: a point in both hulls (rounded from the exact rational point) and the convex weights of
  /// the two sets that produce it (rounded from the exact rational weights; they sum to 1 up to rounding).
  Vec3 witness = Vec3::Zero();
  std::vector<double> weightsFirst;
  std::vector<double> weightsSecond;
  DecisionRoute route = DecisionRoute::kQuickDirection;
};

/// Which stages may be used (all of them by default). The exact simplex always runs last when the others fail, so
/// every combination decides correctly; tests switch stages off to compare routes.
struct SeparationOptions {
  bool useQuickDirection = true;  ///< cheap candidate directions first
  bool useMinNormPoint = true;    ///< Wolfe's algorithm next
  bool useGlpk = true;            ///< GLPK simplex (double) next
};

/// Are the convex hulls of the rows of `first` and of `second` strictly separated? Errors (kInvalidInput): an
/// empty set, more than 3 columns, different column counts, or a non-finite coordinate.
Result<Separation> separateHulls(const Matrix& first, const Matrix& second, const SeparationOptions& options = {});

/// Is the origin outside conv{heads_i - tails_i}? (The differences are never rounded: they are handled exactly.)
/// `first` of the result is the difference set, `second` the origin. Errors as for separateHulls, and
/// heads/tails of different sizes.
Result<Separation> separateFromOrigin(const Matrix& heads, const Matrix& tails, const SeparationOptions& options = {});

/// Exact check that `plane` strictly separates: normal . x > offset for all rows x of `first` and < offset for all
/// rows of `second` (no tolerance: a plane that is off by one unit in the last place is rejected).
bool isStrictlySeparating(const Hyperplane& plane, const Matrix& first, const Matrix& second);

}  // namespace seam::regularity
