// Wolfe's minimum-norm-point algorithm (P. Wolfe, "Finding the nearest point in a polytope", Math. Programming 11,
// 1976) on the Minkowski difference conv(first) - conv(second), without forming it: the support point in direction
// -x is first[argmin x.a] - second[argmax x.b]. Doubles only; the caller checks every answer exactly.
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "separation_internal.h"

namespace seam::regularity::detail {

namespace {

/// Optimality: |x|^2 - x.z <= kWolfeOptimalityRel * max |z|^2 (z the support point).
constexpr double kWolfeOptimalityRel = 1e-13;
/// Corral weights at or below this count as zero (the point leaves the corral).
constexpr double kWolfeWeightTol = 1e-13;
/// Relative pivot size below which the affine hull of the corral is treated as degenerate (give up).
constexpr double kWolfeRankTol = 1e-12;
constexpr int kWolfeMaxIterations = 64;

struct Corral {
  Vec3 z[5];
  std::pair<int, int> id[5];
  double w[5] = {0, 0, 0, 0, 0};
  int size = 0;
};

/// Minimum-norm point of the affine hull of the corral: alpha (summing to 1). False if (numerically) affinely
/// dependent.
bool affineMinNorm(const Corral& c, double* alpha, Vec3& y, double scaleSq) {
  const int m = c.size;
  if (m == 1) {
    alpha[0] = 1.0;
    y = c.z[0];
    return true;
  }
  Eigen::Matrix<double, 3, Eigen::Dynamic, 0, 3, 4> d(3, m - 1);
  for (int k = 1; k < m; ++k) d.col(k - 1) = c.z[k] - c.z[0];
  const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 4, 4> g = d.transpose() * d;
  Eigen::LDLT<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 4, 4>> ldlt(g);
  const auto diag = ldlt.vectorD();
  if (diag.minCoeff() <= kWolfeRankTol * scaleSq) return false;
  const Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 4, 1> beta = ldlt.solve(-d.transpose() * c.z[0]);
  if (!beta.allFinite()) return false;
  alpha[0] = 1.0 - beta.sum();
  for (int k = 1; k < m; ++k) alpha[k] = beta[k - 1];
  y = c.z[0] + d * beta;
  return true;
}

}  // namespace

MinNormResult minNormPoint(std::span<const Vec3> first, std::span<const Vec3> second) {
  MinNormResult result;
  double scaleSq = 0.0;
  for (const Vec3& a : first) scaleSq = std::max(scaleSq, a.squaredNorm());
  for (const Vec3& b : second) scaleSq = std::max(scaleSq, b.squaredNorm());
  scaleSq *= 4.0;  // bound for |a - b|^2
  if (!(scaleSq > 0.0)) {
    // Every point is the origin: the hulls meet at 0.
    result.ok = true;
    result.support = {{0, 0}};
    result.weights = {1.0};
    return result;
  }
  auto support = [&](const Vec3& x) {
    int bi = 0;
    int bj = 0;
    double va = INFINITY;
    double vb = -INFINITY;
    for (size_t i = 0; i < first.size(); ++i) {
      const double v = x.dot(first[i]);
      if (v < va) {
        va = v;
        bi = static_cast<int>(i);
      }
    }
    for (size_t j = 0; j < second.size(); ++j) {
      const double v = x.dot(second[j]);
      if (v > vb) {
        vb = v;
        bj = static_cast<int>(j);
      }
    }
    return std::make_pair(bi, bj);
  };

  Corral c;
  c.z[0] = first[0] - second[0];
  c.id[0] = {0, 0};
  c.w[0] = 1.0;
  c.size = 1;
  Vec3 x = c.z[0];
  for (int iteration = 0; iteration < kWolfeMaxIterations; ++iteration) {
    const auto [i, j] = support(x);
    const Vec3 z = first[i] - second[j];
    if (x.squaredNorm() - x.dot(z) <= kWolfeOptimalityRel * scaleSq) break;
    bool present = false;
    for (int k = 0; k < c.size; ++k) present = present || c.id[k] == std::make_pair(i, j);
    if (present || c.size >= 4) break;
    c.z[c.size] = z;
    c.id[c.size] = {i, j};
    c.w[c.size] = 0.0;
    ++c.size;
    for (int minor = 0; minor < 8; ++minor) {
      double alpha[5];
      Vec3 y;
      if (!affineMinNorm(c, alpha, y, scaleSq)) return result;  // ok = false
      bool interior = true;
      for (int k = 0; k < c.size; ++k) interior = interior && alpha[k] > kWolfeWeightTol;
      if (interior) {
        for (int k = 0; k < c.size; ++k) c.w[k] = alpha[k];
        x = y;
        break;
      }
      double theta = 1.0;
      for (int k = 0; k < c.size; ++k) {
        if (alpha[k] <= kWolfeWeightTol && c.w[k] - alpha[k] > 0.0) {
          theta = std::min(theta, c.w[k] / (c.w[k] - alpha[k]));
        }
      }
      int kept = 0;
      double sum = 0.0;
      for (int k = 0; k < c.size; ++k) {
        const double w = theta * alpha[k] + (1.0 - theta) * c.w[k];
        if (w > kWolfeWeightTol) {
          c.z[kept] = c.z[k];
          c.id[kept] = c.id[k];
          c.w[kept] = w;
          sum += w;
          ++kept;
        }
      }
      if (kept == 0) return result;
      c.size = kept;
      x.setZero();
      for (int k = 0; k < c.size; ++k) {
        c.w[k] /= sum;
        x += c.w[k] * c.z[k];
      }
    }
  }
  result.ok = true;
  result.point = x;
  for (int k = 0; k < c.size; ++k) {
    result.support.push_back(c.id[k]);
    result.weights.push_back(c.w[k]);
  }
  return result;
}

}  // namespace seam::regularity::detail
