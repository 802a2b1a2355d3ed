// libFuzzer target: the runtime reader on arbitrary bytes. Loading must never crash or read out
// of bounds; whatever loads must blend to finite centers and non-negative radii.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <vector>

#include "spx_runtime.h"

namespace {

void check(const uint8_t* data, size_t size) {
  spx::Proxy proxy;
  if (spx::load_memory(data, size, &proxy) != spx::SPX_OK) {
    if (!proxy.empty()) std::abort();
    return;
  }
  const uint32_t n = proxy.sphere_count(), p = proxy.pose_count(), s = proxy.site_count();
  std::vector<float> centers(size_t(n) * 3), radii(n), weights(p, 1.0f), site_weights(size_t(s) * p, 1.0f);
  if (spx::blend_global(proxy, weights.data(), p, centers.data(), radii.data()) != spx::SPX_OK) std::abort();
  for (uint32_t j = 0; j < n; ++j)
    if (!(radii[j] >= 0) || !std::isfinite(centers[3 * j])) std::abort();
  if (spx::blend_local(proxy, site_weights.data(), site_weights.size(), centers.data(), radii.data()) != spx::SPX_OK)
    std::abort();
}

}  // namespace

// Each input twice: as it is, and with its trailing CRC-32 recomputed, so that mutations get
// past the checksum to the structural checks behind it.
extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  check(data, size);
  if (size >= 12) {
    std::vector<uint8_t> fixed(data, data + size);
    const uint32_t crc = spx::detail::crc32(fixed.data(), size - 4);
    for (int k = 0; k < 4; ++k) fixed[size - 4 + size_t(k)] = uint8_t(crc >> (8 * k));
    check(fixed.data(), size);
  }
  return 0;
}
