#include "mesh/file_checks.hpp"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string_view>
#include <vector>

#include "core/error.hpp"
#include "core/file_kind.hpp"
#include "core/format.hpp"
#include "mesh/collada_check.hpp"
#include "mesh/obj_check.hpp"
#include "mesh/ply_file.hpp"
#include "mesh/stl_check.hpp"
#include "mesh/text_words.hpp"

namespace spx {

namespace {

// A file's bytes with a cursor, read as assimp's text readers read: line by line, blank lines
// skipped, words split at spaces and tabs.
class TextScan {
 public:
  TextScan(const std::string& path, const std::string& text) : path_(path), text_(text) {}

 protected:
  [[noreturn]] void fail(const std::string& what) const { fail_input(path_, what); }
  bool at_line_end() const { return text_[at_] == '\n' || text_[at_] == '\r'; }
  void skip_line() {
    while (at_ < text_.size() && !at_line_end()) ++at_;
  }
  // The next line that is not blank, as [begin_, at_); its words are read from word_ on.
  bool next_line() {
    while (at_ < text_.size() && at_line_end()) {
      if (text_[at_] == '\n') ++line_number_;
      ++at_;
    }
    if (at_ >= text_.size()) return false;
    begin_ = word_ = at_;
    skip_line();
    return true;
  }
  std::string_view next_word() { return spx::next_word(std::string_view(text_).substr(0, at_), word_); }
  // The line, as a person reads it in an error.
  std::string this_line() const { return one_line(std::string_view(text_).substr(begin_, at_ - begin_), 60); }

  const std::string& path_;
  const std::string& text_;
  size_t at_ = 0, begin_ = 0, word_ = 0, line_number_ = 1;
};

// An ASCII OFF read as the OFF reader reads it: the header's tokens (comment lines skipped), then
// one line a vertex and one line a face, blank lines skipped. That reader drops a face of more
// than 9 corners and takes an index past the vertices as the last vertex (a corner missing or not
// a number as vertex 0); a line of no corners among the faces it counts as one, so the last face
// is dropped; a comment among the vertices it reads as a vertex. Where the file is not plainly an
// OFF of 3 coordinates (a binary OFF, a header it cannot read), assimp decides.
class OffScan : TextScan {
 public:
  using TextScan::TextScan;

  void check() {
    next_token();
    const size_t keyword = text_.find_first_not_of("STCN4n", at_);
    if (keyword == std::string::npos || text_.compare(keyword, 3, "OFF") != 0) return;
    const bool dimension = text_.find('n', at_) < keyword;
    at_ = keyword + 3;
    if (text_.compare(at_, 7, " BINARY") == 0) return;
    unsigned long counts[4];  // the dimension where the header names one, vertices, faces, edges
    for (int k = dimension ? 0 : 1; k < 4; ++k)
      if (!read_count(counts[k])) return;
    const unsigned long vertices = counts[1], faces = counts[2];
    for (unsigned long v = 0; v < vertices; ++v) {
      if (!next_line()) return;
      const std::string word(next_word());
      char* end = nullptr;
      std::strtod(word.c_str(), &end);
      if (end == word.c_str())
        fail("vertex " + std::to_string(v + 1) + " ('" + this_line() + "') is not a vertex: the OFF reader takes each "
             "line after the counts as one; remove it");
    }
    // The reader drops a line of no face (no corners: a "0", or a comment) from the faces it keeps
    // but reads the next line in its place: each such line costs the file its last face.
    unsigned long slot = 0, kept = faces;
    std::string first_empty;
    while (slot < faces && next_line()) {
      if (!check_face(slot, vertices)) {
        --kept;
        if (first_empty.empty()) first_empty = this_line();
        continue;
      }
      if (slot >= kept) {
        const unsigned long empty = faces - kept;
        fail("face " + std::to_string(slot + 1) + " would be dropped: the OFF reader counts " +
             (empty == 1 ? "a line among the faces that holds none ('" + first_empty + "')"
                         : std::to_string(empty) + " lines among the faces that hold none (the first: '" + first_empty +
                               "')") +
             " as one of the header's " + std::to_string(faces) + "; remove " + (empty == 1 ? "it" : "them"));
      }
      ++slot;
    }
  }

 private:
  void next_token() {
    while (at_ < text_.size() && (std::isspace(static_cast<unsigned char>(text_[at_])) || text_[at_] == '#')) {
      if (text_[at_] == '#') skip_line();
      else ++at_;
    }
  }
  bool read_count(unsigned long& count) {
    next_token();
    const char* start = text_.c_str() + at_;
    if (!std::isdigit(static_cast<unsigned char>(*start))) return false;
    char* end = nullptr;
    count = std::strtoul(start, &end, 10);
    at_ += size_t(end - start);
    return true;
  }
  // False where the line holds no face (no corners, or no count).
  bool check_face(unsigned long f, unsigned long vertices) {
    const long long corners = decimal_whole(next_word());
    if (corners <= 0) return false;
    auto face = [&] { return "face " + std::to_string(f + 1) + " "; };  // built only for an error
    if (corners > 9)
      fail(face() + "has " + std::to_string(corners) + " corners; the OFF reader keeps faces of at most 9 and would "
           "drop it: save the mesh as OBJ or PLY, or split its larger faces");
    for (long long k = 0; k < corners; ++k) {
      const std::string_view word = next_word();
      const long long index = decimal_whole(word);
      if (word.empty())
        fail(face() + "has " + std::to_string(corners) + " corners but names " + std::to_string(k) + " vertices");
      if (index < 0) fail(face() + "names vertex '" + one_line(word) + "', not a vertex index (a whole number from 0)");
      if (static_cast<unsigned long long>(index) >= vertices)
        fail(face() + "names vertex " + std::string(word) + " (counted from 0), past its " + std::to_string(vertices) +
             " vertices");
    }
    return true;
  }
};

// A PLY's data walked as its header lays it out (mesh/ply_file). The PLY reader never returns on a
// header that does not end (a file cut short within its header, or its last line run into the
// data). Past the header it reads on where the data ends early: an ASCII file's next line, or its
// last line again, as the missing ones; a binary file's bytes past its end (indices of 168430090,
// or coordinates of 1e-33). An ASCII line with fewer values than its properties ask it reads with
// zeros, and a word that is not a number as 0. A header this does not know is left to assimp.
void check_ply(const std::string& path, std::string_view text) {
  const PlyHeader header = read_ply_header(path, text);
  const bool walked = header.format == "ascii" || header.format == "binary_little_endian" ||
                      header.format == "binary_big_endian";
  if (!header.unknown.empty() || !walked) return;
  PlyWalk walk(path, text, header);
  for (const PlyElement& e : header.elements) walk.element(e);
}

// A binary STL's header and triangle count: the bytes its check reads.
constexpr size_t kStlHead = 84;

// A NUL within the first 84 bytes (its count's high byte or its header's padding), where no ASCII
// STL holds one.
bool is_binary_stl(std::string_view head) { return head.substr(0, kStlHead).find('\0') != std::string_view::npos; }

// A binary STL is 84 bytes, then 50 a triangle of the count at byte 80.
// The STL reader takes a file as binary only at exactly that size, so one cut short, or with bytes
// after its triangles, failed with "Failed to determine STL storage representation", or, where
// its header opens with "solid" as many exporters write it, was read as text and found no mesh.
// `head` is the file's first bytes (kStlHead of them, or all where fewer), `size` its size.
void check_binary_stl(const std::string& path, std::string_view head, size_t size) {
  head = head.substr(0, kStlHead);
  if (size < kStlHead)
    fail_input(path, "a binary STL holds at least 84 bytes (its header and triangle count), and this one has " +
                         std::to_string(size) + " (a file cut short?)");
  const auto byte = [&](size_t i) { return static_cast<unsigned long long>(static_cast<unsigned char>(head[i])); };
  const unsigned long long count = byte(80) | byte(81) << 8 | byte(82) << 16 | byte(83) << 24;
  const unsigned long long whole = kStlHead + 50 * count;
  if (size == whole) return;
  const std::string is = "a binary STL whose header counts " + counted(size_t(count), "triangle") + " is " +
                         std::to_string(whole) + " bytes, and this one ";
  if (size < whole)
    fail_input(path, is + "ends at " + std::to_string(size) + ", within triangle " +
                         std::to_string((size - kStlHead) / 50 + 1) + " (a file cut short?)");
  fail_input(path, is + "has " + std::to_string(size - whole) + " bytes more (another file's bytes after it, or a "
                        "wrong count?)");
}

// A .blend file names the Blender that wrote it in its first 12 bytes ("BLENDER-v402": 4.2; 17 in
// Blender 5's longer header);
// from 3.0 on it may be Zstandard-compressed instead. assimp 5.2's Blender reader (deprecated by
// its makers) knows the layout up to 2.79: later files fail with a word about its internals
// ("BlendDNA: Did not find a field named `no` in structure `MVert`") or crash it.
void check_blend(const std::string& path, std::string_view head) {
  const std::string advice =
      "; assimp's Blender reader stops at Blender 2.79 (later files fail or crash it): export glTF 2.0 from Blender "
      "(File > Export > glTF 2.0, with its shape keys or animation) and give that";
  if (head.substr(0, 4) == std::string_view("\x28\xB5\x2F\xFD", 4))
    fail_unsupported(path, "is a .blend file compressed with Zstandard (Blender 3.0 or later)" + advice);
  if (head.substr(0, 7) != "BLENDER") return;  // gzip-compressed, or not a .blend: assimp decides
  // The version after the byte order's 'v' or 'V': 3 digits ("BLENDER-v402"), 4 in Blender 5's
  // longer header ("BLENDER17-01v0500").
  const size_t v = head.find_first_of("vV", 7);
  if (v == std::string_view::npos || v > 12) return;
  size_t end = v + 1;
  while (end < head.size() && end < v + 5 && head[end] >= '0' && head[end] <= '9') ++end;
  const long long version = decimal_whole(head.substr(v + 1, end - v - 1));
  if (version < 280) return;
  char name[32];
  std::snprintf(name, sizeof name, version < 300 ? "%lld.%02lld" : "%lld.%lld", version / 100, version % 100);
  fail_unsupported(path, "is a .blend file of Blender " + std::string(name) + advice);
}

bool is_checked(const std::string& ext) {
  return ext == ".off" || ext == ".ply" || ext == ".obj" || ext == ".stl" || ext == ".dae" || ext == ".blend";
}

// `text`: the file's bytes (a binary STL's head alone will do), `size`: the file's size.
void check_text(const std::string& path, const std::string& ext, const std::string& text, size_t size) {
  if (ext == ".off") OffScan(path, text).check();
  if (ext == ".ply") check_ply(path, text);
  if (ext == ".obj") check_obj_text(path, text);
  if (ext == ".stl" && is_binary_stl(text)) check_binary_stl(path, text, size);
  else if (ext == ".stl") check_ascii_stl_text(path, text);
  if (ext == ".dae") check_collada_text(path, text);
  if (ext == ".blend") check_blend(path, text);
}

}  // namespace

void check_mesh_text(const std::string& path, const std::string& text) {
  check_text(path, lower_extension(path), text, text.size());
}

void check_before_assimp(const std::string& path) {
  const std::string ext = lower_extension(path);
  if (!is_checked(ext)) return;
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  const size_t size = size_t(std::max<std::streamoff>(in.tellg(), 0));
  in.seekg(0);
  auto read_up_to = [&](size_t n) {
    std::string bytes(n, '\0');
    in.read(bytes.data(), std::streamsize(n));
    bytes.resize(size_t(std::max<std::streamsize>(in.gcount(), 0)));
    return bytes;
  };
  // A binary STL's triangles need not be read: its head tells its kind and the size it must have.
  // A .blend's version is in its first 17 bytes.
  std::string text = read_up_to(ext == ".stl"     ? std::min(size, kStlHead)
                                : ext == ".blend" ? std::min<size_t>(size, 17)
                                                  : size);
  if (ext == ".stl" && !is_binary_stl(text)) text += read_up_to(size - text.size());  // an ASCII STL is read whole
  check_text(path, ext, text, size);
}

}  // namespace spx
