#pragma once
// Internal: the free DOFs of the reduced stack with the seat held, once for the three places that
// split it (initial_state.cpp's held_seat_start, newmark's rigs, closed-form's held_seat_system):
// the windup rig holds theta_R, the vertical rig holds R's w; every other DOF is free.
#include <Eigen/SparseCore>
#include <stdexcept>
#include <vector>

#include "stackbeam/fe/system.hpp"

namespace stackbeam::detail {

/// The reduced DOFs [m, rad] (w last) split into the held ones H and the free ones F.
struct HeldSeatDofs {
    std::vector<int> held;          ///< H: theta_R (the windup rig) first, then w (the vertical rig)
    std::vector<int> free;          ///< F: every other DOF, ascending
    std::vector<int> index;         ///< reduced DOF -> its position in `free`, -1 for a held one
    Eigen::SparseMatrix<double> S;  ///< F <- all (|F| x n): z_F = S z, and z = S^T z_F + z_H
    bool free_leading = true;       ///< F is the first |F| DOFs (then S is [I 0])
};

/// The split of `system`'s reduced DOFs with theta_R held where `hold_rotation` (the windup rig: the
/// full model's seat rotation, which must exist) and w held where `hold_w` (the vertical rig).
inline HeldSeatDofs held_seat_dofs(const System& system, bool hold_rotation, bool hold_w) {
    const int n = system.num_reduced_dofs(), theta = system.seat_rotation_dof();
    HeldSeatDofs h;
    if (hold_rotation) {
        if (theta < 0) throw std::logic_error("held_seat_dofs: the windup rig on a model without the seat's rotation");
        h.held.push_back(theta);
    }
    if (hold_w) h.held.push_back(system.seat_w_dof());
    h.index.assign(static_cast<std::size_t>(n), -1);
    std::vector<Eigen::Triplet<double>> sel;
    for (int i = 0; i < n; ++i) {
        if ((hold_rotation && i == theta) || (hold_w && i == system.seat_w_dof())) continue;
        const int row = static_cast<int>(h.free.size());
        if (i != row) h.free_leading = false;
        h.index[static_cast<std::size_t>(i)] = row;
        h.free.push_back(i);
        sel.emplace_back(row, i, 1.0);
    }
    h.S.resize(static_cast<int>(h.free.size()), n);
    h.S.setFromTriplets(sel.begin(), sel.end());
    return h;
}

}  // namespace stackbeam::detail
