#pragma once
// Exact closest points (CGAL AABB tree) and robust inside tests (winding number) on one mesh.
#include <memory>

#include "mesh/mesh.hpp"
#include "mesh/winding_number.hpp"

namespace spx {

struct ClosestPoint {
  Eigen::Vector3d point;
  Eigen::Vector3d barycentric;  // of `point` in triangle `triangle`
  int triangle = -1;
  double distance = 0;
};

class MeshQuery {
 public:
  explicit MeshQuery(const TriMesh& mesh);
  ~MeshQuery();
  MeshQuery(const MeshQuery&) = delete;
  MeshQuery& operator=(const MeshQuery&) = delete;

  const TriMesh& mesh() const { return mesh_; }
  double distance(const Eigen::Vector3d& p) const;
  ClosestPoint closest(const Eigen::Vector3d& p) const;
  double winding_number(const Eigen::Vector3d& p) const { return wn_(p); }
  bool inside(const Eigen::Vector3d& p) const { return wn_.inside(p); }
  // Negative inside (winding number > 1/2).
  double signed_distance(const Eigen::Vector3d& p) const;

 private:
  struct Tree;
  TriMesh mesh_;
  WindingNumber wn_;
  std::unique_ptr<Tree> tree_;
};

// Reference for tests and for hot loops that already know the triangle.
Eigen::Vector3d closest_point_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                          const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                                          Eigen::Vector3d* barycentric = nullptr);

}  // namespace spx
