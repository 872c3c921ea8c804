// The separation decision pipeline: quick candidate directions, Wolfe's minimum-norm point, GLPK, and the exact
// simplex; every answer is checked exactly before it is returned.
#include "seam/regularity/separation.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "separation_internal.h"

namespace seam::regularity {

namespace detail {

namespace {

/// A candidate normal that often separates: the difference of the centroids, or (against the origin) the sum of
/// the unit vectors of the set.
Vec3 quickDirection(std::span<const Vec3> first, std::span<const Vec3> second) {
  if (second.size() == 1 && second[0].isZero()) {
    Vec3 s = Vec3::Zero();
    for (const Vec3& a : first) {
      const double n = a.norm();
      if (n > 0.0) s += a / n;
    }
    return s;
  }
  Vec3 ca = Vec3::Zero();
  Vec3 cb = Vec3::Zero();
  for (const Vec3& a : first) ca += a;
  for (const Vec3& b : second) cb += b;
  return ca / static_cast<double>(first.size()) - cb / static_cast<double>(second.size());
}

}  // namespace

Separation decide(std::span<const Gen> first, std::span<const Gen> second, int dim,
                  const SeparationOptions& options) {
  // Scratch buffers of the double values (re-used: this is the hot path of every certificate).
  thread_local std::vector<Vec3> a;
  thread_local std::vector<Vec3> b;
  a.resize(first.size());
  b.resize(second.size());
  for (size_t i = 0; i < first.size(); ++i) a[i] = first[i].value();
  for (size_t j = 0; j < second.size(); ++j) b[j] = second[j].value();

  Separation out;
  if (options.useQuickDirection) {
    if (tryDirection(quickDirection(a, b), first, second, out.plane)) {
      out.separated = true;
      out.route = DecisionRoute::kQuickDirection;
      return out;
    }
  }
  if (options.useMinNormPoint) {
    const MinNormResult r = minNormPoint(a, b);
    if (r.ok) {
      if (!r.point.isZero() && tryDirection(r.point, first, second, out.plane)) {
        out.separated = true;
        out.route = DecisionRoute::kMinNormPoint;
        return out;
      }
      std::vector<int> sf;
      std::vector<int> ss;
      for (const auto& [i, j] : r.support) {
        if (std::find(sf.begin(), sf.end(), i) == sf.end()) sf.push_back(i);
        if (std::find(ss.begin(), ss.end(), j) == ss.end()) ss.push_back(j);
      }
      if (std::optional<ExactWitness> w = witnessOnSupport(first, second, sf, ss, dim)) {
        setWitness(*w, first, out);
        out.route = DecisionRoute::kMinNormPoint;
        return out;
      }
    }
  }
  if (options.useGlpk) {
    if (std::optional<Vec3> n = glpkMarginDirection(a, b, dim)) {
      if (tryDirection(*n, first, second, out.plane)) {
        out.separated = true;
        out.route = DecisionRoute::kGlpk;
        return out;
      }
    }
    if (auto support = glpkFeasibleSupport(a, b, dim)) {
      if (std::optional<ExactWitness> w = witnessOnSupport(first, second, support->first, support->second, dim)) {
        setWitness(*w, first, out);
        out.route = DecisionRoute::kGlpk;
        return out;
      }
    }
  }
  return exactSimplexDecide(first, second, dim);
}

}  // namespace detail

namespace {

/// Validates a point set and converts it to generators (plain points, q = 0).
Status toGens(const Matrix& m, const char* what, std::vector<detail::Gen>& out) {
  if (m.rows() == 0) return invalidInput(std::string(what) + " is empty");
  if (m.cols() < 1 || m.cols() > 3) {
    return {ErrorCode::kUnsupported,
            std::string(what) + " has " + std::to_string(m.cols()) + " coordinates (1, 2 or 3 are supported)"};
  }
  if (!m.allFinite()) return invalidInput(std::string(what) + " has a non-finite coordinate");
  out.resize(static_cast<size_t>(m.rows()));
  for (Eigen::Index i = 0; i < m.rows(); ++i) {
    out[i].p.setZero();
    out[i].q.setZero();
    for (Eigen::Index k = 0; k < m.cols(); ++k) out[i].p[k] = m(i, k);
  }
  return Status::ok();
}

}  // namespace

Result<Separation> separateHulls(const Matrix& first, const Matrix& second, const SeparationOptions& options) {
  std::vector<detail::Gen> f;
  std::vector<detail::Gen> s;
  if (Status st = toGens(first, "the first point set", f); !st) return st;
  if (Status st = toGens(second, "the second point set", s); !st) return st;
  if (first.cols() != second.cols()) {
    return invalidInput("the point sets have different dimensions (" + std::to_string(first.cols()) + " and " +
                        std::to_string(second.cols()) + ")");
  }
  return detail::decide(f, s, static_cast<int>(first.cols()), options);
}

Result<Separation> separateFromOrigin(const Matrix& heads, const Matrix& tails, const SeparationOptions& options) {
  std::vector<detail::Gen> f;
  std::vector<detail::Gen> t;
  if (Status st = toGens(heads, "the heads", f); !st) return st;
  if (Status st = toGens(tails, "the tails", t); !st) return st;
  if (heads.rows() != tails.rows() || heads.cols() != tails.cols()) {
    return invalidInput("heads and tails have different shapes");
  }
  for (size_t i = 0; i < f.size(); ++i) f[i].q = t[i].p;
  const detail::Gen origin;
  return detail::decide(f, std::span<const detail::Gen>(&origin, 1), static_cast<int>(heads.cols()), options);
}

bool isStrictlySeparating(const Hyperplane& plane, const Matrix& first, const Matrix& second) {
  std::vector<detail::Gen> f;
  std::vector<detail::Gen> s;
  if (!toGens(first, "first", f) || !toGens(second, "second", s)) return false;
  return detail::planeSeparates(plane.normal, plane.offset, f, s);
}

}  // namespace seam::regularity
