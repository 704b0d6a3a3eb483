#pragma once
/// @file stresses.hpp
/// The leaves' stress resultants and fibre stresses, the pressure between the leaves, and two
/// accumulators over a run (the extremes of each leaf; the range and mean over a time window).
/// docs/stresses-and-fatigue.md says how to use them; docs/decisions/054-stress-recovery.md why so.
///
/// Sign convention (stated once, used by every figure here):
///  - N, the axial force [N]: tension positive.
///  - M, the bending moment [N m]: M = E I (v'' - v0''), the curvature from the leaf's free
///    (unstressed) shape v0 (a free camber's prestress is in it); M > 0 sags the leaf (concave up:
///    its bottom fibre in tension).
///  - V, the shear force [N]: V = dM/dx.
///  - Fibre stress [Pa], tension positive, at height y above the leaf's axis (+y up):
///        sigma(y) = N / A - M y / I,   A = b t, I = b t^3 / 12,
///    with the leaf's local thickness t and width b (profiled leaves); the top fibre is the +y
///    side (y = t/2): sigma_top = N / (b t) - 6 M / (b t^2), sigma_bottom = N / (b t) + 6 M / (b t^2).
///
/// Recovery: each element's end forces from its own stiffness, f_e = K_e u_e (u_e its nodal
/// displacements from the free shape). They are in exact equilibrium with the nodal forces the
/// element carries (the contact forces at the leaves' surfaces, with their moments about the axis,
/// the supports, clamps and the seat), so the nodal M and N are the statics of the discretised
/// stack, not derivatives of the cubic field. A pair's force at a node stands for the traction over
/// its tributary length, half on each side: at a node between two elements a leaf's N, M and V are
/// the mean of the two elements' end values (a node-to-node friction force jumps them there); at a
/// leaf's end the tributary lies inside, so the pair's axial force and moment there are taken back
/// (the value is the support's reaction: 0 at a free or pinned end).
/// With leaf mass the elements' own distributed loads are taken off (LeafMotion, decision 061):
/// f_e = K_e u_e + C_e v_e + M_e (a_e + a_f e_y), the element's consistent mass M_e times its
/// nodal accelerations relative to the supports a_e plus the frame's a_f = g + y_b'' on every
/// node's v (M_e e_y is the consistent load of a uniform rho A per unit acceleration), and the
/// Rayleigh damping C_e = alpha M_e + beta K_e; the nodal resultants are then in equilibrium
/// with the contact, support and inertia forces (the section's sums close to round-off).
#include <Eigen/Dense>
#include <limits>
#include <optional>
#include <vector>

#include "stackbeam/contact/pair.hpp"
#include "stackbeam/fe/system.hpp"
#include "stackbeam/post/fatigue.hpp"  // the fatigue figures of StressMonitor
#include "stackbeam/time/simulation.hpp"
#include "stackbeam/post/fibre.hpp"

namespace stackbeam {

/// One leaf's resultants and fibre stresses at its nodes, whole leaf (the half model mirrored:
/// N, M and the stresses even about the seat, V odd). Signs: the file comment.
struct LeafStresses {
    int leaf = 0;                          ///< index in ModelSpec::leaves (0: the top leaf)
    std::vector<double> x_m;               ///< x of each node [m], increasing (as LeafNodes)
    std::vector<double> thickness_m;       ///< local thickness t [m]
    std::vector<double> width_m;           ///< local width b [m]
    std::vector<double> axial_force_n;     ///< N [N], tension positive
    std::vector<double> bending_moment_n_m;///< M [N m], sagging positive
    std::vector<double> shear_force_n;     ///< V = dM/dx [N]
    std::vector<double> top_stress_pa;     ///< sigma at y = +t/2 [Pa], tension positive
    std::vector<double> bottom_stress_pa;  ///< sigma at y = -t/2 [Pa], tension positive
};

/// The normal force of one contact pair of System::pairs() (meshed part) as a pressure.
struct PairPressure {
    int pair = 0;              ///< index in System::pairs()
    int interface_index = 0;   ///< interface i: leaf i above, leaf i+1 below (a clip: its first leaf)
    double x_m = 0.0;          ///< position [m]
    PairKind kind = PairKind::coulomb;
    int clip_index = -1;       ///< >= 0: the row of rebound clip clips[clip_index]
    /// The force pressing the surfaces together [N], >= 0 (compression positive: -p_n; at a clamp
    /// the preload with it, F_c - p_n; at a clip the strap's tension).
    double normal_force_n = 0.0;
    double tangential_force_n = 0.0;  ///< p_t on the upper leaf, +x [N]
    /// The length the pair stands for [m]: half the distance to its neighbours on the interface
    /// (half an element at the overlap's ends); a clamp of ClampSpec::length_m > 0: that length.
    double tributary_length_m = 0.0;
    double contact_width_m = 0.0;     ///< min of the two leaves' widths at x [m]
    double line_load_n_per_m = 0.0;   ///< normal_force_n / tributary_length_m [N/m]
    double pressure_pa = 0.0;         ///< line_load_n_per_m / contact_width_m: the mean contact pressure [Pa]
};

/// The largest pressure on one interface and where it sits (clamps included, clips not).
struct InterfacePeak {
    int interface_index = 0;
    int pair = -1;                    ///< index in System::pairs() (-1: no pair on the interface)
    double x_m = std::numeric_limits<double>::quiet_NaN();
    double line_load_n_per_m = 0.0;   ///< [N/m]
    double pressure_pa = 0.0;         ///< [Pa]
};

/// Everything at one output time.
struct Stresses {
    std::vector<LeafStresses> leaves;      ///< one per leaf, ModelSpec::leaves order
    std::vector<PairPressure> pairs;       ///< one per System::pairs(), in that order
    std::vector<InterfacePeak> interfaces; ///< one per interface (ModelSpec::interfaces order)
};

/// The leaves' motion at the time of z, for the elements' distributed loads when the leaves have
/// mass (density > 0). A massless stack (or a static state without gravity) needs none of it:
/// the default is no motion. The steppers with leaf mass fill it (Stepper::stresses()).
struct LeafMotion {
    /// Reduced accelerations z'' [m/s^2, rad/s^2] (System::num_reduced_dofs(), w last), relative to
    /// the supports' frame; empty: zero.
    Eigen::VectorXd acceleration;
    /// Reduced velocities z' [m/s, rad/s], for the structural damping's force; empty: zero.
    Eigen::VectorXd velocity;
    /// The frame's acceleration a_f = g + y_b''(t) [m/s^2], + meaning gravity's sense (-y): every
    /// mass of the leaves carries -rho A a_f per length (gravity and a base acceleration, in the
    /// supports' frame; ReducedLoad's q = -(g + y_b'') l).
    double frame_acceleration_m_per_s2 = 0.0;
    /// Rayleigh damping of the leaves, C = alpha M + beta K (SimulationOptions::damping).
    StructuralDamping damping;
};

/// The stresses for reduced displacements z (System::num_reduced_dofs(), w last) and the pairs'
/// forces at the same time (one PairRecord per System::pairs(), as Stepper::pairs() gives them),
/// with the leaves' motion at that time for their distributed loads (leaves with mass).
/// InputError naming z, pairs, motion.acceleration or motion.velocity when their sizes do not fit
/// `system`.
Stresses compute_stresses(const System& system, const Eigen::VectorXd& z, const std::vector<PairRecord>& pairs,
                          const LeafMotion& motion = {});

/// One extreme fibre stress: where and when.
struct StressExtreme {
    double stress_pa = std::numeric_limits<double>::quiet_NaN();  ///< [Pa] (NaN: nothing fed yet)
    double x_m = std::numeric_limits<double>::quiet_NaN();        ///< [m]
    double t_s = std::numeric_limits<double>::quiet_NaN();        ///< [s]
    Fibre fibre = Fibre::top;
};

/// A leaf's largest tension (the greatest fibre stress, over both fibres, all nodes and times fed)
/// and largest compression (the least). If a leaf is nowhere in tension its "tension" is the least
/// compressive stress: the signs tell.
struct LeafExtremes {
    int leaf = 0;
    StressExtreme tension, compression;
};

/// The per-run extremes of every leaf: feed it each output's stresses (add()).
class StressExtremes {
public:
    /// Takes the stresses at time t_s [s]. InputError naming stresses when its leaves differ in
    /// number or node count from the first call's.
    void add(double t_s, const Stresses& stresses);
    const std::vector<LeafExtremes>& leaves() const noexcept { return leaves_; }

private:
    std::vector<LeafExtremes> leaves_;
    std::vector<std::size_t> nodes_;
};

/// The range (max - min) and mean ((max + min) / 2) of one fibre's stress at one node over a window [Pa].
struct FibreCycle {
    double range_pa = 0.0;
    double mean_pa = std::numeric_limits<double>::quiet_NaN();
};

/// One leaf's ranges and means at its nodes (x as LeafStresses::x_m).
struct LeafCycle {
    int leaf = 0;
    std::vector<double> x_m;
    std::vector<FibreCycle> top, bottom;
};

/// Where the range is largest over every leaf, node and fibre.
struct LargestRange {
    int leaf = -1;
    double x_m = std::numeric_limits<double>::quiet_NaN();
    Fibre fibre = Fibre::top;
    double range_pa = 0.0, mean_pa = std::numeric_limits<double>::quiet_NaN();
};

/// The stress range and mean at every node over a time window the caller chooses (for a periodic
/// loading: its last cycle, the fatigue input). Feed it every output (add()); outputs outside
/// [t_start_s, t_end_s] are ignored. The range is max - min of the stresses fed: on a cycle sampled
/// at the outputs, so a peak between two outputs is missed by at most the change over one output.
class StressWindow {
public:
    /// InputError naming t_start_s / t_end_s unless both are finite and t_start_s < t_end_s.
    StressWindow(double t_start_s, double t_end_s);
    void add(double t_s, const Stresses& stresses);
    /// The outputs taken so far.
    int samples() const noexcept { return samples_; }
    std::vector<LeafCycle> cycles() const;
    LargestRange largest_range() const;

private:
    double t0_, t1_;
    int samples_ = 0;
    std::vector<LeafCycle> shape_;                    // leaf and x per node
    std::vector<std::vector<double>> min_top_, max_top_, min_bottom_, max_bottom_;
};

}  // namespace stackbeam

namespace stackbeam {

/// What a StressMonitor is asked for (the run's loading and length).
struct StressMonitorOptions {
    /// > 0: the loading is periodic with this period [s] (Loading::period_s()): the cycle is the last
    /// period, [t_end_s - period_s, t_end_s], and fatigue takes its max and min at every node
    /// (CycleCounting::periodic; lives in cycles of the loading). 0: an irregular loading (base
    /// excitation, a table, free vibration): the whole run is counted by rainflow at the critical
    /// nodes (lives in repetitions of the run).
    double period_s = 0.0;
    /// The run's end [s] (SimulationOptions::t_end_s): the last record's time. Needed with period_s.
    double t_end_s = 0.0;
    /// Irregular loadings: per leaf, the nodes of the largest stress range (over the run, either
    /// fibre) whose histories are counted by rainflow and Miner, >= 1. With Basquin's exponent
    /// 1/b ~ -10 a node at 0.8 of the largest range takes ~0.1 of its damage, but a node of a
    /// smaller range and a larger tensile mean can be worse: 4 covers a leaf's few hot spots
    /// (the seat, a clamp, the end of the leaf above).
    int critical_nodes = 4;
    /// The rainflow's hysteresis gate [Pa], >= 0 (rainflow_cycles).
    double gate_pa = 0.0;
};

/// One leaf's fatigue over the run (only where the leaf has a material: LeafSpec::material).
struct LeafFatigueResult {
    int leaf = 0;
    bool has_material = false;  ///< false: no figures (fatigue is default)
    /// leaf_fatigue's figures; FatigueSpot::node is the index into LeafStresses::x_m (whole leaf)
    LeafFatigue fatigue;
};

/// Everything a run's stresses give at its end (StressMonitor::summary()).
struct StressSummary {
    int samples = 0;                       ///< outputs fed
    std::vector<LeafExtremes> extremes;    ///< each leaf's largest tension and compression (StressExtremes)
    /// The cycle: the last period (periodic), else the whole run; its range and mean at every node
    /// and fibre, and where the range is largest (StressWindow).
    double cycle_start_s = 0.0, cycle_end_s = 0.0;
    int cycle_samples = 0;
    std::vector<LeafCycle> cycle;
    LargestRange largest_range;
    CycleCounting counting = CycleCounting::periodic;  ///< how fatigue counted (periodic or rainflow)
    std::vector<LeafFatigueResult> fatigue;            ///< one per leaf
};

/// The per-run stress figures in one place: feed it each output's stresses (add()), read summary()
/// at the end. The one call the front-ends make (command line, JSON summary, sweep table, Python).
/// It keeps the extremes and the cycle's max and min per node and fibre; for an irregular loading
/// with a material on some leaf, also each node's turning points (the reversals of its fibres'
/// stresses: rainflow needs nothing else), so its memory grows with the reversals, not the outputs.
class StressMonitor {
public:
    /// InputError naming options.period_s, options.t_end_s, options.critical_nodes or
    /// options.gate_pa when out of range; spec gives each leaf's material.
    StressMonitor(const ModelSpec& spec, const StressMonitorOptions& options);
    /// The stresses of the output at t_s [s] (times increasing). InputError naming stresses when
    /// its leaves differ from the first call's.
    void add(double t_s, const Stresses& stresses);
    /// The figures so far. InputError naming stresses when nothing was fed (or nothing in the
    /// last period).
    StressSummary summary() const;

private:
    StressMonitorOptions options_;
    std::vector<std::optional<FatigueMaterial>> materials_;
    bool keep_histories_ = false;
    int samples_ = 0;
    StressExtremes extremes_;
    StressWindow window_;
    std::vector<std::vector<std::vector<double>>> top_, bottom_;  // [leaf][node]: turning points [Pa]
};

}  // namespace stackbeam
