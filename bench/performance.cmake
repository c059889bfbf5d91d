# Performance tooling: the sweep runner, the stress suite and soak, the
# work-precision benchmark. Included by CMakeLists.txt; uses only the engine and
# CLI11. test/test_stress_short.cpp (globbed with the unit tests) links nscd_sweep_core (the cases, grids and runner of src/nscd_sweep).

add_library(nscd_sweep_core STATIC
  ${PROJECT_SOURCE_DIR}/src/nscd_sweep/run_case.cpp
  ${PROJECT_SOURCE_DIR}/src/nscd_sweep/sweep_grid.cpp
  ${PROJECT_SOURCE_DIR}/src/nscd_sweep/stress_cases.cpp)
target_include_directories(nscd_sweep_core PUBLIC ${PROJECT_SOURCE_DIR}/src/nscd_sweep)
target_link_libraries(nscd_sweep_core PUBLIC nscd_engine nscd_run_output)
target_compile_options(nscd_sweep_core PRIVATE -Wall -Wextra)
set_target_properties(nscd_sweep_core PROPERTIES POSITION_INDEPENDENT_CODE ON)

find_package(Threads REQUIRED)
set(NSCD_SWEEP_BIN ${NSCD_BIN_DIR})

add_executable(nscd_sweep ${PROJECT_SOURCE_DIR}/src/nscd_sweep/main.cpp)
add_executable(nscd_stress ${PROJECT_SOURCE_DIR}/bench/stress.cpp)
add_executable(nscd_work_precision ${PROJECT_SOURCE_DIR}/bench/work_precision.cpp)
foreach(tool nscd_sweep nscd_stress nscd_work_precision)
  target_link_libraries(${tool} nscd_sweep_core CLI11::CLI11 Threads::Threads)
  target_compile_options(${tool} PRIVATE -Wall -Wextra)
  target_compile_definitions(${tool} PRIVATE NSCD_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
  set_target_properties(${tool} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${NSCD_SWEEP_BIN})
endforeach()
install(TARGETS nscd_sweep RUNTIME DESTINATION ${NSCD_INSTALL_BINDIR})

# The unit tests are declared after this file is included: link the short stress
# test once the whole directory has been read.
function(nscd_sweep_link_tests)
  if(TARGET test_stress_short)
    target_link_libraries(test_stress_short nscd_sweep_core Threads::Threads)
    add_dependencies(test_stress_short nscd_sweep)  # runs the tool (sweep over scenes, series)
  endif()
  if(TARGET test_work_precision_tool)
    add_dependencies(test_work_precision_tool nscd_work_precision)  # runs the tool
  endif()
endfunction()
cmake_language(DEFER CALL nscd_sweep_link_tests)

# Solver study: dumped problems (nscd_run --dump-problems) solved again.
add_executable(nscd_solve_problems ${PROJECT_SOURCE_DIR}/bench/solve_problems.cpp)
target_link_libraries(nscd_solve_problems nscd_engine CLI11::CLI11)
target_compile_options(nscd_solve_problems PRIVATE -Wall -Wextra)
set_target_properties(nscd_solve_problems PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${NSCD_SWEEP_BIN})
