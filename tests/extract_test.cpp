// pose-extract: poses out of rigged and morph-target assets, and the chain run on them.
#include <assimp/Exporter.hpp>
#include <assimp/Importer.hpp>
#include <assimp/scene.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <functional>
#include <map>
#include <random>
#include <sstream>
#include <tuple>

#include "core/atomic_file.hpp"
#include "core/error.hpp"
#include "core/gltf_file.hpp"
#include "export/proxy_export_tool.hpp"
#include "extract/asset.hpp"
#include "extract/pose_extract_tool.hpp"
#include "io/pose_manifest.hpp"
#include "io/scene.hpp"
#include "io/skin_file.hpp"
#include "io/proxy_file.hpp"
#include "mesh/defects.hpp"
#include "mesh/gltf_accessors.hpp"
#include "mesh/gltf_input.hpp"
#include "mesh/mesh_query.hpp"
#include "pack/sphere_pack_tool.hpp"
#include "posemap/pose_map_tool.hpp"
#include "sdf/sdf_build_tool.hpp"
#include "spx_runtime.h"
#include "synthetic/sample_gen_tool.hpp"
#include "synthetic/synthetic.hpp"
#include "test_util.hpp"

namespace spx {
namespace {

double max_vertex_distance(const TriMesh& a, const TriMesh& b) {
  double d = 0;
  for (size_t v = 0; v < a.vertices.size(); ++v) d = std::max(d, (a.vertices[v] - b.vertices[v]).norm());
  return d;
}

// The four tools on a rest mesh and its poses, in memory of files: returns the .spx path.
std::string run_chain(const std::string& rest, const std::vector<std::string>& poses, const std::string& dir) {
  json report;
  SdfOptions sdf;
  sdf.resolution = 64;
  sdf_build_files(rest, dir + "/rest.vdb", sdf, Log::silent(), report);
  sphere_pack_files(dir + "/rest.vdb", rest, dir + "/rest.spheres.json", SpherePackOptions{}, Tolerance{},
                    Log::silent(), report);
  pose_map_files(rest, poses, dir + "/rest.spheres.json", dir + "/proxy.json", PoseMapOptions{}, PoseMapTolerances{},
                 Log::silent(), report);
  proxy_export_files(dir + "/proxy.json", dir + "/proxy.spx", ExportOptions{}, Log::silent(), report);
  return dir + "/proxy.spx";
}

// Every sphere of every pose of `proxy` lies inside that pose's mesh.
void expect_spheres_inside(const std::string& proxy_path, const std::vector<TriMesh>& meshes, const std::string& what) {
  const ProxyModel proxy = read_proxy_file(proxy_path);
  ASSERT_EQ(proxy.poses.size(), meshes.size()) << what;
  for (size_t i = 0; i < meshes.size(); ++i) {
    const MeshQuery q(meshes[i]);
    size_t outside = 0;
    for (const Sphere& s : proxy.poses[i].spheres)
      if (s.radius > 0 && (!q.inside(s.center) || s.radius > q.distance(s.center) + 1e-9 * meshes[i].diagonal())) ++outside;
    EXPECT_EQ(outside, 0u) << what << " pose " << i << " of " << proxy.sphere_count() << " spheres";
  }
}

// The acceptance test: the glTF skin evaluated as the spec says (joint matrix = the joint's global
// transform x its inverse bind matrix; the mesh node's own transform ignored) at
// t_k = 0.999 T k / 3 gives back the reference poses, every vertex within 1e-5 of the diagonal.
TEST(PoseExtract, RiggedSimpleClipGivesTheReferencePoses) {
  SPX_REQUIRE_SHARED_DATA();
  const std::string data = test::shared_data() + "/rigged-simple/";
  const Asset asset(data + "RiggedSimple.glb", "");
  ASSERT_EQ(asset.clips().size(), 1u);
  const double end = asset.clips()[0].end;
  EXPECT_NEAR(end, 2.083333, 1e-5);
  PoseExtractOptions opt;
  opt.animation = "0";
  for (int k = 0; k < 4; ++k) opt.times.push_back(0.999 * end * k / 3);
  const std::string dir = test::temp_dir("rigged");
  json report;
  pose_extract_files(data + "RiggedSimple.glb", dir, opt, Log::silent(), report);

  const PoseManifest manifest = read_pose_manifest(dir + "/poses.json");
  ASSERT_EQ(manifest.poses.size(), 4u);
  const LoadedMesh rest = load_mesh(dir + "/" + manifest.rest);
  const double tol = 1e-5 * rest.mesh.diagonal();
  EXPECT_LE(max_vertex_distance(rest.mesh, load_pose(data + "rest.obj", rest)), tol) << "bind pose";
  for (int k = 0; k < 4; ++k) {
    char ref[32];
    std::snprintf(ref, sizeof ref, "pose-%02d.obj", k);
    const TriMesh mine = load_pose(dir + "/" + manifest.poses[size_t(k)].file, rest);
    const TriMesh theirs = load_pose(data + ref, rest);
    EXPECT_LE(max_vertex_distance(mine, theirs), tol) << ref;
    EXPECT_EQ(manifest.poses[size_t(k)].source["time"].get<double>(), opt.times[size_t(k)]);
  }
  // The poses really move (the test would pass on the bind pose alone otherwise).
  EXPECT_GT(max_vertex_distance(rest.mesh, load_pose(data + "pose-02.obj", rest)), 0.01 * rest.mesh.diagonal());
  EXPECT_EQ(report["asset"]["skins"].get<int>(), 1);
  EXPECT_EQ(report["asset"]["meshes"][0]["joints"].get<int>(), 2);
}

// The skin written beside a clip's poses gives them back: every welded rest vertex taken to the
// asset's own space by the rest's joint matrices and skinned with a pose's gives that pose's
// vertex. On the rigged elephant (24 joints, 4 weights a vertex) and on the robot, whose rigid
// parts are joints of weight 1.
TEST(PoseExtract, SkinFileGivesBackEveryPoseFromTheRest) {
  SPX_REQUIRE_SHARED_DATA();
  const std::string dir = test::temp_dir("skin");
  json report;
  sample_gen_files("robot", dir + "/robot", Log::silent(), report);
  const std::pair<std::string, int> assets[] = {{test::shared_data() + "/elephant/elephant-rigged.glb", 24},
                                                {dir + "/robot/robot.glb", 13}};
  for (const auto& [asset, joints] : assets) {
    PoseExtractOptions opt;
    opt.animation = "0";
    opt.every = 7;
    const std::string out = dir + "/" + std::to_string(joints);
    pose_extract_files(asset, out, opt, Log::silent(), report);
    const PoseManifest manifest = read_pose_manifest(out + "/poses.json");
    ASSERT_EQ(manifest.skin, "skin.json") << asset;
    const SkinFile skin = read_skin_file(out + "/skin.json");
    EXPECT_EQ(skin.joints.size(), size_t(joints)) << asset;
    // The clip the radius rule holds over has every key and every half-way time (where hosts
    // and proxy-eval look between keys), within float rounding.
    const Asset rig(asset, "");
    const std::vector<double>& keys = rig.clips()[0].frames;
    for (size_t f = 0; f + 1 < keys.size(); ++f)
      for (double t : {keys[f], 0.5 * (keys[f] + keys[f + 1])}) {
        const auto near = std::lower_bound(skin.clip.times.begin(), skin.clip.times.end(), t - 1e-9);
        ASSERT_TRUE(near != skin.clip.times.end() && *near <= t + 1e-9) << asset << ": the clip misses " << t << " s";
      }
    ASSERT_EQ(skin.poses.size(), manifest.poses.size()) << asset;
    const LoadedMesh rest = load_mesh(out + "/" + manifest.rest);
    const std::vector<JointWeights> weights =
        weights_for_vertices(skin, rest.mesh.vertices, 1e-6 * rest.mesh.diagonal(), out + "/skin.json");
    auto blend = [&](const JointWeights& w, const JointMatrices& m) {
      Eigen::Matrix4d sum = Eigen::Matrix4d::Zero();
      for (const auto& [j, weight] : w) sum += weight * m[size_t(j)];
      return sum;
    };
    double worst = 0, moved = 0;
    for (size_t k = 0; k < manifest.poses.size(); ++k) {
      EXPECT_EQ(skin.poses[k].name, manifest.poses[k].name);
      const TriMesh pose = load_pose(out + "/" + manifest.poses[k].file, rest);
      for (size_t v = 0; v < pose.vertices.size(); ++v) {
        const JointWeights& w = weights[v];
        ASSERT_FALSE(w.empty()) << asset << " vertex " << v;
        const Eigen::Vector4d stored = blend(w, skin.rest).inverse() * rest.mesh.vertices[v].homogeneous();
        const Eigen::Vector3d skinned = (blend(w, skin.poses[k].matrices) * stored).head<3>();
        worst = std::max(worst, (skinned - pose.vertices[v]).norm());
        moved = std::max(moved, (pose.vertices[v] - rest.mesh.vertices[v]).norm());
      }
    }
    EXPECT_LE(worst, 1e-6 * rest.mesh.diagonal()) << asset;
    EXPECT_GT(moved, 0.05 * rest.mesh.diagonal()) << asset << ": the clip should move the body";
  }
}

// A clip's poses with their skin through the chain: the .spx skinned with each pose's joint
// matrices gives back the sphere centers pose-map wrote for that pose (float rounding apart) and
// its one radius, and every sphere is inside every pose.
TEST(PoseExtract, SkinnedProxyFollowsTheClipAsTheToolsMappedIt) {
  SPX_REQUIRE_SHARED_DATA();
  const std::string dir = test::temp_dir("skinned-chain");
  PoseExtractOptions opt;
  opt.animation = "0";
  json report;
  pose_extract_files(test::shared_data() + "/rigged-simple/RiggedSimple.glb", dir + "/poses", opt, Log::silent(), report);
  const PoseManifest manifest = read_pose_manifest(dir + "/poses/poses.json");
  std::vector<std::string> poses;
  for (const auto& p : manifest.poses) poses.push_back(dir + "/poses/" + p.file);
  const std::string rest = dir + "/poses/rest.obj";
  SdfOptions sdf;
  sdf.resolution = 64;
  sdf_build_files(rest, dir + "/rest.vdb", sdf, Log::silent(), report);
  sphere_pack_files(dir + "/rest.vdb", rest, dir + "/rest.spheres.json", SpherePackOptions{}, Tolerance{},
                    Log::silent(), report);
  json map_report;
  pose_map_files(rest, poses, dir + "/rest.spheres.json", dir + "/proxy.json", PoseMapOptions{}, PoseMapTolerances{},
                 Log::silent(), map_report, dir + "/poses/skin.json");
  proxy_export_files(dir + "/proxy.json", dir + "/proxy.spx", ExportOptions{}, Log::silent(), report);

  const ProxyModel model = read_proxy_file(dir + "/proxy.json");
  const SkinFile skin = read_skin_file(dir + "/poses/skin.json");
  Proxy proxy;
  ASSERT_EQ(load_file((dir + "/proxy.spx").c_str(), &proxy), SPX_OK);
  ASSERT_TRUE(proxy.has_skin());
  ASSERT_EQ(proxy.joint_count(), skin.joints.size());
  const LoadedMesh rest_mesh = load_mesh(rest);
  const double tol = 1e-5 * rest_mesh.mesh.diagonal();
  std::vector<TriMesh> meshes = {rest_mesh.mesh};
  for (size_t k = 0; k <= skin.poses.size(); ++k) {
    const JointMatrices& m = k == 0 ? skin.rest : skin.poses[k - 1].matrices;
    std::vector<float> matrices;
    for (const auto& mj : m)
      for (int e = 0; e < 16; ++e) matrices.push_back(float(mj(e % 4, e / 4)));
    std::vector<float> xyzr(size_t(proxy.sphere_count()) * 4);
    ASSERT_EQ(spx::skin(proxy, matrices.data(), int(proxy.joint_count()), xyzr.data()), SPX_OK);
    double worst = 0;
    for (size_t s = 0; s < model.sphere_count(); ++s) {
      const Sphere& want = model.poses[k].spheres[s];
      worst = std::max(worst, (Eigen::Vector3d(xyzr[4 * s], xyzr[4 * s + 1], xyzr[4 * s + 2]) - want.center).norm());
      EXPECT_EQ(xyzr[4 * s + 3], float(want.radius)) << "pose " << k << " sphere " << s;
    }
    EXPECT_LE(worst, tol) << "pose " << k;
    if (k > 0) meshes.push_back(load_pose(poses[k - 1], rest_mesh));
  }
  expect_spheres_inside(dir + "/proxy.json", meshes, "skinned RiggedSimple");
  // The clip bends the body: the skinned centers really move.
  double moved = 0;
  for (const ProxyPose& pose : model.poses)
    for (size_t s = 0; s < model.sphere_count(); ++s)
      moved = std::max(moved, (pose.spheres[s].center - model.poses[0].spheres[s].center).norm());
  EXPECT_GT(moved, 0.05 * rest_mesh.mesh.diagonal());
  // Every frame the tools saw within 1.25x the tolerance (the motion's acceptance).
  const double target = map_report["selection"]["target"].get<double>();
  for (const auto& pose : map_report["poses"]) EXPECT_LE(pose["error"]["max"].get<double>(), 1.25 * target) << pose["name"];
}

// The car's crumples as glTF morph targets: extracted, chained, and blended with the runtime at
// the morph weights, they give the very spheres the OBJ poses give.
TEST(PoseExtract, MorphTargetRoundTripBlendsAsTheObjPoses) {
  const std::string dir = test::temp_dir("morph");
  json report;
  sample_gen_files("car", dir + "/in", Log::silent(), report);
  PoseExtractOptions opt;
  opt.morph_targets = true;
  pose_extract_files(dir + "/in/car-morph.glb", dir + "/ex", opt, Log::silent(), report);

  const PoseManifest manifest = read_pose_manifest(dir + "/ex/poses.json");
  const std::vector<std::string> names = {"front", "rear", "side", "roof"};
  ASSERT_EQ(manifest.poses.size(), names.size());
  const LoadedMesh obj_rest = load_mesh(dir + "/in/rest.obj");
  const LoadedMesh ex_rest = load_mesh(dir + "/ex/rest.obj");
  const double tol = 1e-5 * obj_rest.mesh.diagonal();
  EXPECT_LE(max_vertex_distance(obj_rest.mesh, load_pose(dir + "/ex/rest.obj", obj_rest)), tol);
  std::vector<std::string> obj_poses, ex_poses;
  for (size_t i = 0; i < names.size(); ++i) {
    EXPECT_EQ(manifest.poses[i].name, names[i]);
    obj_poses.push_back(dir + "/in/" + names[i] + ".obj");
    ex_poses.push_back(manifest_file_path(dir + "/ex/poses.json", manifest.poses[i].file));
    EXPECT_LE(max_vertex_distance(load_pose(obj_poses[i], obj_rest), load_pose(ex_poses[i], obj_rest)), tol) << names[i];
  }

  std::filesystem::create_directories(dir + "/chain-obj");
  std::filesystem::create_directories(dir + "/chain-ex");
  const std::string a = run_chain(dir + "/in/rest.obj", obj_poses, dir + "/chain-obj");
  const std::string b = run_chain(dir + "/ex/rest.obj", ex_poses, dir + "/chain-ex");
  Proxy pa, pb;
  ASSERT_EQ(load_file(a.c_str(), &pa), SPX_OK);
  ASSERT_EQ(load_file(b.c_str(), &pb), SPX_OK);
  ASSERT_EQ(pa.sphere_count(), pb.sphere_count());
  ASSERT_EQ(pb.pose_count(), 5u);
  for (uint32_t i = 1; i < 5; ++i) EXPECT_STREQ(pb.pose_name(i), names[i - 1].c_str());
  // The runtime's global blend at morph weights: the rest weight is what the targets leave.
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0, 1);
  const size_t n = pa.sphere_count();
  for (int trial = 0; trial < 8; ++trial) {
    std::vector<float> morph(4, 0.0f);
    for (int k = 0; k < 4; ++k) morph[size_t(k)] = trial < 4 ? float(k == trial) : 0.5f * u(rng);
    float sum = 0;
    for (float w : morph) sum += w;
    std::vector<float> weights = {std::max(0.0f, 1 - sum)};
    weights.insert(weights.end(), morph.begin(), morph.end());
    std::vector<float> ca(3 * n), ra(n), cb(3 * n), rb(n);
    ASSERT_EQ(blend_global(pa, weights.data(), 5, ca.data(), ra.data()), SPX_OK);
    ASSERT_EQ(blend_global(pb, weights.data(), 5, cb.data(), rb.data()), SPX_OK);
    EXPECT_EQ(std::memcmp(ca.data(), cb.data(), ca.size() * sizeof(float)), 0) << "trial " << trial;
    EXPECT_EQ(std::memcmp(ra.data(), rb.data(), ra.size() * sizeof(float)), 0) << "trial " << trial;
  }
  std::vector<TriMesh> meshes = {ex_rest.mesh};
  for (const auto& p : ex_poses) meshes.push_back(load_pose(p, ex_rest));
  expect_spheres_inside(dir + "/chain-ex/proxy.json", meshes, "car morph targets");
}

// The sample's clip drives the morph weights: weight 1 on target k alone at t = k + 1 s, halfway
// between two targets at t = k + 1.5 s, every target at 1 a second after the last. The weights
// the clip gives (Asset::morph_weights) make the same mesh through Asset::morphed, to the bit.
TEST(PoseExtract, ClipDrivenMorphWeightsAreApplied) {
  const std::string dir = test::temp_dir("morph-clip");
  json report;
  sample_gen_files("barrel", dir, Log::silent(), report);
  const Asset asset(dir + "/barrel-morph.glb", "");
  ASSERT_EQ(asset.clips().size(), 1u);
  EXPECT_EQ(asset.clips()[0].morph_channels, 1u);
  const size_t targets = asset.morph_targets().size();
  EXPECT_EQ(asset.clips()[0].frames.size(), targets + 2);
  const auto rest = asset.rest();
  for (size_t k = 0; k < asset.morph_targets().size(); ++k)
    EXPECT_EQ(asset.at_time(0, double(k + 1)), asset.morph_target(k)) << k;
  EXPECT_EQ(asset.at_time(0, 0.0), rest);
  const auto half = asset.at_time(0, 1.5), t0 = asset.morph_target(0), t1 = asset.morph_target(1);
  double worst = 0, moved = 0;
  for (size_t v = 0; v < rest.size(); ++v) {
    worst = std::max(worst, (half[v] - (rest[v] + 0.5 * (t0[v] - rest[v]) + 0.5 * (t1[v] - rest[v]))).norm());
    moved = std::max(moved, (half[v] - rest[v]).norm());
  }
  EXPECT_LT(worst, 1e-6);
  EXPECT_GT(moved, 0.01);
  const auto all = asset.at_time(0, double(targets + 1));
  worst = 0;
  for (size_t v = 0; v < rest.size(); ++v) {
    Eigen::Vector3d sum = rest[v];
    for (size_t k = 0; k < targets; ++k) sum += asset.morph_target(k)[v] - rest[v];
    worst = std::max(worst, (all[v] - sum).norm());
  }
  EXPECT_LT(worst, 1e-6) << "every target at 1: the sum of their moves";
  EXPECT_EQ(asset.morph_weights(0, double(targets + 1)), std::vector<double>(targets, 1.0));
  EXPECT_EQ(asset.morph_weights(0, 1.5), (std::vector<double>{0.5, 0.5, 0.0}));
  for (double t : {0.0, 0.75, 1.5, 2.0, 3.25, 4.0})
    EXPECT_EQ(asset.morphed(asset.morph_weights(0, t)), asset.at_time(0, t)) << t << " s";
}

// Morph targets of one name in one mesh (an exporter's "target" for each): each is its own pose,
// as with their own names. All were read as one target, every one of them at weight 1, and
// pose-extract wrote 1 pose for the barrel's 3.
TEST(PoseExtract, MorphTargetsOfOneNameAreEachTheirOwn) {
  const std::string dir = test::temp_dir("morph-same-name");
  json report;
  sample_gen_files("barrel", dir, Log::silent(), report);
  GltfFile file = read_gltf_file(dir + "/barrel-morph.glb");
  const size_t targets = file.doc["meshes"][0]["extras"]["targetNames"].size();
  ASSERT_EQ(targets, 3u);
  file.doc["meshes"][0]["extras"]["targetNames"] = std::vector<std::string>(targets, "target");
  write_file_atomic(dir + "/same.glb", encode_glb(file));
  const Asset given(dir + "/barrel-morph.glb", ""), same(dir + "/same.glb", "");
  ASSERT_EQ(same.morph_targets(), std::vector<std::string>(targets, "target"));
  for (size_t k = 0; k < targets; ++k) EXPECT_EQ(same.morph_target(k), given.morph_target(k)) << k;
  for (size_t k = 0; k < targets; ++k) EXPECT_EQ(same.at_time(0, double(k + 1)), given.at_time(0, double(k + 1))) << k;
  PoseExtractOptions opt;
  opt.morph_targets = true;
  json out;
  pose_extract_files(dir + "/same.glb", dir + "/ex", opt, Log::silent(), out);
  const PoseManifest manifest = read_pose_manifest(dir + "/ex/poses.json");
  ASSERT_EQ(manifest.poses.size(), targets);
  EXPECT_EQ(manifest.poses[1].file, "target-2.obj");
  EXPECT_EQ(manifest.poses[2].file, "target-3.obj");
}

// A morph target of normals alone (a glTF target with no POSITION, which assimp gives no
// positions) moves no vertex: pose-extract read through a null pointer there and crashed. The
// barrel's last target made one: its pose is the rest, the clip's time at it is the rest and
// half-way to it is half the target before, the other targets are as they were, and pose-extract
// says so.
TEST(PoseExtract, MorphTargetOfNormalsAloneMovesNoVertex) {
  const std::string dir = test::temp_dir("morph-normals");
  json report;
  sample_gen_files("barrel", dir, Log::silent(), report);
  GltfFile file = read_gltf_file(dir + "/barrel-morph.glb");
  for (json& mesh : file.doc["meshes"])
    for (json& primitive : mesh["primitives"]) {
      const size_t count = file.doc["accessors"][primitive["attributes"]["POSITION"].get<size_t>()]["count"];
      primitive["targets"].back() = json{{"NORMAL", detail::add_float_accessor(file, std::vector<double>(3 * count, 0.0), "VEC3")}};
    }
  const std::string path = dir + "/normals.glb";
  write_file_atomic(path, encode_glb(file));
  const Asset given(dir + "/barrel-morph.glb", ""), normals(path, "");
  const size_t last = normals.morph_targets().size() - 1;
  ASSERT_GE(last, 1u);
  const std::vector<Eigen::Vector3d> rest = normals.rest(), before = normals.morph_target(last - 1);
  EXPECT_EQ(normals.morph_target(last), rest);
  for (size_t k = 0; k < last; ++k) EXPECT_EQ(normals.morph_target(k), given.morph_target(k)) << k;
  EXPECT_EQ(normals.at_time(0, double(last + 1)), rest);
  const std::vector<Eigen::Vector3d> half = normals.at_time(0, double(last) + 0.5);
  double worst = 0;
  for (size_t v = 0; v < rest.size(); ++v) worst = std::max(worst, (half[v] - (rest[v] + 0.5 * (before[v] - rest[v]))).norm());
  EXPECT_LT(worst, 1e-6);
  PoseExtractOptions opt;
  opt.morph_targets = true;
  json out;
  Log log("pose-extract", -1);  // quiet: the warnings kept, not shown
  pose_extract_files(path, dir + "/ex", opt, log, out);
  ASSERT_EQ(log.warnings().size(), 1u);
  EXPECT_NE(log.warnings()[0].find("morph target '" + normals.morph_targets()[last] + "' moves no vertex"), std::string::npos)
      << log.warnings()[0];
}

// glTF draws a mesh at its default morph weights (the mesh's `weights`, or its node's) where a
// clip drives none. RiggedSimple given a target that moves every vertex by d, weighted 1 by
// default, plays its clip as RiggedSimple with d in its stored positions, and that is the clip's
// rest (pose-extract's rest.obj); at weights zero (what morph targets are blended from) it is as
// stored. Its node's weights [0] over the mesh's [1] play it as the original. The frames were the
// original's: the default weights were read as zero, and a node's were not read at all.
TEST(PoseExtract, DefaultMorphWeightsShapeTheClip) {
  SPX_REQUIRE_SHARED_DATA();
  const std::string original = test::shared_data() + "/rigged-simple/RiggedSimple.glb";
  const std::string dir = test::temp_dir("default-weights");
  const Eigen::Vector3d d(0.1, 0.05, 0.02);
  GltfFile weighted = read_gltf_file(original), shifted = weighted;
  const size_t given = weighted.doc["meshes"][0]["primitives"][0]["attributes"]["POSITION"];
  ASSERT_EQ(weighted.doc["meshes"][0]["primitives"].size(), 1u);
  const std::vector<double> stored = detail::accessor_values(weighted, weighted.doc["accessors"][given], original);
  std::vector<double> deltas(stored.size()), moved(stored);
  for (size_t i = 0; i < stored.size(); ++i) {
    deltas[i] = d[int(i % 3)];
    moved[i] += d[int(i % 3)];
  }
  auto with_bounds = [](GltfFile& file, size_t accessor, const std::vector<double>& v) {
    json lo = json::array(), hi = json::array();
    for (size_t c = 0; c < 3; ++c) {
      double a = INFINITY, b = -INFINITY;
      for (size_t i = c; i < v.size(); i += 3) a = std::min(a, v[i]), b = std::max(b, v[i]);
      lo.push_back(a);
      hi.push_back(b);
    }
    file.doc["accessors"][accessor]["min"] = lo;
    file.doc["accessors"][accessor]["max"] = hi;
    return accessor;
  };
  const size_t target = with_bounds(weighted, detail::add_float_accessor(weighted, deltas, "VEC3"), deltas);
  weighted.doc["meshes"][0]["primitives"][0]["targets"] = json::array({{{"POSITION", target}}});
  weighted.doc["meshes"][0]["weights"] = {1.0};
  write_file_atomic(dir + "/weighted.glb", encode_glb(weighted));
  shifted.doc["meshes"][0]["primitives"][0]["attributes"]["POSITION"] =
      with_bounds(shifted, detail::add_float_accessor(shifted, moved, "VEC3"), moved);
  write_file_atomic(dir + "/shifted.glb", encode_glb(shifted));
  const size_t skinned = [&] {
    for (size_t n = 0; n < weighted.doc["nodes"].size(); ++n)
      if (weighted.doc["nodes"][n].contains("skin")) return n;
    return size_t(0);
  }();
  weighted.doc["nodes"][skinned]["weights"] = {0.0};
  write_file_atomic(dir + "/node-zero.glb", encode_glb(weighted));

  const Asset a(dir + "/weighted.glb", ""), b(dir + "/shifted.glb", ""), plain(original, ""), zero(dir + "/node-zero.glb", "");
  auto apart = [](const std::vector<Eigen::Vector3d>& x, const std::vector<Eigen::Vector3d>& y) {
    double worst = x.size() == y.size() ? 0 : INFINITY;
    for (size_t v = 0; v < x.size() && v < y.size(); ++v) worst = std::max(worst, (x[v] - y[v]).norm());
    return worst;
  };
  const std::vector<double>& frames = plain.clips()[0].frames;
  for (size_t f = 0; f < frames.size(); ++f)
    for (const double t : {frames[f], f + 1 < frames.size() ? (frames[f] + frames[f + 1]) / 2 : frames[f]}) {
      EXPECT_LT(apart(a.at_time(0, t), b.at_time(0, t)), 1e-6) << "t " << t;
      EXPECT_LT(apart(zero.at_time(0, t), plain.at_time(0, t)), 1e-9) << "t " << t;
      EXPECT_GT(apart(a.at_time(0, t), plain.at_time(0, t)), 0.5 * d.norm()) << "t " << t;
    }
  EXPECT_LT(apart(a.rest(true), b.rest()), 1e-6);
  EXPECT_EQ(a.rest(), plain.rest()) << "weights zero: as stored";
  // sdf-build reads the stored positions, and says the file weighs a target in by default.
  const LoadedMesh loaded = load_mesh(dir + "/weighted.glb");
  EXPECT_EQ(loaded.default_weights.targets, 1u);
  EXPECT_EQ(loaded.default_weights.weight, 1.0);
  EXPECT_EQ(load_mesh(dir + "/node-zero.glb").default_weights.targets, 0u) << "its node's weights [0] over the mesh's";
  EXPECT_EQ(load_mesh(original).default_weights.targets, 0u);
  Log said("sdf-build", -1);
  warn_default_weights(loaded.default_weights, "weighted.glb", said);
  ASSERT_EQ(said.warnings().size(), 1u);
  EXPECT_NE(said.warnings()[0].find("weighted.glb: 1 morph target weighs in by default (the first, '"), std::string::npos)
      << said.warnings()[0];
  // pose-extract's clip rest is the shifted one's; its morph targets' rest the stored one.
  PoseExtractOptions clip;
  clip.animation = "0";
  json report;
  pose_extract_files(dir + "/weighted.glb", dir + "/a", clip, Log::silent(), report);
  pose_extract_files(dir + "/shifted.glb", dir + "/b", clip, Log::silent(), report);
  const TriMesh rest_a = load_mesh(dir + "/a/rest.obj").mesh, rest_b = load_mesh(dir + "/b/rest.obj").mesh;
  EXPECT_LT(apart(rest_a.vertices, rest_b.vertices), 1e-5);
  PoseExtractOptions morph;
  morph.morph_targets = true;
  pose_extract_files(dir + "/weighted.glb", dir + "/m", morph, Log::silent(), report);
  const TriMesh rest_m = load_mesh(dir + "/m/rest.obj").mesh;
  ASSERT_EQ(rest_m.vertices.size(), rest_a.vertices.size());
  EXPECT_GT(apart(rest_m.vertices, rest_a.vertices), 0.5 * d.norm());
}

// The vertex lines of a pose file (its first line names the asset it came from).
std::string vertex_lines(const std::string& obj) {
  std::string out, line;
  std::istringstream in(read_file(obj));
  while (std::getline(in, line))
    if (line.rfind("v ", 0) == 0) out += line + "\n";
  return out;
}

// KHR_animation_pointer to morph weights: the barrel's clip with its weights channel named by a
// pointer to its node's weights, or to its mesh's (which the node takes, having none of its own),
// gives the same poses to the bit. Where the node has weights of its own, the mesh's move nothing:
// the clip then has nothing else, which is an error that says so.
TEST(PoseExtract, AnimationPointerToMorphWeightsIsTheWeightsChannel) {
  const std::string dir = test::temp_dir("pointer-weights");
  json report;
  sample_gen_files("barrel", dir, Log::silent(), report);
  const GltfFile barrel = read_gltf_file(dir + "/barrel-morph.glb");
  ASSERT_EQ(barrel.doc["animations"][0]["channels"][0]["target"], json({{"node", 0}, {"path", "weights"}}));
  PoseExtractOptions clip;
  clip.animation = "0";
  const auto poses = [&](const GltfFile& file, const std::string& name) {  // every pose's vertices
    write_file_atomic(dir + "/" + name + ".glb", encode_glb(file));
    pose_extract_files(dir + "/" + name + ".glb", dir + "/" + name, clip, Log::silent(), report);
    std::vector<std::string> out;
    for (const auto& p : read_pose_manifest(dir + "/" + name + "/poses.json").poses)
      out.push_back(vertex_lines(dir + "/" + name + "/" + p.file));
    return out;
  };
  const std::vector<std::string> plain = poses(barrel, "plain");
  ASSERT_EQ(plain.size(), 5u);
  for (const char* pointer : {"/nodes/0/weights", "/meshes/0/weights"}) {
    GltfFile pointed = barrel;
    pointed.doc["animations"][0]["channels"][0]["target"] = {
        {"path", "pointer"}, {"extensions", {{"KHR_animation_pointer", {{"pointer", pointer}}}}}};
    EXPECT_EQ(poses(pointed, "pointed"), plain) << pointer;
    EXPECT_EQ(report["asset"]["clips"][0]["morph_channels"], 1) << pointer;
    if (std::string(pointer) != "/meshes/0/weights") continue;
    pointed.doc["nodes"][0]["weights"] = {0, 0, 0};
    const std::string error = test::bad_input_error([&] { poses(pointed, "own-weights"); });
    EXPECT_NE(error.find("own-weights.glb: clip 'barrel' has no keys that move a node or morph weights "
                         "(animations[0].channels[0] (KHR_animation_pointer '/meshes/0/weights': no node places "
                         "meshes[0] without weights of its own) move no geometry)"),
              std::string::npos)
        << error;
    // A second node without weights of its own, 5 along x, takes the pointer's channel, and the
    // first, with its own, stays still. (Split first, the node of its own weights keeping the
    // mesh, the second placed a copy and the pointer reached no node.)
    pointed.doc["nodes"].push_back({{"name", "second"}, {"mesh", 0}, {"translation", {5, 0, 0}}});
    pointed.doc["scenes"][0]["nodes"].push_back(1);
    write_file_atomic(dir + "/second.glb", encode_glb(pointed));
    const Asset two(dir + "/second.glb", ""), one(dir + "/plain.glb", "");
    const std::vector<Eigen::Vector3d> rest = one.rest();
    for (const double t : one.clips()[0].frames) {
      const std::vector<Eigen::Vector3d> a = two.at_time(0, t), b = one.at_time(0, t);
      ASSERT_EQ(a.size(), 2 * b.size());
      double still = 0, off = 0;
      for (size_t v = 0; v < b.size(); ++v) {
        still = std::max(still, (a[v] - rest[v]).norm());
        off = std::max(off, (a[b.size() + v] - b[v] - Eigen::Vector3d(5, 0, 0)).norm());
      }
      EXPECT_EQ(still, 0.0) << "t " << t;
      EXPECT_LT(off, 1e-9) << "t " << t;
    }
  }
}

// A STEP clip holds each key's value until the next key: between keys, the pose of the key before
// (assimp read every clip as linear, so the poses glided). The barrel's morph weights (one value
// per target a key) and the rigged elephant's joints, their samplers set to STEP: the same frames,
// the same poses at the keys, and half-way between two keys the first one's.
TEST(PoseExtract, StepClipsHoldEachKeyUntilTheNext) {
  SPX_REQUIRE_SHARED_DATA();
  const std::string dir = test::temp_dir("step");
  json report;
  sample_gen_files("barrel", dir, Log::silent(), report);
  for (const std::string& linear : {dir + "/barrel-morph.glb", test::shared_data() + "/elephant/elephant-rigged.glb"}) {
    GltfFile file = read_gltf_file(linear);
    for (json& sampler : file.doc["animations"][0]["samplers"]) sampler["interpolation"] = "STEP";
    const std::string stepped = linear + ".step.glb";
    write_file_atomic(dir + "/" + std::filesystem::path(stepped).filename().string(), encode_glb(file));
    const Asset glide(linear, ""), step(dir + "/" + std::filesystem::path(stepped).filename().string(), "");
    const std::vector<double>& frames = glide.clips()[0].frames;
    ASSERT_EQ(step.clips()[0].frames, frames) << linear;
    double moved = 0;
    for (size_t f = 1; f + 1 < frames.size(); f += std::max<size_t>(1, frames.size() / 6)) {
      EXPECT_EQ(step.at_time(0, frames[f]), glide.at_time(0, frames[f])) << linear << " at key " << f;
      const double between = 0.5 * (frames[f] + frames[f + 1]);
      const auto held = step.at_time(0, between), key = glide.at_time(0, frames[f]), glided = glide.at_time(0, between);
      double off = 0;  // a value interpolated with itself: equal up to the last bit
      for (size_t v = 0; v < key.size(); ++v) {
        off = std::max(off, (held[v] - key[v]).norm());
        moved = std::max(moved, (glided[v] - key[v]).norm());
      }
      EXPECT_LE(off, 1e-12 * (1 + key[0].norm())) << linear << " half-way after key " << f;
    }
    EXPECT_GT(moved, 0.0) << linear << ": half-way should differ from the key before when gliding";
  }
}

// Elements' widths by glTF type; the floats of `file`'s accessor `index` (tightly packed or
// strided); a float accessor of `type` appended for `values`, returning its index.
size_t width_of(const std::string& type) {
  return std::map<std::string, size_t>{{"SCALAR", 1}, {"VEC2", 2}, {"VEC3", 3}, {"VEC4", 4}}.at(type);
}
std::vector<float> accessor_floats(const GltfFile& file, size_t index) {
  const json& accessor = file.doc["accessors"][index];
  const json& view = file.doc["bufferViews"][accessor["bufferView"].get<size_t>()];
  const size_t n = width_of(accessor["type"].get<std::string>()), count = accessor["count"].get<size_t>();
  const size_t stride = view.value("byteStride", n * 4);
  const size_t begin = view.value("byteOffset", size_t(0)) + accessor.value("byteOffset", size_t(0));
  std::vector<float> out(count * n);
  for (size_t i = 0; i < count; ++i) std::memcpy(&out[i * n], file.bin.data() + begin + i * stride, n * 4);
  return out;
}
size_t append_floats(GltfFile& file, const std::vector<float>& values, const std::string& type) {
  while (file.bin.size() % 4) file.bin += '\0';
  file.doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", file.bin.size()}, {"byteLength", values.size() * 4}});
  file.bin.append(reinterpret_cast<const char*>(values.data()), values.size() * 4);
  json accessor = {{"bufferView", file.doc["bufferViews"].size() - 1}, {"componentType", 5126}, {"type", type},
                   {"count", values.size() / width_of(type)}};
  if (type == "SCALAR") {
    accessor["min"] = {*std::min_element(values.begin(), values.end())};
    accessor["max"] = {*std::max_element(values.begin(), values.end())};
  }
  file.doc["accessors"].push_back(accessor);
  return file.doc["accessors"].size() - 1;
}

// Valid glTF that assimp reads wrong without a word: CUBICSPLINE clips (Maya's and Blender's
// Bezier curves unsampled) glided linearly between their keys. The rigged elephant's joints and the
// barrel's morph weights get tangents (in 0, out 1.5 times the slope to the next key, so the curve
// overshoots), and a linear twin holds the file's keys and, half-way between them, the spline's
// values as the glTF spec's Hermite form gives them (worked out here; a rotation normalized). The
// cubic clip has the linear one's frames (the keys its rewrite added are none), the same poses at
// the keys and the twin's half-way, where it glided before.
TEST(PoseExtract, CubicClipsFollowTheirSplines) {
  SPX_REQUIRE_SHARED_DATA();
  const std::string dir = test::temp_dir("cubic");
  json report;
  sample_gen_files("barrel", dir, Log::silent(), report);
  for (const std::string& linear : {dir + "/barrel-morph.glb", test::shared_data() + "/elephant/elephant-rigged.glb"}) {
    GltfFile cubic = read_gltf_file(linear), twin = cubic;
    for (size_t s = 0; s < cubic.doc["animations"][0]["samplers"].size(); ++s) {
      json& sampler = cubic.doc["animations"][0]["samplers"][s];
      const std::vector<float> times = accessor_floats(cubic, sampler["input"].get<size_t>());
      const std::vector<float> values = accessor_floats(cubic, sampler["output"].get<size_t>());
      const std::string type = cubic.doc["accessors"][sampler["output"].get<size_t>()]["type"];
      const size_t keys = times.size(), width = values.size() / keys;
      std::vector<float> spline, twin_times, twin_values;
      auto out_tangent = [&](size_t k, size_t c) {
        return k + 1 < keys ? 1.5f * (values[(k + 1) * width + c] - values[k * width + c]) / (times[k + 1] - times[k]) : 0.0f;
      };
      for (size_t k = 0; k < keys; ++k) {
        for (size_t c = 0; c < width; ++c) spline.push_back(0.0f);
        for (size_t c = 0; c < width; ++c) spline.push_back(values[k * width + c]);
        for (size_t c = 0; c < width; ++c) spline.push_back(out_tangent(k, c));
        twin_times.push_back(times[k]);
        twin_values.insert(twin_values.end(), values.begin() + long(k * width), values.begin() + long((k + 1) * width));
        if (k + 1 == keys) continue;
        // Half-way: h00 = h01 = 1/2, h10 = 1/8, h11 = -1/8 (the next key's in-tangent is 0).
        const double td = double(times[k + 1]) - times[k];
        std::vector<double> half(width);
        double norm = 0;
        for (size_t c = 0; c < width; ++c) {
          half[c] = 0.5 * values[k * width + c] + 0.125 * td * out_tangent(k, c) + 0.5 * values[(k + 1) * width + c];
          norm += half[c] * half[c];
        }
        twin_times.push_back(float(times[k] + 0.5 * td));
        for (size_t c = 0; c < width; ++c) twin_values.push_back(float(type == "VEC4" ? half[c] / std::sqrt(norm) : half[c]));
      }
      sampler["output"] = append_floats(cubic, spline, type);
      sampler["interpolation"] = "CUBICSPLINE";
      json& twin_sampler = twin.doc["animations"][0]["samplers"][s];
      twin_sampler["input"] = append_floats(twin, twin_times, "SCALAR");
      twin_sampler["output"] = append_floats(twin, twin_values, type);
    }
    const std::string name = std::filesystem::path(linear).stem().string();
    write_file_atomic(dir + "/" + name + ".cubic.glb", encode_glb(cubic));
    write_file_atomic(dir + "/" + name + ".twin.glb", encode_glb(twin));
    const Asset glide(linear, ""), spline(dir + "/" + name + ".cubic.glb", ""), twin_asset(dir + "/" + name + ".twin.glb", "");
    const std::vector<double>& frames = glide.clips()[0].frames;
    ASSERT_EQ(spline.clips()[0].frames, frames) << linear;
    EXPECT_EQ(spline.clips()[0].keys, glide.clips()[0].keys) << linear;
    const double diagonal = weld_body(glide).rest.diagonal();
    double off_key = 0, off_half = 0, from_glide = 0;
    for (size_t f = 0; f + 1 < frames.size(); f += std::max<size_t>(1, frames.size() / 9)) {
      const double between = 0.5 * (frames[f] + frames[f + 1]);
      const auto key = spline.at_time(0, frames[f]), want_key = glide.at_time(0, frames[f]);
      const auto half = spline.at_time(0, between), want_half = twin_asset.at_time(0, between), glided = glide.at_time(0, between);
      for (size_t v = 0; v < key.size(); ++v) {
        off_key = std::max(off_key, (key[v] - want_key[v]).norm());
        off_half = std::max(off_half, (half[v] - want_half[v]).norm());
        from_glide = std::max(from_glide, (half[v] - glided[v]).norm());
      }
    }
    EXPECT_LE(off_key, 1e-9 * diagonal) << linear;
    EXPECT_LE(off_half, 1e-5 * diagonal) << linear << ": half-way off the spline";
    EXPECT_GT(from_glide, 1e-3 * diagonal) << linear << ": the spline should leave the linear glide half-way";
  }
}

// The whole chain on poses taken from a skinned clip with --select: every sphere inside every pose.
TEST(PoseExtract, ChainOnSelectedClipFramesKeepsEverySphereInside) {
  SPX_REQUIRE_SHARED_DATA();
  const std::string dir = test::temp_dir("rigged-chain");
  PoseExtractOptions opt;
  opt.animation = "0";
  opt.select = 2;
  json report;
  pose_extract_files(test::shared_data() + "/rigged-simple/RiggedSimple.glb", dir + "/ex", opt, Log::silent(), report);
  EXPECT_EQ(report["selection"]["candidates"].get<int>(), 3);
  EXPECT_EQ(report["selection"]["kept"].get<int>(), 2);
  std::string rest;
  std::vector<std::string> poses;
  rest_and_poses(dir + "/ex/poses.json", rest, poses);
  ASSERT_EQ(poses.size(), 2u);
  std::filesystem::create_directories(dir + "/chain");
  run_chain(rest, poses, dir + "/chain");
  const LoadedMesh r = load_mesh(rest);
  std::vector<TriMesh> meshes = {r.mesh};
  for (const auto& p : poses) meshes.push_back(load_pose(p, r));
  expect_spheres_inside(dir + "/chain/proxy.json", meshes, "RiggedSimple");
}

// An asset handed over as FBX or COLLADA (the formats DCC tools and asset stores ship rigs in) gives
// the poses its glTF gives, at the same times, within float rounding. The files are the glTF
// re-exported by assimp, with two of its exporters' slips undone first: both write key times as
// seconds whatever the ticks are, so the keys are put in seconds; FBX drops the root node's own
// transform, so an identity root goes above it. (Its binary FBX does not read back into its own
// importer, hence ASCII; its COLLADA of the elephant's matrices does not either, hence
// RiggedSimple there.) The FBX importer also resamples the clip's keys and ends it at its stack's
// stop, so the times asked lie inside.
std::string reexport(const std::string& asset, const std::string& format, const std::string& out) {
  Assimp::Importer importer;
  if (!importer.ReadFile(asset, 0)) return importer.GetErrorString();
  aiScene* scene = importer.GetOrphanedScene();
  for (unsigned a = 0; a < scene->mNumAnimations; ++a) {
    aiAnimation* clip = scene->mAnimations[a];
    const double tps = clip->mTicksPerSecond > 0 ? clip->mTicksPerSecond : 25.0;
    for (unsigned c = 0; c < clip->mNumChannels; ++c) {
      aiNodeAnim* ch = clip->mChannels[c];
      for (unsigned k = 0; k < ch->mNumPositionKeys; ++k) ch->mPositionKeys[k].mTime /= tps;
      for (unsigned k = 0; k < ch->mNumRotationKeys; ++k) ch->mRotationKeys[k].mTime /= tps;
      for (unsigned k = 0; k < ch->mNumScalingKeys; ++k) ch->mScalingKeys[k].mTime /= tps;
    }
    clip->mDuration /= tps;
    clip->mTicksPerSecond = 1;
  }
  if (format == "fbxa") {
    aiNode* root = new aiNode("exported-root");
    root->mNumChildren = 1;
    root->mChildren = new aiNode*[1]{scene->mRootNode};
    scene->mRootNode->mParent = root;
    scene->mRootNode = root;
  }
  Assimp::Exporter exporter;
  const aiReturn written = exporter.Export(scene, format, out);
  delete scene;
  return written == AI_SUCCESS ? out : exporter.GetErrorString();
}

TEST(PoseExtract, FbxAndColladaGiveTheGltfsPoses) {
  SPX_REQUIRE_SHARED_DATA();
  const std::string dir = test::temp_dir("fbx");
  const std::string simple = test::shared_data() + "/rigged-simple/RiggedSimple.glb";
  const std::string elephant = test::shared_data() + "/elephant/elephant-rigged.glb";
  struct Case {
    std::string gltf, format, file;
    std::vector<double> times;
  };
  const Case cases[] = {{simple, "fbxa", "simple.fbx", {0.3, 0.6, 1.0}},
                        {simple, "collada", "simple.dae", {0.3, 0.8, 1.5, 2.0}},
                        {elephant, "fbxa", "elephant.fbx", {0.5, 5.01, 10.3, 14.9}}};
  for (const Case& c : cases) {
    ASSERT_EQ(reexport(c.gltf, c.format, dir + "/" + c.file), dir + "/" + c.file);
    PoseExtractOptions opt;
    opt.animation = "0";
    opt.times = c.times;
    json report;
    pose_extract_files(c.gltf, dir + "/" + c.file + ".gltf-poses", opt, Log::silent(), report);
    pose_extract_files(dir + "/" + c.file, dir + "/" + c.file + ".poses", opt, Log::silent(), report);
    const PoseManifest ours = read_pose_manifest(dir + "/" + c.file + ".poses/poses.json");
    const PoseManifest theirs = read_pose_manifest(dir + "/" + c.file + ".gltf-poses/poses.json");
    ASSERT_EQ(ours.poses.size(), c.times.size()) << c.file;
    const LoadedMesh rest = load_mesh(dir + "/" + c.file + ".gltf-poses/" + theirs.rest);
    const double tol = 1e-5 * rest.mesh.diagonal();
    // The re-exported mesh is matched to the glTF's by its triangles (its vertices come in
    // another order, split at every corner).
    EXPECT_LE(max_vertex_distance(rest.mesh, load_pose(dir + "/" + c.file + ".poses/" + ours.rest, rest)), tol)
        << c.file << ": the bind pose";
    double moved = 0;
    for (size_t k = 0; k < c.times.size(); ++k) {
      const TriMesh mine = load_pose(dir + "/" + c.file + ".poses/" + ours.poses[k].file, rest);
      const TriMesh gltf = load_pose(dir + "/" + c.file + ".gltf-poses/" + theirs.poses[k].file, rest);
      EXPECT_LE(max_vertex_distance(mine, gltf), tol) << c.file << " at " << c.times[k] << " s";
      moved = std::max(moved, max_vertex_distance(gltf, rest.mesh));
    }
    EXPECT_GT(moved, 0.05 * rest.mesh.diagonal()) << c.file << ": the times asked should move the body";
  }
}

// COLLADA's index lists (<p>, <vcount>, <v>) as assimp's reader takes them, one whole number at a
// time: it read a negative corner as another vertex, and a skin's counts or joints with a word
// that is not one as other weights, all without a word (and a word like "5.2" in a <p> never
// ended it: cli.errors, under a memory limit). It reads an array's count of values however many
// it holds, and an accessor's elements wherever they fall: an array's count one less (the
// bind matrices' so crashed it) or an accessor's one more read past the array's end without a
// word. RiggedSimple's COLLADA with one word or count changed: each bad one is one error line
// naming the line and the element; "+" or a leading zero, which it reads right, gives the file's
// poses.
TEST(PoseExtract, ColladaIndexListsTheReaderWouldMisreadAreErrors) {
  SPX_REQUIRE_SHARED_DATA();
  const std::string dir = test::temp_dir("collada-lists");
  const std::string dae = dir + "/simple.dae";
  ASSERT_EQ(reexport(test::shared_data() + "/rigged-simple/RiggedSimple.glb", "collada", dae), dae);
  const std::string text = read_file(dae);
  // The text with the first word of the first `element` after `after` replaced by `word`.
  const auto with_word = [&](const std::string& after, const std::string& element, const std::string& word) {
    const size_t open = text.find("<" + element + ">", text.find(after));
    const size_t begin = open + element.size() + 2, end = text.find(' ', begin);
    return text.substr(0, begin) + word + text.substr(end);
  };
  PoseExtractOptions clip;
  clip.animation = "0";
  json report;
  pose_extract_files(dae, dir + "/plain", clip, Log::silent(), report);
  // A pose's vertices and faces (its first line names the file it came from).
  const auto body = [](const std::string& obj) {
    const std::string text = read_file(obj);
    return text.substr(text.find('\n'));
  };
  const std::string plain = body(dir + "/plain/pose-00.obj");
  struct Case {
    std::string after, element, word, said;
  };
  // The text with the first `element`'s count one less or one more.
  const auto with_count = [&](const std::string& element, int by) {
    const size_t count = text.find("count=\"", text.find("<" + element)) + 7, end = text.find('"', count);
    return text.substr(0, count) + std::to_string(std::stoi(text.substr(count, end - count)) + by) + text.substr(end);
  };
  const Case bad[] = {{"<mesh", "p", "-2", "<p> holds '-2'"},
                      {"<vertex_weights", "vcount", "x", "<vcount> holds 'x'"},
                      {"<vertex_weights", "v", "1.5", "<v> holds '1.5'"},
                      {"", "float_array", "-1", "values (a number changed, or values lost?)"},
                      {"", "accessor", "+1", ": the reader would read past its end"}};
  for (const Case& c : bad) {
    const bool count = c.word == "-1" || c.word == "+1";
    write_file_atomic(dir + "/bad.dae", count ? with_count(c.element, std::stoi(c.word))
                                              : with_word(c.after, c.element, c.word));
    const std::string error =
        test::bad_input_error([&] { pose_extract_files(dir + "/bad.dae", dir + "/bad", clip, Log::silent(), report); });
    EXPECT_NE(error.find("bad.dae: line "), std::string::npos) << error;
    EXPECT_NE(error.find(c.said), std::string::npos) << error;
  }
  const size_t first = text.find("<p>", text.find("<mesh")) + 3;
  const std::string corner = text.substr(first, text.find(' ', first) - first);
  for (const std::string& same : {"+" + corner, "0" + corner}) {
    write_file_atomic(dir + "/good.dae", with_word("<mesh", "p", same));
    pose_extract_files(dir + "/good.dae", dir + "/good", clip, Log::silent(), report);
    EXPECT_TRUE(body(dir + "/good/pose-00.obj") == plain) << same;
  }
}

// A check of assimp's own that fails (ai_assert) aborted the process: RiggedSimple's FBX whose second
// curve node lost its name (a damaged byte) stopped pose-extract and sdf-build with exit 134 and
// assimp's line. It is one error line now, exit 2, in both.
TEST(PoseExtract, AssimpsOwnFailedCheckIsAnErrorLine) {
  SPX_REQUIRE_SHARED_DATA();
  const std::string dir = test::temp_dir("assimp-check");
  const std::string fbx = dir + "/simple.fbx";
  Assimp::Importer importer;  // written as assimp writes it (reexport's keys in seconds do not trip the check)
  ASSERT_TRUE(importer.ReadFile(test::shared_data() + "/rigged-simple/RiggedSimple.glb", 0));
  ASSERT_EQ(Assimp::Exporter().Export(importer.GetScene(), "fbxa", fbx), AI_SUCCESS);
  std::string text = read_file(fbx);
  const size_t second = text.find("AnimationCurveNode: ", text.find("AnimationCurveNode: ") + 1);
  ASSERT_NE(second, std::string::npos);
  text[second + 5] = 'X';  // AnimaXionCurveNode
  write_file_atomic(dir + "/damaged.fbx", text);
  PoseExtractOptions clip;
  clip.animation = "0";
  json report;
  const std::string said = ": assimp stopped on a check of its own (!keys.empty(), FBXConverter.cpp line";
  const std::string extract_error =
      test::bad_input_error([&] { pose_extract_files(dir + "/damaged.fbx", dir + "/out", clip, Log::silent(), report); });
  EXPECT_NE(extract_error.find("damaged.fbx: cannot read asset" + said), std::string::npos) << extract_error;
  const std::string load_error = test::bad_input_error([&] { load_mesh(dir + "/damaged.fbx"); });
  EXPECT_NE(load_error.find("damaged.fbx: cannot read mesh" + said), std::string::npos) << load_error;
}

// An asset's polygons are split as the meshes' are: the heptagram prism's ends, which cross
// themselves, as fans (assimp's ear clipping had stopped part way and left 2 triangles of each
// out, the body open there), in an FBX as a modelling tool writes n-gons.
TEST(PoseExtract, AssetPolygonsThatCrossThemselvesAreFanned) {
  const std::string dir = test::temp_dir("asset-heptagram");
  write_file_atomic(dir + "/prism.obj", test::heptagram_prism_obj(1));
  Assimp::Importer importer;  // its polygons kept
  ASSERT_TRUE(importer.ReadFile(dir + "/prism.obj", 0));
  ASSERT_EQ(Assimp::Exporter().Export(importer.GetScene(), "fbxa", dir + "/prism.fbx"), AI_SUCCESS);
  const Asset asset(dir + "/prism.fbx", "");
  EXPECT_EQ(asset.triangles().size(), 2u * 5 + 7 * 2);
  EXPECT_EQ(asset.fanned().polygons, 2u);
  EXPECT_EQ(asset.fanned().dropped, 4u);
  const WeldedBody body = weld_body(asset);
  EXPECT_TRUE(find_defects(body.rest).watertight());
  EXPECT_EQ(asset.inventory()["polygons_fanned"], 2);
}

// A joint with FBX's pre- and post-rotations (Maya's joint orients; Mixamo's and 3ds Max's rigs
// carry them): FBX places it at T * Rpre * R * Rpost^-1, which assimp keeps as helper nodes
// ("$AssimpFbx$_PreRotation", ...) around the joint. RiggedSimple's FBX with both on its animated
// child joint gives the poses of its glTF twin, whose joint turns by Rpre * R * Rpost^-1 at rest
// and at every key (slerp keeps that between keys). With a rotation pivot Rp too (Maya's pivots;
// assimp then gives the clip's channels to the helpers), T * Rp * Rpre * R * Rpost^-1 * Rp^-1:
// the twin's translation keys move by Rp - M Rp, exact at the keys, where the poses are compared.
TEST(PoseExtract, FbxPreAndPostRotationsPlaceTheJoint) {
  SPX_REQUIRE_SHARED_DATA();
  const std::string dir = test::temp_dir("fbx-turned");
  const std::string simple = test::shared_data() + "/rigged-simple/RiggedSimple.glb";
  ASSERT_EQ(reexport(simple, "fbxa", dir + "/plain.fbx"), dir + "/plain.fbx");
  // FBX's Euler angles in degrees, X first (its XYZ order).
  const auto euler = [](double x, double y, double z) {
    const double r = M_PI / 180;
    return Eigen::Quaterniond(Eigen::AngleAxisd(z * r, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(y * r, Eigen::Vector3d::UnitY()) *
                              Eigen::AngleAxisd(x * r, Eigen::Vector3d::UnitX()));
  };
  const Eigen::Quaterniond pre = euler(30, 0, 45), post = euler(10, 20, 0);
  const auto turned = [&](const float* xyzw) {
    return pre * Eigen::Quaterniond(xyzw[3], xyzw[0], xyzw[1], xyzw[2]) * post.inverse();
  };
  struct Case {
    std::string name;
    Eigen::Vector3d pivot;
    std::vector<double> times;
  };
  for (const Case& c : {Case{"turned", Eigen::Vector3d::Zero(), {0.3, 0.6, 1.0}},
                        Case{"pivoted", Eigen::Vector3d(0, 1, 0.5), {0.0416666195, 1.041666985}}}) {
    std::string text = read_file(dir + "/plain.fbx");
    const size_t model = text.find("\"Model::nodes[3]\"");
    ASSERT_NE(model, std::string::npos);
    const std::string anchor = "P: \"InheritType\", \"enum\", \"\", \"\", 1\n";
    const size_t at = text.find(anchor, model);
    ASSERT_NE(at, std::string::npos);
    std::string lines = "\t\t\tP: \"PreRotation\", \"Vector3D\", \"Vector\", \"\", 30, 0, 45\n"
                        "\t\t\tP: \"PostRotation\", \"Vector3D\", \"Vector\", \"\", 10, 20, 0\n";
    if (!c.pivot.isZero())
      lines += "\t\t\tP: \"RotationPivot\", \"Vector3D\", \"Vector\", \"\", " + std::to_string(c.pivot.x()) + ", " +
               std::to_string(c.pivot.y()) + ", " + std::to_string(c.pivot.z()) + "\n";
    text.insert(at + anchor.size(), lines);
    write_file_atomic(dir + "/" + c.name + ".fbx", text);

    // The twin: the joint's rotation M = Rpre R Rpost^-1, its translation T + Rp - M Rp.
    GltfFile twin = read_gltf_file(simple);
    json& clip = twin.doc["animations"][0];
    std::map<std::string, json*> sampler;  // node 3's, by path
    for (const json& channel : clip["channels"])
      if (channel["target"]["node"] == 3) sampler[channel["target"]["path"]] = &clip["samplers"][channel["sampler"].get<size_t>()];
    ASSERT_EQ(sampler.count("rotation") + sampler.count("translation"), 2u);
    ASSERT_EQ((*sampler["rotation"])["input"], (*sampler["translation"])["input"]);
    const std::vector<float> rotations = accessor_floats(twin, (*sampler["rotation"])["output"].get<size_t>());
    std::vector<float> translations = accessor_floats(twin, (*sampler["translation"])["output"].get<size_t>()), keyed;
    const auto placed = [&](const float* xyzw, float* xyz) {
      const Eigen::Quaterniond m = turned(xyzw);
      const Eigen::Vector3d t = Eigen::Vector3d(xyz[0], xyz[1], xyz[2]) + c.pivot - m * c.pivot;
      for (int k = 0; k < 3; ++k) xyz[k] = float(t[k]);
      for (double v : {m.x(), m.y(), m.z(), m.w()}) keyed.push_back(float(v));
    };
    for (size_t k = 0; k < rotations.size() / 4; ++k) placed(&rotations[4 * k], &translations[3 * k]);
    (*sampler["rotation"])["output"] = append_floats(twin, keyed, "VEC4");
    (*sampler["translation"])["output"] = append_floats(twin, translations, "VEC3");
    json& joint = twin.doc["nodes"][3];
    std::vector<float> r = joint["rotation"].get<std::vector<float>>(), t = joint["translation"].get<std::vector<float>>();
    keyed.clear();
    placed(r.data(), t.data());
    joint["rotation"] = keyed;
    joint["translation"] = t;
    write_file_atomic(dir + "/" + c.name + ".glb", encode_glb(twin));

    PoseExtractOptions opt;
    opt.animation = "0";
    opt.times = c.times;
    json report;
    for (const std::string kind : {".glb", ".fbx"})
      pose_extract_files(dir + "/" + c.name + kind, dir + "/" + c.name + kind + ".poses", opt, Log::silent(), report);
    pose_extract_files(simple, dir + "/plain.poses", opt, Log::silent(), report);
    const PoseManifest ours = read_pose_manifest(dir + "/" + c.name + ".fbx.poses/poses.json");
    const PoseManifest theirs = read_pose_manifest(dir + "/" + c.name + ".glb.poses/poses.json");
    const PoseManifest plain = read_pose_manifest(dir + "/plain.poses/poses.json");
    ASSERT_EQ(ours.poses.size(), opt.times.size()) << c.name;
    const LoadedMesh rest = load_mesh(dir + "/" + c.name + ".glb.poses/" + theirs.rest);
    const double tol = 1e-5 * rest.mesh.diagonal();
    EXPECT_LE(max_vertex_distance(rest.mesh, load_pose(dir + "/" + c.name + ".fbx.poses/" + ours.rest, rest)), tol) << c.name;
    double turn = 0;
    for (size_t k = 0; k < opt.times.size(); ++k) {
      const TriMesh gltf = load_pose(dir + "/" + c.name + ".glb.poses/" + theirs.poses[k].file, rest);
      EXPECT_LE(max_vertex_distance(load_pose(dir + "/" + c.name + ".fbx.poses/" + ours.poses[k].file, rest), gltf), tol)
          << c.name << " at " << opt.times[k] << " s";
      turn = std::max(turn, max_vertex_distance(gltf, load_pose(dir + "/plain.poses/" + plain.poses[k].file, rest)));
    }
    EXPECT_GT(turn, 0.05 * rest.mesh.diagonal()) << c.name << ": the joint's transform should move the body";
  }
}

// An FBX blend shape (a Morpher's channel and its Shape, as Maya and Blender write them; here a
// hand-written ASCII file: the unit cube whose corner (1, 1, 1) the shape lifts by 1) is a morph
// target like glTF's: pose "Bump" moves that corner alone.
TEST(PoseExtract, FbxBlendShapeIsAMorphTarget) {
  const std::string dir = test::temp_dir("fbx-shape");
  auto listed = [](const std::vector<int>& values) {
    std::string out;
    for (int v : values) out += (out.empty() ? "" : ",") + std::to_string(v);
    return out;
  };
  std::vector<int> corners, polygons;
  for (int x : {0, 1})
    for (int y : {0, 1})
      for (int z : {0, 1}) corners.insert(corners.end(), {x, y, z});
  for (const auto& q : {std::array<int, 4>{0, 1, 3, 2}, {4, 6, 7, 5}, {0, 4, 5, 1}, {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 5, 7, 3}})
    polygons.insert(polygons.end(), {q[0], q[1], q[2], -(q[3] + 1)});  // a polygon's last index i is written -(i + 1)
  write_file_atomic(dir + "/bump.fbx", R"(; FBX 7.4.0 project file
FBXHeaderExtension:  {
	FBXHeaderVersion: 1003
	FBXVersion: 7400
}
Objects:  {
	Geometry: 1000, "Geometry::Cube", "Mesh" {
		Vertices: *24 {
			a: )" + listed(corners) + R"(
		}
		PolygonVertexIndex: *24 {
			a: )" + listed(polygons) + R"(
		}
		GeometryVersion: 124
	}
	Geometry: 2000, "Geometry::Bump", "Shape" {
		Version: 100
		Indexes: *1 {
			a: 7
		}
		Vertices: *3 {
			a: 0,0,1
		}
		Normals: *3 {
			a: 0,0,0
		}
	}
	Model: 3000, "Model::Cube", "Mesh" {
		Version: 232
	}
	Deformer: 4000, "Deformer::Morpher", "BlendShape" {
		Version: 100
	}
	Deformer: 5000, "SubDeformer::Bump", "BlendShapeChannel" {
		Version: 100
		DeformPercent: 0
		FullWeights: *1 {
			a: 100
		}
	}
}
Connections:  {
	C: "OO",3000,0
	C: "OO",1000,3000
	C: "OO",4000,1000
	C: "OO",5000,4000
	C: "OO",2000,5000
}
)");
  PoseExtractOptions opt;
  opt.morph_targets = true;
  json report;
  pose_extract_files(dir + "/bump.fbx", dir + "/ex", opt, Log::silent(), report);
  const PoseManifest manifest = read_pose_manifest(dir + "/ex/poses.json");
  ASSERT_EQ(manifest.poses.size(), 1u);
  EXPECT_EQ(manifest.poses[0].name, "Bump");
  const LoadedMesh rest = load_mesh(dir + "/ex/rest.obj");
  ASSERT_EQ(rest.mesh.vertices.size(), 8u);
  EXPECT_NEAR(signed_volume(rest.mesh), 1.0, 1e-12);
  const TriMesh bump = load_pose(dir + "/ex/" + manifest.poses[0].file, rest);
  for (size_t v = 0; v < 8; ++v) {
    const Eigen::Vector3d& p = rest.mesh.vertices[v];
    const Eigen::Vector3d lift = p == Eigen::Vector3d(1, 1, 1) ? Eigen::Vector3d(0, 0, 1) : Eigen::Vector3d::Zero();
    EXPECT_EQ(bump.vertices[v], p + lift) << "corner " << p.transpose();
  }
}

// A float accessor of `file` rewritten with integer components (c = round(v * scale), clamped to
// the type): into `quantized` as glTF stores them, and into `twin` as floats with the values a
// reader must take from them (the spec's c / 255, max(c / 32767, -1), ... where normalized, else c).
void quantize(const GltfFile& file, GltfFile& quantized, GltfFile& twin, size_t index, int type, bool normalized,
              double scale) {
  const auto [lo, hi, divisor] = type == 5121   ? std::tuple(0.0, 255.0, 255.0)
                                 : type == 5120 ? std::tuple(-127.0, 127.0, 127.0)
                                 : type == 5123 ? std::tuple(0.0, 65535.0, 65535.0)
                                                : std::tuple(-32767.0, 32767.0, 32767.0);
  const size_t bytes = type == 5121 || type == 5120 ? 1 : 2;
  std::string ints, floats;
  for (const float v : accessor_floats(file, index)) {
    const double q = std::clamp(std::round(v * scale), lo, hi);
    const int32_t stored = int32_t(q);
    ints.append(reinterpret_cast<const char*>(&stored), bytes);  // little-endian
    const float read = float(normalized ? std::max(q / divisor, -1.0) : q);
    floats.append(reinterpret_cast<const char*>(&read), 4);
  }
  const auto put = [&](GltfFile& out, const std::string& data, int component_type, bool norm) {
    while (out.bin.size() % 4) out.bin += '\0';
    out.doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", out.bin.size()}, {"byteLength", data.size()}});
    out.bin += data;
    json& a = out.doc["accessors"][index];
    a["bufferView"] = out.doc["bufferViews"].size() - 1;
    a["byteOffset"] = 0;
    a["componentType"] = component_type;
    a.erase("min");
    a.erase("max");
    if (norm) a["normalized"] = true;
  };
  put(quantized, ints, type, normalized);
  put(twin, floats, 5126, false);
}

// Valid glTF that assimp reads wrong without a word: integer data where floats are meant. Skin
// weights as normalized bytes and clip rotations as normalized shorts (core glTF), and, under
// KHR_mesh_quantization, positions and morph targets' deltas as shorts (in millimetres). Each
// gives its float twin's poses to the bit. (Before: the weights read as 1e-43 and the elephant's
// poses came out 6 units off, 3 % of its diagonal; the rotations as "vertex 0 is not finite".)
// A required extension the tools cannot read stops with exit 3 naming it.
TEST(PoseExtract, IntegerGltfDataGivesItsFloatTwinsPoses) {
  SPX_REQUIRE_SHARED_DATA();
  const std::string dir = test::temp_dir("quantized");
  json report;
  sample_gen_files("car", dir + "/car", Log::silent(), report);
  struct Case {
    std::string name, asset;
    bool morph;
  };
  for (const Case& c : {Case{"elephant", test::shared_data() + "/elephant/elephant-rigged.glb", false},
                        Case{"car", dir + "/car/car-morph.glb", true}}) {
    const GltfFile file = read_gltf_file(c.asset);
    GltfFile quantized = file, twin = file;
    const json& primitive = file.doc["meshes"][0]["primitives"][0];
    size_t rewritten = 0;
    if (c.morph) {
      quantize(file, quantized, twin, primitive["attributes"]["POSITION"], 5122, false, 1000.0);
      for (const json& target : primitive["targets"]) quantize(file, quantized, twin, target["POSITION"], 5122, false, 1000.0);
      rewritten = 1 + primitive["targets"].size();
      quantized.doc["extensionsUsed"].push_back("KHR_mesh_quantization");
      quantized.doc["extensionsRequired"] = {"KHR_mesh_quantization"};
    } else {
      quantize(file, quantized, twin, primitive["attributes"]["WEIGHTS_0"], 5121, true, 255.0);
      rewritten = 1;
      for (const json& channel : file.doc["animations"][0]["channels"])
        if (channel["target"]["path"] == "rotation") {
          quantize(file, quantized, twin, file.doc["animations"][0]["samplers"][channel["sampler"].get<size_t>()]["output"],
                   5122, true, 32767.0);
          ++rewritten;
        }
    }
    if (!c.morph)  // held keys read from the rewritten rotations' views too
      for (GltfFile* f : {&quantized, &twin})
        for (json& sampler : f->doc["animations"][0]["samplers"]) sampler["interpolation"] = "STEP";
    write_file_atomic(dir + "/" + c.name + "-q.glb", encode_glb(quantized));
    write_file_atomic(dir + "/" + c.name + "-f.glb", encode_glb(twin));
    GltfFile again = read_gltf_file(dir + "/" + c.name + "-q.glb");
    EXPECT_EQ(float_accessors(again, c.name), rewritten) << c.name;
    // The same as a .gltf beside its buffer file (the buffers merged into one, read from memory).
    json document = quantized.doc;
    document["buffers"] = json::array({{{"uri", c.name + "-q.bin"}, {"byteLength", quantized.bin.size()}}});
    write_file_atomic(dir + "/" + c.name + "-q.bin", quantized.bin);
    write_file_atomic(dir + "/" + c.name + "-q.gltf", document.dump());
    PoseExtractOptions opt;
    if (c.morph) {
      opt.morph_targets = true;
    } else {
      opt.animation = "0";
      opt.times = {0.5, 5.01, 10.3};
    }
    pose_extract_files(dir + "/" + c.name + "-q.glb", dir + "/" + c.name + "-q", opt, Log::silent(), report);
    pose_extract_files(dir + "/" + c.name + "-f.glb", dir + "/" + c.name + "-f", opt, Log::silent(), report);
    pose_extract_files(dir + "/" + c.name + "-q.gltf", dir + "/" + c.name + "-qt", opt, Log::silent(), report);
    for (const char* file : {"rest.obj", "pose-00.obj", "pose-02.obj"})
      if (std::filesystem::exists(dir + "/" + c.name + "-q/" + file))
        EXPECT_TRUE(load_mesh(dir + "/" + c.name + "-qt/" + file).mesh.vertices ==
                    load_mesh(dir + "/" + c.name + "-q/" + file).mesh.vertices)
            << c.name << " .gltf " << file;
    const PoseManifest ours = read_pose_manifest(dir + "/" + c.name + "-q/poses.json");
    const PoseManifest theirs = read_pose_manifest(dir + "/" + c.name + "-f/poses.json");
    ASSERT_EQ(ours.poses.size(), theirs.poses.size()) << c.name;
    ASSERT_GE(ours.poses.size(), 3u) << c.name;
    const LoadedMesh rest = load_mesh(dir + "/" + c.name + "-f/" + theirs.rest);
    EXPECT_EQ(load_mesh(dir + "/" + c.name + "-q/" + ours.rest).mesh.vertices, rest.mesh.vertices) << c.name;
    for (size_t k = 0; k < ours.poses.size(); ++k) {
      const TriMesh mine = load_pose(dir + "/" + c.name + "-q/" + ours.poses[k].file, rest);
      const TriMesh gltf = load_pose(dir + "/" + c.name + "-f/" + theirs.poses[k].file, rest);
      EXPECT_EQ(mine.vertices, gltf.vertices) << c.name << " pose " << k;
      EXPECT_GT(max_vertex_distance(gltf, rest.mesh), 0.01 * rest.mesh.diagonal()) << c.name << " pose " << k;
    }
  }
  GltfFile file = read_gltf_file(test::shared_data() + "/rigged-simple/RiggedSimple.glb");
  file.doc["extensionsRequired"] = {"KHR_materials_emissive_strength", "KHR_meshopt_compression"};
  write_file_atomic(dir + "/meshopt.glb", encode_glb(file));
  try {
    load_mesh(dir + "/meshopt.glb");
    ADD_FAILURE() << "a required KHR_meshopt_compression was read";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ExitCode::unsupported);
    EXPECT_NE(e.message().find("requires the glTF extension KHR_meshopt_compression"), std::string::npos) << e.what();
  }
}

// A part placed by a mirroring transform (a left wheel as the right one scaled by -1) is drawn by
// glTF, and every renderer, with its faces' order reversed, so that it faces out. Read so by the
// mesh loader and by pose-extract: the unit cube placed plain, mirrored (det -1, once with the
// clip moving it) and mirrored twice (det +1) makes three outward cubes, volume 3. Before, the
// mirrored one faced inward: "faces inward ... gets no spheres; flip its faces" of a valid file.
TEST(PoseExtract, MirroredPartsFaceOutAsGltfDrawsThem) {
  const std::string dir = test::temp_dir("mirror");
  GltfFile file;
  auto put = [&](auto v) { file.bin.append(reinterpret_cast<const char*>(&v), sizeof v); };
  for (int x : {0, 1})
    for (int y : {0, 1})
      for (int z : {0, 1})
        for (int c : {x, y, z}) put(float(c));
  const uint16_t faces[12][3] = {{0, 1, 2}, {1, 3, 2}, {4, 6, 5}, {5, 6, 7}, {0, 4, 1}, {1, 4, 5},
                                 {2, 3, 6}, {3, 7, 6}, {0, 2, 4}, {2, 6, 4}, {1, 5, 3}, {3, 5, 7}};
  for (const auto& f : faces)
    for (uint16_t v : f) put(v);
  for (float t : {0.0f, 1.0f}) put(t);
  for (float c : {-0.5f, 0.0f, 0.0f, -0.5f, 0.0f, 2.0f}) put(c);  // the mirrored cube's keys: up by 2
  file.doc = json::parse(R"({
    "asset": {"version": "2.0"},
    "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 96}, {"buffer": 0, "byteOffset": 96, "byteLength": 72},
                    {"buffer": 0, "byteOffset": 168, "byteLength": 8}, {"buffer": 0, "byteOffset": 176, "byteLength": 24}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "count": 8, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 1]},
                  {"bufferView": 1, "componentType": 5123, "count": 36, "type": "SCALAR"},
                  {"bufferView": 2, "componentType": 5126, "count": 2, "type": "SCALAR", "min": [0], "max": [1]},
                  {"bufferView": 3, "componentType": 5126, "count": 2, "type": "VEC3"}],
    "meshes": [{"name": "cube", "primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
    "nodes": [{"name": "plain", "mesh": 0},
              {"name": "mirrored", "mesh": 0, "scale": [-1, 1, 1], "translation": [-0.5, 0, 0]},
              {"name": "twice", "mesh": 0, "scale": [-1, -1, 1], "translation": [4, 3, 0]}],
    "scenes": [{"nodes": [0, 1, 2]}], "scene": 0,
    "animations": [{"name": "lift", "samplers": [{"input": 2, "output": 3}],
                    "channels": [{"sampler": 0, "target": {"node": 1, "path": "translation"}}]}]
  })");
  write_file_atomic(dir + "/cubes.glb", encode_glb(file));
  const LoadedMesh loaded = load_mesh(dir + "/cubes.glb");
  EXPECT_NEAR(signed_volume(loaded.mesh), 3.0, 1e-9);
  PoseExtractOptions opt;
  opt.animation = "0";
  opt.times = {1.0};
  json report;
  pose_extract_files(dir + "/cubes.glb", dir + "/ex", opt, Log::silent(), report);
  const LoadedMesh rest = load_mesh(dir + "/ex/rest.obj");
  EXPECT_NEAR(signed_volume(rest.mesh), 3.0, 1e-9);
  const TriMesh lifted = load_pose(dir + "/ex/pose-00.obj", rest);
  EXPECT_NEAR(signed_volume(lifted), 3.0, 1e-9);
  EXPECT_NEAR(max_vertex_distance(lifted, rest.mesh), 2.0, 1e-6);  // the clip moved the mirrored cube
  EXPECT_TRUE(find_defects(rest.mesh).inside_out_parts.empty());
}

// Farthest-point selection against brute force: the greedy choice is a 2-approximation of the
// best k frames (the k-centre bound, with the rest as a centre given in advance).
TEST(PoseExtract, FarthestPosesIsWithinTwiceTheBestCover) {
  std::mt19937 rng(11);
  std::normal_distribution<float> g(0, 1);
  const size_t verts = 5;
  std::vector<Eigen::Vector3d> rest(verts, Eigen::Vector3d::Zero());
  for (int trial = 0; trial < 20; ++trial) {
    std::vector<std::vector<Eigen::Vector3f>> poses(9, std::vector<Eigen::Vector3f>(verts));
    for (auto& p : poses)
      for (auto& v : p) v = Eigen::Vector3f(g(rng), g(rng), g(rng)) * float(1 + trial % 3);
    const std::vector<Eigen::Vector3f> rest_f(verts, Eigen::Vector3f::Zero());
    auto radius = [&](const std::vector<size_t>& centres) {
      double r = 0;
      for (const auto& p : poses) {
        double d = rms_distance(rest_f, p);
        for (size_t c : centres) d = std::min(d, rms_distance(poses[c], p));
        r = std::max(r, d);
      }
      return r;
    };
    for (size_t k = 1; k <= 4; ++k) {
      const std::vector<size_t> greedy = farthest_poses(rest, poses, k);
      ASSERT_EQ(greedy.size(), k);
      EXPECT_TRUE(std::is_sorted(greedy.begin(), greedy.end()));
      double best = INFINITY;
      for (unsigned mask = 0; mask < (1u << poses.size()); ++mask) {
        if (size_t(__builtin_popcount(mask)) != k) continue;
        std::vector<size_t> c;
        for (size_t i = 0; i < poses.size(); ++i)
          if (mask >> i & 1) c.push_back(i);
        best = std::min(best, radius(c));
      }
      EXPECT_LE(radius(greedy), 2 * best + 1e-9) << "trial " << trial << " k " << k;
    }
    // The first pick is the frame farthest from the rest.
    size_t far = 0;
    for (size_t i = 1; i < poses.size(); ++i)
      if (rms_distance(rest_f, poses[i]) > rms_distance(rest_f, poses[far])) far = i;
    EXPECT_EQ(farthest_poses(rest, poses, 1), std::vector<size_t>{far});
  }
}

// Several meshes: merged into one body by default (the report lists them), one by --mesh.
TEST(PoseExtract, SeveralMeshesMergeOrOneIsPicked) {
  const std::string dir = test::temp_dir("two-meshes");
  test::box_and_ball_glb(dir);
  const TriMesh box = test::box_mesh({0, 0, 0}, {1, 1, 1});
  TriMesh ball = test::uv_sphere(0.5, 8, 16);
  for (auto& v : ball.vertices) v += Eigen::Vector3d(3, 0, 0);
  const Asset merged(dir + "/pair.glb", "");
  ASSERT_EQ(merged.meshes().size(), 2u);
  const size_t file_vertices = merged.meshes()[0].vertices + merged.meshes()[1].vertices;
  EXPECT_EQ(merged.rest().size(), file_vertices);
  EXPECT_EQ(merged.triangles().size(), box.triangles.size() + ball.triangles.size());
  const Asset one(dir + "/pair.glb", "ball");
  EXPECT_FALSE(one.meshes()[0].used && one.meshes()[1].used);
  std::vector<Eigen::Vector3d> welded;
  weld_by_position(one.rest(), welded);
  ASSERT_EQ(welded.size(), ball.vertices.size());
  for (size_t v = 0; v < welded.size(); ++v) EXPECT_LT((welded[v] - ball.vertices[v]).norm(), 1e-6);
  try {
    Asset(dir + "/pair.glb", "wheel");
    ADD_FAILURE() << "unknown mesh accepted";
  } catch (const OptionError& e) {
    EXPECT_EQ(e.option(), "mesh");
    EXPECT_NE(std::string(e.what()).find("'box', 'ball'"), std::string::npos) << e.what();
  }
  // Neither poses from morph targets nor from a clip here: both requests are named errors.
  PoseExtractOptions opt;
  opt.morph_targets = true;
  json report;
  EXPECT_THROW(pose_extract_files(dir + "/pair.glb", dir + "/ex", opt, Log::silent(), report), Error);
  opt.animation = "0";
  EXPECT_THROW(pose_extract_files(dir + "/pair.glb", dir + "/ex", opt, Log::silent(), report), OptionError);
}

TEST(PoseExtract, MissingPartsAreClearErrors) {
  SPX_REQUIRE_SHARED_DATA();
  const std::string glb = test::shared_data() + "/rigged-simple/RiggedSimple.glb";
  const std::string dir = test::temp_dir("extract-errors");
  json report;
  auto run = [&](PoseExtractOptions opt) { pose_extract_files(glb, dir + "/out", opt, Log::silent(), report); };
  PoseExtractOptions morph;
  morph.morph_targets = true;
  try {
    run(morph);
    ADD_FAILURE() << "no morph targets accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ExitCode::bad_input);
    EXPECT_NE(std::string(e.what()).find("has no morph targets"), std::string::npos) << e.what();
  }
  PoseExtractOptions clip;
  clip.animation = "Walk";
  EXPECT_THROW(run(clip), OptionError);
  clip.animation = "3";
  EXPECT_THROW(run(clip), OptionError);
  clip.animation = "0";
  clip.frames = {3};
  EXPECT_THROW(run(clip), OptionError);
  clip.frames.clear();
  clip.times = {2.5};
  EXPECT_THROW(run(clip), OptionError);
  EXPECT_FALSE(std::filesystem::exists(dir + "/out/poses.json"));
  // A mesh without a clip.
  MorphAsset still;
  still.name = "still";
  still.base = test::box_mesh({0, 0, 0}, {1, 1, 1});
  write_file_atomic(dir + "/still.glb", encode_morph_glb(still));
  PoseExtractOptions any;
  any.animation = "0";
  try {
    pose_extract_files(dir + "/still.glb", dir + "/out", any, Log::silent(), report);
    ADD_FAILURE() << "no clip accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ExitCode::bad_input);
    EXPECT_NE(std::string(e.what()).find("has no animation clips"), std::string::npos) << e.what();
  }
}

// The bytes of element `i` of `file`'s accessor `index` (its view's stride, or packed `width`).
char* element_bytes(GltfFile& file, size_t index, size_t i, size_t width) {
  const json& accessor = file.doc["accessors"][index];
  const json& view = file.doc["bufferViews"][accessor["bufferView"].get<size_t>()];
  const size_t begin = view.value("byteOffset", size_t(0)) + accessor.value("byteOffset", size_t(0));
  return file.bin.data() + begin + i * view.value("byteStride", width);
}

// A skin may leave out its inverseBindMatrices: glTF reads them as identities. assimp 5.2 crashed
// on such a file (a segmentation fault, from pose-extract and from sdf-build alike). RiggedSimple
// with its matrices made identities, given, and the same file without them give the same poses,
// byte for byte.
// KHR_animation_pointer: a pointer to a node's rotation is that rotation's channel; one to a
// material's colour moves no geometry and is named as passed over, as is a channel with no node.
// assimp read the first two as translations and failed the whole file (the mesh loader too), and
// dropped the third without a word. Morph weights on a joint move nothing either, and are not
// counted as morph channels the skin cannot follow (pose-extract warned so).
TEST(PoseExtract, AnimationPointerChannelsAreHonouredOrPassedOverByName) {
  SPX_REQUIRE_SHARED_DATA();
  const std::string dir = test::temp_dir("extract-animation-pointer");
  const GltfFile good = read_gltf_file(test::shared_data() + "/rigged-simple/RiggedSimple.glb");
  const auto pointer = [](const std::string& to) {
    return json{{"path", "pointer"}, {"extensions", {{"KHR_animation_pointer", {{"pointer", to}}}}}};
  };
  const auto required = [](GltfFile& f) { f.doc["extensionsRequired"] = f.doc["extensionsUsed"] = {"KHR_animation_pointer"}; };
  PoseExtractOptions clip;
  clip.animation = "0";
  const auto extract = [&](const GltfFile& file, const std::string& name, json& report) {
    write_file_atomic(dir + "/" + name + ".glb", encode_glb(file));
    pose_extract_files(dir + "/" + name + ".glb", dir + "/" + name, clip, Log::silent(), report);
    return vertex_lines(dir + "/" + name + "/pose-00.obj") + vertex_lines(dir + "/" + name + "/pose-01.obj");
  };
  json report;
  const std::string poses = extract(good, "good", report);
  const auto passed_over = [&] { return report["asset"]["clips"][0]["channels_passed_over"]; };
  EXPECT_EQ(passed_over(), json::array());

  GltfFile rotation = good;  // channel 4 moves nodes[3]'s rotation
  rotation.doc["animations"][0]["channels"][4]["target"] = pointer("/nodes/3/rotation");
  required(rotation);
  EXPECT_EQ(extract(rotation, "rotation", report), poses);
  EXPECT_EQ(passed_over(), json::array());

  GltfFile colour = good;  // a VEC4 sampler on the base colour
  colour.doc["animations"][0]["samplers"].push_back({{"input", 9}, {"output", 11}});
  colour.doc["animations"][0]["channels"].push_back(
      {{"sampler", 6}, {"target", pointer("/materials/0/pbrMetallicRoughness/baseColorFactor")}});
  required(colour);
  EXPECT_EQ(extract(colour, "colour", report), poses);
  EXPECT_EQ(passed_over(), json::array({"animations[0].channels[6] (KHR_animation_pointer "
                                        "'/materials/0/pbrMetallicRoughness/baseColorFactor')"}));
  EXPECT_EQ(load_mesh(dir + "/colour.glb").mesh.triangles.size(), 188u);

  GltfFile no_node = good;
  no_node.doc["animations"][0]["channels"][4]["target"].erase("node");
  EXPECT_NE(extract(no_node, "no-node", report), poses);  // the rotation is not followed
  EXPECT_EQ(passed_over(), json::array({"animations[0].channels[4] (no target node)"}));

  GltfFile joint_weights = good;  // morph weights on a joint, which has no mesh: nothing moves
  joint_weights.doc["animations"][0]["samplers"].push_back({{"input", 9}, {"output", 9}});
  joint_weights.doc["animations"][0]["channels"].push_back({{"sampler", 6}, {"target", {{"node", 2}, {"path", "weights"}}}});
  EXPECT_EQ(extract(joint_weights, "joint-weights", report), poses);
  EXPECT_EQ(report["asset"]["clips"][0]["morph_channels"], 0);  // no warning that the skin cannot follow them

  GltfFile past = rotation;
  past.doc["animations"][0]["channels"][4]["target"] = pointer("/nodes/9/rotation");
  const std::string error = test::bad_input_error([&] { extract(past, "past", report); });
  EXPECT_NE(error.find("past.glb: animations[0].channels[4].target's KHR_animation_pointer '/nodes/9/rotation' names "
                       "a node past the file's 5"),
            std::string::npos)
      << error;

  GltfFile only_colour = colour;  // a clip of the colour alone, before the walk
  json& clips = only_colour.doc["animations"];
  clips.insert(clips.begin(), json{{"samplers", {{{"input", 9}, {"output", 11}}}},
                                   {"channels", {{{"sampler", 0}, {"target", pointer("/materials/0/emissiveFactor")}}}}});
  const std::string none = test::bad_input_error([&] { extract(only_colour, "only-colour", report); });
  EXPECT_NE(none.find("only-colour.glb: clip 'clip0' has no keys that move a node or morph weights"), std::string::npos)
      << none;
  clip.animation = "1";  // the clips keep their indices
  EXPECT_EQ(extract(only_colour, "second", report), poses);
}

// A joint scaled to nothing (or past a float's range) in the rest collapses the part it moves:
// the rest was welded into another body (RiggedSimple's 96 vertices into 65) and every pose
// warned that the welded vertices parted. A joint scaled small, not flat, is a body still.
TEST(PoseExtract, RestThatCollapsesAJointIsAnError) {
  SPX_REQUIRE_SHARED_DATA();
  const std::string dir = test::temp_dir("extract-collapsed-rest");
  const GltfFile good = read_gltf_file(test::shared_data() + "/rigged-simple/RiggedSimple.glb");
  PoseExtractOptions clip;
  clip.animation = "0";
  json report;
  const auto run = [&](const std::function<void(GltfFile&)>& change, const std::string& name) {
    GltfFile file = good;
    change(file);
    write_file_atomic(dir + "/" + name + ".glb", encode_glb(file));
    pose_extract_files(dir + "/" + name + ".glb", dir + "/" + name, clip, Log::silent(), report);
  };
  const std::string said = "the rest (the nodes' own transforms, the asset without a clip) collapses 32 vertices: joint ";
  for (const json& scale : {json{0, 0, 0}, json{1, 0, 1}, json{1e300, 1, 1}}) {  // the last: infinite as a float
    const std::string error = test::bad_input_error([&] { run([&](GltfFile& f) { f.doc["nodes"][3]["scale"] = scale; }, "flat"); });
    EXPECT_NE(error.find("flat.glb: " + said), std::string::npos) << error;
  }
  const std::string zeros = test::bad_input_error([&] {
    run([](GltfFile& f) { std::memset(element_bytes(f, 13, 1, 64), 0, 64); }, "zero-bind");  // joint 1's matrix
  });
  EXPECT_NE(zeros.find("zero-bind.glb: " + said), std::string::npos) << zeros;
  run([](GltfFile& f) { f.doc["nodes"][3]["scale"] = {1e-3, 1e-3, 1e-3}; }, "small");
  EXPECT_EQ(report["output"]["vertices"], 96);
}

TEST(PoseExtract, SkinWithoutBindMatricesReadsAsIdentities) {
  SPX_REQUIRE_SHARED_DATA();
  const std::string dir = test::temp_dir("extract-no-bind-matrices");
  GltfFile given = read_gltf_file(test::shared_data() + "/rigged-simple/RiggedSimple.glb");
  const size_t matrices = given.doc["skins"][0]["inverseBindMatrices"].get<size_t>();
  for (size_t j = 0; j < given.doc["skins"][0]["joints"].size(); ++j)
    for (int k = 0; k < 16; ++k) {
      const float v = k % 5 == 0 ? 1.0f : 0.0f;
      std::memcpy(element_bytes(given, matrices, j, 64) + 4 * k, &v, 4);
    }
  GltfFile left_out = given;
  left_out.doc["skins"][0].erase("inverseBindMatrices");
  write_file_atomic(dir + "/given.glb", encode_glb(given));
  write_file_atomic(dir + "/left-out.glb", encode_glb(left_out));
  PoseExtractOptions clip;
  clip.animation = "0";
  json report;
  for (const char* name : {"given", "left-out"})
    pose_extract_files(dir + "/" + name + ".glb", dir + "/" + name, clip, Log::silent(), report);
  size_t poses = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir + "/given")) {
    if (entry.path().extension() != ".obj") continue;
    const std::string name = entry.path().filename().string();
    // The first line names the file it came from.
    auto body = [](std::string text) { return text.substr(text.find('\n')); };
    EXPECT_EQ(body(read_file(entry.path().string())), body(read_file(dir + "/left-out/" + name))) << name;
    ++poses;
  }
  EXPECT_GE(poses, 3u);
  EXPECT_EQ(read_file(dir + "/given/skin.json"), read_file(dir + "/left-out/skin.json"));
  EXPECT_NO_THROW(load_mesh(dir + "/left-out.glb"));
}

// glTF files that break a rule of the spec, each one rule: assimp 5.2 read most of them as
// another body without a word (a skin's matrices read past their accessor as numbers like 7e31,
// a node with two parents moved twice, a skin past the list dropped and the body left rigid, a
// clip's missing values or backward times read as other keys) and crashed on a skin without
// joints. Each is now one error line naming the member, exit 2, with no poses written; the file
// unbroken still reads.
TEST(PoseExtract, GltfRulesBrokenAreNamedErrors) {
  SPX_REQUIRE_SHARED_DATA();
  const std::string dir = test::temp_dir("extract-gltf-rules");
  const GltfFile good = read_gltf_file(test::shared_data() + "/rigged-simple/RiggedSimple.glb");
  const auto poke_float = [](GltfFile& f, size_t accessor, size_t i, float v) {
    std::memcpy(element_bytes(f, accessor, i, 4), &v, 4);
  };
  struct Case {
    const char* said;
    std::function<void(GltfFile&)> broken;
  };
  const std::vector<Case> cases{
      {"skins[0] has no joints", [](GltfFile& f) { f.doc["skins"][0].erase("joints"); }},
      {"skins[0] has no joints", [](GltfFile& f) { f.doc["skins"][0]["joints"] = json::array(); }},
      {"skins[0].joints lists node 2 twice", [](GltfFile& f) { f.doc["skins"][0]["joints"] = {2, 2}; }},
      {"skins[0].joints[1] is 9, not one of the file's 5 nodes", [](GltfFile& f) { f.doc["skins"][0]["joints"][1] = 9; }},
      {"skins[0].inverseBindMatrices (accessor 13) holds 1 matrix for 2 joints",
       [](GltfFile& f) { f.doc["accessors"][13]["count"] = 1; }},
      {"skins[0].inverseBindMatrices (accessor 13) is not MAT4 floats",
       [](GltfFile& f) { f.doc["accessors"][13]["type"] = "VEC4"; }},
      {"nodes[1].skin is 1, and the file has 1 skin", [](GltfFile& f) { f.doc["nodes"][1]["skin"] = 1; }},
      {"nodes[2] is a child of both nodes[1] and nodes[4]", [](GltfFile& f) { f.doc["nodes"][1]["children"] = {2}; }},
      {"nodes[2] is its own ancestor",  // 2 -> 3 -> 4 -> 2, no other parent
       [](GltfFile& f) {
         f.doc["nodes"][0]["children"] = {1};
         f.doc["nodes"][3]["children"] = {4};
       }},
      {"vertex 0 of meshes[0].primitives[0] is weighted to joint 7 (JOINTS_0), past skins[0]'s 2 joints",
       [](GltfFile& f) {
         const uint16_t seven = 7;
         std::memcpy(element_bytes(f, 1, 0, 8), &seven, 2);
         const float one = 1;
         std::memcpy(element_bytes(f, 4, 0, 16), &one, 4);
       }},
      {"animations[0].channels[4].sampler is 6, and its clip has 6 samplers",
       [](GltfFile& f) { f.doc["animations"][0]["channels"][4]["sampler"] = 6; }},
      {"animations[0].samplers[1]: 2 values (accessor 7) for 3 key times (accessor 5), where 3 are due",
       [](GltfFile& f) { f.doc["accessors"][7]["count"] = 2; }},
      {"animations[0].samplers[1].output (accessor 6) is VEC3; a channel moving rotation takes VEC4",
       [](GltfFile& f) { f.doc["animations"][0]["samplers"][1]["output"] = 6; }},
      {"animations[0].samplers[3]: key time 2 (0.5 s) comes before key time 1",
       [poke_float](GltfFile& f) { poke_float(f, 9, 2, 0.5f); }},
      {"animations[0].samplers[3]: key time 1 is not a finite number",
       [poke_float](GltfFile& f) { poke_float(f, 9, 1, std::nanf("")); }},
      // assimp dropped a short attribute or target whole, and the indices past the last triangle.
      {"meshes[0].primitives[0].attributes.WEIGHTS_0 (accessor 4) holds 95 elements for the primitive's 96 vertices "
       "(its POSITION's count)",
       [](GltfFile& f) { f.doc["accessors"][4]["count"] = 95; }},
      {"meshes[0].primitives[0].targets[0].POSITION (accessor 13) holds 2 elements for the primitive's 96 vertices",
       [](GltfFile& f) { f.doc["meshes"][0]["primitives"][0]["targets"] = json::array({{{"POSITION", 13}}}); }},
      {"meshes[0].primitives[0].indices (accessor 0) holds 563 indices, not a whole number of triangles (3 each)",
       [](GltfFile& f) { f.doc["accessors"][0]["count"] = 563; }},
      {"mesh 'Cylinder': joint 'nodes[5]' is no node of the scene's tree (a joint outside the scene the file shows)",
       [](GltfFile& f) {
         f.doc["nodes"].push_back(json::object());
         f.doc["skins"][0]["joints"][1] = 5;
       }},
  };
  PoseExtractOptions clip;
  clip.animation = "0";
  json report;
  write_file_atomic(dir + "/good.glb", encode_glb(good));
  EXPECT_NO_THROW(pose_extract_files(dir + "/good.glb", dir + "/good", clip, Log::silent(), report));
  for (size_t c = 0; c < cases.size(); ++c) {
    GltfFile broken = good;
    cases[c].broken(broken);
    const std::string glb = dir + "/broken-" + std::to_string(c) + ".glb", out = dir + "/out-" + std::to_string(c);
    write_file_atomic(glb, encode_glb(broken));
    const std::string error = test::bad_input_error([&] { pose_extract_files(glb, out, clip, Log::silent(), report); });
    EXPECT_NE(error.find(glb + ": " + cases[c].said), std::string::npos) << error;
    EXPECT_FALSE(std::filesystem::exists(out + "/poses.json")) << cases[c].said;
  }
}

// What the proxy calls the poses: the manifest's names, a repeated one made unique as the files
// are, or without a manifest the files' stems.
TEST(PoseExtract, PoseNamesAreTheManifestsOrTheStems) {
  const std::string dir = test::temp_dir("pose-names");
  PoseManifest m;
  m.poses = {{"walk@1s", "pose-00.obj", {}}, {"Key 1", "Key_1.obj", {}}, {"Key 1", "Key_1-2.obj", {}}};
  write_file_atomic(dir + "/poses.json", manifest_to_json(m).dump());
  const std::vector<std::string> files = {dir + "/pose-00.obj", dir + "/Key_1.obj", dir + "/Key_1-2.obj"};
  EXPECT_EQ(pose_names(dir + "/poses.json", files), (std::vector<std::string>{"walk@1s", "Key 1", "Key 1-2"}));
  EXPECT_EQ(pose_names("", files), (std::vector<std::string>{"pose-00", "Key_1", "Key_1-2"}));
}

// A split mesh's midpoints weighed by their ends half and half: each list sums to 1 in ascending
// joints, and its blend of any joint matrices is the average of its ends' blends (so a midpoint
// moves as the midpoint of its ends' skinned places), ends added by an earlier split included.
TEST(SkinFile, MidpointWeightsBlendTheirEndsHalfAndHalf) {
  std::vector<JointWeights> weights = {{{0, 1.0}}, {{2, 0.25}, {0, 0.75}}, {{1, 0.5}, {2, 0.5}}};
  const std::vector<std::pair<int, int>> ends = {{0, 1}, {1, 2}, {3, 4}, {2, 0}};
  append_midpoint_weights(weights, ends);
  ASSERT_EQ(weights.size(), 7u);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  JointMatrices m(3);
  for (Eigen::Matrix4d& j : m) {
    j = Eigen::Matrix4d::Identity();
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) j(r, c) = u(rng);
  }
  auto blend = [&](const JointWeights& w) {
    Eigen::Matrix4d sum = Eigen::Matrix4d::Zero();
    for (const auto& [j, weight] : w) sum += weight * m[size_t(j)];
    return sum;
  };
  for (size_t k = 0; k < ends.size(); ++k) {
    const JointWeights& w = weights[3 + k];
    double total = 0;
    for (size_t n = 0; n < w.size(); ++n) {
      total += w[n].second;
      if (n > 0) EXPECT_LT(w[n - 1].first, w[n].first) << "midpoint " << k;
    }
    EXPECT_NEAR(total, 1.0, 1e-15) << "midpoint " << k;
    const auto [a, b] = ends[k];
    EXPECT_LT((blend(w) - 0.5 * (blend(weights[size_t(a)]) + blend(weights[size_t(b)]))).norm(), 1e-14) << "midpoint " << k;
  }
  EXPECT_EQ(weights[3], (JointWeights{{0, 0.875}, {2, 0.125}}));
}

}  // namespace
}  // namespace spx
