# suitesparse_component(<NAME> <header> <library>): finds one library of SuiteSparse (Debian:
# libsuitesparse-dev, which ships neither CMake packages nor pkg-config files) for
# Find<NAME>.cmake. Sets <NAME>_FOUND, <NAME>_INCLUDE_DIR, <NAME>_LIBRARY, <NAME>_VERSION
# (from <header>'s <NAME>_MAIN/SUB/SUBSUB_VERSION) and the imported target <NAME>::<NAME>
# (its own link dependencies come with the shared library).
include(FindPackageHandleStandardArgs)
macro(suitesparse_component _ss_name _ss_header _ss_library)
  find_path(${_ss_name}_INCLUDE_DIR ${_ss_header} PATH_SUFFIXES suitesparse)
  find_library(${_ss_name}_LIBRARY ${_ss_library})
  if(${_ss_name}_INCLUDE_DIR AND EXISTS "${${_ss_name}_INCLUDE_DIR}/${_ss_header}")
    file(STRINGS "${${_ss_name}_INCLUDE_DIR}/${_ss_header}" _ss_version_lines
         REGEX "^#define ${_ss_name}_(MAIN|SUB|SUBSUB)_VERSION[ \t]+[0-9]+")
    foreach(_ss_part MAIN SUB SUBSUB)
      string(REGEX REPLACE ".*#define ${_ss_name}_${_ss_part}_VERSION[ \t]+([0-9]+).*" "\\1" _ss_${_ss_part}
             "${_ss_version_lines}")
    endforeach()
    set(${_ss_name}_VERSION "${_ss_MAIN}.${_ss_SUB}.${_ss_SUBSUB}")
  endif()
  find_package_handle_standard_args(${_ss_name} REQUIRED_VARS ${_ss_name}_LIBRARY ${_ss_name}_INCLUDE_DIR
                                    VERSION_VAR ${_ss_name}_VERSION)
  if(${_ss_name}_FOUND AND NOT TARGET ${_ss_name}::${_ss_name})
    add_library(${_ss_name}::${_ss_name} UNKNOWN IMPORTED)
    set_target_properties(${_ss_name}::${_ss_name} PROPERTIES IMPORTED_LOCATION "${${_ss_name}_LIBRARY}"
                          INTERFACE_INCLUDE_DIRECTORIES "${${_ss_name}_INCLUDE_DIR}")
  endif()
  mark_as_advanced(${_ss_name}_INCLUDE_DIR ${_ss_name}_LIBRARY)
endmacro()
