#include "mesh/split.hpp"

#include <algorithm>
#include <map>
#include <utility>

namespace spx {

TriMesh split_at_midpoints(TriMesh mesh, int times, std::vector<std::pair<int, int>>* ends) {
  if (ends) ends->clear();
  for (int n = 0; n < times; ++n) {
    std::map<std::pair<int, int>, int> midpoint;
    const auto mid = [&](int a, int b) {
      const auto [it, fresh] = midpoint.emplace(std::minmax(a, b), int(mesh.vertices.size()));
      if (!fresh) return it->second;
      mesh.vertices.push_back(0.5 * (mesh.vertices[size_t(a)] + mesh.vertices[size_t(b)]));
      if (ends) ends->emplace_back(a, b);
      return it->second;
    };
    std::vector<Eigen::Vector3i> split;
    split.reserve(4 * mesh.triangles.size());
    for (const Eigen::Vector3i& t : mesh.triangles) {
      const int ab = mid(t[0], t[1]), bc = mid(t[1], t[2]), ca = mid(t[2], t[0]);
      split.insert(split.end(), {{t[0], ab, ca}, {ab, t[1], bc}, {ca, bc, t[2]}, {ab, bc, ca}});
    }
    mesh.triangles = std::move(split);
  }
  return mesh;
}

}  // namespace spx
