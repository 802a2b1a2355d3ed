#include "posemap/skinned_map.hpp"

#include <Eigen/LU>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <algorithm>
#include <limits>
#include <numeric>
#include <utility>

#include "mesh/split.hpp"

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
Eigen::Matrix4d blend(const JointWeights& w, const JointMatrices& m) {
  Eigen::Matrix4d sum = Eigen::Matrix4d::Zero();
  for (const auto& [joint, weight] : w) sum += weight * m[size_t(joint)];
  return sum;
}
}  // namespace

SkinnedVertices::SkinnedVertices(const SkinFile& skin, const std::vector<Eigen::Vector3d>& rest)
    : weights_(skin.vertex_weights), bind_(rest), bound_(rest.size(), 0) {
  for (size_t v = 0; v < rest.size(); ++v) {
    if (weights_[v].empty()) continue;
    const Eigen::FullPivLU<Eigen::Matrix4d> at_rest(blend(weights_[v], skin.rest));
    if (!at_rest.isInvertible()) continue;
    bind_[v] = at_rest.solve(rest[v].homogeneous()).head<3>();
    bound_[v] = 1;
  }
}

Eigen::Vector3d SkinnedVertices::at(size_t v, const JointMatrices& m) const {
  return bound_[v] ? Eigen::Vector3d((blend(weights_[v], m) * bind_[v].homogeneous()).head<3>()) : bind_[v];
}

std::vector<Eigen::Vector3d> SkinnedVertices::all(const JointMatrices& m) const {
  std::vector<Eigen::Vector3d> out(bind_.size());
  for (size_t v = 0; v < out.size(); ++v) out[v] = at(v, m);
  return out;
}

SplitSkinned split_skinned(const TriMesh& rest, SkinFile skin, int times) {
  SplitSkinned out;
  std::vector<std::pair<int, int>> ends;
  out.rest = split_at_midpoints(rest, times, &ends);
  append_midpoint_weights(skin.vertex_weights, ends);
  skin.vertex_positions = out.rest.vertices;
  out.skin = std::move(skin);
  const SkinnedVertices skinned(out.skin, out.rest.vertices);
  for (const SkinPose& pose : out.skin.poses) out.poses.push_back({skinned.all(pose.matrices), out.rest.triangles});
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
  vertex_weights_ = Eigen::MatrixXd::Zero(Eigen::Index(skin.vertex_weights.size()), Eigen::Index(skin.joints.size()));
  for (size_t v = 0; v < skin.vertex_weights.size(); ++v)
    for (const auto& [j, w] : skin.vertex_weights[v]) vertex_weights_(Eigen::Index(v), j) += w;
  tet_weights_ = f.extend(vertex_weights_);
}

SkinInfluence SkinnedMap::influence(const Eigen::Vector3d& p, const TetLocator::Location& at) const {
  Eigen::VectorXd w = Eigen::VectorXd::Zero(tet_weights_.cols());
  const auto& tet = f_.locator().mesh().tets[size_t(at.tet)];
  for (int k = 0; k < 4; ++k) w += at.weights[k] * tet_weights_.row(tet[k]).transpose();
  SkinInfluence s = heaviest_four(w);
  s.bind = unskin_point(s, skin_.rest, p);
  return s;
}

SkinInfluence SkinnedMap::surface_influence(const Eigen::Vector3d& p, const MeshQuery& rest,
                                            const ClosestPoint& q) const {
  const auto& t = rest.mesh().triangles[size_t(q.triangle)];
  const Eigen::VectorXd w = q.barycentric[0] * vertex_weights_.row(t[0]).transpose() +
                            q.barycentric[1] * vertex_weights_.row(t[1]).transpose() +
                            q.barycentric[2] * vertex_weights_.row(t[2]).transpose();
  SkinInfluence s = heaviest_four(w);
  s.bind = unskin_point(s, skin_.rest, p);
  return s;
}

namespace {
bool same_weights(const SkinInfluence& a, const SkinInfluence& b) { return a.joint == b.joint && a.weight == b.weight; }

// The least of the radii by `solids` of a sphere following `s` from rest centre c, asking a pose
// only where its floor is below the least so far (lowest floors first); given up as soon as it
// is at most `beaten` (the radius another influence keeps). `kept`, where given, gets per pose a
// radius the pose was found to keep (its radius asked, or one surely_at_least told), 0 where
// the pose was not asked.
double least_radius(const SkinnedMap& map, const SkinInfluence& s, const Eigen::Vector3d& c,
                    const std::vector<PoseSolid>& solids, double rest_radius, double beaten,
                    std::vector<double>* kept) {
  std::vector<std::pair<double, size_t>> floors;
  std::vector<Eigen::Vector3d> centers(solids.size());
  for (size_t i = 1; i < solids.size(); ++i) {
    centers[i] = map.center(s, c, i);
    floors.push_back({solids[i].radius_floor(centers[i]), i});
  }
  std::sort(floors.begin(), floors.end());
  if (kept) {
    kept->assign(solids.size(), 0.0);
    (*kept)[0] = rest_radius;
  }
  double least = rest_radius;
  for (const auto& [floor, i] : floors) {
    if (floor >= least || least <= beaten) break;
    double r = least;
    if (!solids[i].surely_at_least(centers[i], least)) {
      r = solids[i].radius(centers[i], false).value;
      least = std::min(least, r);
    }
    if (kept) (*kept)[i] = r;
  }
  return least;
}
}  // namespace

SkinnedMap::Choice SkinnedMap::choose(const Eigen::Vector3d& c, const TetLocator::Location& at,
                                      const std::vector<PoseSolid>& solids, std::vector<double>* kept) const {
  ClosestPoint on_rest;  // asked where the rest radius is positive, as the surface's influence needs
  const double rest_radius = solids[0].radius(c, false, &on_rest).value;
  Choice harmonic{influence(c, at), 0};
  harmonic.radius = least_radius(*this, harmonic.influence, c, solids, rest_radius, -1, kept);
  if (harmonic.radius >= rest_radius || !(rest_radius > 0)) return harmonic;
  Choice surface{surface_influence(c, *solids[0].mesh, on_rest), 0};
  if (same_weights(surface.influence, harmonic.influence)) return harmonic;
  std::vector<double> surface_kept;
  surface.radius = least_radius(*this, surface.influence, c, solids, rest_radius, harmonic.radius,
                                kept ? &surface_kept : nullptr);
  if (!(surface.radius > harmonic.radius)) return harmonic;
  if (kept) *kept = std::move(surface_kept);
  return surface;
}

std::vector<std::pair<Sphere, PoseSolid::Zero>> SkinnedMap::spheres(const Eigen::Vector3d& c,
                                                                     const TetLocator::Location& at,
                                                                     const std::vector<PoseSolid>& solids, bool cause,
                                                                     SkinInfluence* followed) const {
  std::vector<double> kept;
  const Choice chosen = choose(c, at, solids, cause ? nullptr : &kept);
  if (followed) *followed = chosen.influence;
  // choose() skips the poses whose floors are above its radius: the radius written is checked
  // against every pose exactly.
  double radius = chosen.radius;
  std::vector<std::pair<Sphere, PoseSolid::Zero>> out;
  for (size_t i = 0; i < solids.size(); ++i) {
    const Eigen::Vector3d center = this->center(chosen.influence, c, i);
    // Without the causes (a refinement's trial), a pose that surely keeps the radius so far asks
    // no exact query: the least is the same. choose() found what most poses keep, by the same
    // tests (its radius trusts the floor for inside as surely_at_least does); the radius only
    // falls from there, so those poses keep it still.
    if (!cause && ((radius > 0 && kept[i] >= radius) || solids[i].surely_at_least(center, radius))) {
      out.push_back({{center, 0}, PoseSolid::Zero::none});
      continue;
    }
    const PoseSolid::Radius exact = solids[i].exact_radius(center, cause);
    radius = std::min(radius, exact.value);
    out.push_back({{center, 0}, exact.zero});
  }
  for (auto& [sphere, zero] : out) {
    sphere.radius = radius;
    if (radius == 0 && zero == PoseSolid::Zero::none) zero = PoseSolid::Zero::another_pose;
  }
  return out;
}

SkinnedMap::Carried SkinnedMap::carry(const SphereSet& rest, const std::vector<PoseSolid>& solids) const {
  return carried(rest, choices(rest, solids), solids.size());
}

std::vector<SkinnedMap::Choice> SkinnedMap::choices(const SphereSet& rest, const std::vector<PoseSolid>& solids) const {
  std::vector<Choice> out(rest.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, rest.size(), 16), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t s = r.begin(); s != r.end(); ++s) out[s] = choose(rest[s].center, f_.locator().locate(rest[s].center), solids);
  });
  return out;
}

SkinnedMap::Carried SkinnedMap::carried(const SphereSet& rest, const std::vector<Choice>& chosen, size_t poses) const {
  Carried out{std::vector<std::vector<Eigen::Vector3d>>(poses, std::vector<Eigen::Vector3d>(rest.size())),
              std::vector<double>(rest.size()), std::vector<SkinInfluence>(rest.size())};
  tbb::parallel_for(tbb::blocked_range<size_t>(0, rest.size(), 256), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t s = r.begin(); s != r.end(); ++s) {
      for (size_t i = 0; i < poses; ++i) out.centers[i][s] = center(chosen[s].influence, rest[s].center, i);
      out.radii[s] = chosen[s].radius;
      out.influences[s] = chosen[s].influence;
    }
  });
  return out;
}

ProxySkin SkinnedMap::proxy_skin(const SphereSet& rest, const std::vector<SkinInfluence>& influences) const {
  ProxySkin out;
  for (const SkinJoint& j : skin_.joints) {
    out.joints.push_back(j.name);
    out.parents.push_back(j.parent);
  }
  for (size_t i = 0; i < rest.size(); ++i)
    out.spheres.push_back({influences[i].joint, influences[i].weight, influences[i].bind, rest[i].radius});
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
