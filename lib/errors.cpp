// The messages' formatting of the errors (errors.hpp).
#include "stackbeam/errors.hpp"

#include <cstdio>

namespace stackbeam {

std::string format_value(double value) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.10g", value);
    return buf;
}

}  // namespace stackbeam
