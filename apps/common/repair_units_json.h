#pragma once
// The "units" and "tolerances" keys of `seam heal --json`, `seam join --json` and `seam fill --json` (issue 17 §2:
// the model's length unit and the absolute or relative tolerances the repair classified seams with), one builder for
// the CLI and the Python module.
#include "check_json.h"
#include "seam/core/tolerances.h"
#include "seam/core/units.h"

namespace seam::cli {

/// {"distance", "distance_source", "angle_deg", "curvature_rel"}: the tolerances of a repair (the words of
/// `seam check --json`'s tolerances.distance_source).
OrderedJson repairTolerancesJson(const ResolvedTolerances& tol);

/// Adds "units" (unitsJson) and "tolerances" (repairTolerancesJson) to a repair's JSON object: before its "output"
/// key when it has one, else at the end.
void addRepairUnits(OrderedJson& json, const ModelUnits& units, const ResolvedTolerances& tol);

}  // namespace seam::cli
