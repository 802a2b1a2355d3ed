#include <gtest/gtest.h>

#include <array>
#include <random>

#include "core/atomic_file.hpp"
#include "core/pose_lines.hpp"
#include "extract/asset.hpp"
#include "io/scene.hpp"
#include "mesh/mesh_query.hpp"
#include "mesh/winding_number.hpp"
#include "metrics/motion_chart.hpp"
#include "metrics/motion_eval.hpp"
#include "metrics/proxy_eval.hpp"
#include "metrics/rest_match.hpp"
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

TEST(PoseLines, NameColumnIsTheLongestName) {
  struct Named {
    std::string name;
  };
  EXPECT_EQ(pose_name_width(std::vector<Named>{{"rest"}, {"pose-1"}}), 12);
  // A clip's times differ in width: every line's figures start after the longest.
  EXPECT_EQ(pose_name_width(std::vector<Named>{{"rest"}, {"walk@5s"}, {"walk@4.63333s"}}), 13);
  EXPECT_EQ(pose_name_width(std::vector<Named>{}), 12);
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

// A closed mesh's inside is told by ray crossings, any other's by the winding number: the same
// solid both ways gives the same count. Two boxes, one through the other (the winding number is
// 2 where they overlap), then with a face added again and reversed, which cancel in the winding
// number but leave the mesh not closed. The second box's face at y = -0.4 passes through grid
// points at 7 samples (within rounding), where the winding number decides both ways.
TEST(Coverage, ClosedMeshesCountedAsTheWindingNumberCounts) {
  TriMesh boxes = test::box_mesh(Eigen::Vector3d(-1, -1, -1), Eigen::Vector3d(1, 1, 1));
  const TriMesh b = test::box_mesh(Eigen::Vector3d(0.3, -0.4, -0.45), Eigen::Vector3d(1.8, 0.5, 0.2));
  for (const Eigen::Vector3i& t : b.triangles) boxes.triangles.push_back(t + Eigen::Vector3i::Constant(8));
  boxes.vertices.insert(boxes.vertices.end(), b.vertices.begin(), b.vertices.end());
  TriMesh cancelled = boxes;  // a face twice more, once each way: its edges then have 4 triangles
  const Eigen::Vector3i f = boxes.triangles[0];
  cancelled.triangles.insert(cancelled.triangles.end(), {f, Eigen::Vector3i(f[0], f[2], f[1])});
  const SphereSet spheres = {{{0, 0, 0}, 0.7}, {{1.2, 0, 0}, 0.3}, {{-0.6, 0.6, 0.6}, 0.35}};
  for (int samples : {7, 16, 33}) {
    const double closed = union_coverage(boxes, spheres, samples);
    EXPECT_GT(closed, 0.1);
    EXPECT_LT(closed, 0.9);
    EXPECT_EQ(closed, union_coverage(cancelled, spheres, samples)) << samples;
  }
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

// A proxy of `spheres` on one joint that stays put (the identity in every frame).
ProxyModel still_skinned_proxy(const SphereSet& spheres) {
  ProxyModel proxy;
  proxy.poses.push_back({"rest", "rest.obj", spheres, {}});
  proxy.sites = {Eigen::Vector3d::Zero()};
  proxy.sphere_sites.assign(spheres.size(), 0);
  proxy.skin.joints = {"root"};
  proxy.skin.parents = {-1};
  for (const Sphere& s : spheres) proxy.skin.spheres.push_back({{{0, 0, 0, 0}}, {{1, 0, 0, 0}}, s.center, s.radius});
  return proxy;
}

// evaluate_motion over `meshes` (one frame each) against brute force: the exact winding number
// for inside, MeshQuery's exact distances to the solid's boundary, its surface's vertices for
// the union's error. Returns how many centres were inside yet in front of the whole mesh's
// nearest triangle (where a closest point's normal alone would say outside).
size_t expect_frames_measured_exactly(const std::vector<TriMesh>& meshes, const SphereSet& spheres) {
  auto frame = [&](size_t i) {
    MotionFrame f;
    f.time = double(i);
    f.mesh = meshes[i];
    f.joints = {Eigen::Matrix4d::Identity()};
    return f;
  };
  const MotionResult r = evaluate_motion(still_skinned_proxy(spheres), meshes.size(), frame, {}, Log::silent());
  EXPECT_EQ(r.rows.size(), meshes.size());
  size_t inside_in_front = 0;
  for (size_t i = 0; i < meshes.size() && i < r.rows.size(); ++i) {
    const TriMesh& mesh = meshes[i];
    const MeshQuery query(mesh);
    const double rounding = 1e-12 * mesh.diagonal();
    FrameError want;
    const ErrorStats stats = summarize_abs(union_signed_distance(query.surface().vertices, spheres));
    want.median = stats.median, want.max = stats.max;
    for (const Sphere& s : spheres) {
      const bool inside = winding_number_exact(mesh, s.center) > 0.5;
      const double d = query.distance(s.center);
      want.overshoot = std::max(want.overshoot, s.radius + (inside ? -d : d));
      want.outside += !inside;
      double nearest = INFINITY;
      bool in_front = false;
      for (const Eigen::Vector3i& t : mesh.triangles) {
        const Eigen::Vector3d &a = mesh.vertices[size_t(t[0])], &b = mesh.vertices[size_t(t[1])],
                              &c = mesh.vertices[size_t(t[2])];
        const Eigen::Vector3d at = closest_point_on_triangle(s.center, a, b, c);
        if ((at - s.center).norm() < nearest)
          nearest = (at - s.center).norm(), in_front = (b - a).cross(c - a).dot(s.center - at) > 0;
      }
      inside_in_front += inside && in_front;
    }
    for (int k : {kSkinned, kRigid}) {
      const FrameError& got = r.rows[i].error[size_t(k)];
      EXPECT_EQ(got.outside, want.outside) << "frame " << i << " runtime " << k;
      EXPECT_NEAR(got.overshoot, want.overshoot, rounding) << "frame " << i << " runtime " << k;
      EXPECT_NEAR(got.median, want.median, rounding) << "frame " << i;
      EXPECT_NEAR(got.max, want.max, rounding) << "frame " << i;
    }
  }
  return inside_in_front;
}

// Over a clip each frame's spheres are measured against the frame's body: a frame on the first
// frame's closed triangles by one hierarchy refitted to it (the whole mesh where it is one
// piece; with MeshQuery's boundary and the hierarchy's ray count where it is several), any other
// frame by a MeshQuery and its winding number. Centres are exact in float (the runtime skins in
// float), none on a face's plane.
TEST(MotionEval, EveryFrameMeasuredAsTheExactWindingNumberSays) {
  // One piece: a sphere stretched and squashed.
  {
    const TriMesh round = test::uv_sphere(1.0, 12, 24);
    std::vector<TriMesh> meshes;
    for (double t : {0.0, 0.25, 0.5, 0.75, 1.0}) {
      TriMesh m = round;
      for (Eigen::Vector3d& v : m.vertices) v = v.cwiseProduct(Eigen::Vector3d(1 + 0.5 * t, 1, 1 - 0.375 * t));
      meshes.push_back(m);
    }
    const SphereSet spheres = {{{0, 0, 0}, 0.5},        {{0.875, 0, 0}, 0.25},  {{1.25, 0.125, 0}, 0.125},
                               {{0, 0.6875, 0.5}, 0.125}, {{0.25, 0.25, 0.75}, 0.25}, {{-1.125, 0, 0}, 0.0625}};
    expect_frames_measured_exactly(meshes, spheres);
  }
  // Two pieces: one box passing through another, the last frame on other triangles. A centre
  // inside the first box, nearest to a face of the second that lies inside it, is inside.
  {
    const TriMesh a = test::box_mesh(Eigen::Vector3d(-1, -1, -1), Eigen::Vector3d(1, 1, 1));
    std::vector<TriMesh> meshes;
    const std::vector<double> shifts = {-3, -1.75, -0.875, -0.3125, 0.0625, 0.4375, 0.875, 1.25, 0.4375};
    for (size_t i = 0; i < shifts.size(); ++i) {
      TriMesh m = a;
      TriMesh b = test::box_mesh(Eigen::Vector3d(shifts[i], -0.5, -0.5), Eigen::Vector3d(shifts[i] + 1.5, 0.5, 0.5));
      if (i + 1 == shifts.size())  // the same box, its quads split along their other diagonals
        b.triangles = {{0, 3, 1}, {0, 2, 3}, {4, 5, 7}, {4, 7, 6}, {0, 5, 4}, {0, 1, 5},
                       {2, 7, 3}, {2, 6, 7}, {0, 6, 2}, {0, 4, 6}, {1, 7, 5}, {1, 3, 7}};
      for (const Eigen::Vector3i& t : b.triangles) m.triangles.push_back(t + Eigen::Vector3i::Constant(8));
      m.vertices.insert(m.vertices.end(), b.vertices.begin(), b.vertices.end());
      meshes.push_back(m);
    }
    const SphereSet spheres = {{{-0.125, 0, 0}, 0.25},       {{0.625, 0, 0}, 0.125},          {{0.375, 0.75, 0}, 0.1875},
                               {{1.25, 0.125, 0}, 0.0625},   {{-0.8125, 0.875, 0.875}, 0.25}, {{1.625, 0.25, 0.25}, 0.125},
                               {{0.0625, 0.25, 0.375}, 0.375}};
    EXPECT_GT(expect_frames_measured_exactly(meshes, spheres), 0u);
  }
}

// A morph-target body's proxy follows the morph weights as the mesh adds its targets: a ball
// whose two targets move it right and up, and a proxy whose examples move its spheres as much.
// At any weights (two at 1, past 1, negative) the mesh is the rest moved, and the morph blend's
// spheres move with it: the rest's error in every frame. The global blend (the rest at 1 less
// the weights' sum) agrees at convex weights and falls behind where the targets add up.
TEST(MotionEval, MorphWeightsMoveTheSpheresAsTheMeshAddsItsTargets) {
  const TriMesh ball = test::uv_sphere(1.0, 12, 24);
  const Eigen::Vector3d right(0.5, 0, 0), up(0, 0.5, 0);
  const SphereSet rest = {{{0, 0, 0}, 0.75}, {{0.5, 0.25, 0}, 0.375}, {{-0.25, -0.5, 0.25}, 0.25}};
  ProxyModel proxy;
  proxy.poses.push_back({"rest", "rest.obj", rest, {}});
  for (const auto& [name, d] : {std::pair<const char*, Eigen::Vector3d>{"right", right}, {"up", up}}) {
    SphereSet moved = rest;
    for (Sphere& sp : moved) sp.center += d;
    proxy.poses.push_back({name, std::string(name) + ".obj", moved, {}});
  }
  proxy.sites = {Eigen::Vector3d::Zero()};
  proxy.sphere_sites.assign(rest.size(), 0);
  const std::vector<std::array<float, 2>> weights = {{0, 0}, {1, 0}, {0, 1}, {0.5f, 0.5f}, {1, 1}, {2, -0.5f}};
  auto frame = [&](size_t i) {
    MotionFrame f;
    f.time = double(i);
    f.mesh = ball;
    for (Eigen::Vector3d& v : f.mesh.vertices) v += double(weights[i][0]) * right + double(weights[i][1]) * up;
    f.morph_weights = {weights[i][0], weights[i][1]};
    return f;
  };
  const MotionResult r = evaluate_motion(proxy, weights.size(), frame, {}, Log::silent());
  EXPECT_EQ(r.runtimes, (std::vector<int>{kMorph, kGlobal}));
  ASSERT_EQ(r.rows.size(), weights.size());
  const FrameError& at_rest = r.rows[0].error[kMorph];
  EXPECT_GT(at_rest.max, 0.1);
  for (size_t i = 0; i < weights.size(); ++i) {
    const FrameError& e = r.rows[i].error[kMorph];
    EXPECT_NEAR(e.max, at_rest.max, 1e-6) << "frame " << i;
    EXPECT_NEAR(e.median, at_rest.median, 1e-6) << "frame " << i;
    EXPECT_EQ(e.overshoot, 0.0) << "frame " << i;
    EXPECT_EQ(e.outside, 0u) << "frame " << i;
  }
  EXPECT_NEAR(r.rows[3].error[kGlobal].max, at_rest.max, 1e-6) << "convex weights: the global blend too";
  EXPECT_GT(r.rows[4].error[kGlobal].max, at_rest.max + 0.1) << "two targets at 1: half of each";
  EXPECT_GT(r.rows[4].error[kGlobal].overshoot, 0.0);
  // A frame of the wrong weight count is refused, naming it.
  auto short_frame = [&](size_t i) {
    MotionFrame f = frame(i);
    f.morph_weights.pop_back();
    return f;
  };
  try {
    evaluate_motion(proxy, 1, short_frame, {}, Log::silent());
    ADD_FAILURE() << "one weight for two examples must be refused";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("1 morph weights; the proxy has 2 examples after the rest"), std::string::npos)
        << e.what();
  }
}

// The chart of a clip whose numbers are not finite (a diagonal past a float's range, errors of
// NaN) or all 0 still ends, with finite axes: its ticks looped for ever on a top of NaN.
TEST(MotionChart, NumbersNotFiniteOrZeroStillDrawAChart) {
  MotionResult r;
  r.runtimes = {kSkinned, kRigid};
  for (double t : {0.0, 0.5}) {
    MotionRow row;
    row.time = t;
    row.error[kSkinned].max = t > 0 ? std::nan("") : 0.0;
    row.error[kRigid].overshoot = INFINITY;
    r.rows.push_back(row);
  }
  for (double diagonal : {double(INFINITY), std::nan(""), 1.0}) {
    const std::string svg = motion_chart_svg(r, diagonal, 0.0, "clip");
    EXPECT_NE(svg.find("</svg>"), std::string::npos);
    EXPECT_EQ(svg.find("nan"), std::string::npos) << diagonal;
    EXPECT_EQ(svg.find("inf"), std::string::npos) << diagonal;
  }
}

// A proxy of one mesh of an asset of several: the other meshes, whose boxes hold no centre, are
// named in a warning with the --mesh whose box holds every centre; a proxy of both names none,
// nor does an asset of one mesh.
TEST(RestMatch, MeshesHoldingNoSphereAreNamedWithTheMeshThatHoldsThemAll) {
  const std::string dir = test::temp_dir("meshes-without-spheres");
  test::box_and_ball_glb(dir);
  write_file_atomic(dir + "/box.glb", encode_scene({{"box", test::box_mesh({0, 0, 0}, {1, 1, 1}), {}}}, ".glb"));
  ProxyModel in_box;
  in_box.poses.push_back({"rest", "rest.obj", {{{0.3, 0.3, 0.3}, 0.2}, {{0.7, 0.6, 0.5}, 0.25}, {{9, 9, 9}, 0}}, {}});
  ProxyModel in_both = in_box;
  in_both.poses[0].spheres.push_back({{3, 0, 0}, 0.4});
  const Asset pair(dir + "/pair.glb", ""), one(dir + "/box.glb", "");
  Log log("proxy-eval", -1);
  EXPECT_EQ(warn_meshes_without_spheres(in_box, pair, "left bare", log), std::vector<std::string>{"ball"});
  ASSERT_EQ(log.warnings().size(), 1u);
  EXPECT_EQ(log.warnings()[0], "1 of the 2 meshes of " + dir + "/pair.glb hold no sphere of the proxy ('ball'): left "
                               "bare; a proxy of one mesh (pose-extract --mesh) takes --mesh box");
  EXPECT_TRUE(warn_meshes_without_spheres(in_both, pair, "left bare", log).empty());
  EXPECT_TRUE(warn_meshes_without_spheres(in_box, one, "left bare", log).empty());
  // Two meshes of one name are one, as --mesh takes them together.
  TriMesh ball = test::uv_sphere(0.5, 8, 16);
  for (auto& v : ball.vertices) v += Eigen::Vector3d(3, 0, 0);
  write_file_atomic(dir + "/named-once.glb",
                    encode_scene({{"part", test::box_mesh({0, 0, 0}, {1, 1, 1}), {}}, {"part", ball, {}}}, ".glb"));
  const Asset named_once(dir + "/named-once.glb", "");
  ASSERT_EQ(named_once.meshes().size(), 2u);
  EXPECT_TRUE(warn_meshes_without_spheres(in_box, named_once, "left bare", log).empty());
  EXPECT_EQ(log.warnings().size(), 1u);
}

}  // namespace
}  // namespace spx
