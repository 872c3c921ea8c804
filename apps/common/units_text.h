#pragma once
// Lengths with their unit in text (issue 17 §2), shared by the CLI (cli_util.h includes this header) and the Python
// module (the B-rep report's unit note, brep_report.h).
#include <string>

#include "seam/core/units.h"

namespace seam::cli {

/// A number for tables: up to 10 significant digits (%.10g).
std::string formatNumber(double x);
/// "0.001 mm": a formatted length followed by the model's unit (nothing for a unit-less model).
std::string withUnit(const std::string& length, const ModelUnits& units);
/// "length unit: mm (file header: INCH); declared resolution 0.0254 mm", "length unit: m (--units)", "length unit:
/// none (unit-less model; --units gives one)": the model's unit and where it comes from, one line, no newline.
std::string unitText(const ModelUnits& units);

}  // namespace seam::cli
