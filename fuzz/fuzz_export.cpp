// libFuzzer harness: seam's STEP / IGES writer (occt::writeCadFile, include/seam/occt/cad_io.h) on the models the JSON
// loader accepts from arbitrary bytes (issue 39 §6). The first byte picks the format (even: STEP, odd: IGES), the rest
// is the JSON text. Models above kMaxPoles control points are skipped, so that each input (OpenCASCADE's sewing,
// transfer and seam's read-back check) stays fast: 1 000 inputs in about 15 s. The loader's own limits are
// fuzz_json's work.
// OpenCASCADE runs uninstrumented (Debian's libraries); seam's writer code, its guards (signals, exceptions, the
// read-back comparison) and its error messages are instrumented. A refusal is a returned Status; a crash, a hang, a
// leak in seam's code or a sanitizer report is a bug. See docs/reliability.md, "Fuzzing".
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <system_error>

#include "seam/io/json.h"
#include "seam/occt/cad_io.h"

namespace {

/// The largest model written (control points over all patches and curves).
constexpr long kMaxPoles = 400;

/// One output per process (/dev/shm keeps it in memory).
std::filesystem::path outputPath(const char* ext) {
  std::filesystem::path dir = "/dev/shm";
  if (!std::filesystem::is_directory(dir)) dir = std::filesystem::temp_directory_path();
  return dir / ("seam-fuzz-export-" + std::to_string(::getpid()) + ext);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const bool step = data[0] % 2 == 0;
  const std::string_view text(reinterpret_cast<const char*>(data + 1), size - 1);
  const seam::Result<seam::Model> model = seam::io::parseModelJson(text, "fuzz.json");
  if (!model || model->patches.empty()) return 0;
  long poles = 0;
  for (const seam::Patch& p : model->patches) poles += static_cast<long>(p.surface.numU()) * p.surface.numV();
  for (const seam::Curve& c : model->curves) poles += c.curve.numPoints();
  if (poles > kMaxPoles) return 0;
  const std::filesystem::path out = outputPath(step ? ".stp" : ".igs");
  const seam::Status written =
      seam::occt::writeCadFile(*model, out, step ? seam::occt::CadFormat::kStep : seam::occt::CadFormat::kIges);
  if (!written && written.message().empty()) __builtin_trap();  // every refusal says why
  std::error_code ec;
  std::filesystem::remove(out, ec);
  return 0;
}
