// `stackbeam fmu` (fmu.hpp): the subcommand over the library function stackbeam::fmu::export_fmu.
#include "fmu.hpp"

#include <cstdio>

#include "stackbeam/errors.hpp"
#ifdef STACKBEAM_WITH_FMU
#include "stackbeam_fmu/export.hpp"
#endif

namespace stackbeam::cli {

CLI::App* add_fmu_command(CLI::App& app, FmuArgs& args) {
    CLI::App* fmu = app.add_subcommand("fmu", "Write the scenario's spring as an FMI 2.0 co-simulation FMU (seat motion in, "
                                              "forces, dissipated energy and largest leaf stress out; docs/fmu.md)");
    fmu->add_option("scenario", args.scenario, "the scenario file (TOML); its loading is replaced by the importer's seat motion")
        ->required();
    fmu->add_option("--out", args.out, "the FMU to write, e.g. spring.fmu")->required();
    fmu->add_option("--binary", args.binary, "the FMU's binary stackbeam_spring.so (default: this build's)");
    fmu->footer("Example: stackbeam fmu scenarios/rig_friction.toml --out spring.fmu\n"
                "Exit status: 0 written, 2 bad input (the scenario's key and line), 1 other errors.");
    return fmu;
}

int run_fmu_command(const FmuArgs& args) {
#ifdef STACKBEAM_WITH_FMU
    stackbeam::fmu::export_fmu(args.scenario, args.out, args.binary);
    std::printf("fmu                        %s\n", args.out.c_str());
    return 0;
#else
    (void)args;
    throw InputError("fmu", "this stackbeam was built without the FMU (libzip not found: apt-get install libzip-dev, "
                            "then configure again)");
#endif
}

}  // namespace stackbeam::cli
