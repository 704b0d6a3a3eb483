#pragma once
/// @file pair.hpp
/// The contact laws of one pair and how its friction limit is taken: the vocabulary the
/// contact layer (the ground numerics layer: Eigen only) shares with the model above it.
/// Sign convention: conventions.hpp.
#include "stackbeam/words.hpp"

namespace stackbeam {

/// Kind of a contact pair.
enum class PairKind {
    bonded,   ///< tied normally and tangentially
    coulomb,  ///< unilateral normal, Coulomb friction with limit mu*|p_n|
    clamp,    ///< bilateral normal (never opens), Coulomb friction with limit mu*max(0, F_c - p_n)
};
const char* to_string(PairKind kind);
template <>
const std::vector<EnumWord<PairKind>>& enum_words<PairKind>();

/// One contact pair of a contact problem: its law and which rows of the problem are its
/// normal and tangential components (-1: the component is absent, e.g. fixed by a support).
struct ContactPair {
    PairKind kind = PairKind::coulomb;
    double friction_coefficient = 0.0;  ///< mu [-]
    double preload_n = 0.0;             ///< clamp force F_c [N] (clamp pairs)
    int row_n = -1;                     ///< row of the normal component, or -1
    int row_t = -1;                     ///< row of the tangential component, or -1
};

/// How tau in the friction limit mu*tau is taken (paper, after eq. 17).
enum class TauRule {
    current,        ///< tau from the current normal force p_n^j: Coulomb exactly
    previous_step,  ///< tau from the converged previous step (the paper's fallback)
};
template <>
const std::vector<EnumWord<TauRule>>& enum_words<TauRule>();

}  // namespace stackbeam
