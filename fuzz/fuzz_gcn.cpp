// libFuzzer harness: the gcn expression-model parser (rational::parseModelWithExpressions: JSON with "expression"
// patches, each compiled by GiNaC after seam's length, nesting and number-size limits), then each expression patch's
// symbolic derivatives up to second order at its domain's centre (the derivative-size limit). A refusal is a
// returned Status; a crash, a hang, a leak or a sanitizer report is a bug. See docs/reliability.md, "Fuzzing".
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "seam/rational/expression.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const auto model = seam::rational::parseModelWithExpressions(text, "fuzz.json");
  if (!model) return 0;
  for (const seam::rational::ExpressionPatch& patch : model->expressions) {
    const auto surface = seam::rational::compileExpressionPatch(patch);
    if (surface) (void)surface->derivatives(0.5 * (patch.u.lo + patch.u.hi), 0.5 * (patch.v.lo + patch.v.hi), 2);
  }
  return 0;
}
