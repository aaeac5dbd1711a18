# CTest case InstallConsumer.FindPackageBuildRun (registered in cmake/areas/install_consumer.cmake):
# proves that dgtex links as a runtime from a clean project. Run in script mode (cmake -P):
#   1. cmake --install <DGTEX_BUILD_DIR> --prefix <WORK_DIR>/prefix, and start the installed
#      dgtex tool from there (also a one-step bench of an installed example scene); the
#      installed library exports the names of namespace dgtex only,
#   2. configure examples/consumer against that prefix only (CMAKE_PREFIX_PATH), check that
#      find_package(dgtex) found the package there and not some other installed copy,
#   3. build it, with a translation unit that includes every installed header (-Werror), at
#      -std=c++14 unless the package itself asks for the C++17 its headers need,
#   4. run the cut_plate program (it checks its own results), and README.md's C++ example
#      (built beside it from the README's text).
# Any failing step fails the test with that step's output.
# Inputs: DGTEX_BUILD_DIR, SOURCE_DIR, CONSUMER_SOURCE_DIR, WORK_DIR, GENERATOR, MAKE_PROGRAM,
#         CXX_COMPILER, CXX_COMPILER_LAUNCHER (may be empty), NM.
foreach(var DGTEX_BUILD_DIR SOURCE_DIR CONSUMER_SOURCE_DIR WORK_DIR GENERATOR CXX_COMPILER NM)
  if(NOT DEFINED ${var} OR "${${var}}" STREQUAL "")
    message(FATAL_ERROR "install_consumer_test.cmake: -D${var}=... is required")
  endif()
endforeach()

set(prefix ${WORK_DIR}/prefix)
set(consumer_build ${WORK_DIR}/consumer-build)
# Start from nothing so that a stale install or cache can never make the test pass.
file(REMOVE_RECURSE ${WORK_DIR})
file(MAKE_DIRECTORY ${WORK_DIR})

# Runs one step; on failure prints its output and stops with the step's name.
function(run_step name)
  string(TIMESTAMP start "%s")
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE result OUTPUT_VARIABLE out ERROR_VARIABLE out)
  string(TIMESTAMP stop "%s")
  math(EXPR seconds "${stop} - ${start}")
  if(NOT result EQUAL 0)
    string(REPLACE ";" " " command "${ARGN}")
    message(FATAL_ERROR "${name} failed (exit ${result}):\n  ${command}\n${out}")
  endif()
  message(STATUS "${name}: ok (${seconds} s)")
  set(step_output "${out}" PARENT_SCOPE)
endfunction()

run_step("install dgtex" ${CMAKE_COMMAND} --install ${DGTEX_BUILD_DIR} --prefix ${prefix})
# The installed tool must start from the prefix (it finds libdgtex.so through its RUNPATH).
run_step("installed dgtex --help" ${prefix}/bin/dgtex --help)
# Outside a checkout the bench commands find the example scenes installed beside the tool.
execute_process(COMMAND ${prefix}/bin/dgtex bench scenes --scenes spiral1 --steps 1 WORKING_DIRECTORY ${WORK_DIR}
                RESULT_VARIABLE result OUTPUT_VARIABLE out ERROR_VARIABLE out)
string(FIND "${out}" "(${prefix}/share/dgtex/scenes/spiral1.json)" at)
if(NOT result EQUAL 0 OR at EQUAL -1)
  message(FATAL_ERROR "installed dgtex bench scenes did not use ${prefix}/share/dgtex/scenes (exit ${result}):\n${out}")
endif()
message(STATUS "installed dgtex bench scenes: ok (the installed scenes)")

# The installed library exports the names of namespace dgtex only (runtime/exported_symbols.map):
# an exported weak copy of a dependency's template (OpenVDB, oneTBB, nlohmann::json, the
# standard library, Eigen; MPI's C++ bindings until session 77) would stand in for a
# program's own, built against another version.
file(GLOB_RECURSE installed_library ${prefix}/*/libdgtex.so)
if(NOT installed_library)
  message(FATAL_ERROR "no libdgtex.so installed under ${prefix}")
endif()
run_step("exported symbols" ${NM} -D -C --defined-only ${installed_library})
string(REPLACE ";" "\\;" exported "${step_output}")
string(REPLACE "\n" ";" exported "${exported}")
set(foreign "")
set(own 0)
foreach(line IN LISTS exported)
  # "<address> <type> <demangled name>"
  if(line MATCHES "^[0-9a-f]+ [A-Za-z] (.*)$")
    set(name "${CMAKE_MATCH_1}")
    if(name MATCHES "^((typeinfo|typeinfo name|vtable) for )?dgtex::")
      math(EXPR own "${own} + 1")
    else()
      list(APPEND foreign "${name}")
    endif()
  endif()
endforeach()
if(foreign)
  list(LENGTH foreign count)
  list(GET foreign 0 first)
  message(FATAL_ERROR "${installed_library} exports ${count} symbols outside namespace dgtex, e.g.\n  ${first}")
endif()
if(own LESS 100)
  message(FATAL_ERROR "${installed_library} exports ${own} symbols of namespace dgtex: expected its API (hundreds)")
endif()
message(STATUS "exported symbols: ${own}, all of namespace dgtex")

# README.md's C++ example (the first ```cpp block after "## Using dgtex as a library"),
# wrapped in a main() with the includes it assumes, built and run from the source tree below.
file(READ ${SOURCE_DIR}/README.md readme)
string(FIND "${readme}" "## Using dgtex as a library" section)
set(begin -1)
if(NOT section EQUAL -1)
  string(SUBSTRING "${readme}" ${section} -1 readme)
  string(FIND "${readme}" "```cpp\n" begin)
endif()
if(begin EQUAL -1)
  message(FATAL_ERROR "no ```cpp example under \"## Using dgtex as a library\" in ${SOURCE_DIR}/README.md")
endif()
math(EXPR begin "${begin} + 7")
string(SUBSTRING "${readme}" ${begin} -1 readme)
string(FIND "${readme}" "```" end)
string(SUBSTRING "${readme}" 0 ${end} example)
string(REGEX MATCHALL "#include <[^>\n]+>" example_includes "${example}")
string(REGEX REPLACE "#include <[^>\n]+>\n" "" example_body "${example}")
string(REPLACE ";" "\n" example_includes "${example_includes}")
file(WRITE ${WORK_DIR}/readme_example.cpp
     "#include <cstdio>\n${example_includes}\n\nint main() {\n${example_body}  return 0;\n}\n")

set(configure_args -S ${CONSUMER_SOURCE_DIR} -B ${consumer_build} -G ${GENERATOR}
    -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_CXX_COMPILER=${CXX_COMPILER}
    -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF -DDGTEX_CONSUMER_HEADER_CHECK=ON
    # Below what the headers need: only the package's own requirement (cxx_std_17) lifts it.
    -DCMAKE_CXX_STANDARD=14 -DCMAKE_CXX_EXTENSIONS=OFF
    -DDGTEX_CONSUMER_README_EXAMPLE=${WORK_DIR}/readme_example.cpp)
if(MAKE_PROGRAM)
  list(APPEND configure_args -DCMAKE_MAKE_PROGRAM=${MAKE_PROGRAM})
endif()
if(CXX_COMPILER_LAUNCHER)
  list(APPEND configure_args -DCMAKE_CXX_COMPILER_LAUNCHER=${CXX_COMPILER_LAUNCHER})
endif()
run_step("configure consumer" ${CMAKE_COMMAND} ${configure_args})

file(STRINGS ${consumer_build}/CMakeCache.txt dgtex_dir_line REGEX "^dgtex_DIR:")
string(REGEX REPLACE "^dgtex_DIR:[A-Z]+=" "" dgtex_dir "${dgtex_dir_line}")
file(REAL_PATH "${dgtex_dir}" dgtex_dir)
file(REAL_PATH "${prefix}" real_prefix)
string(FIND "${dgtex_dir}/" "${real_prefix}/" at)
if(NOT at EQUAL 0)
  message(FATAL_ERROR "find_package(dgtex) used ${dgtex_dir}, not the package installed under ${prefix}")
endif()

run_step("build consumer" ${CMAKE_COMMAND} --build ${consumer_build})
run_step("run consumer" ${consumer_build}/cut_plate)
message("${step_output}")
# The README example loads examples/scenes/spiral1.json relative to the source tree.
execute_process(COMMAND ${consumer_build}/readme_example WORKING_DIRECTORY ${SOURCE_DIR}
                RESULT_VARIABLE result OUTPUT_VARIABLE out ERROR_VARIABLE out)
if(NOT result EQUAL 0 OR NOT out MATCHES "^u = -?[0-9]")
  message(FATAL_ERROR "README.md's example failed (exit ${result}):\n${out}")
endif()
message(STATUS "README.md's example: ok: ${out}")
