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

# Code whose speed does not matter (the tests' own code, the CLI's and the JSON builders' glue: the work is done in
# the library) is compiled without optimisation in the sanitizer build. At -O1 the heaviest test file took 91 s to
# compile under -fsanitize=address,undefined, at -O0 35 s (docs/reliability.md "CI time and the sanitizer build");
# the library itself keeps -O1, so the sanitized suite runs at the same speed.
function(seam_sanitized_glue target)
  if(SEAM_SANITIZE)
    target_compile_options(${target} PRIVATE -O0)
  endif()
endfunction()
