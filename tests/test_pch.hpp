// The precompiled header of the test programs (tests/CMakeLists.txt, STACKBEAM_TEST_PCH):
// what every test parses before its own code, Boost.Test, Eigen and the public headers,
// compiled once per build and reused by every test (docs/decisions/048-ci-build-time.md).
//
// Boost.Test's main() comes from <boost/test/unit_test.hpp> when BOOST_TEST_MODULE is
// defined before its configuration header, which this header includes before the test's
// `#define BOOST_TEST_MODULE`: so BOOST_TEST_MAIN (what that configuration header would
// define from BOOST_TEST_MODULE) is defined here, and <boost/test/unit_test.hpp> itself (whose
// end defines main() and names the master suite after BOOST_TEST_MODULE) is left to each test.
#define BOOST_TEST_MAIN
#include <boost/test/framework.hpp>
#include <boost/test/test_tools.hpp>
#include <boost/test/tree/auto_registration.hpp>
#include <boost/test/tree/global_fixture.hpp>
#include <boost/test/tree/test_case_template.hpp>

#include <Eigen/Dense>
#include <Eigen/Sparse>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "stackbeam/stackbeam.hpp"
