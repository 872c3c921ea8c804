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

/// The unit named `name` ("mm", "cm", "m", "in", "ft", and "inch" for "in"; exactly, lower case), or nullopt.
inline std::optional<LengthUnit> parseLengthUnit(std::string_view name) {
  if (name == "inch") return LengthUnit::kInch;
  for (const LengthUnitInfo& u : kLengthUnits)
    if (name == u.name) return u.unit;
  return std::nullopt;
}

/// Where the unit of a model's lengths comes from.
enum class UnitSource {
  kNone,        ///< unit-less: a JSON or .bpt model without --units
  kFileHeader,  ///< the STEP/IGES file's header (OpenCASCADE converted the coordinates to millimetres)
  kOption,      ///< the user's --units
  kDisplayOption,  ///< the user's --display-units (the unit an output shows lengths in, issue 38 §1)
};

/// The unit of kLengthUnits a STEP/IGES header names ("MM", "MILLIMETRE", "CM", "M", "METRE", "IN", "INCH", "FT",
/// "FOOT", any case), or nullopt for another (a micron, a mile: such a file is shown in millimetres).
inline std::optional<LengthUnit> lengthUnitOfFileName(std::string_view name) {
  std::string upper(name);
  for (char& c : upper) c = static_cast<char>(c >= 'a' && c <= 'z' ? c - 'a' + 'A' : c);
  if (upper == "MM" || upper == "MILLIMETRE" || upper == "MILLIMETER") return LengthUnit::kMillimetre;
  if (upper == "CM" || upper == "CENTIMETRE" || upper == "CENTIMETER") return LengthUnit::kCentimetre;
  if (upper == "M" || upper == "METRE" || upper == "METER") return LengthUnit::kMetre;
  if (upper == "IN" || upper == "INCH") return LengthUnit::kInch;
  if (upper == "FT" || upper == "FOOT") return LengthUnit::kFoot;
  return std::nullopt;
}

/// The length unit of a model's numbers, and the unit its lengths are shown in (issue 38 §1). A STEP/IGES model is
/// always in millimetres (OpenCASCADE converts on read), so `length` is mm there, `fileUnit` names the unit of the
/// file's header, and `display` is that unit (the user sees the file's own numbers). A JSON/.bpt model has no unit
/// unless --units gives one; --display-units sets `display` for any model with a unit.
struct ModelUnits {
  std::optional<LengthUnit> length;  ///< the unit of the model's numbers; nullopt: unit-less
  std::string fileUnit;              ///< the length unit as the STEP/IGES file names it ("MM", "INCH", ...); "" else
  UnitSource source = UnitSource::kNone;
  /// The precision the file declares (STEP: UNCERTAINTY_MEASURE_WITH_UNIT; IGES: global parameter 19, minimum
  /// user-intended resolution), in model units; nullopt when the file declares none.
  std::optional<double> declaredResolution;
  /// The unit every length of an output is shown in (tables, JSON, reports); nullopt: `length`. Where it comes
  /// from: `displaySource` (kFileHeader: a STEP/IGES file's own unit; kDisplayOption: --display-units).
  std::optional<LengthUnit> display;
  UnitSource displaySource = UnitSource::kNone;

  /// "mm", "in", ...; "" for a unit-less model.
  [[nodiscard]] std::string name() const { return length ? lengthUnitInfo(*length).name : ""; }
  /// `millimetres` (a length in mm) in model units, or nullopt for a unit-less model.
  [[nodiscard]] std::optional<double> fromMillimetres(double millimetres) const {
    if (!length) return std::nullopt;
    return millimetres / lengthUnitInfo(*length).millimetres;
  }
  /// The unit lengths are shown in: `display`, else `length` (nullopt: unit-less).
  [[nodiscard]] std::optional<LengthUnit> shownUnit() const { return display ? display : length; }
  /// The factor from a length in model units to the same length in the shown unit (1 without a display unit).
  [[nodiscard]] double displayScale() const {
    if (!length || !display) return 1.0;
    return lengthUnitInfo(*length).millimetres / lengthUnitInfo(*display).millimetres;
  }
  /// The units of an output whose lengths were converted by displayScale(): `length` is the shown unit, and where
  /// it comes from is the display's source when the display differs from the model's unit.
  [[nodiscard]] ModelUnits shown() const {
    ModelUnits u = *this;
    if (display && length && (*display != *length || displaySource == UnitSource::kDisplayOption)) {
      u.length = display;
      u.source = displaySource;
      if (declaredResolution) u.declaredResolution = *declaredResolution * displayScale();
    }
    u.display.reset();
    return u;
  }
};

/// "file header", "--units", "--display-units" or "none (unit-less model)": the words of `seam check --json`'s units.source.
inline const char* toString(UnitSource s) {
  switch (s) {
    case UnitSource::kFileHeader: return "file header";
    case UnitSource::kOption: return "--units";
    case UnitSource::kDisplayOption: return "--display-units";
    case UnitSource::kNone: break;
  }
  return "none (unit-less model)";
}

}  // namespace seam
