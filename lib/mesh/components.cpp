#include "mesh/components.hpp"

#include <Eigen/Eigenvalues>
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

std::vector<PieceShape> piece_shapes(const TriMesh& mesh, const Components& pieces) {
  std::vector<PieceShape> out(pieces.count);
  std::vector<Eigen::Vector3d> mean(pieces.count, Eigen::Vector3d::Zero());
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& f = mesh.triangles[t];
    const Eigen::Vector3d &a = mesh.vertices[size_t(f[0])], &b = mesh.vertices[size_t(f[1])], &c = mesh.vertices[size_t(f[2])];
    const size_t p = size_t(pieces.of_triangle[t]);
    PieceShape& piece = out[p];
    ++piece.triangles;
    piece.box.extend(a), piece.box.extend(b), piece.box.extend(c);
    piece.volume += a.dot(b.cross(c)) / 6.0;
    mean[p] += a + b + c;
  }
  // Flat: the corners' scatter about their mean has a (near) zero least axis. Two passes, so a
  // piece far from the origin loses no digits to its squares.
  std::vector<Eigen::Matrix3d> scatter(pieces.count, Eigen::Matrix3d::Zero());
  for (size_t p = 0; p < pieces.count; ++p) mean[p] /= 3.0 * double(std::max<size_t>(1, out[p].triangles));
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const size_t p = size_t(pieces.of_triangle[t]);
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d d = mesh.vertices[size_t(mesh.triangles[t][k])] - mean[p];
      scatter[p] += d * d.transpose();
    }
  }
  for (size_t p = 0; p < pieces.count; ++p) {
    if (out[p].triangles == 0) continue;
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(scatter[p] / (3.0 * double(out[p].triangles)));
    out[p].flat = std::sqrt(std::max(0.0, solver.eigenvalues()[0])) <= 1e-7 * out[p].box.diagonal().norm();
  }
  return out;
}

std::string piece_name(const std::string& kind, size_t number, size_t of, const PieceShape& piece) {
  const Eigen::Vector3d around = piece.box.center();
  return kind + " " + std::to_string(number) + " of " + std::to_string(of) + " (" + std::to_string(piece.triangles) +
         (piece.triangles == 1 ? " triangle" : " triangles") + " around " + num(around.x()) + ", " + num(around.y()) +
         ", " + num(around.z()) + ")";
}

}  // namespace spx
