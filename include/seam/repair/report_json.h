#pragma once
// JSON text of seam records and of join/heal reports, for `seam join --json` and `seam heal --json`.
//
// The seam record has the layout of one element of "seams" in `seam check --json` (issue 3, §6):
//   {"a", "a_edge", "b", "b_edge", "overlap": [t0, t1], "g0_max", "g1_max_deg", "g2_max", "g2_rel_max",
//    "lambda_range": [lo, hi], "kappa_range": [lo, hi], "geometric", "parametric", "certified",
//    "worst": {"g0": {"t", "point"}, "g1": {...}, "g2": {...}},
//    then the further keys of apps/seam/cmd_check.cpp: "overlap_b", "reversed", "correspondence", "g0_sampled",
//    "g1_sampled_deg", "g2_sampled", "g2_rel_sampled", "g2_residual_max", "c1_mismatch", "c2_mismatch", "notes"}
// (written here because the serialiser of `seam check` is file-local to cmd_check.cpp; it could move to the library
// and both commands share it). Non-finite numbers are written as null. The text is compact; callers re-indent it.
#include <string>

#include "seam/continuity/seam.h"
#include "seam/repair/corner_join.h"
#include "seam/repair/heal.h"
#include "seam/repair/join.h"

namespace seam {

/// One seam record, as in `seam check --json`.
std::string seamRecordJson(const SeamReport& report);

/// {"method", "reason", "proportional_knots", "requested", "achieved", "before", "after", "max_displacement",
///  "moved_points", "patches_changed", "inserted_knots": {"u", "v"}, "elevated": [du, dv], "lambda_min",
///  "strip": {"junctions": [...], "internal_g1_max_deg"}, "notes"}
std::string joinReportJson(const JoinReport& report);

/// {"requested", "method", "max_gap", "seams": [{"before", "after" (seam records or null), "certified_before",
///  "certified_after", "region", "action", "moved", "achieved", "worse", "notes"}], "regions": [{"patches", "seams",
///  "seams_achieved", "method": "successive"|"local"|"none", "achieved", "note"}], "steps": [{"patch", "region",
///  "accepted", "reason", "notes"}], "steps_reverted", "order", "patches_changed", "patches": [{"name", "region",
///  "size", "max_displacement", "moved_points", "max_surface_displacement", "max_surface_displacement_rel",
///  "max_surface_displacement_sampled", "surface_displacement_certified"}], "max_displacement", "moved_points",
///  "max_surface_displacement", "max_surface_displacement_rel", "surface_displacement_certified", "seams_to_reach",
///  "seams_achieved", "seams_worse", "worst": {"geometric", "g0_max", "g1_max_deg"}, "achieved", "notes"}
std::string healReportJson(const HealReport& report);

/// A §4.1 corner join (`seam corner --json`): {"layout": "three"|"four", "proportionality": {"all_hold",
///  "theorem1_for_hat" (three only), "conditions": [{"name", "statement", "residual", "tolerance", "holds", "detail"}],
///  "chain_ratios", and for three patches "m", "m_tilde", "n", "n_tilde", "q", "corner_index", "n_hat1", "n_hat2"}
///  or null when a patch is not C1 bicubic, "steps": [{"moved", "onto", "method", "reason", "max_displacement",
///  "moved_points", "notes"}], "seams": [{"after": <seam record>, "achieved"}], "achieved", "max_displacement",
///  "worst": {"g0_max", "g1_max_deg"}, "notes"}
std::string threePatchJoinJson(const ThreePatchJoinResult& result);
std::string fourPatchJoinJson(const FourPatchJoinResult& result);

}  // namespace seam
