// The JSON of `seam fill --json` (fill_json.h).
#include "fill_json.h"

#include <string>
#include <vector>

namespace seam::cli {

namespace {

OrderedJson coeffs(const BernsteinPoly& p) {
  OrderedJson a = OrderedJson::array();
  for (Eigen::Index k = 0; k < p.coeffs().rows(); ++k) a.push_back(p.coeffs()(k, 0));
  return a;
}

OrderedJson vec3(const Vec3& v) { return OrderedJson::array({v.x(), v.y(), v.z()}); }

OrderedJson seamRecord(const SeamReport& r) {
  return OrderedJson{{"a", r.a},
                     {"a_edge", edgeName(r.aEdge)},
                     {"b", r.b},
                     {"b_edge", edgeName(r.bEdge)},
                     {"overlap_a", {r.overlapA.lo, r.overlapA.hi}},
                     {"overlap_b", {r.overlapB.lo, r.overlapB.hi}},
                     {"reversed", r.reversed},
                     {"correspondence", toString(r.correspondence)},
                     {"geometric", toString(r.geometric)},
                     {"parametric", toString(r.parametric)},
                     {"certified", r.certified},
                     {"g1_identity", r.g1Identity},
                     {"g0_max", r.g0Max},
                     {"g1_max_deg", r.g1MaxDeg},
                     {"g2_max", r.g2Max},
                     {"g2_rel_max", r.g2RelMax},
                     {"lambda_range", {r.lambdaRange.lo, r.lambdaRange.hi}},
                     {"kappa_range", {r.kappaRange.lo, r.kappaRange.hi}},
                     {"g1_worst", {{"t", r.g1Worst.t}, {"point", vec3(r.g1Worst.point)}}},
                     {"notes", r.notes}};
}

OrderedJson cornerRecord(const CornerReport& r, const Model& model) {
  OrderedJson patches = OrderedJson::array();
  for (const PatchCorner& c : r.corners) {
    patches.push_back({{"patch", model.patches[static_cast<size_t>(c.patch)].name},
                       {"u", c.uMax ? "max" : "min"},
                       {"v", c.vMax ? "max" : "min"}});
  }
  OrderedJson four = nullptr;
  if (r.fourPatch) {
    OrderedJson seams = OrderedJson::array();
    for (const VertexSeam& s : r.fourPatch->seams) {
      seams.push_back({{"from", s.from},
                       {"to", s.to},
                       {"lambda", s.lambda},
                       {"kappa", s.kappa},
                       {"g1_residual", s.g1Residual},
                       {"g1", s.g1}});
    }
    OrderedJson rel = OrderedJson::array();
    for (double x : r.fourPatch->g1Relations) rel.push_back(x);
    four = {{"g1_residual", r.fourPatch->g1Residual}, {"g1_relations", rel}, {"seams", seams}};
  }
  return OrderedJson{
      {"point", vec3(r.point)},
      {"corner_gap", r.cornerGap},
      {"valence", r.valence},
      {"closed", r.closed},
      {"patches", patches},
      {"normal_spread_deg", r.normalSpreadDeg ? OrderedJson(*r.normalSpreadDeg) : OrderedJson(nullptr)},
      {"four_patch", four},
      {"notes", r.notes}};
}

OrderedJson patchRecord(const FilledPatch& p, const FillResult& fill, const G1PatchOptions& options) {
  const G1PatchResult& c = p.construction;
  OrderedJson seams = OrderedJson::array();
  for (const FillSeam& s : fill.seams) {
    if (s.newPatch != p.patch.name) continue;
    seams.push_back({{"neighbour", s.neighbour},
                     {"neighbour_edge", edgeName(s.neighbourEdge)},
                     {"edge", edgeName(s.newEdge)},
                     {"reversed", s.reversed},
                     {"lambda", coeffs(s.functions.lambda)},
                     {"kappa", coeffs(s.functions.kappa)}});
  }
  OrderedJson attempts = OrderedJson::array();
  for (const G1Attempt& a : c.attempts) {
    attempts.push_back({{"degree", {a.degreeU, a.degreeV}},
                        {"unknowns", a.unknowns},
                        {"constraints", a.constraints},
                        {"rank", a.rank},
                        {"residual", a.residual},
                        {"exact", a.exact}});
  }
  OrderedJson compat = OrderedJson::array();
  for (const CornerCompatibility& cc : c.corners) {
    compat.push_back({{"corner", cc.corner},
                      {"tangent_residual", cc.tangentResidual},
                      {"twist_residual", cc.twistResidual},
                      {"twist_normal_residual", cc.twistNormalResidual}});
  }
  return OrderedJson{{"name", p.patch.name},
                     {"role", p.role},
                     {"degree", {c.patch.degreeU(), c.patch.degreeV()}},
                     {"exact", c.exact},
                     {"interior", options.interior == InteriorRule::kTwistRule ? "twist-rule" : "fairness"},
                     {"free_parameters", c.freeParameters},
                     {"energy", c.energy},
                     {"seams", seams},
                     {"compatibility", compat},
                     {"attempts", attempts},
                     {"notes", c.notes}};
}

}  // namespace

OrderedJson fillJson(const std::string& mode, const FillResult& fill, const FillCheck* check, const Model& full,
                     const G1PatchOptions& patchOptions, const std::optional<std::string>& output) {
  OrderedJson patches = OrderedJson::array(), seams = OrderedJson::array(), corners = OrderedJson::array();
  for (const FilledPatch& p : fill.patches) patches.push_back(patchRecord(p, fill, patchOptions));
  if (check) {
    for (const SeamReport& r : check->seams) seams.push_back(seamRecord(r));
    for (const CornerReport& r : check->corners) corners.push_back(cornerRecord(r, full));
  }
  OrderedJson out{{"new_patches", patches}, {"seams", seams}, {"corners", corners}};
  out["mode"] = mode;
  out["g1"] = check ? check->g1 : fill.surroundingG1;
  out["output"] = output ? OrderedJson(*output) : OrderedJson(nullptr);
  if (mode == "hole") {
    OrderedJson sur = OrderedJson::array();
    for (const SeamReport& r : fill.surrounding) sur.push_back(seamRecord(r));
    out["surrounding"] = sur;
    out["surrounding_g1"] = fill.surroundingG1;
  }
  OrderedJson problems = check ? OrderedJson(check->problems) : OrderedJson::array();
  out["problems"] = problems;
  out["notes"] = fill.notes;
  return out;
}

}  // namespace seam::cli
