#pragma once
// proxy-export -o OUT.html: one self-contained page that plays the proxy in a browser. The page's
// script (web/page, three.js bundled by esbuild when the project is built) and its data (the
// proxy, and the body when given: the examples' meshes, or the asset's skinned rest and its
// clips' joint matrices) are written into the page; it needs no network and no server.
#include <string>
#include <vector>

#include "core/json_io.hpp"
#include "io/proxy_file.hpp"
#include "mesh/mesh.hpp"

namespace spx {

class Asset;
struct WeldedBody;

// Clips are sampled at this rate (at most kPageMaxFrames frames each, evenly over the clip).
constexpr double kPageFramesPerSecond = 30;
constexpr size_t kPageMaxFrames = 3600;

// The proxy alone: its spheres in every pose, its blend sites and its skin. `up` is "y" or "z".
json page_data(const ProxyModel& proxy, const std::string& name, const std::string& up);

// The body as blended examples: M_0..M_e on one vertex layout (as proxy-eval loads them), each
// vertex blended by its nearest site's weights in the local blend.
void add_blended_body(json& data, const ProxyModel& proxy, const std::vector<TriMesh>& meshes);

// A skinned proxy's body from its asset: the welded rest with each vertex's joints, and every
// clip's joint matrices (the asset's joints) sampled over the clip, then the bind pose.
void add_skinned_body(json& data, const ProxyModel& proxy, const Asset& rig, const WeldedBody& body);

// The page: `data` and the bundled script in one HTML file. Exit 3 naming `output` when this
// build has no bundle (web/node_modules was missing when it was built).
std::string page_html(const json& data, const std::string& output);

}  // namespace spx
