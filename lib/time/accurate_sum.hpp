#pragma once
// Internal: sums, sparse products and dot products as if computed in twice the working precision
// (Ogita, Rump & Oishi, "Accurate sum and dot product", SIAM J. Sci. Comput. 26 (2005): Sum2 and
// Dot2, with Dekker's product, no FMA needed), then rounded once.
//
// Why: a fine mesh's quadratic forms cancel. On graduated_elastic.toml (1.6 mm elements,
// 12 EI / l^3 ~ 1e11 N/m), z^T K z = 72 J is a sum of terms of magnitude 2e11 J: evaluated in
// double it carries a round-off of ~5e-7 J, and the step's solve K_eff z = b a residual of the same
// origin, so newmark's energy balance (exact in exact arithmetic) showed 1e-8 of the run's energy
// (docs/decisions/065-soak-round-off-and-tolerances.md). With these the error of a result is
// ~eps |result| + eps^2 sum |terms|.
#include <Eigen/Dense>
#include <Eigen/SparseCore>

namespace stackbeam::detail {

/// a + b = s + e exactly (Knuth's TwoSum).
inline void two_sum(double a, double b, double& s, double& e) {
    s = a + b;
    const double z = s - a;
    e = (a - (s - z)) + (b - z);
}

/// a b = p + e exactly (Dekker's TwoProduct by splitting; |a b| below ~1e300).
inline void two_product(double a, double b, double& p, double& e) {
    constexpr double kSplit = 134217729.0;  // 2^27 + 1
    p = a * b;
    const double ca = kSplit * a, cb = kSplit * b;
    const double ah = ca - (ca - a), al = a - ah;
    const double bh = cb - (cb - b), bl = b - bh;
    e = al * bl - (((p - ah * bh) - al * bh) - ah * bl);
}

/// A vector accumulated in twice the working precision: value() = s + c, rounded once.
class AccurateVector {
public:
    explicit AccurateVector(Eigen::Index n) : s_(Eigen::VectorXd::Zero(n)), c_(Eigen::VectorXd::Zero(n)) {}
    /// += x
    void add(const Eigen::VectorXd& x) {
        for (Eigen::Index i = 0; i < s_.size(); ++i) {
            double e;
            two_sum(s_[i], x[i], s_[i], e);
            c_[i] += e;
        }
    }
    /// += scale A x (scale a power of two keeps it exact: 1, -1, 2)
    void add_product(const Eigen::SparseMatrix<double>& A, const Eigen::VectorXd& x, double scale = 1.0) {
        for (Eigen::Index j = 0; j < A.outerSize(); ++j) {
            const double xj = scale * x[j];
            for (Eigen::SparseMatrix<double>::InnerIterator it(A, j); it; ++it) {
                double p, ep, e;
                two_product(it.value(), xj, p, ep);
                const Eigen::Index i = it.row();
                two_sum(s_[i], p, s_[i], e);
                c_[i] += ep + e;
            }
        }
    }
    Eigen::VectorXd value() const { return s_ + c_; }

private:
    Eigen::VectorXd s_, c_;
};

/// A x (column-major A), each entry as if in twice the working precision.
inline Eigen::VectorXd accurate_product(const Eigen::SparseMatrix<double>& A, const Eigen::VectorXd& x) {
    AccurateVector y(A.rows());
    y.add_product(A, x);
    return y.value();
}

/// a^T b as if in twice the working precision (Dot2).
inline double accurate_dot(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
    double s = 0.0, c = 0.0;
    for (Eigen::Index i = 0; i < a.size(); ++i) {
        double p, ep, e;
        two_product(a[i], b[i], p, ep);
        two_sum(s, p, s, e);
        c += ep + e;
    }
    return s + c;
}

/// x^T A x for a symmetric A: x^T (A x) with A x accurate, then Dot2 (x^T A x cancels where A's
/// entries and x are large and the form is small: a fine mesh's strain or kinetic energy).
inline double accurate_quadratic_form(const Eigen::SparseMatrix<double>& A, const Eigen::VectorXd& x) {
    return accurate_dot(x, accurate_product(A, x));
}

}  // namespace stackbeam::detail
