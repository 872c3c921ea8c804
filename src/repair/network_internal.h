#pragma once
// Shared set-up of the network repairs (the local G1 scheme, the G2 network solve): the chosen patches checked, the
// model's size, classification tolerances and pairing distance resolved from the options.
#include <fmt/format.h>

#include <algorithm>
#include <numeric>
#include <optional>
#include <utility>
#include <vector>

#include "seam/core/result.h"
#include "seam/core/tolerances.h"
#include "seam/model/model.h"
#include "seam/repair/join.h"
#include "seam/repair/local_scheme.h"
#include "seam/spline/bspline_surface.h"

namespace seam {

/// The corner (cu, cv) (0: low, 1: high parameter) at an end of an edge (end 0: the low parameter end).
inline std::pair<int, int> cornerOf(Edge e, int end) {
  switch (e) {
    case Edge::U0: return {0, end};
    case Edge::U1: return {1, end};
    case Edge::V0: return {end, 0};
    case Edge::V1: return {end, 1};
  }
  return {0, 0};
}

struct NetworkSetup {
  std::vector<int> chosen;  ///< sorted, unique model patch indices (every patch when the request was empty)
  double diagonal = 1.0;    ///< the model's bounding-box diagonal (1 for an empty box)
  Tolerances tol;
  double maxGap = 0.0;
};

/// Errors: kInvalidInput for a model without patches, a non-3-D patch or an index out of range.
inline Result<NetworkSetup> networkSetup(const Model& model, const std::vector<int>& patches,
                                         const std::optional<Tolerances>& tolerances,
                                         const std::optional<double>& maxGap) {
  if (model.patches.empty()) return invalidInput("the model has no patches");
  NetworkSetup s;
  s.chosen = patches;
  if (s.chosen.empty()) {
    s.chosen.resize(model.patches.size());
    std::iota(s.chosen.begin(), s.chosen.end(), 0);
  }
  std::sort(s.chosen.begin(), s.chosen.end());
  s.chosen.erase(std::unique(s.chosen.begin(), s.chosen.end()), s.chosen.end());
  for (int p : s.chosen)
    if (p < 0 || p >= static_cast<int>(model.patches.size()))
      return invalidInput(fmt::format("patch index {} out of range", p));
  for (const Patch& p : model.patches)
    if (p.surface.dim() != 3) return invalidInput(fmt::format("patch \"{}\" is not 3-D", p.name));
  s.diagonal = model.boundingBox().diagonal();
  if (!(s.diagonal > 0.0)) s.diagonal = 1.0;
  s.tol = tolerances ? *tolerances : Tolerances::forModelSize(s.diagonal);
  s.maxGap = maxGap ? *maxGap : kDefaultMaxGapRel * s.diagonal;
  return s;
}

namespace detail {

/// localG1Scheme, and per patch it wrote (model index) the input patch in the output's knots and degrees (its exact
/// biquintic form, what detail::expressedLike(input, output) gives, bit for bit): heal measures the displacement
/// against it instead of raising and refining the input a second time. `inputForms` may be nullptr.
Result<LocalSchemeResult> localG1Scheme(const Model& model, const LocalSchemeOptions& options,
                                        std::vector<std::pair<int, BSplineSurface>>* inputForms);

}  // namespace detail

}  // namespace seam
