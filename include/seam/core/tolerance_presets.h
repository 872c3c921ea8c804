#pragma once
// The tolerance presets of CAD systems (issue 17 §2): the CLI's `--preset` and Python's `seam.check(..., preset=)`
// both apply them through applyTolerancePreset. docs/tolerances.md, "Presets", gives the values and their sources.
#include <string_view>

#include "seam/core/tolerances.h"

namespace seam {

/// The distance and angle thresholds of a CAD system's continuity checks, for the CLI's `--preset` and Python's
/// `preset=` (issue 17 §2); values and sources in docs/tolerances.md. Distances are absolute, in millimetres,
/// converted to the model's length unit (resolveTolerances; a unit-less model takes the number as is);
/// curvatureRel 0 keeps seam's default.
struct TolerancePreset {
  const char* name;
  double distance;
  double angleDeg;
  double curvatureRel;
};
inline constexpr TolerancePreset kTolerancePresets[] = {
    {"catia", 0.001, 0.5, 0.0},   // CATIA V5 healing / Connect Checker defaults: 0.001 mm, 0.5 deg
    {"rhino", 0.001, 1.0, 0.05},  // Rhino document defaults (mm template): absolute 0.001, angle 1 deg; 5 % curvature
    // Siemens NX modeling preferences: distance 0.0254 mm (0.001 in), angle 0.5 deg. Unconfirmed: no public
    // document states NX's defaults (searched 2026-11-26; docs/tolerances.md lists what was found).
    {"nx", 0.0254, 0.5, 0.0},
};

/// Applies the preset named `name` ("catia", "rhino", "nx") to `o`: its distance (in mm, converted later), and its
/// angle and curvature where `o` has none yet (an explicit --tol-angle / --tol-curvature wins). False, `o`
/// unchanged, for an unknown name.
inline bool applyTolerancePreset(ToleranceOverrides& o, std::string_view name) {
  for (const TolerancePreset& p : kTolerancePresets) {
    if (name != p.name) continue;
    o.preset = p.name;
    o.presetDistanceMm = p.distance;  // converted to model units once the unit is known
    if (!o.angleDeg) {
      o.angleDeg = p.angleDeg;
      o.angleFromPreset = true;
    }
    if (!o.curvatureRel && p.curvatureRel > 0.0) o.curvatureRel = p.curvatureRel;
    return true;
  }
  return false;
}

}  // namespace seam
