# CTest test public_headers_private_deps: no public header (include/stackbeam/)
# includes a header of a private dependency, SUNDIALS or toml11. The compile of a
# user's program would not show such a leak here (the headers are in the system
# include path), a user without them would see it: so the headers are read.
# Nor does one name the library's internals (a detail:: type or namespace, a Testing
# hook; decision 034): those live in lib/.
#   cmake -DINCLUDE_DIR=<include/stackbeam> -P public_headers_test.cmake
cmake_minimum_required(VERSION 3.16)
file(GLOB_RECURSE headers "${INCLUDE_DIR}/*")
set(leaks "")
set(internals "")
foreach(h IN LISTS headers)
  file(STRINGS "${h}" includes REGEX "^[ \t]*#[ \t]*include")
  foreach(line IN LISTS includes)
    # the dependencies' include directories (<cvode/cvode.h>, <sundials/...>, <toml.hpp>);
    # the project's own "stackbeam/time/cvode_stepper.hpp" is not one of them
    if(line MATCHES "[<\"](sundials|cvode|nvector|sunlinsol|sunmatrix|sunnonlinsol|arkode|ida|kinsol)/" OR
       line MATCHES "[<\"]toml(11)?[/.]")
      string(APPEND leaks "  ${h}: ${line}\n")
    endif()
  endforeach()
  file(STRINGS "${h}" code REGEX "detail|Testing")
  foreach(line IN LISTS code)
    string(REGEX REPLACE "//.*$" "" line "${line}")  # comments may name them
    if(line MATCHES "detail::|namespace[ \t]+(stackbeam::)?detail|Testing")
      string(APPEND internals "  ${h}: ${line}\n")
    endif()
  endforeach()
endforeach()
list(LENGTH headers n)
if(n EQUAL 0)
  message(FATAL_ERROR "no header in ${INCLUDE_DIR}")
endif()
if(NOT leaks STREQUAL "")
  message(FATAL_ERROR "public headers include private dependencies (SUNDIALS, toml11):\n${leaks}")
endif()
if(NOT internals STREQUAL "")
  message(FATAL_ERROR "public headers name the library's internals (detail::, Testing):\n${internals}")
endif()
message(STATUS "${n} public headers in ${INCLUDE_DIR}, none includes SUNDIALS or toml11 or names detail::")
