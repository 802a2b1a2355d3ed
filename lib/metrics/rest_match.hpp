#pragma once
// A proxy measured or drawn on a body must be the body it was made from.
#include <string>

#include "io/proxy_file.hpp"
#include "mesh/mesh.hpp"

namespace spx {

// The rest spheres (pose 0) must lie in `rest`: a proxy made from another body's do not. Exit 2
// naming `subject` (an asset, whose welded rest `rest` is, or a rest mesh's file) as not the
// `kind` ("asset" or "mesh") the proxy was made from otherwise. Returns the rest's diagonal.
double check_rest_holds(const ProxyModel& proxy, const TriMesh& rest, const std::string& subject,
                        const std::string& kind = "asset");

}  // namespace spx
