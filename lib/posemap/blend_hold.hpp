#pragma once
// pose-map --hold-over-blends: a blended proxy's spheres held inside the blends a host plays
// between the examples, not only at the examples. The runtime's blend of the spheres and the
// host's blend of the meshes are both the examples' weighted sums, so at a blend each sphere is
// its examples' spheres summed and the body its examples' meshes summed. Where a sphere pokes out
// at a blend, its radii in every example are scaled down by the one factor that brings it inside
// at its worst blend (its centres stay: the map put them there).
#include <vector>

#include "io/proxy_file.hpp"
#include "mesh/mesh.hpp"

namespace spx {

// The blends held, each a weight per pose (the rest's first) summing to 1: every two examples
// (the rest among them) half and half; with `morph_targets` (the examples after the rest are
// morph targets, which a host adds) also two or more targets at 1 at once: every such set of
// them up to 8 targets, every pair past that.
std::vector<std::vector<double>> blends_to_hold(size_t poses, bool morph_targets);

struct BlendHold {
  size_t blends = 0;          // blends checked
  size_t shrunk = 0;          // spheres whose radii were scaled down
  size_t emptied = 0;         // spheres whose centre leaves the body at a blend: radius 0 in every pose
  double overshoot = 0;       // how far the union poked out at its worst blend before (a length)
  std::vector<double> worst;  // that blend's weights (empty: none poked out)
  double least_scale = 1;     // the smallest factor a kept sphere's radii took
};

// `meshes`: the rest and every pose on the rest's vertex layout and triangles. Scales each
// sphere's radii in every pose of `proxy` so that at every blend its summed radius is at most its
// summed centre's depth in the summed mesh. The same result on any number of threads.
BlendHold hold_over_blends(ProxyModel& proxy, const std::vector<const TriMesh*>& meshes,
                           const std::vector<std::vector<double>>& blends);

}  // namespace spx
