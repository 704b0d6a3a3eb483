# FindKLU: SuiteSparse's KLU sparse LU (Debian: libsuitesparse-dev), which ships neither a
# CMake package nor a pkg-config file (as FindCHOLMOD.cmake). Sets
#   KLU_FOUND, KLU_INCLUDE_DIR, KLU_LIBRARY, KLU_VERSION
#   imported target KLU::KLU (its own link dependencies, AMD, COLAMD and BTF, come with the
#   shared library)
find_path(KLU_INCLUDE_DIR klu.h PATH_SUFFIXES suitesparse)
find_library(KLU_LIBRARY klu)
if(KLU_INCLUDE_DIR AND EXISTS "${KLU_INCLUDE_DIR}/klu.h")
  file(STRINGS "${KLU_INCLUDE_DIR}/klu.h" _klu_version_lines
       REGEX "^#define KLU_(MAIN|SUB|SUBSUB)_VERSION[ \t]+[0-9]+")
  foreach(_part MAIN SUB SUBSUB)
    string(REGEX REPLACE ".*#define KLU_${_part}_VERSION[ \t]+([0-9]+).*" "\\1" _klu_${_part}
           "${_klu_version_lines}")
  endforeach()
  set(KLU_VERSION "${_klu_MAIN}.${_klu_SUB}.${_klu_SUBSUB}")
endif()
include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(KLU REQUIRED_VARS KLU_LIBRARY KLU_INCLUDE_DIR VERSION_VAR KLU_VERSION)
if(KLU_FOUND AND NOT TARGET KLU::KLU)
  add_library(KLU::KLU UNKNOWN IMPORTED)
  set_target_properties(KLU::KLU PROPERTIES IMPORTED_LOCATION "${KLU_LIBRARY}"
                        INTERFACE_INCLUDE_DIRECTORIES "${KLU_INCLUDE_DIR}")
endif()
mark_as_advanced(KLU_INCLUDE_DIR KLU_LIBRARY)
