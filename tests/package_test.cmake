# The installed package, as a user gets it (CTest test package_consumer):
#   1. `cmake --install` of this build tree into a fresh prefix;
#   2. no installed public header includes a SUNDIALS or toml11 header (they are
#      private dependencies; the system include path would hide such a leak from
#      the compile in 4, so it is checked by reading the headers);
#   3. the README's API guide example is tests/package_consumer/main.cpp, verbatim;
#   4. tests/package_consumer, a separate project, configured with only
#      CMAKE_PREFIX_PATH=<prefix> (find_package(stackbeam), target
#      stackbeam::stackbeam), built with this build's compiler and flags (so also
#      under the sanitizers), and run: with no argument (the built-in example) and
#      with scenarios/paper_bonded.toml; both print the bonded stiffness 107404 N/m.
#
# cmake -DBUILD_DIR= -DPREFIX= -DCONSUMER_SOURCE= -DCONSUMER_BUILD= -DREADME= -DSCENARIO=
#       -DCXX_COMPILER= -DCXX_FLAGS= -DLINKER_FLAGS= -DBUILD_TYPE= -P package_test.cmake
cmake_minimum_required(VERSION 3.16)

function(run_step what)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${what} failed (exit status ${rc}):\n${out}\n${err}")
  endif()
  set(step_output "${out}${err}" PARENT_SCOPE)
endfunction()

# 1. install
file(REMOVE_RECURSE "${PREFIX}" "${CONSUMER_BUILD}")
run_step("cmake --install" ${CMAKE_COMMAND} --install "${BUILD_DIR}" --prefix "${PREFIX}")
foreach(f include/stackbeam/model/model.hpp include/stackbeam/io/scenario.hpp)
  if(NOT EXISTS "${PREFIX}/${f}")
    message(FATAL_ERROR "the install has no ${f}")
  endif()
endforeach()
file(GLOB_RECURSE configs "${PREFIX}/*/stackbeamConfig.cmake")
if(NOT configs)
  message(FATAL_ERROR "the install has no stackbeamConfig.cmake")
endif()

# 2. public headers do not leak private dependencies (the installed ones)
execute_process(COMMAND ${CMAKE_COMMAND} -DINCLUDE_DIR=${PREFIX}/include/stackbeam
                        -P ${CMAKE_CURRENT_LIST_DIR}/public_headers_test.cmake RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "installed headers include private dependencies")
endif()

# 3. the README's example is main.cpp
file(READ "${README}" readme)
set(marker "<!-- api-example: tests/package_consumer/main.cpp -->")
string(FIND "${readme}" "${marker}" pos)
if(pos EQUAL -1)
  message(FATAL_ERROR "README.md has no '${marker}'")
endif()
string(SUBSTRING "${readme}" ${pos} -1 rest)
string(FIND "${rest}" "```cpp\n" begin)
if(begin EQUAL -1)
  message(FATAL_ERROR "README.md: no ```cpp block after '${marker}'")
endif()
math(EXPR begin "${begin} + 7")
string(SUBSTRING "${rest}" ${begin} -1 rest)
string(FIND "${rest}" "```" end)
string(SUBSTRING "${rest}" 0 ${end} example)
file(READ "${CONSUMER_SOURCE}/main.cpp" main_cpp)
if(NOT example STREQUAL main_cpp)
  message(FATAL_ERROR "the README's API example differs from ${CONSUMER_SOURCE}/main.cpp: update one from the other")
endif()

# 4. a separate project finds, builds against and runs the installed package
run_step("configuring the consumer" ${CMAKE_COMMAND} -S "${CONSUMER_SOURCE}" -B "${CONSUMER_BUILD}"
         "-DCMAKE_PREFIX_PATH=${PREFIX}" -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF "-DCMAKE_BUILD_TYPE=${BUILD_TYPE}"
         "-DCMAKE_CXX_COMPILER=${CXX_COMPILER}" "-DCMAKE_CXX_FLAGS=${CXX_FLAGS}" "-DCMAKE_EXE_LINKER_FLAGS=${LINKER_FLAGS}")
file(READ "${CONSUMER_BUILD}/CMakeCache.txt" cache)
string(FIND "${cache}" "stackbeam_DIR:PATH=${PREFIX}/" found)
if(found EQUAL -1)
  message(FATAL_ERROR "the consumer did not find the installed package in ${PREFIX}")
endif()
run_step("building the consumer" ${CMAKE_COMMAND} --build "${CONSUMER_BUILD}")
foreach(arg "" "${SCENARIO}")
  run_step("running the consumer ${arg}" "${CONSUMER_BUILD}/consumer" ${arg})
  message(STATUS "consumer ${arg}: ${step_output}")
  if(NOT step_output MATCHES "tied stiffness 107404 N/m")
    message(FATAL_ERROR "consumer ${arg}: unexpected output '${step_output}'")
  endif()
endforeach()
