#pragma once
// proxy-export: the runtime .spx binary (layout documented in lib/runtime/spx_runtime.h).
#include <string>

#include "io/proxy_file.hpp"

namespace spx {

std::string encode_spx(const ProxyModel& proxy);

}  // namespace spx
