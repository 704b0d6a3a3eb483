#pragma once
/// @file modal.hpp
/// Natural frequencies of the stack with the leaves' own mass (consistent mass
/// matrices, System::mass_reduced()) and the rigid body, with the contact
/// components tied as a mode of the contact (bonded: all; frictionless: normal).
///
/// The contact components in `tie` are held (G_S z = 0, system.hpp for G), so the
/// motion lies in the null space N of G_S: z = N q, and
///     N^T K N phi = omega^2 N^T M N phi
/// is solved densely (Eigen's generalised self-adjoint solver). Leaves of density 0
/// have no mass; every direction of N must then still carry mass (else InputError):
/// a massless stack has one mode only, the body on the condensed stiffness, which
/// System::tied_stiffness_n_per_m() / free_stiffness_n_per_m() already give.
#include <Eigen/Dense>

#include "stackbeam/fe/system.hpp"

namespace stackbeam {

/// Which contact components a modal analysis holds.
enum class ModalTie {
    all,     ///< every kept component (a bonded stack; also a stack that sticks everywhere)
    normal,  ///< the normal components only (a frictionless stack in contact everywhere)
    none,    ///< none (the leaves move independently; they may interpenetrate)
};

struct ModalResult {
    Eigen::VectorXd omega_rad_per_s;   ///< natural circular frequencies, ascending [rad/s]
    Eigen::MatrixXd shapes;            ///< mode shapes on the reduced DOFs (w last), mass-normalised
    Eigen::VectorXd w_amplitude;       ///< each shape's displacement of the rigid body [m per unit modal coordinate]
};

/// The lowest `count` modes (all if count <= 0). Throws InputError if the tied
/// system has a massless direction.
ModalResult modal_analysis(const System& system, ModalTie tie, int count = 0);

}  // namespace stackbeam
