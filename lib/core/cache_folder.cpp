#include "core/cache_folder.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iterator>
#include <tuple>

#include "core/atomic_file.hpp"
#include "core/error.hpp"
#include "core/format.hpp"
#include "core/hash.hpp"
#include "core/version.hpp"

namespace spx {

void make_cache_folder(const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (!std::filesystem::is_directory(dir))
    fail_write(dir, "cannot make the cache folder" + (ec ? ": " + ec.message() : std::string()));
}

uint64_t cache_key_start() {
  const std::string version = std::string(version_string()) + " " + build_identity();
  return fnv1a(kFnvOffset, version.data(), version.size());
}

std::string cache_file(const std::string& dir, const std::string& kind, const std::string& key,
                       const std::string& extension) {
  return (std::filesystem::path(dir) / (kind + "-" + key + "." + extension)).string();
}

namespace {
// A key's hex digits in a file's name: all of a 64-bit hash's.
constexpr size_t kKeyDigits = 16;
}  // namespace

std::string cache_key_text(uint64_t hash) {
  char text[kKeyDigits + 1];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(hash));
  return text;
}

std::optional<std::string> read_cache_file(const std::string& path, const std::string& head) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) return std::nullopt;
  std::string bytes;
  try {
    bytes = read_file(path);
  } catch (const Error&) {
    return std::nullopt;
  }
  if (bytes.compare(0, head.size(), head) != 0) return std::nullopt;
  mark_cache_file_used(path);
  return bytes;
}

void mark_cache_file_used(const std::string& path) {
  std::error_code ec;
  std::filesystem::last_write_time(path, std::filesystem::file_time_type::clock::now(), ec);
}

namespace {

// Whether `name` is one cache_file makes: KIND-KEY.EXT, KIND and EXT lowercase letters.
bool is_cache_file_name(const std::string& name) {
  const size_t dash = name.find('-'), dot = name.rfind('.');
  if (dash == 0 || dash == std::string::npos || dot != dash + 1 + kKeyDigits || dot + 1 == name.size()) return false;
  const auto all = [&](size_t from, size_t to, auto&& is) {
    return std::all_of(name.begin() + from, name.begin() + to, [&](char c) { return is(c); });
  };
  const auto lower = [](char c) { return c >= 'a' && c <= 'z'; };
  const auto hex = [](char c) { return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'); };
  return all(0, dash, lower) && all(dash + 1, dot, hex) && all(dot + 1, name.size(), lower);
}

// Whether `name` is a temporary file of a cache file's writing (atomic_file: ".NAME.tmp.PID").
bool is_cache_temp_name(const std::string& name) {
  const size_t tmp = name.rfind(".tmp.");
  return name.size() > 1 && name[0] == '.' && tmp != std::string::npos && tmp + 5 < name.size() &&
         is_cache_file_name(name.substr(1, tmp - 1)) &&
         std::all_of(name.begin() + long(tmp + 5), name.end(), [](char c) { return c >= '0' && c <= '9'; });
}

// A temporary file this old is a run's that was killed while writing (SIGKILL leaves them).
constexpr std::chrono::hours kStaleTemp{1};

}  // namespace

CacheTrim trim_cache_folder(const std::string& dir, uint64_t limit, const std::vector<std::string>& in_use) {
  namespace fs = std::filesystem;
  struct Entry {
    fs::file_time_type time;
    std::string name;
    uint64_t bytes;
    bool used;
  };
  std::vector<std::string> used_names;  // in_use's files are in `dir`: their names say which
  for (const std::string& path : in_use) used_names.push_back(fs::path(path).filename().string());
  std::vector<Entry> files;
  CacheTrim trim;
  trim.limit = limit;
  const fs::file_time_type stale = fs::file_time_type::clock::now() - kStaleTemp;
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    const bool temp = is_cache_temp_name(name);
    std::error_code e1, e2;
    if ((!temp && !is_cache_file_name(name)) || !it->is_regular_file(e1)) continue;
    const uint64_t bytes = it->file_size(e1);
    const fs::file_time_type time = it->last_write_time(e2);
    if (e1 || e2) continue;
    if (temp) {  // a killed run's half file goes, whatever the limit; a live run's is left alone
      if (time < stale && fs::remove(it->path(), e1) && !e1) {
        trim.files_removed += 1;
        trim.bytes_removed += bytes;
      }
      continue;
    }
    const bool used = std::find(used_names.begin(), used_names.end(), name) != used_names.end();
    files.push_back({time, name, bytes, used});
  }
  for (const Entry& f : files) trim.bytes_kept += f.bytes;
  trim.files_kept = files.size();
  if (limit == 0 || trim.bytes_kept <= limit) return trim;
  std::sort(files.begin(), files.end(),
            [](const Entry& a, const Entry& b) { return std::tie(a.time, a.name) < std::tie(b.time, b.name); });
  for (const Entry& f : files) {
    if (trim.bytes_kept <= limit) break;
    if (f.used) continue;
    std::error_code failed;
    const bool removed = fs::remove(fs::path(dir) / f.name, failed);
    if (failed) continue;  // still there
    trim.files_kept -= 1;  // gone, by this run or (removed false) by another before it
    trim.bytes_kept -= f.bytes;
    if (!removed) continue;
    trim.files_removed += 1;
    trim.bytes_removed += f.bytes;
  }
  return trim;
}

namespace {
// "388 KiB", "1.2 GiB": a size as a person reads it.
std::string size_text(uint64_t bytes) {
  const char* units[] = {"bytes", "KiB", "MiB", "GiB", "TiB"};
  double v = double(bytes);
  size_t u = 0;
  for (; v >= 1024 && u + 1 < std::size(units); ++u) v /= 1024;
  return num(v) + " " + units[u];
}
}  // namespace

CacheTrim keep_cache_under(const std::string& dir, uint64_t limit, const std::vector<std::string>& in_use, Log& log) {
  const CacheTrim trim = trim_cache_folder(dir, limit, in_use);
  if (trim.files_removed > 0)
    log.info(dir + ": removed " + counted(trim.files_removed, "cache file") + " (" + size_text(trim.bytes_removed) +
             "), the least recently used or left half-written, to keep it under its limit of " + size_text(limit));
  if (limit > 0 && trim.bytes_kept > limit)
    log.detail(dir + ": this run's cache files alone hold " + size_text(trim.bytes_kept) + ", over its limit of " +
               size_text(limit));
  return trim;
}

json cache_trim_json(const std::optional<CacheTrim>& trim) {
  if (!trim) return nullptr;
  return {{"limit_bytes", trim->limit},           {"files_kept", trim->files_kept},
          {"bytes_kept", trim->bytes_kept},       {"files_removed", trim->files_removed},
          {"bytes_removed", trim->bytes_removed}};
}

}  // namespace spx
