#pragma once
// "expression" patches: a rational surface given by its homogeneous coordinates as expressions in u and v
// (+ - * / ^, sin, cos, exp, log, sqrt, the constant pi), parsed and differentiated symbolically with GiNaC
// (Debian libginac-dev). JSON form (docs/format.md):
//   {"name": "B", "type": "expression", "homogeneous": ["<x>", "<y>", "<z>", "<w>"], "domain": [[u0, u1], [v0, v1]]}
// "w" may be omitted (= 1); "domain" may be omitted ([[0, 1], [0, 1]]). GiNaC stays private to the library.
#include <array>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "seam/core/result.h"
#include "seam/model/model.h"
#include "seam/rational/homogeneous_surface.h"

namespace seam::rational {

/// Derivative orders available from an expression surface (symbolic derivatives are formed on demand, up to this).
inline constexpr int kMaxExpressionOrder = 10;

/// The data of an expression patch as written in the file.
struct ExpressionPatch {
  std::string name;
  std::array<std::string, 4> homogeneous{"0", "0", "0", "1"};  ///< x, y, z, w (w = "1" when omitted)
  Interval u{0.0, 1.0};                                          ///< parameter domain
  Interval v{0.0, 1.0};
};

/// Parses and checks the four expressions (only u, v, pi and the functions above; anything else is an error
/// naming the patch, the coordinate and GiNaC's message) and returns the homogeneous surface. Derivatives are
/// symbolic (GiNaC), evaluated in double precision; a point where a value is not finite is an error.
Result<HomogeneousSurface> compileExpressionPatch(const ExpressionPatch& patch);

/// A model plus its expression patches. Until the JSON reader of seam::io knows the "expression" type (see
/// docs/algorithms/zheng-wang-liang.md, "Integration"), the expression entries are taken out of "patches" here and
/// the rest is read by io::parseModelJson. Names are unique across both kinds.
struct ModelWithExpressions {
  Model model;
  std::vector<ExpressionPatch> expressions;
  [[nodiscard]] const ExpressionPatch* findExpression(const std::string& name) const;
};

/// Reads a .json model with expression patches (other extensions: io::readModel, no expression patches).
/// kIoError / kInvalidInput with messages naming the file and the patch.
Result<ModelWithExpressions> readModelWithExpressions(const std::filesystem::path& file);
/// Same from JSON text; `source` names the input in messages.
Result<ModelWithExpressions> parseModelWithExpressions(std::string_view text, std::string_view source);

}  // namespace seam::rational
