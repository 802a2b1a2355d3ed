// Bad and broken input: each case ends in its documented outcome (docs/robustness.md).
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <set>

#include <openvdb/openvdb.h>

#include "core/base64.hpp"
#include "core/atomic_file.hpp"
#include "core/cache_folder.hpp"
#include "core/error.hpp"
#include "core/format.hpp"
#include "core/version.hpp"
#include "tool/tool.hpp"
#include "io/spx_writer.hpp"
#include "mesh/defects.hpp"
#include "mesh/mesh_query.hpp"
#include "mesh/winding_number.hpp"
#include "pack/pack.hpp"
#include "pack/sphere_pack_tool.hpp"
#include "sdf/sdf_build_tool.hpp"
#include "io/spheres_file.hpp"
#include "posemap/posemap.hpp"
#include "io/proxy_file.hpp"
#include "synthetic/synthetic.hpp"
#include "sdf/sdf.hpp"
#include "io/vdb_io.hpp"
#include "spx_runtime.h"
#include "test_util.hpp"

namespace spx {
namespace {

ExitCode code_of(const std::function<void()>& fn) {
  try {
    fn();
  } catch (const Error& e) {
    return e.code();
  }
  return ExitCode::ok;
}

// Sphere surfaces (26 directions at 98% of the radius, `inset` further in) and centers lie in the
// winding-number solid.
void expect_in_winding_solid(const TriMesh& mesh, const SphereSet& spheres, const std::string& what,
                             double inset = 0) {
  ASSERT_FALSE(spheres.empty()) << what;
  for (size_t s = 0; s < spheres.size(); ++s) {
    EXPECT_GT(winding_number_exact(mesh, spheres[s].center), 0.5) << what << " sphere " << s;
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          if (!dx && !dy && !dz) continue;
          const double in = std::max(0.0, 0.98 * spheres[s].radius - inset);
          const Eigen::Vector3d p = spheres[s].center + in * Eigen::Vector3d(dx, dy, dz).normalized();
          EXPECT_GT(winding_number_exact(mesh, p), 0.5) << what << " sphere " << s << " pokes out at " << p.transpose();
        }
  }
}

TEST(BrokenData, ChainCompletesWithARobustSignAndSpheresStayInTheSolid) {
  SPX_REQUIRE_SHARED_DATA();
  for (const char* name : {"broken/truck.obj", "broken/two-boxes-bad-self-union.ply", "broken/hemisphere.obj",
                           "broken/cube_with_fold.ply", "cylinder/rest.obj"}) {
    const TriMesh mesh = load_mesh(test::shared_data() + "/" + name).mesh;
    SdfOptions sopt;
    sopt.resolution = 48;
    const SdfResult sdf = build_sdf(mesh, sopt);
    const MeshQuery query(mesh);
    PackOptions popt;
    popt.field_bounds_radius = sdf.stats.bounded_by_holes;
    expect_in_winding_solid(mesh, pack_spheres(sdf.field, popt, &query).spheres, name);
  }
}

// The tools, as a pipeline chains them: sphere-pack takes the mesh sdf-build recorded. Where
// parts overlap (the two boxes' walls inside the solid) the field's surface is the solid's, and
// those walls' vertices lie inside it: sphere-pack refused the very mesh the field was built
// from ("17 of its 360 vertices lie more than 2 voxels off the field's surface").
TEST(BrokenData, SpherePackTakesTheMeshTheFieldWasBuiltFrom) {
  SPX_REQUIRE_SHARED_DATA();
  const std::string dir = test::temp_dir("broken-tools");
  for (const char* name : {"broken/two-boxes-bad-self-union.ply", "broken/truck.obj", "broken/hemisphere.obj",
                           "broken/cube_with_fold.ply"}) {
    const std::string path = test::shared_data() + "/" + name, field = dir + "/field.vdb";
    SdfOptions sopt;
    sopt.resolution = 48;
    json sdf_report, pack_report;
    sdf_build_files(path, field, sopt, Log::silent(), sdf_report);
    ASSERT_EQ(code_of([&] {
                sphere_pack_files(field, "", dir + "/spheres.json", SpherePackOptions{}, Tolerance{}, Log::silent(),
                                  pack_report);
              }),
              ExitCode::ok)
        << name;
    // The truck is a soup of open parts: at its rims the winding number's 1/2 level, which closes
    // its holes, is placed by the field to a fraction of a voxel, and its smallest spheres cross it
    // by up to 0.034 voxel (docs/robustness.md): checked the field's margin in from their surface.
    const double voxel = sdf_report["grid"]["voxel_size"].get<double>();
    const double inset = std::string(name) == "broken/truck.obj" ? kFieldMargin * voxel : 0.0;
    expect_in_winding_solid(load_mesh(path).mesh, read_spheres_file(dir + "/spheres.json").spheres, name, inset);
  }
}

TEST(BrokenData, DefectsAreReported) {
  SPX_REQUIRE_SHARED_DATA();
  const MeshDefects truck = find_defects(load_mesh(test::shared_data() + "/broken/truck.obj").mesh);
  EXPECT_EQ(truck.boundary_edges, 1388u);  // as the data's README counts them
  EXPECT_EQ(truck.non_manifold_edges, 54u);
  EXPECT_GT(truck.inconsistent_edges, 0u);
  EXPECT_GE(truck.components, 40u);
  EXPECT_FALSE(truck.watertight());
  const MeshDefects hemi = find_defects(load_mesh(test::shared_data() + "/broken/hemisphere.obj").mesh);
  EXPECT_GT(hemi.boundary_edges, 0u);
}

TEST(BrokenData, ZeroVolumeStopsWithAClearError) {
  SPX_REQUIRE_SHARED_DATA();
  const TriMesh flat = load_mesh(test::shared_data() + "/broken/degenerated.obj").mesh;
  EXPECT_EQ(code_of([&] { build_sdf(flat, {}); }), ExitCode::bad_input);
}

// A closed mesh whose triangles all face inward (an asset exported inside out): the winding
// number is -1 within it, so by the tools' rule (inside past 1/2) it encloses nothing, and
// sdf-build says so and how to mend it. Its pseudo-normals had marked the voxels just outside
// its surface as inside: a shell of a field, written without a word, in which sphere-pack then
// found no interior voxel.
TEST(BrokenData, InsideOutMeshStopsWithAClearError) {
  TriMesh box = test::box_mesh(Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones());
  for (auto& t : box.triangles) std::swap(t[1], t[2]);
  // Two such boxes welded face to face: closed, not manifold (4 triangles on the shared face's
  // edges). It was told to try a finer resolution.
  TriMesh two;
  std::vector<Eigen::Vector3d> corners;
  for (const Eigen::Vector3d& shift : {Eigen::Vector3d::Zero().eval(), Eigen::Vector3d::UnitX().eval()})
    for (const Eigen::Vector3i& t : box.triangles)
      for (int k = 0; k < 3; ++k) corners.push_back(box.vertices[size_t(t[k])] + shift);
  const std::vector<int> weld = weld_by_position(corners, two.vertices);
  for (size_t c = 0; c < weld.size(); c += 3) two.triangles.emplace_back(weld[c], weld[c + 1], weld[c + 2]);
  ASSERT_EQ(two.vertices.size(), 12u);
  for (const TriMesh* inward : {&box, &two}) {
    SdfOptions o;
    o.resolution = 24;
    try {
      build_sdf(*inward, o);
      ADD_FAILURE() << "an inside-out mesh gave a field";
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ExitCode::bad_input);
      EXPECT_NE(std::string(e.what()).find("face inward"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("flip its faces"), std::string::npos) << e.what();
    }
  }
}

// One part inside out among others (a wheel exported inside out) encloses nothing and gets no
// spheres: named, where an inward shell inside another part (a cavity) is not.
TEST(BrokenData, InsideOutPartsAreNamedAndCavitiesAreNot) {
  auto joined = [](const TriMesh& a, TriMesh b, bool flip_b) {
    TriMesh out = a;
    const int first = int(out.vertices.size());
    for (const auto& v : b.vertices) out.vertices.push_back(v);
    for (auto t : b.triangles) {
      if (flip_b) std::swap(t[1], t[2]);
      out.triangles.push_back(t + Eigen::Vector3i::Constant(first));
    }
    return out;
  };
  const TriMesh body = test::box_mesh(Eigen::Vector3d::Zero(), Eigen::Vector3d::Constant(3));
  const TriMesh apart = joined(body, test::box_mesh(Eigen::Vector3d(4, 0, 0), Eigen::Vector3d(5, 1, 1)), true);
  const MeshDefects d = find_defects(apart);
  ASSERT_EQ(d.inside_out_parts.size(), 1u);
  EXPECT_EQ(d.inside_out_parts[0].rfind("part 2 of 2 (", 0), 0u) << d.inside_out_parts[0];
  const TriMesh cavity = joined(body, test::box_mesh(Eigen::Vector3d::Ones(), Eigen::Vector3d::Constant(2)), true);
  EXPECT_TRUE(find_defects(cavity).inside_out_parts.empty());
  EXPECT_TRUE(find_defects(body).inside_out_parts.empty());
}

// A stray triangle far off sets the grid's voxel and every tolerance in % of the diagonal:
// named by sdf-build, with the diagonal it stretches; the body's own parts are not.
TEST(BrokenData, AStrayTriangleFarOffIsNamed) {
  TriMesh car = make_car().rest;
  EXPECT_TRUE(find_defects(car).far_parts.empty());
  const double d = car.diagonal();
  const int first = int(car.vertices.size());
  for (const Eigen::Vector3d& v : {Eigen::Vector3d(3 * d, 0, 0), Eigen::Vector3d(3 * d + 0.002 * d, 0, 0),
                                   Eigen::Vector3d(3 * d, 0.002 * d, 0)})
    car.vertices.push_back(v);
  car.triangles.emplace_back(first, first + 1, first + 2);
  const MeshDefects defects = find_defects(car);
  ASSERT_EQ(defects.far_parts.size(), 1u);
  EXPECT_NE(defects.far_parts[0].find(" of 2 (1 triangle around "), std::string::npos) << defects.far_parts[0];
  EXPECT_NE(defects.far_parts[0].find("stretches the diagonal from " + num(d)), std::string::npos) << defects.far_parts[0];
}

TEST(GeneratedInput, DegenerateShapesAndScales) {
  TriMesh triangle;
  triangle.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  triangle.triangles = {{0, 1, 2}};
  EXPECT_EQ(code_of([&] { build_sdf(triangle, {}); }), ExitCode::bad_input);
  TriMesh line;
  line.vertices = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {3, 0, 0}};
  line.triangles = {{0, 1, 2}, {1, 2, 3}};
  EXPECT_EQ(code_of([&] { build_sdf(line, {}); }), ExitCode::bad_input);
  EXPECT_EQ(code_of([&] { MeshQuery q(line); }), ExitCode::bad_input);
  // Far from the origin and huge: works (sizes are relative).
  for (double scale : {1e9, 1e-3}) {
    TriMesh box = test::box_mesh(Eigen::Vector3d::Constant(scale), Eigen::Vector3d::Constant(2 * scale));
    SdfOptions o;
    o.resolution = 24;
    const SdfResult sdf = build_sdf(box, o);
    const MeshQuery q(box);
    const PackResult r = pack_spheres(sdf.field, {}, &q);
    ASSERT_FALSE(r.spheres.empty()) << scale;
    for (const auto& s : r.spheres) EXPECT_GE(q.distance(s.center), s.radius - 1e-9 * scale);
  }
  // Tiny: refused up front with an explanation (OpenVDB's smallest voxel).
  const TriMesh tiny = test::box_mesh(Eigen::Vector3d::Zero(), Eigen::Vector3d::Constant(1e-9));
  EXPECT_EQ(code_of([&] { build_sdf(tiny, {}); }), ExitCode::unsupported);
}

// Every mesh reader reads single precision: a mesh far from the origin for its size is read
// coarser than written, by half the spacing of floats at its largest coordinate.
TEST(GeneratedInput, MeshesReadCoarserThanTheirFieldAreNamed) {
  const auto box_at = [](double offset) {  // a unit box, its corners as a reader gives them
    TriMesh box = test::box_mesh(Eigen::Vector3d::Constant(offset), Eigen::Vector3d::Constant(offset + 1));
    for (Eigen::Vector3d& v : box.vertices) v = v.cast<float>().cast<double>();
    return box;
  };
  EXPECT_EQ(read_rounding(box_at(0)), std::ldexp(1.0, -24));  // floats in [1, 2) are 2^-23 apart
  EXPECT_EQ(read_rounding(box_at(1e5)), std::ldexp(1.0, -8));  // in [65536, 131072) 2^-7
  EXPECT_EQ(read_rounding(box_at(-1e6)), std::ldexp(1.0, -5));
  const double voxel = 1.0 / 128;
  Log near;
  check_read_rounding(box_at(1e4), voxel, "near.obj", near);  // 0.06 of a voxel
  EXPECT_TRUE(near.warnings().empty());
  Log far;
  check_read_rounding(box_at(1e5), voxel, "far.obj", far);  // half a voxel
  ASSERT_EQ(far.warnings().size(), 1u);
  EXPECT_NE(far.warnings()[0].find("far.obj: its coordinates reach 1e+05, where the mesh readers' single precision "
                                   "places a vertex only to within 0.003906 of the file's, 0.5 of a voxel"),
            std::string::npos)
      << far.warnings()[0];
  const std::string refused = test::bad_input_error([&] { check_read_rounding(box_at(1e6), voxel, "farther.obj", far); });
  EXPECT_NE(refused.find("farther.obj: its coordinates reach 1e+06, where the mesh readers' single precision places a "
                         "vertex only to within 0.03125 of the file's, 4 voxels of 0.007812"),
            std::string::npos)
      << refused;
  EXPECT_NE(refused.find("move the mesh near the origin"), std::string::npos) << refused;
  // A coarser field takes the same mesh.
  Log coarse;
  check_read_rounding(box_at(1e6), 1.0, "farther.obj", coarse);
  EXPECT_TRUE(coarse.warnings().empty());
}

TEST(GeneratedInput, AbsurdParameters) {
  const TriMesh box = test::box_mesh({0, 0, 0}, {1, 1, 1});
  for (double v : {-1.0, std::nan(""), std::numeric_limits<double>::infinity()}) {
    SdfOptions o;
    o.voxel_size = v;
    EXPECT_EQ(code_of([&] { build_sdf(box, o); }), ExitCode::usage) << v;
  }
  SdfOptions band;
  band.band = 0;
  EXPECT_EQ(code_of([&] { build_sdf(box, band); }), ExitCode::usage);
  SdfOptions huge;
  huge.resolution = 5000;  // ~125e9 voxels
  EXPECT_EQ(code_of([&] { build_sdf(box, huge); }), ExitCode::unsupported);
  PoseMapOptions pm;
  pm.tets.size = 1e-9;
  EXPECT_EQ(code_of([&] { tetrahedralize(box, pm.tets); }), ExitCode::usage);
}

TEST(PoseInput, SwappedRestAndPoseIsCaught) {
  const SampleAsset car = make_car();
  const SpheresFile spheres = test::pack_file(car.rest, 48);
  // The roof crumple given as the rest mesh, the real rest given as a pose.
  const ExitCode c = code_of([&] { pose_map(car.pose(3), "roof.obj", {{"rest", "rest.obj", car.rest}}, spheres, {}); });
  EXPECT_EQ(c, ExitCode::bad_input);
}

TEST(FilesBetweenTools, VdbWithTheWrongGridIsRejected) {
  openvdb::initialize();
  const std::string dir = test::temp_dir("vdbgrid");
  auto vec = openvdb::Vec3SGrid::create();
  vec->setName("velocity");
  vec->tree().setValue(openvdb::Coord(0, 0, 0), openvdb::Vec3s(1, 0, 0));
  openvdb::io::File(dir + "/vec.vdb").write({vec});
  EXPECT_EQ(code_of([&] { read_sdf_vdb(dir + "/vec.vdb"); }), ExitCode::bad_input);
  openvdb::io::File(dir + "/none.vdb").write(openvdb::GridCPtrVec{});
  EXPECT_EQ(code_of([&] { read_sdf_vdb(dir + "/none.vdb"); }), ExitCode::bad_input);
  auto fog = openvdb::FloatGrid::create(0.0f);  // a density grid: background 0, not a distance
  fog->setName("density");
  fog->tree().setValue(openvdb::Coord(1, 1, 1), 1.0f);
  openvdb::io::File(dir + "/fog.vdb").write({fog});
  EXPECT_EQ(code_of([&] { read_sdf_vdb(dir + "/fog.vdb"); }), ExitCode::bad_input);
}

TEST(FilesBetweenTools, JsonThatViolatesItsSchemaIsRejected) {
  const std::string dir = test::temp_dir("json");
  const std::string head = R"({"format": "spx-spheres", "version": 1, "voxel_size": 0.1, "min_radius": 0.1, "max_radius": null, )";
  const std::vector<std::pair<std::string, ExitCode>> cases = {
      {head + R"("spheres": [[0, 0, 0, -1]]})", ExitCode::bad_input},
      {head + R"("spheres": [[0, 0, 0]]})", ExitCode::bad_input},
      {head + R"("spheres": [[0, "x", 0, 1]]})", ExitCode::bad_input},
      {head + R"("spheres": []})", ExitCode::bad_input},
      {head + R"("spheres": {}})", ExitCode::bad_input},
      {R"({"format": "spx-spheres", "version": 3, "spheres": []})", ExitCode::unsupported},
      {R"([1, 2, 3])", ExitCode::bad_input},
      {R"({"format": "spx-spheres", "version": 1, "voxel_size": 1e999})", ExitCode::bad_input},
  };
  for (size_t i = 0; i < cases.size(); ++i) {
    write_file_atomic(dir + "/s.json", cases[i].first);
    EXPECT_EQ(code_of([&] { read_spheres_file(dir + "/s.json"); }), cases[i].second) << cases[i].first;
  }
  const std::vector<std::string> proxies = {
      R"({"format": "spx-proxy", "version": 1, "max_radius": null, "poses": [{"name": "a", "spheres": [[0,0,0,1]]}], "sites": [[0,0,0]], "sphere_sites": [1]})",
      R"({"format": "spx-proxy", "version": 1, "max_radius": null, "poses": [{"name": "a", "spheres": [[0,0,0,1]]}, {"name": "b", "spheres": []}], "sites": [[0,0,0]], "sphere_sites": [0]})",
      R"({"format": "spx-proxy", "version": 1, "max_radius": null, "poses": [], "sites": [], "sphere_sites": []})",
      R"({"format": "spx-proxy", "version": 1, "max_radius": null, "poses": [{"name": 5, "spheres": [[0,0,0,1]]}], "sites": [[0,0,0]], "sphere_sites": [0]})",
      R"({"format": "spx-proxy", "version": 1, "max_radius": null, "poses": [{"name": "a", "spheres": [[0,0,0,1]], "outside": "x"}], "sites": [[0,0,0]], "sphere_sites": [0]})",
  };
  for (const auto& text : proxies) {
    write_file_atomic(dir + "/p.json", text);
    EXPECT_EQ(code_of([&] { read_proxy_file(dir + "/p.json"); }), ExitCode::bad_input) << text;
  }
  // A skinned sphere with no positive weight would be written to a .spx the runtime refuses
  // (SPX_ERR_BAD_SKIN): the reader refuses it first. The same sphere weighted is read.
  ProxyModel skinned;
  skinned.poses.push_back({"rest", "rest.obj", {{Eigen::Vector3d::Zero(), 1.0}}, {}});
  skinned.sites = {Eigen::Vector3d::Zero()};
  skinned.sphere_sites = {0};
  skinned.skin.joints = {"root"};
  skinned.skin.parents = {-1};
  skinned.skin.spheres.push_back({{{0, 0, 0, 0}}, {{1, 0, 0, 0}}, Eigen::Vector3d::Zero(), 1.0});
  json weighted = proxy_to_json(skinned);
  EXPECT_EQ(code_of([&] { proxy_from_json(weighted, "f.json"); }), ExitCode::ok);
  weighted["skin"]["spheres"][0]["weights"] = {0, 0, 0, 0};
  EXPECT_EQ(code_of([&] { proxy_from_json(weighted, "f.json"); }), ExitCode::bad_input);
  // Nor parents that never reach a root (a joint its own parent, or a cycle): proxy-export wrote
  // the one into a .spx the runtime refused and the other into one a host's walk to the root
  // never leaves. A chain to the root is read.
  skinned.skin.joints = {"hips", "knee", "foot"};
  for (const auto& [parents, valid] : std::vector<std::pair<std::vector<int>, bool>>{
           {{-1, 0, 1}, true}, {{2, -1, 1}, true}, {{-1, 1, 1}, false}, {{2, 0, 1}, false}, {{-1, 2, 1}, false}}) {
    skinned.skin.parents = parents;
    EXPECT_EQ(code_of([&] { proxy_from_json(proxy_to_json(skinned), "f.json"); }),
              valid ? ExitCode::ok : ExitCode::bad_input)
        << parents[0] << " " << parents[1] << " " << parents[2];
  }
  // Fields of the wrong type end in our own error naming the file, never in the JSON library's
  // unnamed type error (fuzz.short found {"format": 625}).
  for (const std::string& text : std::vector<std::string>{R"({"format": 625})", R"({"format": ["spx-spheres"]})",
                                 head + R"("radius_source": 5, "spheres": [[0, 0, 0, 1]]})"})
    EXPECT_EQ(code_of([&] { spheres_from_json(json::parse(text), "f.json"); }), ExitCode::bad_input) << text;
  for (const std::string& text : std::vector<std::string>{R"({"format": 625})",
                                 R"({"format": "spx-proxy", "version": 1, "max_radius": null, "poses": [{"name": "a", "source": 5, "spheres": [[0,0,0,1]]}], "sites": [[0,0,0]], "sphere_sites": [0]})"})
    EXPECT_EQ(code_of([&] { proxy_from_json(json::parse(text), "f.json"); }), ExitCode::bad_input) << text;
}

TEST(FilesBetweenTools, SpxWithASiteOutOfRangeIsBadData) {
  ProxyModel p;
  p.poses.push_back({"rest", "", {{Eigen::Vector3d::Zero(), 1.0}, {Eigen::Vector3d::Ones(), 0.5}}, {}});
  p.sites = {Eigen::Vector3d::Zero()};
  p.sphere_sites = {0, 0};
  std::string bytes = encode_spx(p);
  const uint32_t at = uint32_t(uint8_t(bytes[44])) | uint32_t(uint8_t(bytes[45])) << 8;  // sphere sites offset
  bytes[at + 4] = 7;  // second sphere's site: 7 of 1
  const uint32_t crc = detail::crc32(reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size() - 4);
  for (int k = 0; k < 4; ++k) bytes[bytes.size() - 4 + size_t(k)] = char((crc >> (8 * k)) & 0xFF);
  Proxy proxy;
  EXPECT_EQ(load_memory(bytes.data(), bytes.size(), &proxy), SPX_ERR_BAD_DATA);
  EXPECT_TRUE(proxy.empty());
}

}  // namespace
}  // namespace spx

namespace spx {
namespace {

// Expected failures are spx::Errors with their class; anything else is a bug and says so.
TEST(Tool, UnexpectedExceptionsAreInternalErrors) {
  char name[] = "tool";
  char* argv[] = {name, nullptr};
  Tool bug("tool", "test");
  EXPECT_EQ(bug.run(1, argv, [] { throw std::logic_error("boom"); }), int(ExitCode::internal));
  Tool bad("tool", "test");
  EXPECT_EQ(bad.run(1, argv, [] { fail_input("in.obj", "bad"); }), int(ExitCode::bad_input));
}

// The caches between runs are keyed on the program's build: build_identity must be the build ID
// the linker wrote, as binutils reads it off the program's file.
TEST(Tool, BuildIdentityIsTheProgramsBuildId) {
  // readelf on this program's file (its own /proc/self would be the shell's).
  const std::string self = std::filesystem::read_symlink("/proc/self/exe").string();
  FILE* pipe = popen(("readelf -n '" + self + "' 2>/dev/null").c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  std::string text;
  char buffer[512];
  while (fgets(buffer, sizeof buffer, pipe)) text += buffer;
  pclose(pipe);
  const size_t at = text.find("Build ID: ");
  if (at == std::string::npos) GTEST_SKIP() << "readelf found no build ID in " << self;
  const std::string id = text.substr(at + 10, text.find('\n', at) - at - 10);
  EXPECT_EQ(build_identity(), id);
  EXPECT_GE(build_identity().size(), 16u);
}

}  // namespace
}  // namespace spx

namespace spx {
namespace {

// tests/data/json: documents the schemas accept or reject (ctest schema.*); the readers must
// agree on each one.
TEST(FilesBetweenTools, SharedDocumentsAreJudgedAsTheSchemasJudge) {
  const std::string root = std::string(SPX_TEST_DATA) + "/json/";
  size_t judged = 0;
  for (const std::string kind : {"spheres", "proxy"})
    for (const bool valid : {true, false})
      for (const auto& entry : std::filesystem::directory_iterator(root + kind + (valid ? "/valid" : "/invalid"))) {
        const std::string path = entry.path().string();
        auto read = [&] {
          if (kind == "spheres") read_spheres_file(path);
          else read_proxy_file(path);
        };
        ++judged;
        if (valid) {
          EXPECT_NO_THROW(read()) << path;
          continue;
        }
        try {
          read();
          ADD_FAILURE() << path << " was accepted; its schema rejects it";
        } catch (const Error& e) {
          EXPECT_EQ(e.code(), ExitCode::bad_input) << path << ": " << e.what();
          EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
        }
      }
  EXPECT_GE(judged, 30u);
}

}  // namespace
}  // namespace spx

// The page's arrays and glTF's data: URIs: RFC 4648's test vectors, every byte value and length
// back through the decoder, and a character outside the alphabet refused.
TEST(FilesBetweenTools, Base64RoundTripsEveryByteAndLength) {
  const std::pair<std::string, std::string> rfc[] = {{"", ""},         {"f", "Zg=="},         {"fo", "Zm8="},
                                                     {"foo", "Zm9v"},  {"foob", "Zm9vYg=="}, {"fooba", "Zm9vYmE="},
                                                     {"foobar", "Zm9vYmFy"}};
  for (const auto& [plain, coded] : rfc) {
    EXPECT_EQ(spx::encode_base64(plain.data(), plain.size()), coded);
    EXPECT_EQ(spx::decode_base64(coded).value(), plain);
  }
  std::string all;
  for (int b = 0; b < 256; ++b) all += char(b);
  for (size_t n = 0; n <= all.size(); n += 37) {
    const std::string part = all.substr(all.size() - n);
    EXPECT_EQ(spx::decode_base64(spx::encode_base64(part.data(), part.size())).value(), part) << n;
  }
  EXPECT_FALSE(spx::decode_base64("Zm9v*mFy").has_value());
}

// --cache-limit: the tools' cache files removed least recently used first (time, then name) until
// the folder is under the limit, never this run's nor any file the tools do not name so; against
// the plain account (the shortest run of the oldest files not in use whose removal is enough) at
// every limit between none and all. A file read is marked used and goes last. A killed run's
// temporary file of a cache file, two hours old, goes whatever the limit; a live run's stays.
TEST(CacheFolder, TrimRemovesTheLeastRecentlyUsedFirst) {
  namespace fs = std::filesystem;
  struct File {
    std::string name;
    uint64_t bytes;
    int age;  // seconds before now; two files share one, so that their names decide
  };
  std::vector<File> files;
  for (int k = 0; k < 10; ++k) {
    char key[17];
    std::snprintf(key, sizeof key, "%016llx", 0x9e3779b97f4a7c15ull * (k + 1));
    const char* kinds[] = {"pose-", "tets-", "carry-", "candidates-"};
    const char* exts[] = {".bin", ".mesh", ".bin", ".bin"};
    files.push_back({kinds[k % 4] + std::string(key) + exts[k % 4], uint64_t(100 + 37 * ((k * 7) % 10)),
                     k == 3 ? 500 : 100 * (k + 1)});
  }
  const std::vector<std::string> others = {"notes.txt", "pose-123.bin", ".pose-0123456789abcdef.bin.tmp.99",
                                           "Pose-0123456789abcdef.bin", "pose-0123456789ABCDEF.bin"};
  const std::vector<std::string> in_use = {files[9].name, files[0].name};  // the oldest, and the newest
  uint64_t total = 0;
  for (const File& f : files) total += f.bytes;
  const auto now = fs::file_time_type::clock::now();
  const std::string stale_temp = ".tets-0123456789abcdef.mesh.tmp.4242";
  const auto make = [&](const std::string& dir) {
    fs::remove_all(dir);
    fs::create_directories(dir + "/carry-0123456789abcdef.bin");  // a folder: not a cache file
    for (const File& f : files) {
      spx::write_file_atomic(dir + "/" + f.name, std::string(f.bytes, 'x'));
      fs::last_write_time(dir + "/" + f.name, now - std::chrono::seconds(f.age));
    }
    for (const std::string& name : others) spx::write_file_atomic(dir + "/" + name, std::string(5000, 'y'));
    // Temporary files two hours old: a cache file's (a killed run's: it goes) and another's (stays).
    for (const std::string& name : {stale_temp, std::string(".notes.txt.tmp.5")}) {
      spx::write_file_atomic(dir + "/" + name, std::string(300, 'z'));
      fs::last_write_time(dir + "/" + name, now - std::chrono::hours(2));
    }
  };
  // The plain account: oldest first, names breaking ties; in-use files passed over.
  std::vector<File> order = files;
  std::sort(order.begin(), order.end(), [](const File& a, const File& b) {
    return a.age != b.age ? a.age > b.age : a.name < b.name;
  });
  const std::string dir = spx::test::temp_dir("cache-trim");
  std::vector<std::string> in_use_paths;
  for (const std::string& name : in_use) in_use_paths.push_back(dir + "/" + name);
  for (uint64_t limit = 0; limit <= total + 50; limit += 97) {
    make(dir);
    const spx::CacheTrim trim = spx::trim_cache_folder(dir, limit, in_use_paths);
    std::set<std::string> expected_gone;
    uint64_t left = total;
    for (const File& f : order) {
      if (limit == 0 || left <= limit) break;
      if (std::find(in_use.begin(), in_use.end(), f.name) != in_use.end()) continue;
      expected_gone.insert(f.name);
      left -= f.bytes;
    }
    uint64_t removed_bytes = 0;
    for (const File& f : files) {
      EXPECT_EQ(fs::exists(dir + "/" + f.name), expected_gone.count(f.name) == 0) << f.name << " at " << limit;
      if (expected_gone.count(f.name)) removed_bytes += f.bytes;
    }
    for (const std::string& name : others) EXPECT_TRUE(fs::exists(dir + "/" + name)) << name;
    EXPECT_TRUE(fs::is_directory(dir + "/carry-0123456789abcdef.bin"));
    EXPECT_TRUE(fs::exists(dir + "/.notes.txt.tmp.5"));
    EXPECT_FALSE(fs::exists(dir + "/" + stale_temp)) << "at " << limit;  // whatever the limit
    EXPECT_EQ(trim.files_removed, expected_gone.size() + 1);
    EXPECT_EQ(trim.bytes_removed, removed_bytes + 300);
    EXPECT_EQ(trim.files_kept, files.size() - expected_gone.size());
    EXPECT_EQ(trim.bytes_kept, total - removed_bytes);
    EXPECT_EQ(trim.limit, limit);
  }
  // Read (with its head), the oldest file not in use is marked used: now the last to go.
  make(dir);
  const File& oldest = order[0].name == files[9].name ? order[1] : order[0];
  ASSERT_TRUE(spx::read_cache_file(dir + "/" + oldest.name, "xx").has_value());
  const spx::CacheTrim trim = spx::trim_cache_folder(dir, total - oldest.bytes, in_use_paths);
  EXPECT_TRUE(fs::exists(dir + "/" + oldest.name));
  EXPECT_EQ(trim.files_removed, 2u);  // the oldest not in use, and the stale temporary file
  // Another key's file (a head that does not match) is not marked.
  make(dir);
  EXPECT_FALSE(spx::read_cache_file(dir + "/" + oldest.name, "yy").has_value());
  spx::trim_cache_folder(dir, total - oldest.bytes, in_use_paths);
  EXPECT_FALSE(fs::exists(dir + "/" + oldest.name));
}
