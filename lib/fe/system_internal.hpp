#pragma once
// Internal: the library's private access to System (include/stackbeam/fe/system.hpp names only
// the friendship), and the test-only accessors built on it.
#include "stackbeam/fe/system.hpp"

namespace stackbeam {

/// System's friend: reads its private members for the library and its tests.
struct SystemAccess {
    static bool compliance_held_built(const System& system) noexcept;
};

namespace detail {

/// Whether system.compliance_held() (the dense C' [m/N]) has been built: tests of the
/// sparse path check that it never forms it.
inline bool compliance_held_built(const System& system) noexcept { return SystemAccess::compliance_held_built(system); }

}  // namespace detail
}  // namespace stackbeam
