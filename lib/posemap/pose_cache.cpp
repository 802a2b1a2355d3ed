#include "posemap/pose_cache.hpp"

#include "core/atomic_file.hpp"
#include "core/cache_folder.hpp"
#include "core/error.hpp"
#include "core/hash.hpp"

namespace spx {
namespace {

constexpr const char* kTag = "spx pose field 1 ";

std::optional<DepthField> read_depths(CacheReader& in) {
  DepthField d;
  int box[6];
  for (int& v : box)
    if (!in.get(&v)) return std::nullopt;
  d.shape.origin = {box[0], box[1], box[2]};
  d.shape.dims = {box[3], box[4], box[5]};
  uint64_t count = 0;
  if (!in.get(&d.shape.voxel_size) || !in.get(&d.unit) || !in.get(&count)) return std::nullopt;
  if ((d.shape.dims.array() < 0).any() || count != d.shape.count() || count > in.bytes.size() / sizeof(uint16_t))
    return std::nullopt;
  d.depth.resize(count);
  if (in.bytes.size() - in.at < count * sizeof(uint16_t)) return std::nullopt;
  std::memcpy(d.depth.data(), in.bytes.data() + in.at, count * sizeof(uint16_t));
  in.at += count * sizeof(uint16_t);
  return d;
}

void put_depths(std::string& bytes, const DepthField& d) {
  const GridShape& g = d.shape;
  for (int v : {g.origin.x(), g.origin.y(), g.origin.z(), g.dims.x(), g.dims.y(), g.dims.z()}) cache_put(bytes, v);
  cache_put(bytes, g.voxel_size);
  cache_put(bytes, d.unit);
  cache_put(bytes, uint64_t(d.depth.size()));
  bytes.append(reinterpret_cast<const char*>(d.depth.data()), d.depth.size() * sizeof(uint16_t));
}

}  // namespace

std::string pose_cache_key(const TriMesh& pose, const TriMesh& rest, const SdfOptions& field,
                           const CandidateOptions& candidates) {
  uint64_t h = cache_key_start();
  h = fnv1a_values(h, pose.vertices);
  h = fnv1a_values(h, pose.triangles);
  h = fnv1a_values(h, rest.vertices);
  h = fnv1a_values(h, rest.triangles);
  const double numbers[9] = {field.voxel_size,
                              field.voxel_size > 0 ? 0.0 : double(field.resolution),
                              double(field.band),
                              field.sign_every_voxel ? 1.0 : 0.0,
                              field.inside_only ? 1.0 : 0.0,
                              candidates.min_radius,
                              candidates.max_radius,
                              candidates.growth,
                              candidates.field_bounds_radius ? 1.0 : 0.0};
  h = fnv1a(h, numbers, sizeof numbers);
  return cache_key_text(h);
}

std::string pose_cache_file(const std::string& dir, const std::string& key) {
  return cache_file(dir, "pose", key, "bin");
}

std::optional<CachedPoseField> read_pose_cache(const std::string& path, const std::string& key) {
  const std::string head = std::string(kTag) + key + "\n";
  const std::optional<std::string> file = read_cache_file(path, head);
  if (!file) return std::nullopt;
  const std::string& bytes = *file;
  CacheReader in{bytes, head.size()};
  CachedPoseField out;
  char has_depths = 0, has_voxels = 0;
  if (!in.get(&has_depths) || !in.get(&has_voxels) || !in.get(&out.voxel_size)) return std::nullopt;
  if (has_depths && !(out.depths = read_depths(in))) return std::nullopt;
  if (has_voxels) {
    uint64_t count = 0, grown = 0;
    if (!in.get(&count) || count > bytes.size() / (4 * sizeof(double))) return std::nullopt;
    std::vector<MedialVoxel> voxels(count);
    for (MedialVoxel& v : voxels)
      if (!in.get(&v.center.x()) || !in.get(&v.center.y()) || !in.get(&v.center.z()) || !in.get(&v.depth))
        return std::nullopt;
    if (!in.get(&grown) || grown > count) return std::nullopt;
    out.grown.resize(grown);
    for (auto& [v, s] : out.grown)
      if (!in.get(&v) || v >= count || !in.get(&s)) return std::nullopt;
    out.voxels = std::move(voxels);
  }
  if (!in.done()) return std::nullopt;
  return out;
}

void write_pose_cache(const std::string& path, const std::string& key, const CachedPoseField& cached) {
  std::string bytes = std::string(kTag) + key + "\n";
  cache_put(bytes, char(cached.depths.has_value()));
  cache_put(bytes, char(cached.voxels.has_value()));
  cache_put(bytes, cached.voxel_size);
  if (cached.depths) put_depths(bytes, *cached.depths);
  if (cached.voxels) {
    cache_put(bytes, uint64_t(cached.voxels->size()));
    for (const MedialVoxel& v : *cached.voxels)
      for (double x : {v.center.x(), v.center.y(), v.center.z(), v.depth}) cache_put(bytes, x);
    cache_put(bytes, uint64_t(cached.grown.size()));
    for (const auto& [v, s] : cached.grown) cache_put(bytes, v), cache_put(bytes, s);
  }
  write_file_atomic(path, bytes);
}

}  // namespace spx
