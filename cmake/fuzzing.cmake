# The libFuzzer build (tests/fuzz, tools/fuzz.sh): MCSLAM_FUZZ=ON with clang. Every library is instrumented for
# coverage and built with AddressSanitizer + UBSan; only the fuzz targets link libFuzzer's main.
option(MCSLAM_FUZZ "Build the libFuzzer targets of tests/fuzz (clang only; tools/fuzz.sh)" OFF)
if(NOT MCSLAM_FUZZ)
  return()
endif()
if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
  message(FATAL_ERROR "MCSLAM_FUZZ=ON needs clang (libFuzzer): -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_C_COMPILER=clang")
endif()
if(MCSLAM_SANITIZE)
  message(FATAL_ERROR "MCSLAM_FUZZ=ON brings its own sanitizers: leave MCSLAM_SANITIZE empty")
endif()
set(mcslam_fuzz_sanitizers -fsanitize=address,undefined -fno-sanitize-recover=undefined)
# clang counts sign conversions under -Wconversion (gcc does not): the normal build's warnings are gcc's.
add_compile_options(-fsanitize=fuzzer-no-link ${mcslam_fuzz_sanitizers} -fno-omit-frame-pointer -Wno-sign-conversion)
add_link_options(${mcslam_fuzz_sanitizers})
# As in the ASan build: OpenGV's and other uninstrumented libraries allocate Eigen objects with plain malloc.
add_compile_definitions(EIGEN_MALLOC_ALREADY_ALIGNED=1)
