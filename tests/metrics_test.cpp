#include <gtest/gtest.h>

#include <random>

#include "metrics/proxy_eval.hpp"
#include "mesh/union_distance.hpp"
#include "synthetic/synthetic.hpp"
#include "test_util.hpp"

namespace spx {
namespace {

TEST(UnionError, OneSphereInACubeIsTheCornerDistance) {
  // Cube [-1,1]^3 (its 8 corners are the vertices), unit sphere at the center: every vertex is
  // sqrt(3) from the center, so sqrt(3) - 1 from the sphere.
  const TriMesh cube = test::box_mesh({-1, -1, -1}, {1, 1, 1});
  const ErrorStats e = vertex_error(cube, {{Eigen::Vector3d::Zero(), 1.0}});
  EXPECT_NEAR(e.max, std::sqrt(3.0) - 1, 1e-15);
  EXPECT_NEAR(e.median, std::sqrt(3.0) - 1, 1e-15);
  // A second sphere at one corner's side halves nothing for the others but fixes that corner.
  const SphereSet two = {{Eigen::Vector3d::Zero(), 1.0}, {Eigen::Vector3d(0.5, 0.5, 0.5), 0.5}};
  const std::vector<double> d = union_signed_distance(cube.vertices, two);
  for (size_t v = 0; v < 8; ++v) {
    const bool far_corner = cube.vertices[v] == Eigen::Vector3d(1, 1, 1);
    EXPECT_NEAR(d[v], far_corner ? std::sqrt(0.75) - 0.5 : std::sqrt(3.0) - 1, 1e-15);
  }
}

TEST(UnionError, MatchesBruteForceAndSigns) {
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> u(-1, 1);
  SphereSet spheres;
  for (int i = 0; i < 40; ++i) spheres.push_back({Eigen::Vector3d(u(rng), u(rng), u(rng)), 0.05 + 0.2 * (u(rng) + 1)});
  spheres[3].radius = 0;  // absent
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 500; ++i) points.emplace_back(2 * u(rng), 2 * u(rng), 2 * u(rng));
  const std::vector<double> d = union_signed_distance(points, spheres);
  for (size_t i = 0; i < points.size(); ++i) {
    double best = 1e300;
    bool inside = false;
    for (size_t s = 0; s < spheres.size(); ++s) {
      if (s == 3) continue;
      const double r = (points[i] - spheres[s].center).norm();
      best = std::min(best, r - spheres[s].radius);
      inside = inside || r < spheres[s].radius;
    }
    EXPECT_DOUBLE_EQ(d[i], best);
    EXPECT_EQ(d[i] < 0, inside);
  }
  const SurfaceError e = surface_error(d);
  EXPECT_GE(e.signed_max, e.abs.median - 1e-12);
  EXPECT_GT(e.outside_fraction, 0);
  EXPECT_LT(e.outside_fraction, 1);
}

TEST(Coverage, NestedSpheresCoverTheirVolumeRatio) {
  const TriMesh ball = test::uv_sphere(1.0, 48, 96);
  EXPECT_NEAR(union_coverage(ball, {{Eigen::Vector3d::Zero(), 1.0}}, 64), 1.0, 0.01);
  EXPECT_NEAR(union_coverage(ball, {{Eigen::Vector3d::Zero(), 0.5}}, 64), 0.125, 0.01);
  EXPECT_EQ(union_coverage(ball, {{Eigen::Vector3d::Zero(), 0.0}}, 16), 0.0);
}

TEST(BlendWeights, MidpointsThenSeededConvexCombinations) {
  const auto w = blend_weights(4, 12, 9);
  ASSERT_EQ(w.size(), 12u);
  for (size_t k = 0; k < w.size(); ++k) {
    double sum = 0;
    for (float x : w[k]) {
      EXPECT_GE(x, 0.0f);
      sum += x;
    }
    EXPECT_NEAR(sum, 1.0, 1e-6);
    if (k < 6) EXPECT_EQ(std::count(w[k].begin(), w[k].end(), 0.5f), 2);
  }
  EXPECT_EQ(w, blend_weights(4, 12, 9));
  EXPECT_NE(w, blend_weights(4, 12, 10));
}

TEST(ProxyEval, BlendOfOnePoseIsThatPose) {
  // A proxy whose examples are the rest spheres shifted: every blend's error equals the rest's.
  const SampleAsset barrel = make_barrel();
  ProxyModel proxy;
  SphereSet rest = {{Eigen::Vector3d(0, 0, 0.36), 0.25}, {Eigen::Vector3d(0, 0, 0.15), 0.14}};
  std::vector<TriMesh> meshes;
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector3d shift(0.1 * i, 0, 0);
    ProxyPose p{"p" + std::to_string(i), "", rest, {}};
    for (auto& s : p.spheres) s.center += shift;
    proxy.poses.push_back(p);
    TriMesh m = barrel.rest;
    for (auto& v : m.vertices) v += shift;
    meshes.push_back(m);
  }
  proxy.sites = {Eigen::Vector3d::Zero()};
  proxy.sphere_sites = {0, 0};
  EvalOptions opt;
  opt.blends = 5;
  const EvalResult r = evaluate_proxy(proxy, meshes, opt);
  const double rest_max = r.pose_measurements[0].error.abs.max;
  ASSERT_EQ(r.blend_measurements.size(), 5u);
  for (const Measurement& b : r.blend_measurements) EXPECT_NEAR(b.error.abs.max, rest_max, 1e-5);
  EXPECT_GT(r.blend_global_us, 0);
}

}  // namespace
}  // namespace spx
