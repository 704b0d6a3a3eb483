#define BOOST_TEST_MODULE winkler_layer
#include <boost/test/unit_test.hpp>
BOOST_AUTO_TEST_CASE(placeholder) {}
