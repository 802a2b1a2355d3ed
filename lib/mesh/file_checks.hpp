#pragma once
// What assimp 5.2's OFF, PLY (ply_file.hpp), OBJ (obj_check.hpp), ASCII STL (stl_check.hpp) and
// COLLADA (collada_check.hpp) readers would read wrong, or never finish reading, a binary STL of
// the wrong size, and a .blend newer than its Blender reader (exit 3), told before assimp is
// given the file. Those readers take a file cut short, a face of more corners than they keep, or
// an index they cannot use, as some other mesh, and say so only in their log (or not at all): a
// hole, a triangle in the wrong place, a vertex read from the next line. Here each is one error
// line naming the file and the place (spx::Error, exit 2). A file these checks cannot follow (a
// header they do not know) is left to assimp, as is every other format.
#include <string>

namespace spx {

void check_before_assimp(const std::string& path);

// The same on a file's bytes, the format told by `path`'s extension (what a fuzzer drives).
void check_mesh_text(const std::string& path, const std::string& text);

}  // namespace spx
