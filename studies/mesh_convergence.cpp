// Mesh convergence of a graduated spring with friction, rigid vs elastic interfaces
// (issue 18; docs/contact-solvers.md, "Mesh convergence"): the spring of
// tests/test_support.hpp graduated_stack(el, leaves) (the paper's 5 mm leaves, mu = 0.5,
// kappa_rigid = 0.01 el), mode closed-form, exact solver, run on a series of meshes; one
// Markdown table row per run. Failed steps are counted, not fatal (stop_on_nonconvergence
// off), so the rigid law's failures show.
//
//   mesh_convergence LEAVES T_END_S DT_S LAW EL...   LAW: elastic, rigid or both (elastic first)
//   e.g. mesh_convergence 4 0.1 0.001 both 20 40 80 160 320
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "stackbeam/stackbeam.hpp"
#include "stackbeam/time/closed_form_stepper.hpp"
#include "test_support.hpp"

using namespace stackbeam;

namespace {

void run(int leaves, int el, InterfaceContact law, double t_end_s, double dt_s) {
    ModelSpec spec = testing::graduated_stack(el, leaves);
    for (auto& f : spec.interfaces) f.contact = law;
    const Model model = Model::build(spec);
    const System sys(model);
    SimulationOptions o;
    o.dt_s = dt_s;
    o.t_end_s = t_end_s;
    o.stop_on_nonconvergence = false;
    const auto t0 = std::chrono::steady_clock::now();
    ClosedFormStepper st(sys, o);
    std::vector<StepRecord> rec{st.current()};
    int failed = 0;
    double max_pn = 0.0, max_balance = 0.0, max_residual = 0.0;
    while (rec.back().t_s < t_end_s - 0.5 * dt_s) {
        rec.push_back(st.advance());
        if (rec.back().contact_residual_m > o.solver.tolerance_m) ++failed;
        max_residual = std::max(max_residual, rec.back().contact_residual_m);
        max_balance = std::max(max_balance, std::abs(rec.back().energy_balance_error_j));
        for (const ContactPair& p : sys.pairs())  // largest compressive normal force [N]
            if (p.kind == PairKind::coulomb && p.row_n >= 0) max_pn = std::max(max_pn, -st.contact_forces()[p.row_n]);
    }
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::size_t k = 1;  // the sampled first maximum, for its time
    while (k + 1 < rec.size() && !(rec[k].w_m > rec[k - 1].w_m && rec[k].w_m >= rec[k + 1].w_m)) ++k;
    std::printf("| %d | %s | %d | %.3f | %.2f | %.2f | %d/%zu | %.1e | %.4f | %.4f | %.4f | %.1f | %.1e | %.2f |\n", leaves,
                law == InterfaceContact::elastic ? "elastic" : "rigid", el, 250.0 / el, 0.01 * el,
                friction_mesh_ratio(model).ratio, failed, rec.size() - 1, max_residual, 1e3 * testing::first_max_w(rec), rec[k].t_s,
                rec.back().dissipated_energy_j, max_pn, max_balance, wall);
    std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
    if (argc < 6) {
        std::fprintf(stderr, "usage: %s LEAVES T_END_S DT_S elastic|rigid|both EL... (elements per half leaf)\n",
                     argv[0]);
        return 2;
    }
    const int leaves = std::atoi(argv[1]);
    const double t_end_s = std::atof(argv[2]), dt_s = std::atof(argv[3]);
    const std::string law = argv[4];
    std::printf("graduated %d-leaf spring, mu = 0.5, closed-form, exact solver, dt = %g s, t_end = %g s\n\n", leaves,
                dt_s, t_end_s);
    std::printf("| leaves | law | el | h [mm] | kappa_rigid | kappa | failed steps | max residual [m] | first max w [mm] "
                "| at t [s] | dissipated at t_end [J] | max p_n [N] | max balance error [J] | wall [s] |\n");
    std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
    for (const InterfaceContact c : {InterfaceContact::elastic, InterfaceContact::rigid})
        if (law == "both" || law == (c == InterfaceContact::elastic ? "elastic" : "rigid"))
            for (int i = 5; i < argc; ++i) run(leaves, std::atoi(argv[i]), c, t_end_s, dt_s);
}
