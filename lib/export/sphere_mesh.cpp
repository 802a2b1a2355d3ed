#include "export/sphere_mesh.hpp"

#include <assimp/Exporter.hpp>
#include <assimp/material.h>
#include <assimp/scene.h>

#include <map>

#include "core/error.hpp"

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

aiMesh* to_ai_mesh(const TriMesh& m, const std::string& name) {
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
  mesh->mMaterialIndex = 0;
  return mesh;
}

}  // namespace

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

std::string encode_preview(const ProxyModel& proxy, const std::string& ext, int pose, bool spread) {
  const bool gltf = ext == ".glb";
  if (!gltf && ext != ".ply") fail_unsupported("", "no preview format for '" + ext + "'");
  if (pose < 0 || pose >= int(proxy.poses.size())) fail_usage("--pose", "no pose " + std::to_string(pose));

  aiScene scene;
  scene.mRootNode = new aiNode("proxy");
  scene.mNumMaterials = 1;
  scene.mMaterials = new aiMaterial*[1]{new aiMaterial()};
  aiString material_name("spheres");
  scene.mMaterials[0]->AddProperty(&material_name, AI_MATKEY_NAME);

  std::vector<int> shown;
  if (gltf)
    for (int i = 0; i < int(proxy.poses.size()); ++i) shown.push_back(i);
  else
    shown.push_back(pose);
  // Side by side: each pose shifted by 1.25x the rest pose's width along x.
  double width = 0;
  {
    Eigen::AlignedBox3d box;
    for (const auto& s : proxy.poses.front().spheres)
      if (s.radius > 0) box.extend(s.center + Eigen::Vector3d::Constant(s.radius)).extend(s.center - Eigen::Vector3d::Constant(s.radius));
    if (!box.isEmpty()) width = 1.25 * box.sizes().x();
  }
  scene.mNumMeshes = unsigned(shown.size());
  scene.mMeshes = new aiMesh*[shown.size()];
  scene.mRootNode->mNumChildren = unsigned(shown.size());
  scene.mRootNode->mChildren = new aiNode*[shown.size()];
  for (size_t k = 0; k < shown.size(); ++k) {
    const ProxyPose& p = proxy.poses[size_t(shown[k])];
    // Every pose in one glTF: a coarser sphere keeps the file small.
    TriMesh mesh = sphere_union_mesh(p.spheres, gltf ? 1 : 2);
    if (gltf && spread)
      for (auto& v : mesh.vertices) v.x() += width * double(k);
    scene.mMeshes[k] = to_ai_mesh(mesh, p.name);
    auto* node = new aiNode(p.name);
    node->mParent = scene.mRootNode;
    node->mNumMeshes = 1;
    node->mMeshes = new unsigned[1]{unsigned(k)};
    scene.mRootNode->mChildren[k] = node;
  }
  Assimp::Exporter exporter;
  const aiExportDataBlob* blob = exporter.ExportToBlob(&scene, gltf ? "glb2" : "plyb");
  if (!blob) fail_write("", std::string("preview export failed: ") + exporter.GetErrorString());
  return std::string(static_cast<const char*>(blob->data), blob->size);
}

}  // namespace spx
