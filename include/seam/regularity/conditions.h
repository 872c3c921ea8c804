#pragma once
// The control-point conditions of Dyn, Levin and Yad-Shalom (M2AN 26(1), 1992) and of Lau (CAGD 5, 1988), decided
// exactly (see separation.h) on one set of points or one sub-net:
//   - Lau's condition: 0 not in conv{P_{i+1} - P_i};
//   - Definition 1.1 (curve regularity condition of order k) for a set of splits r;
//   - Theorem 3.7 (Lau's condition for nets) and Definition 1.2 (conditions (1.7), (1.8), (1.9)) for a sub-net.
// The theorems that turn these into statements about curves and surfaces (and when they hold for non-uniform knots)
// are in docs/algorithms/dyn-levin-yadshalom.md; regularity.h applies them to whole curves and surfaces.
#include <vector>

#include "seam/core/result.h"
#include "seam/core/types.h"
#include "seam/regularity/separation.h"

namespace seam::regularity {

/// What one check inside a condition decides.
enum class CheckKind {
  kLau,             ///< 0 not in conv{P_{i+1} - P_i}: first = the differences, second = {0}
  kSplit,           ///< Definition 1.1: conv{Q_1..Q_r} vs conv{Q_{r+1}..Q_k}, r = r1
  kSplitU,          ///< (1.7): rows 1..r1 (all columns) vs rows r1+1..k1
  kSplitV,          ///< (1.8): columns 1..r2 vs columns r2+1..k2
  kConeSame,        ///< (1.9), half 1: 0 not in conv(A_r1 u B_r2) (no direction in pos(A) and in -pos(B))
  kConeOpposite,    ///< (1.9), half 2: 0 not in conv(A_r1 u -B_r2) (no direction in pos(A) and in pos(B))
  kNetLauSame,      ///< Theorem 3.7, half 1: 0 not in conv(Du u Dv)
  kNetLauOpposite,  ///< Theorem 3.7, half 2: 0 not in conv(Du u -Dv)
};

/// One disjointness check. Splits are 1-based as in the paper (r points on the first side).
struct Check {
  CheckKind kind = CheckKind::kLau;
  int r1 = 0;
  int r2 = 0;
  Separation separation;
  /// Cone checks that fail: the common direction (sum over the A / Du part of the witness weights times the
  /// generators), a vector lying in both cones; zero when 0 is already in the convex hull of one generator set.
  Vec3 coneDirection = Vec3::Zero();
};

/// The result of one condition: when it holds, `checks` is the certificate (one separating plane per check); when
/// it does not, `checks` ends with the first failing check, whose separation carries the witness.
struct ConditionResult {
  bool holds = false;
  std::vector<Check> checks;
  /// The failing check, or nullptr when the condition holds.
  [[nodiscard]] const Check* failure() const { return holds || checks.empty() ? nullptr : &checks.back(); }
};

/// W_k of (1.3): {k/2} for even k, {(k-1)/2, (k+1)/2} for odd k (k >= 2). These are the splits that uniform knots
/// need (Lemma 2.1 / Lemma 2.6).
std::vector<int> paperSplits(int k);
/// {1, ..., k-1}: the splits needed for arbitrary knots and for rational curves (see the docs for the proof).
std::vector<int> allSplits(int k);

/// Lau's condition for the rows of `points` (k >= 2 rows, 1..3 columns).
/// Errors: kInvalidInput (fewer than 2 points, non-finite), kUnsupported (more than 3 columns).
Result<ConditionResult> checkLau(const Matrix& points, const SeparationOptions& options = {});

/// Definition 1.1 for the rows Q_1..Q_k of `points` with the given splits (each in 1..k-1; use paperSplits(k)).
/// Errors: as checkLau, and a split outside 1..k-1.
Result<ConditionResult> checkCurveCondition(const Matrix& points, const std::vector<int>& splits,
                                            const SeparationOptions& options = {});

/// Theorem 3.7 for a k1 x k2 net (rows i*k2 + j = Q_ij, i along u; k1, k2 >= 2).
Result<ConditionResult> checkNetLau(const Matrix& net, int k1, int k2, const SeparationOptions& options = {});

/// Definition 1.2 ((1.7), (1.8), (1.9)) for a k1 x k2 net with the given splits in u and in v.
Result<ConditionResult> checkNetCondition(const Matrix& net, int k1, int k2, const std::vector<int>& splitsU,
                                          const std::vector<int>& splitsV, const SeparationOptions& options = {});

}  // namespace seam::regularity
