// The leaves' stress resultants from the element end forces, the pairs' pressures, and the
// accumulators over a run (stresses.hpp; decision 054).
#include "stackbeam/post/stresses.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <string>

#include "fe/leaf_sections.hpp"
#include "stackbeam/errors.hpp"

namespace stackbeam {
namespace {

/// The contact pairs' axial force [N] and moment [N m] on leaf l at grid node j (conventions.hpp):
/// on the upper leaf A, p_t in +x at its bottom surface (h_A/2 below the axis): moment +h_A/2 p_t;
/// on the lower leaf B the reaction -p_t at its top surface: moment +h_B/2 p_t (G's tangential row).
/// With `per_length` (each candidate pair's tributary length, tributary_lengths), each pair's
/// force and moment divided by its tributary length: the traction it stands for, per metre; with
/// `arm_x_m`, the moment's arm (half the thickness) taken at that x rather than at the pair's.
std::pair<double, double> contact_load(const System& system, const std::vector<PairRecord>& pairs, int l, int j,
                                       const std::vector<double>* per_length = nullptr, const double* arm_x_m = nullptr) {
    double fx = 0.0, m = 0.0;
    const auto& leaves = system.model().spec().leaves;
    for (std::size_t k = 0; k < pairs.size(); ++k) {
        const PairSpec& cp = system.pair_spec(static_cast<int>(k));
        if (cp.node != j || cp.clip_index >= 0) continue;
        double p_t = pairs[k].p_t_n;
        if (per_length != nullptr) {
            const double length = (*per_length)[system.pair_candidates()[k]];
            if (!(length > 0.0)) continue;
            p_t /= length;
        }
        const double arm = 0.5 * leaf_thickness_m(leaves[l], arm_x_m != nullptr ? *arm_x_m : cp.x_m);
        if (cp.interface_index == l) {
            fx += p_t;
            m += arm * p_t;
        } else if (cp.interface_index + 1 == l) {
            fx -= p_t;
            m += arm * p_t;
        }
    }
    return {fx, m};
}

/// Each candidate pair's tributary length on its interface [m]: half the distance to its
/// neighbours (the interface's candidates sorted by x; clips are not on an interface: 0).
std::vector<double> tributary_lengths(const Model& model) {
    const auto& cand = model.candidate_pairs();
    std::map<int, std::vector<int>> by_interface;
    for (int c = 0; c < static_cast<int>(cand.size()); ++c)
        if (cand[c].clip_index < 0) by_interface[cand[c].interface_index].push_back(c);
    std::vector<double> out(cand.size(), 0.0);
    for (auto& [iface, list] : by_interface) {
        std::sort(list.begin(), list.end(), [&](int a, int b) { return cand[a].x_m < cand[b].x_m; });
        for (std::size_t k = 0; k < list.size(); ++k) {
            const double left = k > 0 ? cand[list[k - 1]].x_m : cand[list[k]].x_m;
            const double right = k + 1 < list.size() ? cand[list[k + 1]].x_m : cand[list[k]].x_m;
            out[list[k]] = 0.5 * (right - left);
        }
    }
    return out;
}

/// One leaf's N, M, V at its meshed nodes. A contact force at a node stands for the traction over
/// its tributary length, half on each side: at a node between two elements the value is the mean of
/// their end values; at the leaf's end the tributary lies inside, so the value is the element's end
/// value with the contact's axial force and moment at that node taken back (the support's reaction:
/// 0 at a free or pinned end). The half model's seat is not an end (the mirror continues it).
/// The leaves' nodal velocities and accelerations (full DOFs) for the elements' distributed loads;
/// empty when the stack has none to take off (massless leaves, no motion and no frame acceleration).
struct NodalMotion {
    Eigen::VectorXd v, a;  // [m/s, rad/s], [m/s^2, rad/s^2] (empty: zero)
    double a_frame = 0.0;  // g + y_b'' [m/s^2]
    double alpha = 0.0, beta = 0.0;  // Rayleigh's C = alpha M + beta K [1/s, s]
};

/// With leaf mass, N, M, V at an element's ends: the end forces on the element,
/// f_e = K_e (u_e + beta v_e) + M_e (a_e + alpha v_e + a_f e_y) (stresses.hpp), are what its nodes
/// give it; its own loads (inertia, weight, damping) act between them, so N, M, V are no longer
/// constant / linear: each end's value is its own end force (N1 = -f0, N2 = f3; M1 = -f2, M2 = f5;
/// V1 = f1, V2 = -f4, which for an unloaded element are the constant N, V and the linear M's ends).
void leaf_resultants(const System& system, const Eigen::VectorXd& u, const NodalMotion& motion,
                     const std::vector<PairRecord>& pairs, const std::vector<double>& trib, int l, LeafStresses& out) {
    const Model& model = system.model();
    const LeafSpec& leaf = model.spec().leaves[l];
    const auto& xs = model.nodes_x();
    const int first = model.first_node(l), last = model.last_node(l);
    const std::size_t n = static_cast<std::size_t>(last - first + 1);
    std::vector<double> N(n, 0.0), M(n, 0.0), V(n, 0.0), count(n, 0.0);
    const bool massive = leaf.density_kg_per_m3 > 0.0 && (motion.a.size() > 0 || motion.v.size() > 0 || motion.a_frame != 0.0);
    for (int j = first; j < last; ++j) {
        const detail::ElementMatrix k = detail::element_stiffness(leaf, xs[j], xs[j + 1]);
        const int a = 3 * system.node_dof(l, j), b = 3 * system.node_dof(l, j + 1);
        const int dof[6] = {a, a + 1, a + 2, b, b + 1, b + 2};
        double ue[6], me_in[6] = {0.0, motion.a_frame, 0.0, 0.0, motion.a_frame, 0.0};  // me_in: a_e + alpha v_e + a_f e_y
        for (int r = 0; r < 6; ++r) {
            ue[r] = u[dof[r]];
            if (!massive) continue;
            if (motion.v.size() > 0) {
                ue[r] += motion.beta * motion.v[dof[r]];
                me_in[r] += motion.alpha * motion.v[dof[r]];
            }
            if (motion.a.size() > 0) me_in[r] += motion.a[dof[r]];
        }
        double f[6] = {};  // the end forces on the element: K_e (u_e + beta v_e) (+ M_e (a_e + alpha v_e + a_f e_y))
        for (int r = 0; r < 6; ++r)
            for (int c = 0; c < 6; ++c) f[r] += k[r][c] * ue[c];
        if (massive) {
            const detail::ElementMatrix m = detail::element_mass(leaf, xs[j], xs[j + 1]);
            for (int r = 0; r < 6; ++r)
                for (int c = 0; c < 6; ++c) f[r] += m[r][c] * me_in[c];
        }
        // N positive in tension, M from the end moments on the element (counter-clockwise) -m1, m2,
        // V = dM/dx; without loads between the ends f[3] = -f[0] and f[1] = -f[4] = (m2 + m1)/L.
        const std::size_t i = static_cast<std::size_t>(j - first);
        N[i] += -f[0];
        N[i + 1] += f[3];
        M[i] += -f[2];
        M[i + 1] += f[5];
        V[i] += f[1];
        V[i + 1] += -f[4];
        count[i] += 1.0;
        count[i + 1] += 1.0;
    }
    if (n > 1) {  // the ends: left, N(end) = N_inside + F_x, M(end) = M_inside + M_c; right, minus
        const auto [fx0, m0] = contact_load(system, pairs, l, first);
        N[0] += fx0;
        M[0] += m0;
        if (!(model.spec().symmetry == Symmetry::half && last == model.attachment_node())) {
            const auto [fx1, m1] = contact_load(system, pairs, l, last);
            N[n - 1] -= fx1;
            M[n - 1] -= m1;
        }
    }
    // The seat of tied leaves (decision 066): no pair there; the tie carries the traction of the
    // seat's tributary [x_s - h_L/2, x_s + h_R/2] as one point force, 0 in a symmetric stack (the
    // two halves' shear flows cancel), so the mean of the two sides would miss each half's traction
    // (O(h): 5 % of the peak at 20 elements on two bonded leaves). Each half's traction is taken as
    // the neighbouring pair's per metre (its force over its tributary length) over the half element:
    // from the left N(x_s) = N_L - F_L, from the right N(x_s) = N_R + F_R; the value is their mean (M
    // with the pairs' moments likewise, their arms the leaves' half thicknesses at the seat, where
    // the axes are stacked and touch: the correction adds no couple to the section, whose sums stay
    // those of its two sides). The half model's seat is the mirror: N_R = N_L, F_R = -F_L.
    const int seat = model.attachment_node();
    const bool half = model.spec().symmetry == Symmetry::half;
    const auto& tied = model.tied_leaves();
    if (seat > first && (seat < last || (half && seat == last)) && std::find(tied.begin(), tied.end(), l) != tied.end()) {
        const std::size_t i = static_cast<std::size_t>(seat - first);
        const double h_left = xs[seat] - xs[seat - 1];
        const auto [q_left, qm_left] = contact_load(system, pairs, l, seat - 1, &trib, &xs[seat]);
        N[i] -= 0.5 * h_left * q_left;
        M[i] -= 0.5 * h_left * qm_left;
        if (seat < last) {
            const double h_right = xs[seat + 1] - xs[seat];
            const auto [q_right, qm_right] = contact_load(system, pairs, l, seat + 1, &trib, &xs[seat]);
            N[i] += 0.5 * h_right * q_right;
            M[i] += 0.5 * h_right * qm_right;
        }
    }
    out.leaf = l;
    for (std::size_t i = 0; i < n; ++i) {
        const double x = xs[first + static_cast<int>(i)];
        const double c = std::max(count[i], 1.0);
        out.x_m.push_back(x);
        out.thickness_m.push_back(leaf_thickness_m(leaf, x));
        out.width_m.push_back(leaf_width_m(leaf, x));
        out.axial_force_n.push_back(N[i] / c);
        out.bending_moment_n_m.push_back(M[i] / c);
        out.shear_force_n.push_back(V[i] / c);
    }
}

/// The half model's leaf mirrored about the seat x_R (the node there once): N, M even, V odd.
void mirror(LeafStresses& s, double x_r) {
    const std::size_t count = s.x_m.size();
    for (std::size_t i = count - 1; i-- > 0;) {
        s.x_m.push_back(2.0 * x_r - s.x_m[i]);
        s.thickness_m.push_back(s.thickness_m[i]);
        s.width_m.push_back(s.width_m[i]);
        s.axial_force_n.push_back(s.axial_force_n[i]);
        s.bending_moment_n_m.push_back(s.bending_moment_n_m[i]);
        s.shear_force_n.push_back(-s.shear_force_n[i]);
    }
}

void check_leaves(const Stresses& s, std::vector<std::size_t>& nodes, const char* who) {
    if (nodes.empty()) {
        for (const auto& l : s.leaves) nodes.push_back(l.x_m.size());
        return;
    }
    bool same = nodes.size() == s.leaves.size();
    for (std::size_t l = 0; same && l < nodes.size(); ++l) same = nodes[l] == s.leaves[l].x_m.size();
    if (!same)
        throw InputError("stresses", std::string("has other leaves or nodes than the first stresses given to ") + who +
                                         ": feed it the outputs of one run");
}

}  // namespace

Stresses compute_stresses(const System& system, const Eigen::VectorXd& z, const std::vector<PairRecord>& pairs,
                          const LeafMotion& motion) {
    if (pairs.size() != system.pairs().size())
        throw InputError("pairs", "has " + std::to_string(pairs.size()) + " entries: compute_stresses needs one per System::pairs(), " +
                                      std::to_string(system.pairs().size()));
    const Model& model = system.model();
    const ModelSpec& spec = model.spec();
    const Eigen::VectorXd u = system.leaf_displacements(z);  // InputError naming z on a wrong size
    NodalMotion nodal;
    auto full = [&](const Eigen::VectorXd& r, const char* name) {
        if (r.size() == 0) return Eigen::VectorXd();
        if (r.size() != z.size())
            throw InputError(name, "has " + std::to_string(r.size()) + " entries: compute_stresses needs none or one per reduced DOF, " +
                                       std::to_string(z.size()));
        return Eigen::VectorXd(system.leaf_displacements(r));  // P r: the map is linear
    };
    nodal.a = full(motion.acceleration, "motion.acceleration");
    if (motion.damping.active()) nodal.v = full(motion.velocity, "motion.velocity");
    nodal.a_frame = motion.frame_acceleration_m_per_s2;
    nodal.alpha = motion.damping.rayleigh_alpha_per_s;
    nodal.beta = motion.damping.rayleigh_beta_s;
    const bool half = spec.symmetry == Symmetry::half;
    const double x_r = model.nodes_x()[model.attachment_node()];
    const std::vector<double> trib = tributary_lengths(model);
    Stresses out;
    out.leaves.resize(spec.leaves.size());
    for (int l = 0; l < static_cast<int>(spec.leaves.size()); ++l) {
        LeafStresses& s = out.leaves[l];
        leaf_resultants(system, u, nodal, pairs, trib, l, s);
        if (half) mirror(s, x_r);
        const std::size_t n = s.x_m.size();
        s.top_stress_pa.resize(n);
        s.bottom_stress_pa.resize(n);
        for (std::size_t i = 0; i < n; ++i) {  // sigma(y) = N/A - M y/I at y = +-t/2 (stresses.hpp)
            const double b = s.width_m[i], t = s.thickness_m[i];
            const double axial = s.axial_force_n[i] / (b * t), bending = 6.0 * s.bending_moment_n_m[i] / (b * t * t);
            s.top_stress_pa[i] = axial - bending;
            s.bottom_stress_pa[i] = axial + bending;
        }
    }

    // --- the pairs' pressures ------------------------------------------------------
    const double tol = model.x_tolerance_m();
    out.interfaces.resize(spec.interfaces.size());
    for (std::size_t i = 0; i < out.interfaces.size(); ++i) out.interfaces[i].interface_index = static_cast<int>(i);
    out.pairs.resize(pairs.size());
    for (std::size_t k = 0; k < pairs.size(); ++k) {
        const PairSpec& cp = system.pair_spec(static_cast<int>(k));
        PairPressure& q = out.pairs[k];
        q.pair = static_cast<int>(k);
        q.interface_index = cp.interface_index;
        q.x_m = cp.x_m;
        q.kind = cp.kind;
        q.clip_index = cp.clip_index;
        // compression positive; a clamp squeezes with its preload besides (conventions.hpp's tau);
        // a clip's row force is the strap's pull, p_n <= 0, the same sign as a compressed pair's
        q.normal_force_n = -pairs[k].p_n_n + (cp.kind == PairKind::clamp ? cp.preload_n : 0.0);
        q.tangential_force_n = pairs[k].p_t_n;
        const int b_leaf = cp.clip_index >= 0 ? spec.clips[cp.clip_index].last_leaf : cp.interface_index + 1;
        q.contact_width_m = std::min(leaf_width_m(spec.leaves[cp.interface_index], cp.x_m), leaf_width_m(spec.leaves[b_leaf], cp.x_m));
        q.tributary_length_m = trib[system.pair_candidates()[k]];
        if (cp.kind == PairKind::clamp)
            for (const ClampSpec& c : spec.clamps)
                if (std::abs(c.x_m - cp.x_m) <= tol && c.length_m > 0.0) q.tributary_length_m = c.length_m;
        if (q.tributary_length_m > 0.0) q.line_load_n_per_m = q.normal_force_n / q.tributary_length_m;
        if (q.contact_width_m > 0.0) q.pressure_pa = q.line_load_n_per_m / q.contact_width_m;
        if (cp.clip_index >= 0) continue;
        InterfacePeak& peak = out.interfaces[cp.interface_index];
        if (peak.pair < 0 || q.pressure_pa > peak.pressure_pa) {
            peak.pair = q.pair;
            peak.x_m = q.x_m;
            peak.line_load_n_per_m = q.line_load_n_per_m;
            peak.pressure_pa = q.pressure_pa;
        }
    }
    return out;
}

void StressExtremes::add(double t_s, const Stresses& stresses) {
    check_leaves(stresses, nodes_, "StressExtremes");
    if (leaves_.empty()) {
        leaves_.resize(stresses.leaves.size());
        for (std::size_t l = 0; l < leaves_.size(); ++l) leaves_[l].leaf = stresses.leaves[l].leaf;
    }
    for (std::size_t l = 0; l < leaves_.size(); ++l) {
        const LeafStresses& s = stresses.leaves[l];
        LeafExtremes& e = leaves_[l];
        auto take = [&](const std::vector<double>& sigma, Fibre fibre) {
            for (std::size_t i = 0; i < sigma.size(); ++i) {
                if (!(sigma[i] <= e.tension.stress_pa)) e.tension = {sigma[i], s.x_m[i], t_s, fibre};   // NaN at first
                if (!(sigma[i] >= e.compression.stress_pa)) e.compression = {sigma[i], s.x_m[i], t_s, fibre};
            }
        };
        take(s.top_stress_pa, Fibre::top);
        take(s.bottom_stress_pa, Fibre::bottom);
    }
}

StressWindow::StressWindow(double t_start_s, double t_end_s) : t0_(t_start_s), t1_(t_end_s) {
    if (!std::isfinite(t_start_s)) throw InputError("t_start_s", "value " + format_value(t_start_s) + " is not allowed: it must be finite");
    if (!(std::isfinite(t_end_s) && t_end_s > t_start_s))
        throw InputError("t_end_s", "value " + format_value(t_end_s) + " is not allowed: it must be finite and > t_start_s = " +
                                        format_value(t_start_s));
}

void StressWindow::add(double t_s, const Stresses& stresses) {
    if (t_s < t0_ || t_s > t1_) return;
    std::vector<std::size_t> nodes;
    for (const auto& l : shape_) nodes.push_back(l.x_m.size());
    check_leaves(stresses, nodes, "StressWindow");
    if (shape_.empty()) {
        for (const auto& s : stresses.leaves) {
            shape_.push_back({s.leaf, s.x_m, {}, {}});
            min_top_.push_back(s.top_stress_pa);
            max_top_.push_back(s.top_stress_pa);
            min_bottom_.push_back(s.bottom_stress_pa);
            max_bottom_.push_back(s.bottom_stress_pa);
        }
    }
    for (std::size_t l = 0; l < shape_.size(); ++l) {
        const LeafStresses& s = stresses.leaves[l];
        for (std::size_t i = 0; i < s.x_m.size(); ++i) {
            min_top_[l][i] = std::min(min_top_[l][i], s.top_stress_pa[i]);
            max_top_[l][i] = std::max(max_top_[l][i], s.top_stress_pa[i]);
            min_bottom_[l][i] = std::min(min_bottom_[l][i], s.bottom_stress_pa[i]);
            max_bottom_[l][i] = std::max(max_bottom_[l][i], s.bottom_stress_pa[i]);
        }
    }
    ++samples_;
}

std::vector<LeafCycle> StressWindow::cycles() const {
    std::vector<LeafCycle> out = shape_;
    for (std::size_t l = 0; l < out.size(); ++l)
        for (std::size_t i = 0; i < out[l].x_m.size(); ++i) {
            out[l].top.push_back({max_top_[l][i] - min_top_[l][i], 0.5 * (max_top_[l][i] + min_top_[l][i])});
            out[l].bottom.push_back({max_bottom_[l][i] - min_bottom_[l][i], 0.5 * (max_bottom_[l][i] + min_bottom_[l][i])});
        }
    return out;
}

LargestRange StressWindow::largest_range() const {
    LargestRange best;
    for (const LeafCycle& c : cycles())
        for (std::size_t i = 0; i < c.x_m.size(); ++i)
            for (const Fibre f : {Fibre::top, Fibre::bottom}) {
                const FibreCycle& fc = f == Fibre::top ? c.top[i] : c.bottom[i];
                if (best.leaf < 0 || fc.range_pa > best.range_pa) best = {c.leaf, c.x_m[i], f, fc.range_pa, fc.mean_pa};
            }
    return best;
}

}  // namespace stackbeam

namespace stackbeam {
namespace {

/// Appends s to a history kept as its turning points: a sample that continues the last
/// excursion moves its end, one that reverses it starts a new one (rainflow_cycles counts the
/// same cycles from these as from every sample; equal samples add nothing).
void add_turning_point(std::vector<double>& tp, double s) {
    const std::size_t n = tp.size();
    if (n == 0 || (n == 1 && s != tp[0])) {
        tp.push_back(s);
        return;
    }
    if (n == 1 || s == tp[n - 1]) return;
    if ((s > tp[n - 1]) == (tp[n - 1] > tp[n - 2])) tp[n - 1] = s;
    else tp.push_back(s);
}

StressWindow monitor_window(const StressMonitorOptions& o) {
    if (!(std::isfinite(o.period_s) && o.period_s >= 0.0))
        throw InputError("options.period_s", "value " + format_value(o.period_s) + " is not allowed: it must be >= 0 (0: not periodic)");
    if (o.period_s == 0.0) return StressWindow(std::numeric_limits<double>::lowest(), std::numeric_limits<double>::max());
    if (!(std::isfinite(o.t_end_s) && o.t_end_s >= o.period_s))
        throw InputError("options.t_end_s", "value " + format_value(o.t_end_s) +
                                                " is not allowed: with a periodic loading it must be >= options.period_s = " +
                                                format_value(o.period_s) + " (the last period is the cycle)");
    const double tol = 1e-9 * std::max(1.0, o.t_end_s);  // the output grid's round-off
    return StressWindow(o.t_end_s - o.period_s - tol, o.t_end_s + tol);
}

}  // namespace

StressMonitor::StressMonitor(const ModelSpec& spec, const StressMonitorOptions& options)
    : options_(options), window_(monitor_window(options)) {
    if (options.critical_nodes < 1)
        throw InputError("options.critical_nodes", "value " + std::to_string(options.critical_nodes) + " is not allowed: it must be >= 1");
    if (!(std::isfinite(options.gate_pa) && options.gate_pa >= 0.0))
        throw InputError("options.gate_pa", "value " + format_value(options.gate_pa) + " is not allowed: it must be finite and >= 0");
    for (const LeafSpec& l : spec.leaves) {
        materials_.push_back(l.material);
        keep_histories_ = keep_histories_ || (options.period_s == 0.0 && l.material.has_value());
    }
}

void StressMonitor::add(double t_s, const Stresses& stresses) {
    extremes_.add(t_s, stresses);  // checks the leaves against the first call's
    window_.add(t_s, stresses);
    ++samples_;
    if (!keep_histories_) return;
    if (top_.empty()) {
        top_.resize(stresses.leaves.size());
        bottom_.resize(stresses.leaves.size());
        for (std::size_t l = 0; l < stresses.leaves.size(); ++l) {
            top_[l].resize(stresses.leaves[l].x_m.size());
            bottom_[l].resize(stresses.leaves[l].x_m.size());
        }
    }
    for (std::size_t l = 0; l < stresses.leaves.size(); ++l) {
        if (l >= materials_.size() || !materials_[l]) continue;
        const LeafStresses& s = stresses.leaves[l];
        for (std::size_t i = 0; i < s.x_m.size(); ++i) {
            add_turning_point(top_[l][i], s.top_stress_pa[i]);
            add_turning_point(bottom_[l][i], s.bottom_stress_pa[i]);
        }
    }
}

StressSummary StressMonitor::summary() const {
    if (samples_ == 0) throw InputError("stresses", "none were given to StressMonitor: feed it the run's outputs (add())");
    if (window_.samples() == 0)
        throw InputError("stresses", "none fell in the last period [" + format_value(options_.t_end_s - options_.period_s) + ", " +
                                         format_value(options_.t_end_s) + "] s: options.t_end_s must be the run's end");
    StressSummary out;
    out.samples = samples_;
    out.extremes = extremes_.leaves();
    const bool periodic = options_.period_s > 0.0;
    out.cycle_start_s = periodic ? options_.t_end_s - options_.period_s : 0.0;
    out.cycle_end_s = options_.t_end_s;
    out.cycle_samples = window_.samples();
    out.cycle = window_.cycles();
    out.largest_range = window_.largest_range();
    out.counting = periodic ? CycleCounting::periodic : CycleCounting::rainflow;
    for (std::size_t l = 0; l < out.cycle.size(); ++l) {
        LeafFatigueResult r;
        r.leaf = out.cycle[l].leaf;
        r.has_material = l < materials_.size() && materials_[l].has_value();
        if (r.has_material) {
            const LeafCycle& c = out.cycle[l];
            LeafStressHistories h;
            auto take = [&](std::size_t i, std::vector<double> top, std::vector<double> bottom) {
                h.node.push_back(static_cast<int>(i));
                h.x_m.push_back(c.x_m[i]);
                h.top_pa.push_back(std::move(top));
                h.bottom_pa.push_back(std::move(bottom));
            };
            if (periodic) {  // one cycle per node and fibre from the period's max and min
                for (std::size_t i = 0; i < c.x_m.size(); ++i)
                    take(i, {c.top[i].mean_pa - 0.5 * c.top[i].range_pa, c.top[i].mean_pa + 0.5 * c.top[i].range_pa},
                         {c.bottom[i].mean_pa - 0.5 * c.bottom[i].range_pa, c.bottom[i].mean_pa + 0.5 * c.bottom[i].range_pa});
                r.fatigue = leaf_fatigue(*materials_[l], h, CycleCounting::periodic, options_.gate_pa);
            } else {  // the critical nodes' turning points by rainflow, one node at a time (their lengths differ)
                std::vector<std::size_t> order(c.x_m.size());
                for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
                auto range = [&](std::size_t i) { return std::max(c.top[i].range_pa, c.bottom[i].range_pa); };
                const std::size_t k = std::min(order.size(), static_cast<std::size_t>(options_.critical_nodes));
                std::partial_sort(order.begin(), order.begin() + static_cast<std::ptrdiff_t>(k), order.end(),
                                  [&](std::size_t a, std::size_t b) { return range(a) > range(b); });
                bool first = true;
                for (std::size_t n = 0; n < k; ++n) {
                    h = {};
                    take(order[n], top_[l][order[n]], bottom_[l][order[n]]);
                    const LeafFatigue f = leaf_fatigue(*materials_[l], h, CycleCounting::rainflow, options_.gate_pa);
                    if (first) {
                        r.fatigue = f;
                    } else {
                        if (f.has_safety_factor && f.least_safety_factor < r.fatigue.least_safety_factor) {
                            r.fatigue.least_safety_factor = f.least_safety_factor;
                            r.fatigue.safety_spot = f.safety_spot;
                        }
                        // the leaf's life is known where every critical node's is: the largest damage
                        if (r.fatigue.has_life && (!f.has_life || f.damage_per_repetition > r.fatigue.damage_per_repetition)) {
                            r.fatigue.has_life = f.has_life;
                            r.fatigue.shortest_life_repetitions = f.shortest_life_repetitions;
                            r.fatigue.damage_per_repetition = f.damage_per_repetition;
                            r.fatigue.life_spot = f.life_spot;
                        }
                    }
                    first = false;
                }
            }
        }
        out.fatigue.push_back(std::move(r));
    }
    return out;
}

}  // namespace stackbeam
