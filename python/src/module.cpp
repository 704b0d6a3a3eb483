// stackbeam._core: the C++ library under the Python package stackbeam (python/stackbeam/,
// docs/python.md). The package's Python layer (Result, simulate's keyword options, plot)
// is in __init__.py; this file binds the scenario's data, the runs and the stepper.
//
// Names: a scenario's model is reached by the scenario file's key paths
// (scenario.model.leaves[0].height_m is the key leaves[0].height_m), its integrator by the
// members of SimulationOptions (scenario.simulation.cvode.rtol is integrator.cvode.rtol).
// Threads: a run releases the GIL while it steps; the main thread takes it back about every
// 20 ms to let Python see a pending signal (Ctrl-C: KeyboardInterrupt).
//
// The bindings by concern: bindings.hpp (the shared pieces), errors.cpp, scenario.cpp (the
// scenario, its model's entries and the options), results.cpp (results as numpy arrays),
// run.cpp (simulate's run and the Stepper), sweep.cpp.
#include "bindings.hpp"

namespace stackbeam_py {
void bind_fmu(py::module_& m);  // fmu.cpp: export_fmu (docs/fmu.md)
}

PYBIND11_MODULE(_core, m) {
    m.doc() = "stackbeam's C++ core; use the package stackbeam (docs/python.md)";

    // numpy's C API now, while the import holds the GIL on one thread: pybind11 2.10 looks it up
    // in a function-local static on the first array made, importing numpy inside the static's
    // guard, and two runs finishing at once on two threads deadlocked there (one thread holding
    // the guard and waiting for the GIL, the other holding the GIL and waiting for the guard)
    py::array_t<double> first_array(0);
    (void)first_array;

    stackbeam_py::bind_errors(m);
    stackbeam_py::bind_scenario(m);
    stackbeam_py::bind_run(m);
    stackbeam_py::bind_sweep(m);
    stackbeam_py::bind_fit(m);
    stackbeam_py::bind_fmu(m);
}
