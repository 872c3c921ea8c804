// libFuzzer harness: the JSON model loader (io::parseModelJson, docs/format.md) on arbitrary bytes. A refusal is a
// returned Status; a crash, a hang, a leak or a sanitizer report is a bug. See docs/reliability.md, "Fuzzing".
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "seam/io/json.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const seam::Result<seam::Model> model = seam::io::parseModelJson(text, "fuzz.json");
  if (model) (void)model->boundingBox();  // what every command does first with a model
  return 0;
}
