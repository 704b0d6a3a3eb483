/// @file main.cpp
/// `stackbeam`: the command line of the stackbeam library.
///
/// The physical problem: a leaf spring made of elastic leaves (Bernoulli-Euler
/// beams, massless) stacked on top of each other and held together by narrow
/// clamps. The leaves can slide on each other against Coulomb friction. A rigid
/// body R (the axle seat with its mass) is attached at midspan and starts moving
/// normal to the stack; the friction between the leaves makes the spring
/// hysteretic, so the vibration of R decays. This program simulates the built-in
/// example of Lee & Lim (1992), section 5: three leaves 0.5 x 0.05 x 0.005 m,
/// E = 2e10 Pa, pinned at both ends, four clamps at x = 0.1 ... 0.4 m, a 20 kg
/// body at midspan moving at 2 m/s, in one of three cases (bonded leaves,
/// friction mu = 0.5 with clamp force 1000 N, frictionless). Geometry:
/// docs/method.md; signs and units: include/stackbeam/conventions.hpp.
///
///   stackbeam simulate --case friction --t-end 2 --out friction.csv
///   stackbeam simulate --case friction --mode cvode --rtol 1e-8 --events events.csv --out friction.csv
///   stackbeam simulate --scenario scenarios/paper_friction.toml   (any stack: docs/model-and-scenarios.md;
///                      integrator options and --out given here override the file's)
///
/// writes one CSV row per time step (closed-form) or output time (cvode, every --dt),
/// columns of stackbeam::step_record_columns(); --events writes the cvode event log.
/// Every file is written to FILE.partial and renamed to FILE only when the whole run
/// succeeded; SIGINT / SIGTERM stop the run cleanly (run.hpp). Exit status: 0 success,
/// 2 bad input, 3 solver failure, 130 / 143 stopped by SIGINT / SIGTERM, 1 other errors.
///
/// `stackbeam sweep SPEC.toml` runs a base scenario at many points (docs/sweep.md):
/// sweep.cpp over the library's stackbeam/study/, sweep_plot.cpp, sweep_mpi.cpp (mpirun).
///
/// The files: options.cpp (arguments -> ModelSpec + SimulationOptions; the integrator's
/// flags come from the library's option table, option_table.hpp), run.cpp (the run, its
/// files, progress, interruption), summary.cpp (text and JSON summary), plot.cpp (--plot).
#include <CLI/CLI.hpp>

#include <iostream>
#include <sstream>
#include <string>

#include "fmu.hpp"
#include "options.hpp"
#include "plot.hpp"
#include "run.hpp"
#include "stackbeam/errors.hpp"
#include "stackbeam/model/model.hpp"
#include "summary.hpp"
#include "sweep.hpp"
#include "fit.hpp"

namespace {

using namespace stackbeam::cli;

int run_request(const SimulateRequest& request) {
    const stackbeam::Model model = stackbeam::Model::build(request.spec);
    const stackbeam::System system(model);
    if (const std::string advice = stackbeam::friction_mesh_advice(model); !advice.empty())
        std::cerr << "stackbeam: note: " << advice << "\n";
    stackbeam::choose_contact_path(system, request.options);  // throws for a path the solver cannot take
    install_interrupt_handlers();
    const RunResult result = run(request, system);
    if (result.signal == 0) {
        print_summary(request, system, result);
        if (!request.plot.empty()) {
            std::string note;
            const auto files = plot_run(request.out, request.plot, note, result.summary.loop.fancher_loop,
                                        result.summary.windup.has_value(), model.probe_pair() >= 0);
            for (const auto& f : files) std::printf("figure                     %s\n", f.c_str());
            if (files.empty()) std::printf("figures                    none: %s\n", note.c_str());
            if (!files.empty()) {  // the deformed stack at the extreme deflections (run.hpp kept them)
                const auto stack = plot_stack(system, result, request.plot, note, request.stack_stress);
                for (const auto& f : stack) std::printf("figure                     %s\n", f.c_str());
                if (stack.empty()) std::printf("figure (stack)             none: %s\n", note.c_str());
            }
        }
    }
    if (!request.summary.empty()) {
        write_json_summary(request, model, result);
        if (result.signal == 0) std::printf("summary                    %s\n", request.summary.c_str());
    }
    return result.signal != 0 ? 128 + result.signal : exit_ok;
}


int run_simulate(const SimulateArgs& args) {
    const SimulateRequest request = make_request(args);  // every argument checked before any work
    try {
        return run_request(request);
    } catch (const stackbeam::InputError& e) {
        // found when the run starts: a scenario's value is named by its key and line
        if (request.scenario && e.location().empty()) stackbeam::rethrow_in_scenario(*request.scenario, e);
        throw;
    }
}

int run_main(int argc, char** argv, const MpiWorld& world);

}  // namespace

int main(int argc, char** argv) {
    // under mpirun (sweep): MPI first, it may take its own arguments; a plain command never starts MPI
    MpiWorld world;
    try {
        world = mpi_start(argc, argv);
    } catch (const std::exception& e) {
        std::cerr << "stackbeam: error: " << e.what() << "\n";
        return exit_other;
    }
    const int status = run_main(argc, argv, world);
    mpi_finish(world);
    return status;
}

namespace {

int run_main(int argc, char** argv, const MpiWorld& world) {
    CLI::App app{"stackbeam: vibration of a stacked-beam leaf spring with Coulomb friction between the leaves\n"
                 "(Lee & Lim 1992, section 5 example: three leaves, four clamps, 20 kg body at 2 m/s)",
                 "stackbeam"};
    app.require_subcommand(1);
    app.footer("Examples:\n  stackbeam simulate --case friction --t-end 2 --out friction.csv\n"
               "  stackbeam simulate --scenario scenarios/paper_friction.toml\n"
               "  stackbeam sweep map.toml --jobs 2 --out-dir map   (a map over scenario keys: docs/sweep.md)\n"
               "Exit status: 0 success, 2 bad input, 3 solver failure, 130 / 143 stopped by SIGINT / SIGTERM\n"
               "(the rows so far stay in FILE.partial), 1 other errors.");

    // the subcommands, each with its flags (options.hpp, sweep.hpp, fit.hpp, fmu.hpp)
    SimulateArgs args;
    CLI::App* sim = add_simulate_command(app, args);
    SweepArgs sweep_args;
    CLI::App* sweep = add_sweep_command(app, sweep_args);
    FitArgs fit_args;
    CLI::App* fit = add_fit_command(app, fit_args);
    FmuArgs fmu_args;
    CLI::App* fmu = add_fmu_command(app, fmu_args);  // `stackbeam fmu SCENARIO.toml --out spring.fmu` (fmu.hpp)

    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForAllHelp& e) {
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        std::cerr << "stackbeam: error: " << e.what() << "\n(run 'stackbeam --help', 'stackbeam simulate --help' or 'stackbeam sweep --help')\n";
        return exit_input;
    }
    for (const CLI::Option* option : sim->get_options())
        if (option->count() > 0) args.given.insert(option->get_name());

    // an error: printed by rank 0 alone under mpirun, where it also stops the other ranks
    auto fail = [&](int status, const std::string& message) {
        if (world.rank == 0) std::cerr << "stackbeam: error: " << message << "\n";
        if (world.active && world.size > 1) mpi_abort(world, status);
        return status;
    };
    try {
        if (sim->parsed()) return run_simulate(args);
        if (sweep->parsed()) return run_sweep_command(sweep_args, world);
        if (fit->parsed()) return run_fit_command(fit_args);
        if (fmu->parsed()) return run_fmu_command(fmu_args);
        return exit_other;
    } catch (const ArgumentError& e) {
        return fail(exit_input, e.what());
    } catch (const stackbeam::InputError& e) {
        return fail(exit_input, e.what());
    } catch (const stackbeam::SolverError& e) {
        std::ostringstream message;  // the numbers as a stream prints them (6 digits)
        message << "solver failure at step " << e.step() << " (t = " << e.time_s() << " s, residual " << e.residual()
                << "): " << e.what();
        return fail(exit_solver, message.str());
    } catch (const std::exception& e) {
        return fail(exit_other, e.what());
    }
}

}  // namespace
