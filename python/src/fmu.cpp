// stackbeam.export_fmu: the scenario's spring as an FMI 2.0 co-simulation FMU (docs/fmu.md), the
// library function of fmu/include/stackbeam_fmu/export.hpp (as `stackbeam fmu` on the command line).
#include <pybind11/pybind11.h>

#include <string>

#include "stackbeam/errors.hpp"
#ifdef STACKBEAM_WITH_FMU
#include "stackbeam_fmu/export.hpp"
#endif

namespace py = pybind11;

namespace stackbeam_py {

void bind_fmu(py::module_& m) {
    m.def(
        "export_fmu",
        [](const std::string& scenario_path, const std::string& out_path, const std::string& binary_path) {
#ifdef STACKBEAM_WITH_FMU
            py::gil_scoped_release release;
            stackbeam::fmu::export_fmu(scenario_path, out_path, binary_path);
#else
            (void)scenario_path, (void)out_path, (void)binary_path;
            throw stackbeam::InputError("export_fmu", "this stackbeam was built without the FMU (libzip not found: "
                                                      "apt-get install libzip-dev, then configure again)");
#endif
        },
        py::arg("scenario_path"), py::arg("out_path"), py::arg("binary_path") = "",
        "Writes the scenario file's spring as an FMI 2.0 co-simulation FMU (a zip archive) to out_path: the seat's "
        "motion in, the forces on the seat, the dissipated energy and the largest leaf stress out (docs/fmu.md). "
        "binary_path: the FMU's binary (default: this build's). InputError for a bad scenario.");
}

}  // namespace stackbeam_py
