#include "seam/continuity/overlap.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "continuity/model_check_internal.h"

namespace seam {

namespace {

/// Gauss-Newton steps of the projection onto a patch, and the parameter step (relative to the domain) that ends it.
constexpr int kProjectionIterations = 24;
constexpr double kProjectionStepRel = 1e-12;
/// Start points of the projection: a (kStartGrid x kStartGrid) grid over the domain, boundaries included.
constexpr int kStartGrid = 5;
/// A closest point within this fraction of the domain's width from a side counts as on the boundary (not interior):
/// the projection of a point beyond the patch stops on its boundary.
constexpr double kBoundaryRel = 1e-9;
/// Ridge of the projection's 2 x 2 normal equations, relative to their trace (a pole: S_u or S_v vanishes).
constexpr double kNormalRidgeRel = 1e-14;
/// Round-off allowed when minFraction x samples is turned into a count (1/8 of 64 is 8, not 9).
constexpr double kCountRoundOff = 1e-9;

/// What the overlap test needs of one patch.
struct PatchData {
  bool usable = false;  ///< a 3-D patch
  BoundingBox box;
  Vec3 centre = Vec3::Zero(), normal = Vec3::UnitZ();
  double thickness = 0.0;        ///< the control points lie within this distance of the mean plane
  std::vector<Vec3> samples;     ///< interior samples
  std::vector<Vec3> starts;      ///< the start grid's points
  std::vector<double> startU, startV;
  Interval du, dv;
};

PatchData prepare(const BSplineSurface& s, int n) {
  PatchData d;
  if (s.dim() != 3 || s.points().rows() == 0) return d;
  d.usable = true;
  d.box = controlBox(s);
  const Matrix& P = s.points();
  d.centre = P.colwise().mean().transpose();
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (Eigen::Index i = 0; i < P.rows(); ++i) {
    const Vec3 x = P.row(i).transpose() - d.centre;
    cov += x * x.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
  d.normal = eig.eigenvectors().col(0).normalized();  // the smallest spread: the mean plane's normal
  for (Eigen::Index i = 0; i < P.rows(); ++i)
    d.thickness = std::max(d.thickness, std::abs(d.normal.dot(P.row(i).transpose() - d.centre)));
  d.du = s.domainU();
  d.dv = s.domainV();
  Vec3 p, su, sv;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      s.pointAndFirstDerivatives(d.du.lo + (i + 0.5) / n * d.du.length(), d.dv.lo + (j + 0.5) / n * d.dv.length(), p,
                                 su, sv);
      d.samples.push_back(p);
    }
  for (int i = 0; i < kStartGrid; ++i)
    for (int j = 0; j < kStartGrid; ++j) {
      const double u = d.du.lo + d.du.length() * i / (kStartGrid - 1), v = d.dv.lo + d.dv.length() * j / (kStartGrid - 1);
      s.pointAndFirstDerivatives(u, v, p, su, sv);
      d.starts.push_back(p);
      d.startU.push_back(u);
      d.startV.push_back(v);
    }
  return d;
}

bool boxesWithin(const BoundingBox& a, const BoundingBox& b, double tol) {
  return (a.min.array() <= b.max.array() + tol).all() && (b.min.array() <= a.max.array() + tol).all();
}

/// The distance from p to patch s at an interior closest point, or nothing (not near, or nearest on the boundary).
std::optional<double> onInterior(const BSplineSurface& s, const PatchData& d, const Vec3& p, double tol) {
  if (detail::boxDistance(d.box, p) > tol) return std::nullopt;
  if (std::abs(d.normal.dot(p - d.centre)) > d.thickness + tol) return std::nullopt;
  size_t best = 0;
  for (size_t k = 1; k < d.starts.size(); ++k)
    if ((d.starts[k] - p).squaredNorm() < (d.starts[best] - p).squaredNorm()) best = k;
  double u = d.startU[best], v = d.startV[best];
  Vec3 q, su, sv;
  for (int it = 0; it < kProjectionIterations; ++it) {
    s.pointAndFirstDerivatives(u, v, q, su, sv);
    const Vec3 r = p - q;
    Eigen::Matrix2d J;
    J << su.dot(su), su.dot(sv), su.dot(sv), sv.dot(sv);
    J += Eigen::Matrix2d::Identity() * (kNormalRidgeRel * J.trace() + std::numeric_limits<double>::min());
    const Eigen::Vector2d step = J.ldlt().solve(Eigen::Vector2d(su.dot(r), sv.dot(r)));
    if (!step.allFinite()) break;
    const double nu = std::clamp(u + step.x(), d.du.lo, d.du.hi), nv = std::clamp(v + step.y(), d.dv.lo, d.dv.hi);
    const bool done = std::abs(nu - u) <= kProjectionStepRel * d.du.length() &&
                      std::abs(nv - v) <= kProjectionStepRel * d.dv.length();
    u = nu;
    v = nv;
    if (done) break;
  }
  s.pointAndFirstDerivatives(u, v, q, su, sv);
  const double dist = (p - q).norm();
  const bool interior = u - d.du.lo > kBoundaryRel * d.du.length() && d.du.hi - u > kBoundaryRel * d.du.length() &&
                        v - d.dv.lo > kBoundaryRel * d.dv.length() && d.dv.hi - v > kBoundaryRel * d.dv.length();
  if (!interior || !(dist <= tol)) return std::nullopt;
  return dist;
}

struct Direction {
  int hits = 0;
  double maxDistance = 0.0;
  Vec3 first = Vec3::Zero();
};

Direction samplesOn(const PatchData& from, const BSplineSurface& to, const PatchData& toData, double tol) {
  Direction r;
  for (const Vec3& p : from.samples)
    if (const std::optional<double> dist = onInterior(to, toData, p, tol)) {
      if (r.hits == 0) r.first = p;
      ++r.hits;
      r.maxDistance = std::max(r.maxDistance, *dist);
    }
  return r;
}

}  // namespace

std::vector<FaceOverlap> findOverlaps(const Model& model, double distanceTolerance, const OverlapOptions& options) {
  std::vector<FaceOverlap> out;
  const int n = std::max(options.samplesPerDirection, 1);
  const size_t count = model.patches.size();
  if (count < 2 || !(distanceTolerance >= 0.0)) return out;
  std::vector<PatchData> data(count);
  tbb::task_arena arena(options.threads > 0 ? options.threads : tbb::task_arena::automatic);
  arena.execute([&] {
    tbb::parallel_for(size_t{0}, count, [&](size_t p) { data[p] = prepare(model.patches[p].surface, n); });
  });
  // Candidate pairs: boxes within the tolerance (a sweep along x).
  std::vector<size_t> order;
  for (size_t p = 0; p < count; ++p)
    if (data[p].usable) order.push_back(p);
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return data[a].box.min.x() < data[b].box.min.x(); });
  std::vector<std::pair<size_t, size_t>> pairs;
  for (size_t i = 0; i < order.size(); ++i)
    for (size_t j = i + 1; j < order.size() && data[order[j]].box.min.x() <= data[order[i]].box.max.x() + distanceTolerance;
         ++j)
      if (boxesWithin(data[order[i]].box, data[order[j]].box, distanceTolerance))
        pairs.emplace_back(std::min(order[i], order[j]), std::max(order[i], order[j]));
  std::vector<std::optional<FaceOverlap>> found(pairs.size());
  const size_t needed = static_cast<size_t>(std::ceil(options.minFraction * n * n - kCountRoundOff));
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, pairs.size()), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t k = r.begin(); k != r.end(); ++k) {
        const auto [a, b] = pairs[k];
        const Direction ab = samplesOn(data[a], model.patches[b].surface, data[b], distanceTolerance);
        const Direction ba = samplesOn(data[b], model.patches[a].surface, data[a], distanceTolerance);
        const Direction& more = ab.hits >= ba.hits ? ab : ba;
        if (more.hits == 0 || static_cast<size_t>(more.hits) < std::max<size_t>(needed, 1)) continue;
        FaceOverlap o;
        o.a = static_cast<int>(a);
        o.b = static_cast<int>(b);
        o.fraction = static_cast<double>(more.hits) / (n * n);
        o.maxDistance = more.maxDistance;
        o.point = more.first;
        found[k] = o;
      }
    });
  });
  for (const auto& f : found)
    if (f) out.push_back(*f);
  std::sort(out.begin(), out.end(), [](const FaceOverlap& x, const FaceOverlap& y) {
    return std::pair(x.a, x.b) < std::pair(y.a, y.b);
  });
  return out;
}

}  // namespace seam
