#include "mesh/components.hpp"

#include <tbb/parallel_sort.h>

#include <algorithm>
#include <numeric>

#include "core/format.hpp"

namespace spx {

std::vector<EdgeUse> sorted_edge_uses(const TriMesh& mesh) {
  std::vector<EdgeUse> edges;
  edges.reserve(mesh.triangles.size() * 3);
  for (size_t t = 0; t < mesh.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      const int a = mesh.triangles[t][k], b = mesh.triangles[t][(k + 1) % 3];
      if (a != b) edges.push_back({std::min(a, b), std::max(a, b), int(t), a < b});
    }
  tbb::parallel_sort(edges.begin(), edges.end(), [](const EdgeUse& x, const EdgeUse& y) {
    return x.lo != y.lo ? x.lo < y.lo : x.hi != y.hi ? x.hi < y.hi : x.tri < y.tri;
  });
  return edges;
}

Components components_of(size_t triangles, const std::vector<EdgeUse>& edges) {
  std::vector<int> parent(triangles);
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&parent](int x) {
    while (parent[size_t(x)] != x) x = parent[size_t(x)] = parent[size_t(parent[size_t(x)])];
    return x;
  };
  // Triangles sharing an edge are neighbours in the sorted list; the smaller root wins, so
  // each component's root is its first triangle.
  for (size_t k = 1; k < edges.size(); ++k)
    if (edges[k].lo == edges[k - 1].lo && edges[k].hi == edges[k - 1].hi) {
      const int a = find(edges[k].tri), b = find(edges[k - 1].tri);
      parent[size_t(std::max(a, b))] = std::min(a, b);
    }
  Components c;
  c.of_triangle.assign(triangles, -1);
  std::vector<int> id(triangles, -1);
  for (size_t t = 0; t < parent.size(); ++t) {
    const int root = find(int(t));
    if (id[size_t(root)] < 0) id[size_t(root)] = int(c.count++);
    c.of_triangle[t] = id[size_t(root)];
  }
  return c;
}

Components edge_components(const TriMesh& mesh) { return components_of(mesh.triangles.size(), sorted_edge_uses(mesh)); }

std::string piece_name(const std::string& kind, size_t number, size_t of, size_t triangles, const Eigen::Vector3d& around) {
  return kind + " " + std::to_string(number) + " of " + std::to_string(of) + " (" + std::to_string(triangles) +
         (triangles == 1 ? " triangle" : " triangles") + " around " + num(around.x()) + ", " + num(around.y()) + ", " +
         num(around.z()) + ")";
}

}  // namespace spx
