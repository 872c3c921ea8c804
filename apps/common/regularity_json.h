#pragma once
// The JSON of `seam regularity --json`, shared by the CLI (apps/seam/cmd_regularity.cpp, which streams the large
// segment / sub-net arrays) and the Python module (python/seam_module.cpp, seam.regularity): one builder, so a
// Python dict has exactly the keys of the CLI's output. Part of the target seam_check_json (apps/common).
//
// {"file", "curves": [{"name", "order", "segments": [...], "ell_certified", "critical_points", "self_intersections",
//  "search"}], "patches": [{"name", "order": [ku, kv], "subnets": [...], "ell_certified", "critical_points",
//  "self_intersections", "search"}]}; a segment / sub-net: {"index", "interval" | "u", "v", "uniform", "verdict",
//  "condition", "certificate" | "witness", "failed_check", "defect_nearby"}.
#include <nlohmann/json.hpp>

#include <optional>
#include <string>
#include <vector>

#include "seam/regularity/regularity.h"

namespace seam::cli {

/// JSON with keys kept in insertion order (what the commands print).
using OrderedJson = nlohmann::ordered_json;

/// One curve segment / one surface sub-net of `seam regularity --json`.
OrderedJson regularitySegmentJson(const regularity::SegmentVerdict& s, int dim);
OrderedJson regularitySubnetJson(const regularity::SubnetVerdict& s, int dim);

/// One curve / patch object. `segments` / `subnets`: the value of that key (the CLI passes a placeholder that it
/// streams in place); empty: the array of every segment's / sub-net's record.
OrderedJson regularityCurveJson(const std::string& name, const regularity::CurveRegularity& r,
                                const std::optional<OrderedJson>& segments = std::nullopt);
OrderedJson regularityPatchJson(const std::string& name, const regularity::SurfaceRegularity& r,
                                const std::optional<OrderedJson>& subnets = std::nullopt);

/// The whole document {"file", "curves", "patches"} (names[i] names results[i]).
OrderedJson regularityJson(const std::string& file, const std::vector<std::string>& curveNames,
                           const std::vector<regularity::CurveRegularity>& curves,
                           const std::vector<std::string>& patchNames,
                           const std::vector<regularity::SurfaceRegularity>& patches);

}  // namespace seam::cli
