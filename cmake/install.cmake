# `cmake --install BUILD --prefix P`: the growbench binary, the plugin SDK (headers and a CMake package
# with growbench_add_plugin), and the data files the binary and its report read.
#
# Components, so the SDK can be installed from a configured tree before growbench is built:
#   runtime  bin/growbench and share/growbench/ (report scripts, schema, bundled meshes, L-system
#            example grammars, suites)
#   sdk      include/growbench/plugin.h, plugin.hpp and lib/cmake/growbench/
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

install(TARGETS growbench RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT runtime)
# The Python bridge, which the binary finds at lib/growbench beside its bin/ (core/data_path.hpp).
install(TARGETS python_bridge LIBRARY DESTINATION lib/growbench COMPONENT runtime)

# The data keeps the checkout's layout under share/growbench: report.py finds the results schema and
# docs/metrics.md relative to itself, and the binary (core/data_path.hpp) reads from here once the
# checkout it was built from is gone.
set(GROWBENCH_INSTALL_DATADIR ${CMAKE_INSTALL_DATADIR}/growbench)
install(FILES reports/report.py reports/paper_tables.py reports/viewer.py reports/explore.py reports/history.py
              reports/history_view.py DESTINATION ${GROWBENCH_INSTALL_DATADIR}/reports COMPONENT runtime)
# The report's 3D viewer, as scripts/install-deps built it (reports/viewer.py finds it relative to itself);
# without it, reports have no 3D views and say why.
install(DIRECTORY tools/viewer/dist/ DESTINATION ${GROWBENCH_INSTALL_DATADIR}/tools/viewer/dist COMPONENT runtime
        OPTIONAL)
install(FILES harness/record/results.schema.json DESTINATION ${GROWBENCH_INSTALL_DATADIR}/harness/record
        COMPONENT runtime)
install(FILES docs/metrics.md DESTINATION ${GROWBENCH_INSTALL_DATADIR}/docs COMPONENT runtime)
install(DIRECTORY scenes/meshes/ DESTINATION ${GROWBENCH_INSTALL_DATADIR}/scenes/meshes COMPONENT runtime
        FILES_MATCHING PATTERN "*.obj" PATTERN "*.md")
install(DIRECTORY algorithms/lsystem/examples/ DESTINATION ${GROWBENCH_INSTALL_DATADIR}/algorithms/lsystem/examples
        COMPONENT runtime FILES_MATCHING PATTERN "*.lsys")
install(DIRECTORY bench/suites/ DESTINATION ${GROWBENCH_INSTALL_DATADIR}/suites COMPONENT runtime
        FILES_MATCHING PATTERN "*.json")

install(FILES include/growbench/plugin.h include/growbench/plugin.hpp
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/growbench COMPONENT sdk)

# The ABI version the headers declare, so a plugin's build can check it without compiling anything.
file(STRINGS include/growbench/plugin.h _gb_abi_line REGEX "^#define GROWBENCH_PLUGIN_ABI_VERSION ")
string(REGEX REPLACE "^#define GROWBENCH_PLUGIN_ABI_VERSION ([0-9]+)u.*" "\\1" GROWBENCH_PLUGIN_ABI_VERSION
                     "${_gb_abi_line}")

set(GROWBENCH_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/growbench)
configure_package_config_file(cmake/growbenchConfig.cmake.in ${PROJECT_BINARY_DIR}/growbenchConfig.cmake
                              INSTALL_DESTINATION ${GROWBENCH_INSTALL_CMAKEDIR}
                              PATH_VARS CMAKE_INSTALL_INCLUDEDIR CMAKE_INSTALL_BINDIR GROWBENCH_INSTALL_DATADIR)
# Whether a plugin loads is decided at load time by GROWBENCH_PLUGIN_ABI_VERSION, not by this version;
# it only lets a project ask for a release line. Not arch-independent: a plugin must match the binary.
write_basic_package_version_file(${PROJECT_BINARY_DIR}/growbenchConfigVersion.cmake VERSION ${PROJECT_VERSION}
                                 COMPATIBILITY SameMajorVersion)
install(FILES ${PROJECT_BINARY_DIR}/growbenchConfig.cmake ${PROJECT_BINARY_DIR}/growbenchConfigVersion.cmake
        DESTINATION ${GROWBENCH_INSTALL_CMAKEDIR} COMPONENT sdk)
