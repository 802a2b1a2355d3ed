#pragma once
// Generalized winding number (Jacobson et al. 2013) with the fast hierarchical evaluation
// of Barill et al. 2018: exact solid angles near the query, and the
// Taylor expansion to second order (Barill's order 2) far away.
// Inside is w > 1/2; this holds for open meshes, soups and self-intersections.
#include <cmath>
#include <memory>
#include <mutex>
#include <vector>

#include "mesh/mesh.hpp"

namespace spx {

// Exact sum of triangle solid angles / 4pi (O(triangles)); the reference for tests.
double winding_number_exact(const TriMesh& mesh, const Eigen::Vector3d& q);

class WindingNumber {
 public:
  // `accuracy` is Barill's beta: expansions are used beyond beta * cluster radius.
  explicit WindingNumber(const TriMesh& mesh, double accuracy = 2.0);
  // The same, built on the first question (from any thread) instead: for a holder that may never
  // ask one (a closed pose's MeshQuery, whose inside another hierarchy's ray count tells), where
  // the hierarchy is the largest part of its memory. `mesh` must outlive it.
  static WindingNumber on_first_use(const TriMesh& mesh, double accuracy = 2.0);
  WindingNumber(const WindingNumber&) = delete;
  WindingNumber& operator=(const WindingNumber&) = delete;
  ~WindingNumber();
  double operator()(const Eigen::Vector3d& q) const;
  // The exact sum over every triangle (O(triangles)).
  double exact(const Eigen::Vector3d& q) const;
  // w > 1/2, decided as the exact sum decides (exact(q) > 1/2 + kTie) wherever the expansion
  // lands within kExactBand of 1/2: the approximation's error may not flip a point near the
  // threshold (an open mesh's hole). A point on the threshold itself (the plane of a
  // hemisphere's rim: 1/2 up to the sum's rounding) is outside, whatever order the solid angles
  // are added in.
  bool inside(const Eigen::Vector3d& q) const {
    const double w = (*this)(q);
    if (std::abs(w - 0.5) < kExactBand) return exactly_inside(q);
    return w > 0.5;
  }
  static constexpr double kExactBand = 0.02, kTie = 1e-9;
  // From this many triangles up, inside() near 1/2 refines bounded() before the exact sum.
  static constexpr size_t kRefinedFrom = 1024;

  // w within `error` of the true sum: the far clusters' expansions (to third order) each with a
  // bound on what they leave out, the near triangles' solid angles summed as exact() sums them.
  // Refined (the clusters of largest bound opened first) until the interval leaves out `level`,
  // or past `max_triangles` summed one by one.
  struct Bounded {
    double value = 0, error = 0;
    size_t triangles = 0;  // summed one by one
  };
  Bounded bounded(const Eigen::Vector3d& q, double level, size_t max_triangles) const;
  // Whether the hierarchy has been built (on_first_use: not until asked); not synchronised with
  // a build under way on another thread.
  bool built() const { return tree_ != nullptr; }

 private:
  struct Node {
    Eigen::Vector3d center;      // area-weighted centroid
    Eigen::Vector3d dipole;      // sum of area vectors
    Eigen::Matrix3d quadrupole;  // sum over triangles of (centroid - center) * area vector^T
    Eigen::Matrix3d octupole[3]; // [i](j,k): sum of area vector_i * second moment_jk about center
    double radius = 0;
    double area = 0;             // sum of the triangles' areas
    double quartic = 0;          // sum of each triangle's area times its farthest corner's distance from center, ^4
    int first = 0, count = 0;    // triangle range when a leaf
    int left = -1, right = -1;
  };
  // A node's degree-3 moments, T(i,j,k,l) = sum over triangles of the integral of n_i h_j h_k h_l
  // (h = x - center), as the degree-3 term asks for them: bounded()'s expansion only, so kept
  // apart from the nodes the fast evaluation walks, and made on bounded()'s first call (most
  // hierarchies never see one: 200 bytes a node).
  struct Third {
    double quartic[15] = {};  // T contracted with R four times: the coefficient of each monomial of R
    Eigen::Matrix3d pairs = Eigen::Matrix3d::Zero();  // sum_i T(i,i,.,.) + sym(sum_j T(.,j,j,.)): R.pairs.R
    double traces = 0;        // sum_ik T(i,i,k,k)
  };
  struct Tree {
    std::vector<Eigen::Vector3d> a, b, c;  // triangle corners in tree order
    std::vector<Node> nodes;
    explicit Tree(const TriMesh& mesh);
    int build(int first, int count);
    const std::vector<Third>& third() const;  // by node, made on the first call (from any thread)

   private:
    std::vector<Third> third_moments() const;
    mutable std::once_flag third_once_;
    mutable std::vector<Third> third_;
  };
  struct Lazy;
  WindingNumber(const TriMesh& mesh, double accuracy, bool now);
  // exact(q) > 1/2 + kTie, by bounded() wherever its interval leaves that level out.
  bool exactly_inside(const Eigen::Vector3d& q) const;
  static double far_field(const Node& node, const Eigen::Vector3d& r, double d);
  static double third_order(const Third& third, const Eigen::Vector3d& r, double d);
  static double truncation_bound(const Node& node, double d);
  const Tree& tree() const;

  double beta_;
  mutable std::unique_ptr<const Tree> tree_;
  std::unique_ptr<Lazy> lazy_;  // on_first_use: the mesh and its once flag until built
};

}  // namespace spx
