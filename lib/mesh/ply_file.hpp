#pragma once
// A PLY file as assimp 5.2's reader walks it: its header (the elements, their properties and
// types), then its data instance by instance, an ASCII instance a line (blank lines skipped,
// values past its properties ignored) and a binary one its types' bytes. What the checks before
// assimp (mesh/file_checks) and the PLY made ready for assimp (mesh/ply_input) both read, so that
// the two read one file alike.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace spx {

struct PlyType {
  int size = 0;  // bytes; 0: no PLY type of that name
  bool is_signed = false, is_float = false;
};

// The type a header names (by name or by alias: "uchar" or "uint8").
PlyType ply_type(std::string_view name);

struct PlyProperty {
  PlyType count, value;  // count.size > 0: a list, its count first
};

struct PlyElement {
  std::string name;
  size_t count = 0;
  std::vector<std::string> lines;  // its header lines: the element's, then its properties' (comments too)
  std::vector<PlyProperty> properties;
};

struct PlyHeader {
  std::string format;              // "ascii", "binary_little_endian", "binary_big_endian", or another word
  std::vector<std::string> lines;  // before the first element: ply, format, comments
  std::vector<PlyElement> elements;
  size_t data = 0;       // the byte where the data begins
  size_t data_line = 1;  // its line, counted from 1
  // Where the header cannot be followed (a line that is not PLY's, a type PLY does not name, an
  // element with no count, no format), why; else empty.
  std::string unknown;
};

// The header of the PLY `text`; exit 2 naming `path` where it does not end (no "end_header"
// line: a file cut short within its header), on which assimp's reader never returns.
PlyHeader read_ply_header(const std::string& path, std::string_view text);

// The data walked as the header lays it out (ASCII or binary of either byte order), each error
// exit 2 naming `path` and the instance: data that ends before the header's counts, an ASCII
// line of fewer values than its properties or a word that is not a number of its type (assimp
// reads these as the next line, bytes past the file's end, or zeros), a list of fewer than 0
// values.
class PlyWalk {
 public:
  PlyWalk(const std::string& path, std::string_view text, const PlyHeader& header);

  // Past instance `k` (counted from 0, each in turn) of `e`; the values of its first list go to
  // `list` where given (a float's truncated). Returns the instance's bytes [begin, end): an
  // ASCII line without its end.
  std::pair<size_t, size_t> instance(const PlyElement& e, size_t k, std::vector<int64_t>* list = nullptr);
  // Past every instance of `e` (a binary element without lists in one step).
  void element(const PlyElement& e);

 private:
  std::string instance_name(const PlyElement& e, size_t k) const;
  [[noreturn]] void fail(const std::string& what) const;
  bool next_line();
  std::pair<size_t, size_t> ascii_instance(const PlyElement& e, size_t k, std::vector<int64_t>* list);
  std::pair<size_t, size_t> binary_instance(const PlyElement& e, size_t k, std::vector<int64_t>* list);
  int64_t binary_value(const PlyType& t, const PlyElement& e, size_t k);

  const std::string& path_;
  std::string_view text_;
  size_t at_, line_begin_ = 0, line_number_;
  bool ascii_, big_endian_;
};

}  // namespace spx
