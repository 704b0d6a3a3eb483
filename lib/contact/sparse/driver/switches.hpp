#pragma once
// Internal: the sparse path's methods under their internal names. The configuration is the
// public SparsePathMethods (stackbeam/contact/sparse_methods.hpp), passed to each
// SparseContactSolver in SparsePathTuning::methods with the problem (no global state).
#include "stackbeam/contact/sparse_methods.hpp"

namespace stackbeam::detail::sparse {

using TransitionMethod = SparseTransitionMethod;
using BoxQpMethod = SparseBoxQpMethod;
using Switches = SparsePathMethods;

}  // namespace stackbeam::detail::sparse
