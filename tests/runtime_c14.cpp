// The runtime header in a translation unit of its own: C++14, -Wall -Wextra -Werror
// -fno-exceptions, nothing but the standard library. Reads a .spx that proxy-export wrote and
// checks that weight 1 on pose i returns S_i and that uniform local weights equal global ones.
#include "spx_runtime.h"

#include <cstdio>
#include <vector>

int main(int argc, char** argv) {
  if (argc != 2) return 2;
  spx::Proxy proxy;
  const spx::Status s = spx::load_file(argv[1], &proxy);
  if (s != spx::SPX_OK) {
    std::printf("load: %s\n", spx::status_string(s));
    return 1;
  }
  const uint32_t n = proxy.sphere_count(), p = proxy.pose_count();
  std::vector<float> c(size_t(n) * 3), r(n), lc(size_t(n) * 3), lr(n);
  int failed = 0;
  for (uint32_t i = 0; i < p; ++i) {
    std::vector<float> w(p, 0.0f);
    w[i] = 1.0f;
    std::vector<float> sw;
    for (uint32_t site = 0; site < proxy.site_count(); ++site) sw.insert(sw.end(), w.begin(), w.end());
    if (spx::blend_global(proxy, w.data(), p, c.data(), r.data()) != spx::SPX_OK) ++failed;
    if (spx::blend_local(proxy, sw.data(), sw.size(), lc.data(), lr.data()) != spx::SPX_OK) ++failed;
    for (uint32_t j = 0; j < n; ++j) {
      const float* sphere = proxy.pose_spheres(i) + 4 * size_t(j);
      if (c[3 * j] != sphere[0] || c[3 * j + 1] != sphere[1] || c[3 * j + 2] != sphere[2] || r[j] != sphere[3]) ++failed;
      if (lc[3 * j] != c[3 * j] || lr[j] != r[j]) ++failed;
    }
  }
  std::printf("%d passed, %d failed\n", failed == 0 ? 1 : 0, failed == 0 ? 0 : 1);
  return failed == 0 ? 0 : 1;
}
