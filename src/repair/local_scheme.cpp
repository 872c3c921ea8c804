// The local G1 scheme (see seam/repair/local_scheme.h). Work in progress: being implemented.
#include "seam/repair/local_scheme.h"

namespace seam {

Result<LocalSchemeResult> localG1Scheme(const Model& model, const LocalSchemeOptions& options) {
  (void)model;
  (void)options;
  return Status(ErrorCode::kUnsupported, "the local scheme is not implemented yet");
}

}  // namespace seam
