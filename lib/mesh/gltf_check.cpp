#include "mesh/gltf_check.hpp"

#include <cmath>
#include <cstdio>
#include <set>
#include <vector>

#include "core/error.hpp"
#include "core/format.hpp"
#include "mesh/gltf_accessors.hpp"

namespace spx {

using namespace detail;

namespace {

std::string at(const std::string& list, size_t i) { return list + "[" + std::to_string(i) + "]"; }

// A key time as a float holds it (two times apart in their last digits still read apart).
std::string seconds(double t) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.7g s", t);
  return buf;
}

// `object`'s list `name`, read in place (empty where it has none, or where `object` is no object).
// The document's lists are lists of objects where given: the container's reader and the lists'
// own checks below make sure of it.
const json& list_of(const json& object, const char* name) {
  static const json none = json::array();
  if (!object.is_object()) return none;
  const auto it = object.find(name);
  return it != object.end() && it->is_array() ? *it : none;
}

class Rules {
 public:
  Rules(const GltfFile& file, const std::string& path)
      : file_(file), path_(path), nodes_(list_of(file.doc, "nodes")), meshes_(list_of(file.doc, "meshes")),
        skins_(list_of(file.doc, "skins")), accessors_(list_of(file.doc, "accessors")) {
    for (const char* name : {"skins", "animations", "accessors"})
      for (const json& item : list_of(file.doc, name))
        if (!item.is_object()) fail(std::string("its '") + name + "' is not a list of objects");
  }

  void check() {
    check_tree();
    for (size_t m = 0; m < meshes_.size(); ++m) check_mesh(m);
    for (size_t s = 0; s < skins_.size(); ++s) check_skin(s);
    for (size_t n = 0; n < nodes_.size(); ++n) check_weighted_joints(n);
    const json& clips = list_of(file_.doc, "animations");
    for (size_t a = 0; a < clips.size(); ++a) check_clip(clips[a], at("animations", a));
  }

 private:
  [[noreturn]] void fail(const std::string& what) const { fail_input(path_, what); }

  // `object`'s index member `key` into `holder`'s list of `size` `noun`s, or SIZE_MAX where it has none.
  size_t index(const json& object, const char* key, size_t size, const std::string& where, const char* noun,
               const char* holder = "the file") const {
    const auto it = object.find(key);
    if (it == object.end()) return SIZE_MAX;
    if (!is_index(*it)) fail(where + "." + key + " is not an index (" + it->dump() + ")");
    const size_t i = size_t(it->get<int64_t>());
    if (i >= size)
      fail(where + "." + key + " is " + std::to_string(i) + ", and " + holder + " has " + counted(size, noun));
    return i;
  }

  // The node `v` names, element `k` of the list `list`, or exit 2 where it names none.
  size_t node_in_list(const json& v, const std::string& list, size_t k) const {
    if (!is_index(v) || size_t(v.get<int64_t>()) >= nodes_.size())
      fail(at(list, k) + " is " + v.dump() + ", not one of the file's " + std::to_string(nodes_.size()) + " nodes");
    return size_t(v.get<int64_t>());
  }

  // Accessor `a`, its componentType and type as the spec lists them, and a count of at least 1.
  const json& accessor(size_t a, const std::string& where) const {
    const json& acc = accessors_[a];
    static const std::set<int> types{5120, 5121, 5122, 5123, 5125, kFloat};
    static const std::set<std::string> shapes{"SCALAR", "VEC2", "VEC3", "VEC4", "MAT2", "MAT3", "MAT4"};
    const auto kind = acc.find("componentType");
    if (kind == acc.end() || !kind->is_number_integer() || !types.count(kind->get<int>()) || !shapes.count(text(acc, "type")))
      fail(where + " (accessor " + std::to_string(a) + ") has no componentType and type as glTF lists them");
    if (gltf_whole_number(acc, "count", 0, path_, "an accessor") == 0)
      fail(where + " (accessor " + std::to_string(a) + ") has no elements (a count of at least 1)");
    return acc;
  }

  // The node tree: indices in range, each node a child of one parent at most, none its own
  // ancestor (a second parent would move it twice; a cycle never ends).
  void check_tree() const {
    std::vector<size_t> parent(nodes_.size(), SIZE_MAX);
    for (size_t n = 0; n < nodes_.size(); ++n) {
      const json& node = nodes_[n];
      const std::string where = at("nodes", n);
      index(node, "mesh", meshes_.size(), where, "mesh");
      index(node, "skin", skins_.size(), where, "skin");
      const auto children = node.find("children");
      if (children == node.end()) continue;
      if (!children->is_array()) fail(where + ".children is not a list");
      for (size_t k = 0; k < children->size(); ++k) {
        const size_t child = node_in_list((*children)[k], where + ".children", k);
        if (child == n) fail(where + " lists itself among its children");
        if (parent[child] != SIZE_MAX)
          fail(at("nodes", child) + " is a child of both " + at("nodes", parent[child]) + " and " + where +
               " (a node has one parent)");
        parent[child] = n;
      }
    }
    for (size_t n = 0; n < nodes_.size(); ++n) {  // one parent each: a walk up ends, or comes back within nodes_ steps
      size_t up = parent[n];
      for (size_t steps = 0; up != SIZE_MAX; up = parent[up])
        if (up == n || ++steps > nodes_.size()) fail(at("nodes", n) + " is its own ancestor (its children lead back to it)");
    }
  }

  // Each primitive's attributes and its targets' hold an element for each of its vertices (its
  // POSITION's count), and its triangles' indices whole triangles: assimp drops a shorter
  // attribute whole (a skin's weights: the body unskinned), and the indices past the last triangle.
  void check_mesh(size_t m) const {
    const json& primitives = list_of(meshes_[m], "primitives");
    for (size_t p = 0; p < primitives.size(); ++p) {
      const std::string where = at(at("meshes", m) + ".primitives", p);
      const auto attributes = primitives[p].is_object() ? primitives[p].find("attributes") : primitives[p].end();
      if (attributes == primitives[p].end() || !attributes->is_object()) continue;
      const size_t position = index(*attributes, "POSITION", accessors_.size(), where + ".attributes", "accessor");
      if (position == SIZE_MAX) continue;
      const size_t vertices = count_of(position, where + ".attributes.POSITION");
      auto check_counts = [&](const json& set, const std::string& in) {
        if (!set.is_object()) return;
        for (const auto& [name, value] : set.items()) {
          const size_t a = index(set, name.c_str(), accessors_.size(), in, "accessor");
          const size_t n = count_of(a, in + "." + name);
          if (n < vertices)
            fail(in + "." + name + " (accessor " + std::to_string(a) + ") holds " + std::to_string(n) +
                 " elements for the primitive's " + std::to_string(vertices) + " vertices (its POSITION's count)");
        }
      };
      check_counts(*attributes, where + ".attributes");
      const json& targets = list_of(primitives[p], "targets");
      for (size_t t = 0; t < targets.size(); ++t) check_counts(targets[t], at(where + ".targets", t));
      const size_t indices = index(primitives[p], "indices", accessors_.size(), where, "accessor");
      const json mode = primitives[p].value("mode", json(4));
      if (indices == SIZE_MAX || mode != 4) continue;
      const size_t n = count_of(indices, where + ".indices");
      if (n % 3 != 0)
        fail(where + ".indices (accessor " + std::to_string(indices) + ") holds " + std::to_string(n) +
             " indices, not a whole number of triangles (3 each)");
    }
  }
  size_t count_of(size_t a, const std::string& where) const {
    return gltf_whole_number(accessor(a, where), "count", 0, path_, "an accessor");
  }

  void check_skin(size_t s) const {
    const json& skin = skins_[s];
    const std::string where = at("skins", s);
    const auto joints = skin.find("joints");
    if (joints == skin.end() || !joints->is_array() || joints->empty())
      fail(where + " has no joints (glTF requires the list of its joint nodes)");
    std::set<size_t> seen;
    for (size_t j = 0; j < joints->size(); ++j) {
      const size_t joint = node_in_list((*joints)[j], where + ".joints", j);
      if (!seen.insert(joint).second)
        fail(where + ".joints lists node " + std::to_string(joint) +
             " twice (a vertex weighted to either would be weighted to one)");
    }
    index(skin, "skeleton", nodes_.size(), where, "node");
    const size_t matrices = index(skin, "inverseBindMatrices", accessors_.size(), where, "accessor");
    if (matrices == SIZE_MAX) return;
    const std::string what = where + ".inverseBindMatrices";
    const json& acc = accessor(matrices, what);
    if (text(acc, "type") != "MAT4" || acc["componentType"] != kFloat)
      fail(what + " (accessor " + std::to_string(matrices) + ") is not MAT4 floats");
    const size_t count = gltf_whole_number(acc, "count", 0, path_, "an accessor");
    if (count < joints->size())
      fail(what + " (accessor " + std::to_string(matrices) + ") holds " + std::to_string(count) +
           (count == 1 ? " matrix" : " matrices") + " for " + counted(joints->size(), "joint"));
  }

  // Every joint a skinned vertex is weighted to (a weight not 0) is one of its skin's: assimp
  // would read past the skin's bones.
  void check_weighted_joints(size_t n) const {
    const json& node = nodes_[n];
    const size_t skin = index(node, "skin", skins_.size(), at("nodes", n), "skin");
    const size_t mesh = index(node, "mesh", meshes_.size(), at("nodes", n), "mesh");
    if (skin == SIZE_MAX || mesh == SIZE_MAX) return;
    const size_t joints = skins_[skin]["joints"].size();
    const json& primitives = list_of(meshes_[mesh], "primitives");
    for (size_t p = 0; p < primitives.size(); ++p) {
      const auto found = primitives[p].find("attributes");  // end() where the primitive is no object
      if (found == primitives[p].end() || !found->is_object()) continue;
      const json& attributes = *found;
      const std::string where = at(at("meshes", mesh) + ".primitives", p);
      for (int set = 0;; ++set) {
        const std::string j_name = "JOINTS_" + std::to_string(set), w_name = "WEIGHTS_" + std::to_string(set);
        const size_t j_acc = index(attributes, j_name.c_str(), accessors_.size(), where + ".attributes", "accessor");
        if (j_acc == SIZE_MAX) break;
        const json& ids_acc = accessor(j_acc, where + "." + j_name);
        if (text(ids_acc, "type") != "VEC4" || (ids_acc["componentType"] != 5121 && ids_acc["componentType"] != 5123))
          fail(where + "." + j_name + " (accessor " + std::to_string(j_acc) + ") is not VEC4 unsigned bytes or shorts");
        const size_t w_acc = index(attributes, w_name.c_str(), accessors_.size(), where + ".attributes", "accessor");
        const std::vector<double> ids = values(j_acc, where + "." + j_name);
        const std::vector<double> weights = w_acc == SIZE_MAX ? std::vector<double>() : values(w_acc, where + "." + w_name);
        for (size_t k = 0; k < ids.size(); ++k) {
          if (!(ids[k] >= double(joints)) || (k < weights.size() && weights[k] == 0)) continue;
          fail("vertex " + std::to_string(k / 4) + " of " + where + " is weighted to joint " +
               std::to_string(int64_t(ids[k])) + " (" + j_name + "), past " + at("skins", skin) + "'s " +
               std::to_string(joints) + " joints");
        }
      }
    }
  }

  // An accessor's values as a reader takes them (its elements' components one after another).
  std::vector<double> values(size_t a, const std::string& where) const {
    return accessor_values(file_, accessor(a, where), path_);
  }

  void check_clip(const json& clip, const std::string& where) const {
    const json& samplers = list_of(clip, "samplers");
    const json& channels = list_of(clip, "channels");
    for (size_t c = 0; c < channels.size(); ++c) {
      const std::string channel = at(where + ".channels", c);
      if (!channels[c].is_object()) fail(channel + " is not an object");
      const size_t s = index(channels[c], "sampler", samplers.size(), channel, "sampler", "its clip");
      if (s == SIZE_MAX) fail(channel + " has no sampler");
      const json target = channels[c].value("target", json::object());
      if (!target.is_object()) fail(channel + ".target is not an object");
      const ChannelTarget moved = channel_target(channels[c]);
      if (moved.pointer.empty()) {
        const size_t node = index(target, "node", nodes_.size(), channel + ".target", "node");
        check_sampler(samplers[s], at(where + ".samplers", s), text(target, "path"), node);
        continue;
      }
      if (moved.node != SIZE_MAX && moved.node >= nodes_.size())
        fail(channel + ".target's KHR_animation_pointer '" + moved.pointer + "' names a node past the file's " +
             std::to_string(nodes_.size()));
      if (moved.mesh != SIZE_MAX && moved.mesh >= meshes_.size())
        fail(channel + ".target's KHR_animation_pointer '" + moved.pointer + "' names a mesh past the file's " +
             std::to_string(meshes_.size()));
      check_sampler(samplers[s], at(where + ".samplers", s), moved.path, moved.node, moved.mesh);
    }
  }

  // A sampler's key times and values, for the channel that moves `node`'s `moved` (or, for
  // weights, `mesh`'s where no node is given).
  void check_sampler(const json& sampler, const std::string& where, const std::string& moved, size_t node,
                     size_t mesh = SIZE_MAX) const {
    if (!sampler.is_object()) fail(where + " is not an object");
    const size_t input = index(sampler, "input", accessors_.size(), where, "accessor");
    const size_t output = index(sampler, "output", accessors_.size(), where, "accessor");
    if (input == SIZE_MAX || output == SIZE_MAX) fail(where + " has no input (key times) or no output (values)");
    const json& in = accessor(input, where + ".input");
    if (text(in, "type") != "SCALAR" || in["componentType"] != kFloat)
      fail(where + ".input (accessor " + std::to_string(input) + ") is not SCALAR floats (key times in seconds)");
    const std::vector<double> times = values(input, where + ".input");
    for (size_t k = 0; k < times.size(); ++k) {
      if (!std::isfinite(times[k])) fail(where + ": key time " + std::to_string(k) + " is not a finite number");
      if (k > 0 && times[k] < times[k - 1])
        fail(where + ": key time " + std::to_string(k) + " (" + seconds(times[k]) + ") comes before key time " +
             std::to_string(k - 1) + " (" + seconds(times[k - 1]) + "); key times go forward");
    }
    const json& out = accessor(output, where + ".output");
    if (moved != "translation" && moved != "rotation" && moved != "scale" && moved != "weights") return;  // an extension's
    const std::string type = moved == "rotation" ? "VEC4" : moved == "weights" ? "SCALAR" : "VEC3";
    if (text(out, "type") != type)
      fail(where + ".output (accessor " + std::to_string(output) + ") is " + text(out, "type") + "; a channel moving " +
           moved + " takes " + type);
    size_t per_key = text(sampler, "interpolation") == "CUBICSPLINE" ? 3 : 1;
    if (moved == "weights") {
      if (node != SIZE_MAX) mesh = index(nodes_[node], "mesh", meshes_.size(), at("nodes", node), "mesh");
      if (mesh == SIZE_MAX) return;
      const json& primitives = list_of(meshes_[mesh], "primitives");
      if (primitives.empty() || !primitives[0].is_object()) return;
      const size_t targets = list_of(primitives[0], "targets").size();
      if (targets == 0) return;
      per_key *= targets;
    }
    const size_t count = gltf_whole_number(out, "count", 0, path_, "an accessor");
    if (count != times.size() * per_key)
      fail(where + ": " + std::to_string(count) + " values (accessor " + std::to_string(output) + ") for " +
           std::to_string(times.size()) + " key times (accessor " + std::to_string(input) + "), where " +
           std::to_string(times.size() * per_key) + " are due");
  }

  const GltfFile& file_;
  const std::string& path_;
  const json& nodes_;
  const json& meshes_;
  const json& skins_;
  const json& accessors_;
};

}  // namespace

void check_gltf_rules(const GltfFile& file, const std::string& path) { Rules(file, path).check(); }

size_t skins_given_bind_matrices(GltfFile& file) {
  if (!file.doc.contains("skins") || !file.doc["skins"].is_array()) return 0;
  size_t changed = 0;
  for (json& skin : file.doc["skins"]) {
    if (!skin.is_object() || skin.contains("inverseBindMatrices")) continue;
    std::vector<double> identities;
    for (size_t j = 0; j < skin["joints"].size(); ++j)
      for (int k = 0; k < 16; ++k) identities.push_back(k % 5 == 0 ? 1.0 : 0.0);
    skin["inverseBindMatrices"] = add_float_accessor(file, identities, "MAT4");
    ++changed;
  }
  return changed;
}

}  // namespace spx
