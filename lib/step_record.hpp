#pragma once
// Internal: the part of a StepRecord that both time-stepping modes fill alike from
// the state (w, w', contact forces p) and the energies.
#include <Eigen/Dense>

#include "stackbeam/simulation.hpp"

namespace stackbeam::detail {

/// Sets r's w, w', force on the mass, probe friction force, pair-state counts (by
/// `laws`, the pairs and their tau rule), kinetic energy, the given whole-spring strain
/// and dissipated energies [J] and the balance against e0_j [J]. Leaves t, the
/// counters and the residual to the caller.
void fill_state(const System& system, const ContactProblem& laws, const Eigen::VectorXd& p, double w_m,
                double w_dot_m_per_s, double strain_energy_j, double dissipated_energy_j, double e0_j, StepRecord& r);

}  // namespace stackbeam::detail
