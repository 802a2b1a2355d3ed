#include "mesh/assimp_scene.hpp"

#include <assimp/SceneCombiner.h>

#include <algorithm>
#include <cctype>
#include <fstream>
#include <map>
#include <optional>
#include <string_view>
#include <vector>

#include "core/error.hpp"
#include "core/file_kind.hpp"
#include "core/gltf_file.hpp"
#include "mesh/gltf_input.hpp"

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

// assimp 5.2's PLY reader never returns on a header that does not end (no "end_header" line: a
// file cut short within its header, or its last line run into the data), so such a file is
// refused before assimp is given it. The word ends as assimp's reader takes it: at a space or the
// line's end.
void check_ply_header_ends(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string line;
  while (std::getline(in, line)) {
    const size_t start = line.find_first_not_of(" \t");
    if (start == std::string::npos || line.compare(start, 10, "end_header") != 0) continue;
    const size_t after = start + 10;
    if (after == line.size() || std::isspace(static_cast<unsigned char>(line[after]))) return;
  }
  fail_input(path, "its PLY header does not end (no end_header line: a file cut short?)");
}

// An ASCII OFF read as assimp 5.2's reader reads it: the header's tokens (comment lines skipped),
// then one line a vertex and one line a face, blank lines skipped. That reader drops a face of
// more than 9 corners and takes an index past the vertices as the last vertex, and says so only
// in its log: a polygon lost, or a triangle in the wrong place. Either is one error line here.
// Where the file is not plainly that (a binary OFF, a header it cannot read), assimp decides.
class OffScan {
 public:
  explicit OffScan(const std::string& path) {
    std::ifstream in(path, std::ios::binary | std::ios::ate);
    text_.resize(size_t(std::max<std::streamoff>(in.tellg(), 0)));
    in.seekg(0);
    in.read(text_.data(), std::streamsize(text_.size()));
    text_.resize(size_t(std::max<std::streamsize>(in.gcount(), 0)));
  }

  void check(const std::string& path) {
    next_token();
    const size_t keyword = text_.find_first_not_of("STCN4n", at_);
    if (keyword == std::string::npos || text_.compare(keyword, 3, "OFF") != 0) return;
    const bool dimension = text_.find('n', at_) < keyword;
    at_ = keyword + 3;
    if (text_.compare(at_, 7, " BINARY") == 0) return;
    unsigned long counts[4];  // the dimension where the header names one, vertices, faces, edges
    for (int k = dimension ? 0 : 1; k < 4; ++k)
      if (!read_count(counts[k])) return;
    const unsigned long vertices = counts[1], faces = counts[2];
    for (unsigned long v = 0; v < vertices; ++v) {
      if (!next_line()) return;
      const std::string word(next_word());
      char* end = nullptr;
      std::strtod(word.c_str(), &end);
      if (end == word.c_str())
        fail_input(path, "vertex " + std::to_string(v + 1) + " ('" + this_line() + "') is not a vertex: the OFF reader "
                         "takes each line after the counts as one; remove it");
    }
    // The reader drops a line of no face (no corners: a "0", or a comment) from the faces it keeps
    // but reads the next line in its place: each such line costs the file its last face.
    unsigned long slot = 0, kept = faces;
    std::string first_empty;
    while (slot < faces && next_line()) {
      const std::string line = this_line();
      if (!check_face(path, slot, vertices)) {
        --kept;
        if (first_empty.empty()) first_empty = line;
        continue;
      }
      if (slot >= kept) {
        const unsigned long empty = faces - kept;
        fail_input(path, "face " + std::to_string(slot + 1) + " would be dropped: the OFF reader counts " +
                             (empty == 1 ? "a line among the faces that holds none ('" + first_empty + "')"
                                         : std::to_string(empty) + " lines among the faces that hold none (the first: '" +
                                               first_empty + "')") +
                             " as one of the header's " + std::to_string(faces) + "; remove " +
                             (empty == 1 ? "it" : "them"));
      }
      ++slot;
    }
  }

 private:
  bool at_line_end() const { return text_[at_] == '\n' || text_[at_] == '\r'; }
  void skip_line() {
    while (at_ < text_.size() && !at_line_end()) ++at_;
  }
  void next_token() {
    while (at_ < text_.size() && (std::isspace(static_cast<unsigned char>(text_[at_])) || text_[at_] == '#')) {
      if (text_[at_] == '#') skip_line();
      else ++at_;
    }
  }
  bool read_count(unsigned long& count) {
    next_token();
    const char* start = text_.c_str() + at_;
    if (!std::isdigit(static_cast<unsigned char>(*start))) return false;
    char* end = nullptr;
    count = std::strtoul(start, &end, 10);
    at_ += size_t(end - start);
    return true;
  }
  // The next line that is not blank, as [begin_, at_); its words are read from line_ on.
  bool next_line() {
    while (at_ < text_.size() && at_line_end()) ++at_;
    if (at_ >= text_.size()) return false;
    begin_ = line_ = at_;
    skip_line();
    return true;
  }
  std::string this_line() const {
    const size_t shown = std::min<size_t>(at_ - begin_, 60);
    return text_.substr(begin_, shown) + (shown < at_ - begin_ ? "..." : "");
  }
  // The next word of the line [line_, at_), advancing line_; empty at the line's end.
  std::string_view next_word() {
    while (line_ < at_ && (text_[line_] == ' ' || text_[line_] == '\t')) ++line_;
    const size_t start = line_;
    while (line_ < at_ && text_[line_] != ' ' && text_[line_] != '\t') ++line_;
    return std::string_view(text_).substr(start, line_ - start);
  }
  // The word as a whole number from 0, or -1 where it is not one.
  static long long whole_number(std::string_view word) {
    if (word.empty() || word.size() > 18) return -1;
    long long value = 0;
    for (char c : word) {
      if (c < '0' || c > '9') return -1;
      value = value * 10 + (c - '0');
    }
    return value;
  }
  // False where the line holds no face (no corners, or no count).
  bool check_face(const std::string& path, unsigned long f, unsigned long vertices) {
    const long long corners = whole_number(next_word());
    if (corners <= 0) return false;
    auto fail = [&](const std::string& what) { fail_input(path, "face " + std::to_string(f + 1) + " " + what); };
    if (corners > 9)
      fail("has " + std::to_string(corners) + " corners; the OFF reader keeps faces of at most 9 and would drop it: "
           "save the mesh as OBJ or PLY, or split its larger faces");
    for (long long k = 0; k < corners; ++k) {
      const std::string_view word = next_word();
      const long long index = whole_number(word);
      if (word.empty())
        fail("has " + std::to_string(corners) + " corners but names " + std::to_string(k) + " vertices");
      if (index < 0) fail("names vertex '" + std::string(word) + "', not a vertex index (a whole number from 0)");
      if (static_cast<unsigned long long>(index) >= vertices)
        fail("names vertex " + std::string(word) + " (counted from 0), past its " + std::to_string(vertices) + " vertices");
    }
    return true;
  }

  std::string text_;
  size_t at_ = 0, begin_ = 0, line_ = 0;
};

// The file as assimp reads it, before any post-processing.
const aiScene* read_unprocessed(Assimp::Importer& importer, const std::string& path, const std::string& what,
                                std::vector<AddedKeys>* added_keys) {
  if (added_keys) added_keys->clear();
  const std::string ext = lower_extension(path);
  const bool gltf = ext == ".gltf" || ext == ".glb";
  if (ext == ".ply") check_ply_header_ends(path);
  if (ext == ".off") OffScan(path).check(path);
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
    // Each, whatever the one before finds (no short circuit): Draco's meshes first (into plain
    // accessors), the instances next (they read their accessors as a reader takes them), then the
    // floats, which the others read. Views the file compressed came out decoded, which assimp
    // cannot do.
    size_t changes = file->decoded_views;
    changes += draco_primitives_decoded(*file, path);
    changes += instances_as_nodes(*file, path);
    changes += float_accessors(*file, path);
    changes += complete_mirrored_channels(*file, path);
    changes += step_samplers_as_held_keys(*file, path);
    std::vector<AddedKeys> added;
    changes += cubic_samplers_as_keys(*file, path, added);
    if (added_keys) *added_keys = std::move(added);
    if (changes > 0) {
      const std::string glb = encode_glb(*file);
      const aiScene* scene = importer.ReadFileFromMemory(glb.data(), glb.size(), 0, "glb");
      if (scene && scene->mRootNode) return scene;
      fail_reading(path, what, importer.GetErrorString());
    }
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
                          std::vector<AddedKeys>* added_keys) {
  // Read without flags and post-processed after: what reading with them does, in the same order,
  // with the faces checked before any step trusts them.
  const aiScene* scene = read_unprocessed(importer, path, what, added_keys);
  check_faces(scene, path);
  if (!flags) return scene;
  scene = importer.ApplyPostProcessing(flags);
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
