#include "mesh/ply_input.hpp"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <vector>

#include "core/error.hpp"
#include "core/format.hpp"
#include "mesh/ply_file.hpp"

namespace spx {

namespace {

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
std::vector<std::string> data_for_assimp(const std::string& path, const std::string& text, const PlyHeader& h,
                                         const std::string& cannot, std::vector<size_t>& triangles) {
  const bool ascii = h.format == "ascii", big = h.format == "binary_big_endian";
  size_t vertices = 0;
  for (const PlyElement& e : h.elements)
    if (e.name == "vertex") vertices = e.count;
  PlyWalk walk(path, text, h);
  std::vector<std::string> data(h.elements.size());
  triangles.assign(h.elements.size(), 0);
  std::vector<int64_t> strip;
  for (size_t i = 0; i < h.elements.size(); ++i) {
    const PlyElement& e = h.elements[i];
    if (e.properties.empty() && e.count > 0)
      fail_input(path, "its PLY element '" + one_line(e.name, 40) + "' has no properties, so " + cannot);
    if (e.name != "tristrips") {
      for (size_t k = 0; k < e.count; ++k) {
        const auto [begin, end] = walk.instance(e, k);
        data[i].append(text, begin, end - begin);
        if (ascii) data[i] += '\n';
      }
      continue;
    }
    // An unsigned list's restart is its type's all-ones.
    const auto list = std::find_if(e.properties.begin(), e.properties.end(),
                                   [](const PlyProperty& p) { return p.count.size > 0; });
    if (list == e.properties.end())
      fail_input(path, "its triangle strips (element 'tristrips') hold no list of vertex indices");
    const PlyType index = list->value;
    const int64_t all_set = index.is_signed || index.size >= 8 ? -2 : (int64_t(1) << (8 * index.size)) - 1;
    for (size_t k = 0; k < e.count; ++k) {
      walk.instance(e, k, &strip);
      for (int64_t& v : strip) {
        if (v == all_set) v = -1;
        if (v < -1 || (v >= 0 && size_t(v) >= vertices))
          fail_input(path, "triangle strip " + std::to_string(k + 1) + " names vertex " + std::to_string(v) +
                               (v < 0 ? ", below -1 (which restarts a strip)"
                                      : " (counted from 0), past its " + std::to_string(vertices) + " vertices"));
      }
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
  const PlyHeader h = read_ply_header(path, text);
  if (!h.unknown.empty()) {
    if (named) fail_input(path, h.unknown + ", so its triangle strips cannot be read");
    return std::nullopt;
  }
  size_t vertex = SIZE_MAX, face = SIZE_MAX, strips = SIZE_MAX;
  for (size_t i = h.elements.size(); i-- > 0;) {  // each the first of its name
    const std::string& name = h.elements[i].name;
    if (name == "vertex") vertex = i;
    if (name == "face") face = i;
    if (name == "tristrips") strips = i;
  }
  const bool faces_first = face < vertex && vertex != SIZE_MAX;
  if (strips == SIZE_MAX && !faces_first) return std::nullopt;
  const std::string cannot =
      strips != SIZE_MAX ? "its triangle strips cannot be read" : "its faces, given before its vertices, cannot be read";
  if (h.format != "ascii" && h.format != "binary_little_endian" && h.format != "binary_big_endian")
    fail_input(path, "its PLY format '" + one_line(h.format, 40) + "' is none of ascii, binary_little_endian and "
                     "binary_big_endian, so " + cannot);
  if (strips != SIZE_MAX && face != SIZE_MAX)
    fail_input(path, "holds both faces and triangle strips (elements 'face' and 'tristrips'), which assimp cannot read "
                     "together: write one of them");
  std::vector<size_t> triangles;
  const std::vector<std::string> data = data_for_assimp(path, text, h, cannot, triangles);
  // The vertices first (assimp refuses faces before them), the rest in the file's order.
  std::vector<size_t> order;
  if (vertex != SIZE_MAX) order.push_back(vertex);
  for (size_t i = 0; i < h.elements.size(); ++i)
    if (i != vertex) order.push_back(i);
  std::string out;
  for (const std::string& line : h.lines) out += line + "\n";
  for (size_t i : order) {
    if (h.elements[i].name == "tristrips")
      out += "element face " + std::to_string(triangles[i]) + "\nproperty list uchar int vertex_indices\n";
    else
      for (const std::string& line : h.elements[i].lines) out += line + "\n";
  }
  out += "end_header\n";
  for (size_t i : order) out += data[i];
  return out;
}

}  // namespace spx
