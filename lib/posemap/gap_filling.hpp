#pragma once
// Gap filling, the paper's future work (PoseMapOptions::fill_gaps): what a pose's mapped spheres
// leave uncovered, packed in that pose's own field; pose-map maps the spheres kept back to the rest.
#include <string>

#include "core/log.hpp"
#include "mesh/mesh_query.hpp"
#include "pack/pack.hpp"
#include "sdf/sdf.hpp"

namespace spx {

struct PoseGaps {
  SphereSet spheres;  // in the pose, in packing order
  bool target_met = false;
  double max_error_reached = 0;  // the pose's max vertex error with them
};

// The pose's interior (`field`, its own) less what `mapped` covers, packed greedily with `pack`;
// of those, the fewest that bring the pose within `target` (as sphere-pack's tolerance) or, out
// of reach, those that still lower its max error (warned, naming `source`). At most `max_count`
// (0: no limit).
PoseGaps pack_pose_gaps(DenseField field, const SphereSet& mapped, const MeshQuery& pose, const PackOptions& pack,
                        double target, size_t max_count, const std::string& source, Log& log);

}  // namespace spx
