#pragma once
// Numbers in messages: %g, so 1.5e-05 and 0.0417 read as written, never "0.000000"; counts
// with their nouns. Lines that hold a path or a name are built as strings, not in a fixed buffer,
// so that a long path is never cut off.
#include <cstdio>
#include <string>
#include <string_view>

namespace spx {

inline std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}

// "1 pose", "3 poses": a count and its noun, which takes an s unless the count is one.
inline std::string counted(size_t n, const std::string& noun) { return std::to_string(n) + " " + noun + (n == 1 ? "" : "s"); }

// `text` padded with spaces to `width` characters (a column of names); longer text is kept whole.
inline std::string padded(const std::string& text, size_t width) {
  return text.size() >= width ? text : text + std::string(width - text.size(), ' ');
}

// Words from a file quoted in a message, which stays one line: a control character shown as '?',
// and past `most` characters cut, with "...".
inline std::string one_line(std::string_view words, size_t most = std::string_view::npos) {
  std::string out(words.substr(0, most));
  for (char& c : out)
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = '?';
  return words.size() > most ? out + "..." : out;
}

}  // namespace spx
