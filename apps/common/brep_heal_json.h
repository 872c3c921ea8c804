#pragma once
// The JSON of `seam heal --json` of a STEP/IGES B-rep (occt::healBRepFile), one builder for the CLI and the Python
// module (`seam.heal` of a model read from STEP/IGES).
#include <optional>
#include <string>

#include "check_json.h"
#include "seam/continuity/seam.h"
#include "seam/occt/brep_heal.h"

namespace seam::cli {

/// One seam's state in the words of `seam check` (gap, kink, crease, G1, G2).
std::string brepSeamState(const SeamReport& r, double creaseDeg);

/// {"input", "output" (when given), "route": "brep", "requested", "unit", "units" (the shown unit, as `seam check
/// --json`'s: every length whose key has no _mm ends in it), "tolerances", "max_gap", "max_gap_mm",
/// "crease_angle_deg", "seams" (each with "moved" and "moved_mm"), "faces_changed", "faces_reverted",
/// "max_surface_displacement_mm", "face_moves", "counts", "seams_to_heal", "seams_healed", "seams_worse", "notes",
/// "achieved"} (docs/brep-repair.md, "The report").
OrderedJson brepHealJson(const occt::BRepHealReport& r, const std::string& input,
                         const std::optional<std::string>& output);

}  // namespace seam::cli
