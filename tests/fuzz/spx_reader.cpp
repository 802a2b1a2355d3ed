// libFuzzer target: the runtime reader on arbitrary bytes. Loading must never crash or read out
// of bounds; whatever loads must blend to finite centers and non-negative radii.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <vector>

#include "spx_runtime.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  spx::Proxy proxy;
  if (spx::load_memory(data, size, &proxy) != spx::SPX_OK) {
    if (!proxy.empty()) std::abort();
    return 0;
  }
  const uint32_t n = proxy.sphere_count(), p = proxy.pose_count(), s = proxy.site_count();
  std::vector<float> centers(size_t(n) * 3), radii(n), weights(p, 1.0f), site_weights(size_t(s) * p, 1.0f);
  if (spx::blend_global(proxy, weights.data(), p, centers.data(), radii.data()) != spx::SPX_OK) std::abort();
  for (uint32_t j = 0; j < n; ++j)
    if (!(radii[j] >= 0) || !std::isfinite(centers[3 * j])) std::abort();
  if (spx::blend_local(proxy, site_weights.data(), site_weights.size(), centers.data(), radii.data()) != spx::SPX_OK)
    std::abort();
  return 0;
}
