// Python values checked before they reach the library (bindings.hpp: checked, field): the
// type first (InputTypeError), then whether a C++ number holds the value (InputError).
#include "bindings.hpp"

namespace stackbeam_py {

namespace {

bool is_bool(const py::handle& value) {
    if (py::isinstance<py::bool_>(value)) return true;
    // numpy.bool_ is no Python bool, and has __index__ / __float__ in old numpy: by its type's name
    const std::string type = py::str(py::type::handle_of(value).attr("__name__"));
    return type == "bool_" || type == "bool";
}

}  // namespace

std::string value_repr(const py::handle& value) {
    std::string text = py::repr(value).cast<std::string>();
    if (text.size() > 60) text = text.substr(0, 40) + "...(" + std::to_string(text.size()) + " characters)";
    return text;
}

double real_arg(const py::handle& value, const std::string& name) {
    const bool number = py::isinstance<py::float_>(value) || py::isinstance<py::int_>(value) ||
                        py::hasattr(value, "__float__") || py::hasattr(value, "__index__");
    if (value.is_none() || is_bool(value) || py::isinstance<py::str>(value) || !number)
        throw InputTypeError(name, "value " + value_repr(value) + " is not allowed: must be a real number (a float or an int)");
    const double x = PyFloat_AsDouble(value.ptr());
    if (x == -1.0 && PyErr_Occurred()) {
        const bool overflow = PyErr_ExceptionMatches(PyExc_OverflowError);
        PyErr_Clear();
        throw InputError(name, "value " + value_repr(value) + " is not allowed: " +
                                   (overflow ? "beyond a double's range (|x| <= 1.8e308)" : "must be a real number"));
    }
    return x;
}

long long integer_arg(const py::handle& value, const std::string& name, long long lo, long long hi) {
    const std::string allowed = "must be an integer from " + std::to_string(lo) + " to " + std::to_string(hi);
    if (value.is_none() || is_bool(value) || py::isinstance<py::float_>(value) || !py::hasattr(value, "__index__"))
        throw InputTypeError(name, "value " + value_repr(value) + " is not allowed: " + allowed);
    const py::object index = py::reinterpret_steal<py::object>(PyNumber_Index(value.ptr()));
    if (!index) {
        PyErr_Clear();
        throw InputTypeError(name, "value " + value_repr(value) + " is not allowed: " + allowed);
    }
    int overflow = 0;
    const long long n = PyLong_AsLongLongAndOverflow(index.ptr(), &overflow);
    if (n == -1 && PyErr_Occurred()) PyErr_Clear();
    if (overflow != 0 || n < lo || n > hi)
        throw InputError(name, "value " + value_repr(value) + " is not allowed: " + allowed);
    return n;
}

bool bool_arg(const py::handle& value, const std::string& name) {
    if (!is_bool(value))
        throw InputTypeError(name, "value " + value_repr(value) + " is not allowed: must be True or False");
    return PyObject_IsTrue(value.ptr()) == 1;
}

std::string string_arg(const py::handle& value, const std::string& name) {
    if (!py::isinstance<py::str>(value))
        throw InputTypeError(name, "value " + value_repr(value) + " is not allowed: must be a string");
    return value.cast<std::string>();
}

const ScenarioPtr& scenario_arg(const ScenarioPtr& scenario, const std::string& name) {
    if (!scenario) throw InputTypeError(name, "value None is not allowed: must be a stackbeam.Scenario");
    return scenario;
}

}  // namespace stackbeam_py
