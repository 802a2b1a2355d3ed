#include "mesh/collada_check.hpp"

#include <algorithm>
#include <map>
#include <optional>
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

// Attribute `key`'s value in the opening tag `tag`, where it has one.
std::optional<std::string_view> attribute(std::string_view tag, std::string_view key) {
  for (size_t at = tag.find(key); at != std::string_view::npos; at = tag.find(key, at + 1)) {
    const size_t eq = at + key.size();
    if (!is_space(tag[at - 1]) || eq + 1 >= tag.size() || tag[eq] != '=' || (tag[eq + 1] != '"' && tag[eq + 1] != '\''))
      continue;
    const size_t end = tag.find(tag[eq + 1], eq + 2);
    if (end == std::string_view::npos) return std::nullopt;
    return tag.substr(eq + 2, end - eq - 2);
  }
  return std::nullopt;
}

// A count, stride or offset as the reader's XML parser takes it: blanks, a plus sign, then decimal
// digits (or hexadecimal after "0x") up to the first other character ("3\f" is 3); none where it
// gives no digits (left to the reader).
std::optional<size_t> whole_attribute(std::string_view tag, std::string_view key) {
  std::string_view value = attribute(tag, key).value_or("");
  while (!value.empty() && is_space(value[0])) value.remove_prefix(1);
  if (!value.empty() && value[0] == '+') value.remove_prefix(1);
  const bool hex = value.size() > 2 && value[0] == '0' && (value[1] == 'x' || value[1] == 'X');
  if (hex) value.remove_prefix(2);
  const auto digit = [&](char c) {
    if (c >= '0' && c <= '9') return c - '0';
    const char lower = char(c | 0x20);
    return hex && lower >= 'a' && lower <= 'f' ? lower - 'a' + 10 : -1;
  };
  size_t n = 0, digits = 0;
  for (; digits < value.size() && digits < 15 && digit(value[digits]) >= 0; ++digits)
    n = n * (hex ? 16 : 10) + size_t(digit(value[digits]));
  return digits > 0 ? std::optional<size_t>(n) : std::nullopt;
}

// The elements the checks read: index lists, arrays of values, and the accessors into arrays.
bool is_index_list(std::string_view name) { return name == "p" || name == "vcount" || name == "v" || name == "h"; }
bool is_array(std::string_view name) {
  return name == "float_array" || name == "int_array" || name == "Name_array" || name == "IDREF_array" ||
         name == "bool_array";
}

class ColladaScan {
 public:
  ColladaScan(const std::string& path, std::string_view text) : path_(path), all_(text) {}

  void check() {
    for (size_t at = all_.find('<'); at != std::string_view::npos; at = all_.find('<', at + 1)) {
      // Comments and character data are no elements, whatever they hold.
      for (const auto& [open, close] : {std::pair{"<!--", "-->"}, std::pair{"<![CDATA[", "]]>"}})
        if (all_.compare(at, std::string_view(open).size(), open) == 0) {
          at = all_.find(close, at);
          if (at == std::string_view::npos) return;
        }
      const std::string_view name = name_at(all_, at + 1);
      if (!is_index_list(name) && !is_array(name) && name != "accessor") continue;
      const size_t open_end = all_.find('>', at);
      if (open_end == std::string_view::npos) return;
      const std::string_view tag = all_.substr(at, open_end - at);
      if (name == "accessor") {
        check_accessor(tag, at, open_end);
        continue;
      }
      if (all_[open_end - 1] == '/') continue;
      const size_t close = std::min(all_.find('<', open_end), all_.size());
      if (is_index_list(name)) check_index_list(name, open_end + 1, close);
      if (is_array(name)) check_array(name, tag, at, open_end + 1, close);
      at = close - 1;
    }
  }

 private:
  [[noreturn]] void fail(size_t at, const std::string& what) {
    line_ += size_t(std::count(all_.begin() + long(counted_to_), all_.begin() + long(at), '\n'));
    counted_to_ = at;
    fail_input(path_, "line " + std::to_string(line_) + ": " + what);
  }

  // Calls `word` with each word of the text in [begin, end) and where it starts.
  template <class Word>
  void words(size_t begin, size_t end, Word&& word) const {
    for (size_t w = begin; w < end;) {
      while (w < end && is_space(all_[w])) ++w;
      size_t e = w;
      while (e < end && !is_space(all_[e])) ++e;
      if (e > w) word(all_.substr(w, e - w), w);
      w = e;
    }
  }

  // assimp's reader of index lists does not move past a character it cannot read: in a <p> it
  // never ended, in a skin's lists it read other weights.
  void check_index_list(std::string_view name, size_t begin, size_t end) {
    words(begin, end, [&](std::string_view word, size_t at) {
      if (!is_whole(word))
        fail(at, "<" + std::string(name) + "> holds '" + one_line(word, 40) +
                     "', where the COLLADA reader takes whole numbers from 0 (indices, counts); it would read the "
                     "list wrong, or, in a <p>, never end");
    });
  }

  // An array holds as many values as its count says: the reader reads `count` of them, and an
  // accessor past them read memory the array does not have (a crash, or other numbers).
  void check_array(std::string_view name, std::string_view tag, size_t at, size_t begin, size_t end) {
    const auto count = whole_attribute(tag, "count");
    if (!count) return;
    size_t held = 0;
    words(begin, end, [&](std::string_view, size_t) { ++held; });
    const std::string id(attribute(tag, "id").value_or(""));
    if (held != *count)
      fail(at, "<" + std::string(name) + " id=\"" + one_line(id, 60) + "\"> says count=\"" + std::to_string(*count) +
                   "\" and holds " + std::to_string(held) + " values (a number changed, or values lost?)");
    if (!id.empty()) array_sizes_[id] = held;
  }

  // An accessor reads `count` elements `stride` values apart from `offset`, each of its params'
  // width: all within the array it names (one this file gives before it).
  void check_accessor(std::string_view tag, size_t at, size_t open_end) {
    const auto source = attribute(tag, "source");
    const auto count = whole_attribute(tag, "count");
    if (!source || source->empty() || (*source)[0] != '#' || !count || *count == 0) return;
    const auto array = array_sizes_.find(std::string(source->substr(1)));
    if (array == array_sizes_.end()) return;
    const size_t stride = whole_attribute(tag, "stride").value_or(1), offset = whole_attribute(tag, "offset").value_or(0);
    const size_t close = std::min(all_.find("</accessor", open_end), all_.size());
    size_t params = 0;
    for (size_t p = all_.find("<param", open_end); p < close; p = all_.find("<param", p + 1)) ++params;
    const size_t needed = offset + stride * (*count - 1) + std::max<size_t>(params, 1);
    if (needed > array->second)
      fail(at, "<accessor source=\"" + one_line(*source, 60) + "\"> reads " + std::to_string(*count) +
                   " elements, " + std::to_string(stride) + " values apart from value " + std::to_string(offset) +
                   ", and its array holds " + std::to_string(array->second) + ": the reader would read past its end");
  }

  const std::string& path_;
  std::string_view all_;
  size_t line_ = 1, counted_to_ = 0;  // the line number at counted_to_
  std::map<std::string, size_t> array_sizes_;  // by id: the values each array holds
};

}  // namespace

void check_collada_text(const std::string& path, const std::string& text) { ColladaScan(path, text).check(); }

}  // namespace spx
