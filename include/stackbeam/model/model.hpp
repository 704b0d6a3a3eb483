#pragma once
/// @file model.hpp
/// The model description of a stacked-beam spring: what the user specifies
/// (ModelSpec, plain data) and its validated, immutable, meshed form (Model).
/// Sign conventions and units: conventions.hpp.
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "stackbeam/contact/pair.hpp"  // PairKind: the contact layer is below the model
#include "stackbeam/words.hpp"

namespace stackbeam {

/// Support at a leaf end.
enum class SupportKind {
    free,    ///< no constraint
    pinned,  ///< transverse displacement v = 0; rotation and axial displacement free
    fixed,   ///< built in: u = v = theta = 0
    hinged,  ///< a pin through the eye: the support point (LeafEndSpec::eye_offset_m) held in x and y, rotation free
    shackle, ///< a link (small deflection: an inclined roller): the support point does not move along the link
    bushing, ///< elastic: springs (LeafEndSpec::bushing_*) between the support point and the ground
};

/// A leaf's thickness and width along it, piecewise linear between points (empty: constant
/// height_m / width_m). docs/model-and-scenarios.md, "Leaf profiles, eyes and shackles".
/// Each leaf keeps a straight axis, its thickness symmetric about it; the leaves are stacked
/// touching at the seat (RigidBodySpec::x_m), so where they are thinner than there a pair's gap
/// is larger by half the thinning of the two (PairSpec::initial_gap_m). Every point is a node.
struct LeafProfile {
    std::vector<double> x_m;          ///< points from the leaf's left end [m]: 0 first, length_m last, increasing
    std::vector<double> thickness_m;  ///< thickness at each point [m], > 0 (empty: height_m, which must then be given)
    std::vector<double> width_m;      ///< width at each point [m], > 0 (empty: width_m, which must then be given)
};

/// The support point at a leaf end and its eye, shackle or bushings (SupportKind). Small
/// deflection: the support point at height e above the leaf's axis moves (u - e theta, v).
struct LeafEndSpec {
    double eye_offset_m = 0.0;  ///< e: the support point (eye centre) above the leaf's axis [m], signed (+y up)
    /// Shackle: the link's inclination from the vertical (+y) [rad], |angle| < pi/2, positive when its
    /// upper end lies at larger x (hanging or standing alike); 0 is a vertical link (a roller, as pinned).
    double shackle_angle_rad = 0.0;
    double bushing_x_n_per_m = 0.0;               ///< bushing: axial stiffness at the support point [N/m], >= 0
    double bushing_y_n_per_m = 0.0;               ///< bushing: transverse stiffness [N/m], >= 0
    double bushing_rotation_n_m_per_rad = 0.0;    ///< bushing: rotational stiffness [N m/rad], >= 0
};

/// Contact law of an interface between two adjacent leaves.
enum class InterfaceLaw {
    bonded,  ///< perfectly bonded: every pair tied normally and tangentially (p = p_bar, v = s)
    coulomb, ///< unilateral contact with incremental Coulomb friction (mu = 0: frictionless)
};

/// How the surfaces of an interface meet through the leaves' thickness.
enum class InterfaceContact {
    rigid,    ///< rigid surface points, node to node (the paper's model; the default)
    elastic,  ///< an elastic layer between the surfaces: a closed pair carries p_n = -k_n A x (its approach),
              ///< a sticking pair p_t = -k_t A x (its elastic slip), up to the friction limit (Jenkins-like);
              ///< k_n, k_t per unit contact area [Pa/m], A the pair's tributary area [m^2]
              ///< (docs/model-and-scenarios.md, "Elastic interfaces")
};

/// Whether the whole spring is meshed, or its left half with symmetry conditions
/// at the rigid body's attachment (u = 0 and theta = 0 on every leaf there).
enum class Symmetry { full, half };

/// How a fatigue cycle's mean stress is allowed for (include/stackbeam/post/fatigue.hpp;
/// docs/stresses-and-fatigue.md, "Fatigue"): each a line or curve in the (mean, amplitude) plane
/// through the endurance limit at zero mean.
enum class MeanStressCorrection {
    goodman,    ///< straight to the ultimate strength (the default)
    gerber,     ///< a parabola to the ultimate strength
    soderberg,  ///< straight to the yield strength (needs yield_strength_pa)
    morrow,     ///< straight to the fatigue strength coefficient sigma_f' (needs it)
};

/// A leaf's fatigue strength (optional: without it a leaf has no fatigue figures). Stresses
/// in Pa, tension positive; 0 means "not given" for every optional strength. At least an
/// endurance limit or a Basquin S-N curve sigma_a = sigma_f' (2N)^b (both its constants);
/// validated by Model::build (validate_fatigue_material).
struct FatigueMaterial {
    double ultimate_strength_pa = 0.0;             ///< S_u [Pa], > 0 (required)
    double yield_strength_pa = 0.0;                ///< S_y [Pa], in (0, S_u]; 0: not given (Soderberg needs it)
    double endurance_limit_pa = 0.0;               ///< S_e [Pa]: the fully reversed amplitude of infinite life, in (0, S_u); 0: not given
    double fatigue_strength_coefficient_pa = 0.0;  ///< sigma_f' [Pa], > 0; 0: not given (the S-N curve and Morrow need it)
    double fatigue_strength_exponent = 0.0;        ///< Basquin's b [-], in (-1, 0); 0: not given (with sigma_f' or neither)
    MeanStressCorrection mean_stress_correction = MeanStressCorrection::goodman;
};

/// Whether the material has a Basquin S-N curve (sigma_f' and b given).
inline bool has_sn_curve(const FatigueMaterial& m) {
    return m.fatigue_strength_coefficient_pa != 0.0 && m.fatigue_strength_exponent != 0.0;
}
/// Checks a fatigue material: every given strength finite and > 0, b in (-1, 0), S_y <= S_u,
/// S_e < S_u, an endurance limit or an S-N curve, the correction's strength given. Throws
/// InputError naming `path` + "." + the key, e.g. "leaves[2].material.ultimate_strength_pa".
void validate_fatigue_material(const FatigueMaterial& material, const std::string& path);
const char* to_string(MeanStressCorrection correction);

/// One leaf (beam) of the stack.
struct LeafSpec {
    double length_m = 0.0;                  ///< leaf length [m], > 0
    double x_start_m = 0.0;                 ///< x of its left end [m]
    double height_m = 0.0;                  ///< thickness, normal to the stack [m], > 0 (0 with profile.thickness_m)
    double width_m = 0.0;                   ///< width [m], > 0 (0 with profile.width_m)
    double youngs_modulus_pa = 0.0;         ///< Young's modulus [Pa], > 0
    double density_kg_per_m3 = 0.0;         ///< mass density [kg/m^3], >= 0 (0: massless, as in the paper)
    SupportKind left_support = SupportKind::free;   ///< support at x_start_m
    SupportKind right_support = SupportKind::free;  ///< support at x_start_m + length_m
    double poisson_ratio = 0.3;             ///< Poisson's ratio nu [-], in (-1, 0.5): the elastic interface's
                                            ///< derived stiffness (interface_layer); nothing else uses it
    LeafProfile profile;                    ///< thickness / width along x (empty: constant)
    LeafEndSpec left_end, right_end;        ///< eyes, shackle, bushings at the two ends
    /// Free (unassembled) camber: the arc height H [m] of the unstressed leaf over its length, a
    /// circular arc of curvature 8 H / L^2 (small deflection: the free shape is
    /// v0(x) = 4 H (x - x_R)^2 / L^2, x_R the rigid body's attachment, where v0 = v0' = 0).
    /// H > 0: the ends above the seat (+y), the usual spring that a load on R in +y flattens;
    /// 0: flat. |H| <= L/10. At most one of free_camber_m, free_radius_m.
    /// docs/model-and-scenarios.md, "Free camber, assembly and rebound clips".
    double free_camber_m = 0.0;
    /// Free camber as the radius R [m] of the arc instead (curvature 1/R, v0 = (x - x_R)^2 / (2 R)):
    /// R > 0 ends up, R < 0 ends down, 0: flat (no radius given). |R| >= 1.25 L (arc height <= L/10).
    double free_radius_m = 0.0;
    /// Fatigue strength (absent: no fatigue figures for this leaf; nothing of the run uses it).
    std::optional<FatigueMaterial> material;
};

/// Thickness and width of a leaf at x [m] (absolute x; the profile, or height_m / width_m).
double leaf_thickness_m(const LeafSpec& leaf, double x_m);
double leaf_width_m(const LeafSpec& leaf, double x_m);

/// The interface between leaf i (above) and leaf i+1 (below).
struct InterfaceSpec {
    InterfaceLaw law = InterfaceLaw::coulomb;
    double friction_coefficient = 0.0;  ///< Coulomb mu [-], >= 0 (ignored when bonded)
    /// Initial normal gap d_n [m], finite (0: touching). < 0 is an interference: the free leaves
    /// overlap by -initial_gap_m along the interface, and the assembly (mode closed-form) closes it
    /// where a contact row can (needs_assembly); where the seat or supports fix both leaves' normal
    /// motion (the seat's own node, common pins) an interference is refused (System).
    double initial_gap_m = 0.0;
    InterfaceContact contact = InterfaceContact::rigid;  ///< rigid (the paper's) or elastic layer
    /// Elastic contact: normal stiffness per unit contact area k_n [Pa/m], > 0; 0 = derived from the
    /// two leaves (interface_layer). Only with contact = elastic.
    double normal_stiffness_pa_per_m = 0.0;
    /// Elastic contact: tangential stiffness per unit contact area k_t [Pa/m], > 0; 0 = derived.
    double tangential_stiffness_pa_per_m = 0.0;
};

/// A clamp (band, U-bolt) of negligible width. It ties every
/// interface it crosses in the normal direction (never opens) and squeezes it
/// with its preload, which adds to the compressive reaction in the friction limit.
struct ClampSpec {
    double x_m = 0.0;        ///< position [m]
    double preload_n = 0.0;  ///< clamp force F_c [N], >= 0
    /// Physical length of the clamp along x [m], >= 0. 0: a point tie, rigid on every interface.
    /// > 0: on an elastic interface the clamp's pair gets the layer over width x length_m (never
    /// over the mesh's tributary length, which would soften the clamp with every refinement).
    double length_m = 0.0;
};

/// A rebound clip: a strap around leaves first_leaf..last_leaf at x_m that lets them open
/// (separate in y) by at most clearance_m in total, and is free tangentially (no friction).
/// A unilateral limit on the opening: one contact row s = (gap sum) - clearance - T/k <= 0 whose
/// force (the strap's tension T >= 0) holds the outer leaves together once the clearance is
/// used up; the strap's elastic stretch T/k is the row's compliance (as an elastic interface's).
/// Modes closed-form, newmark and cvode's massive stack (docs/model-and-scenarios.md, "Free camber,
/// assembly and rebound clips").
struct ClipSpec {
    double x_m = 0.0;          ///< position [m]: on every strapped leaf, not at the rigid body's seat
    int first_leaf = 0;        ///< the top leaf in the strap
    int last_leaf = 1;         ///< the bottom leaf in the strap, > first_leaf
    double clearance_m = 0.0;  ///< free opening allowed [m], > 0: the sum of the strapped interfaces' gaps
    /// The strap's stiffness in tension k [N/m], > 0: once engaged, the opening grows by T / k
    /// with the clip's tension T (default 1e8 N/m, about a steel band of 1 cm^2 over a 0.2 m loop)
    double stiffness_n_per_m = 1e8;
};

/// Whether the seat locates the stack axially (RigidBodySpec::axial; conventions.hpp, "Seat").
enum class SeatAxial {
    automatic,  ///< held unless an end's eye locates the stack axially (a hinged eye, an inclined
                ///< shackle, a bushing with k_x > 0); then free (the default: the model before windup)
    held,       ///< the seat locates the stack: u_R = 0, each tied leaf's axial u = -y theta_R
    free,       ///< the seat slides with its own axial DOF u_R (u = u_R - y theta_R); the ends must locate it
};

/// The rigid body R on the stack (the axle seat and the mass it carries).
/// At x_m the tied leaves move as one rigid plane section: they share the
/// transverse displacement w and the rotation theta_R, and each tied leaf's axial
/// displacement is u_R - y*theta_R (y its centroid height above the mid-height of the
/// tied leaves); u_R = 0 where the seat locates the stack axially (axial).
struct RigidBodySpec {
    double mass_kg = 0.0;                  ///< mass m [kg], > 0
    double x_m = 0.0;                      ///< attachment position [m]
    std::vector<int> tied_leaves;          ///< leaves tied by the seat (empty: every leaf present at x_m)
    double initial_displacement_m = 0.0;   ///< w(0) [m] (+y)
    double initial_velocity_m_per_s = 0.0; ///< dw/dt(0) [m/s] (+y)
    /// J: the axle's pitch inertia about the seat [kg m^2], >= 0, on theta_R (whole spring; full
    /// model only, the half model has no theta_R). 0: the seat's rotation has no inertia of its own.
    double pitch_inertia_kg_m2 = 0.0;
    SeatAxial axial = SeatAxial::automatic;  ///< whether the seat locates the stack axially
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
    std::vector<ClipSpec> clips;             ///< rebound clips
};

/// A contact pair: the facing surface points of adjacent leaves at one node.
struct PairSpec {
    int interface_index = 0;  ///< interface i: leaf i above, leaf i+1 below
    int node = 0;             ///< node index on the grid
    double x_m = 0.0;         ///< position [m]
    PairKind kind = PairKind::coulomb;
    double friction_coefficient = 0.0;  ///< mu [-]
    double preload_n = 0.0;             ///< clamp force F_c [N] (clamp pairs)
    double initial_gap_m = 0.0;         ///< d_n [m]: the interface's gap plus the taper's gap (LeafProfile) plus the
                                        ///< free shapes' difference v0_A - v0_B (< 0: interference, resolved by the
                                        ///< assembly); a clip row: clearance - the strapped gaps' sum
    /// Elastic interface: the layer's compliance of this pair, 1 / (k_n A) and 1 / (k_t A) [m/N],
    /// A its tributary area [m^2]; 0 on a rigid interface and at a point clamp.
    double normal_compliance_m_per_n = 0.0;
    double tangential_compliance_m_per_n = 0.0;
    int clip_index = -1;                ///< >= 0: the row of clips[clip_index] (kind coulomb, mu 0), on
                                        ///< v_first - v_last; interface_index is then the clip's first leaf
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
    /// What build() changed in the spec it was given, one sentence each naming the keys as the
    /// user wrote them (empty: nothing). So far the close clamps it merged (docs/model-and-scenarios.md,
    /// "Mesh"; decision 071): "clamps[0] (x = 0.29965 m) and clamps[2] (x = 0.3 m), 0.00035 m apart,
    /// act as one clamp at x = 0.299825 m, ...". Every front-end shows them with the run's answers
    /// (RunSummary::model_adjustments: the JSON summary's "model_adjustments", the text summary, a
    /// sweep point's message).
    const std::vector<std::string>& adjustments() const noexcept { return adjustments_; }

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
    std::vector<std::string> adjustments_;
};

/// The curvature of a leaf's free shape [1/m]: 1/free_radius_m, or 8 free_camber_m / L^2 (0: flat).
double free_curvature_per_m(const LeafSpec& leaf);
/// Whether the seat slides, with an axial DOF u_R of its own (RigidBodySpec::axial): 'free', or
/// 'auto' where an end's eye locates the stack axially (a hinged eye, an inclined shackle, a bushing
/// with k_x > 0); never on the half model.
bool seat_slides(const ModelSpec& spec);
/// Whether an end's eye locates the stack axially (a hinged eye, an inclined shackle, a bushing with k_x > 0).
bool ends_locate_axially(const ModelSpec& spec);
/// Whether any leaf has a free camber.
bool has_free_camber(const ModelSpec& spec);
/// Whether a run of the model starts with the assembly (simulation.hpp, "assembly"): a
/// free camber, a rebound clip or an interference (an interface's initial_gap_m < 0).
bool needs_assembly(const ModelSpec& spec);

template <>
const std::vector<EnumWord<SupportKind>>& enum_words<SupportKind>();
template <>
const std::vector<EnumWord<InterfaceContact>>& enum_words<InterfaceContact>();
template <>
const std::vector<EnumWord<Symmetry>>& enum_words<Symmetry>();
template <>
const std::vector<EnumWord<SeatAxial>>& enum_words<SeatAxial>();
const char* to_string(SeatAxial axial);
template <>
const std::vector<EnumWord<MeanStressCorrection>>& enum_words<MeanStressCorrection>();
const char* to_string(SupportKind kind);
const char* to_string(InterfaceContact contact);
/// Parses "rigid" | "elastic"; throws InputError naming `field`.
InterfaceContact parse_interface_contact(const std::string& text, const std::string& field);

/// The elastic layer of interface i, per unit contact area. Derived (a given value replaces it):
/// each leaf contributes its half-thickness in plane strain, in series,
///
///     1 / k_n = t_A / (2 E'_A) + t_B / (2 E'_B),   E' = E / (1 - nu^2)
///     1 / k_t = t_A / (2 G_A)  + t_B / (2 G_B),    G  = E / (2 (1 + nu))
///
/// (7 mm steel leaves, E = 200 GPa, nu = 0.3: k_n = 3.14e13 Pa/m, k_t = 1.10e13 Pa/m). The
/// layer spreads a couple on the interface over the Winkler decay length of the two leaves'
/// relative bending (Hetenyi), l = (4 E I_eq / (k_n b))^(1/4), E I_eq = (E I)_A (E I)_B /
/// ((E I)_A + (E I)_B), b the contact width min(b_A, b_B) (l = 1 / lambda).
struct InterfaceLayer {
    double normal_stiffness_pa_per_m = 0.0;      ///< k_n [Pa/m]
    double tangential_stiffness_pa_per_m = 0.0;  ///< k_t [Pa/m]
    double contact_width_m = 0.0;                ///< b [m]
    double decay_length_m = 0.0;                 ///< l [m]
};
/// The layer of interface i of a spec (whatever its contact law; validated leaves assumed),
/// with the leaves' sections at x_m (NaN: at the left end of their overlap; the same for constant leaves).
InterfaceLayer interface_layer(const ModelSpec& spec, int interface_index, double x_m = std::nan(""));

/// The friction-mesh ratio of a model: how strongly a change of the friction forces
/// moves the normal forces of neighbouring contact pairs, per Coulomb interface
///
///     kappa_i = mu_i (t_i + t_i+1) / (2 h_i),
///
/// t_i, t_i+1 the thicknesses of the leaves above and below [m] (profiles: the largest local sum
/// over the interface's pairs, and on an elastic interface the shortest decay length l), h_i the
/// shortest spacing of neighbouring pairs of interface i [m] (on this mesh the node spacing).
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
///
/// On an elastic interface the couple is spread over the layer's decay length l
/// (interface_layer) where that is longer than h, and the ratio is mu (t_i + t_i+1) /
/// (2 max(h, l)): bounded on every mesh. Measured on a graduated 4-leaf spring, the
/// friction-to-limit loop's gain there is about 0.6 mu with every pair slipping one way and
/// 1.43 mu in the worst combination of slip directions, so the elastic law is well posed on any
/// mesh up to mu of about 0.7 (friction_mesh_advice warns above).
struct FrictionMeshRatio {
    double ratio = 0.0;           ///< the largest kappa over the Coulomb interfaces [-] (0: no friction)
    int interface_index = -1;     ///< the interface where it is largest (-1: none with friction)
    double pair_spacing_m = 0.0;  ///< h of that interface [m]
    double spacing_for_one_m = 0.0;  ///< mu (t_i + t_i+1)/2 there: the pair spacing at which kappa = 1 [m]
    double decay_length_m = 0.0;  ///< l of that interface if elastic, else 0 [m]
    bool elastic = false;         ///< that interface has the elastic law
};

/// kappa of every Coulomb interface with mu > 0 and two or more pairs; the largest.
FrictionMeshRatio friction_mesh_ratio(const Model& model);

/// One sentence for error messages and notes, or empty: on a rigid interface with kappa >= 1 it
/// names the interface, kappa, h, and the spacing, mu or the elastic law that bring kappa below 1;
/// on an elastic interface with mu >= 0.7 it warns that the worst combination of slip directions
/// may reach a gain of 1 (1.43 mu).
std::string friction_mesh_advice(const Model& model);

}  // namespace stackbeam
