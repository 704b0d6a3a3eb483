#pragma once
/// @file export.hpp
/// The exporter of stackbeam's FMI 2.0 co-simulation FMU (docs/fmu.md): a scenario's spring
/// as spring.fmu, the seat's motion in, the forces on the seat, the dissipated energy and the
/// largest leaf stress out. `stackbeam fmu SCENARIO.toml --out spring.fmu` and the Python
/// module's stackbeam.export_fmu call it. Target stackbeam::fmu_export (built when libzip is found).
#include <string>

#include "stackbeam/io/scenario.hpp"

namespace stackbeam::fmu {

/// The FMU's binary this build made (binaries/linux64/stackbeam_spring.so inside the archive):
/// the environment variable STACKBEAM_FMU_BINARY when set, else the build's own file.
std::string default_binary_path();

/// modelDescription.xml of the FMU of `scenario` whose file text is `scenario_text` (its GUID is
/// made from the text, which the FMU carries as resources/scenario.toml).
std::string model_description(const Scenario& scenario, const std::string& scenario_text);

/// Writes the FMU of the scenario file `scenario_path` to `out_path` (a zip archive:
/// modelDescription.xml, resources/scenario.toml, binaries/linux64/stackbeam_spring.so).
/// `binary_path`: the FMU's binary; empty: default_binary_path(). Throws InputError for a bad
/// scenario (its key and line) or a binary that is missing (field "binary"), std::runtime_error
/// when the archive cannot be written. Prints nothing.
void export_fmu(const std::string& scenario_path, const std::string& out_path, const std::string& binary_path = "");

}  // namespace stackbeam::fmu
