#pragma once
// What assimp 5.2's OBJ reader would read as some other mesh, told before it is given the file
// (file_checks.hpp calls it). That reader skips a vertex it cannot count (two numbers, seven, a
// word like ".5"), and every vertex after it then stands in for the one before; it reads a word
// that only starts as a number ("0x10", "1.5.2", MSVC's NaN "-1.#IND00") as its start, and a
// corner with a leading zero or a plus ("05", "+5") twice; it skips an indented line, a first
// line behind a UTF-8 byte order mark, a line a '\' joins onto a comment, and a face of fewer
// than three corners; all without a word. Each is one error line naming the file, the line and
// the fix (exit 2). Its rules here were found by running it on each case.
#include <string>

namespace spx {

// `text` is the file's bytes; `path` names it in the error.
void check_obj_text(const std::string& path, const std::string& text);

}  // namespace spx
