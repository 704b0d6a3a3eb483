#pragma once
// Helpers shared by the physics tests (and the benchmarks' stacks): runs of the paper
// example, the many-leaf stacks built from its leaf, and measurements on time series
// (period from zero crossings, peaks).
#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "stackbeam/errors.hpp"
#include "stackbeam/io/scenario.hpp"
#include "stackbeam/model/paper_example.hpp"
#include "stackbeam/time/closed_form_stepper.hpp"
#include "stackbeam/time/simulation.hpp"

namespace stackbeam::testing {

constexpr double kPi = 3.14159265358979323846;
constexpr double kSteel = 7850.0;  ///< steel's density [kg/m^3]

/// The InputError of parsing the scenario `text` as "test.toml": its field and message
/// ("accepted" if none).
inline std::pair<std::string, std::string> scenario_refusal(const std::string& text) {
    try {
        parse_scenario(text, "test.toml");
    } catch (const InputError& e) {
        return {e.field(), e.what()};
    }
    return {"accepted", ""};
}

inline std::vector<StepRecord> run_paper(PaperCase c, double t_end_s, double dt_s,
                                         Symmetry sym = Symmetry::half, double tol_m = 1e-10,
                                         SolverKind solver = SolverKind::exact) {
    PaperExampleOptions o;
    o.symmetry = sym;
    const System s(Model::build(paper_example(c, o)));
    SimulationOptions so;
    so.dt_s = dt_s;
    so.t_end_s = t_end_s;
    so.solver.kind = solver;
    so.solver.tolerance_m = tol_m;
    return simulate(s, so);
}

/// The paper example's case `c` with every leaf of density `density_kg_per_m3`; `massive_stack`:
/// set up for the whole massive stack under cvode (CvodeMassiveStepper): every interface elastic,
/// the clamps 10 mm long (an elastic layer over them), 10 elements per half leaf.
inline ModelSpec paper_with_mass(PaperCase c, double density_kg_per_m3, bool massive_stack) {
    PaperExampleOptions po;
    if (massive_stack) po.elements_per_half_leaf = 10;
    ModelSpec spec = paper_example(c, po);
    for (auto& leaf : spec.leaves) leaf.density_kg_per_m3 = density_kg_per_m3;
    if (massive_stack) {
        for (auto& f : spec.interfaces) f.contact = InterfaceContact::elastic;
        for (auto& cl : spec.clamps) cl.length_m = 0.01;
    }
    return spec;
}

/// A loading of `kind` whose time function (force_n [N] for an applied force, else displacement_m
/// [m]) is `shape` with `amplitude`, `frequency_hz` and `phase_rad` (time_function.hpp).
inline Loading periodic_loading(LoadingKind kind, TimeFunction::Shape shape, double amplitude, double frequency_hz,
                                double phase_rad = 0.0) {
    Loading load;
    load.kind = kind;
    TimeFunction& f = kind == LoadingKind::applied_force ? load.force_n : load.displacement_m;
    f.shape = shape;
    f.amplitude = amplitude;
    f.frequency_hz = frequency_hz;
    f.phase_rad = phase_rad;
    return load;
}

/// Options of a run in `mode` to t_end_s [s], a record every dt_s [s] (mode cvode's output
/// interval), the contact solver's tolerance tol_m [m] and CVODE's relative tolerance rtol.
inline SimulationOptions run_options(Mode mode, double t_end_s, double dt_s, double tol_m,
                                     double rtol = SimulationOptions{}.cvode.rtol) {
    SimulationOptions so;
    so.mode = mode;
    so.dt_s = dt_s;
    so.t_end_s = t_end_s;
    so.cvode.rtol = rtol;
    so.solver.tolerance_m = tol_m;
    return so;
}

/// The paper example's case `c` with `leaves` identical leaves of `elements` per half
/// leaf (its last leaf and interface repeated below, or the lowest ones dropped).
inline ModelSpec paper_stack(PaperCase c, int elements, int leaves) {
    ModelSpec spec = paper_example(c, PaperExampleOptions{elements});
    while (static_cast<int>(spec.leaves.size()) < leaves) {
        spec.leaves.push_back(spec.leaves.back());
        spec.interfaces.push_back(spec.interfaces.back());
    }
    spec.leaves.resize(static_cast<std::size_t>(leaves));
    spec.interfaces.resize(static_cast<std::size_t>(leaves - 1));
    return spec;
}

/// Every interface of `spec` with the elastic law, k_n and k_t per unit area [Pa/m] (0: derived).
inline ModelSpec with_elastic_interfaces(ModelSpec spec, double k_n_pa_per_m = 0.0, double k_t_pa_per_m = 0.0) {
    for (auto& f : spec.interfaces) {
        f.contact = InterfaceContact::elastic;
        f.normal_stiffness_pa_per_m = k_n_pa_per_m;
        f.tangential_stiffness_pa_per_m = k_t_pa_per_m;
    }
    return spec;
}

/// A graduated spring from the paper's leaf (friction case, mu = 0.5): the main leaf pinned
/// at both ends, leaf k below it shorter by 72 % of L x k / (leaves - 1) (0.5 m down to
/// 0.14 m), centred, free ends; two clamps of 1000 N at x = 0.2 and 0.3 m (inside every leaf).
/// The paper's stack of 3 leaves at 10 elements per half leaf with steel density [kg/m^3],
/// elastic interfaces (derived layer) and 10 mm clamps (an elastic layer over them); R starts at
/// w0 [m], at rest (each case sets its own initial conditions or loading).
inline ModelSpec steel_elastic_stack(PaperCase c, double w0_m = 0.0) {
    ModelSpec spec = with_elastic_interfaces(paper_stack(c, 10, 3));
    for (auto& leaf : spec.leaves) leaf.density_kg_per_m3 = 7850.0;
    for (auto& cl : spec.clamps) cl.length_m = 0.01;
    spec.rigid_body.initial_displacement_m = w0_m;
    spec.rigid_body.initial_velocity_m_per_s = 0.0;
    return spec;
}

inline ModelSpec graduated_stack(int elements, int leaves) {
    ModelSpec spec = paper_stack(PaperCase::friction, elements, leaves);
    const double L = spec.leaves[0].length_m;
    for (int k = 1; k < leaves; ++k) {
        auto& leaf = spec.leaves[static_cast<std::size_t>(k)];
        leaf.length_m = L * (1.0 - 0.72 * k / (leaves - 1));
        leaf.x_start_m = 0.5 * (L - leaf.length_m);
        leaf.left_support = leaf.right_support = SupportKind::free;
    }
    spec.clamps = {{0.2, 1000.0}, {0.3, 1000.0}};
    return spec;
}

/// Times [s] where w crosses zero upwards, by linear interpolation between steps.
/// max |w_a - w_b| [m] over the records two runs share by index (runs on the same output times).
inline double max_w_deviation(const std::vector<StepRecord>& a, const std::vector<StepRecord>& b) {
    double d = 0.0;
    for (std::size_t i = 0; i < std::min(a.size(), b.size()); ++i) d = std::max(d, std::abs(a[i].w_m - b[i].w_m));
    return d;
}

/// The largest |energy balance error| [J] over a run's records.
inline double max_balance_error(const std::vector<StepRecord>& r) {
    double e = 0.0;
    for (const auto& rec : r) e = std::max(e, std::abs(rec.energy_balance_error_j));
    return e;
}

inline std::vector<double> upward_zero_crossings(const std::vector<StepRecord>& r) {
    std::vector<double> t;
    for (std::size_t i = 1; i < r.size(); ++i)
        if (r[i - 1].w_m < 0.0 && r[i].w_m >= 0.0)
            t.push_back(r[i - 1].t_s + (r[i].t_s - r[i - 1].t_s) * (-r[i - 1].w_m) / (r[i].w_m - r[i - 1].w_m));
    return t;
}

/// Mean period [s] from the first to the last upward zero crossing (t = 0 counts: w(0) = 0, w' > 0).
inline double mean_period(const std::vector<StepRecord>& r) {
    std::vector<double> t = upward_zero_crossings(r);
    t.insert(t.begin(), 0.0);
    return (t.back() - t.front()) / static_cast<double>(t.size() - 1);
}

/// Extreme value of the parabola through three equally spaced samples a, b, c (b the extreme one).
inline double parabola_extremum(double a, double b, double c) {
    const double den = a - 2 * b + c;
    return den == 0.0 ? b : b - 0.125 * (a - c) * (a - c) / den;
}

/// Largest |w| [m], refined by a parabola through the sampled maximum and its neighbours.
inline double peak_abs_w(const std::vector<StepRecord>& r) {
    std::size_t k = 1;
    for (std::size_t i = 1; i + 1 < r.size(); ++i)
        if (std::abs(r[i].w_m) > std::abs(r[k].w_m)) k = i;
    return parabola_extremum(std::abs(r[k - 1].w_m), std::abs(r[k].w_m), std::abs(r[k + 1].w_m));
}

/// First local maximum of w [m] (the first swing's extremum: w(0) = 0, w' > 0), refined by a
/// parabola through the sampled maximum and its neighbours, so that the dt grid does not
/// quantise it; NaN if the records hold none.
inline double first_max_w(const std::vector<StepRecord>& r) {
    for (std::size_t i = 1; i + 1 < r.size(); ++i)
        if (r[i].w_m > r[i - 1].w_m && r[i].w_m >= r[i + 1].w_m)
            return parabola_extremum(r[i - 1].w_m, r[i].w_m, r[i + 1].w_m);
    return std::nan("");
}

/// Steel leaves of a vehicle spring (E = 200 GPa, 60 mm wide), for the assembly and clip tests.
constexpr double kSteelE_pa = 2e11, kSteelLeafWidth_m = 0.06;
inline double steel_leaf_bending_stiffness(double t_m) { return kSteelE_pa * kSteelLeafWidth_m * t_m * t_m * t_m / 12.0; }

/// A steel leaf of length 2 half_length centred on x = seat_x (the seat), thickness t, free
/// radius R (0: flat), pinned at both ends or free.
inline LeafSpec steel_leaf(double seat_x_m, double half_length_m, double t_m, double free_radius_m, bool pinned) {
    LeafSpec s;
    s.length_m = 2.0 * half_length_m;
    s.x_start_m = seat_x_m - half_length_m;
    s.height_m = t_m;
    s.width_m = kSteelLeafWidth_m;
    s.youngs_modulus_pa = kSteelE_pa;
    s.free_radius_m = free_radius_m;
    s.left_support = s.right_support = pinned ? SupportKind::pinned : SupportKind::free;
    return s;
}

/// A two-leaf spring: leaf 0 (half length L1 = 0.5 m, t1 = 8 mm, free radius R1) pinned at its
/// eyes, below it leaf 1 (L2 = 0.3 m, t2 = 6 mm, R2), centred and free, frictionless; the seat
/// (R, 10 kg) at x = L1; elements of 10 mm.
constexpr double kTwoLeafL1_m = 0.5, kTwoLeafL2_m = 0.3, kTwoLeafT1_m = 0.008, kTwoLeafT2_m = 0.006;
inline ModelSpec two_leaf_spring(double R1_m, double R2_m) {
    ModelSpec spec;
    spec.leaves = {steel_leaf(kTwoLeafL1_m, kTwoLeafL1_m, kTwoLeafT1_m, R1_m, true),
                   steel_leaf(kTwoLeafL1_m, kTwoLeafL2_m, kTwoLeafT2_m, R2_m, false)};
    spec.interfaces = {{InterfaceLaw::coulomb, 0.0}};
    spec.rigid_body.mass_kg = 10.0;
    spec.rigid_body.x_m = kTwoLeafL1_m;
    spec.mesh.element_length_m = 0.01;
    return spec;
}

/// A clamped two-leaf stack (test_close_clamps, test_soak): two massless steel leaves (E = 2.06e11 Pa)
/// of one thickness and width, the top one `top_length_m` long from x = 0 and pinned at both ends, the
/// lower one `lower_length_m` long centred under it with free ends; one Coulomb interface (rigid
/// contact or an elastic layer); the body at mid-span. No clamps: the caller places them. The defaults
/// are test_soak's clamp_stack.
struct ClampedPairSpec {
    double top_length_m = 0.6, lower_length_m = 0.5, thickness_m = 0.006, width_m = 0.05;
    double friction_coefficient = 0.2;
    InterfaceContact contact = InterfaceContact::rigid;
    double body_mass_kg = 1.0, element_length_m = 0.025;
};
inline ModelSpec clamped_pair_stack(const ClampedPairSpec& c) {
    ModelSpec s;
    for (int i = 0; i < 2; ++i) {
        LeafSpec l;
        l.length_m = i == 0 ? c.top_length_m : c.lower_length_m;
        l.x_start_m = 0.5 * (c.top_length_m - l.length_m);
        l.height_m = c.thickness_m;
        l.width_m = c.width_m;
        l.youngs_modulus_pa = 2.06e11;
        l.left_support = l.right_support = i == 0 ? SupportKind::pinned : SupportKind::free;
        s.leaves.push_back(l);
    }
    InterfaceSpec f;
    f.law = InterfaceLaw::coulomb;
    f.friction_coefficient = c.friction_coefficient;
    f.contact = c.contact;
    s.interfaces.push_back(f);
    s.rigid_body.x_m = 0.5 * c.top_length_m;
    s.rigid_body.mass_kg = c.body_mass_kg;
    s.mesh.element_length_m = c.element_length_m;
    return s;
}

/// The field named by the InputError that `f` throws, or "" when it throws none.
template <class F>
std::string input_error_field(F&& f) {
    try {
        f();
    } catch (const InputError& e) {
        return e.field();
    }
    return "";
}

/// The sparse contact problems of the first `steps` closed-form steps of `spec` on the sparse
/// path (so.contact_path is set to sparse), in order: to replay them with other solvers.
inline std::vector<SparseContactProblem> sparse_step_problems(const ModelSpec& spec, int steps,
                                                              SimulationOptions so = {}) {
    const System sys(Model::build(spec));
    so.contact_path = ContactPath::sparse;
    ClosedFormStepper st(sys, so);
    std::vector<SparseContactProblem> problems;
    for (int i = 0; i < steps; ++i) {
        st.advance();
        problems.push_back(st.contact_solver().last_sparse_problem());
    }
    return problems;
}

}  // namespace stackbeam::testing
