# The installed package, as a user gets it (CTest test package_consumer):
#   1. install components: `cmake --install --component library` into <prefix>
#      gives headers, libraries, CMake package and pkg-config files only (no
#      program), `--component programs` the programs only, and these two with
#      `--component python` (the Python module, when built; its own test is
#      python/install_test.cmake) are the whole install (no install rule without a component);
#   2. no installed public header includes a SUNDIALS or toml11 header (they are
#      private dependencies; the system include path would hide such a leak from
#      the compiles below, so it is checked by reading the headers);
#   3. the README's API guide example is tests/package_consumer/main.cpp, verbatim;
#   4. the installed CMake package: the config requires the SUNDIALS version of this
#      build (for a static library), the exported targets name the include
#      directory once;
#   5. tests/package_consumer, a separate project, configured with only
#      CMAKE_PREFIX_PATH=<prefix> (find_package(stackbeam), target
#      stackbeam::stackbeam), built with this build's compiler and flags (so also
#      under the sanitizers), and run: with no argument (the built-in example) and
#      with scenarios/paper_bonded.toml; both print the bonded stiffness 107404 N/m;
#   6. tests/package_contact_consumer finds the component `contact` alone with
#      SUNDIALS' CMake package disabled, builds and runs; asking for the whole
#      library that way must fail when it is static (so the first proves something);
#   7. pkg-config (required): main.cpp of 5 and 6 compiled and linked by hand with
#      `c++ main.cpp $(pkg-config --cflags --libs [--static] stackbeam[-contact])`
#      (--static for a static library), and run.
#
# cmake -DBUILD_DIR= -DPREFIX= -DLIBDIR= -DCONSUMER_SOURCE= -DCONTACT_CONSUMER_SOURCE=
#       -DCONSUMER_BUILD= -DREADME= -DSCENARIO= -DCXX_COMPILER= -DCXX_FLAGS=
#       -DCXX_FLAGS_CONFIG= -DLINKER_FLAGS= -DBUILD_TYPE= -DLIBRARY_TYPE= -DSUNDIALS_VERSION=
#       -DPROGRAMS= -P package_test.cmake
#   LIBDIR: CMAKE_INSTALL_LIBDIR; LIBRARY_TYPE: STATIC_LIBRARY or SHARED_LIBRARY;
#   PROGRAMS: the file names the component `programs` must install in bin/, comma-separated (may be empty)
cmake_minimum_required(VERSION 3.16)

function(run_step what)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${what} failed (exit status ${rc}):\n${out}\n${err}")
  endif()
  set(step_output "${out}${err}" PARENT_SCOPE)
endfunction()

# run_fails(what command...): the command must fail; its output in step_output
function(run_fails what)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(rc EQUAL 0)
    message(FATAL_ERROR "${what} succeeded, but must fail:\n${out}\n${err}")
  endif()
  set(step_output "${out}${err}" PARENT_SCOPE)
endfunction()

# installed_files(var prefix [component]): `cmake --install` (of one component) into
# a fresh prefix; var = the installed files, relative to the prefix, sorted
function(installed_files var prefix)
  set(component "")
  if(ARGC GREATER 2)
    set(component --component ${ARGV2})
  endif()
  file(REMOVE_RECURSE "${prefix}")
  run_step("cmake --install ${component}" ${CMAKE_COMMAND} --install "${BUILD_DIR}" --prefix "${prefix}" ${component})
  file(GLOB_RECURSE files RELATIVE "${prefix}" "${prefix}/*")
  list(SORT files)
  set(${var} "${files}" PARENT_SCOPE)
endfunction()

# 1. install components
file(REMOVE_RECURSE "${CONSUMER_BUILD}")
installed_files(library_files "${PREFIX}" library)
installed_files(program_files "${PREFIX}-programs" programs)
installed_files(python_files "${PREFIX}-python" python)
installed_files(all_files "${PREFIX}-all")
foreach(f include/stackbeam/model/model.hpp include/stackbeam/io/scenario.hpp ${LIBDIR}/cmake/stackbeam/stackbeamConfig.cmake
          ${LIBDIR}/pkgconfig/stackbeam.pc ${LIBDIR}/pkgconfig/stackbeam-contact.pc)
  if(NOT f IN_LIST library_files)
    message(FATAL_ERROR "the component library did not install ${f}")
  endif()
endforeach()
# the library's files only: headers, the two libraries (static, or shared with their
# links), the CMake package, the pkg-config files; no program
foreach(f IN LISTS library_files)
  if(NOT f MATCHES "^include/stackbeam/.*\\.hpp$" AND
     NOT f MATCHES "^${LIBDIR}/libstackbeam(_contact)?\\.(a|so(\\.[0-9]+)*)$" AND
     NOT f MATCHES "^${LIBDIR}/cmake/stackbeam/stackbeam[A-Za-z]*(-[a-z]+)?\\.cmake$" AND
     NOT f MATCHES "^${LIBDIR}/pkgconfig/stackbeam(-contact)?\\.pc$")
    message(FATAL_ERROR "the component library installed ${f}, which is not part of the library")
  endif()
endforeach()
set(expected_programs "")
string(REPLACE "," ";" PROGRAMS "${PROGRAMS}")
foreach(program IN LISTS PROGRAMS)
  list(APPEND expected_programs bin/${program})
endforeach()
list(SORT expected_programs)
if(NOT program_files STREQUAL expected_programs)
  message(FATAL_ERROR "the component programs installed '${program_files}', expected '${expected_programs}'")
endif()
set(union ${library_files} ${program_files} ${python_files})
list(SORT union)
if(NOT all_files STREQUAL union)
  message(FATAL_ERROR "the whole install is not the components library, programs and python together (an install() "
                      "without COMPONENT?):\n  all: ${all_files}\n  library + programs + python: ${union}")
endif()
message(STATUS "install components: library ${PREFIX}, programs ${PREFIX}-programs (${program_files})")

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

# 4. the installed CMake package
set(cmake_dir "${PREFIX}/${LIBDIR}/cmake/stackbeam")
file(READ "${cmake_dir}/stackbeamConfig.cmake" config)
# the version is recorded for both kinds of library, required for a static one
if(NOT config MATCHES "set\\(_stackbeam_sundials_version \"${SUNDIALS_VERSION}\"\\)" OR
   NOT config MATCHES "find_dependency\\(SUNDIALS \\$\\{_stackbeam_sundials_version\\}\\)")
  message(FATAL_ERROR "the installed stackbeamConfig.cmake does not require SUNDIALS ${SUNDIALS_VERSION} (this build's):\n${config}")
endif()
# the include directory once over all exported targets (stackbeam::contact declares
# it, stackbeam::stackbeam has it through stackbeam::contact)
file(GLOB targets_files "${cmake_dir}/stackbeam*Targets.cmake")
set(include_count 0)
foreach(targets_file IN LISTS targets_files)
  file(STRINGS "${targets_file}" lines REGEX "INTERFACE_INCLUDE_DIRECTORIES")
  foreach(line IN LISTS lines)
    string(REGEX MATCHALL "\\\$\\{_IMPORT_PREFIX\\}/include" hits "${line}")
    list(LENGTH hits n)
    math(EXPR include_count "${include_count} + ${n}")
  endforeach()
endforeach()
if(NOT include_count EQUAL 1)
  message(FATAL_ERROR "the exported targets (${targets_files}) name the include directory ${include_count} times, not once")
endif()

# consumer_cmake_args(var): the arguments that configure a consumer project against
# the installed package with this build's compiler and flags
set(consumer_cmake_args "-DCMAKE_PREFIX_PATH=${PREFIX}" -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF "-DCMAKE_BUILD_TYPE=${BUILD_TYPE}"
    "-DCMAKE_CXX_COMPILER=${CXX_COMPILER}" "-DCMAKE_CXX_FLAGS=${CXX_FLAGS}" "-DCMAKE_EXE_LINKER_FLAGS=${LINKER_FLAGS}")

# run_consumer(what expected command...): runs the command, its output must match expected
function(run_consumer what expected)
  run_step("running ${what}" ${ARGN})
  message(STATUS "${what}: ${step_output}")
  if(NOT step_output MATCHES "${expected}")
    message(FATAL_ERROR "${what}: unexpected output '${step_output}', expected '${expected}'")
  endif()
endfunction()

# 5. a separate project finds, builds against and runs the installed package
set(build "${CONSUMER_BUILD}/whole")
run_step("configuring the consumer" ${CMAKE_COMMAND} -S "${CONSUMER_SOURCE}" -B "${build}" ${consumer_cmake_args})
file(READ "${build}/CMakeCache.txt" cache)
string(FIND "${cache}" "stackbeam_DIR:PATH=${PREFIX}/" found)
if(found EQUAL -1)
  message(FATAL_ERROR "the consumer did not find the installed package in ${PREFIX}")
endif()
run_step("building the consumer" ${CMAKE_COMMAND} --build "${build}")
set(whole_expected "tied stiffness 107404 N/m")
foreach(arg "" "${SCENARIO}")
  run_consumer("the consumer ${arg}" "${whole_expected}" "${build}/consumer" ${arg})
endforeach()

# 6. the component contact alone, without SUNDIALS' CMake package
# (the pair's forces are exact up to round-off: the exact solver solves the
# sticking pair's 2 x 2 system directly)
set(contact_expected "tied stiffness 107404 N/m, pair forces \\(-10.000, 3.000\\) N, converged")
set(build "${CONSUMER_BUILD}/contact")
run_step("configuring the contact-only consumer" ${CMAKE_COMMAND} -S "${CONTACT_CONSUMER_SOURCE}" -B "${build}"
         ${consumer_cmake_args} -DCMAKE_DISABLE_FIND_PACKAGE_SUNDIALS=ON)
run_step("building the contact-only consumer" ${CMAKE_COMMAND} --build "${build}")
run_consumer("the contact-only consumer" "${contact_expected}" "${build}/contact_consumer")
if(LIBRARY_TYPE STREQUAL "STATIC_LIBRARY")
  run_fails("configuring the whole-library consumer without SUNDIALS' CMake package"
            ${CMAKE_COMMAND} -S "${CONTACT_CONSUMER_SOURCE}" -B "${CONSUMER_BUILD}/whole-without-sundials"
            ${consumer_cmake_args} -DCMAKE_DISABLE_FIND_PACKAGE_SUNDIALS=ON -DSTACKBEAM_COMPONENT=stackbeam)
  if(NOT step_output MATCHES "SUNDIALS")
    message(FATAL_ERROR "the whole static library without SUNDIALS failed without naming SUNDIALS:\n${step_output}")
  endif()
endif()

# 7. pkg-config consumers, compiled and linked by hand
find_program(PKG_CONFIG NAMES pkg-config pkgconf)
if(NOT PKG_CONFIG)
  message(FATAL_ERROR "pkg-config not found: the test of the installed stackbeam.pc needs it "
                      "(Debian: apt-get install pkgconf; scripts/common.sh installs it)")
endif()
set(ENV{PKG_CONFIG_PATH} "${PREFIX}/${LIBDIR}/pkgconfig")
set(static_flag "")
if(LIBRARY_TYPE STREQUAL "STATIC_LIBRARY")
  set(static_flag --static)  # Libs.private: the SUNDIALS libraries
endif()
separate_arguments(compile_flags UNIX_COMMAND "${CXX_FLAGS} ${CXX_FLAGS_CONFIG}")
separate_arguments(link_flags UNIX_COMMAND "${LINKER_FLAGS}")
file(MAKE_DIRECTORY "${CONSUMER_BUILD}/pkgconfig")
foreach(case "stackbeam;${CONSUMER_SOURCE};${whole_expected}" "stackbeam-contact;${CONTACT_CONSUMER_SOURCE};${contact_expected}")
  list(GET case 0 package)
  list(GET case 1 source)
  list(GET case 2 expected)
  run_step("pkg-config ${package}" ${PKG_CONFIG} --cflags --libs ${static_flag} ${package})
  string(STRIP "${step_output}" pc_output)
  message(STATUS "pkg-config --cflags --libs ${static_flag} ${package}: ${pc_output}")
  if(package STREQUAL "stackbeam-contact" AND pc_output MATCHES "sundials")
    message(FATAL_ERROR "stackbeam-contact.pc names SUNDIALS: ${pc_output}")
  endif()
  separate_arguments(pc_flags UNIX_COMMAND "${pc_output}")
  set(program "${CONSUMER_BUILD}/pkgconfig/${package}")
  run_step("compiling ${source}/main.cpp with pkg-config ${package}"
           ${CXX_COMPILER} -std=c++17 ${compile_flags} "${source}/main.cpp" -o "${program}" ${pc_flags} ${link_flags})
  # a shared library from a prefix outside the loader's paths, as a user would run it
  run_consumer("the pkg-config ${package} consumer" "${expected}"
               ${CMAKE_COMMAND} -E env "LD_LIBRARY_PATH=${PREFIX}/${LIBDIR}" "${program}")
endforeach()
