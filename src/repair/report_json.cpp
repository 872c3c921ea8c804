#include "seam/repair/report_json.h"
#include "seam/repair/report_json_value.h"

#include <cmath>
#include <nlohmann/json.hpp>

namespace seam {

namespace {

using Json = nlohmann::ordered_json;

Json num(double x) { return std::isfinite(x) ? Json(x) : Json(nullptr); }
Json pair(double a, double b) { return Json::array({num(a), num(b)}); }
Json point(const Vec3& p) { return Json::array({num(p.x()), num(p.y()), num(p.z())}); }
Json worst(const WorstLocation& w) { return Json{{"t", num(w.t)}, {"point", point(w.point)}}; }

Json seamJson(const SeamReport& r) {
  Json j{{"a", r.a},
         {"a_edge", std::string(edgeName(r.aEdge))},
         {"b", r.b},
         {"b_edge", std::string(edgeName(r.bEdge))},
         {"overlap", pair(r.overlapA.lo, r.overlapA.hi)},
         {"g0_max", num(r.g0Max)},
         {"g1_max_deg", num(r.g1MaxDeg)},
         {"g2_max", num(r.g2Max)},
         {"g2_rel_max", num(r.g2RelMax)},
         {"lambda_range", pair(r.lambdaRange.lo, r.lambdaRange.hi)},
         {"kappa_range", pair(r.kappaRange.lo, r.kappaRange.hi)},
         {"geometric", std::string(toString(r.geometric))},
         {"parametric", std::string(toString(r.parametric))},
         {"certified", r.certified},
         {"worst", Json{{"g0", worst(r.g0Worst)}, {"g1", worst(r.g1Worst)}, {"g2", worst(r.g2Worst)}}}};
  // The further keys `seam check --json` writes (apps/seam/cmd_check.cpp), in the same order.
  j["overlap_b"] = pair(r.overlapB.lo, r.overlapB.hi);
  j["reversed"] = r.reversed;
  j["correspondence"] = std::string(toString(r.correspondence));
  j["g0_sampled"] = num(r.g0Sampled);
  j["g1_sampled_deg"] = num(r.g1SampledDeg);
  j["g2_sampled"] = num(r.g2Sampled);
  j["g2_rel_sampled"] = num(r.g2RelSampled);
  j["g2_residual_max"] = num(r.g2ResidualMax);
  j["c1_mismatch"] = num(r.c1Mismatch);
  j["c2_mismatch"] = num(r.c2Mismatch);
  Json notes = Json::array();
  for (const std::string& n : r.notes) notes.push_back(n);
  j["notes"] = notes;
  return j;
}

Json strings(const std::vector<std::string>& v) {
  Json a = Json::array();
  for (const std::string& s : v) a.push_back(s);
  return a;
}
Json numbers(const std::vector<double>& v) {
  Json a = Json::array();
  for (double x : v) a.push_back(num(x));
  return a;
}

}  // namespace

std::string seamRecordJson(const SeamReport& report) { return seamJson(report).dump(); }

nlohmann::ordered_json joinReportValue(const JoinReport& r) {
  Json j;
  j["method"] = std::string(toString(r.method));
  j["reason"] = r.reason;
  j["proportional_knots"] = r.proportionalKnots ? Json(*r.proportionalKnots) : Json(nullptr);
  j["requested"] = std::string(toString(r.requested));
  j["achieved"] = r.achieved;
  j["before"] = seamJson(r.before);
  j["after"] = seamJson(r.after);
  j["reverted"] = r.reverted;
  j["crease_kept"] = r.creaseKept;
  j["max_displacement"] = num(r.maxDisplacement);
  j["max_surface_displacement"] = num(r.maxSurfaceDisplacement);
  j["max_surface_displacement_sampled"] = num(r.maxSurfaceDisplacementSampled);
  j["max_surface_displacement_rel"] = num(r.maxSurfaceDisplacementRel);
  j["moved_points"] = r.movedPoints;
  j["patches_changed"] = strings(r.patchesChanged);
  j["inserted_knots"] = Json{{"u", numbers(r.insertedKnotsU)}, {"v", numbers(r.insertedKnotsV)}};
  j["elevated"] = Json::array({r.elevatedU, r.elevatedV});
  j["lambda_min"] = r.lambdaMin ? num(*r.lambdaMin) : Json(nullptr);
  j["lambda_fixed"] = r.lambdaFixed;
  j["lambda0"] = r.lambda0 ? num(*r.lambda0) : Json(nullptr);
  j["weights_fixed"] = r.weightsFixed;
  if (r.method == JoinMethod::kBezierStrip) {
    Json js = Json::array();
    for (const StripJunction& J : r.junctions)
      js.push_back(Json{{"index", J.index},
                        {"u", num(J.u)},
                        {"wrinkled", J.wrinkled},
                        {"ell", num(J.ell)},
                        {"displacement", num(J.displacement)}});
    j["strip"] = Json{{"junctions", js},
                      {"internal_g1_max_deg", r.stripInternalG1MaxDeg ? num(*r.stripInternalG1MaxDeg) : Json(nullptr)}};
  }
  j["notes"] = strings(r.notes);
  return j;
}

std::string joinReportJson(const JoinReport& r) { return joinReportValue(r).dump(); }

nlohmann::ordered_json healReportValue(const HealReport& r) {
  Json j;
  j["requested"] = std::string(toString(r.requested));
  j["method"] = std::string(toString(r.method));
  j["max_gap"] = num(r.maxGap);
  j["max_angle_deg"] = num(r.maxAngleDeg);
  Json seams = Json::array();
  for (const HealSeam& s : r.seams)
    seams.push_back(Json{{"before", seamJson(s.before)},
                         {"after", s.after ? seamJson(*s.after) : Json(nullptr)},
                         {"certified_before", s.before.certified},
                         {"certified_after", s.after ? Json(s.after->certified) : Json(nullptr)},
                         {"region", s.region},
                         {"action", s.action},
                         {"moved", s.moved.empty() ? Json(nullptr) : Json(s.moved)},
                         {"edge_moved", num(s.edgeMoved)},
                         {"achieved", s.achieved},
                         {"worse", s.worse},
                         {"notes", strings(s.notes)}});
  j["seams"] = seams;
  Json regions = Json::array();
  for (const HealRegion& g : r.regions)
    regions.push_back(Json{{"patches", strings(g.patches)},
                           {"seams", g.seams},
                           {"seams_achieved", g.seamsAchieved},
                           {"method", g.method},
                           {"achieved", g.achieved},
                           {"successive_displacement_rel", g.successiveDisplacementRel >= 0.0
                                                               ? num(g.successiveDisplacementRel)
                                                               : Json(nullptr)},
                           {"local_displacement_rel",
                            g.localDisplacementRel >= 0.0 ? num(g.localDisplacementRel) : Json(nullptr)},
                           {"note", g.note}});
  j["regions"] = regions;
  Json steps = Json::array();
  for (const HealStep& s : r.steps)
    steps.push_back(Json{{"patch", s.patch},
                         {"region", s.region},
                         {"accepted", s.accepted},
                         {"kept", s.kept},
                         {"reason", s.reason.empty() ? Json(nullptr) : Json(s.reason)},
                         {"notes", strings(s.notes)}});
  j["steps"] = steps;
  j["steps_reverted"] = r.stepsReverted;
  j["order"] = strings(r.order);
  j["patches_changed"] = strings(r.patchesChanged);
  Json patches = Json::array();
  for (const HealPatch& p : r.patches)
    patches.push_back(Json{{"name", p.name},
                           {"region", p.region},
                           {"size", num(p.size)},
                           {"max_displacement", num(p.maxDisplacement)},
                           {"moved_points", p.movedPoints},
                           {"max_surface_displacement", num(p.maxSurfaceDisplacement)},
                           {"max_surface_displacement_rel", num(p.maxSurfaceDisplacementRel)},
                           {"max_surface_displacement_sampled", num(p.maxSurfaceDisplacementSampled)},
                           {"surface_displacement_certified", p.surfaceDisplacementCertified}});
  j["patches"] = patches;
  j["max_displacement"] = num(r.maxDisplacement);
  j["moved_points"] = r.movedPoints;
  j["max_surface_displacement"] = num(r.maxSurfaceDisplacement);
  j["max_surface_displacement_rel"] = num(r.maxSurfaceDisplacementRel);
  j["surface_displacement_certified"] = r.surfaceDisplacementCertified;
  j["seams_to_reach"] = r.seamsToReach;
  j["creases_kept"] = r.creasesKept;
  j["crease_gaps_closed"] = r.creaseGapsClosed;
  j["seams_achieved"] = r.seamsAchieved;
  j["seams_worse"] = r.seamsWorse;
  j["worst"] = Json{{"geometric", std::string(toString(r.worst))}, {"g0_max", num(r.worstG0)},
                    {"g1_max_deg", num(r.worstG1Deg)}};
  j["achieved"] = r.achieved;
  j["notes"] = strings(r.notes);
  return j;
}

std::string healReportJson(const HealReport& r) { return healReportValue(r).dump(); }

namespace {

Json conditionsJson(const std::vector<ConditionCheck>& checks) {
  Json a = Json::array();
  for (const ConditionCheck& k : checks)
    a.push_back(Json{{"name", std::string(toString(k.condition))},
                     {"statement", k.statement},
                     {"residual", num(k.residual)},
                     {"tolerance", num(k.tolerance)},
                     {"holds", k.holds},
                     {"detail", k.detail}});
  return a;
}

Json cornerReportJson(const CornerJoinReport& r, Json proportionality, const char* layout) {
  Json j;
  j["layout"] = layout;
  j["proportionality"] = std::move(proportionality);
  Json steps = Json::array();
  for (const CornerJoinStep& s : r.steps)
    steps.push_back(Json{{"moved", strings(s.moved)},
                         {"onto", strings(s.onto)},
                         {"method", std::string(toString(s.method))},
                         {"reason", s.reason},
                         {"max_displacement", num(s.maxDisplacement)},
                         {"moved_points", s.movedPoints},
                         {"notes", strings(s.notes)}});
  j["steps"] = steps;
  Json seams = Json::array();
  for (const CornerSeam& s : r.seams)
    seams.push_back(Json{{"a", s.a},
                         {"a_edge", std::string(edgeName(s.aEdge))},
                         {"b", s.b},
                         {"b_edge", std::string(edgeName(s.bEdge))},
                         {"before", s.before ? seamJson(*s.before) : Json(nullptr)},
                         {"after", seamJson(s.after)},
                         {"certified_before", s.before ? Json(s.before->certified) : Json(nullptr)},
                         {"certified_after", s.after.certified},
                         {"achieved", s.achieved},
                         {"worse", s.worse},
                         {"worse_why", s.worseWhy.empty() ? Json(nullptr) : Json(s.worseWhy)}});
  j["seams"] = seams;
  j["achieved"] = r.achieved;
  j["reverted"] = r.reverted;
  j["seams_worse"] = r.seamsWorse;
  j["max_displacement"] = num(r.maxDisplacement);
  j["max_surface_displacement"] = num(r.maxSurfaceDisplacement);
  j["max_surface_displacement_rel"] = num(r.maxSurfaceDisplacementRel);
  j["max_surface_displacement_sampled"] = num(r.maxSurfaceDisplacementSampled);
  j["worst"] = Json{{"g0_max", num(r.worstG0)}, {"g1_max_deg", num(r.worstG1Deg)}};
  j["notes"] = strings(r.notes);
  return j;
}

}  // namespace

std::string threePatchJoinJson(const ThreePatchJoinResult& res) {
  Json p(nullptr);
  if (res.proportionality) {
    const ThreePatchProportionality& q = *res.proportionality;
    p = Json{{"all_hold", q.allHold},
             {"theorem1_for_hat", q.theorem1ForHat},
             {"conditions", conditionsJson(q.checks)},
             {"chain_ratios", numbers(q.chainRatios)},
             {"m", q.m},
             {"m_tilde", q.mTilde},
             {"n", q.n},
             {"n_tilde", q.nTilde},
             {"q", q.q},
             {"corner_index", q.cornerIndex},
             {"n_hat1", q.nHat1},
             {"n_hat2", q.nHat2},
             {"notes", strings(q.notes)}};
  }
  return cornerReportJson(res.report, std::move(p), "three").dump();
}

std::string fourPatchJoinJson(const FourPatchJoinResult& res) {
  Json p(nullptr);
  if (res.proportionality)
    p = Json{{"all_hold", res.proportionality->allHold},
             {"conditions", conditionsJson(res.proportionality->checks)},
             {"chain_ratios", numbers(res.proportionality->chainRatios)}};
  return cornerReportJson(res.report, std::move(p), "four").dump();
}

}  // namespace seam
