#pragma once
// Words of a mesh file's line as assimp's text readers split them (at spaces and tabs), and a
// count as they read one: what the OFF and PLY walks (mesh/file_checks, mesh/ply_file) share.
#include <string_view>
#include <vector>

namespace spx {

// The word of `line` from `at` on (empty past its last), `at` moved past it.
inline std::string_view next_word(std::string_view line, size_t& at) {
  while (at < line.size() && (line[at] == ' ' || line[at] == '\t')) ++at;
  const size_t start = at;
  while (at < line.size() && line[at] != ' ' && line[at] != '\t') ++at;
  return line.substr(start, at - start);
}

inline std::vector<std::string_view> words_of(std::string_view line) {
  std::vector<std::string_view> out;
  size_t at = 0;
  for (std::string_view word = next_word(line, at); !word.empty(); word = next_word(line, at)) out.push_back(word);
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
