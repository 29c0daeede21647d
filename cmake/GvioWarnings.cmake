# gvio_set_warnings(<target>): the project's warning set, errors when GVIO_WERROR is on.
function(gvio_set_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor
                                           -Wold-style-cast -Wcast-align -Wunused -Woverloaded-virtual
                                           -Wdouble-promotion -Wformat=2 -Wimplicit-fallthrough)
  # GCC 12 reports std::string concatenation at -O3 as overlapping memcpy (GCC bug 105329, a false
  # positive inside libstdc++), so -Wrestrict is off for that compiler.
  if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU" AND CMAKE_CXX_COMPILER_VERSION VERSION_LESS 13)
    target_compile_options(${target} PRIVATE -Wno-restrict)
  endif()
  if(GVIO_WERROR)
    target_compile_options(${target} PRIVATE -Werror)
  endif()
endfunction()
