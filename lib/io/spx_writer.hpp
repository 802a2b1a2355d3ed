#pragma once
// proxy-export: the runtime .spx binary (layout documented in lib/runtime/spx_runtime.h).
#include <cstddef>
#include <string>

#include "io/proxy_file.hpp"

namespace spx {

std::string encode_spx(const ProxyModel& proxy);

// The most poses (the rest among them) a .spx holds: the runtime's SPX_MAX_POSES.
size_t spx_max_poses();
// Fails (unsupported, about `subject`) when `poses` (the rest among them) are more than a .spx
// holds: a tool that would spend minutes on them says so before it starts.
void check_spx_pose_count(size_t poses, const std::string& subject);

}  // namespace spx
