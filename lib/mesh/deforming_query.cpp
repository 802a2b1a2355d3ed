#include "mesh/deforming_query.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>
#include <tuple>

#include "mesh/defects.hpp"
#include "mesh/mesh_query.hpp"

namespace spx {

DeformingQuery::DeformingQuery(const TriMesh& rest) : tri_(rest.triangles) {
  closed_ = !tri_.empty() && find_defects(rest).watertight();
  // Edges: each undirected edge once, for its pseudo-normal.
  struct Half {
    int lo, hi, tri, k;
  };
  std::vector<Half> halves;
  for (size_t t = 0; t < tri_.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      const int a = tri_[t][k], b = tri_[t][(k + 1) % 3];
      halves.push_back({std::min(a, b), std::max(a, b), int(t), k});
    }
  std::sort(halves.begin(), halves.end(), [](const Half& x, const Half& y) {
    return std::tie(x.lo, x.hi, x.tri) < std::tie(y.lo, y.hi, y.tri);
  });
  edge_of_.resize(tri_.size());
  for (size_t i = 0; i < halves.size();) {
    size_t j = i;
    while (j < halves.size() && halves[j].lo == halves[i].lo && halves[j].hi == halves[i].hi) ++j;
    for (size_t k = i; k < j; ++k) edge_of_[size_t(halves[k].tri)][size_t(halves[k].k)] = int(edges_);
    ++edges_;
    i = j;
  }
  std::vector<Eigen::Vector3d> centroid(tri_.size());
  for (size_t t = 0; t < tri_.size(); ++t)
    centroid[t] = (rest.vertices[size_t(tri_[t][0])] + rest.vertices[size_t(tri_[t][1])] + rest.vertices[size_t(tri_[t][2])]) / 3;
  order_.resize(tri_.size());
  std::iota(order_.begin(), order_.end(), 0);
  if (!tri_.empty()) build(centroid, 0, int(tri_.size()));
}

// Median split along the longest side of the centroids' box; leaves of at most 4 triangles.
int DeformingQuery::build(const std::vector<Eigen::Vector3d>& centroid, int first, int count) {
  const int id = int(nodes_.size());
  nodes_.push_back({first, count, -1, -1});
  if (count <= 4) return id;
  Eigen::AlignedBox3d box;
  for (int i = first; i < first + count; ++i) box.extend(centroid[size_t(order_[size_t(i)])]);
  int axis = 0;
  box.sizes().maxCoeff(&axis);
  const int half = count / 2;
  std::nth_element(order_.begin() + first, order_.begin() + first + half, order_.begin() + first + count,
                   [&](int a, int b) { return centroid[size_t(a)][axis] < centroid[size_t(b)][axis]; });
  const int left = build(centroid, first, half);
  const int right = build(centroid, first + half, count - half);
  nodes_[size_t(id)].left = left, nodes_[size_t(id)].right = right;
  return id;
}

DeformingQuery::Shape DeformingQuery::shape(std::vector<Eigen::Vector3d> vertices) const {
  Shape s;
  s.q_ = this;
  s.v_ = std::move(vertices);
  // Boxes bottom-up: children come after their parent.
  s.box_.resize(nodes_.size());
  for (size_t n = nodes_.size(); n-- > 0;) {
    const Node& node = nodes_[n];
    Eigen::AlignedBox3d box;
    if (node.left < 0) {
      for (int i = node.first; i < node.first + node.count; ++i)
        for (int k = 0; k < 3; ++k) box.extend(s.v_[size_t(tri_[size_t(order_[size_t(i)])][k])]);
    } else {
      box = s.box_[size_t(node.left)].merged(s.box_[size_t(node.right)]);
    }
    s.box_[n] = box;
  }
  // Pseudo-normals: faces; edges, the sum of their two faces' unit normals; vertices, the
  // faces' unit normals weighted by the angle at the vertex.
  s.face_n_.resize(tri_.size());
  s.edge_n_.assign(edges_, Eigen::Vector3d::Zero());
  s.vertex_n_.assign(s.v_.size(), Eigen::Vector3d::Zero());
  for (size_t t = 0; t < tri_.size(); ++t) {
    const Eigen::Vector3d n = (s.v_[size_t(tri_[t][1])] - s.v_[size_t(tri_[t][0])])
                                  .cross(s.v_[size_t(tri_[t][2])] - s.v_[size_t(tri_[t][0])])
                                  .normalized();
    s.face_n_[t] = n;
    for (int k = 0; k < 3; ++k) {
      s.edge_n_[size_t(edge_of_[t][size_t(k)])] += n;
      const Eigen::Vector3d& p = s.v_[size_t(tri_[t][k])];
      const Eigen::Vector3d e1 = s.v_[size_t(tri_[t][(k + 1) % 3])] - p, e2 = s.v_[size_t(tri_[t][(k + 2) % 3])] - p;
      const double angle = std::atan2(e1.cross(e2).norm(), e1.dot(e2));
      s.vertex_n_[size_t(tri_[t][k])] += angle * n;
    }
  }
  return s;
}

double DeformingQuery::Shape::signed_distance(const Eigen::Vector3d& p) const {
  const DeformingQuery& q = *q_;
  double best = std::numeric_limits<double>::infinity();
  int best_tri = -1;
  Eigen::Vector3d best_point = Eigen::Vector3d::Zero(), best_bary = Eigen::Vector3d::Zero();
  // Depth first, nearer child first, pruned by the boxes' distances.
  std::array<int, 128> stack;
  int top = 0;
  if (!q.nodes_.empty()) stack[size_t(top++)] = 0;
  while (top > 0) {
    const int n = stack[size_t(--top)];
    if (box_[size_t(n)].squaredExteriorDistance(p) >= best) continue;
    const Node& node = q.nodes_[size_t(n)];
    if (node.left < 0) {
      for (int i = node.first; i < node.first + node.count; ++i) {
        const int t = q.order_[size_t(i)];
        const Eigen::Vector3i& f = q.tri_[size_t(t)];
        Eigen::Vector3d bary;
        const Eigen::Vector3d c = closest_point_on_triangle(p, v_[size_t(f[0])], v_[size_t(f[1])], v_[size_t(f[2])], &bary);
        const double d = (p - c).squaredNorm();
        if (d < best) best = d, best_tri = t, best_point = c, best_bary = bary;
      }
      continue;
    }
    const double dl = box_[size_t(node.left)].squaredExteriorDistance(p);
    const double dr = box_[size_t(node.right)].squaredExteriorDistance(p);
    stack[size_t(top++)] = dl < dr ? node.right : node.left;
    stack[size_t(top++)] = dl < dr ? node.left : node.right;
  }
  if (best_tri < 0) return std::numeric_limits<double>::infinity();
  // The closest feature's pseudo-normal: a corner (two coordinates 0), an edge (one), the face.
  const Eigen::Vector3i& f = q.tri_[size_t(best_tri)];
  Eigen::Vector3d n = face_n_[size_t(best_tri)];
  const int zeros = int(best_bary[0] == 0) + int(best_bary[1] == 0) + int(best_bary[2] == 0);
  if (zeros == 2) {
    int k = 0;
    best_bary.maxCoeff(&k);
    n = vertex_n_[size_t(f[k])];
  } else if (zeros == 1) {
    int opposite = 0;
    best_bary.minCoeff(&opposite);  // the edge from corner opposite+1 to opposite+2
    n = edge_n_[size_t(q.edge_of_[size_t(best_tri)][size_t((opposite + 1) % 3)])];
  }
  const double d = std::sqrt(best);
  return (p - best_point).dot(n) < 0 ? -d : d;
}

}  // namespace spx
