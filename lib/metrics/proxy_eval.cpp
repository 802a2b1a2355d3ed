#include "metrics/proxy_eval.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <optional>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/error.hpp"
#include "core/random.hpp"
#include "io/spx_writer.hpp"
#include "mesh/deforming_query.hpp"
#include "mesh/solid_boundary.hpp"
#include "mesh/winding_number.hpp"
#include "runtime/spx_runtime.h"

namespace spx {

double union_coverage(const TriMesh& mesh, const SphereSet& spheres, int samples) {
  const Eigen::AlignedBox3d box = mesh.bounds();
  const double cell = box.sizes().maxCoeff() / std::max(1, samples);
  if (!(cell > 0)) return 0;
  const Eigen::Vector3i n = (box.sizes() / cell).array().ceil().cast<int>().max(1);
  // Inside by a ray's crossings where the mesh is closed (cheaper than the winding number's
  // expansions); on its surface, and on a mesh that is not closed, by the winding number.
  const RayInside rays(mesh);
  const WindingNumber wn = WindingNumber::on_first_use(mesh);
  auto is_inside = [&](const Eigen::Vector3d& p) {
    const std::optional<bool> in = rays(p);
    return in ? *in : wn.inside(p);
  };
  std::atomic<size_t> inside{0}, covered{0};
  tbb::parallel_for(tbb::blocked_range<int>(0, n.x()), [&](const tbb::blocked_range<int>& r) {
    size_t in = 0, cov = 0;
    for (int i = r.begin(); i != r.end(); ++i)
      for (int j = 0; j < n.y(); ++j)
        for (int k = 0; k < n.z(); ++k) {
          const Eigen::Vector3d p = box.min() + cell * Eigen::Vector3d(i + 0.5, j + 0.5, k + 0.5);
          if (!is_inside(p)) continue;
          ++in;
          for (const auto& s : spheres)
            if (s.radius > 0 && (p - s.center).squaredNorm() <= s.radius * s.radius) {
              ++cov;
              break;
            }
        }
    inside += in;
    covered += cov;
  });
  return inside > 0 ? double(covered) / double(inside) : 0.0;
}

SurfaceError surface_error(const std::vector<double>& d) {
  SurfaceError e;
  e.abs = summarize_abs(d);
  if (d.empty()) return e;
  std::vector<double> s(d);
  std::sort(s.begin(), s.end());
  e.signed_min = s.front();
  e.signed_max = s.back();
  e.signed_median = s.size() % 2 ? s[s.size() / 2] : 0.5 * (s[s.size() / 2 - 1] + s[s.size() / 2]);
  e.outside_fraction = double(std::count_if(d.begin(), d.end(), [](double v) { return v > 0; })) / double(d.size());
  return e;
}

nlohmann::json SurfaceError::to_json() const {
  return {{"median", abs.median},
          {"p95", abs.p95},
          {"max", abs.max},
          {"signed", {{"median", signed_median}, {"min", signed_min}, {"max", signed_max}}},
          {"outside_fraction", outside_fraction}};
}

double median_call_us(const std::function<void()>& call) {
  std::vector<double> times;
  for (int rep = 0; rep < 31; ++rep) {
    const auto t0 = std::chrono::steady_clock::now();
    for (int k = 0; k < 20; ++k) call();
    times.push_back(std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count() / 20);
  }
  std::sort(times.begin(), times.end());
  return times[times.size() / 2];
}

std::vector<std::vector<float>> blend_weights(size_t poses, int count, unsigned seed) {
  std::vector<std::vector<float>> out;
  for (size_t a = 0; a < poses && int(out.size()) < count; ++a)
    for (size_t b = a + 1; b < poses && int(out.size()) < count; ++b) {
      std::vector<float> w(poses, 0.0f);
      w[a] = w[b] = 0.5f;
      out.push_back(w);
    }
  SplitMix rng{seed};  // normalised exponentials: uniform on the simplex
  while (int(out.size()) < count) {
    std::vector<double> x(poses);
    double sum = 0;
    for (auto& v : x) sum += (v = rng.exponential());
    std::vector<float> w(poses);
    for (size_t i = 0; i < poses; ++i) w[i] = float(x[i] / sum);
    out.push_back(w);
  }
  return out;
}

namespace {

// `mesh` with its spheres measured: the error at the vertices of the solid's surface (walls
// inside the solid are no part of it), coverage of the whole mesh's solid. `p` keeps the surface
// and its vertices' errors (the colours).
Measurement measure(const TriMesh& mesh, PoseError& p, int coverage_samples) {
  p.mesh = solid_surface(mesh);
  p.vertex_error = union_signed_distance(p.mesh.vertices, p.spheres);
  Measurement m;
  m.error = surface_error(p.vertex_error);
  m.coverage = union_coverage(mesh, p.spheres, coverage_samples);
  for (const auto& s : p.spheres) m.zero_radius += s.radius <= 0;
  return m;
}

}  // namespace

EvalResult evaluate_proxy(const ProxyModel& proxy, const std::vector<TriMesh>& meshes, const EvalOptions& opt, Log& log) {
  if (meshes.size() != proxy.poses.size())
    fail_option("poses", "the proxy has " + std::to_string(proxy.poses.size() - 1) + " example poses, " +
                             std::to_string(meshes.size() - 1) + " were given");
  if (opt.blends < 0) fail_option("blends", "must not be negative");
  if (opt.blends > kMaxBlends)
    fail_option("blends", "at most " + std::to_string(kMaxBlends) + ", not " + std::to_string(opt.blends) +
                              " (each blend is a whole measurement of the body)");
  if (opt.coverage_samples < 1) fail_option("coverage_samples", "must be above 0");
  EvalResult result;
  for (size_t i = 0; i < meshes.size(); ++i) {
    PoseError p{proxy.poses[i].name, {}, proxy.poses[i].spheres, {}};
    result.pose_measurements.push_back(measure(meshes[i], p, opt.coverage_samples));
    result.poses.push_back(std::move(p));
  }

  // Blends, through the runtime reader on the bytes a host would load.
  const std::string bytes = encode_spx(proxy);
  Proxy runtime;
  const Status status = load_memory(bytes.data(), bytes.size(), &runtime);
  if (status != SPX_OK) fail_input("", std::string("runtime cannot load the proxy: ") + status_string(status));
  const uint32_t n = runtime.sphere_count();
  std::vector<float> centers(size_t(n) * 3), radii(n);
  for (const auto& w : blend_weights(meshes.size(), opt.blends, opt.seed)) {
    if (blend_global(runtime, w.data(), uint32_t(w.size()), centers.data(), radii.data()) != SPX_OK)
      fail_input("", "blend failed");
    TriMesh blended = meshes[0];
    for (size_t v = 0; v < blended.vertices.size(); ++v) {
      Eigen::Vector3d x = Eigen::Vector3d::Zero();
      for (size_t i = 0; i < meshes.size(); ++i) x += double(w[i]) * meshes[i].vertices[v];
      blended.vertices[v] = x;
    }
    PoseError p;
    for (uint32_t s = 0; s < n; ++s)
      p.spheres.push_back({Eigen::Vector3d(centers[3 * s], centers[3 * s + 1], centers[3 * s + 2]), double(radii[s])});
    result.blend_measurements.push_back(measure(blended, p, opt.coverage_samples));
    result.blend_weights.push_back(w);
  }

  // Runtime cost per frame: median time of a global blend, measured here.
  const std::vector<float> w = blend_weights(meshes.size(), std::max<int>(1, int(meshes.size())), opt.seed).back();
  result.blend_global_us =
      median_call_us([&] { blend_global(runtime, w.data(), uint32_t(w.size()), centers.data(), radii.data()); });
  log.detail("global blend: " + std::to_string(result.blend_global_us) + " us");
  return result;
}

}  // namespace spx
