#pragma once
// Named tolerances. Every comparison against a threshold in seam goes through one of these; see
// docs/tolerances.md for what each means, its default and how it scales with the model.
#include <algorithm>
#include <cmath>
#include <optional>
#include <string>

#include "seam/core/units.h"

namespace seam {

/// Relative round-off level of double arithmetic on well-scaled data (about 2^-40). A quantity whose magnitude is
/// below kRoundoff * scale (scale = the magnitude of the data it was computed from) is "zero up to round-off".
inline constexpr double kRoundoff = 1e-12;

/// Two knots closer than kKnotRelTol * (knot-vector length) are the same knot (multiplicity counting, span search).
inline constexpr double kKnotRelTol = 1e-12;

/// A polynomial identity (e.g. "the normals of two patches are parallel along the whole seam") is taken to hold when
/// every Bernstein coefficient of the difference is below kIdentityRelTol x the scale of the data it was computed
/// from. Products of several factors of degree up to ~30 lose a few digits more than kRoundoff; 1e-10 leaves two
/// orders of margin while any real defect of a CAD model (>= 1e-8 relative) stays far above it.
inline constexpr double kIdentityRelTol = 1e-10;

/// seam's own G1 angle, in degrees: the default of Tolerances::angleDeg (unit-less models), and the level below which
/// a certified angle's number is worth sharpening whatever the tolerance (e.g. the B-rep route's closest-point retry).
inline constexpr double kStrictAngleDeg = 0.01;

/// Model-dependent tolerances used to classify geometry. Defaults follow `seam check` (issue 3):
/// distance = 1e-6 x bounding-box diagonal, angle = 0.01 degrees, curvature = 1 % relative.
struct Tolerances {
  double distance = 1e-6;       ///< absolute length; G0 gaps at or below it count as closed
  double angleDeg = kStrictAngleDeg;  ///< degrees; tangent-plane angles at or below it count as G1
  double curvatureRel = 0.01;   ///< relative; normal-curvature jumps at or below it (relative) count as G2
  double parametric = 1e-9;     ///< relative; parametric derivative mismatch (C1/C2) relative to the derivative size

  /// seam's strict angle scale, min(angleDeg, kStrictAngleDeg): what "never worse" judges angles by and where a
  /// certified angle is worth sharpening, whatever the verdict's tolerance (a CAD tolerance of 0.5 degrees must not
  /// let a repair turn 0.1 degrees into 0.5).
  [[nodiscard]] double strictAngleDeg() const { return angleDeg < kStrictAngleDeg ? angleDeg : kStrictAngleDeg; }

  /// Defaults scaled to a model whose bounding-box diagonal is `diagonal` (a zero or non-finite diagonal -> 1).
  static Tolerances forModelSize(double diagonal) {
    Tolerances t;
    const double d = (std::isfinite(diagonal) && diagonal > 0.0) ? diagonal : 1.0;
    t.distance = 1e-6 * d;
    return t;
  }
};

/// Default G0 tolerance of a model whose length unit is known (STEP/IGES; JSON/.bpt with --units), in millimetres:
/// the 0.001 mm CATIA and Rhino (mm template) work with. CAD checkers judge gaps in absolute length, not relative to
/// the part's size. docs/tolerances.md, "Units", gives the measurements behind the choice.
inline constexpr double kDefaultAbsoluteDistanceMm = 0.001;

/// Default G1 angle of a model whose length unit is known (STEP/IGES; JSON/.bpt with --units), in degrees: the
/// tangency threshold CAD checkers ship (CATIA's smooth/sharp edge limit and Connect Checker habit, NX's modeling
/// angle tolerance: 0.5 degrees; Rhino's document default is 1 degree). Exported B-reps carry kinks of 0.02-0.25
/// degrees from their modellers' own approximations, which every CAD checker calls tangent (issue 38 goal 2).
/// Unit-less models (JSON/.bpt networks, constructions) keep Tolerances::angleDeg (0.01 degrees), seam's strict
/// default; `--tol-angle 0.01` asks for it on a CAD file. docs/tolerances.md gives the sources.
inline constexpr double kDefaultCadAngleDeg = 0.5;

/// Where a classification's angle tolerance comes from.
enum class AngleSource {
  kStrictDefault,  ///< Tolerances::angleDeg (0.01 degrees): unit-less models
  kCadDefault,     ///< kDefaultCadAngleDeg: models with a length unit
  kPreset,         ///< a --preset's angle
  kOption,         ///< --tol-angle
};

/// The words of the text output and of `--json`'s tolerances.angle_source.
inline const char* toString(AngleSource s) {
  switch (s) {
    case AngleSource::kStrictDefault: return "strict default";
    case AngleSource::kCadDefault: return "CAD default";
    case AngleSource::kPreset: return "preset";
    case AngleSource::kOption: break;
  }
  return "option";
}

/// "default for unit-less models", "default for models with a length unit (CATIA, NX: 0.5 deg)", "--preset catia",
/// "--tol-angle".
inline std::string angleSourceText(AngleSource s, const std::string& preset = {}) {
  switch (s) {
    case AngleSource::kStrictDefault: return "default for unit-less models";
    case AngleSource::kCadDefault: return "default for models with a length unit, as CATIA and NX";
    case AngleSource::kPreset: return "--preset " + preset;
    case AngleSource::kOption: break;
  }
  return "--tol-angle";
}

/// Where a classification's distance tolerance comes from.
enum class DistanceSource {
  kRelative,         ///< 1e-6 x bounding-box diagonal (Tolerances::forModelSize): unit-less models
  kAbsoluteDefault,  ///< kDefaultAbsoluteDistanceMm converted to model units: models with a length unit
  kPreset,           ///< a --preset's distance
  kOption,           ///< --tol-distance
};

/// "default for unit-less models: 1e-6 x bounding-box diagonal", "default for models with a unit", "--preset catia",
/// "--tol-distance" (`preset` names the preset).
inline std::string distanceSourceText(DistanceSource s, const std::string& preset = {}) {
  switch (s) {
    case DistanceSource::kRelative: return "default for unit-less models: 1e-6 x bounding-box diagonal";
    case DistanceSource::kAbsoluteDefault: return "default for models with a length unit, e.g. CAD files";
    case DistanceSource::kPreset: return "--preset " + preset;
    case DistanceSource::kOption: break;
  }
  return "--tol-distance";
}

/// "relative", "absolute default", "preset", "option": the words of `seam check --json`'s tolerances.distance_source.
inline const char* toString(DistanceSource s) {
  switch (s) {
    case DistanceSource::kRelative: return "relative default";
    case DistanceSource::kAbsoluteDefault: return "absolute default";
    case DistanceSource::kPreset: return "preset";
    case DistanceSource::kOption: break;
  }
  return "option";
}

/// User choices (e.g. the CLI's --tol-* / --preset / --units options) that replace single fields of the defaults.
struct ToleranceOverrides {
  std::optional<double> distance, angleDeg, curvatureRel;
  /// A preset's distance, in millimetres: converted to model units once the model's unit is known (for a unit-less
  /// model it is taken as a number in model units). `distance` wins over it.
  std::optional<double> presetDistanceMm;
  std::string preset;                 ///< the preset's name ("" without one)
  bool angleFromPreset = false;       ///< `angleDeg` is the preset's (no --tol-angle given)
  /// The unit of the model's numbers as the user states it (--units): a JSON/.bpt model gets this unit; a STEP/IGES
  /// file's coordinates are taken in it whatever its header says (and rescaled to mm). nullopt: as the file says.
  std::optional<LengthUnit> units;
  /// The unit the output shows lengths in (--display-units, issue 38 §1); nullopt: the model's, or a STEP/IGES
  /// file's own unit. `distance` is given in the shown unit (ModelUnits::shownUnit).
  std::optional<LengthUnit> display;

  [[nodiscard]] Tolerances appliedTo(Tolerances t) const {
    if (distance) t.distance = *distance;
    else if (presetDistanceMm) t.distance = *presetDistanceMm;
    if (angleDeg) t.angleDeg = *angleDeg;
    if (curvatureRel) t.curvatureRel = *curvatureRel;
    return t;
  }
};

/// The units of a JSON/.bpt model under `o`: unit-less, or --units' unit; shown in --display-units' unit when given.
inline ModelUnits declaredModelUnits(const ToleranceOverrides& o) {
  ModelUnits u;
  if (o.units) {
    u.length = o.units;
    u.source = UnitSource::kOption;
  }
  if (o.display) {
    u.display = o.display;
    u.displaySource = UnitSource::kDisplayOption;
  }
  return u;
}

/// Classification tolerances with the origin of their distance.
struct ResolvedTolerances {
  Tolerances tolerances;
  DistanceSource distanceSource = DistanceSource::kRelative;
  AngleSource angleSource = AngleSource::kStrictDefault;
  std::string preset;  ///< the preset's name when a value comes from it
};

/// The tolerances of a model with `units` and bounding-box diagonal `diagonal`, in model units: the overrides (the
/// distance converted from the shown unit, ModelUnits::displayScale), and for the distance
/// without one: kDefaultAbsoluteDistanceMm in model units when the model has a length unit, else 1e-6 x diagonal;
/// for the angle without one: kDefaultCadAngleDeg when the model has a length unit, else Tolerances::angleDeg.
inline ResolvedTolerances resolveTolerances(const ToleranceOverrides& o, const ModelUnits& units, double diagonal) {
  ResolvedTolerances r;
  r.tolerances = o.appliedTo(Tolerances::forModelSize(diagonal));
  r.preset = o.preset;
  if (o.angleDeg) {
    r.angleSource = o.angleFromPreset ? AngleSource::kPreset : AngleSource::kOption;
  } else if (units.fromMillimetres(kDefaultAbsoluteDistanceMm)) {
    r.angleSource = AngleSource::kCadDefault;
    r.tolerances.angleDeg = kDefaultCadAngleDeg;
  }
  if (o.distance) {
    r.distanceSource = DistanceSource::kOption;
    r.tolerances.distance = *o.distance / units.displayScale();  // given in the shown unit
  } else if (o.presetDistanceMm) {
    r.distanceSource = DistanceSource::kPreset;
    r.tolerances.distance = units.fromMillimetres(*o.presetDistanceMm).value_or(*o.presetDistanceMm);
  } else if (const std::optional<double> d = units.fromMillimetres(kDefaultAbsoluteDistanceMm)) {
    r.distanceSource = DistanceSource::kAbsoluteDefault;
    r.tolerances.distance = *d;
  }
  return r;
}

}  // namespace seam
