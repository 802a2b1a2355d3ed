#include "mesh/triangulation.hpp"

#include "mesh/assimp_scene.hpp"

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <limits>
#include <optional>
#include <unordered_map>

#include "core/hash.hpp"

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

size_t points_and_lines(const aiScene& scene) {
  size_t count = 0;
  for (unsigned m = 0; m < scene.mNumMeshes; ++m)
    for (unsigned f = 0; f < scene.mMeshes[m]->mNumFaces; ++f) count += scene.mMeshes[m]->mFaces[f].mNumIndices < 3;
  return count;
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
      // Its triangles: up to n - 2 faces of its own corners (fewer, or none, where its ear
      // clipping found no ear).
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
      out.polygons.push_back(std::move(triangles));
    }
    if (o != mesh.mNumFaces) return {};
  }
  if (!out.polygons.empty()) out.faces = before;
  return out;
}

namespace {

// Rebuilds the faces of `scene` (as read: `faces`) with each polygon split as `split` says.
void apply_split(aiScene& scene, const FaceLists& faces, const Triangulation& split) {
  size_t polygon = 0;
  for (unsigned m = 0; m < scene.mNumMeshes; ++m) {
    aiMesh& mesh = *scene.mMeshes[m];
    const FaceLists::Mesh& lists = faces.meshes[m];
    std::vector<aiFace> out;
    out.reserve(lists.corners.size());
    for (size_t f = 0; f + 1 < lists.start.size(); ++f) {
      const unsigned* corners = lists.corners.data() + lists.start[f];
      const unsigned n = lists.start[f + 1] - lists.start[f];
      if (n <= 3) {
        out.emplace_back();
        out.back().mNumIndices = n;
        out.back().mIndices = new unsigned[n];
        std::copy(corners, corners + n, out.back().mIndices);
        continue;
      }
      for (const std::array<uint16_t, 3>& t : split.polygons[polygon]) {
        out.emplace_back();
        out.back().mNumIndices = 3;
        out.back().mIndices = new unsigned[3]{corners[t[0]], corners[t[1]], corners[t[2]]};
      }
      ++polygon;
    }
    delete[] mesh.mFaces;  // each aiFace frees its own corners
    mesh.mFaces = new aiFace[out.size()];
    for (size_t f = 0; f < out.size(); ++f) {  // the corners move over, not copied
      std::swap(mesh.mFaces[f].mNumIndices, out[f].mNumIndices);
      std::swap(mesh.mFaces[f].mIndices, out[f].mIndices);
    }
    mesh.mNumFaces = unsigned(out.size());
    mesh.mPrimitiveTypes = 0;
    for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
      const unsigned n = mesh.mFaces[f].mNumIndices;
      mesh.mPrimitiveTypes |= n == 1 ? aiPrimitiveType_POINT : n == 2 ? aiPrimitiveType_LINE : aiPrimitiveType_TRIANGLE;
    }
  }
}

// Each polygon of `split` with fewer than its n - 2 triangles becomes the fan 0, k, k + 1.
FannedPolygons fan_unfinished(Triangulation& split, const aiScene& scene) {
  FannedPolygons fanned;
  size_t polygon = 0;
  for (size_t m = 0; m < split.faces.meshes.size(); ++m) {
    const FaceLists::Mesh& lists = split.faces.meshes[m];
    for (size_t f = 0; f + 1 < lists.start.size(); ++f) {
      const size_t n = lists.start[f + 1] - lists.start[f];
      if (n <= 3) continue;
      std::vector<std::array<uint16_t, 3>>& triangles = split.polygons[polygon++];
      if (triangles.size() == n - 2) continue;
      if (fanned.polygons++ == 0) {
        fanned.first_corners = n;
        fanned.first_at = to_eigen(scene.mMeshes[m]->mVertices[lists.corners[lists.start[f]]]);
      }
      fanned.dropped += n - 2 - triangles.size();
      triangles.clear();
      for (size_t k = 1; k + 1 < n; ++k) triangles.push_back({0, uint16_t(k), uint16_t(k + 1)});
    }
  }
  return fanned;
}

// A corner's position as the polygon's other copies give it (-0 as 0).
std::array<float, 3> position(const aiMesh& mesh, unsigned v) {
  const aiVector3D& p = mesh.mVertices[v];
  return {p.x + 0.0f, p.y + 0.0f, p.z + 0.0f};
}

// Polygon q's corners on polygon p's places: to[a] is q's corner where p's corner a lies, from
// where q repeats p's corner 0, running on (`turned` false) or back; none where q does not
// repeat p's positions so (n corners each).
std::optional<std::vector<uint16_t>> corners_on(const aiMesh& pm, const unsigned* p, const aiMesh& qm, const unsigned* q,
                                               size_t n, bool turned) {
  std::vector<uint16_t> to(n);
  for (size_t k = 0; k < n; ++k) {
    bool all = true;
    for (size_t a = 0; a < n && all; ++a) {
      to[a] = uint16_t(turned ? (k + n - a) % n : (k + a) % n);
      all = position(pm, p[a]) == position(qm, q[to[a]]);
    }
    if (all) return to;
  }
  return std::nullopt;
}

// Each polygon that repeats an earlier one's corner positions, from another first corner or in
// the other turn (faces doubled, a closed part given both ways), split as that one was, its
// triangles on the same places (in the other turn: turned too). Split by its own shape, a quad
// from its other first corner or turn takes the other diagonal, and the two overlap without
// repeating: neither drop_repeated_triangles nor drop_inner_sides would see them. Returns how
// many were split anew. Polygons are first told apart by a hash of their positions that no
// rotation or turn changes (a sum), and compared corner by corner only where it is the same.
size_t split_repeats_alike(Triangulation& split, const aiScene& scene) {
  struct Polygon {
    size_t mesh, index;
    const unsigned* corners;
    size_t n;
  };
  std::unordered_map<uint64_t, std::vector<Polygon>> seen;
  seen.reserve(split.polygons.size());
  size_t polygon = 0, resplit = 0;
  for (size_t m = 0; m < split.faces.meshes.size(); ++m) {
    const FaceLists::Mesh& lists = split.faces.meshes[m];
    const aiMesh& mesh = *scene.mMeshes[m];
    for (size_t f = 0; f + 1 < lists.start.size(); ++f) {
      const size_t n = lists.start[f + 1] - lists.start[f];
      if (n <= 3) continue;
      const Polygon q{m, polygon++, lists.corners.data() + lists.start[f], n};
      uint64_t key = n;
      for (size_t k = 0; k < n; ++k) {
        const std::array<float, 3> at = position(mesh, q.corners[k]);
        key += mix64(fnv1a(kFnvOffset, at.data(), sizeof at));
      }
      std::vector<Polygon>& alike = seen[key];
      bool repeats = false;
      for (const Polygon& p : alike) {
        if (p.n != n) continue;
        const aiMesh& pm = *scene.mMeshes[p.mesh];
        for (bool turned : {false, true}) {
          const auto to = corners_on(pm, p.corners, mesh, q.corners, n, turned);
          if (!to) continue;
          std::vector<std::array<uint16_t, 3>> triangles;
          for (const std::array<uint16_t, 3>& t : split.polygons[p.index])
            triangles.push_back(turned ? std::array<uint16_t, 3>{(*to)[t[2]], (*to)[t[1]], (*to)[t[0]]}
                                       : std::array<uint16_t, 3>{(*to)[t[0]], (*to)[t[1]], (*to)[t[2]]});
          if (triangles != split.polygons[q.index]) split.polygons[q.index] = std::move(triangles), ++resplit;
          repeats = true;
          break;
        }
        if (repeats) break;
      }
      if (!repeats) alike.push_back(q);
    }
  }
  return resplit;
}

// The triangles a full split of `faces` makes, faces of up to 3 corners counted as one.
size_t full_split_size(const FaceLists& faces) {
  size_t count = 0;
  for (const FaceLists::Mesh& lists : faces.meshes)
    for (size_t f = 0; f + 1 < lists.start.size(); ++f) {
      const size_t n = lists.start[f + 1] - lists.start[f];
      count += n > 3 ? n - 2 : 1;
    }
  return count;
}

}  // namespace

Triangulation triangulate(Assimp::Importer& importer, const FaceLists& faces, const std::string& path,
                          const std::string& what, FannedPolygons& fanned) {
  aiScene& scene = *const_cast<aiScene*>(post_processed(importer, aiProcess_Triangulate, path, what));
  Triangulation split = triangulation_of(faces, scene);
  if (split.empty()) {  // nothing to mend by, but what was left out is counted
    size_t made = 0;
    for (unsigned m = 0; m < scene.mNumMeshes; ++m) made += scene.mMeshes[m]->mNumFaces;
    const size_t full = full_split_size(faces);
    fanned = {};
    fanned.dropped = full - std::min(made, full);
    return split;
  }
  fanned = fan_unfinished(split, scene);
  const size_t resplit = split_repeats_alike(split, scene);
  if (fanned.polygons > 0 || resplit > 0) apply_split(scene, faces, split);
  return split;
}

bool split_as(aiScene& scene, const FaceLists& faces, const Triangulation& rest) {
  if (rest.empty() || faces.meshes.size() != rest.faces.meshes.size()) return false;
  for (size_t m = 0; m < faces.meshes.size(); ++m)
    if (!(faces.meshes[m] == rest.faces.meshes[m])) return false;
  apply_split(scene, faces, rest);
  return true;
}

}  // namespace spx
