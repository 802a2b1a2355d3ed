#pragma once
// What assimp 5.2's ASCII STL reader would misread without a word, told before it is given the
// file (file_checks.hpp calls it). It reads a coordinate as far as it is a number: a decimal
// comma ("0,5", from an exporter in a locale that writes one) is read as 0, and the vertex lands
// elsewhere. It keeps the first 3 vertices of a facet of more and drops the rest. And it reads a
// file cut short within a facet as the facets before it, so the body loses its last triangles.
// Each is one error line naming the file, the line and the facet (exit 2). A file this does not
// follow (a binary STL, words it does not know) is left to assimp.
#include <string_view>
#include <string>

namespace spx {

// `text` is the file's bytes; `path` names it in the error.
void check_ascii_stl_text(const std::string& path, std::string_view text);

}  // namespace spx
