#include "posemap/carry_cache.hpp"

#include <algorithm>
#include <cstring>

#include "core/atomic_file.hpp"
#include "core/cache_folder.hpp"
#include "core/error.hpp"
#include "core/hash.hpp"

namespace spx {
namespace {

bool get_value(CacheReader& in, SkinnedMap::Choice* c) {
  for (int& j : c->influence.joint)
    if (!in.get(&j)) return false;
  for (float& w : c->influence.weight)
    if (!in.get(&w)) return false;
  return in.get(&c->influence.bind.x()) && in.get(&c->influence.bind.y()) && in.get(&c->influence.bind.z()) &&
         in.get(&c->radius);
}
bool get_value(CacheReader& in, double* v) { return in.get(v); }

void put_value(std::string& bytes, const SkinnedMap::Choice& c) {
  for (int j : c.influence.joint) cache_put(bytes, j);
  for (float w : c.influence.weight) cache_put(bytes, w);
  for (double v : {c.influence.bind.x(), c.influence.bind.y(), c.influence.bind.z(), c.radius}) cache_put(bytes, v);
}
void put_value(std::string& bytes, double v) { cache_put(bytes, v); }

}  // namespace

template <size_t Words, class Value>
size_t BitsCache<Words, Value>::Hash::operator()(const Key& k) const {
  return size_t(fnv1a(kFnvOffset, k.data(), sizeof(Key)));
}

template <size_t Words, class Value>
BitsCache<Words, Value>::BitsCache(std::string path, const std::string& kind, std::string key)
    : path_(std::move(path)), head_("spx " + kind + " 1 " + key + "\n") {
  const std::optional<std::string> file = read_cache_file(path_, head_);
  if (!file) return;
  const std::string& bytes = *file;
  CacheReader in{bytes, head_.size()};
  uint64_t count = 0;
  if (!in.get(&count) || count > bytes.size() / sizeof(Key)) return;
  std::unordered_map<Key, Value, Hash> read;
  for (uint64_t n = 0; n < count; ++n) {
    Key k;
    Value v;
    for (uint64_t& w : k)
      if (!in.get(&w)) return;
    if (!get_value(in, &v)) return;
    read.emplace(k, v);
  }
  if (in.done()) known_ = std::move(read);
}

template <size_t Words, class Value>
std::vector<Value> BitsCache<Words, Value>::values(const std::vector<Key>& keys, const Make& make) {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<Value> out(keys.size());
  std::vector<size_t> missing;
  for (size_t n = 0; n < keys.size(); ++n) {
    const auto it = known_.find(keys[n]);
    if (it != known_.end()) out[n] = it->second;
    else missing.push_back(n);
  }
  read_ += keys.size() - missing.size();
  if (missing.empty()) return out;
  const std::vector<Value> made = make(missing);
  for (size_t m = 0; m < missing.size(); ++m) {
    out[missing[m]] = made[m];
    made_ += known_.emplace(keys[missing[m]], made[m]).second;
  }
  return out;
}

template <size_t Words, class Value>
void BitsCache<Words, Value>::save() const {
  if (made_ == 0) return;
  // In the keys' order, whatever the order they were asked in: the same file for the same set.
  std::vector<std::pair<Key, Value>> all(known_.begin(), known_.end());
  std::sort(all.begin(), all.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  std::string bytes = head_;
  cache_put(bytes, uint64_t(all.size()));
  for (const auto& [k, v] : all) {
    for (uint64_t w : k) cache_put(bytes, w);
    put_value(bytes, v);
  }
  write_file_atomic(path_, bytes);
}

template class BitsCache<3, SkinnedMap::Choice>;
template class BitsCache<8, double>;

CarryCache::Key carry_key(const Eigen::Vector3d& c) { return {bits_of(c.x()), bits_of(c.y()), bits_of(c.z())}; }

HeldCache::Key held_key(const SkinInfluence& in, double radius) {
  HeldCache::Key k{};
  static_assert(sizeof(in.joint) + sizeof(in.weight) == 4 * sizeof(uint64_t), "joints and weights fill 4 words");
  std::memcpy(k.data(), in.joint.data(), sizeof(in.joint));
  std::memcpy(reinterpret_cast<char*>(k.data()) + sizeof(in.joint), in.weight.data(), sizeof(in.weight));
  k[4] = bits_of(in.bind.x());
  k[5] = bits_of(in.bind.y());
  k[6] = bits_of(in.bind.z());
  k[7] = bits_of(radius);
  return k;
}

}  // namespace spx
