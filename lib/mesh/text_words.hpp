#pragma once
// Words of a mesh file's line as assimp's text readers split them (at spaces and tabs), and a
// count as they read one: what the OFF and PLY walks (mesh/file_checks, mesh/ply_file) share.
#include <string_view>
#include <vector>

namespace spx {

inline std::vector<std::string_view> words_of(std::string_view line) {
  std::vector<std::string_view> out;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
    const size_t start = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
    if (i > start) out.push_back(line.substr(start, i - start));
  }
  return out;
}

// The word as a whole number from 0 (decimal digits alone, at most 18), or -1 where it is not one.
inline long long decimal_whole(std::string_view word) {
  if (word.empty() || word.size() > 18) return -1;
  long long value = 0;
  for (char c : word) {
    if (c < '0' || c > '9') return -1;
    value = value * 10 + (c - '0');
  }
  return value;
}

}  // namespace spx
