// Not built by CMake (a study record of docs/decisions/047-held-set-factor-cost.md).
// KLU's controls (tol, scale, ordering, AMD's aggressive absorption) on held systems dumped from a run:
// analyse + factorise each, the variants interleaved per set, the minimum of R rounds per set.
// The sets: apply dump_held_systems.diff to fixed_saddle.cpp at commit e2a39d9 (and link
// stackbeam_contact with amd), run the benchmark with FC_DUMP=DIR (every 5th held system,
// As_ in binary CSC), then
//   g++ -O2 -I/usr/include/suitesparse FILE.cpp -o h -lklu -lamd && ./h DIR 5
// Study harness (decision 047): analyse + factorise the held systems dumped from a run, per variant.
#include <klu.h>
#include <amd.h>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <string>
#include <vector>
#include <algorithm>
#include <cmath>
#include "held_sets.hpp"
static double g_aggr = 1, g_dense = 10;
static int uorder(int n, int* Ap, int* Ai, int* P, klu_common*) {
    double c[AMD_CONTROL], inf[AMD_INFO]; amd_defaults(c); c[AMD_AGGRESSIVE] = g_aggr; c[AMD_DENSE] = g_dense;
    if (amd_order(n, Ap, Ai, P, c, inf) < AMD_OK) return 0;
    return (int)inf[AMD_LNZ] + n;
}
int main(int argc, char** argv) {
    const std::vector<M> ms = read_sets(argv[1]);
    const int reps = argc > 2 ? atoi(argv[2]) : 3;
    struct V { const char* name; int ordering; double tol; int scale; double aggr, dense; };
    std::vector<V> vs = {{"default", 0, 0.001, 2, 1, 10}, {"user-amd", 3, 0.001, 2, 1, 10}, {"amd-aggr0", 3, 0.001, 2, 0, 10},
                         {"colamd", 1, 0.001, 2, 1, 10}, {"tol1e-6", 0, 1e-6, 2, 1, 10}, {"tol0.1", 0, 0.1, 2, 1, 10},
                         {"tol1e-12", 0, 1e-12, 2, 1, 10},
                         {"scale0", 0, 0.001, 0, 1, 10}, {"scale1", 0, 0.001, 1, 1, 10}, {"scale-1", 0, 0.001, -1, 1, 10}};
    const int nv = vs.size(), nm = ms.size();
    std::vector<double> ta(nv * nm, 1e9), tf(nv * nm, 1e9), ts(nv * nm, 1e9), lu(nv, 0), berr(nv, 0), offd(nv, 0);
    for (int r = 0; r < reps; ++r)
        for (int mi = 0; mi < nm; ++mi)
            for (int vi = 0; vi < nv; ++vi) {
                const auto& v = vs[vi]; const auto& m = ms[mi];
                klu_common c; klu_defaults(&c); c.btf = 0; c.ordering = v.ordering; c.tol = v.tol; c.scale = v.scale; c.user_order = uorder;
                g_aggr = v.aggr; g_dense = v.dense;
                double t0 = cpu();
                klu_symbolic* S = klu_analyze(m.n, (int*)m.p.data(), (int*)m.i.data(), &c);
                double t1 = cpu();
                klu_numeric* N = klu_factor((int*)m.p.data(), (int*)m.i.data(), (double*)m.x.data(), S, &c);
                double t2 = cpu();
                if (!N) { printf("FAIL %s\n", v.name); return 1; }
                std::vector<double> b(m.n), xx;
                for (int k = 0; k < m.n; ++k) b[k] = std::sin(0.37 * k) + 0.2;
                xx = b;
                double t3 = cpu();
                klu_solve(S, N, m.n, 1, xx.data(), &c);
                double t4 = cpu();
                const int at = vi * nm + mi;
                ta[at] = std::min(ta[at], t1 - t0); tf[at] = std::min(tf[at], t2 - t1); ts[at] = std::min(ts[at], t4 - t3);
                if (r == 0) {
                    lu[vi] += N->lnz + N->unz;
                    berr[vi] = std::max(berr[vi], backward_error(m, b, xx));
                    int off = 0; for (int k = 0; k < m.n; ++k) off += N->Pnum[k] != S->Q[k]; offd[vi] += off;
                }
                klu_free_numeric(&N, &c); klu_free_symbolic(&S, &c);
            }
    double a0 = 0, f0 = 0;
    for (int mi = 0; mi < nm; ++mi) { a0 += ta[mi]; f0 += tf[mi]; }
    for (int vi = 0; vi < nv; ++vi) {
        double A = 0, F = 0, S = 0;
        for (int mi = 0; mi < nm; ++mi) { A += ta[vi * nm + mi]; F += tf[vi * nm + mi]; S += ts[vi * nm + mi]; }
        printf("%-10s analyze %.3f ms (x%.3f) factor %.3f ms (x%.3f) solve %.3f ms | nnz(L+U) %.0f | off-diagonal pivots %.1f | max backward error %.1e\n", vs[vi].name, 1e3 * A / nm, A / a0, 1e3 * F / nm, F / f0, 1e3 * S / nm, lu[vi] / nm, offd[vi] / nm, berr[vi]);
    }
}
