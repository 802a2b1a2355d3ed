#include "mesh/obj_check.hpp"

#include <array>
#include <string_view>

#include "core/error.hpp"
#include "core/format.hpp"

namespace spx {

namespace {

// The reader's line ends (a NUL and a form feed end a line too).
bool is_line_end(char c) { return c == '\n' || c == '\r' || c == '\0' || c == '\f'; }
// Where a line scan stops: a line end or a '\'.
constexpr auto kStop = [] {
  std::array<bool, 256> stop{};
  for (unsigned char c : {'\n', '\r', '\0', '\f', '\\'}) stop[c] = true;
  return stop;
}();
bool is_blank(char c) { return c == ' ' || c == '\t'; }
bool is_digit(char c) { return c >= '0' && c <= '9'; }

bool equal_ci(std::string_view word, std::string_view lower) {
  if (word.size() != lower.size()) return false;
  for (size_t i = 0; i < word.size(); ++i)
    if ((word[i] | 0x20) != lower[i]) return false;
  return true;
}

// A word the reader counts as a number: it starts with a digit or a sign, or is a NaN or an
// infinity. ".5" is not one.
bool counted_as_number(std::string_view word) {
  return is_digit(word[0]) || word[0] == '-' || word[0] == '+' || equal_ci(word.substr(0, 3), "nan") ||
         equal_ci(word.substr(0, 3), "inf");
}

// A word the reader's number parser reads to its end: a sign, digits with a '.' or ',' (its
// decimal comma) among them, an exponent; or a NaN or an infinity (refused later, by value).
bool whole_number(std::string_view word) {
  size_t i = word[0] == '-' || word[0] == '+' ? 1 : 0;
  const std::string_view rest = word.substr(i);
  if (equal_ci(rest, "nan") || equal_ci(rest, "inf") || equal_ci(rest, "infinity")) return true;
  size_t digits = 0;
  auto run = [&] {
    size_t n = 0;
    while (i < word.size() && is_digit(word[i])) ++i, ++n;
    return n;
  };
  digits += run();
  if (i < word.size() && (word[i] == '.' || word[i] == ',')) ++i, digits += run();
  if (digits == 0) return false;
  if (i < word.size() && (word[i] == 'e' || word[i] == 'E')) {
    ++i;
    if (i < word.size() && (word[i] == '-' || word[i] == '+')) ++i;
    if (run() == 0) return false;
  }
  return i == word.size();
}

// An index as the reader reads it right: an optional '-', then a whole number from 1 without a
// leading zero (it reads "05" and "+5" as two corners, having stepped one digit). 0 if not one.
long long corner_index(std::string_view part) {
  const bool back = !part.empty() && part[0] == '-';
  const std::string_view digits = part.substr(back ? 1 : 0);
  if (digits.empty() || digits.size() > 9 || digits[0] == '0') return 0;
  long long value = 0;
  for (char c : digits) {
    if (!is_digit(c)) return 0;
    value = value * 10 + (c - '0');
  }
  return back ? -value : value;
}

// An OBJ walked line by line as the reader splits it (a '\' is dropped, and one directly before a
// line end joins the next line on, without a blank), its vertex and face lines read as it reads
// them.
class ObjScan {
 public:
  ObjScan(const std::string& path, const std::string& text) : path_(path), text_(text) {}

  void check() {
    const bool bom = text_.compare(0, 3, "\xEF\xBB\xBF") == 0;
    if (bom) at_ = 3;
    for (bool first = true; next_line(); first = false) {
      if (line_.empty()) continue;
      size_t indent = 0, after = 0;
      while (indent < line_.size() && is_blank(line_[indent])) ++indent;
      if (indent == line_.size()) continue;
      for (after = indent; after < line_.size() && !is_blank(line_[after]);) ++after;
      const std::string_view keyword = line_.substr(indent, after - indent);
      check_opening(keyword, indent, first && bom);
      if (keyword == "v") check_vertex(line_.substr(indent + 1));
      else if (line_[0] == 'f') check_face(line_.substr(indent + keyword.size()));
    }
    if (static_cast<unsigned long long>(highest_.index) > vertices_) {
      line_number_ = highest_.line;
      line_ = physical_line(highest_.begin);
      fail("corner '" + one_line(highest_.word) + "' names vertex " + std::to_string(highest_.index) +
           ", past the file's " + std::to_string(vertices_) + " vertices");
    }
  }

 private:
  // How the line opens: its first word `keyword`, after `indent` blanks; `after_bom`: the file's
  // first line, behind a byte order mark.
  void check_opening(std::string_view keyword, size_t indent, bool after_bom) {
    const bool vertex = keyword == "v", face = keyword == "f" || keyword == "fo";
    if (indent > 0 && (vertex || face))
      fail(std::string("the line is indented; the OBJ reader skips a line that does not start with its keyword and "
                       "would drop this ") + (vertex ? "vertex (every vertex after it taking the place of the one "
                                                       "before)" : "face") + ": remove the blanks before it");
    if (after_bom && (vertex || face))
      fail("the file opens with a UTF-8 byte order mark, which the OBJ reader takes as part of this line, and it "
           "would drop the line: save the file without one");
    if (keyword.size() > 1 && (keyword[0] == 'v' || keyword[0] == 'f') &&
        (is_digit(keyword[1]) || keyword[1] == '-' || keyword[1] == '+' || keyword[1] == '.'))
      fail(std::string("no blank after '") + keyword[0] + "'; the OBJ reader would " +
           (keyword[0] == 'v' ? "drop this vertex" : "drop this face's first corner") + ": write '" + keyword[0] +
           " " + one_line(line_.substr(1)) + "'");
    if (!vertex && line_[0] != 'f' && joins_) {
      line_ = physical_line(begin_);
      fail("it ends in '\\', which joins the next line to it, and the OBJ reader would read the vertex or face "
           "there as part of this line and drop it: remove the '\\'");
    }
  }

  [[noreturn]] void fail(const std::string& what) const {
    fail_input(path_, "line " + std::to_string(line_number_) + " ('" + one_line(line_, 60) + "'): " + what);
  }

  // The next logical line into line_ (a view of the text, or joined_ where a '\' joined lines).
  bool next_line() {
    if (at_ >= text_.size()) return false;
    line_number_ = next_number_;
    const size_t begin = begin_ = at_;
    size_t piece = at_;
    bool joined = false;
    joins_ = false;
    while (true) {
      at_ = stop_from(at_);
      if (at_ >= text_.size() || text_[at_] != '\\') break;
      if (!joined) joined_.clear();
      joined = true;
      joined_.append(text_, piece, at_ - piece);
      ++at_;
      if (at_ < text_.size() && is_line_end(text_[at_])) {
        skip_line_end();
        joins_ = joins_ || opens_vertex_or_face(at_);
      }
      piece = at_;
    }
    if (joined) joined_.append(text_, piece, at_ - piece);
    line_ = joined ? std::string_view(joined_) : std::string_view(text_).substr(begin, at_ - begin);
    if (at_ < text_.size()) skip_line_end();
    return true;
  }
  // The first line end or '\\' from `i` on (the text's size if none).
  size_t stop_from(size_t i) const {
    const char *p = text_.data() + i, *end = text_.data() + text_.size();
    while (p < end && !kStop[static_cast<unsigned char>(*p)]) ++p;
    return size_t(p - text_.data());
  }
  // The text from `begin` to its line's end, as an editor shows that line.
  std::string_view physical_line(size_t begin) const {
    size_t end = begin;
    while (end < text_.size() && !is_line_end(text_[end])) ++end;
    return std::string_view(text_).substr(begin, end - begin);
  }
  // Whether the text at `i` opens a vertex or a face line ("v ", "f ", "fo ").
  bool opens_vertex_or_face(size_t i) const {
    const std::string_view rest = std::string_view(text_).substr(i, 3);
    return (rest.size() > 1 && (rest[0] == 'v' || rest[0] == 'f') && is_blank(rest[1])) ||
           (rest.size() > 2 && rest[0] == 'f' && rest[1] == 'o' && is_blank(rest[2]));
  }
  void skip_line_end() {
    if (text_[at_] == '\n' || text_[at_] == '\r') ++next_number_;
    at_ += text_[at_] == '\r' && at_ + 1 < text_.size() && text_[at_ + 1] == '\n' ? 2 : 1;
  }

  // The words of `words` up to a comment ('#' opening a word); a '#' within a word ends it.
  template <class Fn>
  static void for_each_word(std::string_view words, const Fn& fn) {
    size_t i = 0;
    while (true) {
      while (i < words.size() && is_blank(words[i])) ++i;
      if (i >= words.size() || words[i] == '#') return;
      const size_t start = i;
      size_t end = 0;  // a '#' within the word ends it, but for MSVC's "1.#QNAN0" (NaN), "-1.#INF00"
      while (i < words.size() && !is_blank(words[i])) {
        if (words[i] == '#' && end == 0 && words[i - 1] != '.') end = i;
        ++i;
      }
      fn(words.substr(start, (end ? end : i) - start));
    }
  }

  void check_vertex(std::string_view words) {
    size_t numbers = 0;
    for_each_word(words, [&](std::string_view word) {
      const bool number = whole_number(word);
      if (number && !counted_as_number(word))
        fail("the OBJ reader does not take '" + one_line(word) + "' for a number (only a word that starts with a digit "
             "or a sign), and would misread this vertex: write '0" + one_line(word) + "'");
      if (!number)
        fail("'" + one_line(word) + "' is not a number" +
             (counted_as_number(word) ? " (the OBJ reader would read only its start)" : ""));
      ++numbers;
    });
    if (numbers != 3 && numbers != 4 && numbers != 6)
      fail("a vertex of " + counted(numbers, "number") +
           "; the OBJ reader reads 3 (x y z), 4 (x y z w) or 6 (x y z and a colour), and would drop it, every vertex "
           "after it taking the place of the one before");
    ++vertices_;
  }

  void check_face(std::string_view words) {
    size_t corners = 0;
    for_each_word(words, [&](std::string_view word) {
      if (word.find_first_not_of('/') == std::string_view::npos) return;  // a stray '/': the reader skips it
      long long vertex = 0;
      size_t part = 0;
      for (size_t start = 0; start <= word.size(); ++part) {
        size_t end = start;
        while (end < word.size() && word[end] != '/') ++end;
        const std::string_view index = word.substr(start, end - start);
        if (part > 2 || (part == 0 && index.empty()))
          fail("'" + one_line(word) + "' is not a corner (v, v/vt, v/vt/vn or v//vn)");
        if (!index.empty()) {
          const long long value = corner_index(index);
          if (value == 0)
            fail("corner '" + one_line(word) + "'" + (index == word ? "" : ": '" + one_line(index) + "'") +
                 (index == "0" ? std::string(": OBJ counts from 1")
                               : " is not an index the OBJ reader reads right (a whole number from 1 with no leading "
                                 "zero or plus sign, or negative to count back)"));
          if (part == 0) vertex = value;
        }
        start = end + 1;
      }
      if (vertex < 0 && static_cast<unsigned long long>(-vertex) > vertices_)
        fail("corner '" + one_line(word) + "' counts back past the " + std::to_string(vertices_) +
             " vertices before it");
      if (vertex > highest_.index) highest_ = {vertex, line_number_, begin_, std::string(word)};
      ++corners;
    });
    if (corners < 3)
      fail("a face of " + counted(corners, "corner") +
           "; the OBJ reader keeps faces of 3 or more and would drop it (a line is 'l')");
  }

  const std::string& path_;
  const std::string& text_;
  size_t at_ = 0, next_number_ = 1, line_number_ = 0, begin_ = 0;  // begin_: where line_ starts in the text
  std::string joined_;
  std::string_view line_;
  bool joins_ = false;  // a '\' joined a vertex or face line onto this one
  unsigned long long vertices_ = 0;
  struct {
    long long index = 0;
    size_t line = 0, begin = 0;
    std::string word;
  } highest_;  // the corner naming the highest vertex, checked against the count at the end
};

}  // namespace

void check_obj_text(const std::string& path, const std::string& text) { ObjScan(path, text).check(); }

}  // namespace spx
