# All dependencies are Debian packages (see scripts/setup.sh).
find_package(Eigen3 3.4 REQUIRED NO_MODULE)
find_package(nlohmann_json 3.10 REQUIRED)
find_package(fmt REQUIRED)
find_package(TBB REQUIRED)  # parallel seam analysis in checkModel
find_package(simdjson 3 REQUIRED)  # the fast route of the JSON model reader (src/io/json.cpp)

# GLPK ships no CMake config: wrap it in an imported target.
find_path(GLPK_INCLUDE_DIR glpk.h REQUIRED)
find_library(GLPK_LIBRARY glpk REQUIRED)
find_path(GMP_INCLUDE_DIR gmpxx.h REQUIRED)
find_library(GMP_LIBRARY gmp REQUIRED)
find_library(GMPXX_LIBRARY gmpxx REQUIRED)
add_library(seam_glpk INTERFACE)
target_include_directories(seam_glpk SYSTEM INTERFACE ${GLPK_INCLUDE_DIR} ${GMP_INCLUDE_DIR})
target_link_libraries(seam_glpk INTERFACE ${GLPK_LIBRARY} ${GMPXX_LIBRARY} ${GMP_LIBRARY})
install(TARGETS seam_glpk EXPORT seamTargets)

# GiNaC (symbolic expressions of "expression" patches) and Boost headers (autodiff), issue 6.
find_package(PkgConfig REQUIRED)
pkg_check_modules(GINAC REQUIRED IMPORTED_TARGET ginac)
find_package(Boost 1.74 REQUIRED)
add_library(seam_symbolic INTERFACE)
target_link_libraries(seam_symbolic INTERFACE PkgConfig::GINAC Boost::headers)
install(TARGETS seam_symbolic EXPORT seamTargets)

if(SEAM_SANITIZE)
  add_compile_options(-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined)
  add_link_options(-fsanitize=address,undefined)
endif()
# Determinism: no contraction of a*b+c into fma, so results do not depend on -march.
add_compile_options(-ffp-contract=off)
