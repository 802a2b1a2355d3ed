// The runtime header built the way some hosts build it: compiled twice by tests/CMakeLists.txt,
// with -ffast-math (checks must still reject NaN and Inf, found by their bits) and with a small
// SPX_MAX_POSES (files with more poses are refused, not overrun).
//   runtime_config_check FILE.spx   (a proxy with more than 4 poses, from the chain)
#include "spx_runtime.h"

#include <cstdio>
#include <cstring>
#include <limits>
#include <vector>

namespace {

int failed = 0;
void expect(bool ok, const char* what) {
  if (!ok) {
    std::printf("FAIL: %s\n", what);
    ++failed;
  }
}

std::vector<unsigned char> read(const char* path) {
  std::vector<unsigned char> bytes;
  if (std::FILE* f = std::fopen(path, "rb")) {
    unsigned char buf[4096];
    size_t got;
    while ((got = std::fread(buf, 1, sizeof buf, f)) > 0) bytes.insert(bytes.end(), buf, buf + got);
    std::fclose(f);
  }
  return bytes;
}

// The file with one sphere coordinate replaced by `value`, checksum rewritten.
std::vector<unsigned char> with_value(std::vector<unsigned char> bytes, float value) {
  const uint32_t off = spx::detail::rd32(bytes.data() + 40);
  std::memcpy(bytes.data() + off + 4, &value, 4);
  const uint32_t crc = spx::detail::crc32(bytes.data(), bytes.size() - 4);
  for (int k = 0; k < 4; ++k) bytes[bytes.size() - 4 + k] = static_cast<unsigned char>(crc >> (8 * k));
  return bytes;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) return 2;
  const std::vector<unsigned char> bytes = read(argv[1]);
  spx::Proxy proxy;
  const spx::Status s = spx::load_memory(bytes.data(), bytes.size(), &proxy);
#if SPX_MAX_POSES < 5
  expect(s == spx::SPX_ERR_BAD_SIZES, "a file with more poses than SPX_MAX_POSES is refused");
  expect(proxy.empty(), "and nothing is loaded");
#else
  expect(s == spx::SPX_OK, "the file loads");
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  for (float bad : {nan, inf, -inf}) {
    spx::Proxy other;
    const std::vector<unsigned char> b = with_value(bytes, bad);
    expect(spx::load_memory(b.data(), b.size(), &other) == spx::SPX_ERR_BAD_DATA, "a non-finite coordinate is bad data");
  }
  const uint32_t p = proxy.pose_count(), n = proxy.sphere_count();
  std::vector<float> w(p, 0.0f), xyzr(4 * size_t(n)), c(3 * size_t(n)), r(n);
  w[0] = 1;
  expect(spx::blend_global_xyzr(proxy, w.data(), p, xyzr.data()) == spx::SPX_OK, "rest blend");
  for (float bad : {nan, inf}) {
    w[1] = bad;
    expect(spx::blend_global(proxy, w.data(), p, c.data(), r.data()) == spx::SPX_ERR_BAD_WEIGHTS, "non-finite weight");
    expect(spx::blend_global_xyzr(proxy, w.data(), p, xyzr.data()) == spx::SPX_ERR_BAD_WEIGHTS, "non-finite weight, xyzr");
    std::vector<float> sw(size_t(proxy.site_count()) * p, 0.5f), normalized(sw.size());
    sw[1] = bad;
    expect(spx::normalize_site_weights(proxy, sw.data(), sw.size(), normalized.data()) == spx::SPX_ERR_BAD_WEIGHTS,
           "non-finite site weight");
  }
#endif
  std::printf("%d passed, %d failed\n", failed == 0 ? 1 : 0, failed == 0 ? 0 : 1);
  return failed == 0 ? 0 : 1;
}
