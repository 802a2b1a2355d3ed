#include <gtest/gtest.h>

#include <cstring>
#include <functional>
#include <limits>
#include <random>

#include <Eigen/Geometry>

#include "io/spx_writer.hpp"
#include "io/proxy_file.hpp"
#include "spx_runtime.h"

namespace spx {
namespace {

ProxyModel small_proxy(size_t spheres = 7, size_t poses = 4, size_t sites = 3) {
  ProxyModel p;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  for (size_t i = 0; i < poses; ++i) {
    ProxyPose pose;
    pose.name = i == 0 ? "rest" : "pose-" + std::to_string(i);
    for (size_t s = 0; s < spheres; ++s) pose.spheres.push_back({Eigen::Vector3d(u(rng), u(rng), u(rng)), 0.5 + 0.4 * u(rng)});
    p.poses.push_back(pose);
  }
  for (size_t s = 0; s < sites; ++s) p.sites.emplace_back(u(rng), u(rng), u(rng));
  for (size_t s = 0; s < spheres; ++s) p.sphere_sites.push_back(int(s % sites));
  return p;
}

// small_proxy() with a skin of `joints` joints: up to 4 random joints a sphere, float weights
// summing to 1 (some slots 0), centers and radii at random.
ProxyModel skinned_proxy(size_t spheres = 7, size_t poses = 4, size_t sites = 3, int joints = 5) {
  ProxyModel p = small_proxy(spheres, poses, sites);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int j = 0; j < joints; ++j) {
    p.skin.joints.push_back("joint-" + std::to_string(j));
    p.skin.parents.push_back(j - 1);
  }
  for (size_t s = 0; s < spheres; ++s) {
    SkinnedSphere k;
    const int used = 1 + int(s % 4);
    float left = 1;
    for (int i = 0; i < used; ++i) {
      k.joint[size_t(i)] = int(rng() % unsigned(joints));
      k.weight[size_t(i)] = i + 1 == used ? left : float(0.5 * left * (1 + u(rng)) / 2);
      left -= k.weight[size_t(i)];
    }
    k.center = Eigen::Vector3d(u(rng), u(rng), u(rng));
    k.radius = 0.3 + 0.2 * u(rng);
    p.skin.spheres.push_back(k);
  }
  return p;
}

// sum_k w_k M_k c in double: what skin() computes in float.
Eigen::Vector3d skin_in_double(const SkinnedSphere& s, const std::vector<float>& m) {
  Eigen::Vector3d out = Eigen::Vector3d::Zero();
  for (size_t k = 0; k < 4; ++k) {
    Eigen::Matrix4d mk;
    for (int e = 0; e < 16; ++e) mk(e % 4, e / 4) = m[size_t(s.joint[k]) * 16 + size_t(e)];
    out += double(s.weight[k]) * (mk * s.center.cast<float>().cast<double>().homogeneous()).head<3>();
  }
  return out;
}

std::vector<float> random_joint_matrices(int joints, std::mt19937& rng) {
  std::uniform_real_distribution<float> u(-1, 1);
  std::vector<float> m;
  for (int j = 0; j < joints; ++j) {
    const Eigen::Matrix3f r = Eigen::AngleAxisf(3 * u(rng), Eigen::Vector3f(u(rng), u(rng), u(rng)).normalized()).matrix();
    for (int c = 0; c < 4; ++c)
      for (int row = 0; row < 4; ++row) m.push_back(c < 3 ? (row < 3 ? r(row, c) : 0.0f) : (row < 3 ? 5 * u(rng) : 1.0f));
  }
  return m;
}

Status load(const std::string& bytes, Proxy* out) { return load_memory(bytes.data(), bytes.size(), out); }

// The checksum recomputed after a mutation, so that the structural checks behind it run.
std::string with_fixed_crc(std::string b) {
  if (b.size() < 4) return b;
  const uint32_t crc = detail::crc32(reinterpret_cast<const unsigned char*>(b.data()), b.size() - 4);
  for (int k = 0; k < 4; ++k) b[b.size() - 4 + size_t(k)] = char((crc >> (8 * k)) & 0xFF);
  return b;
}

TEST(Runtime, LoadsWhatTheWriterWrote) {
  const ProxyModel model = small_proxy();
  const std::string bytes = encode_spx(model);
  Proxy proxy;
  ASSERT_EQ(load(bytes, &proxy), SPX_OK);
  EXPECT_EQ(proxy.sphere_count(), 7u);
  EXPECT_EQ(proxy.pose_count(), 4u);
  EXPECT_EQ(proxy.site_count(), 3u);
  EXPECT_STREQ(proxy.pose_name(0), "rest");
  EXPECT_STREQ(proxy.pose_name(3), "pose-3");
  for (uint32_t i = 0; i < 4; ++i)
    for (uint32_t s = 0; s < 7; ++s) {
      EXPECT_EQ(proxy.pose_spheres(i)[4 * s], float(model.poses[i].spheres[s].center.x()));
      EXPECT_EQ(proxy.pose_spheres(i)[4 * s + 3], float(model.poses[i].spheres[s].radius));
    }
  EXPECT_EQ(encode_spx(model), bytes) << "deterministic bytes";
}

TEST(Runtime, SkinnedSpheresFollowTheJointMatrices) {
  const ProxyModel model = skinned_proxy(40, 3, 5, 6);
  const std::string bytes = encode_spx(model);
  EXPECT_EQ(bytes[10], 1) << "a skin makes a format 1.1 file";
  EXPECT_EQ(encode_spx(small_proxy())[10], 0) << "without one the file is format 1.0";
  Proxy proxy;
  ASSERT_EQ(load(bytes, &proxy), SPX_OK);
  ASSERT_TRUE(proxy.has_skin());
  EXPECT_EQ(proxy.joint_count(), 6u);
  EXPECT_STREQ(proxy.joint_name(5), "joint-5");
  EXPECT_EQ(proxy.joint_parent(0), -1);
  EXPECT_EQ(proxy.joint_parent(4), 3);
  EXPECT_EQ(proxy.joint_name(6), nullptr);
  std::mt19937 rng(3);
  for (int frame = 0; frame < 5; ++frame) {
    const std::vector<float> m = random_joint_matrices(6, rng);
    std::vector<float> xyzr(40 * 4);
    ASSERT_EQ(skin(proxy, m.data(), 6, xyzr.data()), SPX_OK);
    for (size_t s = 0; s < 40; ++s) {
      const Eigen::Vector3d want = skin_in_double(model.skin.spheres[s], m);
      for (int k = 0; k < 3; ++k) EXPECT_NEAR(xyzr[4 * s + size_t(k)], want[k], 1e-5 * (1 + std::abs(want[k])));
      EXPECT_EQ(xyzr[4 * s + 3], float(model.skin.spheres[s].radius));
    }
  }
}

TEST(Runtime, SkinChecksItsArguments) {
  Proxy plain, skinned;
  ASSERT_EQ(load(encode_spx(small_proxy()), &plain), SPX_OK);
  ASSERT_EQ(load(encode_spx(skinned_proxy()), &skinned), SPX_OK);
  std::mt19937 rng(3);
  std::vector<float> m = random_joint_matrices(5, rng), xyzr(7 * 4, -7.0f);
  EXPECT_FALSE(plain.has_skin());
  EXPECT_EQ(plain.joint_count(), 0u);
  EXPECT_EQ(skin(plain, m.data(), 5, xyzr.data()), SPX_ERR_NO_SKIN);
  EXPECT_EQ(skin(skinned, m.data(), 4, xyzr.data()), SPX_ERR_JOINT_COUNT);
  EXPECT_EQ(skin(skinned, m.data(), -1, xyzr.data()), SPX_ERR_JOINT_COUNT);
  EXPECT_EQ(skin(skinned, nullptr, 5, xyzr.data()), SPX_ERR_INVALID_ARGUMENT);
  EXPECT_EQ(skin(Proxy(), m.data(), 5, xyzr.data()), SPX_ERR_EMPTY);
  for (float bad : {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity()}) {
    std::vector<float> broken = m;
    broken[37] = bad;
    EXPECT_EQ(skin(skinned, broken.data(), 5, xyzr.data()), SPX_ERR_BAD_MATRICES);
  }
  for (float v : xyzr) EXPECT_EQ(v, -7.0f) << "a refused call leaves the output alone";
}

// The skin section's own damage, each with a valid checksum: a joint index past the joints,
// a weight or center that is not finite, weights with no positive entry, a parent out of
// range or parents in a cycle (a host walking them to the root would never stop), a joint
// count or section size that reaches past the file.
TEST(Runtime, DamagedSkinSectionsHaveTheirOwnStatus) {
  const std::string bytes = encode_spx(skinned_proxy());
  const uint32_t at = detail::rd32(reinterpret_cast<const unsigned char*>(bytes.data()) + 60);
  auto put32 = [](std::string& b, size_t i, uint32_t v) {
    for (int k = 0; k < 4; ++k) b[i + size_t(k)] = char((v >> (8 * k)) & 0xFF);
  };
  auto putf = [&](std::string& b, size_t i, float f) {
    uint32_t u;
    std::memcpy(&u, &f, 4);
    put32(b, i, u);
  };
  const size_t record = at + 8 + 2 * 48;  // the third sphere's
  std::vector<std::pair<std::string, std::function<void(std::string&)>>> damage = {
      {"joint index 5 of 5 joints", [&](std::string& b) { put32(b, record + 32, 5); }},
      {"joint index far out", [&](std::string& b) { put32(b, record + 44, 0xFFFFFFF0u); }},
      {"weight NaN", [&](std::string& b) { putf(b, record + 16, std::numeric_limits<float>::quiet_NaN()); }},
      {"weight negative", [&](std::string& b) { putf(b, record + 20, -0.5f); }},
      {"weights all 0", [&](std::string& b) { for (int k = 0; k < 4; ++k) putf(b, record + 16 + 4 * size_t(k), 0.0f); }},
      {"center infinite", [&](std::string& b) { putf(b, record + 4, std::numeric_limits<float>::infinity()); }},
      {"radius negative", [&](std::string& b) { putf(b, record + 12, -1.0f); }},
      {"parent out of range", [&](std::string& b) { put32(b, at + 8 + 7 * 48 + 4, 9); }},
      {"parent its own joint", [&](std::string& b) { put32(b, at + 8 + 7 * 48 + 8, 2); }},
      {"parents in a cycle", [&](std::string& b) { put32(b, at + 8 + 7 * 48, 4); }},  // 0 -> 4 -> 3 -> 2 -> 1 -> 0
      {"joint count past the file", [&](std::string& b) { put32(b, at, 0x10000000u); }},
      {"no joints", [&](std::string& b) { put32(b, at, 0); }},
      {"section size past the file", [&](std::string& b) { put32(b, at + 4, 0x7FFFFFF0u); }},
      {"section offset past the file", [&](std::string& b) { put32(b, 60, 0x7FFFFFF0u); }},
  };
  for (auto& [what, apply] : damage) {
    std::string bad = bytes;
    apply(bad);
    Proxy proxy;
    EXPECT_EQ(load(with_fixed_crc(bad), &proxy), SPX_ERR_BAD_SKIN) << what;
    EXPECT_TRUE(proxy.empty()) << what;
  }
}

TEST(Runtime, WeightOneOnExampleIReturnsSi) {
  const ProxyModel model = small_proxy();
  Proxy proxy;
  ASSERT_EQ(load(encode_spx(model), &proxy), SPX_OK);
  std::vector<float> c(21), r(7);
  for (uint32_t i = 0; i < 4; ++i) {
    std::vector<float> w(4, 0.0f);
    w[i] = 1;
    ASSERT_EQ(blend_global(proxy, w.data(), 4, c.data(), r.data()), SPX_OK);
    for (uint32_t s = 0; s < 7; ++s) {
      EXPECT_EQ(c[3 * s + 1], proxy.pose_spheres(i)[4 * s + 1]);
      EXPECT_EQ(r[s], proxy.pose_spheres(i)[4 * s + 3]);
    }
    // Local blend with that same vector at every site.
    std::vector<float> sw;
    for (int site = 0; site < 3; ++site) sw.insert(sw.end(), w.begin(), w.end());
    std::vector<float> lc(21), lr(7);
    ASSERT_EQ(blend_local(proxy, sw.data(), sw.size(), lc.data(), lr.data()), SPX_OK);
    EXPECT_EQ(lc, c);
    EXPECT_EQ(lr, r);
  }
}

TEST(Runtime, LocalBlendWithUniformSiteWeightsEqualsGlobal) {
  Proxy proxy;
  ASSERT_EQ(load(encode_spx(small_proxy(50, 6, 11)), &proxy), SPX_OK);
  const std::vector<float> w = {0.1f, 0.3f, 0.05f, 0.25f, 0.2f, 0.1f};
  std::vector<float> gc(150), gr(50), lc(150), lr(50);
  ASSERT_EQ(blend_global(proxy, w.data(), 6, gc.data(), gr.data()), SPX_OK);
  std::vector<float> sw;
  for (int site = 0; site < 11; ++site) sw.insert(sw.end(), w.begin(), w.end());
  ASSERT_EQ(blend_local(proxy, sw.data(), sw.size(), lc.data(), lr.data()), SPX_OK);
  for (size_t k = 0; k < gc.size(); ++k) EXPECT_NEAR(lc[k], gc[k], 1e-6f);
  for (size_t k = 0; k < gr.size(); ++k) EXPECT_NEAR(lr[k], gr[k], 1e-6f);
  // A blend is the convex combination of the examples, computed here in double.
  for (uint32_t s = 0; s < 50; ++s) {
    double x = 0;
    for (uint32_t i = 0; i < 6; ++i) x += double(w[i]) * proxy.pose_spheres(i)[4 * s];
    EXPECT_NEAR(gc[3 * s], x, 1e-6);
  }
}

TEST(Runtime, LocalBlendUsesEachSpheresSite) {
  Proxy proxy;
  ASSERT_EQ(load(encode_spx(small_proxy(9, 3, 3)), &proxy), SPX_OK);
  // Site k fully in pose k: sphere s (site s % 3) must equal pose (s % 3).
  const std::vector<float> sw = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  std::vector<float> c(27), r(9);
  ASSERT_EQ(blend_local(proxy, sw.data(), sw.size(), c.data(), r.data()), SPX_OK);
  for (uint32_t s = 0; s < 9; ++s) {
    const uint32_t pose = proxy.sphere_sites()[s];
    EXPECT_EQ(c[3 * s], proxy.pose_spheres(pose)[4 * s]);
    EXPECT_EQ(r[s], proxy.pose_spheres(pose)[4 * s + 3]);
  }
}

TEST(Runtime, WeightPolicy) {
  Proxy proxy;
  ASSERT_EQ(load(encode_spx(small_proxy()), &proxy), SPX_OK);
  std::vector<float> c(21, -7.0f), r(7, -7.0f);
  const float nan = std::nanf("");
  const float inf = std::numeric_limits<float>::infinity();
  const float bad_nan[4] = {1, nan, 0, 0}, bad_inf[4] = {inf, 0, 0, 0}, zero[4] = {0, 0, 0, 0},
              negative_only[4] = {-1, -1, 0, 0};
  EXPECT_EQ(blend_global(proxy, bad_nan, 4, c.data(), r.data()), SPX_ERR_BAD_WEIGHTS);
  EXPECT_EQ(blend_global(proxy, bad_inf, 4, c.data(), r.data()), SPX_ERR_BAD_WEIGHTS);
  EXPECT_EQ(blend_global(proxy, zero, 4, c.data(), r.data()), SPX_ERR_BAD_WEIGHTS);
  EXPECT_EQ(blend_global(proxy, negative_only, 4, c.data(), r.data()), SPX_ERR_BAD_WEIGHTS);
  EXPECT_EQ(blend_global(proxy, zero, 3, c.data(), r.data()), SPX_ERR_WEIGHT_COUNT);
  EXPECT_EQ(blend_global(proxy, nullptr, 4, c.data(), r.data()), SPX_ERR_INVALID_ARGUMENT);
  for (float v : c) EXPECT_EQ(v, -7.0f) << "failed blends leave the output untouched";
  // Negative weights are clamped, the rest normalised: {-1, 2, 0, 2} acts as {0, .5, 0, .5}.
  const float mixed[4] = {-1, 2, 0, 2}, clean[4] = {0, 0.5f, 0, 0.5f};
  std::vector<float> c2(21), r2(7);
  ASSERT_EQ(blend_global(proxy, mixed, 4, c.data(), r.data()), SPX_OK);
  ASSERT_EQ(blend_global(proxy, clean, 4, c2.data(), r2.data()), SPX_OK);
  EXPECT_EQ(c, c2);
  for (float v : r) EXPECT_GE(v, 0.0f);
  Proxy empty;
  EXPECT_EQ(blend_global(empty, clean, 4, c.data(), r.data()), SPX_ERR_EMPTY);
}

TEST(Runtime, EveryTruncationIsRejected) {
  const std::string bytes = encode_spx(small_proxy());
  for (size_t n = 0; n < bytes.size(); ++n) {
    Proxy proxy;
    const Status s = load_memory(bytes.data(), n, &proxy);
    EXPECT_NE(s, SPX_OK) << "cut at " << n;
    EXPECT_TRUE(proxy.empty());
  }
  std::string longer = bytes + "x";
  Proxy proxy;
  EXPECT_EQ(load(longer, &proxy), SPX_ERR_BAD_SIZES);
}

TEST(Runtime, EveryFlippedByteIsRejected) {
  const std::string bytes = encode_spx(small_proxy());
  for (size_t i = 0; i < bytes.size(); ++i)
    for (unsigned char mask : {0x01, 0x80, 0xFF}) {
      std::string bad = bytes;
      bad[i] = char(bad[i] ^ mask);
      Proxy proxy;
      EXPECT_NE(load(bad, &proxy), SPX_OK) << "byte " << i << " mask " << int(mask);
    }
}

// The checksum alone would reject every mutation above: recompute it after mutating, so the
// structural checks behind it run. A header byte changed is always rejected (by a structural
// status, never the checksum); a data byte changed either is rejected or loads a proxy whose
// blends stay finite with radii >= 0.

void expect_safe_if_loaded(const std::string& bytes, const std::string& what) {
  Proxy proxy;
  const Status s = load(bytes, &proxy);
  EXPECT_NE(s, SPX_ERR_CHECKSUM) << what;
  if (s != SPX_OK) {
    EXPECT_TRUE(proxy.empty()) << what;
    return;
  }
  const uint32_t n = proxy.sphere_count(), p = proxy.pose_count();
  std::vector<float> w(p, 1.0f), c(size_t(n) * 3), r(n), sw(size_t(proxy.site_count()) * p, 1.0f);
  ASSERT_EQ(blend_global(proxy, w.data(), p, c.data(), r.data()), SPX_OK) << what;
  for (uint32_t j = 0; j < n; ++j) {
    EXPECT_GE(r[j], 0.0f) << what;
    EXPECT_TRUE(std::isfinite(c[3 * j]) && std::isfinite(c[3 * j + 1]) && std::isfinite(c[3 * j + 2])) << what;
  }
  ASSERT_EQ(blend_local(proxy, sw.data(), uint32_t(sw.size()), c.data(), r.data()), SPX_OK) << what;
  if (!proxy.has_skin()) return;
  for (uint32_t j = 0; j < proxy.joint_count(); ++j) {  // a host's walk to the root ends
    int32_t up = int32_t(j);
    for (uint32_t steps = 0; up != -1 && steps <= proxy.joint_count(); ++steps) up = proxy.joint_parent(uint32_t(up));
    EXPECT_EQ(up, -1) << what << ": joint " << j;
  }
  std::mt19937 rng(1);
  const std::vector<float> m = random_joint_matrices(int(proxy.joint_count()), rng);
  std::vector<float> xyzr(size_t(n) * 4);
  ASSERT_EQ(skin(proxy, m.data(), int(proxy.joint_count()), xyzr.data()), SPX_OK) << what;
  for (float v : xyzr) EXPECT_TRUE(std::isfinite(v)) << what;
}

TEST(Runtime, EveryFlippedByteWithAFixedChecksumIsCheckedStructurally) {
  for (const bool skinned : {false, true}) {
  const std::string bytes = encode_spx(skinned ? skinned_proxy() : small_proxy());
  size_t loaded = 0;
  for (size_t i = 0; i + 4 < bytes.size(); ++i)
    for (unsigned char mask : {0x01, 0x80, 0xFF}) {
      std::string bad = bytes;
      bad[i] = char(bad[i] ^ mask);
      bad = with_fixed_crc(bad);
      const std::string what = "byte " + std::to_string(i) + " mask " + std::to_string(int(mask));
      // A newer minor version (bytes 10-11) must still load; a skin needs 1.1 or later.
      if (skinned && i == 10) {
        Proxy proxy;
        EXPECT_EQ(load(bad, &proxy), bad[10] == 0 ? SPX_ERR_BAD_SIZES : SPX_OK) << what;
      } else if (i < 64 && i != 10 && i != 11) {
        Proxy proxy;
        const Status s = load(bad, &proxy);
        EXPECT_NE(s, SPX_OK) << what;
        EXPECT_NE(s, SPX_ERR_CHECKSUM) << what;
      } else {
        expect_safe_if_loaded(bad, what);
        Proxy proxy;
        loaded += load(bad, &proxy) == SPX_OK;
      }
    }
  EXPECT_GT(loaded, 0u) << "no data byte survived the structural checks: is the checksum still deciding?";
  }
}

TEST(Runtime, RandomBytesWithAValidHeaderAndChecksum) {
  for (const bool skinned : {false, true}) {
  const std::string bytes = encode_spx(skinned ? skinned_proxy() : small_proxy());
  std::mt19937 rng(5);
  for (int trial = 0; trial < 3000; ++trial) {
    std::string junk = bytes;
    const int edits = 1 + int(rng() % 8);
    for (int e = 0; e < edits; ++e) junk[rng() % (junk.size() - 4)] = char(rng());
    expect_safe_if_loaded(with_fixed_crc(junk), "trial " + std::to_string(trial));
  }
  }
}

TEST(Runtime, VersionsAndChecksumHaveTheirOwnStatus) {
  const std::string bytes = encode_spx(small_proxy());
  Proxy proxy;
  std::string newer = bytes;
  newer[8] = 2;  // format major 2
  EXPECT_EQ(load(newer, &proxy), SPX_ERR_NEWER_VERSION);
  std::string legacy = bytes;
  legacy[8] = 0;
  EXPECT_EQ(load(legacy, &proxy), SPX_ERR_BAD_VERSION);
  std::string corrupt = bytes;
  corrupt[100] = char(corrupt[100] ^ 0x10);
  EXPECT_EQ(load(corrupt, &proxy), SPX_ERR_CHECKSUM);
  std::string magic = bytes;
  magic[1] = 'Q';
  EXPECT_EQ(load(magic, &proxy), SPX_ERR_BAD_MAGIC);
  EXPECT_EQ(load_file("/nonexistent/file.spx", &proxy), SPX_ERR_IO);
}

TEST(Runtime, RandomBytesNeverLoad) {
  std::mt19937 rng(99);
  for (int trial = 0; trial < 2000; ++trial) {
    std::string junk(size_t(rng() % 300), '\0');
    for (auto& c : junk) c = char(rng());
    if (trial % 2 == 0 && junk.size() >= 8) std::memcpy(&junk[0], SPX_MAGIC, 8);
    Proxy proxy;
    EXPECT_NE(load(junk, &proxy), SPX_OK);
  }
}

}  // namespace
}  // namespace spx

namespace spx {
namespace {

// The xyzr entry points give the split layout's numbers exactly: global for any weights, local
// from weights normalised once; the sphere block is 16-byte aligned whatever the pose count.
TEST(Runtime, XyzrBlendsEqualTheSplitLayout) {
  std::mt19937 rng(9);
  std::uniform_real_distribution<float> u(-0.3f, 1);
  for (size_t poses : {1, 2, 3, 5, 8}) {
    const ProxyModel model = small_proxy(37, poses, 6);
    Proxy proxy;
    ASSERT_EQ(load(encode_spx(model), &proxy), SPX_OK);
    EXPECT_EQ(reinterpret_cast<uintptr_t>(proxy.pose_spheres(0)) % 16, 0u) << poses << " poses";
    const uint32_t n = proxy.sphere_count(), p = proxy.pose_count();
    std::vector<float> c(3 * n), r(n), xyzr(4 * n);
    for (int trial = 0; trial < 10; ++trial) {
      std::vector<float> w(p);
      for (auto& x : w) x = u(rng);  // some negative (clamped), some zero after clamping
      w[size_t(trial) % p] = 0.5f;
      ASSERT_EQ(blend_global(proxy, w.data(), p, c.data(), r.data()), SPX_OK);
      ASSERT_EQ(blend_global_xyzr(proxy, w.data(), p, xyzr.data()), SPX_OK);
      for (uint32_t j = 0; j < n; ++j) {
        for (int k = 0; k < 3; ++k) ASSERT_EQ(xyzr[4 * j + k], c[3 * j + k]) << "global, sphere " << j;
        ASSERT_EQ(xyzr[4 * j + 3], r[j]) << "global radius, sphere " << j;
      }
      std::vector<float> sw(size_t(proxy.site_count()) * p), normalized(sw.size());
      for (auto& x : sw) x = u(rng);
      for (size_t site = 0; site < proxy.site_count(); ++site) sw[site * p] = 0.25f;  // every site has weight
      ASSERT_EQ(blend_local(proxy, sw.data(), sw.size(), c.data(), r.data()), SPX_OK);
      ASSERT_EQ(normalize_site_weights(proxy, sw.data(), sw.size(), normalized.data()), SPX_OK);
      ASSERT_EQ(blend_local_normalized(proxy, normalized.data(), normalized.size(), xyzr.data()), SPX_OK);
      for (uint32_t j = 0; j < n; ++j) {
        for (int k = 0; k < 3; ++k) ASSERT_EQ(xyzr[4 * j + k], c[3 * j + k]) << "local, sphere " << j;
        ASSERT_EQ(xyzr[4 * j + 3], r[j]) << "local radius, sphere " << j;
      }
    }
    std::vector<float> w(p, 0.0f), sw(size_t(proxy.site_count()) * p, 0.0f), normalized(sw.size());
    EXPECT_EQ(blend_global_xyzr(proxy, w.data(), p, xyzr.data()), SPX_ERR_BAD_WEIGHTS) << "no positive weight";
    EXPECT_EQ(blend_global_xyzr(proxy, w.data(), p + 1, xyzr.data()), SPX_ERR_WEIGHT_COUNT);
    EXPECT_EQ(normalize_site_weights(proxy, sw.data(), sw.size(), normalized.data()), SPX_ERR_BAD_WEIGHTS);
    EXPECT_EQ(normalize_site_weights(proxy, sw.data(), sw.size() - 1, normalized.data()), SPX_ERR_WEIGHT_COUNT);
    EXPECT_EQ(blend_local_normalized(proxy, normalized.data(), sw.size() + 1, xyzr.data()), SPX_ERR_WEIGHT_COUNT);
    EXPECT_EQ(blend_global_xyzr(Proxy(), w.data(), p, xyzr.data()), SPX_ERR_EMPTY);
  }
}

// The morph blend is the mesh's morph-target sum: rest + sum_i w_i (S_i - rest), computed here
// in double, for weights a host gives blend shapes (past 1, negative, two at once); one target
// at 1 alone gives its example to the bit; convex weights give blend_global's spheres at
// (1 - their sum, weights...); both layouts agree to the bit.
TEST(Runtime, MorphBlendAddsTheExamplesDifferencesAsMorphTargetsDo) {
  std::mt19937 rng(21);
  std::uniform_real_distribution<float> u(-0.5f, 1.5f);
  for (size_t poses : {1, 2, 4, 7}) {
    Proxy proxy;
    ASSERT_EQ(load(encode_spx(small_proxy(23, poses, 5)), &proxy), SPX_OK);
    const uint32_t n = proxy.sphere_count(), p = proxy.pose_count(), k = p - 1;
    std::vector<float> c(3 * n), r(n), xyzr(4 * n);
    for (int trial = 0; trial < 20; ++trial) {
      std::vector<float> w(k);
      for (auto& x : w) x = u(rng);
      ASSERT_EQ(blend_morph(proxy, w.data(), k, c.data(), r.data()), SPX_OK);
      ASSERT_EQ(blend_morph_xyzr(proxy, w.data(), k, xyzr.data()), SPX_OK);
      for (uint32_t j = 0; j < n; ++j) {
        const float* rest = proxy.pose_spheres(0) + 4 * j;
        double expect[4] = {rest[0], rest[1], rest[2], rest[3]};
        for (uint32_t i = 1; i < p; ++i)
          for (int a = 0; a < 4; ++a) expect[a] += double(w[i - 1]) * (proxy.pose_spheres(i)[4 * j + a] - double(rest[a]));
        for (int a = 0; a < 3; ++a) ASSERT_NEAR(c[3 * j + a], expect[a], 2e-5) << poses << " poses, sphere " << j;
        ASSERT_NEAR(r[j], std::max(expect[3], 0.0), 2e-5) << poses << " poses, sphere " << j;
        for (int a = 0; a < 3; ++a) ASSERT_EQ(xyzr[4 * j + a], c[3 * j + a]);
        ASSERT_EQ(xyzr[4 * j + 3], r[j]);
      }
    }
    for (uint32_t i = 1; i < p; ++i) {
      std::vector<float> w(k, 0.0f);
      w[i - 1] = 1;
      ASSERT_EQ(blend_morph_xyzr(proxy, w.data(), k, xyzr.data()), SPX_OK);
      for (uint32_t a = 0; a < 4 * n; ++a) ASSERT_EQ(xyzr[a], proxy.pose_spheres(i)[a]) << "target " << i << " alone";
    }
    // Convex morph weights: the global blend with the rest at 1 less their sum.
    if (k > 0) {
      std::vector<float> w(k, 0.5f / float(k)), full(p);
      full[0] = 0.5f;
      for (uint32_t i = 1; i < p; ++i) full[i] = w[i - 1];
      std::vector<float> g(4 * n);
      ASSERT_EQ(blend_global_xyzr(proxy, full.data(), p, g.data()), SPX_OK);
      ASSERT_EQ(blend_morph_xyzr(proxy, w.data(), k, xyzr.data()), SPX_OK);
      for (uint32_t a = 0; a < 4 * n; ++a) ASSERT_NEAR(xyzr[a], g[a], 1e-6f);
    }
    // No weights (the rest only) is the rest; a weight not finite or a wrong count is refused
    // and leaves the output untouched.
    if (k == 0) {
      ASSERT_EQ(blend_morph_xyzr(proxy, nullptr, 0, xyzr.data()), SPX_OK);
      for (uint32_t a = 0; a < 4 * n; ++a) ASSERT_EQ(xyzr[a], proxy.pose_spheres(0)[a]);
      continue;
    }
    std::vector<float> w(k, 0.25f);
    std::fill(xyzr.begin(), xyzr.end(), -7.0f);
    w[0] = std::nanf("");
    EXPECT_EQ(blend_morph_xyzr(proxy, w.data(), k, xyzr.data()), SPX_ERR_BAD_WEIGHTS);
    w[0] = std::numeric_limits<float>::infinity();
    EXPECT_EQ(blend_morph(proxy, w.data(), k, c.data(), r.data()), SPX_ERR_BAD_WEIGHTS);
    w[0] = -16777216.0f;
    EXPECT_EQ(blend_morph_xyzr(proxy, w.data(), k, xyzr.data()), SPX_ERR_BAD_WEIGHTS) << "the rest's 1 lost in float";
    for (float v : xyzr) EXPECT_EQ(v, -7.0f) << "failed blends leave the output untouched";
    w[0] = 0.25f;
    EXPECT_EQ(blend_morph_xyzr(proxy, w.data(), p, xyzr.data()), SPX_ERR_WEIGHT_COUNT) << "one per pose, rest included";
    EXPECT_EQ(blend_morph_xyzr(proxy, nullptr, k, xyzr.data()), SPX_ERR_INVALID_ARGUMENT);
    EXPECT_EQ(blend_morph(Proxy(), w.data(), k, c.data(), r.data()), SPX_ERR_EMPTY);
  }
}

// The skeleton's rule in linear time against walking every joint's parents (at most as many
// steps as joints): the first joint whose walk meets a parent out of range or does not reach a
// root. Random forests with a few parents re-pointed (cycles, self-parents, out of range).
TEST(Runtime, JointTreeAgreesWithWalkingEveryJoint) {
  std::mt19937 rng(5);
  size_t failing = 0;
  for (int trial = 0; trial < 4000; ++trial) {
    const uint32_t n = 1 + rng() % 9;
    std::vector<int32_t> parents(n);
    for (uint32_t j = 0; j < n; ++j) parents[j] = j == 0 || rng() % 4 == 0 ? -1 : int32_t(rng() % j);
    for (int k = int(rng() % 3); k > 0; --k) parents[rng() % n] = int32_t(rng() % (n + 2)) - 1;
    int64_t brute = -1;
    for (uint32_t j = 0; j < n && brute < 0; ++j) {
      int64_t up = j;
      uint32_t steps = 0;
      while (up >= 0 && up < int64_t(n) && steps++ <= n) up = parents[size_t(up)];
      if (up != -1) brute = j;
    }
    std::vector<uint32_t> marks(n);
    const int64_t fast = detail::joint_off_the_tree(n, [&](uint32_t j) { return int64_t(parents[j]); }, marks.data());
    EXPECT_EQ(fast, brute) << "trial " << trial;
    failing += brute >= 0;
  }
  EXPECT_GT(failing, 500u);  // both outcomes well exercised
  EXPECT_LT(failing, 3500u);
}

TEST(Runtime, FiniteIsDecidedByTheBits) {
  EXPECT_TRUE(detail::finite(0.0f));
  EXPECT_TRUE(detail::finite(-3.4e38f));
  EXPECT_TRUE(detail::finite(1e-45f));  // subnormal
  EXPECT_FALSE(detail::finite(std::numeric_limits<float>::infinity()));
  EXPECT_FALSE(detail::finite(-std::numeric_limits<float>::infinity()));
  EXPECT_FALSE(detail::finite(std::numeric_limits<float>::quiet_NaN()));
}

}  // namespace
}  // namespace spx
