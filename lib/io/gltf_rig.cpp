#include "io/gltf_rig.hpp"

#include "core/error.hpp"
#include "io/glb_builder.hpp"

namespace spx {

std::string encode_rig_glb(const RigAsset& asset) {
  detail::GlbBuilder b;
  json nodes = json::array(), meshes = json::array(), roots = json::array();
  const size_t joints = asset.joints.size();
  for (size_t j = 0; j < joints; ++j) {
    const RigJoint& joint = asset.joints[j];
    if (joint.parent >= int(j)) fail_usage(asset.name, "joint '" + joint.name + "' must come after its parent");
    if (joint.rotations.size() != asset.times.size())
      fail_usage(asset.name, "joint '" + joint.name + "' needs one rotation per key time");
    const Eigen::Vector3f t = detail::to_float(joint.translation);
    json node = {{"name", joint.name}, {"translation", {t.x(), t.y(), t.z()}}, {"children", json::array()}};
    if (!joint.rotations.empty()) {
      const Eigen::Quaterniond& q = joint.rotations.front();
      node["rotation"] = {float(q.x()), float(q.y()), float(q.z()), float(q.w())};
    }
    nodes.push_back(node);
    if (joint.parent < 0) roots.push_back(j);
    else nodes[size_t(joint.parent)]["children"].push_back(j);
  }
  for (const RigPart& part : asset.parts) {
    if (part.joint < 0 || size_t(part.joint) >= joints) fail_usage(asset.name, "part '" + part.name + "' names no joint");
    std::vector<Eigen::Vector3f> positions;
    for (const auto& p : part.mesh.vertices) positions.push_back(detail::to_float(p));
    const json primitive = {{"attributes", {{"POSITION", b.add_vec3(positions)}}},
                            {"indices", b.add_indices(part.mesh.triangles)},
                            {"mode", 4}};
    meshes.push_back({{"name", part.name}, {"primitives", {primitive}}});
    nodes[size_t(part.joint)]["children"].push_back(nodes.size());
    nodes.push_back({{"name", part.name}, {"mesh", meshes.size() - 1}});
  }
  for (auto& node : nodes)
    if (node.contains("children") && node["children"].empty()) node.erase("children");
  json doc = {{"asset", {{"version", "2.0"}, {"generator", "spx"}}},
              {"scene", 0},
              {"scenes", {{{"name", asset.name}, {"nodes", roots}}}},
              {"nodes", nodes},
              {"meshes", meshes}};
  if (!asset.times.empty()) {
    std::vector<float> times(asset.times.begin(), asset.times.end());
    const int input = b.add_floats(times, true);
    json samplers = json::array(), channels = json::array();
    for (size_t j = 0; j < joints; ++j) {
      std::vector<float> xyzw;
      for (const auto& q : asset.joints[j].rotations)
        for (double c : {q.x(), q.y(), q.z(), q.w()}) xyzw.push_back(float(c));
      samplers.push_back({{"input", input}, {"output", b.add_vec4(xyzw)}, {"interpolation", "LINEAR"}});
      channels.push_back({{"sampler", j}, {"target", {{"node", j}, {"path", "rotation"}}}});
    }
    doc["animations"] = json::array({json{{"name", asset.name}, {"samplers", samplers}, {"channels", channels}}});
  }
  return b.glb(std::move(doc));
}

}  // namespace spx
