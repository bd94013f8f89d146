# Sanitizer builds, one option each (presets asan, tsan, fuzz). They change how every target in the build
# is compiled, so they are set before any target is declared, and at most one may be on.
#   GROWBENCH_ASAN  AddressSanitizer and UBSan (the test suite runs under them in CI)
#   GROWBENCH_TSAN  ThreadSanitizer (the parallel algorithm tests run under it in CI)
#   GROWBENCH_FUZZ  the libFuzzer targets in fuzz/ (clang only): every library is compiled with coverage
#                   instrumentation as well as ASan and UBSan, so that the fuzzer sees the code it drives
#                   and a bad access there is a finding; UB aborts rather than printing and going on
set(_gb_sanitizers 0)
foreach(_gb_option GROWBENCH_ASAN GROWBENCH_TSAN GROWBENCH_FUZZ)
  if(${_gb_option})
    math(EXPR _gb_sanitizers "${_gb_sanitizers} + 1")
  endif()
endforeach()
if(_gb_sanitizers GREATER 1)
  message(FATAL_ERROR "GROWBENCH_ASAN, GROWBENCH_TSAN and GROWBENCH_FUZZ exclude each other; turn on one")
endif()

if(GROWBENCH_ASAN)
  add_compile_options(-fsanitize=address,undefined -fno-omit-frame-pointer)
  add_link_options(-fsanitize=address,undefined)
endif()
# TSan sees only the synchronization of instrumented code, and TBB's (spawn, steal, join) is in libtbb:
# preset tsan links the libtbb that scripts/tsan-tbb builds with TSan (its directory goes in the rpath,
# and OpenVDB and Embree, which need the same libtbb.so.12, get the one already loaded). g++, not clang:
# g++'s TSan runtime is a shared library, linked by that libtbb and by our plugins (which refuse undefined
# symbols) as well as by the executables; clang links its runtime into executables only, and its shared
# runtime (-shared-libsan) crashes at start with Debian's clang 14.
if(GROWBENCH_TSAN)
  if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "GNU" OR NOT EXISTS "${TBB_DIR}/../../../growbench-stamp")
    message(FATAL_ERROR "GROWBENCH_TSAN needs g++ and the TBB of scripts/tsan-tbb: scripts/sanitize tsan")
  endif()
  add_compile_options(-fsanitize=thread)
  add_link_options(-fsanitize=thread)
endif()
if(GROWBENCH_FUZZ)
  if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
    message(FATAL_ERROR "GROWBENCH_FUZZ needs clang (libFuzzer): cmake --preset fuzz")
  endif()
  # fuzzer-no-link: coverage for the libraries; only the fuzz targets link libFuzzer's main.
  add_compile_options(-fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=undefined
                      -fno-omit-frame-pointer)
  add_link_options(-fsanitize=address,undefined)
endif()
