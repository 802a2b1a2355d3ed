#include "mesh/collada_check.hpp"

#include <algorithm>
#include <string_view>

#include "core/error.hpp"
#include "core/format.hpp"

namespace spx {

namespace {

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }

// A whole number as the reader takes one: digits, a plus sign before them at most (it reads
// "+52" and "052" as 52, as XML's unsigned integers are written).
bool is_whole(std::string_view word) {
  if (!word.empty() && word[0] == '+') word.remove_prefix(1);
  return !word.empty() && std::all_of(word.begin(), word.end(), [](char c) { return c >= '0' && c <= '9'; });
}

// The element name that starts at `at` (just past a '<').
std::string_view name_at(std::string_view text, size_t at) {
  size_t end = at;
  while (end < text.size() && !is_space(text[end]) && text[end] != '>' && text[end] != '/') ++end;
  return text.substr(at, end - at);
}

}  // namespace

void check_collada_text(const std::string& path, const std::string& text) {
  const std::string_view all(text);
  size_t line = 1, counted_to = 0;  // the line number at counted_to
  const auto line_at = [&](size_t at) {
    line += size_t(std::count(all.begin() + long(counted_to), all.begin() + long(at), '\n'));
    counted_to = at;
    return line;
  };
  for (size_t at = all.find('<'); at != std::string_view::npos; at = all.find('<', at + 1)) {
    // Comments and character data are no elements, whatever they hold.
    for (const auto& [open, close] : {std::pair{"<!--", "-->"}, std::pair{"<![CDATA[", "]]>"}})
      if (all.compare(at, std::string_view(open).size(), open) == 0) {
        at = all.find(close, at);
        if (at == std::string_view::npos) return;
      }
    const std::string_view name = name_at(all, at + 1);
    if (name != "p" && name != "vcount" && name != "v" && name != "h") continue;
    const size_t open_end = all.find('>', at);
    if (open_end == std::string_view::npos || all[open_end - 1] == '/') continue;
    const size_t close = std::min(all.find('<', open_end), all.size());
    for (size_t w = open_end + 1; w < close;) {
      while (w < close && is_space(all[w])) ++w;
      size_t end = w;
      while (end < close && !is_space(all[end])) ++end;
      const std::string_view word = all.substr(w, end - w);
      if (!word.empty() && !is_whole(word))
        fail_input(path, "line " + std::to_string(line_at(w)) + ": <" + std::string(name) + "> holds '" +
                             one_line(word, 40) + "', where the COLLADA reader takes whole numbers from 0 (indices, "
                             "counts); it would read the list wrong, or, in a <p>, never end");
      w = end;
    }
    at = close - 1;
  }
}

}  // namespace spx
