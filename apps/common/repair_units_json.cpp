#include "repair_units_json.h"

namespace seam::cli {

OrderedJson repairTolerancesJson(const ResolvedTolerances& tol) {
  OrderedJson j;
  j["distance"] = tol.tolerances.distance;
  j["distance_source"] = toString(tol.distanceSource);
  j["angle_deg"] = tol.tolerances.angleDeg;
  j["angle_source"] = toString(tol.angleSource);
  j["curvature_rel"] = tol.tolerances.curvatureRel;
  return j;
}

void addRepairUnits(OrderedJson& json, const ModelUnits& units, const ResolvedTolerances& tol) {
  OrderedJson out;
  bool added = false;
  auto add = [&] {
    out["units"] = unitsJson(units);
    out["tolerances"] = repairTolerancesJson(tol);
    added = true;
  };
  for (auto it = json.begin(); it != json.end(); ++it) {
    if (it.key() == "output" && !added) add();
    out[it.key()] = it.value();
  }
  if (!added) add();
  json = std::move(out);
}

}  // namespace seam::cli
