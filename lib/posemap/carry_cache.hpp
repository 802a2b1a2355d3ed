#pragma once
// pose-map's caches (`--cache DIR`) of what a skinned body's candidates get from the poses and
// the clip, which no tolerance or budget changes:
// - the carries (CarryCache, DIR/carry-KEY.bin): for each candidate centre at rest, the influence
//   it follows and its one radius over the poses (SkinnedMap::choose), most of a clip's selection
//   once the poses' fields are cached (pose_cache.hpp);
// - with --hold-over-clip, the radii held over the clip (HeldCache, DIR/held-KEY.bin): for each
//   influence and radius, ClipRadius::least's, most of that option's time.
// KEY hashes what a value depends on: the rest, every pose, the skin and its clip, the tets, the
// poses' fields' options, the largest radius (and the overshoot the clip allows), the project's
// version and the program's build. An entry is looked up by its inputs' bits, so a candidate
// offered again (the spheres file's, a frame's own mapped back to the rest) gets the same value
// to the bit.
#include <array>
#include <cstdint>
#include <functional>
#include <mutex>
#include <string>
#include <unordered_map>
#include <vector>

#include "core/sphere.hpp"
#include "posemap/skinned_map.hpp"

namespace spx {

// Values of type Value by keys of `Words` 64-bit words, kept in one file.
template <size_t Words, class Value>
class BitsCache {
 public:
  using Key = std::array<uint64_t, Words>;
  // The values of the keys at `missing` (indices into the keys asked), in that order.
  using Make = std::function<std::vector<Value>(const std::vector<size_t>& missing)>;
  // Reads `path` where it holds `kind` and `key`'s values; a file cut short or another key's is
  // taken as empty, and written over.
  BitsCache(std::string path, const std::string& kind, std::string key);
  // The values of `keys`: the cache's, and `make`'s for those it lacks (asked once, in order;
  // then kept).
  std::vector<Value> values(const std::vector<Key>& keys, const Make& make);
  // Writes the file (atomically) where this run added to it; throws Error(cannot_write).
  void save() const;

  const std::string& file() const { return path_; }
  size_t read() const { return read_; }
  size_t made() const { return made_; }

 private:
  struct Hash {
    size_t operator()(const Key& k) const;
  };
  std::string path_, head_;
  std::unordered_map<Key, Value, Hash> known_;
  size_t read_ = 0, made_ = 0;
  std::mutex mutex_;
};

using CarryCache = BitsCache<3, SkinnedMap::Choice>;
using HeldCache = BitsCache<8, double>;

// A carry's key: the centre at rest.
CarryCache::Key carry_key(const Eigen::Vector3d& rest_center);
// A held radius's key: what ClipRadius::least walks (the influence) and the radius it starts from.
HeldCache::Key held_key(const SkinInfluence& influence, double radius);

}  // namespace spx
