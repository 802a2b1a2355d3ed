#include "core/cache_folder.hpp"

#include <cstdio>
#include <filesystem>

#include "core/error.hpp"

namespace spx {

void make_cache_folder(const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (!std::filesystem::is_directory(dir))
    fail_write(dir, "cannot make the cache folder" + (ec ? ": " + ec.message() : std::string()));
}

std::string cache_key_text(uint64_t hash) {
  char text[17];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(hash));
  return text;
}

}  // namespace spx
