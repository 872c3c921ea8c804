#pragma once
// "expression" patches: a rational surface given by its homogeneous coordinates as expressions in u and v
// (+ - * / ^, sin, cos, exp, log, sqrt, the constant pi), parsed and differentiated symbolically with GiNaC
// (Debian libginac-dev). JSON form (docs/format.md):
//   {"name": "B", "type": "expression", "homogeneous": ["<x>", "<y>", "<z>", "<w>"], "domain": [[u0, u1], [v0, v1]]}
// "w" may be omitted (= 1); "domain" may be omitted ([[0, 1], [0, 1]]). GiNaC stays private to the library.
#include <array>
#include <cstddef>
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

/// Longest expression text accepted (characters, per coordinate).
inline constexpr size_t kMaxExpressionChars = 10000;
/// Deepest nesting of parentheses plus consecutive unary signs accepted (GiNaC's parser recurses per level and
/// overflows the stack at about 10 000 levels).
inline constexpr int kMaxExpressionNesting = 200;
/// Deepest nesting of function calls accepted (sin(cos(exp(...))), sqrt counts): the symbolic derivatives swell
/// with the nesting (`seam gcn --order 8` with sin nested 3, 4, 8 deep: 1.3 s, 2.9 s, more than 60 s).
inline constexpr int kMaxFunctionNesting = 4;

/// Largest exact number, in bits, that an expression may hold or that GiNaC's exact arithmetic may form from its
/// numbers while parsing (2^9999999 or 3^(3^15) take seconds, (1 + 2^-99999)^999 more than 20 s): 65 536 bits,
/// about 19 700 decimal digits, far beyond the range of a double (1e308). Float literals' decimal exponents are
/// limited to the same size (about 19 728). Checked before GiNaC evaluates anything.
inline constexpr int kMaxExpressionNumberBits = 1 << 16;

/// Largest size (expression-tree nodes) accepted for the symbolic derivatives of one order, predicted from the order
/// before: the product rule multiplies the terms (the third derivative of a product of 100 factors took 23 s and
/// 840 MB; the second, 0.5 s). About 2 million nodes, a few tens of MB and a fraction of a second to evaluate.
inline constexpr size_t kMaxDerivativeNodes = size_t{1} << 21;

/// The data of an expression patch as written in the file.
struct ExpressionPatch {
  std::string name;
  std::array<std::string, 4> homogeneous{"0", "0", "0", "1"};  ///< x, y, z, w (w = "1" when omitted)
  Interval u{0.0, 1.0};                                          ///< parameter domain
  Interval v{0.0, 1.0};
};

/// Parses and checks the four expressions (only u, v, pi and the functions above, each called with its argument;
/// anything else is an error naming the patch, the coordinate and the problem or GiNaC's message; an expression
/// beyond kMaxExpressionChars, kMaxExpressionNesting, kMaxFunctionNesting or kMaxExpressionNumberBits is refused
/// before GiNaC evaluates it) and returns the homogeneous surface. Derivatives are symbolic (GiNaC), formed on demand
/// (an order beyond kMaxDerivativeNodes is an error), evaluated in double precision; a point where a value is not
/// finite is an error.
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
