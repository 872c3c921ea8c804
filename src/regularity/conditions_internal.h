#pragma once
// Allocation-light versions of the conditions of conditions.h on embedded points (Vec3, extra coordinates zero),
// used by the whole-curve / whole-surface analysis.
#include <span>

#include "seam/regularity/conditions.h"

namespace seam::regularity::detail {

/// Lau's condition on Q_0..Q_{k-1}.
ConditionResult lauCondition(std::span<const Vec3> points, int dim, const SeparationOptions& options);
/// Definition 1.1 with 1-based splits.
ConditionResult curveCondition(std::span<const Vec3> points, std::span<const int> splits, int dim,
                               const SeparationOptions& options);
/// Theorem 3.7 on a k1 x k2 net (index i*k2 + j).
ConditionResult netLauCondition(std::span<const Vec3> net, int k1, int k2, int dim,
                                const SeparationOptions& options);
/// Definition 1.2 on a k1 x k2 net.
ConditionResult netCondition(std::span<const Vec3> net, int k1, int k2, std::span<const int> splitsU,
                             std::span<const int> splitsV, int dim, const SeparationOptions& options);

}  // namespace seam::regularity::detail
