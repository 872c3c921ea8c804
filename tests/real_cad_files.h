#pragma once
// The real STEP/IGES files of ../shared/data (its README), shared by the OpenCASCADE tests.
#include <array>
#include <filesystem>

namespace seam::test {

/// ../shared/data (SEAM_SHARED_DATA_DIR, set by tests/CMakeLists.txt).
inline const std::filesystem::path kData = SEAM_SHARED_DATA_DIR;
/// The real STEP/IGES files, relative to kData.
inline constexpr std::array<const char*, 8> kRealFiles{"step/bug28366_fuselage.stp", "step/trj3_s1-al-214.stp",
                                                       "step/linkrods.step",         "step/boxed_sphere.step",
                                                       "iges/sunglasses_lens.igs",   "iges/BUC50025.igs",
                                                       "iges/occ22470.igs",          "iges/bearing.iges"};

}  // namespace seam::test
