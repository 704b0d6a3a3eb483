#pragma once
// Internal: mode "cvode" with leaves of density > 0 (docs/inertia.md), first part: a
// stack whose contact components are all held for good (every kept pair bonded), so
// the contact mode never changes. The motion lies in the null space of the contact
// rows, G (z - z_p) = 0, z = z_p + N q with N an orthonormal basis of null(G):
//     (N^T M N) q'' + N^T K N q = -N^T K z_p,
// a stiff linear ODE (leaf bending modes up to ~1e5..1e6 rad/s next to the 70 rad/s
// body mode) integrated by CVODE's BDF at order <= 2 (higher orders are unstable on
// the lightly damped oscillatory modes), Newton with a dense direct solver and the
// analytic (constant) Jacobian [0 I; -B 0], B = (N^T M N)^-1 N^T K N.
// Stacks with pairs that may open, close, stick or slip are refused (InputError):
// events between massive leaves are not built yet (use mode newmark).
#include <memory>

#include "stackbeam/cvode_stepper.hpp"
#include "stackbeam/simulation.hpp"

namespace stackbeam::detail {

class CvodeInertiaStepper {
public:
    CvodeInertiaStepper(const System& system, const SimulationOptions& options);
    ~CvodeInertiaStepper();
    CvodeInertiaStepper(const CvodeInertiaStepper&) = delete;
    CvodeInertiaStepper& operator=(const CvodeInertiaStepper&) = delete;
    /// Integrates to the next output time (t = i dt_s) and returns its record.
    const StepRecord& advance();
    const StepRecord& current() const noexcept;
    const CvodeStats& stats() const noexcept;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

/// True when mode cvode runs `system` with leaf inertia (a leaf has density > 0).
bool has_leaf_mass(const System& system);

}  // namespace stackbeam::detail
