// character-host: a rigged body plays its clip in Bullet, its collision shape the proxy's spheres
// skinned each frame by the clip's joint matrices, while boxes and balls fall on it.
//   character-host BODY.spx --asset ASSET.glb [--animation N] [--seconds S] [--objects K]
//                  [--json OUT.json]
#include <cstdio>

#include "character_host.hpp"
#include "core/json_io.hpp"
#include "core/error.hpp"
#include "core/version.hpp"
#include "extract/asset.hpp"
#include "tool/tool.hpp"

using namespace spx;

int main(int argc, char** argv) {
  Tool tool("character-host", "A rigged body plays its clip in Bullet, its spheres skinned every frame, while "
                              "objects fall on it.");
  std::string proxy_path, asset_path, animation = "0", out_path;
  character::SceneOptions opt;
  tool.app.add_option("proxy", proxy_path, ".spx with a skin (proxy-export of a rigged body's proxy)")->required();
  tool.app.add_option("--asset", asset_path, "The rigged asset the proxy was made from (glTF, FBX, ...)")->required();
  tool.app.add_option("--animation", animation, "Clip to play, by name or index")->capture_default_str();
  tool.app.add_option("--seconds", opt.seconds, "Simulated time")->check(CLI::Range(0.1, 600.0))->capture_default_str();
  tool.app.add_option("--objects", opt.objects, "Boxes and balls dropped on the body")->check(CLI::Range(0, 10000))
      ->capture_default_str();
  tool.app.add_option("--height", opt.body_height, "The body's height in metres (the asset is scaled to it)")
      ->check(spx::kPositive)->capture_default_str();
  tool.app.add_option("--seed", opt.seed, "Where the objects are dropped")->capture_default_str();
  tool.app.add_option("--json", out_path, "Write the results here");
  return tool.run(argc, argv, [&] {
    Proxy proxy;
    if (const Status s = load_file(proxy_path.c_str(), &proxy); s != SPX_OK) fail_input(proxy_path, status_string(s));
    const Asset asset(asset_path, "");
    opt.clip = asset.find_clip(animation);
    const character::RunStats r = character::run_scene(asset, proxy, opt);
    char line[256];
    std::snprintf(line, sizeof line, "%u spheres, %u joints, clip of %.2f s played for %d frames", proxy.sphere_count(),
                proxy.joint_count(), r.clip_seconds, r.frames);
    tool.log.info(line);
    std::snprintf(line, sizeof line, "per frame (median ms): animation %.3f, skin %.4f, step %.3f", r.animate_ms,
                  r.skin_ms, r.step_ms);
    tool.log.info(line);
    std::snprintf(line, sizeof line, "objects: %d dropped, %d on the body at the end, %d off it; %d frames with contact",
                r.objects_dropped, r.objects_on_body, r.objects_fell_off, r.frames_with_contact);
    tool.log.info(line);
    std::snprintf(line, sizeof line,
                  "contacts against the skinned mesh: %llu checked, median %.4f m, max %.4f m from its surface",
                static_cast<unsigned long long>(r.contacts_checked), r.contact_to_mesh_median, r.contact_to_mesh_max);
    tool.log.info(line);
    json result = {{"generator", std::string("character-host (spx) ") + version_string()},
                   {"proxy", proxy_path},
                   {"asset", asset_path},
                   {"spheres", proxy.sphere_count()},
                   {"joints", proxy.joint_count()},
                   {"clip_seconds", r.clip_seconds},
                   {"frames", r.frames},
                   {"dt_s", opt.dt},
                   {"per_frame_ms_median", {{"animation", r.animate_ms}, {"skin", r.skin_ms}, {"step", r.step_ms}}},
                   {"objects", {{"dropped", r.objects_dropped}, {"on_body", r.objects_on_body},
                                {"off_body", r.objects_fell_off}}},
                   {"body_contacts", r.body_contacts},
                   {"frames_with_contact", r.frames_with_contact},
                   {"contacts_checked", r.contacts_checked},
                   {"contact_to_mesh_m", {{"median", r.contact_to_mesh_median}, {"max", r.contact_to_mesh_max}}},
                   {"zero_radius_spheres", r.zero_radius_spheres}};
    if (!out_path.empty()) write_json_atomic(out_path, result);
    tool.report = result;
  });
}
