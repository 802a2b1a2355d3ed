#include "mesh/ply_file.hpp"

#include <algorithm>
#include <charconv>
#include <cstring>

#include "core/error.hpp"
#include "core/format.hpp"
#include "mesh/text_words.hpp"

namespace spx {

namespace {

bool is_line_end(char c) { return c == '\n' || c == '\r'; }

// A float value as the whole number a list keeps (truncated; 0 for NaN).
int64_t truncated(double real) { return real == real ? int64_t(std::clamp(real, -9.2e18, 9.2e18)) : 0; }

// A property line's type, or why it names none.
std::string read_property(const std::vector<std::string_view>& w, PlyProperty& p) {
  if (w.size() >= 5 && w[1] == "list") {
    p.count = ply_type(w[2]);
    p.value = ply_type(w[3]);
    if (p.count.size == 0 || p.count.is_float) return "names no whole-number type for the list's count";
  } else if (w.size() >= 3 && w[1] != "list") {
    p.value = ply_type(w[1]);
  }
  return p.value.size == 0 ? "names no PLY type" : "";
}

}  // namespace

PlyType ply_type(std::string_view name) {
  static const struct {
    const char *name, *alias;
    PlyType type;
  } types[] = {{"char", "int8", {1, true, false}},    {"uchar", "uint8", {1, false, false}},
               {"short", "int16", {2, true, false}},  {"ushort", "uint16", {2, false, false}},
               {"int", "int32", {4, true, false}},    {"uint", "uint32", {4, false, false}},
               {"float", "float32", {4, true, true}}, {"double", "float64", {8, true, true}}};
  for (const auto& t : types)
    if (name == t.name || name == t.alias) return t.type;
  return {};
}

PlyHeader read_ply_header(const std::string& path, std::string_view text) {
  PlyHeader h;
  size_t at = 0, line_number = 1;
  while (at < text.size()) {
    if (is_line_end(text[at])) {  // blank lines, and the end of the one before
      if (text[at++] == '\n') ++line_number;
      continue;
    }
    const size_t begin = at;
    while (at < text.size() && !is_line_end(text[at])) ++at;
    const std::string_view line = text.substr(begin, at - begin);
    const std::vector<std::string_view> w = words_of(line);
    auto unknown = [&](const std::string& why) {
      if (h.unknown.empty()) h.unknown = "its PLY header's line '" + one_line(line, 60) + "' " + why;
    };
    if (w.empty()) continue;  // spaces alone
    if (w[0] == "end_header") {
      if (at < text.size() && text[at] == '\r') ++at;
      if (at < text.size() && text[at] == '\n') ++at, ++line_number;
      h.data = at;
      h.data_line = line_number;
      if (h.format.empty()) unknown("ends a header that names no format");
      return h;
    }
    if (w[0] == "element") {
      const long long count = w.size() >= 3 ? decimal_whole(w[2]) : -1;
      if (count < 0) unknown("gives no count");
      h.elements.push_back({std::string(w.size() > 1 ? w[1] : ""), size_t(std::max(count, 0LL)), {}, {}});
      h.elements.back().lines.emplace_back(line);
      continue;
    }
    if (w[0] == "property") {
      PlyProperty p;
      const std::string problem = read_property(w, p);
      if (!problem.empty()) unknown(problem);
      if (h.elements.empty()) unknown("comes before any element");
      else h.elements.back().properties.push_back(p);
    } else if (w[0] == "format" && w.size() > 1) {
      h.format = std::string(w[1]);
    } else if (w[0] != "ply" && w[0] != "comment" && w[0] != "obj_info") {
      unknown("is not PLY's");
    }
    (h.elements.empty() ? h.lines : h.elements.back().lines).emplace_back(line);
  }
  fail_input(path, "its PLY header does not end (no end_header line: a file cut short?)");
}

PlyWalk::PlyWalk(const std::string& path, std::string_view text, const PlyHeader& header)
    : path_(path),
      text_(text),
      at_(header.data),
      line_number_(header.data_line),
      ascii_(header.format == "ascii"),
      big_endian_(header.format == "binary_big_endian") {}

std::string PlyWalk::instance_name(const PlyElement& e, size_t k) const {
  return one_line(e.name) + " " + std::to_string(k + 1) + " of " + std::to_string(e.count);
}

void PlyWalk::fail(const std::string& what) const { fail_input(path_, what); }

// The next line that is not blank, as [line_begin_, at_).
bool PlyWalk::next_line() {
  while (at_ < text_.size() && is_line_end(text_[at_]))
    if (text_[at_++] == '\n') ++line_number_;
  if (at_ >= text_.size()) return false;
  line_begin_ = at_;
  while (at_ < text_.size() && !is_line_end(text_[at_])) ++at_;
  return true;
}

std::pair<size_t, size_t> PlyWalk::instance(const PlyElement& e, size_t k, std::vector<int64_t>* list) {
  if (list) list->clear();
  return ascii_ ? ascii_instance(e, k, list) : binary_instance(e, k, list);
}

void PlyWalk::element(const PlyElement& e) {
  size_t fixed = 0;
  bool lists = false;
  for (const PlyProperty& p : e.properties) {
    fixed += p.count.size ? 0 : size_t(p.value.size);
    lists = lists || p.count.size > 0;
  }
  if (ascii_ || lists) {
    for (size_t k = 0; k < e.count; ++k) instance(e, k);
    return;
  }
  const size_t left = text_.size() - std::min(at_, text_.size());
  const size_t fit = fixed ? left / fixed : e.count;
  if (fit < e.count) fail("its data ends within " + instance_name(e, fit) + " (a file cut short?)");
  at_ += fixed * e.count;
}

std::pair<size_t, size_t> PlyWalk::ascii_instance(const PlyElement& e, size_t k, std::vector<int64_t>* list) {
  if (!next_line()) fail("its data ends before " + instance_name(e, k) + " (a file cut short?)");
  const std::string_view line = text_.substr(line_begin_, at_ - line_begin_);
  auto where = [&] {
    return "line " + std::to_string(line_number_) + " (" + instance_name(e, k) + ", '" + one_line(line, 60) + "')";
  };
  size_t values = 0, cursor = 0;  // words read, and where the next begins
  // The next value; where `whole` (a list's count, a list of indices), a whole number.
  auto value = [&](bool whole) -> int64_t {
    std::string_view word = next_word(line, cursor);  // no list of a line's words: files have millions of lines
    if (word.empty())
      fail(where() + " holds " + std::to_string(values) + " values, fewer than its header asks for: a file cut "
           "short, or a line broken?");
    ++values;
    if (word[0] == '+') word.remove_prefix(1);
    long long integer = 0;
    double real = 0;
    const char* end = word.data() + word.size();
    const std::from_chars_result read =
        whole ? std::from_chars(word.data(), end, integer) : std::from_chars(word.data(), end, real);
    if (word.empty() || read.ec != std::errc() || read.ptr != end)
      fail(where() + ": '" + one_line(word) + "' is not " + (whole ? "a whole number" : "a number"));
    return whole ? int64_t(integer) : truncated(real);
  };
  bool listed = false;
  for (const PlyProperty& p : e.properties) {
    if (p.count.size == 0) {
      value(false);
      continue;
    }
    const int64_t n = value(true);
    if (n < 0) fail(where() + ": a list of " + std::to_string(n) + " values");
    const bool keep = list && !listed;
    for (int64_t i = 0; i < n; ++i) {
      const int64_t v = value(!p.value.is_float);
      if (keep) list->push_back(v);
    }
    listed = listed || keep;
  }
  return {line_begin_, at_};
}

std::pair<size_t, size_t> PlyWalk::binary_instance(const PlyElement& e, size_t k, std::vector<int64_t>* list) {
  const size_t begin = at_;
  bool listed = false;
  for (const PlyProperty& p : e.properties) {
    if (p.count.size == 0) {
      binary_value(p.value, e, k);
      continue;
    }
    const int64_t n = binary_value(p.count, e, k);
    if (n < 0) fail(instance_name(e, k) + " holds a list of " + std::to_string(n) + " values");
    const bool keep = list && !listed;
    if (!keep) {  // stepped over whole
      if (uint64_t(n) * uint64_t(p.value.size) > text_.size() - at_)
        fail("its data ends within " + instance_name(e, k) + " (a file cut short?)");
      at_ += size_t(n) * size_t(p.value.size);
      continue;
    }
    for (int64_t i = 0; i < n; ++i) list->push_back(binary_value(p.value, e, k));
    listed = true;
  }
  return {begin, at_};
}

// The next value of type `t`, as a whole number (a float's value truncated).
int64_t PlyWalk::binary_value(const PlyType& t, const PlyElement& e, size_t k) {
  if (at_ > text_.size() || size_t(t.size) > text_.size() - at_)
    fail("its data ends within " + instance_name(e, k) + " (a file cut short?)");
  unsigned char b[8];
  std::memcpy(b, text_.data() + at_, size_t(t.size));
  at_ += size_t(t.size);
  if (big_endian_) std::reverse(b, b + t.size);
  if (t.is_float) {
    double real = 0;
    if (t.size == 4) {
      float f;
      std::memcpy(&f, b, 4);
      real = f;
    } else {
      std::memcpy(&real, b, 8);
    }
    return truncated(real);
  }
  uint64_t u = 0;
  for (int i = t.size - 1; i >= 0; --i) u = (u << 8) | b[i];
  if (t.is_signed && t.size < 8 && (u >> (8 * t.size - 1)) & 1) u |= ~uint64_t(0) << (8 * t.size);  // sign-extended
  return int64_t(u);
}

}  // namespace spx
