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
