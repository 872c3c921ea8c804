function(seam_set_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wshadow -Wconversion -Wno-sign-conversion)
  if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU" AND CMAKE_CXX_COMPILER_VERSION VERSION_LESS 13)
    # GCC 12 reports -Wrestrict inside libstdc++'s std::string for code that has no overlap (GCC bug 105329).
    target_compile_options(${target} PRIVATE -Wno-restrict)
  endif()
  if(SEAM_WERROR)
    target_compile_options(${target} PRIVATE -Werror)
  endif()
endfunction()

# Code whose speed matters less (the tests' own code, the CLI's and the JSON builders' glue: most of the work is done
# in the library) is compiled at -Og in the sanitizer build, the library itself at -O1. Under -fsanitize=address,
# undefined, model_check_test.cpp took 77 s to compile at -O1 and 41 s at -Og (heal_test.cpp: 91 s at -O1, 35 s at
# -O0). -O0 was tried first and is slower in all: tests whose independent oracles are brute force in the test's own
# code ran 10x longer (ModelCheck.GridPairingMatchesBruteForce: 172 s at -O0, 18 s at -Og). docs/reliability.md,
# "CI time and the sanitizer build".
function(seam_sanitized_glue target)
  if(SEAM_SANITIZE)
    target_compile_options(${target} PRIVATE -Og)
  endif()
endfunction()

# The tests' own code in an optimised (Release) build: -O1 instead of the build type's -O3. A test file spends its
# compile time on gtest's and Eigen's templates, not on hot loops (tests/join_test.cpp: 47 s at -O3, 34 s at -O1,
# 21 s for the front end alone); the library it tests keeps its -O3. docs/reliability.md, "CI time".
function(seam_test_optimization target)
  if(NOT SEAM_SANITIZE AND NOT SEAM_FUZZ AND CMAKE_CXX_COMPILER_ID MATCHES "GNU|Clang")
    target_compile_options(${target} PRIVATE $<$<NOT:$<CONFIG:Debug>>:-O1>)
    if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
      # GCC 12 at -O1 reports Eigen's fixed-size storage as maybe uninitialised (model_check_test, seam_test), a
      # false positive that -O3's inlining hides.
      target_compile_options(${target} PRIVATE -Wno-maybe-uninitialized)
    endif()
  endif()
endfunction()

# Precompiled headers (SEAM_PRECOMPILED_HEADERS, default on) for the tests and the CLI: the third-party and standard
# headers that most of their files include (gtest, Eigen, nlohmann::json, fmt, CLI11), parsed once per target instead
# of once per file. Parsing them was about 8 of a test file's 47 s. Only third-party headers: a change to a seam header
# rebuilds the files that include it, not every file of the target. Not for the library, whose files spend their time
# in the optimiser, and where GCC 12 with a precompiled header reports -Warray-bounds/-Wstringop-overflow false
# positives from inside libstdc++ (src/continuity/corner.cpp, seam.cpp, report.cpp) that it does not report without
# one. Turn off to check that every file includes what it uses.
option(SEAM_PRECOMPILED_HEADERS "Precompile the common third-party headers of each target" ON)
function(seam_precompile target)
  if(SEAM_PRECOMPILED_HEADERS AND NOT SEAM_FUZZ)
    target_precompile_headers(${target} PRIVATE ${ARGN})
    target_compile_options(${target} PRIVATE -Winvalid-pch)  # says so when a precompiled header cannot be used
  endif()
endfunction()
