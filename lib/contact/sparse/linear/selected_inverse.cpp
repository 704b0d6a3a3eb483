// The diagonal of W = G K^-1 G^T from the selected inverse of K (see the header).
#include "contact/sparse/linear/selected_inverse.hpp"

#include <algorithm>
#include <vector>

#include "stackbeam/errors.hpp"

namespace stackbeam::detail::sparse {

/// diag(G K^-1 G^T) [m/N], the compliance of each contact row alone (it scales force
/// violations to metres). Each row g_i of G touches a few DOFs (two leaves at one
/// node), so W_ii = sum_{a,b} g_ia g_ib (K^-1)_ab needs a few entries of K^-1 only:
///  - The leaves are coupled in K only through the rigid body's DOFs ("hubs": w, and
///    the seat rotation on the full model), which tie the attachment node of every tied
///    leaf. With K = [A B; B^T C] (C: the hubs, at most kMaxHubs DOFs of degree above
///    kHubDegree), K^-1 = [A^-1 + X S^-1 X^T, -X S^-1; -S^-1 X^T, S^-1] with
///    X = A^-1 B and S = C - B^T X, so
///        W_ii = g_A^T A^-1 g_A + t^T S^-1 t,   t = X^T g_A - g_C.
///  - A^-1 is needed on pairs of DOFs within one cross-section of one leaf: taken from
///    the selected inverse of A (the entries of A^-1 on the pattern of its Cholesky
///    factor L, L L^T = P A P^T), by Takahashi's recurrence from the last column back,
///        Z_ij = (delta_ij / L_jj - sum_{k > j} Z_ik L_kj) / L_jj,  i in struct(L_:j) + {j},
///    which only reads entries of the pattern (a column's structure is a clique of the
///    filled graph); cost sum_j |L_:j|^2, about that of the factorisation. An entry
///    between different connected components of A (different leaves) is exactly 0.
///  - A row that needs an entry of A^-1 off the pattern within one component (not met
///    with the models here) is computed directly from K's factor as ||L_K^-1 P_K g_i||^2.
/// All of it is exact to round-off (test: sparse_compliance_diagonal_is_exact). Before,
/// the whole diagonal was m dense triangular solves: 0.35-0.65 s at 10 leaves x 400
/// elements, now a few milliseconds.
Eigen::VectorXd selected_compliance_diagonal(const SpMat& K, const SpMat& G, const KCholesky& k_llt) {
    constexpr int kHubDegree = 12;  // a beam DOF couples to at most 9 (its node and the two neighbours)
    constexpr int kMaxHubs = 8;
    const int n = static_cast<int>(K.rows()), m = static_cast<int>(G.rows());
    std::vector<int> hubs;
    for (int j = 0; j < n; ++j)
        if (K.outerIndexPtr()[j + 1] - K.outerIndexPtr()[j] > kHubDegree) hubs.push_back(j);
    if (static_cast<int>(hubs.size()) > kMaxHubs || static_cast<int>(hubs.size()) >= n) hubs.clear();
    const int h = static_cast<int>(hubs.size()), na = n - h;
    std::vector<int> index(static_cast<std::size_t>(n));  // DOF -> index in A (>= 0) or -1 - index in C
    {
        int ia = 0, ic = 0;
        for (int j = 0; j < n; ++j) {
            const bool hub = std::binary_search(hubs.begin(), hubs.end(), j);
            index[static_cast<std::size_t>(j)] = hub ? -1 - ic++ : ia++;
        }
    }
    std::vector<Eigen::Triplet<double>> ta, tb;
    Eigen::MatrixXd C = Eigen::MatrixXd::Zero(h, h);
    for (int j = 0; j < n; ++j)
        for (SpMat::InnerIterator it(K, j); it; ++it) {
            const int r = index[static_cast<std::size_t>(it.row())], c = index[static_cast<std::size_t>(j)];
            if (r >= 0 && c >= 0) ta.emplace_back(r, c, it.value());
            else if (r >= 0) tb.emplace_back(r, -1 - c, it.value());
            else if (c < 0) C(-1 - r, -1 - c) = it.value();
        }
    SpMat A(na, na), B(na, h);
    A.setFromTriplets(ta.begin(), ta.end());
    B.setFromTriplets(tb.begin(), tb.end());
    Eigen::SimplicialLLT<SpMat, Eigen::Lower, Eigen::AMDOrdering<int>> llt(A);
    if (llt.info() != Eigen::Success) throw InputError("problem.K", "is not positive definite");
    const Eigen::MatrixXd X = h > 0 ? Eigen::MatrixXd(llt.solve(Eigen::MatrixXd(B))) : Eigen::MatrixXd(na, 0);
    const Eigen::LLT<Eigen::MatrixXd> s_llt(C - B.transpose() * X);
    // selected inverse of A
    const SpMat& L = llt.matrixL().nestedExpression();  // column-major, diagonal first, rows ascending
    const int* Lp = L.outerIndexPtr();
    const int* Li = L.innerIndexPtr();
    const double* Lx = L.valuePtr();
    std::vector<double> Z(static_cast<std::size_t>(L.nonZeros()), 0.0);
    auto find = [&](int i, int k) -> long {  // position of (i, k), i != k, in the pattern, or -1
        const int c = std::min(i, k), r = std::max(i, k);
        const int* e = Li + Lp[c + 1];
        const int* f = std::lower_bound(Li + Lp[c] + 1, e, r);
        return (f != e && *f == r) ? static_cast<long>(f - Li) : -1L;
    };
    auto at = [&](long pos) -> double& { return Z[static_cast<std::size_t>(pos)]; };
    for (int j = na - 1; j >= 0; --j) {
        const int p0 = Lp[j], p1 = Lp[j + 1];
        const double ljj = Lx[p0];
        for (int pi = p0 + 1; pi < p1; ++pi) {
            const int i = Li[pi];
            double sum = 0.0;
            for (int pk = p0 + 1; pk < p1; ++pk) {
                const int k = Li[pk];
                sum += (k == i ? at(Lp[i]) : at(find(i, k))) * Lx[pk];
            }
            at(pi) = -sum / ljj;
        }
        double sum = 0.0;
        for (int pk = p0 + 1; pk < p1; ++pk) sum += at(pk) * Lx[pk];
        at(p0) = (1.0 / ljj - sum) / ljj;
    }
    // connected components of A's graph (union-find, path halving)
    std::vector<int> parent(static_cast<std::size_t>(na));
    for (int i = 0; i < na; ++i) parent[static_cast<std::size_t>(i)] = i;
    auto root = [&](int i) {
        while (parent[static_cast<std::size_t>(i)] != i) {
            parent[static_cast<std::size_t>(i)] = parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(i)])];
            i = parent[static_cast<std::size_t>(i)];
        }
        return i;
    };
    for (int j = 0; j < na; ++j)
        for (SpMat::InnerIterator it(A, j); it; ++it) {
            const int a = root(static_cast<int>(it.row())), b = root(j);
            if (a != b) parent[static_cast<std::size_t>(a)] = b;
        }
    const auto& perm = llt.permutationP().indices();
    const RowMat Grow = G;  // the rows of G
    Eigen::VectorXd diag(m), t(h);
    std::vector<int> direct;
    for (int r = 0; r < m; ++r) {
        double w = 0.0;
        bool ok = true;
        t.setZero();
        for (RowMat::InnerIterator a(Grow, r); a && ok; ++a) {
            const int ia = index[static_cast<std::size_t>(a.col())];
            if (ia < 0) {
                t[-1 - ia] -= a.value();
                continue;
            }
            if (h > 0) t += a.value() * X.row(ia).transpose();  // X is empty without held rows: no row view of it
            for (RowMat::InnerIterator b(Grow, r); b; ++b) {
                const int ib = index[static_cast<std::size_t>(b.col())];
                if (ib < 0) continue;
                const int pa = perm[ia], pb = perm[ib];
                double z = 0.0;
                if (pa == pb) {
                    z = at(Lp[pa]);
                } else if (root(ia) == root(ib)) {
                    const long f = find(pa, pb);
                    if (f < 0) {
                        ok = false;
                        break;
                    }
                    z = at(f);
                }
                w += a.value() * b.value() * z;
            }
        }
        if (!ok) {
            direct.push_back(r);
            continue;
        }
        diag[r] = h > 0 ? w + t.dot(s_llt.solve(t)) : w;
    }
    // rows off the pattern: column norms of L_K^-1 P_K g_i, in blocks of columns
    if (!direct.empty()) {
        const SpMat Gt = SpMat(G.transpose());
        const auto& kperm = k_llt.permutationP().indices();
        constexpr int kBlock = 64;
        for (std::size_t j0 = 0; j0 < direct.size(); j0 += kBlock) {
            const int nb = static_cast<int>(std::min<std::size_t>(kBlock, direct.size() - j0));
            Eigen::MatrixXd Y = Eigen::MatrixXd::Zero(n, nb);
            for (int c = 0; c < nb; ++c)
                for (SpMat::InnerIterator it(Gt, direct[j0 + static_cast<std::size_t>(c)]); it; ++it)
                    Y(kperm[it.row()], c) = it.value();
            k_llt.matrixL().solveInPlace(Y);
            for (int c = 0; c < nb; ++c) diag[direct[j0 + static_cast<std::size_t>(c)]] = Y.col(c).squaredNorm();
        }
    }
    return diag;
}

}  // namespace stackbeam::detail::sparse
