// The loop figures of a run's last cycle (run/loop_figures.hpp): the one place they are computed.
#include "stackbeam/run/loop_figures.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Dense>
#include <Eigen/SparseLU>

#include "stackbeam/errors.hpp"

namespace stackbeam {

LoopFigures loop_figures(const std::vector<StepRecord>& records, double period_s) {
    LoopFigures loop;
    if (!(period_s > 0.0)) {
        loop.note = "no periodic loading: no steady cycle";
        return loop;
    }
    try {
        const auto cycle = last_cycle(records, period_s);
        loop.metrics = hysteresis_metrics(records, cycle.first, cycle.second);
    } catch (const InputError& e) {
        loop.note = e.what();
        return loop;
    }
    try {
        const FancherLoopFit fit = fit_fancher_loop(records, loop.metrics->t_start_s, loop.metrics->t_end_s);
        loop.fancher = fit.fit;
        for (std::size_t i = 0; i < fit.w_m.size(); ++i) loop.fancher_loop.emplace_back(fit.w_m[i], fit.model_force_n[i]);
    } catch (const InputError& e) {
        loop.fancher_note = e.what();
    }
    return loop;
}

bool loads_the_seat(const Loading& loading) { return loading.windup_rig() || loading.has_seat_load(); }

namespace {

/// The loop figures of `columns` over the last period `period_s` of `records`, or the note why none.
std::optional<HysteresisMetrics> last_loop(const std::vector<StepRecord>& records, double period_s,
                                           const LoopColumns& columns, const std::string& what, std::string& note) {
    if (!(period_s > 0.0)) {
        note = "no periodic " + what + ": no steady cycle";
        return std::nullopt;
    }
    try {
        const auto cycle = last_cycle(records, period_s);
        return hysteresis_metrics(records, cycle.first, cycle.second, columns);
    } catch (const InputError& e) {
        note = e.what();
        return std::nullopt;
    }
}

}  // namespace

double windup_period_s(const Loading& loading) {
    if (loading.seat_rotation_rad) return loading.seat_rotation_rad->period_s();
    if (loading.seat_moment_n_m && loading.seat_moment_n_m->period_s() > 0.0) return loading.seat_moment_n_m->period_s();
    if (loading.longitudinal_force_n && loading.longitudinal_force_height_m != 0.0)
        return loading.longitudinal_force_n->period_s();  // its moment -H h
    return 0.0;
}

WindupFigures windup_figures(const std::vector<StepRecord>& records, const Loading& loading, const LoopFigures& vertical) {
    WindupFigures f;
    const double period_s = windup_period_s(loading);
    LoopColumns windup;
    windup.displacement_name = "seat_rotation";
    windup.displacement = [](const StepRecord& r) { return r.seat_rotation_rad; };
    windup.force = [](const StepRecord& r) { return r.seat_moment_n_m; };
    f.windup = last_loop(records, period_s, windup, "windup rig or seat moment", f.windup_note);
    // the longitudinal loop: H(t) against u_R
    if (loading.longitudinal_force_n) {
        LoopColumns axial;
        axial.displacement_name = "seat_axial";
        axial.displacement = [](const StepRecord& r) { return r.seat_axial_m; };
        axial.force = [&loading](const StepRecord& r) { return loading.longitudinal_force_n_at(r.t_s); };
        f.longitudinal = last_loop(records, loading.longitudinal_force_n->period_s(), axial, "longitudinal force",
                                   f.longitudinal_note);
        if (f.longitudinal && f.longitudinal->secant_stiffness_n_per_m > 0.0)
            f.longitudinal_compliance_m_per_n = 1.0 / f.longitudinal->secant_stiffness_n_per_m;
    } else {
        f.longitudinal_note = "no longitudinal force";
    }
    // the vertical rate where the vertical loading has a period of its own (Loading::period_s falls back
    // to the windup rig's: then w only follows the windup, and its "loop" is no rate)
    if (vertical.metrics && vertical_period_s(loading) > 0.0) f.vertical_rate_n_per_m = vertical.metrics->secant_stiffness_n_per_m;
    return f;
}

double vertical_period_s(const Loading& loading) {
    return loading.kind == LoadingKind::applied_force        ? loading.force_n.period_s()
           : loading.kind == LoadingKind::initial_conditions ? 0.0
                                                             : loading.displacement_m.period_s();
}

SeatStiffness seat_tangent_stiffness(const System& system, const std::vector<PairRecord>& pairs, double t_s) {
    SeatStiffness st;
    st.t_s = t_s;
    const Eigen::SparseMatrix<double>& K = system.stiffness_reduced();
    const Eigen::SparseMatrix<double>& G = system.contact_rows();  // s = G z + c_L p - d
    const Eigen::VectorXd& layer = system.layer_compliance_m_per_n();
    const int n = system.num_reduced_dofs();
    // the seat's motions, in the matrix's order (w, theta_R, u_R); -1 where the seat has none
    const std::array<int, 3> seat = {system.seat_w_dof(), system.seat_rotation_dof(), system.seat_axial_dof()};
    // the held rows: a sticking pair's both, a slipping pair's normal one (a frictionless pair, which
    // the state counts as sticking with p_t = 0, cannot hold tangentially: counted as slipping)
    std::vector<int> rows;
    for (const PairRecord& p : pairs) {
        const ContactPair& cp = system.pairs()[static_cast<std::size_t>(p.pair)];
        if (p.state == PairState::open) {
            ++st.open;
            continue;
        }
        if (cp.row_n >= 0) rows.push_back(cp.row_n);
        const bool holds = cp.kind == PairKind::bonded || cp.friction_coefficient > 0.0;
        if (p.state == PairState::stick && holds) {
            ++st.stick;
            if (cp.row_t >= 0) rows.push_back(cp.row_t);
        } else {
            ++st.slip;
        }
    }
    // the unknowns: every DOF but the seat's (prescribed), then one multiplier dp per held row
    std::vector<int> free_index(static_cast<std::size_t>(n), -1);
    int nf = 0;
    for (int d = 0; d < n; ++d)
        if (std::find(seat.begin(), seat.end(), d) == seat.end()) free_index[static_cast<std::size_t>(d)] = nf++;
    const int m = static_cast<int>(rows.size());
    // the saddle-point system, symmetric: [K_FF, -G_aF^T; -G_aF, -C_a] [dz_F; dp] = rhs
    // (K dz = G^T dp + f: the held rows keep s, G_a dz + C_a dp = 0)
    const Eigen::SparseMatrix<double> Ga = [&] {
        Eigen::SparseMatrix<double> rowsel(m, G.rows());
        std::vector<Eigen::Triplet<double>> t;
        for (int j = 0; j < m; ++j) t.emplace_back(j, rows[static_cast<std::size_t>(j)], 1.0);
        rowsel.setFromTriplets(t.begin(), t.end());
        return Eigen::SparseMatrix<double>(rowsel * G);
    }();
    std::vector<Eigen::Triplet<double>> a;
    for (int col = 0; col < K.outerSize(); ++col)
        for (Eigen::SparseMatrix<double>::InnerIterator it(K, col); it; ++it) {
            const int r = free_index[static_cast<std::size_t>(it.row())], c = free_index[static_cast<std::size_t>(col)];
            if (r >= 0 && c >= 0) a.emplace_back(r, c, it.value());
        }
    const Eigen::SparseMatrix<double> GaT = Ga.transpose();
    for (int col = 0; col < GaT.outerSize(); ++col)  // column j: held row j
        for (Eigen::SparseMatrix<double>::InnerIterator it(GaT, col); it; ++it) {
            const int f = free_index[static_cast<std::size_t>(it.row())];
            if (f < 0) continue;
            a.emplace_back(f, nf + col, -it.value());
            a.emplace_back(nf + col, f, -it.value());
        }
    for (int j = 0; j < m; ++j) {
        const double c = layer.size() > 0 ? layer[rows[static_cast<std::size_t>(j)]] : 0.0;
        a.emplace_back(nf + j, nf + j, -c);
    }
    Eigen::SparseMatrix<double> A(nf + m, nf + m);
    A.setFromTriplets(a.begin(), a.end());
    Eigen::SparseLU<Eigen::SparseMatrix<double>> lu;
    lu.compute(A);
    if (lu.info() != Eigen::Success)
        throw SolverError("the seat's tangent stiffness: the stack with " + std::to_string(m) +
                              " held contact rows is singular with the seat held (" + lu.lastErrorMessage() + ")",
                          0, t_s, 0.0);
    const double nan = std::numeric_limits<double>::quiet_NaN(), factor = system.model().whole_spring_factor();
    for (auto& row : st.matrix) row.fill(nan);
    for (int c = 0; c < 3; ++c) {
        if (seat[static_cast<std::size_t>(c)] < 0) continue;
        const int s = seat[static_cast<std::size_t>(c)];
        // unit motion of seat DOF s, the others of the seat held: rhs = [-K_Fs; G_a,s]
        Eigen::VectorXd rhs = Eigen::VectorXd::Zero(nf + m);
        for (Eigen::SparseMatrix<double>::InnerIterator it(K, s); it; ++it)
            if (free_index[static_cast<std::size_t>(it.row())] >= 0) rhs[free_index[static_cast<std::size_t>(it.row())]] = -it.value();
        const Eigen::VectorXd gs = Ga.col(s);
        rhs.tail(m) = gs;
        const Eigen::VectorXd x = lu.solve(rhs);
        Eigen::VectorXd dz = Eigen::VectorXd::Zero(n);
        for (int d = 0; d < n; ++d)
            if (free_index[static_cast<std::size_t>(d)] >= 0) dz[d] = x[free_index[static_cast<std::size_t>(d)]];
        dz[s] = 1.0;
        // the force on the spring at the seat: (K dz - G_a^T dp) on the seat's rows
        const Eigen::VectorXd f = K * dz - GaT * x.tail(m);
        for (int i = 0; i < 3; ++i)
            if (seat[static_cast<std::size_t>(i)] >= 0) st.matrix[i][c] = factor * f[seat[static_cast<std::size_t>(i)]];
    }
    // condensed to w: theta_R and u_R free (the rows and columns the seat has)
    std::vector<int> other;
    for (int i = 1; i < 3; ++i)
        if (seat[static_cast<std::size_t>(i)] >= 0) other.push_back(i);
    double kv = st.matrix[0][0];
    if (!other.empty()) {
        Eigen::MatrixXd koo(other.size(), other.size());
        Eigen::VectorXd kow(other.size());
        for (std::size_t i = 0; i < other.size(); ++i) {
            kow[static_cast<Eigen::Index>(i)] = st.matrix[other[i]][0];
            for (std::size_t j = 0; j < other.size(); ++j)
                koo(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) = st.matrix[other[i]][other[j]];
        }
        kv -= kow.dot(koo.ldlt().solve(kow));
    }
    st.vertical_rate_n_per_m = kv;
    return st;
}

}  // namespace stackbeam
