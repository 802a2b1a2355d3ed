// Reads a proxy-export --physics .glb back through assimp and checks every collider against the
// .spx: one node per sphere of radius > 0 (none for radius 0), its centre where the runtime puts
// it at rest (the .spx rest pose; with the asset, the sphere on its heaviest joint at the
// asset's rest) and its shape's radius (times the node's world scale) the sphere's, within float
// rounding; with the asset, its meshes, skin and clips read the same from both files.
// usage: physics_readback OUT.glb PROXY.spx [ASSET]
#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <cstdio>
#include <map>
#include <string>

#include "extract/asset.hpp"
#include "core/gltf_file.hpp"
#include "mesh/assimp_scene.hpp"
#include "spx_runtime.h"

namespace {

int failures = 0;
void expect(bool ok, const std::string& what) {
  if (!ok && failures++ < 10) std::printf("FAIL: %s\n", what.c_str());
}

// Every node named spx-sphere-<j>: its world transform.
std::map<int, Eigen::Matrix4d> sphere_nodes(const aiNode& root) {
  std::map<int, Eigen::Matrix4d> out;
  for (const auto& [node, world] : spx::node_globals(root)) {
    const std::string name = node->mName.C_Str();
    if (name.rfind("spx-sphere-", 0) != 0) continue;
    const int j = std::stoi(name.substr(11));
    expect(!out.count(j), name + " twice");
    out[j] = world;
  }
  return out;
}

// The asset as pose-extract reads it, from the original and from the export.
void compare_assets(const std::string& original, const std::string& exported) {
  const spx::Asset a(original, ""), b(exported, "");
  expect(a.vertex_count() == b.vertex_count() && a.triangles() == b.triangles(), "the asset's meshes changed");
  expect(a.rest() == b.rest(), "the asset's rest positions changed");
  expect(a.joints().size() == b.joints().size(), "the asset's skin changed");
  expect(a.clips().size() == b.clips().size(), "the asset's clips changed");
  for (size_t c = 0; c < a.clips().size() && c < b.clips().size(); ++c) {
    expect(a.clips()[c].name == b.clips()[c].name && a.clips()[c].frames == b.clips()[c].frames, "a clip changed");
    for (double t : {0.0, 0.37 * a.clips()[c].end, a.clips()[c].end})
      expect(a.at_time(c, t) == b.at_time(c, t), "the clip plays differently at " + std::to_string(t) + " s");
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) return std::printf("usage: physics_readback OUT.glb PROXY.spx [ASSET]\n"), 2;
  const std::string glb = argv[1], spx_path = argv[2], asset = argc > 3 ? argv[3] : "";
  spx::Proxy proxy;
  if (spx::load_file(spx_path.c_str(), &proxy) != spx::SPX_OK) return std::printf("cannot read %s\n", argv[2]), 2;
  const spx::json doc = spx::read_gltf_file(glb).doc;
  Assimp::Importer importer;
  const aiScene* scene = importer.ReadFile(glb, 0);
  if (!scene) return std::printf("assimp cannot read %s: %s\n", argv[1], importer.GetErrorString()), 1;
  const std::map<int, Eigen::Matrix4d> nodes = sphere_nodes(*scene->mRootNode);

  // Where each sphere should be at rest: the .spx's rest, or on its heaviest joint in the asset.
  const uint32_t n = proxy.sphere_count();
  std::vector<Eigen::Vector4d> want(n);
  const float* rest = proxy.pose_spheres(0);
  for (uint32_t j = 0; j < n; ++j) want[j] = Eigen::Vector4d(rest[4 * j], rest[4 * j + 1], rest[4 * j + 2], rest[4 * j + 3]);
  double scale = 0;
  for (const auto& w : want) scale = std::max(scale, w.head<3>().norm() + w[3]);
  if (!asset.empty() && proxy.has_skin()) {
    const spx::Asset rig(asset, "");
    std::vector<std::string> names;
    for (uint32_t k = 0; k < proxy.joint_count(); ++k) names.push_back(proxy.joint_name(k));
    const std::vector<size_t> joint_of = rig.joints_named(names);
    const std::vector<Eigen::Matrix4d> m = rig.rest_joint_matrices();
    for (uint32_t j = 0; j < n; ++j) {
      const float* s = proxy.skin_spheres() + 8 * j;
      const int heaviest = int(std::max_element(s + 4, s + 8) - (s + 4));
      const Eigen::Vector4d c(s[0], s[1], s[2], 1);
      want[j] << (m[joint_of[proxy.skin_joints()[4 * j + size_t(heaviest)]]] * c).head<3>(), s[3];
    }
  }
  const spx::json& shapes = doc["extensions"]["KHR_implicit_shapes"]["shapes"];
  size_t colliders = 0;
  for (uint32_t j = 0; j < n; ++j) {
    const auto it = nodes.find(int(j));
    if (!(want[j][3] > 0)) {
      expect(it == nodes.end(), "sphere " + std::to_string(j) + " has radius 0 but a collider");
      continue;
    }
    if (it == nodes.end()) {
      expect(false, "sphere " + std::to_string(j) + " has no collider node");
      continue;
    }
    ++colliders;
    const Eigen::Vector3d centre = it->second.col(3).head<3>();
    const double world_scale = std::cbrt(std::abs(it->second.topLeftCorner<3, 3>().determinant()));
    // The node's collider shape, found in the document by the node's name.
    double radius = -1;
    for (const auto& node : doc["nodes"])
      if (node.value("name", "") == "spx-sphere-" + std::to_string(j))
        radius = shapes.at(node["extensions"]["KHR_physics_rigid_bodies"]["collider"]["geometry"]["shape"].get<size_t>())
                     ["sphere"]["radius"].get<double>();
    const double tol = 2e-6 * scale;
    expect((centre - want[j].head<3>()).norm() <= tol, "sphere " + std::to_string(j) + " centre off by " +
                                                           std::to_string((centre - want[j].head<3>()).norm()));
    expect(std::abs(radius * world_scale - want[j][3]) <= tol, "sphere " + std::to_string(j) + " radius " +
                                                                   std::to_string(radius * world_scale) + " not " +
                                                                   std::to_string(want[j][3]));
  }
  expect(nodes.size() == colliders, "collider nodes that are no sphere of the proxy");
  if (!asset.empty()) compare_assets(asset, glb);
  if (failures) return std::printf("%d failures\n", failures), 1;
  std::printf("%s: %zu colliders match %s\n", glb.c_str(), colliders, spx_path.c_str());
  return 0;
}
