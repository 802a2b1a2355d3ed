#include "posemap/carry_cache.hpp"

#include <algorithm>
#include <cstring>

#include "core/atomic_file.hpp"
#include "core/cache_folder.hpp"
#include "core/error.hpp"
#include "core/hash.hpp"

namespace spx {
namespace {

constexpr const char* kTag = "spx carries 1 ";

bool get_choice(CacheReader& in, SkinnedMap::Choice* c) {
  for (int& j : c->influence.joint)
    if (!in.get(&j)) return false;
  for (float& w : c->influence.weight)
    if (!in.get(&w)) return false;
  return in.get(&c->influence.bind.x()) && in.get(&c->influence.bind.y()) && in.get(&c->influence.bind.z()) &&
         in.get(&c->radius);
}

void put_choice(std::string& bytes, const SkinnedMap::Choice& c) {
  for (int j : c.influence.joint) cache_put(bytes, j);
  for (float w : c.influence.weight) cache_put(bytes, w);
  for (double v : {c.influence.bind.x(), c.influence.bind.y(), c.influence.bind.z(), c.radius}) cache_put(bytes, v);
}

}  // namespace

size_t CarryCache::CentreHash::operator()(const Centre& c) const { return size_t(fnv1a(kFnvOffset, c.bits, sizeof c.bits)); }

CarryCache::Centre CarryCache::centre_of(const Eigen::Vector3d& c) {
  Centre out;
  for (int a = 0; a < 3; ++a) std::memcpy(&out.bits[a], &c[a], sizeof(double));
  return out;
}

CarryCache::CarryCache(std::string path, std::string key) : path_(std::move(path)), key_(std::move(key)) {
  const std::string head = std::string(kTag) + key_ + "\n";
  const std::optional<std::string> file = read_cache_file(path_, head);
  if (!file) return;
  const std::string& bytes = *file;
  CacheReader in{bytes, head.size()};
  uint64_t count = 0;
  if (!in.get(&count) || count > bytes.size() / sizeof(Centre)) return;
  std::unordered_map<Centre, SkinnedMap::Choice, CentreHash> read;
  for (uint64_t n = 0; n < count; ++n) {
    Centre c;
    SkinnedMap::Choice choice;
    if (!in.get(&c.bits[0]) || !in.get(&c.bits[1]) || !in.get(&c.bits[2]) || !get_choice(in, &choice)) return;
    read.emplace(c, choice);
  }
  if (in.done()) known_ = std::move(read);
}

std::vector<SkinnedMap::Choice> CarryCache::choices(const SphereSet& rest, const Make& make) {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<SkinnedMap::Choice> out(rest.size());
  std::vector<size_t> missing;
  SphereSet ask;
  for (size_t s = 0; s < rest.size(); ++s) {
    const auto it = known_.find(centre_of(rest[s].center));
    if (it != known_.end()) {
      out[s] = it->second;
    } else {
      missing.push_back(s);
      ask.push_back(rest[s]);
    }
  }
  read_ += rest.size() - missing.size();
  if (missing.empty()) return out;
  const std::vector<SkinnedMap::Choice> made = make(ask);
  for (size_t n = 0; n < missing.size(); ++n) {
    out[missing[n]] = made[n];
    made_ += known_.emplace(centre_of(ask[n].center), made[n]).second;
  }
  return out;
}

void CarryCache::save() const {
  if (made_ == 0) return;
  // In the centres' order, whatever the order they were asked in: the same file for the same set.
  std::vector<std::pair<Centre, SkinnedMap::Choice>> all(known_.begin(), known_.end());
  std::sort(all.begin(), all.end(), [](const auto& a, const auto& b) {
    return std::lexicographical_compare(a.first.bits, a.first.bits + 3, b.first.bits, b.first.bits + 3);
  });
  std::string bytes = std::string(kTag) + key_ + "\n";
  cache_put(bytes, uint64_t(all.size()));
  for (const auto& [c, choice] : all) {
    for (uint64_t b : c.bits) cache_put(bytes, b);
    put_choice(bytes, choice);
  }
  write_file_atomic(path_, bytes);
}

}  // namespace spx
