# FindKLU: SuiteSparse's KLU sparse LU (Debian: libsuitesparse-dev). Sets
#   KLU_FOUND, KLU_INCLUDE_DIR, KLU_LIBRARY, KLU_VERSION
#   imported target KLU::KLU (its own link dependencies, AMD, COLAMD and BTF, come with the
#   shared library)
include(${CMAKE_CURRENT_LIST_DIR}/SuiteSparseComponent.cmake)
suitesparse_component(KLU klu.h klu)
