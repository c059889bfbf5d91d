# Optional comparison targets; included from CMakeLists.txt.
#   nscd_siconos_compare  the ball and the planar clearance pendulum in nscd_sim and
#                         in Siconos, side by side (needs the Siconos kernel);
#   nscd_fclib            solves FCLib HDF5 friction-contact problems with our solver
#                         (needs libfclib-dev and libhdf5-dev; with Siconos numerics it also runs
#                         Siconos's fc3d solvers and converts Siconos .dat problems).
# scripts/install_siconos.sh installs the Debian packages. Nothing here is required:
# a missing or unusable package only skips its target, with one status line.
#
# Everything runs inside a function because siconos-config sets variables for its
# caller (CMAKE_CXX_STANDARD 11); imported targets are still visible to the
# directory. FCLib and HDF5 are found by tools/fclib/fclib_libraries.cmake.
function(nscd_optional_siconos_targets)
  # Imported targets must not point at missing files: CMake would stop with an error.
  function(nscd_target_usable target out)
    set(ok TRUE)
    if(NOT TARGET ${target})
      set(ok FALSE)
    else()
      get_target_property(dirs ${target} INTERFACE_INCLUDE_DIRECTORIES)
      get_target_property(libs ${target} INTERFACE_LINK_LIBRARIES)
      foreach(item IN LISTS dirs libs)
        if(item MATCHES "^/" AND NOT EXISTS "${item}")
          set(ok FALSE)
        elseif(item MATCHES "::" AND NOT TARGET "${item}")
          set(ok FALSE)
        endif()
      endforeach()
    endif()
    set(${out} ${ok} PARENT_SCOPE)
  endfunction()

  set(cxx_standard ${CMAKE_CXX_STANDARD})
  find_package(Boost QUIET)  # Siconos::kernel links Boost::boost
  find_package(siconos CONFIG QUIET)
  set(CMAKE_CXX_STANDARD ${cxx_standard})  # the targets below keep the project's standard
  include(${PROJECT_SOURCE_DIR}/tools/fclib/fclib_libraries.cmake)

  set(have_kernel FALSE)
  set(have_numerics FALSE)
  if(siconos_FOUND)
    nscd_target_usable(Siconos::numerics have_numerics)
    nscd_target_usable(Siconos::kernel have_kernel)
  endif()
  set(have_fclib ${NSCD_FCLIB_FOUND})

  set(bin_dir ${NSCD_BIN_DIR})
  if(have_kernel AND have_numerics)
    add_executable(nscd_siconos_compare
      ${PROJECT_SOURCE_DIR}/bench/siconos/siconos_compare.cpp
      ${PROJECT_SOURCE_DIR}/bench/siconos/siconos_models.cpp
      ${PROJECT_SOURCE_DIR}/bench/siconos/nscd_models.cpp)
    target_include_directories(nscd_siconos_compare PRIVATE ${PROJECT_SOURCE_DIR}/test)
    target_link_libraries(nscd_siconos_compare nscd_engine Siconos::kernel Siconos::numerics)
    target_compile_options(nscd_siconos_compare PRIVATE -Wall -Wextra)
    set_target_properties(nscd_siconos_compare PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${bin_dir})
    message(STATUS "nscd_sim: Siconos ${siconos_VERSION} found: building nscd_siconos_compare")
  else()
    message(STATUS "nscd_sim: Siconos kernel not found (optional): no nscd_siconos_compare")
  endif()

  if(have_fclib)
    add_executable(nscd_fclib ${PROJECT_SOURCE_DIR}/tools/fclib/nscd_fclib.cpp
      ${PROJECT_SOURCE_DIR}/tools/fclib/condense_problem.cpp ${NSCD_FCLIB_READER_SOURCES})
    target_include_directories(nscd_fclib SYSTEM PRIVATE ${NSCD_FCLIB_INCLUDE_DIRS})
    target_link_libraries(nscd_fclib nscd_engine ${NSCD_FCLIB_LIBRARIES})
    if(have_numerics)
      target_link_libraries(nscd_fclib Siconos::numerics)
      target_compile_definitions(nscd_fclib PRIVATE NSCD_WITH_SICONOS)
    endif()
    target_compile_options(nscd_fclib PRIVATE -Wall -Wextra)
    set_target_properties(nscd_fclib PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${bin_dir})
    message(STATUS "nscd_sim: FCLib found: building nscd_fclib (Siconos solvers: ${have_numerics})")
    if(NSCD_ROS AND CATKIN_ENABLE_TESTING)  # its reader of FCLib files
      catkin_add_gtest(test_fclib_reader ${PROJECT_SOURCE_DIR}/tools/fclib/test_fclib_reader.cpp
        ${NSCD_FCLIB_READER_SOURCES})
      target_include_directories(test_fclib_reader PRIVATE ${PROJECT_SOURCE_DIR}/tools/fclib)
      target_include_directories(test_fclib_reader SYSTEM PRIVATE ${NSCD_FCLIB_INCLUDE_DIRS})
      target_link_libraries(test_fclib_reader ${NSCD_FCLIB_LIBRARIES} Eigen3::Eigen gtest_main)
      target_compile_definitions(test_fclib_reader PRIVATE NSCD_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
    endif()
  else()
    message(STATUS "nscd_sim: FCLib not found (optional): no nscd_fclib")
  endif()
endfunction()

nscd_optional_siconos_targets()
