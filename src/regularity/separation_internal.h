#pragma once
// Private machinery of the hull-separation decisions (separation.cpp, exact.cpp, min_norm.cpp, glpk_stage.cpp).
#include <gmpxx.h>

#include <optional>
#include <span>
#include <utility>
#include <vector>

#include "seam/core/types.h"
#include "seam/regularity/separation.h"

namespace seam::regularity::detail {

/// A point given as the difference p - q of two input points (q = 0 for a plain point). Differences are never
/// rounded in the exact stages: they are formed in rational arithmetic from p and q.
struct Gen {
  Vec3 p = Vec3::Zero();
  Vec3 q = Vec3::Zero();
  [[nodiscard]] Vec3 value() const { return p - q; }
};

/// Relative error bound of the double evaluation of n . (p - q) - b against the sum of the magnitudes
/// sum_k |n_k| (|p_k| + |q_k|) + |b|: gamma_6 = 6u/(1-6u) ~ 6.7e-16 (u = 2^-53), rounded up with margin for the
/// rounding of the magnitude itself. Signs of values beyond this bound are certain.
inline constexpr double kFilterRelError = 1e-15;
/// Below this magnitude sum the filter is not trusted (products could be subnormal): GMP decides.
inline constexpr double kFilterMinMagnitude = 1e-250;

/// Exact sign (-1, 0, 1) of n . (g.p - g.q) - b: a filtered double evaluation, GMP rationals when it cannot decide.
int exactSign(const Vec3& n, const Gen& g, double b);

/// Exact check: n . x > b for every x of `first` and n . y < b for every y of `second`.
bool planeSeparates(const Vec3& n, double b, std::span<const Gen> first, std::span<const Gen> second);

/// Turns a candidate normal into a verified plane: normalises n (|n|_inf = 1), puts the offset midway between
/// min over `first` and max over `second` of n . x, and checks exactly. False when the candidate does not separate.
bool tryDirection(const Vec3& n, std::span<const Gen> first, std::span<const Gen> second, Hyperplane& plane);

/// Exact rational witness: sum_i wf_i x_i = sum_j ws_j y_j with wf, ws >= 0, each summing to 1.
struct ExactWitness {
  std::vector<mpq_class> weightsFirst;
  std::vector<mpq_class> weightsSecond;
};

/// Tries to find exact non-negative weights supported on the given indices (a linear solve in GMP rationals with
/// the non-pivot unknowns set to zero). nullopt when that solve has no non-negative solution.
std::optional<ExactWitness> witnessOnSupport(std::span<const Gen> first, std::span<const Gen> second,
                                             const std::vector<int>& supportFirst,
                                             const std::vector<int>& supportSecond, int dim);

/// Fills the witness fields of `out` (not separated) from exact weights.
void setWitness(const ExactWitness& w, std::span<const Gen> first, Separation& out);

/// The exact phase-1 simplex (Bland's rule, GMP rationals) on the feasibility problem
/// { wf, ws >= 0 : sum wf = sum ws = 1, sum wf x - sum ws y = 0 }: feasible -> witness, infeasible -> a separating
/// plane from the Farkas certificate. Always decides.
Separation exactSimplexDecide(std::span<const Gen> first, std::span<const Gen> second, int dim);

/// Wolfe's minimum-norm-point algorithm on conv(first) - conv(second), in doubles.
struct MinNormResult {
  bool ok = false;  ///< false: numerical trouble (near-singular corral); the caller falls back to the LP stages
  Vec3 point = Vec3::Zero();
  std::vector<std::pair<int, int>> support;  ///< Minkowski points first[i] - second[j] of the final corral
  std::vector<double> weights;
};
MinNormResult minNormPoint(std::span<const Vec3> first, std::span<const Vec3> second);

/// GLPK stage: maximise the margin delta of n . x - b >= delta, b - n . y >= delta, |n|_inf <= 1, delta <= 1, on
/// centred and scaled data. Returns n when delta > 0.
std::optional<Vec3> glpkMarginDirection(std::span<const Vec3> first, std::span<const Vec3> second, int dim);
/// GLPK stage: the feasibility LP of exactSimplexDecide in doubles; returns the basic columns (support) when GLPK
/// finds it feasible.
std::optional<std::pair<std::vector<int>, std::vector<int>>> glpkFeasibleSupport(std::span<const Vec3> first,
                                                                                 std::span<const Vec3> second,
                                                                                 int dim);

/// The whole pipeline (quick direction, Wolfe, GLPK, exact simplex), on generator sets. `dim` (1..3) is the number
/// of meaningful coordinates (the others are zero in every point).
Separation decide(std::span<const Gen> first, std::span<const Gen> second, int dim,
                  const SeparationOptions& options);

}  // namespace seam::regularity::detail
