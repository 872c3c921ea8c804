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

/// Model-dependent tolerances used to classify geometry. Defaults follow `seam check` (issue 3):
/// distance = 1e-6 x bounding-box diagonal, angle = 0.01 degrees, curvature = 1 % relative.
struct Tolerances {
  double distance = 1e-6;       ///< absolute length; G0 gaps at or below it count as closed
  double angleDeg = 0.01;       ///< degrees; tangent-plane angles at or below it count as G1
  double curvatureRel = 0.01;   ///< relative; normal-curvature jumps at or below it (relative) count as G2
  double parametric = 1e-9;     ///< relative; parametric derivative mismatch (C1/C2) relative to the derivative size

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
  /// The unit of the model's numbers as the user states it (--units): a JSON/.bpt model gets this unit; a STEP/IGES
  /// file's coordinates are taken in it whatever its header says (and rescaled to mm). nullopt: as the file says.
  std::optional<LengthUnit> units;

  [[nodiscard]] Tolerances appliedTo(Tolerances t) const {
    if (distance) t.distance = *distance;
    else if (presetDistanceMm) t.distance = *presetDistanceMm;
    if (angleDeg) t.angleDeg = *angleDeg;
    if (curvatureRel) t.curvatureRel = *curvatureRel;
    return t;
  }
};

/// Classification tolerances with the origin of their distance.
struct ResolvedTolerances {
  Tolerances tolerances;
  DistanceSource distanceSource = DistanceSource::kRelative;
  std::string preset;  ///< the preset's name when distanceSource is kPreset
};

/// The tolerances of a model with `units` and bounding-box diagonal `diagonal`: the overrides, and for the distance
/// without one: kDefaultAbsoluteDistanceMm in model units when the model has a length unit, else 1e-6 x diagonal.
inline ResolvedTolerances resolveTolerances(const ToleranceOverrides& o, const ModelUnits& units, double diagonal) {
  ResolvedTolerances r;
  r.tolerances = o.appliedTo(Tolerances::forModelSize(diagonal));
  if (o.distance) {
    r.distanceSource = DistanceSource::kOption;
  } else if (o.presetDistanceMm) {
    r.distanceSource = DistanceSource::kPreset;
    r.preset = o.preset;
    r.tolerances.distance = units.fromMillimetres(*o.presetDistanceMm).value_or(*o.presetDistanceMm);
  } else if (const std::optional<double> d = units.fromMillimetres(kDefaultAbsoluteDistanceMm)) {
    r.distanceSource = DistanceSource::kAbsoluteDefault;
    r.tolerances.distance = *d;
  }
  return r;
}

}  // namespace seam
