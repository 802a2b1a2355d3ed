#include "extract/asset.hpp"

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <set>

#include "core/error.hpp"
#include "core/file_kind.hpp"
#include "core/format.hpp"
#include "mesh/assimp_scene.hpp"

namespace spx {

struct Asset::Instance {
  const aiNode* node = nullptr;
  const aiMesh* mesh = nullptr;
  size_t offset = 0;                // first vertex in the body's layout
  std::vector<size_t> target_of;    // anim mesh -> index into targets_
  // Skin: per vertex, (bone, weight) pairs, and each bone's joint. A mesh without a skin has
  // one joint, its node.
  std::vector<std::vector<std::pair<int, double>>> weights;
  std::vector<int> bone_joint;
  int rigid_joint = -1;
};

// What to evaluate: node transforms at rest or in a clip, and the morph weights.
struct Asset::Pose {
  const aiAnimation* clip = nullptr;
  double ticks = 0;
  int target = -1;  // a morph target at weight 1 (rest and clips: -1)
  bool placed = true;  // false: as stored, before skin and node transforms
  bool default_weights = false;  // the meshes' default morph weights where no clip drives them (else 0)
  const std::vector<double>* weights = nullptr;  // or these, one per target of the body
};

namespace {

double ticks_per_second(const aiAnimation* a) { return a->mTicksPerSecond > 0 ? a->mTicksPerSecond : 25.0; }

// Keeps of a clip's key times (ticks) those of the file's keys, `asset_times` (seconds, sorted):
// assimp's times are the file's floats times 1 000 in float, so within a float's rounding.
void drop_added_keys(std::set<double>& times, double ticks_per_second, const std::vector<double>& asset_times) {
  for (auto it = times.begin(); it != times.end();) {
    const double s = *it / ticks_per_second;
    const auto next = std::lower_bound(asset_times.begin(), asset_times.end(), s);
    const auto near = [&](std::vector<double>::const_iterator k) {
      return k != asset_times.end() && std::abs(*k - s) <= 1e-6 * std::max(1.0, std::abs(s));
    };
    const bool asset_key = near(next) || (next != asset_times.begin() && near(std::prev(next)));
    it = asset_key ? std::next(it) : times.erase(it);
  }
}

// The key value at `t`: held before the first and after the last key, interpolated between.
template <class Key, class Lerp>
auto sample(const Key* keys, unsigned n, double t, Lerp lerp) -> decltype(lerp(keys[0], keys[0], 0.0)) {
  if (n == 1 || t <= keys[0].mTime) return lerp(keys[0], keys[0], 0.0);
  if (t >= keys[n - 1].mTime) return lerp(keys[n - 1], keys[n - 1], 0.0);
  const Key* hi = std::upper_bound(keys, keys + n, t, [](double x, const Key& k) { return x < k.mTime; });
  const Key* lo = hi - 1;
  const double span = hi->mTime - lo->mTime;
  return lerp(*lo, *hi, span > 0 ? (t - lo->mTime) / span : 0.0);
}

Eigen::Matrix4d local_at(const aiNodeAnim* ch, const aiNode* node, double t) {
  aiVector3D s0, p0;
  aiQuaternion r0;
  node->mTransformation.Decompose(s0, r0, p0);
  auto vec = [](const aiVectorKey& a, const aiVectorKey& b, double f) -> Eigen::Vector3d {
    return (1 - f) * to_eigen(a.mValue) + f * to_eigen(b.mValue);
  };
  auto quat = [](const aiQuatKey& a, const aiQuatKey& b, double f) -> Eigen::Quaterniond {
    return to_eigen(a.mValue).normalized().slerp(f, to_eigen(b.mValue).normalized());
  };
  const Eigen::Vector3d p = ch->mNumPositionKeys ? sample(ch->mPositionKeys, ch->mNumPositionKeys, t, vec) : to_eigen(p0);
  const Eigen::Quaterniond r =
      ch->mNumRotationKeys ? sample(ch->mRotationKeys, ch->mNumRotationKeys, t, quat) : to_eigen(r0).normalized();
  const Eigen::Vector3d s = ch->mNumScalingKeys ? sample(ch->mScalingKeys, ch->mNumScalingKeys, t, vec) : to_eigen(s0);
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topLeftCorner<3, 3>() = r.toRotationMatrix() * s.asDiagonal();
  m.topRightCorner<3, 1>() = p;
  return m;
}

std::string mesh_name(const aiScene* scene, unsigned index) {
  const std::string name = scene->mMeshes[index]->mName.C_Str();
  return name.empty() ? "mesh-" + std::to_string(index) : name;
}

std::string target_name(const aiMesh* mesh, unsigned k) {
  const std::string name = mesh->mAnimMeshes[k]->mName.C_Str();
  return name.empty() ? "target-" + std::to_string(k) : name;
}

// Vertex `v` of `mesh`'s morph target `k`: a target that gives no positions (a glTF target of
// normals alone) moves no vertex.
Eigen::Vector3d target_position(const aiMesh* mesh, size_t k, unsigned v) {
  const aiAnimMesh* target = mesh->mAnimMeshes[k];
  return target->mVertices && v < target->mNumVertices ? to_eigen(target->mVertices[v]) : to_eigen(mesh->mVertices[v]);
}

// The clip's morph weights for one mesh instance at `t`, one per anim mesh; where the clip does
// not drive them, the mesh's default weights (`defaults`: what glTF draws then) or zero.
std::vector<double> clip_weights(const aiAnimation* clip, const aiNode* node, const aiMesh* mesh, double t,
                                 bool defaults) {
  std::vector<double> w(mesh->mNumAnimMeshes, 0.0);
  for (unsigned k = 0; defaults && k < mesh->mNumAnimMeshes; ++k) w[k] = mesh->mAnimMeshes[k]->mWeight;
  for (unsigned c = 0; clip && c < clip->mNumMorphMeshChannels; ++c) {
    const aiMeshMorphAnim* ch = clip->mMorphMeshChannels[c];
    const std::string name = ch->mName.C_Str();
    if ((name != node->mName.C_Str() && name != mesh->mName.C_Str()) || ch->mNumKeys == 0) continue;
    // Weights of the two keys around t, by target index.
    auto weights_of = [&](const aiMeshMorphKey& key) {
      std::vector<double> v(w.size(), 0.0);
      for (unsigned j = 0; j < key.mNumValuesAndWeights; ++j)
        if (key.mValues[j] < v.size()) v[key.mValues[j]] = key.mWeights[j];
      return v;
    };
    auto lerp = [&](const aiMeshMorphKey& a, const aiMeshMorphKey& b, double f) {
      std::vector<double> va = weights_of(a), vb = weights_of(b);
      for (size_t k = 0; k < va.size(); ++k) va[k] = f == 0 ? va[k] : (1 - f) * va[k] + f * vb[k];
      return va;
    };
    w = sample(ch->mKeys, ch->mNumKeys, t, lerp);
  }
  return w;
}

}  // namespace

Asset::Asset(const std::string& path, const std::string& wanted) : path_(path), importer_(new Assimp::Importer) {
  check_importable(path, "an asset", "glTF/GLB, FBX or COLLADA");
  // Triangulate only: vertices, skins and morph targets stay as the file has them.
  ClipMends mends;
  scene_ = read_scene(*importer_, path, 0, "asset", &mends);
  if (has_polygons(*scene_)) triangulate(*importer_, face_lists(*scene_), path, "asset", fanned_);
  face_out_mirrored(const_cast<aiScene*>(scene_));  // the importer's own scene, ours to change
  fold_fbx_chains_under_channels(const_cast<aiScene*>(scene_));

  const std::vector<std::pair<const aiNode*, unsigned>> placed = mesh_instances(*scene_->mRootNode);
  list_meshes(placed, wanted);
  use_meshes(placed);
  read_clips(mends);
}

// Every mesh instance the hierarchy places, and which of them make the body.
void Asset::list_meshes(const std::vector<std::pair<const aiNode*, unsigned>>& placed, const std::string& wanted) {
  std::vector<std::string> names;
  for (const auto& [node, index] : placed) {
    const aiMesh* m = scene_->mMeshes[index];
    AssetMesh info;
    info.name = mesh_name(scene_, index);
    info.node = node->mName.C_Str();
    info.vertices = m->mNumVertices;
    for (unsigned f = 0; f < m->mNumFaces; ++f) (m->mFaces[f].mNumIndices == 3 ? info.triangles : info.other_faces)++;
    info.joints = m->mNumBones;
    for (unsigned k = 0; k < m->mNumAnimMeshes; ++k) info.morph_targets.push_back(target_name(m, k));
    info.used = info.triangles > 0 && (wanted.empty() || wanted == info.name || wanted == info.node);
    meshes_.push_back(info);
    if (info.triangles) names.push_back(info.name);
  }
  if (names.empty()) fail_input(path_, "contains no triangle mesh");
  if (std::none_of(meshes_.begin(), meshes_.end(), [](const AssetMesh& m) { return m.used; }))
    fail_option("mesh", "no mesh or node named '" + wanted + "' in " + path_ + " (its meshes: " + quoted_names(names) + ")");
}

// The used instances: their vertices laid out in turn, their triangles, morph targets and skins.
void Asset::use_meshes(const std::vector<std::pair<const aiNode*, unsigned>>& placed) {
  for (size_t i = 0; i < placed.size(); ++i) {
    if (!meshes_[i].used) continue;
    Instance inst;
    inst.node = placed[i].first;
    inst.mesh = scene_->mMeshes[placed[i].second];
    inst.offset = vertex_count_;
    // A body split into meshes shares its targets by name; within one mesh, targets of one name
    // (an exporter's "target" for each) are each their own, matched to another mesh's in order.
    std::map<std::string, size_t> seen;
    for (const auto& t : meshes_[i].morph_targets) {
      const size_t nth = seen[t]++;
      size_t k = 0;
      for (size_t n = 0; k < targets_.size(); ++k)
        if (targets_[k] == t && n++ == nth) break;
      if (k == targets_.size()) targets_.push_back(t);
      inst.target_of.push_back(k);
    }
    const aiMesh* m = inst.mesh;
    for (unsigned f = 0; f < m->mNumFaces; ++f) {
      const aiFace& face = m->mFaces[f];
      if (face.mNumIndices != 3) continue;
      triangles_.emplace_back(int(inst.offset + face.mIndices[0]), int(inst.offset + face.mIndices[1]),
                              int(inst.offset + face.mIndices[2]));
    }
    if (m->mNumBones) {
      inst.weights.resize(m->mNumVertices);
      for (unsigned b = 0; b < m->mNumBones; ++b) {
        const aiBone* bone = m->mBones[b];
        const aiNode* joint = scene_->mRootNode->FindNode(bone->mName);
        if (!joint)
          fail_input(path_, "mesh '" + meshes_[i].name + "': joint '" + bone->mName.C_Str() +
                                "' is no node of the scene's tree (a joint outside the scene the file shows)");
        inst.bone_joint.push_back(joint_of(joint, to_eigen(bone->mOffsetMatrix)));
        for (unsigned w = 0; w < bone->mNumWeights; ++w) {
          const aiVertexWeight& vw = bone->mWeights[w];
          if (vw.mVertexId < m->mNumVertices && vw.mWeight > 0) inst.weights[vw.mVertexId].emplace_back(int(b), vw.mWeight);
        }
      }
      for (const auto& w : inst.weights) unweighted_ += w.empty();
    } else {
      inst.rigid_joint = joint_of(inst.node, Eigen::Matrix4d::Identity());
    }
    vertex_count_ += m->mNumVertices;
    instances_.push_back(std::move(inst));
  }
  link_joint_parents();
}

// The joint of (node, inverse bind), added on first use.
int Asset::joint_of(const aiNode* node, const Eigen::Matrix4d& inverse_bind) {
  int bound = 0;
  for (size_t j = 0; j < joints_.size(); ++j) {
    if (joint_nodes_[j] != node) continue;
    if (joints_[j].inverse_bind == inverse_bind) return int(j);
    ++bound;
  }
  AssetJoint joint;
  joint.name = std::string(node->mName.C_Str()) + (bound ? "#" + std::to_string(bound + 1) : "");
  joint.inverse_bind = inverse_bind;
  joints_.push_back(joint);
  joint_nodes_.push_back(node);
  return int(joints_.size() - 1);
}

void Asset::link_joint_parents() {
  for (size_t j = 0; j < joints_.size(); ++j)
    for (const aiNode* up = joint_nodes_[j]->mParent; up && joints_[j].parent < 0; up = up->mParent) {
      const auto it = std::find(joint_nodes_.begin(), joint_nodes_.end(), up);
      if (it != joint_nodes_.end()) joints_[j].parent = int(it - joint_nodes_.begin());
    }
}

// Every clip with its distinct key times: the file's, not those that made its cubic splines
// linear; and the channels passed over (`mends`, per clip).
void Asset::read_clips(const ClipMends& mends) {
  const std::vector<AddedKeys>& added = mends.added_keys;
  for (unsigned a = 0; a < scene_->mNumAnimations; ++a) {
    const aiAnimation* anim = scene_->mAnimations[a];
    AssetClip clip;
    clip.name = anim->mName.C_Str();
    clip.ticks_per_second = ticks_per_second(anim);
    std::set<double> times;
    for (unsigned c = 0; c < anim->mNumChannels; ++c) {
      const aiNodeAnim* ch = anim->mChannels[c];
      for (unsigned k = 0; k < ch->mNumPositionKeys; ++k) times.insert(ch->mPositionKeys[k].mTime);
      for (unsigned k = 0; k < ch->mNumRotationKeys; ++k) times.insert(ch->mRotationKeys[k].mTime);
      for (unsigned k = 0; k < ch->mNumScalingKeys; ++k) times.insert(ch->mScalingKeys[k].mTime);
      clip.keys += ch->mNumPositionKeys + ch->mNumRotationKeys + ch->mNumScalingKeys;
    }
    for (unsigned c = 0; c < anim->mNumMorphMeshChannels; ++c) {
      const aiMeshMorphAnim* ch = anim->mMorphMeshChannels[c];
      for (unsigned k = 0; k < ch->mNumKeys; ++k) times.insert(ch->mKeys[k].mTime);
      clip.keys += ch->mNumKeys;
    }
    clip.node_channels = anim->mNumChannels;
    // Only those that weigh a target of the body's meshes: a weights channel on a joint, on a
    // mesh without targets or on a mesh --mesh left out moves nothing the poses hold.
    for (unsigned c = 0; c < anim->mNumMorphMeshChannels; ++c) {
      const aiMeshMorphAnim* ch = anim->mMorphMeshChannels[c];
      const std::string name = ch->mName.C_Str();
      clip.morph_channels += ch->mNumKeys > 0 && std::any_of(instances_.begin(), instances_.end(), [&](const Instance& i) {
        return i.mesh->mNumAnimMeshes > 0 && (name == i.node->mName.C_Str() || name == i.mesh->mName.C_Str());
      });
    }
    if (a < mends.passed_over.size()) clip.passed_over = mends.passed_over[a];
    if (a < added.size() && added[a].added > 0) {
      drop_added_keys(times, clip.ticks_per_second, added[a].asset_times);
      clip.keys -= added[a].added;
    }
    // Key times of separate channels that differ by rounding are one frame.
    for (double t : times) {
      const double s = t / clip.ticks_per_second;
      if (clip.frames.empty() || s - clip.frames.back() > 1e-9 * std::max(1.0, std::abs(s))) clip.frames.push_back(s);
    }
    clip.end = clip.frames.empty() ? 0.0 : clip.frames.back();
    clips_.push_back(clip);
  }
}

Asset::~Asset() = default;

std::vector<std::string> Asset::clip_labels() const {
  std::vector<std::string> labels;
  for (size_t i = 0; i < clips_.size(); ++i)
    labels.push_back(clips_[i].name.empty() ? std::to_string(i) + " (unnamed)" : clips_[i].name);
  return labels;
}

size_t Asset::find_clip(const std::string& which) const {
  if (clips_.empty()) fail_input(path_, "has no animation clips (--animation needs one)");
  for (size_t i = 0; i < clips_.size(); ++i)
    if (clips_[i].name == which) return i;
  if (!which.empty() && std::all_of(which.begin(), which.end(), ::isdigit)) {
    const size_t i = std::stoul(which);
    if (i < clips_.size()) return i;
    fail_option("animation", "no clip " + which + " in " + path_ + " (it has clips 0.." + std::to_string(clips_.size() - 1) + ")");
  }
  fail_option("animation", "no clip named '" + which + "' in " + path_ + " (its clips: " + quoted_names(clip_labels()) + ")");
}

std::vector<Eigen::Matrix4d> Asset::joint_matrices(const Pose& pose) const {
  std::map<std::string, const aiNodeAnim*> channels;
  for (unsigned c = 0; pose.clip && c < pose.clip->mNumChannels; ++c)
    channels[pose.clip->mChannels[c]->mNodeName.C_Str()] = pose.clip->mChannels[c];
  // The clip's channels replace the local transforms of the nodes they move.
  const std::map<const aiNode*, Eigen::Matrix4d> globals = node_globals(*scene_->mRootNode, [&](const aiNode& node) {
    const auto ch = channels.find(node.mName.C_Str());
    return ch == channels.end() ? to_eigen(node.mTransformation) : local_at(ch->second, &node, pose.ticks);
  });
  std::vector<Eigen::Matrix4d> out;
  for (size_t j = 0; j < joints_.size(); ++j) {
    const Eigen::Matrix4d& global = globals.at(joint_nodes_[j]);
    // A rigid part's matrix is its node's, bit for bit.
    out.push_back(joints_[j].inverse_bind.isIdentity(0.0) ? global : Eigen::Matrix4d(global * joints_[j].inverse_bind));
  }
  return out;
}

std::vector<Eigen::Vector3d> Asset::evaluate(const Pose& pose) const {
  const std::vector<Eigen::Matrix4d> joint = joint_matrices(pose);
  std::vector<Eigen::Vector3d> out(vertex_count_);
  for (const Instance& inst : instances_) {
    const aiMesh* m = inst.mesh;
    std::vector<double> w = clip_weights(pose.clip, inst.node, m, pose.ticks, pose.default_weights);
    for (size_t k = 0; k < inst.target_of.size(); ++k) {
      if (pose.target >= 0) w[k] = inst.target_of[k] == size_t(pose.target) ? 1.0 : 0.0;
      if (pose.weights) w[k] = (*pose.weights)[inst.target_of[k]];
    }
    // Morph targets first (glTF applies them before the skin). One target alone takes its
    // stored positions exactly, so a target written from an OBJ pose reads back bit for bit.
    int alone = -1;
    if (std::count(w.begin(), w.end(), 0.0) + 1 == std::ptrdiff_t(w.size()))
      for (size_t k = 0; k < w.size(); ++k)
        if (w[k] == 1.0) alone = int(k);
    std::vector<Eigen::Vector3d> p(m->mNumVertices);
    for (unsigned v = 0; v < m->mNumVertices; ++v) {
      if (alone >= 0) {
        p[v] = target_position(m, size_t(alone), v);
        continue;
      }
      p[v] = to_eigen(m->mVertices[v]);
      for (size_t k = 0; k < w.size(); ++k)
        if (w[k] != 0.0) p[v] += w[k] * (target_position(m, k, v) - to_eigen(m->mVertices[v]));
    }
    if (pose.placed && !inst.bone_joint.empty()) {
      for (unsigned v = 0; v < m->mNumVertices; ++v) {
        const auto& vw = inst.weights[v];
        if (vw.empty()) continue;
        Eigen::Vector3d sum = Eigen::Vector3d::Zero();
        double total = 0;
        for (const auto& [b, weight] : vw) {
          sum += weight * (joint[size_t(inst.bone_joint[size_t(b)])] * p[v].homogeneous()).head<3>();
          total += weight;
        }
        p[v] = sum / total;
      }
    } else if (pose.placed) {
      const Eigen::Matrix4d& g = joint[size_t(inst.rigid_joint)];
      if (!g.isIdentity(0.0))
        for (auto& q : p) q = (g * q.homogeneous()).head<3>();
    }
    std::copy(p.begin(), p.end(), out.begin() + std::ptrdiff_t(inst.offset));
  }
  return out;
}

std::vector<Eigen::Vector3d> Asset::rest(bool at_default_weights) const {
  Pose pose;
  pose.default_weights = at_default_weights;
  return evaluate(pose);
}

std::vector<Eigen::Vector3d> Asset::stored() const {
  Pose pose;
  pose.placed = false;
  return evaluate(pose);
}

Asset::Pose Asset::clip_pose(size_t clip, double seconds) const {
  Pose pose;
  pose.clip = scene_->mAnimations[clip];
  pose.ticks = seconds * clips_[clip].ticks_per_second;
  pose.default_weights = true;
  return pose;
}

std::vector<Eigen::Vector3d> Asset::morph_target(size_t target) const {
  Pose pose;
  pose.target = int(target);
  return evaluate(pose);
}

std::vector<Eigen::Vector3d> Asset::morphed(const std::vector<double>& weights) const {
  if (weights.size() != targets_.size()) fail_usage("morphed", "one weight per morph target");
  Pose pose;
  pose.weights = &weights;
  return evaluate(pose);
}

std::vector<double> Asset::morph_weights(size_t clip, double seconds) const {
  const Pose pose = clip_pose(clip, seconds);
  std::vector<double> out(targets_.size(), 0.0);
  std::vector<char> given(targets_.size(), 0);
  for (const Instance& inst : instances_) {
    const std::vector<double> w = clip_weights(pose.clip, inst.node, inst.mesh, pose.ticks, true);
    for (size_t k = 0; k < inst.target_of.size(); ++k)
      if (!given[inst.target_of[k]]) out[inst.target_of[k]] = w[k], given[inst.target_of[k]] = 1;
  }
  return out;
}

std::vector<Eigen::Vector3d> Asset::at_time(size_t clip, double seconds) const {
  return evaluate(clip_pose(clip, seconds));
}

std::vector<std::vector<std::pair<int, double>>> Asset::vertex_joints() const {
  std::vector<std::vector<std::pair<int, double>>> out(vertex_count_);
  for (const Instance& inst : instances_)
    for (unsigned v = 0; v < inst.mesh->mNumVertices; ++v) {
      auto& w = out[inst.offset + v];
      if (inst.bone_joint.empty()) {
        w = {{inst.rigid_joint, 1.0}};
        continue;
      }
      double total = 0;
      for (const auto& [b, weight] : inst.weights[v]) total += weight;
      for (const auto& [b, weight] : inst.weights[v]) w.emplace_back(inst.bone_joint[size_t(b)], weight / total);
    }
  return out;
}

std::vector<size_t> Asset::joints_named(const std::vector<std::string>& names) const {
  std::vector<size_t> out;
  for (const std::string& name : names) {
    const auto it = std::find_if(joints_.begin(), joints_.end(), [&](const AssetJoint& j) { return j.name == name; });
    if (it == joints_.end())
      fail_input(path_, "has no joint '" + name + "', which the proxy's skin uses: not the asset the proxy was made from");
    out.push_back(size_t(it - joints_.begin()));
  }
  return out;
}

std::vector<Eigen::Matrix4d> Asset::rest_joint_matrices() const { return joint_matrices(Pose{}); }

std::vector<Eigen::Matrix4d> Asset::joint_matrices(size_t clip, double seconds) const {
  return joint_matrices(clip_pose(clip, seconds));
}

json Asset::inventory() const {
  json meshes = json::array(), clips = json::array();
  size_t skinned = 0;
  for (const auto& m : meshes_) {
    meshes.push_back({{"name", m.name}, {"node", m.node}, {"vertices", m.vertices}, {"triangles", m.triangles},
                      {"other_faces", m.other_faces}, {"joints", m.joints}, {"morph_targets", m.morph_targets},
                      {"used", m.used}});
    skinned += m.joints > 0;
  }
  for (size_t i = 0; i < clips_.size(); ++i) {
    const auto& c = clips_[i];
    clips.push_back({{"index", i}, {"name", c.name}, {"duration", c.end}, {"frames", c.frames.size()},
                     {"keys", c.keys}, {"node_channels", c.node_channels}, {"morph_channels", c.morph_channels},
                     {"channels_passed_over", c.passed_over},
                     {"ticks_per_second", c.ticks_per_second}});
  }
  return {{"meshes", meshes}, {"skins", skinned}, {"clips", clips}, {"morph_targets", targets_},
          {"unweighted_vertices", unweighted_}, {"polygons_fanned", fanned_.polygons}};
}

}  // namespace spx
