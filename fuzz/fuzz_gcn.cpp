// libFuzzer harness: the gcn expression-model parser (rational::parseModelWithExpressions: JSON with "expression"
// patches, each compiled by GiNaC after seam's length and nesting limits). A refusal is a returned Status; a crash,
// a hang, a leak or a sanitizer report is a bug. See docs/reliability.md, "Fuzzing".
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "seam/rational/expression.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  (void)seam::rational::parseModelWithExpressions(text, "fuzz.json");
  return 0;
}
