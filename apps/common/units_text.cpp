#include "units_text.h"

#include <fmt/format.h>

#include <algorithm>

namespace seam::cli {

namespace {
int gDisplayDigits = kDefaultDisplayDigits;
}  // namespace

void setDisplayDigits(int digits) { gDisplayDigits = std::clamp(digits, 1, kMaxDisplayDigits); }

std::string formatNumber(double x) { return fmt::format("{:.{}g}", x, gDisplayDigits); }

std::string withUnit(const std::string& length, const ModelUnits& units) {
  return units.length ? length + " " + units.name() : length;
}

std::string unitText(const ModelUnits& units) {
  std::string unit;
  if (!units.length) {
    unit = "length unit: none (unit-less model; --units gives one)";
  } else if (units.source == UnitSource::kDisplayOption) {
    unit = fmt::format("length unit: {} (--display-units{})", units.name(),
                       units.fileUnit.empty() ? "" : fmt::format("; the file header says {}", units.fileUnit));
  } else if (units.source == UnitSource::kOption) {
    unit = fmt::format("length unit: {} (--units{})", units.name(),
                       units.fileUnit.empty() ? "" : fmt::format("; the file header says {}", units.fileUnit));
  } else {
    unit = fmt::format("length unit: {} (file header: {})", units.name(),
                       units.fileUnit.empty() ? "none" : units.fileUnit);
  }
  if (units.declaredResolution)
    unit += fmt::format("; declared resolution {}", withUnit(formatNumber(*units.declaredResolution), units));
  return unit;
}

}  // namespace seam::cli
