// libFuzzer harness: the Newell .bpt loader (io::parseBpt, include/seam/io/bpt.h) on arbitrary bytes. A refusal is a
// returned Status; a crash, a hang, a leak or a sanitizer report is a bug. See docs/reliability.md, "Fuzzing".
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "seam/io/bpt.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const seam::Result<seam::Model> model = seam::io::parseBpt(text, "fuzz.bpt");
  if (model) (void)model->boundingBox();
  return 0;
}
