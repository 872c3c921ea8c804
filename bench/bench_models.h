// Models shared by the benchmark programs (one definition, so that bench/check_bench.cpp and
// bench/occt_side_by_side.cpp time the same surfaces).
#pragma once

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
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

}  // namespace seam::bench
