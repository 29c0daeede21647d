# Instrumented builds (./setup.sh sanitize and ./setup.sh fuzz use their own build folder):
#   GVIO_SANITIZE="address,undefined": every target compiled and linked with it; a
#     sanitizer report stops the program (no recovery), so a test that triggers one fails.
#   GVIO_FUZZ=ON: every target also carries libFuzzer's coverage instrumentation and the fuzz
#     targets in tests/fuzz are built (clang only: GCC has no libFuzzer).
set(GVIO_SANITIZE "" CACHE STRING "Sanitizers for every target, e.g. address,undefined (empty: none)")
option(GVIO_FUZZ "Build the libFuzzer targets (clang)" OFF)

if(GVIO_SANITIZE)
  add_compile_options(-fsanitize=${GVIO_SANITIZE} -fno-sanitize-recover=all
                      -fno-omit-frame-pointer -gline-tables-only)
  add_link_options(-fsanitize=${GVIO_SANITIZE})
endif()

if(GVIO_FUZZ)
  if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
    message(FATAL_ERROR "GVIO_FUZZ needs clang (CXX=clang++-14): GCC has no libFuzzer")
  endif()
  add_compile_options(-fsanitize=fuzzer-no-link)
endif()
