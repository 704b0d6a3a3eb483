#pragma once
// Internal: the friction-mesh advice (model.hpp) as a suffix of a failed step's message.
#include <string>

#include "stackbeam/model/model.hpp"

namespace stackbeam::detail {

/// "; " + friction_mesh_advice(model) when kappa >= 1 (the likely cause of a contact
/// iteration that did not settle on a fine frictional mesh), else empty.
inline std::string mesh_note(const Model& model) {
    const std::string advice = friction_mesh_advice(model);
    return advice.empty() ? std::string() : "; " + advice;
}

}  // namespace stackbeam::detail
