#include <gtest/gtest.h>

#include <cstring>

#include <random>

#include "core/atomic_file.hpp"
#include "core/error.hpp"
#include "mesh/mesh_query.hpp"
#include "mesh/winding_number.hpp"
#include "sdf/edt.hpp"
#include "sdf/sdf.hpp"
#include "synthetic/synthetic.hpp"
#include "sdf/surface_layer.hpp"
#include "io/vdb_io.hpp"
#include "test_util.hpp"

namespace spx {
namespace {

TEST(Edt, NearestSeedMatchesBruteForce) {
  std::mt19937 rng(11);
  for (int trial = 0; trial < 6; ++trial) {
    GridShape shape;
    shape.dims = Eigen::Vector3i(3 + int(rng() % 12), 3 + int(rng() % 12), 3 + int(rng() % 12));
    std::vector<uint8_t> seed(shape.count(), 0);
    std::vector<size_t> seeds;
    const int count = 1 + int(rng() % 12);
    for (int s = 0; s < count; ++s) {
      const size_t idx = rng() % shape.count();
      seed[idx] = 1;
      seeds.push_back(idx);
    }
    const auto nearest = nearest_seed_transform(shape, seed);
    for (size_t idx = 0; idx < shape.count(); ++idx) {
      const Eigen::Vector3i c = shape.coords(idx);
      int best = std::numeric_limits<int>::max();
      for (size_t s : seeds) best = std::min(best, (shape.coords(s) - c).squaredNorm());
      ASSERT_GE(nearest[idx], 0);
      ASSERT_TRUE(seed[size_t(nearest[idx])]);
      EXPECT_EQ((shape.coords(size_t(nearest[idx])) - c).squaredNorm(), best) << "voxel " << idx;
    }
  }
}

// Past about 13 400 voxels along one side squared distances leave 32 bits: the transform's wide
// path, checked the same way on a long thin grid.
TEST(Edt, LongGridsMatchBruteForceToo) {
  GridShape shape;
  shape.dims = Eigen::Vector3i(14000, 3, 4);
  std::vector<uint8_t> seed(shape.count(), 0);
  const std::vector<size_t> seeds = {shape.index(0, 0, 0), shape.index(9000, 2, 3), shape.index(13999, 1, 0),
                                     shape.index(4500, 1, 2)};
  for (size_t s : seeds) seed[s] = 1;
  const auto nearest = nearest_seed_transform(shape, seed);
  for (size_t idx = 0; idx < shape.count(); ++idx) {
    const Eigen::Vector3i c = shape.coords(idx);
    int64_t best = std::numeric_limits<int64_t>::max();
    for (size_t s : seeds) best = std::min(best, int64_t((shape.coords(s) - c).cast<int64_t>().squaredNorm()));
    ASSERT_GE(nearest[idx], 0);
    ASSERT_EQ((shape.coords(size_t(nearest[idx])) - c).cast<int64_t>().squaredNorm(), best) << "voxel " << idx;
  }
}

TEST(Edt, NoSeedsGivesNone) {
  GridShape shape;
  shape.dims = Eigen::Vector3i(4, 5, 6);
  const auto nearest = nearest_seed_transform(shape, std::vector<uint8_t>(shape.count(), 0));
  for (int32_t n : nearest) EXPECT_EQ(n, -1);
}

// The slab rasterizer against every triangle tried at every voxel, for narrow triangles (a
// sphere) and wide ones (a box many slabs across) in one mesh: same distances, same triangles
// (the lowest index on ties).
TEST(SurfaceLayer, MatchesBruteForce) {
  TriMesh mesh = test::uv_sphere(1.0, 12, 24);
  const TriMesh box = test::box_mesh({1.2, -0.9, -0.8}, {3.4, 0.9, 0.8});
  const int offset = int(mesh.vertices.size());
  mesh.vertices.insert(mesh.vertices.end(), box.vertices.begin(), box.vertices.end());
  for (const auto& f : box.triangles) mesh.triangles.push_back(f + Eigen::Vector3i::Constant(offset));
  GridShape shape;
  shape.voxel_size = 0.13;
  shape.origin = (mesh.bounds().min() / shape.voxel_size).array().floor().cast<int>() - 2;
  shape.dims = (mesh.bounds().max() / shape.voxel_size).array().ceil().cast<int>() + 2 - shape.origin.array() + 1;
  ASSERT_GT(shape.dims.x(), 16 + 8);  // the box is wider than a slab
  GridVector<float> dist(shape.count(), std::numeric_limits<float>::infinity());
  GridVector<int32_t> closest(shape.count());
  std::fill(closest.begin(), closest.end(), -1);
  rasterize_surface_layer(mesh, shape, dist, closest);
  const double h = shape.voxel_size;
  size_t layer = 0;
  for (size_t idx = 0; idx < shape.count(); ++idx) {
    const Eigen::Vector3d p = shape.world(idx);
    int32_t best = -1;
    float best_d = 0;
    for (size_t t = 0; t < mesh.triangles.size(); ++t) {
      const auto& f = mesh.triangles[t];
      const double d2 = (closest_point_on_triangle(p, mesh.vertices[f[0]], mesh.vertices[f[1]], mesh.vertices[f[2]]) - p).squaredNorm();
      if (d2 > h * h) continue;
      const float d = float(std::sqrt(d2));
      if (best < 0 || d < best_d) {
        best = int32_t(t);
        best_d = d;
      }
    }
    ASSERT_EQ(closest[idx], best) << "voxel " << idx;
    if (best >= 0) {
      ++layer;
      ASSERT_EQ(dist[idx], best_d) << "voxel " << idx;
    }
  }
  EXPECT_GT(layer, 1000u);
}

// A sphere's field is known: |p| - R. Interior values must match within the mesh's own
// faceting error plus a fraction of a voxel.
TEST(Sdf, SphereInteriorDistancesAreAccurate) {
  const double radius = 1.0;
  const TriMesh sphere = test::uv_sphere(radius, 48, 96);
  SdfOptions opt;
  opt.resolution = 40;
  const SdfResult sdf = build_sdf(sphere, opt);
  const GridShape& s = sdf.field.shape;
  const MeshQuery query(sphere);
  double worst = 0;
  size_t inside = 0;
  for (size_t idx = 0; idx < s.count(); ++idx) {
    const Eigen::Vector3d p = s.world(idx);
    const float v = sdf.field.values[idx];
    const bool in = query.inside(p);
    if (std::abs(query.distance(p)) > 0.5 * s.voxel_size) EXPECT_EQ(v < 0, in) << p.transpose();
    if (v < 0) {
      ++inside;
      worst = std::max(worst, std::abs(-double(v) - query.distance(p)));
    }
  }
  EXPECT_EQ(inside, sdf.stats.interior_voxels);
  EXPECT_GT(inside, 10000u);
  EXPECT_LT(worst, 0.1 * s.voxel_size) << "interior distance error vs exact mesh distance";
  EXPECT_EQ(sdf.stats.defects.boundary_edges, 0u);
  EXPECT_NE(sdf.stats.sign_method.find("closed surface"), std::string::npos);
}

// depth_bound (a floor under radii) against its definition: the largest of the 8 voxels around
// a point less their offsets to it, or 0, at random points in and around a sphere's field, and
// the same from the field's held 16-bit depths.
TEST(Sdf, DepthBoundIsTheBestOfTheEightVoxelsAround) {
  SdfOptions opt;
  opt.resolution = 24;
  const DenseField field = build_sdf(test::uv_sphere(1.0, 24, 48), opt).field;
  const DepthField held = depth_field(field);
  const GridShape& g = field.shape;
  auto brute = [&](const GridShape& shape, const Eigen::Vector3d& c, auto&& depth) {
    const Eigen::Vector3d at = c / shape.voxel_size - shape.origin.cast<double>();
    double best = 0;
    for (int i = 0; i < 2; ++i)
      for (int j = 0; j < 2; ++j)
        for (int k = 0; k < 2; ++k) {
          const Eigen::Vector3i v = at.array().floor().cast<int>().matrix() + Eigen::Vector3i(i, j, k);
          if ((v.array() < 0).any() || (v.array() >= shape.dims.array()).any()) continue;
          best = std::max(best, depth(shape.index(v.x(), v.y(), v.z())) - (shape.world(v.x(), v.y(), v.z()) - c).norm());
        }
    return best;
  };
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.3, 1.3);
  size_t positive = 0;
  for (int n = 0; n < 20000; ++n) {
    const Eigen::Vector3d c(u(rng), u(rng), u(rng));
    const double whole = depth_bound(field, c);
    ASSERT_EQ(whole, brute(g, c, [&](size_t i) { return -double(field.values[i]); })) << c.transpose();
    ASSERT_EQ(depth_bound(held, c), brute(held.shape, c, [&](size_t i) { return held.unit * held.depth[i]; }))
        << c.transpose();
    positive += whole > 0;
  }
  EXPECT_GT(positive, 3000u);
}

TEST(Sdf, OpenMeshSignFollowsTheWindingNumber) {
  SPX_REQUIRE_SHARED_DATA();
  const TriMesh mesh = load_mesh(test::shared_data() + "/cylinder/rest.obj").mesh;
  SdfOptions opt;
  opt.resolution = 32;
  const SdfResult sdf = build_sdf(mesh, opt);
  EXPECT_NE(sdf.stats.sign_method.find("every voxel"), std::string::npos);
  EXPECT_GT(sdf.stats.defects.boundary_edges, 0u);
  size_t checked = 0;
  for (size_t idx = 0; idx < sdf.field.shape.count(); idx += 7) {
    const Eigen::Vector3d p = sdf.field.shape.world(idx);
    const double w = winding_number_exact(mesh, p);
    if (std::abs(w - 0.5) < 0.02) continue;  // too close to call
    EXPECT_EQ(sdf.field.values[idx] < 0, w > 0.5) << p.transpose() << " w=" << w;
    ++checked;
  }
  EXPECT_GT(checked, 1000u);
  EXPECT_GT(sdf.stats.interior_voxels, 0u);
}

// A single closed surface is signed by a flood from its inside layer voxels, one winding number
// per region: every voxel clear of 1/2 gets the winding number's side, on shapes whose inside
// splits into many regions at coarse grids (thin legs, a trunk, fertility's handles).
TEST(Sdf, ClosedSurfaceFloodFollowsTheWindingNumber) {
  SPX_REQUIRE_SHARED_DATA();
  for (const char* name : {"elephant/rest.obj", "static/fertility.off"}) {
    const TriMesh mesh = load_mesh(test::shared_data() + "/" + name).mesh;
    const WindingNumber wn(mesh);
    for (int resolution : {24, 61}) {
      SdfOptions o;
      o.resolution = resolution;
      const SdfResult sdf = build_sdf(mesh, o);
      ASSERT_NE(sdf.stats.sign_method.find("closed surface"), std::string::npos) << name;
      size_t checked = 0, wrong = 0;
      for (size_t idx = 0; idx < sdf.field.shape.count(); ++idx) {
        const double w = wn(sdf.field.shape.world(idx));
        if (std::abs(w - 0.5) < 0.05) continue;
        wrong += (sdf.field.values[idx] < 0) != (w > 0.5);
        ++checked;
      }
      EXPECT_EQ(wrong, 0u) << name << " at " << resolution;
      EXPECT_GT(checked, 10000u);
    }
  }
}

// pose-map builds a frame's field without the exterior band when it asks only for depths and
// medial voxels: the inside must be the same to the bit (an inside voxel's face neighbours are
// inside or in the surface layer).
TEST(Sdf, InsideOnlyKeepsTheInsideToTheBit) {
  std::vector<TriMesh> meshes{test::uv_sphere(1.0, 20, 40)};
  if (test::have_shared_data()) meshes.push_back(load_mesh(test::shared_data() + "/elephant/rest.obj").mesh);
  for (const TriMesh& mesh : meshes) {
    SdfOptions whole, inside_only;
    whole.resolution = inside_only.resolution = 48;
    inside_only.inside_only = true;
    const DenseField a = build_sdf(mesh, whole).field, b = build_sdf(mesh, inside_only).field;
    ASSERT_EQ(a.shape.origin, b.shape.origin);
    ASSERT_EQ(a.shape.dims, b.shape.dims);
    size_t inside = 0, band = 0;
    for (size_t idx = 0; idx < b.shape.count(); ++idx) {
      if (!(a.values[idx] < 0) && !(b.values[idx] < 0)) {
        band += a.values[idx] > b.shape.voxel_size && a.values[idx] < a.background;
        continue;
      }
      ASSERT_EQ(a.values[idx], b.values[idx]) << "voxel " << idx;
      ++inside;
    }
    EXPECT_GT(inside, 1000u);
    EXPECT_GT(band, 1000u);  // the whole field has an exterior band to leave out
  }
}

// Signing by winding numbers block by block gives every voxel the side that evaluating it
// alone gives: the open shared meshes, the truck's soup and the robot sample's open parts.
TEST(Sdf, BlockSignEqualsEveryVoxelSign) {
  std::vector<std::pair<std::string, TriMesh>> meshes;
  meshes.emplace_back("robot", test::rest_of(*test::robot_asset(test::temp_dir("robot-sign"))));
  if (test::have_shared_data())
    for (const char* name : {"cylinder/rest.obj", "broken/hemisphere.obj", "broken/truck.obj"})
      meshes.emplace_back(name, load_mesh(test::shared_data() + "/" + name).mesh);
  size_t by_blocks = 0, by_voxels = 0;
  for (const auto& [name, mesh] : meshes) {
    for (int resolution : {37, 64}) {
      SdfOptions o;
      o.resolution = resolution;
      const SdfResult blocks = build_sdf(mesh, o);
      o.sign_every_voxel = true;
      const SdfResult every = build_sdf(mesh, o);
      ASSERT_EQ(blocks.field.values.size(), every.field.values.size());
      size_t differ = 0;
      for (size_t i = 0; i < every.field.values.size(); ++i)
        differ += (blocks.field.values[i] < 0) != (every.field.values[i] < 0) || blocks.field.values[i] != every.field.values[i];
      EXPECT_EQ(differ, 0u) << name << " at " << resolution;
      by_blocks += blocks.stats.winding_evaluations;
      by_voxels += every.stats.winding_evaluations;
    }
  }
  EXPECT_LT(by_blocks, by_voxels);  // the point of it: fewer evaluations
}

TEST(Sdf, RefusesGridsThatDoNotFitAndBadOptions) {
  const TriMesh box = test::box_mesh({0, 0, 0}, {1, 1, 1});
  SdfOptions huge;
  huge.resolution = 100000;
  try {
    build_sdf(box, huge);
    FAIL();
  } catch (const GridTooLarge& e) {
    EXPECT_EQ(e.code(), ExitCode::unsupported);
    EXPECT_NE(std::string(e.what()).find("GiB"), std::string::npos) << e.what();
    // The estimate alone, for callers with other advice (pose-map: another spheres file).
    EXPECT_EQ(e.grid().rfind("a 1000", 0), 0u) << e.grid();
    EXPECT_NE(e.grid().find(" grid needs about "), std::string::npos) << e.grid();
    EXPECT_EQ(e.grid().find("coarser"), std::string::npos) << e.grid();
    EXPECT_NE(std::string(e.what()).find("coarser resolution"), std::string::npos) << e.what();
  }
  SdfOptions zero;
  zero.resolution = 0;
  EXPECT_THROW(build_sdf(box, zero), Error);
  SdfOptions negative;
  negative.voxel_size = -1;
  EXPECT_THROW(build_sdf(box, negative), Error);
}

TEST(VdbIo, RoundTripAndDeterministicBytes) {
  const std::string dir = test::temp_dir("vdb");
  SdfOptions opt;
  opt.resolution = 24;
  const SdfResult sdf = build_sdf(test::uv_sphere(0.7), opt);
  write_sdf_vdb(dir + "/a.vdb", sdf.field, {{"spx_source_mesh", "sphere"}});
  write_sdf_vdb(dir + "/b.vdb", sdf.field, {{"spx_source_mesh", "sphere"}});
  EXPECT_EQ(read_file(dir + "/a.vdb"), read_file(dir + "/b.vdb"));

  const LoadedSdf back = read_sdf_vdb(dir + "/a.vdb");
  EXPECT_EQ(back.metadata.at("spx_source_mesh"), "sphere");
  EXPECT_DOUBLE_EQ(back.field.shape.voxel_size, sdf.field.shape.voxel_size);
  // Every voxel of the original reads back with the same value (outside the active box: background).
  const GridShape& a = sdf.field.shape;
  const GridShape& b = back.field.shape;
  for (size_t idx = 0; idx < a.count(); ++idx) {
    const Eigen::Vector3i g = a.coords(idx) + a.origin - b.origin;
    float v = back.field.background;
    if ((g.array() >= 0).all() && (g.array() < b.dims.array()).all()) v = back.field.values[b.index(g.x(), g.y(), g.z())];
    ASSERT_EQ(v, sdf.field.values[idx]);
  }
}

TEST(VdbIo, RejectsFilesThatAreNotSdfs) {
  const std::string dir = test::temp_dir("vdbbad");
  write_file_atomic(dir + "/text.vdb", "hello, not a vdb\n");
  EXPECT_THROW(read_sdf_vdb(dir + "/text.vdb"), Error);
  EXPECT_THROW(read_sdf_vdb(dir + "/missing.vdb"), Error);
}

// Threads must not change a single bit: the surface layer keeps the minimum over (distance,
// triangle) whatever order the slabs run in, and every later stage writes only its own voxel.
TEST(Sdf, RepeatedBuildsAreBitIdentical) {
  SPX_REQUIRE_SHARED_DATA();
  const TriMesh mesh = load_mesh(test::shared_data() + "/static/armadillo.obj").mesh;
  SdfOptions opt;
  opt.resolution = 128;
  const SdfResult first = build_sdf(mesh, opt);
  for (int run = 0; run < 3; ++run) {
    const SdfResult again = build_sdf(mesh, opt);
    ASSERT_EQ(again.field.values.size(), first.field.values.size());
    size_t differ = 0, sign = 0;
    double largest = 0;
    for (size_t i = 0; i < first.field.values.size(); ++i) {
      const float a = first.field.values[i], b = again.field.values[i];
      if (std::memcmp(&a, &b, sizeof(float)) == 0) continue;
      ++differ;
      sign += (a < 0) != (b < 0);
      largest = std::max(largest, double(std::abs(a - b)));
    }
    EXPECT_EQ(differ, 0u) << "run " << run << ": " << sign << " signs differ, values by up to " << largest;
  }
}

}  // namespace
}  // namespace spx
