#pragma once
// The JSON of `seam fill --json` (Johansson §4 constructions, construct/fill.h), shared by the CLI
// (apps/seam/cmd_fill.cpp) and the Python module (python/seam_module.cpp, seam.fill): one builder, so a Python dict
// has exactly the keys of the CLI's output. Part of the target seam_check_json (apps/common).
//
// {"new_patches": [{"name", "role", "degree", "exact", "interior", "free_parameters", "energy", "seams",
//  "compatibility", "attempts", "notes"}], "seams": [seam records], "corners": [corner records], "mode", "g1",
//  "output", ("surrounding", "surrounding_g1" for holes), "problems", "notes"}
#include <nlohmann/json.hpp>

#include <optional>
#include <string>

#include "seam/construct/fill.h"
#include "seam/model/model.h"

namespace seam::cli {

/// JSON with keys kept in insertion order (what the commands print).
using OrderedJson = nlohmann::ordered_json;

/// `seam fill --json`: `mode` "quad" | "hole" | "fillet"; `check` the verification (null when the surrounding of a
/// hole is not G1 and nothing was built); `full` = withFill(input, fill); `output` the written file (null when none).
OrderedJson fillJson(const std::string& mode, const FillResult& fill, const FillCheck* check, const Model& full,
                     const G1PatchOptions& patchOptions, const std::optional<std::string>& output);

}  // namespace seam::cli
