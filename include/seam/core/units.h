#pragma once
// Length units (issue 17 §2): the unit of a model's numbers, where it comes from, and the conversions of absolute
// tolerances given in millimetres (the presets, the CAD default) into model units. docs/tolerances.md, "Units".
#include <optional>
#include <string>
#include <string_view>

namespace seam {

/// The length units `--units` accepts.
enum class LengthUnit { kMillimetre, kCentimetre, kMetre, kInch, kFoot };

struct LengthUnitInfo {
  LengthUnit unit;
  const char* name;    ///< the short name used by `--units` and printed after lengths ("mm", "in", ...)
  double millimetres;  ///< the unit's length in millimetres (exact: the inch is 25.4 mm by definition)
};

inline constexpr LengthUnitInfo kLengthUnits[] = {
    {LengthUnit::kMillimetre, "mm", 1.0},  {LengthUnit::kCentimetre, "cm", 10.0}, {LengthUnit::kMetre, "m", 1000.0},
    {LengthUnit::kInch, "in", 25.4},       {LengthUnit::kFoot, "ft", 304.8},
};

/// The unit's entry in kLengthUnits.
inline const LengthUnitInfo& lengthUnitInfo(LengthUnit unit) {
  for (const LengthUnitInfo& u : kLengthUnits)
    if (u.unit == unit) return u;
  return kLengthUnits[0];
}

/// The unit named `name` ("mm", "cm", "m", "in", "ft"; exactly, lower case), or nullopt.
inline std::optional<LengthUnit> parseLengthUnit(std::string_view name) {
  for (const LengthUnitInfo& u : kLengthUnits)
    if (name == u.name) return u.unit;
  return std::nullopt;
}

/// Where the unit of a model's lengths comes from.
enum class UnitSource {
  kNone,        ///< unit-less: a JSON or .bpt model without --units
  kFileHeader,  ///< the STEP/IGES file's header (OpenCASCADE converted the coordinates to millimetres)
  kOption,      ///< the user's --units
};

/// The length unit of a model's numbers. A STEP/IGES model is always in millimetres (OpenCASCADE converts on read;
/// with --units the coordinates are rescaled from the stated unit), so `length` is mm there and `fileUnit` names
/// the unit of the file's header. A JSON/.bpt model has no unit unless --units gives one.
struct ModelUnits {
  std::optional<LengthUnit> length;  ///< the unit of the model's numbers; nullopt: unit-less
  std::string fileUnit;              ///< the length unit as the STEP/IGES file names it ("MM", "INCH", ...); "" else
  UnitSource source = UnitSource::kNone;
  /// The precision the file declares (STEP: UNCERTAINTY_MEASURE_WITH_UNIT; IGES: global parameter 19, minimum
  /// user-intended resolution), in model units; nullopt when the file declares none.
  std::optional<double> declaredResolution;

  /// "mm", "in", ...; "" for a unit-less model.
  [[nodiscard]] std::string name() const { return length ? lengthUnitInfo(*length).name : ""; }
  /// `millimetres` (a length in mm) in model units, or nullopt for a unit-less model.
  [[nodiscard]] std::optional<double> fromMillimetres(double millimetres) const {
    if (!length) return std::nullopt;
    return millimetres / lengthUnitInfo(*length).millimetres;
  }
};

/// "file header", "--units" or "none (unit-less model)": the words of `seam check --json`'s units.source.
inline const char* toString(UnitSource s) {
  switch (s) {
    case UnitSource::kFileHeader: return "file header";
    case UnitSource::kOption: return "--units";
    case UnitSource::kNone: break;
  }
  return "none (unit-less model)";
}

}  // namespace seam
