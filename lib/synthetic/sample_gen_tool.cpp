#include "synthetic/sample_gen_tool.hpp"

#include <filesystem>

#include "core/atomic_file.hpp"
#include "core/error.hpp"
#include "synthetic/synthetic.hpp"

namespace spx {
namespace {

void create_folder(const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) fail_write(dir, "cannot create folder: " + ec.message());
}

}  // namespace

void sample_gen_files(const std::string& name, const std::string& dir, Log& log, json& report) {
  if (name == "robot") {
    create_folder(dir);
    const RigAsset robot = make_robot();
    write_file_atomic(dir + "/robot.glb", encode_rig_glb(robot));
    size_t triangles = 0;
    for (const RigPart& p : robot.parts) triangles += p.mesh.triangles.size();
    log.info(dir + ": robot.glb, " + std::to_string(robot.parts.size()) + " open parts on " +
             std::to_string(robot.joints.size()) + " joints, " + std::to_string(triangles) + " triangles, a " +
             std::to_string(robot.times.size()) + "-key walk");
    report["triangles"] = triangles;
    report["parts"] = robot.parts.size();
    report["joints"] = robot.joints.size();
    report["asset"] = "robot.glb";
    return;
  }
  const SampleAsset asset = make_sample(name);
  create_folder(dir);
  // The OBJ files hold exactly what the glTF holds (single precision), so the chain run on the
  // OBJ poses and on pose-extract's reading of the glTF sees the same numbers.
  const MorphAsset morph = morph_asset(asset);
  const std::string tag = "spx sample " + name;
  TriMesh mesh = asset.rest;
  mesh.vertices = stored_base(morph);
  write_file_atomic(dir + "/rest.obj", to_obj(mesh, tag + " rest pose"));
  for (size_t i = 0; i < asset.pose_names.size(); ++i) {
    mesh.vertices = stored_target(morph, i);
    write_file_atomic(dir + "/" + asset.pose_names[i] + ".obj", to_obj(mesh, tag + " pose " + asset.pose_names[i]));
  }
  write_file_atomic(dir + "/" + name + "-morph.glb", encode_morph_glb(morph));
  log.info(dir + ": rest + " + std::to_string(asset.pose_names.size()) + " poses (OBJ, and " + name +
           "-morph.glb with them as morph targets), " + std::to_string(asset.rest.triangles.size()) + " triangles");
  report["triangles"] = asset.rest.triangles.size();
  report["poses"] = asset.pose_names;
  report["morph_asset"] = name + "-morph.glb";
}

}  // namespace spx
