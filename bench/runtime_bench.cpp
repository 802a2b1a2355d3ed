// runtime-bench: the runtime header's blends (global and local) at 66 to 10 000 spheres and 1 to
// 16 examples, as spheres blended per second, beside a plain memcpy of the same bytes (the
// S_0..S_e block a blend reads) measured in the same run. scripts/runtime-bench.sh prints the
// ratios. Then spx::skin at 100 to 10 000 spheres beside the plain 4-influence skinning loop a
// host runs for its mesh, over as many points.
#include <benchmark/benchmark.h>

#include <Eigen/Geometry>
#include <cstring>
#include <random>

#include "io/spx_writer.hpp"
#include "spx_runtime.h"

namespace {

// A proxy shaped like pose-map's: about 0.9 sites per sphere, spheres in packing order (so
// their sites are in no particular order).
spx::Proxy make_proxy(size_t spheres, size_t examples) {
  spx::ProxyModel model;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  for (size_t i = 0; i <= examples; ++i) {
    spx::ProxyPose pose;
    pose.name = i == 0 ? "rest" : "example-" + std::to_string(i);
    for (size_t s = 0; s < spheres; ++s) pose.spheres.push_back({Eigen::Vector3d(u(rng), u(rng), u(rng)), 0.5 + 0.4 * u(rng)});
    model.poses.push_back(pose);
  }
  const size_t sites = std::max<size_t>(1, spheres * 9 / 10);
  for (size_t s = 0; s < sites; ++s) model.sites.emplace_back(u(rng), u(rng), u(rng));
  std::uniform_int_distribution<int> pick(0, int(sites) - 1);
  for (size_t s = 0; s < spheres; ++s) model.sphere_sites.push_back(pick(rng));
  const std::string bytes = spx::encode_spx(model);
  spx::Proxy proxy;
  if (spx::load_memory(bytes.data(), bytes.size(), &proxy) != spx::SPX_OK) std::abort();
  return proxy;
}

void report(benchmark::State& state, size_t spheres, size_t poses) {
  state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(spheres));
  state.SetBytesProcessed(int64_t(state.iterations()) * int64_t(spheres * poses * 4 * sizeof(float)));
  state.counters["spheres"] = double(spheres);
  state.counters["examples"] = double(poses - 1);
}

void BM_BlendGlobal(benchmark::State& state) {
  const size_t n = size_t(state.range(0)), e = size_t(state.range(1));
  const spx::Proxy proxy = make_proxy(n, e);
  std::vector<float> weights(e + 1, 1.0f / float(e + 1)), centers(3 * n), radii(n);
  for (auto _ : state) {
    spx::blend_global(proxy, weights.data(), uint32_t(e + 1), centers.data(), radii.data());
    benchmark::DoNotOptimize(radii.data());
    benchmark::ClobberMemory();
  }
  report(state, n, e + 1);
}

void BM_BlendLocal(benchmark::State& state) {
  const size_t n = size_t(state.range(0)), e = size_t(state.range(1));
  const spx::Proxy proxy = make_proxy(n, e);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0, 1);
  std::vector<float> weights(proxy.site_count() * (e + 1)), centers(3 * n), radii(n);
  for (auto& w : weights) w = u(rng);
  for (auto _ : state) {
    spx::blend_local(proxy, weights.data(), weights.size(), centers.data(), radii.data());
    benchmark::DoNotOptimize(radii.data());
    benchmark::ClobberMemory();
  }
  report(state, n, e + 1);
}

// The xyzr layout (the loops vectorise): global, and local from weights normalised once.
void BM_BlendGlobalXyzr(benchmark::State& state) {
  const size_t n = size_t(state.range(0)), e = size_t(state.range(1));
  const spx::Proxy proxy = make_proxy(n, e);
  std::vector<float> weights(e + 1, 1.0f / float(e + 1)), xyzr(4 * n);
  for (auto _ : state) {
    spx::blend_global_xyzr(proxy, weights.data(), uint32_t(e + 1), xyzr.data());
    benchmark::DoNotOptimize(xyzr.data());
    benchmark::ClobberMemory();
  }
  report(state, n, e + 1);
}

void BM_BlendLocalNormalized(benchmark::State& state) {
  const size_t n = size_t(state.range(0)), e = size_t(state.range(1));
  const spx::Proxy proxy = make_proxy(n, e);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0, 1);
  std::vector<float> weights(proxy.site_count() * (e + 1)), normalized(weights.size()), xyzr(4 * n);
  for (auto& w : weights) w = u(rng);
  if (spx::normalize_site_weights(proxy, weights.data(), weights.size(), normalized.data()) != spx::SPX_OK) std::abort();
  for (auto _ : state) {
    spx::blend_local_normalized(proxy, normalized.data(), normalized.size(), xyzr.data());
    benchmark::DoNotOptimize(xyzr.data());
    benchmark::ClobberMemory();
  }
  report(state, n, e + 1);
}

// The floor: copying the bytes a blend reads.
void BM_Memcpy(benchmark::State& state) {
  const size_t n = size_t(state.range(0)), e = size_t(state.range(1));
  const spx::Proxy proxy = make_proxy(n, e);
  const size_t bytes = n * (e + 1) * 4 * sizeof(float);
  std::vector<char> out(bytes);
  for (auto _ : state) {
    std::memcpy(out.data(), proxy.pose_spheres(0), bytes);
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
  }
  report(state, n, e + 1);
}

// A skinned proxy: `spheres` spheres on `joints` joints, 4 influences each (weights summing to
// 1), and the frame's joint matrices, column-major as a host has them.
struct Skinned {
  spx::Proxy proxy;
  std::vector<float> matrices;
};
Skinned make_skinned(size_t spheres, size_t joints) {
  spx::ProxyModel model;
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(-1, 1);
  std::uniform_int_distribution<int> joint(0, int(joints) - 1);
  spx::ProxyPose rest{"rest", "", {}, {}};
  for (size_t j = 0; j < joints; ++j) model.skin.joints.push_back("joint-" + std::to_string(j)), model.skin.parents.push_back(int(j) - 1);
  for (size_t s = 0; s < spheres; ++s) {
    spx::SkinnedSphere k;
    float sum = 0;
    for (int i = 0; i < 4; ++i) k.joint[size_t(i)] = joint(rng), sum += (k.weight[size_t(i)] = float(1.5 + u(rng)));
    for (float& w : k.weight) w /= sum;
    k.center = Eigen::Vector3d(u(rng), u(rng), u(rng));
    k.radius = 0.5 + 0.4 * u(rng);
    model.skin.spheres.push_back(k);
    rest.spheres.push_back({k.center, k.radius});
  }
  model.poses.push_back(rest);
  model.sites.emplace_back(0, 0, 0);
  model.sphere_sites.assign(spheres, 0);
  Skinned out;
  const std::string bytes = spx::encode_spx(model);
  if (spx::load_memory(bytes.data(), bytes.size(), &out.proxy) != spx::SPX_OK) std::abort();
  for (size_t j = 0; j < joints; ++j) {
    Eigen::Matrix4f m = Eigen::Matrix4f::Identity();
    m.topLeftCorner<3, 3>() = Eigen::AngleAxisf(float(u(rng)), Eigen::Vector3f(float(u(rng)), 1, 0).normalized()).matrix();
    m.topRightCorner<3, 1>() = Eigen::Vector3f(float(u(rng)), float(u(rng)), float(u(rng)));
    out.matrices.insert(out.matrices.end(), m.data(), m.data() + 16);
  }
  return out;
}

void report_skin(benchmark::State& state, size_t spheres) {
  state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(spheres));
  state.counters["spheres"] = double(spheres);
}

// spx::skin: x y z r of every sphere from the frame's joint matrices.
void BM_Skin(benchmark::State& state) {
  const size_t n = size_t(state.range(0));
  const Skinned k = make_skinned(n, 24);
  std::vector<float> xyzr(4 * n);
  for (auto _ : state) {
    spx::skin(k.proxy, k.matrices.data(), 24, xyzr.data());
    benchmark::DoNotOptimize(xyzr.data());
    benchmark::ClobberMemory();
  }
  report_skin(state, n);
}

// What a host already runs for its mesh: 4-influence linear blend skinning of as many points,
// positions, joints and weights in arrays of their own (the layout of glTF's attributes).
void BM_PlainLbs(benchmark::State& state) {
  const size_t n = size_t(state.range(0));
  const Skinned k = make_skinned(n, 24);
  std::vector<float> position(3 * n), weight(4 * n), out(3 * n);
  std::vector<uint32_t> joint(4 * n);
  for (size_t i = 0; i < n; ++i) {
    const float* s = k.proxy.skin_spheres() + 8 * i;
    for (int c = 0; c < 3; ++c) position[3 * i + size_t(c)] = s[c];
    for (int w = 0; w < 4; ++w) weight[4 * i + size_t(w)] = s[4 + w], joint[4 * i + size_t(w)] = k.proxy.skin_joints()[4 * i + size_t(w)];
  }
  const float* m0 = k.matrices.data();
  for (auto _ : state) {
    for (size_t i = 0; i < n; ++i) {
      const float* p = &position[3 * i];
      float x = 0, y = 0, z = 0;
      for (size_t w = 0; w < 4; ++w) {
        const float a = weight[4 * i + w];
        const float* m = m0 + 16 * size_t(joint[4 * i + w]);
        x += a * (m[0] * p[0] + m[4] * p[1] + m[8] * p[2] + m[12]);
        y += a * (m[1] * p[0] + m[5] * p[1] + m[9] * p[2] + m[13]);
        z += a * (m[2] * p[0] + m[6] * p[1] + m[10] * p[2] + m[14]);
      }
      out[3 * i] = x, out[3 * i + 1] = y, out[3 * i + 2] = z;
    }
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
  }
  report_skin(state, n);
}

void skin_sizes(benchmark::internal::Benchmark* b) {
  for (int n : {100, 320, 1000, 10000}) b->Args({n});
}

void sizes(benchmark::internal::Benchmark* b) {
  for (int n : {66, 320, 1000, 10000})
    for (int e : {1, 4, 16}) b->Args({n, e});
}

}  // namespace

BENCHMARK(BM_Memcpy)->Apply(sizes);
BENCHMARK(BM_BlendGlobal)->Apply(sizes);
BENCHMARK(BM_BlendLocal)->Apply(sizes);
BENCHMARK(BM_BlendGlobalXyzr)->Apply(sizes);
BENCHMARK(BM_BlendLocalNormalized)->Apply(sizes);
BENCHMARK(BM_PlainLbs)->Apply(skin_sizes);
BENCHMARK(BM_Skin)->Apply(skin_sizes);
BENCHMARK_MAIN();
