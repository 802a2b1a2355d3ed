#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <fstream>
#include <functional>
#include <iomanip>
#include <limits>
#include <memory>
#include <numeric>
#include <random>
#include <tuple>

#include <tbb/global_control.h>

#include "core/atomic_file.hpp"
#include "core/error.hpp"
#include "extract/asset.hpp"
#include "extract/pose_extract_tool.hpp"
#include "io/gltf_rig.hpp"
#include "io/pose_manifest.hpp"
#include "io/skin_file.hpp"
#include "mesh/defects.hpp"
#include "mesh/deforming_query.hpp"
#include "mesh/winding_number.hpp"
#include "mesh/mesh_query.hpp"
#include "mesh/normals.hpp"
#include "mesh/solid_boundary.hpp"
#include "mesh/split.hpp"
#include "mesh/union_distance.hpp"
#include "pack/pack.hpp"
#include "posemap/blend_hold.hpp"
#include "posemap/carry_cache.hpp"
#include "posemap/clip_radius.hpp"
#include "posemap/gap_filling.hpp"
#include "posemap/harmonic_map.hpp"
#include "pack/sphere_pack_tool.hpp"
#include "pack/candidates.hpp"
#include "pack/coverage.hpp"
#include "posemap/joint_selection.hpp"
#include "posemap/pose_map_tool.hpp"
#include "posemap/pose_cache.hpp"
#include "posemap/posemap.hpp"
#include "posemap/pose_solid.hpp"
#include "posemap/skinned_map.hpp"
#include "synthetic/synthetic.hpp"
#include "sdf/sdf.hpp"
#include "test_util.hpp"

namespace spx {
namespace {

// A sample asset's poses as pose-map takes them, each named as the asset names it.
std::vector<PoseInput> sample_poses(const SampleAsset& asset) {
  std::vector<PoseInput> out;
  for (size_t i = 0; i < asset.pose_names.size(); ++i) out.push_back({asset.pose_names[i], asset.pose_names[i], asset.pose(i)});
  return out;
}

Eigen::Affine3d some_affine() {
  Eigen::Affine3d a = Eigen::Affine3d::Identity();
  a.translate(Eigen::Vector3d(1.5, -2.0, 0.25));
  a.rotate(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()));
  a.scale(Eigen::Vector3d(1.3, 0.8, 1.1));
  a.linear() += 0.1 * (Eigen::Matrix3d() << 0, 1, 0, 0, 0, 0, 0, 0, 0).finished();  // a shear too
  return a;
}

// pose-map reproduces affine poses exactly: mapped centers within 1e-6 of the image's diagonal.
void expect_affine_exact(const TriMesh& rest, int resolution, const std::string& what) {
  const Eigen::Affine3d a = some_affine();
  TriMesh pose = rest;
  for (auto& v : pose.vertices) v = a * v;
  const SpheresFile spheres = test::pack_file(rest, resolution);
  const PoseMapResult r = pose_map(rest, "rest.obj", {{"affine", "affine.obj", pose}}, spheres, {});
  const double tol = 1e-6 * pose.diagonal();
  ASSERT_EQ(r.proxy.poses.size(), 2u);
  double worst = 0;
  for (size_t s = 0; s < spheres.spheres.size(); ++s)
    worst = std::max(worst, (r.proxy.poses[1].spheres[s].center - a * spheres.spheres[s].center).norm());
  EXPECT_LT(worst, tol) << what;
  // Radii are distances to the pose's surface, so they follow the map too (no center outside).
  EXPECT_TRUE(r.proxy.poses[1].outside.empty()) << what;
}

TEST(PoseMap, AffinePosesAreReproducedExactly) {
  expect_affine_exact(make_car().rest, 64, "car");
  expect_affine_exact(make_barrel().rest, 48, "barrel");
}

TEST(PoseMap, AffinePosesOfSharedMeshes) {
  SPX_REQUIRE_SHARED_DATA();
  expect_affine_exact(load_mesh(test::shared_data() + "/cube/rest.obj").mesh, 48, "cube");
  expect_affine_exact(load_mesh(test::shared_data() + "/elephant/rest.obj").mesh, 48, "elephant");
}

// The samples' true map f is known: the harmonic map must follow it closely. The analytic maps
// are not harmonic inside, so they differ most at the deepest part of a dent (the gap does not
// shrink with finer tets: it is the model, not the discretisation).
TEST(PoseMap, AnalyticSampleMapsClosely) {
  const SampleAsset car = make_car();
  const SpheresFile spheres = test::pack_file(car.rest, 64);
  const std::vector<PoseInput> poses = sample_poses(car);
  const PoseMapResult r = pose_map(car.rest, "rest", poses, spheres, {});
  const double diag = car.rest.diagonal();
  for (size_t i = 0; i < poses.size(); ++i) {
    double worst = 0, sum = 0;
    for (size_t s = 0; s < spheres.spheres.size(); ++s) {
      const double e = (r.proxy.poses[i + 1].spheres[s].center - car.deform(i, spheres.spheres[s].center)).norm();
      worst = std::max(worst, e);
      sum += e;
    }
    EXPECT_LT(worst, 0.025 * diag) << car.pose_names[i];
    EXPECT_LT(sum / double(spheres.spheres.size()), 0.002 * diag) << car.pose_names[i];
  }
}

TEST(PoseMap, RadiiAreDistancesToEachPoseAndSitesAreNearest) {
  const SampleAsset barrel = make_barrel();
  const SpheresFile spheres = test::pack_file(barrel.rest, 48);
  std::vector<PoseInput> poses;
  for (size_t i = 0; i < barrel.pose_names.size(); ++i) poses.push_back({barrel.pose_names[i], "", barrel.pose(i)});
  PoseMapOptions opt;
  opt.max_radius = 0.2;
  const PoseMapResult r = pose_map(barrel.rest, "rest", poses, spheres, opt);
  for (size_t i = 0; i < poses.size(); ++i) {
    const MeshQuery q(poses[i].mesh);
    for (const auto& s : r.proxy.poses[i + 1].spheres) {
      if (s.radius == 0) continue;
      EXPECT_NEAR(s.radius, std::min(0.2, q.distance(s.center)), 1e-12);
      EXPECT_TRUE(q.inside(s.center));
    }
  }
  ASSERT_EQ(r.proxy.sphere_sites.size(), spheres.spheres.size());
  for (size_t s = 0; s < spheres.spheres.size(); ++s) {
    const int site = r.proxy.sphere_sites[s];
    ASSERT_GE(site, 0);
    ASSERT_LT(site, int(r.proxy.sites.size()));
    const double d = (r.proxy.sites[size_t(site)] - spheres.spheres[s].center).norm();
    for (const auto& other : r.proxy.sites) EXPECT_LE(d, (other - spheres.spheres[s].center).norm() + 1e-12);
  }
}

TEST(PoseMap, CentersOutsideAPoseAreReportedNotKept) {
  // A narrow, deep crease pressed into a ball: the smooth interior map moves the centers under
  // it less than the surface, so they land outside (a broad squash would carry them along).
  const TriMesh rest = test::uv_sphere(1.0, 16, 32);
  TriMesh pose = rest;
  for (auto& v : pose.vertices)
    if (std::abs(v.y()) < 0.25 && v.z() > 0.3) v.z() = 0.3 + 0.05 * (v.z() - 0.3) - 0.6 * (0.25 - std::abs(v.y()));
  PackOptions small;
  small.max_radius = 0.3;  // many spheres, some deep in the cap
  const SpheresFile spheres = test::pack_file(rest, 32, small);
  const PoseMapResult r = pose_map(rest, "rest", {{"flat", "", pose}}, spheres, {});
  const MeshQuery q(pose);
  size_t outside = 0;
  for (size_t s = 0; s < spheres.spheres.size(); ++s) {
    const Sphere& m = r.proxy.poses[1].spheres[s];
    if (!q.inside(m.center)) {
      ++outside;
      EXPECT_EQ(m.radius, 0.0);
      EXPECT_NE(std::find(r.proxy.poses[1].outside.begin(), r.proxy.poses[1].outside.end(), int(s)),
                r.proxy.poses[1].outside.end());
    }
  }
  EXPECT_GT(outside, 0u) << "the flattened pose was meant to push centers out";
  EXPECT_EQ(outside, r.proxy.poses[1].outside.size());
}

TEST(TetLocator, FindsTheContainingTet) {
  const TriMesh mesh = make_barrel().rest;
  const TetMesh tets = tetrahedralize(mesh, {});
  ASSERT_GT(tets.tets.size(), 100u);
  const TetLocator locator(tets);
  for (size_t t = 0; t < tets.tets.size(); t += 13) {
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (int k = 0; k < 4; ++k) c += tets.vertices[size_t(tets.tets[t][k])] / 4;
    const auto at = locator.locate(c);
    EXPECT_EQ(at.outside, 0.0);
    EXPECT_GE(at.weights.minCoeff(), -1e-9);
    Eigen::Vector3d back = Eigen::Vector3d::Zero();
    for (int k = 0; k < 4; ++k) back += at.weights[k] * tets.vertices[size_t(tets.tets[size_t(at.tet)][k])];
    EXPECT_LT((back - c).norm(), 1e-12);
  }
}

// Spheres of a pose taken back to the rest: with the tets moved rigidly, each centre comes back
// where the inverse motion puts it (to rounding), in order; those landing outside the rest mesh
// are dropped and the rest get the rest's distance there (brute-force checks per sphere).
TEST(TetLocator, SpheresTakenBackToTheRest) {
  const TriMesh mesh = make_barrel().rest;
  const TetMesh tets = tetrahedralize(mesh, {});
  const MeshQuery rest(mesh);
  const Eigen::Vector3d shift(0.3, -0.2, 0.1);
  std::vector<Eigen::Vector3d> moved;
  for (const auto& v : tets.vertices) moved.push_back(v + shift);
  std::mt19937 rng(4);
  const Eigen::AlignedBox3d box = mesh.bounds();
  std::uniform_real_distribution<double> u(0, 1);
  SphereSet in_pose;
  for (int n = 0; n < 400; ++n)
    in_pose.push_back({box.min() + box.sizes().cwiseProduct(Eigen::Vector3d(u(rng), u(rng), u(rng))) + shift, 1.0});
  const double max_radius = 0.2;
  const SphereSet back = undeform_centres(tets, moved, in_pose, rest, max_radius);
  const TetLocator locator(tets);
  size_t k = 0;
  for (const Sphere& s : in_pose) {
    const Eigen::Vector3d c = s.center - shift;
    if (!rest.inside(c) || locator.locate(c).outside > 0) continue;
    ASSERT_LT(k, back.size());
    EXPECT_LT((back[k].center - c).norm(), 1e-9);
    EXPECT_NEAR(back[k].radius, std::min(max_radius, rest.distance(back[k].center)), 1e-12);
    ++k;
  }
  EXPECT_GT(k, 50u);
  EXPECT_EQ(k, back.size());
}

}  // namespace
}  // namespace spx

namespace spx {
namespace {

std::string to_medit(const TetMesh& m) {
  std::string s = "MeshVersionFormatted 1\nDimension 3\nVertices\n" + std::to_string(m.vertices.size()) + "\n";
  char line[160];
  for (const auto& v : m.vertices) {
    std::snprintf(line, sizeof line, "%.17g %.17g %.17g 0\n", v.x(), v.y(), v.z());
    s += line;
  }
  s += "Tetrahedra\n" + std::to_string(m.tets.size()) + "\n";
  for (const auto& t : m.tets) s += std::to_string(t[0] + 1) + " " + std::to_string(t[1] + 1) + " " + std::to_string(t[2] + 1) + " " + std::to_string(t[3] + 1) + " 1\n";
  return s + "End\n";
}

TEST(PoseMap, AcceptsUserTetsAndStillMapsAffinePosesExactly) {
  const std::string dir = test::temp_dir("medit");
  const TriMesh rest = make_barrel().rest;
  TetOptions coarse;
  coarse.size = rest.diagonal() / 12;
  const TetMesh tets = tetrahedralize(rest, coarse);
  {
    std::ofstream out(dir + "/rest.mesh");
    out << to_medit(tets);
  }
  const TetMesh back = read_medit_tets(dir + "/rest.mesh");
  ASSERT_EQ(back.tets.size(), tets.tets.size());
  EXPECT_EQ(back.boundary_faces.size(), tets.boundary_faces.size());

  Eigen::Affine3d a = Eigen::Affine3d::Identity();
  a.rotate(Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitZ())).scale(1.2);
  TriMesh pose = rest;
  for (auto& v : pose.vertices) v = a * v;
  const SpheresFile spheres = test::pack_file(rest, 40);
  PoseMapOptions opt;
  opt.tet_file = dir + "/rest.mesh";
  const PoseMapResult r = pose_map(rest, "rest", {{"turned", "", pose}}, spheres, opt);
  EXPECT_EQ(r.summary.tetrahedra, tets.tets.size());
  for (size_t s = 0; s < spheres.spheres.size(); ++s)
    EXPECT_LT((r.proxy.poses[1].spheres[s].center - a * spheres.spheres[s].center).norm(), 1e-6 * pose.diagonal());

  {
    std::ofstream bad(dir + "/bad.mesh");
    bad << "Vertices\n2\n0 0 0 0\n1 0 0 0\nTetrahedra\n1\n1 2 3 4 1\nEnd\n";
  }
  EXPECT_THROW(read_medit_tets(dir + "/bad.mesh"), Error);

  // Tets that do not fit the rest (in another unit, moved) are refused naming the file: the map
  // pinned their boundary to the nearest surface and wrote a proxy (the tenfold one, one blend site).
  const Eigen::Vector3d away = Eigen::Vector3d::UnitX() * rest.diagonal() / 5;
  for (const auto& [name, move] : std::vector<std::pair<std::string, std::function<Eigen::Vector3d(const Eigen::Vector3d&)>>>{
           {"tenfold", [](const Eigen::Vector3d& v) { return Eigen::Vector3d(10 * v); }},
           {"moved", [&](const Eigen::Vector3d& v) { return Eigen::Vector3d(v + away); }}}) {
    TetMesh other = tets;
    for (Eigen::Vector3d& v : other.vertices) v = move(v);
    const std::string path = dir + "/" + name + ".mesh";
    std::ofstream(path) << to_medit(other);
    opt.tet_file = path;
    const std::string said = test::bad_input_error([&] { pose_map(rest, "rest.obj", {{"turned", "", pose}}, spheres, opt); });
    EXPECT_NE(said.find(path + ": does not fit the rest mesh rest.obj: half its boundary's vertices lie farther than"),
              std::string::npos)
        << said;
  }
}

void expect_same_proxy(const ProxyModel& a, const ProxyModel& b) {
  ASSERT_EQ(a.poses.size(), b.poses.size());
  for (size_t i = 0; i < a.poses.size(); ++i) {
    ASSERT_EQ(a.poses[i].spheres.size(), b.poses[i].spheres.size());
    for (size_t s = 0; s < a.poses[i].spheres.size(); ++s) {
      EXPECT_EQ(a.poses[i].spheres[s].center, b.poses[i].spheres[s].center) << "pose " << i << " sphere " << s;
      EXPECT_EQ(a.poses[i].spheres[s].radius, b.poses[i].spheres[s].radius) << "pose " << i << " sphere " << s;
    }
  }
  EXPECT_EQ(a.sites, b.sites);
  EXPECT_EQ(a.sphere_sites, b.sphere_sites);
}

std::string first_line(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  return line;
}

// --cache: the first run meshes and writes the rest's tets there, the next reads them and maps to
// the same spheres to the bit (the same joint selection too); another tet size or rest meshes
// again into a file of its own; a cache file cut short is meshed again and written over.
TEST(PoseMap, TetsCacheMapsAsMeshingDoes) {
  const std::string dir = test::temp_dir("tets-cache") + "/cache/made";  // made by the run
  const SampleAsset car = make_car();
  const SpheresFile spheres = test::pack_file(car.rest, 48);
  std::vector<PoseInput> poses;
  for (size_t i = 0; i < 2; ++i) poses.push_back({car.pose_names[i], car.pose_names[i], car.pose(i)});
  PoseMapOptions opt;
  opt.tets.size = car.rest.diagonal() / 12;  // coarse: a quick test
  const PoseMapResult fresh = pose_map(car.rest, "rest", poses, spheres, opt);
  opt.cache_dir = dir;
  const PoseMapResult writing = pose_map(car.rest, "rest", poses, spheres, opt);
  EXPECT_FALSE(writing.summary.tets_from_cache);
  const std::string file = writing.summary.tet_cache;
  EXPECT_EQ(file, tets_cache_file(dir, tets_cache_key(car.rest, opt.tets)));
  EXPECT_EQ(first_line(file), "# spx tets cache " + tets_cache_key(car.rest, opt.tets));
  const PoseMapResult reading = pose_map(car.rest, "rest", poses, spheres, opt);
  EXPECT_TRUE(reading.summary.tets_from_cache);
  EXPECT_EQ(reading.summary.tetrahedra, fresh.summary.tetrahedra);
  expect_same_proxy(fresh.proxy, writing.proxy);
  expect_same_proxy(fresh.proxy, reading.proxy);

  // Another tet size: meshed again, into its own file; both are then read.
  PoseMapOptions finer = opt;
  finer.tets.size = car.rest.diagonal() / 10;
  const PoseMapResult other = pose_map(car.rest, "rest", poses, spheres, finer);
  EXPECT_FALSE(other.summary.tets_from_cache);
  EXPECT_NE(other.summary.tet_cache, file);
  EXPECT_TRUE(pose_map(car.rest, "rest", poses, spheres, finer).summary.tets_from_cache);
  // Another rest (the barrel): meshed, not mapped by the car's tets.
  const SampleAsset barrel = make_barrel();
  const SpheresFile barrel_spheres = test::pack_file(barrel.rest, 32);
  PoseMapOptions given;
  given.map_given = true;
  given.cache_dir = dir;
  EXPECT_FALSE(pose_map(barrel.rest, "barrel", {{"dent", "", barrel.pose(0)}}, barrel_spheres, given)
                   .summary.tets_from_cache);

  // The car's file cut short after its key: meshed again, the same proxy, the file whole again.
  const std::string whole = read_file(file);
  write_file_atomic(file, whole.substr(0, whole.size() / 2));
  const PoseMapResult repaired = pose_map(car.rest, "rest", poses, spheres, opt);
  EXPECT_FALSE(repaired.summary.tets_from_cache);
  expect_same_proxy(fresh.proxy, repaired.proxy);
  EXPECT_EQ(read_file(file), whole);

  // A cache folder that cannot be made (a file is in the way) fails before any work.
  write_file_atomic(dir + "/a-file", "x");
  given.cache_dir = dir + "/a-file";
  try {
    pose_map(barrel.rest, "barrel", {{"dent", "", barrel.pose(0)}}, barrel_spheres, given);
    ADD_FAILURE() << "a file as the cache folder was taken";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ExitCode::cannot_write) << e.what();
    EXPECT_NE(std::string(e.what()).find("cannot make the cache folder"), std::string::npos) << e.what();
  }
}

// The cache keeps every bit of the tets, and the bodies that got none (the report names them from
// a cached run too); its MEDIT file is one read_medit_tets reads.
TEST(TetMesh, CacheKeepsTheTetsAndTheUnmeshedBodies) {
  const std::string dir = test::temp_dir("tets-cache-file");
  const TriMesh rest = make_barrel().rest;
  TetOptions coarse;
  coarse.size = rest.diagonal() / 12;
  TetMesh tets = tetrahedralize(rest, coarse);
  tets.unmeshed_bodies = {"body 2 of 2 (12 triangles around 3.5, 0.5, 5e-05)", "body 3 of 3 (#4)"};
  const std::string key = tets_cache_key(rest, coarse);
  write_tets_cache(dir + "/t.mesh", key, tets);
  const std::optional<TetMesh> back = read_tets_cache(dir + "/t.mesh", key);
  ASSERT_TRUE(back.has_value());
  EXPECT_EQ(back->vertices, tets.vertices);
  EXPECT_EQ(back->tets, tets.tets);
  EXPECT_EQ(back->boundary_faces, tets.boundary_faces);
  EXPECT_EQ(back->unmeshed_bodies, tets.unmeshed_bodies);
  EXPECT_EQ(read_medit_tets(dir + "/t.mesh").tets, tets.tets);
  EXPECT_FALSE(read_tets_cache(dir + "/t.mesh", tets_cache_key(rest, {})).has_value());
  EXPECT_FALSE(read_tets_cache(dir + "/none.mesh", key).has_value());
  write_file_atomic(dir + "/empty.mesh", "");
  EXPECT_FALSE(read_tets_cache(dir + "/empty.mesh", key).has_value());
  write_file_atomic(dir + "/cut.mesh", "# spx tets cache " + key + "\nVertices\n3\n0 0 0 0\n");
  EXPECT_FALSE(read_tets_cache(dir + "/cut.mesh", key).has_value());
}

}  // namespace
}  // namespace spx

namespace spx {
namespace {

// Gap filling: every pose ends within the target (or says it could not), no pose gets worse,
// and every sphere of every pose stays inside that pose's mesh.
TEST(PoseMap, FillGapsBringsPosesWithinTheTarget) {
  const SampleAsset car = make_car();
  SpheresFile spheres = test::pack_file(car.rest, 64);
  const std::vector<PoseInput> poses = sample_poses(car);
  PoseMapOptions opt;
  opt.fill_gaps = true;
  opt.fill_tolerance = 0.015 * car.rest.diagonal();
  const double target = 0.015 * car.rest.diagonal();
  const PoseMapResult r = pose_map(car.rest, "rest", poses, spheres, opt);
  ASSERT_TRUE(r.summary.fill.has_value());
  const GapFilling& fill = *r.summary.fill;
  EXPECT_GT(fill.spheres_after, fill.spheres_before);
  for (size_t i = 0; i < poses.size(); ++i) {
    const double before = fill.errors_before[i + 1].max;
    const double after = r.summary.errors[i + 1].max;
    EXPECT_LE(after, before + 1e-12) << poses[i].name;
    // 1.5% is within reach at 64 voxels on every car pose: the fill must get there.
    EXPECT_TRUE(fill.poses[i].target_met) << poses[i].name;
    EXPECT_LE(after, target * (1 + 1e-9)) << poses[i].name;
    const MeshQuery q(poses[i].mesh);
    for (const auto& s : r.proxy.poses[i + 1].spheres)
      if (s.radius > 0) EXPECT_GE(q.distance(s.center), s.radius - 1e-9);
  }
  const MeshQuery rest(car.rest);
  for (const auto& s : r.proxy.poses[0].spheres) {
    EXPECT_TRUE(rest.inside(s.center));
    EXPECT_GE(rest.distance(s.center), s.radius - 1e-9);
  }
  EXPECT_EQ(r.proxy.sphere_sites.size(), r.proxy.poses[0].spheres.size());
}

// A pose's gaps: the spheres kept are the shortest prefix of the packing that meets the target
// with the spheres the pose has (checked against every prefix), inside the pose; out of reach,
// the shortest that reaches the least error any prefix does; never past the count asked.
TEST(GapFilling, KeepsTheShortestPrefixThatMeetsTheTarget) {
  const SampleAsset car = make_car();
  const TriMesh& pose = car.pose(1);
  const MeshQuery q(pose);
  SdfOptions so;
  so.voxel_size = pose.diagonal() / 48;
  const DenseField field = build_sdf(pose, so).field;
  PackOptions pack;
  pack.min_radius = 0.75 * so.voxel_size;
  SphereSet mapped = pack_spheres(field, pack, &q).spheres;
  mapped.resize(4);  // what the pose has: its largest few
  const SphereSet all = pack_spheres([&] {
    DenseField f = field;
    for (const auto& s : mapped) clear_inside(f.values, f.shape, s.center, s.radius);
    return f;
  }(), pack, &q).spheres;
  const auto error_with = [&](size_t k) {
    SphereSet u = mapped;
    u.insert(u.end(), all.begin(), all.begin() + long(k));
    return vertex_error(q.surface(), u).max;
  };
  const double target = 0.5 * (error_with(0) + error_with(all.size()));
  const PoseGaps met = pack_pose_gaps(field, mapped, q, pack, target, 0, "pose", Log::silent());
  ASSERT_TRUE(met.target_met);
  const size_t k = met.spheres.size();
  ASSERT_GT(k, 0u);
  EXPECT_LE(error_with(k), target);
  EXPECT_GT(error_with(k - 1), target);
  EXPECT_DOUBLE_EQ(met.max_error_reached, error_with(k));
  for (size_t i = 0; i < k; ++i) {
    EXPECT_EQ(met.spheres[i].center, all[i].center);
    EXPECT_GE(q.distance(met.spheres[i].center), met.spheres[i].radius - 1e-9);
  }
  EXPECT_LE(pack_pose_gaps(field, mapped, q, pack, target, 2, "pose", Log::silent()).spheres.size(), 2u);
  // Out of reach: the least error of any prefix (the whole packing's: errors only fall as
  // spheres join), by the shortest prefix that reaches it.
  const PoseGaps short_of = pack_pose_gaps(field, mapped, q, pack, 1e-9, 0, "pose", Log::silent());
  EXPECT_FALSE(short_of.target_met);
  const double least = error_with(all.size());
  const size_t n = short_of.spheres.size();
  EXPECT_LE(error_with(n), least * (1 + 1e-9));
  if (n > 0) EXPECT_GT(error_with(n - 1), least * (1 + 1e-9));
}

}  // namespace
}  // namespace spx

namespace spx {
namespace {

TriMesh translated(TriMesh m, const Eigen::Vector3d& by) {
  for (auto& v : m.vertices) v += by;
  return m;
}

TriMesh merged(const TriMesh& a, const TriMesh& b) {
  TriMesh m = a;
  const int offset = int(a.vertices.size());
  m.vertices.insert(m.vertices.end(), b.vertices.begin(), b.vertices.end());
  for (const auto& t : b.triangles) m.triangles.push_back(t + Eigen::Vector3i::Constant(offset));
  return m;
}

// Mesh_3's own first points come from rays shot from one centre: a small body off to the side
// is missed, gets no tets, and its spheres used to follow the other body's map into radius 0.
TEST(PoseMap, EveryBodyIsMeshedAndAStillBodyKeepsItsRadii) {
  const TriMesh big = test::uv_sphere(1.0, 16, 32);
  TriMesh small = test::uv_sphere(0.3, 12, 24);
  for (auto& v : small.vertices) v = Eigen::Vector3d(3 * v.x() + 4, v.y() + 0.5, v.z());
  const TriMesh rest = merged(big, small);
  TriMesh moved = big;  // the big body squashes and shifts; the small one stays put
  for (auto& v : moved.vertices) v = Eigen::Vector3d(1.2 * v.x() + 0.1, 0.9 * v.y(), v.z());
  const TriMesh pose = merged(moved, small);

  const SpheresFile spheres = test::pack_file(rest, 96);
  const PoseMapResult r = pose_map(rest, "two.obj", {{"pose", "pose.obj", pose}}, spheres, {});
  size_t still = 0;
  for (size_t s = 0; s < spheres.spheres.size(); ++s) {
    const Sphere& at_rest = r.proxy.poses[0].spheres[s];
    if (at_rest.center.x() < 2.5) continue;
    ++still;
    EXPECT_EQ(r.proxy.poses[1].spheres[s].center, at_rest.center) << "sphere " << s;
    EXPECT_EQ(r.proxy.poses[1].spheres[s].radius, at_rest.radius) << "sphere " << s;
    EXPECT_GT(at_rest.radius, 0.0);
  }
  EXPECT_GT(still, 3u);
  for (size_t cause : r.summary.zero_radius[1]) EXPECT_EQ(cause, 0u);
}

TEST(PoseMap, ABodyThatCannotBeMeshedIsNamed) {
  // A plate far thinner than the tets, even refined there: no tet's circumcentre falls in it.
  const TriMesh rest = merged(test::uv_sphere(1.0, 16, 32), test::box_mesh({3, 0, 0}, {4, 1, 0.0001}));
  const TetMesh tets = tetrahedralize(rest, {});
  ASSERT_EQ(tets.unmeshed_bodies.size(), 1u);
  EXPECT_EQ(tets.unmeshed_bodies[0].rfind("body 2 of 2 (12 triangles around 3.5, 0.5", 0), 0u) << tets.unmeshed_bodies[0];
  // A plate thin for the tets, not for a finer size in it, is meshed.
  EXPECT_TRUE(tetrahedralize(merged(test::uv_sphere(1.0, 16, 32), test::box_mesh({3, 0, 0}, {4, 1, 0.05})), {})
                  .unmeshed_bodies.empty());
}

// On a closed surface Mesh_3's signs come from a ray's crossing count instead of the winding
// number's expansions: the same tets, vertex for vertex (one body, a car, two bodies). Meshing
// again gives them again: no step stops on a clock (exudation's default limit was the
// refinement's own time, and cut it short once refinement got fast).
TEST(TetMesh, RayCountGivesTheWindingNumbersTetsEveryTime) {
  TetOptions expansions;
  expansions.winding_expansions = true;
  for (const TriMesh& mesh : {make_barrel().rest, make_car().rest,
                              merged(test::uv_sphere(1.0, 16, 32), test::box_mesh({3, 0, 0}, {4, 1, 0.5}))}) {
    const TetMesh reference = tetrahedralize(mesh, expansions);
    ASSERT_GT(reference.tets.size(), 100u);
    for (int run = 0; run < 2; ++run) {
      const TetMesh rays = tetrahedralize(mesh, {});
      ASSERT_EQ(rays.vertices.size(), reference.vertices.size()) << "run " << run;
      ASSERT_EQ(rays.tets.size(), reference.tets.size()) << "run " << run;
      for (size_t v = 0; v < rays.vertices.size(); ++v) ASSERT_EQ(rays.vertices[v], reference.vertices[v]) << v;
      for (size_t t = 0; t < rays.tets.size(); ++t) ASSERT_EQ(rays.tets[t], reference.tets[t]) << t;
    }
  }
}

// Counts the radius-0 spheres of each pose against the report, which splits them by cause.
void expect_zero_radii_counted(const PoseMapResult& r) {
  const json report = pose_map_report(r);
  for (size_t i = 0; i < r.proxy.poses.size(); ++i) {
    size_t zeros = 0;
    for (const auto& s : r.proxy.poses[i].spheres) zeros += s.radius == 0;
    const auto& z = report["poses"][i]["zero_radius"];
    EXPECT_EQ(z["total"].get<size_t>(), zeros) << r.proxy.poses[i].name;
    EXPECT_EQ(z["center_outside"].get<size_t>() + z["hole_bound"].get<size_t>() + z["other"].get<size_t>(), zeros);
    EXPECT_EQ(z["center_outside"].get<size_t>(), r.proxy.poses[i].outside.size());
  }
}

// One rule sets every radius, the rest's included: a pose identical to the rest keeps the rest
// radii exactly, on open meshes too (whose solid is bounded across the holes by a field).
void expect_rest_copy_keeps_radii(const std::string& file, int resolution, const std::vector<std::string>& extra_poses) {
  const LoadedMesh loaded = load_mesh(file);
  const TriMesh& rest = loaded.mesh;
  PackOptions pack;
  pack.field_bounds_radius = true;  // as sphere-pack does for an open solid
  const SpheresFile spheres = test::pack_file(rest, resolution, pack);
  std::vector<PoseInput> poses{{"copy", "copy.obj", rest}};
  for (const auto& p : extra_poses) poses.push_back({stem_of(p), p, load_pose(p, loaded)});
  const PoseMapResult r = pose_map(rest, file, poses, spheres, {});
  EXPECT_TRUE(r.summary.open_solid);
  size_t positive = 0;
  for (size_t s = 0; s < spheres.spheres.size(); ++s) {
    EXPECT_EQ(r.proxy.poses[1].spheres[s].radius, r.proxy.poses[0].spheres[s].radius) << file << " sphere " << s;
    EXPECT_EQ(r.proxy.poses[1].spheres[s].center, r.proxy.poses[0].spheres[s].center) << file << " sphere " << s;
    positive += r.proxy.poses[0].spheres[s].radius > 0;
  }
  EXPECT_GT(positive, spheres.spheres.size() / 2) << file;
  expect_zero_radii_counted(r);
}

TEST(PoseMap, OpenMeshesPoseEqualToRestKeepsRestRadii) {
  SPX_REQUIRE_SHARED_DATA();
  const std::string d = test::shared_data();
  expect_rest_copy_keeps_radii(d + "/cylinder/rest.obj", 64,
                               {d + "/cylinder/pose-1.obj", d + "/cylinder/pose-2.obj", d + "/cylinder/pose-3.obj",
                                d + "/cylinder/pose-4.obj"});
  expect_rest_copy_keeps_radii(d + "/broken/hemisphere.obj", 64, {});
}

// A pose that is inside out is refused naming the pose, not the rest: a closed body's (its signed
// volume, before the tets are made) and an open body's (its field encloses nothing).
TEST(PoseMap, InsideOutPoseIsNamed) {
  SPX_REQUIRE_SHARED_DATA();
  const auto refused_as = [](const TriMesh& rest, const TriMesh& pose, const SpheresFile& spheres) {
    try {
      pose_map(rest, "rest.obj", {{"mirror", "mirror.obj", pose}}, spheres, {});
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ExitCode::bad_input) << e.what();
      return e.subject();
    }
    return std::string("(not refused)");
  };
  const auto mirrored = [](TriMesh m) {
    for (auto& v : m.vertices) v.x() = -v.x();
    return m;
  };
  const SampleAsset barrel = make_barrel();
  EXPECT_EQ(refused_as(barrel.rest, mirrored(barrel.rest), test::pack_file(barrel.rest, 32, {})), "mirror.obj");
  const TriMesh open = load_mesh(test::shared_data() + "/broken/hemisphere.obj").mesh;
  PackOptions pack;
  pack.field_bounds_radius = true;
  EXPECT_EQ(refused_as(open, mirrored(open), test::pack_file(open, 48, pack)), "mirror.obj");
}

// Radii packed from the field alone (sphere-pack without --mesh) become exact distances in the
// rest pose too, as in every other pose: one source, named in the report.
TEST(PoseMap, RestRadiiComeFromTheSameSourceAsPoseRadii) {
  const SampleAsset barrel = make_barrel();
  SdfOptions sopt;
  sopt.resolution = 40;
  const SdfResult sdf = build_sdf(barrel.rest, sopt);
  SpheresFile spheres;
  spheres.spheres = pack_spheres(sdf.field, {}, nullptr).spheres;  // field radii
  spheres.voxel_size = sdf.field.shape.voxel_size;
  const PoseMapResult r = pose_map(barrel.rest, "rest", {{"copy", "", barrel.rest}}, spheres, {});
  const MeshQuery q(barrel.rest);
  size_t changed = 0;
  for (size_t s = 0; s < spheres.spheres.size(); ++s) {
    const Sphere& m = r.proxy.poses[0].spheres[s];
    EXPECT_EQ(m.radius, q.distance(m.center));
    EXPECT_EQ(m.radius, r.proxy.poses[1].spheres[s].radius);
    changed += m.radius != spheres.spheres[s].radius;
  }
  EXPECT_GT(changed, 0u);
  EXPECT_EQ(pose_map_report(r)["radius_source"].get<std::string>(), "exact distance to each pose's mesh");
}

}  // namespace
}  // namespace spx

namespace spx {
namespace {

// Joint selection: one sphere set from the rest's candidates, chosen over the rest and every
// pose. Every pose meets the tolerance, every sphere stays inside every pose, a budget is kept,
// and the set stays near the size the rest alone needs.
// sphere-pack's cover method on the rest at `resolution`, as a spheres file with its pool.
CoverSelection pack_rest(const TriMesh& rest, int resolution, const Tolerance& tolerance, SpheresFile& file,
                         size_t area_samples = 4000) {
  SdfOptions o;
  o.resolution = resolution;
  const SdfResult sdf = build_sdf(rest, o);
  const MeshQuery query(rest);
  SpherePackOptions pack;
  pack.tolerance = tolerance.length(rest.diagonal());
  pack.area_samples = area_samples;
  pack.pack.field_bounds_radius = sdf.stats.bounded_by_holes;
  CoverSelection sel = select_by_cover(sdf.field, query, pack);
  file.spheres = sel.spheres;
  file.candidates = sel.pool;
  file.voxel_size = sdf.field.shape.voxel_size;
  file.tolerance = sel.target;
  return sel;
}

void expect_joint_selection(const TriMesh& rest, const std::vector<PoseInput>& poses, const std::string& what) {
  SpheresFile file;
  const CoverSelection alone = pack_rest(rest, 96, {2, true}, file);
  PoseMapOptions opt;
  opt.tolerance = 0.02 * rest.diagonal();
  const PoseMapResult r = pose_map(rest, what, poses, file, opt);
  const double target = 0.02 * rest.diagonal();
  const size_t n = r.proxy.sphere_count();
  for (size_t i = 0; i < r.proxy.poses.size(); ++i) {
    const TriMesh& mesh = i == 0 ? rest : poses[i - 1].mesh;
    const MeshQuery q(mesh);
    EXPECT_LE(vertex_error(mesh, r.proxy.poses[i].spheres).max, target * (1 + 1e-9)) << what << " pose " << i;
    for (const Sphere& s : r.proxy.poses[i].spheres) {
      if (s.radius == 0) continue;
      EXPECT_TRUE(q.inside(s.center)) << what << " pose " << i;
      EXPECT_LE(s.radius, q.distance(s.center) + 1e-9) << what << " pose " << i;
    }
  }
  ASSERT_TRUE(r.summary.selection.has_value()) << what;
  EXPECT_EQ(r.summary.selection->cover.uncoverable() + r.summary.selection->bare_elsewhere, 0u) << what;
  EXPECT_LE(r.summary.selection->cover.lower_bound, n) << what;
  EXPECT_LE(double(n), 1.5 * double(alone.spheres.size())) << what << ": " << n << " jointly, " << alone.spheres.size()
                                                          << " for the rest alone";
  // A budget: at most that many spheres, each inside every pose, and the chosen centres moved
  // off the candidates until every pose's largest vertex error is below the least delta any
  // cover of the candidates fits the budget at.
  PoseMapOptions budget;
  budget.max_spheres = 40;
  budget.polish_rounds = 0;  // the first refinement's own bound (the polish: PolishLowersTheWorstPosesMax)
  const PoseMapResult b = pose_map(rest, what, poses, file, budget);
  EXPECT_LE(b.proxy.sphere_count(), 40u) << what;
  ASSERT_TRUE(b.summary.selection.has_value()) << what;
  EXPECT_GT(b.summary.selection->refined_moves, 0u) << what;
  for (size_t i = 0; i < b.proxy.poses.size(); ++i) {
    const TriMesh& mesh = i == 0 ? rest : poses[i - 1].mesh;
    const MeshQuery q(mesh);
    EXPECT_LT(vertex_error(mesh, b.proxy.poses[i].spheres).max, b.summary.selection->cover.least_max_delta)
        << what << " pose " << i;
    for (const Sphere& s : b.proxy.poses[i].spheres) {
      ASSERT_GT(s.radius, 0) << what << " pose " << i;
      EXPECT_TRUE(q.inside(s.center)) << what << " pose " << i;
      EXPECT_LE(s.radius, q.distance(s.center) + 1e-9) << what << " pose " << i;
    }
  }
}

TEST(PoseMap, JointSelectionOnTheCarSample) {
  const SampleAsset car = make_car();
  const std::vector<PoseInput> poses = sample_poses(car);
  expect_joint_selection(car.rest, poses, "car");
}

// --hold-over-blends on the car sample, its crumples taken as morph targets: at every blend held
// (two examples half and half, two or more crumples added) no sphere pokes out of the blended
// body, where without it some do; the centres stay and no radius grows. blends_to_hold against
// counting: 10 pairs of the 5 poses and the 11 sets of two or more of the 4 crumples, each
// summing to 1.
TEST(PoseMap, HeldOverBlendsNoSpherePokesOutBetweenTheExamples) {
  const std::vector<std::vector<double>> blends = blends_to_hold(5, true);
  ASSERT_EQ(blends.size(), 21u);
  ASSERT_EQ(blends_to_hold(5, false).size(), 10u);
  for (const auto& w : blends) EXPECT_NEAR(std::accumulate(w.begin(), w.end(), 0.0), 1.0, 1e-12);
  const SampleAsset car = make_car();
  const std::vector<PoseInput> poses = sample_poses(car);
  SpheresFile file;
  pack_rest(car.rest, 96, {2, true}, file);
  PoseMapOptions opt;
  const PoseMapResult free = pose_map(car.rest, "car", poses, file, opt);
  opt.hold_over_blends = opt.morph_targets = true;
  const PoseMapResult held = pose_map(car.rest, "car", poses, file, opt);
  ASSERT_TRUE(held.summary.blend_hold.has_value());
  EXPECT_EQ(held.summary.blend_hold->blends, 21u);
  ASSERT_EQ(free.proxy.sphere_count(), held.proxy.sphere_count());
  const double rounding = 1e-9 * car.rest.diagonal();
  double poked = 0;
  for (const auto& w : blends) {
    TriMesh mesh = car.rest;
    for (size_t v = 0; v < mesh.vertices.size(); ++v) {
      mesh.vertices[v] = w[0] * car.rest.vertices[v];
      for (size_t i = 1; i < w.size(); ++i) mesh.vertices[v] += w[i] * poses[i - 1].mesh.vertices[v];
    }
    const MeshQuery q(mesh);
    for (const PoseMapResult* r : {&free, &held})
      for (size_t j = 0; j < r->proxy.sphere_count(); ++j) {
        Eigen::Vector3d c = Eigen::Vector3d::Zero();
        double radius = 0;
        for (size_t i = 0; i < w.size(); ++i) {
          c += w[i] * r->proxy.poses[i].spheres[j].center;
          radius += w[i] * r->proxy.poses[i].spheres[j].radius;
        }
        if (!(radius > 0)) continue;
        const double over = radius + q.signed_distance(c);
        if (r == &free) poked = std::max(poked, over);
        else EXPECT_LE(over, rounding) << "sphere " << j << " pokes out at a blend";
      }
  }
  EXPECT_GT(poked, 1e-3 * car.rest.diagonal()) << "without the hold, some sphere pokes out at a blend";
  EXPECT_NEAR(held.summary.blend_hold->overshoot, poked, rounding);
  EXPECT_GT(held.summary.blend_hold->shrunk, 0u);
  for (size_t i = 0; i < held.proxy.poses.size(); ++i)
    for (size_t j = 0; j < held.proxy.sphere_count(); ++j) {
      EXPECT_EQ(held.proxy.poses[i].spheres[j].center, free.proxy.poses[i].spheres[j].center);
      EXPECT_LE(held.proxy.poses[i].spheres[j].radius, free.proxy.poses[i].spheres[j].radius);
    }
}

// A sphere whose centre leaves the body at a blend is emptied (radius 0 in every pose) and
// counted, not kept poking out: two boxes apart, the same in both examples, a sphere in the one
// at rest and in the other in the pose, whose centre half-way lies between them. A sphere that
// stays inside is left as it was. Past 8 morph targets only pairs of targets are held.
TEST(PoseMap, BlendHoldEmptiesASphereWhoseCentreLeavesTheBody) {
  TriMesh body = test::box_mesh({0, 0, 0}, {1, 1, 1});
  const TriMesh other = test::box_mesh({3, 0, 0}, {4, 1, 1});
  for (const Eigen::Vector3i& t : other.triangles) body.triangles.push_back(t + Eigen::Vector3i::Constant(8));
  body.vertices.insert(body.vertices.end(), other.vertices.begin(), other.vertices.end());
  ProxyModel proxy;
  proxy.poses.push_back({"rest", "rest.obj", {{{0.5, 0.5, 0.5}, 0.25}, {{0.5, 0.5, 0.5}, 0.4}}, {}});
  proxy.poses.push_back({"moved", "moved.obj", {{{3.5, 0.5, 0.5}, 0.25}, {{0.5, 0.5, 0.5}, 0.4}}, {}});
  const BlendHold held = hold_over_blends(proxy, {&body, &body}, blends_to_hold(2, false));
  EXPECT_EQ(held.blends, 1u);
  EXPECT_EQ(held.emptied, 1u);
  EXPECT_EQ(held.shrunk, 0u);
  EXPECT_NEAR(held.overshoot, 0.25 + 1.0, 1e-9) << "half-way, the centre is 1 from either box";
  for (const ProxyPose& p : proxy.poses) {
    EXPECT_EQ(p.spheres[0].radius, 0.0) << p.name;
    EXPECT_EQ(p.spheres[1].radius, 0.4) << p.name;
  }
  // 10 targets: the 55 pairs of the 11 poses half and half, and the 45 pairs of targets at 1.
  const std::vector<std::vector<double>> many = blends_to_hold(11, true);
  ASSERT_EQ(many.size(), 100u);
  EXPECT_EQ(many.back()[0], -1.0);
  EXPECT_EQ(std::count(many.back().begin(), many.back().end(), 1.0), 2);
}

// Budget mode's polish over every pose: the refined spheres offered to the cover again and the
// new cover refined. On the car sample at 64 spheres a polished set is kept: its worst pose's max
// vertex error is lower than the first refinement's (no polish), by the same measure the tool
// reports, and its spheres are inside every pose.
TEST(PoseMap, PolishLowersTheWorstPosesMax) {
  const SampleAsset car = make_car();
  const std::vector<PoseInput> poses = sample_poses(car);
  SpheresFile file;
  pack_rest(car.rest, 96, {2, true}, file);
  auto worst_max = [&](const PoseMapResult& r) {
    double worst = 0;
    for (size_t i = 0; i < r.proxy.poses.size(); ++i)
      worst = std::max(worst, vertex_error(i == 0 ? car.rest : poses[i - 1].mesh, r.proxy.poses[i].spheres).max);
    return worst;
  };
  PoseMapOptions opt;
  opt.max_spheres = 64;
  opt.polish_rounds = 0;
  const PoseMapResult first = pose_map(car.rest, "car", poses, file, opt);
  opt.polish_rounds = 2;
  const PoseMapResult polished = pose_map(car.rest, "car", poses, file, opt);
  ASSERT_TRUE(first.summary.selection.has_value() && polished.summary.selection.has_value());
  EXPECT_EQ(first.summary.selection->polished, 0u);
  EXPECT_GT(polished.summary.selection->polished, 0u);
  EXPECT_LE(polished.proxy.sphere_count(), 64u);
  EXPECT_LT(worst_max(polished), worst_max(first));
  for (size_t i = 0; i < polished.proxy.poses.size(); ++i) {
    const MeshQuery q(i == 0 ? car.rest : poses[i - 1].mesh);
    for (const Sphere& s : polished.proxy.poses[i].spheres) {
      ASSERT_GT(s.radius, 0) << "pose " << i;
      EXPECT_TRUE(q.inside(s.center)) << "pose " << i;
      EXPECT_LE(s.radius, q.distance(s.center) + 1e-9) << "pose " << i;
    }
  }
}

TEST(PoseMap, JointSelectionOnSharedPoseSets) {
  SPX_REQUIRE_SHARED_DATA();
  for (const std::string set : {"cube", "elephant"}) {
    const std::string d = test::shared_data() + "/" + set + "/";
    const LoadedMesh rest = load_mesh(d + "rest.obj");
    std::vector<PoseInput> poses;
    for (const auto& entry : std::filesystem::directory_iterator(d)) {
      const std::string name = entry.path().filename().string();
      if (name.rfind("pose-", 0) == 0 && entry.path().extension() == ".obj")
        poses.push_back({stem_of(name), entry.path().string(), load_pose(entry.path().string(), rest)});
    }
    std::sort(poses.begin(), poses.end(), [](const PoseInput& a, const PoseInput& b) { return a.name < b.name; });
    ASSERT_EQ(poses.size(), 4u) << set;
    expect_joint_selection(rest.mesh, poses, set);
  }
}

// Poses far denser than the tolerance (the barrel and its poses split 64-fold, 43 000 vertices,
// at 8 %): each pose is covered on its vertices an eighth of the tolerance apart, the vertices
// that cover leaves past the tolerance join (on this instance some), and every vertex of every
// pose ends within it, every sphere inside. --every-vertex solves on every vertex from the start,
// in as many spheres give or take a few.
TEST(PoseMap, SpacedJointSelectionLeavesNoVertexPastTheTolerance) {
  const SampleAsset barrel = make_barrel();
  const TriMesh rest = split_at_midpoints(barrel.rest, 3);
  std::vector<PoseInput> poses;
  for (size_t i = 0; i < barrel.pose_names.size(); ++i)
    poses.push_back({barrel.pose_names[i], barrel.pose_names[i], split_at_midpoints(barrel.pose(i), 3)});
  SpheresFile file;
  pack_rest(rest, 48, {8, true}, file, 500);
  PoseMapOptions opt;
  opt.tolerance = 0.08 * rest.diagonal();
  opt.area_samples = 500;
  const PoseMapResult r = pose_map(rest, "barrel", poses, file, opt);
  ASSERT_TRUE(r.summary.selection.has_value());
  const JointSelection& sel = *r.summary.selection;
  EXPECT_EQ(sel.spaced_frames, poses.size() + 1) << "the poses' vertices were not spaced";
  EXPECT_GT(sel.spaced_joined, 0u) << "the first cover left no vertex bare on this instance";
  EXPECT_LT(sel.samples, (poses.size() + 1) * rest.vertices.size() / 2);
  EXPECT_EQ(sel.limited_by, Limit::tolerance);
  for (size_t i = 0; i < r.proxy.poses.size(); ++i) {
    const TriMesh& mesh = i == 0 ? rest : poses[i - 1].mesh;
    EXPECT_LE(vertex_error(mesh, r.proxy.poses[i].spheres).max, opt.tolerance * (1 + 1e-9)) << "pose " << i;
    const MeshQuery q(mesh);
    for (const Sphere& s : r.proxy.poses[i].spheres) {
      if (s.radius == 0) continue;
      EXPECT_TRUE(q.inside(s.center)) << "pose " << i;
      EXPECT_LE(s.radius, q.distance(s.center) + 1e-9) << "pose " << i;
    }
  }
  opt.every_vertex = true;
  const PoseMapResult every = pose_map(rest, "barrel", poses, file, opt);
  ASSERT_TRUE(every.summary.selection.has_value());
  EXPECT_EQ(every.summary.selection->spaced_frames, 0u);
  EXPECT_LE(r.proxy.sphere_count(), every.proxy.sphere_count() + 3);
}

// sphere-pack's --min-radius, kept in the spheres file, holds for pose-map's selection too: the
// poses' own candidates and the balls through their vertices had brought spheres below it back.
// Tolerance and budget (whose refinement moves the centres) alike, and --min-radius given to
// pose-map instead; every rest sphere at least that large, the smaller candidates counted.
TEST(PoseMap, SelectionKeepsTheSpheresFilesMinRadius) {
  const SampleAsset car = make_car();
  const std::vector<PoseInput> poses = sample_poses(car);
  SpheresFile file;
  pack_rest(car.rest, 64, {2, true}, file);
  auto smallest = [](const PoseMapResult& r) {
    double least = std::numeric_limits<double>::infinity();
    for (const Sphere& s : r.proxy.poses[0].spheres) least = std::min(least, s.radius);
    return least;
  };
  const PoseMapResult free = pose_map(car.rest, "car", poses, file, {});
  const double limit = 0.25;
  ASSERT_LT(smallest(free), limit) << "no sphere below the limit to keep out on this instance";
  ASSERT_EQ(free.summary.selection->below_min_radius, 0u);
  SpheresFile limited = file;
  limited.min_radius_asked = limit;
  PoseMapOptions budget;
  budget.max_spheres = 30;
  PoseMapOptions asked;
  asked.min_radius = limit;
  for (const auto& [what, f, opt] : {std::tuple{"the file's, a tolerance", &limited, PoseMapOptions{}},
                                     std::tuple{"the file's, a budget", &limited, budget},
                                     std::tuple{"pose-map's own", &file, asked}}) {
    const PoseMapResult r = pose_map(car.rest, "car", poses, *f, opt);
    ASSERT_TRUE(r.summary.selection.has_value()) << what;
    EXPECT_GE(smallest(r), limit) << what;
    EXPECT_GT(r.summary.selection->below_min_radius, 0u) << what;
    EXPECT_EQ(r.summary.selection_min_radius, limit) << what;
    if (opt.max_spheres > 0) EXPECT_LE(r.proxy.sphere_count(), opt.max_spheres) << what;
  }
  PoseMapOptions too_large;
  too_large.min_radius = 10;
  too_large.max_radius = 1;
  EXPECT_THROW(pose_map(car.rest, "car", poses, file, too_large), OptionError);
}

TEST(PoseMap, JointSelectionNeedsCandidates) {
  const SampleAsset barrel = make_barrel();
  const SpheresFile greedy = test::pack_file(barrel.rest, 32);  // no candidate pool
  PoseMapOptions opt;
  opt.tolerance = 0.02 * barrel.rest.diagonal();
  EXPECT_THROW(pose_map(barrel.rest, "rest", {{"copy", "", barrel.rest}}, greedy, opt), OptionError);
}

}  // namespace
}  // namespace spx

namespace spx {
namespace {

// A rigged asset's clip through pose-extract (every `every`th frame, or `times`) into `dir`, with its rig, the
// skin's weights found for the rest as pose-map finds them.
struct ExtractedClip {
  PoseManifest manifest;
  LoadedMesh rest;
  std::vector<PoseInput> poses;
  SkinFile skin;
};
ExtractedClip extract_clip(const std::string& asset, const std::string& dir, int every,
                           const std::vector<double>& times = {}) {
  PoseExtractOptions extract;
  extract.animation = "0";
  extract.every = every;
  extract.times = times;
  json report;
  pose_extract_files(asset, dir, extract, Log::silent(), report);
  ExtractedClip clip;
  clip.manifest = read_pose_manifest(dir + "/poses.json");
  clip.rest = load_mesh(dir + "/rest.obj");
  for (const auto& p : clip.manifest.poses) clip.poses.push_back({p.name, p.file, load_pose(dir + "/" + p.file, clip.rest)});
  clip.skin = read_skin_file(dir + "/skin.json");
  clip.skin.vertex_weights = weights_for_vertices(clip.skin, clip.rest.mesh.vertices, 1e-6 * clip.rest.mesh.diagonal(), "skin");
  return clip;
}

// RiggedSimple's bend at `frames` times evenly over its 2 seconds (the shared data's).
ExtractedClip rigged_simple_frames(const std::string& name, int frames) {
  std::vector<double> times;
  for (int k = 1; k <= frames; ++k) times.push_back(2.0 * k / frames);
  return extract_clip(test::shared_data() + "/rigged-simple/RiggedSimple.glb", test::temp_dir(name), 1, times);
}

// The robot sample's walk.
ExtractedClip robot_clip(int every) {
  const std::string dir = test::temp_dir("robot-clip-" + std::to_string(every));
  write_file_atomic(dir + "/robot.glb", encode_rig_glb(make_robot()));
  return extract_clip(dir + "/robot.glb", dir + "/poses", every);
}

// Open and multi-part bodies at the defaults: the selection's claim is true of the file. Each
// pose's max vertex error, measured here by brute force, is within the selection's target when
// it says it met it; no sphere is 0 in half the poses or more (dead weight for the host); every
// centre is inside by the tools' rule, the exact winding number above 1/2.
// `percent`: the tolerance both tools are given; `samples`: their area samples.
PoseMapResult expect_claim_holds(const TriMesh& rest, const std::vector<PoseInput>& poses, const std::string& what,
                                 const SkinFile* skin = nullptr, int resolution = 64,
                                 double percent = kDefaultTolerancePercent, size_t samples = 4000) {
  SpheresFile file;
  const CoverSelection alone = pack_rest(rest, resolution, {percent, true}, file, samples);
  PoseMapOptions opt;
  opt.area_samples = samples;
  const PoseMapResult r = pose_map(rest, what, poses, file, opt, Log::silent(), skin);
  const json selection = pose_map_report(r)["selection"];
  const double target = selection["target"].get<double>();
  EXPECT_EQ(target, alone.target) << what;
  // Met where every vertex (the tolerance is on them) is within reach; samples between them may not be.
  const bool met = selection["limited_by"].get<std::string>() == "met the tolerance";
  EXPECT_EQ(met, selection["uncoverable_vertices"].get<size_t>() == 0) << what;
  EXPECT_LE(selection["uncoverable_vertices"].get<size_t>(), selection["uncoverable_samples"].get<size_t>()) << what;
  const size_t n = r.proxy.sphere_count(), pose_count = r.proxy.poses.size();
  std::vector<size_t> zero(n, 0);
  size_t no_solid = 0;  // vertices past the target with the winding number under 1/2 on both sides
  for (size_t i = 0; i < pose_count; ++i) {
    const TriMesh& mesh = i == 0 ? rest : poses[i - 1].mesh;
    const SphereSet& spheres = r.proxy.poses[i].spheres;
    const WindingNumber wn(mesh);
    const TriMesh surface = solid_surface(mesh);
    const std::vector<Eigen::Vector3d> normals = angle_weighted_normals(surface, face_normals(surface));
    const double probe = kWallProbe * mesh.diagonal();
    double worst = 0;
    for (size_t k = 0; k < surface.vertices.size(); ++k) {
      const Eigen::Vector3d& v = surface.vertices[k];
      double gap = std::numeric_limits<double>::infinity();
      for (const Sphere& s : spheres)
        if (s.radius > 0) gap = std::min(gap, (v - s.center).norm() - s.radius);
      worst = std::max(worst, std::abs(gap));
      if (gap > target && !skin)
        no_solid += winding_number_exact(mesh, v - probe * normals[k]) <= 0.5 &&
                    winding_number_exact(mesh, v + probe * normals[k]) <= 0.5;
    }
    if (met) EXPECT_LE(worst, target * (1 + 1e-9)) << what << " pose " << i;
    // Not met, and not skinned: the vertices out of reach are as near as any candidate comes.
    if (!met && !skin)
      EXPECT_LE(worst, selection["least_reachable_delta"].get<double>() * (1 + 1e-9)) << what << " pose " << i;
    EXPECT_EQ(worst, r.summary.errors[i].max) << what << " pose " << i;
    for (size_t s = 0; s < n; ++s) {
      if (!(spheres[s].radius > 0)) {
        ++zero[s];
        continue;
      }
      EXPECT_GT(winding_number_exact(mesh, spheres[s].center), 0.5) << what << " pose " << i << " sphere " << s;
      // The whole sphere inside the solid, walls inside it crossed or not: its points in 26
      // directions, the field's margin in from its surface (across an open mesh's holes the
      // solid is the field's, to a tenth of a voxel: slivers of outside thinner than that, as
      // in the truck's soup, are not seen) and 1% besides.
      const double in = std::max(0.0, 0.99 * spheres[s].radius - kFieldMargin * file.voxel_size);
      size_t out = 0;
      for (int d = 0; d < 27; ++d) {
        const Eigen::Vector3d dir(d % 3 - 1, d / 3 % 3 - 1, d / 9 - 1);
        if (d != 13) out += !wn.inside(spheres[s].center + in * dir.normalized());
      }
      EXPECT_EQ(out, 0u) << what << " pose " << i << " sphere " << s;
    }
  }
  for (size_t s = 0; s < n; ++s) EXPECT_LT(2 * zero[s], pose_count) << what << " sphere " << s << " is 0 in " << zero[s];
  // Of the vertices out of reach, those with no solid beside them in their pose (no field reaches
  // them, and the report says so rather than naming a finer one): as brute force counts them.
  if (!skin) {
    EXPECT_EQ(selection["uncoverable_vertices_with_no_solid_beside"].get<size_t>(), no_solid) << what;
    if (no_solid > 0 && no_solid == selection["uncoverable_vertices"].get<size_t>())
      EXPECT_EQ(selection["limited_by"].get<std::string>().rfind("flat parts", 0), 0u) << what;
  }
  return r;
}

TEST(PoseMap, OpenArticulatedSampleMeetsItsClaimInEveryFrame) {
  const std::string dir = test::temp_dir("robot");
  const std::unique_ptr<Asset> robot = test::robot_asset(dir);
  const Asset& asset = *robot;
  const TriMesh rest = test::rest_of(asset);
  ASSERT_FALSE(find_defects(rest).watertight());
  std::vector<PoseInput> poses;
  for (int k = 2; k < 24; k += 4) {
    const std::string name = "frame-" + std::to_string(k);
    poses.push_back({name, name, {asset.at_time(0, asset.clips()[0].frames[size_t(k)]), rest.triangles}});
  }
  expect_claim_holds(rest, poses, "robot");
}

// The same walk with its rig, as pose-extract gives it: the spheres follow the skin, one radius
// each. Parts overlap and move against each other at every joint (the thighs sweep through the
// pelvis): radii are to the solid's boundary, not to the walls inside it, so every frame is met.
TEST(PoseMap, SkinnedOpenArticulatedSampleMeetsTheToleranceInEveryFrame) {
  const ExtractedClip clip = robot_clip(4);
  // At the tools' default resolution (at 64 cells the robot's thin parts hold too few candidates).
  const PoseMapResult r = expect_claim_holds(clip.rest.mesh, clip.poses, "skinned robot", &clip.skin, 128);
  ASSERT_TRUE(r.summary.selection.has_value());
  EXPECT_EQ(r.summary.selection->limited_by, Limit::tolerance);
  EXPECT_FALSE(r.proxy.skin.joints.empty());
  // The walls it measured around are named, pose by pose (the pelvis inside the torso, the
  // limbs' tubes reaching into the pelvis and the torso).
  const json report = pose_map_report(r);
  for (const auto& pose : report["poses"]) EXPECT_GT(pose["walls_inside"]["left_out"].get<size_t>(), 0u);
}

// A skinned clip split at its edges' midpoints `times` over, with its skin (split_skinned).
ExtractedClip split_clip(ExtractedClip clip, int times) {
  SplitSkinned split = split_skinned(clip.rest.mesh, std::move(clip.skin), times);
  clip.rest.mesh = std::move(split.rest);
  clip.skin = std::move(split.skin);
  for (size_t k = 0; k < clip.poses.size(); ++k) clip.poses[k].mesh = std::move(split.poses[k]);
  return clip;
}

// A rigged body far denser than the tolerance (the elephant's walk split 4-fold, 48 256
// triangles, at 8 %): each frame selected on is covered on its vertices an eighth of the tolerance
// apart. With 4 frames, every one selected on, every vertex of theirs is then checked and those
// left near or past the tolerance join; over 13 the other frames' samples join round by round and
// the problem is compacted, its checks then reading every vertex of every frame. Either way the
// claim holds at every vertex of every frame, every sphere inside.
TEST(PoseMap, SpacedSkinnedSelectionLeavesNoVertexPastTheTolerance) {
  SPX_REQUIRE_SHARED_DATA();
  for (const int every : {150, 38}) {
    const std::string dir = test::temp_dir("elephant-dense-" + std::to_string(every));
    const ExtractedClip clip =
        split_clip(extract_clip(test::shared_data() + "/elephant/elephant-rigged.glb", dir, every), 1);
    const std::string what = "dense elephant, " + std::to_string(clip.poses.size()) + " frames";
    const PoseMapResult r = expect_claim_holds(clip.rest.mesh, clip.poses, what, &clip.skin, 64, 8, 500);
    ASSERT_TRUE(r.summary.selection.has_value());
    const JointSelection& sel = *r.summary.selection;
    EXPECT_EQ(sel.limited_by, Limit::tolerance) << what;
    EXPECT_EQ(sel.spaced_frames, sel.frames.size()) << what << ": the frames' vertices were not spaced";
    if (sel.frames.size() == clip.poses.size() + 1) {
      EXPECT_GT(sel.spaced_joined, 0u) << what << ": the first cover left no vertex near the tolerance";
      EXPECT_LT(sel.samples, (clip.poses.size() + 1) * clip.rest.mesh.vertices.size() / 2) << what;
    } else {
      EXPECT_GT(sel.samples_elsewhere, 0u) << what << ": no other frame's samples joined";
    }
  }
}

// Asked for half the tolerance its spheres file was packed for, the skinned robot's open parts
// leave vertices out of reach: across an open mesh's holes every radius is its field's bound,
// balls through the vertices included, so the report names the field's resolution (a finer
// field raises the bound), not the motion.
TEST(PoseMap, OpenPartsOutOfReachNameTheResolution) {
  const ExtractedClip clip = robot_clip(6);
  SpheresFile file;
  pack_rest(clip.rest.mesh, 64, {kDefaultTolerancePercent, true}, file);
  PoseMapOptions opt;
  opt.tolerance = 0.01 * clip.rest.mesh.diagonal();
  const PoseMapResult r = pose_map(clip.rest.mesh, "robot", clip.poses, file, opt, Log::silent(), &clip.skin);
  ASSERT_TRUE(r.summary.selection.has_value());
  EXPECT_GT(r.summary.selection->touched, 0u);
  EXPECT_GT(r.summary.selection->vertices_out_of_reach, 0u);
  EXPECT_EQ(r.summary.selection->limited_by, Limit::resolution);
}

// The poses' solids are built beside the tets and the map (pose_map), and the selection runs on
// both cores: a skinned, open clip (its fields kept to bound radii) gives the same proxy, bit for
// bit, on one thread.
TEST(PoseMap, SkinnedClipIsTheSameOnOneThread) {
  const ExtractedClip clip = robot_clip(6);
  SpheresFile file;
  pack_rest(clip.rest.mesh, 64, {kDefaultTolerancePercent, true}, file);
  const PoseMapResult both = pose_map(clip.rest.mesh, "robot", clip.poses, file, {}, Log::silent(), &clip.skin);
  PoseMapResult one;
  {
    tbb::global_control single(tbb::global_control::max_allowed_parallelism, 1);
    one = pose_map(clip.rest.mesh, "robot", clip.poses, file, {}, Log::silent(), &clip.skin);
  }
  ASSERT_GT(both.proxy.sphere_count(), 0u);
  expect_same_proxy(both.proxy, one.proxy);
  EXPECT_EQ(both.proxy.skin.spheres.size(), one.proxy.skin.spheres.size());
}

// A pool made again from another's voxels and the candidates it grew (what pose-map's cache
// keeps, through its file) offers what the first would, ask for ask, though it grows only those
// the first had not: grown ones given back are offered exactly when a grown one would be.
TEST(PoseMap, PoseCacheFileOffersAsTheField) {
  const TriMesh mesh = make_barrel().rest;
  SdfOptions o;
  o.resolution = 48;
  const DenseField field = build_sdf(mesh, o).field;
  const MeshQuery query(mesh);
  const CandidateOptions options;
  const std::vector<Eigen::Vector3d> samples = surface_samples(mesh, 300, 7);
  const double reach = 0.01 * mesh.diagonal();
  auto points = [&](size_t from) {
    return std::vector<Eigen::Vector3d>(samples.begin() + long(from), samples.begin() + long(from + 40));
  };
  CandidatesOnDemand first(field, options);
  first.offer_near(points(0), reach, query);
  ASSERT_GT(first.grown().size(), 0u);

  const std::string path = test::temp_dir("pose-cache-unit") + "/pose.bin";
  CachedPoseField kept;
  kept.voxels = first.voxels();
  kept.voxel_size = first.voxel_size();
  kept.grown = first.grown();
  kept.depths = depth_field(field);
  write_pose_cache(path, "k1", kept);
  EXPECT_FALSE(read_pose_cache(path, "k2").has_value()) << "another key's file was read";
  const std::optional<CachedPoseField> back = read_pose_cache(path, "k1");
  ASSERT_TRUE(back && back->voxels && back->depths);
  EXPECT_EQ(back->depths->depth, kept.depths->depth);
  EXPECT_EQ(back->depths->shape.dims, kept.depths->shape.dims);
  EXPECT_EQ(back->depths->shape.origin, kept.depths->shape.origin);
  EXPECT_EQ(back->depths->shape.voxel_size, kept.depths->shape.voxel_size);
  EXPECT_EQ(back->depths->unit, kept.depths->unit);

  CandidatesOnDemand again(*back->voxels, back->voxel_size, options);
  again.give_grown(back->grown);
  CandidatesOnDemand fresh(field, options);
  for (const size_t from : {size_t(0), size_t(100), size_t(200), size_t(0)}) {
    const SphereSet want = fresh.offer_near(points(from), reach, query);
    const SphereSet got = again.offer_near(points(from), reach, query);
    ASSERT_EQ(got.size(), want.size()) << "from " << from;
    for (size_t n = 0; n < got.size(); ++n) {
      EXPECT_EQ(got[n].center, want[n].center);
      EXPECT_EQ(got[n].radius, want[n].radius);
    }
  }
  EXPECT_EQ(again.grown().size(), fresh.grown().size());
}

// RiggedSimple's clip at `frames` times and its rest's spheres at `resolution` cells: pose_map
// on them with the options given.
struct RiggedRun {
  ExtractedClip clip;
  SpheresFile file;
  RiggedRun(const std::string& name, int frames, int resolution) : clip(rigged_simple_frames(name, frames)) {
    pack_rest(clip.rest.mesh, resolution, {kDefaultTolerancePercent, true}, file);
  }
  PoseMapResult operator()(const PoseMapOptions& opt) const {
    return pose_map(clip.rest.mesh, "rigged", clip.poses, file, opt, Log::silent(), &clip.skin);
  }
};

// Skinned, the one radius each sphere keeps in every frame is at least the file's --min-radius.
TEST(PoseMap, SkinnedSelectionKeepsTheSpheresFilesMinRadius) {
  SPX_REQUIRE_SHARED_DATA();
  RiggedRun run("skinned-min-radius", 4, 64);
  const PoseMapResult free = run({});
  double least = std::numeric_limits<double>::infinity();
  for (const Sphere& s : free.proxy.poses[0].spheres) least = std::min(least, s.radius);
  const double limit = 0.15;
  ASSERT_LT(least, limit) << "no sphere below the limit to keep out on this instance";
  run.file.min_radius_asked = limit;
  const PoseMapResult r = run({});
  ASSERT_TRUE(r.summary.selection.has_value());
  EXPECT_GT(r.summary.selection->below_min_radius, 0u);
  for (size_t i = 0; i < r.proxy.poses.size(); ++i)
    for (const Sphere& s : r.proxy.poses[i].spheres) EXPECT_GE(s.radius, limit) << "frame " << i;
}

// A cache of pose-map's over three runs: none without it, written by the first run with it,
// read by the next, which makes nothing again.
void expect_written_then_read(const PoseMapResult& fresh, const PoseMapResult& writing, const PoseMapResult& reading,
                              PoseMapSummary::CacheUse PoseMapSummary::*use) {
  EXPECT_TRUE((fresh.summary.*use).file.empty());
  EXPECT_FALSE((writing.summary.*use).file.empty());
  EXPECT_GT((writing.summary.*use).made, 0u);
  EXPECT_EQ((reading.summary.*use).file, (writing.summary.*use).file);
  EXPECT_EQ((reading.summary.*use).made, 0u) << "what the cache held was made again";
  EXPECT_GT((reading.summary.*use).read, 0u);
}

// The carries' cache asks `make` only for the centres it lacks (each once, by its bits), gives
// back what was made to the bit after a round trip through its file, and takes a file of
// another key or kind, or cut short, as empty.
TEST(PoseMap, CarryCacheAsksOnlyForTheCentresItLacks) {
  const std::string path = test::temp_dir("carry-cache-unit") + "/carry.bin";
  auto choice_of = [](const Eigen::Vector3d& c) {
    SkinnedMap::Choice out;
    out.influence.joint = {int(c.x() * 10) % 7, 1, 2, 3};
    out.influence.weight = {0.5f, 0.25f, 0.125f, 0.125f};
    out.influence.bind = c * 3;
    out.radius = c.norm() / 3;  // not a round number: every bit must come back
    return out;
  };
  size_t asked = 0;
  SphereSet first, second;
  for (int k = 0; k < 20; ++k) first.push_back({Eigen::Vector3d(0.1 * k, 0.7 / (k + 1), -0.3 * k), 0});
  for (int k = 10; k < 30; ++k) second.push_back({Eigen::Vector3d(0.1 * k, 0.7 / (k + 1), -0.3 * k), 0});
  auto choices = [&](CarryCache& cache, const SphereSet& set) {
    std::vector<CarryCache::Key> keys;
    for (const Sphere& s : set) keys.push_back(carry_key(s.center));
    return cache.values(keys, [&](const std::vector<size_t>& missing) {
      asked += missing.size();
      std::vector<SkinnedMap::Choice> out;
      for (size_t m : missing) out.push_back(choice_of(set[m].center));
      return out;
    });
  };
  auto expect_choices = [&](const SphereSet& set, const std::vector<SkinnedMap::Choice>& got) {
    ASSERT_EQ(got.size(), set.size());
    for (size_t n = 0; n < set.size(); ++n) {
      const SkinnedMap::Choice want = choice_of(set[n].center);
      EXPECT_EQ(got[n].influence.joint, want.influence.joint);
      EXPECT_EQ(got[n].influence.weight, want.influence.weight);
      EXPECT_EQ(got[n].influence.bind, want.influence.bind);
      EXPECT_EQ(got[n].radius, want.radius);
    }
  };
  {
    CarryCache cache(path, "carries", "k1");
    expect_choices(first, choices(cache, first));
    expect_choices(second, choices(cache, second));
    EXPECT_EQ(asked, 30u) << "a centre the cache held was asked again";
    EXPECT_EQ(cache.read(), 10u);
    EXPECT_EQ(cache.made(), 30u);
    cache.save();
  }
  asked = 0;
  {
    CarryCache cache(path, "carries", "k1");
    expect_choices(second, choices(cache, second));
    EXPECT_EQ(asked, 0u);
  }
  CarryCache other_key(path, "carries", "k2"), other_kind(path, "held radii", "k1");
  EXPECT_EQ(choices(other_key, first).size(), first.size());
  EXPECT_EQ(asked, first.size()) << "another key's file was read";
  choices(other_kind, first);
  EXPECT_EQ(asked, 2 * first.size()) << "another kind's file was read";
  const std::string whole = read_file(path);
  write_file_atomic(path, whole.substr(0, whole.size() - 1));
  asked = 0;
  CarryCache cut(path, "carries", "k1");
  choices(cut, first);
  EXPECT_EQ(asked, first.size()) << "a file cut short was read";
}

// A held radius's key is everything ClipRadius::least walks: two inputs that differ in any one
// joint, weight, bind coordinate or the radius have different keys.
TEST(PoseMap, HeldRadiusKeyTellsEveryInputApart) {
  SkinInfluence in;
  in.joint = {3, 1, 0, 7};
  in.weight = {0.5f, 0.25f, 0.2f, 0.05f};
  in.bind = {0.1, -2.0, 3.5};
  const HeldCache::Key base = held_key(in, 0.75);
  std::vector<HeldCache::Key> changed;
  for (int k = 0; k < 4; ++k) {
    SkinInfluence j = in, w = in;
    j.joint[size_t(k)] += 1;
    w.weight[size_t(k)] = std::nextafter(w.weight[size_t(k)], 1.0f);
    changed.push_back(held_key(j, 0.75));
    changed.push_back(held_key(w, 0.75));
  }
  for (int a = 0; a < 3; ++a) {
    SkinInfluence b = in;
    b.bind[a] = std::nextafter(b.bind[a], 10.0);
    changed.push_back(held_key(b, 0.75));
  }
  changed.push_back(held_key(in, std::nextafter(0.75, 1.0)));
  for (size_t n = 0; n < changed.size(); ++n) EXPECT_NE(changed[n], base) << "input " << n << " left out of the key";
  EXPECT_EQ(held_key(in, 0.75), base);
}

// The poses' cache (pose_cache.hpp): each pose's field's depths, voxels and grown candidates
// kept between runs give the same proxy, bit for bit, as building the fields: on a skinned
// clip (every frame's field) and on poses asked for their own candidates, at the tolerance it
// was written at and at another; a file cut short is built again and written whole.
TEST(PoseMap, PoseCacheMapsAsBuildingTheFields) {
  SPX_REQUIRE_SHARED_DATA();
  const std::string dir = test::temp_dir("pose-cache") + "/cache";
  const RiggedRun run("pose-cache-clip", 6, 64);
  const ExtractedClip& clip = run.clip;
  const TriMesh& rest = clip.rest.mesh;
  PoseMapOptions opt;
  const PoseMapResult fresh = run(opt);
  EXPECT_TRUE(fresh.summary.pose_caches.empty());
  opt.cache_dir = dir;
  const PoseMapResult writing = run(opt);
  const PoseMapResult reading = run(opt);
  expect_same_proxy(fresh.proxy, writing.proxy);
  expect_same_proxy(fresh.proxy, reading.proxy);
  ASSERT_EQ(reading.summary.pose_caches.size(), clip.poses.size() + 1);
  size_t read = 0;
  for (size_t i = 0; i < reading.summary.pose_caches.size(); ++i) {
    const PoseCacheUse& w = writing.summary.pose_caches[i];
    const PoseCacheUse& r = reading.summary.pose_caches[i];
    EXPECT_FALSE(w.file.empty()) << "frame " << i;  // skinned: every frame's field is asked
    EXPECT_FALSE(w.read) << "frame " << i;
    EXPECT_EQ(w.grown_read, 0u);
    EXPECT_EQ(r.file, w.file);
    EXPECT_TRUE(r.read) << "frame " << i;
    EXPECT_EQ(r.grown_made, 0u) << "frame " << i << ": grown again what the cache held";
    EXPECT_EQ(r.grown_read, w.grown_made) << "frame " << i;
    read += r.grown_read;
  }
  EXPECT_GT(read, 0u) << "no frame's own candidates were cached";
  // The carries: every candidate's choice made and written by the first run, read by the next.
  expect_written_then_read(fresh, writing, reading, &PoseMapSummary::carry_cache);

  // Another tolerance: the same fields, read; the proxy as without the cache.
  PoseMapOptions finer = opt;
  finer.tolerance = 0.6 * kDefaultTolerancePercent / 100 * rest.diagonal();
  PoseMapOptions finer_fresh = finer;
  finer_fresh.cache_dir.clear();
  const PoseMapResult other = run(finer);
  expect_same_proxy(run(finer_fresh).proxy, other.proxy);
  for (const PoseCacheUse& u : other.summary.pose_caches) EXPECT_TRUE(u.read);
  EXPECT_GT(other.summary.carry_cache.read, 0u);

  // The carries' file cut short: every choice made again, the same proxy, and written whole (the
  // next run makes none).
  const std::string carry_file = other.summary.carry_cache.file;
  const std::string carries = read_file(carry_file);
  write_file_atomic(carry_file, carries.substr(0, carries.size() - 3));
  const PoseMapResult remade = run(finer);
  EXPECT_EQ(remade.summary.carry_cache.read, 0u);
  EXPECT_GT(remade.summary.carry_cache.made, 0u);
  expect_same_proxy(other.proxy, remade.proxy);
  EXPECT_EQ(run(finer).summary.carry_cache.made, 0u);

  // A frame's file cut short: its field built again, the same proxy, the file whole again.
  const std::string frame_file = other.summary.pose_caches[2].file;
  const std::string whole = read_file(frame_file);
  write_file_atomic(frame_file, whole.substr(0, whole.size() / 2));
  const PoseMapResult repaired = run(finer);
  EXPECT_FALSE(repaired.summary.pose_caches[2].read);
  EXPECT_TRUE(repaired.summary.pose_caches[1].read);
  expect_same_proxy(other.proxy, repaired.proxy);
  EXPECT_EQ(read_file(frame_file), whole);

  // Poses that are not skinned: fields built only for those asked for their own candidates.
  const SampleAsset car = make_car();
  SpheresFile car_spheres;
  pack_rest(car.rest, 64, {kDefaultTolerancePercent, true}, car_spheres);
  const std::vector<PoseInput> poses = sample_poses(car);
  PoseMapOptions car_opt;
  car_opt.tets.size = car.rest.diagonal() / 12;
  car_opt.tolerance = 0.01 * car.rest.diagonal();  // fine enough that some pose needs its own
  const PoseMapResult car_fresh = pose_map(car.rest, "car", poses, car_spheres, car_opt);
  car_opt.cache_dir = dir;
  const PoseMapResult car_writing = pose_map(car.rest, "car", poses, car_spheres, car_opt);
  const PoseMapResult car_reading = pose_map(car.rest, "car", poses, car_spheres, car_opt);
  expect_same_proxy(car_fresh.proxy, car_writing.proxy);
  expect_same_proxy(car_fresh.proxy, car_reading.proxy);
  size_t asked = 0;
  for (size_t i = 0; i < car_reading.summary.pose_caches.size(); ++i) {
    const PoseCacheUse& r = car_reading.summary.pose_caches[i];
    EXPECT_EQ(r.file, car_writing.summary.pose_caches[i].file);
    if (r.file.empty()) continue;
    ++asked;
    EXPECT_TRUE(r.read);
    EXPECT_EQ(r.grown_made, 0u);
  }
  EXPECT_TRUE(car_reading.summary.pose_caches[0].file.empty()) << "the rest's field is not asked for";
  EXPECT_TRUE(car_reading.summary.carry_cache.file.empty()) << "a body that is not skinned carries nothing";
  EXPECT_GT(asked, 0u) << "no pose was asked for its own candidates";
}

// Not skinned, the first round's poses list their own candidates while Mesh_3 keeps the other
// core: the same lists as when first asked, so the same proxy as a run that lists none ahead (a
// cache folder's, which lists each when asked; the same proxy as without the cache:
// PoseCacheMapsAsBuildingTheFields).
TEST(PoseMap, OwnCandidatesListedBesideTheTetsMapAsListedWhenAsked) {
  const SampleAsset car = make_car();
  SpheresFile file;
  pack_rest(car.rest, 64, {kDefaultTolerancePercent, true}, file);
  const std::vector<PoseInput> poses = sample_poses(car);
  PoseMapOptions opt;
  opt.tolerance = 0.01 * car.rest.diagonal();  // fine enough that the poses need their own
  // Whether a run listed some pose ahead: its stage's time is recorded only then.
  auto listed_ahead = [](const Log& log) {
    const auto& timings = log.timings();
    return std::any_of(timings.begin(), timings.end(), [](const auto& t) { return t.first == "own-candidates-beside-tets"; });
  };
  Log ahead_log;
  const PoseMapResult ahead = pose_map(car.rest, "car", poses, file, opt, ahead_log);
  EXPECT_TRUE(listed_ahead(ahead_log)) << "no pose listed its own candidates beside the tets";
  ASSERT_TRUE(ahead.summary.selection.has_value());
  EXPECT_GT(ahead.summary.selection->from_frames, 0u) << "no pose's own candidates were offered";
  opt.cache_dir = test::temp_dir("beside-tets") + "/cache";
  Log asked_log;
  const PoseMapResult asked = pose_map(car.rest, "car", poses, file, opt, asked_log);
  EXPECT_FALSE(listed_ahead(asked_log)) << "a run with a cache folder listed a pose ahead";
  expect_same_proxy(ahead.proxy, asked.proxy);
}

// Listing a pose's own candidates ahead fails no run the selection would not fail: a pose flat
// at the spheres' voxel size has no field, and at a tolerance so loose that the file's candidates
// reach every sample it is never asked for its own.
TEST(PoseMap, APoseWithNoFieldFailsOnlyWhereItsOwnCandidatesAreAsked) {
  const SampleAsset car = make_car();
  SpheresFile file;
  pack_rest(car.rest, 64, {kDefaultTolerancePercent, true}, file);
  std::vector<PoseInput> poses = sample_poses(car);
  TriMesh flat = car.rest;
  const double mid = flat.bounds().center().z();
  for (auto& v : flat.vertices) v.z() = mid + 1e-6 * (v.z() - mid);
  poses.insert(poses.begin(), {"flat", "flat.obj", flat});
  PoseMapOptions opt;
  opt.tolerance = 0.5 * car.rest.diagonal();
  const PoseMapResult loose = pose_map(car.rest, "car", poses, file, opt);
  ASSERT_TRUE(loose.summary.selection.has_value());
  EXPECT_EQ(loose.summary.selection->from_frames, 0u);
  opt.tolerance = 0.01 * car.rest.diagonal();  // now it is asked: its error, naming it
  try {
    pose_map(car.rest, "car", poses, file, opt);
    ADD_FAILURE() << "the flat pose's own candidates were asked, and it has no field";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("flat.obj: encloses no volume"), std::string::npos) << e.what();
  }
}

// With --hold-over-clip, the radii held over the clip kept between runs give the same proxy, bit
// for bit, as holding them: the second run holds none again; another overshoot allowed is another
// file; a file cut short is held again and written whole. (Within a run, the written spheres'
// radii are read: the selection held them.)
TEST(PoseMap, HeldRadiiCacheMapsAsHoldingThem) {
  SPX_REQUIRE_SHARED_DATA();
  const std::string dir = test::temp_dir("held-cache") + "/cache";
  const RiggedRun run("held-cache-clip", 3, 48);
  const TriMesh& rest = run.clip.rest.mesh;
  PoseMapOptions opt;
  opt.hold_over_clip = true;
  const PoseMapResult fresh = run(opt);
  ASSERT_GT(fresh.summary.clip_times, 0u);
  EXPECT_GT(fresh.summary.selection->clip_shrunk, 0u) << "the clip shrank no candidate: the cache is not tried";
  opt.cache_dir = dir;
  const PoseMapResult writing = run(opt);
  const PoseMapResult reading = run(opt);
  expect_same_proxy(fresh.proxy, writing.proxy);
  expect_same_proxy(fresh.proxy, reading.proxy);
  expect_written_then_read(fresh, writing, reading, &PoseMapSummary::held_cache);

  PoseMapOptions looser = opt;
  looser.clip_overshoot = 0.01 * rest.diagonal();
  const PoseMapResult other = run(looser);
  EXPECT_NE(other.summary.held_cache.file, writing.summary.held_cache.file) << "another overshoot, the same file";
  EXPECT_GT(other.summary.held_cache.made, 0u);
  PoseMapOptions looser_fresh = looser;
  looser_fresh.cache_dir.clear();
  expect_same_proxy(run(looser_fresh).proxy, other.proxy);

  const std::string held_file = writing.summary.held_cache.file;
  const std::string whole = read_file(held_file);
  write_file_atomic(held_file, whole.substr(0, whole.size() - 5));
  const PoseMapResult remade = run(opt);
  EXPECT_EQ(remade.summary.held_cache.made, writing.summary.held_cache.made) << "a file cut short was read";
  expect_same_proxy(fresh.proxy, remade.proxy);
  EXPECT_EQ(read_file(held_file), whole);
}

TEST(PoseMap, OpenSharedMeshesMeetTheirClaim) {
  SPX_REQUIRE_SHARED_DATA();
  const std::string d = test::shared_data() + "/";
  {
    const LoadedMesh rest = load_mesh(d + "cylinder/rest.obj");
    std::vector<PoseInput> poses;
    for (int i = 1; i <= 4; ++i) {
      const std::string path = d + "cylinder/pose-" + std::to_string(i) + ".obj";
      poses.push_back({stem_of(path), path, load_pose(path, rest)});
    }
    expect_claim_holds(rest.mesh, poses, "cylinder");
  }
  for (const char* name : {"broken/hemisphere.obj", "broken/truck.obj"}) {
    const TriMesh rest = load_mesh(d + name).mesh;
    // An identity pose and a moved one: turned a little about the body's centre and stretched.
    const Eigen::Vector3d c = rest.bounds().center();
    const Eigen::Matrix3d turn = Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 0.5).normalized()).toRotationMatrix();
    TriMesh moved = rest;
    for (auto& v : moved.vertices) v = c + turn * (v - c).cwiseProduct(Eigen::Vector3d(1.1, 0.95, 1.0));
    expect_claim_holds(rest, {{"same", "same", rest}, {"moved", "moved", moved}}, name);
  }
}

// `count` rest points drawn evenly over the rest's box that lie in f's tets (and pass `keep`),
// each with where it lies.
std::vector<std::pair<Eigen::Vector3d, TetLocator::Location>> points_in_tets(
    const TriMesh& rest, const HarmonicMap& f, size_t count, unsigned seed,
    const std::function<bool(const Eigen::Vector3d&)>& keep = {}) {
  std::mt19937 rng(seed);
  const Eigen::AlignedBox3d box = rest.bounds();
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<std::pair<Eigen::Vector3d, TetLocator::Location>> out;
  while (out.size() < count) {
    const Eigen::Vector3d c = box.min() + box.sizes().cwiseProduct(Eigen::Vector3d(u(rng), u(rng), u(rng)));
    if (keep && !keep(c)) continue;
    const TetLocator::Location at = f.locator().locate(c);
    if (at.tet >= 0) out.push_back({c, at});
  }
  return out;
}

// A skinned sphere follows the harmonic influence, or its closest surface point's where that
// keeps it larger over the clip (choose). On the robot's rigid parts, each on its own joint, the
// harmonic extension blends the pelvis and the thighs through the shared tets, and spheres there
// drift out of both. Checked against brute force over every pose (no floors, no early exit): the
// radius choose gives is the least over the poses of the influence it picked, and no less than
// either influence's.
TEST(PoseMap, SkinnedSphereKeepsTheInfluenceThatKeepsItLarger) {
  const ExtractedClip clip = robot_clip(4);
  const TriMesh& rest = clip.rest.mesh;
  std::vector<TriMesh> meshes{rest};
  for (const PoseInput& p : clip.poses) meshes.push_back(p.mesh);
  const SkinFile& skin = clip.skin;
  const TetMesh tets = tetrahedralize(rest, {});
  const HarmonicMap f(tets, rest);
  const SkinnedMap map(skin, f);
  std::vector<std::unique_ptr<MeshQuery>> queries;
  std::vector<DenseField> fields;
  std::vector<DepthField> depths;
  SdfOptions o;
  o.voxel_size = rest.diagonal() / 64;
  for (const TriMesh& m : meshes) {
    queries.push_back(std::make_unique<MeshQuery>(m));
    fields.push_back(build_sdf(m, o).field);
    depths.push_back(depth_field(fields.back()));
  }
  std::vector<PoseSolid> solids;
  for (size_t i = 0; i < meshes.size(); ++i)
    solids.push_back({queries[i].get(), &fields[i], std::numeric_limits<double>::infinity(), &depths[i]});
  auto least = [&](const SkinInfluence& s, const Eigen::Vector3d& c) {
    double out = std::numeric_limits<double>::infinity();
    for (size_t i = 0; i < solids.size(); ++i) out = std::min(out, solids[i].radius(map.center(s, c, i), false).value);
    return out;
  };
  size_t surface_wins = 0;
  for (const auto& [c, at] : points_in_tets(rest, f, 300, 5, [&](const Eigen::Vector3d& p) {
         return solids[0].radius(p, false).value > 0;
       })) {
    const SkinnedMap::Choice chosen = map.choose(c, at, solids);
    const double harmonic = least(map.influence(c, at), c);
    const double surface = least(map.surface_influence(c, *queries[0], queries[0]->closest(c)), c);
    EXPECT_EQ(chosen.radius, least(chosen.influence, c)) << c.transpose();
    EXPECT_EQ(chosen.radius, std::max(harmonic, surface)) << c.transpose();
    surface_wins += surface > harmonic;
  }
  EXPECT_GT(surface_wins, 10u);
}

// A refinement's trial (spheres without the causes) reuses what choose() found each pose keeps
// and asks only the others; its radius must be what asking every pose gives (surely_at_least,
// else the exact radius), and the spheres written (every pose exact) the least over the poses
// of the exact radius at the chosen influence's centres. On a closed skinned body with every
// shortcut on (floors, the refitted hierarchy's bounded searches and ray count), the floors
// taken from the rest's field for every pose: where the body moves they lie, choose() skips
// poses by them, and the checks after it must not.
TEST(PoseMap, SkinnedTrialRadiusAsksWhatChooseSkipped) {
  SPX_REQUIRE_SHARED_DATA();
  const ExtractedClip clip = extract_clip(test::shared_data() + "/rigged-simple/RiggedSimple.glb",
                                          test::temp_dir("skinned-trial"), 1, {0.4, 0.8, 1.2, 1.6, 2.0});
  const TriMesh& rest = clip.rest.mesh;
  std::vector<const TriMesh*> meshes{&rest};
  for (const PoseInput& p : clip.poses) meshes.push_back(&p.mesh);
  const TetMesh tets = tetrahedralize(rest, {});
  const HarmonicMap f(tets, rest);
  const SkinnedMap map(clip.skin, f);
  const DeformingQuery deforming(rest);
  ASSERT_TRUE(deforming.closed());
  SdfOptions o;
  o.voxel_size = rest.diagonal() / 64;
  const DepthField rest_depths = depth_field(build_sdf(rest, o).field);
  std::vector<std::unique_ptr<MeshQuery>> queries;
  std::vector<DeformingQuery::Shape> shapes;
  for (const TriMesh* m : meshes) {
    queries.push_back(std::make_unique<MeshQuery>(*m));
    shapes.push_back(deforming.shape(m->vertices));
  }
  std::vector<PoseSolid> solids;
  for (size_t i = 0; i < meshes.size(); ++i)
    solids.push_back({queries[i].get(), nullptr, std::numeric_limits<double>::infinity(), &rest_depths, &shapes[i]});
  size_t lowered = 0;
  for (const auto& [c, at] : points_in_tets(rest, f, 2000, 11)) {
    SkinInfluence followed;
    const auto trial = map.spheres(c, at, solids, false, &followed);
    const auto written = map.spheres(c, at, solids, true, nullptr);
    const SkinnedMap::Choice chosen = map.choose(c, at, solids);
    double asked = chosen.radius, least = std::numeric_limits<double>::infinity();
    for (size_t i = 0; i < solids.size(); ++i) {
      const Eigen::Vector3d center = map.center(chosen.influence, c, i);
      if (!solids[i].surely_at_least(center, asked)) asked = std::min(asked, solids[i].exact_radius(center, false).value);
      least = std::min(least, solids[i].exact_radius(center, false).value);
    }
    lowered += asked < chosen.radius;
    ASSERT_EQ(trial.size(), solids.size());
    EXPECT_EQ(followed.joint, chosen.influence.joint) << c.transpose();
    EXPECT_EQ(followed.weight, chosen.influence.weight) << c.transpose();
    for (size_t i = 0; i < solids.size(); ++i) {
      EXPECT_EQ(trial[i].first.center, map.center(chosen.influence, c, i)) << c.transpose() << ", pose " << i;
      EXPECT_EQ(trial[i].first.radius, asked) << c.transpose() << ", pose " << i;
      EXPECT_EQ(written[i].first.radius, least) << c.transpose() << ", pose " << i;
    }
  }
  EXPECT_GT(lowered, 20u) << "the floors must make choose() skip poses that lower the radius";
}

// The influence kept per sphere against a brute-force ranking: the 4 largest weights (ties to
// the lower joint), never negative, renormalised over the kept positive ones.
TEST(PoseMap, HeaviestFourKeepsTheLargestWeightsAsBruteForceDoes) {
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(-0.2, 1);
  for (int trial = 0; trial < 500; ++trial) {
    const int joints = 1 + trial % 9;
    Eigen::VectorXd w(joints);
    for (int j = 0; j < joints; ++j) w[j] = trial % 7 == 0 ? std::round(4 * u(rng)) / 4 : u(rng);
    const SkinInfluence s = heaviest_four(w);
    std::vector<std::pair<double, int>> ranked;
    for (int j = 0; j < joints; ++j) ranked.push_back({-w[j], j});
    std::sort(ranked.begin(), ranked.end());
    double total = 0;
    for (int k = 0; k < std::min(4, joints); ++k) total += std::max(0.0, -ranked[size_t(k)].first);
    for (int k = 0; k < 4; ++k) {
      EXPECT_GE(s.weight[size_t(k)], 0.0f);
      if (!(total > 0)) continue;
      if (k < joints) {
        EXPECT_EQ(s.joint[size_t(k)], ranked[size_t(k)].second) << "trial " << trial;
        EXPECT_FLOAT_EQ(s.weight[size_t(k)], float(std::max(0.0, -ranked[size_t(k)].first) / total));
      } else {
        EXPECT_EQ(s.weight[size_t(k)], 0.0f);
      }
    }
    if (!(total > 0)) EXPECT_EQ(s.weight[0], 1.0f);
  }
}

}  // namespace
}  // namespace spx

namespace spx {
namespace {

// The floor a pose's field puts under a radius (which lets a skinned sphere's one radius skip
// poses) is within a fraction of a voxel of the radius by the exact rule, never more above it,
// on a closed and an open mesh (the selection then checks the radii that count exactly).
TEST(PoseMap, RadiusFloorIsWithinAFractionOfAVoxelOfTheRadius) {
  for (const std::string set : {"elephant", "cylinder"}) {
    const TriMesh mesh = load_mesh(test::shared_data() + "/" + set + "/rest.obj").mesh;
    const MeshQuery query(mesh);
    const DenseField field = build_sdf(mesh, SdfOptions()).field;
    const bool open = !find_defects(mesh).watertight();
    const DepthField depths = depth_field(field);
    const PoseSolid solid{&query, open ? &field : nullptr, 0.2 * mesh.diagonal(), &depths};
    Eigen::AlignedBox3d box;
    for (const auto& v : mesh.vertices) box.extend(v);
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(0, 1);
    size_t above_zero = 0;
    for (int n = 0; n < 20000; ++n) {
      const Eigen::Vector3d c = box.min() + box.sizes().cwiseProduct(Eigen::Vector3d(u(rng), u(rng), u(rng)));
      const double floor = solid.radius_floor(c), radius = solid.exact_radius(c, false).value;
      ASSERT_LE(floor, radius + 0.5 * field.shape.voxel_size) << set << " at " << c.transpose();
      // The depths kept are the field's, rounded down to 1/512 voxel.
      const double whole = depth_bound(field, c), held = depth_bound(depths, c);
      ASSERT_LE(held, whole) << set << " at " << c.transpose();
      ASSERT_GE(held, whole - field.shape.voxel_size / 256) << set << " at " << c.transpose();
      above_zero += floor > 0;
    }
    EXPECT_GT(above_zero, 1000u) << set << ": the floor should bound most interior points";
  }
}


// A frame's refitted hierarchy lets a skinned sphere's one radius skip the exact query where the
// radius is surely at least the least so far: wherever it says so, the exact rule agrees, and it
// says so for most deep points (on the elephant at rest and with its front half pushed back
// through its rear, parts passing through each other).
TEST(PoseMap, SurelyAtLeastNeverClaimsMoreThanTheExactRadius) {
  SPX_REQUIRE_SHARED_DATA();
  const TriMesh rest = load_mesh(test::shared_data() + "/elephant/rest.obj").mesh;
  const DeformingQuery deforming(rest);
  ASSERT_TRUE(deforming.closed());
  const Eigen::AlignedBox3d box = rest.bounds();
  for (int kind = 0; kind < 2; ++kind) {
    TriMesh mesh = rest;
    if (kind == 1)
      for (auto& v : mesh.vertices)
        if (v.x() > box.center().x()) v.x() -= 0.3 * box.sizes().x();
    const MeshQuery query(mesh);
    const DenseField field = build_sdf(mesh, SdfOptions()).field;
    const DeformingQuery::Shape shape = deforming.shape(mesh.vertices);
    const DepthField depths = depth_field(field);
    const PoseSolid solid{&query, nullptr, 0.2 * mesh.diagonal(), &depths, &shape};
    std::mt19937 rng(9);
    std::uniform_real_distribution<double> u(0, 1), share(0.2, 1.2);
    size_t skipped = 0, asked = 0;
    for (int n = 0; n < 4000; ++n) {
      const Eigen::Vector3d c = box.min() + box.sizes().cwiseProduct(Eigen::Vector3d(u(rng), u(rng), u(rng)));
      const double radius = solid.radius(c, false).value;
      if (!(radius > 0)) {
        EXPECT_FALSE(solid.surely_at_least(c, 0.01 * mesh.diagonal())) << "kind " << kind << " at " << c.transpose();
        continue;
      }
      const double r = share(rng) * radius;
      ++asked;
      if (!solid.surely_at_least(c, r)) continue;
      ++skipped;
      ASSERT_GE(radius, r) << "kind " << kind << " at " << c.transpose();
    }
    EXPECT_GT(skipped, asked / 3) << "kind " << kind;
  }
}

}  // namespace
}  // namespace spx

namespace spx {
namespace {

// A clip of box meshes for the selection over frames: each rest candidate becomes in_frame() in
// every frame, one radius throughout; no frame offers candidates of its own.
class MovingClip : public SelectionFrames {
 public:
  explicit MovingClip(std::vector<TriMesh> meshes) : meshes_(std::move(meshes)) {}
  size_t frame_count() const override { return meshes_.size(); }
  const TriMesh& frame_mesh(size_t f) const override { return meshes_[f]; }
  SphereSet spheres_in(const SphereSet&, size_t) const override { return {}; }
  bool one_radius() const override { return true; }
  SkinnedMap::Carried carry_skinned(const SphereSet& rest) const override {
    SkinnedMap::Carried out;
    for (size_t f = 0; f < meshes_.size(); ++f) {
      out.centers.emplace_back();
      for (const Sphere& s : rest) out.centers.back().push_back(in_frame(s, f).center);
    }
    for (const Sphere& s : rest) out.radii.push_back(s.radius);
    return out;
  }
  // The radii carried are exact here (they are what the frames are built around).
  double exact_radius(const Eigen::Vector3d&, size_t) const override { return std::numeric_limits<double>::infinity(); }
  SphereSet frame_candidates(size_t, const std::vector<Eigen::Vector3d>&, double) override { return {}; }
  SphereSet touching_candidates(size_t, const SurfaceSamples&, const std::vector<uint32_t>&, double, bool) override {
    return {};
  }
  virtual Sphere in_frame(const Sphere& s, size_t f) const = 0;

 private:
  std::vector<TriMesh> meshes_;
};

// Frame f is the box moved by shift[f], and each candidate with it, except in `lost` where every
// candidate lands far away, so that nothing reaches that frame's samples.
class BoxClip : public MovingClip {
 public:
  BoxClip(std::vector<double> shift, size_t lost) : MovingClip(boxes(shift)), shift_(std::move(shift)), lost_(lost) {}
  Sphere in_frame(const Sphere& s, size_t f) const override {
    return {s.center + Eigen::Vector3d::Constant(f == lost_ ? 10.0 : shift_[f]), s.radius};
  }

 private:
  static std::vector<TriMesh> boxes(const std::vector<double>& shift) {
    std::vector<TriMesh> out;
    for (double s : shift) out.push_back(test::box_mesh(Eigen::Vector3d::Constant(s), Eigen::Vector3d::Constant(1 + s)));
    return out;
  }
  std::vector<double> shift_;
  size_t lost_;
};

// Past the first round's frames, every other frame is checked: the spheres chosen cover every
// sample of every frame some candidate reaches, and a frame nothing reaches is counted and
// decides what the report says limited the selection.
TEST(PoseMap, ClipSelectionCoversEveryFrameAndCountsWhatNothingReaches) {
  // Frame 8 barely moves from the rest, so the first round (the rest and the 6 poses farthest
  // apart) leaves it out.
  const std::vector<double> shift{0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.001};
  BoxClip frames(shift, 8);
  SphereSet candidates;
  for (double x : {0.25, 0.75})
    for (double y : {0.25, 0.75})
      for (double z : {0.25, 0.75}) candidates.push_back({Eigen::Vector3d(x, y, z), 0.25});
  JointSelectionOptions options;
  options.target = 0.3;
  options.reach = 0.3;
  options.area_samples = 200;
  const JointSelection selection = select_jointly(frames, candidates, options);
  EXPECT_FALSE(std::binary_search(selection.frames.begin(), selection.frames.end(), size_t(8)));
  EXPECT_EQ(selection.cover.uncoverable(), 0u);
  EXPECT_EQ(selection.bare_elsewhere, frames.frame_mesh(8).vertices.size() + options.area_samples);
  EXPECT_EQ(selection.vertices_out_of_reach, frames.frame_mesh(8).vertices.size());
  EXPECT_EQ(selection.limited_by, Limit::motion) << "vertices out of reach, even of balls through them: not met";
  for (size_t f = 0; f < 8; ++f) {
    SphereSet in_frame;
    for (const Sphere& s : selection.chosen) in_frame.push_back({s.center + Eigen::Vector3d::Constant(shift[f]), s.radius});
    EXPECT_TRUE(bare_samples(surface_samples(frames.frame_mesh(f), options.area_samples, options.seed), in_frame,
                             options.target).empty()) << "frame " << f;
  }
}

// A clip that stretches a box along x by stretch[f], the candidates' centres with it, their radii
// kept: each frame's samples lie otherwise against the spheres, so the selection takes rounds.
class StretchClip : public MovingClip {
 public:
  explicit StretchClip(std::vector<double> stretch) : MovingClip(boxes(stretch)), stretch_(std::move(stretch)) {}
  Sphere in_frame(const Sphere& s, size_t f) const override {
    return {Eigen::Vector3d(s.center.x() * stretch_[f], s.center.y(), s.center.z()), s.radius};
  }

 private:
  static std::vector<TriMesh> boxes(const std::vector<double>& stretch) {
    std::vector<TriMesh> out;
    for (double a : stretch) out.push_back(test::box_mesh(Eigen::Vector3d::Zero(), Eigen::Vector3d(a, 1, 1)));
    return out;
  }
  std::vector<double> stretch_;
};

// The unit cube cut into n^3 cells for each n, a sphere inscribed in each.
SphereSet cell_candidates(std::initializer_list<int> cuts) {
  SphereSet out;
  for (int n : cuts)
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j)
        for (int k = 0; k < n; ++k) out.push_back({Eigen::Vector3d(i + 0.5, j + 0.5, k + 0.5) / n, 0.5 / n});
  return out;
}

// Frame f stretched by 1 + amplitude |sin(rate f)|.
std::vector<double> sine_stretch(int frames, double amplitude, double rate) {
  std::vector<double> out;
  for (int f = 0; f < frames; ++f) out.push_back(1 + amplitude * std::abs(std::sin(rate * f)));
  return out;
}

JointSelectionOptions tolerance_options(double target, size_t area_samples) {
  JointSelectionOptions out;
  out.target = target;
  out.reach = target;
  out.area_samples = area_samples;
  return out;
}

// Frame f's samples, and how many of them the chosen spheres carried into f leave farther than
// the target.
struct FrameCover {
  size_t samples = 0, bare = 0;
};
FrameCover cover_in_frame(const MovingClip& frames, const SphereSet& chosen, size_t f, const JointSelectionOptions& options) {
  const std::vector<Eigen::Vector3d> samples = surface_samples(frames.frame_mesh(f), options.area_samples, options.seed);
  SphereSet in_frame;
  for (const Sphere& s : chosen) in_frame.push_back(frames.in_frame(s, f));
  return {samples.size(), bare_samples(samples, in_frame, options.target).size()};
}

// Over many frames the problem keeps, round to round, only the samples its reduction kept; the
// spheres chosen still cover every sample of every frame, the frames it dropped samples of too.
TEST(PoseMap, CompactedClipSelectionStillCoversEveryFrame) {
  const std::vector<double> stretch = sine_stretch(24, 0.6, 0.37);
  StretchClip frames(stretch);
  const SphereSet candidates = cell_candidates({5, 7});
  const JointSelectionOptions options = tolerance_options(0.09, 300);
  const JointSelection selection = select_jointly(frames, candidates, options);
  EXPECT_GE(selection.rounds, 3u) << "the check should find samples the first round's frames leave bare";
  size_t every = 0;
  for (size_t f = 0; f < stretch.size(); ++f) {
    const FrameCover c = cover_in_frame(frames, selection.chosen, f, options);
    every += c.samples;
    EXPECT_EQ(c.bare, 0u) << "frame " << f;
  }
  EXPECT_EQ(selection.cover.uncoverable() + selection.bare_elsewhere, 0u);
  EXPECT_LT(selection.samples, every / 4) << "the last problem should hold a few of the clip's samples";
}

// The carry's radii skip frames by their fields' floors, which may be a fraction of a voxel high:
// here every carried radius is twice the candidate's, too large at the walls in some frames. The
// chosen radii are checked against the exact ones in every frame and the cover redone, so every
// chosen sphere is inside every frame and still covers it.
class HighFloorClip : public StretchClip {
 public:
  explicit HighFloorClip(std::vector<double> stretch) : StretchClip(std::move(stretch)) {
    for (size_t f = 0; f < frame_count(); ++f) queries_.push_back(std::make_unique<MeshQuery>(frame_mesh(f)));
  }
  SkinnedMap::Carried carry_skinned(const SphereSet& rest) const override {
    SkinnedMap::Carried out = StretchClip::carry_skinned(rest);
    for (double& r : out.radii) r *= 2;
    return out;
  }
  double exact_radius(const Eigen::Vector3d& c, size_t f) const override {
    return queries_[f]->inside(c) ? queries_[f]->distance(c) : 0.0;
  }

 private:
  std::vector<std::unique_ptr<MeshQuery>> queries_;
};

TEST(PoseMap, ClipSelectionChecksEveryChosenRadiusExactly) {
  const std::vector<double> stretch = sine_stretch(12, 0.5, 0.45);
  HighFloorClip frames(stretch);
  const SphereSet candidates = cell_candidates({4, 6});
  const JointSelectionOptions options = tolerance_options(0.12, 200);
  const JointSelection selection = select_jointly(frames, candidates, options);
  EXPECT_GT(selection.radii_lowered, 0u) << "the doubled radii at the walls should be found too large";
  // Lowered twice in a row, every candidate is checked at once: a round covers at most three times.
  EXPECT_GT(selection.candidates_checked, 0u);
  EXPECT_GE(selection.radii_checked + selection.candidates_checked, selection.chosen.size());
  EXPECT_LE(selection.covers_redone, 2 * (selection.rounds - selection.covers_redone))
      << selection.rounds << " covers, " << selection.covers_redone << " of them redone";
  for (size_t f = 0; f < stretch.size(); ++f) {
    for (const Sphere& s : selection.chosen) {
      const Sphere at = frames.in_frame(s, f);
      EXPECT_LE(at.radius, frames.exact_radius(at.center, f) + 1e-12) << "frame " << f << ": a sphere pokes out";
    }
    EXPECT_EQ(cover_in_frame(frames, selection.chosen, f, options).bare, 0u) << "frame " << f;
  }
}

// A rigged body at a sphere budget: the chosen centres refined as the unrigged ones are, each
// move's sphere skinned into every frame with its one radius, exact (spheres_at). At most the
// budget; every frame's largest vertex error (by brute force over the spheres written) below the
// least delta any cover of the candidates fits the budget at; every sphere inside every frame at
// the skin's centre; and over a clip longer than the first round's frames (the bare samples of
// the others join round by round) the same.
TEST(PoseMap, SkinnedBudgetRefinedInEveryFrame) {
  SPX_REQUIRE_SHARED_DATA();
  for (int frames : {4, 12}) {
    const ExtractedClip clip = rigged_simple_frames("skinned-budget-" + std::to_string(frames), frames);
    const TriMesh& rest = clip.rest.mesh;
    SpheresFile file;
    pack_rest(rest, 64, {kDefaultTolerancePercent, true}, file);
    PoseMapOptions opt;
    opt.max_spheres = 12;
    opt.polish_rounds = 0;  // the first refinement's own bound (the polish: SkinnedPolishKeepsNoHigherMax)
    const PoseMapResult r = pose_map(rest, "rigged", clip.poses, file, opt, Log::silent(), &clip.skin);
    const std::string what = std::to_string(clip.poses.size()) + " frames";
    ASSERT_TRUE(r.summary.selection.has_value()) << what;
    EXPECT_LE(r.proxy.sphere_count(), 12u) << what;
    EXPECT_GT(r.summary.selection->refined_moves, 0u) << what;
    for (size_t i = 0; i < r.proxy.poses.size(); ++i) {
      const TriMesh& mesh = i == 0 ? rest : clip.poses[i - 1].mesh;
      const MeshQuery q(mesh);
      double worst = 0;
      for (const Eigen::Vector3d& v : mesh.vertices) {
        double gap = std::numeric_limits<double>::infinity();
        for (const Sphere& sp : r.proxy.poses[i].spheres) gap = std::min(gap, (v - sp.center).norm() - sp.radius);
        worst = std::max(worst, std::abs(gap));
      }
      EXPECT_LT(worst, r.summary.selection->cover.least_max_delta) << what << ", frame " << i;
      for (const Sphere& sp : r.proxy.poses[i].spheres) {
        ASSERT_GT(sp.radius, 0) << what << ", frame " << i;
        EXPECT_TRUE(q.inside(sp.center)) << what << ", frame " << i;
        EXPECT_LE(sp.radius, q.distance(sp.center) + 1e-9) << what << ", frame " << i;
      }
    }
    if (frames == 12)  // the others only checked (and their bare samples added)
      EXPECT_LT(r.summary.selection->frames.size(), r.proxy.poses.size()) << "the clip must pass the first round's frames";
  }
}

// The polish on a skinned body (each candidate's one radius checked in every frame as the
// rounds choose it): the set kept has no higher max vertex error over the frames than the first
// refinement's, and every sphere is inside every frame at no more than its exact distance.
TEST(PoseMap, SkinnedPolishKeepsNoHigherMax) {
  SPX_REQUIRE_SHARED_DATA();
  const ExtractedClip clip = rigged_simple_frames("skinned-polish", 12);
  const TriMesh& rest = clip.rest.mesh;
  SpheresFile file;
  pack_rest(rest, 64, {kDefaultTolerancePercent, true}, file);
  auto worst_max = [&](const PoseMapResult& r) {
    double worst = 0;
    for (size_t i = 0; i < r.proxy.poses.size(); ++i)
      worst = std::max(worst, vertex_error(i == 0 ? rest : clip.poses[i - 1].mesh, r.proxy.poses[i].spheres).max);
    return worst;
  };
  PoseMapOptions opt;
  opt.max_spheres = 12;
  opt.polish_rounds = 0;
  const PoseMapResult first = pose_map(rest, "rigged", clip.poses, file, opt, Log::silent(), &clip.skin);
  opt.polish_rounds = 2;
  const PoseMapResult polished = pose_map(rest, "rigged", clip.poses, file, opt, Log::silent(), &clip.skin);
  ASSERT_TRUE(polished.summary.selection.has_value());
  EXPECT_LE(polished.proxy.sphere_count(), 12u);
  EXPECT_LE(worst_max(polished), worst_max(first) * (1 + 1e-12));
  for (size_t i = 0; i < polished.proxy.poses.size(); ++i) {
    const MeshQuery q(i == 0 ? rest : clip.poses[i - 1].mesh);
    for (const Sphere& sp : polished.proxy.poses[i].spheres) {
      ASSERT_GT(sp.radius, 0) << "frame " << i;
      EXPECT_TRUE(q.inside(sp.center)) << "frame " << i;
      EXPECT_LE(sp.radius, q.distance(sp.center) + 1e-9) << "frame " << i;
    }
  }
}

// The elephant's walk at `times`, its rest packed at 64 cells at the default tolerance, mapped at
// pose-map's defaults: the selection meets the tolerance at every vertex of every frame (brute
// force) and says so. Returns the selection.
JointSelection expect_walk_within_tolerance(const std::string& name, const std::vector<double>& times) {
  const ExtractedClip clip =
      extract_clip(test::shared_data() + "/elephant/elephant-rigged.glb", test::temp_dir(name), 1, times);
  const TriMesh& rest = clip.rest.mesh;
  SpheresFile file;
  pack_rest(rest, 64, {kDefaultTolerancePercent, true}, file);
  const PoseMapResult r = pose_map(rest, "walk", clip.poses, file, {}, Log::silent(), &clip.skin);
  if (!r.summary.selection) {
    ADD_FAILURE() << "no joint selection";
    return {};
  }
  const JointSelection& sel = *r.summary.selection;
  EXPECT_EQ(sel.vertices_out_of_reach, 0u);
  EXPECT_EQ(sel.limited_by, Limit::tolerance);
  for (size_t i = 0; i < r.proxy.poses.size(); ++i)
    EXPECT_LE(vertex_error(i == 0 ? rest : clip.poses[i - 1].mesh, r.proxy.poses[i].spheres).max,
              r.summary.selection_target * (1 + 1e-9)) << "frame " << i;
  return sel;
}

// Four frames of the elephant's walk: in some, no candidate comes within the tolerance of a few
// vertices (knees, whose large spheres the clip shrinks). Those are offered balls through them,
// and the selection meets the tolerance at every vertex of every frame; before, it missed it by
// up to 44 % and said the field's resolution was the limit.
TEST(PoseMap, VerticesOutOfReachAreOfferedBallsThroughThem) {
  SPX_REQUIRE_SHARED_DATA();
  const JointSelection sel =
      expect_walk_within_tolerance("touching-walk", {4.6333330078125, 6.53333349609375, 7.8666669921875, 10.7});
  EXPECT_GT(sel.touched, 0u);
  EXPECT_GT(sel.from_touching, 0u);
}

// Six frames of the walk as a knee bends: a ball through a vertex at the back of the knee is cut
// by the fold in some frame, so that a skinned sphere through it keeps no radius; a small ball
// beside it stays inside in every frame and reaches it. Before the balls around, a vertex stayed
// out of reach (3.81 against a tolerance of 3.72) and the report blamed the fold.
TEST(PoseMap, VerticesWhereTheSkinFoldsAreOfferedBallsAroundThem) {
  SPX_REQUIRE_SHARED_DATA();
  const JointSelection sel = expect_walk_within_tolerance(
      "around-walk", {12.033333984375, 12.1, 12.266666015625, 12.466666015625, 12.8, 13.0});
  EXPECT_GT(sel.around, 0u);
  EXPECT_GT(sel.from_around, 0u);
}

// A host plays the whole clip, not the poses given: one frame of RiggedSimple's bend leaves
// spheres that poke out of the cylinder at other times (some centres leave it). pose-map counts
// them at every time of the skin's clip, as brute force over every time's mesh queried afresh
// finds; before, its report said nothing between the poses.
TEST(PoseMap, SpheresPokingOutBetweenThePosesAreCounted) {
  SPX_REQUIRE_SHARED_DATA();
  const ExtractedClip clip =
      extract_clip(test::shared_data() + "/rigged-simple/RiggedSimple.glb", test::temp_dir("between"), 1, {0.5});
  const TriMesh& rest = clip.rest.mesh;
  SpheresFile file;
  pack_rest(rest, 64, {kDefaultTolerancePercent, true}, file);
  Log log("pose-map", -1);
  const PoseMapResult r = pose_map(rest, "bend", clip.poses, file, {}, log, &clip.skin);
  const ClipOvershoot& between = r.summary.between;
  // The warning names what holds them, and how far that lets them out (not "inside").
  EXPECT_EQ(std::count_if(log.warnings().begin(), log.warnings().end(),
                          [](const std::string& w) {
                            return w.find("poke out of the body") != std::string::npos &&
                                   w.find("--hold-over-clip holds them within 0.25 % of the diagonal") != std::string::npos;
                          }),
            1);
  ASSERT_EQ(between.times, clip.skin.clip.times.size());
  const ClipRadius meshes(clip.skin, rest, 1e30);
  std::vector<TriMesh> mesh;
  for (size_t t = 0; t < between.times; ++t) mesh.push_back(meshes.mesh_at(t));
  std::vector<std::unique_ptr<MeshQuery>> at;
  for (const TriMesh& m : mesh) at.push_back(std::make_unique<MeshQuery>(m));
  size_t out = 0, outside = 0;
  double worst = 0;
  for (size_t s = 0; s < r.proxy.skin.spheres.size(); ++s) {
    const SkinnedSphere& sk = r.proxy.skin.spheres[s];
    const SkinInfluence follows{sk.joint, sk.weight, sk.center};
    double past = 0;  // how far past the surface at worst (the radius where the centre leaves)
    bool left = false;
    for (size_t t = 0; t < between.times; ++t) {
      const Eigen::Vector3d c = skin_point(follows, clip.skin.clip.matrices[t]);
      left = left || !at[t]->inside(c);
      past = std::max(past, at[t]->inside(c) ? sk.radius - at[t]->distance(c) : sk.radius);
    }
    if (past <= 1e-6 * rest.diagonal()) continue;
    ++out;
    outside += left;
    worst = std::max(worst, past);
  }
  EXPECT_GT(out, 0u);
  EXPECT_GT(outside, 0u);
  EXPECT_EQ(between.spheres_out, out);
  EXPECT_EQ(between.centres_outside, outside);
  EXPECT_NEAR(between.worst, worst, 1e-9 * rest.diagonal());
}

// The warning over the clip reads as a sentence whatever its counts: no "0 centres leave it"
// where none does (the walk's 6 frames said so), the verb agreeing with one sphere.
TEST(PoseMap, BetweenPosesWarningSaysOnlyWhatHappened) {
  const std::string none = between_poses_warning({1315, 98, 0, 12.51}, 134, 185.8);
  EXPECT_EQ(none, "between the poses given, 98 of 134 spheres poke out of the body at some of the clip's 1315 times "
                  "(by up to 12.51, 6.733 % of the diagonal): --hold-over-clip holds them within 0.25 % of the "
                  "diagonal (--clip-overshoot), and more of the clip's frames in the chain (pose-extract --select, "
                  "--every) bring it down");
  const std::string one = between_poses_warning({17, 1, 1, 2}, 5, 100);
  EXPECT_NE(one.find("1 of 5 spheres pokes out"), std::string::npos) << one;
  EXPECT_NE(one.find("(by up to 2, 2 % of the diagonal; 1 centre leaves it)"), std::string::npos) << one;
  EXPECT_NE(between_poses_warning({17, 3, 2, 2}, 5, 100).find("; 2 centres leave it)"), std::string::npos);
}

// Rest vertex v's 4 heaviest joints (no bind point yet).
SkinInfluence vertex_influence(const SkinFile& skin, size_t v) {
  Eigen::VectorXd w = Eigen::VectorXd::Zero(Eigen::Index(skin.joints.size()));
  for (const auto& [j, x] : skin.vertex_weights[v]) w[j] += x;
  return heaviest_four(w);
}

// Spheres at `count` random interior points of `rest` (seeded), each following its nearest
// vertex's 4 heaviest joints; the point is its bind (the rest matrices of the shared rigs are the
// identity where they are bound).
std::vector<SkinInfluence> random_followers(const TriMesh& rest, const SkinFile& skin, size_t count, unsigned seed) {
  std::mt19937 rng(seed);
  const WindingNumber wn(rest);
  const Eigen::AlignedBox3d box = rest.bounds();
  std::vector<SkinInfluence> out;
  while (out.size() < count) {
    std::uniform_real_distribution<double> u(0, 1);
    const Eigen::Vector3d p = box.min() + box.sizes().cwiseProduct(Eigen::Vector3d(u(rng), u(rng), u(rng)));
    if (!wn.inside(p)) continue;
    size_t nearest = 0;
    for (size_t v = 0; v < rest.vertices.size(); ++v)
      if ((rest.vertices[v] - p).norm() < (rest.vertices[nearest] - p).norm()) nearest = v;
    out.push_back(vertex_influence(skin, nearest));
    out.back().bind = p;
  }
  return out;
}

// The clip between the poses: its meshes at the poses' own times are the extracted poses, and
// the least radius over it is, sphere by sphere, what a MeshQuery of every clip mesh finds (the
// refitted hierarchy and the pseudo-normals against trees and winding numbers built afresh).
TEST(ClipRadius, MatchesEveryClipMeshQueriedAfresh) {
  SPX_REQUIRE_SHARED_DATA();
  const ExtractedClip extracted =
      extract_clip(test::shared_data() + "/rigged-simple/RiggedSimple.glb", test::temp_dir("clip-radius"), 3);
  const PoseManifest& manifest = extracted.manifest;
  const LoadedMesh& rest = extracted.rest;
  const SkinFile& skin = extracted.skin;
  ASSERT_FALSE(skin.clip.empty());
  const ClipRadius clip(skin, rest.mesh, 1e30);
  const double diag = rest.mesh.diagonal();
  for (size_t k = 0; k < manifest.poses.size(); ++k) {
    const double t = manifest.poses[k].source["time"].get<double>();
    const size_t at = size_t(std::min_element(skin.clip.times.begin(), skin.clip.times.end(),
                                              [&](double a, double b) { return std::abs(a - t) < std::abs(b - t); }) -
                             skin.clip.times.begin());
    const TriMesh& pose = extracted.poses[k].mesh;
    const TriMesh mine = clip.mesh_at(at);
    for (size_t v = 0; v < pose.vertices.size(); ++v) ASSERT_LE((pose.vertices[v] - mine.vertices[v]).norm(), 1e-6 * diag);
  }
  const std::vector<SkinInfluence> influences = random_followers(rest.mesh, skin, 60, 5);
  const std::vector<double> radius(influences.size(), 0.2 * diag);
  // Strict, then with an overshoot allowed at the clip's times (the depth plus it; 0 outside).
  for (const double overshoot : {0.0, 0.01 * diag}) {
    const ClipRadius loose(skin, rest.mesh, 1e30, overshoot);
    const std::vector<double> least = loose.least(influences, radius);
    EXPECT_EQ(least, ClipRadius(skin, rest.mesh, 1e30, overshoot, false).least(influences, radius));
    std::vector<double> brute(radius);
    for (size_t k = 0; k < clip.time_count(); ++k) {
      const MeshQuery q(clip.mesh_at(k));
      for (size_t i = 0; i < brute.size(); ++i) {
        const Eigen::Vector3d c = skin_point(influences[i], skin.clip.matrices[k]);
        brute[i] = std::min(brute[i], q.inside(c) ? q.distance(c) + overshoot : 0.0);
      }
    }
    size_t shrunk = 0, outside = 0;
    for (size_t i = 0; i < least.size(); ++i) {
      EXPECT_NEAR(least[i], brute[i], 1e-9 * diag) << "sphere " << i << " overshoot " << overshoot;
      shrunk += least[i] < radius[i];
      outside += least[i] == 0;
    }
    EXPECT_GT(shrunk, 30u);  // the clip really bounds them
    EXPECT_GT(outside, 0u);  // and some centres leave the body between the poses
  }
}

// A body of open parts (the robot's walk: walls inside the solid where its parts overlap): each
// time's boundary is decided only near the spheres (NearBoundaryQuery), and the least radius over
// the clip is still, to the bit, what a MeshQuery of every clip mesh finds.
TEST(ClipRadius, OpenPartsMatchEveryClipMeshQueriedAfresh) {
  const ExtractedClip clip = robot_clip(8);
  const TriMesh& rest = clip.rest.mesh;
  const SkinFile& skin = clip.skin;
  const double diag = rest.diagonal();
  std::vector<SkinInfluence> influences = random_followers(rest, skin, 60, 7);
  // And on walls themselves: a wall's centroid, at the clip's middle time, has the solid on both
  // sides (each part is rigid on one joint, so the point is bound through that joint's matrix).
  const ClipRadius clip_meshes(skin, rest, 1e30);
  const size_t middle = skin.clip.times.size() / 2;
  const TriMesh at = clip_meshes.mesh_at(middle);
  const SolidBoundary boundary = solid_boundary(at, WindingNumber(at));
  std::vector<char> bounds(at.triangles.size(), 0);
  for (int t : boundary.source) bounds[size_t(t)] = 1;
  for (size_t t = 0; t < at.triangles.size() && influences.size() < 120; t += 2) {
    const auto& f = at.triangles[t];
    SkinInfluence s = vertex_influence(skin, size_t(f[0]));
    if (bounds[t] || s.weight[0] != 1.0f) continue;
    const Eigen::Vector3d centroid = (at.vertices[size_t(f[0])] + at.vertices[size_t(f[1])] + at.vertices[size_t(f[2])]) / 3;
    s.bind = (skin.clip.matrices[middle][size_t(s.joint[0])].inverse() * centroid.homogeneous()).head<3>();
    ASSERT_LT((skin_point(s, skin.clip.matrices[middle]) - centroid).norm(), 1e-9 * diag);
    influences.push_back(s);
  }
  ASSERT_GT(influences.size(), 70u);
  const std::vector<double> radius(influences.size(), 0.05 * diag);
  const std::vector<double> overshoots{0.0, 0.005 * diag};
  std::vector<std::vector<double>> brute(overshoots.size(), radius);
  size_t walls = 0;
  for (size_t k = 0; k < skin.clip.times.size(); ++k) {
    const MeshQuery q(clip_meshes.mesh_at(k));
    walls += q.internal_walls() + q.split_triangles();
    for (size_t i = 0; i < influences.size(); ++i) {
      const Eigen::Vector3d c = skin_point(influences[i], skin.clip.matrices[k]);
      for (size_t o = 0; o < overshoots.size(); ++o)
        brute[o][i] = std::min(brute[o][i], q.inside(c) ? q.distance(c) + overshoots[o] : 0.0);
    }
  }
  ASSERT_GT(walls, 0u);
  for (size_t o = 0; o < overshoots.size(); ++o) {
    const std::vector<double> least = ClipRadius(skin, rest, 1e30, overshoots[o]).least(influences, radius);
    EXPECT_EQ(least, brute[o]) << "overshoot " << overshoots[o];
    size_t shrunk = 0;
    for (size_t i = 0; i < least.size(); ++i) shrunk += least[i] < radius[i];
    EXPECT_GT(shrunk, 10u) << "overshoot " << overshoots[o];  // the clip really bounds them
  }
}

// The sweeps: a block of times where every triangle stays farther than a sphere's radius needs,
// in the frame of its heaviest joint (the sweep, then the few near it each step), is not asked.
// On the elephant's walk (its parts rigid on their joints, the legs swinging past one another)
// they settle many blocks, and the radii are those of every sphere walked through every one of
// the clip's times, to the bit.
TEST(ClipRadius, SweptBlocksChangeNoRadius) {
  SPX_REQUIRE_SHARED_DATA();
  const ExtractedClip extracted = extract_clip(test::shared_data() + "/elephant/elephant-rigged.glb",
                                               test::temp_dir("clip-sweep"), 1, {0.5});
  const TriMesh& rest = extracted.rest.mesh;
  const SkinFile& skin = extracted.skin;
  ASSERT_GT(skin.clip.times.size(), 1000u);
  const MeshQuery query(rest);
  const std::vector<SkinInfluence> influences = random_followers(rest, skin, 250, 11);
  std::vector<double> radius;
  for (const SkinInfluence& s : influences) radius.push_back(query.distance(s.bind));
  for (const double overshoot : {0.0, 0.0025 * rest.diagonal()}) {
    const ClipRadius sweeping(skin, rest, 1e30, overshoot), walking(skin, rest, 1e30, overshoot, false);
    ClipRadius::Tally tally;
    const std::vector<double> exact = walking.least(influences, radius);
    EXPECT_EQ(sweeping.least(influences, radius, nullptr, &tally), exact) << overshoot;
    // Most of them even with no overshoot, where a sphere touches the surface at its least: the
    // triangles near it, tested against its centre step by step, move with it (an eighth without).
    EXPECT_GT(tally.settled, tally.blocks / 2)
        << "overshoot " << overshoot << ": " << tally.settled << " of " << tally.blocks;
    // A hair above their least: only the block where each is least may lower it, and must.
    std::vector<double> tight(exact);
    for (double& r : tight) r *= 1 + 1e-9;
    EXPECT_EQ(sweeping.least(influences, tight), walking.least(influences, tight)) << overshoot;
  }
}

}  // namespace
}  // namespace spx
