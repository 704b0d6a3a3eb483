#pragma once
/// @file conventions.hpp
/// Units and sign conventions of stackbeam, stated once and used everywhere.
///
/// Units: SI throughout (m, s, kg, N, Pa, J). Names carry the unit where it
/// could be ambiguous (`length_m`, `mass_kg`, `preload_n`).
///
/// Axes:
///  - x runs along the leaves [m]; every leaf lies on x_start_m <= x <= x_start_m + length_m.
///  - y is the stack's normal direction, positive UP. Leaves are listed from the
///    TOP of the stack to the bottom: leaf 0 is the top leaf.
///  - Beam degrees of freedom per node: axial displacement u (+x) [m],
///    transverse displacement v (+y) [m], rotation theta = dv/dx (counter-clockwise) [rad].
///  - A point at height y above a leaf's centroid moves axially by u - y*theta
///    (plane sections, Bernoulli-Euler); so the top surface moves u - (h/2) theta
///    and the bottom surface u + (h/2) theta (paper eq. 1).
///  - A leaf end's support point (an eye's centre) lies eye_offset_m = e above the axis
///    (+y; negative below) and moves by (u - e*theta, v). A shackle's angle is the link's
///    inclination from +y, positive when its upper end lies at larger x.
///
/// Rigid body R: its displacement w [m] is along +y (up); its initial velocity
/// sets the direction of the motion. Output "w positive in the direction of the
/// initial velocity" is met by giving the paper example an initial velocity of
/// +2 m/s (the example is mirror-symmetric in y, so the sign is immaterial).
///
/// Seat (the rigid body's attachment, full model; loading.hpp "Seat loads and the windup rig"):
///  - its reference point lies on the tied leaves' mid-height at x_R (RigidBodySpec::x_m); the tied
///    leaves move there as one plane section with R's w (+y) [m], theta_R (counter-clockwise, +theta)
///    [rad] and, where the seat slides (RigidBodySpec::axial), u_R (+x) [m]: a tied leaf at height y
///    moves (u_R - y theta_R, w). The half model has neither theta_R nor u_R (its symmetry plane).
///  - A seat moment M [N m] is counter-clockwise positive (it turns the seat by +theta_R).
///  - A longitudinal force H [N] is +x, its line of action h [m] above the reference point (+y; a
///    braking force at the tyre's contact patch has h < 0): it acts as H on u_R and the moment
///    M_z = x F_y - y F_x = -H h on theta_R.
///  - The seat's moment in the records is the moment applied to the spring there, M - H h plus the
///    windup rig's reaction.
///
/// Contact (the paper's convention, eqs. 7-10, kept so the equations read as printed):
///  - Interface i lies between leaf i (upper, body "A") and leaf i+1 (lower, body "B").
///  - The pair normal n points from A into B, i.e. DOWN (-y); the tangent t is +x.
///  - Relative position s = u^A - u^B - d (eq. 7), with u the surface
///    displacements along n and t. s_n > 0 is interpenetration, s_n < 0 an open gap.
///    d_n is the initial gap [m] (>= 0), d_t the tangential anchor [m].
///  - The contact force p acts on A along (n, t) and its reaction -p on B.
///    p_n < 0 is COMPRESSION; p_n = 0 open. p_t > 0 pushes the upper leaf in +x.
///  - Coulomb: |p_t| <= mu * tau, tau = |p_n| (unilateral pair) or
///    max(0, F_c - p_n) at a clamp with preload F_c (compression adds to the preload).
///  - Slip opposes the force: s_t = -beta p_t, beta > 0 (eq. 8).
///
/// Energies are whole-spring values also on the half model (doubled there).
namespace stackbeam {}
