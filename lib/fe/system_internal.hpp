#pragma once
// Internal: test-only accessors of System (include/stackbeam/fe/system.hpp).
#include "stackbeam/fe/system.hpp"

namespace stackbeam::detail {

/// Whether system.compliance_held() (the dense C' [m/N]) has been built: tests of the
/// sparse path check that it never forms it.
bool compliance_held_built(const System& system) noexcept;

}  // namespace stackbeam::detail
