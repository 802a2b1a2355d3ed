#include "pack/candidate_cache.hpp"

#include <limits>

#include "core/atomic_file.hpp"
#include "core/cache_folder.hpp"
#include "core/error.hpp"
#include "core/hash.hpp"

namespace spx {
namespace {

constexpr const char* kTag = "spx candidates 1 ";
constexpr uint64_t kNoVoxels = std::numeric_limits<uint64_t>::max();

std::string key_of(const DenseField& field, const TriMesh& mesh, const SurfaceSamples& samples,
                   const CandidateOptions& limits) {
  uint64_t h = cache_key_start();
  const GridShape& g = field.shape;
  const int grid[6] = {g.origin.x(), g.origin.y(), g.origin.z(), g.dims.x(), g.dims.y(), g.dims.z()};
  h = fnv1a(h, grid, sizeof grid);
  const double numbers[6] = {g.voxel_size, double(field.background), limits.min_radius, limits.max_radius,
                             limits.growth, limits.field_bounds_radius ? 1.0 : 0.0};
  h = fnv1a(h, numbers, sizeof numbers);
  h = fnv1a(h, field.values.data(), field.values.size() * sizeof(float));
  h = fnv1a_values(h, mesh.vertices);
  h = fnv1a_values(h, mesh.triangles);
  h = fnv1a_values(h, samples.points);
  h = fnv1a_values(h, samples.triangle);
  return cache_key_text(h);
}

}  // namespace

CandidateCache::CandidateCache(const std::string& dir, const DenseField& field, const TriMesh& mesh,
                               const SurfaceSamples& samples, const CandidateOptions& limits)
    : key_(key_of(field, mesh, samples, limits)),
      known_(samples.points.size(), 0),
      balls_(samples.points.size(), {Sphere{{0, 0, 0}, 0}, Sphere{{0, 0, 0}, 0}}) {
  make_cache_folder(dir);
  path_ = cache_file(dir, "candidates", key_, "bin");
  const std::string head = std::string(kTag) + key_ + "\n";
  const std::optional<std::string> file = read_cache_file(path_, head);
  if (!file) return;
  const std::string& bytes = *file;
  CacheReader in{bytes, head.size()};
  uint64_t voxels = 0, count = 0, known = 0;
  if (!in.get(&voxels)) return;
  SphereSet read_voxels;
  if (voxels != kNoVoxels) {
    if (voxels > bytes.size() / (4 * sizeof(double))) return;  // more than the file holds
    read_voxels.resize(voxels);
    for (Sphere& s : read_voxels)
      if (!in.get(&s)) return;
  }
  if (!in.get(&count) || count != samples.points.size() || !in.get(&known) || known > count) return;
  std::vector<char> read_known(count, 0);
  std::vector<SampleBalls> read_balls(count, {Sphere{{0, 0, 0}, 0}, Sphere{{0, 0, 0}, 0}});
  for (uint64_t k = 0; k < known; ++k) {
    uint32_t i = 0;
    if (!in.get(&i) || i >= count || read_known[i] || !in.get(&read_balls[i][0]) || !in.get(&read_balls[i][1])) return;
    read_known[i] = 1;
  }
  if (!in.done()) return;
  if (voxels != kNoVoxels) voxels_ = std::move(read_voxels);
  known_ = std::move(read_known);
  balls_ = std::move(read_balls);
}

SphereSet CandidateCache::voxel_candidates(const std::function<SphereSet()>& make) {
  if (!active()) return make();
  voxels_read_ = voxels_.has_value();
  if (!voxels_) voxels_ = make(), changed_ = true;
  return *voxels_;
}

std::vector<SampleBalls> CandidateCache::tangent_balls(
    const std::vector<uint32_t>& which, const std::function<std::vector<SampleBalls>(const std::vector<uint32_t>&)>& make) {
  if (!active()) return make(which);
  std::vector<uint32_t> missing;
  for (uint32_t i : which)
    if (!known_[i]) missing.push_back(i);
  balls_read_ += which.size() - missing.size();
  if (!missing.empty()) {
    const std::vector<SampleBalls> made = make(missing);
    for (size_t n = 0; n < missing.size(); ++n) balls_[missing[n]] = made[n], known_[missing[n]] = 1;
    balls_made_ += missing.size();
    changed_ = true;
  }
  std::vector<SampleBalls> out;
  out.reserve(which.size());
  for (uint32_t i : which) out.push_back(balls_[i]);
  return out;
}

std::string CandidateCache::save() const {
  if (!active() || !changed_) return {};
  std::string bytes = std::string(kTag) + key_ + "\n";
  const uint64_t voxels = voxels_ ? voxels_->size() : kNoVoxels, count = known_.size();
  cache_put(bytes, voxels);
  if (voxels_)
    for (const Sphere& s : *voxels_) cache_put(bytes, s);
  uint64_t known = 0;
  for (char k : known_) known += k != 0;
  cache_put(bytes, count);
  cache_put(bytes, known);
  for (uint32_t i = 0; i < known_.size(); ++i)
    if (known_[i]) cache_put(bytes, i), cache_put(bytes, balls_[i][0]), cache_put(bytes, balls_[i][1]);
  try {
    write_file_atomic(path_, bytes);
  } catch (const Error& e) {
    return e.what();
  }
  return {};
}

}  // namespace spx
