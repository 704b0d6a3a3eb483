// Not built by CMake (a study record of docs/decisions/047-held-set-factor-cost.md).
// The sets: apply dump_held_systems.diff to fixed_saddle.cpp at commit e2a39d9 (and link
// stackbeam_contact with amd), run the benchmark with FC_DUMP=DIR (every 5th held system,
// As_ in binary CSC), then
//   g++ -O2 -I/usr/include/suitesparse FILE.cpp -o h -lklu -lamd && ./h DIR 5
// Study (decision 047): orderings cheaper than AMD on the whole held system.
//  amd       : AMD on A + A^T (what klu_analyze does)
//  quotient  : AMD on the quotient graph of K's supervariables (DOFs with the same column pattern in K: a node's DOFs)
//              plus the held rows, expanded (a node's DOFs together)
//  k-rule    : K's own AMD order (once per run: not timed) with each held row placed after its last DOF in that order
#include <klu.h>
#include <amd.h>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <string>
#include <vector>
#include <algorithm>
#include <unordered_map>
#include <cmath>
#include "held_sets.hpp"
int main(int argc, char** argv) {
    const std::vector<M> ms = read_sets(argv[1]);
    const int reps = argc > 2 ? atoi(argv[2]) : 3;
    const int nv = 3, nm = ms.size();
    const char* vname[] = {"amd", "quotient", "k-rule"};
    std::vector<double> to(nv * nm, 1e9), tf(nv * nm, 1e9), lu(nv, 0), berr(nv, 0);
    for (int r = 0; r < reps; ++r)
        for (int mi = 0; mi < nm; ++mi) {
            const M& m = ms[mi];
            int nd = 0; // DOFs: columns with a diagonal entry (first nd)
            for (int j = 0; j < m.n; ++j) { bool dg = false; for (int q = m.p[j]; q < m.p[j + 1]; ++q) dg |= m.i[q] == j; if (!dg) break; ++nd; }
            // supervariables of K (once per run in practice): DOFs with identical K pattern
            std::vector<int> node(nd); int nn = 0;
            {
                std::unordered_map<std::string, int> h;
                for (int j = 0; j < nd; ++j) { std::string key; for (int q = m.p[j]; q < m.p[j + 1]; ++q) if (m.i[q] < nd) key.append((char*)&m.i[q], 4);
                    auto it = h.find(key); if (it == h.end()) { h[key] = nn; node[j] = nn++; } else node[j] = it->second; }
            }
            // K's AMD (once per run in practice)
            std::vector<int> kord(nd);
            {
                std::vector<int> kp(nd + 1, 0), ki;
                for (int j = 0; j < nd; ++j) { for (int q = m.p[j]; q < m.p[j + 1]; ++q) if (m.i[q] < nd) ki.push_back(m.i[q]); kp[j + 1] = ki.size(); }
                amd_order(nd, kp.data(), ki.data(), kord.data(), nullptr, nullptr);
            }
            std::vector<int> kpos(nd); for (int k = 0; k < nd; ++k) kpos[kord[k]] = k;
            for (int vi = 0; vi < nv; ++vi) {
                std::vector<int> Q(m.n);
                double t0 = cpu();
                if (vi == 0) {
                    amd_order(m.n, m.p.data(), m.i.data(), Q.data(), nullptr, nullptr);
                } else if (vi == 1) {
                    const int nq = nn + (m.n - nd);
                    auto qv = [&](int u) { return u < nd ? node[u] : nn + (u - nd); };
                    std::vector<int> cnt(nq + 1, 0), stamp(nq, -1);
                    std::vector<std::vector<int>> adj(nq);
                    for (int j = 0; j < m.n; ++j) { const int a = qv(j); for (int q = m.p[j]; q < m.p[j + 1]; ++q) { const int b = qv(m.i[q]); if (a != b) { adj[a].push_back(b); adj[b].push_back(a); } } }
                    std::vector<int> qp(nq + 1, 0), qi;
                    for (int a = 0; a < nq; ++a) { for (int b : adj[a]) if (stamp[b] != a) { stamp[b] = a; qi.push_back(b); } std::sort(qi.begin() + qp[a], qi.end()); qp[a + 1] = qi.size(); }
                    std::vector<int> qo(nq); amd_order(nq, qp.data(), qi.data(), qo.data(), nullptr, nullptr);
                    std::vector<int> rank(nq); for (int k = 0; k < nq; ++k) rank[qo[k]] = k;
                    // expand: DOFs by their node's rank (stable), held rows by theirs
                    std::vector<std::pair<int, int>> key(m.n);
                    for (int u = 0; u < m.n; ++u) key[u] = {rank[qv(u)], u};
                    std::sort(key.begin(), key.end());
                    for (int k = 0; k < m.n; ++k) Q[k] = key[k].second;
                } else {
                    std::vector<std::pair<int, int>> key; key.reserve(m.n);
                    for (int u = 0; u < nd; ++u) key.push_back({2 * kpos[u], u});
                    for (int u = nd; u < m.n; ++u) { int last = -1; for (int q = m.p[u]; q < m.p[u + 1]; ++q) if (m.i[q] < nd) last = std::max(last, kpos[m.i[q]]); key.push_back({2 * last + 1, u}); }
                    std::sort(key.begin(), key.end());
                    for (int k = 0; k < m.n; ++k) Q[k] = key[k].second;
                }
                double t1 = cpu();
                klu_common c; klu_defaults(&c); c.btf = 0;
                klu_symbolic* S = klu_analyze_given(m.n, (int*)m.p.data(), (int*)m.i.data(), Q.data(), Q.data(), &c);
                double t2 = cpu();
                klu_numeric* N = klu_factor((int*)m.p.data(), (int*)m.i.data(), (double*)m.x.data(), S, &c);
                double t3 = cpu();
                if (!N) { printf("FAIL %s\n", vname[vi]); return 1; }
                const int at = vi * nm + mi;
                to[at] = std::min(to[at], t1 - t0); tf[at] = std::min(tf[at], t3 - t2);
                if (r == 0) {
                    lu[vi] += N->lnz + N->unz;
                    std::vector<double> b(m.n), xx; for (int k = 0; k < m.n; ++k) b[k] = std::sin(0.37 * k) + 0.2; xx = b;
                    klu_solve(S, N, m.n, 1, xx.data(), &c);
                    berr[vi] = std::max(berr[vi], backward_error(m, b, xx));
                    if (vi == 0 && mi == 0) printf("n %d dofs %d held %d K-supervariables %d\n", m.n, nd, m.n - nd, nn);
                }
                klu_free_numeric(&N, &c); klu_free_symbolic(&S, &c);
            }
        }
    double o0 = 0, f0 = 0; for (int mi = 0; mi < nm; ++mi) { o0 += to[mi]; f0 += tf[mi]; }
    for (int vi = 0; vi < nv; ++vi) { double O = 0, F = 0; for (int mi = 0; mi < nm; ++mi) { O += to[vi * nm + mi]; F += tf[vi * nm + mi]; }
        printf("%-9s ordering %.3f ms (x%.3f) klu_factor %.3f ms (x%.3f) | nnz(L+U) %.0f | max backward error %.1e\n", vname[vi], 1e3 * O / nm, O / o0, 1e3 * F / nm, F / f0, lu[vi] / nm, berr[vi]); }
}
