// Lau's condition, Definition 1.1, Theorem 3.7 and Definition 1.2 as sequences of exact separation decisions.
#include "seam/regularity/conditions.h"

#include <string>

#include "conditions_internal.h"
#include "separation_internal.h"

namespace seam::regularity {

namespace detail {

namespace {

const Gen kOrigin{};

/// Runs one check; appends it; returns whether it separated.
bool runCheck(ConditionResult& result, CheckKind kind, int r1, int r2, std::span<const Gen> first,
              std::span<const Gen> second, int dim, const SeparationOptions& options, int coneSplit = -1) {
  Check c;
  c.kind = kind;
  c.r1 = r1;
  c.r2 = r2;
  c.separation = decide(first, second, dim, options);
  if (!c.separation.separated && coneSplit >= 0) {
    // The first `coneSplit` generators are the A (or Du) part: their weighted sum lies in both cones.
    for (int g = 0; g < coneSplit && g < static_cast<int>(c.separation.weightsFirst.size()); ++g) {
      c.coneDirection += c.separation.weightsFirst[g] * first[g].value();
    }
  }
  const bool ok = c.separation.separated;
  result.checks.push_back(std::move(c));
  return ok;
}

}  // namespace

ConditionResult lauCondition(std::span<const Vec3> points, int dim, const SeparationOptions& options) {
  thread_local std::vector<Gen> gens;
  gens.clear();
  for (size_t i = 0; i + 1 < points.size(); ++i) gens.push_back({points[i + 1], points[i]});
  ConditionResult result;
  result.checks.reserve(1);
  result.holds = runCheck(result, CheckKind::kLau, 0, 0, gens, std::span<const Gen>(&kOrigin, 1), dim, options);
  return result;
}

ConditionResult curveCondition(std::span<const Vec3> points, std::span<const int> splits, int dim,
                               const SeparationOptions& options) {
  thread_local std::vector<Gen> gens;
  gens.clear();
  for (const Vec3& p : points) gens.push_back({p, Vec3::Zero()});
  ConditionResult result;
  result.checks.reserve(splits.size());
  result.holds = true;
  const std::span<const Gen> all(gens);
  for (int r : splits) {
    if (!runCheck(result, CheckKind::kSplit, r, 0, all.subspan(0, r), all.subspan(r), dim, options)) {
      result.holds = false;
      return result;
    }
  }
  return result;
}

ConditionResult netLauCondition(std::span<const Vec3> net, int k1, int k2, int dim,
                                const SeparationOptions& options) {
  auto at = [&](int i, int j) -> const Vec3& { return net[static_cast<size_t>(i) * k2 + j]; };
  thread_local std::vector<Gen> gens;
  ConditionResult result;
  result.checks.reserve(2);
  result.holds = true;
  for (int half = 0; half < 2; ++half) {
    gens.clear();
    for (int i = 0; i + 1 < k1; ++i) {
      for (int j = 0; j < k2; ++j) gens.push_back({at(i + 1, j), at(i, j)});
    }
    const int du = static_cast<int>(gens.size());
    for (int i = 0; i < k1; ++i) {
      for (int j = 0; j + 1 < k2; ++j) {
        gens.push_back(half == 0 ? Gen{at(i, j + 1), at(i, j)} : Gen{at(i, j), at(i, j + 1)});
      }
    }
    const CheckKind kind = half == 0 ? CheckKind::kNetLauSame : CheckKind::kNetLauOpposite;
    if (!runCheck(result, kind, 0, 0, gens, std::span<const Gen>(&kOrigin, 1), dim, options, du)) {
      result.holds = false;
      return result;
    }
  }
  return result;
}

ConditionResult netCondition(std::span<const Vec3> net, int k1, int k2, std::span<const int> splitsU,
                             std::span<const int> splitsV, int dim, const SeparationOptions& options) {
  auto at = [&](int i, int j) -> const Vec3& { return net[static_cast<size_t>(i) * k2 + j]; };
  thread_local std::vector<Gen> first;
  thread_local std::vector<Gen> second;
  ConditionResult result;
  result.holds = true;
  // (1.7): rows i < r1 against rows i >= r1 (0-based), all columns.
  for (int r1 : splitsU) {
    first.clear();
    second.clear();
    for (int i = 0; i < k1; ++i) {
      for (int j = 0; j < k2; ++j) (i < r1 ? first : second).push_back({at(i, j), Vec3::Zero()});
    }
    if (!runCheck(result, CheckKind::kSplitU, r1, 0, first, second, dim, options)) {
      result.holds = false;
      return result;
    }
  }
  // (1.8): columns j < r2 against columns j >= r2.
  for (int r2 : splitsV) {
    first.clear();
    second.clear();
    for (int i = 0; i < k1; ++i) {
      for (int j = 0; j < k2; ++j) (j < r2 ? first : second).push_back({at(i, j), Vec3::Zero()});
    }
    if (!runCheck(result, CheckKind::kSplitV, 0, r2, first, second, dim, options)) {
      result.holds = false;
      return result;
    }
  }
  // (1.9): A = {Q_lj - Q_ij : i < r1 <= l}, B = {Q_il - Q_ij : j < r2 <= l}; the double cones meet only at 0 iff
  // 0 is outside conv(A u B) and conv(A u -B) (given (1.7), (1.8)).
  for (int r1 : splitsU) {
    for (int r2 : splitsV) {
      for (int half = 0; half < 2; ++half) {
        first.clear();
        for (int i = 0; i < r1; ++i) {
          for (int l = r1; l < k1; ++l) {
            for (int j = 0; j < k2; ++j) first.push_back({at(l, j), at(i, j)});
          }
        }
        const int na = static_cast<int>(first.size());
        for (int j = 0; j < r2; ++j) {
          for (int l = r2; l < k2; ++l) {
            for (int i = 0; i < k1; ++i) {
              first.push_back(half == 0 ? Gen{at(i, l), at(i, j)} : Gen{at(i, j), at(i, l)});
            }
          }
        }
        const CheckKind kind = half == 0 ? CheckKind::kConeSame : CheckKind::kConeOpposite;
        if (!runCheck(result, kind, r1, r2, first, std::span<const Gen>(&kOrigin, 1), dim, options, na)) {
          result.holds = false;
          return result;
        }
      }
    }
  }
  return result;
}

}  // namespace detail

std::vector<int> paperSplits(int k) {
  if (k < 2) return {};
  if (k % 2 == 0) return {k / 2};
  return {(k - 1) / 2, (k + 1) / 2};
}

std::vector<int> allSplits(int k) {
  std::vector<int> r;
  for (int i = 1; i < k; ++i) r.push_back(i);
  return r;
}

namespace {

Status toPoints(const Matrix& m, const std::string& what, int minRows, std::vector<Vec3>& out) {
  if (m.rows() < minRows) {
    return invalidInput(what + " has " + std::to_string(m.rows()) + " points, at least " +
                        std::to_string(minRows) + " are needed");
  }
  if (m.cols() < 1 || m.cols() > 3) {
    return {ErrorCode::kUnsupported,
            what + " has " + std::to_string(m.cols()) + " coordinates (1, 2 or 3 are supported)"};
  }
  if (!m.allFinite()) return invalidInput(what + " has a non-finite coordinate");
  out.assign(static_cast<size_t>(m.rows()), Vec3::Zero());
  for (Eigen::Index i = 0; i < m.rows(); ++i) {
    for (Eigen::Index k = 0; k < m.cols(); ++k) out[i][k] = m(i, k);
  }
  return Status::ok();
}

Status checkSplits(const std::vector<int>& splits, int k, const std::string& what) {
  for (int r : splits) {
    if (r < 1 || r > k - 1) {
      return invalidInput(what + " split r = " + std::to_string(r) + " is outside 1.." + std::to_string(k - 1));
    }
  }
  return Status::ok();
}

Status checkNetShape(const Matrix& net, int k1, int k2) {
  if (k1 < 2 || k2 < 2) return invalidInput("the net must be at least 2 x 2");
  if (net.rows() != static_cast<Eigen::Index>(k1) * k2) {
    return invalidInput("the net has " + std::to_string(net.rows()) + " points, expected " + std::to_string(k1) +
                        " x " + std::to_string(k2));
  }
  return Status::ok();
}

}  // namespace

Result<ConditionResult> checkLau(const Matrix& points, const SeparationOptions& options) {
  std::vector<Vec3> p;
  if (Status s = toPoints(points, "the control polygon", 2, p); !s) return s;
  return detail::lauCondition(p, static_cast<int>(points.cols()), options);
}

Result<ConditionResult> checkCurveCondition(const Matrix& points, const std::vector<int>& splits,
                                            const SeparationOptions& options) {
  std::vector<Vec3> p;
  if (Status s = toPoints(points, "the control polygon", 2, p); !s) return s;
  if (Status s = checkSplits(splits, static_cast<int>(p.size()), "Definition 1.1:"); !s) return s;
  return detail::curveCondition(p, splits, static_cast<int>(points.cols()), options);
}

Result<ConditionResult> checkNetLau(const Matrix& net, int k1, int k2, const SeparationOptions& options) {
  if (Status s = checkNetShape(net, k1, k2); !s) return s;
  std::vector<Vec3> p;
  if (Status s = toPoints(net, "the net", 4, p); !s) return s;
  return detail::netLauCondition(p, k1, k2, static_cast<int>(net.cols()), options);
}

Result<ConditionResult> checkNetCondition(const Matrix& net, int k1, int k2, const std::vector<int>& splitsU,
                                          const std::vector<int>& splitsV, const SeparationOptions& options) {
  if (Status s = checkNetShape(net, k1, k2); !s) return s;
  std::vector<Vec3> p;
  if (Status s = toPoints(net, "the net", 4, p); !s) return s;
  if (Status s = checkSplits(splitsU, k1, "(1.7)"); !s) return s;
  if (Status s = checkSplits(splitsV, k2, "(1.8)"); !s) return s;
  return detail::netCondition(p, k1, k2, splitsU, splitsV, static_cast<int>(net.cols()), options);
}

}  // namespace seam::regularity
