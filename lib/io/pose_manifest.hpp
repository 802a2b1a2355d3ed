#pragma once
// poses.json: the rest mesh and the example poses pose-extract wrote, in the asset's order.
// {"rest": "rest.obj", "poses": [{"name", "file", "source"}, ...], "skin": "skin.json"}, files
// relative to the manifest's folder, "skin" only for a clip's poses (io/skin_file.hpp);
// pose-map --manifest reads it.
#include <string>
#include <vector>

#include "core/json_io.hpp"

namespace spx {

struct ManifestPose {
  std::string name;
  std::string file;  // relative to the manifest's folder
  json source;       // where in the asset it came from
};

struct PoseManifest {
  std::string rest = "rest.obj";
  std::vector<ManifestPose> poses;
  std::string skin;  // empty: the poses come without a rig
};

json manifest_to_json(const PoseManifest& manifest);
// Exit 2 naming `path` and the field when the document is not a manifest.
PoseManifest read_pose_manifest(const std::string& path);
// Whether every pose is a morph target of the asset (pose-extract --morph-targets): a host plays
// such a proxy by the targets' weights (spx::blend_morph). False for no pose.
bool poses_are_morph_targets(const PoseManifest& manifest);
// `file` of a manifest at `manifest_path`, as a path usable from the working folder.
std::string manifest_file_path(const std::string& manifest_path, const std::string& file);

// The tools' --manifest: rest and pose paths (and the skin's, empty without one) from
// `manifest` when it is given, else `rest` and `poses` as given (exit 1 when neither names a
// rest mesh).
void rest_and_poses(const std::string& manifest, std::string& rest, std::vector<std::string>& poses,
                    std::string* skin = nullptr);

// What the poses are called in a proxy: the manifest's names when `manifest` is given (a clip's
// "walk@4.63333s", not its file's "pose-00"; a name given twice gets "-2", "-3" as pose-extract's
// files do), else each pose file's stem.
std::vector<std::string> pose_names(const std::string& manifest, const std::vector<std::string>& pose_paths);

}  // namespace spx
