#pragma once
// A PLY made ready for assimp (5.2), whose reader reads some valid ones wrong or not at all. It
// reads triangle strips (an element "tristrips", each instance a list of vertex indices in which
// -1 restarts the strip, as Stanford's scans and older exporters write them) as one triangle per
// instance: a body of thousands of triangles in one strip read as one triangle and was refused as
// flat ("encloses no volume"). And it refuses a file whose faces come before its vertices, which
// PLY allows. Such a file is given to assimp as the same PLY with the strips written out as
// triangles and the vertices first, so that assimp reads it as it reads any other.
#include <optional>
#include <string>

namespace spx {

// The PLY at `path` with its "tristrips" element replaced by an element "face" of the strips'
// triangles and its vertex element moved first (in the same format, ASCII or binary of either
// byte order; every other element copied as it is), or nullopt where assimp reads the file as
// it is. Triangle k of a strip is (a, b, c) for its three indices in turn, (b, a, c) where k is
// odd (its turn kept); a triangle with a repeated corner (a strip's stitch) is left out. Exit 2
// naming `path` where the file cannot be followed: an index past the vertices or below -1, data
// cut short, strips beside an element "face" of its own, a header line that is not PLY's (with
// strips).
std::optional<std::string> ply_for_assimp(const std::string& path);

// The same on a file's bytes (what a fuzzer drives); `path` names it in errors.
std::optional<std::string> ply_text_for_assimp(const std::string& path, const std::string& text);

}  // namespace spx
