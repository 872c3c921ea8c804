#pragma once
// The join and heal reports of report_json.h as JSON values rather than text, for callers that add keys and print
// them in their own layout (the CLI's `seam join --json`, `seam heal --json`): no text written and parsed back (for a
// 6 000-patch heal that round trip cost as much as the heal). The values are exactly what joinReportJson /
// healReportJson write (those functions dump them). Needs nlohmann-json (header-only) on the include path.
#include <nlohmann/json.hpp>

#include "seam/repair/heal.h"
#include "seam/repair/join.h"

namespace seam {

/// The value whose text is joinReportJson(report).
nlohmann::ordered_json joinReportValue(const JoinReport& report);

/// The value whose text is healReportJson(report).
nlohmann::ordered_json healReportValue(const HealReport& report);

}  // namespace seam
