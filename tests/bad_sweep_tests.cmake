# The bad sweep specs: every tests/bad_sweep/*.toml is a sweep spec that `stackbeam sweep`
# must refuse before any run. One CTest test per file (bad_sweep.<name>).
#
# Each file states in comment lines at its top:
#   # expect-text: @FILE@:7: key: ...   a part of the message (@FILE@: the spec's own path,
#                                      so the spec's line is checked)
#   # expect-exit: 2                   the exit status (default 2, bad input)
# and the checker asserts that exit status, the text on stderr, and that the results
# directory was not created (nothing ran).
#
# Included from tests/CMakeLists.txt; also the checker itself (script mode):
#   cmake -DCLI=<stackbeam> -DFILE=<bad.toml> -DOUT=<dir> -P bad_sweep_tests.cmake

if(CMAKE_SCRIPT_MODE_FILE)
  cmake_minimum_required(VERSION 3.16)
  file(STRINGS "${FILE}" header REGEX "^# expect-")
  set(texts "")
  set(expect_rc 2)
  foreach(line IN LISTS header)
    if(line MATCHES "^# expect-text: (.+)$")
      string(REPLACE "@FILE@" "${FILE}" t "${CMAKE_MATCH_1}")
      list(APPEND texts "${t}")
    elseif(line MATCHES "^# expect-exit: ([0-9]+)$")
      set(expect_rc "${CMAKE_MATCH_1}")
    endif()
  endforeach()
  if(texts STREQUAL "")
    message(FATAL_ERROR "${FILE} states no '# expect-text:' line")
  endif()
  file(REMOVE_RECURSE "${OUT}")
  execute_process(COMMAND "${CLI}" sweep "${FILE}" --out-dir "${OUT}" --jobs 1
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  message(STATUS "stackbeam sweep ${FILE}\n-- exit status ${rc}\n-- stdout:\n${out}\n-- stderr:\n${err}")
  set(failures "")
  if(NOT rc STREQUAL "${expect_rc}")
    string(APPEND failures "exit status '${rc}', expected ${expect_rc}\n")
  endif()
  foreach(t IN LISTS texts)
    string(FIND "${err}" "${t}" pos)
    if(pos EQUAL -1)
      string(APPEND failures "stderr does not contain '${t}'\n")
    endif()
  endforeach()
  if(EXISTS "${OUT}")
    string(APPEND failures "${OUT} was created: the spec must be refused before any run\n")
  endif()
  file(REMOVE_RECURSE "${OUT}")
  if(NOT failures STREQUAL "")
    message(FATAL_ERROR "${failures}")
  endif()
  return()
endif()

file(GLOB _bad_sweep_files CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/bad_sweep/*.toml)
file(MAKE_DIRECTORY ${CMAKE_CURRENT_BINARY_DIR}/bad_sweep_out)
foreach(_file IN LISTS _bad_sweep_files)
  get_filename_component(_name ${_file} NAME_WE)
  add_test(NAME bad_sweep.${_name}
           COMMAND ${CMAKE_COMMAND} -DCLI=$<TARGET_FILE:stackbeam_cli> -DFILE=${_file}
                   -DOUT=${CMAKE_CURRENT_BINARY_DIR}/bad_sweep_out/${_name} -P ${CMAKE_CURRENT_LIST_FILE})
  set_tests_properties(bad_sweep.${_name} PROPERTIES LABELS "bad_input;sweep" TIMEOUT 60)
endforeach()
