#include "io/scene.hpp"

#include <assimp/Exporter.hpp>
#include <assimp/material.h>
#include <assimp/scene.h>

#include <cmath>
#include <cstring>
#include <map>

#include "core/error.hpp"
#include "core/version.hpp"

namespace spx {
namespace {

TriMesh icosphere(int subdivisions) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  TriMesh m;
  for (auto v : {Eigen::Vector3d(-1, t, 0), Eigen::Vector3d(1, t, 0), Eigen::Vector3d(-1, -t, 0),
                 Eigen::Vector3d(1, -t, 0), Eigen::Vector3d(0, -1, t), Eigen::Vector3d(0, 1, t),
                 Eigen::Vector3d(0, -1, -t), Eigen::Vector3d(0, 1, -t), Eigen::Vector3d(t, 0, -1),
                 Eigen::Vector3d(t, 0, 1), Eigen::Vector3d(-t, 0, -1), Eigen::Vector3d(-t, 0, 1)})
    m.vertices.push_back(v.normalized());
  m.triangles = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                 {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                 {3, 8, 9},  {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (int s = 0; s < subdivisions; ++s) {
    std::map<std::pair<int, int>, int> mid;
    auto midpoint = [&](int a, int b) {
      auto key = std::minmax(a, b);
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      m.vertices.push_back((m.vertices[size_t(a)] + m.vertices[size_t(b)]).normalized());
      return mid[key] = int(m.vertices.size() - 1);
    };
    std::vector<Eigen::Vector3i> next;
    for (const auto& f : m.triangles) {
      const int a = midpoint(f[0], f[1]), b = midpoint(f[1], f[2]), c = midpoint(f[2], f[0]);
      next.insert(next.end(), {{f[0], a, c}, {f[1], b, a}, {f[2], c, b}, {a, b, c}});
    }
    m.triangles = next;
  }
  return m;
}

aiMesh* to_ai_mesh(const TriMesh& m, const std::vector<Eigen::Vector3f>& colors, const std::string& name) {
  auto* mesh = new aiMesh();
  mesh->mName = name;
  mesh->mPrimitiveTypes = aiPrimitiveType_TRIANGLE;
  mesh->mNumVertices = unsigned(m.vertices.size());
  mesh->mVertices = new aiVector3D[m.vertices.size()];
  for (size_t i = 0; i < m.vertices.size(); ++i)
    mesh->mVertices[i] = aiVector3D(ai_real(m.vertices[i].x()), ai_real(m.vertices[i].y()), ai_real(m.vertices[i].z()));
  mesh->mNumFaces = unsigned(m.triangles.size());
  mesh->mFaces = new aiFace[m.triangles.size()];
  for (size_t f = 0; f < m.triangles.size(); ++f) {
    aiFace& face = mesh->mFaces[f];
    face.mNumIndices = 3;
    face.mIndices = new unsigned[3]{unsigned(m.triangles[f][0]), unsigned(m.triangles[f][1]), unsigned(m.triangles[f][2])};
  }
  if (colors.size() == m.vertices.size() && !colors.empty()) {
    mesh->mColors[0] = new aiColor4D[colors.size()];
    for (size_t i = 0; i < colors.size(); ++i) mesh->mColors[0][i] = aiColor4D(colors[i].x(), colors[i].y(), colors[i].z(), 1.0f);
  }
  mesh->mMaterialIndex = 0;
  return mesh;
}

// Every sphere with a positive radius as an icosphere (`subdivisions` 0..4).
TriMesh sphere_union_mesh(const SphereSet& spheres, int subdivisions) {
  const TriMesh unit = icosphere(std::clamp(subdivisions, 0, 4));
  TriMesh out;
  for (const auto& s : spheres) {
    if (!(s.radius > 0)) continue;
    const int base = int(out.vertices.size());
    for (const auto& v : unit.vertices) out.vertices.push_back(s.center + s.radius * v);
    for (const auto& f : unit.triangles) out.triangles.push_back(f.array() + base);
  }
  return out;
}

// How far apart poses are laid along x when shown side by side.
double side_by_side_step(const ProxyModel& proxy) {
  Eigen::AlignedBox3d box;
  for (const auto& s : proxy.poses.front().spheres)
    if (s.radius > 0) box.extend(s.center + Eigen::Vector3d::Constant(s.radius)).extend(s.center - Eigen::Vector3d::Constant(s.radius));
  return box.isEmpty() ? 0.0 : 1.25 * box.sizes().x();
}

// Binary little-endian PLY, written here: assimp 5.2's binary PLY exporter writes colours as
// floats under a uchar header, which other readers then misread.
std::string encode_ply(const std::vector<SceneNode>& nodes) {
  size_t nv = 0, nf = 0;
  bool colors = false;
  for (const auto& n : nodes) {
    nv += n.mesh.vertices.size();
    nf += n.mesh.triangles.size();
    colors = colors || !n.colors.empty();
  }
  std::string out = "ply\nformat binary_little_endian 1.0\ncomment spx " + std::string(version_string()) +
                    "\nelement vertex " + std::to_string(nv) + "\nproperty float x\nproperty float y\nproperty float z\n";
  if (colors) out += "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  out += "element face " + std::to_string(nf) + "\nproperty list uchar int vertex_indices\nend_header\n";
  auto put = [&out](const void* p, size_t n) { out.append(static_cast<const char*>(p), n); };
  auto put32 = [&put](uint32_t u) {
    const unsigned char b[4] = {uint8_t(u), uint8_t(u >> 8), uint8_t(u >> 16), uint8_t(u >> 24)};
    put(b, 4);
  };
  for (const auto& n : nodes)
    for (size_t i = 0; i < n.mesh.vertices.size(); ++i) {
      for (int k = 0; k < 3; ++k) {
        const float f = float(n.mesh.vertices[i][k]);
        uint32_t u;
        std::memcpy(&u, &f, 4);
        put32(u);
      }
      if (colors) {
        const Eigen::Vector3f c = n.colors.empty() ? Eigen::Vector3f(0.8f, 0.8f, 0.8f) : n.colors[i];
        for (int k = 0; k < 3; ++k) out += char(uint8_t(std::lround(std::clamp(c[k], 0.0f, 1.0f) * 255)));
      }
    }
  uint32_t base = 0;
  for (const auto& n : nodes) {
    for (const auto& t : n.mesh.triangles) {
      out += char(3);
      for (int k = 0; k < 3; ++k) put32(base + uint32_t(t[k]));
    }
    base += uint32_t(n.mesh.vertices.size());
  }
  return out;
}

}  // namespace

std::string encode_scene(const std::vector<SceneNode>& nodes, const std::string& ext) {
  const bool gltf = ext == ".glb";
  if (!gltf && ext != ".ply") fail_unsupported("", "no mesh format for '" + ext + "' (use .glb or .ply)");
  if (!gltf) return encode_ply(nodes);
  aiScene scene;
  scene.mRootNode = new aiNode("root");
  scene.mNumMaterials = 1;
  scene.mMaterials = new aiMaterial*[1]{new aiMaterial()};
  aiString material_name("spx");
  scene.mMaterials[0]->AddProperty(&material_name, AI_MATKEY_NAME);
  scene.mNumMeshes = unsigned(nodes.size());
  scene.mMeshes = new aiMesh*[nodes.size()];
  scene.mRootNode->mNumChildren = unsigned(nodes.size());
  scene.mRootNode->mChildren = new aiNode*[nodes.size()];
  for (size_t k = 0; k < nodes.size(); ++k) {
    scene.mMeshes[k] = to_ai_mesh(nodes[k].mesh, nodes[k].colors, nodes[k].name);
    auto* node = new aiNode(nodes[k].name);
    node->mParent = scene.mRootNode;
    node->mNumMeshes = 1;
    node->mMeshes = new unsigned[1]{unsigned(k)};
    scene.mRootNode->mChildren[k] = node;
  }
  Assimp::Exporter exporter;
  const aiExportDataBlob* blob = exporter.ExportToBlob(&scene, gltf ? "glb2" : "plyb");
  if (!blob) {
    rethrow_out_of_memory(exporter.GetErrorString());
    fail_write("", std::string("mesh export failed: ") + exporter.GetErrorString());
  }
  return std::string(static_cast<const char*>(blob->data), blob->size);
}

std::vector<Eigen::Vector3f> error_colors(const std::vector<double>& e, double scale) {
  std::vector<Eigen::Vector3f> out(e.size());
  for (size_t i = 0; i < e.size(); ++i) {
    const float t = float(std::clamp(std::abs(e[i]) / std::max(scale, 1e-300), 0.0, 1.0));
    if (e[i] < 0) out[i] = Eigen::Vector3f(1 - t, 1 - t, 1);                          // white -> blue
    else if (t < 0.5f) out[i] = Eigen::Vector3f(1, 1, 1 - 2 * t);                     // white -> yellow
    else out[i] = Eigen::Vector3f(1, 2 - 2 * t, 0);                                   // yellow -> red
  }
  return out;
}

std::string encode_preview(const ProxyModel& proxy, const std::string& ext, int pose, bool spread) {
  const bool gltf = ext == ".glb";
  if (!gltf && ext != ".ply") fail_unsupported("", "no preview format for '" + ext + "'");
  if (pose < 0 || pose >= int(proxy.poses.size()))
    fail_option("pose", "no pose " + std::to_string(pose) + " (the proxy has poses 0.." +
                                 std::to_string(proxy.poses.size() - 1) + ")");
  std::vector<int> shown;
  if (gltf)
    for (int i = 0; i < int(proxy.poses.size()); ++i) shown.push_back(i);
  else
    shown.push_back(pose);
  const double width = spread ? side_by_side_step(proxy) : 0.0;
  std::vector<SceneNode> nodes;
  for (size_t k = 0; k < shown.size(); ++k) {
    const ProxyPose& p = proxy.poses[size_t(shown[k])];
    // Every pose in one glTF: a coarser sphere keeps the file small.
    SceneNode node{p.name, sphere_union_mesh(p.spheres, gltf ? 1 : 2), {}};
    if (gltf)
      for (auto& v : node.mesh.vertices) v.x() += width * double(k);
    nodes.push_back(std::move(node));
  }
  return encode_scene(nodes, ext);
}

void check_pose_number(int pose, size_t count) {
  if (pose < 0 || size_t(pose) >= count)
    fail_option("pose", "no pose " + std::to_string(pose) + " (there are poses 0.." + std::to_string(count - 1) + ")");
}

std::string encode_error_scene(const std::vector<PoseError>& evals, const std::string& ext, int pose, double scale,
                               double step) {
  std::vector<SceneNode> nodes;
  const bool gltf = ext == ".glb";
  if (!gltf) check_pose_number(pose, evals.size());
  for (size_t k = 0; k < evals.size(); ++k) {
    if (!gltf && int(k) != pose) continue;
    const PoseError& e = evals[k];
    SceneNode mesh{e.name + "-error", e.mesh, error_colors(e.vertex_error, scale)};
    SceneNode spheres{e.name + "-spheres", sphere_union_mesh(e.spheres, 1), {}};
    if (gltf)
      for (auto* n : {&mesh, &spheres})
        for (auto& v : n->mesh.vertices) v.x() += step * double(k);
    nodes.push_back(std::move(mesh));
    if (gltf) nodes.push_back(std::move(spheres));
  }
  return encode_scene(nodes, ext);
}

}  // namespace spx
