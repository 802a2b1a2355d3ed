#pragma once
// Generalized winding number (Jacobson et al. 2013) with the fast hierarchical evaluation
// of Barill et al. 2018: exact solid angles near the query, and the
// Taylor expansion to second order (Barill's order 2) far away.
// Inside is w > 1/2; this holds for open meshes, soups and self-intersections.
#include <vector>

#include "mesh/mesh.hpp"

namespace spx {

// Exact sum of triangle solid angles / 4pi (O(triangles)); the reference for tests.
double winding_number_exact(const TriMesh& mesh, const Eigen::Vector3d& q);

class WindingNumber {
 public:
  // `accuracy` is Barill's beta: expansions are used beyond beta * cluster radius.
  explicit WindingNumber(const TriMesh& mesh, double accuracy = 2.0);
  double operator()(const Eigen::Vector3d& q) const;
  bool inside(const Eigen::Vector3d& q) const { return (*this)(q) > 0.5; }

 private:
  struct Node {
    Eigen::Vector3d center;      // area-weighted centroid
    Eigen::Vector3d dipole;      // sum of area vectors
    Eigen::Matrix3d quadrupole;  // sum over triangles of (centroid - center) * area vector^T
    Eigen::Matrix3d octupole[3]; // [i](j,k): sum of area vector_i * second moment_jk about center
    double radius = 0;
    int first = 0, count = 0;    // triangle range when a leaf
    int left = -1, right = -1;
  };
  int build(int first, int count);

  std::vector<Eigen::Vector3d> a_, b_, c_;  // triangle corners in tree order
  std::vector<Node> nodes_;
  double beta_;
};

}  // namespace spx
