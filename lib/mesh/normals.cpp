#include "mesh/normals.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cmath>

namespace spx {

std::vector<Eigen::Vector3d> face_normals(const TriMesh& mesh) {
  std::vector<Eigen::Vector3d> out(mesh.triangles.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, out.size(), 1024), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t t = r.begin(); t != r.end(); ++t) {
      const auto& f = mesh.triangles[t];
      const Eigen::Vector3d area = (mesh.vertices[size_t(f[1])] - mesh.vertices[size_t(f[0])])
                                       .cross(mesh.vertices[size_t(f[2])] - mesh.vertices[size_t(f[0])]);
      out[t] = area.norm() > 0 ? Eigen::Vector3d(area / area.norm()) : Eigen::Vector3d::Zero();
    }
  });
  return out;
}

std::vector<Eigen::Vector3d> angle_weighted_normals(const TriMesh& mesh, const std::vector<Eigen::Vector3d>& faces) {
  const size_t count = mesh.triangles.size();
  std::vector<Eigen::Vector3d> corner_weight(3 * count);  // angle * face normal, per corner
  tbb::parallel_for(tbb::blocked_range<size_t>(0, count, 1024), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t t = r.begin(); t != r.end(); ++t) {
      const auto& f = mesh.triangles[t];
      for (int corner = 0; corner < 3; ++corner) {
        const Eigen::Vector3d& p = mesh.vertices[size_t(f[corner])];
        const Eigen::Vector3d u = mesh.vertices[size_t(f[(corner + 1) % 3])] - p,
                              v = mesh.vertices[size_t(f[(corner + 2) % 3])] - p;
        corner_weight[3 * t + size_t(corner)] = std::atan2(u.cross(v).norm(), u.dot(v)) * faces[t];
      }
    }
  });
  std::vector<Eigen::Vector3d> out(mesh.vertices.size(), Eigen::Vector3d::Zero());
  for (size_t t = 0; t < count; ++t)
    for (int corner = 0; corner < 3; ++corner) out[size_t(mesh.triangles[t][corner])] += corner_weight[3 * t + size_t(corner)];
  return out;
}

}  // namespace spx
