// Installs occt::readCadFile as the STEP/IGES reader of io::readModel, so that a program linking seam::occt reads
// .step/.stp/.iges/.igs through the core library's readModel (issue 17 §6). The link interface of seam::occt names
// seam_occt_register_reader as undefined, which keeps this object (and its initialiser) in every program linking the
// static library.
#include "seam/io/file.h"
#include "seam/occt/cad_io.h"

namespace {

seam::Result<seam::Model> readCadModel(const std::filesystem::path& file) {
  seam::Result<seam::occt::CadImport> cad = seam::occt::readCadFile(file);
  if (!cad) return cad.status();
  return std::move(cad->model);
}

}  // namespace

// NOLINTNEXTLINE: referenced by name from the link options of seam::occt (CMakeLists.txt)
extern "C" const int seam_occt_register_reader = [] {
  seam::io::registerCadReader(&readCadModel);
  return 1;
}();
