// Per-segment / per-sub-net regularity verdicts for whole curves and surfaces (Dyn-Levin-Yad-Shalom), Theorems
// 2.7 / 3.5, and the defect search as an independent check.
#include "seam/regularity/regularity.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>

#include "conditions_internal.h"
#include "seam/core/tolerances.h"

namespace seam::regularity {

std::string_view verdictName(Verdict v) {
  switch (v) {
    case Verdict::kCertified: return "certified";
    case Verdict::kFails: return "fails";
    case Verdict::kNotApplicable: return "not-applicable";
  }
  return "?";
}

std::string_view conditionName(Condition c) {
  switch (c) {
    case Condition::kNone: return "none";
    case Condition::kLau: return "lau";
    case Condition::kRegularity: return "regularity";
  }
  return "?";
}

std::string_view checkKindName(CheckKind k) {
  switch (k) {
    case CheckKind::kLau: return "lau";
    case CheckKind::kSplit: return "split";
    case CheckKind::kSplitU: return "(1.7)";
    case CheckKind::kSplitV: return "(1.8)";
    case CheckKind::kConeSame: return "(1.9)+";
    case CheckKind::kConeOpposite: return "(1.9)-";
    case CheckKind::kNetLauSame: return "(3.25)+";
    case CheckKind::kNetLauOpposite: return "(3.25)-";
  }
  return "?";
}

bool uniformKnots(const std::vector<double>& knots, int first, int last, double relTol) {
  if (first < 0 || last >= static_cast<int>(knots.size()) || last <= first) return false;
  const double h = (knots[last] - knots[first]) / (last - first);
  if (!(h > 0.0)) return false;
  for (int i = first; i < last; ++i) {
    if (std::abs(knots[i + 1] - knots[i] - h) > relTol * h) return false;
  }
  return true;
}

bool CurveRegularity::anyFails() const {
  for (const SegmentVerdict& s : segments) {
    if (s.verdict == Verdict::kFails) return true;
  }
  return search && search->defectFound();
}

bool SurfaceRegularity::anyFails() const {
  for (const SubnetVerdict& s : subnets) {
    if (s.verdict == Verdict::kFails) return true;
  }
  return search && search->defectFound();
}

namespace {

Status checkOptions(const RegularityOptions& o) {
  if (o.maxEll < 0) return invalidInput("maxEll must be >= 0, got " + std::to_string(o.maxEll));
  if (!(o.uniformKnotRelTol >= 0.0)) return invalidInput("the uniform-knot tolerance must be >= 0");
  return Status::ok();
}

/// Outcome of one window (a segment, or a window of Theorem 2.7/3.5).
struct WindowOutcome {
  Verdict verdict = Verdict::kNotApplicable;
  Condition condition = Condition::kNone;
  std::vector<int> splits, splits2;
  ConditionResult lau;
  ConditionResult result;
};

WindowOutcome curveWindow(std::span<const Vec3> pts, bool uniform, int dim, const RegularityOptions& o) {
  WindowOutcome w;
  w.lau = detail::lauCondition(pts, dim, o.separation);
  if (w.lau.holds) {
    w.verdict = Verdict::kCertified;
    w.condition = Condition::kLau;
    w.result = w.lau;
    return w;
  }
  const int k = static_cast<int>(pts.size());
  if (uniform) {
    w.splits = paperSplits(k);
  } else if (o.allSplitsForNonUniform) {
    w.splits = allSplits(k);
  } else {
    w.result = w.lau;
    return w;
  }
  w.result = detail::curveCondition(pts, w.splits, dim, o.separation);
  w.condition = Condition::kRegularity;
  w.verdict = w.result.holds ? Verdict::kCertified : (uniform ? Verdict::kFails : Verdict::kNotApplicable);
  return w;
}

WindowOutcome netWindow(std::span<const Vec3> net, int k1, int k2, bool uniformU, bool uniformV, int dim,
                        const RegularityOptions& o) {
  WindowOutcome w;
  w.lau = detail::netLauCondition(net, k1, k2, dim, o.separation);
  if (w.lau.holds) {
    w.verdict = Verdict::kCertified;
    w.condition = Condition::kLau;
    w.result = w.lau;
    return w;
  }
  if ((!uniformU || !uniformV) && !o.allSplitsForNonUniform) {
    w.result = w.lau;
    return w;
  }
  w.splits = uniformU ? paperSplits(k1) : allSplits(k1);
  w.splits2 = uniformV ? paperSplits(k2) : allSplits(k2);
  w.result = detail::netCondition(net, k1, k2, w.splits, w.splits2, dim, o.separation);
  w.condition = Condition::kRegularity;
  w.verdict = w.result.holds ? Verdict::kCertified
                             : (uniformU && uniformV ? Verdict::kFails : Verdict::kNotApplicable);
  return w;
}

std::vector<Vec3> embedded(const Matrix& points) {
  std::vector<Vec3> out(static_cast<size_t>(points.rows()), Vec3::Zero());
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    for (Eigen::Index k = 0; k < points.cols(); ++k) out[i][k] = points(i, k);
  }
  return out;
}

}  // namespace

Result<CurveRegularity> analyzeCurve(const BSplineCurve& curve, const RegularityOptions& options) {
  if (Status s = checkOptions(options); !s) return s;
  if (curve.dim() < 1 || curve.dim() > 3) {
    return Status(ErrorCode::kUnsupported,
                  "the curve has " + std::to_string(curve.dim()) + " coordinates (1, 2 or 3 are supported)");
  }
  if (curve.degree() < 1) return Status(ErrorCode::kUnsupported, "regularity needs degree >= 1 (order >= 2)");
  if (!curve.points().allFinite()) return invalidInput("the curve has a non-finite control point");

  CurveRegularity out;
  const int p = curve.degree();
  const int k = p + 1;
  const int n = curve.numPoints();
  const int dim = curve.dim();
  out.order = k;
  out.dim = dim;
  out.rational = curve.isRational();
  const std::vector<Vec3> pts = embedded(curve.points());
  const std::vector<double>& t = curve.knots().values();
  const double emptyTol = kKnotRelTol * (t.back() - t.front());

  bool allCertified = true;
  for (int j = p; j < n; ++j) {
    if (options.progress && (j - p) % 4096 == 4095) options.progress("certificates", j - p, n - p);
    if (!(t[j + 1] - t[j] > emptyTol)) continue;
    SegmentVerdict seg;
    seg.index = j - p;
    seg.interval = {t[j], t[j + 1]};
    seg.uniform = !out.rational && uniformKnots(t, j - p, j + p + 1, options.uniformKnotRelTol);
    WindowOutcome w = curveWindow(std::span<const Vec3>(pts).subspan(seg.index, k), seg.uniform, dim, options);
    seg.verdict = w.verdict;
    seg.condition = w.condition;
    seg.splits = std::move(w.splits);
    seg.result = std::move(w.result);
    allCertified = allCertified && seg.verdict == Verdict::kCertified;
    out.segments.push_back(std::move(seg));
  }

  if (allCertified && !out.segments.empty()) {
    out.ellCertified = 0;
    const int maxEll = std::min(options.maxEll, n - k);
    for (int l = 1; l <= maxEll; ++l) {
      const int window = k + l;
      bool ok = true;
      for (int i = 0; i + window <= n && ok; ++i) {
        if (options.progress && i % 4096 == 4095) options.progress("theorem 2.7 windows", i, n - window + 1);
        const bool uniform = !out.rational && uniformKnots(t, i, i + window + p, options.uniformKnotRelTol);
        WindowOutcome w = curveWindow(std::span<const Vec3>(pts).subspan(i, window), uniform, dim, options);
        if (w.verdict != Verdict::kCertified) {
          ok = false;
          EllLimit limit;
          limit.order1 = window;
          limit.first1 = i;
          limit.lau = std::move(w.lau);
          if (w.condition == Condition::kRegularity) limit.regularity = std::move(w.result);
          out.ellLimit = std::move(limit);
        }
      }
      if (!ok) break;
      out.ellCertified = l;
    }
  }

  if (options.runSearch) {
    SearchOptions so = options.search;
    if (!so.progress) so.progress = options.progress;
    Result<CurveSearchResult> search = searchCurveDefects(curve, so);
    if (!search) return search.status();
    out.search = std::move(search).value();
    for (SegmentVerdict& seg : out.segments) {
      auto inside = [&](double x) { return x >= seg.interval.lo && x <= seg.interval.hi; };
      for (const CurveCriticalPoint& c : out.search->criticalPoints) seg.defectNearby |= inside(c.t);
      for (const CurveSelfIntersection& c : out.search->selfIntersections) {
        seg.defectNearby |= inside(c.t1) || inside(c.t2);
      }
    }
  }
  return out;
}

Result<SurfaceRegularity> analyzeSurface(const BSplineSurface& surface, const RegularityOptions& options) {
  if (Status s = checkOptions(options); !s) return s;
  if (surface.dim() < 2 || surface.dim() > 3) {
    return Status(ErrorCode::kUnsupported,
                  "the surface has " + std::to_string(surface.dim()) + " coordinates (2 or 3 are supported)");
  }
  if (surface.degreeU() < 1 || surface.degreeV() < 1) {
    return Status(ErrorCode::kUnsupported, "regularity needs degrees >= 1 in both directions");
  }
  if (!surface.points().allFinite()) return invalidInput("the surface has a non-finite control point");

  SurfaceRegularity out;
  const int pu = surface.degreeU();
  const int pv = surface.degreeV();
  const int k1 = pu + 1;
  const int k2 = pv + 1;
  const int nu = surface.numU();
  const int nv = surface.numV();
  const int dim = surface.dim();
  out.orderU = k1;
  out.orderV = k2;
  out.dim = dim;
  out.rational = surface.isRational();
  const std::vector<Vec3> pts = embedded(surface.points());
  const std::vector<double>& tu = surface.knotsU().values();
  const std::vector<double>& tv = surface.knotsV().values();
  const double emptyU = kKnotRelTol * (tu.back() - tu.front());
  const double emptyV = kKnotRelTol * (tv.back() - tv.front());
  std::vector<Vec3> net;
  auto gather = [&](int i0, int j0, int m1, int m2) {
    net.resize(static_cast<size_t>(m1) * m2);
    for (int a = 0; a < m1; ++a) {
      for (int b = 0; b < m2; ++b) net[static_cast<size_t>(a) * m2 + b] = pts[static_cast<size_t>(i0 + a) * nv + j0 + b];
    }
  };

  bool allCertified = true;
  for (int ju = pu; ju < nu; ++ju) {
    if (options.progress) options.progress("certificates", static_cast<long>(ju - pu) * (nv - pv), static_cast<long>(nu - pu) * (nv - pv));
    if (!(tu[ju + 1] - tu[ju] > emptyU)) continue;
    for (int jv = pv; jv < nv; ++jv) {
      if (!(tv[jv + 1] - tv[jv] > emptyV)) continue;
      SubnetVerdict sub;
      sub.indexU = ju - pu;
      sub.indexV = jv - pv;
      sub.u = {tu[ju], tu[ju + 1]};
      sub.v = {tv[jv], tv[jv + 1]};
      sub.uniformU = !out.rational && uniformKnots(tu, ju - pu, ju + pu + 1, options.uniformKnotRelTol);
      sub.uniformV = !out.rational && uniformKnots(tv, jv - pv, jv + pv + 1, options.uniformKnotRelTol);
      if (!out.rational) {
        gather(sub.indexU, sub.indexV, k1, k2);
        WindowOutcome w = netWindow(net, k1, k2, sub.uniformU, sub.uniformV, dim, options);
        sub.verdict = w.verdict;
        sub.condition = w.condition;
        sub.splitsU = std::move(w.splits);
        sub.splitsV = std::move(w.splits2);
        sub.result = std::move(w.result);
      }
      allCertified = allCertified && sub.verdict == Verdict::kCertified;
      out.subnets.push_back(std::move(sub));
    }
  }

  if (allCertified && !out.subnets.empty()) {
    int done1 = 0;
    int done2 = 0;
    bool ok = true;
    for (int l = 1; l <= options.maxEll && ok; ++l) {
      const int l1 = std::min(l, nu - k1);
      const int l2 = std::min(l, nv - k2);
      if (l1 == done1 && l2 == done2) break;
      for (int a = 0; a <= l1 && ok; ++a) {
        for (int b = 0; b <= l2 && ok; ++b) {
          if (a <= done1 && b <= done2) continue;
          const int m1 = k1 + a;
          const int m2 = k2 + b;
          for (int i = 0; i + m1 <= nu && ok; ++i) {
            if (options.progress) options.progress("theorem 3.5 windows", i, nu - m1 + 1);
            for (int j = 0; j + m2 <= nv && ok; ++j) {
              gather(i, j, m1, m2);
              const bool uu = uniformKnots(tu, i, i + m1 + pu, options.uniformKnotRelTol);
              const bool uv = uniformKnots(tv, j, j + m2 + pv, options.uniformKnotRelTol);
              WindowOutcome w = netWindow(net, m1, m2, uu, uv, dim, options);
              if (w.verdict != Verdict::kCertified) {
                ok = false;
                EllLimit limit;
                limit.order1 = m1;
                limit.order2 = m2;
                limit.first1 = i;
                limit.first2 = j;
                limit.lau = std::move(w.lau);
                if (w.condition == Condition::kRegularity) limit.regularity = std::move(w.result);
                out.ellLimit = std::move(limit);
              }
            }
          }
        }
      }
      if (ok) {
        done1 = l1;
        done2 = l2;
      }
    }
    out.ellU = done1;
    out.ellV = done2;
  }

  if (options.runSearch) {
    SearchOptions so = options.search;
    if (!so.progress) so.progress = options.progress;
    Result<SurfaceSearchResult> search = searchSurfaceDefects(surface, so);
    if (!search) return search.status();
    out.search = std::move(search).value();
    for (SubnetVerdict& sub : out.subnets) {
      auto inside = [&](double u, double v) { return sub.u.contains(u) && sub.v.contains(v); };
      for (const SurfaceCriticalPoint& c : out.search->criticalPoints) sub.defectNearby |= inside(c.u, c.v);
      for (const SurfaceSelfIntersection& c : out.search->selfIntersections) {
        sub.defectNearby |= inside(c.u1, c.v1) || inside(c.u2, c.v2);
      }
    }
  }
  return out;
}

namespace {

template <class R, class Object, class Analyse>
std::vector<Result<R>> analyseAll(const std::vector<const Object*>& objects, const RegularityOptions& options,
                                  const ProgressOf& progressOf, Analyse analyse) {
  std::vector<std::optional<Result<R>>> got(objects.size());
  tbb::parallel_for(size_t{0}, objects.size(), [&](size_t i) {
    RegularityOptions own = options;
    if (progressOf) own.progress = progressOf(i);
    got[i].emplace(analyse(*objects[i], own));
  });
  std::vector<Result<R>> out;
  out.reserve(objects.size());
  for (std::optional<Result<R>>& r : got) out.push_back(std::move(*r));
  return out;
}

}  // namespace

std::vector<Result<CurveRegularity>> analyzeCurves(const std::vector<const BSplineCurve*>& curves,
                                                   const RegularityOptions& options, const ProgressOf& progressOf) {
  return analyseAll<CurveRegularity>(curves, options, progressOf, [](const BSplineCurve& c, const RegularityOptions& o) {
    return analyzeCurve(c, o);
  });
}

std::vector<Result<SurfaceRegularity>> analyzeSurfaces(const std::vector<const BSplineSurface*>& surfaces,
                                                       const RegularityOptions& options,
                                                       const ProgressOf& progressOf) {
  return analyseAll<SurfaceRegularity>(surfaces, options, progressOf,
                                       [](const BSplineSurface& s, const RegularityOptions& o) {
                                         return analyzeSurface(s, o);
                                       });
}

}  // namespace seam::regularity
