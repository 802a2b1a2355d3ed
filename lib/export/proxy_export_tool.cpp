#include "export/proxy_export_tool.hpp"

#include <filesystem>

#include "core/atomic_file.hpp"
#include "core/error.hpp"
#include "core/subject.hpp"
#include "io/spx_writer.hpp"
#include "io/scene.hpp"
#include "metrics/proxy_eval_tool.hpp"
#include "io/proxy_file.hpp"

namespace spx {

namespace {

// The sphere unions with each pose's mesh coloured by its vertex error (as proxy-eval --colors).
std::string colored_preview(const ProxyModel& proxy, const std::string& input, const std::string& ext,
                            const ExportOptions& options, Log& log) {
  const std::vector<TriMesh> meshes = load_pose_meshes(options.rest, options.poses, proxy, input, log);
  std::vector<PoseError> evals;
  double scale = 0;
  for (size_t i = 0; i < meshes.size(); ++i) {
    PoseError e{proxy.poses[i].name, meshes[i], proxy.poses[i].spheres, {}};
    e.vertex_error = union_signed_distance(e.mesh.vertices, e.spheres);
    for (double d : e.vertex_error) scale = std::max(scale, std::abs(d));
    evals.push_back(std::move(e));
  }
  const double step = options.spread ? 1.25 * meshes[0].bounds().sizes().x() : 0.0;
  return encode_error_scene(evals, ext, options.pose, scale, step);
}

}  // namespace

void proxy_export_files(const std::string& input, const std::string& output, const ExportOptions& options, Log& log,
                  json& report) {
  std::string ext = std::filesystem::path(output).extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  if (ext != ".spx" && ext != ".json" && ext != ".glb" && ext != ".ply")
    fail_usage(output, "unknown output format '" + ext + "' (use .spx, .json, .glb or .ply)");
  const ProxyModel proxy = read_proxy_file(input);
  std::string bytes;
  about_file(input, [&] {
    if (ext == ".spx") bytes = encode_spx(proxy);
    else if (ext == ".json") bytes = dump_json(proxy_to_plain_json(proxy));
    else if (options.rest.empty()) bytes = encode_preview(proxy, ext, options.pose, options.spread);
    else bytes = colored_preview(proxy, input, ext, options, log);
  });
  write_file_atomic(output, bytes);
  log.info(output + ": " + std::to_string(bytes.size()) + " bytes, " + std::to_string(proxy.sphere_count()) +
           " spheres x " + std::to_string(proxy.poses.size()) + " poses");
  report["input"] = input;
  report["output"] = output;
  report["format"] = ext.substr(1);
  report["bytes"] = bytes.size();
  report["sphere_count"] = proxy.sphere_count();
  report["pose_count"] = proxy.poses.size();
}

}  // namespace spx
