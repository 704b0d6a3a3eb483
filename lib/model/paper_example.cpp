#include "stackbeam/model/paper_example.hpp"

#include <cmath>

#include "stackbeam/errors.hpp"

namespace stackbeam {
namespace {
constexpr double kLength = 0.5, kWidth = 0.05, kHeight = 0.005;
constexpr int kLeaves = 3;
}  // namespace

STACKBEAM_ENUM_WORDS(PaperCase, {PaperCase::bonded, "bonded"}, {PaperCase::friction, "friction"},
    {PaperCase::frictionless, "frictionless"})

const char* to_string(PaperCase c) { return word_of(c); }

PaperCase parse_paper_case(const std::string& text, const std::string& field) {
    return parse_word<PaperCase>(text, field, "case");
}

ModelSpec paper_example(PaperCase c, const PaperExampleOptions& o) {
    if (o.elements_per_half_leaf < 1)
        throw InputError("elements_per_half_leaf", "value " + std::to_string(o.elements_per_half_leaf) + " must be >= 1");
    ModelSpec s;
    for (int i = 0; i < kLeaves; ++i) {
        LeafSpec l;
        l.length_m = kLength;
        l.x_start_m = 0.0;
        l.height_m = kHeight;
        l.width_m = kWidth;
        l.youngs_modulus_pa = o.youngs_modulus_pa;
        l.density_kg_per_m3 = o.density_kg_per_m3;
        l.left_support = l.right_support = SupportKind::pinned;
        s.leaves.push_back(l);
    }
    for (int i = 0; i + 1 < kLeaves; ++i) {
        InterfaceSpec f;
        f.law = c == PaperCase::bonded ? InterfaceLaw::bonded : InterfaceLaw::coulomb;
        f.friction_coefficient = c == PaperCase::friction ? o.friction_coefficient : 0.0;
        s.interfaces.push_back(f);
    }
    for (double x : {0.1, 0.2, 0.3, 0.4}) s.clamps.push_back({x, o.clamp_preload_n});
    s.rigid_body.mass_kg = o.mass_kg;
    s.rigid_body.x_m = 0.5 * kLength;
    s.rigid_body.initial_velocity_m_per_s = o.initial_velocity_m_per_s;
    s.mesh.element_length_m = 0.5 * kLength / o.elements_per_half_leaf;
    s.symmetry = o.symmetry;
    s.probe = ProbeSpec{0, 0.1};
    return s;
}

PaperAnalytic paper_analytic(PaperCase c, const PaperExampleOptions& o) {
    double b = kWidth, h = kHeight;
    if (c == PaperCase::bonded) h = kLeaves * kHeight;
    else if (c == PaperCase::frictionless) b = kLeaves * kWidth;
    else throw InputError("case", "the friction case has no analytic solution");
    const double I = b * h * h * h / 12.0;
    PaperAnalytic a;
    a.stiffness_n_per_m = 48.0 * o.youngs_modulus_pa * I / std::pow(kLength, 3);
    a.omega_rad_per_s = std::sqrt(a.stiffness_n_per_m / o.mass_kg);
    a.amplitude_m = o.initial_velocity_m_per_s / a.omega_rad_per_s;
    return a;
}

}  // namespace stackbeam
