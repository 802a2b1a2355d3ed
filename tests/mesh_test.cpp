#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Simple_cartesian.h>
#include <assimp/postprocess.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <random>
#include <set>
#include <stdexcept>
#include <tuple>
#include <tbb/parallel_for.h>

#include "core/atomic_file.hpp"
#include "core/error.hpp"
#include "core/format.hpp"
#include "core/gltf_file.hpp"
#include "core/side_by_side.hpp"
#include "mesh/assimp_scene.hpp"
#include "mesh/components.hpp"
#include "mesh/defects.hpp"
#include "mesh/deforming_query.hpp"
#include "mesh/gltf_input.hpp"
#include "mesh/split.hpp"
#include "mesh/inscribed.hpp"
#include "mesh/mesh_query.hpp"
#include "mesh/near_boundary.hpp"
#include "mesh/normals.hpp"
#include "mesh/solid_boundary.hpp"
#include "mesh/winding_number.hpp"
#include "synthetic/synthetic.hpp"
#include "test_util.hpp"

namespace spx {
namespace {

TEST(MeshLoad, WeldsCornersAndKeepsTopology) {
  const std::string dir = test::temp_dir("load");
  const TriMesh box = test::box_mesh({0, 0, 0}, {1, 2, 3});
  write_file_atomic(dir + "/box.obj", to_obj(box));
  const LoadedMesh loaded = load_mesh(dir + "/box.obj");
  EXPECT_EQ(loaded.mesh.vertices.size(), 8u);
  EXPECT_EQ(loaded.mesh.triangles.size(), 12u);
  const MeshDefects d = find_defects(loaded.mesh);
  EXPECT_TRUE(d.watertight());
  EXPECT_EQ(d.components, 1u);
  EXPECT_NEAR(d.signed_volume, 6.0, 1e-12);
}

TEST(MeshLoad, PoseMustShareTheRestTopology) {
  const std::string dir = test::temp_dir("topology");
  TriMesh box = test::box_mesh({0, 0, 0}, {1, 1, 1});
  write_file_atomic(dir + "/rest.obj", to_obj(box));
  const LoadedMesh rest = load_mesh(dir + "/rest.obj");

  TriMesh moved = box;
  for (auto& v : moved.vertices) v += Eigen::Vector3d(3, 0, 0);
  write_file_atomic(dir + "/ok.obj", to_obj(moved));
  const TriMesh pose = load_pose(dir + "/ok.obj", rest);
  for (size_t v = 0; v < pose.vertices.size(); ++v)
    EXPECT_EQ(pose.vertices[v], rest.mesh.vertices[v] + Eigen::Vector3d(3, 0, 0));

  TriMesh fewer = box;
  fewer.triangles.pop_back();
  write_file_atomic(dir + "/fewer.obj", to_obj(fewer));
  EXPECT_THROW(load_pose(dir + "/fewer.obj", rest), Error);

  TriMesh reordered = box;  // same vertices and count, another triangle list
  std::swap(reordered.triangles[0][0], reordered.triangles[3][1]);
  write_file_atomic(dir + "/reordered.obj", to_obj(reordered));
  try {
    load_pose(dir + "/reordered.obj", rest);
    FAIL() << "a different triangle list was accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ExitCode::bad_input);
    EXPECT_NE(std::string(e.what()).find("reordered.obj"), std::string::npos);
  }
}

// Poses read side by side: each as load_pose reads it, and of several bad files the first in
// the given order is the one named, however the threads run (a missing file after a bad one,
// many times over).
// Steps side by side: every one runs to its end, and the failure reported is the first in the
// order given, whichever thread failed first.
TEST(SideBySide, EveryStepRunsAndTheFirstFailureInOrderIsRethrown) {
  for (int run = 0; run < 50; ++run) {
    std::atomic<int> ran{0};
    try {
      side_by_side([&] { ++ran; },
                   [&] {
                     ++ran;
                     throw std::runtime_error("second");
                   },
                   [&] {
                     ++ran;
                     throw std::runtime_error("third");
                   });
      FAIL() << "no failure was rethrown";
    } catch (const std::runtime_error& e) {
      EXPECT_STREQ(e.what(), "second");
    }
    EXPECT_EQ(ran, 3);
  }
  int sum = 0;
  side_by_side([&] { sum += 1; }, [] {});
  EXPECT_EQ(sum, 1);
}

TEST(MeshLoad, PosesReadSideBySideReportTheFirstBadFile) {
  const std::string dir = test::temp_dir("poses");
  const TriMesh box = test::box_mesh({0, 0, 0}, {1, 1, 1});
  write_file_atomic(dir + "/rest.obj", to_obj(box));
  const LoadedMesh rest = load_mesh(dir + "/rest.obj");
  std::vector<std::string> paths;
  for (int k = 0; k < 16; ++k) {
    TriMesh moved = box;
    for (auto& v : moved.vertices) v += Eigen::Vector3d(k, 0.5 * k, 0);
    paths.push_back(dir + "/pose-" + std::to_string(k) + ".obj");
    write_file_atomic(paths.back(), to_obj(moved));
  }
  const std::vector<TriMesh> read = load_poses(paths, rest);
  ASSERT_EQ(read.size(), paths.size());
  for (size_t k = 0; k < paths.size(); ++k) EXPECT_EQ(read[k].vertices, load_pose(paths[k], rest).vertices);

  TriMesh fewer = box;
  fewer.triangles.pop_back();
  write_file_atomic(dir + "/fewer.obj", to_obj(fewer));
  std::vector<std::string> bad = paths;
  bad[5] = dir + "/fewer.obj";
  bad[9] = dir + "/missing.obj";
  bad[2] = dir + "/missing-first.obj";
  for (int run = 0; run < 20; ++run) {
    try {
      load_poses(bad, rest);
      FAIL() << "bad poses were accepted";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("missing-first.obj"), std::string::npos) << e.what();
    }
  }
}

// A pose listing the rest's faces in another order, with their corners rotated (as another
// exporter writes them): matched by its triangles, each vertex lands on its own rest vertex,
// even on a symmetric mesh that maps onto itself in many ways.
// The same triangles listed in a shuffled order, two in three with their corners rotated
// (orientation kept).
void shuffle_faces(TriMesh& mesh, unsigned seed) {
  std::mt19937 rng(seed);
  std::shuffle(mesh.triangles.begin(), mesh.triangles.end(), rng);
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const Eigen::Vector3i f = mesh.triangles[t];
    mesh.triangles[t] = t % 3 == 0 ? f : t % 3 == 1 ? Eigen::Vector3i(f[1], f[2], f[0]) : Eigen::Vector3i(f[2], f[0], f[1]);
  }
}

TEST(MeshLoad, PoseWithReorderedFacesIsMatchedByItsTriangles) {
  const std::string dir = test::temp_dir("reorder");
  const TriMesh rest_mesh = test::uv_sphere(1.0, 12, 24);
  write_file_atomic(dir + "/rest.obj", to_obj(rest_mesh));
  const LoadedMesh rest = load_mesh(dir + "/rest.obj");
  auto bend = [](const Eigen::Vector3d& v) { return Eigen::Vector3d(1.2 * v.x() + 0.3 * v.z() * v.z(), 0.9 * v.y(), v.z()); };
  TriMesh pose = rest_mesh;
  for (auto& v : pose.vertices) v = bend(v);
  shuffle_faces(pose, 7);
  write_file_atomic(dir + "/shuffled.obj", to_obj(pose));
  const TriMesh got = load_pose(dir + "/shuffled.obj", rest);
  ASSERT_EQ(got.vertices.size(), rest.mesh.vertices.size());
  for (size_t v = 0; v < got.vertices.size(); ++v)
    EXPECT_LT((got.vertices[v] - bend(rest.mesh.vertices[v])).norm(), 1e-6) << "vertex " << v;

  TriMesh other = pose;  // one triangle really differs: it says how, naming both files
  std::swap(other.triangles[0][0], other.triangles[5][1]);
  write_file_atomic(dir + "/other.obj", to_obj(other));
  try {
    load_pose(dir + "/other.obj", rest);
    FAIL() << "a pose with other triangles was accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ExitCode::bad_input);
    EXPECT_NE(std::string(e.what()).find("other.obj: its triangles connect its vertices otherwise"), std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("rest.obj"), std::string::npos) << e.what();
  }
}

// assimp splits a polygon by its shape (a quad from its concave corner, a larger polygon by ear
// clipping): a pose whose quad or hexagon turned concave was split along other diagonals than its
// rest, and refused as "its triangles connect its vertices otherwise". Its polygons are now split
// as the rest's were, and every vertex gets its place in the pose.
TEST(MeshLoad, PolygonPosesAreSplitAsTheirRest) {
  const std::string dir = test::temp_dir("polygons");
  // A hexagonal prism: hexagons at the ends, quads around; then each end corner in turn pulled
  // towards the axis (the hexagon concave there, and the quads beside it bent).
  std::vector<Eigen::Vector3d> prism;
  for (double z : {0.0, 1.0})
    for (int i = 0; i < 6; ++i) prism.emplace_back(std::cos(M_PI * i / 3), std::sin(M_PI * i / 3), z);
  std::vector<std::vector<int>> faces = {{5, 4, 3, 2, 1, 0}, {6, 7, 8, 9, 10, 11}};
  for (int i = 0; i < 6; ++i) faces.push_back({i, (i + 1) % 6, 6 + (i + 1) % 6, 6 + i});
  // A bar of quads, 3 by 3 on each side of a unit cube; a corner of the side x = 1 pulled within
  // it makes the quad beside it concave at its corner 3 (assimp then splits it along 1-3, not 0-2).
  std::vector<Eigen::Vector3d> cube;
  std::vector<std::vector<int>> quads;
  std::map<std::tuple<int, int, int>, int> index;
  const auto at = [&](int x, int y, int z) {
    const auto [it, fresh] = index.emplace(std::make_tuple(x, y, z), int(cube.size()));
    if (fresh) cube.emplace_back(x / 3.0, y / 3.0, z / 3.0);
    return it->second;
  };
  for (int axis = 0; axis < 3; ++axis)
    for (int side : {0, 3})
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
          std::vector<int> q;
          for (const auto& [a, b] : {std::pair{i, j}, {i + 1, j}, {i + 1, j + 1}, {i, j + 1}}) {
            int c[3];
            c[axis] = side, c[(axis + 1) % 3] = a, c[(axis + 2) % 3] = b;
            q.push_back(at(c[0], c[1], c[2]));
          }
          if (side == 0) std::reverse(q.begin(), q.end());
          quads.push_back(q);
        }
  struct Case {
    std::string name;
    const std::vector<Eigen::Vector3d>& rest;
    const std::vector<std::vector<int>>& faces;
    int moved;
    Eigen::Vector3d to;
  };
  std::vector<Case> cases;
  for (int k = 0; k < 6; ++k)
    cases.push_back({"prism-" + std::to_string(k), prism, faces, 6 + k, Eigen::Vector3d(0.25 * prism[size_t(6 + k)].x(), 0.25 * prism[size_t(6 + k)].y(), 1)});
  cases.push_back({"bar", cube, quads, at(3, 1, 1), Eigen::Vector3d(1, 0.55, 0.1)});
  for (const Case& c : cases) {
    write_file_atomic(dir + "/" + c.name + "-rest.obj", test::polygon_obj(c.rest, c.faces));
    std::vector<Eigen::Vector3d> posed = c.rest;
    posed[size_t(c.moved)] = c.to;
    write_file_atomic(dir + "/" + c.name + "-pose.obj", test::polygon_obj(posed, c.faces));
    const LoadedMesh rest = load_mesh(dir + "/" + c.name + "-rest.obj");
    ASSERT_FALSE(rest.triangulation.empty()) << c.name;
    const TriMesh pose = load_pose(dir + "/" + c.name + "-pose.obj", rest);
    for (size_t v = 0; v < rest.mesh.vertices.size(); ++v) {  // each rest vertex where the pose put it
      const auto file = std::find_if(c.rest.begin(), c.rest.end(), [&](const Eigen::Vector3d& p) {
        return (p - rest.mesh.vertices[v]).norm() < 1e-6;
      });
      ASSERT_NE(file, c.rest.end());
      EXPECT_LT((pose.vertices[v] - posed[size_t(file - c.rest.begin())]).norm(), 1e-6) << c.name << " vertex " << v;
    }
  }
}

// The heptagram prism (test::heptagram_prism_obj) read with 2 of each end's 5 triangles left out,
// open there and said to be only "not watertight".
TEST(MeshLoad, PolygonsThatCrossThemselvesAreFannedNotDropped) {
  const std::string dir = test::temp_dir("heptagram");
  write_file_atomic(dir + "/rest.obj", test::heptagram_prism_obj(1));
  write_file_atomic(dir + "/pose.obj", test::heptagram_prism_obj(1.5));
  const LoadedMesh rest = load_mesh(dir + "/rest.obj");
  EXPECT_EQ(rest.mesh.triangles.size(), 2u * 5 + 7 * 2);  // every polygon's n - 2 triangles
  EXPECT_TRUE(find_defects(rest.mesh).watertight());
  EXPECT_EQ(rest.fanned.polygons, 2u);
  EXPECT_EQ(rest.fanned.dropped, 4u);
  EXPECT_EQ(rest.fanned.first_corners, 7u);
  EXPECT_LT((rest.fanned.first_at - Eigen::Vector3d(std::cos(36 * M_PI / 7), std::sin(36 * M_PI / 7), 0)).norm(), 1e-6);
  // The pose, the same faces, is split as the rest: the same triangles, each vertex raised.
  const TriMesh pose = load_pose(dir + "/pose.obj", rest);
  ASSERT_EQ(pose.triangles, rest.mesh.triangles);
  for (size_t i = 0; i < pose.vertices.size(); ++i)
    EXPECT_DOUBLE_EQ(pose.vertices[i].z(), rest.mesh.vertices[i].z() * 1.5) << i;
  Log log;
  warn_fanned(rest.fanned, "rest.obj", log);
  ASSERT_EQ(log.warnings().size(), 1u);
  EXPECT_NE(log.warnings()[0].find("rest.obj: 2 polygons (the first of 7 corners, at "), std::string::npos) << log.warnings()[0];
  EXPECT_NE(log.warnings()[0].find("cross themselves as seen along their normals, where the mesh reader's ear clipping "
                                   "stops (4 triangles left out); each is split as a fan"),
            std::string::npos)
      << log.warnings()[0];
  // With a line and a point among the faces (an OBJ's `l` and `p`), which the reader sets aside
  // with their corners, and counts.
  write_file_atomic(dir + "/rest-line.obj", test::heptagram_prism_obj(1) + "v 5 5 5\nv 6 6 6\nl 15 16\np 15\n");
  write_file_atomic(dir + "/pose-line.obj", test::heptagram_prism_obj(1.5) + "v 5 5 5\nv 6 6 6\nl 15 16\np 15\n");
  const LoadedMesh lined = load_mesh(dir + "/rest-line.obj");
  EXPECT_EQ(lined.points_and_lines, 2u);
  EXPECT_EQ(rest.points_and_lines, 0u);
  EXPECT_EQ(lined.mesh.vertices.size(), rest.mesh.vertices.size());
  EXPECT_EQ(lined.mesh.triangles, rest.mesh.triangles);
  EXPECT_EQ(load_pose(dir + "/pose-line.obj", lined).vertices, pose.vertices);
  // A mesh whose polygons are all simple is split by assimp alone, and nothing is said.
  write_file_atomic(dir + "/simple.obj", test::heptagram_prism_obj(1, 1));
  const LoadedMesh simple = load_mesh(dir + "/simple.obj");
  EXPECT_EQ(simple.mesh.triangles.size(), 2u * 5 + 7 * 2);
  EXPECT_EQ(simple.fanned.polygons + simple.fanned.dropped, 0u);
}

// Faces doubled (listed twice, or a copy of the part left where it was made, with vertices of its
// own) read once: the cube's 12 triangles, closed, as the single cube reads. Read twice, every edge
// met four triangles, sdf-build said "not watertight (... non-manifold ...)", and the car so
// doubled packed into 155 spheres against its 116. A sheet's two sides (the same corners in the
// other turn) are kept, and poses of the doubled file read as the rest, in its layout or another.
TEST(MeshLoad, RepeatedTrianglesAreReadOnce) {
  const std::string dir = test::temp_dir("repeated");
  const TriMesh cube = test::box_mesh({0, 0, 0}, {1, 1, 1});
  const auto doubled = [&](double scale, bool shuffled) {
    TriMesh out = cube;
    for (Eigen::Vector3d& v : out.vertices) v *= scale;
    const int n = int(out.vertices.size());
    out.vertices.insert(out.vertices.end(), out.vertices.begin(), out.vertices.end());  // the copy's own vertices
    for (size_t t = 0; t < cube.triangles.size(); ++t) {
      const Eigen::Vector3i& f = cube.triangles[t];
      out.triangles.emplace_back(f[1], f[2], f[0]);                   // the same face, another first corner
      if (t % 3 == 0) out.triangles.emplace_back(f[2] + n, f[0] + n, f[1] + n);  // and on the copy's vertices
    }
    if (shuffled) std::reverse(out.triangles.begin(), out.triangles.end());
    return out;
  };
  write_file_atomic(dir + "/cube.obj", to_obj(cube));
  write_file_atomic(dir + "/rest.obj", to_obj(doubled(1, false)));
  write_file_atomic(dir + "/pose.obj", to_obj(doubled(2, false)));
  write_file_atomic(dir + "/shuffled.obj", to_obj(doubled(2, true)));
  const LoadedMesh single = load_mesh(dir + "/cube.obj"), rest = load_mesh(dir + "/rest.obj");
  EXPECT_EQ(single.repeated.count, 0u);
  EXPECT_EQ(rest.mesh.vertices, single.mesh.vertices);
  EXPECT_EQ(rest.mesh.triangles, single.mesh.triangles);
  EXPECT_TRUE(find_defects(rest.mesh).watertight());
  EXPECT_EQ(rest.repeated.count, 12u + 4);
  EXPECT_EQ(rest.repeated.first_at, cube.vertices[size_t(cube.triangles[0][1])]);
  const TriMesh pose = load_pose(dir + "/pose.obj", rest);  // laid out as the rest file
  EXPECT_EQ(pose.triangles, rest.mesh.triangles);
  for (size_t v = 0; v < pose.vertices.size(); ++v) EXPECT_EQ(pose.vertices[v], 2 * rest.mesh.vertices[v]) << v;
  // Laid out otherwise, matched by its triangles: the cube's connections have symmetries, so the
  // vertices may be matched by one of them; the surface is the doubled cube's either way.
  const auto faces_at = [](const TriMesh& m) {
    std::multiset<std::array<std::array<double, 3>, 3>> out;
    for (const Eigen::Vector3i& t : m.triangles) {
      std::array<std::array<double, 3>, 3> f;
      for (int c = 0; c < 3; ++c) f[size_t(c)] = {m.vertices[size_t(t[c])].x(), m.vertices[size_t(t[c])].y(), m.vertices[size_t(t[c])].z()};
      std::rotate(f.begin(), std::min_element(f.begin(), f.end()), f.end());
      out.insert(f);
    }
    return out;
  };
  const TriMesh shuffled = load_pose(dir + "/shuffled.obj", rest);
  EXPECT_EQ(shuffled.triangles, rest.mesh.triangles);
  EXPECT_EQ(faces_at(shuffled), faces_at(pose));
  Log log;
  warn_repeated(rest.repeated, "rest.obj", log);
  ASSERT_EQ(log.warnings().size(), 1u);
  EXPECT_EQ(log.warnings()[0], "rest.obj: 16 triangles repeat another's corners (the first at 0, 1, 0): a part placed "
                               "twice in one place, or faces doubled; each is read once");
  // A face and its other side: a sheet, kept whole.
  TriMesh sheet = cube;
  sheet.triangles.emplace_back(cube.triangles[0][2], cube.triangles[0][1], cube.triangles[0][0]);
  write_file_atomic(dir + "/sheet.obj", to_obj(sheet));
  const LoadedMesh sided = load_mesh(dir + "/sheet.obj");
  EXPECT_EQ(sided.repeated.count, 0u);
  EXPECT_EQ(sided.mesh.triangles.size(), 13u);
}

// drop_repeated_triangles against the rule read plainly: a triangle is kept unless an earlier kept
// one is one of its three turns. Random triangles on 4 vertices (many repeats, turns, mirrors and
// degenerate ones).
TEST(MeshLoad, RepeatedTrianglesDroppedAsBruteForceDoes) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> corner(0, 3);
  for (int round = 0; round < 200; ++round) {
    TriMesh mesh;
    for (int v = 0; v < 4; ++v) mesh.vertices.emplace_back(v, v * v, 1);
    const int n = 1 + round % 40;
    for (int t = 0; t < n; ++t) mesh.triangles.emplace_back(corner(rng), corner(rng), corner(rng));
    std::vector<Eigen::Vector3i> expected;
    size_t repeats = 0;
    Eigen::Vector3d first = Eigen::Vector3d::Zero();
    for (const Eigen::Vector3i& t : mesh.triangles) {
      const bool seen = std::any_of(expected.begin(), expected.end(), [&](const Eigen::Vector3i& k) {
        return k == t || k == Eigen::Vector3i(t[1], t[2], t[0]) || k == Eigen::Vector3i(t[2], t[0], t[1]);
      });
      if (!seen) expected.push_back(t);
      else if (repeats++ == 0) first = mesh.vertices[size_t(t[0])];
    }
    const RepeatedTriangles got = drop_repeated_triangles(mesh);
    ASSERT_EQ(mesh.triangles, expected) << round;
    EXPECT_EQ(got.count, repeats) << round;
    EXPECT_EQ(got.first_at, first) << round;
  }
}

// weld_by_position against the rule read plainly: a position is the vertex of the first equal one
// before it (-0 equal to +0, a NaN equal to none), vertices numbered in order of first appearance.
// Random positions from a few values, so that most repeat.
TEST(MeshLoad, WeldByPositionAsBruteForceDoes) {
  std::mt19937 rng(11);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::vector<double> values = {0.0, -0.0, 1.0, -1.0, 1e-300, 2.5, nan};
  std::uniform_int_distribution<size_t> pick(0, values.size() - 1);
  for (int round = 0; round < 200; ++round) {
    std::vector<Eigen::Vector3d> positions(size_t(1 + round % 60));
    for (Eigen::Vector3d& p : positions) p = {values[pick(rng)], values[pick(rng)], values[pick(rng) % 3]};
    std::vector<Eigen::Vector3d> expected_welded;
    std::vector<int> expected(positions.size());
    for (size_t i = 0; i < positions.size(); ++i) {
      size_t j = 0;
      while (j < i && !(positions[j] == positions[i])) ++j;  // == is false for NaN, -0 == +0
      if (j < i) {
        expected[i] = expected[j];
      } else {
        expected[i] = int(expected_welded.size());
        expected_welded.push_back(positions[i]);
      }
    }
    std::vector<Eigen::Vector3d> welded = {Eigen::Vector3d(7, 7, 7)};  // appended to
    const std::vector<int> got = weld_by_position(positions, welded);
    ASSERT_EQ(welded.size(), expected_welded.size() + 1) << round;
    ASSERT_EQ(got.size(), expected.size()) << round;
    for (size_t i = 0; i < got.size(); ++i) {
      ASSERT_EQ(got[i], expected[i] + 1) << round << " position " << i;
      const Eigen::Vector3d& a = welded[size_t(got[i])];
      const Eigen::Vector3d& b = positions[i];
      for (int c = 0; c < 3; ++c) EXPECT_TRUE(a[c] == b[c] || (std::isnan(a[c]) && std::isnan(b[c]))) << round;
    }
  }
}

// A closed part given both ways (a double-sided export: each face also in the other turn) enclosed
// nothing: its two sides cancel, so the winding number is 0 within it ("encloses no volume: its
// triangles face inward", for the car so given). Its outer side is kept, whichever side comes
// first in the file; a wall two touching parts share and an open sheet's two sides are kept.
TEST(MeshLoad, ClosedPartGivenBothWaysKeepsItsOuterSide) {
  const std::string dir = test::temp_dir("double-sided");
  const TriMesh cube = test::box_mesh({0, 0, 0}, {1, 1, 1});
  const auto flipped = [](const Eigen::Vector3i& f) { return Eigen::Vector3i(f[2], f[1], f[0]); };
  // Both sides: the inner one first for every other face, and on vertices of its own.
  const auto both_ways = [&](const TriMesh& part, double scale) {
    TriMesh out = part;
    for (Eigen::Vector3d& v : out.vertices) v *= scale;
    const int n = int(out.vertices.size());
    out.vertices.insert(out.vertices.end(), out.vertices.begin(), out.vertices.end());
    out.triangles.clear();
    for (size_t t = 0; t < part.triangles.size(); ++t) {
      const Eigen::Vector3i& f = part.triangles[t];
      const Eigen::Vector3i inner = flipped(f) + Eigen::Vector3i::Constant(n);
      if (t % 2) out.triangles.push_back(inner), out.triangles.push_back(f);
      else out.triangles.push_back(f), out.triangles.push_back(inner);
    }
    return out;
  };
  const auto welded = [](TriMesh m) {  // as the loader welds
    std::vector<Eigen::Vector3d> at;
    const std::vector<int> weld = weld_by_position(m.vertices, at);
    for (Eigen::Vector3i& f : m.triangles) f = Eigen::Vector3i(weld[size_t(f[0])], weld[size_t(f[1])], weld[size_t(f[2])]);
    m.vertices = at;
    return m;
  };
  write_file_atomic(dir + "/cube.obj", to_obj(cube));
  write_file_atomic(dir + "/rest.obj", to_obj(both_ways(cube, 1)));
  write_file_atomic(dir + "/pose.obj", to_obj(both_ways(cube, 2)));
  const LoadedMesh single = load_mesh(dir + "/cube.obj"), rest = load_mesh(dir + "/rest.obj");
  EXPECT_EQ(single.repeated.inner_sides, 0u);
  EXPECT_EQ(rest.mesh.vertices, single.mesh.vertices);
  EXPECT_EQ(rest.mesh.triangles, single.mesh.triangles);
  EXPECT_TRUE(find_defects(rest.mesh).watertight());
  EXPECT_GT(signed_volume(rest.mesh), 0.99);
  EXPECT_EQ(rest.repeated.inner_sides, 12u);
  EXPECT_EQ(rest.repeated.double_sided_parts, 1u);
  EXPECT_EQ(rest.repeated.count, 0u);
  const TriMesh pose = load_pose(dir + "/pose.obj", rest);
  EXPECT_EQ(pose.triangles, rest.mesh.triangles);
  for (size_t v = 0; v < pose.vertices.size(); ++v) EXPECT_EQ(pose.vertices[v], 2 * rest.mesh.vertices[v]) << v;
  Log log;
  warn_repeated(rest.repeated, "rest.obj", log);
  ASSERT_EQ(log.warnings().size(), 1u);
  EXPECT_EQ(log.warnings()[0], "rest.obj: 1 closed part given both ways (12 faces also in the other turn, the first at "
                               "1, 0, 0): the two sides cancel and enclose nothing, so its inner side is dropped");

  // An inside-out cube given both ways: its outer side is the copy's, the second of each pair.
  TriMesh inside_out = cube;
  for (Eigen::Vector3i& f : inside_out.triangles) f = flipped(f);
  TriMesh mesh = welded(both_ways(inside_out, 1));
  EXPECT_EQ(read_triangles_once(mesh).inner_sides, 12u);
  EXPECT_GT(signed_volume(mesh), 0.99);
  EXPECT_TRUE(find_defects(mesh).watertight());

  // Beside a closed part given once: that part as it is, in its place among the triangles.
  TriMesh two = cube;
  const TriMesh far = welded(both_ways(cube, 1));
  const int base = int(two.vertices.size());
  for (const Eigen::Vector3d& v : far.vertices) two.vertices.push_back(v + Eigen::Vector3d(3, 0, 0));
  for (const Eigen::Vector3i& f : far.triangles) two.triangles.push_back(f + Eigen::Vector3i::Constant(base));
  const RepeatedTriangles dropped = drop_inner_sides(two);
  EXPECT_EQ(dropped.inner_sides, 12u);
  EXPECT_EQ(dropped.inner_first_at, Eigen::Vector3d(3, 0, 0) + far.vertices[size_t(far.triangles[1][0])]);
  ASSERT_EQ(two.triangles.size(), 24u);
  EXPECT_TRUE(std::equal(cube.triangles.begin(), cube.triangles.end(), two.triangles.begin()));
  EXPECT_NEAR(signed_volume(two), 2.0, 1e-12);

  // Left as they are: two cubes touching face to face (their shared wall is a face and its twin),
  // a sheet's two sides, and a part with a twin missing.
  TriMesh wall = cube;
  const TriMesh next = test::box_mesh({1, 0, 0}, {2, 1, 1});
  for (const Eigen::Vector3d& v : next.vertices) wall.vertices.push_back(v);
  for (const Eigen::Vector3i& f : next.triangles) wall.triangles.push_back(f + Eigen::Vector3i::Constant(8));
  wall = welded(wall);
  TriMesh sheet;
  sheet.vertices = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0.2}};
  sheet.triangles = {{0, 1, 2}, {0, 2, 3}, {2, 1, 0}, {3, 2, 0}};
  TriMesh missing = welded(both_ways(cube, 1));
  missing.triangles.pop_back();
  for (TriMesh kept : {wall, sheet, missing}) {
    const size_t before = kept.triangles.size();
    EXPECT_EQ(drop_inner_sides(kept).inner_sides, 0u);
    EXPECT_EQ(kept.triangles.size(), before);
  }
}

// Polygons that repeat another's corners from another first corner, or in the other turn: split by
// their own shape, a quad from its second corner takes the other diagonal, and the copies overlapped
// without repeating a triangle (a 12-gon prism's faces doubled so read 799 037 voxels inside against
// 774 284). Each is now split as the first was, so that its triangles repeat that one's.
TEST(MeshLoad, RepeatedPolygonsAreSplitAsTheFirst) {
  const std::string dir = test::temp_dir("repeated-polygons");
  const int n = 12;
  std::string vertices;
  for (int z = 0; z < 2; ++z)
    for (int i = 0; i < n; ++i)
      vertices += "v " + num(std::cos(2 * M_PI * i / n)) + " " + num(std::sin(2 * M_PI * i / n)) + " " + std::to_string(z) + "\n";
  std::vector<std::vector<int>> faces;  // 1-based, facing out
  std::vector<int> bottom, top;
  for (int i = 0; i < n; ++i) bottom.push_back(n - i), top.push_back(n + 1 + i);
  faces = {bottom, top};
  for (int i = 0; i < n; ++i) faces.push_back({i + 1, (i + 1) % n + 1, n + (i + 1) % n + 1, n + i + 1});
  const auto obj = [&](const std::vector<std::vector<int>>& list) {
    std::string out = vertices;
    for (const auto& f : list) {
      out += "f";
      for (int c : f) out += " " + std::to_string(c);
      out += "\n";
    }
    return out;
  };
  std::vector<std::vector<int>> doubled = faces, both = faces;
  std::mt19937 rng(5);
  for (auto f : faces) {
    std::rotate(f.begin(), f.begin() + std::ptrdiff_t(1 + rng() % (f.size() - 1)), f.end());  // from another corner
    doubled.push_back(f);
    std::reverse(f.begin(), f.end());  // and in the other turn
    both.push_back(f);
  }
  write_file_atomic(dir + "/prism.obj", obj(faces));
  write_file_atomic(dir + "/doubled.obj", obj(doubled));
  write_file_atomic(dir + "/both.obj", obj(both));
  const LoadedMesh single = load_mesh(dir + "/prism.obj");
  ASSERT_TRUE(find_defects(single.mesh).watertight());
  for (const char* name : {"doubled", "both"}) {
    const LoadedMesh read = load_mesh(dir + "/" + name + ".obj");
    EXPECT_EQ(read.mesh.vertices, single.mesh.vertices) << name;
    EXPECT_EQ(read.mesh.triangles, single.mesh.triangles) << name;
    EXPECT_EQ(read.repeated.count + read.repeated.inner_sides, single.mesh.triangles.size()) << name;
    const TriMesh pose = load_pose(dir + "/" + name + ".obj", read);  // its poses split so too
    EXPECT_EQ(pose.triangles, read.mesh.triangles) << name;
  }
}

// drop_inner_sides against the rule read plainly, over every choice of one triangle of each twin:
// a part all of whose triangles have twins loses one of each where exactly one choice is a closed,
// consistently oriented surface of positive volume. Random closed polyhedra (tetrahedra and
// octahedra, jittered), given once or both ways in random orders and turns, some with a stray
// triangle on one of their edges.
TEST(MeshLoad, InnerSidesDroppedAsBruteForceDoes) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> jitter(-0.2, 0.2);
  const std::vector<Eigen::Vector3i> tetra = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {0, 3, 2}};
  const std::vector<Eigen::Vector3i> octa = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4},
                                             {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
  const std::vector<Eigen::Vector3d> tetra_at = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  const std::vector<Eigen::Vector3d> octa_at = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  size_t rounds_dropping = 0, rounds_keeping = 0;
  for (int round = 0; round < 300; ++round) {
    TriMesh mesh;
    const int parts = 1 + round % 3;
    for (int p = 0; p < parts; ++p) {
      const bool is_octa = rng() % 2;
      const auto& faces = is_octa ? octa : tetra;
      const auto& at = is_octa ? octa_at : tetra_at;
      const int base = int(mesh.vertices.size());
      for (const Eigen::Vector3d& v : at)
        mesh.vertices.push_back(v + Eigen::Vector3d(4.0 * p + jitter(rng), jitter(rng), jitter(rng)));
      const bool inside_out = rng() % 2, doubled = rng() % 4 != 0;
      for (const Eigen::Vector3i& f0 : faces) {
        Eigen::Vector3i f = f0 + Eigen::Vector3i::Constant(base);
        if (inside_out) f = Eigen::Vector3i(f[2], f[1], f[0]);
        mesh.triangles.push_back(f);
        if (doubled) mesh.triangles.push_back(Eigen::Vector3i(f[1], f[0], f[2]));
      }
      if (rng() % 5 == 0) {  // a stray triangle on the part's first edge
        mesh.vertices.push_back(mesh.vertices[size_t(base)] + Eigen::Vector3d(0, 0, -1));
        mesh.triangles.emplace_back(base, base + 1, int(mesh.vertices.size()) - 1);
      }
    }
    std::shuffle(mesh.triangles.begin(), mesh.triangles.end(), rng);
    // The rule, brute force: parts by shared edges, then every choice of one of each twin.
    const size_t n = mesh.triangles.size();
    const auto sorted = [&](size_t t) {
      std::array<int, 3> k = {mesh.triangles[t][0], mesh.triangles[t][1], mesh.triangles[t][2]};
      std::sort(k.begin(), k.end());
      return k;
    };
    const auto shares_edge = [&](size_t a, size_t b) {
      int common = 0;
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) common += mesh.triangles[a][i] == mesh.triangles[b][j];
      return common >= 2;
    };
    std::vector<int> part(n, -1);
    for (size_t s = 0; s < n; ++s) {
      if (part[s] >= 0) continue;
      part[s] = int(s);
      for (bool grew = true; grew;) {
        grew = false;
        for (size_t a = 0; a < n; ++a)
          for (size_t b = 0; b < n; ++b)
            if (part[a] == int(s) && part[b] < 0 && shares_edge(a, b)) part[b] = int(s), grew = true;
      }
    }
    std::vector<char> drop(n, 0);
    for (size_t s = 0; s < n; ++s) {
      if (part[s] != int(s)) continue;
      std::vector<std::pair<size_t, size_t>> pairs;
      bool all_twinned = true;
      for (size_t a = 0; a < n; ++a) {
        if (part[a] != int(s)) continue;
        size_t twin = n;
        for (size_t b = 0; b < n; ++b)
          if (b != a && sorted(b) == sorted(a)) twin = b;
        if (twin == n) all_twinned = false;
        else if (a < twin) pairs.emplace_back(a, twin);
      }
      if (!all_twinned) continue;
      int good = 0;
      size_t pick = 0;
      for (size_t choice = 0; choice < (size_t(1) << pairs.size()); ++choice) {
        std::map<std::pair<int, int>, int> runs;
        double volume = 0;
        for (size_t k = 0; k < pairs.size(); ++k) {
          const Eigen::Vector3i& f = mesh.triangles[(choice >> k) & 1 ? pairs[k].second : pairs[k].first];
          for (int c = 0; c < 3; ++c) ++runs[{f[c], f[(c + 1) % 3]}];
          volume += mesh.vertices[size_t(f[0])].dot(mesh.vertices[size_t(f[1])].cross(mesh.vertices[size_t(f[2])])) / 6;
        }
        bool closed = true;
        for (const auto& [edge, count] : runs) closed = closed && count == 1 && runs.count({edge.second, edge.first});
        if (closed && volume > 1e-9) ++good, pick = choice;
      }
      ASSERT_LE(good, 1) << round;
      if (good == 1)
        for (size_t k = 0; k < pairs.size(); ++k) drop[(pick >> k) & 1 ? pairs[k].first : pairs[k].second] = 1;
    }
    std::vector<Eigen::Vector3i> expected;
    for (size_t t = 0; t < n; ++t)
      if (!drop[t]) expected.push_back(mesh.triangles[t]);
    const size_t dropped = n - expected.size();
    const RepeatedTriangles got = drop_inner_sides(mesh);
    ASSERT_EQ(mesh.triangles, expected) << round;
    EXPECT_EQ(got.inner_sides, dropped) << round;
    ++(dropped > 0 ? rounds_dropping : rounds_keeping);
  }
  EXPECT_GT(rounds_dropping, 100u);  // both outcomes drawn often
  EXPECT_GT(rounds_keeping, 30u);
}

// Two cubes touching face to face, each with its own 8 vertices in the file: at rest the 4 of the
// face they share are one vertex each to the tools (welded by position). A pose that parts them
// is refused saying so; it was "has 16 distinct vertices and 12 triangles, the rest mesh 12".
TEST(MeshLoad, PointsOneAtRestThatPartInAPoseAreNamed) {
  const std::string dir = test::temp_dir("parting");
  const auto two_cubes = [](double gap) {
    TriMesh a = test::box_mesh({0, 0, 0}, {1, 1, 1}), b = test::box_mesh({1 + gap, 0, 0}, {2 + gap, 1, 1});
    const int n = int(a.vertices.size());
    a.vertices.insert(a.vertices.end(), b.vertices.begin(), b.vertices.end());
    for (const Eigen::Vector3i& t : b.triangles) a.triangles.emplace_back(t + Eigen::Vector3i::Constant(n));
    return a;
  };
  write_file_atomic(dir + "/rest.obj", to_obj(two_cubes(0)));
  write_file_atomic(dir + "/apart.obj", to_obj(two_cubes(0.3)));
  const LoadedMesh rest = load_mesh(dir + "/rest.obj");
  ASSERT_EQ(rest.mesh.vertices.size(), 12u);
  const std::string said = test::bad_input_error([&] { load_pose(dir + "/apart.obj", rest); });
  EXPECT_NE(said.find("apart.obj: 4 vertices of the rest part in this pose (the first at 1, "), std::string::npos) << said;
  EXPECT_NE(said.find("keep them together in every pose, or apart at rest"), std::string::npos) << said;
  write_file_atomic(dir + "/together.obj", to_obj(two_cubes(0)));  // the same pose reads
  EXPECT_EQ(load_pose(dir + "/together.obj", rest).vertices.size(), 12u);
}

// The same on a real mesh of thousands of vertices whose pose moves far (the elephant's legs):
// matching may not hinge on where the triangles are, only on how they connect.
TEST(MeshLoad, RealPoseWithShuffledFacesAndRotatedCornersIsMatched) {
  SPX_REQUIRE_SHARED_DATA();
  const std::string d = test::shared_data() + "/elephant/", dir = test::temp_dir("reorder-elephant");
  const LoadedMesh rest = load_mesh(d + "rest.obj");
  ASSERT_EQ(rest.mesh.vertices.size(), 6034u);
  const TriMesh expected = load_pose(d + "pose-456.obj", rest);
  TriMesh pose = load_mesh(d + "pose-456.obj").mesh;
  shuffle_faces(pose, 11);
  write_file_atomic(dir + "/shuffled.obj", to_obj(pose));
  const TriMesh got = load_pose(dir + "/shuffled.obj", rest);
  ASSERT_EQ(got.vertices.size(), expected.vertices.size());
  size_t wrong = 0;
  for (size_t v = 0; v < got.vertices.size(); ++v) wrong += (got.vertices[v] - expected.vertices[v]).norm() > 1e-9;
  EXPECT_EQ(wrong, 0u);
}

// Mixed formats: a GLB rest (its own vertex list) with OBJ poses (face corners). Each pose
// vertex must land where the same pose read against the OBJ rest puts it.
TEST(MeshLoad, GlbRestWithObjPoses) {
  SPX_REQUIRE_SHARED_DATA();
  const std::string d = test::shared_data() + "/rigged-simple/";
  const LoadedMesh glb = load_mesh(d + "RiggedSimple.glb");
  const LoadedMesh obj = load_mesh(d + "rest.obj");
  ASSERT_EQ(glb.mesh.vertices.size(), obj.mesh.vertices.size());
  std::vector<size_t> same(glb.mesh.vertices.size());  // GLB vertex -> OBJ vertex at the same rest point
  for (size_t v = 0; v < same.size(); ++v) {
    double best = 1e30;
    for (size_t u = 0; u < obj.mesh.vertices.size(); ++u) {
      const double e = (glb.mesh.vertices[v] - obj.mesh.vertices[u]).norm();
      if (e < best) best = e, same[v] = u;
    }
    ASSERT_LT(best, 1e-5 * glb.mesh.diagonal());
  }
  for (const char* name : {"pose-00.obj", "pose-01.obj", "pose-02.obj", "pose-03.obj"}) {
    const TriMesh a = load_pose(d + name, glb), b = load_pose(d + name, obj);
    for (size_t v = 0; v < same.size(); ++v) EXPECT_EQ(a.vertices[v], b.vertices[same[v]]) << name << " vertex " << v;
  }
}

// A .gltf beside its buffer "My Body.bin", the URI percent-encoded as Blender writes it
// ("My%20Body.bin"): assimp opens the URI as written and fails; the file reads as the GLB does.
// The integer accessors rewritten as floats, against the values worked out by hand from the spec:
// a strided view, an accessor's own offset, a sparse one with and without a view, the signed
// types' -1 clamp, min and max; the attributes left alone (joints, floats, "_NAME").
TEST(GltfInput, IntegerAccessorsBecomeTheSpecsFloats) {
  GltfFile file;
  auto put = [&](auto v) { file.bin.append(reinterpret_cast<const char*>(&v), sizeof v); };
  // View 0, stride 8: two pad bytes, then per element two uint16 (normalized VEC2) and a 4-byte gap.
  put(uint16_t(0));
  const uint16_t pairs[3][2] = {{0, 65535}, {32768, 1}, {7, 9}};
  for (const auto& pair : pairs) {
    put(pair[0]);
    put(pair[1]);
    put(uint32_t(0xDEADBEEF));
  }
  ASSERT_EQ(file.bin.size(), 26u);
  // View 1: int8 normalized SCALAR -128, -127, 0, 127; view 2: sparse indices (uint8) 2, 0;
  // view 3: sparse values (int16 normalized) -32768, 16384.
  for (int8_t c : {-128, -127, 0, 127}) put(c);
  for (uint8_t c : {2, 0}) put(c);
  put(uint16_t(0));
  for (int16_t c : {-32768, 16384}) put(c);
  file.doc = json::parse(R"({
    "asset": {"version": "2.0"},
    "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 26, "byteStride": 8},
                    {"buffer": 0, "byteOffset": 26, "byteLength": 4},
                    {"buffer": 0, "byteOffset": 30, "byteLength": 2},
                    {"buffer": 0, "byteOffset": 34, "byteLength": 4}],
    "accessors": [
      {"bufferView": 0, "byteOffset": 2, "componentType": 5123, "normalized": true, "count": 3, "type": "VEC2",
       "min": [0, 1], "max": [65535, 65535]},
      {"bufferView": 1, "componentType": 5120, "normalized": true, "count": 4, "type": "SCALAR",
       "sparse": {"count": 2, "indices": {"bufferView": 2, "componentType": 5121},
                  "values": {"bufferView": 1, "byteOffset": 2}}},
      {"componentType": 5122, "normalized": true, "count": 3, "type": "SCALAR",
       "sparse": {"count": 2, "indices": {"bufferView": 2, "componentType": 5121}, "values": {"bufferView": 3}}},
      {"bufferView": 1, "componentType": 5121, "count": 4, "type": "SCALAR"},
      {"bufferView": 1, "componentType": 5121, "count": 4, "type": "VEC4"}],
    "meshes": [{"primitives": [{"attributes": {"TEXCOORD_0": 0, "JOINTS_0": 4, "_ID": 3},
                                "targets": [{"POSITION": 1}]}]}],
    "animations": [{"samplers": [{"input": 3, "output": 2}], "channels": []}]
  })");
  const json before = file.doc;
  ASSERT_EQ(float_accessors(file, "t.glb"), 3u);
  auto floats = [&](size_t a) {
    const json& accessor = file.doc["accessors"][a];
    EXPECT_EQ(accessor["componentType"], 5126);
    EXPECT_FALSE(accessor.contains("sparse") || accessor.contains("normalized") || accessor.contains("byteOffset"));
    const json& view = file.doc["bufferViews"][accessor["bufferView"].get<size_t>()];
    std::vector<float> out(view["byteLength"].get<size_t>() / 4);
    std::memcpy(out.data(), file.bin.data() + view["byteOffset"].get<size_t>(), out.size() * 4);
    return out;
  };
  EXPECT_EQ(floats(0), (std::vector<float>{0.0f, 1.0f, float(32768 / 65535.0), float(1 / 65535.0), float(7 / 65535.0),
                                           float(9 / 65535.0)}));
  EXPECT_EQ(file.doc["accessors"][0]["min"], json::array({0.0, double(float(1 / 65535.0))}));
  EXPECT_EQ(file.doc["accessors"][0]["max"], json::array({1.0, 1.0}));
  // Element 2 takes the first sparse value (0 as int8), element 0 the second (127: 1).
  EXPECT_EQ(floats(1), (std::vector<float>{1.0f, float(-127 / 127.0), 0.0f, 1.0f}));
  EXPECT_EQ(floats(2), (std::vector<float>{float(16384 / 32767.0), 0.0f, -1.0f}));
  for (size_t a : {3u, 4u}) EXPECT_EQ(file.doc["accessors"][a], before["accessors"][a]) << a;
  EXPECT_EQ(float_accessors(file, "t.glb"), 0u) << "floats already";
  // A view past the buffer, an accessor past its view: exit 2 naming the file.
  for (const char* broken : {R"({"bufferViews": [{"buffer": 0, "byteOffset": 30, "byteLength": 40}]})",
                             R"({"accessors": [{"bufferView": 1, "componentType": 5121, "count": 5, "type": "SCALAR"}]})"}) {
    GltfFile bad;
    bad.bin = file.bin;
    bad.doc = before;
    bad.doc.merge_patch(json::parse(broken));
    try {
      float_accessors(bad, "bad.glb");
      ADD_FAILURE() << broken;
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ExitCode::bad_input) << broken;
      EXPECT_EQ(e.subject(), "bad.glb");
    }
  }
}

// Cubic splines made linear: keys between the file's (as often as the tools sample a clip, so
// half-way is one) valued on the spline, against the Hermite form of the glTF spec worked out here
// per basis function; a rotation normalized; a morph weights' key of two targets; the file's key
// times kept apart from the added ones.
TEST(GltfInput, CubicSplinesBecomeKeysOnTheSpline) {
  GltfFile file;
  auto put = [&](float v) { file.bin.append(reinterpret_cast<const char*>(&v), sizeof v); };
  // Times 0, 0.5, 2 (view 0); per key in-tangent, value, out-tangent: translation (view 1),
  // rotation (view 2), weights of 2 targets (view 3).
  const std::vector<float> times = {0, 0.5f, 2}, translation = {9, 9, 9, 0, 0, 0, 1, 2, 3,  //
                                                                  4, 0, 0, 1, 1, 1, -2, 0, 5,    //
                                                                  0, 1, 0, 3, 1, 2, 7, 7, 7};
  const std::vector<float> rotation = {0, 0, 0, 0, 0, 0, 0, 1, 1, 0, 0, 0,  //
                                       0, 2, 0, 0, 0, 0.6f, 0, 0.8f, 0, 0, 0, 0,  //
                                       0, 0, 0, 0, 1, 0, 0, 0, 5, 5, 5, 5};
  const std::vector<float> weights = {0, 0, 0, 1, 2, 0,  //
                                      1, 1, 1, 0, 0, 0,  //
                                      0, 0, 0.5f, 0.5f, 0, 0};
  for (const auto* list : {&times, &translation, &rotation, &weights})
    for (float v : *list) put(v);
  file.doc = json::parse(R"({
    "asset": {"version": "2.0"},
    "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 12}, {"buffer": 0, "byteOffset": 12, "byteLength": 108},
                    {"buffer": 0, "byteOffset": 120, "byteLength": 144}, {"buffer": 0, "byteOffset": 264, "byteLength": 72}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "SCALAR", "min": [0], "max": [2]},
                  {"bufferView": 1, "componentType": 5126, "count": 9, "type": "VEC3"},
                  {"bufferView": 2, "componentType": 5126, "count": 9, "type": "VEC4"},
                  {"bufferView": 3, "componentType": 5126, "count": 18, "type": "SCALAR"}],
    "animations": [{"samplers": [{"input": 0, "output": 0, "interpolation": "LINEAR"}], "channels": []},
                   {"samplers": [{"input": 0, "output": 1, "interpolation": "CUBICSPLINE"},
                                 {"input": 0, "output": 2, "interpolation": "CUBICSPLINE"},
                                 {"input": 0, "output": 3, "interpolation": "CUBICSPLINE"}], "channels": []}]
  })");
  std::vector<AddedKeys> added;
  ASSERT_EQ(cubic_samplers_as_keys(file, "t.glb", added), 3u);
  ASSERT_EQ(added.size(), 2u);
  EXPECT_EQ(added[0].added, 0u);
  EXPECT_TRUE(added[0].asset_times.empty());
  EXPECT_EQ(added[1].asset_times, (std::vector<double>{0, 0.5, 2}));
  // 0.5 s apart: 30 steps; 1.5 s: 90. So 29 + 89 keys added to each sampler.
  EXPECT_EQ(added[1].added, 3u * (29 + 89));
  EXPECT_EQ(file.doc["animations"][0]["samplers"][0]["interpolation"], "LINEAR");
  auto floats = [&](size_t a) {
    const json& accessor = file.doc["accessors"][a];
    EXPECT_EQ(accessor["componentType"], 5126);
    const json& view = file.doc["bufferViews"][accessor["bufferView"].get<size_t>()];
    std::vector<float> out(view["byteLength"].get<size_t>() / 4);
    std::memcpy(out.data(), file.bin.data() + view["byteOffset"].get<size_t>(), out.size() * 4);
    return out;
  };
  // Hermite basis at s over a key gap td: p = h00 v0 + h10 td b0 + h01 v1 + h11 td a1.
  auto spline = [](const std::vector<float>& v, size_t width, size_t k, double s, double td, size_t c) {
    const double h00 = 2 * s * s * s - 3 * s * s + 1, h10 = s * s * s - 2 * s * s + s, h01 = -2 * s * s * s + 3 * s * s,
                 h11 = s * s * s - s * s;
    auto at = [&](size_t key, size_t part) { return double(v[(3 * key + part) * width + c]); };
    return h00 * at(k, 1) + h10 * td * at(k, 2) + h01 * at(k + 1, 1) + h11 * td * at(k + 1, 0);
  };
  const std::vector<std::pair<const std::vector<float>*, size_t>> outputs = {{&translation, 3}, {&rotation, 4}, {&weights, 2}};
  for (size_t n = 0; n < 3; ++n) {
    const json& sampler = file.doc["animations"][1]["samplers"][n];
    EXPECT_EQ(sampler["interpolation"], "LINEAR");
    const std::vector<float> t = floats(sampler["input"].get<size_t>()), v = floats(sampler["output"].get<size_t>());
    const auto& [given, width] = outputs[n];
    ASSERT_EQ(t.size(), 3u + 29 + 89);
    ASSERT_EQ(v.size(), t.size() * width);
    EXPECT_EQ(t[0], 0.0f);
    EXPECT_EQ(t[30], 0.5f);
    EXPECT_EQ(t[15], 0.25f);
    EXPECT_EQ(t.back(), 2.0f);
    EXPECT_EQ(file.doc["accessors"][sampler["output"].get<size_t>()]["type"], n == 0 ? "VEC3" : n == 1 ? "VEC4" : "SCALAR");
    for (size_t c = 0; c < width; ++c) {
      EXPECT_EQ(v[30 * width + c], (*given)[(3 * 1 + 1) * width + c]) << "the key's own value, sampler " << n;
      EXPECT_EQ(v[t.size() * width - width + c], (*given)[(3 * 2 + 1) * width + c]) << "the last key, sampler " << n;
    }
    // Half-way and a quarter of the way through each gap.
    for (const auto& [i, k, s, td] : std::vector<std::tuple<size_t, size_t, double, double>>{
             {15, 0, 0.5, 0.5}, {8, 0, 8 / 30.0, 0.5}, {30 + 45, 1, 0.5, 1.5}, {30 + 22, 1, 22 / 90.0, 1.5}}) {
      std::vector<double> want(width);
      double norm = 0;
      for (size_t c = 0; c < width; ++c) norm += std::pow(want[c] = spline(*given, width, k, s, td, c), 2);
      for (size_t c = 0; c < width; ++c) {
        const double expected = n == 1 ? want[c] / std::sqrt(norm) : want[c];
        EXPECT_NEAR(v[i * width + c], expected, 1e-6) << "sampler " << n << " key " << i << " component " << c;
      }
    }
  }
  EXPECT_EQ(cubic_samplers_as_keys(file, "t.glb", added), 0u) << "linear already";
}

TEST(MeshLoad, GltfWithAPercentEncodedBufferReadsAsItsGlb) {
  SPX_REQUIRE_SHARED_DATA();
  const std::string glb_path = test::shared_data() + "/rigged-simple/RiggedSimple.glb";
  const std::string dir = test::temp_dir("percent-uri");
  GltfFile file = read_gltf_file(glb_path);
  write_file_atomic(dir + "/My Body.bin", file.bin);
  file.doc["buffers"] = json::array({{{"uri", "My%20Body.bin"}, {"byteLength", file.bin.size()}}});
  write_file_atomic(dir + "/body.gltf", file.doc.dump());
  const LoadedMesh glb = load_mesh(glb_path), gltf = load_mesh(dir + "/body.gltf");
  EXPECT_EQ(gltf.mesh.vertices, glb.mesh.vertices);
  EXPECT_EQ(gltf.mesh.triangles, glb.mesh.triangles);
  // A buffer that is not there is named as the file gives it, not assimp's "could not open".
  file.doc["buffers"][0]["uri"] = "Other%20Body.bin";
  write_file_atomic(dir + "/other.gltf", file.doc.dump());
  try {
    load_mesh(dir + "/other.gltf");
    ADD_FAILURE() << "read a .gltf whose buffer is not there";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("its buffer 'Other%20Body.bin' is not beside it"), std::string::npos) << e.what();
  }
}

// A skinned mesh is where its skin puts it, as glTF draws it and pose-extract's rest has it: not
// where its node would place a static mesh. RiggedSimple with its skinned node moved 5 along z
// (which glTF ignores) read 5 away from pose-extract's rest, and the chain from that field stopped
// at pose-map ("20 of 20 spheres do not fit inside this rest mesh"). The file as it is reads as
// before, and as the rest.
TEST(MeshLoad, SkinnedMeshIsPlacedByItsSkinAsPoseExtractsRest) {
  SPX_REQUIRE_SHARED_DATA();
  const std::string dir = test::temp_dir("skinned-node");
  const std::string original = test::shared_data() + "/rigged-simple/RiggedSimple.glb";
  GltfFile file = read_gltf_file(original);
  ASSERT_TRUE(file.doc["nodes"][1].contains("skin"));
  file.doc["nodes"][1]["translation"] = json::array({0, 0, 5});
  write_file_atomic(dir + "/moved.glb", encode_glb(file));
  // A second node places the same skinned mesh 3 along x: glTF draws both where the skin puts
  // them, one place, so it is read once (it read 3 away, doubling the body).
  file.doc["nodes"].push_back({{"name", "second"}, {"mesh", 0}, {"skin", 0}, {"translation", {3, 0, 0}}});
  file.doc["scenes"][0]["nodes"].push_back(file.doc["nodes"].size() - 1);
  write_file_atomic(dir + "/twice.glb", encode_glb(file));
  const size_t triangles = load_mesh(original).mesh.triangles.size();
  for (const std::string& path : {original, dir + "/moved.glb", dir + "/twice.glb"}) {
    const LoadedMesh mesh = load_mesh(path);
    const Asset asset(path, "");
    const WeldedBody body = weld_body(asset);
    ASSERT_EQ(mesh.mesh.vertices.size(), body.rest.vertices.size()) << path;
    EXPECT_EQ(mesh.mesh.triangles.size(), triangles) << path;
    EXPECT_EQ(body.rest.triangles.size(), triangles) << path;
    const size_t repeated = path == dir + "/twice.glb" ? triangles : 0;
    EXPECT_EQ(mesh.repeated.count, repeated) << path;
    EXPECT_EQ(body.repeated.count, repeated) << path;
    const double size = body.rest.bounds().diagonal().norm();
    for (const Eigen::Vector3d& v : mesh.mesh.vertices) {
      double nearest = INFINITY;
      for (const Eigen::Vector3d& r : body.rest.vertices) nearest = std::min(nearest, (v - r).norm());
      ASSERT_LT(nearest, 1e-6 * size) << path << ": a vertex at " << v.transpose();
    }
  }
}

// glTF skins a node, not a mesh: RiggedSimple's skinned mesh placed again by a node without a
// skin, 3 along x, is drawn there as stored, unmoved by the clip, and by a node of another skin
// where that skin puts it. assimp gave the shared mesh the
// skin's bones, so the copy read where the skin puts the body and was dropped as a repeat ("a part
// placed twice in one place"): 188 triangles where glTF draws 376.
TEST(MeshLoad, SkinnedMeshIsDrawnByEachNodesOwnSkinOrNone) {
  SPX_REQUIRE_SHARED_DATA();
  const std::string original = test::shared_data() + "/rigged-simple/RiggedSimple.glb";
  GltfFile file = read_gltf_file(original);
  file.doc["nodes"].push_back({{"name", "rigid"}, {"mesh", 0}, {"translation", {3, 0, 0}}});
  file.doc["scenes"][0]["nodes"].push_back(file.doc["nodes"].size() - 1);
  const std::string path = test::temp_dir("unskinned-node") + "/rigid.glb";
  write_file_atomic(path, encode_glb(file));
  const LoadedMesh single = load_mesh(original), both = load_mesh(path);
  EXPECT_EQ(both.repeated.count, 0u);
  ASSERT_EQ(both.mesh.triangles.size(), 2 * single.mesh.triangles.size());
  // The skinned copy where it was; the rigid one at the stored positions moved 3 along x.
  const json& positions = file.doc["accessors"][file.doc["meshes"][0]["primitives"][0]["attributes"]["POSITION"].get<size_t>()];
  const Eigen::Vector3d shift(3, 0, 0);
  const Eigen::AlignedBox3d stored(Eigen::Vector3d(positions["min"][0], positions["min"][1], positions["min"][2]) + shift,
                                   Eigen::Vector3d(positions["max"][0], positions["max"][1], positions["max"][2]) + shift);
  const double size = single.mesh.bounds().diagonal().norm();
  auto nearest = [](const Eigen::Vector3d& p, const std::vector<Eigen::Vector3d>& in) {
    double d = INFINITY;
    for (const Eigen::Vector3d& q : in) d = std::min(d, (p - q).norm());
    return d;
  };
  Eigen::AlignedBox3d rigid;
  size_t skinned = 0;
  for (const Eigen::Vector3d& v : both.mesh.vertices)
    if (nearest(v, single.mesh.vertices) < 1e-6 * size) ++skinned;
    else rigid.extend(v);
  EXPECT_EQ(skinned, single.mesh.vertices.size());
  EXPECT_LT((rigid.min() - stored.min()).norm(), 1e-5 * size) << rigid.min().transpose();
  EXPECT_LT((rigid.max() - stored.max()).norm(), 1e-5 * size) << rigid.max().transpose();
  // pose-extract reads the same body, and its clip moves the skinned copy but not the rigid one.
  const Asset asset(path, "");
  const WeldedBody body = weld_body(asset);
  EXPECT_EQ(body.repeated.count, 0u);
  ASSERT_EQ(body.rest.vertices.size(), both.mesh.vertices.size());
  for (const Eigen::Vector3d& v : both.mesh.vertices) ASSERT_LT(nearest(v, body.rest.vertices), 1e-6 * size) << v.transpose();
  const std::vector<Eigen::Vector3d> rest = asset.rest(), bent = asset.at_time(0, asset.clips()[0].end / 2);
  size_t moved = 0, kept = 0;
  for (size_t v = 0; v < rest.size(); ++v) {
    const bool in_rigid = nearest(rest[v], single.mesh.vertices) > 1e-6 * size;
    if (in_rigid) kept += (bent[v] - rest[v]).norm() < 1e-9 * size;
    else moved += (bent[v] - rest[v]).norm() > 1e-3 * size;
  }
  EXPECT_EQ(kept, asset.vertex_count() / 2);
  EXPECT_GT(moved, 0u);

  // A second skeleton, the first's joints copied 5 along x and not animated, skins the mesh again
  // (a crowd): each copy where its own skin puts it. assimp's mesh took the last skin's bones, so
  // only the copy 5 away was read, and the animated body was lost.
  file = read_gltf_file(original);
  json& nodes = file.doc["nodes"];
  const size_t at = nodes.size();
  ASSERT_EQ(file.doc["skins"][0]["joints"], json::array({2, 3}));
  nodes.push_back(nodes[4]);
  nodes[at]["translation"] = {5, 0, 0};
  nodes[at]["children"] = {at + 1};
  nodes.push_back(nodes[2]);
  nodes[at + 1]["children"] = {at + 2};
  nodes.push_back(nodes[3]);
  json skin = file.doc["skins"][0];
  skin["joints"] = {at + 1, at + 2};
  skin["skeleton"] = at + 1;
  file.doc["skins"].push_back(skin);
  nodes.push_back({{"name", "second"}, {"mesh", 0}, {"skin", 1}});
  nodes[0]["children"].push_back(at);
  nodes[0]["children"].push_back(at + 3);
  const std::string crowd = test::temp_dir("unskinned-node") + "/crowd.glb";
  write_file_atomic(crowd, encode_glb(file));
  const LoadedMesh two = load_mesh(crowd);
  EXPECT_EQ(two.repeated.count, 0u);
  ASSERT_EQ(two.mesh.triangles.size(), 2 * single.mesh.triangles.size());
  const Asset crowd_asset(crowd, "");
  const std::vector<Eigen::Vector3d> two_rest = crowd_asset.rest(), two_bent = crowd_asset.at_time(0, crowd_asset.clips()[0].end / 2);
  const std::vector<Eigen::Vector3d> one_rest = Asset(original, "").rest();
  ASSERT_EQ(two_rest.size(), 2 * one_rest.size());
  for (size_t v = 0; v < one_rest.size(); ++v) {
    const Eigen::Vector3d& second = two_rest[one_rest.size() + v];
    EXPECT_LT((two_rest[v] - one_rest[v]).norm(), 1e-9 * size) << "vertex " << v;
    EXPECT_LT((second - one_rest[v] - Eigen::Vector3d(5, 0, 0)).norm(), 1e-6 * size) << "vertex " << v;
    EXPECT_LT((two_bent[one_rest.size() + v] - second).norm(), 1e-9 * size) << "vertex " << v << ": its skeleton is still";
    EXPECT_LT(nearest(second, two.mesh.vertices), 1e-6 * size) << "vertex " << v;
  }
}

// Each way of drawing a mesh (its skin or none, its node's weights or none) after the first draws
// its own copy; nodes drawing it alike share one, and a mesh one way alone draws is left as it
// is. A node's weights become its copy's.
TEST(MeshLoad, MeshesAreSplitByNode) {
  GltfFile file;
  file.doc = {{"nodes", {{{"mesh", 0}, {"skin", 0}}, {{"mesh", 0}}, {{"mesh", 0}, {"skin", 1}}, {{"mesh", 0}, {"skin", 0}},
                         {{"mesh", 0}}, {{"mesh", 1}}, {{"mesh", 1}}, {{"children", {0}}},
                         {{"mesh", 0}, {"weights", {0.5}}}, {{"mesh", 0}, {"weights", {0.5}}}, {{"mesh", 1}, {"weights", {1}}}}},
              {"meshes", {{{"name", "body"}, {"primitives", {{{"attributes", {{"POSITION", 0}}}}}}, {"weights", {0}}},
                          {{"name", "prop"}}}}};
  const json given = file.doc["meshes"];
  EXPECT_EQ(meshes_split_by_node(file), 6u) << "4 copies, 2 given weights";
  const json& nodes = file.doc["nodes"];
  const std::vector<int> want{0, 2, 3, 0, 2, 1, 1, -1, 4, 4, 5};
  for (size_t n = 0; n < want.size(); ++n)
    if (want[n] < 0) EXPECT_FALSE(nodes[n].contains("mesh"));
    else EXPECT_EQ(nodes[n]["mesh"], want[n]) << "node " << n;
  ASSERT_EQ(file.doc["meshes"].size(), 6u);
  EXPECT_EQ(file.doc["meshes"][0], given[0]);
  EXPECT_EQ(file.doc["meshes"][2], given[0]);
  EXPECT_EQ(file.doc["meshes"][3], given[0]);
  json weighed = given[0];
  weighed["weights"] = {0.5};
  EXPECT_EQ(file.doc["meshes"][4], weighed);
  EXPECT_EQ(file.doc["meshes"][1], given[1]);
  json prop = given[1];
  prop["weights"] = {1};
  EXPECT_EQ(file.doc["meshes"][5], prop);
  EXPECT_EQ(meshes_split_by_node(file), 0u) << "split already";
}

// A mesh instanced by EXT_mesh_gpu_instancing (gltfpack -mi): each instance where renderers draw
// it, in the node's frame (the node moved by 10 along x). A unit cube three times: as it is; scaled
// 2 along x, turned a quarter about z (a rotation of normalized shorts) and moved 3 along x;
// mirrored in x and moved 3 along y. The body is the three cubes, volume 4, faces out, in the box
// worked out by hand, whether the extension is used or required (assimp placed the cube once at
// the node; required, the tools refused it).
TEST(MeshLoad, GpuInstancesArePlacedAsRenderersDrawThem) {
  const TriMesh cube = test::box_mesh({0, 0, 0}, {1, 1, 1});
  GltfFile file;
  auto floats = [&](const std::vector<float>& v) {
    const size_t at = file.bin.size();
    file.bin.append(reinterpret_cast<const char*>(v.data()), v.size() * 4);
    return at;
  };
  std::vector<float> corners;
  for (const auto& p : cube.vertices) corners.insert(corners.end(), {float(p.x()), float(p.y()), float(p.z())});
  std::vector<uint32_t> indices;
  for (const auto& f : cube.triangles) indices.insert(indices.end(), {uint32_t(f[0]), uint32_t(f[1]), uint32_t(f[2])});
  const size_t positions = floats(corners), faces = file.bin.size();
  file.bin.append(reinterpret_cast<const char*>(indices.data()), indices.size() * 4);
  const size_t t = floats({0, 0, 0, 3, 0, 0, 0, 3, 0}), rotations = file.bin.size();
  for (int16_t c : {0, 0, 0, 32767, 0, 0, 23170, 23170, 0, 0, 0, 32767}) file.bin.append(reinterpret_cast<const char*>(&c), 2);
  const size_t scales = floats({1, 1, 1, 2, 1, 1, -1, 1, 1});
  file.doc = {{"asset", {{"version", "2.0"}}},
              {"scene", 0},
              {"scenes", {{{"nodes", {0}}}}},
              {"nodes", {{{"name", "bolts"}, {"mesh", 0}, {"translation", {10, 0, 0}},
                          {"extensions", {{"EXT_mesh_gpu_instancing",
                                           {{"attributes", {{"TRANSLATION", 2}, {"ROTATION", 3}, {"SCALE", 4}}}}}}}}}},
              {"meshes", {{{"primitives", {{{"attributes", {{"POSITION", 0}}}, {"indices", 1}}}}}}},
              {"bufferViews", {{{"buffer", 0}, {"byteOffset", positions}, {"byteLength", corners.size() * 4}},
                               {{"buffer", 0}, {"byteOffset", faces}, {"byteLength", indices.size() * 4}},
                               {{"buffer", 0}, {"byteOffset", t}, {"byteLength", 36}},
                               {{"buffer", 0}, {"byteOffset", rotations}, {"byteLength", 24}},
                               {{"buffer", 0}, {"byteOffset", scales}, {"byteLength", 36}}}},
              {"accessors", {{{"bufferView", 0}, {"componentType", 5126}, {"count", cube.vertices.size()}, {"type", "VEC3"},
                              {"min", {0, 0, 0}}, {"max", {1, 1, 1}}},
                             {{"bufferView", 1}, {"componentType", 5125}, {"count", indices.size()}, {"type", "SCALAR"}},
                             {{"bufferView", 2}, {"componentType", 5126}, {"count", 3}, {"type", "VEC3"}},
                             {{"bufferView", 3}, {"componentType", 5122}, {"normalized", true}, {"count", 3}, {"type", "VEC4"}},
                             {{"bufferView", 4}, {"componentType", 5126}, {"count", 3}, {"type", "VEC3"}}}},
              {"extensionsUsed", {"EXT_mesh_gpu_instancing"}}};
  const std::string dir = test::temp_dir("instances");
  for (const bool required : {false, true}) {
    if (required) file.doc["extensionsRequired"] = {"EXT_mesh_gpu_instancing"};
    const std::string path = dir + (required ? "/required.glb" : "/used.glb");
    write_file_atomic(path, encode_glb(file));
    const TriMesh body = load_mesh(path).mesh;
    EXPECT_EQ(body.triangles.size(), 3 * cube.triangles.size()) << path;
    const MeshDefects d = find_defects(body);
    EXPECT_EQ(d.components, 3u) << path;
    EXPECT_NEAR(d.signed_volume, 4.0, 2e-4) << path;  // the quarter turn in shorts: 1/32767 off unit
    const Eigen::AlignedBox3d box = body.bounds();
    EXPECT_LT((box.min() - Eigen::Vector3d(9, 0, 0)).norm(), 1e-4) << path << ": " << box.min().transpose();
    EXPECT_LT((box.max() - Eigen::Vector3d(13, 4, 1)).norm(), 1e-4) << path << ": " << box.max().transpose();
  }
  // Attributes that count different numbers of instances: exit 2 naming the file.
  file.doc["accessors"][4]["count"] = 2;
  write_file_atomic(dir + "/uneven.glb", encode_glb(file));
  try {
    load_mesh(dir + "/uneven.glb");
    ADD_FAILURE() << "read instances of uneven counts";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ExitCode::bad_input);
    EXPECT_NE(std::string(e.what()).find("count different numbers of instances"), std::string::npos) << e.what();
  }
}

TEST(MeshLoad, ReadsEveryListedFormat) {
  const std::string dir = test::temp_dir("formats");
  // ASCII STL of a unit box, written by hand: STL repeats corners per facet, the weld joins them.
  const TriMesh box = test::box_mesh({0, 0, 0}, {1, 1, 1});
  std::string stl = "solid box\n";
  for (const auto& t : box.triangles) {
    stl += " facet normal 0 0 0\n  outer loop\n";
    for (int k = 0; k < 3; ++k) {
      const auto& v = box.vertices[size_t(t[k])];
      stl += "   vertex " + std::to_string(v.x()) + " " + std::to_string(v.y()) + " " + std::to_string(v.z()) + "\n";
    }
    stl += "  endloop\n endfacet\n";
  }
  write_file_atomic(dir + "/box.stl", stl + "endsolid box\n");
  const LoadedMesh from_stl = load_mesh(dir + "/box.stl");
  EXPECT_EQ(from_stl.mesh.vertices.size(), 8u);
  EXPECT_TRUE(find_defects(from_stl.mesh).watertight());

  SPX_REQUIRE_SHARED_DATA();
  struct Case { const char* file; size_t triangles; };
  for (const Case& c : {Case{"static/bunny.off", 6966}, Case{"static/decimated-knight.off", 1000},
                        Case{"broken/cube_with_fold.ply", 0}, Case{"rigged-simple/RiggedSimple.glb", 188},
                        Case{"cube/rest.obj", 3072}}) {
    const LoadedMesh m = load_mesh(test::shared_data() + "/" + c.file);
    if (c.triangles) EXPECT_EQ(m.mesh.triangles.size(), c.triangles) << c.file;
    EXPECT_GT(m.mesh.triangles.size(), 0u) << c.file;
  }
  // The glTF's seams are welded back into a closed surface.
  EXPECT_TRUE(find_defects(load_mesh(test::shared_data() + "/rigged-simple/RiggedSimple.glb").mesh).watertight());
}

namespace {

// A mesh's triangles as strips: each paired with a neighbour across its second edge where one is
// left (a, b, c then d, as (a, b, c) and (c, b, d)), else alone.
std::vector<std::vector<int64_t>> as_strips(const TriMesh& mesh) {
  std::map<std::pair<int, int>, size_t> by_edge;
  for (size_t t = 0; t < mesh.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) by_edge[{mesh.triangles[t][k], mesh.triangles[t][(k + 1) % 3]}] = t;
  std::vector<bool> used(mesh.triangles.size(), false);
  std::vector<std::vector<int64_t>> strips;
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    if (used[t]) continue;
    used[t] = true;
    const Eigen::Vector3i& f = mesh.triangles[t];
    std::vector<int64_t> strip{f[0], f[1], f[2]};
    for (int k = 0; k < 3 && strip.size() == 3; ++k) {
      const int a = f[k], b = f[(k + 1) % 3], c = f[(k + 2) % 3];
      const auto n = by_edge.find({c, b});
      if (n == by_edge.end() || used[n->second]) continue;
      used[n->second] = true;
      const Eigen::Vector3i& g = mesh.triangles[n->second];
      strip = {a, b, c, g[0] + g[1] + g[2] - b - c};
    }
    strips.push_back(strip);
  }
  return strips;
}

// Sorted triangles by their corners' positions, each from its least corner (its turn kept).
std::vector<std::array<double, 9>> triangles_by_position(const TriMesh& mesh) {
  std::vector<std::array<double, 9>> out;
  for (const Eigen::Vector3i& t : mesh.triangles) {
    std::array<std::array<double, 3>, 3> c;
    for (int k = 0; k < 3; ++k) c[size_t(k)] = {mesh.vertices[size_t(t[k])].x(), mesh.vertices[size_t(t[k])].y(), mesh.vertices[size_t(t[k])].z()};
    std::rotate(c.begin(), std::min_element(c.begin(), c.end()), c.end());
    out.push_back({c[0][0], c[0][1], c[0][2], c[1][0], c[1][1], c[1][2], c[2][0], c[2][1], c[2][2]});
  }
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace

// assimp 5.2 read a PLY's triangle strips as one triangle per strip element: a sphere of 2 208
// triangles in strips read as 1 (the ASCII file here), refused as enclosing no volume. Its strips are now read as the
// triangles they stand for, the same as the sphere's faces: ASCII with -1 restarting the strip in
// one element, binary (little-endian) joined by repeated corners in one run, binary big-endian
// with one element per strip in uint indices (the restart 4294967295 between two of them). Its
// faces given before its vertices, which PLY allows and assimp refused, are read too.
TEST(MeshLoad, PlyTriangleStripsReadAsTheirTriangles) {
  TriMesh sphere = test::uv_sphere(1024.0, 24, 48);
  for (Eigen::Vector3d& v : sphere.vertices) v = v.array().round();  // whole numbers: every reader reads them exactly
  const std::vector<std::vector<int64_t>> strips = as_strips(sphere);
  ASSERT_LT(strips.size(), sphere.triangles.size() * 3 / 4) << "mostly pairs";
  const std::string dir = test::temp_dir("ply-strips");
  std::string head = "ply\nformat FORMAT 1.0\ncomment strips\nelement vertex " + std::to_string(sphere.vertices.size()) +
                     "\nproperty float x\nproperty float y\nproperty float z\n";
  auto exact = [](const Eigen::Vector3d& v) {
    char text[96];
    std::snprintf(text, sizeof text, "%.0f %.0f %.0f", v.x(), v.y(), v.z());
    return std::string(text);
  };
  auto with_format = [&](const std::string& format) { return std::string(head).replace(head.find("FORMAT"), 6, format); };
  auto bytes = [](auto value, bool big) {
    std::string b(sizeof(value), '\0');
    std::memcpy(b.data(), &value, sizeof(value));
    if (big) std::reverse(b.begin(), b.end());
    return b;
  };
  // ASCII: one element, the strips restarted by -1.
  std::string ascii = with_format("ascii") + "element tristrips 1\nproperty list int int vertex_indices\nend_header\n";
  for (const Eigen::Vector3d& v : sphere.vertices) ascii += exact(v) + "\n";
  std::vector<int64_t> restarted;
  for (const auto& s : strips) {
    if (!restarted.empty()) restarted.push_back(-1);
    restarted.insert(restarted.end(), s.begin(), s.end());
  }
  ascii += std::to_string(restarted.size());
  for (int64_t i : restarted) ascii += " " + std::to_string(i);
  write_file_atomic(dir + "/ascii.ply", ascii + "\n");
  // Binary: one run, the strips joined by repeated corners (one more where the next would start odd).
  std::vector<int64_t> run;
  for (const auto& s : strips) {
    if (!run.empty()) {
      const int64_t last = run.back();
      run.push_back(last);
      if (run.size() % 2 == 0) run.push_back(last);
      run.push_back(s[0]);
    }
    run.insert(run.end(), s.begin(), s.end());
  }
  for (const bool big : {false, true}) {
    std::string bin = with_format(big ? "binary_big_endian" : "binary_little_endian");
    bin += big ? "element tristrips " + std::to_string(strips.size() - 1) + "\nproperty list uchar uint vertex_indices\n"
               : "element tristrips 1\nproperty list int int vertex_indices\n";
    bin += "end_header\n";
    for (const Eigen::Vector3d& v : sphere.vertices)
      for (int k = 0; k < 3; ++k) bin += bytes(float(v[k]), big);
    if (!big) {
      bin += bytes(int32_t(run.size()), false);
      for (int64_t i : run) bin += bytes(int32_t(i), false);
    } else {
      for (size_t s = 0; s + 1 < strips.size(); ++s) {
        std::vector<int64_t> one = strips[s];
        if (s == 0) {  // the last strip after a restart in the first element
          one.push_back(-1);
          one.insert(one.end(), strips.back().begin(), strips.back().end());
        }
        bin += char(one.size());
        for (int64_t i : one) bin += bytes(i < 0 ? uint32_t(0xFFFFFFFF) : uint32_t(i), true);
      }
    }
    write_file_atomic(dir + (big ? "/big.ply" : "/little.ply"), bin);
  }
  std::string faces = with_format("ascii") + "element face " + std::to_string(sphere.triangles.size()) +
                      "\nproperty list uchar int vertex_indices\nend_header\n";
  for (const Eigen::Vector3d& v : sphere.vertices) faces += exact(v) + "\n";
  for (const Eigen::Vector3i& t : sphere.triangles) faces += "3 " + std::to_string(t[0]) + " " + std::to_string(t[1]) + " " + std::to_string(t[2]) + "\n";
  write_file_atomic(dir + "/faces.ply", faces);
  const LoadedMesh given = load_mesh(dir + "/faces.ply");
  ASSERT_EQ(given.mesh.triangles.size(), sphere.triangles.size());
  // The faces before the vertices, which PLY allows (assimp refused them): a comment between.
  const size_t element_face = faces.find("element face"), vertex_lines = faces.find("end_header\n") + 11;
  const size_t face_lines = vertex_lines + faces.substr(vertex_lines).find("\n3 ") + 1;
  std::string faces_first = faces.substr(0, faces.find("element vertex")) + faces.substr(element_face, faces.find("end_header") - element_face);
  faces_first += "comment the vertices next\n" + faces.substr(faces.find("element vertex"), element_face - faces.find("element vertex"));
  faces_first += "end_header\n" + faces.substr(face_lines) + faces.substr(vertex_lines, face_lines - vertex_lines);
  write_file_atomic(dir + "/faces-first.ply", faces_first);
  // A value past a line's properties, which the reader passes over (a vertex's colour index left
  // in the file): the faces and strips after it are read from their own lines. The rewrite read on
  // into the next line, so every vertex after the first was misread.
  auto with_extra_values = [](std::string text, size_t from, size_t lines) {
    for (size_t at = text.find('\n', from); lines-- > 0; at = text.find('\n', at + 3)) text.insert(at, " 7");
    return text;
  };
  write_file_atomic(dir + "/faces-first-extra.ply",
                    with_extra_values(faces_first, faces_first.size() - (face_lines - vertex_lines), sphere.vertices.size()));
  write_file_atomic(dir + "/ascii-extra.ply", with_extra_values(ascii, ascii.find("end_header\n") + 11, sphere.vertices.size()));
  for (const char* name : {"/ascii.ply", "/little.ply", "/big.ply", "/faces-first.ply", "/faces-first-extra.ply", "/ascii-extra.ply"}) {
    const LoadedMesh m = load_mesh(dir + name);
    EXPECT_EQ(m.mesh.triangles.size(), sphere.triangles.size()) << name;
    const auto read = triangles_by_position(m.mesh), want = triangles_by_position(given.mesh);
    std::vector<std::array<double, 9>> missing;
    std::set_difference(want.begin(), want.end(), read.begin(), read.end(), std::back_inserter(missing));
    EXPECT_TRUE(missing.empty()) << name << ": " << missing.size() << " of the faces' triangles not read, the first from "
                                 << missing[0][0] << ", " << missing[0][1] << ", " << missing[0][2];
  }
  // Exit 2 naming the file: a strip past the vertices; strips beside faces.
  std::string past = ascii;
  past.replace(past.rfind(' '), std::string::npos, " 99999\n");
  write_file_atomic(dir + "/past.ply", past);
  std::string both = ascii;
  both.replace(both.find("element tristrips"), 0, "element face 0\nproperty list uchar int vertex_indices\n");
  write_file_atomic(dir + "/both.ply", both);
  for (const auto& [name, says] : {std::pair<std::string, std::string>{"/past.ply", "triangle strip 1 names vertex 99999 (counted from 0), past its "},
                                   {"/both.ply", "holds both faces and triangle strips"}}) {
    try {
      load_mesh(dir + name);
      ADD_FAILURE() << name << " read";
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ExitCode::bad_input) << name;
      EXPECT_NE(std::string(e.what()).find(says), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(name.substr(1)), std::string::npos) << e.what();
    }
  }
}

TEST(MeshLoad, BadFilesGiveClassifiedErrors) {
  const std::string dir = test::temp_dir("bad");
  auto code_of = [](const std::string& path) {
    try {
      load_mesh(path);
    } catch (const Error& e) {
      return e.code();
    }
    return ExitCode::ok;
  };
  EXPECT_EQ(code_of(dir + "/missing.obj"), ExitCode::bad_input);
  write_file_atomic(dir + "/empty.obj", "");
  EXPECT_EQ(code_of(dir + "/empty.obj"), ExitCode::bad_input);
  write_file_atomic(dir + "/mesh.xyz123", "v 0 0 0\n");
  EXPECT_EQ(code_of(dir + "/mesh.xyz123"), ExitCode::unsupported);
  write_file_atomic(dir + "/garbage.obj", "this is not a mesh\n\x01\x02 at all\n");
  EXPECT_EQ(code_of(dir + "/garbage.obj"), ExitCode::bad_input);
  write_file_atomic(dir + "/nan.obj", "v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n");
  EXPECT_EQ(code_of(dir + "/nan.obj"), ExitCode::bad_input);
  // The message names the vertex by where it is: assimp's index is not the file's (it gave
  // "vertex 5" of a file with 4), and 1e300 is finite in the file but not as the float read.
  auto message_of = [](const std::string& path) {
    try {
      load_mesh(path);
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  const std::string tetra = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1e300\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
  write_file_atomic(dir + "/huge.obj", tetra);
  EXPECT_NE(message_of(dir + "/huge.obj").find("huge.obj: a vertex at (0, 0, inf) is not a finite number (read as a "
                                               "32-bit float: NaN, infinite or past 3.4e38)"),
            std::string::npos)
      << message_of(dir + "/huge.obj");
  EXPECT_NE(message_of(dir + "/nan.obj").find("a vertex at (nan, 1, 0)"), std::string::npos) << message_of(dir + "/nan.obj");
}

// The error load_mesh gives `path` (checked to be bad input's), or "no error".
std::string load_error(const std::string& path) {
  return test::bad_input_error([&] { load_mesh(path); });
}

// assimp keeps the faces of a file cut short with no corners (its triangulation then aborted the
// process) and a PLY face's index past the vertices (read past their end), and its PLY reader
// never returned on a header cut short: each is one error.
TEST(MeshLoad, FacesWithoutCornersOrPastTheVerticesAreErrors) {
  const std::string dir = test::temp_dir("bad-faces");
  const std::string tetra = "0 0 0\n1 0 0\n0 1 0\n0 0 1\n";
  write_file_atomic(dir + "/cut.off", "OFF\n4 4 0\n" + tetra + "3 0 2 1\n");
  write_file_atomic(dir + "/bare.off", "OFF\n4 4 0\n");
  write_file_atomic(dir + "/past.ply",
                    "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
                    "element face 4\nproperty list uchar int vertex_indices\nend_header\n" +
                        tetra + "3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 7\n");
  write_file_atomic(dir + "/head.ply", "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\n");
  const std::string header = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
                             "end_header";
  write_file_atomic(dir + "/run-on.ply", header + "-1\n" + tetra);  // its end run into the data
  write_file_atomic(dir + "/crlf.ply", header + " \r\n" + tetra);   // ends, with a space and CR LF
  auto error_of = [](const std::function<void()>& read) {
    try {
      read();
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ExitCode::bad_input) << e.what();
      return std::string(e.what());
    }
    return std::string("no error");
  };
  for (const unsigned flags : {0u, unsigned(aiProcess_Triangulate)}) {  // as sdf-build and as pose-extract read
    auto read = [&](const std::string& name) {
      return error_of([&] {
        Assimp::Importer importer;
        read_scene(importer, dir + "/" + name, flags, "mesh");
      });
    };
    EXPECT_NE(read("cut.off").find("cut.off: face 2 has no corners"), std::string::npos) << read("cut.off");
    EXPECT_NE(read("bare.off").find("bare.off: face 1 has no corners"), std::string::npos) << read("bare.off");
    EXPECT_NE(read("past.ply").find("past.ply: face 4 names vertex 7 (counted from 0), past its 4 vertices"),
              std::string::npos)
        << read("past.ply");
    EXPECT_NE(read("head.ply").find("head.ply: its PLY header does not end (no end_header line"), std::string::npos)
        << read("head.ply");
    EXPECT_NE(read("run-on.ply").find("run-on.ply: its PLY header does not end"), std::string::npos) << read("run-on.ply");
    EXPECT_EQ(read("crlf.ply").find("does not end"), std::string::npos) << read("crlf.ply");
  }
  EXPECT_NE(error_of([&] { load_mesh(dir + "/past.ply"); }).find("past.ply: face 4 names vertex 7"), std::string::npos);
  // The same files whole read as they did.
  write_file_atomic(dir + "/whole.off", "OFF\n4 4 0\n" + tetra + "3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n");
  const LoadedMesh whole = load_mesh(dir + "/whole.off");
  EXPECT_EQ(whole.mesh.triangles.size(), 4u);
  EXPECT_TRUE(find_defects(whole.mesh).watertight());
}

// assimp's OFF reader drops a face of more than 9 corners and takes an index past the vertices (or
// a corner it cannot read) as another vertex, saying so only in its log: each is an error naming
// the face. What it reads whole (comments, blank lines, colours, a face of 9 corners) still reads.
TEST(MeshLoad, OffFacesTheReaderWouldDropOrMoveAreErrors) {
  const std::string dir = test::temp_dir("off-faces");
  const std::string tetra = "0 0 0\n1 0 0\n0 1 0\n0 0 1\n";
  const std::string three = "3 0 2 1\n3 0 1 3\n3 0 3 2\n";
  const std::vector<std::pair<std::string, std::string>> bad = {
      {"OFF\n4 4 0\n" + tetra + three + "3 1 2 9\n", "face 4 names vertex 9 (counted from 0), past its 4 vertices"},
      {"OFF\n4 4 0\n" + tetra + three + "3 1 2 -1\n", "face 4 names vertex '-1', not a vertex index"},
      {"OFF\n4 4 0\n" + tetra + three + "3 1 2 3.5\n", "face 4 names vertex '3.5', not a vertex index"},
      {"OFF\n4 4 0\n" + tetra + three + "3 1 2\n", "face 4 has 3 corners but names 2 vertices"},
      {"OFF\n4 4 0\n" + tetra + "10 0 1 2 3 0 1 2 3 0 1\n" + three, "face 1 has 10 corners; the OFF reader keeps"},
      {"OFF\n4 4 0\n" + tetra + three.substr(0, 8) + "# the sides\n" + three.substr(8) + "3 1 2 3\n",
       "face 4 would be dropped: the OFF reader counts a line among the faces that holds none ('# the sides') as one "
       "of the header's 4; remove it"},
      {"OFF\n4 4 0\n# the corners\n" + tetra + three + "3 1 2 3\n", "vertex 1 ('# the corners') is not a vertex"},
      // A vertical tab, which the reader does not skip (the corner after it read as vertex 0), shown
      // as '?' to keep the error on one line.
      {"OFF\n4 4 0\n" + tetra + three + "3 1 2\v3\n", "face 4 names vertex '2?3', not a vertex index"},
  };
  for (size_t k = 0; k < bad.size(); ++k) {
    const std::string path = dir + "/bad" + std::to_string(k) + ".off";
    write_file_atomic(path, bad[k].first);
    const std::string error = load_error(path);
    EXPECT_NE(error.find(path + ": " + bad[k].second), std::string::npos) << error;
  }
  // A pyramid on a base of one face of 9 corners, with what the format allows around it: comments,
  // blank lines, colours after a face's corners, a line of no corners.
  std::string ring, sides, base = "9";
  for (int i = 0; i < 9; ++i) {
    const double a = 2 * M_PI * i / 9;
    ring += std::to_string(std::cos(a)) + " " + std::to_string(std::sin(a)) + " 0\n";
    sides += "3 " + std::to_string(i) + " " + std::to_string((i + 1) % 9) + " 9 0.5 0.5 0.5\n";
    base += " " + std::to_string(8 - i);
  }
  // The line of no corners is one of the header's 11 faces, as the format counts it.
  write_file_atomic(dir + "/good.off", "# a comment\nOFF # after the keyword\n# before the counts\n10 11 0\n\n" + ring +
                                           "0 0 1\n\n" + sides + "0\n" + base + "\n");
  const LoadedMesh pyramid = load_mesh(dir + "/good.off");
  EXPECT_EQ(pyramid.mesh.vertices.size(), 10u);
  EXPECT_EQ(pyramid.mesh.triangles.size(), 9u + 7u);
  EXPECT_TRUE(find_defects(pyramid.mesh).watertight());
}

// assimp's PLY reader reads on where the data ends early (an ASCII file's next line as the
// missing one, a binary file's bytes past its end) and reads a line of too few values, or a word
// that is not a number, with zeros. Every cut of a cube's binary file (either byte order), and each
// damaged ASCII line, is an error naming the element; the whole files, with colours and a list of
// floats beside the indices, read as the cube.
TEST(MeshLoad, PlyDataCutShortOrDamagedIsAnError) {
  const std::string dir = test::temp_dir("ply-data");
  const TriMesh cube = test::box_mesh({0, 0, 0}, {1, 1, 1});
  auto header = [&](const std::string& format) {
    return "ply\nformat " + format + " 1.0\ncomment a cube\nelement vertex " + std::to_string(cube.vertices.size()) +
           "\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\nelement face " +
           std::to_string(cube.triangles.size()) +
           "\nproperty list uchar int vertex_indices\nproperty list uchar float texcoord\nend_header\n";
  };
  const auto error_of = load_error;
  auto reads_as_cube = [&](const std::string& path) {
    const LoadedMesh m = load_mesh(path);
    EXPECT_EQ(m.mesh.vertices, cube.vertices) << path;
    EXPECT_EQ(m.mesh.triangles, cube.triangles) << path;
  };
  for (const bool little : {true, false}) {
    std::string body;
    auto put = [&](const void* value, size_t size) {
      const char* bytes = static_cast<const char*>(value);
      for (size_t b = 0; b < size; ++b) body += bytes[little ? b : size - 1 - b];
    };
    for (const auto& v : cube.vertices) {
      for (int a = 0; a < 3; ++a) {
        const float x = float(v[a]);
        put(&x, 4);
      }
      body += char(200);
    }
    for (const auto& t : cube.triangles) {
      body += char(3);
      for (int a = 0; a < 3; ++a) put(&t[a], 4);
      body += char(2);
      for (const float uv : {0.25f, 0.75f}) put(&uv, 4);
    }
    const std::string head = header(little ? "binary_little_endian" : "binary_big_endian");
    write_file_atomic(dir + "/whole.ply", head + body);
    reads_as_cube(dir + "/whole.ply");
    for (size_t keep = 0; keep < body.size(); ++keep) {
      write_file_atomic(dir + "/cut.ply", head + body.substr(0, keep));
      const std::string error = error_of(dir + "/cut.ply");
      ASSERT_NE(error.find("cut.ply: its data ends within "), std::string::npos) << keep << " bytes: " << error;
    }
  }
  std::vector<std::string> lines;
  for (const auto& v : cube.vertices) lines.push_back(num(v.x()) + " " + num(v.y()) + " " + num(v.z()) + " 200");
  for (const auto& t : cube.triangles)
    lines.push_back("3 " + std::to_string(t[0]) + " " + std::to_string(t[1]) + " " + std::to_string(t[2]) + " 2 0.25 +0.75");
  auto ascii = [&](const std::vector<std::string>& data) {
    std::string text = header("ascii");
    for (const auto& line : data) text += line + "\r\n";
    write_file_atomic(dir + "/text.ply", text);
    return dir + "/text.ply";
  };
  reads_as_cube(ascii(lines));
  const size_t face = cube.vertices.size() + 4, last = lines.size() - 1;  // face 5, and the last face
  std::vector<std::string> damaged = lines;
  damaged.pop_back();
  EXPECT_NE(error_of(ascii(damaged)).find("text.ply: its data ends before face 12 of 12 (a file cut short?)"),
            std::string::npos);
  damaged = lines;
  damaged[face] = "3 0 1 2 2 0.25";
  EXPECT_NE(error_of(ascii(damaged)).find("text.ply: line 25 (face 5 of 12, '3 0 1 2 2 0.25') holds 6 values, fewer "
                                          "than its header asks for"),
            std::string::npos)
      << error_of(ascii(damaged));
  damaged = lines;
  damaged[last] = "3 0 x 2 2 0.25 0.75";
  EXPECT_NE(error_of(ascii(damaged)).find("(face 12 of 12, '3 0 x 2 2 0.25 0.75'): 'x' is not a whole number"),
            std::string::npos);
  damaged = lines;
  damaged[1] = "1 0 0,5 200";
  EXPECT_NE(error_of(ascii(damaged)).find("line 14 (vertex 2 of 8, '1 0 0,5 200'): '0,5' is not a number"),
            std::string::npos)
      << error_of(ascii(damaged));
  // A byte of no UTF-8 character (a flipped bit) is quoted as '?', so the line stays text (it was
  // written as it came, which a terminal shows as a broken character); a whole character stays.
  damaged = lines;
  damaged[1] = "1 0\xF2.5 \xC3\xA9";
  EXPECT_NE(error_of(ascii(damaged)).find("(vertex 2 of 8, '1 0?.5 \xC3\xA9'): '0?.5' is not a number"), std::string::npos)
      << error_of(ascii(damaged));
}

// Quoted words stay one line of UTF-8 text, as a brute-force reading of UTF-8's rules (RFC 3629)
// keeps them, over every one- and two-byte string and random longer ones.
TEST(MeshLoad, QuotedWordsStayUtf8Text) {
  // Whether bytes [i, i + n) are one character: the code point decoded and checked in full.
  auto character = [](const std::string& s, size_t i, size_t n) {
    if (i + n > s.size()) return false;
    const unsigned c = static_cast<unsigned char>(s[i]);
    unsigned cp = n == 1 ? c : n == 2 ? c & 0x1F : n == 3 ? c & 0x0F : c & 0x07;
    if (n == 1) return c < 0x80;
    if ((c & (0xFF << (7 - n))) != ((0xFF << (8 - n)) & 0xFF)) return false;
    for (size_t k = 1; k < n; ++k) {
      const unsigned b = static_cast<unsigned char>(s[i + k]);
      if ((b & 0xC0) != 0x80) return false;
      cp = (cp << 6) | (b & 0x3F);
    }
    const unsigned least[] = {0, 0, 0x80, 0x800, 0x10000};
    return cp >= least[n] && cp <= 0x10FFFF && !(cp >= 0xD800 && cp <= 0xDFFF);
  };
  auto expected = [&](const std::string& s) {
    std::string out = s;
    for (size_t i = 0; i < s.size();) {
      size_t n = 1;
      while (n <= 4 && !character(s, i, n)) ++n;
      const unsigned c = static_cast<unsigned char>(s[i]);
      if (n > 4 || c < 0x20 || c == 0x7f) {
        out[i++] = '?';
        continue;
      }
      i += n;
    }
    return out;
  };
  std::vector<std::string> cases;
  for (int a = 0; a < 256; ++a)
    for (int b = 0; b < 256; ++b) cases.push_back({char(a), char(b)});
  std::mt19937 rng(7);
  const std::string pieces[] = {"a", "\xC3\xA9", "\xE2\x82\xAC", "\xF0\x9F\x98\x80", "\xED\xA0\x80", "\xC0\xAF", "\xF4\x90\x80\x80", "\xE0\x80\x80",
                                "\x80", "\xFF", "\xE2\x82", "\xF0\x9F", "\n"};
  for (int r = 0; r < 20000; ++r) {
    std::string s;
    for (int k = int(rng() % 6); k >= 0; --k) s += pieces[rng() % std::size(pieces)];
    cases.push_back(s);
  }
  for (const std::string& s : cases) ASSERT_EQ(one_line(s), expected(s)) << "bytes of '" << s << "'";
  EXPECT_EQ(one_line("caf\xC3\xA9 au lait", 4), "caf?...") << "a character cut";
}

// assimp's OBJ reader skips a vertex line it cannot count (two numbers, seven, ".5"), and every
// vertex after it then stands in for the one before; it reads "0x1" as 0 and "04" or "+5" as two
// corners, and skips an indented line, a first line behind a byte order mark, a line a '\' joins
// onto a comment, and a face of two corners, all without an error. The cube below keeps a vertex
// no face uses, so a dropped vertex names no vertex past the end either: each case read as some
// other mesh before. Each is now an error naming the line; what the format allows reads as the cube.
TEST(MeshLoad, ObjLinesTheReaderWouldDropOrMisreadAreErrors) {
  const std::string dir = test::temp_dir("obj-lines");
  const std::vector<std::string> base = {"v 0 0 0", "v 1 0 0", "v 1 1 0", "v 0 1 0", "v 0 0 1", "v 1 0 1",
                                         "v 1 1 1", "v 0 1 1", "v 5 5 5", "f 1 4 3", "f 1 3 2", "f 5 6 7",
                                         "f 5 7 8", "f 1 2 6", "f 1 6 5", "f 2 3 7", "f 2 7 6", "f 3 4 8",
                                         "f 3 8 7", "f 4 1 5", "f 4 5 8"};
  auto text_of = [&](size_t line, const std::string& as, const std::string& end = "\n") {
    std::string text;
    for (size_t k = 0; k < base.size(); ++k) text += (k == line ? as : base[k]) + end;
    return text;
  };
  auto load = [&](const std::string& text) {
    write_file_atomic(dir + "/cube.obj", text);
    return load_mesh(dir + "/cube.obj");
  };
  const std::vector<std::tuple<size_t, std::string, std::string>> bad = {
      {2, "v 1 1", "line 3 ('v 1 1'): a vertex of 2 numbers; the OBJ reader reads 3 (x y z), 4 (x y z w) or 6"},
      {2, "v 1 1 0 1 1 1 1", "line 3 ('v 1 1 0 1 1 1 1'): a vertex of 7 numbers"},
      {2, "v .5 1 0", "line 3 ('v .5 1 0'): the OBJ reader does not take '.5' for a number"},
      {2, "v 1 1 0x1", "line 3 ('v 1 1 0x1'): '0x1' is not a number (the OBJ reader would read only its start)"},
      {2, "v 1 1 -1.#IND00", "line 3 ('v 1 1 -1.#IND00'): '-1.#IND00' is not a number"},
      {2, " v 1 1 0", "line 3 (' v 1 1 0'): the line is indented"},
      {2, "v1 1 0", "line 3 ('v1 1 0'): no blank after 'v'; the OBJ reader would drop this vertex: write 'v 1 1 0'"},
      {1, "v 1 0 0\n# from C:\\", "line 3 ('# from C:\\'): it ends in '\\', which joins the next line to it"},
      {19, "f 4 1", "line 20 ('f 4 1'): a face of 2 corners; the OBJ reader keeps faces of 3 or more"},
      {19, "f 04 1 5", "line 20 ('f 04 1 5'): corner '04' is not an index the OBJ reader reads right"},
      {19, "f 4 1 +5", "line 20 ('f 4 1 +5'): corner '+5' is not an index"},
      {19, "f 4/1 1/0 5", "line 20 ('f 4/1 1/0 5'): corner '1/0': '0': OBJ counts from 1"},
      {19, "f 4 1 99", "line 20 ('f 4 1 99'): corner '99' names vertex 99, past the file's 9 vertices"},
  };
  auto error_of = [&](const std::string& text) {
    write_file_atomic(dir + "/cube.obj", text);
    return load_error(dir + "/cube.obj");
  };
  for (const auto& [line, as, error] : bad) {
    const std::string what = error_of(text_of(line, as));
    EXPECT_NE(what.find("cube.obj: " + error), std::string::npos) << as << ": " << what;
  }
  const std::string what = error_of("\xEF\xBB\xBF" + text_of(99, ""));
  EXPECT_NE(what.find("cube.obj: line 1 ('v 0 0 0'): the file opens with a UTF-8 byte order mark"), std::string::npos)
      << what;
  const LoadedMesh cube = load(text_of(99, ""));
  ASSERT_EQ(cube.mesh.vertices.size(), 8u);  // the unused vertex is not kept
  for (const std::string& good :
       {text_of(99, "", "\r\n"), text_of(2, "v 1 1 \\\n0"), text_of(2, "v 1 1 \\\r\n0"), text_of(2, "v 1 1 0 # a corner"),
        text_of(2, "v 1 1 0#c"), text_of(2, "v 1 1 0 0.5 0.5 0.5"), text_of(2, "v 1 1 0 1"), text_of(2, "v 1,0 1 +0"),
        text_of(2, "v\t1\t1\t0"), text_of(19, "f 4/1/1 1//1 5/1/"), text_of(19, "f -6 -9 -5"), text_of(19, "f 4 1 5 /"),
        "\xEF\xBB\xBF# a cube\n" + text_of(99, ""), text_of(8, "v 5 5 5\nvt 0 0\nvn 0 0 1\n# a comment \\\nl 1 2")}) {
    const LoadedMesh m = load(good);
    EXPECT_EQ(m.mesh.vertices, cube.mesh.vertices) << good;
    EXPECT_EQ(m.mesh.triangles, cube.mesh.triangles) << good;
  }
}

// assimp reads an STL as binary only at exactly 84 bytes plus 50 a triangle of its count: one cut
// short, or with bytes after its triangles, failed with "Failed to determine STL storage
// representation", or where its header opens with "solid" (as many exporters write it) was read
// as text and found no mesh. Every cut of a binary cube, and the cube with bytes after it, is an
// error naming the size it should have.
TEST(MeshLoad, BinaryStlOfAnotherSizeThanItsCountIsNamed) {
  const std::string dir = test::temp_dir("stl-size");
  const TriMesh cube = test::box_mesh({0, 0, 0}, {1, 1, 1});
  std::string bytes = "solid cube, binary";
  bytes.resize(80, '\0');
  auto put = [&](const void* value, size_t size) { bytes.append(static_cast<const char*>(value), size); };
  const uint32_t count = uint32_t(cube.triangles.size());
  put(&count, 4);
  for (const auto& t : cube.triangles) {
    bytes.append(12, '\0');
    for (int k = 0; k < 3; ++k)
      for (int a = 0; a < 3; ++a) {
        const float x = float(cube.vertices[size_t(t[k])][a]);
        put(&x, 4);
      }
    bytes.append(2, '\0');
  }
  auto error_of = [&](const std::string& text) {
    write_file_atomic(dir + "/cube.stl", text);
    return load_error(dir + "/cube.stl");
  };
  EXPECT_EQ(error_of(bytes), "no error");
  for (size_t keep = 19; keep < bytes.size(); ++keep) {  // from the first NUL on: binary
    const std::string error = error_of(bytes.substr(0, keep));
    const std::string expected = keep < 84 ? "cube.stl: a binary STL holds at least 84 bytes"
                                           : "cube.stl: a binary STL whose header counts 12 triangles is 684 bytes, "
                                             "and this one ends at " + std::to_string(keep) + ", within triangle " +
                                                 std::to_string((keep - 84) / 50 + 1) + " (a file cut short?)";
    ASSERT_NE(error.find(expected), std::string::npos) << keep << ": " << error;
  }
  EXPECT_NE(error_of(bytes + std::string(50, '\0')).find("cube.stl: a binary STL whose header counts 12 triangles is "
                                                         "684 bytes, and this one has 50 bytes more"),
            std::string::npos);
  // An ASCII STL padded with NULs after its end, which the reader reads, is no binary one.
  std::string text = "solid cube\n";
  for (const auto& t : cube.triangles) {
    text += "facet normal 0 0 0\nouter loop\n";
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d& v = cube.vertices[size_t(t[k])];
      text += "vertex " + num(v.x()) + " " + num(v.y()) + " " + num(v.z()) + "\n";
    }
    text += "endloop\nendfacet\n";
  }
  EXPECT_EQ(error_of(text + "endsolid cube\n" + std::string(16, '\0')), "no error");
}

// assimp's ASCII STL reader reads a coordinate as far as it is a number (a decimal comma's "0,5"
// as 0, the vertex moved), keeps 3 vertices of a facet of more, and reads a file cut short within
// a facet as the facets before it: each was a body missing triangles or moved, with only "not
// watertight" said. Every cut within a facet of the cube, a decimal comma and a facet of 4 vertices are
// errors naming the facet; what the reader reads right (no endsolid, CRLF, tabs, "nan" normals,
// two solids) reads as the cube.
TEST(MeshLoad, AsciiStlTheReaderWouldMisreadIsNamed) {
  const std::string dir = test::temp_dir("stl-text");
  const TriMesh cube = test::box_mesh({0, 0, 0}, {1, 1, 1});
  auto facet = [&](const Eigen::Vector3i& t, const std::string& normal) {
    std::string f = "facet normal " + normal + "\n outer loop\n";
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d& v = cube.vertices[size_t(t[k])];
      f += "  vertex " + num(v.x()) + " " + num(v.y()) + " " + num(v.z()) + "\n";
    }
    return f + " endloop\nendfacet\n";
  };
  std::string body;
  for (const auto& t : cube.triangles) body += facet(t, "0 0 0");
  auto load_text = [&](const std::string& text) {
    write_file_atomic(dir + "/cube.stl", text);
    return load_error(dir + "/cube.stl");
  };
  auto reads_as_cube = [&](const std::string& text) {
    write_file_atomic(dir + "/cube.stl", text);
    const LoadedMesh m = load_mesh(dir + "/cube.stl");
    EXPECT_EQ(m.mesh.vertices.size(), cube.vertices.size());
    EXPECT_EQ(m.mesh.triangles.size(), cube.triangles.size());
    EXPECT_TRUE(find_defects(m.mesh).watertight());
  };
  const std::string whole = "solid cube\n" + body + "endsolid cube\n";
  reads_as_cube(whole);
  reads_as_cube("solid cube\n" + body);  // no endsolid
  std::string crlf_tabs = whole;
  for (size_t at = 0; (at = crlf_tabs.find('\n', at)) != std::string::npos; at += 2) crlf_tabs.replace(at, 1, "\r\n");
  for (size_t at = 0; (at = crlf_tabs.find(' ', at)) != std::string::npos; ++at) crlf_tabs[at] = '\t';
  reads_as_cube(crlf_tabs);
  std::string nan_normals, halves[2];
  for (size_t i = 0; i < cube.triangles.size(); ++i) {
    nan_normals += facet(cube.triangles[i], "nan -nan nan");
    halves[i % 2] += facet(cube.triangles[i], "0 0 0");
  }
  reads_as_cube("solid cube\n" + nan_normals + "endsolid cube\n");
  reads_as_cube("solid a\n" + halves[0] + "endsolid a\nsolid b\n" + halves[1] + "endsolid b\n");
  // Every cut from a facet's "facet" to its "endfacet" ends within it.
  size_t cuts = 0;
  for (size_t k = 1, start = whole.find("facet normal"); start != std::string::npos;
       ++k, start = whole.find("facet normal", start + 1)) {
    const size_t end = whole.find("endfacet", start) + 8;
    for (size_t keep = start + 5; keep < end; ++keep, ++cuts) {
      const std::string error = load_text(whole.substr(0, keep));
      ASSERT_NE(error.find("cube.stl: its data ends within facet " + std::to_string(k) + ", begun on line "),
                std::string::npos)
          << keep << " bytes: " << error;
    }
  }
  EXPECT_GT(cuts, 12u * 80u);
  std::string comma = whole;
  comma.replace(comma.find("vertex 1 0 0"), 12, "vertex 1 0,5 0");
  EXPECT_NE(load_text(comma).find("cube.stl: line 6 (facet 1): '0,5' is not a coordinate (a decimal comma? the STL "
                                  "reader would read 0 and move the vertex: write a decimal point)"),
            std::string::npos)
      << load_text(comma);
  std::string four = whole;
  four.insert(four.find(" endloop"), "  vertex 0.5 0.5 0.5\n");
  EXPECT_NE(load_text(four).find("cube.stl: facet 1, begun on line 2, has 4 vertices; the STL reader reads a facet as "
                                 "one triangle (3 vertices) and would drop the others"),
            std::string::npos)
      << load_text(four);
}

TEST(Defects, OpenFlippedAndNonManifold) {
  TriMesh box = test::box_mesh({0, 0, 0}, {1, 1, 1});
  TriMesh open = box;
  open.triangles.pop_back();
  MeshDefects d = find_defects(open);
  EXPECT_EQ(d.boundary_edges, 3u);
  EXPECT_FALSE(d.watertight());

  TriMesh flipped = box;
  std::swap(flipped.triangles[0][1], flipped.triangles[0][2]);
  d = find_defects(flipped);
  EXPECT_EQ(d.inconsistent_edges, 3u);

  TriMesh fin = box;  // a third triangle on edge (0,1)
  fin.vertices.emplace_back(0.5, -1, 0.5);
  fin.triangles.emplace_back(0, 1, 8);
  d = find_defects(fin);
  EXPECT_EQ(d.non_manifold_edges, 1u);
  EXPECT_EQ(d.boundary_edges, 2u);

  TriMesh two = box;
  for (int i = 0; i < 8; ++i) two.vertices.push_back(box.vertices[size_t(i)] + Eigen::Vector3d(5, 0, 0));
  for (int t = 0; t < 12; ++t) two.triangles.push_back(box.triangles[size_t(t)].array() + 8);
  two.triangles.emplace_back(0, 0, 1);
  d = find_defects(two);
  EXPECT_EQ(d.components, 2u);  // the degenerate triangle shares edge (0,1) with the first box
  EXPECT_EQ(d.degenerate_triangles, 1u);
}

// The fast (hierarchical) winding number against the exact sum of solid angles.
void check_winding_numbers(const TriMesh& mesh, int samples, double tolerance) {
  const WindingNumber fast(mesh);
  const Eigen::AlignedBox3d box = mesh.bounds();
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-0.2, 1.2);
  const MeshQuery query(mesh);
  int checked = 0;
  for (int i = 0; i < samples; ++i) {
    const Eigen::Vector3d p = box.min() + Eigen::Vector3d(u(rng), u(rng), u(rng)).cwiseProduct(box.sizes());
    const double exact = winding_number_exact(mesh, p);
    EXPECT_NEAR(fast(p), exact, tolerance) << p.transpose();
    // Away from the surface, the inside test agrees with the exact value.
    if (query.distance(p) > 1e-3 * box.diagonal().norm() && std::abs(exact - 0.5) > 0.05) {
      EXPECT_EQ(fast.inside(p), exact > 0.5);
      ++checked;
    }
  }
  EXPECT_GT(checked, samples / 2);
}

// One hierarchy, many shapes: each shape's signed distances against brute force (every triangle),
// bounded searches, and sides against the exact winding number, on the box (corner and edge
// regions everywhere) and the elephant: at rest, twisted about its vertical axis, and with its
// front half pushed back through its rear (parts passing through each other: winding number 2,
// walls inside the solid; a box's corners only make a shorter box).
void check_deforming_query(const TriMesh& rest, int points, unsigned seed, bool overlaps) {
  const DeformingQuery query(rest);
  ASSERT_TRUE(query.closed());
  const Eigen::AlignedBox3d box = rest.bounds();
  const double diag = rest.diagonal();
  for (int kind = 0; kind < 3; ++kind) {
    TriMesh shape = rest;
    for (auto& v : shape.vertices) {
      if (kind == 1) {
        const double a = 0.6 * (v.y() - box.min().y()) / box.sizes().y();
        v = Eigen::Vector3d(std::cos(a) * v.x() + std::sin(a) * v.z(), v.y(), -std::sin(a) * v.x() + std::cos(a) * v.z());
      }
      if (kind == 2 && v.x() > box.center().x()) v.x() -= 0.3 * box.sizes().x();
    }
    const DeformingQuery::Shape s = query.shape(shape.vertices);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-0.1, 1.1), near(-0.02, 0.02);
    std::uniform_int_distribution<size_t> vertex(0, shape.vertices.size() - 1);
    int checked_sides = 0, deep = 0;
    for (int i = 0; i < points; ++i) {
      // Half in the box, half a hair from a vertex (its corner and edge regions).
      const Eigen::Vector3d p =
          i % 2 ? Eigen::Vector3d(box.min() + box.sizes().cwiseProduct(Eigen::Vector3d(u(rng), u(rng), u(rng))))
                : Eigen::Vector3d(shape.vertices[vertex(rng)] + diag * Eigen::Vector3d(near(rng), near(rng), near(rng)));
      double brute = 1e300;
      for (const auto& t : shape.triangles)
        brute = std::min(brute, (p - closest_point_on_triangle(p, shape.vertices[size_t(t[0])], shape.vertices[size_t(t[1])],
                                                               shape.vertices[size_t(t[2])])).norm());
      const double d = s.signed_distance(p);
      EXPECT_NEAR(std::abs(d), brute, 1e-12 * diag) << "shape " << kind << " point " << i;
      // Bounded: the same where the surface is nearer than the bound, else nothing.
      EXPECT_EQ(s.signed_distance_within(p, 2 * brute), d);
      EXPECT_TRUE(std::isinf(s.signed_distance_within(p, 0.5 * brute)));
      EXPECT_TRUE(s.nearer_than(p, 1.01 * brute + 1e-12 * diag));
      EXPECT_FALSE(s.nearer_than(p, 0.99 * brute));
      // And a billionth either side of the distance, whatever rules a triangle out first (its
      // box, its plane): only the closest point decides that near.
      EXPECT_TRUE(s.nearer_than(p, brute * (1 + 1e-9) + 1e-13 * diag)) << "shape " << kind << " point " << i;
      EXPECT_FALSE(s.nearer_than(p, brute * (1 - 1e-9))) << "shape " << kind << " point " << i;
      const double w = winding_number_exact(shape, p);
      if (brute < 1e-6 * diag || std::abs(w - std::round(w)) > 0.05) continue;
      ++checked_sides;
      deep += w > 1.5;
      EXPECT_EQ(s.inside(p), w > 0.5) << "shape " << kind << " point " << i << " w " << w;
      // The closest surface's pseudo-normal tells the side where no part passes through another.
      if (w < 1.5 && w > -0.5 && kind < 2) EXPECT_EQ(d < 0, w > 0.5) << "shape " << kind << " point " << i << " w " << w;
    }
    EXPECT_GT(checked_sides, points * 3 / 4);
    if (kind == 2 && overlaps) EXPECT_GT(deep, 0);  // the overlap was really probed
  }
}

// Each piece's shape from its own triangles alone: the box and count as brute force finds them,
// the volume's sign by facing, flat only where every corner lies in one plane (a thin slab is not).
TEST(Defects, PieceShapesAreEachPiecesOwn) {
  TriMesh mesh = test::box_mesh({0, 0, 0}, {1, 1, 1});
  const auto add = [&mesh](const TriMesh& piece, bool flip) {
    const int first = int(mesh.vertices.size());
    for (const auto& v : piece.vertices) mesh.vertices.push_back(v);
    for (auto f : piece.triangles) {
      if (flip) std::swap(f[1], f[2]);
      mesh.triangles.push_back(f.array() + first);
    }
  };
  add(test::box_mesh({5, 0, 0}, {6, 1, 1}), true);
  add(test::box_mesh({0, 3, 0}, {1, 3.001, 1}), false);  // a slab a thousandth thick
  TriMesh decal;  // a tilted square far off, in one plane
  const Eigen::Vector3d o(1e6, 2e6, -3e6), u = Eigen::Vector3d(1, 2, 3).normalized(), w = Eigen::Vector3d(3, 0, -1).normalized();
  decal.vertices = {o, o + u, o + u + w, o + w};
  decal.triangles = {{0, 1, 2}, {0, 2, 3}};
  add(decal, false);
  const Components pieces = edge_components(mesh);
  const std::vector<PieceShape> shapes = piece_shapes(mesh, pieces);
  ASSERT_EQ(shapes.size(), 4u);
  for (size_t p = 0; p < shapes.size(); ++p) {
    Eigen::AlignedBox3d box;
    size_t triangles = 0;
    for (size_t t = 0; t < mesh.triangles.size(); ++t)
      if (size_t(pieces.of_triangle[t]) == p) {
        ++triangles;
        for (int k = 0; k < 3; ++k) box.extend(mesh.vertices[size_t(mesh.triangles[t][k])]);
      }
    EXPECT_EQ(shapes[p].triangles, triangles) << p;
    EXPECT_TRUE(shapes[p].box.isApprox(box)) << p;
  }
  EXPECT_NEAR(shapes[0].volume, 1, 1e-12);
  EXPECT_NEAR(shapes[1].volume, -1, 1e-12);
  EXPECT_NEAR(shapes[2].volume, 1e-3, 1e-12);
  EXPECT_FALSE(shapes[0].flat);
  EXPECT_FALSE(shapes[1].flat);
  EXPECT_FALSE(shapes[2].flat);
  EXPECT_TRUE(shapes[3].flat);
  EXPECT_EQ(piece_name("part", 2, 4, shapes[1]), "part 2 of 4 (12 triangles around 5.5, 0.5, 0.5)");
}

TEST(DeformingQuery, SignedDistancesMatchBruteForceInEveryShape) {
  check_deforming_query(test::box_mesh({-1, -2, -0.5}, {1, 2, 0.5}), 2000, 3, false);
  SPX_REQUIRE_SHARED_DATA();
  check_deforming_query(load_mesh(test::shared_data() + "/elephant/rest.obj").mesh, 400, 4, true);
}

// The elephant swept: most vertices rigid (no inflation), the others free to move up to 3 % of
// the diagonal. The query is held where the shape's pointer to it stays put.
struct SweptElephant {
  TriMesh rest;
  std::unique_ptr<DeformingQuery> query;
  std::vector<double> inflation;
  std::optional<DeformingQuery::Shape> swept;
  double diag = 0;
  Eigen::AlignedBox3d box;
};
SweptElephant swept_elephant(std::mt19937& rng) {
  SweptElephant e;
  e.rest = load_mesh(test::shared_data() + "/elephant/rest.obj").mesh;
  e.query = std::make_unique<DeformingQuery>(e.rest);
  e.diag = e.rest.diagonal();
  e.box = e.rest.bounds();
  std::uniform_real_distribution<double> u(0, 1);
  e.inflation.resize(e.rest.vertices.size());
  for (double& i : e.inflation) i = u(rng) < 0.7 ? 0.0 : 0.03 * e.diag * u(rng);
  e.swept.emplace(e.query->swept(e.rest.vertices, e.inflation));
  return e;
}

// The swept shape's search for one ball: the leaves its own box reaches, then the triangles.
bool inflated_near(const DeformingQuery::Shape& swept, const Eigen::Vector3d& p, double bound, size_t most,
                   std::vector<int>& found) {
  std::vector<int> leaves;
  const Eigen::Vector3d reach = Eigen::Vector3d::Constant(std::max(bound, 0.0));  // a point where negative
  swept.leaves_near(Eigen::AlignedBox3d(p - reach, p + reach), leaves);
  return swept.inflated_triangles_nearer_than(p, bound, most, found, leaves);
}

// The swept shape's test: some triangle nearer than a bound plus its vertices' largest inflation,
// exactly where brute force finds the least of distance less inflation below the bound; and that
// least is below the distance to any shape whose vertices moved within their inflation.
TEST(DeformingQuery, InflatedSearchMatchesBruteForceAndBoundsEveryMovedShape) {
  SPX_REQUIRE_SHARED_DATA();
  std::mt19937 rng(7);
  const SweptElephant e = swept_elephant(rng);
  const TriMesh& rest = e.rest;
  const DeformingQuery& query = *e.query;
  const std::vector<double>& inflation = e.inflation;
  const DeformingQuery::Shape& swept = *e.swept;
  const double diag = e.diag;
  const Eigen::AlignedBox3d box = e.box;
  std::uniform_real_distribution<double> u(0, 1), unit(-1, 1);
  // Three shapes within the sweep: each vertex moved by at most its inflation.
  std::vector<DeformingQuery::Shape> moved;
  for (int k = 0; k < 3; ++k) {
    std::vector<Eigen::Vector3d> v = rest.vertices;
    for (size_t i = 0; i < v.size(); ++i) {
      Eigen::Vector3d d(unit(rng), unit(rng), unit(rng));
      if (d.norm() > 0) v[i] += inflation[i] * u(rng) * d.normalized();
    }
    moved.push_back(query.shape(v));
  }
  for (int n = 0; n < 300; ++n) {
    const Eigen::Vector3d p = box.min() + box.sizes().cwiseProduct(Eigen::Vector3d(u(rng), u(rng), u(rng)));
    // Per triangle, its distance less its corners' largest inflation; the least of them.
    std::vector<double> gap;
    for (const auto& t : rest.triangles) {
      const double most = std::max({inflation[size_t(t[0])], inflation[size_t(t[1])], inflation[size_t(t[2])]});
      gap.push_back((p - closest_point_on_triangle(p, rest.vertices[size_t(t[0])], rest.vertices[size_t(t[1])],
                                                   rest.vertices[size_t(t[2])])).norm() - most);
    }
    const double brute = *std::min_element(gap.begin(), gap.end());
    std::vector<int> found;
    for (double off : {1e-9, 1e-3, 0.05}) {
      EXPECT_FALSE(inflated_near(swept, p, brute + off * diag, 0, found))
          << "point " << n << " off " << off;
      EXPECT_TRUE(inflated_near(swept, p, brute - off * diag, 0, found))
          << "point " << n << " off " << off;
    }
    // The triangles it finds within a bound: those brute force finds, and none past `most`.
    const double bound = brute + 0.02 * diag;
    std::vector<int> expected;
    for (size_t t = 0; t < gap.size(); ++t)
      if (gap[t] < bound) expected.push_back(int(t));
    ASSERT_TRUE(inflated_near(swept, p, bound, expected.size(), found)) << "point " << n;
    std::sort(found.begin(), found.end());
    EXPECT_EQ(found, expected) << "point " << n;
    EXPECT_FALSE(inflated_near(swept, p, bound, expected.size() - 1, found)) << "point " << n;
    EXPECT_EQ(found.size(), expected.size() - 1) << "point " << n;
    for (const DeformingQuery::Shape& s : moved) EXPECT_GE(std::abs(s.signed_distance(p)), brute) << "point " << n;
  }
}

// Searches near one another from the leaves their run's region reaches (the tree entered once)
// find what each finds from the leaves its own ball's box reaches: the same triangles in the same
// order, and the same cap.
TEST(DeformingQuery, GroupSearchFindsWhatEachSearchFinds) {
  SPX_REQUIRE_SHARED_DATA();
  std::mt19937 rng(11);
  const SweptElephant e = swept_elephant(rng);
  const DeformingQuery::Shape& swept = *e.swept;
  const double diag = e.diag;
  const Eigen::AlignedBox3d box = e.box;
  const size_t triangles = e.rest.triangles.size();
  std::uniform_real_distribution<double> u(0, 1), unit(-1, 1);
  size_t compared = 0, capped = 0;
  for (int g = 0; g < 60; ++g) {
    // 16 points within a twentieth of the diagonal, each with its own bound.
    const Eigen::Vector3d middle = box.min() + box.sizes().cwiseProduct(Eigen::Vector3d(u(rng), u(rng), u(rng)));
    std::vector<std::pair<Eigen::Vector3d, double>> asks;
    Eigen::AlignedBox3d region;
    for (int k = 0; k < 16; ++k) {
      const Eigen::Vector3d p = middle + 0.05 * diag * Eigen::Vector3d(unit(rng), unit(rng), unit(rng));
      const double bound = (0.002 + 0.03 * u(rng)) * diag;
      asks.emplace_back(p, bound);
      region.extend(p - Eigen::Vector3d::Constant(bound));
      region.extend(p + Eigen::Vector3d::Constant(bound));
    }
    std::vector<int> leaves, each, grouped;
    swept.leaves_near(region, leaves);
    for (const auto& [p, bound] : asks) {
      ASSERT_TRUE(inflated_near(swept, p, bound, triangles, each));
      ASSERT_TRUE(swept.inflated_triangles_nearer_than(p, bound, triangles, grouped, leaves));
      EXPECT_EQ(grouped, each) << "group " << g;
      compared += each.size();
      if (each.empty()) continue;
      // Capped one short: both stop at the same triangle.
      EXPECT_FALSE(swept.inflated_triangles_nearer_than(p, bound, each.size() - 1, grouped, leaves));
      EXPECT_FALSE(inflated_near(swept, p, bound, each.size() - 1, each));
      EXPECT_EQ(grouped, each) << "group " << g;
      ++capped;
    }
  }
  EXPECT_GT(compared, size_t(5000));  // the asks reach the surface, not only empty space
  EXPECT_GT(capped, size_t(300));
}

// A triangle and a point each going in a straight line: the bound on their least distance over
// the step is below the distance at every point of it (brute force, finely); and in some steps
// the distance dips below both ends by more than a quarter of the farthest corner's move, so the
// bound cannot be min(ends) less a quarter of it.
TEST(DeformingQuery, StepBoundIsBelowEveryPointOfTheStep) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> unit(-1, 1);
  auto point = [&] { return Eigen::Vector3d(unit(rng), unit(rng), unit(rng)); };
  size_t dips = 0;
  for (int n = 0; n < 2000; ++n) {
    Corners from{point(), point(), point()}, to;
    // Steps of every length: some pass the triangle through the origin between its ends.
    const Eigen::Vector3d across = (n % 2 ? 0.1 : 2.0) * point();
    for (size_t c = 0; c < 3; ++c) to[c] = from[c] + across + (n % 3 ? 0.0 : 0.3) * point();
    const double a = distance_to_origin(from), b = distance_to_origin(to);
    const double bound = least_distance_over_step(from, a, to, b);
    double brute = std::min(a, b);
    for (int k = 1; k < 1000; ++k) {
      const double s = k / 1000.0;
      Corners at;
      for (size_t c = 0; c < 3; ++c) at[c] = (1 - s) * from[c] + s * to[c];
      brute = std::min(brute, distance_to_origin(at));
    }
    EXPECT_LE(bound, brute + 1e-12) << "step " << n;
    double most = 0;
    for (size_t c = 0; c < 3; ++c) most = std::max(most, (to[c] - from[c]).norm());
    dips += brute < std::min(a, b) - most / 4;
  }
  EXPECT_GT(dips, 20u);
}

TEST(DeformingQuery, OpenMeshesAreNotClosed) {
  TriMesh open = test::box_mesh({0, 0, 0}, {1, 1, 1});
  open.triangles.pop_back();
  EXPECT_FALSE(DeformingQuery(open).closed());
  TriMesh flipped = test::box_mesh({0, 0, 0}, {1, 1, 1});
  std::swap(flipped.triangles[0][1], flipped.triangles[0][2]);
  EXPECT_FALSE(DeformingQuery(flipped).closed());
}

TEST(WindingNumber, ClosedMeshIsOneInsideZeroOutside) {
  const TriMesh sphere = test::uv_sphere(1.0);
  EXPECT_NEAR(winding_number_exact(sphere, {0.1, 0.2, -0.3}), 1.0, 1e-9);
  EXPECT_NEAR(winding_number_exact(sphere, {2, 0, 0}), 0.0, 1e-9);
  const WindingNumber fast(sphere);
  EXPECT_NEAR(fast({0.1, 0.2, -0.3}), 1.0, 5e-3);
  EXPECT_NEAR(fast({3, 1, 0}), 0.0, 5e-3);
}

TEST(WindingNumber, FastMatchesBruteForceOnTheCar) { check_winding_numbers(make_car().rest, 400, 5e-3); }

TEST(WindingNumber, FastMatchesBruteForceOnOpenAndBrokenMeshes) {
  SPX_REQUIRE_SHARED_DATA();
  for (const char* name : {"cylinder/rest.obj", "broken/truck.obj", "broken/hemisphere.obj"})
    check_winding_numbers(load_mesh(test::shared_data() + "/" + name).mesh, 150, 1e-2);
}

// An open bowl (a sphere without its upper cap) and two of them overlapping: the winding number
// passes 1/2 across the rim's disc and near the walls, where inside() needs more than the
// expansion.
TriMesh open_bowls() {
  TriMesh bowl = test::uv_sphere(1.0, 40, 80);
  std::vector<Eigen::Vector3i> kept;
  for (const auto& t : bowl.triangles)
    if (bowl.vertices[size_t(t[0])].z() + bowl.vertices[size_t(t[1])].z() + bowl.vertices[size_t(t[2])].z() < 1.5)
      kept.push_back(t);
  bowl.triangles = kept;
  TriMesh two = bowl;
  const int offset = int(bowl.vertices.size());
  for (const auto& v : bowl.vertices) two.vertices.push_back(v + Eigen::Vector3d(1.4, 0.3, 0.2));
  for (const auto& t : bowl.triangles) two.triangles.emplace_back(t[0] + offset, t[1] + offset, t[2] + offset);
  return two;
}

// Points where deciding inside is hard: random in the box, a hair off the triangles on either
// side (as the solid boundary's probes sit), and on or near the rims' discs.
std::vector<Eigen::Vector3d> hard_points(const TriMesh& mesh, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  const Eigen::AlignedBox3d box = mesh.bounds();
  const double diagonal = box.diagonal().norm();
  std::vector<Eigen::Vector3d> out;
  for (int n = 0; n < 300; ++n) out.push_back(box.min() + Eigen::Vector3d(u(rng), u(rng), u(rng)).cwiseProduct(box.sizes()));
  for (int n = 0; n < 300; ++n) {
    const auto& t = mesh.triangles[size_t(rng() % mesh.triangles.size())];
    const Eigen::Vector3d a = mesh.vertices[size_t(t[0])], b = mesh.vertices[size_t(t[1])], c = mesh.vertices[size_t(t[2])];
    const Eigen::Vector3d normal = (b - a).cross(c - a).normalized();
    const double x = u(rng), y = u(rng) * (1 - x);
    out.push_back(a + x * (b - a) + y * (c - a) + (n % 2 ? 1e-5 : -1e-5) * diagonal * normal);
  }
  double rim = -1;  // the first bowl's rim (the open_bowls' first vertices' highest used)
  for (const auto& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) rim = std::max(rim, mesh.vertices[size_t(t[k])].z() - (t[k] >= int(mesh.vertices.size() / 2)) * 9);
  for (int n = 0; n < 300; ++n) {  // that rim's disc, and a hair above and below it
    const double angle = 2 * M_PI * u(rng), radius = 1.2 * u(rng);
    const double z = rim + (n % 3 == 0 ? 0.0 : (n % 3 == 1 ? 1e-3 : -1e-3)) * u(rng);
    out.emplace_back(radius * std::cos(angle), radius * std::sin(angle), z);
  }
  return out;
}

// bounded()'s interval holds the exact sum, unrefined (the expansions' bounds themselves) and
// refined; and inside() decides as the exact sum does, mostly without taking it.
TEST(WindingNumber, BoundedHoldsTheExactSumAndDecidesAsItDoes) {
  const TriMesh meshes[] = {open_bowls(), make_car().rest};
  ASSERT_GE(meshes[0].triangles.size(), WindingNumber::kRefinedFrom);  // inside() refines there
  for (const TriMesh& mesh : meshes) {
    const WindingNumber wn(mesh);
    const size_t n = mesh.triangles.size();
    size_t near_half = 0, decided_cheaply = 0, loose = 0;
    for (const Eigen::Vector3d& q : hard_points(mesh, 11)) {
      const double exact = wn.exact(q);
      const WindingNumber::Bounded raw = wn.bounded(q, 0.5, 0);
      ASSERT_LE(std::abs(raw.value - exact), raw.error) << q.transpose();
      loose += std::abs(raw.value - exact) > 1e-12;  // the expansions leave something out
      const WindingNumber::Bounded refined = wn.bounded(q, 0.5 + WindingNumber::kTie, n / 4);
      ASSERT_LE(std::abs(refined.value - exact), refined.error) << q.transpose();
      ASSERT_EQ(wn.inside(q), std::abs(wn(q) - 0.5) < WindingNumber::kExactBand ? exact > 0.5 + WindingNumber::kTie
                                                                                  : wn(q) > 0.5)
          << q.transpose();
      if (std::abs(wn(q) - 0.5) >= WindingNumber::kExactBand) continue;
      ++near_half;
      decided_cheaply += std::abs(refined.value - (0.5 + WindingNumber::kTie)) > refined.error;
    }
    EXPECT_GT(loose, 100u);
    if (&mesh != &meshes[0]) continue;  // the car is closed: nothing near 1/2
    EXPECT_GT(near_half, 100u);
    // Off the rims' discs themselves (w = 1/2 there to the sum's rounding), the interval decides.
    EXPECT_GT(decided_cheaply, near_half / 2) << decided_cheaply << " of " << near_half;
  }
}

// The third-order expansion's bound, on single triangles, clusters of 8 (one leaf) and of 40 (a
// parent, its moments moved up from its children's): never below what the expansion leaves out,
// and not so far above it that refining would open clusters for nothing.
TEST(WindingNumber, TruncationBoundHoldsWhereverItIsTaken) {
  std::mt19937 rng(21);
  std::uniform_real_distribution<double> u(-1, 1);
  double worst = 0;
  for (int trial = 0; trial < 600; ++trial) {
    TriMesh m;
    const int triangles = trial % 3 == 0 ? 1 : trial % 3 == 1 ? 8 : 40;  // one leaf, or 8 under a root
    for (int t = 0; t < triangles; ++t) {
      const Eigen::Vector3d corner(u(rng), u(rng), u(rng));
      for (int k = 0; k < 3; ++k) m.vertices.push_back(corner + 0.5 * Eigen::Vector3d(u(rng), u(rng), u(rng)));
      m.triangles.emplace_back(3 * t, 3 * t + 1, 3 * t + 2);
    }
    const WindingNumber wn(m);
    const Eigen::Vector3d center = m.bounds().center();
    const double radius = m.bounds().diagonal().norm();  // past every corner's distance from any centre inside
    for (int k = 0; k < 20; ++k) {
      // Half just past 4 radii, where the bound is loosest; half out to 44, where an expansion
      // wrong at third order would leave more than the fourth-order bound.
      const double radii = 4.05 + (k < 10 ? 1 : 40) * std::abs(u(rng));
      const Eigen::Vector3d q = center + Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized() * radius * radii;
      const WindingNumber::Bounded b = wn.bounded(q, 0.5, 0);
      ASSERT_EQ(b.triangles, 0u);  // the expansion, not the triangles
      const double left_out = std::abs(b.value - wn.exact(q));
      ASSERT_LE(left_out, b.error) << "trial " << trial << " at " << q.transpose();
      worst = std::max(worst, left_out / b.error);
    }
  }
  EXPECT_GT(worst, 0.05);
}

// A winding number built on first use answers to the bit as one built at once, however many
// threads ask first.
TEST(WindingNumber, BuiltOnFirstUseGivesTheSameBits) {
  const TriMesh mesh = make_car().rest;
  const WindingNumber now(mesh);
  const WindingNumber later = WindingNumber::on_first_use(mesh);
  EXPECT_TRUE(now.built());
  EXPECT_FALSE(later.built());
  const Eigen::AlignedBox3d box = mesh.bounds();
  std::mt19937 rng(5);
  std::vector<Eigen::Vector3d> points(2000);
  for (auto& p : points) {
    const Eigen::Vector3d u(std::uniform_real_distribution<double>(0, 1)(rng),
                            std::uniform_real_distribution<double>(0, 1)(rng),
                            std::uniform_real_distribution<double>(0, 1)(rng));
    p = box.min() + u.cwiseProduct(box.sizes());
  }
  std::vector<double> asked(points.size());
  tbb::parallel_for(size_t(0), points.size(), [&](size_t n) { asked[n] = later(points[n]); });
  EXPECT_TRUE(later.built());
  for (size_t n = 0; n < points.size(); ++n) {
    ASSERT_EQ(asked[n], now(points[n])) << n;
    ASSERT_EQ(later.inside(points[n]), now.inside(points[n])) << n;
    ASSERT_EQ(later.exact(points[n]), now.exact(points[n])) << n;
  }
}

// A closed mesh's query told inside by its refitted hierarchy gives every answer the winding
// number gives off the surface, and never builds the winding number's hierarchy (a dense pose's
// largest part).
TEST(MeshQuery, InsideToldByItsShapeBuildsNoWindingNumber) {
  const TriMesh mesh = make_barrel().rest;
  const DeformingQuery hierarchy(mesh);
  ASSERT_TRUE(hierarchy.closed());
  const DeformingQuery::Shape shape = hierarchy.shape(mesh.vertices);
  const MeshQuery plain(mesh);
  MeshQuery told(mesh);
  told.tell_inside_by(&shape);
  EXPECT_FALSE(told.winding_number_built());
  const Eigen::AlignedBox3d box = mesh.bounds();
  std::mt19937 rng(7);
  size_t in = 0;
  for (int i = 0; i < 3000; ++i) {
    const Eigen::Vector3d u(std::uniform_real_distribution<double>(-0.1, 1.1)(rng),
                            std::uniform_real_distribution<double>(-0.1, 1.1)(rng),
                            std::uniform_real_distribution<double>(-0.1, 1.1)(rng));
    const Eigen::Vector3d p = box.min() + u.cwiseProduct(box.sizes());
    const bool truth = winding_number_exact(mesh, p) > 0.5;
    in += truth;
    ASSERT_EQ(told.inside(p), truth) << i;
    ASSERT_EQ(plain.inside(p), truth) << i;
    ASSERT_EQ(told.signed_distance(p), plain.signed_distance(p)) << i;
  }
  EXPECT_GT(in, 300u);
  EXPECT_LT(in, 2700u);
  EXPECT_FALSE(told.winding_number_built());
  EXPECT_TRUE(plain.winding_number_built());
}

// The solid beside a surface vertex, on either side: everywhere on a closed sphere, nowhere on
// the same sphere facing inward (the winding number -1 within), and on its lower half (open)
// where the exact winding number passes 1/2 a probe's length off it, along its normal or against
// it (near the rim it falls under 1/2 on both sides).
TEST(MeshQuery, SolidBesideOnlyWhereTheWindingNumberPassesAHalf) {
  const TriMesh closed = test::uv_sphere(1.0, 16, 32);
  TriMesh inward = closed;
  for (auto& t : inward.triangles) std::swap(t[1], t[2]);
  TriMesh open = closed;
  open.triangles.clear();
  for (const auto& t : closed.triangles)
    if (closed.vertices[size_t(t[0])].z() < 0.0 && closed.vertices[size_t(t[1])].z() < 0.0 &&
        closed.vertices[size_t(t[2])].z() < 0.0)
      open.triangles.push_back(t);
  auto beside = [](const TriMesh& mesh) {
    const MeshQuery query(mesh);
    const std::vector<Eigen::Vector3d> normals = angle_weighted_normals(mesh, face_normals(mesh));
    std::vector<bool> out(mesh.vertices.size());
    for (size_t v = 0; v < out.size(); ++v) out[v] = query.solid_beside(mesh.vertices[v], normals[v]);
    return out;
  };
  const std::vector<bool> on_closed = beside(closed), on_inward = beside(inward), on_open = beside(open);
  EXPECT_EQ(std::count(on_closed.begin(), on_closed.end(), true), long(closed.vertices.size()));
  EXPECT_EQ(std::count(on_inward.begin(), on_inward.end(), true), 0);
  const std::vector<Eigen::Vector3d> normals = angle_weighted_normals(open, face_normals(open));
  const double step = kWallProbe * open.diagonal();
  size_t used = 0, with = 0;
  std::vector<bool> in_use(open.vertices.size(), false);
  for (const auto& t : open.triangles)
    for (int k = 0; k < 3; ++k) in_use[size_t(t[k])] = true;
  for (size_t v = 0; v < open.vertices.size(); ++v) {
    if (!in_use[v]) continue;
    ++used;
    const Eigen::Vector3d& p = open.vertices[v];
    const bool truth = winding_number_exact(open, p - step * normals[v]) > 0.5 ||
                       winding_number_exact(open, p + step * normals[v]) > 0.5;
    EXPECT_EQ(on_open[v], truth) << v;
    with += truth;
  }
  EXPECT_GT(with, used / 4) << "most of the open sphere still bounds a solid";
  EXPECT_LT(with, used) << "near the hole it does not";
}

TEST(MeshQuery, ClosestPointMatchesBruteForce) {
  const TriMesh mesh = make_barrel().rest;
  const MeshQuery query(mesh);
  using K = CGAL::Simple_cartesian<double>;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-0.5, 0.9);
  for (int i = 0; i < 200; ++i) {
    const Eigen::Vector3d p(u(rng), u(rng), u(rng));
    double best = std::numeric_limits<double>::infinity();
    for (const auto& t : mesh.triangles) {
      const K::Triangle_3 tri({mesh.vertices[t[0]].x(), mesh.vertices[t[0]].y(), mesh.vertices[t[0]].z()},
                             {mesh.vertices[t[1]].x(), mesh.vertices[t[1]].y(), mesh.vertices[t[1]].z()},
                             {mesh.vertices[t[2]].x(), mesh.vertices[t[2]].y(), mesh.vertices[t[2]].z()});
      best = std::min(best, std::sqrt(CGAL::squared_distance(K::Point_3(p.x(), p.y(), p.z()), tri)));
    }
    const ClosestPoint c = query.closest(p);
    EXPECT_NEAR(query.distance(p), best, 1e-12);
    EXPECT_NEAR(c.distance, best, 1e-12);
    // A caller that needs the distance and the point asks once: the same bits as distance().
    EXPECT_EQ(c.tree_distance, query.distance(p));
    const auto& f = mesh.triangles[size_t(c.triangle)];
    const Eigen::Vector3d rebuilt = c.barycentric[0] * mesh.vertices[f[0]] + c.barycentric[1] * mesh.vertices[f[1]] +
                                    c.barycentric[2] * mesh.vertices[f[2]];
    EXPECT_LT((rebuilt - c.point).norm(), 1e-12);
  }
}

// closest_apart (the shrinking ball's search past a point's own faces, a pruned traversal of the
// tree) against a scan of every triangle: the nearest point nearer than the radius on a triangle
// without the corners, or none. Points near the car's vertices, their own faces left out, and
// radii from past the nearest other triangle to well short of it.
TEST(MeshQuery, ClosestApartMatchesAScanOfEveryTriangle) {
  const TriMesh mesh = make_car().rest;
  const MeshQuery query(mesh);
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(-1, 1), share(0.05, 1.5);
  const double diag = mesh.diagonal();
  size_t found = 0, none = 0;
  for (int i = 0; i < 400; ++i) {
    const Eigen::Vector3i& own = mesh.triangles[size_t(i * 7) % mesh.triangles.size()];
    const std::vector<Eigen::Vector3d> corners = {mesh.vertices[size_t(own[0])], mesh.vertices[size_t(own[1])],
                                                  mesh.vertices[size_t(own[2])]};
    const Eigen::Vector3d p = corners[0] + 0.05 * diag * Eigen::Vector3d(u(rng), u(rng), u(rng));
    double nearest = std::numeric_limits<double>::infinity();
    int triangle = -1;
    for (size_t t = 0; t < mesh.triangles.size(); ++t) {
      const Eigen::Vector3i& f = mesh.triangles[t];
      const Eigen::Vector3d &a = mesh.vertices[size_t(f[0])], &b = mesh.vertices[size_t(f[1])], &c = mesh.vertices[size_t(f[2])];
      if (has_corner(corners, a, b, c)) continue;
      const double d = (closest_point_on_triangle(p, a, b, c) - p).norm();
      if (d < nearest) nearest = d, triangle = int(t);
    }
    const double radius = share(rng) * nearest;
    const ClosestPoint c = query.closest_apart(p, radius, corners);
    if (nearest < radius) {
      ++found;
      ASSERT_GE(c.triangle, 0) << "point " << i;
      EXPECT_EQ(c.distance, nearest) << "point " << i;
      EXPECT_NEAR((c.point - p).norm(), nearest, 1e-12 * diag);
      const Eigen::Vector3i& f = mesh.triangles[size_t(c.triangle)];
      EXPECT_FALSE(has_corner(corners, mesh.vertices[size_t(f[0])], mesh.vertices[size_t(f[1])], mesh.vertices[size_t(f[2])]));
      if (c.triangle != triangle)  // equally near (a shared edge or corner)
        EXPECT_EQ((closest_point_on_triangle(p, mesh.vertices[size_t(f[0])], mesh.vertices[size_t(f[1])],
                                             mesh.vertices[size_t(f[2])]) - p).norm(), nearest);
    } else {
      ++none;
      EXPECT_EQ(c.triangle, -1) << "point " << i << ": nothing nearer than " << radius;
      EXPECT_EQ(c.distance, radius);
    }
  }
  EXPECT_GT(found, 100u);
  EXPECT_GT(none, 100u);
}

// MeshQuery's tree skips far leaves by a closed-form closest point before CGAL's projection, and
// a search from a hint starts bounded: both must give what CGAL's own traits give from
// nothing, to the bit, or outputs would change with a speed-up. Points near the surface, deep
// inside and far out, on the barrel and the car (mirror-symmetric: equally near triangles).
TEST(MeshQuery, FilteredAndHintedSearchesGiveCgalsOwnResultToTheBit) {
  using K = CGAL::Simple_cartesian<double>;
  using Triangles = std::vector<K::Triangle_3>;
  using Stock = CGAL::AABB_tree<CGAL::AABB_traits<K, CGAL::AABB_triangle_primitive<K, Triangles::const_iterator>>>;
  for (const TriMesh& mesh : {make_barrel().rest, make_car().rest}) {
    const MeshQuery query(mesh);
    Triangles triangles;
    for (const auto& t : mesh.triangles) {
      auto at = [&](int k) { return K::Point_3(mesh.vertices[t[k]].x(), mesh.vertices[t[k]].y(), mesh.vertices[t[k]].z()); };
      triangles.emplace_back(at(0), at(1), at(2));
    }
    Stock stock(triangles.cbegin(), triangles.cend());
    stock.accelerate_distance_queries();
    Eigen::AlignedBox3d box;
    for (const auto& v : mesh.vertices) box.extend(v);
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(-0.25, 1.25), step(-0.02, 0.02);
    for (int i = 0; i < 2000; ++i) {
      Eigen::Vector3d p;
      for (int a = 0; a < 3; ++a) p[a] = box.min()[a] + u(rng) * box.sizes()[a];
      if (i % 2)  // within 1 % of the diagonal of a vertex
        p = mesh.vertices[size_t(i) % mesh.vertices.size()] + 0.5 * box.sizes().norm() * Eigen::Vector3d(step(rng), step(rng), step(rng));
      const double expected = std::sqrt(stock.squared_distance(K::Point_3(p.x(), p.y(), p.z())));
      const ClosestPoint c = query.closest(p);
      ASSERT_EQ(c.tree_distance, expected) << "point " << i;
      EXPECT_EQ(query.distance(p), expected);
      // Searched from the closest point of a point nearby (as the shrinking ball asks).
      const Eigen::Vector3d near = p + 0.01 * box.sizes().norm() * Eigen::Vector3d(step(rng), step(rng), step(rng));
      const ClosestPoint hinted = query.closest(p, query.closest(near));
      EXPECT_EQ(hinted.tree_distance, expected) << "point " << i;
      EXPECT_EQ(query.distance(p, query.closest(near).point), expected) << "point " << i;
      EXPECT_EQ(hinted.point, c.point);
      // Another triangle only where the point is on both (a shared corner or edge: a tie).
      const auto& f = mesh.triangles[size_t(hinted.triangle)];
      EXPECT_LT((closest_point_on_triangle(c.point, mesh.vertices[f[0]], mesh.vertices[f[1]], mesh.vertices[f[2]]) - c.point).norm(),
                1e-12 * box.sizes().norm());
      // As a growing ball asks (grow_inscribed): from its touching point along its normal, a
      // little past where it fits and well past, hinted with that point, as CGAL's own traits
      // answer with the same hint. Near the planes of the triangles around the touching point:
      // where the leaf test tells triangles apart by their planes.
      if (!query.inside(p) || !(c.distance > 0)) continue;
      for (double past : {1.0, 1.07, 1.3, 2.0}) {
        const Eigen::Vector3d q = c.point + past * (p - c.point);
        const K::Point_3 at(q.x(), q.y(), q.z()), hint(c.point.x(), c.point.y(), c.point.z());
        EXPECT_EQ(query.distance(q, c.point), std::sqrt(stock.squared_distance(at, hint))) << "point " << i << " at " << past;
      }
    }
  }
}

// The solid's boundary against brute force. Two closed boxes pressed into each other (two
// pieces): the smaller's face inside the larger is a wall inside the solid, and the faces that
// pass out of the larger bound only where they are out. Points on every triangle (a grid of
// spacing s), each classified by the exact winding number a hair off both sides, give the
// brute-force distance from a point inside to the boundary. MeshQuery's distance is never more
// (spheres stay inside), and less only by about a piece where a triangle crosses the boundary;
// the distance to every triangle, walls included, is far less at many of the points.
TEST(SolidBoundary, DistancesAreToTheBoundaryAsBruteForceFindsIt) {
  TriMesh mesh = test::box_mesh({0, 0, 0}, {2, 2, 2});
  const TriMesh b = test::box_mesh({1.5, 0.5, 0.5}, {3, 1.5, 1.5});
  for (const auto& t : b.triangles) mesh.triangles.push_back(t + Eigen::Vector3i::Constant(int(mesh.vertices.size())));
  mesh.vertices.insert(mesh.vertices.end(), b.vertices.begin(), b.vertices.end());
  const double s = 0.02, eps = 1e-7;
  std::vector<Eigen::Vector3d> boundary;
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d &p0 = mesh.vertices[size_t(t[0])], &p1 = mesh.vertices[size_t(t[1])],
                          &p2 = mesh.vertices[size_t(t[2])];
    const Eigen::Vector3d n = (p1 - p0).cross(p2 - p0).normalized();
    const int steps = int(std::ceil(std::max((p1 - p0).norm(), (p2 - p0).norm()) / s));
    for (int i = 0; i < steps; ++i)
      for (int j = 0; i + j < steps; ++j) {  // strictly inside the triangle: no edge lies on another's plane
        const Eigen::Vector3d p = p0 + (p1 - p0) * (i + 0.3) / steps + (p2 - p0) * (j + 0.3) / steps;
        if (winding_number_exact(mesh, p + eps * n) <= 0.5 || winding_number_exact(mesh, p - eps * n) <= 0.5)
          boundary.push_back(p);
      }
  }
  const MeshQuery query(mesh);
  EXPECT_EQ(query.internal_walls(), 2u);  // the small box's face at x = 1.5
  EXPECT_GT(query.split_triangles(), 0u);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> x(0, 3), yz(0, 2);
  size_t tried = 0, walls_would_bound = 0;
  while (tried < 300) {
    const Eigen::Vector3d c(x(rng), yz(rng), yz(rng));
    if (!query.inside(c)) continue;
    ++tried;
    double brute = std::numeric_limits<double>::infinity(), any = std::numeric_limits<double>::infinity();
    for (const auto& p : boundary) brute = std::min(brute, (p - c).norm());
    for (const auto& t : mesh.triangles)
      any = std::min(any, (closest_point_on_triangle(c, mesh.vertices[size_t(t[0])], mesh.vertices[size_t(t[1])],
                                                     mesh.vertices[size_t(t[2])]) - c).norm());
    const double d = query.distance(c);
    EXPECT_LE(d, brute + 1e-12) << c.transpose();
    EXPECT_GE(d, brute - s - 2.0 / (1 << kWallSplitDepth)) << c.transpose();
    EXPECT_NEAR(query.closest(c).distance, d, 1e-12);
    walls_would_bound += any < brute - 0.3;
  }
  EXPECT_GT(walls_would_bound, 10u);
  // A single closed surface is its own boundary.
  const MeshQuery barrel(make_barrel().rest);
  EXPECT_EQ(barrel.internal_walls() + barrel.split_triangles(), 0u);
}

// Inscribed spheres at random interior points of the barrel, grown: each grown sphere contains
// the first, lies inside (its radius is the brute-force distance from its center), offsets
// by at most the growth asked, keeps the cap, and lies in grown_extent's ball, which is no
// larger than the growth allows; and many do grow. A hinted distance query gives the plain one.
TEST(Inscribed, GrownSpheresContainTheFirstAndStayInside) {
  const TriMesh mesh = make_barrel().rest;
  const MeshQuery query(mesh);
  auto brute_distance = [&](const Eigen::Vector3d& p) {
    double best = std::numeric_limits<double>::infinity();
    for (const auto& t : mesh.triangles)
      best = std::min(best, (closest_point_on_triangle(p, mesh.vertices[size_t(t[0])], mesh.vertices[size_t(t[1])],
                                                       mesh.vertices[size_t(t[2])]) -
                             p)
                                .norm());
    return best;
  };
  Eigen::AlignedBox3d box;
  for (const auto& v : mesh.vertices) box.extend(v);
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(0, 1);
  size_t grown = 0, tried = 0;
  for (int i = 0; tried < 300 && i < 5000; ++i) {
    const Eigen::Vector3d c = box.min() + box.sizes().cwiseProduct(Eigen::Vector3d(u(rng), u(rng), u(rng)));
    if (!query.inside(c)) continue;
    ++tried;
    const double r = query.distance(c);
    EXPECT_NEAR(query.distance(c, mesh.vertices[0]), r, 1e-12);
    for (double cap : {1e300, 0.8 * r + 0.5 * r * u(rng)}) {
      const Sphere first{c, std::min(r, cap)};
      const Sphere g = grow_inscribed(query, first, cap, 1.0);
      const Sphere extent = grown_extent(first, query.closest(c), cap, 1.0);
      EXPECT_LE((g.center - extent.center).norm() + g.radius, extent.radius) << "outside its extent";
      EXPECT_LE(extent.radius, 2 * first.radius * (1 + 1e-5));
      EXPECT_GE(g.radius, first.radius);
      EXPECT_LE((g.center - c).norm() + first.radius, g.radius * (1 + 1e-6)) << "does not contain the first";
      EXPECT_TRUE(query.inside(g.center));
      EXPECT_NEAR(g.radius, std::min(cap, brute_distance(g.center)), 1e-9 * g.radius) << "not inscribed";
      EXPECT_LE(g.radius, cap);
      EXPECT_LE((g.center - c).norm(), first.radius * (1 + 1e-9)) << "moved more than the growth asked";
      if (cap > 1e299) grown += g.radius > first.radius * 1.05;
      if (cap < r) EXPECT_EQ(g.center, c) << "a capped sphere does not touch the surface: it stays";
    }
  }
  EXPECT_EQ(tried, 300u);
  EXPECT_GT(grown, 150u);
}

TEST(Samples, AreClosedOutwardAndSized) {
  const SampleAsset car = make_car(), barrel = make_barrel();
  const MeshDefects dc = find_defects(car.rest), db = find_defects(barrel.rest);
  EXPECT_TRUE(dc.watertight());
  EXPECT_TRUE(db.watertight());
  EXPECT_GT(dc.signed_volume, 0);
  EXPECT_GT(db.signed_volume, 0);
  EXPECT_NEAR(car.rest.bounds().sizes().x(), 5.25, 1e-9);
  EXPECT_NEAR(barrel.rest.bounds().sizes().z(), 0.72, 1e-9);
  EXPECT_GE(car.rest.triangles.size(), 1400u);
  EXPECT_LE(car.rest.triangles.size(), 1600u);
  EXPECT_GE(car.pose_names.size(), 4u);
  // Every pose is a valid embedding: still closed with positive volume, no degenerate faces.
  for (const SampleAsset* a : {&car, &barrel})
    for (size_t i = 0; i < a->pose_names.size(); ++i) {
      const MeshDefects d = find_defects(a->pose(i));
      EXPECT_GT(d.signed_volume, 0) << a->name << " " << a->pose_names[i];
      EXPECT_EQ(d.degenerate_triangles, 0u);
    }
}

// NearBoundaryQuery decides the boundary only near its queries: its distance must be MeshQuery's
// to the bit wherever that is below the reach asked, and nothing (infinity) where it is not. On
// two boxes pressed into each other (a wall inside the solid, faces kept in pieces) and on the
// robot sample's 13 open parts, at random points, near vertices and a hair off the triangles.
TEST(NearBoundaryQuery, GivesMeshQuerysDistanceToTheBitBelowTheReach) {
  TriMesh boxes = test::box_mesh({0, 0, 0}, {2, 2, 2});
  const TriMesh b = test::box_mesh({1.5, 0.5, 0.5}, {3, 1.5, 1.5});
  for (const auto& t : b.triangles) boxes.triangles.push_back(t + Eigen::Vector3i::Constant(int(boxes.vertices.size())));
  boxes.vertices.insert(boxes.vertices.end(), b.vertices.begin(), b.vertices.end());
  const std::string dir = test::temp_dir("near-boundary");
  const TriMesh robot = test::rest_of(*test::robot_asset(dir));
  size_t below = 0, walls = 0;
  for (const TriMesh* mesh : std::vector<const TriMesh*>{&boxes, &robot}) {
    const MeshQuery query(*mesh);
    ASSERT_GT(query.internal_walls() + query.split_triangles(), 0u);
    const DeformingQuery hierarchy(*mesh);
    const NearBoundaryQuery near(hierarchy, *mesh);
    const double diagonal = mesh->diagonal();
    Eigen::AlignedBox3d box;
    for (const auto& v : mesh->vertices) box.extend(v);
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(0, 1), step(-0.02, 0.02);
    for (int i = 0; i < 4000; ++i) {
      Eigen::Vector3d p;
      const auto& f = mesh->triangles[size_t(i * 7919) % mesh->triangles.size()];
      const Eigen::Vector3d &a = mesh->vertices[size_t(f[0])], &c1 = mesh->vertices[size_t(f[1])],
                            &c2 = mesh->vertices[size_t(f[2])];
      if (i % 3 == 0)
        for (int k = 0; k < 3; ++k) p[k] = box.min()[k] + u(rng) * box.sizes()[k];
      else if (i % 3 == 1)  // near a vertex
        p = a + diagonal * Eigen::Vector3d(step(rng), step(rng), step(rng));
      else  // a hair off a triangle, either side
        p = (a + c1 + c2) / 3 + (u(rng) - 0.5) * 1e-4 * diagonal * (c1 - a).cross(c2 - a).normalized();
      const double reach = diagonal * std::pow(10.0, -4 * u(rng));
      const double expected = query.distance(p), got = near.distance_below(p, reach);
      EXPECT_EQ(near.inside(p), query.inside(p)) << "point " << i;
      if (expected < reach) {
        ++below;
        ASSERT_EQ(got, expected) << "point " << i << " reach " << reach;
        // Where a wall (or a piece left out) is nearer than the boundary: brute force over every triangle.
        double raw = std::numeric_limits<double>::infinity();
        for (const auto& t : mesh->triangles)
          raw = std::min(raw, (closest_point_on_triangle(p, mesh->vertices[size_t(t[0])], mesh->vertices[size_t(t[1])],
                                                         mesh->vertices[size_t(t[2])]) - p).norm());
        walls += raw < 0.5 * expected;
      } else {
        ASSERT_EQ(got, std::numeric_limits<double>::infinity()) << "point " << i << ": " << expected << " past " << reach;
      }
    }
  }
  EXPECT_GT(below, 2000u);
  EXPECT_GT(walls, 0u);
}

// Split at the midpoints: the same surface (area and enclosed volume to rounding), four times the
// triangles per split, each edge's midpoint shared by its two triangles (the box stays closed and
// of genus 0: V - E + F = 2), every old vertex kept in place.
TEST(MeshSplit, SplitAtMidpointsKeepsTheSurfaceAndItsClosure) {
  const TriMesh box = test::box_mesh({0, 0, 0}, {1, 2, 3});
  const auto area_and_volume = [](const TriMesh& m) {
    double area = 0, volume = 0;
    for (const Eigen::Vector3i& t : m.triangles) {
      const Eigen::Vector3d &a = m.vertices[size_t(t[0])], &b = m.vertices[size_t(t[1])], &c = m.vertices[size_t(t[2])];
      area += 0.5 * (b - a).cross(c - a).norm();
      volume += a.dot(b.cross(c)) / 6;
    }
    return std::make_pair(area, volume);
  };
  for (int times : {1, 2, 3}) {
    const TriMesh split = split_at_midpoints(box, times);
    ASSERT_EQ(split.triangles.size(), box.triangles.size() << (2 * times));
    std::map<std::pair<int, int>, int> edges;
    for (const Eigen::Vector3i& t : split.triangles)
      for (int k = 0; k < 3; ++k) ++edges[std::minmax(t[k], t[(k + 1) % 3])];
    for (const auto& [edge, count] : edges) ASSERT_EQ(count, 2) << "edge " << edge.first << "-" << edge.second;
    EXPECT_EQ(long(split.vertices.size()) - long(edges.size()) + long(split.triangles.size()), 2);
    const auto [area, volume] = area_and_volume(split);
    EXPECT_NEAR(area, area_and_volume(box).first, 1e-12);
    EXPECT_NEAR(volume, area_and_volume(box).second, 1e-12);
    for (size_t v = 0; v < box.vertices.size(); ++v) EXPECT_EQ(split.vertices[v], box.vertices[v]);
    std::vector<std::pair<int, int>> ends;
    ASSERT_EQ(split_at_midpoints(box, times, &ends).vertices, split.vertices);
    ASSERT_EQ(ends.size(), split.vertices.size() - box.vertices.size());
    for (size_t k = 0; k < ends.size(); ++k) {
      const auto [a, b] = ends[k];
      ASSERT_LT(size_t(std::max(a, b)), box.vertices.size() + k) << "an end added after its midpoint";
      EXPECT_EQ(split.vertices[box.vertices.size() + k], 0.5 * (split.vertices[size_t(a)] + split.vertices[size_t(b)]));
    }
  }
}

}  // namespace
}  // namespace spx
