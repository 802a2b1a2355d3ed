// runtime-bench: the runtime header's blends (global and local) at 66 to 10 000 spheres and 1 to
// 16 examples, as spheres blended per second, beside a plain memcpy of the same bytes (the
// S_0..S_e block a blend reads) measured in the same run. scripts/runtime-bench.sh prints the
// ratios.
#include <benchmark/benchmark.h>

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
BENCHMARK_MAIN();
