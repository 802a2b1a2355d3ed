#pragma once
// Sphere unions as triangles to look at (Blender, any glTF/PLY viewer).
#include <string>

#include "mesh/mesh.hpp"
#include "posemap/proxy.hpp"

namespace spx {

// Every sphere with a positive radius as an icosphere (`subdivisions` 0..4).
TriMesh sphere_union_mesh(const SphereSet& spheres, int subdivisions = 2);

// Binary glTF with one node per pose (named after it), laid side by side along +x when
// `spread` is set; or binary PLY of one pose. The format comes from the extension.
std::string encode_preview(const ProxyModel& proxy, const std::string& extension, int pose, bool spread);

}  // namespace spx
