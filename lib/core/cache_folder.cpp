#include "core/cache_folder.hpp"

#include <cstdio>
#include <filesystem>

#include "core/atomic_file.hpp"
#include "core/error.hpp"
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

std::string cache_key_text(uint64_t hash) {
  char text[17];
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
  return bytes;
}

}  // namespace spx
