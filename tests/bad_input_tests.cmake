# The bad-input suite: every tests/bad_input/*.toml is a scenario file that
# `stackbeam simulate --scenario FILE` must reject. One CTest test per file
# (bad_input.<name>), added at configure time (a new file re-runs the configure).
#
# Each file states what is expected in comment lines at its top:
#   # expect-field: leaves[2].height_m   the message must name this field path first, after the
#                                        key's place in the file ("stackbeam: error: FILE:LINE:COL:
#                                        leaves[2].height_m: ", or without the place);
#                                        @FILE@ stands for the file's own path (syntax errors)
#                                        (also in expect-text: "(@FILE@:65:8)", where the key is)
#   # expect-text: value -0.005 is not allowed    a part of the message (value, what is allowed)
#   # expect-exit: 3                     the exit status (default 2, bad input; 3 is a solver failure)
# and the checker asserts: that exit status (so no crash: a signal is no exit
# status), the field and text on stderr, and no output file (no FILE.csv; no
# FILE.csv.partial either after bad input, which is rejected before any output is
# opened; after a solver failure the rows up to it may stay in FILE.csv.partial,
# never in FILE.csv).
#
# Included from tests/CMakeLists.txt; also the checker itself (script mode):
#   cmake -DCLI=<stackbeam> -DFILE=<bad.toml> -DOUT=<csv> -P bad_input_tests.cmake

if(CMAKE_SCRIPT_MODE_FILE)
  cmake_minimum_required(VERSION 3.16)  # policies: @FILE@ is plain text (CMP0053)
  file(STRINGS "${FILE}" header REGEX "^# expect-")
  set(field "")
  set(text "")
  set(expect_rc 2)
  foreach(line IN LISTS header)
    if(line MATCHES "^# expect-field: (.+)$")
      set(field "${CMAKE_MATCH_1}")
    elseif(line MATCHES "^# expect-text: (.+)$")
      set(text "${CMAKE_MATCH_1}")
    elseif(line MATCHES "^# expect-exit: ([0-9]+)$")
      set(expect_rc "${CMAKE_MATCH_1}")
    endif()
  endforeach()
  if(field STREQUAL "" AND text STREQUAL "")
    message(FATAL_ERROR "${FILE} states no '# expect-field:' nor '# expect-text:' line")
  endif()
  string(REPLACE "@FILE@" "${FILE}" field "${field}")
  string(REPLACE "@FILE@" "${FILE}" text "${text}")

  file(REMOVE "${OUT}" "${OUT}.partial")
  execute_process(COMMAND "${CLI}" simulate --scenario "${FILE}" --out "${OUT}"
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  message(STATUS "stackbeam simulate --scenario ${FILE}\n-- exit status ${rc}\n-- stdout:\n${out}\n-- stderr:\n${err}")
  set(failures "")
  if(NOT rc STREQUAL "${expect_rc}")
    string(APPEND failures "exit status '${rc}', expected ${expect_rc}\n")
  endif()
  if(NOT field STREQUAL "")
    # "stackbeam: error: FIELD: ..." or, where the file has the key, "stackbeam: error: FILE:LINE:COL: FIELD: ..."
    string(REGEX MATCH "stackbeam: error: [^\n]*" first_line "${err}")
    string(FIND "${first_line}" "stackbeam: error: ${field}: " at_start)
    string(FIND "${first_line}" ": ${field}: " after_place)
    if(NOT at_start EQUAL 0 AND after_place EQUAL -1)
      string(APPEND failures "stderr does not name the field: no 'stackbeam: error: [FILE:LINE:COL: ]${field}: '\n")
    endif()
  endif()
  if(NOT text STREQUAL "")
    string(FIND "${err}" "${text}" pos)
    if(pos EQUAL -1)
      string(APPEND failures "stderr does not contain '${text}'\n")
    endif()
  endif()
  if(EXISTS "${OUT}")
    string(APPEND failures "${OUT} exists after a failed run\n")
  endif()
  if(expect_rc EQUAL 2 AND EXISTS "${OUT}.partial")
    string(APPEND failures "${OUT}.partial exists after bad input\n")
  endif()
  file(REMOVE "${OUT}" "${OUT}.partial")
  if(NOT failures STREQUAL "")
    message(FATAL_ERROR "${failures}")
  endif()
  return()
endif()

# ---- configure mode: one test per file ---------------------------------------------------
file(GLOB _bad_input_files CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/bad_input/*.toml)
list(LENGTH _bad_input_files _bad_input_count)
if(_bad_input_count EQUAL 0)
  message(FATAL_ERROR "tests/bad_input/ has no .toml file")
endif()
file(MAKE_DIRECTORY ${CMAKE_CURRENT_BINARY_DIR}/bad_input_out)
foreach(_file IN LISTS _bad_input_files)
  get_filename_component(_name ${_file} NAME_WE)
  add_test(NAME bad_input.${_name}
           COMMAND ${CMAKE_COMMAND} -DCLI=$<TARGET_FILE:stackbeam_cli> -DFILE=${_file}
                   -DOUT=${CMAKE_CURRENT_BINARY_DIR}/bad_input_out/${_name}.csv -P ${CMAKE_CURRENT_LIST_FILE})
  set_tests_properties(bad_input.${_name} PROPERTIES LABELS bad_input TIMEOUT 60)
endforeach()
