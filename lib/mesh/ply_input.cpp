#include "mesh/ply_input.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <vector>

#include "core/error.hpp"
#include "core/format.hpp"
#include "mesh/ply_types.hpp"

namespace spx {

namespace {

struct Property {
  PlyType count, value;  // count.size > 0: a list
};

struct Element {
  std::string name;
  size_t count = 0;
  std::vector<std::string> lines;  // its header lines: the element's, then its properties'
  std::vector<Property> properties;
};

struct Header {
  std::string format;
  std::vector<std::string> lines;  // before the first element (ply, format, comments)
  std::vector<Element> elements;
  size_t data = 0;  // where the data begins
};

std::vector<std::string> words_of(const std::string& line) {
  std::vector<std::string> out;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
    const size_t start = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
    if (i > start) out.push_back(line.substr(start, i - start));
  }
  return out;
}

// The header; where it cannot be followed (a line that is not PLY's), `problem` says why.
std::optional<Header> read_header(const std::string& text, std::string& problem) {
  Header h;
  size_t at = 0;
  while (at < text.size()) {
    size_t end = text.find('\n', at);
    if (end == std::string::npos) break;
    std::string line = text.substr(at, end - at);
    if (!line.empty() && line.back() == '\r') line.pop_back();
    at = end + 1;
    const std::vector<std::string> w = words_of(line);
    auto unknown = [&](const std::string& why) {
      problem = "its PLY header's line '" + one_line(line, 60) + "' " + why;
      return std::nullopt;
    };
    if (w.empty()) continue;
    if (w[0] == "end_header") {
      h.data = at;
      return h;
    }
    if (w[0] == "format" && w.size() > 1) h.format = w[1];
    if (w[0] == "element") {
      size_t count = 0;
      if (w.size() < 3 || std::from_chars(w[2].data(), w[2].data() + w[2].size(), count).ec != std::errc())
        return unknown("gives no count");
      h.elements.push_back({w[1], count, {line}, {}});
    } else if (w[0] == "property" && !h.elements.empty()) {
      Property p;
      if (w.size() >= 5 && w[1] == "list") {
        p.count = ply_type(w[2]);
        p.value = ply_type(w[3]);
        if (p.count.size == 0 || p.count.is_float) return unknown("names no whole-number type for the list's count");
      } else if (w.size() >= 3) {
        p.value = ply_type(w[1]);
      }
      if (p.value.size == 0) return unknown("names no PLY type");
      h.elements.back().lines.push_back(line);
      h.elements.back().properties.push_back(p);
    } else if (h.elements.empty()) {
      h.lines.push_back(line);
    } else {
      h.elements.back().lines.push_back(line);  // a comment among the properties
    }
  }
  problem = "its PLY header does not end (no end_header line: a file cut short?)";
  return std::nullopt;
}

// The file's data, element by element: each instance's bytes (to copy), and a list's whole
// numbers (the strips' indices).
class DataWalk {
 public:
  DataWalk(const std::string& path, const std::string& text, const Header& h)
      : path_(path), text_(text), at_(h.data), ascii_(h.format == "ascii"), swap_(h.format == "binary_big_endian") {}

  // Past one instance of `e`; the first list's values go to `list` where given. Returns the
  // instance's bytes [begin, end).
  std::pair<size_t, size_t> instance(const Element& e, size_t k, std::vector<int64_t>* list) {
    if (ascii_) skip_space();
    const size_t begin = at_;
    bool listed = false;
    for (const Property& p : e.properties) {
      if (p.count.size == 0) {
        value(p.value, e, k);
        continue;
      }
      const int64_t n = value(p.count, e, k);
      if (n < 0) fail(e, k, "a list of " + std::to_string(n) + " values");
      const bool keep = list && !listed;
      if (keep) list->clear();
      const int64_t all_set = p.value.is_signed || p.value.size >= 8 ? -2 : (int64_t(1) << (8 * p.value.size)) - 1;
      for (int64_t i = 0; i < n; ++i) {
        int64_t v = value(p.value, e, k);
        if (v == all_set) v = -1;  // an unsigned list's restart
        if (keep) list->push_back(v);
      }
      listed = listed || keep;
    }
    return {begin, at_};
  }
  size_t at() const { return at_; }

 private:
  [[noreturn]] void fail(const Element& e, size_t k, const std::string& what) const {
    fail_input(path_, one_line(e.name) + " " + std::to_string(k + 1) + " of " + std::to_string(e.count) + ": " + what);
  }
  void skip_space() {
    while (at_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[at_]))) ++at_;
  }
  // The next value of type `t`, as a whole number (a float's value truncated: only a list's
  // count and indices are kept, and those are whole).
  int64_t value(const PlyType& t, const Element& e, size_t k) {
    if (ascii_) {
      skip_space();
      const size_t start = at_;
      while (at_ < text_.size() && !std::isspace(static_cast<unsigned char>(text_[at_]))) ++at_;
      if (start == at_) fail(e, k, "the data ends within it (a file cut short?)");
      if (t.is_float) return 0;
      int64_t v = 0;
      if (std::from_chars(text_.data() + start, text_.data() + at_, v).ec != std::errc())
        fail(e, k, "'" + one_line(std::string_view(text_).substr(start, at_ - start), 20) + "' is not a whole number");
      return v;
    }
    if (at_ + size_t(t.size) > text_.size()) fail(e, k, "the data ends within it (a file cut short?)");
    unsigned char b[8];
    std::memcpy(b, text_.data() + at_, size_t(t.size));
    at_ += size_t(t.size);
    if (swap_) std::reverse(b, b + t.size);
    if (t.is_float) return 0;
    uint64_t u = 0;
    for (int i = t.size - 1; i >= 0; --i) u = (u << 8) | b[i];
    if (t.is_signed && t.size < 8 && (u >> (8 * t.size - 1)) & 1) u |= ~uint64_t(0) << (8 * t.size);  // sign-extended
    return int64_t(u);
  }

  const std::string& path_;
  const std::string& text_;
  size_t at_;
  bool ascii_, swap_;
};

// A strip's triangles, appended to `out` as the format writes a face (a uchar 3, then three int).
void add_strip_triangles(const std::vector<int64_t>& strip, bool ascii, bool big_endian, std::string& out,
                         size_t& added) {
  auto put = [&](int64_t a, int64_t b, int64_t c) {
    ++added;
    if (ascii) {
      out += "3 " + std::to_string(a) + " " + std::to_string(b) + " " + std::to_string(c) + "\n";
      return;
    }
    out += char(3);
    for (int64_t v : {a, b, c}) {
      const uint32_t u = uint32_t(int32_t(v));
      for (int i = 0; i < 4; ++i) out += char((u >> (8 * (big_endian ? 3 - i : i))) & 0xFF);
    }
  };
  size_t run = 0;  // indices since the strip (re)started
  for (size_t i = 0; i < strip.size(); ++i) {
    if (strip[i] == -1) {
      run = 0;
      continue;
    }
    if (++run < 3) continue;
    const int64_t a = strip[i - 2], b = strip[i - 1], c = strip[i];
    if (a == b || b == c || a == c) continue;  // a stitch between runs
    if ((run - 3) % 2 == 0) put(a, b, c);
    else put(b, a, c);
  }
}

// The elements' data as assimp is to read it: each element's instances copied as they are, the
// strips' written out as faces (`triangles[i]` counts those of element i).
std::vector<std::string> data_for_assimp(const std::string& path, const std::string& text, const Header& h,
                                         const std::string& cannot, std::vector<size_t>& triangles) {
  const bool ascii = h.format == "ascii", big = h.format == "binary_big_endian";
  size_t vertices = 0;
  for (const Element& e : h.elements)
    if (e.name == "vertex") vertices = e.count;
  DataWalk walk(path, text, h);
  std::vector<std::string> data(h.elements.size());
  triangles.assign(h.elements.size(), 0);
  std::vector<int64_t> strip;
  for (size_t i = 0; i < h.elements.size(); ++i) {
    const Element& e = h.elements[i];
    const bool is_strips = e.name == "tristrips";
    if (e.properties.empty() && e.count > 0)
      fail_input(path, "its PLY element '" + one_line(e.name, 40) + "' has no properties, so " + cannot);
    for (size_t k = 0; k < e.count; ++k) {
      strip.clear();
      const auto [begin, end] = walk.instance(e, k, is_strips ? &strip : nullptr);
      if (!is_strips) {
        data[i].append(text, begin, end - begin);
        if (ascii) data[i] += '\n';
        continue;
      }
      for (int64_t v : strip)
        if (v < -1 || (v >= 0 && size_t(v) >= vertices))
          fail_input(path, "triangle strip " + std::to_string(k + 1) + " names vertex " + std::to_string(v) +
                               (v < 0 ? ", below -1 (which restarts a strip)"
                                      : " (counted from 0), past its " + std::to_string(vertices) + " vertices"));
      add_strip_triangles(strip, ascii, big, data[i], triangles[i]);
    }
  }
  return data;
}

}  // namespace

std::optional<std::string> ply_for_assimp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string head(65536, '\0');
  in.read(head.data(), std::streamsize(head.size()));
  head.resize(size_t(std::max<std::streamsize>(in.gcount(), 0)));
  // The header comes first: only a file whose header may need it is read whole.
  if (head.find("tristrips") == std::string::npos && head.find("element face") > head.find("element vertex"))
    return std::nullopt;
  in.clear();
  in.seekg(0, std::ios::end);
  std::string text(size_t(std::max<std::streamoff>(in.tellg(), 0)), '\0');
  in.seekg(0);
  in.read(text.data(), std::streamsize(text.size()));
  text.resize(size_t(std::max<std::streamsize>(in.gcount(), 0)));
  return ply_text_for_assimp(path, text);
}

std::optional<std::string> ply_text_for_assimp(const std::string& path, const std::string& text) {
  // Strips that cannot be followed are an error: assimp reads them wrong even where it can.
  const bool named = text.compare(0, 3, "ply") == 0 && text.find("\nelement tristrips ") < text.find("end_header");
  std::string problem;
  const std::optional<Header> h = read_header(text, problem);
  if (!h) {
    if (named) fail_input(path, problem + ", so its triangle strips cannot be read");
    return std::nullopt;
  }
  size_t vertex = SIZE_MAX, face = SIZE_MAX, strips = SIZE_MAX;
  for (size_t i = h->elements.size(); i-- > 0;) {  // each the first of its name
    const std::string& name = h->elements[i].name;
    if (name == "vertex") vertex = i;
    if (name == "face") face = i;
    if (name == "tristrips") strips = i;
  }
  const bool faces_first = face < vertex && vertex != SIZE_MAX;
  if (strips == SIZE_MAX && !faces_first) return std::nullopt;
  const std::string cannot =
      strips != SIZE_MAX ? "its triangle strips cannot be read" : "its faces, given before its vertices, cannot be read";
  if (h->format != "ascii" && h->format != "binary_little_endian" && h->format != "binary_big_endian")
    fail_input(path, "its PLY format '" + one_line(h->format, 40) + "' is none of ascii, binary_little_endian and "
                     "binary_big_endian, so " + cannot);
  if (strips != SIZE_MAX && face != SIZE_MAX)
    fail_input(path, "holds both faces and triangle strips (elements 'face' and 'tristrips'), which assimp cannot read "
                     "together: write one of them");
  std::vector<size_t> triangles;
  const std::vector<std::string> data = data_for_assimp(path, text, *h, cannot, triangles);
  // The vertices first (assimp refuses faces before them), the rest in the file's order.
  std::vector<size_t> order;
  if (vertex != SIZE_MAX) order.push_back(vertex);
  for (size_t i = 0; i < h->elements.size(); ++i)
    if (i != vertex) order.push_back(i);
  std::string out;
  for (const std::string& line : h->lines) out += line + "\n";
  for (size_t i : order) {
    if (h->elements[i].name == "tristrips")
      out += "element face " + std::to_string(triangles[i]) + "\nproperty list uchar int vertex_indices\n";
    else
      for (const std::string& line : h->elements[i].lines) out += line + "\n";
  }
  out += "end_header\n";
  for (size_t i : order) out += data[i];
  return out;
}

}  // namespace spx
