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
if(GROWBENCH_TSAN)
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
