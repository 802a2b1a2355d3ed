#include "posemap/pose_map_tool.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <stdexcept>

#include "core/error.hpp"
#include "core/format.hpp"
#include "core/pose_lines.hpp"
#include "core/side_by_side.hpp"
#include "core/subject.hpp"
#include "posemap/skinned_map.hpp"

namespace spx {
namespace {

// Pose k must be where the skin takes the rest with that pose's joint matrices (each vertex back
// to the asset's space by its blended rest matrix, then blended by the pose's): a pose set that
// mixes a clip's frames with other meshes is refused naming the first that is not.
void check_pose_is_skinned(const SkinFile& skin, const SkinnedVertices& skinned, const PoseInput& pose, size_t k,
                           double tolerance, const std::string& path) {
  for (size_t v = 0; v < pose.mesh.vertices.size(); ++v) {
    if (!skinned.bound(v)) continue;  // no joint weighs it: it keeps its bind position
    const double off = (skinned.at(v, skin.poses[k].matrices) - pose.mesh.vertices[v]).norm();
    if (off > tolerance)
      fail_input(pose.source, "is not the skin of its joint matrices in " + path + " (pose " + std::to_string(k + 1) +
                                  " '" + skin.poses[k].name + "': vertex " + std::to_string(v) + " is " + num(off) +
                                  " away): every pose must come with the rig, or none");
  }
}

// `skin`, read from `path`, matched to the rest mesh and the poses: weights found for every
// rest vertex (by its position, whatever order the mesh was read in), a pose each, and each pose
// the skin of its joint matrices.
void match_skin(SkinFile& skin, const std::string& path, const TriMesh& rest, const std::vector<PoseInput>& poses) {
  // Positions went through OBJ text (9 significant digits): a little of the diagonal, and of the
  // coordinates' size for a body far from the origin.
  double far = 0;
  for (const auto& p : rest.vertices) far = std::max(far, p.cwiseAbs().maxCoeff());
  const double tolerance = 1e-6 * rest.diagonal() + 1e-8 * far;
  skin.vertex_weights = weights_for_vertices(skin, rest.vertices, tolerance, path);
  skin.vertex_positions = rest.vertices;
  if (skin.poses.size() != poses.size())
    fail_input(path, "holds the joint matrices of " + std::to_string(skin.poses.size()) + " poses; " +
                         std::to_string(poses.size()) + " poses are given (every pose must come with the rig, or none)");
  if (skin.morph_channels == 0) {  // a clip that also drives morph weights is more than its skin
    const SkinnedVertices skinned(skin, rest.vertices);
    for (size_t k = 0; k < poses.size(); ++k) check_pose_is_skinned(skin, skinned, poses[k], k, 10 * tolerance, path);
  }
}

struct PoseMapInputs {
  LoadedMesh rest;
  std::vector<PoseInput> poses;
  SpheresFile spheres;
  SkinFile skin;
};

// The input files, the poses, spheres and skin read side by side (they do not depend on one
// another); a failure is reported as reading them one after another would report it.
PoseMapInputs read_inputs(const std::string& rest_path, const std::vector<std::string>& pose_paths,
                          std::vector<std::string> names, const std::string& spheres_path,
                          const std::string& skin_path, Log& log) {
  PoseMapInputs in;
  in.rest = load_mesh(rest_path);
  if (names.empty()) {
    std::set<std::string> stems;
    for (const auto& path : pose_paths) {
      if (!stems.insert(stem_of(path)).second) fail_usage(path, "two poses are named '" + stem_of(path) + "'");
      names.push_back(stem_of(path));
    }
  }
  std::vector<TriMesh> meshes;
  side_by_side([&] { meshes = load_poses(pose_paths, in.rest); }, [&] { in.spheres = read_spheres_file(spheres_path); },
               [&] {
                 if (!skin_path.empty()) in.skin = read_skin_file(skin_path);
               });
  for (size_t i = 0; i < pose_paths.size(); ++i) {
    PoseInput pose{names[i], pose_paths[i], std::move(meshes[i])};
    // A pose at another scale is most likely another unit (cm vs m).
    const double ratio = pose.mesh.diagonal() / in.rest.mesh.diagonal();
    if (ratio > 3 || ratio < 1.0 / 3)
      log.warn(pose.source + ": its size is " + num(ratio) + "x the rest mesh's; is it in another unit?");
    in.poses.push_back(std::move(pose));
  }
  // Read coarser than the spheres' voxel, a pose's field and candidates would follow the reading.
  check_read_rounding(in.rest.mesh, in.spheres.voxel_size, rest_path, log);
  const auto coarsest = std::max_element(in.poses.begin(), in.poses.end(), [](const PoseInput& a, const PoseInput& b) {
    return read_rounding(a.mesh) < read_rounding(b.mesh);
  });
  if (coarsest != in.poses.end()) check_read_rounding(coarsest->mesh, in.spheres.voxel_size, coarsest->source, log);
  if (!skin_path.empty()) match_skin(in.skin, skin_path, in.rest.mesh, in.poses);
  return in;
}

json error_list(const std::vector<ErrorStats>& errors) {
  json out = json::array();
  for (const ErrorStats& e : errors) out.push_back(e.to_json());
  return out;
}

json selection_report(const PoseMapSummary& s, const ProxyModel& proxy) {
  if (!s.selection) return nullptr;
  const JointSelection& sel = *s.selection;
  std::vector<std::string> selected_on;
  for (size_t f : sel.frames) selected_on.push_back(proxy.poses[f].name);
  return {{"method", s.skinned ? "one set cover over the rest and every pose of the spheres file's candidates, each "
                                 "skinned into every pose with one radius, the least over the poses"
                               : "one set cover over the rest and every pose of the spheres file's candidates, each "
                                 "mapped into every pose and grown there to the largest inscribed sphere containing it"},
          {"candidates", sel.candidates},
          {"candidates_from_poses", sel.from_frames},
          {"candidates_touching_samples", {{"samples", sel.touched}, {"candidates", sel.from_touching}}},
          {"candidates_around_samples", {{"samples", sel.around}, {"candidates", sel.from_around}}},
          {"candidates_mostly_absent", sel.mostly_absent},
          {"min_radius", s.selection_min_radius > 0 ? json(s.selection_min_radius) : json(nullptr)},
          {"candidates_below_min_radius", sel.below_min_radius},
          {"samples", sel.samples},
          {"sampling", {{"area_samples", s.selection_sampling.area_samples}, {"seed", s.selection_sampling.seed},
                        {"every_vertex", s.selection_sampling.every_vertex}}},
          {"target", s.selection_target > 0 ? json(s.selection_target) : json(nullptr)},
          {"delta", sel.cover.delta},
          {"lower_bound", sel.cover.lower_bound},
          {"uncoverable_samples", sel.out_of_reach()},
          {"uncoverable_vertices", sel.vertices_out_of_reach},
          {"uncoverable_vertices_with_no_solid_beside", sel.vertices_with_no_solid},
          {"spheres_for_uncoverable_vertices", sel.out_of_reach_added},
          {"least_reachable_delta", sel.out_of_reach_delta > 0 ? json(sel.out_of_reach_delta) : json(nullptr)},
          {"spheres", sel.chosen.size()},
          {"limited_by", limit_wording(sel.limited_by)},
          {"frames", {{"selected_on", selected_on}, {"samples_of_the_others", sel.samples_elsewhere},
                      {"checked", proxy.poses.size()}, {"rounds", sel.rounds}}},
          {"spaced_vertices", {{"frames", sel.spaced_frames}, {"vertex_spacing", sel.vertex_spacing},
                               {"vertices_joined", sel.spaced_joined}}},
          {"clip", {{"candidates_shrunk", sel.clip_shrunk}}},
          {"one_radius_checked", {{"chosen", sel.radii_checked}, {"lowered", sel.radii_lowered},
                                  {"covers_redone", sel.covers_redone},
                                  {"every_candidate", {{"checked", sel.candidates_checked}, {"lowered", sel.candidates_lowered}}}}},
          {"refined_moves", sel.refined_moves},
          {"polish", {{"rounds", sel.polish_rounds}, {"kept", sel.polished}}}};
}

json fill_report(const PoseMapSummary& s, const ProxyModel& proxy) {
  if (!s.fill) return nullptr;
  const GapFilling& fill = *s.fill;
  json poses = json::array();
  for (size_t i = 0; i < fill.poses.size(); ++i) {
    const GapFilling::Pose& p = fill.poses[i];
    poses.push_back({{"pose", proxy.poses[i + 1].name}, {"added", p.added}, {"lost_outside_rest", p.lost_outside_rest},
                     {"target_met", p.target_met}, {"max_error_reached", p.max_error_reached}});
  }
  return {{"min_radius", fill.min_radius}, {"target", fill.target}, {"poses", poses},
          {"spheres_before", fill.spheres_before}, {"spheres_after", fill.spheres_after},
          {"errors_before", error_list(fill.errors_before)}};
}

// The pose of the largest max error (the rest is 0), or errors.size() where none is finite.
size_t worst_pose(const std::vector<ErrorStats>& errors) {
  size_t worst = errors.size();
  for (size_t i = 0; i < errors.size(); ++i)
    if (std::isfinite(errors[i].max) && (worst == errors.size() || errors[i].max > errors[worst].max)) worst = i;
  return worst;
}

// "max error X (Y% of the diagonal) in pose P" of the worst pose.
std::string worst_error_words(const PoseMapSummary& s, const std::vector<ProxyPose>& poses, double diagonal) {
  const size_t worst = worst_pose(s.errors);
  if (worst >= s.errors.size() || worst >= poses.size()) return "";
  return "max error " + num(s.errors[worst].max) + " (" + num(100 * s.errors[worst].max / diagonal) +
         "% of the diagonal) in " + (worst == 0 ? "the rest" : "pose " + poses[worst].name);
}

// Whether --hold-over-blends took the examples past the tolerance the selection met.
bool hold_broke_tolerance(const PoseMapSummary& s) {
  const size_t worst = worst_pose(s.errors);
  return s.blend_hold && s.selection && met_tolerance(s.selection->limited_by) && s.selection_target > 0 &&
         worst < s.errors.size() && s.errors[worst].max > s.selection_target * (1 + 1e-9);
}

// A blend's weights by pose name, those not 0.
json blend_weights_json(const std::vector<double>& w, const ProxyModel& proxy) {
  json out = json::object();
  for (size_t i = 0; i < w.size() && i < proxy.poses.size(); ++i)
    if (w[i] != 0) out[proxy.poses[i].name] = w[i];
  return out;
}

json blend_hold_report(const PoseMapSummary& s, const ProxyModel& proxy) {
  if (!s.blend_hold) return nullptr;
  const BlendHold& h = *s.blend_hold;
  return {{"blends", h.blends}, {"spheres_shrunk", h.shrunk}, {"spheres_emptied", h.emptied},
          {"least_scale", h.least_scale}, {"overshoot_before", h.overshoot},
          {"worst_blend", h.worst.empty() ? json(nullptr) : blend_weights_json(h.worst, proxy)},
          {"tolerance_kept", s.selection_target > 0 ? json(!hold_broke_tolerance(s)) : json(nullptr)}};
}

// What the hold over the blends did, in a line.
std::string blend_hold_line(const BlendHold& h, const ProxyModel& proxy, double diagonal) {
  std::string at;
  const json worst = blend_weights_json(h.worst, proxy);
  for (const auto& [name, w] : worst.items())
    at += (at.empty() ? "" : " + ") + name + " " + num(w.get<double>());
  return "held over " + counted(h.blends, "blend") + " between the examples: " + counted(h.shrunk, "sphere") +
         " scaled down" + (h.shrunk ? " (the least to " + num(h.least_scale) + "x)" : "") + ", " +
         std::to_string(h.emptied) + " emptied; before, the union poked out by up to " + num(h.overshoot) + " (" +
         num(100 * h.overshoot / diagonal) + "% of the diagonal)" + (at.empty() ? "" : " at " + at);
}

json pose_cache_json(const std::vector<PoseCacheUse>& caches, size_t i) {
  if (i >= caches.size() || caches[i].file.empty()) return nullptr;
  const PoseCacheUse& c = caches[i];
  return {{"file", c.file}, {"read", c.read}, {"candidates_read", c.grown_read}, {"candidates_grown", c.grown_made}};
}

}  // namespace

json pose_map_report(const PoseMapResult& result) {
  const PoseMapSummary& s = result.summary;
  const ProxyModel& proxy = result.proxy;
  json poses = json::array();
  for (size_t i = 0; i < proxy.poses.size(); ++i) {
    const auto& [outside, holes, other, elsewhere] = s.zero_radius[i];
    poses.push_back({{"name", proxy.poses[i].name},
                     {"source", proxy.poses[i].source},
                     {"outside", proxy.poses[i].outside},
                     {"zero_radius",
                      {{"total", outside + holes + other + elsewhere},
                       {"center_outside", outside},
                       {"hole_bound", holes},
                       {"other", other},
                       {"another_pose", elsewhere}}},
                     {"error", s.errors[i].to_json()},
                     {"walls_inside", {{"left_out", s.walls[i].first}, {"split", s.walls[i].second}}},
                     {"cache", pose_cache_json(s.pose_caches, i)}});
  }
  return {{"tets",
           {{"method", s.tet_file.empty() ? "CGAL Mesh_3 on the winding-number domain" : "user tets"},
            {"source", s.tet_file},
            {"cache", s.tet_cache.empty() ? json(nullptr)
                                          : json{{"file", s.tet_cache}, {"read", s.tets_from_cache}}},
            {"vertices", s.tet_vertices},
            {"tetrahedra", s.tetrahedra},
            {"boundary_faces", s.boundary_faces},
            {"unmeshed_bodies", s.unmeshed_bodies}}},
          {"map",
           {{"method", s.skinned ? "linear blend skinning: the surface's joint weights carried in by the harmonic "
                                   "extension, the 4 heaviest kept per sphere; one radius per sphere, the least over "
                                   "the rest, every pose and the clip's times (map.clip)"
                                 : "harmonic extension of the surface motion (least squares), barycentric in tets"},
            {"joints", s.joints},
            {"clip", s.clip_times > 0 ? json{{"times", s.clip_times},
                                               {"overshoot", s.clip_overshoot},
                                               {"spheres_shrunk", s.clip_shrunk},
                                               {"cache", s.held_cache.file.empty()
                                                             ? json(nullptr)
                                                             : json{{"file", s.held_cache.file},
                                                                    {"radii_read", s.held_cache.read},
                                                                    {"radii_made", s.held_cache.made}}}}
                                        : json(nullptr)},
            {"between_poses", s.between.times > 0 ? json{{"times", s.between.times},
                                                         {"spheres_out", s.between.spheres_out},
                                                         {"centres_outside", s.between.centres_outside},
                                                         {"worst_overshoot", s.between.worst}}
                                                  : json(nullptr)},
            {"data_points", s.data_points},
            {"dropped_points", s.dropped_points},
            {"centers_outside_tets", s.centers_outside_tets},
            {"cache", s.carry_cache.file.empty() ? json(nullptr)
                                                 : json{{"file", s.carry_cache.file},
                                                        {"choices_read", s.carry_cache.read},
                                                        {"choices_made", s.carry_cache.made}}}}},
          {"cache_folder", cache_trim_json(s.cache_folder)},
          {"open_solid", s.open_solid},
          {"radius_source", s.open_solid ? "exact distance to each pose's mesh, bounded across its holes by "
                                           "that pose's own field"
                                         : "exact distance to each pose's mesh"},
          {"sphere_count", proxy.sphere_count()},
          {"site_count", proxy.sites.size()},
          {"poses", poses},
          {"fill_gaps", fill_report(s, proxy)},
          {"hold_over_blends", blend_hold_report(s, proxy)},
          {"selection", selection_report(s, proxy)}};
}

// What ended the selection, for the tool's first line: the tolerance it met over every pose (a
// default would otherwise go unsaid), or the limit that stopped it after the max error it left
// and the pose of it, as sphere-pack says it.
std::string selection_outcome(const PoseMapSummary& s, const std::vector<ProxyPose>& poses, double diagonal) {
  if (!s.selection) return "";
  const Limit limit = s.selection->limited_by;
  const bool met = met_tolerance(limit);
  std::string out;
  if (!met && !worst_error_words(s, poses, diagonal).empty()) out += ", " + worst_error_words(s, poses, diagonal);
  out += std::string(met ? "; " : "; limited by ") + limit_wording(limit);
  if (met && s.selection_target > 0)
    out += " " + num(s.selection_target) + " (" + num(100 * s.selection_target / diagonal) +
           "% of the diagonal) in every pose";
  if (hold_broke_tolerance(s)) out += " before --hold-over-blends; " + worst_error_words(s, poses, diagonal) + " after";
  return out;
}

void pose_map_files(const std::string& rest_path, const std::vector<std::string>& pose_paths,
                    const std::string& spheres_path, const std::string& output, const PoseMapOptions& given,
                    const PoseMapTolerances& tolerances, Log& log, json& report, const std::string& skin_path,
                    const std::vector<std::string>& names) {
  if (pose_paths.empty())
    fail_option("poses", "give at least one example pose (for a body that does not deform, the rest itself: --pose " +
                             rest_path + ")");
  if (!names.empty() && names.size() != pose_paths.size())
    throw std::logic_error("pose_map_files: a name per pose, or none");
  PoseMapInputs in;
  {
    StageTimer t(log, "load");
    in = read_inputs(rest_path, pose_paths, names, spheres_path, skin_path, log);
  }
  const LoadedMesh& rest = in.rest;
  const std::vector<PoseInput>& poses = in.poses;
  const SpheresFile& spheres = in.spheres;
  const SkinFile& skin = in.skin;
  // The tolerances become lengths here, once, and travel down as lengths.
  PoseMapOptions options = given;
  const double diagonal = rest.mesh.diagonal();
  if (tolerances.selection.set()) options.tolerance = tolerances.selection.length(diagonal);
  if (tolerances.fill.set()) options.fill_tolerance = tolerances.fill.length(diagonal);
  options.clip_overshoot = (tolerances.clip_overshoot.set() ? tolerances.clip_overshoot
                                                            : Tolerance{kDefaultClipOvershootPercent, true})
                               .length(diagonal);
  PoseMapResult result = about_file(rest_path, [&] {
    return pose_map(rest.mesh, rest_path, poses, spheres, options, log, skin_path.empty() ? nullptr : &skin);
  });
  write_json_atomic(output, proxy_to_json(result.proxy));

  // Each sphere's largest radius over the poses (a skinned one's one radius).
  std::vector<double> largest(result.proxy.sphere_count(), 0.0);
  for (const ProxyPose& pose : result.proxy.poses)
    for (size_t s = 0; s < largest.size(); ++s) largest[s] = std::max(largest[s], pose.spheres[s].radius);
  const json tiny = warn_tiny_spheres(largest, diagonal, selects_jointly(options, spheres) ? "sphere-pack's or pose-map's"
                                                                                         : "sphere-pack's", log);
  log.info(output + ": " + counted(result.proxy.sphere_count(), "sphere") + " x " +
           counted(result.proxy.poses.size(), "pose") + ", " + counted(result.proxy.sites.size(), "blend site") +
           selection_outcome(result.summary, result.proxy.poses, diagonal));
  if (result.summary.blend_hold) log.info(blend_hold_line(*result.summary.blend_hold, result.proxy, diagonal));
  if (hold_broke_tolerance(result.summary))
    log.warn("--hold-over-blends: " + worst_error_words(result.summary, result.proxy.poses, diagonal) +
             ", past the tolerance " + num(result.summary.selection_target) +
             " the selection met: the radii scaled down keep every sphere inside the blends between the examples, "
             "and cover less at the examples");
  const int name_width = pose_name_width(result.proxy.poses);
  std::vector<PoseLine> lines;
  for (size_t i = 0; i < result.proxy.poses.size(); ++i) {
    const ProxyPose& pose = result.proxy.poses[i];
    if (std::none_of(pose.spheres.begin(), pose.spheres.end(), [](const Sphere& s) { return s.radius > 0; })) {
      // No union to measure against (the warning above says why): not an error of nan.
      lines.push_back({pose.name + ": no sphere of radius above 0 in this pose, " + std::to_string(pose.outside.size()) +
                           " centres outside",
                       std::numeric_limits<double>::infinity()});
      continue;
    }
    lines.push_back({padded(pose.name, name_width) + " error median " + num(result.summary.errors[i].median) + " max " +
                         num(result.summary.errors[i].max) + ", " + counted(pose.outside.size(), "centre") + " outside",
                     result.summary.errors[i].max});
  }
  print_pose_lines(lines, log, "  ");
  report.update(pose_map_report(result));
  report["tiny_spheres"] = tiny;
  report["output"] = output;
  if (!skin_path.empty()) report["skin"] = skin_path;
}

}  // namespace spx
