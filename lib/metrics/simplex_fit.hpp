#pragma once
// The convex combination of examples nearest a target: the weights a host would need to blend
// its examples into a frame it never saw, at best.
#include <Eigen/Core>

namespace spx {

// w >= 0 with sum 1 minimising |A w - v|^2, given G = A^T A and b = A^T v (the Gram form, so a
// mesh of any size costs one matrix-vector product per frame). A primal active-set method:
// exact up to rounding, and finite (each step drops or adds one example). Needs G symmetric
// positive semi-definite; a ridge of 1e-12 of its mean diagonal stands in for examples that are
// affinely dependent.
Eigen::VectorXd simplex_least_squares(const Eigen::MatrixXd& G, const Eigen::VectorXd& b);

}  // namespace spx
