// Finite elements of the leaves, constraints, and the condensation of the
// paper's eqs. (1)-(6) and (A3). See system.hpp for the formulation.
#include "stackbeam/fe/system.hpp"

#include <cmath>
#include <algorithm>
#include <atomic>
#include <mutex>
#include <string>

#include "fe/leaf_sections.hpp"
#include "fe/system_internal.hpp"
#include "model/assembly.hpp"
#include "stackbeam/errors.hpp"

namespace stackbeam {

struct System::LazyCompliance {
    std::once_flag once;
    std::atomic<bool> built{false};
    Eigen::MatrixXd C;
};

namespace {

using Triplets = std::vector<Eigen::Triplet<double>>;
using Terms = std::vector<std::pair<int, double>>;  // (DOF, coefficient)

// The constructor's steps, in order (each a function of what the previous ones made).

/// The leaves' element stiffness on the full DOFs (3 per node, System::node_dof).
Triplets leaf_stiffness(const System& sys, const Model& model) {
    const auto& spec = model.spec();
    const auto& xs = model.nodes_x();
    Triplets kt;
    for (int l = 0; l < static_cast<int>(spec.leaves.size()); ++l) {
        for (int j = model.first_node(l); j < model.last_node(l); ++j)
            detail::add_matrix(kt, sys.node_dof(l, j), sys.node_dof(l, j + 1), detail::element_stiffness(spec.leaves[l], xs[j], xs[j + 1]));
    }
    return kt;
}

/// Each full DOF's role in the constraints: -1 fixed, -2 seat w, -3 seat theta, -4 seat axial
/// (-y theta_R), >= 0 its own master, -5 a combination of other full DOFs (an eye or a shackle:
/// dependent[dof]).
struct DofRoles {
    std::vector<int> role;
    std::vector<Terms> dependent;
};

/// A support of kind `s` at the leaf end whose node's first full DOF is `b`: the support point at
/// height e above the axis moves (u - e theta, v) (small deflection). A bushing's springs go to `kt`.
void add_support(SupportKind s, const LeafEndSpec& end, int b, DofRoles& roles, Triplets& kt) {
    auto& role = roles.role;
    const double e = end.eye_offset_m;
    if (s == SupportKind::pinned) role[b + 1] = -1;
    if (s == SupportKind::fixed) role[b] = role[b + 1] = role[b + 2] = -1;
    if (s == SupportKind::hinged) {  // v = 0, u - e theta = 0
        role[b + 1] = -1;
        role[b] = e == 0.0 ? -1 : -5;
        roles.dependent[b] = {{b + 2, e}};
    }
    if (s == SupportKind::shackle) {  // along the link (sin a, cos a): sin a (u - e theta) + cos a v = 0
        const double tan_a = std::tan(end.shackle_angle_rad);
        role[b + 1] = tan_a == 0.0 ? -1 : -5;
        roles.dependent[b + 1] = {{b, -tan_a}, {b + 2, tan_a * e}};
    }
    if (s == SupportKind::bushing) {  // springs from the support point to the ground
        const double kx = end.bushing_x_n_per_m;
        const int d[3] = {b, b + 1, b + 2};
        const double ax[3] = {1.0, 0.0, -e};  // its axial displacement u - e theta
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c)
                if (ax[r] * ax[c] != 0.0 && kx > 0.0) kt.emplace_back(d[r], d[c], kx * ax[r] * ax[c]);
        if (end.bushing_y_n_per_m > 0.0) kt.emplace_back(b + 1, b + 1, end.bushing_y_n_per_m);
        if (end.bushing_rotation_n_m_per_rad > 0.0) kt.emplace_back(b + 2, b + 2, end.bushing_rotation_n_m_per_rad);
    }
}

/// The roles of the supports, the seat (on the tied leaves' attachment node) and the half model's
/// symmetry plane; the bushings' springs go to `kt`.
DofRoles constraint_roles(const System& sys, const Model& model, int num_full, Triplets& kt) {
    const auto& spec = model.spec();
    const auto& xs = model.nodes_x();
    const bool half = spec.symmetry == Symmetry::half;
    const bool seat_rotates = !half;
    const double tol = model.x_tolerance_m();
    const int attach = model.attachment_node();
    const auto& tied = model.tied_leaves();
    DofRoles roles{std::vector<int>(num_full, 0), std::vector<Terms>(num_full)};
    auto& role = roles.role;
    for (int l = 0; l < static_cast<int>(spec.leaves.size()); ++l) {
        const auto& leaf = spec.leaves[l];
        const bool is_tied = std::find(tied.begin(), tied.end(), l) != tied.end();
        for (int j = model.first_node(l); j <= model.last_node(l); ++j) {
            const int b = 3 * sys.node_dof(l, j);
            const bool left_end = std::abs(xs[j] - leaf.x_start_m) <= tol;
            const bool right_end = std::abs(xs[j] - (leaf.x_start_m + leaf.length_m)) <= tol;
            if (left_end) add_support(leaf.left_support, leaf.left_end, b, roles, kt);
            if (right_end) add_support(leaf.right_support, leaf.right_end, b, roles, kt);
            if (j == attach && is_tied) {
                if ((left_end && leaf.left_support != SupportKind::free) ||
                    (right_end && leaf.right_support != SupportKind::free))
                    throw InputError("rigid_body.x_m", "value " + format_value(spec.rigid_body.x_m) +
                                                           " is at a supported end of leaves[" + std::to_string(l) +
                                                           "]: the rigid body must be free to move");
                role[b + 1] = -2;
                role[b + 2] = seat_rotates ? -3 : -1;
                role[b] = seat_rotates ? -4 : -1;
            }
            if (half && j == attach) {  // symmetry plane: u = 0, theta = 0
                role[b] = -1;
                role[b + 2] = -1;
            }
        }
    }
    return roles;
}

/// The reduced DOFs (masters): node-major order for a narrow band, then u_R (when the seat
/// slides), theta_R (when it rotates), then w.
struct Masters {
    std::vector<int> of_full;  // the master of a full DOF of role 0, else -1
    int count = 0;
    int slide = -1, theta = -1, w = -1;
};

Masters number_masters(const System& sys, const Model& model, const std::vector<int>& role, bool seat_slides,
                       bool seat_rotates) {
    Masters m;
    m.of_full.assign(role.size(), -1);
    const int nleaf = static_cast<int>(model.spec().leaves.size());
    for (int j = 0; j < static_cast<int>(model.nodes_x().size()); ++j)
        for (int l = 0; l < nleaf; ++l) {
            if (!model.leaf_has_node(l, j)) continue;
            for (int d = 0; d < 3; ++d)
                if (role[3 * sys.node_dof(l, j) + d] == 0) m.of_full[3 * sys.node_dof(l, j) + d] = m.count++;
        }
    m.slide = seat_slides ? m.count++ : -1;
    m.theta = seat_rotates ? m.count++ : -1;
    m.w = m.count++;
    return m;
}

/// P's entries (full DOFs <- masters): each full DOF as a sum of coefficient * master.
Triplets reduction_entries(const System& sys, const Model& model, const DofRoles& roles, const Masters& masters) {
    const auto& yc = model.centroid_heights_m();
    const auto& master = masters.of_full;
    Triplets pt;
    for (int l = 0; l < static_cast<int>(model.spec().leaves.size()); ++l)
        for (int j = model.first_node(l); j <= model.last_node(l); ++j)
            for (int d = 0; d < 3; ++d) {
                const int i = 3 * sys.node_dof(l, j) + d;
                switch (roles.role[i]) {
                    case 0: pt.emplace_back(i, master[i], 1.0); break;
                    case -2: pt.emplace_back(i, masters.w, 1.0); break;
                    case -3: pt.emplace_back(i, masters.theta, 1.0); break;
                    case -4:
                        if (yc[l] != 0.0) pt.emplace_back(i, masters.theta, -yc[l]);
                        if (masters.slide >= 0) pt.emplace_back(i, masters.slide, 1.0);
                        break;
                    case -5:
                        for (const auto& [dof, coef] : roles.dependent[i])
                            if (coef != 0.0 && master[dof] >= 0) pt.emplace_back(i, master[dof], coef);
                        break;
                    default: break;
                }
            }
    return pt;
}

/// A contact row on the full DOFs as a row on the reduced ones: each full DOF is a few masters
/// times coefficients (a row of P), so a row is a few (master, value) terms; near-zero sums are
/// dropped (1e-12).
Terms reduce_row(const Eigen::SparseMatrix<double, Eigen::RowMajor>& Prow, std::initializer_list<std::pair<int, double>> full) {
    Terms out;
    for (const auto& [dof, g] : full)
        for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(Prow, dof); it; ++it) {
            auto f = std::find_if(out.begin(), out.end(), [&](const auto& e) { return e.first == it.col(); });
            if (f == out.end()) out.emplace_back(static_cast<int>(it.col()), g * it.value());
            else f->second += g * it.value();
        }
    out.erase(std::remove_if(out.begin(), out.end(), [](const auto& e) { return std::abs(e.second) < 1e-12; }), out.end());
    std::sort(out.begin(), out.end());
    return out;
}

/// The contact rows of the candidate pairs that carry something: G's entries, per row its gap and
/// layer compliance, the pairs and the candidate each came from.
struct ContactRows {
    Triplets g;
    int rows = 0;
    std::vector<double> gaps, layer;
    std::vector<ContactPair> pairs;
    std::vector<int> candidate;
    int probe = -1;
};

// --- contact rows: surface kinematics (eq. 1), normal from upper A into lower B ---
ContactRows carrying_rows(const System& sys, const Model& model, const Eigen::SparseMatrix<double>& P) {
    const auto& spec = model.spec();
    const auto& cand = model.candidate_pairs();
    const Eigen::SparseMatrix<double, Eigen::RowMajor> Prow = P;
    ContactRows out;
    int& row = out.rows;
    for (int ci = 0; ci < static_cast<int>(cand.size()); ++ci) {
        const auto& cp = cand[ci];
        const int a = cp.interface_index, b = a + 1;
        const int da = 3 * sys.node_dof(a, cp.node), db = 3 * sys.node_dof(b, cp.node);
        // the moment arms: half the local thickness (a profiled leaf's axis lies midway between its surfaces)
        const double ha = leaf_thickness_m(spec.leaves[a], cp.x_m), hb = leaf_thickness_m(spec.leaves[b], cp.x_m);
        // s_n = -v_A + v_B - d_n ; s_t = (u_A + h_A/2 th_A) - (u_B - h_B/2 th_B) - d_t
        auto rn = reduce_row(Prow, {{da + 1, -1.0}, {db + 1, 1.0}});
        auto rt = reduce_row(Prow, {{da, 1.0}, {da + 2, 0.5 * ha}, {db, -1.0}, {db + 2, 0.5 * hb}});
        if (cp.clip_index >= 0) {  // rebound clip: s = v_first - v_last - d (opening beyond the clearance), no tangent
            const int last = spec.clips[cp.clip_index].last_leaf;
            rn = reduce_row(Prow, {{da + 1, 1.0}, {3 * sys.node_dof(last, cp.node) + 1, -1.0}});
            rt.clear();
            if (rn.empty())
                throw InputError("clips[" + std::to_string(cp.clip_index) + "].x_m",
                                 "value " + format_value(cp.x_m) + " is where supports fix the strapped leaves' opening: the clip does nothing there");
        }
        const bool has_n = !rn.empty();
        bool has_t = !rt.empty();
        if (!has_n && cp.initial_gap_m < 0.0) {  // named by the part that makes it: a gap or either leaf's camber
            const detail::Interference why = detail::interference_source(spec, a, cp.x_m);
            throw InputError(why.field, "value " + format_value(why.value) + " gives an interference of " + format_value(-cp.initial_gap_m) +
                                            " m between leaves[" + std::to_string(a) + "] and leaves[" + std::to_string(b) +
                                            "] at x = " + format_value(cp.x_m) +
                                            " m, where the seat or supports fix both leaves' normal motion: the assembly "
                                            "cannot close it, so the offset must be >= 0 there (a free camber is 0 at the seat)");
        }
        // A friction pair whose normal motion a support or the seat fixes has no normal
        // force of its own, so no friction limit: it carries nothing (a clamp keeps its preload).
        if (!has_n && cp.kind == PairKind::coulomb) has_t = false;
        if (cp.kind != PairKind::bonded && cp.friction_coefficient == 0.0) has_t = false;  // mu = 0: p_t = 0
        if (!has_n && !has_t) continue;
        ContactPair p;
        p.kind = cp.kind;
        p.friction_coefficient = cp.friction_coefficient;
        p.preload_n = cp.preload_n;
        if (has_n) {
            p.row_n = row++;
            for (const auto& [col, v] : rn) out.g.emplace_back(p.row_n, col, v);
            out.gaps.push_back(cp.initial_gap_m);
            out.layer.push_back(cp.normal_compliance_m_per_n);
        }
        if (has_t) {
            p.row_t = row++;
            for (const auto& [col, v] : rt) out.g.emplace_back(p.row_t, col, v);
            out.gaps.push_back(0.0);
            out.layer.push_back(cp.tangential_compliance_m_per_n);
        }
        if (ci == model.probe_pair()) out.probe = static_cast<int>(out.pairs.size());
        out.pairs.push_back(p);
        out.candidate.push_back(ci);
    }
    return out;
}

/// C' = G_r K_rr^-1 G_r^T + C_L is SPD when the rows without a layer (c_L = 0) of G_r have
/// full row rank (K_rr is SPD; a layer row adds c_L > 0 to the diagonal), i.e.
/// when their G_r G_r^T is: checked by a sparse LDL^T of it (the rows are local, so it is
/// sparse and cheap) rather than by factorising the dense C', which is built only on demand.
/// A pivot below 1e-10 of the largest diagonal entry counts as zero (the entries of G
/// are 1 and h/2, so an independent set of rows stays far above that).
void check_rigid_rows_independent(const Eigen::SparseMatrix<double>& Gr, const Eigen::VectorXd& layer) {
    const int row = static_cast<int>(layer.size());
    std::vector<Eigen::Triplet<double>> rigid_rows;
    int n_rigid = 0;
    for (int r = 0; r < row; ++r)
        if (layer[r] == 0.0) rigid_rows.emplace_back(n_rigid++, r, 1.0);
    if (n_rigid > 0) {
        Eigen::SparseMatrix<double> R(n_rigid, row);
        R.setFromTriplets(rigid_rows.begin(), rigid_rows.end());
        const Eigen::SparseMatrix<double> Gr_rigid = R * Gr;
        const Eigen::SparseMatrix<double> GGt = Gr_rigid * Gr_rigid.transpose();
        Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(GGt);
        const double scale = GGt.diagonal().maxCoeff();
        if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 1e-10 * scale))
            throw InputError("interfaces", "the contact compliance C' is singular: contact components are not independent");
    }
}

}  // namespace

int System::node_dof(int leaf, int node) const {
    if (!model_.leaf_has_node(leaf, node)) return -1;
    return node_offset_[leaf] + node;
}

System::System(const Model& model) : model_(model) {
    const auto& spec = model_.spec();
    const int nleaf = static_cast<int>(spec.leaves.size());
    const bool half = spec.symmetry == Symmetry::half;

    // --- full DOF numbering: leaf by leaf, 3 per node ---------------------------
    node_offset_.resize(nleaf);
    int nfull_nodes = 0;
    for (int l = 0; l < nleaf; ++l) {
        node_offset_[l] = nfull_nodes - model_.first_node(l);
        nfull_nodes += model_.last_node(l) - model_.first_node(l) + 1;
    }
    num_full_ = 3 * nfull_nodes;

    // --- constraints: each full DOF = sum of coef * master ------------------------
    Triplets kt = leaf_stiffness(*this, model_);
    const bool seat_rotates = !half;
    // The seat locates the stack axially unless an end's eye does (a hinged eye, a shackle, a bushing):
    // then it slides, with the axial displacement u_R of its own (docs/model-and-scenarios.md).
    // rigid_body.axial: 'auto' as described, 'held' never slides, 'free' always does.
    const SeatAxial axial = spec.rigid_body.axial;
    const bool ends_locate = ends_locate_axially(spec);
    const bool seat_slides = stackbeam::seat_slides(spec);
    const DofRoles roles = constraint_roles(*this, model_, num_full_, kt);
    const Masters masters = number_masters(*this, model_, roles.role, seat_slides, seat_rotates);
    const int nm = masters.count;
    seat_axial_dof_ = masters.slide;
    seat_rotation_dof_ = masters.theta;
    const Triplets pt = reduction_entries(*this, model_, roles, masters);
    Eigen::SparseMatrix<double> K(num_full_, num_full_);  // the leaves and the bushings
    K.setFromTriplets(kt.begin(), kt.end());
    P_.resize(num_full_, nm);
    P_.setFromTriplets(pt.begin(), pt.end());
    K_red_ = (P_.transpose() * K * P_).pruned();

    // --- contact rows ----------------------------------------------------------------
    ContactRows rows = carrying_rows(*this, model_, P_);
    const int row = rows.rows;
    pairs_ = std::move(rows.pairs);
    pair_candidate_ = std::move(rows.candidate);
    probe_ = rows.probe;
    gaps_ = Eigen::Map<Eigen::VectorXd>(rows.gaps.data(), static_cast<Eigen::Index>(rows.gaps.size()));
    layer_ = Eigen::Map<Eigen::VectorXd>(rows.layer.data(), static_cast<Eigen::Index>(rows.layer.size()));
    Eigen::SparseMatrix<double> G(row, nm);
    G.setFromTriplets(rows.g.begin(), rows.g.end());

    // --- condensation with R held ------------------------------------------------
    const int nr = nm - 1;
    const Eigen::SparseMatrix<double> Krr = K_red_.topLeftCorner(nr, nr);
    Krw_col_ = K_red_.block(0, nr, nr, 1);
    const double Kww = K_red_.coeff(nr, nr);
    Krr_llt_.compute(Krr);
    const bool fixed_end = std::any_of(spec.leaves.begin(), spec.leaves.end(), [](const LeafSpec& l) {
        return l.left_support == SupportKind::fixed || l.right_support == SupportKind::fixed;
    });
    if (seat_slides && axial == SeatAxial::free && !ends_locate && !fixed_end)  // the factor may not see it
        throw InputError("rigid_body.axial", "value 'free': the stack is not located axially, as no end holds it "
                                             "(give an end a hinged eye, an inclined shackle, a bushing with "
                                             "bushing_x_n_per_m > 0 or a fixed support, or rigid_body.axial = 'held')");
    if (Krr_llt_.info() != Eigen::Success)
        throw InputError("leaves", "the stack is not restrained with the rigid body held: some leaf (or the seat) can move "
                                   "as a rigid body; give it supports or tie it to the rigid body (rigid_body.tied_leaves)");
    Gr_ = G.leftCols(nr);
    G_ = G;
    const Eigen::VectorXd gw = Eigen::VectorXd(G.col(nr));
    C_held_ = std::make_shared<LazyCompliance>();
    const Eigen::VectorXd y = Krr_llt_.solve(Eigen::VectorXd(Krw_col_));
    c_ = gw - Gr_ * y;
    k_ = Kww - Eigen::VectorXd(Krw_col_).dot(y);
    if (!(k_ > 0.0))
        throw InputError("rigid_body.x_m", "the stack has no stiffness at the attachment (k = " + format_value(k_) +
                                               " N/m): the rigid body must be carried by supported leaves");
    check_rigid_rows_independent(Gr_, layer_);
    mass_ = spec.rigid_body.mass_kg / model_.whole_spring_factor();
}

const Eigen::MatrixXd& System::compliance_held() const {
    std::call_once(C_held_->once, [this] {
        // no rows (no contact): C' is 0 x 0 (Eigen's solve would permute the rows of an empty matrix)
        const Eigen::MatrixXd X = Gr_.rows() > 0 ? Eigen::MatrixXd(Krr_llt_.solve(Eigen::MatrixXd(Gr_.transpose())))
                                                 : Eigen::MatrixXd(Gr_.cols(), 0);
        Eigen::MatrixXd C = Gr_ * X;
        C_held_->C = 0.5 * (C + C.transpose());
        C_held_->C.diagonal() += layer_;  // the elastic interface layer (system.hpp)
        C_held_->built = true;
    });
    return C_held_->C;
}

bool SystemAccess::compliance_held_built(const System& system) noexcept {
    return system.C_held_->built;
}

double System::tied_stiffness_n_per_m() const {
    if (c_.size() == 0) return free_stiffness_n_per_m();
    const Eigen::VectorXd x = compliance_held().llt().solve(c_);
    return model_.whole_spring_factor() * (k_ + c_.dot(x));
}

Eigen::VectorXd System::reduced_displacements(const Eigen::VectorXd& p, double w) const {
    const int nr = static_cast<int>(K_red_.rows()) - 1;
    Eigen::VectorXd rhs = Gr_.transpose() * p - Eigen::VectorXd(Krw_col_) * w;
    Eigen::VectorXd z(nr + 1);
    z.head(nr) = Krr_llt_.solve(rhs);
    z[nr] = w;
    return z;
}

Eigen::VectorXd System::reduced_displacements(const Eigen::VectorXd& p, double w, const Eigen::Vector2d& seat_loads) const {
    Eigen::VectorXd z = reduced_displacements(p, w);
    const int nr = static_cast<int>(K_red_.rows()) - 1;
    Eigen::VectorXd e = Eigen::VectorXd::Zero(nr);
    if (seat_rotation_dof_ >= 0) e[seat_rotation_dof_] = seat_loads[0];
    if (seat_axial_dof_ >= 0) e[seat_axial_dof_] = seat_loads[1];
    if (e.squaredNorm() > 0.0) z.head(nr) += Krr_llt_.solve(e);
    return z;
}

System::SeatCondensation System::seat_condensation() const {
    const int nr = static_cast<int>(K_red_.rows()) - 1;
    SeatCondensation out;
    out.B = Eigen::MatrixXd::Zero(Gr_.rows(), 2);
    const Eigen::VectorXd krw = Eigen::VectorXd(Krw_col_);
    const int dofs[2] = {seat_rotation_dof_, seat_axial_dof_};
    Eigen::MatrixXd X = Eigen::MatrixXd::Zero(nr, 2);  // K_rr^-1 E
    for (int j = 0; j < 2; ++j) {
        if (dofs[j] < 0) continue;
        X.col(j) = Krr_llt_.solve(Eigen::VectorXd::Unit(nr, dofs[j]));
        if (Gr_.rows() > 0) out.B.col(j) = Gr_ * X.col(j);
        out.g[j] = krw.dot(X.col(j));
    }
    for (int i = 0; i < 2; ++i)
        for (int j = 0; j < 2; ++j)
            if (dofs[i] >= 0) out.F(i, j) = X(dofs[i], j);
    return out;
}

Eigen::VectorXd System::leaf_displacements(const Eigen::VectorXd& p, double w) const {
    return P_ * reduced_displacements(p, w);
}

Eigen::VectorXd System::leaf_displacements(const Eigen::VectorXd& z) const {
    if (z.size() != P_.cols())
        throw InputError("z", "has " + std::to_string(z.size()) + " entries: System::leaf_displacements needs one per reduced DOF, " +
                                  std::to_string(P_.cols()) + " (num_reduced_dofs())");
    return P_ * z;
}

std::vector<LeafNodes> System::leaf_nodes(const Eigen::VectorXd& z) const {
    if (z.size() != P_.cols())
        throw InputError("z", "has " + std::to_string(z.size()) + " entries: System::leaf_nodes needs one per reduced DOF, " +
                                  std::to_string(P_.cols()) + " (num_reduced_dofs())");
    const Eigen::VectorXd u = P_ * z;
    const auto& xs = model_.nodes_x();
    const bool half = model_.spec().symmetry == Symmetry::half;
    const double x_r = xs[model_.attachment_node()];
    const int nleaf = static_cast<int>(model_.spec().leaves.size());
    std::vector<LeafNodes> out(nleaf);
    for (int l = 0; l < nleaf; ++l) {
        LeafNodes& leaf = out[l];
        leaf.leaf = l;
        const int first = model_.first_node(l), last = model_.last_node(l);
        const std::size_t count = static_cast<std::size_t>(last - first + 1);
        const std::size_t total = half ? 2 * count - 1 : count;  // the half model: the leaf ends at x_R
        leaf.x_m.reserve(total);
        leaf.w_m.reserve(total);
        leaf.theta_rad.reserve(total);
        for (int j = first; j <= last; ++j) {
            const int b = 3 * node_dof(l, j);
            leaf.x_m.push_back(xs[j]);
            leaf.w_m.push_back(u[b + 1]);
            leaf.theta_rad.push_back(u[b + 2]);
        }
        if (half)  // the mirror image of the half, from the node next to x_R outwards
            for (std::size_t i = count - 1; i-- > 0;) {
                leaf.x_m.push_back(2.0 * x_r - leaf.x_m[i]);
                leaf.w_m.push_back(leaf.w_m[i]);
                leaf.theta_rad.push_back(-leaf.theta_rad[i]);
            }
    }
    return out;
}

}  // namespace stackbeam
