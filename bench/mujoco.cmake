# Optional MuJoCo comparison; included from CMakeLists.txt.
#   nscd_mujoco_compare   a pendulum, a double pendulum, a four-bar and a ball in
#                         nscd_sim and in MuJoCo side by side (bench/mujoco/,
#                         scripts/mujoco_compare.sh, docs/mujoco_comparison.md);
#   test_mujoco_models    (with the tests) the MuJoCo models against ours and against
#                         the engine-free references.
# Needs Debian's libmujoco-dev (2.2.2; `sudo apt-get install libmujoco-dev`), not
# needed by anything else: without it the build skips both targets with one status
# line. Found by hand, not with mujoco's CMake config, which stops the configuration
# with an error when one of its files is missing.
find_path(NSCD_MUJOCO_INCLUDE_DIR mujoco/mujoco.h)
find_library(NSCD_MUJOCO_LIBRARY mujoco)
if(NSCD_MUJOCO_INCLUDE_DIR AND NSCD_MUJOCO_LIBRARY)
  add_library(nscd_mujoco_models STATIC
    ${PROJECT_SOURCE_DIR}/bench/mujoco/compare_models.cpp
    ${PROJECT_SOURCE_DIR}/bench/mujoco/reference_models.cpp
    ${PROJECT_SOURCE_DIR}/bench/mujoco/nscd_runs.cpp
    ${PROJECT_SOURCE_DIR}/bench/mujoco/mujoco_runs.cpp)
  target_include_directories(nscd_mujoco_models PUBLIC ${PROJECT_SOURCE_DIR}/bench/mujoco)
  target_include_directories(nscd_mujoco_models SYSTEM PRIVATE ${NSCD_MUJOCO_INCLUDE_DIR})
  target_link_libraries(nscd_mujoco_models PUBLIC nscd_engine ${NSCD_MUJOCO_LIBRARY})
  target_compile_options(nscd_mujoco_models PRIVATE -Wall -Wextra)

  add_executable(nscd_mujoco_compare ${PROJECT_SOURCE_DIR}/bench/mujoco/mujoco_compare.cpp)
  target_link_libraries(nscd_mujoco_compare nscd_mujoco_models)
  target_compile_definitions(nscd_mujoco_compare PRIVATE NSCD_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
  target_compile_options(nscd_mujoco_compare PRIVATE -Wall -Wextra)
  set_target_properties(nscd_mujoco_compare PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${NSCD_BIN_DIR})

  # The unit tests are declared after this file is included (catkin's gtest).
  function(nscd_mujoco_tests)
    if(NSCD_ROS AND CATKIN_ENABLE_TESTING)
      catkin_add_gtest(test_mujoco_models ${PROJECT_SOURCE_DIR}/bench/mujoco/test_mujoco_models.cpp)
      target_link_libraries(test_mujoco_models nscd_mujoco_models gtest_main)
      target_include_directories(test_mujoco_models SYSTEM PRIVATE ${NSCD_MUJOCO_INCLUDE_DIR})
      target_compile_definitions(test_mujoco_models PRIVATE NSCD_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
    endif()
  endfunction()
  cmake_language(DEFER CALL nscd_mujoco_tests)
  message(STATUS "nscd_sim: MuJoCo found (${NSCD_MUJOCO_LIBRARY}): building nscd_mujoco_compare")
else()
  message(STATUS "nscd_sim: MuJoCo not found (optional; sudo apt-get install libmujoco-dev): no nscd_mujoco_compare")
endif()
