#include "mesh/deforming_query.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>
#include <tuple>

#include "mesh/defects.hpp"
#include "mesh/mesh_query.hpp"
#include "mesh/winding_number.hpp"

namespace spx {

double distance_to_origin(const Corners& u) {
  return closest_point_on_triangle(Eigen::Vector3d::Zero(), u[0], u[1], u[2]).norm();
}

double least_distance_over_step(const Corners& from, double from_distance, const Corners& to, double to_distance) {
  const double most = std::max({(to[0] - from[0]).norm(), (to[1] - from[1]).norm(), (to[2] - from[2]).norm()});
  return std::min(from_distance, to_distance) - most / 2;
}

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
    for (size_t k = i; k < j; ++k) edge_of_[size_t(halves[k].tri)][size_t(halves[k].k)] = int(edge_tris_.size());
    // A closed mesh's edge has two triangles; others are never asked for a sign.
    edge_tris_.push_back({halves[i].tri, halves[j - 1].tri});
    i = j;
  }
  corner_start_.assign(rest.vertices.size() + 1, 0);
  for (const Eigen::Vector3i& t : tri_)
    for (int k = 0; k < 3; ++k) ++corner_start_[size_t(t[k]) + 1];
  for (size_t v = 0; v < rest.vertices.size(); ++v) corner_start_[v + 1] += corner_start_[v];
  corners_.resize(3 * tri_.size());
  std::vector<int> fill(corner_start_.begin(), corner_start_.end() - 1);
  for (size_t t = 0; t < tri_.size(); ++t)
    for (int k = 0; k < 3; ++k) corners_[size_t(fill[size_t(tri_[t][k])]++)] = {int(t), k};
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
  return s;
}

DeformingQuery::Shape DeformingQuery::swept(std::vector<Eigen::Vector3d> vertices, std::vector<double> inflation) const {
  Shape s = shape(std::move(vertices));
  const size_t v = inflation.size();
  s.inflation_ = std::move(inflation);
  s.inflation_.resize(v + nodes_.size(), 0.0);
  for (size_t n = nodes_.size(); n-- > 0;) {
    const Node& node = nodes_[n];
    double& most = s.inflation_[v + n];
    if (node.left < 0) {
      for (int i = node.first; i < node.first + node.count; ++i)
        for (int k = 0; k < 3; ++k) most = std::max(most, s.inflation_[size_t(tri_[size_t(order_[size_t(i)])][k])]);
    } else {
      most = std::max(s.inflation_[v + size_t(node.left)], s.inflation_[v + size_t(node.right)]);
    }
  }
  return s;
}

Eigen::Vector3d DeformingQuery::Shape::face_normal(int t) const {
  const Eigen::Vector3i& f = q_->tri_[size_t(t)];
  return (v_[size_t(f[1])] - v_[size_t(f[0])]).cross(v_[size_t(f[2])] - v_[size_t(f[0])]).normalized();
}

// The faces' unit normals weighted by the angle at the vertex.
Eigen::Vector3d DeformingQuery::Shape::vertex_normal(int v) const {
  Eigen::Vector3d n = Eigen::Vector3d::Zero();
  for (int c = q_->corner_start_[size_t(v)]; c < q_->corner_start_[size_t(v) + 1]; ++c) {
    const auto [t, k] = q_->corners_[size_t(c)];
    const Eigen::Vector3i& f = q_->tri_[size_t(t)];
    const Eigen::Vector3d& p = v_[size_t(f[k])];
    const Eigen::Vector3d e1 = v_[size_t(f[(k + 1) % 3])] - p, e2 = v_[size_t(f[(k + 2) % 3])] - p;
    n += std::atan2(e1.cross(e2).norm(), e1.dot(e2)) * face_normal(t);
  }
  return n;
}

double DeformingQuery::Shape::signed_distance(const Eigen::Vector3d& p) const {
  return signed_distance_within(p, std::numeric_limits<double>::infinity());
}

// Depth first, nearer child first, pruned by the boxes' squared distances against `best`:
// leaf(t) for every triangle of a leaf box nearer than `best`; it may lower `best`, and stops the
// search by returning false.
template <class Leaf>
void DeformingQuery::Shape::search(const Eigen::Vector3d& p, double& best, Leaf&& leaf) const {
  const DeformingQuery& q = *q_;
  std::array<int, 128> stack;
  int top = 0;
  if (!q.nodes_.empty()) stack[size_t(top++)] = 0;
  while (top > 0) {
    const int n = stack[size_t(--top)];
    if (box_[size_t(n)].squaredExteriorDistance(p) >= best) continue;
    const Node& node = q.nodes_[size_t(n)];
    if (node.left < 0) {
      for (int i = node.first; i < node.first + node.count; ++i)
        if (!leaf(q.order_[size_t(i)])) return;
      continue;
    }
    const double dl = box_[size_t(node.left)].squaredExteriorDistance(p);
    const double dr = box_[size_t(node.right)].squaredExteriorDistance(p);
    stack[size_t(top++)] = dl < dr ? node.right : node.left;
    stack[size_t(top++)] = dl < dr ? node.left : node.right;
  }
}

double DeformingQuery::Shape::signed_distance_within(const Eigen::Vector3d& p, double bound) const {
  const DeformingQuery& q = *q_;
  double best = bound * bound;
  int best_tri = -1;
  Eigen::Vector3d best_point = Eigen::Vector3d::Zero(), best_bary = Eigen::Vector3d::Zero();
  search(p, best, [&](int t) {
    const Eigen::Vector3i& f = q.tri_[size_t(t)];
    Eigen::Vector3d bary;
    const Eigen::Vector3d c = closest_point_on_triangle(p, v_[size_t(f[0])], v_[size_t(f[1])], v_[size_t(f[2])], &bary);
    const double d = (p - c).squaredNorm();
    if (d < best) best = d, best_tri = t, best_point = c, best_bary = bary;
    return true;
  });
  if (best_tri < 0) return std::numeric_limits<double>::infinity();
  // The closest feature's pseudo-normal: a corner (two coordinates 0), an edge (one), the face.
  const Eigen::Vector3i& f = q.tri_[size_t(best_tri)];
  Eigen::Vector3d n;
  const int zeros = int(best_bary[0] == 0) + int(best_bary[1] == 0) + int(best_bary[2] == 0);
  if (zeros == 2) {
    int k = 0;
    best_bary.maxCoeff(&k);
    n = vertex_normal(f[k]);
  } else if (zeros == 1) {
    int opposite = 0;
    best_bary.minCoeff(&opposite);  // the edge from corner opposite+1 to opposite+2
    const auto [a, b] = q.edge_tris_[size_t(q.edge_of_[size_t(best_tri)][size_t((opposite + 1) % 3)])];
    n = face_normal(a) + face_normal(b);
  } else {
    n = face_normal(best_tri);
  }
  const double d = std::sqrt(best);
  return (p - best_point).dot(n) < 0 ? -d : d;
}

namespace {

// Whether the ray meets the box (slabs; `inv` = 1 / dir).
bool ray_hits_box(const Eigen::AlignedBox3d& box, const Eigen::Vector3d& p, const Eigen::Vector3d& inv) {
  double near = 0, far = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3; ++a) {
    double t0 = (box.min()[a] - p[a]) * inv[a], t1 = (box.max()[a] - p[a]) * inv[a];
    if (t0 > t1) std::swap(t0, t1);
    near = std::max(near, t0), far = std::min(far, t1);
  }
  return near <= far;
}

// Barycentric coordinates this close to 0, or a determinant this small against the triangle's
// size, make a crossing's count uncertain.
constexpr double kGraze = 1e-9;

}  // namespace

std::optional<int> DeformingQuery::Shape::crossings(const Eigen::Vector3d& p, const Eigen::Vector3d& dir) const {
  const DeformingQuery& q = *q_;
  const Eigen::Vector3d inv = dir.cwiseInverse();
  int count = 0;
  std::array<int, 128> stack;
  int top = 0;
  if (!q.nodes_.empty()) stack[size_t(top++)] = 0;
  while (top > 0) {
    const int n = stack[size_t(--top)];
    if (!ray_hits_box(box_[size_t(n)], p, inv)) continue;
    const Node& node = q.nodes_[size_t(n)];
    if (node.left >= 0) {
      stack[size_t(top++)] = node.left, stack[size_t(top++)] = node.right;
      continue;
    }
    for (int i = node.first; i < node.first + node.count; ++i) {
      // Moller-Trumbore.
      const Eigen::Vector3i& f = q.tri_[size_t(q.order_[size_t(i)])];
      const Eigen::Vector3d &a = v_[size_t(f[0])], e1 = v_[size_t(f[1])] - a, e2 = v_[size_t(f[2])] - a;
      const Eigen::Vector3d h = dir.cross(e2), n = e1.cross(e2);
      const double det = e1.dot(h), scale = n.norm();
      const Eigen::Vector3d s = p - a;
      const Eigen::Vector3d qv = s.cross(e1);
      if (std::abs(det) <= kGraze * scale) {
        // Along the triangle's plane: uncertain only if the ray lies in it.
        if (std::abs(s.dot(n)) <= kGraze * scale * (s.norm() + e1.norm())) return std::nullopt;
        continue;
      }
      const double u = s.dot(h) / det, v = dir.dot(qv) / det, t = e2.dot(qv) / det;
      if (u < -kGraze || v < -kGraze || u + v > 1 + kGraze || t < 0) continue;
      if (u < kGraze || v < kGraze || u + v > 1 - kGraze || t <= kGraze) return std::nullopt;
      count += det < 0 ? 1 : -1;  // det = dir . (e1 x e2) negated: < 0 where the ray leaves
    }
  }
  return count;
}

bool DeformingQuery::Shape::nearer_than(const Eigen::Vector3d& p, double bound) const {
  double best = bound * bound;
  bool found = false;
  search(p, best, [&](int t) {
    const Eigen::Vector3i& f = q_->tri_[size_t(t)];
    found = (p - closest_point_on_triangle(p, v_[size_t(f[0])], v_[size_t(f[1])], v_[size_t(f[2])])).squaredNorm() < best;
    return !found;
  });
  return found;
}

double DeformingQuery::Shape::grow(int n) const { return inflation_[inflation_.size() - q_->nodes_.size() + size_t(n)]; }

bool DeformingQuery::Shape::may_reach(int n, const Eigen::Vector3d& p, double bound) const {
  const double reach = bound + grow(n);
  return reach > 0 && box_[size_t(n)].squaredExteriorDistance(p) < reach * reach;
}

bool DeformingQuery::Shape::add_inflated_near(int n, const Eigen::Vector3d& p, double bound, size_t most,
                                              std::vector<int>& found) const {
  const DeformingQuery& q = *q_;
  const Node& node = q.nodes_[size_t(n)];
  for (int i = node.first; i < node.first + node.count; ++i) {
    const int t = q.order_[size_t(i)];
    const Eigen::Vector3i& f = q.tri_[size_t(t)];
    const double reach =
        bound + std::max({inflation_[size_t(f[0])], inflation_[size_t(f[1])], inflation_[size_t(f[2])]});
    if (!(reach > 0 && (p - closest_point_on_triangle(p, v_[size_t(f[0])], v_[size_t(f[1])], v_[size_t(f[2])]))
                               .squaredNorm() < reach * reach))
      continue;
    if (found.size() == most) return false;
    found.push_back(t);
  }
  return true;
}

void DeformingQuery::Shape::triangles_near(const Eigen::Vector3d& p, double bound, std::vector<int>& found) const {
  const DeformingQuery& q = *q_;
  found.clear();
  double best = bound * bound;  // never lowered: every box within the bound is opened
  search(p, best, [&](int t) {
    Eigen::AlignedBox3d box;
    for (int k = 0; k < 3; ++k) box.extend(v_[size_t(q.tri_[size_t(t)][k])]);
    if (box.squaredExteriorDistance(p) < best) found.push_back(t);
    return true;
  });
}

void DeformingQuery::Shape::leaves_near(const Eigen::AlignedBox3d& region, std::vector<int>& leaves) const {
  const DeformingQuery& q = *q_;
  leaves.clear();
  // A ball in the region that a node's grown box reaches: the box comes within its inflation of
  // the region (no nearer test, so that an inflation of 0 keeps a box touching it).
  auto may = [&](int n) {
    const Eigen::AlignedBox3d& box = box_[size_t(n)];
    const Eigen::Vector3d gap =
        (region.min() - box.max()).cwiseMax(box.min() - region.max()).cwiseMax(Eigen::Vector3d::Zero());
    return gap.squaredNorm() <= grow(n) * grow(n);
  };
  std::array<int, 128> stack;
  int top = 0;
  if (!q.nodes_.empty() && may(0)) stack[size_t(top++)] = 0;
  while (top > 0) {
    const int n = stack[size_t(--top)];
    const Node& node = q.nodes_[size_t(n)];
    if (node.left < 0) {
      leaves.push_back(n);
      continue;
    }
    if (may(node.right)) stack[size_t(top++)] = node.right;
    if (may(node.left)) stack[size_t(top++)] = node.left;
  }
}

bool DeformingQuery::Shape::inflated_triangles_nearer_than(const Eigen::Vector3d& p, double bound, size_t most,
                                                           std::vector<int>& found,
                                                           const std::vector<int>& leaves) const {
  found.clear();
  // A leaf whose grown box reaches p is among them (the region holds the ball p +- bound).
  for (int n : leaves)
    if (may_reach(n, p, bound) && !add_inflated_near(n, p, bound, most, found)) return false;
  return true;
}

bool DeformingQuery::Shape::inside(const Eigen::Vector3d& p) const {
  // Directions no mesh's edges line up with.
  static const std::array<Eigen::Vector3d, 3> kDirections{Eigen::Vector3d(0.5773, 0.5871, 0.5675).normalized(),
                                                          Eigen::Vector3d(-0.6123, 0.3307, 0.7182).normalized(),
                                                          Eigen::Vector3d(0.2419, -0.9013, 0.3594).normalized()};
  for (const Eigen::Vector3d& dir : kDirections)
    if (const std::optional<int> n = crossings(p, dir)) return *n > 0;
  return winding_number_exact(TriMesh{v_, q_->tri_}, p) > 0.5;
}

RayInside::RayInside(const TriMesh& mesh, bool use) : rays_(mesh), on_surface_(1e-9 * mesh.diagonal()) {
  if (use && rays_.closed()) shape_.emplace(rays_.shape(mesh.vertices));
}

std::optional<bool> RayInside::operator()(const Eigen::Vector3d& p) const {
  if (!shape_ || shape_->nearer_than(p, on_surface_)) return std::nullopt;
  return shape_->inside(p);
}

}  // namespace spx
