#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <set>

#include "core/atomic_file.hpp"
#include "core/error.hpp"
#include "core/file_kind.hpp"
#include "core/format.hpp"
#include "core/hash.hpp"
#include "core/side_by_side.hpp"
#include "mesh/assimp_scene.hpp"
#include "mesh/mesh.hpp"
#include "mesh/pose_match.hpp"
#include "mesh/sorted_keys.hpp"
#include "mesh/triangulation.hpp"

namespace spx {
namespace {

struct RawMesh {
  std::vector<Eigen::Vector3d> positions;
  std::vector<Eigen::Vector3i> triangles;
  Triangulation triangulation;  // how its polygons were split (a rest's)
  FannedPolygons fanned;        // those assimp's split left unfinished
  size_t points_and_lines = 0;  // faces left out: no surface
  RepeatedTriangles skinned_repeats;  // a skinned mesh's other instances, read once
  DefaultWeights default_weights;
};

DefaultWeights default_weights_of(const aiScene& scene) {
  DefaultWeights out;
  std::set<std::string> named;
  for (unsigned m = 0; m < scene.mNumMeshes; ++m)
    for (unsigned k = 0; k < scene.mMeshes[m]->mNumAnimMeshes; ++k) {
      const aiAnimMesh& target = *scene.mMeshes[m]->mAnimMeshes[k];
      if (target.mWeight == 0 || !named.insert(target.mName.C_Str()).second) continue;
      if (out.targets++ == 0) out.first = target.mName.C_Str(), out.weight = target.mWeight;
    }
  return out;
}

// Where a format not read here is one artists hand over often, the way from it to one that is.
std::string way_from(const std::string& ext) {
  if (ext == ".abc") return "; an Alembic cache: write its frames as OBJ files, one a pose, from the tool that made it";
  if (ext == ".usd" || ext == ".usda" || ext == ".usdc" || ext == ".usdz")
    return "; a USD stage: export glTF 2.0 from the tool that made it";
  if (ext == ".max" || ext == ".ma" || ext == ".mb" || ext == ".c4d" || ext == ".hip" || ext == ".hipnc")
    return "; a modelling tool's own scene: export glTF 2.0, FBX or OBJ from it";
  return "";
}

}  // namespace

void check_importable(const std::string& path, const std::string& kind, const std::string& formats) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) fail_no_such_file(path);
  if (std::filesystem::is_directory(path, ec)) fail_input(path, "is a directory, not " + kind + " file");
  if (std::filesystem::file_size(path, ec) == 0) fail_input(path, "file is empty");
  const std::string ext = lower_extension(path);
  if (ext.empty() || !Assimp::Importer().IsExtensionSupported(ext))
    fail_unsupported(path, "unknown " + kind.substr(kind.find(' ') + 1) + " format '" + ext + "' (use " + formats +
                               ")" + way_from(ext));
}

namespace {

// `rest`: how the rest's polygons were split, for a pose's same polygons to be split so.
RawMesh read_raw(const std::string& path, const Triangulation* rest = nullptr) {
  check_importable(path, "a mesh", "OBJ, PLY, STL, OFF, glTF/GLB or FBX");
  Assimp::Importer importer;
  // Keep only triangles; never drop degenerate ones silently (the report lists them).
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  // Read as it is, its mirrored parts turned to face out, its skinned parts where their skin puts
  // them, then placed (pre-transformed): the same steps in the same order as reading with those
  // flags.
  aiScene* read = const_cast<aiScene*>(read_scene(importer, path, 0, "mesh"));
  face_out_mirrored(read);
  const RepeatedTriangles skinned_repeats = place_skinned_by_skin(read);
  const DefaultWeights weights = default_weights_of(*read);  // before the placing drops the targets
  // assimp's steps in its own order, the split apart where there are polygons, to see their faces
  // before it (a split scene's aiProcess_Triangulate does nothing).
  aiScene& placed = *const_cast<aiScene*>(post_processed(importer, aiProcess_PreTransformVertices, path, "mesh"));
  RawMesh raw;
  raw.skinned_repeats = skinned_repeats;
  raw.default_weights = weights;
  raw.points_and_lines = points_and_lines(placed);
  if (has_polygons(placed)) {
    const FaceLists faces = face_lists(placed);
    if (!rest || !split_as(placed, faces, *rest)) {
      Triangulation own = triangulate(importer, faces, path, "mesh", raw.fanned);
      if (!rest) raw.triangulation = std::move(own);
    }
  }
  const aiScene* scene = post_processed(importer, aiProcess_Triangulate | aiProcess_SortByPType, path, "mesh");

  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh* mesh = scene->mMeshes[m];
    if (!(mesh->mPrimitiveTypes & aiPrimitiveType_TRIANGLE)) continue;
    const int offset = static_cast<int>(raw.positions.size());
    for (unsigned v = 0; v < mesh->mNumVertices; ++v) {
      const aiVector3D& p = mesh->mVertices[v];
      Eigen::Vector3d q(p.x, p.y, p.z);
      // assimp reads 32-bit floats and may split a file's vertex by its faces, so its index
      // would not be the file's: the position names it.
      if (!q.allFinite())
        fail_input(path, "a vertex at (" + num(q.x()) + ", " + num(q.y()) + ", " + num(q.z()) +
                             ") is not a finite number (read as a 32-bit float: NaN, infinite or past 3.4e38)");
      raw.positions.push_back(q);
    }
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
      const aiFace& face = mesh->mFaces[f];
      if (face.mNumIndices != 3) continue;
      raw.triangles.emplace_back(offset + static_cast<int>(face.mIndices[0]),
                                 offset + static_cast<int>(face.mIndices[1]),
                                 offset + static_cast<int>(face.mIndices[2]));
    }
  }
  if (raw.triangles.empty()) fail_input(path, "contains no triangles");
  return raw;
}

}  // namespace

Eigen::AlignedBox3d TriMesh::bounds() const {
  Eigen::AlignedBox3d box;
  for (const auto& v : vertices) box.extend(v);
  return box;
}

std::vector<int> weld_by_position(const std::vector<Eigen::Vector3d>& positions, std::vector<Eigen::Vector3d>& welded) {
  // Sorted by their bits, equal positions lie together, the first of each in front (+ 0.0: -0
  // and +0 weld together).
  using Bits = std::array<uint64_t, 3>;
  const std::vector<KeyedIndex<Bits>> sorted = sorted_keys<Bits>(positions.size(), [&](size_t i) {
    const Eigen::Vector3d& p = positions[i];
    return Bits{bits_of(p.x() + 0.0), bits_of(p.y() + 0.0), bits_of(p.z() + 0.0)};
  });
  // Each position's first occurrence (a NaN is equal to none, as in a hash table).
  std::vector<uint32_t> first(positions.size());
  for (size_t k = 0; k < sorted.size(); ++k) {
    const uint32_t i = sorted[k].second;
    const bool same = k > 0 && positions[i] == positions[sorted[k - 1].second];
    first[i] = same ? first[sorted[k - 1].second] : i;
  }
  std::vector<int> weld(positions.size());
  for (size_t i = 0; i < positions.size(); ++i) {
    if (first[i] == i) {
      weld[i] = int(welded.size());
      welded.push_back(positions[i]);
    } else {
      weld[i] = weld[first[i]];
    }
  }
  return weld;
}

LoadedMesh load_mesh(const std::string& path) {
  RawMesh raw = read_raw(path);
  LoadedMesh out;
  out.path = path;
  out.weld = weld_by_position(raw.positions, out.mesh.vertices);
  out.file_triangles = std::move(raw.triangles);
  out.triangulation = std::move(raw.triangulation);
  out.fanned = raw.fanned;
  out.points_and_lines = raw.points_and_lines;
  out.default_weights = raw.default_weights;
  out.mesh.triangles.reserve(out.file_triangles.size());
  for (const auto& t : out.file_triangles)
    out.mesh.triangles.emplace_back(out.weld[t[0]], out.weld[t[1]], out.weld[t[2]]);
  out.repeated = raw.skinned_repeats;
  out.repeated.add(read_triangles_once(out.mesh));
  return out;
}

RepeatedTriangles drop_repeated_triangles(TriMesh& mesh) {
  RepeatedTriangles out;
  using Corners = std::array<int, 3>;
  // The least of its three turns names a triangle whichever corner it starts from.
  const std::vector<KeyedIndex<Corners>> sorted = sorted_keys<Corners>(mesh.triangles.size(), [&](size_t t) {
    const Eigen::Vector3i& f = mesh.triangles[t];
    return std::min({Corners{f[0], f[1], f[2]}, Corners{f[1], f[2], f[0]}, Corners{f[2], f[0], f[1]}});
  });
  std::vector<char> repeat(mesh.triangles.size(), 0);
  for (size_t k = 1; k < sorted.size(); ++k) repeat[sorted[k].second] = sorted[k].first == sorted[k - 1].first;
  size_t kept = 0;
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    if (!repeat[t]) {
      mesh.triangles[kept++] = mesh.triangles[t];
    } else if (out.count++ == 0) {
      out.first_at = mesh.vertices[size_t(mesh.triangles[t][0])];
    }
  }
  mesh.triangles.resize(kept);
  return out;
}

namespace {

// The pose file lays out its vertices and triangles as the rest file does.
bool laid_out_as_rest(const RawMesh& raw, const LoadedMesh& rest) {
  return raw.positions.size() == rest.file_vertex_count() && raw.triangles == rest.file_triangles;
}

// A pose laid out as the rest file: the rest's own weld gives its vertices. False when points
// that are one at rest part (the faces are in another order, or a seam really opens).
bool pose_by_rest_weld(const RawMesh& raw, const LoadedMesh& rest, TriMesh& pose) {
  if (!laid_out_as_rest(raw, rest)) return false;
  std::vector<char> set(rest.mesh.vertices.size(), 0);
  double scale = 0;
  for (const auto& p : raw.positions) scale = std::max(scale, p.cwiseAbs().maxCoeff());
  const double tol = 1e-6 * std::max(scale, 1e-30);
  for (size_t i = 0; i < raw.positions.size(); ++i) {
    const size_t v = size_t(rest.weld[i]);
    if (!set[v]) {
      pose.vertices[v] = raw.positions[i];
      set[v] = 1;
    } else if ((pose.vertices[v] - raw.positions[i]).norm() > tol) {
      return false;
    }
  }
  return true;
}

// A pose laid out as the rest file whose own weld splits some of the rest's vertices and joins
// none (two parts touching at rest, or a seam, that open in the pose) is refused saying so: those
// points are one vertex to the tools. (Faces in another order, whose weld does not split the
// rest's, go on to be matched by their triangles.)
// `own`: the pose welded by its own positions (its vertices), `weld`: each file vertex's.
void fail_where_rest_vertices_part(const std::string& path, const RawMesh& raw, const std::vector<int>& weld,
                                   const TriMesh& own, const LoadedMesh& rest) {
  if (!laid_out_as_rest(raw, rest)) return;
  std::vector<int> rest_of(own.vertices.size(), -1);
  std::vector<int> parts(rest.mesh.vertices.size(), 0);
  for (size_t i = 0; i < weld.size(); ++i) {
    int& r = rest_of[size_t(weld[i])];
    if (r >= 0 && r != rest.weld[i]) return;  // joins two rest vertices: another layout
    if (r < 0) ++parts[size_t(r = rest.weld[i])];
  }
  const auto first = std::find_if(parts.begin(), parts.end(), [](int n) { return n > 1; });
  if (first == parts.end()) return;
  const size_t n = size_t(std::count_if(parts.begin(), parts.end(), [](int k) { return k > 1; }));
  const Eigen::Vector3d& at = rest.mesh.vertices[size_t(first - parts.begin())];
  fail_input(path, (n == 1 ? std::string("1 vertex") : std::to_string(n) + " vertices") +
                       " of the rest part in this pose (the first at " + num(at.x()) + ", " + num(at.y()) + ", " +
                       num(at.z()) + " in " + rest.path +
                       "): points its file has in one place (two parts touching, a seam) are one vertex to the tools, "
                       "and the map from the rest cannot tear them apart; keep them together in every pose, or apart at rest");
}

// The pose welded by its own positions; `weld`: the vertex each file vertex became.
TriMesh welded_on_its_own(const RawMesh& raw, std::vector<int>& weld) {
  TriMesh own;
  weld = weld_by_position(raw.positions, own.vertices);
  for (const auto& t : raw.triangles) own.triangles.emplace_back(weld[size_t(t[0])], weld[size_t(t[1])], weld[size_t(t[2])]);
  read_triangles_once(own);  // as the rest's were
  return own;
}

// Any other layout (a GLB's vertices against an OBJ's face corners, faces in another order or
// their corners rotated): the pose welded on its own (`own`), matched to the rest by its triangles.
void pose_by_triangles(const std::string& path, const TriMesh& own, const LoadedMesh& rest, const std::string& differs,
                       TriMesh& pose) {
  std::vector<int> to_rest;
  try {
    to_rest = match_pose_vertices(rest.mesh, own, path);
  } catch (const Error& e) {
    throw Error(e.code(), "", e.what() + differs);
  }
  for (size_t v = 0; v < own.vertices.size(); ++v) pose.vertices[size_t(to_rest[v])] = own.vertices[v];
}

}  // namespace

TriMesh load_pose(const std::string& path, const LoadedMesh& rest) {
  const RawMesh raw = read_raw(path, &rest.triangulation);
  const std::string differs = " (poses must share the rest mesh's topology: " + rest.path + ")";
  if (raw.triangles.size() != rest.file_triangles.size())
    fail_input(path, "has " + std::to_string(raw.triangles.size()) + " triangles, the rest mesh has " +
                         std::to_string(rest.file_triangles.size()) + differs);
  TriMesh pose;
  pose.triangles = rest.mesh.triangles;
  pose.vertices.assign(rest.mesh.vertices.size(), Eigen::Vector3d::Constant(std::nan("")));
  if (!pose_by_rest_weld(raw, rest, pose)) {
    std::vector<int> weld;
    const TriMesh own = welded_on_its_own(raw, weld);
    fail_where_rest_vertices_part(path, raw, weld, own, rest);
    pose_by_triangles(path, own, rest, differs, pose);
  }
  return pose;
}

std::vector<TriMesh> load_poses(const std::vector<std::string>& paths, const LoadedMesh& rest) {
  std::vector<TriMesh> out(paths.size());
  each_side_by_side(paths.size(), [&](size_t i) { out[i] = load_pose(paths[i], rest); });
  return out;
}

std::string to_obj(const TriMesh& mesh, const std::string& comment) {
  std::string out;
  out.reserve(mesh.vertices.size() * 40 + mesh.triangles.size() * 24);
  if (!comment.empty()) out += "# " + comment + "\n";
  char line[128];
  for (const auto& v : mesh.vertices) {
    std::snprintf(line, sizeof line, "v %.9g %.9g %.9g\n", v.x(), v.y(), v.z());
    out += line;
  }
  for (const auto& t : mesh.triangles) {
    std::snprintf(line, sizeof line, "f %d %d %d\n", t[0] + 1, t[1] + 1, t[2] + 1);
    out += line;
  }
  return out;
}

double read_rounding(const TriMesh& mesh) {
  float largest = 0;
  for (const Eigen::Vector3d& v : mesh.vertices) largest = std::max(largest, float(v.cwiseAbs().maxCoeff()));
  return 0.5 * (double(std::nextafter(largest, INFINITY)) - double(largest));
}

void check_read_rounding(const TriMesh& mesh, double voxel, const std::string& file, Log& log) {
  const double rounding = read_rounding(mesh);
  if (!(voxel > 0) || rounding <= 0.1 * voxel) return;
  const Eigen::AlignedBox3d box = mesh.bounds();
  const std::string said =
      "its coordinates reach " + num(std::max(box.min().cwiseAbs().maxCoeff(), box.max().cwiseAbs().maxCoeff())) +
      ", where the mesh readers' single precision places a vertex only to within " + num(rounding) +
      " of the file's, " + num(rounding / voxel) + (rounding > voxel ? " voxels of " : " of a voxel of ") + num(voxel) +
      " (the mesh is " +
      num(box.sizes().maxCoeff()) + " across)";
  if (rounding > voxel)
    fail_input(file, said + ": the field would follow that reading, not the file; move the mesh near the origin");
  log.warn(file + ": " + said + "; move the mesh near the origin for the field to follow the file");
}

void warn_fanned(const FannedPolygons& fanned, const std::string& file, Log& log) {
  const std::string at = num(fanned.first_at.x()) + ", " + num(fanned.first_at.y()) + ", " + num(fanned.first_at.z());
  const std::string corners = std::to_string(fanned.first_corners) + " corners";
  const std::string stops =
      "where the mesh reader's ear clipping stops (" + counted(fanned.dropped, "triangle") + " left out); ";
  if (fanned.polygons == 1)
    log.warn(file + ": a polygon of " + corners + " (the first at " + at + ") crosses itself as seen along its normal, " +
             stops + "it is split as a fan from its first corner instead, closed as in the file; check it in a "
             "modelling tool");
  else if (fanned.polygons > 1)
    log.warn(file + ": " + std::to_string(fanned.polygons) + " polygons (the first of " + corners + ", at " + at +
             ") cross themselves as seen along their normals, " + stops + "each is split as a fan from its first "
             "corner instead, closed as in the file; check them in a modelling tool");
  else if (fanned.left_out() > 0)
    log.warn(file + ": the mesh reader's split left out " + counted(fanned.left_out(), "triangle") +
             " of polygons that cross themselves, and the mesh is open there; split them into triangles in a "
             "modelling tool");
}

void warn_default_weights(const DefaultWeights& weights, const std::string& file, Log& log) {
  if (weights.targets == 0) return;
  log.warn(file + ": " + counted(weights.targets, "morph target") + (weights.targets == 1 ? " weighs" : " weigh") +
           " in by default (the first, '" + weights.first + "', at " + num(weights.weight) + ") where the file is "
           "drawn; read here at weight 0, its stored positions, as pose-extract --morph-targets' rest is (pose-extract "
           "--animation writes its rest at those weights, as its clip plays them)");
}

void warn_repeated(const RepeatedTriangles& repeated, const std::string& file, Log& log) {
  if (repeated.inner_sides > 0) {
    const Eigen::Vector3d& at = repeated.inner_first_at;
    log.warn(file + ": " + counted(repeated.double_sided_parts, "closed part") + " given both ways (" +
             counted(repeated.inner_sides, "face") + " also in the other turn, the first at " + num(at.x()) + ", " +
             num(at.y()) + ", " + num(at.z()) + "): the two sides cancel and enclose nothing, so " +
             (repeated.double_sided_parts == 1 ? "its" : "each one's") + " inner side is dropped");
  }
  if (repeated.count == 0) return;
  log.warn(file + ": " + counted(repeated.count, "triangle") + (repeated.count == 1 ? " repeats" : " repeat") +
           " another's corners (the first at " + num(repeated.first_at.x()) + ", " + num(repeated.first_at.y()) + ", " +
           num(repeated.first_at.z()) + "): a part placed twice in one place, or faces doubled; each is read once");
}

std::string stem_of(const std::string& path) { return std::filesystem::path(path).stem().string(); }

}  // namespace spx
