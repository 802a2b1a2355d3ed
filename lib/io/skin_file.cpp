#include "io/skin_file.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>

#include "core/error.hpp"
#include "core/version.hpp"
#include "runtime/spx_runtime.h"

namespace spx {
namespace {
constexpr const char* kFormat = "spx.skin";
constexpr int kVersion = 1;

json matrix_to_json(const Eigen::Matrix4d& m) {
  json out = json::array();
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) out.push_back(m(r, c));  // column-major, as the runtime takes them
  return out;
}

json matrices_to_json(const JointMatrices& ms) {
  json out = json::array();
  for (const auto& m : ms) out.push_back(matrix_to_json(m));
  return out;
}

Eigen::Matrix4d matrix_from_json(const json& j, const std::string& what, const std::string& path) {
  if (!j.is_array() || j.size() != 16) fail_input(path, what + " is not 16 numbers (a column-major 4x4 matrix)");
  Eigen::Matrix4d m;
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) m(r, c) = as_finite_number(j[size_t(4 * c + r)], what, path);
  return m;
}

JointMatrices matrices_from_json(const json& j, size_t joints, const std::string& what, const std::string& path) {
  if (!j.is_array() || j.size() != joints)
    fail_input(path, what + " does not hold one matrix per joint (" + std::to_string(joints) + ")");
  JointMatrices out;
  for (size_t i = 0; i < j.size(); ++i) out.push_back(matrix_from_json(j[i], what + " " + std::to_string(i), path));
  return out;
}

JointWeights weights_from_json(const json& j, size_t joints, const std::string& what, const std::string& path) {
  if (!j.is_array() || j.size() % 2) fail_input(path, what + " is not a list of joint, weight pairs");
  JointWeights out;
  for (size_t k = 0; k < j.size(); k += 2) {
    if (!j[k].is_number_integer() || j[k].get<long long>() < 0 || size_t(j[k].get<long long>()) >= joints)
      fail_input(path, what + ": joint index out of range (the skin has " + std::to_string(joints) + " joints)");
    const double w = as_finite_number(j[k + 1], what, path);
    if (w < 0) fail_input(path, what + ": negative weight");
    out.emplace_back(j[k].get<int>(), w);
  }
  return out;
}

SkinClip clip_from_json(const json& j, size_t joints, const std::string& path) {
  SkinClip clip;
  clip.name = require_string(j, "name", path);
  const json& times = require(j, "times", path);
  const json& matrices = require(j, "joint_matrices", path);
  if (!times.is_array() || !matrices.is_array() || times.size() != matrices.size())
    fail_input(path, "field 'clip' does not hold one list of joint matrices per time");
  for (size_t k = 0; k < times.size(); ++k) {
    const std::string what = "clip time " + std::to_string(k);
    clip.times.push_back(as_finite_number(times[k], what, path));
    clip.matrices.push_back(matrices_from_json(matrices[k], joints, what + " joint_matrices", path));
  }
  return clip;
}

}  // namespace

json skin_to_json(const SkinFile& skin) {
  json joints = json::array(), weights = json::array(), poses = json::array();
  for (const auto& j : skin.joints)
    joints.push_back({{"name", j.name}, {"parent", j.parent}, {"inverse_bind", matrix_to_json(j.inverse_bind)}});
  json positions = json::array();
  for (const auto& p : skin.vertex_positions) positions.push_back({p.x(), p.y(), p.z()});
  for (const auto& vw : skin.vertex_weights) {
    json pairs = json::array();
    for (const auto& [joint, w] : vw) pairs.insert(pairs.end(), {joint, w});
    weights.push_back(pairs);
  }
  for (const auto& p : skin.poses) poses.push_back({{"name", p.name}, {"joint_matrices", matrices_to_json(p.matrices)}});
  json out = {{"format", kFormat},
          {"version", kVersion},
          {"generator", std::string("spx ") + version_string()},
          {"joints", joints},
          {"vertex_positions", positions},
          {"vertex_weights", weights},
          {"rest", {{"joint_matrices", matrices_to_json(skin.rest)}}},
          {"poses", poses},
          {"morph_channels", skin.morph_channels}};
  if (!skin.clip.empty()) {
    json matrices = json::array();
    for (const auto& m : skin.clip.matrices) matrices.push_back(matrices_to_json(m));
    out["clip"] = {{"name", skin.clip.name}, {"times", skin.clip.times}, {"joint_matrices", matrices}};
  }
  return out;
}

void require_joint_tree(const std::vector<int>& parents, const std::string& field, const std::string& path) {
  std::vector<uint32_t> marks(parents.size());
  const int64_t off = detail::joint_off_the_tree(
      uint32_t(parents.size()), [&](uint32_t j) { return int64_t(parents[j]); }, marks.data());
  if (off >= 0)
    fail_input(path, field + ": following joint " + std::to_string(off) +
                         "'s parents never reaches a root (-1): they form a cycle");
}

SkinFile read_skin_file(const std::string& path) {
  return read_json_document(path, "skin", [&](const json& j) { return skin_from_json(j, path); });
}

SkinFile skin_from_json(const json& j, const std::string& path) {
  require_header(j, kFormat, "skin", kVersion, path);
  SkinFile skin;
  const json& joints = require(j, "joints", path);
  if (!joints.is_array() || joints.empty()) fail_input(path, "field 'joints' is not a list of joints");
  for (size_t i = 0; i < joints.size(); ++i) {
    const std::string what = "joint " + std::to_string(i);
    SkinJoint joint;
    joint.name = require_string(joints[i], "name", path);
    const json& parent = require(joints[i], "parent", path);
    if (!parent.is_number_integer() || parent.get<long long>() < -1 || parent.get<long long>() >= (long long)joints.size() ||
        parent.get<long long>() == (long long)i)
      fail_input(path, what + ": parent is not -1 or another joint");
    joint.parent = parent.get<int>();
    joint.inverse_bind = matrix_from_json(require(joints[i], "inverse_bind", path), what + " inverse_bind", path);
    skin.joints.push_back(joint);
  }
  std::vector<int> parents;
  for (const SkinJoint& joint : skin.joints) parents.push_back(joint.parent);
  require_joint_tree(parents, "joints", path);
  const json& weights = require(j, "vertex_weights", path);
  if (!weights.is_array()) fail_input(path, "field 'vertex_weights' is not an array");
  for (size_t v = 0; v < weights.size(); ++v)
    skin.vertex_weights.push_back(weights_from_json(weights[v], joints.size(), "vertex " + std::to_string(v), path));
  const json& positions = require(j, "vertex_positions", path);
  if (!positions.is_array() || positions.size() != weights.size())
    fail_input(path, "field 'vertex_positions' does not hold one position per weighted vertex");
  for (size_t v = 0; v < positions.size(); ++v) {
    const std::string what = "vertex_positions[" + std::to_string(v) + "]";
    if (!positions[v].is_array() || positions[v].size() != 3) fail_input(path, what + " is not [x, y, z]");
    Eigen::Vector3d p;
    for (int k = 0; k < 3; ++k) p[k] = as_finite_number(positions[v][size_t(k)], what, path);
    skin.vertex_positions.push_back(p);
  }
  skin.rest = matrices_from_json(require(require(j, "rest", path), "joint_matrices", path), joints.size(),
                                 "rest joint_matrices", path);
  const json& poses = require(j, "poses", path);
  if (!poses.is_array()) fail_input(path, "field 'poses' is not an array");
  for (const json& p : poses) {
    SkinPose pose;
    pose.name = require_string(p, "name", path);
    pose.matrices = matrices_from_json(require(p, "joint_matrices", path), joints.size(),
                                       "pose '" + pose.name + "' joint_matrices", path);
    skin.poses.push_back(std::move(pose));
  }
  skin.morph_channels = j.value("morph_channels", size_t(0));
  if (j.contains("clip")) skin.clip = clip_from_json(j["clip"], joints.size(), path);
  return skin;
}

std::vector<JointWeights> weights_for_vertices(const SkinFile& skin, const std::vector<Eigen::Vector3d>& vertices,
                                               double tolerance, const std::string& path) {
  // The skin's vertices sorted by x; each mesh vertex looks in its x slab for the nearest.
  const auto& at = skin.vertex_positions;
  std::vector<size_t> order(at.size());
  std::iota(order.begin(), order.end(), size_t(0));
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return at[a].x() < at[b].x(); });
  std::vector<JointWeights> out;
  for (size_t v = 0; v < vertices.size(); ++v) {
    const Eigen::Vector3d& p = vertices[v];
    auto lo = std::lower_bound(order.begin(), order.end(), p.x() - tolerance, [&](size_t i, double x) { return at[i].x() < x; });
    size_t best = at.size();
    double best_d = tolerance;
    for (auto it = lo; it != order.end() && at[*it].x() <= p.x() + tolerance; ++it) {
      const double d = (at[*it] - p).norm();
      if (d <= best_d) best = *it, best_d = d;
    }
    if (best == at.size())
      fail_input(path, "has no vertex at the rest mesh's vertex " + std::to_string(v) +
                           " (is it the skin of another mesh, or of another rest pose?)");
    out.push_back(skin.vertex_weights[best]);
  }
  return out;
}

void append_midpoint_weights(std::vector<JointWeights>& weights, const std::vector<std::pair<int, int>>& ends) {
  for (const auto& [a, b] : ends) {
    std::map<int, double> sum;  // by joint, ascending
    for (int end : {a, b})
      for (const auto& [joint, w] : weights[size_t(end)]) sum[joint] += 0.5 * w;
    weights.emplace_back(sum.begin(), sum.end());
  }
}

}  // namespace spx
