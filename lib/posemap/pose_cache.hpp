#pragma once
// pose-map's cache (`--cache DIR`) of what each pose's own field gives the selection: its depths
// (a skinned body's radius floors), its near-medial voxels and the candidates grown at them so
// far. No tolerance or budget changes these, and on a clip they are most of a run: a run with
// another tolerance or budget on the same poses reads them and writes the same proxy to the byte.
// DIR/pose-KEY.bin per pose; KEY hashes the pose, the rest (whose hierarchy is refitted to it),
// the field's and the candidates' options, the project's version and the program's build.
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "mesh/mesh.hpp"
#include "io/dense_field.hpp"
#include "pack/candidates.hpp"
#include "sdf/sdf.hpp"

namespace spx {

struct CachedPoseField {
  std::optional<DepthField> depths;           // asked for a skinned body's floors
  std::optional<std::vector<MedialVoxel>> voxels;  // asked for the pose's own candidates
  double voxel_size = 0;
  std::vector<std::pair<uint32_t, Sphere>> grown;  // by voxel: the candidates grown so far
};

std::string pose_cache_key(const TriMesh& pose, const TriMesh& rest, const SdfOptions& field,
                           const CandidateOptions& candidates);
std::string pose_cache_file(const std::string& dir, const std::string& key);
// What `path` holds for `key`; none where there is no such file, or one that does not read as
// this key's (cut short, or another's): the pose's field is then built and the file written again.
std::optional<CachedPoseField> read_pose_cache(const std::string& path, const std::string& key);
// Writes `cached` to `path` for `key`, atomically; throws Error(cannot_write) where it cannot.
void write_pose_cache(const std::string& path, const std::string& key, const CachedPoseField& cached);

}  // namespace spx
