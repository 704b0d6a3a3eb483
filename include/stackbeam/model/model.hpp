#pragma once
/// @file model.hpp
/// The model description of a stacked-beam spring: what the user specifies
/// (ModelSpec, plain data) and its validated, immutable, meshed form (Model).
/// Sign conventions and units: conventions.hpp.
#include <optional>
#include <string>
#include <vector>

namespace stackbeam {

/// Support at a leaf end.
enum class SupportKind {
    free,    ///< no constraint
    pinned,  ///< transverse displacement v = 0; rotation and axial displacement free
    fixed,   ///< built in: u = v = theta = 0
};

/// Contact law of an interface between two adjacent leaves.
enum class InterfaceLaw {
    bonded,  ///< perfectly bonded: every pair tied normally and tangentially (p = p_bar, v = s)
    coulomb, ///< unilateral contact with incremental Coulomb friction (mu = 0: frictionless)
};

/// Whether the whole spring is meshed, or its left half with symmetry conditions
/// at the rigid body's attachment (u = 0 and theta = 0 on every leaf there).
enum class Symmetry { full, half };

/// One leaf (beam) of the stack.
struct LeafSpec {
    double length_m = 0.0;                  ///< leaf length [m], > 0
    double x_start_m = 0.0;                 ///< x of its left end [m]
    double height_m = 0.0;                  ///< thickness, normal to the stack [m], > 0
    double width_m = 0.0;                   ///< width [m], > 0
    double youngs_modulus_pa = 0.0;         ///< Young's modulus [Pa], > 0
    double density_kg_per_m3 = 0.0;         ///< mass density [kg/m^3], >= 0 (0: massless, as in the paper)
    SupportKind left_support = SupportKind::free;   ///< support at x_start_m
    SupportKind right_support = SupportKind::free;  ///< support at x_start_m + length_m
};

/// The interface between leaf i (above) and leaf i+1 (below).
struct InterfaceSpec {
    InterfaceLaw law = InterfaceLaw::coulomb;
    double friction_coefficient = 0.0;  ///< Coulomb mu [-], >= 0 (ignored when bonded)
    double initial_gap_m = 0.0;         ///< initial normal gap d_n [m], >= 0 (0: touching)
};

/// A clamp (band, U-bolt, rebound clip) of negligible width. It ties every
/// interface it crosses in the normal direction (never opens) and squeezes it
/// with its preload, which adds to the compressive reaction in the friction limit.
struct ClampSpec {
    double x_m = 0.0;        ///< position [m]
    double preload_n = 0.0;  ///< clamp force F_c [N], >= 0
};

/// The rigid body R on the stack (the axle seat and the mass it carries).
/// At x_m the tied leaves move as one rigid plane section: they share the
/// transverse displacement w and the rotation theta_R, and each tied leaf's axial
/// displacement is -y*theta_R (y its centroid height above the mid-height of the
/// tied leaves), which also locates the stack axially.
struct RigidBodySpec {
    double mass_kg = 0.0;                  ///< mass m [kg], > 0
    double x_m = 0.0;                      ///< attachment position [m]
    std::vector<int> tied_leaves;          ///< leaves tied by the seat (empty: every leaf present at x_m)
    double initial_displacement_m = 0.0;   ///< w(0) [m] (+y)
    double initial_velocity_m_per_s = 0.0; ///< dw/dt(0) [m/s] (+y)
};

/// Mesh: one node grid shared by all leaves. Every leaf end, clamp, the
/// attachment and the probe are nodes; between such points the elements are
/// equal and no longer than element_length_m.
struct MeshSpec {
    double element_length_m = 0.0;  ///< target (maximum) element length [m], > 0
};

/// Where the "probe" friction force is read: the tangential contact force of
/// interface `interface_index` at x_m.
struct ProbeSpec {
    int interface_index = 0;
    double x_m = 0.0;
};

/// Everything a user specifies. Plain data; validated by Model::build.
struct ModelSpec {
    std::vector<LeafSpec> leaves;            ///< from the top of the stack down
    std::vector<InterfaceSpec> interfaces;   ///< leaves.size() - 1 entries, interface i below leaf i
    std::vector<ClampSpec> clamps;
    RigidBodySpec rigid_body;
    MeshSpec mesh;
    Symmetry symmetry = Symmetry::full;
    std::optional<ProbeSpec> probe;          ///< default: top interface at the leftmost clamp
};

/// Kind of a contact pair.
enum class PairKind {
    bonded,   ///< tied normally and tangentially
    coulomb,  ///< unilateral normal, Coulomb friction with limit mu*|p_n|
    clamp,    ///< bilateral normal (never opens), Coulomb friction with limit mu*max(0, F_c - p_n)
};

/// A contact pair: the facing surface points of adjacent leaves at one node.
struct PairSpec {
    int interface_index = 0;  ///< interface i: leaf i above, leaf i+1 below
    int node = 0;             ///< node index on the grid
    double x_m = 0.0;         ///< position [m]
    PairKind kind = PairKind::coulomb;
    double friction_coefficient = 0.0;  ///< mu [-]
    double preload_n = 0.0;             ///< clamp force F_c [N] (clamp pairs)
    double initial_gap_m = 0.0;         ///< d_n [m]
};

/// The validated, meshed model. Immutable; build with Model::build.
class Model {
public:
    /// Validates `spec` and meshes it. Throws InputError naming the field path,
    /// the value and what is allowed.
    static Model build(ModelSpec spec);

    const ModelSpec& spec() const noexcept { return spec_; }
    /// x of every grid node [m], increasing (on the half model up to the attachment).
    const std::vector<double>& nodes_x() const noexcept { return nodes_x_; }
    /// Whether leaf `leaf` has a node at grid node `node`.
    bool leaf_has_node(int leaf, int node) const;
    /// First and last grid node of a leaf (inclusive, within the meshed region).
    int first_node(int leaf) const { return first_node_[leaf]; }
    int last_node(int leaf) const { return last_node_[leaf]; }
    /// All candidate contact pairs, every node where both leaves of an interface exist.
    const std::vector<PairSpec>& candidate_pairs() const noexcept { return pairs_; }
    /// Leaves tied by the rigid body's seat (resolved when the spec left it empty).
    const std::vector<int>& tied_leaves() const noexcept { return tied_; }
    /// Centroid height of each leaf [m] above the mid-height of the tied leaves (y up).
    const std::vector<double>& centroid_heights_m() const noexcept { return y_centroid_; }
    /// Grid node of the rigid body's attachment.
    int attachment_node() const noexcept { return attach_node_; }
    /// Index into candidate_pairs() of the probe pair.
    int probe_pair() const noexcept { return probe_pair_; }
    /// 2 on the half model (whole-spring values are twice the half's), 1 otherwise.
    double whole_spring_factor() const noexcept { return spec_.symmetry == Symmetry::half ? 2.0 : 1.0; }
    /// Tolerance used to decide that two x positions coincide [m].
    double x_tolerance_m() const noexcept { return x_tol_; }

private:
    ModelSpec spec_;
    std::vector<double> nodes_x_;
    std::vector<int> first_node_, last_node_;
    std::vector<PairSpec> pairs_;
    std::vector<int> tied_;
    std::vector<double> y_centroid_;
    int attach_node_ = 0;
    int probe_pair_ = -1;
    double x_tol_ = 0.0;
};

const char* to_string(SupportKind kind);
const char* to_string(PairKind kind);

/// The friction-mesh ratio of a model: how strongly a change of the friction forces
/// moves the normal forces of neighbouring contact pairs, per Coulomb interface
///
///     kappa_i = mu_i (t_i + t_i+1) / (2 h_i),
///
/// t_i, t_i+1 the thicknesses of the leaves above and below [m], h_i the shortest
/// spacing of neighbouring pairs of interface i [m] (on this mesh the node spacing).
/// Why: a change dT of a pair's tangential force acts at the interface, t/2 off each
/// leaf's axis, so it puts a moment dT (t_i + t_i+1)/2 on the two leaves. Where a
/// contact zone ends (a leaf tip, the edge of a closed zone) only the couple of the
/// nearest pairs, arm h, answers it: dN ~ dT (t_i + t_i+1)/(2 h), and with dT = mu dN
/// (a slipping pair's force follows its limit) the limits-to-normal-forces map has a
/// gain of order kappa. Measured on graduated 10-leaf springs (docs/decisions/
/// 008-friction-mesh-ratio.md), the exact solvers' plain fixed point on the friction limits
/// settles in at most 8-9 passes at kappa 0.25-0.5, in up to 24 or not within 100 at 1, and
/// not at all at 2 or more; at 1 the incremental problem was seen to have two
/// solutions (graduated 10 x 100, mu = 0.5). This is a property of the
/// node-to-node discretisation with Coulomb's law, not of a solver: refining the mesh
/// of a frictional stack raises kappa (paper example, 5 mm leaves, mu = 0.5: kappa =
/// 0.2 at its 20 elements per half leaf, 1 at 100, 4 at 400).
struct FrictionMeshRatio {
    double ratio = 0.0;           ///< the largest kappa over the Coulomb interfaces [-] (0: no friction)
    int interface_index = -1;     ///< the interface where it is largest (-1: none with friction)
    double pair_spacing_m = 0.0;  ///< h of that interface [m]
    double spacing_for_one_m = 0.0;  ///< mu (t_i + t_i+1)/2 there: the pair spacing at which kappa = 1 [m]
};

/// kappa of every Coulomb interface with mu > 0 and two or more pairs; the largest.
FrictionMeshRatio friction_mesh_ratio(const Model& model);

/// When kappa >= 1: one sentence naming the interface, kappa, h and the spacing or mu
/// that bring kappa below 1 (for error messages and notes); otherwise empty.
std::string friction_mesh_advice(const Model& model);

}  // namespace stackbeam
