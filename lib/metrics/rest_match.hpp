#pragma once
// A proxy measured or drawn on a body must be the body it was made from.
#include <string>

#include <vector>

#include "core/log.hpp"
#include "io/proxy_file.hpp"
#include "mesh/mesh.hpp"

namespace spx {

// The rest spheres (pose 0) must lie in `rest`: a proxy made from another body's do not. Exit 2
// naming `subject` (an asset, whose welded rest `rest` is, or a rest mesh's file) as not the
// `kind` ("asset" or "mesh") the proxy was made from otherwise. Returns the rest's diagonal.
double check_rest_holds(const ProxyModel& proxy, const TriMesh& rest, const std::string& subject,
                        const std::string& kind = "asset");

class Asset;

// For a body of several meshes: the used meshes of `asset` (those of one name as one, the unit
// --mesh takes) whose rest box holds no centre of the proxy's rest spheres, which a proxy made
// from one of the others (pose-extract --mesh) leaves uncovered. When there are some, a warning
// names them, says `effect` ("the page shows them uncovered") and names --mesh with the meshes
// whose box holds every centre. Returns their names.
std::vector<std::string> warn_meshes_without_spheres(const ProxyModel& proxy, const Asset& asset,
                                                     const std::string& effect, Log& log);

}  // namespace spx
