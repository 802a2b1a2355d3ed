#include "mesh/stl_check.hpp"

#include <cstdlib>

#include "core/error.hpp"
#include "core/format.hpp"

namespace spx {

namespace {

// An ASCII STL's words, as its reader takes them: split at any white space, lines counted.
class StlWords {
 public:
  StlWords(const std::string& path, std::string_view text) : path_(path), text_(text) {}

  void check() {
    if (next() != "solid") return;  // not plainly an ASCII STL: the reader decides
    skip_line();                     // the solid's name
    for (size_t facets = 0;;) {
      const std::string_view word = next();
      if (word.empty()) return;  // no endsolid: left to the reader (a writer may leave it out)
      if (word == "endsolid") {
        skip_line();
        const std::string_view after = next();
        if (after != "solid") return;  // the end, or words this does not know
        skip_line();
        continue;
      }
      if (word != "facet") return;
      check_facet(++facets);
    }
  }

 private:
  [[noreturn]] void fail(const std::string& what) const { fail_input(path_, what); }
  bool is_space(char c) const { return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\f' || c == '\v'; }
  std::string_view next() {
    while (at_ < text_.size() && is_space(text_[at_]))
      if (text_[at_++] == '\n') ++line_;
    const size_t start = at_;
    while (at_ < text_.size() && !is_space(text_[at_])) ++at_;
    return text_.substr(start, at_ - start);
  }
  void skip_line() {
    while (at_ < text_.size() && text_[at_] != '\n') ++at_;
  }

  // Up to its "endfacet": 3 vertices of 3 numbers each (the normal's words are not read: an
  // exporter may write "nan" for a degenerate facet, which the tools compute again anyway).
  void check_facet(size_t facet) {
    const std::string which = "facet " + std::to_string(facet);
    const std::string begun = which + ", begun on line " + std::to_string(line_) + ",";
    size_t vertices = 0;
    for (;;) {
      const std::string_view word = next();
      if (word.empty()) fail("its data ends within " + begun + " (a file cut short?)");
      if (word == "endfacet") break;
      if (word == "facet" || word == "endsolid")
        fail(begun + " has no endfacet before '" + std::string(word) + "' on line " + std::to_string(line_) +
             " (a file cut short, or two run together?)");
      if (word != "vertex") continue;
      ++vertices;
      for (int k = 0; k < 3; ++k) check_coordinate(which, begun);
    }
    if (vertices != 3)
      fail(begun + " has " + std::to_string(vertices) + (vertices == 1 ? " vertex" : " vertices") +
           "; the STL reader reads a facet as one triangle (3 vertices)" +
           (vertices > 3 ? " and would drop the others: split it into triangles" : ""));
  }

  void check_coordinate(const std::string& which, const std::string& begun) {
    const std::string word(next());
    if (word.empty()) fail("its data ends within " + begun + " (a file cut short?)");
    char* end = nullptr;
    std::strtod(word.c_str(), &end);
    if (end == word.c_str() + word.size()) return;
    const size_t comma = word.find(',');
    fail("line " + std::to_string(line_) + " (" + which + "): '" + one_line(word, 40) + "' is not a coordinate" +
         (comma != std::string::npos ? " (a decimal comma? the STL reader would read " +
                                           one_line(word.substr(0, comma), 40) +
                                           " and move the vertex: write a decimal point)"
                                     : " (a vertex of fewer than 3 numbers?)"));
  }

  const std::string& path_;
  std::string_view text_;
  size_t at_ = 0, line_ = 1;
};

}  // namespace

void check_ascii_stl_text(const std::string& path, std::string_view text) { StlWords(path, text).check(); }

}  // namespace spx
