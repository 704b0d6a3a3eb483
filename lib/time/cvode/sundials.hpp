#pragma once
// Internal: the one SUNDIALS layer of the cvode modes (SUNDIALS 6.4.1). CvodeSession owns
// the SUNContext, the CVODE memory, the state vectors and the solvers (RAII: freed in
// reverse order of creation), checks every SUNDIALS call (check(): SolverError naming the
// call and CVODE's flag name, with the time, the step count and the last step size), keeps
// CVODE's counters across restarts (CVodeReInit resets CVODE's own) and reads them in one
// place.
//
// Step limit (one policy for every cvode stepper): CvodeOptions::max_steps is the user's
// limit on CVODE's internal steps over the whole run. step() checks it after every CVode
// call (SolverError "cvode mode: more than cvode.max_steps = N steps at t = ... s"); CVODE's
// own per-call limit (CVodeSetMaxNumSteps) is set to kCvodeMaxStepsPerCall, an internal
// guard against a single runaway call of the output-driven stepper (CV_NORMAL); the
// event-driven steppers take one step per call (CV_ONE_STEP).
#include <cvode/cvode.h>
#include <sundials/sundials_context.h>

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "stackbeam/time/run_report.hpp"

namespace stackbeam::detail {

/// CVODE's per-call step limit (see above): 1e5 steps within one CVode call.
constexpr long kCvodeMaxStepsPerCall = 100000;

/// CVODE's name of a return flag (CVodeGetReturnFlagName, freed here).
std::string cvode_flag_name(int flag);

/// CVODE's cumulative counters over a run (across restarts).
struct CvodeCounters {
    long steps = 0, rhs_evaluations = 0, root_evaluations = 0, jacobian_evaluations = 0, linear_setups = 0;
};

/// Write access to a SUNDIALS band matrix (a band Jacobian: CvodeSession::use_band_newton), so
/// that the code filling it needs no SUNDIALS header.
class BandMatrixView {
public:
    explicit BandMatrixView(SUNMatrix J) : J_(J) {}
    /// Every entry 0: SUNMatZero's flag (0 on success).
    int set_zero();
    /// Entry (i, j), within the matrix's half-bandwidths.
    double& operator()(int i, int j);

private:
    SUNMatrix J_;
};

class CvodeSession {
public:
    /// `who` prefixes every message ("cvode mode", "cvode mode (leaf inertia)"); n: the
    /// state size. Creates the context and the vectors y (state), ydky (dense output) and
    /// atol (absolute tolerances), all zero.
    CvodeSession(std::string who, int n);
    ~CvodeSession();
    CvodeSession(const CvodeSession&) = delete;
    CvodeSession& operator=(const CvodeSession&) = delete;

    /// The state, dense-output and tolerance vectors as Eigen maps (length n).
    Eigen::Map<Eigen::VectorXd> y() { return map(y_); }
    Eigen::Map<Eigen::VectorXd> ydky() { return map(ydky_); }
    Eigen::Map<Eigen::VectorXd> atol() { return map(atol_); }
    N_Vector y_vector() { return y_; }

    /// CVODE memory with the method `lmm` (CV_ADAMS, CV_BDF) on rhs from t0 = 0 with the
    /// current y, rtol and the vector atol, `user` as user data; the error handler keeps
    /// CVODE's last error message for the diagnostics (nothing is printed).
    void create(int lmm, CVRhsFn rhs, void* user, double rtol);
    /// Fixed-point iteration (Adams, non-stiff).
    void use_fixed_point();
    /// Newton with a band direct solver of half-bandwidths (mu, ml) and the Jacobian jac.
    void use_band_newton(int mu, int ml, CVLsJacFn jac);
    /// Newton whose linear systems the stepper solves exactly itself: a matrix-embedded
    /// SUNLinearSolver (SUNLINEARSOLVER_MATRIX_EMBEDDED) that factorises with `setup` at
    /// CVODE's current gamma and solves with `solve` at the gamma of that factorisation (a
    /// modified Newton iteration, as with a direct solver), no Krylov iteration around it.
    /// `setup` and `solve` have the preconditioner signatures (their fy argument is null);
    /// `user` is their user data.
    void use_embedded_newton(CVLsPrecSetupFn setup, CVLsPrecSolveFn solve, void* user);
    /// The step limits: the per-call guard and the user's largest step [s] (0: none).
    void set_limits(double max_step_s);
    /// CVODE stops exactly at t_stop [s] (kept across reinit()).
    void set_stop_time(double t_stop);
    void set_max_order(int order);
    /// Root-finding on n witness functions, decreasing crossings only.
    void set_roots(int n, CVRootFn g);

    /// One CVode call to tout (itask CV_ONE_STEP or CV_NORMAL); returns its flag (>= 0)
    /// and the time reached. Throws SolverError on a failure or past `max_steps` steps.
    int advance(double tout, int itask, long max_steps, double& t_reached);
    /// CVODE's dense output at t within the last step, into ydky().
    void dense_output(double t);
    /// Restarts at (t, y()) with the stop time kept: CVodeReInit, counters carried on.
    void reinit(double t);
    void root_info(std::vector<int>& found);
    double last_step() const;
    const CvodeCounters& counters() const noexcept { return counters_; }

    /// Throws SolverError when flag < 0: "<who>: <call> failed: <FLAG NAME> (<CVODE's
    /// message>) at t = .. s after N steps, last step size h s".
    void check(int flag, const char* call) const;

private:
    std::string who_;
    int n_ = 0;
    SUNContext ctx_ = nullptr;
    N_Vector y_ = nullptr, ydky_ = nullptr, atol_ = nullptr;
    void* cv_ = nullptr;
    SUNNonlinearSolver nls_ = nullptr;
    SUNMatrix J_ = nullptr;
    SUNLinearSolver ls_ = nullptr;
    std::string error_;           // CVODE's last error message
    double t_stop_ = 0.0;
    bool has_stop_ = false;
    bool roots_ = false, linear_ = false;
    struct Embedded;                      // the matrix-embedded solver's content
    std::unique_ptr<Embedded> embedded_;
    CvodeCounters counters_, base_;  // now, and before the last CVodeReInit
    double t_ = 0.0;                 // the last time reached [s]

    Eigen::Map<Eigen::VectorXd> map(N_Vector v);
    void read_counters();
    static void error_handler(int code, const char* module, const char* function, char* msg, void* user);
};

}  // namespace stackbeam::detail
