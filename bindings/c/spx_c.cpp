// The C API: spx_runtime.h behind an opaque handle.
#include "spx_c.h"

#include <new>

#include "spx_runtime.h"

struct spx_proxy {
  spx::Proxy proxy;
};

namespace {

const spx::Proxy& get(const spx_proxy* p) {
  static const spx::Proxy empty;
  return p ? p->proxy : empty;
}

template <class Load>
int load(spx_proxy** out, Load&& fill) {
  if (!out) return spx::SPX_ERR_INVALID_ARGUMENT;
  *out = nullptr;
  spx_proxy* p = new (std::nothrow) spx_proxy;
  if (!p) return spx::SPX_ERR_OUT_OF_MEMORY;
  const spx::Status s = fill(&p->proxy);
  if (s != spx::SPX_OK) {
    delete p;
    return s;
  }
  *out = p;
  return spx::SPX_OK;
}

}  // namespace

extern "C" {

int spx_load_file(const char* path, spx_proxy** out) {
  return load(out, [&](spx::Proxy* p) { return spx::load_file(path, p); });
}
int spx_load_memory(const void* data, size_t size, spx_proxy** out) {
  return load(out, [&](spx::Proxy* p) { return spx::load_memory(data, size, p); });
}
void spx_free(spx_proxy* proxy) { delete proxy; }
const char* spx_status_string(int status) { return spx::status_string(spx::Status(status)); }

uint32_t spx_sphere_count(const spx_proxy* p) { return get(p).sphere_count(); }
uint32_t spx_pose_count(const spx_proxy* p) { return get(p).pose_count(); }
uint32_t spx_site_count(const spx_proxy* p) { return get(p).site_count(); }
const float* spx_pose_spheres(const spx_proxy* p, uint32_t pose) { return get(p).pose_spheres(pose); }
const char* spx_pose_name(const spx_proxy* p, uint32_t pose) { return get(p).pose_name(pose); }
const uint32_t* spx_sphere_sites(const spx_proxy* p) { return get(p).sphere_sites(); }
const float* spx_site_positions(const spx_proxy* p) { return get(p).site_positions(); }

int spx_blend_global(const spx_proxy* p, const float* w, uint32_t count, float* centers, float* radii) {
  return spx::blend_global(get(p), w, count, centers, radii);
}
int spx_blend_local(const spx_proxy* p, const float* w, size_t count, float* centers, float* radii) {
  return spx::blend_local(get(p), w, count, centers, radii);
}
int spx_blend_global_xyzr(const spx_proxy* p, const float* w, uint32_t count, float* xyzr) {
  return spx::blend_global_xyzr(get(p), w, count, xyzr);
}
int spx_blend_morph(const spx_proxy* p, const float* w, uint32_t count, float* centers, float* radii) {
  return spx::blend_morph(get(p), w, count, centers, radii);
}
int spx_blend_morph_xyzr(const spx_proxy* p, const float* w, uint32_t count, float* xyzr) {
  return spx::blend_morph_xyzr(get(p), w, count, xyzr);
}
int spx_normalize_site_weights(const spx_proxy* p, const float* w, size_t count, float* normalized) {
  return spx::normalize_site_weights(get(p), w, count, normalized);
}
uint32_t spx_joint_count(const spx_proxy* p) { return get(p).joint_count(); }
const char* spx_joint_name(const spx_proxy* p, uint32_t joint) { return get(p).joint_name(joint); }
int32_t spx_joint_parent(const spx_proxy* p, uint32_t joint) { return get(p).joint_parent(joint); }
int spx_skin(const spx_proxy* p, const float* joint_matrices, int joint_count, float* xyzr) {
  return spx::skin(get(p), joint_matrices, joint_count, xyzr);
}
int spx_blend_local_normalized(const spx_proxy* p, const float* normalized, size_t count, float* xyzr) {
  return spx::blend_local_normalized(get(p), normalized, count, xyzr);
}

}  // extern "C"
