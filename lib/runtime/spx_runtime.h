// spx_runtime.h - load and blend sphere-union collision proxies (.spx files).
//
// One self-contained header: C++14, standard library only, no exceptions, no allocation after
// loading. Every failure returns a status code; any bytes are safe to hand to the loader.
//
//   spx::Proxy proxy;
//   if (spx::load_file("car.spx", &proxy) != spx::SPX_OK) ...
//   spx::blend_global(proxy, weights, proxy.pose_count(), centers, radii);   // each frame
//   spx::blend_morph(proxy, morph_weights, proxy.pose_count() - 1, centers, radii);   // blend shapes
//   spx::skin(proxy, joint_matrices, proxy.joint_count(), xyzr);   // each frame, a rigged body
//
// Two output layouts: centers (x y z per sphere) + radii, or xyzr (x y z r per sphere, the
// layout of pose_spheres(); the fastest: the loops vectorise). For the local blend at memory
// speed, normalise the site weights once when they change (normalize_site_weights) and blend
// from them every frame (blend_local_normalized).
//
// Configuration (define before including):
//   SPX_MAX_POSES   largest pose count accepted (default 256). Files with more poses are
//                   rejected (SPX_ERR_BAD_SIZES); blends keep SPX_MAX_POSES floats on the stack.
//   SPX_MALLOC / SPX_FREE   the allocator used once per load (default std::malloc / std::free);
//                   it must return memory aligned to 16 bytes, as malloc does on 64-bit systems
//                   (the sphere block starts the allocation, so SIMD loads of x y z r align).
//
// Thread safety: a loaded Proxy is never modified by a blend. Blends are const, reentrant and
// allocate nothing, so any number of threads may blend one proxy at once, each into its own
// output. Loading into a Proxy, reset() and moving it need exclusive access.
//
// Checks do not depend on the compiler's floating-point mode: non-finite values are found by
// their bits, so -ffast-math builds reject NaN and Inf as strict ones do.
//
// Weights policy (global and local blends alike): a weight vector must have exactly
// pose_count() finite entries; negative entries are clamped to 0, and the rest are divided by
// their sum, which must be positive. Anything else is rejected with SPX_ERR_BAD_WEIGHTS or
// SPX_ERR_WEIGHT_COUNT and the output buffers are left untouched. Radii are never negative.
// The morph blend (blend_morph) instead takes one weight per example after the rest, as a host
// weighs its mesh's morph targets, and adds them as the mesh adds its targets (no clamping, no
// normalising; the rest weighs 1 less their sum).
//
// Skin (a rigged body's proxy, has_skin()): each sphere follows the body's skeleton by linear
// blend skinning of its center with up to 4 joints, exactly as a host skins its mesh, and keeps
// one radius in every frame. joint_matrices are joint_count() column-major 4x4 matrices in the
// skin's joint order (joint_name()): each joint's global transform times its inverse bind, the
// matrices the host computes for its own skinned mesh, acting on the mesh as the asset stores
// it (glTF POSITION). The sphere centers are stored in that space. The radii are lengths of the
// asset's scene (skin.json's matrices): matrices that also carry a scale of the host's own (the
// body's node scaled to the level, world matrices of a scaled object) scale the centers, not the
// radii, so a host placing the body at scale s multiplies each radius by s (or skins in the
// asset's scene and places the result, as samples/character does).
//
// File layout (little-endian), format 1.1 (1.0: the same without the skin section):
//   0  u8[8]  magic 89 'S' 'P' 'X' 0D 0A 1A 0A
//   8  u16    format major, u16 minor
//   12 u32    header size (64)
//   16 u64    file size in bytes, including the trailing checksum
//   24 u32    sphere count n, u32 pose count p, u32 site count s
//   36 u8     sizeof(float) = 4, u8 sizeof(index) = 4, u16 flags (bit 0: a skin section; no others)
//   40 u32    offsets of: spheres (p*n*4 f32: x y z r, pose-major), sphere sites (n u32),
//             sites (s*3 f32), names (per pose: u32 length + bytes, padded to 4); u32 names size
//   60 u32    offset of the skin section (0 without one), format 1.1:
//             u32 joint count J, u32 section size in bytes (all of it, these 8 included);
//             n records of x y z r, w0..w3 (f32) and j0..j3 (u32): the sphere's center in the
//             asset's space, its radius, its joints' weights (0 past the last) and indices;
//             J i32 parents (-1: none; no cycle); J names (u32 length + bytes, padded to 4)
//   ...       sections, each 4-byte aligned
//   end-4 u32 CRC-32 (IEEE 802.3) of every byte before it
#ifndef SPX_RUNTIME_H
#define SPX_RUNTIME_H

#define SPX_RUNTIME_VERSION_MAJOR 1
#define SPX_RUNTIME_VERSION_MINOR 0
#define SPX_FORMAT_VERSION_MAJOR 1
#define SPX_FORMAT_VERSION_MINOR 1

#ifndef SPX_MAX_POSES
#define SPX_MAX_POSES 256
#endif
#if !defined(SPX_MALLOC) || !defined(SPX_FREE)
#include <cstdlib>
#define SPX_MALLOC(size) std::malloc(size)
#define SPX_FREE(ptr) std::free(ptr)
#endif

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstring>

namespace spx {

enum Status {
  SPX_OK = 0,
  SPX_ERR_INVALID_ARGUMENT,  // a null pointer where data was required
  SPX_ERR_IO,                // the file could not be opened or read
  SPX_ERR_OUT_OF_MEMORY,
  SPX_ERR_TRUNCATED,         // fewer bytes than the header says
  SPX_ERR_BAD_MAGIC,         // not a .spx file
  SPX_ERR_NEWER_VERSION,     // written by a newer major format version
  SPX_ERR_BAD_VERSION,       // a version this reader never knew (legacy or corrupt)
  SPX_ERR_BAD_SIZES,         // header sizes, counts or offsets inconsistent; flags or reserved set
  SPX_ERR_CHECKSUM,          // CRC-32 mismatch: corrupt bytes
  SPX_ERR_BAD_DATA,          // non-finite value, negative radius or site index out of range
  SPX_ERR_WEIGHT_COUNT,      // weight vector length is not pose_count() (pose_count() - 1 for blend_morph)
  SPX_ERR_BAD_WEIGHTS,       // non-finite weights, no positive weight, or morph weights adding up past 2^24
  SPX_ERR_EMPTY,             // the proxy holds nothing (not loaded)
  SPX_ERR_BAD_SKIN,          // skin section damaged: joint index out of range, weights or centers not finite, counts
  SPX_ERR_NO_SKIN,           // skin() on a proxy without a skin
  SPX_ERR_JOINT_COUNT,       // joint matrix count is not joint_count()
  SPX_ERR_BAD_MATRICES       // joint matrices not finite
};

inline const char* status_string(Status s) {
  switch (s) {
    case SPX_OK: return "ok";
    case SPX_ERR_INVALID_ARGUMENT: return "invalid argument";
    case SPX_ERR_IO: return "cannot read file";
    case SPX_ERR_OUT_OF_MEMORY: return "out of memory";
    case SPX_ERR_TRUNCATED: return "file is truncated";
    case SPX_ERR_BAD_MAGIC: return "not an .spx file";
    case SPX_ERR_NEWER_VERSION: return "file was written by a newer format version";
    case SPX_ERR_BAD_VERSION: return "unknown format version";
    case SPX_ERR_BAD_SIZES: return "inconsistent sizes in header";
    case SPX_ERR_CHECKSUM: return "checksum mismatch (corrupt file)";
    case SPX_ERR_BAD_DATA: return "invalid values in file";
    case SPX_ERR_WEIGHT_COUNT: return "weight count does not match pose count";
    case SPX_ERR_BAD_WEIGHTS: return "weights are not finite, none is positive, or (morph) they add up past 2^24";
    case SPX_ERR_EMPTY: return "proxy is empty";
    case SPX_ERR_BAD_SKIN: return "skin section is damaged";
    case SPX_ERR_NO_SKIN: return "proxy has no skin";
    case SPX_ERR_JOINT_COUNT: return "joint matrix count does not match the skin's joint count";
    case SPX_ERR_BAD_MATRICES: return "joint matrices are not finite";
  }
  return "unknown status";
}

class Proxy;
Status load_memory(const void* data, size_t size, Proxy* out);

// A loaded proxy: S_0..S_e (pose 0 is the rest pose), the blend site of every sphere, and the
// sites' rest positions. Owns one block of memory; move-only.
class Proxy {
 public:
  Proxy() {}
  ~Proxy() { reset(); }
  Proxy(Proxy&& o) noexcept { take(o); }
  Proxy& operator=(Proxy&& o) noexcept {
    if (this != &o) {
      reset();
      take(o);
    }
    return *this;
  }
  Proxy(const Proxy&) = delete;
  Proxy& operator=(const Proxy&) = delete;

  uint32_t sphere_count() const { return spheres_n_; }
  uint32_t pose_count() const { return poses_n_; }
  uint32_t site_count() const { return sites_n_; }
  // x, y, z, r for each sphere of `pose` (nullptr when out of range).
  const float* pose_spheres(uint32_t pose) const {
    return pose < poses_n_ ? spheres_ + size_t(pose) * spheres_n_ * 4 : nullptr;
  }
  const uint32_t* sphere_sites() const { return sphere_sites_; }
  const float* site_positions() const { return sites_; }  // x, y, z per site
  const char* pose_name(uint32_t pose) const { return pose < poses_n_ ? names_[pose] : nullptr; }
  bool empty() const { return block_ == nullptr; }
  // The skin: 0 joints without one. Per sphere x y z r w0 w1 w2 w3 (skin_spheres) and j0..j3
  // (skin_joints); per joint its parent (-1: none; parents lead every joint to a root, the
  // loader checks it) and name.
  bool has_skin() const { return joints_n_ > 0; }
  uint32_t joint_count() const { return joints_n_; }
  const float* skin_spheres() const { return skin_; }
  const uint32_t* skin_joints() const { return skin_joints_; }
  int32_t joint_parent(uint32_t joint) const { return joint < joints_n_ ? parents_[joint] : -1; }
  const char* joint_name(uint32_t joint) const { return joint < joints_n_ ? names_[poses_n_ + joint] : nullptr; }

  void reset() {
    if (block_) SPX_FREE(block_);
    block_ = nullptr;
    spheres_ = sites_ = skin_ = nullptr;
    sphere_sites_ = skin_joints_ = nullptr;
    parents_ = nullptr;
    names_ = nullptr;
    spheres_n_ = poses_n_ = sites_n_ = joints_n_ = 0;
  }

 private:
  friend Status load_memory(const void* data, size_t size, Proxy* out);
  void take(Proxy& o) {
    block_ = o.block_;
    spheres_ = o.spheres_;
    sites_ = o.sites_;
    sphere_sites_ = o.sphere_sites_;
    names_ = o.names_;
    skin_ = o.skin_;
    skin_joints_ = o.skin_joints_;
    parents_ = o.parents_;
    spheres_n_ = o.spheres_n_;
    poses_n_ = o.poses_n_;
    sites_n_ = o.sites_n_;
    joints_n_ = o.joints_n_;
    o.block_ = nullptr;
    o.reset();
  }
  void* block_ = nullptr;
  float* spheres_ = nullptr;
  float* sites_ = nullptr;
  uint32_t* sphere_sites_ = nullptr;
  char** names_ = nullptr;  // the poses', then the joints'
  float* skin_ = nullptr;
  uint32_t* skin_joints_ = nullptr;
  int32_t* parents_ = nullptr;
  uint32_t spheres_n_ = 0, poses_n_ = 0, sites_n_ = 0, joints_n_ = 0;
};

namespace detail {

inline uint32_t crc32(const unsigned char* p, size_t n) {
  uint32_t table[256];
  for (uint32_t i = 0; i < 256; ++i) {
    uint32_t c = i;
    for (int k = 0; k < 8; ++k) c = (c & 1u) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
    table[i] = c;
  }
  uint32_t c = 0xFFFFFFFFu;
  for (size_t i = 0; i < n; ++i) c = table[(c ^ p[i]) & 0xFFu] ^ (c >> 8);
  return c ^ 0xFFFFFFFFu;
}
inline uint16_t rd16(const unsigned char* p) { return uint16_t(p[0] | (p[1] << 8)); }
inline uint32_t rd32(const unsigned char* p) {
  return uint32_t(p[0]) | (uint32_t(p[1]) << 8) | (uint32_t(p[2]) << 16) | (uint32_t(p[3]) << 24);
}
inline uint64_t rd64(const unsigned char* p) { return uint64_t(rd32(p)) | (uint64_t(rd32(p + 4)) << 32); }
inline float rdf32(const unsigned char* p) {
  const uint32_t u = rd32(p);
  float f;
  std::memcpy(&f, &u, 4);
  return f;
}
// By the bits (exponent all ones: Inf or NaN), which -ffast-math cannot assume away.
inline bool finite(float f) {
  uint32_t u;
  std::memcpy(&u, &f, 4);
  return (u & 0x7F800000u) != 0x7F800000u;
}

// Clamps negatives to 0 and divides by the sum; false when not finite or no positive weight.
inline bool normalize(const float* w, uint32_t n, float* out) {
  float sum = 0;
  for (uint32_t i = 0; i < n; ++i) {
    if (!finite(w[i])) return false;
    out[i] = w[i] > 0 ? w[i] : 0.0f;
    sum += out[i];
  }
  if (!(sum > 0) || !finite(sum)) return false;
  for (uint32_t i = 0; i < n; ++i) out[i] /= sum;
  return true;
}

// The skeleton's one rule, for this loader and the tools' readers alike: following parents
// (parent_of(j): -1 for a root, else another joint) from every joint reaches a root. Returns the
// first joint from which it does not (a parent out of range, or a cycle, a joint its own parent
// included), or -1. A host walks parents to the root, which a cycle never reaches. O(count):
// `marks` (count entries, scratch) holds which walk passed a joint first.
template <class ParentOf>
inline int64_t joint_off_the_tree(uint32_t count, const ParentOf& parent_of, uint32_t* marks) {
  const uint32_t unseen = 0xFFFFFFFFu;
  for (uint32_t j = 0; j < count; ++j) marks[j] = unseen;
  for (uint32_t j = 0; j < count; ++j)
    // Up from j to a root, or to a joint an earlier walk passed (which reaches one).
    for (int64_t u = j; marks[u] == unseen;) {
      marks[u] = j;
      const int64_t parent = parent_of(uint32_t(u));
      if (parent < -1 || parent >= int64_t(count) || (parent >= 0 && marks[parent] == j)) return j;
      if (parent == -1) break;
      u = parent;
    }
  return -1;
}

}  // namespace detail

static const unsigned char SPX_MAGIC[8] = {0x89, 'S', 'P', 'X', 0x0D, 0x0A, 0x1A, 0x0A};
enum { SPX_HEADER_SIZE = 64 };

namespace detail {

// Where a file's sections lie, once its header has been checked.
struct Layout {
  uint32_t header, n, p, s;
  uint32_t off_spheres, off_ss, off_sites, off_names, names_size;
  uint64_t sphere_bytes, ss_bytes, site_bytes, name_chars;
  uint32_t off_skin, skin_size, joints;  // all 0 without a skin
  uint64_t joint_name_chars;
};

enum { SPX_FLAG_SKIN = 1, SPX_SKIN_RECORD = 48 };

// The skin section's head: where it lies and its joint count, inside the body and big enough
// for its records and parents.
inline Status check_skin_head(const unsigned char* b, uint64_t body, Layout* l) {
  l->off_skin = rd32(b + 60);
  if (l->off_skin < l->header || l->off_skin % 4 != 0 || uint64_t(l->off_skin) + 8 > body) return SPX_ERR_BAD_SKIN;
  l->joints = rd32(b + l->off_skin);
  l->skin_size = rd32(b + l->off_skin + 4);
  const uint64_t least = 8 + uint64_t(l->n) * SPX_SKIN_RECORD + uint64_t(l->joints) * 8;
  if (l->joints == 0 || l->skin_size % 4 != 0 || l->skin_size < least || uint64_t(l->off_skin) + l->skin_size > body)
    return SPX_ERR_BAD_SKIN;
  return SPX_OK;
}

// Magic, version, sizes, checksum and the header's fields; the sections' ranges inside the
// body, apart and tiling it exactly (each padded to 4 bytes): a count that shrank would
// otherwise leave bytes nobody reads, and a file that silently loses spheres.
inline Status check_header(const unsigned char* b, size_t size, Layout* l) {
  if (size < 8) return size == 0 || std::memcmp(b, SPX_MAGIC, size) == 0 ? SPX_ERR_TRUNCATED : SPX_ERR_BAD_MAGIC;
  if (std::memcmp(b, SPX_MAGIC, 8) != 0) return SPX_ERR_BAD_MAGIC;
  if (size < 12) return SPX_ERR_TRUNCATED;
  const uint16_t major = rd16(b + 8);
  if (major > SPX_FORMAT_VERSION_MAJOR) return SPX_ERR_NEWER_VERSION;
  if (major < 1) return SPX_ERR_BAD_VERSION;
  if (size < SPX_HEADER_SIZE + 4) return SPX_ERR_TRUNCATED;
  const uint64_t file_size = rd64(b + 16);
  if (file_size > size) return SPX_ERR_TRUNCATED;
  if (file_size < size) return SPX_ERR_BAD_SIZES;
  if (rd32(b + size - 4) != crc32(b, size - 4)) return SPX_ERR_CHECKSUM;

  l->header = rd32(b + 12);
  l->n = rd32(b + 24), l->p = rd32(b + 28), l->s = rd32(b + 32);
  l->off_spheres = rd32(b + 40), l->off_ss = rd32(b + 44), l->off_sites = rd32(b + 48);
  l->off_names = rd32(b + 52), l->names_size = rd32(b + 56);
  // Flags and the reserved word have no meaning in format 1: a set bit is a file this reader
  // cannot honour, not one to half-read.
  const uint16_t flags = rd16(b + 38);
  if (l->header < SPX_HEADER_SIZE || b[36] != 4 || b[37] != 4 || (flags & ~uint16_t(SPX_FLAG_SKIN)) != 0 ||
      (flags == 0 && rd32(b + 60) != 0) || (flags != 0 && rd16(b + 10) < 1))
    return SPX_ERR_BAD_SIZES;
  if (l->n == 0 || l->p == 0 || l->s == 0 || l->p > SPX_MAX_POSES || l->s > l->n) return SPX_ERR_BAD_SIZES;
  const uint64_t body = size - 4;
  l->off_skin = l->skin_size = l->joints = 0;
  if (flags & SPX_FLAG_SKIN) {
    const Status skin = check_skin_head(b, body, l);
    if (skin != SPX_OK) return skin;
  }
  l->sphere_bytes = uint64_t(l->p) * l->n * 16, l->ss_bytes = uint64_t(l->n) * 4, l->site_bytes = uint64_t(l->s) * 12;
  struct Range { uint64_t at, len; } ranges[5] = {
      {l->off_spheres, l->sphere_bytes}, {l->off_ss, l->ss_bytes}, {l->off_sites, l->site_bytes},
      {l->off_names, l->names_size}, {l->off_skin, l->skin_size}};
  for (int i = 0; i < 5; ++i) {
    if (ranges[i].len == 0 && i == 4) continue;
    if (ranges[i].at < l->header || ranges[i].at % 4 != 0 || ranges[i].at + ranges[i].len > body) return SPX_ERR_BAD_SIZES;
    for (int j = 0; j < i; ++j)
      if (ranges[i].at < ranges[j].at + ranges[j].len && ranges[j].at < ranges[i].at + ranges[i].len)
        return SPX_ERR_BAD_SIZES;
  }
  const uint64_t padded = ((l->sphere_bytes + 3) & ~uint64_t(3)) + ((l->ss_bytes + 3) & ~uint64_t(3)) +
                          ((l->site_bytes + 3) & ~uint64_t(3)) + ((uint64_t(l->names_size) + 3) & ~uint64_t(3)) +
                          l->skin_size;
  if (l->header + padded != body) return SPX_ERR_BAD_SIZES;
  return SPX_OK;
}

// `count` length-prefixed strings (each padded to 4 bytes) from `at` that end exactly at `end`;
// `chars` gets their characters with a terminator each.
inline bool check_name_list(const unsigned char* b, uint64_t at, uint64_t end, uint32_t count, uint64_t* chars) {
  *chars = 0;
  for (uint32_t i = 0; i < count; ++i) {
    if (at + 4 > end) return false;
    const uint32_t len = rd32(b + at);
    if (at + 4 + len > end) return false;
    *chars += len + 1;
    at += 4 + ((uint64_t(len) + 3) & ~uint64_t(3));
  }
  return at == end;
}

// The checked list copied: names[i] points at its terminated copy in `chars`. Returns the
// position after the list.
inline uint64_t copy_name_list(const unsigned char* b, uint64_t at, uint32_t count, char** names, char* chars) {
  for (uint32_t i = 0; i < count; ++i) {
    const uint32_t len = rd32(b + at);
    names[i] = chars;
    std::memcpy(chars, b + at + 4, len);
    chars[len] = '\0';
    chars += len + 1;
    at += 4 + ((uint64_t(len) + 3) & ~uint64_t(3));
  }
  return at;
}

// Names: p strings that fill the names section.
inline Status check_names(const unsigned char* b, Layout* l) {
  return check_name_list(b, l->off_names, uint64_t(l->off_names) + l->names_size, l->p, &l->name_chars) ? SPX_OK
                                                                                                         : SPX_ERR_BAD_SIZES;
}

// The skin's joint names: J strings that fill the rest of its section.
inline Status check_skin_names(const unsigned char* b, Layout* l) {
  l->joint_name_chars = 0;
  if (l->joints == 0) return SPX_OK;
  const uint64_t at = uint64_t(l->off_skin) + 8 + uint64_t(l->n) * SPX_SKIN_RECORD + uint64_t(l->joints) * 4;
  return check_name_list(b, at, uint64_t(l->off_skin) + l->skin_size, l->joints, &l->joint_name_chars)
             ? SPX_OK
             : SPX_ERR_BAD_SKIN;
}

// The skin's records, parents and names into `skin` (x y z r w0..w3 per sphere), `joints`,
// `parents`, `names` and `chars`; SPX_ERR_BAD_SKIN for a value out of range or not finite,
// weights with no positive entry, or parents that do not lead every joint to a root.
inline Status copy_skin(const unsigned char* b, const Layout& l, float* skin, uint32_t* joints, int32_t* parents,
                        char** names, char* chars) {
  Status status = SPX_OK;
  const unsigned char* r = b + l.off_skin + 8;
  for (uint64_t i = 0; i < l.n; ++i, r += SPX_SKIN_RECORD) {
    float weight_sum = 0;
    for (int k = 0; k < 8; ++k) {
      const float v = rdf32(r + 4 * k);
      skin[i * 8 + k] = v;
      if (!finite(v) || (k >= 3 && v < 0)) status = SPX_ERR_BAD_SKIN;
      if (k >= 4 && finite(v)) weight_sum += v;
    }
    if (!(weight_sum > 0)) status = SPX_ERR_BAD_SKIN;
    for (int k = 0; k < 4; ++k) {
      joints[i * 4 + k] = rd32(r + 32 + 4 * k);
      if (joints[i * 4 + k] >= l.joints) status = SPX_ERR_BAD_SKIN;
    }
  }
  // Checked with the parents' own slots as the walks' marks, then filled.
  const unsigned char* at = r;
  const auto parent_of = [at](uint32_t j) { return int64_t(int32_t(rd32(at + 4 * uint64_t(j)))); };
  if (joint_off_the_tree(l.joints, parent_of, reinterpret_cast<uint32_t*>(parents)) >= 0) status = SPX_ERR_BAD_SKIN;
  for (uint32_t j = 0; j < l.joints; ++j, r += 4) parents[j] = int32_t(rd32(r));
  copy_name_list(b, uint64_t(r - b), l.joints, names, chars);
  return status;
}

// The sections copied into one block laid out as `spheres, names, sites, ss, chars` say;
// SPX_ERR_BAD_DATA for a non-finite number, a negative radius or a site out of range.
inline Status copy_sections(const unsigned char* b, const Layout& l, float* spheres, char** names, float* sites,
                            uint32_t* ss, char* chars) {
  Status status = SPX_OK;
  for (uint64_t i = 0; i < uint64_t(l.p) * l.n; ++i) {
    for (int k = 0; k < 4; ++k) spheres[i * 4 + k] = rdf32(b + l.off_spheres + i * 16 + k * 4);
    if (!finite(spheres[i * 4]) || !finite(spheres[i * 4 + 1]) || !finite(spheres[i * 4 + 2]) ||
        !finite(spheres[i * 4 + 3]) || spheres[i * 4 + 3] < 0)
      status = SPX_ERR_BAD_DATA;
  }
  for (uint64_t i = 0; i < uint64_t(l.s) * 3; ++i) {
    sites[i] = rdf32(b + l.off_sites + i * 4);
    if (!finite(sites[i])) status = SPX_ERR_BAD_DATA;
  }
  for (uint32_t i = 0; i < l.n; ++i) {
    ss[i] = rd32(b + l.off_ss + uint64_t(i) * 4);
    if (ss[i] >= l.s) status = SPX_ERR_BAD_DATA;
  }
  copy_name_list(b, l.off_names, l.p, names, chars);
  return status;
}

}  // namespace detail

inline Status load_memory(const void* data, size_t size, Proxy* out) {
  using namespace detail;
  if (!out || (!data && size > 0)) return SPX_ERR_INVALID_ARGUMENT;
  const unsigned char* b = static_cast<const unsigned char*>(data);
  Layout l;
  Status status = check_header(b, size, &l);
  if (status == SPX_OK) status = check_names(b, &l);
  if (status == SPX_OK) status = check_skin_names(b, &l);
  if (status != SPX_OK) return status;

  // One block: the spheres first (16-byte aligned, and a multiple of 16 bytes long), the skin's
  // records (32 bytes each), then the name pointers (the poses', the joints'), sites, sphere
  // sites, skin joints, parents (all 4-byte types) and the name characters.
  const uint64_t skin_bytes = l.joints ? uint64_t(l.n) * 32 : 0, skin_joint_bytes = l.joints ? uint64_t(l.n) * 16 : 0;
  const uint64_t pointer_bytes = (uint64_t(l.p) + l.joints) * sizeof(char*), parent_bytes = uint64_t(l.joints) * 4;
  const uint64_t total = l.sphere_bytes + skin_bytes + pointer_bytes + l.site_bytes + l.ss_bytes + skin_joint_bytes +
                         parent_bytes + l.name_chars + l.joint_name_chars;
  if (total > SIZE_MAX) return SPX_ERR_OUT_OF_MEMORY;
  unsigned char* block = static_cast<unsigned char*>(SPX_MALLOC(size_t(total)));
  if (!block) return SPX_ERR_OUT_OF_MEMORY;
  unsigned char* at = block;
  auto take = [&at](uint64_t bytes) {
    unsigned char* here = at;
    at += bytes;
    return here;
  };
  float* spheres = reinterpret_cast<float*>(take(l.sphere_bytes));
  float* skin = reinterpret_cast<float*>(take(skin_bytes));
  char** names = reinterpret_cast<char**>(take(pointer_bytes));
  float* sites = reinterpret_cast<float*>(take(l.site_bytes));
  uint32_t* ss = reinterpret_cast<uint32_t*>(take(l.ss_bytes));
  uint32_t* skin_joints = reinterpret_cast<uint32_t*>(take(skin_joint_bytes));
  int32_t* parents = reinterpret_cast<int32_t*>(take(parent_bytes));
  char* chars = reinterpret_cast<char*>(take(l.name_chars));
  char* joint_chars = reinterpret_cast<char*>(at);
  status = copy_sections(b, l, spheres, names, sites, ss, chars);
  if (status == SPX_OK && l.joints) status = copy_skin(b, l, skin, skin_joints, parents, names + l.p, joint_chars);
  if (status != SPX_OK) {
    SPX_FREE(block);
    return status;
  }
  out->reset();
  out->block_ = block;
  out->spheres_ = spheres;
  out->sites_ = sites;
  out->sphere_sites_ = ss;
  out->names_ = names;
  if (l.joints) {
    out->skin_ = skin;
    out->skin_joints_ = skin_joints;
    out->parents_ = parents;
  }
  out->spheres_n_ = l.n;
  out->poses_n_ = l.p;
  out->sites_n_ = l.s;
  out->joints_n_ = l.joints;
  return SPX_OK;
}

inline Status load_file(const char* path, Proxy* out) {
  if (!path || !out) return SPX_ERR_INVALID_ARGUMENT;
  std::FILE* f = std::fopen(path, "rb");
  if (!f) return SPX_ERR_IO;
  Status status = SPX_ERR_IO;
  long size = -1;
  if (std::fseek(f, 0, SEEK_END) == 0) size = std::ftell(f);
  if (size >= 0 && std::fseek(f, 0, SEEK_SET) == 0) {
    void* bytes = SPX_MALLOC(size_t(size) + 1);
    if (!bytes) {
      status = SPX_ERR_OUT_OF_MEMORY;
    } else {
      if (std::fread(bytes, 1, size_t(size), f) == size_t(size)) status = load_memory(bytes, size_t(size), out);
      SPX_FREE(bytes);
    }
  }
  std::fclose(f);
  return status;
}

namespace detail {

// The blend at full weights `w` (pose_count() of them, the rest's first) into centers + radii;
// radii below 0 become 0.
inline void blend_split(const Proxy& proxy, const float* w, float* centers, float* radii) {
  const uint32_t p = proxy.pose_count(), n = proxy.sphere_count();
  for (uint32_t j = 0; j < n; ++j) {
    const float* s = proxy.pose_spheres(0) + size_t(j) * 4;
    centers[3 * j] = w[0] * s[0];
    centers[3 * j + 1] = w[0] * s[1];
    centers[3 * j + 2] = w[0] * s[2];
    radii[j] = w[0] * s[3];
  }
  for (uint32_t i = 1; i < p; ++i) {
    const float wi = w[i];
    if (wi == 0) continue;
    const float* s = proxy.pose_spheres(i);
    for (uint32_t j = 0; j < n; ++j) {
      centers[3 * j] += wi * s[4 * j];
      centers[3 * j + 1] += wi * s[4 * j + 1];
      centers[3 * j + 2] += wi * s[4 * j + 2];
      radii[j] += wi * s[4 * j + 3];
    }
  }
  for (uint32_t j = 0; j < n; ++j) radii[j] = radii[j] > 0 ? radii[j] : 0.0f;
}

// Morph weights (one per example after the rest) as full weights: the rest's is 1 less their
// sum, so the weights sum to 1 and one target at 1 alone gives its example exactly. False when
// one is not finite, or their magnitudes add up to 2^24 or more (there a float's 1 - sum has
// lost the rest).
inline bool morph_to_full(const float* morph, uint32_t p, float* w) {
  double sum = 0, magnitude = 0;
  for (uint32_t i = 1; i < p; ++i) {
    if (!finite(morph[i - 1])) return false;
    w[i] = morph[i - 1];
    sum += w[i];
    magnitude += w[i] < 0 ? -w[i] : w[i];
  }
  if (!(magnitude < 16777216.0)) return false;
  w[0] = float(1.0 - sum);
  return true;
}

// The global blends' weights (pose_count() of them) checked and normalised into `w`.
inline Status global_weights(const Proxy& proxy, const float* weights, uint32_t weight_count, float* w) {
  if (!weights) return SPX_ERR_INVALID_ARGUMENT;
  if (weight_count != proxy.pose_count()) return SPX_ERR_WEIGHT_COUNT;
  return normalize(weights, weight_count, w) ? SPX_OK : SPX_ERR_BAD_WEIGHTS;
}

// The morph blends' weights (pose_count() - 1 of them; null when there are none) checked and
// made full weights in `w`.
inline Status morph_weights(const Proxy& proxy, const float* weights, uint32_t weight_count, float* w) {
  const uint32_t p = proxy.pose_count();
  if (!weights && p > 1) return SPX_ERR_INVALID_ARGUMENT;
  if (weight_count != p - 1) return SPX_ERR_WEIGHT_COUNT;
  return morph_to_full(weights, p, w) ? SPX_OK : SPX_ERR_BAD_WEIGHTS;
}

// A global or morph blend into centers + radii: the proxy and the outputs checked, then the
// caller's weights made full by `full` (global_weights or morph_weights), then the blend.
template <class FullWeights>
inline Status blend_split_with(const Proxy& proxy, const float* weights, uint32_t weight_count, float* centers,
                               float* radii, FullWeights full) {
  if (proxy.empty()) return SPX_ERR_EMPTY;
  if (!centers || !radii) return SPX_ERR_INVALID_ARGUMENT;
  float w[SPX_MAX_POSES];
  const Status status = full(proxy, weights, weight_count, w);
  if (status == SPX_OK) blend_split(proxy, w, centers, radii);
  return status;
}

}  // namespace detail

// One weight per example (pose_count() of them). Writes 3 floats per sphere to `centers`
// and one to `radii`.
inline Status blend_global(const Proxy& proxy, const float* weights, uint32_t weight_count, float* centers,
                           float* radii) {
  return detail::blend_split_with(proxy, weights, weight_count, centers, radii, detail::global_weights);
}

// A morph-target (blend-shape) body's blend: one weight per example after the rest
// (pose_count() - 1 of them; `weights` may be null when there are none), each the weight the
// host gives that example's morph target. Each sphere is the rest's plus the weighted
// differences of the examples' from it, as glTF and every engine add morph targets to a mesh:
// two targets at 1 add both deformations. Any finite weight is taken, negative or past 1, as
// the mesh takes it; radii below 0 become 0. With weights of sum at most 1 and none negative it
// is blend_global at (1 - their sum, weights...). SPX_ERR_BAD_WEIGHTS for a weight not finite,
// or magnitudes adding up to 2^24 or more.
inline Status blend_morph(const Proxy& proxy, const float* weights, uint32_t weight_count, float* centers,
                          float* radii) {
  return detail::blend_split_with(proxy, weights, weight_count, centers, radii, detail::morph_weights);
}

// The paper's local blend: `site_weights` holds pose_count() weights for each blend site
// (site-major, weight_count = site_count() * pose_count()); each sphere uses its site's.
inline Status blend_local(const Proxy& proxy, const float* site_weights, size_t weight_count, float* centers,
                          float* radii) {
  if (proxy.empty()) return SPX_ERR_EMPTY;
  if (!site_weights || !centers || !radii) return SPX_ERR_INVALID_ARGUMENT;
  const uint32_t p = proxy.pose_count(), n = proxy.sphere_count(), s = proxy.site_count();
  if (weight_count != size_t(s) * p) return SPX_ERR_WEIGHT_COUNT;
  float w[SPX_MAX_POSES];
  for (uint32_t site = 0; site < s; ++site)
    if (!detail::normalize(site_weights + size_t(site) * p, p, w)) return SPX_ERR_BAD_WEIGHTS;
  const uint32_t* sites = proxy.sphere_sites();
  uint32_t current = UINT32_MAX;
  for (uint32_t j = 0; j < n; ++j) {
    if (sites[j] != current) {
      current = sites[j];
      detail::normalize(site_weights + size_t(current) * p, p, w);
    }
    float x = 0, y = 0, z = 0, r = 0;
    for (uint32_t i = 0; i < p; ++i) {
      if (w[i] == 0 && i > 0) continue;
      const float* sp = proxy.pose_spheres(i) + size_t(j) * 4;
      x += w[i] * sp[0];
      y += w[i] * sp[1];
      z += w[i] * sp[2];
      r += w[i] * sp[3];
    }
    centers[3 * j] = x;
    centers[3 * j + 1] = y;
    centers[3 * j + 2] = z;
    radii[j] = r > 0 ? r : 0.0f;
  }
  return SPX_OK;
}

#if defined(__GNUC__) || defined(_MSC_VER)
#define SPX_RESTRICT __restrict
#else
#define SPX_RESTRICT
#endif

namespace detail {

// The blend at full weights `w` (pose_count(), the rest's first) into xyzr; radii below 0 become 0.
inline void blend_xyzr(const Proxy& proxy, const float* w, float* xyzr) {
  const uint32_t p = proxy.pose_count();
  const size_t m = size_t(proxy.sphere_count()) * 4;
  float* SPX_RESTRICT out = xyzr;
  {
    const float* SPX_RESTRICT s = proxy.pose_spheres(0);
    const float w0 = w[0];
    for (size_t k = 0; k < m; ++k) out[k] = w0 * s[k];
  }
  for (uint32_t i = 1; i < p; ++i) {
    const float wi = w[i];
    if (wi == 0) continue;
    const float* SPX_RESTRICT s = proxy.pose_spheres(i);
    for (size_t k = 0; k < m; ++k) out[k] += wi * s[k];
  }
  for (size_t k = 3; k < m; k += 4) out[k] = out[k] > 0 ? out[k] : 0.0f;
}

// A global or morph blend into xyzr, checked as blend_split_with checks.
template <class FullWeights>
inline Status blend_xyzr_with(const Proxy& proxy, const float* weights, uint32_t weight_count, float* xyzr,
                              FullWeights full) {
  if (proxy.empty()) return SPX_ERR_EMPTY;
  if (!xyzr) return SPX_ERR_INVALID_ARGUMENT;
  float w[SPX_MAX_POSES];
  const Status status = full(proxy, weights, weight_count, w);
  if (status == SPX_OK) blend_xyzr(proxy, w, xyzr);
  return status;
}

}  // namespace detail

// The global blend into xyzr (4 floats per sphere: x, y, z, r). Same weights policy and result
// as blend_global; `xyzr` must not overlap the proxy.
inline Status blend_global_xyzr(const Proxy& proxy, const float* weights, uint32_t weight_count, float* xyzr) {
  return detail::blend_xyzr_with(proxy, weights, weight_count, xyzr, detail::global_weights);
}

// The morph-target blend into xyzr: same weights and result as blend_morph; `xyzr` must not
// overlap the proxy.
inline Status blend_morph_xyzr(const Proxy& proxy, const float* weights, uint32_t weight_count, float* xyzr) {
  return detail::blend_xyzr_with(proxy, weights, weight_count, xyzr, detail::morph_weights);
}

// Checks and normalises local-blend weights once (site-major, site_count() * pose_count() of
// them, the weights policy applied per site) into `normalized`, for blend_local_normalized.
// On failure `normalized` may be partly written and must not be used.
inline Status normalize_site_weights(const Proxy& proxy, const float* site_weights, size_t weight_count,
                                     float* normalized) {
  if (proxy.empty()) return SPX_ERR_EMPTY;
  if (!site_weights || !normalized) return SPX_ERR_INVALID_ARGUMENT;
  const uint32_t p = proxy.pose_count(), s = proxy.site_count();
  if (weight_count != size_t(s) * p) return SPX_ERR_WEIGHT_COUNT;
  for (uint32_t site = 0; site < s; ++site)
    if (!detail::normalize(site_weights + size_t(site) * p, p, normalized + size_t(site) * p))
      return SPX_ERR_BAD_WEIGHTS;
  return SPX_OK;
}

// The local blend into xyzr from weights normalize_site_weights() produced (not checked again:
// that is what makes it fast). Radii are clamped to 0 as always.
inline Status blend_local_normalized(const Proxy& proxy, const float* normalized, size_t weight_count, float* xyzr) {
  if (proxy.empty()) return SPX_ERR_EMPTY;
  if (!normalized || !xyzr) return SPX_ERR_INVALID_ARGUMENT;
  const uint32_t p = proxy.pose_count(), n = proxy.sphere_count();
  if (weight_count != size_t(proxy.site_count()) * p) return SPX_ERR_WEIGHT_COUNT;
  const uint32_t* sites = proxy.sphere_sites();
  const float* SPX_RESTRICT spheres = proxy.pose_spheres(0);
  const size_t stride = size_t(n) * 4;  // from one pose's sphere j to the next pose's
  float* SPX_RESTRICT out = xyzr;
  for (uint32_t j = 0; j < n; ++j) {
    const float* SPX_RESTRICT w = normalized + size_t(sites[j]) * p;
    const float* SPX_RESTRICT sp = spheres + size_t(j) * 4;
    float v[4] = {w[0] * sp[0], w[0] * sp[1], w[0] * sp[2], w[0] * sp[3]};
    for (uint32_t i = 1; i < p; ++i) {
      const float* SPX_RESTRICT q = sp + i * stride;
      for (int k = 0; k < 4; ++k) v[k] += w[i] * q[k];
    }
    out[4 * size_t(j)] = v[0];
    out[4 * size_t(j) + 1] = v[1];
    out[4 * size_t(j) + 2] = v[2];
    out[4 * size_t(j) + 3] = v[3] > 0 ? v[3] : 0.0f;
  }
  return SPX_OK;
}

// A rigged body's spheres in the frame the joint matrices describe: joint_count column-major
// 4x4 matrices (16 floats each, the skin's joint order), x y z r per sphere out. The matrices
// are checked (finite) every call; the output is left untouched on failure.
inline Status skin(const Proxy& proxy, const float* joint_matrices, int joint_count, float* xyzr) {
  if (proxy.empty()) return SPX_ERR_EMPTY;
  if (!proxy.has_skin()) return SPX_ERR_NO_SKIN;
  if (!joint_matrices || !xyzr) return SPX_ERR_INVALID_ARGUMENT;
  if (joint_count < 0 || uint32_t(joint_count) != proxy.joint_count()) return SPX_ERR_JOINT_COUNT;
  for (size_t k = 0; k < size_t(joint_count) * 16; ++k)
    if (!detail::finite(joint_matrices[k])) return SPX_ERR_BAD_MATRICES;
  const uint32_t n = proxy.sphere_count();
  const float* SPX_RESTRICT s = proxy.skin_spheres();
  const uint32_t* SPX_RESTRICT j = proxy.skin_joints();
  float* SPX_RESTRICT out = xyzr;
  for (uint32_t i = 0; i < n; ++i, s += 8, j += 4, out += 4) {
    float x = 0, y = 0, z = 0;
    for (int k = 0; k < 4; ++k) {
      const float w = s[4 + k];
      const float* SPX_RESTRICT m = joint_matrices + size_t(j[k]) * 16;
      x += w * (m[0] * s[0] + m[4] * s[1] + m[8] * s[2] + m[12]);
      y += w * (m[1] * s[0] + m[5] * s[1] + m[9] * s[2] + m[13]);
      z += w * (m[2] * s[0] + m[6] * s[1] + m[10] * s[2] + m[14]);
    }
    out[0] = x;
    out[1] = y;
    out[2] = z;
    out[3] = s[3];
  }
  return SPX_OK;
}

}  // namespace spx

#endif  // SPX_RUNTIME_H
