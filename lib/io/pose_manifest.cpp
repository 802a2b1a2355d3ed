#include "io/pose_manifest.hpp"

#include <algorithm>
#include <filesystem>
#include <map>
#include <set>

#include "core/error.hpp"
#include "core/version.hpp"
#include "mesh/mesh.hpp"

namespace spx {
namespace {
constexpr const char* kFormat = "spx.poses";
constexpr int kVersion = 1;
}  // namespace

json manifest_to_json(const PoseManifest& m) {
  json poses = json::array();
  for (const auto& p : m.poses) poses.push_back({{"name", p.name}, {"file", p.file}, {"source", p.source}});
  json out = {{"format", kFormat}, {"version", kVersion}, {"generator", std::string("spx ") + version_string()},
              {"rest", m.rest}, {"poses", poses}};
  if (!m.skin.empty()) out["skin"] = m.skin;
  return out;
}

PoseManifest read_pose_manifest(const std::string& path) {
  return read_json_document(path, "pose manifest", [&](const json& j) {
    require_header(j, kFormat, "pose manifest", kVersion, path, false);  // its schema asks no generator
    PoseManifest m;
    m.rest = require_string(j, "rest", path);
    const json& poses = require(j, "poses", path);
    if (!poses.is_array()) fail_input(path, "field 'poses' is not an array");
    std::map<std::string, std::string> listed;  // each file where it lies, as it was written
    for (const json& p : poses) {
      if (!p.is_object()) fail_input(path, "an entry of 'poses' is not an object");
      m.poses.push_back({require_string(p, "name", path), require_string(p, "file", path), p.value("source", json())});
      const std::string& file = m.poses.back().file;
      // The same file however it is written ("front.obj", "./front.obj", its whole path).
      const std::string where = std::filesystem::absolute(manifest_file_path(path, file)).lexically_normal().string();
      const auto [earlier, added] = listed.emplace(where, file);
      if (!added)
        fail_input(path, "lists the pose file '" + earlier->second + "' twice" +
                             (earlier->second == file ? "" : " (the second time as '" + file + "')"));
    }
    if (m.poses.empty()) fail_input(path, "lists no poses");
    if (j.contains("skin")) m.skin = require_string(j, "skin", path);
    return m;
  });
}

bool poses_are_morph_targets(const PoseManifest& manifest) {
  return !manifest.poses.empty() && std::all_of(manifest.poses.begin(), manifest.poses.end(), [](const ManifestPose& p) {
           return p.source.is_object() && p.source.value("kind", "") == "morph-target";
         });
}

std::string manifest_file_path(const std::string& manifest_path, const std::string& file) {
  const std::filesystem::path f(file);
  if (f.is_absolute()) return file;
  return (std::filesystem::path(manifest_path).parent_path() / f).lexically_normal().string();
}

void rest_and_poses(const std::string& manifest, std::string& rest, std::vector<std::string>& poses, std::string* skin) {
  if (manifest.empty()) {
    if (rest.empty()) fail_option("rest", "give --rest and --pose, or --manifest");
    return;
  }
  const PoseManifest m = read_pose_manifest(manifest);
  rest = manifest_file_path(manifest, m.rest);
  poses.clear();
  for (const auto& p : m.poses) poses.push_back(manifest_file_path(manifest, p.file));
  if (skin && !m.skin.empty()) *skin = manifest_file_path(manifest, m.skin);
}

std::vector<std::string> pose_names(const std::string& manifest, const std::vector<std::string>& pose_paths) {
  std::vector<std::string> names;
  if (manifest.empty()) {
    for (const std::string& path : pose_paths) names.push_back(stem_of(path));
    return names;
  }
  std::set<std::string> taken;
  for (const ManifestPose& p : read_pose_manifest(manifest).poses) {
    std::string name = p.name;
    for (int n = 2; !taken.insert(name).second; ++n) name = p.name + "-" + std::to_string(n);
    names.push_back(name);
  }
  return names;
}

}  // namespace spx
