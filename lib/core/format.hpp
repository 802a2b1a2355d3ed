#pragma once
// Numbers in messages: %g, so 1.5e-05 and 0.0417 read as written, never "0.000000"; counts
// with their nouns. Lines that hold a path or a name are built as strings, not in a fixed buffer,
// so that a long path is never cut off.
#include <cstdio>
#include <string>
#include <string_view>
#include <vector>

namespace spx {

inline std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}

// "1 pose", "3 poses": a count and its noun, which takes an s unless the count is one.
inline std::string counted(size_t n, const std::string& noun) { return std::to_string(n) + " " + noun + (n == 1 ? "" : "s"); }

// "'a', 'b', 'c'" (names a file gives, in a message), or "none".
inline std::string quoted_names(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "'" : ", '") + n + "'";
  return out.empty() ? "none" : out;
}

// `text` padded with spaces to `width` characters (a column of names); longer text is kept whole.
inline std::string padded(const std::string& text, size_t width) {
  return text.size() >= width ? text : text + std::string(width - text.size(), ' ');
}

// Words from a file quoted in a message, which stays one line of text: a control character, and
// a byte of no UTF-8 character (a damaged file's, or a character cut at `most`), shown as '?';
// past `most` bytes cut, with "...".
inline std::string one_line(std::string_view words, size_t most = std::string_view::npos) {
  std::string out(words.substr(0, most));
  for (size_t i = 0; i < out.size();) {
    const auto byte = [&](size_t k) { return k < out.size() ? static_cast<unsigned char>(out[k]) : 0u; };
    const unsigned c = byte(i);
    // The character's length, and the range its second byte must fall in (no overlong form, no
    // surrogate, nothing past U+10FFFF); 0 where `c` starts none.
    const size_t n = c < 0x80 ? 1 : c >= 0xC2 && c <= 0xDF ? 2 : c >= 0xE0 && c <= 0xEF ? 3 : c >= 0xF0 && c <= 0xF4 ? 4 : 0;
    const unsigned low = c == 0xE0 ? 0xA0 : c == 0xF0 ? 0x90 : 0x80, high = c == 0xED ? 0x9F : c == 0xF4 ? 0x8F : 0xBF;
    bool whole = n > 0 && (n == 1 || (byte(i + 1) >= low && byte(i + 1) <= high));
    for (size_t k = 2; whole && k < n; ++k) whole = byte(i + k) >= 0x80 && byte(i + k) <= 0xBF;
    if (!whole || c < 0x20 || c == 0x7f) {
      out[i++] = '?';
      continue;
    }
    i += n;
  }
  return words.size() > most ? out + "..." : out;
}

// `line` with each control character written as its escape (a newline as \n, an escape as \x1b):
// a message that must stay one line (the error line, a warning) though it quotes a file name that
// holds a newline.
inline std::string escape_controls(std::string_view line) {
  std::string out;
  for (const char c : line) {
    const unsigned byte = static_cast<unsigned char>(c);
    if (byte >= 0x20 && byte != 0x7f) out += c;
    else if (c == '\n') out += "\\n";
    else if (c == '\r') out += "\\r";
    else if (c == '\t') out += "\\t";
    else {
      char escaped[8];
      std::snprintf(escaped, sizeof escaped, "\\x%02x", byte);
      out += escaped;
    }
  }
  return out;
}

}  // namespace spx
