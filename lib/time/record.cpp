// The record's state part and the pairs at one time (record.hpp).
#include "time/record.hpp"

#include <algorithm>
#include <limits>

namespace stackbeam {

std::vector<PairRecord> detail::pair_records(const System& system, const ContactLaws& laws, const Eigen::VectorXd& p,
                                             const Eigen::VectorXd& rel) {
    std::vector<PairRecord> out(laws.pairs.size());
    const Eigen::VectorXd& d0 = system.initial_offsets_m();
    for (std::size_t k = 0; k < out.size(); ++k) {
        const ContactPair& pr = laws.pairs[k];
        const PairSpec& spec = system.pair_spec(static_cast<int>(k));
        PairRecord& r = out[k];
        r.pair = static_cast<int>(k);
        r.interface_index = spec.interface_index;
        r.x_m = spec.x_m;
        r.state = pair_state(laws, static_cast<int>(k), p);
        if (pr.row_n >= 0) {
            r.p_n_n = p[pr.row_n];
            r.gap_m = std::max(0.0, d0[pr.row_n] - rel[pr.row_n]);
        }
        if (pr.row_t >= 0) {
            r.p_t_n = p[pr.row_t];
            r.slip_m = rel[pr.row_t];
        }
    }
    return out;
}

void detail::fill_state(const System& system, const ContactLaws& laws, const Eigen::VectorXd& p, double w_m,
                        double w_dot_m_per_s, double strain_energy_j, double dissipated_energy_j, double e0_j,
                        const LoadState& load, StepRecord& r) {
    const double f = system.model().whole_spring_factor();
    r.w_m = w_m;
    r.w_dot_m_per_s = w_dot_m_per_s;
    const double cp = p.size() > 0 ? system.coupling().dot(p) : 0.0;
    r.spring_force_n = f * (system.stiffness_n_per_m() * w_m - cp);
    r.external_force_n = load.external_force_n;
    r.force_on_mass_n = load.prescribed ? load.force_on_mass_n : load.external_force_n - r.spring_force_n;
    r.base_displacement_m = load.base_displacement_m;
    r.external_work_j = load.external_work_j;
    // The probe pair may carry no tangential component (mu = 0, or fixed by a support):
    // its friction force is then zero. NaN only when the model has no probe at all.
    const int probe = system.probe_pair();
    const bool has_probe = system.model().probe_pair() >= 0;
    r.probe_friction_force_n = !has_probe ? std::numeric_limits<double>::quiet_NaN()
                               : (probe >= 0 && system.pairs()[probe].row_t >= 0) ? p[system.pairs()[probe].row_t]
                                                                                   : 0.0;
    r.n_stick = r.n_slip = r.n_open = 0;
    for (int k = 0; k < static_cast<int>(laws.pairs.size()); ++k) {
        const PairState s = pair_state(laws, k, p);
        if (s == PairState::stick) ++r.n_stick;
        else if (s == PairState::slip) ++r.n_slip;
        else ++r.n_open;
    }
    r.kinetic_energy_j = 0.5 * system.model().spec().rigid_body.mass_kg * w_dot_m_per_s * w_dot_m_per_s;
    r.strain_energy_j = strain_energy_j;
    r.dissipated_energy_j = dissipated_energy_j;
    r.energy_balance_error_j =
        e0_j + load.external_work_j - (r.kinetic_energy_j + r.strain_energy_j + r.dissipated_energy_j);
}

}  // namespace stackbeam
