// The factored sparse normal equations (approx_normal.hpp): their solution and the
// trace generalized cross-validation needs.

#include "constructions/approximate/approx_normal.hpp"

#include <random>

namespace interpatch::detail::approx {

void SparseEquations::factor(double lambda) {
  Eigen::SparseMatrix<double> m = data;
  if (lambda > 0) m += (lambda * scale) * fairness;
  if (!analyzed) {
    ldlt.analyzePattern(m);
    analyzed = true;
  }
  ldlt.factorize(m);
  bool ok = ldlt.info() == Eigen::Success;
  // A positive definite matrix has positive pivots; one at or below 1e-14 of the
  // largest (rounding) means no unique solution.
  const double largest = ok ? ldlt.vectorD().cwiseAbs().maxCoeff() : 0.0;
  for (Eigen::Index i = 0; i < ldlt.vectorD().size() && ok; ++i) ok = ldlt.vectorD()[i] > 1e-14 * largest;
  if (!ok)
    fail(errc::singular, "the least-squares system of ", m.rows(),
         " control points has no unique solution: some control points have no data under them and no fairness "
         "term to fix them");
}

// The ratio of the data term's diagonal to the fairness term's: what makes λ s K
// a given fraction of the data term.
double SparseEquations::diagonal_ratio() const {
  const double k = fairness.diagonal().sum() * scale;
  return k > 0 ? data.diagonal().sum() / k : 0.0;
}

std::vector<double> SparseEquations::solve(const std::vector<double>& rhs) const {
  const auto n = data.rows();
  Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>> b(rhs.data(), n, 3);
  Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> x = ldlt.solve(Eigen::MatrixXd(b));
  return {x.data(), x.data() + x.size()};
}

// tr(M⁻¹ λ s K) = C − tr(M⁻¹ G), M = G + λ s K: the control points minus the
// degrees of freedom of the fit, by Hutchinson's estimator, the mean of
// zᵀ M⁻¹ λ s K z over random ±1 vectors z (a fixed seed: the same value on every
// run). Estimating this part rather than tr(M⁻¹ G) keeps the estimate's error
// (of the order of its Frobenius norm) small where it is small: near
// interpolation, where n − tr H is the small difference that decides the score.
double SparseEquations::fairness_trace(double lambda, int probes) const {
  const auto n = data.rows();
  std::mt19937_64 rng(20261124);
  double sum = 0;
  for (int k = 0; k < probes; ++k) {
    Eigen::VectorXd z(n);
    for (Eigen::Index i = 0; i < n; ++i) z[i] = (rng() & 1) != 0 ? 1.0 : -1.0;
    const Eigen::VectorXd kz = fairness.selfadjointView<Eigen::Lower>() * z;
    sum += z.dot(ldlt.solve(kz));
  }
  return lambda * scale * sum / probes;
}

}  // namespace interpatch::detail::approx
