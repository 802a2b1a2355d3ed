#include "metrics/simplex_fit.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <vector>

namespace spx {
namespace {

// The minimiser of 1/2 w'Gw - b'w over the free examples with sum 1 (the others 0): the KKT
// system [G_FF 1; 1' 0] [z; m] = [b_F; 1].
Eigen::VectorXd equality_step(const Eigen::MatrixXd& G, const Eigen::VectorXd& b, const std::vector<int>& free_set) {
  const int f = int(free_set.size());
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(f + 1, f + 1);
  Eigen::VectorXd rhs(f + 1);
  for (int i = 0; i < f; ++i) {
    for (int j = 0; j < f; ++j) K(i, j) = G(free_set[i], free_set[j]);
    K(i, f) = K(f, i) = 1;
    rhs[i] = b[free_set[i]];
  }
  rhs[f] = 1;
  const Eigen::VectorXd x = K.fullPivLu().solve(rhs);  // indefinite: LU, not Cholesky
  return x.head(f);
}

}  // namespace

Eigen::VectorXd simplex_least_squares(const Eigen::MatrixXd& G_in, const Eigen::VectorXd& b) {
  const int n = int(b.size());
  if (n == 0) return {};
  Eigen::MatrixXd G = G_in;
  G.diagonal().array() += 1e-12 * std::max(G.diagonal().mean(), 1e-300);
  // Start at the best single example: a vertex of the simplex, feasible.
  int start = 0;
  for (int i = 1; i < n; ++i)
    if (0.5 * G(i, i) - b[i] < 0.5 * G(start, start) - b[start]) start = i;
  Eigen::VectorXd w = Eigen::VectorXd::Zero(n);
  w[start] = 1;
  std::vector<char> is_free(n, 0);
  is_free[start] = 1;
  for (int iteration = 0; iteration < 10 * n + 100; ++iteration) {
    std::vector<int> free_set;
    for (int i = 0; i < n; ++i)
      if (is_free[i]) free_set.push_back(i);
    const Eigen::VectorXd z = equality_step(G, b, free_set);
    // Move towards z as far as every weight stays non-negative; the first to reach 0 leaves.
    double step = 1;
    int leaving = -1;
    for (size_t k = 0; k < free_set.size(); ++k) {
      const double from = w[free_set[k]], to = z[k];
      if (to < 0 && from - to > 0 && from / (from - to) < step) step = from / (from - to), leaving = free_set[k];
    }
    for (size_t k = 0; k < free_set.size(); ++k) w[free_set[k]] += step * (z[k] - w[free_set[k]]);
    if (leaving >= 0) {
      w[leaving] = 0;
      is_free[leaving] = 0;
      continue;
    }
    // At the subspace's minimum the free examples share one gradient, the sum's multiplier; an
    // example at 0 whose gradient is below it would lower the misfit by joining.
    const Eigen::VectorXd gradient = G * w - b;
    double lambda = 0;
    for (int i : free_set) lambda += gradient[i];
    lambda /= double(free_set.size());
    int entering = -1;
    double most = -1e-14 * (std::abs(lambda) + G.diagonal().maxCoeff());
    for (int i = 0; i < n; ++i)
      if (!is_free[i] && gradient[i] - lambda < most) most = gradient[i] - lambda, entering = i;
    if (entering < 0) break;
    is_free[entering] = 1;
  }
  for (int i = 0; i < n; ++i) w[i] = std::max(0.0, w[i]);
  return w / w.sum();
}

}  // namespace spx
