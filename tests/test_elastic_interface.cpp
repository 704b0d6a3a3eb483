#define BOOST_TEST_MODULE elastic_interface
#include <boost/test/unit_test.hpp>
BOOST_AUTO_TEST_CASE(placeholder) {}
