// The Bullet crash host: dents matched to impacts, plastic weights kept on the simplex, runs
// repeatable to the bit, no tunnelling at the default step, error over time bounded.
#include <gtest/gtest.h>

#include "core/error.hpp"
#include "crash_host.hpp"
#include "export/spx_writer.hpp"
#include "mesh/mesh_query.hpp"
#include "pack/pack.hpp"
#include "posemap/posemap.hpp"
#include "samples/samples.hpp"
#include "sdf/sdf.hpp"

using namespace spx;
using namespace spx::crash;

namespace {

struct CarProxy {
  std::vector<TriMesh> meshes;  // rest + examples
  Proxy proxy;
};

// The car sample through the library's own chain, capped at `max_spheres`.
const CarProxy& car_proxy() {
  static const CarProxy car = [] {
    const SampleAsset asset = make_car();
    SdfOptions sopt;
    sopt.resolution = 64;
    const SdfResult sdf = build_sdf(asset.rest, sopt);
    const MeshQuery query(asset.rest);
    PackOptions popt;
    popt.max_spheres = 100;
    SpheresFile spheres;
    spheres.spheres = pack_spheres(sdf.field, popt, &query).spheres;
    spheres.voxel_size = sdf.field.shape.voxel_size;
    std::vector<PoseInput> poses;
    for (size_t i = 0; i < asset.pose_names.size(); ++i) poses.push_back({asset.pose_names[i], "", asset.pose(i)});
    const std::string bytes = encode_spx(pose_map(asset.rest, "rest", poses, spheres, {}).proxy);
    CarProxy out;
    out.meshes.push_back(asset.rest);
    for (size_t i = 0; i < asset.pose_names.size(); ++i) out.meshes.push_back(asset.pose(i));
    EXPECT_EQ(load_memory(bytes.data(), bytes.size(), &out.proxy), SPX_OK);
    return out;
  }();
  return car;
}

}  // namespace

TEST(CrashHost, ImpactsPickTheExampleDentedThatWay) {
  const CarProxy& car = car_proxy();
  const CarAsset a = make_car_asset("spheres", true, car.proxy, car.meshes);
  ASSERT_EQ(a.dents.size(), 5u);  // rest + front, rear, side, roof
  const Eigen::Vector3d lo = a.rest.bounds().min(), hi = a.rest.bounds().max(), mid = a.rest.bounds().center();
  EXPECT_EQ(match_dent(a.dents, {hi.x(), mid.y(), mid.z()}, {-1, 0, 0}, a.length), 1);  // nose pushed back
  EXPECT_EQ(match_dent(a.dents, {lo.x(), mid.y(), mid.z()}, {1, 0, 0}, a.length), 2);   // tail pushed forward
  EXPECT_EQ(match_dent(a.dents, {mid.x(), hi.y(), mid.z()}, {0, -1, 0}, a.length), 3);  // right door pushed in
  EXPECT_EQ(match_dent(a.dents, {mid.x(), mid.y(), hi.z()}, {0, 0, -1}, a.length), 4);  // roof pushed down
  EXPECT_EQ(match_dent(a.dents, {mid.x(), mid.y(), lo.z()}, {0, 0, 1}, a.length), 0);   // no example dents upward
  EXPECT_EQ(match_dent(a.dents, {mid.x(), lo.y(), mid.z()}, {0, 1, 0}, a.length), 0);   // nor the left side
}

TEST(CrashHost, VerticesTakeTheirNearestSite) {
  const CarProxy& car = car_proxy();
  const CarAsset a = make_car_asset("spheres", true, car.proxy, car.meshes);
  const float* sites = car.proxy.site_positions();
  for (size_t v = 0; v < a.rest.vertices.size(); v += 17) {
    auto dist = [&](uint32_t s) {
      return (Eigen::Vector3d(sites[3 * s], sites[3 * s + 1], sites[3 * s + 2]) - a.rest.vertices[v]).norm();
    };
    for (uint32_t s = 0; s < car.proxy.site_count(); ++s) EXPECT_LE(dist(a.vertex_site[v]), dist(s) + 1e-12);
  }
}

TEST(CrashHost, MismatchedPosesAreRejected) {
  const CarProxy& car = car_proxy();
  std::vector<TriMesh> fewer(car.meshes.begin(), car.meshes.end() - 1);
  EXPECT_THROW(make_car_asset("spheres", true, car.proxy, fewer), Error);
  std::vector<TriMesh> other = car.meshes;
  std::swap(other[2].triangles[0][0], other[2].triangles[0][1]);
  EXPECT_THROW(make_car_asset("spheres", true, car.proxy, other), Error);
}

// The crash happens in the air at about 1.6 s; 2.5 s covers it and the landing.
void expect_sane_crash(bool spheres) {
  const CarProxy& car = car_proxy();
  const CarAsset a = make_car_asset(spheres ? "spheres" : "triangle-mesh", spheres, car.proxy, car.meshes);
  SceneOptions opt;
  opt.seconds = 2.5;
  opt.monitor = true;
  const RunStats first = run_scene(a, opt);
  opt.monitor = false;
  const RunStats second = run_scene(a, opt);
  EXPECT_EQ(first.state_hash, second.state_hash) << "same inputs, same bits";
  EXPECT_EQ(first.steps, 150);
  EXPECT_GT(first.contacts, 0u);
  EXPECT_GT(first.reblends, 0u) << "the crash must dent the cars";
  EXPECT_GT(first.max_weight_moved, 0.1);
  EXPECT_LT(first.simplex_error, 1e-5) << "weights stay non-negative and sum to one";
  EXPECT_EQ(first.ground_tunnels, 0);
  EXPECT_EQ(first.car_tunnels, 0);
  EXPECT_FALSE(first.energy_blew_up()) << first.max_energy_ratio;
  EXPECT_LT(first.max_ground_penetration, 0.3);
  if (spheres) {
    ASSERT_EQ(first.error.size(), 8u);
    for (const auto& trace : first.error) {
      ASSERT_EQ(trace.median.size(), first.sample_times.size());
      for (size_t i = 0; i < trace.median.size(); ++i) {
        EXPECT_LT(trace.median[i], 0.1) << "median vertex-to-union error, m";
        EXPECT_LT(trace.max[i], 0.5) << "max vertex-to-union error, m";
      }
    }
  }
}

TEST(CrashHost, SphereProxiesCrashRepeatablyWithoutTunnelling) { expect_sane_crash(true); }
TEST(CrashHost, TriangleMeshesCrashRepeatablyWithoutTunnelling) { expect_sane_crash(false); }
