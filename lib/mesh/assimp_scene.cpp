#include "mesh/assimp_scene.hpp"

#include <assimp/SceneCombiner.h>
#include <assimp/ai_assert.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <stdexcept>
#include <vector>

#include "core/error.hpp"
#include "core/file_kind.hpp"
#include "core/gltf_file.hpp"
#include "mesh/file_checks.hpp"
#include "mesh/gltf_check.hpp"
#include "mesh/gltf_input.hpp"
#include "mesh/ply_input.hpp"

namespace spx {
namespace {

// A check of assimp's own that failed (ai_assert), as an exception: below.
struct AssimpCheckFailed : std::runtime_error {
  using std::runtime_error::runtime_error;
};

}  // namespace
}  // namespace spx

// assimp's internal checks (ai_assert) abort the process where they fail (exit 134, its own line
// on stderr: a damaged FBX whose curve node lost its name stopped pose-extract so), and Debian's
// build of 5.2 offers no handler of one's own. The library calls this function through its
// procedure linkage table, so this definition, linked into every tool that reads through assimp,
// takes its place: the failed check becomes an exception, which assimp's ReadFile turns into its
// error string, and post_processed below into one error line.
namespace Assimp {
void aiAssertViolation(const char* expression, const char* file, int line) {
  const std::string where = file;
  throw spx::AssimpCheckFailed("assimp stopped on a check of its own (" + std::string(expression) + ", " +
                               where.substr(where.find_last_of('/') + 1) + " line " + std::to_string(line) +
                               "): a damaged file, or one its reader does not handle");
}
}  // namespace Assimp

namespace spx {

namespace {

// Some of assimp's errors quote the rest of the file (an ASCII STL's number that does not parse:
// 140 000 characters on one line); the line keeps the error's start and end, cut between whole
// UTF-8 characters.
std::string shortened(const std::string& error) {
  const size_t head = 160, tail = 120;
  if (error.size() <= head + tail + 40) return error;
  auto starts_char = [&](size_t i) { return (static_cast<unsigned char>(error[i]) & 0xC0) != 0x80; };
  size_t end = head, start = error.size() - tail;
  while (end > 0 && !starts_char(end)) --end;
  while (start < error.size() && !starts_char(start)) ++start;
  return error.substr(0, end) + " [... " + std::to_string(start - end) + " characters ...] " + error.substr(start);
}

// The file as assimp reads it, before any post-processing.
const aiScene* read_unprocessed(Assimp::Importer& importer, const std::string& path, const std::string& what,
                                ClipMends* clips) {
  if (clips) *clips = {};
  const std::string ext = lower_extension(path);
  const bool gltf = ext == ".gltf" || ext == ".glb";
  check_before_assimp(path);
  // A glTF is parsed once: mended for assimp where it needs it, and asked why where assimp fails.
  std::optional<GltfFile> file;
  std::optional<Error> not_gltf;  // the container's fault, told only where assimp fails too
  if (gltf) {
    try {
      file = read_gltf_file(path);
    } catch (const Error& e) {
      not_gltf = e;
    }
  }
  if (file) {
    check_required_extensions(file->doc, path);
    check_gltf_rules(*file, path);
    // Each, whatever the one before finds (no short circuit): Draco's meshes first (into plain
    // accessors), the instances next (they read their accessors as a reader takes them), then the
    // floats, which the others read. Views the file compressed came out decoded, which assimp
    // cannot do.
    size_t changes = file->decoded_views;
    changes += draco_primitives_decoded(*file, path);
    changes += instances_as_nodes(*file, path);
    changes += skins_given_bind_matrices(*file);
    ClipMends mends;
    changes += channels_as_assimp_reads(*file, mends.passed_over);  // before the others read the channels
    // After the instances, which place meshes too, and after a pointer to a mesh's weights has
    // become its nodes' channels, which a node's own copy of the mesh then keeps.
    changes += meshes_split_by_node(*file);
    changes += float_accessors(*file, path);
    changes += complete_mirrored_channels(*file, path);
    changes += step_samplers_as_held_keys(*file, path);
    changes += cubic_samplers_as_keys(*file, path, mends.added_keys);
    if (clips) *clips = std::move(mends);
    if (changes > 0) {
      const std::string glb = encode_glb(*file);
      const aiScene* scene = importer.ReadFileFromMemory(glb.data(), glb.size(), 0, "glb");
      if (scene && scene->mRootNode) return scene;
      fail_reading(path, what, importer.GetErrorString());
    }
  }
  if (ext == ".ply")
    if (const std::optional<std::string> readable = ply_for_assimp(path)) {
      const aiScene* scene = importer.ReadFileFromMemory(readable->data(), readable->size(), 0, "ply");
      if (scene && scene->mRootNode) return scene;
      fail_reading(path, what, importer.GetErrorString());
    }
  const aiScene* scene = importer.ReadFile(path, 0);
  if (scene && scene->mRootNode) return scene;
  const std::string error = importer.GetErrorString();
  if (not_gltf) throw *not_gltf;  // says what is wrong with the container
  if (file) {
    if (file->doc.value("meshes", json::array()).empty()) fail_input(path, "contains no mesh");
    if (ext == ".gltf") {
      const std::string glb = encode_glb(*file);
      scene = importer.ReadFileFromMemory(glb.data(), glb.size(), 0, "glb");
      if (scene && scene->mRootNode) return scene;
    }
  }
  fail_reading(path, what, error);
}

// assimp's readers are lenient where a file is cut short or names a vertex it does not have: an
// OFF that ends early leaves faces with no corners (assimp's triangulation then aborts the whole
// process), and a PLY keeps a face whose index is past its vertices. Either is one error line.
void check_faces(const aiScene* scene, const std::string& path) {
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh* mesh = scene->mMeshes[m];
    auto name = [&](unsigned f) {
      return "face " + std::to_string(f + 1) + (scene->mNumMeshes > 1 ? " of mesh " + std::to_string(m + 1) : "");
    };
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
      const aiFace& face = mesh->mFaces[f];
      if (face.mNumIndices == 0 || !face.mIndices)
        fail_input(path, name(f) + " has no corners (a file cut short, or a face without its vertices)");
      for (unsigned k = 0; k < face.mNumIndices; ++k)
        if (face.mIndices[k] >= mesh->mNumVertices)
          fail_input(path, name(f) + " names vertex " + std::to_string(face.mIndices[k]) + " (counted from 0), past its " +
                               std::to_string(mesh->mNumVertices) + " vertices");
    }
  }
}

}  // namespace

void fail_reading(const std::string& path, const std::string& what, const std::string& error) {
  rethrow_out_of_memory(error);
  fail_input(path, "cannot read " + what + ": " + shortened(error));
}

const aiScene* read_scene(Assimp::Importer& importer, const std::string& path, unsigned flags, const std::string& what,
                          ClipMends* clips) {
  // Read without flags and post-processed after: what reading with them does, in the same order,
  // with the faces checked before any step trusts them.
  const aiScene* scene = read_unprocessed(importer, path, what, clips);
  check_faces(scene, path);
  return flags ? post_processed(importer, flags, path, what) : scene;
}

const aiScene* post_processed(Assimp::Importer& importer, unsigned flags, const std::string& path,
                              const std::string& what) {
  const aiScene* scene = nullptr;
  try {
    scene = importer.ApplyPostProcessing(flags);
  } catch (const AssimpCheckFailed& e) {
    fail_reading(path, what, e.what());
  }
  if (!scene || !scene->mRootNode) fail_reading(path, what, importer.GetErrorString());
  return scene;
}

namespace {

void face_out_mirrored(aiScene* scene, aiNode* node, const aiMatrix4x4& parent, std::map<unsigned, unsigned>& reversed,
                       std::vector<aiMesh*>& added) {
  const aiMatrix4x4 global = parent * node->mTransformation;
  if (global.Determinant() < 0)
    for (unsigned i = 0; i < node->mNumMeshes; ++i) {
      const unsigned k = node->mMeshes[i];
      if (k >= scene->mNumMeshes || scene->mMeshes[k]->mNumBones) continue;
      auto it = reversed.find(k);
      if (it == reversed.end()) {
        aiMesh* copy = nullptr;
        Assimp::SceneCombiner::Copy(&copy, scene->mMeshes[k]);
        for (unsigned f = 0; f < copy->mNumFaces; ++f)
          std::reverse(copy->mFaces[f].mIndices, copy->mFaces[f].mIndices + copy->mFaces[f].mNumIndices);
        it = reversed.emplace(k, unsigned(scene->mNumMeshes + added.size())).first;
        added.push_back(copy);
      }
      node->mMeshes[i] = it->second;
    }
  for (unsigned c = 0; c < node->mNumChildren; ++c) face_out_mirrored(scene, node->mChildren[c], global, reversed, added);
}

}  // namespace

void face_out_mirrored(aiScene* scene) {
  std::map<unsigned, unsigned> reversed;
  std::vector<aiMesh*> added;
  face_out_mirrored(scene, scene->mRootNode, aiMatrix4x4(), reversed, added);
  if (added.empty()) return;
  aiMesh** meshes = new aiMesh*[scene->mNumMeshes + added.size()];
  std::copy(scene->mMeshes, scene->mMeshes + scene->mNumMeshes, meshes);
  std::copy(added.begin(), added.end(), meshes + scene->mNumMeshes);
  delete[] scene->mMeshes;
  scene->mMeshes = meshes;
  scene->mNumMeshes += unsigned(added.size());
}

namespace {

void add_globals(const aiNode& node, const Eigen::Matrix4d& parent, const NodeLocal& local,
                 std::map<const aiNode*, Eigen::Matrix4d>& out) {
  const Eigen::Matrix4d g = parent * (local ? local(node) : to_eigen(node.mTransformation));
  out[&node] = g;
  for (unsigned c = 0; c < node.mNumChildren; ++c) add_globals(*node.mChildren[c], g, local, out);
}

void add_instances(const aiNode& node, std::vector<std::pair<const aiNode*, unsigned>>& out) {
  for (unsigned i = 0; i < node.mNumMeshes; ++i) out.emplace_back(&node, node.mMeshes[i]);
  for (unsigned c = 0; c < node.mNumChildren; ++c) add_instances(*node.mChildren[c], out);
}

using Instances = std::vector<std::pair<const aiNode*, unsigned>>;

// A skinned mesh (`index`) that nodes other than `first` place too (`instances`: the scene's) is
// drawn by each where its skin puts it, the same place: those nodes lose it, and the triangles it
// would have added are counted as repeated (`at`: where its skin puts its first vertex).
RepeatedTriangles read_once(const aiScene& scene, const Instances& instances, unsigned index, const aiNode* first,
                            const Eigen::Vector3d& at) {
  size_t triangles = 0;
  const aiMesh& mesh = *scene.mMeshes[index];
  for (unsigned f = 0; f < mesh.mNumFaces; ++f) triangles += std::max(mesh.mFaces[f].mNumIndices, 2u) - 2;
  RepeatedTriangles out;
  out.first_at = at;
  for (const auto& [placing, i] : instances) {
    if (i != index || placing == first) continue;
    aiNode& node = *const_cast<aiNode*>(placing);  // the scene is ours to change
    node.mNumMeshes = unsigned(std::remove(node.mMeshes, node.mMeshes + node.mNumMeshes, index) - node.mMeshes);
    out.count += triangles;
  }
  return out;
}

}  // namespace

std::map<const aiNode*, Eigen::Matrix4d> node_globals(const aiNode& root, const NodeLocal& local) {
  std::map<const aiNode*, Eigen::Matrix4d> out;
  add_globals(root, Eigen::Matrix4d::Identity(), local, out);
  return out;
}

std::vector<std::pair<const aiNode*, unsigned>> mesh_instances(const aiNode& root) {
  std::vector<std::pair<const aiNode*, unsigned>> out;
  add_instances(root, out);
  return out;
}

Eigen::Matrix4d to_eigen(const aiMatrix4x4& m) {
  Eigen::Matrix4d e;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) e(r, c) = m[r][c];
  return e;
}

RepeatedTriangles place_skinned_by_skin(aiScene* scene) {
  RepeatedTriangles repeated;
  const std::map<const aiNode*, Eigen::Matrix4d> global = node_globals(*scene->mRootNode);
  // (read_once takes a mesh from nodes, which leaves every other mesh's instances as they are.)
  const Instances instances = mesh_instances(*scene->mRootNode);
  std::map<unsigned, const aiNode*> placed_by;  // the first node that places each mesh
  for (const auto& [node, index] : instances) placed_by.emplace(index, node);
  for (const auto& [index, node] : placed_by) {
    aiMesh& mesh = *scene->mMeshes[index];
    const Eigen::Matrix4d& g = global.at(node);
    if (mesh.mNumBones == 0 || !(std::abs(g.topLeftCorner<3, 3>().determinant()) > 1e-12)) continue;
    std::vector<Eigen::Vector3d> sum(mesh.mNumVertices, Eigen::Vector3d::Zero());
    std::vector<double> total(mesh.mNumVertices, 0.0);
    bool joints_found = true;
    for (unsigned b = 0; b < mesh.mNumBones && joints_found; ++b) {
      const aiBone& bone = *mesh.mBones[b];
      const aiNode* joint = scene->mRootNode->FindNode(bone.mName);
      joints_found = joint != nullptr;  // else pose-extract names it; here the node places the mesh
      if (!joints_found) break;
      const Eigen::Matrix4d skin = global.at(joint) * to_eigen(bone.mOffsetMatrix);
      for (unsigned w = 0; w < bone.mNumWeights; ++w) {
        const aiVertexWeight& vw = bone.mWeights[w];
        if (vw.mVertexId >= mesh.mNumVertices) continue;
        sum[vw.mVertexId] += vw.mWeight * (skin * to_eigen(mesh.mVertices[vw.mVertexId]).homogeneous()).head<3>();
        total[vw.mVertexId] += vw.mWeight;
      }
    }
    if (!joints_found) continue;
    // Where the skin puts each vertex, and how far that is from where its node puts it.
    // (A skin that places a vertex nowhere, its weights or matrices not finite or past what a
    // float holds, places none: the node does, and pose-extract names what is wrong.)
    Eigen::AlignedBox3d box;
    double apart = 0;
    bool finite = true;
    for (unsigned v = 0; v < mesh.mNumVertices && finite; ++v) {
      const Eigen::Vector3d by_node = (g * to_eigen(mesh.mVertices[v]).homogeneous()).head<3>();
      sum[v] = total[v] > 0 ? Eigen::Vector3d(sum[v] / total[v]) : to_eigen(mesh.mVertices[v]);
      finite = sum[v].allFinite() && sum[v].cwiseAbs().maxCoeff() < 1e30;  // a float can hold it
      apart = std::max(apart, (sum[v] - by_node).norm());
      box.extend(sum[v]);
    }
    if (!finite) continue;
    repeated.add(read_once(*scene, instances, index, node, mesh.mNumVertices ? sum[0] : Eigen::Vector3d::Zero()));
    if (!(apart > 1e-6 * box.diagonal().norm())) continue;
    const Eigen::Matrix4d back = g.inverse();
    for (unsigned v = 0; v < mesh.mNumVertices; ++v) {
      const Eigen::Vector3d local = (back * sum[v].homogeneous()).head<3>();
      mesh.mVertices[v] = aiVector3D(ai_real(local.x()), ai_real(local.y()), ai_real(local.z()));
    }
  }
  return repeated;
}

namespace {

// The helper nodes assimp's FBX importer places above `node`, nearest first.
std::vector<aiNode*> fbx_helpers(aiNode* node) {
  const std::string prefix = std::string(node->mName.C_Str()) + "_$AssimpFbx$_";
  std::vector<aiNode*> out;
  for (aiNode* up = node->mParent; up && std::string(up->mName.C_Str()).rfind(prefix, 0) == 0; up = up->mParent) out.push_back(up);
  return out;
}

using Channels = std::map<std::string, std::vector<aiNodeAnim*>>;  // by node name, over every clip

size_t fold_fbx_chains(aiNode* node, const Channels& channels) {
  size_t folded = 0;
  const auto own = channels.find(node->mName.C_Str());
  if (own != channels.end()) {
    const std::vector<aiNode*> helpers = fbx_helpers(node);
    const bool helper_animated =
        std::any_of(helpers.begin(), helpers.end(), [&](const aiNode* h) { return channels.count(h->mName.C_Str()) > 0; });
    if (!helpers.empty() && !helper_animated) {
      aiMatrix4x4 chain;
      for (aiNode* helper : helpers) {
        // The channel's rotation holds the pre-rotation, the joint's own and the post-rotation
        // itself where FBX (and the chain's helper) has its inverse, P: each key is mended by P twice.
        const std::string name = helper->mName.C_Str();
        if (name.size() >= 13 && name.compare(name.size() - 13, 13, "_PostRotation") == 0) {
          const aiQuaternion p(aiMatrix3x3(helper->mTransformation));
          for (aiNodeAnim* ch : own->second)
            for (unsigned k = 0; k < ch->mNumRotationKeys; ++k) ch->mRotationKeys[k].mValue = ch->mRotationKeys[k].mValue * p * p;
        }
        chain = helper->mTransformation * chain;
        helper->mTransformation = aiMatrix4x4();
      }
      node->mTransformation = chain * node->mTransformation;
      ++folded;
    }
  }
  for (unsigned c = 0; c < node->mNumChildren; ++c) folded += fold_fbx_chains(node->mChildren[c], channels);
  return folded;
}

}  // namespace

size_t fold_fbx_chains_under_channels(aiScene* scene) {
  Channels channels;
  for (unsigned a = 0; a < scene->mNumAnimations; ++a)
    for (unsigned c = 0; c < scene->mAnimations[a]->mNumChannels; ++c)
      channels[scene->mAnimations[a]->mChannels[c]->mNodeName.C_Str()].push_back(scene->mAnimations[a]->mChannels[c]);
  return channels.empty() ? 0 : fold_fbx_chains(scene->mRootNode, channels);
}

}  // namespace spx
