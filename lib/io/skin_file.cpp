#include "io/skin_file.hpp"

#include <cmath>

#include "core/error.hpp"
#include "core/version.hpp"

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

}  // namespace

json skin_to_json(const SkinFile& skin) {
  json joints = json::array(), weights = json::array(), poses = json::array();
  for (const auto& j : skin.joints)
    joints.push_back({{"name", j.name}, {"parent", j.parent}, {"inverse_bind", matrix_to_json(j.inverse_bind)}});
  for (const auto& vw : skin.vertex_weights) {
    json pairs = json::array();
    for (const auto& [joint, w] : vw) pairs.insert(pairs.end(), {joint, w});
    weights.push_back(pairs);
  }
  for (const auto& p : skin.poses) poses.push_back({{"name", p.name}, {"joint_matrices", matrices_to_json(p.matrices)}});
  return {{"format", kFormat},
          {"version", kVersion},
          {"generator", std::string("spx ") + version_string()},
          {"joints", joints},
          {"vertex_weights", weights},
          {"rest", {{"joint_matrices", matrices_to_json(skin.rest)}}},
          {"poses", poses},
          {"morph_channels", skin.morph_channels}};
}

SkinFile read_skin_file(const std::string& path) {
  return read_json_document(path, "skin", [&](const json& j) {
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
    const json& weights = require(j, "vertex_weights", path);
    if (!weights.is_array()) fail_input(path, "field 'vertex_weights' is not an array");
    for (size_t v = 0; v < weights.size(); ++v)
      skin.vertex_weights.push_back(weights_from_json(weights[v], joints.size(), "vertex " + std::to_string(v), path));
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
    return skin;
  });
}

}  // namespace spx
