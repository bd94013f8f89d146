# Sanitizer builds (presets asan and tsan). They change how every target in the build is compiled, so they
# are set before any target is declared.
#   GROWBENCH_ASAN  AddressSanitizer and UBSan, UB aborting: the test suite runs under them in CI
#   GROWBENCH_FUZZ  with GROWBENCH_ASAN and clang: the libFuzzer targets in fuzz/ too, and every library
#                   compiled with libFuzzer's coverage instrumentation so that the fuzzer sees the code it
#                   drives. One build serves the ASan tests and the fuzz targets, which CI could not afford
#                   to compile twice.
#   GROWBENCH_TSAN  ThreadSanitizer (the parallel algorithm tests run under it in CI)
if(GROWBENCH_ASAN AND GROWBENCH_TSAN)
  message(FATAL_ERROR "GROWBENCH_ASAN and GROWBENCH_TSAN exclude each other; turn on one")
endif()
if(GROWBENCH_FUZZ AND NOT (GROWBENCH_ASAN AND CMAKE_CXX_COMPILER_ID STREQUAL "Clang"))
  message(FATAL_ERROR "GROWBENCH_FUZZ needs GROWBENCH_ASAN and clang (libFuzzer): cmake --preset asan")
endif()

if(GROWBENCH_ASAN)
  add_compile_options(-fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer)
  add_link_options(-fsanitize=address,undefined)
  if(CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
    add_compile_options(-fsanitize-ignorelist=${CMAKE_CURRENT_LIST_DIR}/sanitizer-ignorelist.txt)
  endif()
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
  # fuzzer-no-link: coverage for the libraries; only the fuzz targets link libFuzzer's main.
  add_compile_options(-fsanitize=fuzzer-no-link)
endif()

# Plugins link with --no-undefined, so that a missing symbol fails at build time rather than at dlopen.
# Under clang's sanitizers the runtime lives in the executable alone, and a plugin's calls into it are
# resolved when the host loads it, so the check cannot apply there.
set(GROWBENCH_PLUGIN_LINK_CHECK -Wl,--no-undefined)
if(CMAKE_CXX_COMPILER_ID STREQUAL "Clang" AND (GROWBENCH_ASAN OR GROWBENCH_TSAN))
  set(GROWBENCH_PLUGIN_LINK_CHECK)
endif()
