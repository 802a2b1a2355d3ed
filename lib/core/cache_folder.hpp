#pragma once
// The folder the tools keep files in between runs (`--cache`): what no tolerance or budget
// changes, in files named by a key of what they were made from.
#include <cstdint>
#include <cstring>
#include <optional>
#include <string>
#include <vector>

#include "core/json_io.hpp"
#include "core/log.hpp"
#include "core/sphere.hpp"

namespace spx {

// `dir` made with its parents where it is not there; throws Error(cannot_write) naming it where it
// cannot be (a file in its place).
void make_cache_folder(const std::string& dir);

// A key's hash begun (FNV-1a) with the project's version and the program's build, which every
// key holds (a tool rebuilt from other code starts afresh); then what the file is made from.
uint64_t cache_key_start();
// A key (a hash of what a file was made from) as the 16 hex digits of its name.
std::string cache_key_text(uint64_t hash);
// The file `kind`-KEY.`extension` in the cache folder `dir`.
std::string cache_file(const std::string& dir, const std::string& kind, const std::string& key,
                       const std::string& extension);

// The bytes of the cache file at `path`, where they begin with `head` (its tag and key, a line);
// none where there is no such file, it cannot be read (a cache is never a reason to fail), or it
// is another key's. A file read is marked used (mark_cache_file_used).
std::optional<std::string> read_cache_file(const std::string& path, const std::string& head);
// The cache file at `path` used now: its time set, which trim_cache_folder goes by (a file that
// cannot be touched keeps its time).
void mark_cache_file_used(const std::string& path);

// The tools' cache files kept under a size: the folder's files named as cache_file names them
// (KIND-KEY.EXT, KEY 16 hex digits) removed, least recently used first (by their times, then
// names), until what is left is at most `limit` bytes; never those of `in_use` (this run's), nor
// any other file. `limit` 0: nothing removed. A file another run removes first is passed over.
// Whatever the limit, a cache file's temporary file over an hour old (".NAME.tmp.PID": a run
// killed while writing it) is removed too, and counted as removed.
struct CacheTrim {
  uint64_t limit = 0;
  size_t files_removed = 0;
  uint64_t bytes_removed = 0;
  size_t files_kept = 0;
  uint64_t bytes_kept = 0;
};
CacheTrim trim_cache_folder(const std::string& dir, uint64_t limit, const std::vector<std::string>& in_use);

// trim_cache_folder at the end of a tool's run, said where it removed anything (or where this
// run's files alone pass the limit).
CacheTrim keep_cache_under(const std::string& dir, uint64_t limit, const std::vector<std::string>& in_use, Log& log);
// The report's `cache_folder`: null without a cache folder.
json cache_trim_json(const std::optional<CacheTrim>& trim);

// The default of the tools' --cache-limit: a farm's clips fill a disk otherwise (a rigged clip's
// frames keep about 2.5 MB each).
inline constexpr uint64_t kDefaultCacheLimit = uint64_t(4) << 30;

// A cache file's plain values, in the machine's own layout (a cache is never moved between
// machines: its key names the program's build). Read off `bytes` from `at`, false past its end.
struct CacheReader {
  const std::string& bytes;
  size_t at = 0;
  template <class T>
  bool get(T* out) {
    if (bytes.size() - at < sizeof(T)) return false;
    std::memcpy(out, bytes.data() + at, sizeof(T));
    at += sizeof(T);
    return true;
  }
  bool get(Sphere* s) { return get(&s->center.x()) && get(&s->center.y()) && get(&s->center.z()) && get(&s->radius); }
  bool done() const { return at == bytes.size(); }
};

template <class T>
void cache_put(std::string& bytes, const T& value) {
  bytes.append(reinterpret_cast<const char*>(&value), sizeof(T));
}
inline void cache_put(std::string& bytes, const Sphere& s) {
  for (double v : {s.center.x(), s.center.y(), s.center.z(), s.radius}) cache_put(bytes, v);
}

}  // namespace spx
