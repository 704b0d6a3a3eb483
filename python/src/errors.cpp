// The module's exceptions (bindings.hpp): InputError(ValueError) with .field and .location;
// InputTypeError(InputError, TypeError), a value of the wrong type; SolverError(RuntimeError)
// with .step, .time_s, .residual; ThreadStartError(RuntimeError), a thread the system refused
// (std::system_error: the module's std::system_error come from starting threads, std::thread
// in the sweep and std::async here), with .errno.
#include "bindings.hpp"

#include <system_error>

namespace stackbeam_py {

void bind_errors(py::module_& m) {
    static py::exception<InputError> input_error(m, "InputError", PyExc_ValueError);
    static py::object input_type_error = py::reinterpret_steal<py::object>(PyErr_NewExceptionWithDoc(
        "stackbeam._core.InputTypeError", "A value of the wrong type (None, a bool for a number, ...): an InputError and a TypeError",
        py::make_tuple(input_error, py::handle(PyExc_TypeError)).ptr(), nullptr));
    m.attr("InputTypeError") = input_type_error;
    static py::exception<SolverError> solver_error(m, "SolverError", PyExc_RuntimeError);
    static py::exception<std::system_error> thread_start_error(m, "ThreadStartError", PyExc_RuntimeError);
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const InputError& e) {
            const py::handle type = dynamic_cast<const InputTypeError*>(&e) ? input_type_error : py::handle(input_error.ptr());
            py::object exc = type(e.what());
            exc.attr("field") = e.field();
            exc.attr("location") = e.location();
            PyErr_SetObject(type.ptr(), exc.ptr());
        } catch (const SolverError& e) {
            py::object exc = py::handle(solver_error.ptr())(e.what());
            exc.attr("step") = e.step();
            exc.attr("time_s") = e.time_s();
            exc.attr("residual") = e.residual();
            PyErr_SetObject(solver_error.ptr(), exc.ptr());
        } catch (const std::system_error& e) {
            py::object exc = py::handle(thread_start_error.ptr())(e.what());
            exc.attr("errno") = e.code().value();
            PyErr_SetObject(thread_start_error.ptr(), exc.ptr());
        }
    });
}

}  // namespace stackbeam_py
