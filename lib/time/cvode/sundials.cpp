// The SUNDIALS layer of the cvode modes (sundials.hpp).
#include "time/cvode/sundials.hpp"

#include <nvector/nvector_serial.h>
#include <sunlinsol/sunlinsol_band.h>
#include <sunmatrix/sunmatrix_band.h>
#include <sunnonlinsol/sunnonlinsol_fixedpoint.h>

#include <cmath>
#include <cstdlib>
#include <utility>

#include "stackbeam/errors.hpp"

namespace stackbeam::detail {

/// The content of the matrix-embedded linear solver: the stepper's factorisation and solve,
/// the gamma of the last factorisation, and the number of factorisations.
struct CvodeSession::Embedded {
    void* cv = nullptr;
    CVLsPrecSetupFn setup = nullptr;
    CVLsPrecSolveFn solve = nullptr;
    void* user = nullptr;
    double gamma = 0.0;
    long setups = 0;

    static Embedded* of(SUNLinearSolver S) { return static_cast<Embedded*>(S->content); }
    static SUNLinearSolver_Type type(SUNLinearSolver) { return SUNLINEARSOLVER_MATRIX_EMBEDDED; }
    static SUNLinearSolver_ID id(SUNLinearSolver) { return SUNLINEARSOLVER_CUSTOM; }
    /// CVODE (6.x) calls no setup on a matrix-embedded solver: the solve decides. It
    /// factorises at the current gamma when there is no factorisation of the current modes
    /// (the stepper's solve answers > 0) or gamma moved by more than kRefactor since the last
    /// one (CVODE's own rule for its direct solvers, dgmax = 0.3), and scales the solution by
    /// 2 / (1 + gamma / gamma_lu) as CVODE does for a direct solver's stale gamma.
    static constexpr double kRefactor = 0.3;
    int factorise(sunrealtype t, N_Vector y, sunrealtype gamma_now) {
        sunbooleantype jcur = SUNFALSE;
        const int flag = setup(t, y, nullptr, SUNFALSE, &jcur, gamma_now, user);
        if (flag != 0) return flag > 0 ? SUNLS_PSET_FAIL_REC : SUNLS_PSET_FAIL_UNREC;
        gamma = gamma_now;
        ++setups;
        return SUNLS_SUCCESS;
    }
    static int do_solve(SUNLinearSolver S, SUNMatrix, N_Vector x, N_Vector b, sunrealtype tol) {
        Embedded* e = of(S);
        sunrealtype t = 0.0, gamma_now = 0.0;
        N_Vector y = nullptr;
        if (CVodeGetCurrentTime(e->cv, &t) < 0 || CVodeGetCurrentGamma(e->cv, &gamma_now) < 0 ||
            CVodeGetCurrentState(e->cv, &y) < 0)
            return SUNLS_PSOLVE_FAIL_UNREC;
        if (!(e->gamma > 0.0) || std::abs(gamma_now / e->gamma - 1.0) > kRefactor) {
            const int f = e->factorise(t, y, gamma_now);
            if (f != SUNLS_SUCCESS) return f;
        }
        int flag = e->solve(t, y, nullptr, b, x, e->gamma, tol, 0, e->user);
        if (flag > 0) {  // no factorisation of the current modes yet (a restart): factorise, again
            const int f = e->factorise(t, y, gamma_now);
            if (f != SUNLS_SUCCESS) return f;
            flag = e->solve(t, y, nullptr, b, x, e->gamma, tol, 0, e->user);
        }
        if (flag != 0) return flag > 0 ? SUNLS_PSOLVE_FAIL_REC : SUNLS_PSOLVE_FAIL_UNREC;
        if (gamma_now != e->gamma) N_VScale(2.0 / (1.0 + gamma_now / e->gamma), x, x);
        return SUNLS_SUCCESS;
    }
    static int do_free(SUNLinearSolver S) {
        if (S == nullptr) return SUNLS_SUCCESS;
        S->content = nullptr;  // owned by the session
        SUNLinSolFreeEmpty(S);
        return SUNLS_SUCCESS;
    }
};

int BandMatrixView::set_zero() { return SUNMatZero(J_); }
double& BandMatrixView::operator()(int i, int j) { return SM_ELEMENT_B(J_, i, j); }

std::string cvode_flag_name(int flag) {
    char* name = CVodeGetReturnFlagName(flag);
    std::string out = name ? name : "unknown flag";
    free(name);
    return out;
}

CvodeSession::CvodeSession(std::string who, int n) : who_(std::move(who)), n_(n) {
    check(SUNContext_Create(nullptr, &ctx_), "SUNContext_Create");
    y_ = N_VNew_Serial(n, ctx_);
    ydky_ = N_VNew_Serial(n, ctx_);
    atol_ = N_VNew_Serial(n, ctx_);
    if (!y_ || !ydky_ || !atol_) throw SolverError(who_ + ": N_VNew_Serial failed", 0, 0.0, 0.0);
    N_VConst(0.0, y_);
    N_VConst(0.0, ydky_);
    N_VConst(0.0, atol_);
}

CvodeSession::~CvodeSession() {
    if (cv_) CVodeFree(&cv_);
    if (nls_) SUNNonlinSolFree(nls_);
    if (ls_) SUNLinSolFree(ls_);
    if (J_) SUNMatDestroy(J_);
    if (y_) N_VDestroy(y_);
    if (ydky_) N_VDestroy(ydky_);
    if (atol_) N_VDestroy(atol_);
    if (ctx_) SUNContext_Free(&ctx_);
}

Eigen::Map<Eigen::VectorXd> CvodeSession::map(N_Vector v) { return {N_VGetArrayPointer(v), n_}; }

void CvodeSession::error_handler(int code, const char* module, const char* function, char* msg, void* user) {
    auto* self = static_cast<CvodeSession*>(user);
    if (code > 0) return;  // warnings (e.g. about inactive roots) are not errors
    self->error_ = std::string(module ? module : "") + "::" + (function ? function : "") + ": " + (msg ? msg : "");
}

void CvodeSession::check(int flag, const char* call) const {
    if (flag >= 0) return;
    double h = 0.0;
    if (cv_) CVodeGetLastStep(cv_, &h);  // diagnostics only: h stays 0 if it fails
    throw SolverError(who_ + ": " + call + " failed: " + cvode_flag_name(flag) +
                          (error_.empty() ? "" : " (" + error_ + ")") + " at t = " + format_value(t_) + " s after " +
                          std::to_string(counters_.steps) + " steps, last step size " + format_value(h) + " s",
                      counters_.steps, t_, 0.0);
}

void CvodeSession::create(int lmm, CVRhsFn rhs, void* user, double rtol) {
    cv_ = CVodeCreate(lmm, ctx_);
    if (!cv_) throw SolverError(who_ + ": CVodeCreate failed", 0, 0.0, 0.0);
    check(CVodeSetErrHandlerFn(cv_, &CvodeSession::error_handler, this), "CVodeSetErrHandlerFn");
    check(CVodeInit(cv_, rhs, 0.0, y_), "CVodeInit");
    check(CVodeSVtolerances(cv_, rtol, atol_), "CVodeSVtolerances");
    check(CVodeSetUserData(cv_, user), "CVodeSetUserData");
}

void CvodeSession::use_fixed_point() {
    nls_ = SUNNonlinSol_FixedPoint(y_, 0, ctx_);
    if (!nls_) throw SolverError(who_ + ": SUNNonlinSol_FixedPoint failed", 0, 0.0, 0.0);
    check(CVodeSetNonlinearSolver(cv_, nls_), "CVodeSetNonlinearSolver");
}

void CvodeSession::use_band_newton(int mu, int ml, CVLsJacFn jac) {
    J_ = SUNBandMatrix(n_, mu, ml, ctx_);
    ls_ = J_ ? SUNLinSol_Band(y_, J_, ctx_) : nullptr;
    if (!J_ || !ls_) throw SolverError(who_ + ": band linear solver creation failed", 0, 0.0, 0.0);
    check(CVodeSetLinearSolver(cv_, ls_, J_), "CVodeSetLinearSolver");
    check(CVodeSetJacFn(cv_, jac), "CVodeSetJacFn");
    linear_ = true;
}

void CvodeSession::use_embedded_newton(CVLsPrecSetupFn setup, CVLsPrecSolveFn solve, void* user) {
    embedded_ = std::make_unique<Embedded>();
    embedded_->cv = cv_;
    embedded_->setup = setup;
    embedded_->solve = solve;
    embedded_->user = user;
    ls_ = SUNLinSolNewEmpty(ctx_);
    if (!ls_) throw SolverError(who_ + ": SUNLinSolNewEmpty failed", 0, 0.0, 0.0);
    ls_->content = embedded_.get();
    ls_->ops->gettype = &Embedded::type;
    ls_->ops->getid = &Embedded::id;
    ls_->ops->solve = &Embedded::do_solve;
    ls_->ops->free = &Embedded::do_free;
    check(CVodeSetLinearSolver(cv_, ls_, nullptr), "CVodeSetLinearSolver");
    linear_ = true;
}

void CvodeSession::set_limits(double max_step_s) {
    check(CVodeSetMaxNumSteps(cv_, kCvodeMaxStepsPerCall), "CVodeSetMaxNumSteps");
    if (max_step_s > 0.0) check(CVodeSetMaxStep(cv_, max_step_s), "CVodeSetMaxStep");
}

void CvodeSession::set_stop_time(double t_stop) {
    t_stop_ = t_stop;
    has_stop_ = true;
    check(CVodeSetStopTime(cv_, t_stop), "CVodeSetStopTime");
}

void CvodeSession::set_max_order(int order) { check(CVodeSetMaxOrd(cv_, order), "CVodeSetMaxOrd"); }

void CvodeSession::set_roots(int n, CVRootFn g) {
    check(CVodeRootInit(cv_, n, g), "CVodeRootInit");
    std::vector<int> dir(static_cast<std::size_t>(n), -1);  // every witness: decreasing crossings only
    check(CVodeSetRootDirection(cv_, dir.data()), "CVodeSetRootDirection");
    check(CVodeSetNoInactiveRootWarn(cv_), "CVodeSetNoInactiveRootWarn");
    roots_ = true;
}

void CvodeSession::read_counters() {
    long v = 0;
    check(CVodeGetNumSteps(cv_, &v), "CVodeGetNumSteps");
    counters_.steps = base_.steps + v;
    check(CVodeGetNumRhsEvals(cv_, &v), "CVodeGetNumRhsEvals");
    counters_.rhs_evaluations = base_.rhs_evaluations + v;
    if (roots_) {
        check(CVodeGetNumGEvals(cv_, &v), "CVodeGetNumGEvals");
        counters_.root_evaluations = base_.root_evaluations + v;
    }
    if (linear_) {
        if (embedded_) {  // the stepper's factorisations are its Jacobians and Newton matrices
            counters_.jacobian_evaluations = counters_.linear_setups = embedded_->setups;  // across reinit
        } else {
            check(CVodeGetNumJacEvals(cv_, &v), "CVodeGetNumJacEvals");
            counters_.jacobian_evaluations = base_.jacobian_evaluations + v;
            check(CVodeGetNumLinSolvSetups(cv_, &v), "CVodeGetNumLinSolvSetups");
            counters_.linear_setups = base_.linear_setups + v;
        }
    }
}

int CvodeSession::advance(double tout, int itask, long max_steps, double& t_reached) {
    sunrealtype tret = t_;
    const int flag = CVode(cv_, tout, y_, &tret, itask);
    t_ = tret;
    t_reached = tret;
    read_counters();
    check(flag, "CVode");
    if (counters_.steps > max_steps)
        throw SolverError(who_ + ": more than cvode.max_steps = " + std::to_string(max_steps) + " steps at t = " +
                              format_value(tret) + " s",
                          counters_.steps, tret, 0.0);
    return flag;
}

void CvodeSession::dense_output(double t) { check(CVodeGetDky(cv_, t, 0, ydky_), "CVodeGetDky"); }

void CvodeSession::reinit(double t) {
    base_ = counters_;
    check(CVodeReInit(cv_, t, y_), "CVodeReInit");
    if (has_stop_) check(CVodeSetStopTime(cv_, t_stop_), "CVodeSetStopTime");
    t_ = t;
}

void CvodeSession::root_info(std::vector<int>& found) { check(CVodeGetRootInfo(cv_, found.data()), "CVodeGetRootInfo"); }

double CvodeSession::last_step() const {
    double h = 0.0;
    check(CVodeGetLastStep(cv_, &h), "CVodeGetLastStep");
    return h;
}

}  // namespace stackbeam::detail
