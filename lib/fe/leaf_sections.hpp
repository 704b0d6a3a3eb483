#pragma once
// Internal: element matrices of a leaf with a profile (LeafProfile), integrated exactly
// (system.cpp stiffness, system_mass.cpp mass). The mesh has a node at every profile
// point (Model::build), so within an element the thickness t and width b are linear in x;
// then E b t^3 / 12 is a polynomial of degree 4 and the bending integrand EI B_i B_j (B the
// Hermite shapes' curvatures, linear) of degree 6; rho b t N_i N_j (cubic N) of degree 8.
// 5-point Gauss-Legendre is exact to degree 9.
#include <Eigen/Sparse>
#include <array>
#include <cmath>
#include <vector>

#include "stackbeam/model/model.hpp"

namespace stackbeam::detail {

/// 6 x 6 matrix over an element's DOFs (u1, v1, th1, u2, v2, th2).
using ElementMatrix = std::array<std::array<double, 6>, 6>;

/// Integrates f(xi, b, t, N, B) over the element [x1, x2] of `leaf`: N the Hermite shapes of
/// (v1, th1, v2, th2), B = d2N/dx2, the axial shapes (1 - xi, xi); see the two users.
template <class F>
void integrate_profiled(const LeafSpec& leaf, double x1, double x2, F&& f) {
    static constexpr double s[5] = {-0.9061798459386640, -0.5384693101056831, 0.0, 0.5384693101056831, 0.9061798459386640};
    static constexpr double w[5] = {0.2369268850561891, 0.4786286704993665, 0.5688888888888889, 0.4786286704993665,
                                    0.2369268850561891};
    const double L = x2 - x1;
    for (int g = 0; g < 5; ++g) {
        const double xi = 0.5 * (1.0 + s[g]), x = x1 + xi * L;
        const double N[4] = {1 - 3 * xi * xi + 2 * xi * xi * xi, L * (xi - 2 * xi * xi + xi * xi * xi),
                             3 * xi * xi - 2 * xi * xi * xi, L * (xi * xi * xi - xi * xi)};
        const double B[4] = {(-6 + 12 * xi) / (L * L), (-4 + 6 * xi) / L, (6 - 12 * xi) / (L * L), (-2 + 6 * xi) / L};
        const double Na[2] = {1 - xi, xi};
        f(0.5 * w[g] * L, leaf_width_m(leaf, x), leaf_thickness_m(leaf, x), N, B, Na);
    }
}

/// The bending DOFs' places in ElementMatrix, and the axial ones.
constexpr int kBendingDofs[4] = {1, 2, 4, 5};
constexpr int kAxialDofs[2] = {0, 3};

/// Bernoulli-Euler 2-node element of a uniform leaf, DOFs (u1, v1, th1, u2, v2, th2): axial EA/L
/// and bending EI/L^3 [12 6L -12 6L; 6L 4L^2 -6L 2L^2; ...], exact for end loads.
inline ElementMatrix uniform_stiffness(double EA, double EI, double L) {
    ElementMatrix k{};
    k[0][0] = k[3][3] = EA / L;
    k[0][3] = k[3][0] = -EA / L;
    const double c = EI / (L * L * L);
    const double kb[4][4] = {{12 * c, 6 * L * c, -12 * c, 6 * L * c},
                             {6 * L * c, 4 * L * L * c, -6 * L * c, 2 * L * L * c},
                             {-12 * c, -6 * L * c, 12 * c, -6 * L * c},
                             {6 * L * c, 2 * L * L * c, -6 * L * c, 4 * L * L * c}};
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) k[kBendingDofs[i]][kBendingDofs[j]] = kb[i][j];
    return k;
}

/// Stiffness of an element of a profiled leaf: int EA N_a' N_a' dx (axial), int EI B B dx (bending).
inline ElementMatrix profiled_stiffness(const LeafSpec& leaf, double x1, double x2) {
    ElementMatrix k{};
    const double E = leaf.youngs_modulus_pa, L = x2 - x1;
    integrate_profiled(leaf, x1, x2, [&](double dx, double b, double t, const double*, const double* B, const double*) {
        const double EA = E * b * t, EI = E * b * t * t * t / 12.0;
        for (int i = 0; i < 2; ++i)
            for (int j = 0; j < 2; ++j) k[kAxialDofs[i]][kAxialDofs[j]] += dx * EA * (i == j ? 1.0 : -1.0) / (L * L);
        for (int i = 0; i < 4; ++i)
            for (int j = 0; j < 4; ++j) k[kBendingDofs[i]][kBendingDofs[j]] += dx * EI * B[i] * B[j];
    });
    return k;
}

/// The stiffness of element [x1, x2] of `leaf` (uniform or profiled), as System assembles it.
inline ElementMatrix element_stiffness(const LeafSpec& leaf, double x1, double x2) {
    if (!leaf.profile.x_m.empty()) return profiled_stiffness(leaf, x1, x2);
    const double EA = leaf.youngs_modulus_pa * leaf.width_m * leaf.height_m;
    const double EI = leaf.youngs_modulus_pa * leaf.width_m * std::pow(leaf.height_m, 3) / 12.0;
    return uniform_stiffness(EA, EI, x2 - x1);
}

/// Consistent mass of an element of a profiled leaf: int rho b t N N dx (axial and bending shapes).
inline ElementMatrix profiled_mass(const LeafSpec& leaf, double x1, double x2) {
    ElementMatrix m{};
    integrate_profiled(leaf, x1, x2, [&](double dx, double b, double t, const double* N, const double*, const double* Na) {
        const double rho_a = leaf.density_kg_per_m3 * b * t;
        for (int i = 0; i < 2; ++i)
            for (int j = 0; j < 2; ++j) m[kAxialDofs[i]][kAxialDofs[j]] += dx * rho_a * Na[i] * Na[j];
        for (int i = 0; i < 4; ++i)
            for (int j = 0; j < 4; ++j) m[kBendingDofs[i]][kBendingDofs[j]] += dx * rho_a * N[i] * N[j];
    });
    return m;
}

/// Consistent mass of a Bernoulli-Euler 2-node element of a uniform leaf, m = rho A L [kg], DOFs
/// (u1, v1, th1, u2, v2, th2): axial m/6 [2 1; 1 2]; bending (cubic Hermite shapes, rotary inertia
/// neglected as in the stiffness) m/420 [156 22L 54 -13L; 22L 4L^2 13L -3L^2; ...].
inline ElementMatrix uniform_mass(double m, double L) {
    ElementMatrix me{};
    me[0][0] = me[3][3] = m / 3.0;
    me[0][3] = me[3][0] = m / 6.0;
    const double c = m / 420.0;
    const double mb[4][4] = {{156 * c, 22 * L * c, 54 * c, -13 * L * c},
                             {22 * L * c, 4 * L * L * c, 13 * L * c, -3 * L * L * c},
                             {54 * c, 13 * L * c, 156 * c, -22 * L * c},
                             {-13 * L * c, -3 * L * L * c, -22 * L * c, 4 * L * L * c}};
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) me[kBendingDofs[i]][kBendingDofs[j]] = mb[i][j];
    return me;
}

/// The consistent mass of element [x1, x2] of `leaf` (uniform or profiled), as System assembles it.
inline ElementMatrix element_mass(const LeafSpec& leaf, double x1, double x2) {
    if (!leaf.profile.x_m.empty()) return profiled_mass(leaf, x1, x2);
    return uniform_mass(leaf.density_kg_per_m3 * leaf.width_m * leaf.height_m * (x2 - x1), x2 - x1);
}

/// Adds a 6 x 6 element matrix over nodes a, b (full DOF offsets / 3): its nonzero entries.
inline void add_matrix(std::vector<Eigen::Triplet<double>>& t, int a, int b, const ElementMatrix& k) {
    const int d[6] = {3 * a, 3 * a + 1, 3 * a + 2, 3 * b, 3 * b + 1, 3 * b + 2};
    for (int i = 0; i < 6; ++i)
        for (int j = 0; j < 6; ++j)
            if (k[i][j] != 0.0) t.emplace_back(d[i], d[j], k[i][j]);
}

}  // namespace stackbeam::detail
