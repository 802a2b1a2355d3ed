// A closed part given both ways (drop_inner_sides, mesh.hpp): its outer side kept.
#include <algorithm>
#include <array>
#include <vector>

#include "mesh/components.hpp"
#include "mesh/defects.hpp"
#include "mesh/mesh.hpp"
#include "mesh/sorted_keys.hpp"

namespace spx {
namespace {

// Each triangle's twin (the same corners in the other turn), -1 where it has none. Triangles with
// a repeated corner have none.
std::vector<int> twins_of(const TriMesh& mesh) {
  using Corners = std::array<int, 3>;
  const std::vector<KeyedIndex<Corners>> sorted = sorted_keys<Corners>(mesh.triangles.size(), [&](size_t t) {
    const Eigen::Vector3i& f = mesh.triangles[t];
    Corners key = {f[0], f[1], f[2]};
    std::sort(key.begin(), key.end());
    return key;
  });
  // Repeats in the same turn were dropped before: of the triangles on these corners, the first
  // two are twins (a third would repeat one of them).
  std::vector<int> twin(mesh.triangles.size(), -1);
  for (size_t k = 1; k < sorted.size(); ++k) {
    const Corners& key = sorted[k].first;
    if (key != sorted[k - 1].first || key[0] == key[1] || key[1] == key[2]) continue;
    if (k >= 2 && sorted[k - 2].first == key) continue;  // a third
    twin[sorted[k].second] = int(sorted[k - 1].second), twin[sorted[k - 1].second] = int(sorted[k].second);
  }
  return twin;
}

// Which of each twin faces out, for the parts whose every triangle has a twin and whose one side
// is a closed surface, oriented consistently: `keep` per triangle (1 kept, 0 dropped, -1 not such
// a part), and in `found` how many such parts. A part's side is grown from its first triangle
// across its edges, each neighbour taken in the turn that runs their shared edge the other way.
std::vector<int> outer_sides(const TriMesh& mesh, const std::vector<int>& twin, size_t& found) {
  const std::vector<EdgeUse> uses = sorted_edge_uses(mesh);
  const Components parts = components_of(mesh.triangles.size(), uses);
  std::vector<char> fit(parts.count, 1);  // every triangle twinned, every edge between two twins
  for (size_t t = 0; t < twin.size(); ++t)
    if (twin[t] < 0) fit[size_t(parts.of_triangle[t])] = 0;
  // Across each edge of a fit part's side: the triangles taken with each.
  std::vector<std::vector<int>> next(mesh.triangles.size());
  for (size_t k = 0; k < uses.size();) {
    size_t end = k;
    while (end < uses.size() && uses[end].lo == uses[k].lo && uses[end].hi == uses[k].hi) ++end;
    const size_t part = size_t(parts.of_triangle[size_t(uses[k].tri)]);
    if (end - k != 4) {
      fit[part] = 0;  // an open edge, or more than two twins meet there
    } else {
      for (size_t a = k; a < end; ++a)
        for (size_t b = k; b < end; ++b)
          if (uses[b].tri != uses[a].tri && uses[b].tri != twin[size_t(uses[a].tri)] && uses[a].forward != uses[b].forward)
            next[size_t(uses[a].tri)].push_back(uses[b].tri);
    }
    k = end;
  }
  std::vector<int> keep(mesh.triangles.size(), -1);
  std::vector<char> seeded(parts.count, 0);
  std::vector<int> stack;
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const size_t part = size_t(parts.of_triangle[t]);
    if (!fit[part] || seeded[part]) continue;
    seeded[part] = 1;
    stack = {int(t)};
    keep[t] = 1, keep[size_t(twin[t])] = 0;
    while (!stack.empty() && fit[part]) {
      const int a = stack.back();
      stack.pop_back();
      for (int b : next[size_t(a)]) {
        if (keep[size_t(b)] == 1) continue;
        if (keep[size_t(b)] == 0) {
          fit[part] = 0;  // not orientable as one side
          break;
        }
        keep[size_t(b)] = 1, keep[size_t(twin[size_t(b)])] = 0;
        stack.push_back(b);
      }
    }
  }
  // The side faces out where its volume is positive (measured about the part's box, for digits).
  std::vector<Eigen::AlignedBox3d> box(parts.count);
  for (size_t t = 0; t < mesh.triangles.size(); ++t)
    for (int c = 0; c < 3; ++c) box[size_t(parts.of_triangle[t])].extend(mesh.vertices[size_t(mesh.triangles[t][c])]);
  std::vector<double> volume(parts.count, 0);
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const size_t part = size_t(parts.of_triangle[t]);
    if (!fit[part] || keep[t] != 1) continue;
    const Eigen::Vector3d o = box[part].center();
    const Eigen::Vector3i& f = mesh.triangles[t];
    const Eigen::Vector3d a = mesh.vertices[size_t(f[0])] - o, b = mesh.vertices[size_t(f[1])] - o, c = mesh.vertices[size_t(f[2])] - o;
    volume[part] += a.dot(b.cross(c)) / 6.0;
  }
  found = 0;
  for (size_t part = 0; part < parts.count; ++part) {
    fit[part] = fit[part] && !negligible_volume(volume[part], box[part].sizes().maxCoeff());
    found += fit[part] != 0;
  }
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const size_t part = size_t(parts.of_triangle[t]);
    if (!fit[part]) keep[t] = -1;
    else if (volume[part] < 0) keep[t] = 1 - keep[t];
  }
  return keep;
}

}  // namespace

RepeatedTriangles drop_inner_sides(TriMesh& mesh) {
  RepeatedTriangles out;
  const std::vector<int> twin = twins_of(mesh);
  if (std::all_of(twin.begin(), twin.end(), [](int t) { return t < 0; })) return out;
  const std::vector<int> keep = outer_sides(mesh, twin, out.double_sided_parts);
  size_t kept = 0;
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    if (keep[t] != 0) {
      mesh.triangles[kept++] = mesh.triangles[t];
      continue;
    }
    if (out.inner_sides++ == 0) out.inner_first_at = mesh.vertices[size_t(mesh.triangles[t][0])];
  }
  mesh.triangles.resize(kept);
  return out;
}

RepeatedTriangles read_triangles_once(TriMesh& mesh) {
  RepeatedTriangles out = drop_repeated_triangles(mesh);
  out.add(drop_inner_sides(mesh));
  return out;
}

}  // namespace spx
