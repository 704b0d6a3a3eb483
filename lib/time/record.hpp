#pragma once
// Internal: the part of a StepRecord every mode fills alike from the state (w, w', contact
// forces p) and the energies, the pairs at one time, and a fixed-step mode's counters.
#include <Eigen/Dense>

#include "stackbeam/time/run_report.hpp"
#include "stackbeam/time/simulation.hpp"

namespace stackbeam::detail {

/// The loading's part of a record at one time (loading.hpp, StepRecord).
struct LoadState {
    double external_force_n = 0.0;   ///< whole spring [N]: F - m g - m y_b'' (rig: the spring force)
    double external_work_j = 0.0;    ///< whole spring [J]
    double base_displacement_m = 0.0;
    bool prescribed = false;         ///< w is prescribed: force_on_mass_n is m w''(t), not the force balance
    double force_on_mass_n = 0.0;    ///< prescribed only: m w''(t) [N]
};

/// Sets r's w, w', force on the mass, probe friction force, pair-state counts (by
/// `laws`, the pairs and their tau rule), kinetic energy, the given whole-spring strain
/// and dissipated energies [J], the loading's fields and the balance
/// e0 + external work - (kinetic + strain + dissipated) [J]. Leaves t, the
/// counters and the residual to the caller.
void fill_state(const System& system, const ContactLaws& laws, const Eigen::VectorXd& p, double w_m,
                double w_dot_m_per_s, double strain_energy_j, double dissipated_energy_j, double e0_j,
                const LoadState& load, StepRecord& r);

/// The pairs at one time (Stepper::pairs()): states by `laws` (the pairs and their tau
/// rule), forces p [N] and the relative positions rel = s + d [m], all rows; the gap of
/// a normal row is max(0, d0 - rel) with d0 the system's initial offsets.
std::vector<PairRecord> pair_records(const System& system, const ContactLaws& laws, const Eigen::VectorXd& p,
                                     const Eigen::VectorXd& rel);

/// A fixed-step mode's counters after one more step whose record is `r`: one step, its
/// contact iterations and factorisations added.
inline void count_step(const StepRecord& r, RunReport& report) {
    ++report.steps;
    report.contact_iterations += r.contact_iterations;
    report.factorizations += r.factorizations;
}

}  // namespace stackbeam::detail
