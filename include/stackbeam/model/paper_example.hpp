#pragma once
/// @file paper_example.hpp
/// The built-in example of the paper's section 5 (geometry as read in
/// docs/method.md, section 5): three identical leaves 0.5 x 0.05 x 0.005 m,
/// E = 2e10 Pa, pinned at both ends, four clamps at x = 0.1, 0.2, 0.3, 0.4 m,
/// a 20 kg rigid body at midspan moving at 2 m/s, 20 elements per half leaf.
#include <string>

#include "stackbeam/model/model.hpp"

namespace stackbeam {

/// The paper's three cases.
enum class PaperCase {
    bonded,        ///< all pairs tied: one beam 0.05 x 0.015 m (k = 48EI/L^3 = 108,000 N/m)
    friction,      ///< mu = 0.5, clamp force 1000 N
    frictionless,  ///< mu = 0: one beam 0.15 x 0.005 m (k = 12,000 N/m)
};
template <>
const std::vector<EnumWord<PaperCase>>& enum_words<PaperCase>();
const char* to_string(PaperCase c);
/// Parses "bonded" | "friction" | "frictionless"; throws InputError naming `field`.
PaperCase parse_paper_case(const std::string& text, const std::string& field);

/// Options of the example; each item of the reading is a parameter.
struct PaperExampleOptions {
    int elements_per_half_leaf = 20;       ///< mesh: elements on 0 <= x <= L/2 of each leaf
    Symmetry symmetry = Symmetry::half;    ///< half model (the paper's) or full model
    double friction_coefficient = 0.5;     ///< mu of the friction case [-]
    double clamp_preload_n = 1000.0;       ///< clamp force F_c [N]
    double mass_kg = 20.0;                 ///< m [kg]
    double initial_velocity_m_per_s = 2.0; ///< dw/dt(0) [m/s], +y
    double youngs_modulus_pa = 2.0e10;     ///< E [Pa] (as printed in the paper)
    double density_kg_per_m3 = 0.0;        ///< leaf density [kg/m^3] (0: massless, the paper)
};

/// The model specification of the example in case `c`. Throws InputError for bad options.
ModelSpec paper_example(PaperCase c, const PaperExampleOptions& options = {});

/// Analytic figures of the example (one equivalent beam, pinned, load at midspan).
struct PaperAnalytic {
    double stiffness_n_per_m;  ///< 48 E I / L^3 of the equivalent beam
    double omega_rad_per_s;    ///< sqrt(k/m)
    double amplitude_m;        ///< v0 / omega
};
/// Bonded: one beam 0.05 x 0.015 m; frictionless: one beam 0.15 x 0.005 m.
/// The friction case has no analytic solution: throws InputError.
PaperAnalytic paper_analytic(PaperCase c, const PaperExampleOptions& options = {});

}  // namespace stackbeam
