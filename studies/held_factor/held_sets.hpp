// The held systems dumped by dump_held_systems.diff (binary CSC: n, nnz, Ap, Ai, Ax), for the
// study programs of docs/decisions/047 (not built by CMake).
#pragma once
#include <dirent.h>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <string>
#include <vector>
struct M { int n, nz; std::vector<int> p, i; std::vector<double> x; };
static double cpu() { timespec t; clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t); return t.tv_sec + 1e-9 * t.tv_nsec; }
/// Every DIR/*.bin, in name order.
static std::vector<M> read_sets(const char* dir) {
    std::vector<M> ms;
    std::vector<std::string> names;
    DIR* d = opendir(dir);
    while (dirent* e = d ? readdir(d) : nullptr) if (strstr(e->d_name, ".bin")) names.push_back(std::string(dir) + "/" + e->d_name);
    if (d) closedir(d);
    std::sort(names.begin(), names.end());
    for (auto& nm : names) {
        FILE* f = fopen(nm.c_str(), "rb");
        M m;
        if (!f || fread(&m.n, 4, 1, f) != 1 || fread(&m.nz, 4, 1, f) != 1) continue;
        m.p.resize(m.n + 1); m.i.resize(m.nz); m.x.resize(m.nz);
        const bool ok = fread(m.p.data(), 4, m.n + 1, f) == size_t(m.n + 1) && fread(m.i.data(), 4, m.nz, f) == size_t(m.nz) &&
                        fread(m.x.data(), 8, m.nz, f) == size_t(m.nz);
        fclose(f);
        if (ok) ms.push_back(m);
    }
    return ms;
}
/// The normwise backward error ||b - A x|| / (||A|| ||x|| + ||b||) (infinity norms).
static double backward_error(const M& m, const std::vector<double>& b, const std::vector<double>& x) {
    std::vector<double> res = b, rows(m.n, 0.0);
    for (int j = 0; j < m.n; ++j) for (int q = m.p[j]; q < m.p[j + 1]; ++q) { res[m.i[q]] -= m.x[q] * x[j]; rows[m.i[q]] += std::fabs(m.x[q]); }
    double rn = 0, an = 0, xn = 0, bn = 0;
    for (int k = 0; k < m.n; ++k) { rn = std::max(rn, std::fabs(res[k])); an = std::max(an, rows[k]); xn = std::max(xn, std::fabs(x[k])); bn = std::max(bn, std::fabs(b[k])); }
    return rn / (an * xn + bn);
}
