#include "export/physics_gltf.hpp"

#include "metrics/rest_match.hpp"

#include <algorithm>
#include <cmath>

#include "core/error.hpp"
#include "core/version.hpp"
#include "extract/asset.hpp"

namespace spx {
namespace {

constexpr const char* kExtensions[] = {"KHR_implicit_shapes", "KHR_physics_rigid_bodies", "OMI_physics_shape",
                                       "OMI_physics_body"};

// A sphere shape in both extensions' top-level arrays (after any the asset has).
struct ShapeIndex {
  size_t khr = 0, omi = 0;
};
ShapeIndex add_sphere_shape(json& doc, double radius) {
  const json shape = {{"type", "sphere"}, {"sphere", {{"radius", radius}}}};
  json& khr = doc["extensions"]["KHR_implicit_shapes"]["shapes"];
  json& omi = doc["extensions"]["OMI_physics_shape"]["shapes"];
  khr.push_back(shape);
  omi.push_back(shape);
  return {khr.size() - 1, omi.size() - 1};
}

json collider_node(int sphere, const Eigen::Vector3d& t, ShapeIndex shape) {
  json ext = {{"KHR_physics_rigid_bodies", {{"collider", {{"geometry", {{"shape", shape.khr}}}}}}},
              {"OMI_physics_body", {{"collider", {{"shape", shape.omi}}}}}};
  return {{"name", "spx-sphere-" + std::to_string(sphere)}, {"translation", {t.x(), t.y(), t.z()}}, {"extensions", ext}};
}

// A body the host moves (by animation or by hand), not the solver.
void make_kinematic(json& node) {
  node["extensions"]["KHR_physics_rigid_bodies"]["motion"] = {{"isKinematic", true}};
  node["extensions"]["OMI_physics_body"]["motion"] = {{"type", "kinematic"}};
}

void declare_extensions(json& doc) {
  json& used = doc["extensionsUsed"];
  for (const char* name : kExtensions)
    if (std::find(used.begin(), used.end(), name) == used.end()) used.push_back(name);
}

size_t add_child(json& doc, json node, long parent) {
  doc["nodes"].push_back(std::move(node));
  const size_t index = doc["nodes"].size() - 1;
  if (parent >= 0) doc["nodes"][size_t(parent)]["children"].push_back(index);
  return index;
}

// The rest spheres (pose 0) as colliders under a new kinematic body node; returns its index.
size_t add_body(PhysicsGltf& out, const ProxyModel& proxy) {
  json& doc = out.file.doc;
  json body = {{"name", "spx-proxy"}};
  make_kinematic(body);
  const long b = long(add_child(doc, std::move(body), -1));
  const SphereSet& rest = proxy.poses.at(0).spheres;
  for (size_t j = 0; j < rest.size(); ++j) {
    if (!(rest[j].radius > 0)) {
      out.zero_radius.push_back(int(j));
      continue;
    }
    add_child(doc, collider_node(int(j), rest[j].center, add_sphere_shape(doc, rest[j].radius)), b);
    ++out.colliders;
  }
  return size_t(b);
}

// The node of a joint as assimp names it: its glTF name, or "nodes[i]" for an unnamed node i.
long node_named(const json& doc, const std::string& name) {
  const json& nodes = doc["nodes"];
  for (size_t n = 0; n < nodes.size(); ++n)
    if (nodes[n].contains("name") ? nodes[n]["name"] == name : name == "nodes[" + std::to_string(n) + "]") return long(n);
  return -1;
}

// Each node's parent (-1 for a root): glTF nodes name their children, not their parent.
std::vector<long> parents_of(const json& doc, const std::string& path) {
  const json& nodes = doc["nodes"];
  std::vector<long> parent(nodes.size(), -1);
  for (size_t n = 0; n < nodes.size(); ++n)
    for (const json& c : nodes[n].value("children", json::array())) {
      if (!c.is_number_unsigned() || c.get<size_t>() >= nodes.size() || parent[c.get<size_t>()] >= 0)
        fail_input(path, "node " + std::to_string(n) + " names a child that is no node or already has a parent");
      parent[c.get<size_t>()] = long(n);
    }
  return parent;
}

int heaviest(const SkinnedSphere& s) { return int(std::max_element(s.weight.begin(), s.weight.end()) - s.weight.begin()); }

// A skinned proxy's spheres on their heaviest joints' nodes, in those joints' frames at bind.
void attach_to_joints(PhysicsGltf& out, const ProxyModel& proxy, const Asset& rig) {
  json& doc = out.file.doc;
  const std::vector<size_t> joint_of = rig.joints_named(proxy.skin.joints);
  const std::vector<Eigen::Matrix4d> rest = rig.rest_joint_matrices();
  const std::vector<long> parent = parents_of(doc, rig.path());  // of the asset's nodes; colliders are leaves
  std::vector<size_t> bodies, used(proxy.skin.joints.size(), 0);
  for (size_t j = 0; j < proxy.skin.spheres.size(); ++j) {
    const SkinnedSphere& s = proxy.skin.spheres[j];
    if (!(s.radius > 0)) {
      out.zero_radius.push_back(int(j));
      continue;
    }
    const int joint = s.joint[size_t(heaviest(s))];
    const AssetJoint& aj = rig.joints()[joint_of[size_t(joint)]];
    const long node = node_named(doc, aj.name);
    if (node < 0) fail_input(rig.path(), "has no node named '" + aj.name + "' for the joint the proxy's skin names");
    // The joint's frame at bind is the inverse bind's; its world scale (rest matrix x bind)
    // would scale the radius, so the shape is given in the node's units.
    const Eigen::Matrix4d global = rest[joint_of[size_t(joint)]] * aj.inverse_bind.inverse();
    const double scale = std::cbrt(std::abs(global.topLeftCorner<3, 3>().determinant()));
    const Eigen::Vector3d t = (aj.inverse_bind * s.center.homogeneous()).head<3>();
    add_child(doc, collider_node(int(j), t, add_sphere_shape(doc, s.radius / scale)), node);
    ++out.colliders;
    ++used[size_t(joint)];
    size_t root = size_t(node);
    for (size_t up = 0; parent[root] >= 0 && up < parent.size(); ++up) root = size_t(parent[root]);
    if (std::find(bodies.begin(), bodies.end(), root) == bodies.end()) bodies.push_back(root);
  }
  for (size_t root : bodies) make_kinematic(doc["nodes"][root]);
  json joints = json::object();
  for (size_t k = 0; k < used.size(); ++k)
    if (used[k] > 0) joints[proxy.skin.joints[k]] = used[k];
  out.attachment = {{"spheres_per_joint", joints}, {"bodies", bodies}};
}

// An asset the colliders can go into: not one this tool already put a proxy's colliders in (a
// host would collide with both sets), and with a list to append each extension's shapes to.
void check_asset_takes_colliders(const json& doc, const std::string& path) {
  for (const json& node : doc.value("nodes", json::array())) {
    const json name = node.value("name", json());
    if (name.is_string() && (name == "spx-proxy" || name.get<std::string>().rfind("spx-sphere-", 0) == 0))
      fail_input(path, "already holds a proxy's colliders (node '" + name.get<std::string>() +
                           "'): give the asset without them");
  }
  if (!doc.contains("extensions")) return;
  for (const char* ext : {"KHR_implicit_shapes", "OMI_physics_shape"}) {
    const json list = doc["extensions"].value(ext, json::object());
    if (!list.is_object() || (list.contains("shapes") && !list["shapes"].is_array()))
      fail_input(path, std::string("its extension ") + ext + " has no list of shapes to add the spheres to");
  }
}

}  // namespace

PhysicsGltf physics_gltf(const ProxyModel& proxy) {
  PhysicsGltf out;
  out.file.doc = {{"asset", {{"version", "2.0"}, {"generator", std::string("spx proxy-export ") + version_string()}}},
                  {"scene", 0}, {"nodes", json::array()}};
  const size_t body = add_body(out, proxy);
  out.file.doc["scenes"] = json::array({{{"nodes", {body}}}});
  declare_extensions(out.file.doc);
  return out;
}

PhysicsGltf physics_gltf(const ProxyModel& proxy, GltfFile asset, const Asset& rig) {
  PhysicsGltf out;
  out.diagonal = check_rest_holds(proxy, weld_body(rig).rest, rig.path());
  check_asset_takes_colliders(asset.doc, rig.path());
  out.file = std::move(asset);
  json& doc = out.file.doc;
  if (!doc.contains("nodes")) doc["nodes"] = json::array();
  if (!proxy.skin.empty()) {
    attach_to_joints(out, proxy, rig);
  } else {
    const size_t body = add_body(out, proxy);
    if (!doc.contains("scenes") || doc["scenes"].empty()) doc["scenes"] = json::array({json::object()}), doc["scene"] = 0;
    doc["scenes"][doc.value("scene", size_t(0))]["nodes"].push_back(body);
  }
  declare_extensions(doc);
  return out;
}

json rigid_attachment_offsets(const ProxyModel& proxy, const Asset& rig, size_t clip, double diagonal) {
  const std::vector<size_t> joint_of = rig.joints_named(proxy.skin.joints);
  const AssetClip& c = rig.clips().at(clip);
  std::vector<double> worst(proxy.skin.spheres.size(), 0);
  for (double t : c.frames) {
    const std::vector<Eigen::Matrix4d> m = rig.joint_matrices(clip, t);
    for (size_t j = 0; j < worst.size(); ++j) {
      const SkinnedSphere& s = proxy.skin.spheres[j];
      if (!(s.radius > 0)) continue;
      Eigen::Vector3d skinned = Eigen::Vector3d::Zero();
      for (size_t k = 0; k < 4; ++k)
        skinned += double(s.weight[k]) * (m[joint_of[size_t(s.joint[k])]] * s.center.homogeneous()).head<3>();
      const Eigen::Vector3d rigid = (m[joint_of[size_t(s.joint[size_t(heaviest(s))])]] * s.center.homogeneous()).head<3>();
      worst[j] = std::max(worst[j], (rigid - skinned).norm());
    }
  }
  std::vector<double> sorted = worst;
  std::sort(sorted.begin(), sorted.end());
  const double median = sorted.empty() ? 0 : sorted[sorted.size() / 2];
  return {{"clip", c.name},
          {"frames", c.frames.size()},
          {"centre_offset_pct", {{"median_sphere", 100 * median / diagonal},
                                 {"worst", 100 * (sorted.empty() ? 0 : sorted.back()) / diagonal}}},
          {"error", "proxy-eval --asset measures the vertex error of this attachment (runtime rigid_per_bone)"}};
}

}  // namespace spx
