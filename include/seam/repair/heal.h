#pragma once
// `seam heal`: the whole-model version of `seam join`, like CATIA Healing but with a certified verdict. Every seam
// found by the model check's pairing whose gap is below maxGap and whose continuity is below the requested one is
// joined; patches are processed in breadth-first order from the first patch of each group of connected seams (the
// successive joins of Lai-Lian-Cassidy §4.1: each patch moves once, onto all of its already settled neighbours at
// the same time, corners included). A patch's edge that is already joined to a neighbour that has not moved yet is
// locked (never moved); one whose neighbour has settled stays a constraint of the solve, so it remains joined.
// Patches that need not move are bit-identical in the output. Every seam is reported before and after.
#include <optional>
#include <string>
#include <vector>

#include "seam/continuity/seam.h"
#include "seam/core/result.h"
#include "seam/core/tolerances.h"
#include "seam/model/model.h"

namespace seam {

struct HealOptions {
  GeometricClass continuity = GeometricClass::kG1;  ///< G0 or G1 (G2: use `seam join` seam by seam)
  /// Seams with a larger gap are left alone (default kDefaultMaxGapRel x the model's bounding-box diagonal).
  std::optional<double> maxGap;
  /// Classification tolerances (default Tolerances::forModelSize(diagonal)).
  std::optional<Tolerances> tolerances;
  SeamOptions seam;  ///< analysis settings (its `tol` is replaced by the tolerances above)
};

struct HealSeam {
  std::string a, b;
  Edge aEdge = Edge::U0, bEdge = Edge::U0;
  SeamReport before;
  std::optional<SeamReport> after;  ///< empty when the analysis failed after healing
  std::string moved;                ///< the patch that moved to meet this seam ("" if none did)
  /// "kept" (already at the requested continuity), "joined", "skipped" (gap above maxGap), "failed".
  std::string action;
  bool achieved = false;            ///< after.geometric meets the requested continuity
  std::vector<std::string> notes;
};

struct HealReport {
  GeometricClass requested = GeometricClass::kG1;
  double maxGap = 0.0;
  std::vector<HealSeam> seams;
  std::vector<std::string> order;           ///< the patches in the order they moved
  std::vector<std::string> patchesChanged;
  double maxDisplacement = 0.0;
  int movedPoints = 0;
  GeometricClass worst = GeometricClass::kG2;  ///< worst geometric class over the seams after healing
  double worstG0 = 0.0, worstG1Deg = 0.0;      ///< worst values after healing
  bool achieved = false;                        ///< every seam within maxGap meets the requested continuity
  std::vector<std::string> notes;
};

struct HealResult {
  Model model;
  HealReport report;
};

/// Heals the model. Errors: kInvalidInput (no patches, a non-3-D patch, continuity other than G0/G1), and those of
/// the pairing (continuity/model_check.h). Seams that cannot be joined are reported, not errors.
Result<HealResult> healModel(const Model& model, const HealOptions& options = {});

}  // namespace seam
