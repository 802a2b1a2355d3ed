#pragma once
// Helpers shared by the unit tests: real data beside the checkout, small generated meshes.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>
#include <system_error>
#include <vector>

#include "core/atomic_file.hpp"
#include "core/error.hpp"
#include "extract/asset.hpp"
#include "mesh/mesh.hpp"
#include "mesh/mesh_query.hpp"
#include "pack/pack.hpp"
#include "io/scene.hpp"
#include "io/spheres_file.hpp"
#include "sdf/sdf.hpp"
#include "synthetic/synthetic.hpp"

namespace spx::test {

// ../shared/data beside the checkout; tests that need it skip (with a message) only when absent.
inline std::string shared_data() { return SPX_SHARED_DATA; }

// The error `run` gives, checked to be bad input's (exit 2), or "no error".
template <class Run>
std::string bad_input_error(Run&& run) {
  try {
    run();
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ExitCode::bad_input) << e.what();
    return e.what();
  }
  return "no error";
}
inline bool have_shared_data() { return std::filesystem::exists(shared_data() + "/README.md"); }
#define SPX_REQUIRE_SHARED_DATA()                                                   \
  do {                                                                              \
    if (!::spx::test::have_shared_data()) GTEST_SKIP() << "no " << SPX_SHARED_DATA; \
  } while (0)

// The folders temp_dir made, removed when the test program exits, so that runs of the suite do
// not pile up in the temp folder (a full run writes about 100 MB there). SPX_KEEP_TEST_DIRS=1
// keeps them, for a look after a failure.
struct MadeDirs {
  std::vector<std::filesystem::path> paths;
  ~MadeDirs() {
    if (std::getenv("SPX_KEEP_TEST_DIRS")) return;
    std::error_code ignored;
    for (const auto& p : paths) std::filesystem::remove_all(p, ignored);
  }
};
inline MadeDirs& made_dirs() {
  static MadeDirs dirs;
  return dirs;
}

inline std::string temp_dir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / ("spx-test-" + name + "-" + std::to_string(::getpid()));
  if (std::filesystem::create_directories(dir)) made_dirs().paths.push_back(dir);
  return dir.string();
}

// The chain's first two stages in memory: the SDF at `resolution`, then packing with exact radii.
inline SpheresFile pack_file(const TriMesh& mesh, int resolution, const PackOptions& pack = {}) {
  SdfOptions sopt;
  sopt.resolution = resolution;
  const SdfResult sdf = build_sdf(mesh, sopt);
  const MeshQuery query(mesh);
  SpheresFile f;
  f.spheres = pack_spheres(sdf.field, pack, &query).spheres;
  f.voxel_size = sdf.field.shape.voxel_size;
  return f;
}

// The robot sample's glb written to `dir`, read back as the asset pose-extract reads.
inline std::unique_ptr<Asset> robot_asset(const std::string& dir) {
  write_file_atomic(dir + "/robot.glb", encode_rig_glb(make_robot()));
  return std::make_unique<Asset>(dir + "/robot.glb", "");
}
inline TriMesh rest_of(const Asset& asset) {
  TriMesh rest;
  rest.vertices = asset.rest();
  rest.triangles = asset.triangles();
  return rest;
}

// Axis-aligned box as 12 outward triangles.
inline TriMesh box_mesh(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  TriMesh m;
  for (int i = 0; i < 8; ++i)
    m.vertices.emplace_back(i & 1 ? hi.x() : lo.x(), i & 2 ? hi.y() : lo.y(), i & 4 ? hi.z() : lo.z());
  m.triangles = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                 {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  return m;
}

// UV sphere, closed and outward.
inline TriMesh uv_sphere(double radius, int rings = 24, int sectors = 48) {
  std::vector<std::pair<double, double>> profile;  // (r, z), one ring per latitude
  for (int r = 1; r < rings; ++r) {
    const double phi = M_PI * r / rings - M_PI / 2;
    profile.emplace_back(radius * std::cos(phi), radius * std::sin(phi));
  }
  return lathe(profile, -radius, radius, sectors);
}

// Two meshes in one glb, `dir`/pair.glb (its path): "box", the unit box, and "ball", a ball of
// radius 0.5 at (3, 0, 0).
inline std::string box_and_ball_glb(const std::string& dir) {
  TriMesh ball = uv_sphere(0.5, 8, 16);
  for (auto& v : ball.vertices) v += Eigen::Vector3d(3, 0, 0);
  write_file_atomic(dir + "/pair.glb", encode_scene({{"box", box_mesh({0, 0, 0}, {1, 1, 1}), {}}, {"ball", ball, {}}}, ".glb"));
  return dir + "/pair.glb";
}

// OBJ text of a polygon mesh (faces of any number of corners, counted from 0).
inline std::string polygon_obj(const std::vector<Eigen::Vector3d>& vertices, const std::vector<std::vector<int>>& faces) {
  std::string out;
  char line[100];
  for (const Eigen::Vector3d& v : vertices) {
    std::snprintf(line, sizeof line, "v %.9g %.9g %.9g\n", v.x(), v.y(), v.z());
    out += line;
  }
  for (const std::vector<int>& face : faces) {
    out += "f";
    for (int c : face) out += " " + std::to_string(c + 1);
    out += "\n";
  }
  return out;
}

// A heptagram prism: its ends are the star polygon {7/3}, which crosses itself; assimp's ear
// clipping finds no ear in it after 3 triangles and stops.
// (`step` 1: a heptagon's prism, which crosses nothing.)
inline std::string heptagram_prism_obj(double top, int step = 3) {
  std::vector<Eigen::Vector3d> v;
  for (double z : {0.0, top})
    for (int i = 0; i < 7; ++i) v.emplace_back(std::cos(2 * step * M_PI * i / 7), std::sin(2 * step * M_PI * i / 7), z);
  std::vector<std::vector<int>> faces = {{6, 5, 4, 3, 2, 1, 0}, {7, 8, 9, 10, 11, 12, 13}};
  for (int i = 0; i < 7; ++i) faces.push_back({i, (i + 1) % 7, 7 + (i + 1) % 7, 7 + i});
  return polygon_obj(v, faces);
}
}  // namespace spx::test
