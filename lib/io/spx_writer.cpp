#include "io/spx_writer.hpp"

#include <cstring>

#include "core/error.hpp"
#include "runtime/spx_runtime.h"

namespace spx {
namespace {

void put16(std::string& b, size_t at, uint16_t v) {
  b[at] = char(v & 0xFF);
  b[at + 1] = char(v >> 8);
}
void put32(std::string& b, size_t at, uint32_t v) {
  for (int k = 0; k < 4; ++k) b[at + k] = char((v >> (8 * k)) & 0xFF);
}
void put64(std::string& b, size_t at, uint64_t v) {
  put32(b, at, uint32_t(v));
  put32(b, at + 4, uint32_t(v >> 32));
}
void append32(std::string& b, uint32_t v) {
  b.resize(b.size() + 4);
  put32(b, b.size() - 4, v);
}
void append_f32(std::string& b, double v) {
  const float f = float(v);
  uint32_t u;
  std::memcpy(&u, &f, 4);
  append32(b, u);
}

void append_name(std::string& b, const std::string& name) {
  append32(b, uint32_t(name.size()));
  b += name;
  b.resize((b.size() + 3) & ~size_t(3), '\0');
}

// The skin section (format 1.1): joint count, size, a record per sphere, parents, names.
void append_skin(std::string& b, const ProxySkin& skin) {
  const size_t at = b.size();
  append32(b, uint32_t(skin.joints.size()));
  append32(b, 0);  // the size, once known
  for (const SkinnedSphere& s : skin.spheres) {
    for (int k = 0; k < 3; ++k) append_f32(b, s.center[k]);
    append_f32(b, s.radius);
    for (float w : s.weight) append_f32(b, w);
    for (int j : s.joint) append32(b, uint32_t(j));
  }
  for (int parent : skin.parents) append32(b, uint32_t(int32_t(parent)));
  for (const auto& name : skin.joints) append_name(b, name);
  put32(b, at + 4, uint32_t(b.size() - at));
}

}  // namespace

size_t spx_max_poses() { return SPX_MAX_POSES; }

void check_spx_pose_count(size_t poses, const std::string& subject) {
  if (poses > SPX_MAX_POSES)
    fail_unsupported(subject, "has " + std::to_string(poses) + " poses (the rest and " + std::to_string(poses - 1) +
                                  " examples); a .spx holds at most " + std::to_string(SPX_MAX_POSES) +
                                  ", the runtime's SPX_MAX_POSES: map fewer poses (pose-extract --select N or --every K)");
}

std::string encode_spx(const ProxyModel& proxy) {
  const size_t n = proxy.sphere_count(), p = proxy.poses.size(), s = proxy.sites.size();
  if (n == 0 || p == 0 || s == 0) fail_input("", "proxy has no spheres, poses or sites");
  check_spx_pose_count(p, "");
  std::string b(SPX_HEADER_SIZE, '\0');
  std::memcpy(&b[0], SPX_MAGIC, 8);
  put16(b, 8, SPX_FORMAT_VERSION_MAJOR);
  // A proxy without a skin is a format 1.0 file, byte for byte.
  put16(b, 10, proxy.skin.empty() ? 0 : SPX_FORMAT_VERSION_MINOR);
  put32(b, 12, SPX_HEADER_SIZE);
  put32(b, 24, uint32_t(n));
  put32(b, 28, uint32_t(p));
  put32(b, 32, uint32_t(s));
  b[36] = 4;
  b[37] = 4;

  put32(b, 40, uint32_t(b.size()));
  for (const auto& pose : proxy.poses)
    for (const auto& sphere : pose.spheres) {
      for (int k = 0; k < 3; ++k) append_f32(b, sphere.center[k]);
      append_f32(b, sphere.radius);
    }
  put32(b, 44, uint32_t(b.size()));
  for (int site : proxy.sphere_sites) append32(b, uint32_t(site));
  put32(b, 48, uint32_t(b.size()));
  for (const auto& site : proxy.sites)
    for (int k = 0; k < 3; ++k) append_f32(b, site[k]);
  const size_t names_at = b.size();
  put32(b, 52, uint32_t(names_at));
  for (const auto& pose : proxy.poses) append_name(b, pose.name);
  put32(b, 56, uint32_t(b.size() - names_at));
  if (!proxy.skin.empty()) {
    if (proxy.skin.spheres.size() != n) fail_input("", "proxy's skin does not have one entry per sphere");
    put16(b, 38, detail::SPX_FLAG_SKIN);
    put32(b, 60, uint32_t(b.size()));
    append_skin(b, proxy.skin);
  }
  if (b.size() + 4 > 0xFFFFFFFFull) fail_unsupported("", "proxy is too large for the .spx format");
  put64(b, 16, b.size() + 4);
  append32(b, detail::crc32(reinterpret_cast<const unsigned char*>(b.data()), b.size()));
  return b;
}

}  // namespace spx
