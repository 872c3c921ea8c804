// libFuzzer harness: seam's STEP / IGES reader (occt::readCadFile, include/seam/occt/cad_io.h) on arbitrary bytes,
// built twice: fuzz_step (the input written as a .stp file) and fuzz_iges (as an .igs file), SEAM_FUZZ_CAD_EXT.
// OpenCASCADE's readers run uninstrumented (Debian's libraries): the coverage that guides the search is seam's own
// code, and every input goes through OpenCASCADE's parser, transfer and seam's guards (signals, exceptions, counts).
// A refusal is a returned Status; a crash, a hang, a leak in seam's code or a sanitizer report is a bug.
// See docs/reliability.md, "Fuzzing".
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

#include "seam/occt/cad_io.h"

#ifndef SEAM_FUZZ_CAD_EXT
#error "SEAM_FUZZ_CAD_EXT (\".stp\" or \".igs\") must be defined"
#endif

namespace {

/// One file per process, rewritten for every input (the reader takes a path; /dev/shm keeps it in memory).
const std::filesystem::path& inputPath() {
  static const std::filesystem::path path = [] {
    std::filesystem::path dir = "/dev/shm";
    if (!std::filesystem::is_directory(dir)) dir = std::filesystem::temp_directory_path();
    return dir / ("seam-fuzz-" + std::to_string(::getpid()) + SEAM_FUZZ_CAD_EXT);
  }();
  return path;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  {
    std::ofstream out(inputPath(), std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
    if (!out) return 0;  // the disk, not the reader
  }
  const seam::Result<seam::occt::CadImport> cad = seam::occt::readCadFile(inputPath());
  if (cad) (void)cad->model.boundingBox();
  return 0;
}
