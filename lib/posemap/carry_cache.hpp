#pragma once
// pose-map's cache (`--cache DIR`) of a skinned body's carries: for each candidate centre at rest,
// the influence it follows and its one radius over the clip (SkinnedMap::choose), which no
// tolerance or budget changes and which is most of a clip's selection once the poses' fields are
// cached (pose_cache.hpp). DIR/carry-KEY.bin; KEY hashes what a choice depends on: the rest, every
// pose, the skin, the tets, the poses' fields' options, the largest radius, the project's version
// and the program's build. A centre is looked up by its bits, so a candidate offered again (the
// spheres file's, a frame's own mapped back to the rest) gets the same choice to the bit.
#include <cstdint>
#include <functional>
#include <mutex>
#include <string>
#include <unordered_map>
#include <vector>

#include "core/sphere.hpp"
#include "posemap/skinned_map.hpp"

namespace spx {

class CarryCache {
 public:
  using Make = std::function<std::vector<SkinnedMap::Choice>(const SphereSet&)>;
  // Reads `path` where it holds `key`'s choices; a file cut short or another key's is taken as
  // empty, and written over.
  CarryCache(std::string path, std::string key);
  // The choices of `rest`'s centres: the cache's, and `make`'s for those it lacks (asked once, in
  // order; then kept).
  std::vector<SkinnedMap::Choice> choices(const SphereSet& rest, const Make& make);
  // Writes the file (atomically) where this run added to it; throws Error(cannot_write).
  void save() const;

  const std::string& file() const { return path_; }
  size_t read() const { return read_; }
  size_t made() const { return made_; }

 private:
  struct Centre {
    uint64_t bits[3];
    bool operator==(const Centre& o) const { return bits[0] == o.bits[0] && bits[1] == o.bits[1] && bits[2] == o.bits[2]; }
  };
  struct CentreHash {
    size_t operator()(const Centre& c) const;
  };
  static Centre centre_of(const Eigen::Vector3d& c);

  std::string path_, key_;
  std::unordered_map<Centre, SkinnedMap::Choice, CentreHash> known_;
  size_t read_ = 0, made_ = 0;
  std::mutex mutex_;
};

}  // namespace spx
