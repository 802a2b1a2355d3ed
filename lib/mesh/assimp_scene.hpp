#pragma once
// A file read by assimp, or one error line that says why not (assimp's own words mislead for
// glTF: "no suitable reader found" for a document whose JSON does not parse).
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <assimp/Importer.hpp>
#include <assimp/scene.h>

#include <functional>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "mesh/gltf_input.hpp"
#include "mesh/mesh.hpp"

namespace spx {

// assimp's single-precision types as Eigen's in double.
Eigen::Matrix4d to_eigen(const aiMatrix4x4& m);
inline Eigen::Vector3d to_eigen(const aiVector3D& v) { return {v.x, v.y, v.z}; }
inline Eigen::Quaterniond to_eigen(const aiQuaternion& q) { return Eigen::Quaterniond(q.w, q.x, q.y, q.z); }

// Every node's global transform: the product of the local transforms from the root down, each
// node's local given by `local` (where none is given, the node's own: the still pose).
using NodeLocal = std::function<Eigen::Matrix4d(const aiNode&)>;
std::map<const aiNode*, Eigen::Matrix4d> node_globals(const aiNode& root, const NodeLocal& local = {});

// Every (node, mesh index) pair the hierarchy places, depth first: a mesh two nodes place, twice.
std::vector<std::pair<const aiNode*, unsigned>> mesh_instances(const aiNode& root);

// importer.ReadFile(path, flags). A .gltf or .glb is first checked for the extensions it requires
// (exit 3 for one the tools cannot honour) and, where it holds what assimp would read wrong
// (meshes instanced by a node, integer data meant as floats, a mirrored node a clip moves, STEP
// keys, cubic splines, channels of KHR_animation_pointer), read from memory made right
// (mesh/gltf_input.hpp); `clips`, where given, receives what the clips' mends tell per clip (empty
// for a file of another kind): the keys the cubic splines' rewrite added, and the channels passed
// over as moving no geometry. Where assimp cannot read a .gltf or .glb, the project's glTF reader
// says what is wrong with the file ("not a glTF: its JSON does not parse (...)", "truncated",
// "contains no mesh"); a .gltf it finds nothing wrong with (a buffer whose URI is
// percent-encoded, "My%20Body.bin", which assimp opens as written) is read again from memory as
// the GLB that reader makes of it. Otherwise throws spx::Error naming `path` (exit 2): "cannot read
// <what>: <assimp's error>"; and so where a face has no corners or names a vertex past its mesh's,
// which assimp keeps (a file cut short; its triangulation would abort the process), and where an
// OFF, PLY, OBJ or COLLADA file holds what assimp's reader would read wrong or never finish
// (mesh/file_checks.hpp); and where a check of assimp's own fails (ai_assert, which would abort
// the process: a damaged FBX). The file is read without flags and then post-processed with them,
// as ReadFile does. The scene is the importer's.
const aiScene* read_scene(Assimp::Importer& importer, const std::string& path, unsigned flags, const std::string& what,
                          ClipMends* clips = nullptr);

// importer.ApplyPostProcessing(flags) on the scene it read, or exit 2 as read_scene says, a failed
// check of assimp's own (ai_assert, which would abort the process) included.
const aiScene* post_processed(Assimp::Importer& importer, unsigned flags, const std::string& path,
                              const std::string& what);

// assimp's error reading `path` said: spx::Error (exit 2) "cannot read <what>: <error>" (an error
// past 320 characters keeps its first 160 and last 120, saying how many it leaves out), or
// std::bad_alloc where the error is assimp's word for it (the tools then say out of memory).
[[noreturn]] void fail_reading(const std::string& path, const std::string& what, const std::string& error);

// Each mesh that a node places by a mirroring transform (its global transform's determinant below
// 0) gets its faces' order reversed, as glTF says and renderers draw it: with its vertices
// transformed and the order kept, the part would face inward (and be no solid). Where other nodes
// place it unmirrored, the reversed faces are a copy of the mesh of its own. A mesh with bones is
// left as it is (its skin places it, not its node).
void face_out_mirrored(aiScene* scene);

// aiProcess_PreTransformVertices places every mesh by its node, but a skinned mesh is placed by
// its skin: glTF ignores a skinned mesh's node, and pose-extract's rest (extract/asset) follows
// the joints. Each skinned vertex goes to sum_b w_b (joint b's global * its inverse bind) v / sum_b
// w_b at the nodes' own transforms (one no joint weighs stays as stored), taken back through its
// node's inverse, which PreTransformVertices then applies. A mesh both place alike (within 1e-6
// of its size: the usual file) is left as it is, to the bit. A skinned mesh several nodes place is
// drawn by each where its skin puts it, in one place: it is read once, at its first node, and the
// triangles the others would have added are returned as repeated.
RepeatedTriangles place_skinned_by_skin(aiScene* scene);

// assimp 5.2's FBX importer keeps a joint X's translation, pre-rotation, rotation, post-rotation
// and scaling as a chain of helper nodes above it ("X_$AssimpFbx$_PreRotation", ...), and yet,
// where those are all X's transform has, gives a clip's channel for X itself holding X's whole
// local transform, pre- and post-rotation baked in (assimp issue 5759): played, the chain turned
// and moved the joint twice (Maya's joint orients and Mixamo's rigs carry pre-rotations on most
// joints). Where a clip has a channel for X and no helper of X has one, the chain is folded into X:
// X's transform becomes the chain's product and each helper's the identity, so the still pose is
// the same and the channel stands where the chain stood. Returns how many chains were folded.
size_t fold_fbx_chains_under_channels(aiScene* scene);

}  // namespace spx
