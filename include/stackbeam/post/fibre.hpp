#pragma once
/// @file fibre.hpp
/// The two extreme fibres of a leaf's section, shared by the stresses (stresses.hpp) and the
/// fatigue figures (fatigue.hpp).
namespace stackbeam {

/// A fibre of a leaf's section: its top (+y side) or bottom surface.
enum class Fibre { top, bottom };
/// "top" or "bottom".
const char* to_string(Fibre fibre);

}  // namespace stackbeam
