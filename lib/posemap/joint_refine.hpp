#pragma once
// pose-map's joint selection, budget mode: the chosen rest centres moved off the candidates
// where that lowers every frame's errors (pack's refine_jointly), each frame's sphere by that
// frame's own rule, as sphere-pack refines the rest pose's alone.
#include "core/log.hpp"
#include "core/sphere.hpp"
#include "posemap/joint_selection.hpp"

namespace spx {

// `chosen` (rest spheres) refined from `step` over every frame's `samples` (the selection's:
// each frame's vertices first, weighted), no frame's sample leaving `delta` that was within it;
// then largest first by the rest sphere each becomes; no move makes a rest sphere smaller than
// `min_radius` (0: none). Returns the moves made.
size_t refine_chosen(const SelectionFrames& frames, const std::vector<std::vector<Eigen::Vector3d>>& samples,
                     double step, double min_radius, SphereSet& chosen, double delta, Log& log = Log::silent());

}  // namespace spx
