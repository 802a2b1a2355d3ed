#pragma once
// What assimp 5.2's COLLADA reader would misread or never finish reading, told before it is given
// the file (file_checks.hpp calls it). Its index lists (<p>, <vcount>, <v>, <h>: a primitive's
// corners, a skin's weights per vertex and their joints) are read one whole number at a time by
// a parser that does not move past a character it cannot read: a word like "5.2", "x2" or "inf"
// in a <p>, or a damaged byte, had it allocate without end (6 GB in 15 s on a 21 KB file), and in
// a skin's <vcount> or <v> it read other weights without a word; "-2" is read as another index.
// And it reads `count` values of an array however many it holds, and an accessor's elements
// wherever they fall: an array that holds more values than its count, or an accessor reaching
// past its array, read memory the array does not have (a segmentation fault, or other numbers).
// Each is one error line naming the file, the line and the element (exit 2).
#include <string>

namespace spx {

// `text` is the file's bytes; `path` names it in the error.
void check_collada_text(const std::string& path, const std::string& text);

}  // namespace spx
