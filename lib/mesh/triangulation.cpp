#include "mesh/triangulation.hpp"

#include <assimp/scene.h>

#include <algorithm>
#include <limits>

namespace spx {

FaceLists face_lists(const aiScene& scene) {
  FaceLists out;
  out.meshes.resize(scene.mNumMeshes);
  for (unsigned m = 0; m < scene.mNumMeshes; ++m) {
    const aiMesh& mesh = *scene.mMeshes[m];
    FaceLists::Mesh& lists = out.meshes[m];
    lists.start.reserve(size_t(mesh.mNumFaces) + 1);
    for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
      const aiFace& face = mesh.mFaces[f];
      lists.corners.insert(lists.corners.end(), face.mIndices, face.mIndices + face.mNumIndices);
      lists.start.push_back(uint32_t(lists.corners.size()));
    }
  }
  return out;
}

bool has_polygons(const aiScene& scene) {
  for (unsigned m = 0; m < scene.mNumMeshes; ++m)
    for (unsigned f = 0; f < scene.mMeshes[m]->mNumFaces; ++f)
      if (scene.mMeshes[m]->mFaces[f].mNumIndices > 3) return true;
  return false;
}

Triangulation triangulation_of(const FaceLists& before, const aiScene& after) {
  Triangulation out;
  if (after.mNumMeshes != before.meshes.size()) return {};
  for (unsigned m = 0; m < after.mNumMeshes; ++m) {
    const aiMesh& mesh = *after.mMeshes[m];
    const FaceLists::Mesh& lists = before.meshes[m];
    unsigned o = 0;  // the next face assimp wrote: each face's triangles follow one another
    for (size_t f = 0; f + 1 < lists.start.size(); ++f) {
      const unsigned* corners = lists.corners.data() + lists.start[f];
      const size_t n = lists.start[f + 1] - lists.start[f];
      if (n <= 3) {  // copied as it was
        if (o >= mesh.mNumFaces || mesh.mFaces[o].mNumIndices != n) return {};
        ++o;
        continue;
      }
      if (n > std::numeric_limits<uint16_t>::max()) return {};
      // Its triangles: up to n - 2 faces of its own corners (fewer where its ear clipping failed).
      std::vector<std::array<uint16_t, 3>> triangles;
      for (; o < mesh.mNumFaces && triangles.size() + 2 < n; ++o) {
        const aiFace& t = mesh.mFaces[o];
        if (t.mNumIndices != 3) break;
        std::array<uint16_t, 3> local{};
        bool own = true;
        for (int k = 0; k < 3 && own; ++k) {
          const unsigned* at = std::find(corners, corners + n, t.mIndices[k]);
          own = at != corners + n;
          local[size_t(k)] = uint16_t(at - corners);
        }
        if (!own) break;
        triangles.push_back(local);
      }
      if (triangles.empty()) return {};
      out.polygons.push_back(std::move(triangles));
    }
    if (o != mesh.mNumFaces) return {};
  }
  if (!out.polygons.empty()) out.faces = before;
  return out;
}

bool split_as(aiScene& scene, const FaceLists& faces, const Triangulation& rest) {
  if (rest.empty() || faces.meshes.size() != rest.faces.meshes.size()) return false;
  for (size_t m = 0; m < faces.meshes.size(); ++m)
    if (!(faces.meshes[m] == rest.faces.meshes[m])) return false;
  size_t polygon = 0;
  for (unsigned m = 0; m < scene.mNumMeshes; ++m) {
    aiMesh& mesh = *scene.mMeshes[m];
    const FaceLists::Mesh& lists = faces.meshes[m];
    size_t count = 0, polygons = 0;
    for (unsigned f = 0; f < mesh.mNumFaces; ++f)
      count += mesh.mFaces[f].mNumIndices > 3 ? rest.polygons[polygon + polygons++].size() : 1;
    if (polygons == 0) continue;
    aiFace* split = new aiFace[count];
    aiFace* next = split;
    for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
      aiFace& face = mesh.mFaces[f];
      if (face.mNumIndices <= 3) {  // kept as it is: its corners move over
        std::swap(next->mNumIndices, face.mNumIndices);
        std::swap(next->mIndices, face.mIndices);
        ++next;
        continue;
      }
      const unsigned* corners = lists.corners.data() + lists.start[f];
      for (const std::array<uint16_t, 3>& t : rest.polygons[polygon]) {
        next->mNumIndices = 3;
        next->mIndices = new unsigned[3]{corners[t[0]], corners[t[1]], corners[t[2]]};
        ++next;
      }
      ++polygon;
    }
    delete[] mesh.mFaces;
    mesh.mFaces = split;
    mesh.mNumFaces = unsigned(count);
    mesh.mPrimitiveTypes = (mesh.mPrimitiveTypes & ~aiPrimitiveType_POLYGON) | aiPrimitiveType_TRIANGLE;
  }
  return true;
}

}  // namespace spx
