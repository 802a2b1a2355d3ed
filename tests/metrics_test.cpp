#include <gtest/gtest.h>

#include <random>

#include "core/pose_lines.hpp"
#include "metrics/proxy_eval.hpp"
#include "metrics/simplex_fit.hpp"
#include "mesh/union_distance.hpp"
#include "synthetic/synthetic.hpp"
#include "test_util.hpp"

namespace spx {
namespace {

// A long clip prints the rest and its worst poses: against a sort of every pose by hand.
TEST(PoseLines, ALongClipShowsTheRestAndItsWorstPoses) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> value(0, 9);  // few values: ties to break
  for (size_t count : {1u, 5u, 12u, 13u, 40u, 458u}) {
    std::vector<PoseLine> lines(count);
    for (size_t i = 0; i < count; ++i) lines[i] = {"pose " + std::to_string(i), double(value(rng))};
    lines[0].worst = 100;  // the rest is shown whatever its error, and only once
    std::vector<size_t> all(count);
    for (size_t i = 0; i < count; ++i) all[i] = i;
    EXPECT_EQ(pose_lines_shown(lines, true), all);
    if (count <= kAllPoseLines) {
      EXPECT_EQ(pose_lines_shown(lines, false), all) << count;
      continue;
    }
    // By hand: the first, then each other pose shown when fewer than kWorstPoseLines others are
    // worse than it, or as bad and earlier.
    std::vector<size_t> expected{0};
    for (size_t i = 1; i < count; ++i) {
      size_t ahead = 0;
      for (size_t j = 1; j < count; ++j)
        ahead += lines[j].worst > lines[i].worst || (lines[j].worst == lines[i].worst && j < i);
      if (ahead < kWorstPoseLines) expected.push_back(i);
    }
    EXPECT_EQ(pose_lines_shown(lines, false), expected) << count;
    EXPECT_EQ(expected.size(), kWorstPoseLines + 1);
  }
}

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

// The best-fit blend weights: against a dense search of the simplex (3 examples, some optima on
// an edge or a vertex), and the KKT conditions on 40 examples, some affinely dependent.
TEST(SimplexFit, MatchesBruteForceOnTheSimplex) {
  std::mt19937 rng(11);
  std::normal_distribution<double> g;
  for (int trial = 0; trial < 40; ++trial) {
    Eigen::MatrixXd A(12, 3);
    for (int i = 0; i < A.size(); ++i) A.data()[i] = g(rng);
    Eigen::VectorXd v(12);
    for (int i = 0; i < v.size(); ++i) v[i] = 2 * g(rng);
    const Eigen::VectorXd w = simplex_least_squares(A.transpose() * A, A.transpose() * v);
    ASSERT_EQ(w.size(), 3);
    EXPECT_NEAR(w.sum(), 1, 1e-12);
    EXPECT_GE(w.minCoeff(), 0);
    double best = 1e300;
    const int n = 400;
    for (int a = 0; a <= n; ++a)
      for (int b = 0; a + b <= n; ++b) {
        const Eigen::Vector3d x(a / double(n), b / double(n), (n - a - b) / double(n));
        best = std::min(best, (A * x - v).squaredNorm());
      }
    EXPECT_LE((A * w - v).squaredNorm(), best + 1e-12) << "trial " << trial;
  }
}

TEST(SimplexFit, MeetsItsOptimalityConditions) {
  std::mt19937 rng(12);
  std::normal_distribution<double> g;
  Eigen::MatrixXd A(300, 40);
  for (int i = 0; i < A.size(); ++i) A.data()[i] = g(rng);
  A.col(7) = 0.5 * (A.col(3) + A.col(5));  // dependent examples
  A.col(9) = A.col(3);
  // A target inside the hull is reproduced exactly.
  Eigen::VectorXd inside = Eigen::VectorXd::Zero(40);
  inside[1] = 0.2, inside[2] = 0.3, inside[20] = 0.5;
  const Eigen::VectorXd exact = simplex_least_squares(A.transpose() * A, A.transpose() * (A * inside));
  EXPECT_LE((A * exact - A * inside).norm(), 1e-9 * (A * inside).norm());
  // Far outside it: free weights share one gradient, the others' gradients are no lower.
  Eigen::VectorXd v(300);
  for (int i = 0; i < v.size(); ++i) v[i] = 3 * g(rng);
  const Eigen::MatrixXd G = A.transpose() * A;
  const Eigen::VectorXd w = simplex_least_squares(G, A.transpose() * v);
  const Eigen::VectorXd grad = G * w - A.transpose() * v;
  double lambda = 0;
  int free_count = 0;
  for (int i = 0; i < 40; ++i)
    if (w[i] > 1e-12) lambda += grad[i], ++free_count;
  ASSERT_GT(free_count, 1);
  lambda /= free_count;
  const double scale = grad.cwiseAbs().maxCoeff();
  for (int i = 0; i < 40; ++i) {
    if (w[i] > 1e-12) EXPECT_NEAR(grad[i], lambda, 1e-8 * scale) << i;
    else EXPECT_GE(grad[i], lambda - 1e-8 * scale) << i;
  }
}

}  // namespace
}  // namespace spx
