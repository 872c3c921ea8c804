#pragma once
// Lengths with their unit in text (issue 17 §2), shared by the CLI (cli_util.h includes this header) and the Python
// module (the B-rep report's unit note, brep_report.h).
#include <string>

#include "seam/core/units.h"

namespace seam::cli {

/// Significant digits of every number in text output (tables, summaries, messages; JSON keeps round-trip
/// precision): `--digits N` of the CLI (issue 38 §7), kDefaultDisplayDigits otherwise.
inline constexpr int kDefaultDisplayDigits = 4;
/// --digits accepts 1 to this (17: every double prints exactly, as in JSON).
inline constexpr int kMaxDisplayDigits = 17;
/// Sets the digits of formatNumber (clamped to [1, kMaxDisplayDigits]). Set once, before any output (the CLI's
/// option parser); not meant to change while other threads format numbers.
void setDisplayDigits(int digits);
/// A number for text (gaps, angles, ratios, coordinates): the digits of setDisplayDigits, significant (%.{d}g:
/// "0.3282", "2.818", "92.51", "3.187e-05"); 0 as "0", never "0.0000".
std::string formatNumber(double x);
/// "0.001 mm": a formatted length followed by the model's unit (nothing for a unit-less model).
std::string withUnit(const std::string& length, const ModelUnits& units);
/// "length unit: mm (file header: INCH); declared resolution 0.0254 mm", "length unit: m (--units)", "length unit:
/// none (unit-less model; --units gives one)": the model's unit and where it comes from, one line, no newline.
std::string unitText(const ModelUnits& units);

}  // namespace seam::cli
