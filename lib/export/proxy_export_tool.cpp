#include "export/proxy_export_tool.hpp"

#include <algorithm>
#include <filesystem>

#include "core/atomic_file.hpp"
#include "core/error.hpp"
#include "core/file_kind.hpp"
#include "core/format.hpp"
#include "core/subject.hpp"
#include "io/spx_writer.hpp"
#include "metrics/rest_match.hpp"
#include "export/page_html.hpp"
#include "export/physics_gltf.hpp"
#include "extract/asset.hpp"
#include "io/scene.hpp"
#include "metrics/proxy_eval_tool.hpp"
#include "io/pose_manifest.hpp"
#include "io/proxy_file.hpp"

namespace spx {

namespace {

// The sphere unions with each pose's mesh coloured by its vertex error (as proxy-eval --colors).
std::string colored_preview(const ProxyModel& proxy, const std::string& input, const std::string& ext,
                            const ExportOptions& options, Log& log) {
  const std::vector<TriMesh> meshes = load_pose_meshes(options.rest, options.poses, proxy, input, log, options.manifest);
  std::vector<PoseError> evals;
  double scale = 0;
  for (size_t i = 0; i < meshes.size(); ++i) {
    PoseError e{proxy.poses[i].name, meshes[i], proxy.poses[i].spheres, {}};
    e.vertex_error = union_signed_distance(e.mesh.vertices, e.spheres);
    for (double d : e.vertex_error) scale = std::max(scale, std::abs(d));
    evals.push_back(std::move(e));
  }
  const double step = options.stacked ? 0.0 : 1.25 * meshes[0].bounds().sizes().x();
  return encode_error_scene(evals, ext, std::max(options.pose, 0), scale, step);
}

// The colliders as glTF physics shapes, alone or in the asset; what was left out in the report.
std::string physics_glb(const ProxyModel& proxy, const ExportOptions& options, Log& log, json& report) {
  PhysicsGltf out;
  if (options.asset.empty()) {
    out = physics_gltf(proxy);
  } else {
    GltfFile file = read_gltf_file(options.asset);  // first: "not a glTF" before assimp's words
    const Asset rig(options.asset, "");
    out = physics_gltf(proxy, std::move(file), rig);
    if (!proxy.skin.empty()) {
      json clips = json::array();
      for (size_t c = 0; c < rig.clips().size(); ++c) clips.push_back(rigid_attachment_offsets(proxy, rig, c, out.diagonal));
      out.attachment["rigid_against_skinned"] = clips;
    }
  }
  if (!out.zero_radius.empty())
    log.info(std::to_string(out.zero_radius.size()) + " spheres of radius 0 at rest left out (report: physics.zero_radius)");
  report["physics"] = {{"colliders", out.colliders},
                       {"zero_radius", out.zero_radius.size()},
                       {"zero_radius_spheres", out.zero_radius},
                       {"extensions_used", out.file.doc["extensionsUsed"]},
                       {"asset", options.asset.empty() ? json(nullptr) : json(options.asset)}};
  if (!out.attachment.is_null()) report["physics"]["attachment"] = out.attachment;
  return encode_glb(out.file);
}

// The page: the proxy with its body (the examples' meshes, or a skinned proxy's asset) when given.
std::string page(const ProxyModel& proxy, const std::string& input, const std::string& output,
                 const ExportOptions& options, Log& log, json& report) {
  std::string up = options.up;
  if (up.empty()) up = options.asset.empty() && options.manifest.empty() ? "z" : "y";
  json data = page_data(proxy, std::filesystem::path(input).stem().stem().string(), up);
  size_t zero = 0;
  for (const Sphere& s : proxy.poses.at(0).spheres) zero += !(s.radius > 0);
  json page = {{"up", up}, {"body", "none"}, {"clips", json::array()}, {"zero_radius", zero}};
  if (!options.asset.empty()) {
    if (proxy.skin.empty())
      fail_usage("--asset", "with .html plays a skinned proxy's clips; " + input +
                                " has no skin: give its examples with --rest/--pose or --manifest");
    const Asset rig(options.asset, options.mesh);
    const WeldedBody body = weld_body(rig);
    check_rest_holds(proxy, body.rest, options.asset);
    add_skinned_body(data, proxy, rig, body);
    page["body"] = "asset";
    page["mesh"] = options.mesh.empty() ? json(nullptr) : json(options.mesh);
    page["meshes_without_spheres"] = warn_meshes_without_spheres(proxy, rig, "the page shows them uncovered", log);
    page["influences_cut"] = data["body"]["influences_cut"];
    for (const json& c : data["clips"])
      page["clips"].push_back({{"name", c["name"]}, {"frames", c["frames"]}, {"seconds", c["seconds"]}});
  } else if (!options.rest.empty()) {
    add_blended_body(data, proxy, load_pose_meshes(options.rest, options.poses, proxy, input, log, options.manifest));
    page["body"] = "examples";
    // Morph targets are played as the host plays them: a slider per target, added up.
    const bool morph = !options.manifest.empty() && poses_are_morph_targets(read_pose_manifest(options.manifest));
    data["morph"] = morph;
    page["morph_targets"] = morph;
  } else {
    log.warn("no body given: the page shows the spheres alone (--rest/--pose, --manifest or --asset adds the body "
             "and its error)");
  }
  if (!data["body"].is_null()) page["vertices"] = data["body"]["vertex_count"];
  report["page"] = page;
  return page_html(data, output);
}

}  // namespace

void proxy_export_files(const std::string& input, const std::string& output, const ExportOptions& options, Log& log,
                  json& report) {
  const std::string ext = lower_extension(output);
  if (options.physics && ext != ".glb")
    fail_usage("--physics", "writes glTF physics shapes: the output must be .glb, not '" + ext + "'");
  if (!options.asset.empty() && !options.physics && ext != ".html")
    fail_usage("--asset", "needs --physics (a .glb) or a .html page");
  if (!options.mesh.empty() && (options.asset.empty() || options.physics))
    fail_usage("--mesh", "is for a .html page with --asset");
  if (!options.asset.empty() && !options.rest.empty())
    fail_usage("--asset", "gives the body: leave out --rest/--pose/--manifest");
  if (!options.up.empty() && ext != ".html") fail_usage("--up", "is for a .html page");
  if (options.pose >= 0 && ext != ".ply") fail_usage("--ply-pose", "is for a .ply output (one pose)");
  if (options.stacked && (ext != ".glb" || options.physics)) fail_usage("--stacked", "is for a .glb of sphere meshes");
  if (!options.up.empty() && options.up != "y" && options.up != "z") fail_usage("--up", "must be y or z");
  if (ext != ".spx" && ext != ".json" && ext != ".glb" && ext != ".ply" && ext != ".html")
    fail_usage(output, "unknown output format '" + ext + "' (use .spx, .json, .glb, .ply or .html)");
  const ProxyModel proxy = read_proxy_file(input);
  std::string bytes;
  if (options.physics) bytes = physics_glb(proxy, options, log, report);
  else if (ext == ".html") bytes = page(proxy, input, output, options, log, report);
  else about_file(input, [&] {
    if (ext == ".spx") bytes = encode_spx(proxy);
    else if (ext == ".json") bytes = dump_json(proxy_to_plain_json(proxy));
    else if (options.rest.empty()) bytes = encode_preview(proxy, ext, std::max(options.pose, 0), !options.stacked);
    else bytes = colored_preview(proxy, input, ext, options, log);
  });
  write_file_atomic(output, bytes);
  log.info(output + ": " + std::to_string(bytes.size()) + " bytes, " + counted(proxy.sphere_count(), "sphere") + " x " +
           counted(proxy.poses.size(), "pose"));
  report["input"] = input;
  report["output"] = output;
  report["format"] = ext.substr(1);
  report["bytes"] = bytes.size();
  report["sphere_count"] = proxy.sphere_count();
  report["pose_count"] = proxy.poses.size();
}

}  // namespace spx
