// Models shared by the benchmark programs (one definition, so that bench/check_bench.cpp and
// bench/occt_side_by_side.cpp time the same surfaces).
#pragma once

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "seam/model/model.h"
#include "seam/spline/bezier.h"
#include "seam/spline/bspline_surface.h"

namespace seam::bench {

/// A bicubic B-spline surface with 50 x 50 jittered control points (weights in [0.5, 2] when rational), seed 42:
/// the evaluation benchmarks' surface.
inline BSplineSurface jitteredSurface50(bool rational) {
  constexpr int n = 50;
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> jitter(-0.3, 0.3), weight(0.5, 2.0);
  Matrix P(n * n, 3);
  VecX W(rational ? n * n : 0);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      P.row(i * n + j) << i + jitter(rng), j + jitter(rng), jitter(rng);
      if (rational) W[i * n + j] = weight(rng);
    }
  return BSplineSurface(3, 3, KnotVector::clampedUniform(3, n), KnotVector::clampedUniform(3, n), n, n,
                        std::move(P), std::move(W));
}

/// Every kPerturbEvery-th patch of gridPatches gets one perturbed seam: even ones a 1e-4 gap (a lifted boundary
/// row), odd ones a 2e-3 kink (the row next to the boundary moved along z).
inline constexpr int kPerturbEvery = 97;

/// The n x n bicubic Bezier patches cut (exact knot insertion) from one C2 bicubic B-spline surface over
/// [0, 1]^2, some perturbed (kPerturbEvery), with their span indices and parameter boxes; patch k is named "P<k>".
inline std::vector<BezierPatchPiece> gridPieces(int n) {
  const int np = n + 3;
  Matrix pts(np * np, 3);
  for (int i = 0; i < np; ++i)
    for (int j = 0; j < np; ++j)
      pts.row(i * np + j) = Eigen::RowVector3d(double(i) / n, double(j) / n,
                                               0.05 * std::sin(6.0 * i / n) * std::cos(5.0 * j / n + 0.3));
  std::vector<double> knots(static_cast<size_t>(np + 4));
  for (int k = 0; k < np + 4; ++k) knots[static_cast<size_t>(k)] = std::clamp(double(k - 3), 0.0, double(n)) / n;
  const BSplineSurface s = BSplineSurface::create(3, 3, knots, knots, np, np, pts).value();
  std::vector<BezierPatchPiece> pieces = s.bezierPatches();
  for (size_t index = 0; index < pieces.size(); ++index) {
    BezierPatchPiece& piece = pieces[index];
    const int k = static_cast<int>(index);
    if (k % kPerturbEvery == kPerturbEvery - 1 && piece.spanU > 0) {
      Matrix q = piece.patch.toBSpline(piece.u, piece.v).points();  // points[i * 4 + j], i along u
      const bool gap = (k / kPerturbEvery) % 2 == 0;
      for (int j = 0; j < 4; ++j) q(gap ? j : 4 + j, 2) += gap ? 1e-4 : 2e-3;  // row i = 0 (U0 edge) or i = 1
      piece.patch = BezierPatch(3, 3, std::move(q));
    }
  }
  return pieces;
}

/// gridPieces as a model of Bezier patches, each over its own parameter box.
inline Model gridModel(int n) {
  Model m;
  int index = 0;
  for (const BezierPatchPiece& piece : gridPieces(n))
    m.patches.push_back({"P" + std::to_string(index++), PatchKind::kBezier, piece.patch.toBSpline(piece.u, piece.v)});
  return m;
}

// ---- the evaluation benchmarks' parameters and seam's two timing loops (bench/eval_bench.cpp,
// bench/occt_side_by_side.cpp) ------------------------------------------------------------------------------------

inline constexpr int kEvalGrid = 256;                 ///< grid benchmarks: kEvalGrid x kEvalGrid points
inline constexpr int kEvalRandomPoints = 1'000'000;   ///< random-parameter benchmarks

/// n parameters evenly spaced over [0, 1], both ends included.
inline std::vector<double> evenParameters(int n) {
  std::vector<double> g(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) g[static_cast<size_t>(i)] = static_cast<double>(i) / (n - 1);
  return g;
}

/// kEvalRandomPoints parameter pairs uniform in [0, 1]^2 (seed 7).
inline std::pair<std::vector<double>, std::vector<double>> randomParameterPairs() {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  std::vector<double> us(kEvalRandomPoints), vs(kEvalRandomPoints);
  for (int i = 0; i < kEvalRandomPoints; ++i) {
    us[static_cast<size_t>(i)] = u01(rng);
    vs[static_cast<size_t>(i)] = u01(rng);
  }
  return {us, vs};
}

/// Times seam's point + first derivatives at the randomParameterPairs (allocation-free path).
inline void timeRandomEvaluation(benchmark::State& state, const BSplineSurface& s) {
  const auto [us, vs] = randomParameterPairs();
  for (auto _ : state) {
    double acc = 0.0;
    for (size_t i = 0; i < us.size(); ++i) {
      Vec3 p, du, dv;
      s.pointAndFirstDerivatives(us[i], vs[i], p, du, dv);
      acc += p[0] + du[1] + dv[2];
    }
    benchmark::DoNotOptimize(acc);
  }
  state.SetItemsProcessed(state.iterations() * kEvalRandomPoints);
}

/// Times seam's GridEvaluator (point + first derivatives) on the kEvalGrid x kEvalGrid grid.
inline void timeGridEvaluation(benchmark::State& state, const BSplineSurface& s) {
  const std::vector<double> g = evenParameters(kEvalGrid);
  const GridEvaluator eval(s, g, g);
  Matrix P, Du, Dv;
  for (auto _ : state) {
    eval.evaluate(&P, &Du, &Dv);
    benchmark::DoNotOptimize(P.data());
    benchmark::DoNotOptimize(Du.data());
    benchmark::DoNotOptimize(Dv.data());
  }
  state.SetItemsProcessed(state.iterations() * kEvalGrid * kEvalGrid);
}

}  // namespace seam::bench
