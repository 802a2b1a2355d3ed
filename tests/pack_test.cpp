#include <gtest/gtest.h>

#include "core/atomic_file.hpp"
#include "core/error.hpp"
#include "extract/asset.hpp"
#include "io/spheres_file.hpp"
#include "pack/sphere_pack_tool.hpp"
#include "sdf/sdf_build_tool.hpp"
#include "mesh/union_distance.hpp"
#include "mesh/components.hpp"
#include "mesh/defects.hpp"
#include "mesh/mesh_query.hpp"
#include "pack/pack.hpp"
#include "synthetic/synthetic.hpp"
#include "sdf/sdf.hpp"
#include "test_util.hpp"

namespace spx {
namespace {

// Every sphere of S_0 lies inside M_0: center inside, exact distance to the surface >= radius.
void expect_inside(const TriMesh& mesh, const SphereSet& spheres, const std::string& what) {
  const MeshQuery query(mesh);
  const double tol = 1e-9 * mesh.diagonal();
  ASSERT_FALSE(spheres.empty()) << what;
  for (size_t i = 0; i < spheres.size(); ++i) {
    EXPECT_TRUE(query.inside(spheres[i].center)) << what << " sphere " << i;
    EXPECT_GE(query.distance(spheres[i].center), spheres[i].radius - tol) << what << " sphere " << i;
  }
}

PackResult pack_mesh(const TriMesh& mesh, int resolution, const PackOptions& opt = {}, bool exact = true) {
  SdfOptions sopt;
  sopt.resolution = resolution;
  const SdfResult sdf = build_sdf(mesh, sopt);
  const MeshQuery query(mesh);
  return pack_spheres(sdf.field, opt, exact ? &query : nullptr);
}

// Spheres too small to collide with are counted and named with the least of them; radius 0 (a
// sphere absent) is no sphere, and one just at the share is not tiny.
TEST(Pack, TinySpheresAreSaid) {
  Log log("sphere-pack", -1);
  json tiny = warn_tiny_spheres({1e-7, 0.5, 0.0, 1.0, 1e-3}, 10, "", log);
  EXPECT_EQ(tiny["count"], 1);
  EXPECT_DOUBLE_EQ(tiny["below"].get<double>(), 1e-3);
  ASSERT_EQ(log.warnings().size(), 1u);
  EXPECT_EQ(log.warnings()[0], "1 of the 4 spheres is under 0.01% of the diagonal (down to 1e-07): a sharp tip's or a "
                               "fold's own ball, too small for a host to collide with; --min-radius keeps them out (the "
                               "tolerance may then be missed at those tips)");
  tiny = warn_tiny_spheres({2e-4, 3e-4, 1.0}, 10, "sphere-pack's or pose-map's", log);
  EXPECT_EQ(tiny["count"], 2);
  ASSERT_EQ(log.warnings().size(), 2u);
  EXPECT_NE(log.warnings()[1].find("2 of the 3 spheres are under 0.01% of the diagonal (down to 0.0002): sharp tips' "
                                   "or folds' own balls, too small for a host to collide with; sphere-pack's or "
                                   "pose-map's --min-radius"),
            std::string::npos)
      << log.warnings()[1];
  EXPECT_EQ(warn_tiny_spheres({1e-3, 1.0}, 10, "", log)["count"], 0);
  EXPECT_EQ(log.warnings().size(), 2u);
}

TEST(Pack, SpheresInsideTheSamples) {
  for (const SampleAsset& a : {make_car(), make_barrel()}) expect_inside(a.rest, pack_mesh(a.rest, 96).spheres, a.name);
}

TEST(Pack, SpheresInsideSharedMeshes) {
  SPX_REQUIRE_SHARED_DATA();
  for (const char* name : {"cube/rest.obj", "elephant/rest.obj", "static/bunny.off", "cylinder/rest.obj"}) {
    const TriMesh mesh = load_mesh(test::shared_data() + "/" + name).mesh;
    expect_inside(mesh, pack_mesh(mesh, 64).spheres, name);
  }
}

TEST(Pack, FieldRadiiStayInsideWithinAVoxel) {
  const TriMesh mesh = make_barrel().rest;
  SdfOptions sopt;
  sopt.resolution = 64;
  const SdfResult sdf = build_sdf(mesh, sopt);
  const PackResult r = pack_spheres(sdf.field, {}, nullptr);
  EXPECT_EQ(r.stats.radius_source, "field");
  const MeshQuery query(mesh);
  for (const auto& s : r.spheres) EXPECT_GE(query.distance(s.center), s.radius - 0.05 * sdf.field.shape.voxel_size);
}

TEST(Pack, LimitsAreHonoured) {
  const TriMesh mesh = make_car().rest;
  PackOptions opt;
  opt.min_radius = 0.1;
  opt.max_radius = 0.3;
  const PackResult r = pack_mesh(mesh, 80, opt);
  for (const auto& s : r.spheres) {
    EXPECT_GE(s.radius, 0.1);
    EXPECT_LE(s.radius, 0.3);
  }
  opt.max_spheres = 17;
  const PackResult capped = pack_mesh(mesh, 80, opt);
  EXPECT_EQ(capped.spheres.size(), 17u);
  EXPECT_EQ(capped.stats.stop_reason, "reached the max sphere count");
  // The capped run is a prefix of the full one: the order is the paper's deepest-first order.
  for (size_t i = 0; i < capped.spheres.size(); ++i) EXPECT_EQ(capped.spheres[i].center, r.spheres[i].center);
  // A smaller min radius only adds spheres.
  PackOptions finer = opt;
  finer.max_spheres = 0;
  finer.min_radius = 0.06;
  EXPECT_GT(pack_mesh(mesh, 80, finer).spheres.size(), r.spheres.size());
}

// The default method honours --min-radius and --max-radius too, after its centres move off the
// grid: on the knight (sharp tips, where a centre moved toward the surface shrinks) the tolerance
// run at 0.005 had chosen spheres down to 0.00044 (the candidates were all 0.005 or more).
TEST(Pack, CoverHonoursTheRadiusLimits) {
  SPX_REQUIRE_SHARED_DATA();
  const std::string dir = test::temp_dir("cover-limits");
  const std::string mesh = test::shared_data() + "/static/decimated-knight.off";
  json sdf_report;
  sdf_build_files(mesh, dir + "/knight.vdb", {}, Log::silent(), sdf_report);
  for (size_t budget : {size_t(0), size_t(40)}) {
    SpherePackOptions opt;
    opt.pack.min_radius = 0.005;
    opt.pack.max_radius = 0.05;
    opt.pack.max_spheres = budget;
    json report;
    sphere_pack_files(dir + "/knight.vdb", mesh, dir + "/knight.spheres.json", opt, {}, Log::silent(), report);
    const SphereSet spheres = read_spheres_file(dir + "/knight.spheres.json").spheres;
    ASSERT_FALSE(spheres.empty());
    for (const Sphere& s : spheres) {
      EXPECT_GE(s.radius, 0.005) << "budget " << budget;
      EXPECT_LE(s.radius, 0.05) << "budget " << budget;
    }
  }
}

TEST(Pack, CentersAreDeepestFirstAndNotInsideEarlierSpheres) {
  const TriMesh mesh = make_barrel().rest;
  const PackResult r = pack_mesh(mesh, 64, {}, false);
  for (size_t i = 1; i < r.spheres.size(); ++i) {
    EXPECT_LE(r.spheres[i].radius, r.spheres[i - 1].radius + 1e-6);  // field radii: deepest first
    for (size_t j = 0; j < i; ++j)
      EXPECT_GT((r.spheres[i].center - r.spheres[j].center).norm(), r.spheres[j].radius * (1 - 1e-9));
  }
}

// Tolerance search: the kept prefix meets T by the independent metric, and one sphere fewer
// does not (or the count is already 1).
TEST(Pack, ToleranceKeepsTheFewestSpheresThatMeetIt) {
  const TriMesh mesh = make_car().rest;
  PackOptions opt;
  opt.min_radius = 0.03;
  const PackResult all = pack_mesh(mesh, 96, opt);
  for (double fraction : {0.03, 0.015, 0.01}) {
    const double t = fraction * mesh.diagonal();
    const ToleranceResult r = fewest_spheres_within(mesh, all.spheres, t);
    ASSERT_TRUE(r.met) << fraction;
    const SphereSet kept(all.spheres.begin(), all.spheres.begin() + long(r.count));
    const ErrorStats e = vertex_error(mesh, kept);
    EXPECT_LE(e.max, t);
    EXPECT_NEAR(e.max, r.max_error, 1e-12);
    if (r.count > 1) {
      const SphereSet fewer(all.spheres.begin(), all.spheres.begin() + long(r.count) - 1);
      EXPECT_GT(vertex_error(mesh, fewer).max, t) << fraction;
    }
  }
  // A tolerance the sequence cannot reach reports the error it did reach, with every sphere.
  const ToleranceResult impossible = fewest_spheres_within(mesh, all.spheres, 1e-9);
  EXPECT_FALSE(impossible.met);
  EXPECT_EQ(impossible.count, all.spheres.size());
  EXPECT_NEAR(impossible.max_error, vertex_error(mesh, all.spheres).max, 1e-12);
  // Max error never grows as spheres are added.
  for (size_t k = 1; k < impossible.max_error_by_count.size(); ++k)
    EXPECT_LE(impossible.max_error_by_count[k], impossible.max_error_by_count[k - 1] + 1e-12);
}

TEST(Pack, RefinedCentersGrowSpheresAndStayInside) {
  const TriMesh mesh = make_car().rest;
  PackOptions grid, refined;
  grid.refine_centers = false;
  grid.max_spheres = refined.max_spheres = 150;
  const PackResult a = pack_mesh(mesh, 96, grid), b = pack_mesh(mesh, 96, refined);
  expect_inside(mesh, b.spheres, "refined");
  EXPECT_GT(b.stats.centers_refined, 0u);
  // At the same count the refined union is closer to the surface.
  EXPECT_LT(vertex_error(mesh, b.spheres).median, vertex_error(mesh, a.spheres).median);
}

TEST(Pack, BadOptionsAreUsageErrors) {
  const TriMesh mesh = make_barrel().rest;
  SdfOptions sopt;
  sopt.resolution = 16;
  const SdfResult sdf = build_sdf(mesh, sopt);
  auto code = [&](PackOptions opt) {
    try {
      pack_spheres(sdf.field, opt, nullptr);
    } catch (const Error& e) {
      return e.code();
    }
    return ExitCode::ok;
  };
  PackOptions a;
  a.min_radius = -1;
  EXPECT_EQ(code(a), ExitCode::usage);
  PackOptions b;
  b.max_radius = 0.001;
  b.min_radius = 0.01;
  EXPECT_EQ(code(b), ExitCode::usage);
  PackOptions c;
  c.max_radius = std::nan("");
  EXPECT_EQ(code(c), ExitCode::usage);
}

}  // namespace
}  // namespace spx

namespace spx {
namespace {

// Where the tolerance is out of reach, the parts whose vertices no candidate reaches are named
// with what would reach them. The robot's thin open parts at a coarse field (every radius also
// bounded by the field across the holes): the resolution that would, and a field of that
// resolution does. The car, closed, at a field too coarse for its voxels' candidates alone: its
// samples' own candidates meet the tolerance; where nothing can (spheres no smaller than a large
// --min-radius) the parts are named with no resolution, which would not help.
TEST(SpherePack, PartsOutOfReachAreNamedWithWhatWouldReachThem) {
  const std::string dir = test::temp_dir("reach");
  write_file_atomic(dir + "/robot.obj", to_obj(test::rest_of(*test::robot_asset(dir))));
  write_file_atomic(dir + "/car.obj", to_obj(make_car().rest));
  auto pack_at = [&](const std::string& name, int resolution, const SpherePackOptions& opt, Tolerance tolerance = {}) {
    SdfOptions o;
    o.resolution = resolution;
    json sdf_report, report;
    sdf_build_files(dir + "/" + name + ".obj", dir + "/" + name + ".vdb", o, Log::silent(), sdf_report);
    sphere_pack_files(dir + "/" + name + ".vdb", "", dir + "/" + name + ".spheres.json", opt, tolerance, Log::silent(),
                      report);
    return report;
  };
  const json coarse = pack_at("robot", 24, {});
  ASSERT_TRUE(coarse.contains("parts_out_of_reach"));
  const json& parts = coarse["parts_out_of_reach"];
  ASSERT_GT(parts.size(), 2u);
  double finest = 0;
  // The input's parts, not the solid surface's pieces of split triangles (each on vertices of
  // its own: 1367 "parts" of one triangle each, at 24 cells, before).
  const std::string of_parts = " of " + std::to_string(edge_components(load_mesh(dir + "/robot.obj").mesh).count) + " (";
  for (const json& part : parts) {
    EXPECT_EQ(part["part"].get<std::string>().rfind("part ", 0), 0u);
    EXPECT_NE(part["part"].get<std::string>().find(of_parts), std::string::npos) << part["part"];
    EXPECT_FALSE(part["flat"].get<bool>()) << part["part"];
    EXPECT_GT(part["vertices_out_of_reach"].get<size_t>(), 0u);
    EXPECT_GT(part["resolution_needed"].get<double>(), 24);
    finest = std::max(finest, part["resolution_needed"].get<double>());
  }
  EXPECT_LE(finest, coarse["resolution_needed"].get<double>());
  const json fine = pack_at("robot", int(finest), {});
  EXPECT_FALSE(fine.contains("parts_out_of_reach"));
  EXPECT_TRUE(fine["tolerance"]["met"].get<bool>());

  const Tolerance tight{0.4, true};
  SpherePackOptions voxels_only;
  voxels_only.tangent_candidates = false;
  const json car_voxels = pack_at("car", 16, voxels_only, tight);
  EXPECT_TRUE(car_voxels.contains("resolution_needed"));
  EXPECT_FALSE(car_voxels["tolerance"]["met"].get<bool>());
  const json car = pack_at("car", 16, {}, tight);
  EXPECT_FALSE(car.contains("parts_out_of_reach"));
  EXPECT_TRUE(car["tolerance"]["met"].get<bool>());
  EXPECT_GT(car["cover"]["chosen_from"]["samples"].get<size_t>(), 0u);
  EXPECT_EQ(car["cover"]["candidates_from"]["samples_unreached"].get<size_t>(), 0u);

  SpherePackOptions blunt;
  blunt.pack.min_radius = 0.03 * make_car().rest.diagonal();
  const json far = pack_at("car", 16, blunt, tight);
  ASSERT_TRUE(far.contains("parts_out_of_reach"));
  EXPECT_FALSE(far.contains("resolution_needed"));
  EXPECT_FALSE(far["tolerance"]["met"].get<bool>());
  EXPECT_GT(far["cover"]["candidates_from"]["samples_unreached"].get<size_t>(), 0u);
  for (const json& part : far["parts_out_of_reach"]) EXPECT_FALSE(part.contains("resolution_needed"));

  // A stray triangle far off (flat: it encloses no volume at any resolution) is named as flat,
  // and no resolution is said to reach it (the figure had been 6464 cells).
  TriMesh stray = make_car().rest;
  const int first = int(stray.vertices.size());
  const double d = stray.diagonal();
  for (const Eigen::Vector3d& v : {Eigen::Vector3d(3 * d, 0, 0), Eigen::Vector3d(3 * d + 0.002 * d, 0, 0),
                                   Eigen::Vector3d(3 * d, 0.002 * d, 0.001 * d)})
    stray.vertices.push_back(v);
  stray.triangles.emplace_back(first, first + 1, first + 2);
  write_file_atomic(dir + "/stray.obj", to_obj(stray));
  const json flat = pack_at("stray", 64, {});
  ASSERT_TRUE(flat.contains("parts_out_of_reach"));
  ASSERT_EQ(flat["parts_out_of_reach"].size(), 1u);
  const json& part = flat["parts_out_of_reach"][0];
  EXPECT_TRUE(part["flat"].get<bool>());
  EXPECT_EQ(part["part"].get<std::string>().rfind("part 2 of 2 (1 triangle around", 0), 0u) << part["part"];
  // sdf-build names the same part around the same point.
  const std::vector<std::string> far_parts = find_defects(stray).far_parts;
  ASSERT_EQ(far_parts.size(), 1u);
  EXPECT_EQ(far_parts[0].rfind(part["part"].get<std::string>() + " stretches", 0), 0u) << far_parts[0] << part["part"];
  EXPECT_FALSE(part.contains("resolution_needed"));
  EXPECT_FALSE(flat.contains("resolution_needed"));
  EXPECT_EQ(flat["tolerance"]["limited_by"].get<std::string>().rfind("flat parts", 0), 0u) << flat["tolerance"];

  // A box off to the side, open (one face missing) and facing inward, beside the car: the
  // winding number is under 1/2 on both sides of its walls, which hold no sphere at any
  // resolution. Its vertices are counted as having no solid beside them and no resolution is
  // named for them (the broken truck's 1 504 cells, at 133, had named a field that reached none).
  TriMesh inward = make_car().rest;
  const int base = int(inward.vertices.size());
  for (int k = 0; k < 8; ++k)
    inward.vertices.emplace_back(3 * d + 0.1 * d * (k & 1), 0.1 * d * ((k >> 1) & 1), 0.1 * d * ((k >> 2) & 1));
  // The box's faces wound inward (clockwise seen from outside); the top (z = 1) left out.
  for (const auto& [a, b, c] : std::vector<std::array<int, 3>>{{0, 1, 2}, {1, 3, 2}, {0, 4, 1}, {1, 4, 5},
                                                                {2, 3, 6}, {3, 7, 6}, {0, 2, 4}, {2, 6, 4},
                                                                {1, 5, 3}, {3, 5, 7}})
    inward.triangles.emplace_back(base + a, base + b, base + c);
  write_file_atomic(dir + "/inward.obj", to_obj(inward));
  // Closed too (its top put back): the mesh is then watertight, the field does not bound the
  // radii, and the cause had been given as sharp features.
  TriMesh closed_inward = inward;
  closed_inward.triangles.emplace_back(base + 4, base + 6, base + 5);
  closed_inward.triangles.emplace_back(base + 5, base + 6, base + 7);
  write_file_atomic(dir + "/closed-inward.obj", to_obj(closed_inward));
  for (const auto& [name, triangles] : {std::pair<std::string, int>{"inward", 10}, {"closed-inward", 12}}) {
    const json box = pack_at(name, 64, {});
    ASSERT_TRUE(box.contains("parts_out_of_reach")) << name << box["tolerance"];
    ASSERT_EQ(box["parts_out_of_reach"].size(), 1u) << name << box["parts_out_of_reach"];
    const json& box_part = box["parts_out_of_reach"][0];
    EXPECT_FALSE(box_part["flat"].get<bool>()) << name;
    EXPECT_EQ(box_part["part"].get<std::string>().rfind("part 2 of 2 (" + std::to_string(triangles) + " triangles around", 0),
              0u)
        << box_part["part"];
    EXPECT_GT(box_part["vertices_out_of_reach"].get<size_t>(), 0u) << name;
    EXPECT_EQ(box_part["vertices_with_no_solid_beside"], box_part["vertices_out_of_reach"]) << name;
    EXPECT_FALSE(box_part.contains("resolution_needed")) << name;
    EXPECT_FALSE(box.contains("resolution_needed")) << name;
    EXPECT_EQ(box["tolerance"]["limited_by"].get<std::string>().rfind("flat parts, or surface with no solid", 0), 0u)
        << name << box["tolerance"];
  }
}

}  // namespace
}  // namespace spx
