#include <cstdio>

#include "stackbeam/errors.hpp"
#include "stackbeam/model/paper_example.hpp"
#include "stackbeam/io/scenario.hpp"
#include "stackbeam/time/simulation.hpp"

int main(int argc, char** argv) try {
    stackbeam::Scenario run;  // a scenario file if one is given, else the built-in example
    if (argc > 1) run = stackbeam::load_scenario(argv[1]);
    else run.model = stackbeam::paper_example(stackbeam::PaperCase::bonded);
    const stackbeam::System system(stackbeam::Model::build(run.model));
    run.simulation.t_end_s = 0.1;  // 100 closed-form steps of 1 ms
    const std::vector<stackbeam::StepRecord> records = stackbeam::simulate(system, run.simulation);
    std::printf("tied stiffness %.0f N/m, w(%g s) = %.6f m\n", system.tied_stiffness_n_per_m(),
                records.back().t_s, records.back().w_m);
    return 0;
} catch (const stackbeam::InputError& e) {  // names the field, e.g. "leaves[2].height_m: ..."
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
}
