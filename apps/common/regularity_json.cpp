// The JSON of `seam regularity --json` (regularity_json.h).
#include "regularity_json.h"

#include <string>
#include <vector>

namespace seam::cli {

using namespace seam::regularity;

namespace {

OrderedJson point(const Vec3& p, int dim) {
  OrderedJson a = OrderedJson::array();
  for (int k = 0; k < dim; ++k) a.push_back(p[k]);
  return a;
}

OrderedJson checkJson(const Check& c, int dim) {
  OrderedJson j;
  j["check"] = std::string(checkKindName(c.kind));
  if (c.r1 > 0) j["r1"] = c.r1;
  if (c.r2 > 0) j["r2"] = c.r2;
  if (c.separation.separated) {
    j["normal"] = point(c.separation.plane.normal, dim);
    j["offset"] = c.separation.plane.offset;
    j["exact"] = c.separation.planeExact;
  } else {
    j["witness"] = point(c.separation.witness, dim);
    if (!c.coneDirection.isZero()) j["cone_direction"] = point(c.coneDirection, dim);
  }
  return j;
}

/// "certificate" (certified) or "witness" / "failed_check" (otherwise) of a verdict.
void verdictJson(OrderedJson& j, Verdict v, Condition c, const ConditionResult& r, int dim) {
  j["verdict"] = std::string(verdictName(v));
  j["condition"] = c == Condition::kNone ? OrderedJson(nullptr) : OrderedJson(std::string(conditionName(c)));
  if (v == Verdict::kCertified) {
    OrderedJson checks = OrderedJson::array();
    for (const Check& k : r.checks) checks.push_back(checkJson(k, dim));
    j["certificate"] = {{"checks", checks}};
  } else if (const Check* f = r.failure()) {
    j["witness"] = point(f->separation.witness, dim);
    j["failed_check"] = checkJson(*f, dim);
  }
}

OrderedJson summaryJson(const SearchSummary& s) {
  return {{"resolution", s.resolution}, {"distance", s.distance}, {"unresolved", s.unresolved},
          {"complete", s.complete},     {"truncated", s.truncated}};
}

OrderedJson allSegments(const CurveRegularity& r) {
  OrderedJson a = OrderedJson::array();
  for (const SegmentVerdict& s : r.segments) a.push_back(regularitySegmentJson(s, r.dim));
  return a;
}

OrderedJson allSubnets(const SurfaceRegularity& r) {
  OrderedJson a = OrderedJson::array();
  for (const SubnetVerdict& s : r.subnets) a.push_back(regularitySubnetJson(s, r.dim));
  return a;
}

}  // namespace

OrderedJson regularitySegmentJson(const SegmentVerdict& s, int dim) {
  OrderedJson j = {{"index", s.index}, {"interval", {s.interval.lo, s.interval.hi}}, {"uniform", s.uniform}};
  verdictJson(j, s.verdict, s.condition, s.result, dim);
  j["defect_nearby"] = s.defectNearby;
  return j;
}

OrderedJson regularitySubnetJson(const SubnetVerdict& s, int dim) {
  OrderedJson j = {{"index", {s.indexU, s.indexV}},
                   {"u", {s.u.lo, s.u.hi}},
                   {"v", {s.v.lo, s.v.hi}},
                   {"uniform", s.uniformU && s.uniformV}};
  verdictJson(j, s.verdict, s.condition, s.result, dim);
  j["defect_nearby"] = s.defectNearby;
  return j;
}

OrderedJson regularityCurveJson(const std::string& name, const CurveRegularity& r,
                                const std::optional<OrderedJson>& segments) {
  OrderedJson crit = OrderedJson::array();
  OrderedJson inter = OrderedJson::array();
  for (const CurveCriticalPoint& x : r.search->criticalPoints) {
    crit.push_back({{"t", x.t}, {"point", point(x.point, r.dim)}, {"speed", x.speed}});
  }
  for (const CurveSelfIntersection& x : r.search->selfIntersections) {
    inter.push_back({{"t1", x.t1}, {"t2", x.t2}, {"point", point(x.point, r.dim)}, {"distance", x.distance}});
  }
  return {{"name", name},
          {"order", r.order},
          {"segments", segments ? *segments : allSegments(r)},
          {"ell_certified", r.ellCertified ? OrderedJson(*r.ellCertified) : OrderedJson(nullptr)},
          {"critical_points", crit},
          {"self_intersections", inter},
          {"search", summaryJson(r.search->summary)}};
}

OrderedJson regularityPatchJson(const std::string& name, const SurfaceRegularity& r,
                                const std::optional<OrderedJson>& subnets) {
  OrderedJson crit = OrderedJson::array();
  OrderedJson inter = OrderedJson::array();
  for (const SurfaceCriticalPoint& x : r.search->criticalPoints) {
    crit.push_back({{"u", x.u}, {"v", x.v}, {"point", point(x.point, r.dim)}, {"normal_norm", x.normalNorm}});
  }
  for (const SurfaceSelfIntersection& x : r.search->selfIntersections) {
    inter.push_back({{"u1", x.u1},
                     {"v1", x.v1},
                     {"u2", x.u2},
                     {"v2", x.v2},
                     {"point", point(x.point, r.dim)},
                     {"distance", x.distance}});
  }
  const bool haveEll = r.ellU.has_value();
  return {{"name", name},
          {"order", {r.orderU, r.orderV}},
          {"subnets", subnets ? *subnets : allSubnets(r)},
          {"ell_certified", haveEll ? OrderedJson({*r.ellU, *r.ellV}) : OrderedJson(nullptr)},
          {"critical_points", crit},
          {"self_intersections", inter},
          {"search", summaryJson(r.search->summary)}};
}

OrderedJson regularityJson(const std::string& file, const std::vector<std::string>& curveNames,
                           const std::vector<CurveRegularity>& curves, const std::vector<std::string>& patchNames,
                           const std::vector<SurfaceRegularity>& patches) {
  OrderedJson c = OrderedJson::array(), p = OrderedJson::array();
  for (size_t i = 0; i < curves.size(); ++i) c.push_back(regularityCurveJson(curveNames[i], curves[i]));
  for (size_t i = 0; i < patches.size(); ++i) p.push_back(regularityPatchJson(patchNames[i], patches[i]));
  return {{"file", file}, {"curves", c}, {"patches", p}};
}

}  // namespace seam::cli
