#pragma once
// Internal: the state the units of the sparse contact path share (sparse_path.cpp): the
// mode solver of the current (K, G), the pair laws, the current modes and the active-set
// passes on them, and the natural map of the contact laws. The box-QP methods
// (box_qp_methods.hpp) and the transition methods (transitions.hpp) each take it with
// one signature; SparseContactSolver (sparse_solver.cpp) orchestrates them.
#include <Eigen/Dense>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseLU>
#include <memory>
#include <vector>

#include "contact/active_set.hpp"
#include "contact/sparse/linear/mode_solver.hpp"
#include "contact/sparse/driver/switches.hpp"
#include "stackbeam/contact/contact.hpp"

namespace stackbeam::detail::sparse {

/// The right-hand side of one solve: K z = b + G^T p, s = G z - d.
struct Step {
    const Eigen::VectorXd& b;  ///< load with p = 0, one entry per DOF
    const Eigen::VectorXd& d;  ///< offsets [m], one entry per contact row
};

/// The elastic layer of `pr` (SparseContactProblem::layer_compliance) as extra degrees of
/// freedom (docs/decisions/013): layered.K = diag(K, 1/c_L) over the layer rows, layered.G =
/// [G  E] with E(r, n + j) = 1 for the j-th layer row r, layered.b = 0 (n + layer rows
/// entries); the rest of `layered` is left as it was. False (nothing set) if no row has a layer.
bool layer_structure(const SparseContactProblem& pr, SparseContactProblem& layered);

/// `tuning` with the switches' choice of the fixed-pattern LU.
inline ModeSolverTuning with_switches(ModeSolverTuning tuning, const Switches& sw) {
    tuning.fixed_pattern = sw.fixed_pattern == 1                 ? FixedPatternLu::eigen
                           : sw.fixed_pattern == 2 && klu_built() ? FixedPatternLu::klu
                           : sw.fixed_pattern == 3 && klu_built() ? FixedPatternLu::klu_held
                           : sw.fixed_pattern == 4 && klu_built() ? FixedPatternLu::klu_held_amd
                                                                  : FixedPatternLu::off;
    tuning.residual_refactor_check = sw.residual_refactor_check;
    tuning.block_border_solves = sw.block_border_solves;
    tuning.fixed_max_border_rows = sw.fixed_border_rows;
    tuning.schur_fresh_max_rows = sw.schur_fresh_max_rows;
    return tuning;
}

/// The mode solver's key of a set of modes: its modes and the tau rule (the slip coupling depends
/// on it), as SparsePath::solve_modes and the homotopy's base name a set.
inline std::vector<signed char> solver_key(const ContactProblem& laws, const modes::ModeSet& modes) {
    std::vector<signed char> key = modes.key();
    key.push_back(static_cast<signed char>(laws.tau_rule));
    return key;
}

struct KeptBase;  // the homotopy's base kept across steps (path_following.cpp, Switches::path_keep_base)

struct SparsePath {
    SolverOptions options;   ///< tolerance_m, max_active_set_iterations, tresca_anderson_depth
    Switches switches;       ///< the methods (SparsePathTuning::methods, switches.hpp)
    /// the caller's observer (SparsePathTuning::observer, trace.hpp), or nullptr: nothing recorded
    TransitionTrace* observer = nullptr;
    ModeSolver solver;       ///< the linear problem of a set of modes on the current (K, G)
    ContactProblem laws;     ///< pairs and tau rule; W empty, q zero (sizes only)
    modes::ModeSet modes;    ///< the current modes
    Eigen::VectorXd s;       ///< s = G z - d [m] where the last unit left it (the solver's answer's at the end)
    Eigen::VectorXd best_p;  ///< the semismooth Newton method's iterate of smallest ||F|| (its last run)
    bool handed_over = false;  ///< its last run stopped for the homotopy (Switches::rest_path_violations)
    // workspaces made once per (K, G): the interior-point method's LDL^T of K + G^T Sigma^-1 G
    // (its ordering) and the smoothing Newton method's Jacobian and LU (its ordering)
    Eigen::SimplicialLDLT<SpMat, Eigen::Lower, Eigen::AMDOrdering<int>> ipm_ldlt;
    bool ipm_analysed = false;
    Eigen::Index ipm_nnz = 0;
    SpMat Js;
    std::unique_ptr<PatternLu> js_lu;  ///< Eigen's SparseLU, or KLU with Switches::fixed_pattern >= 2
    bool js_analysed = false;
    /// the homotopy's base, its columns and solutions, kept while the mode solver's current
    /// factorisation is the base's (Switches::path_keep_base, docs/decisions/045)
    std::shared_ptr<KeptBase> kept;
    /// solves (steps) begun since the homotopy last ran: the kept base serves the step of the path
    /// and the next one only (a set of modes that stays is then factorised once, so the steps after
    /// it are the cached affine solves, not a kept-base solve each)
    int solves_since_path = 0;

    SparsePath(const SolverOptions& o, const ModeSolverTuning& tuning, const Switches& sw,
               TransitionTrace* obs = nullptr)
        : options(o), switches(sw), observer(obs), solver(with_switches(tuning, sw)) {
        if (obs) solver.set_route_stats(&obs->routes);  // the study's routes (decision 038)
    }

    /// A new structure (K, G, pairs): validates `pr` (InputError), refactorises, forgets the modes.
    void reset(const SparseContactProblem& pr);
    const SparseStiffness& stiffness() const { return solver.stiffness(); }
    const Eigen::VectorXd& diag() const { return solver.stiffness().diag; }

    /// Solves the linear problem of the current modes for `step` into p and z; returns 1
    /// if it factorised. Throws SingularModes.
    int solve_modes(const Step& step, Eigen::VectorXd& p, Eigen::VectorXd& z);
    /// Sets s = G z - d and returns the number of violated modes at (p, s) (threshold
    /// kAccept x tolerance, or the round-off of s if larger).
    int count_violations(const Eigen::VectorXd& d, const Eigen::VectorXd& p, const Eigen::VectorXd& z);
    /// At most max_passes active-set passes from the current modes (active_set.hpp);
    /// true when no mode is violated.
    bool passes(const Step& step, Eigen::VectorXd& p, Eigen::VectorXd& z, int max_passes, SolveResult& r);
    /// The natural map F(p, s) of the contact laws per component in metres, and with
    /// `set_modes` the modes of its generalised Jacobian at (p, s) (sparse_path.cpp).
    void natural_residual(const Eigen::VectorXd& p, const Eigen::VectorXd& s, Eigen::VectorXd& F, bool set_modes);

private:
    // the linearisation of the modes solve_modes last solved (kept while they stay)
    modes::ModeLinearization lin_;
    bool lin_ok_ = false;
    std::vector<signed char> lin_nmode_, lin_tmode_, lin_key_;
    TauRule lin_tau_rule_ = TauRule::current;
};

}  // namespace stackbeam::detail::sparse
