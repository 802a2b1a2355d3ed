#pragma once
// An asset given beside a proxy (--asset) must be the body the proxy was made from.
#include <string>

#include "io/proxy_file.hpp"
#include "mesh/mesh.hpp"

namespace spx {

// The rest spheres (pose 0, on pose-extract's rest of the asset) must lie in the asset's welded
// rest: a proxy made from another body does not. Exit 2 naming `asset` otherwise. Returns the
// rest's diagonal.
double check_rest_holds(const ProxyModel& proxy, const TriMesh& rest, const std::string& asset);

}  // namespace spx
