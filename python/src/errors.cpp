// The module's exceptions: stackbeam.InputError, stackbeam.SolverError (bindings.hpp).
#include "bindings.hpp"

namespace stackbeam_py {

void bind_errors(py::module_& m) {
    // --- exceptions: InputError(ValueError) with .field and .location; SolverError(RuntimeError)
    static py::exception<InputError> input_error(m, "InputError", PyExc_ValueError);
    static py::exception<SolverError> solver_error(m, "SolverError", PyExc_RuntimeError);
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const InputError& e) {
            py::object exc = py::handle(input_error.ptr())(e.what());
            exc.attr("field") = e.field();
            exc.attr("location") = e.location();
            PyErr_SetObject(input_error.ptr(), exc.ptr());
        } catch (const SolverError& e) {
            py::object exc = py::handle(solver_error.ptr())(e.what());
            exc.attr("step") = e.step();
            exc.attr("time_s") = e.time_s();
            exc.attr("residual") = e.residual();
            PyErr_SetObject(solver_error.ptr(), exc.ptr());
        }
    });
}

}  // namespace stackbeam_py
