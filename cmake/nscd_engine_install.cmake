# `cmake --install` without ROS (included by CMakeLists.txt when NSCD_ROS is off):
#   bin/nscd_run, bin/nscd_sweep
#   lib/libnscd_engine.a (.so with -DBUILD_SHARED_LIBS=ON), include/nscd_sim/*.hpp
#   lib/cmake/nscd_engine/  the package config: find_package(nscd_engine) gives the
#                           target nscd_engine::nscd_engine
#   lib/python3/dist-packages/nscd_sim/  the Python package (NSCD_PYTHON_INSTALL_DIR)
#   share/nscd_sim/urdf, share/nscd_sim/config  the example scenes and settings files
# (lib is CMAKE_INSTALL_LIBDIR: lib/x86_64-linux-gnu under /usr on Debian.)
include(CMakePackageConfigHelpers)

target_include_directories(nscd_engine PUBLIC $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)

# The version of package.xml, the package's one version.
file(STRINGS ${PROJECT_SOURCE_DIR}/package.xml nscd_version_line REGEX "<version>")
string(REGEX REPLACE ".*<version>([0-9.]+)</version>.*" "\\1" NSCD_VERSION "${nscd_version_line}")

get_target_property(nscd_engine_type nscd_engine TYPE)
if(nscd_engine_type STREQUAL "SHARED_LIBRARY")
  # Installed binaries find the engine beside them wherever the prefix goes.
  file(RELATIVE_PATH nscd_bin_to_lib /${CMAKE_INSTALL_BINDIR} /${CMAKE_INSTALL_LIBDIR})
  file(RELATIVE_PATH nscd_py_to_lib /${NSCD_INSTALL_PYTHONDIR} /${CMAKE_INSTALL_LIBDIR})
  set_target_properties(nscd_run nscd_sweep PROPERTIES INSTALL_RPATH "$ORIGIN/${nscd_bin_to_lib}")
  if(TARGET nscd_sim_python)
    set_target_properties(nscd_sim_python PROPERTIES INSTALL_RPATH "$ORIGIN/${nscd_py_to_lib}")
  endif()
  set(NSCD_ENGINE_STATIC OFF)
else()
  set(NSCD_ENGINE_STATIC ON)  # its consumers link the parsers themselves
endif()

install(TARGETS nscd_engine EXPORT nscd_engineTargets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
  INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(TARGETS nscd_run RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})  # nscd_sweep: bench/performance.cmake
install(DIRECTORY ${PROJECT_SOURCE_DIR}/include/nscd_sim DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(DIRECTORY ${PROJECT_SOURCE_DIR}/urdf DESTINATION ${CMAKE_INSTALL_DATADIR}/nscd_sim)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/config DESTINATION ${CMAKE_INSTALL_DATADIR}/nscd_sim
  FILES_MATCHING PATTERN "*.yaml")  # the settings files (the .rviz files are the node's)

set(nscd_config_dir ${CMAKE_INSTALL_LIBDIR}/cmake/nscd_engine)
install(EXPORT nscd_engineTargets NAMESPACE nscd_engine:: DESTINATION ${nscd_config_dir})
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/nscd_engineConfig.cmake.in
  ${CMAKE_BINARY_DIR}/nscd_engineConfig.cmake INSTALL_DESTINATION ${nscd_config_dir}
  PATH_VARS CMAKE_INSTALL_BINDIR)
write_basic_package_version_file(${CMAKE_BINARY_DIR}/nscd_engineConfigVersion.cmake
  VERSION ${NSCD_VERSION} COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_BINARY_DIR}/nscd_engineConfig.cmake ${CMAKE_BINARY_DIR}/nscd_engineConfigVersion.cmake
  DESTINATION ${nscd_config_dir})
