#pragma once
// The exact response of a stack whose contact rows all stay held (bonded, or compressed and
// frictionless) with elastic interfaces: M z'' + K_t z = q(t), K_t = K + G_S^T C_L^-1 G_S, by the
// modal superposition of the generalized eigen-solve (K_t, M) with each mode's response to
// constant and harmonic forcing in closed form. The independent value of the leaf-mass
// steppers' loadings (test_leaf_mass_loadings.cpp, test_cvode_modal_loadings.cpp).
#include <boost/test/unit_test.hpp>
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <functional>
#include <vector>

#include "stackbeam/fe/system.hpp"
#include "stackbeam/time/simulation.hpp"
#include "test_support.hpp"  // kPi

namespace stackbeam::testing {

/// The linear stack with every held row tied by its layer spring: normal rows always, tangential
/// rows where the pair is bonded or carries friction (as the steppers' initial tied shape).
struct Linear {
    Eigen::MatrixXd M, K;  // [kg], [N/m] (reduced DOFs, w last)
    Eigen::VectorXd l;     // System::vertical_inertia_kg
    int w = 0;
    double f = 1.0;        // whole-spring factor
    double m_half = 0.0;   // R's mass on the meshed part [kg]
};

inline Linear linear(const System& s) {
    Linear L;
    L.M = Eigen::MatrixXd(s.mass_reduced());
    L.K = Eigen::MatrixXd(s.stiffness_reduced());
    const Eigen::MatrixXd G(s.contact_rows());
    const Eigen::VectorXd& c = s.layer_compliance_m_per_n();
    for (const auto& pr : s.pairs()) {
        std::vector<int> rows;
        if (pr.row_n >= 0) rows.push_back(pr.row_n);
        if (pr.row_t >= 0 && (pr.kind == PairKind::bonded || pr.friction_coefficient > 0.0)) rows.push_back(pr.row_t);
        for (int r : rows) {
            BOOST_REQUIRE(c[r] > 0.0);
            L.K += G.row(r).transpose() * G.row(r) / c[r];
        }
    }
    L.l = s.vertical_inertia_kg();
    L.w = static_cast<int>(L.K.rows()) - 1;
    L.f = s.model().whole_spring_factor();
    L.m_half = s.mass_kg();
    return L;
}

/// Loading q(t) = a + b cos(Omega t) + c sin(Omega t) [N per DOF].
struct Forcing {
    Eigen::VectorXd a, b, c;
    double omega = 0.0;  // [rad/s]
};

/// Exact response of M z'' + K z = q(t) from z0, v0 (modal superposition; every mode's
/// forcing frequency kept away from its own). Returns z(t) and z''(t) at the times asked.
struct Modal {
    Eigen::VectorXd omega;  // [rad/s]
    Eigen::MatrixXd phi;    // M-orthonormal
    Eigen::VectorXd eta0, etad0, fa, fb, fc;
    double Om = 0.0;
    StructuralDamping damping;  // Rayleigh: mode i has zeta_i = alpha / (2 omega_i) + beta omega_i / 2 (free response only)
    Modal(const Eigen::MatrixXd& M, const Eigen::MatrixXd& K, const Eigen::VectorXd& z0, const Eigen::VectorXd& v0,
          const Forcing& q, const StructuralDamping& c = {})
        : damping(c) {
        Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> es(K, M);
        BOOST_REQUIRE(es.info() == Eigen::Success);
        omega = es.eigenvalues().cwiseSqrt();
        phi = es.eigenvectors();
        eta0 = phi.transpose() * M * z0;
        etad0 = phi.transpose() * M * v0;
        const Eigen::Index n = z0.size();
        fa = phi.transpose() * (q.a.size() ? q.a : Eigen::VectorXd::Zero(n));
        fb = phi.transpose() * (q.b.size() ? q.b : Eigen::VectorXd::Zero(n));
        fc = phi.transpose() * (q.c.size() ? q.c : Eigen::VectorXd::Zero(n));
        Om = q.omega;
    }
    void at(double t, Eigen::VectorXd& z, Eigen::VectorXd& acc) const {
        Eigen::VectorXd eta(omega.size()), etadd(omega.size());
        for (Eigen::Index i = 0; i < omega.size(); ++i) {
            const double w = omega[i], d = w * w - Om * Om;
            if (damping.active()) {  // free damped response: the roots of s^2 + 2 zeta w s + w^2
                const double zeta = damping.rayleigh_alpha_per_s / (2.0 * w) + damping.rayleigh_beta_s * w / 2.0;
                const double x0 = eta0[i], v0 = etad0[i];
                double x = 0.0, v = 0.0;
                if (zeta < 1.0) {
                    const double wd = w * std::sqrt(1.0 - zeta * zeta), e = std::exp(-zeta * w * t);
                    const double B = (v0 + zeta * w * x0) / wd;
                    x = e * (x0 * std::cos(wd * t) + B * std::sin(wd * t));
                    v = e * (-zeta * w * (x0 * std::cos(wd * t) + B * std::sin(wd * t)) +
                             wd * (-x0 * std::sin(wd * t) + B * std::cos(wd * t)));
                } else {  // overdamped: x = c1 e^{s1 t} + c2 e^{s2 t}
                    const double r = w * std::sqrt(zeta * zeta - 1.0), s1 = -zeta * w + r, s2 = -zeta * w - r;
                    const double c1 = (v0 - s2 * x0) / (s1 - s2), c2 = x0 - c1;
                    x = c1 * std::exp(s1 * t) + c2 * std::exp(s2 * t);
                    v = c1 * s1 * std::exp(s1 * t) + c2 * s2 * std::exp(s2 * t);
                }
                eta[i] = x;
                etadd[i] = -w * w * x - 2.0 * zeta * w * v;
                continue;
            }
            // particular: fa/w^2 + fb/d cos(Om t) + fc/d sin(Om t); its value and rate at 0
            const double p = fa[i] / (w * w) + fb[i] / d * std::cos(Om * t) + fc[i] / d * std::sin(Om * t);
            const double p0 = fa[i] / (w * w) + fb[i] / d, pd0 = fc[i] * Om / d;
            const double h = (eta0[i] - p0) * std::cos(w * t) + (etad0[i] - pd0) / w * std::sin(w * t);
            eta[i] = p + h;
            const double force = fa[i] + fb[i] * std::cos(Om * t) + fc[i] * std::sin(Om * t);
            etadd[i] = force - w * w * eta[i];
        }
        z = phi * eta;
        acc = phi * etadd;
    }
};

/// Largest |a_i - b_i| over the records, with `ref(t)` the reference.
inline double max_deviation(const std::vector<StepRecord>& r, const std::function<double(const StepRecord&)>& got,
                     const std::function<double(double)>& ref) {
    double e = 0.0;
    for (const auto& rec : r) e = std::max(e, std::abs(got(rec) - ref(rec.t_s)));
    return e;
}

inline double max_abs(const std::vector<StepRecord>& r, const std::function<double(double)>& ref) {
    double e = 0.0;
    for (const auto& rec : r) e = std::max(e, std::abs(ref(rec.t_s)));
    return e;
}

/// The reference's w(t) for a Modal response.
inline std::function<double(double)> w_reference(const Modal& ref, int w) {
    return [&ref, w](double t) {
        Eigen::VectorXd z, a;
        ref.at(t, z, a);
        return z[w];
    };
}

/// z0 with R held at w0 and the leaves in the static shape there: [-K_rr^-1 K_rw w0; w0] (+ z_load).
inline Eigen::VectorXd held_shape(const Linear& L, double w0) {
    const int w = L.w;
    Eigen::VectorXd z0 = Eigen::VectorXd::Zero(w + 1);
    z0.head(w) = -L.K.topLeftCorner(w, w).ldlt().solve(L.K.block(0, w, w, 1)) * w0;
    z0[w] = w0;
    return z0;
}

/// The supports moved by y_b = A cos(Omega t), Omega = 2 pi frequency_hz, from rest relative to them
/// (Loading::base_excitation): the loading and its exact response, every mass feeling -y_b'' times
/// itself, q = A Omega^2 cos(Omega t) l.
struct BaseExcitationCase {
    Loading load;
    Modal ref;
};

inline BaseExcitationCase base_excitation_case(const Linear& L, double amplitude_m, double frequency_hz) {
    const double Om = 2.0 * kPi * frequency_hz;
    Forcing q;
    q.omega = Om;
    q.b = amplitude_m * Om * Om * L.l;
    return {periodic_loading(LoadingKind::base_excitation, TimeFunction::Shape::harmonic, amplitude_m, frequency_hz,
                             kPi / 2.0),
            Modal(L.M, L.K, Eigen::VectorXd::Zero(L.w + 1), Eigen::VectorXd::Zero(L.w + 1), q)};
}

/// F(t) = amplitude_n sin(2 pi frequency_hz t) on R from rest (Loading::applied_force): the
/// loading, its exact response (q = e_w F / f: the whole-spring force on the meshed part) and the
/// energy scale k_t A^2 / 2 of the static amplitude A = F / k_t [J] (the balance's scale).
struct HarmonicForceCase {
    Loading load;
    Modal ref;
    double energy_scale_j;
};

inline HarmonicForceCase harmonic_force_case(const System& s, const Linear& L, double amplitude_n, double frequency_hz) {
    const Loading load =
        periodic_loading(LoadingKind::applied_force, TimeFunction::Shape::harmonic, amplitude_n, frequency_hz);
    Forcing q;
    q.omega = 2.0 * kPi * frequency_hz;
    q.c = Eigen::VectorXd::Zero(L.w + 1);
    q.c[L.w] = amplitude_n / L.f;
    const double amp = amplitude_n / s.tied_stiffness_n_per_m();
    return {load, Modal(L.M, L.K, Eigen::VectorXd::Zero(L.w + 1), Eigen::VectorXd::Zero(L.w + 1), q),
            0.5 * s.tied_stiffness_n_per_m() * amp * amp};
}

}  // namespace stackbeam::testing
