#include "posemap/skinned_map.hpp"

#include <Eigen/LU>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <algorithm>
#include <limits>
#include <numeric>

namespace spx {

SkinInfluence heaviest_four(const Eigen::VectorXd& weights) {
  std::vector<int> order(size_t(weights.size()));
  std::iota(order.begin(), order.end(), 0);
  const size_t keep = std::min<size_t>(4, order.size());
  std::partial_sort(order.begin(), order.begin() + std::ptrdiff_t(keep), order.end(),
                    [&](int a, int b) { return weights[a] > weights[b] || (weights[a] == weights[b] && a < b); });
  SkinInfluence s;
  double total = 0;
  for (size_t k = 0; k < keep; ++k) total += std::max(0.0, weights[order[k]]);
  if (!(total > 0)) {  // nothing weighs it (an unweighted region): its heaviest joint alone
    s.joint[0] = order.empty() ? 0 : order[0];
    s.weight[0] = 1;
    return s;
  }
  // Rounded to float, as the runtime holds them; the tools skin with these very weights.
  for (size_t k = 0; k < keep; ++k) {
    s.joint[k] = order[k];
    s.weight[k] = float(std::max(0.0, weights[order[k]]) / total);
  }
  return s;
}

Eigen::Vector3d skin_point(const SkinInfluence& s, const JointMatrices& m) {
  Eigen::Vector3d out = Eigen::Vector3d::Zero();
  for (size_t k = 0; k < 4; ++k)
    if (s.weight[k] != 0) {
      const Eigen::Matrix4d& mk = m[size_t(s.joint[k])];
      out += double(s.weight[k]) * (mk.topLeftCorner<3, 3>() * s.bind + mk.topRightCorner<3, 1>());
    }
  return out;
}

namespace {
// p taken to the asset's space: the inverse of s's blended rest matrix (an affine map).
Eigen::Vector3d unskin_point(const SkinInfluence& s, const JointMatrices& rest, const Eigen::Vector3d& p) {
  Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  for (size_t k = 0; k < 4; ++k) {
    const Eigen::Matrix4d& m = rest[size_t(s.joint[k])];
    a += double(s.weight[k]) * m.topLeftCorner<3, 3>();
    t += double(s.weight[k]) * m.topRightCorner<3, 1>();
  }
  return a.lu().solve(p - t);
}
}  // namespace

SkinnedMap::SkinnedMap(const SkinFile& skin, const HarmonicMap& f) : skin_(skin), f_(f) {
  Eigen::MatrixXd per_vertex = Eigen::MatrixXd::Zero(Eigen::Index(skin.vertex_weights.size()), Eigen::Index(skin.joints.size()));
  for (size_t v = 0; v < skin.vertex_weights.size(); ++v)
    for (const auto& [j, w] : skin.vertex_weights[v]) per_vertex(Eigen::Index(v), j) += w;
  tet_weights_ = f.extend(per_vertex);
}

SkinInfluence SkinnedMap::influence(const Eigen::Vector3d& p, const TetLocator::Location& at) const {
  Eigen::VectorXd w = Eigen::VectorXd::Zero(tet_weights_.cols());
  const auto& tet = f_.locator().mesh().tets[size_t(at.tet)];
  for (int k = 0; k < 4; ++k) w += at.weights[k] * tet_weights_.row(tet[k]).transpose();
  SkinInfluence s = heaviest_four(w);
  s.bind = unskin_point(s, skin_.rest, p);
  return s;
}

std::vector<std::pair<Sphere, PoseSolid::Zero>> SkinnedMap::spheres(const Eigen::Vector3d& c,
                                                                     const TetLocator::Location& at,
                                                                     const std::vector<PoseSolid>& solids,
                                                                     bool cause) const {
  const SkinInfluence s = influence(c, at);
  std::vector<std::pair<Sphere, PoseSolid::Zero>> out;
  double least = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < solids.size(); ++i) {
    const Eigen::Vector3d center = this->center(s, c, i);
    const PoseSolid::Radius radius = solids[i].radius(center, cause);
    out.push_back({{center, radius.value}, radius.zero});
    least = std::min(least, radius.value);
  }
  for (auto& [sphere, zero] : out) {
    sphere.radius = least;
    if (least == 0 && zero == PoseSolid::Zero::none) zero = PoseSolid::Zero::another_pose;
  }
  return out;
}

namespace {
// The least of a sphere's radii by `solids` at its centre in each pose, asking a pose only where
// its floor is below the least so far (lowest floors first).
double least_radius(const std::vector<Eigen::Vector3d>& centers, const std::vector<PoseSolid>& solids) {
  std::vector<std::pair<double, size_t>> floors(solids.size());
  for (size_t i = 0; i < solids.size(); ++i) floors[i] = {solids[i].radius_floor(centers[i]), i};
  std::sort(floors.begin(), floors.end());
  double least = std::numeric_limits<double>::infinity();
  for (const auto& [floor, i] : floors) {
    if (floor >= least) break;
    least = std::min(least, solids[i].radius(centers[i], false).value);
  }
  return least;
}
}  // namespace

SkinnedMap::Carried SkinnedMap::carry(const SphereSet& rest, const std::vector<PoseSolid>& solids) const {
  Carried out{std::vector<std::vector<Eigen::Vector3d>>(solids.size(), std::vector<Eigen::Vector3d>(rest.size())),
              std::vector<double>(rest.size())};
  tbb::parallel_for(tbb::blocked_range<size_t>(0, rest.size(), 16), [&](const tbb::blocked_range<size_t>& r) {
    std::vector<Eigen::Vector3d> in_poses(solids.size());
    for (size_t s = r.begin(); s != r.end(); ++s) {
      const Eigen::Vector3d& c = rest[s].center;
      const SkinInfluence in = influence(c, f_.locator().locate(c));
      for (size_t i = 0; i < solids.size(); ++i) out.centers[i][s] = in_poses[i] = center(in, c, i);
      out.radii[s] = least_radius(in_poses, solids);
    }
  });
  return out;
}

ProxySkin SkinnedMap::proxy_skin(const SphereSet& rest) const {
  ProxySkin out;
  for (const SkinJoint& j : skin_.joints) {
    out.joints.push_back(j.name);
    out.parents.push_back(j.parent);
  }
  for (const Sphere& sphere : rest) {
    const SkinInfluence s = influence(sphere.center, f_.locator().locate(sphere.center));
    out.spheres.push_back({s.joint, s.weight, s.bind, sphere.radius});
  }
  return out;
}

std::vector<Eigen::Vector3d> SkinnedMap::deform_tets(size_t i) const {
  const TetMesh& tets = f_.locator().mesh();
  std::vector<Eigen::Vector3d> out(tets.vertices.size());
  for (size_t v = 0; v < out.size(); ++v) {
    SkinInfluence s = heaviest_four(tet_weights_.row(Eigen::Index(v)).transpose());
    s.bind = unskin_point(s, skin_.rest, tets.vertices[v]);
    out[v] = skin_point(s, matrices(i));
  }
  return out;
}

}  // namespace spx
