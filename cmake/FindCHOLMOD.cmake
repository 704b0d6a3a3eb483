# FindCHOLMOD: SuiteSparse's CHOLMOD (Debian: libsuitesparse-dev). Sets
#   CHOLMOD_FOUND, CHOLMOD_INCLUDE_DIR, CHOLMOD_LIBRARY, CHOLMOD_VERSION
#   imported target CHOLMOD::CHOLMOD (its own link dependencies come with the shared library)
include(${CMAKE_CURRENT_LIST_DIR}/SuiteSparseComponent.cmake)
suitesparse_component(CHOLMOD cholmod_core.h cholmod)
