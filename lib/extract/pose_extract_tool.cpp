#include "extract/pose_extract_tool.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <set>

#include "core/atomic_file.hpp"
#include "core/clip_steps.hpp"
#include "core/error.hpp"
#include "core/format.hpp"
#include "extract/asset.hpp"
#include "io/pose_manifest.hpp"
#include "io/skin_file.hpp"
#include "io/spx_writer.hpp"

namespace spx {
namespace {

// One pose to write: where it comes from and how to evaluate it.
struct PoseRequest {
  std::string name, file;
  json source;
  int target = -1;  // morph target, or
  size_t clip = 0;  // clip and time
  double time = 0;
};

std::vector<Eigen::Vector3f> as_float(const std::vector<Eigen::Vector3d>& p) {
  std::vector<Eigen::Vector3f> out(p.size());
  for (size_t i = 0; i < p.size(); ++i) out[i] = p[i].cast<float>();
  return out;
}

// A file name from a pose name: letters, digits, '-', '_' and '.' kept, the rest '_'.
std::string file_stem(const std::string& name) {
  std::string s;
  for (char c : name) s += std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_' || c == '.' ? c : '_';
  while (!s.empty() && s.front() == '.') s.erase(s.begin());
  return s.empty() ? "pose" : s;
}

std::string format_seconds(double s) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", s);
  return buf;
}

std::vector<PoseRequest> morph_requests(const Asset& asset) {
  if (asset.morph_targets().empty()) fail_input(asset.path(), "has no morph targets (--morph-targets needs them)");
  std::vector<PoseRequest> out;
  std::set<std::string> taken = {"rest"};
  for (size_t k = 0; k < asset.morph_targets().size(); ++k) {
    PoseRequest r;
    r.name = asset.morph_targets()[k];
    std::string stem = file_stem(r.name);
    for (int n = 2; !taken.insert(stem).second; ++n) stem = file_stem(r.name) + "-" + std::to_string(n);
    r.file = stem + ".obj";
    r.target = int(k);
    r.source = {{"kind", "morph-target"}, {"target", r.name}, {"index", k}};
    out.push_back(r);
  }
  return out;
}

// The clip's channels that move no geometry, named (the first few) for a warning or an error.
std::string passed_over_list(const AssetClip& c) {
  constexpr size_t kListed = 3;
  std::string out;
  for (size_t i = 0; i < c.passed_over.size() && i < kListed; ++i) out += (i ? ", " : "") + c.passed_over[i];
  if (c.passed_over.size() > kListed) out += " and " + std::to_string(c.passed_over.size() - kListed) + " more";
  return out;
}

std::vector<PoseRequest> clip_requests(const Asset& asset, const PoseExtractOptions& opt, Log& log) {
  const size_t clip = asset.find_clip(opt.animation);
  const AssetClip& c = asset.clips()[clip];
  const std::string clip_name = c.name.empty() ? "clip" + std::to_string(clip) : c.name;
  if (c.frames.empty())
    fail_input(asset.path(), "clip '" + clip_name + "' has no keys" +
                                 (c.passed_over.empty() ? std::string()
                                                        : " that move a node or morph weights (" +
                                                              passed_over_list(c) + " move no geometry)"));
  if (!c.passed_over.empty())
    log.warn(asset.path() + ": clip '" + clip_name + "': " + counted(c.passed_over.size(), "channel") +
             " moving no node's transform or morph weights passed over (" + passed_over_list(c) +
             "); the poses follow its other channels");
  const std::string range = " (the clip runs 0 .. " + format_seconds(c.end) + " s)";
  std::vector<std::pair<double, int>> at;  // (time, frame or -1)
  if (!opt.times.empty()) {
    for (double t : opt.times)
      if (!std::isfinite(t) || t < 0 || t > c.end * (1 + 1e-9) + 1e-12)
        fail_option("times", format_seconds(t) + " s is outside the clip '" + clip_name + "'" + range);
      else
        at.emplace_back(t, -1);
  } else if (!opt.frames.empty()) {
    for (int f : opt.frames)
      if (f < 0 || size_t(f) >= c.frames.size())
        fail_option("frames", "frame " + std::to_string(f) + " is outside the clip '" + clip_name + "' (it has frames 0.." +
                                  std::to_string(c.frames.size() - 1) + ")");
      else
        at.emplace_back(c.frames[size_t(f)], f);
  } else {
    const size_t step = size_t(std::max(opt.every, 1));
    for (size_t f = 0; f < c.frames.size(); f += step) at.emplace_back(c.frames[f], int(f));
  }
  // A pose asked twice would be mapped twice and blended as two examples.
  std::vector<std::pair<double, int>> sorted = at;
  std::sort(sorted.begin(), sorted.end());
  const auto twice = std::adjacent_find(sorted.begin(), sorted.end(),
                                        [](const auto& a, const auto& b) { return a.first == b.first; });
  if (twice != sorted.end())
    fail_option(opt.times.empty() ? "frames" : "times",
                (opt.times.empty() ? "frame " + std::to_string(twice->second) : format_seconds(twice->first) + " s") +
                    " is asked twice (each pose once)");
  std::vector<PoseRequest> out;
  const int width = at.size() > 100 ? int(std::to_string(at.size() - 1).size()) : 2;
  for (size_t i = 0; i < at.size(); ++i) {
    PoseRequest r;
    r.clip = clip;
    r.time = at[i].first;
    r.name = clip_name + "@" + format_seconds(r.time) + "s";
    char file[32];
    std::snprintf(file, sizeof file, "pose-%0*zu.obj", width, i);
    r.file = file;
    r.source = {{"kind", "animation"}, {"clip", c.name}, {"clip_index", clip}, {"time", r.time}};
    if (at[i].second >= 0) r.source["frame"] = at[i].second;
    out.push_back(r);
  }
  return out;
}

std::vector<Eigen::Vector3d> evaluate(const Asset& asset, const PoseRequest& r) {
  return r.target >= 0 ? asset.morph_target(size_t(r.target)) : asset.at_time(r.clip, r.time);
}

}  // namespace

double rms_distance(const std::vector<Eigen::Vector3f>& a, const std::vector<Eigen::Vector3f>& b) {
  double sum = 0;
  for (size_t i = 0; i < a.size(); ++i) sum += double((a[i] - b[i]).squaredNorm());
  return a.empty() ? 0.0 : std::sqrt(sum / double(a.size()));
}

std::vector<size_t> farthest_poses(const std::vector<Eigen::Vector3d>& rest,
                                   const std::vector<std::vector<Eigen::Vector3f>>& poses, size_t k) {
  const std::vector<Eigen::Vector3f> r = as_float(rest);
  std::vector<double> nearest(poses.size());
  for (size_t i = 0; i < poses.size(); ++i) nearest[i] = rms_distance(r, poses[i]);
  std::vector<size_t> chosen;
  std::vector<char> taken(poses.size(), 0);
  while (chosen.size() < std::min(k, poses.size())) {
    size_t best = poses.size();
    for (size_t i = 0; i < poses.size(); ++i)
      if (!taken[i] && (best == poses.size() || nearest[i] > nearest[best])) best = i;
    taken[best] = 1;
    chosen.push_back(best);
    for (size_t i = 0; i < poses.size(); ++i) nearest[i] = std::min(nearest[i], rms_distance(poses[best], poses[i]));
  }
  std::sort(chosen.begin(), chosen.end());
  return chosen;
}

namespace {

void check_options(const PoseExtractOptions& opt) {
  if (opt.morph_targets && !opt.animation.empty())
    fail_option("animation", "give --morph-targets or --animation (one of them)");
  if (opt.animation.empty() && (!opt.frames.empty() || !opt.times.empty() || opt.every || opt.select))
    fail_option("animation", "--frames, --times, --every and --select choose frames of a clip: give --animation");
  if (opt.select < 0) fail_option("select", "must be at least 1");
  if (opt.every < 0) fail_option("every", "must be at least 1");
}

// What the asset holds to take poses from: its clips (index, name, frames, length) and its
// morph targets, for the error that asks for one of them.
std::string poses_on_offer(const Asset& asset) {
  std::string clips;
  constexpr size_t kListed = 8;
  for (size_t i = 0; i < asset.clips().size() && i < kListed; ++i) {
    const AssetClip& c = asset.clips()[i];
    clips += (i ? ", " : "") + std::to_string(i) + (c.name.empty() ? "" : " '" + c.name + "'") + " (" +
             counted(c.frames.size(), "frame") + " over " + num(c.end) + " s)";
  }
  if (asset.clips().size() > kListed) clips += " and " + std::to_string(asset.clips().size() - kListed) + " more";
  const size_t targets = asset.morph_targets().size();
  return (asset.clips().empty() ? std::string("no animation clips") : counted(asset.clips().size(), "clip") + ": " + clips) +
         (targets > 0 ? "; " + counted(targets, "morph target") : std::string("; no morph targets"));
}

// The body and what the report and the log say of it.
struct Body {
  WeldedBody welded;
  double diagonal = 0, seam_tolerance = 0;
};
// A clip's rest is at the meshes' default morph weights, as every frame of a clip that drives no
// weights is, so the skin deforms what the clip plays; morph targets are blended from weights 0.
Body read_body(const Asset& asset, const PoseExtractOptions& opt, const std::string& input, Log& log) {
  check_rest_not_collapsed(asset, input);
  Body out{weld_body(asset, !opt.animation.empty())};
  check_rest_finite(out.welded, input);
  out.diagonal = out.welded.rest.diagonal();
  out.seam_tolerance = 1e-7 * std::max(out.diagonal, 1e-30);
  const TriMesh& rest = out.welded.rest;
  warn_repeated(out.welded.repeated, input, log);
  size_t meshes_used = 0;
  for (const auto& m : asset.meshes()) meshes_used += m.used;
  log.info(input + ": " + std::to_string(meshes_used) + " mesh" + (meshes_used == 1 ? "" : "es") + ", " +
           std::to_string(rest.vertices.size()) + " vertices (" +
           std::to_string(asset.vertex_count() - rest.vertices.size()) + " welded), " +
           std::to_string(rest.triangles.size()) + " triangles");
  if (asset.unweighted_vertices())
    log.warn(std::to_string(asset.unweighted_vertices()) + " skinned vertices have no joint weight; they keep their bind position");
  return out;
}

// --select: the K frames that best span the clip, by farthest-point sampling; named pose-NN.
std::vector<PoseRequest> select_frames(const Asset& asset, const Body& body, const std::vector<PoseRequest>& requests,
                                       size_t k, const std::string& input, Log& log, json& report) {
  StageTimer timer(log, "select");
  std::vector<std::vector<Eigen::Vector3f>> candidates;
  for (size_t i = 0; i < requests.size(); ++i) {
    log.progress("evaluating frames", i, requests.size());
    size_t opened = 0;
    const TriMesh pose = welded_pose(body.welded, evaluate(asset, requests[i]), body.seam_tolerance, opened,
                                     requests[i].name, input);
    candidates.push_back(as_float(pose.vertices));
  }
  const std::vector<size_t> keep = farthest_poses(body.welded.rest.vertices, candidates, k);
  // How far the farthest frame left out is from the rest or a kept frame: how well K spans the clip.
  double spread = 0;
  const std::vector<Eigen::Vector3f> rest_f = as_float(body.welded.rest.vertices);
  for (const auto& c : candidates) {
    double nearest = rms_distance(rest_f, c);
    for (size_t kept : keep) nearest = std::min(nearest, rms_distance(candidates[kept], c));
    spread = std::max(spread, nearest);
  }
  json chosen = json::array();
  for (size_t kept : keep) chosen.push_back(requests[kept].source.value("frame", int(kept)));
  report["selection"] = {{"candidates", requests.size()}, {"kept", keep.size()}, {"frames", chosen},
                         {"farthest_left_out", spread}, {"farthest_left_out_percent", 100 * spread / body.diagonal}};
  if (k > requests.size())
    log.info("--select " + std::to_string(k) + ": the clip has only " + std::to_string(requests.size()) +
             " frames; all are kept");
  log.info("kept " + std::to_string(keep.size()) + " of " + std::to_string(requests.size()) +
           " frames; every frame is within " + num(100 * spread / body.diagonal) +
           " % of the diagonal (RMS) of the rest or a kept frame");
  std::vector<PoseRequest> kept;
  for (size_t i = 0; i < keep.size(); ++i) {
    kept.push_back(requests[keep[i]]);
    char file[32];
    std::snprintf(file, sizeof file, "pose-%02zu.obj", i);
    kept.back().file = file;
  }
  return kept;
}

// The rig of a clip's poses: the joints, the welded rest's vertices and weights (a welded vertex
// takes its first file vertex's, as its position), and the joint matrices of the rest and
// every pose.
SkinFile skin_of(const Asset& asset, const WeldedBody& body, const std::vector<PoseRequest>& requests) {
  SkinFile skin;
  for (const AssetJoint& j : asset.joints()) skin.joints.push_back({j.name, j.parent, j.inverse_bind});
  const auto weights = asset.vertex_joints();
  skin.vertex_positions = body.rest.vertices;
  for (size_t first : first_file_vertices(body)) skin.vertex_weights.push_back(weights[first]);
  skin.rest = asset.rest_joint_matrices();
  for (const PoseRequest& r : requests) skin.poses.push_back({r.name, asset.joint_matrices(r.clip, r.time)});
  if (requests.empty()) return skin;
  const AssetClip& clip = asset.clips()[requests.front().clip];
  skin.morph_channels = clip.morph_channels;
  // The whole clip for the radius rule over the motion: every key, and between keys at least
  // half-way and as often as a host samples it (clip_steps_between: keys far apart leave the
  // skeleton to interpolate through many frames).
  skin.clip.name = clip.name;
  for (size_t f = 0; f < clip.frames.size(); ++f) {
    if (f > 0) {
      const double from = clip.frames[f - 1], gap = clip.frames[f] - from;
      const int steps = clip_steps_between(gap);
      for (int k = 1; k < steps; ++k) skin.clip.times.push_back(from + gap * k / steps);
    }
    skin.clip.times.push_back(clip.frames[f]);
  }
  for (double t : skin.clip.times) skin.clip.matrices.push_back(asset.joint_matrices(requests.front().clip, t));
  return skin;
}

double max_displacement(const TriMesh& pose, const TriMesh& rest) {
  double d = 0;
  for (size_t v = 0; v < pose.vertices.size(); ++v) d = std::max(d, (pose.vertices[v] - rest.vertices[v]).norm());
  return d;
}

// The list of files a run is writing, beside its poses until its manifest is written: a run that
// failed half-way left no manifest, and this names its files for the next run to remove.
constexpr const char* kWritingList = ".pose-extract-writing.json";

// The files an earlier run wrote in `dir`: those its manifest names (the poses whose entry says
// where in an asset they came from, as pose-extract writes them, and their clip's skin: a
// hand-written manifest's files are not pose-extract's), or, where it failed half-way, its list.
std::set<std::string> files_of_earlier_run(const std::string& dir, Log& log) {
  std::set<std::string> files;
  std::error_code ec;
  const std::string manifest = dir + "/poses.json", list = dir + "/" + kWritingList;
  if (std::filesystem::is_regular_file(manifest, ec)) {
    try {
      const PoseManifest earlier = read_pose_manifest(manifest);
      bool clip = false;
      for (const ManifestPose& p : earlier.poses) {
        const std::string kind = p.source.is_object() ? p.source.value("kind", "") : "";
        if (kind == "animation" || kind == "morph-target") files.insert(p.file);
        clip = clip || kind == "animation";
      }
      if (clip && !earlier.skin.empty()) files.insert(earlier.skin);
    } catch (const Error& e) {
      log.warn(std::string(e.what()) + "; replaced, and any files of an earlier run it named are left");
    }
  }
  if (std::filesystem::is_regular_file(list, ec)) {
    try {
      const json named = read_json_file(list);
      for (const json& f : named.is_array() ? named : json::array())
        if (f.is_string()) files.insert(f.get<std::string>());
    } catch (const Error&) {  // not a list a run wrote: what it named stays
    }
  }
  return files;
}

// An earlier run's manifest in `dir` and its files that this run will not write (frames no
// longer kept, the skin of a clip where now morph targets), removed before this run writes any
// file, and this run's list written. Left, the manifest would name files of two runs while the
// poses are rewritten (a run that failed half-way left it over the new rest, for pose-map to read
// with the earlier poses), and the files a second set of poses for a glob or a rule to pick up.
// Only plain names in the folder are removed; returns them.
json clear_earlier_run(const std::string& dir, const std::set<std::string>& planned, Log& log) {
  const std::set<std::string> files = files_of_earlier_run(dir, log);
  const std::string manifest = dir + "/poses.json";
  std::error_code ec;
  if (!std::filesystem::remove(manifest, ec) && ec)
    fail_write(manifest, "cannot remove the earlier run's manifest: " + ec.message());
  json removed = json::array();
  for (const std::string& f : files) {
    const std::filesystem::path name(f);
    if (planned.count(f) || name.filename() != name || f == "." || f == "..") continue;
    if (std::filesystem::remove(dir + "/" + f, ec)) removed.push_back(f);
    else if (ec) fail_write(dir + "/" + f, "cannot remove this file of the earlier run: " + ec.message());
  }
  write_json_atomic(dir + "/" + kWritingList, json(planned));
  if (removed.empty()) return removed;
  std::string names;
  for (size_t i = 0; i < removed.size() && i < 4; ++i) names += (i ? ", " : "") + removed[i].get<std::string>();
  if (removed.size() > 4) names += ", ...";
  log.info(dir + ": removed " + counted(removed.size(), "file") + " of the earlier run that this one does not write (" +
           names + ")");
  return removed;
}

// The rest and every pose as OBJ (and a clip's skin), then the manifest last: its presence
// means every file it names is complete and of this run.
void write_poses(const Asset& asset, const Body& body, const std::vector<PoseRequest>& requests,
                 const PoseExtractOptions& opt, const std::string& input, const std::string& dir, Log& log,
                 json& report) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) fail_write(dir, "cannot create folder: " + ec.message());
  // From clearing an earlier run's files to this run's manifest, the folder is this run's alone.
  const FolderLock hold(dir, [&] { log.info(dir + ": another run is writing poses here; waiting for it to finish"); });
  StageTimer write_timer(log, "write");
  const TriMesh& rest = body.welded.rest;
  const std::string tag = "spx pose-extract " + std::filesystem::path(input).filename().string();
  PoseManifest manifest;
  if (!opt.animation.empty()) manifest.skin = "skin.json";
  std::set<std::string> planned = {manifest.rest};
  for (const PoseRequest& r : requests) planned.insert(r.file);
  if (!manifest.skin.empty()) planned.insert(manifest.skin);
  const json removed = clear_earlier_run(dir, planned, log);
  write_file_atomic(dir + "/" + manifest.rest, to_obj(rest, tag + " rest (bind pose)"));
  json poses = json::array();
  size_t opened_total = 0;
  for (size_t i = 0; i < requests.size(); ++i) {
    const PoseRequest& r = requests[i];
    log.progress("writing poses", i, requests.size());
    size_t opened = 0;
    const TriMesh pose = welded_pose(body.welded, evaluate(asset, r), body.seam_tolerance, opened, r.name, input);
    if (opened) {
      log.warn(r.name + ": " + std::to_string(opened) + " vertices that coincide at rest part in this pose; the first "
               "of each is written");
      opened_total += opened;
    }
    const double displacement = max_displacement(pose, rest);
    if (r.target >= 0 && displacement == 0)
      log.warn(input + ": morph target '" + r.name + "' moves no vertex (it changes normals alone, or nothing), so "
               "its pose is the rest");
    write_file_atomic(dir + "/" + r.file, to_obj(pose, tag + " " + r.name));
    manifest.poses.push_back({r.name, r.file, r.source});
    poses.push_back({{"name", r.name}, {"file", r.file}, {"source", r.source}, {"opened_seams", opened},
                     {"max_displacement", displacement}});
  }
  if (!opt.animation.empty()) {
    const SkinFile skin = skin_of(asset, body.welded, requests);
    if (skin.morph_channels)
      log.warn(input + ": the clip also drives " + std::to_string(skin.morph_channels) +
               " morph channels; the skin written beside the poses does not follow them");
    write_json_atomic(dir + "/" + manifest.skin, skin_to_json(skin));
    report["skin"] = {{"file", manifest.skin}, {"joints", skin.joints.size()}, {"morph_channels", skin.morph_channels}};
  }
  write_json_atomic(dir + "/poses.json", manifest_to_json(manifest));
  std::filesystem::remove(dir + "/" + kWritingList, ec);  // the manifest names them now
  report["output"] = {{"folder", dir}, {"manifest", "poses.json"}, {"rest", manifest.rest},
                      {"vertices", rest.vertices.size()}, {"triangles", rest.triangles.size()},
                      {"welded", asset.vertex_count() - rest.vertices.size()},
                      {"triangles_repeated", body.welded.repeated.count},
                      {"inner_sides_dropped", body.welded.repeated.inner_sides}, {"diagonal", body.diagonal},
                      {"removed_from_earlier_run", removed}};
  report["poses"] = poses;
  report["opened_seams"] = opened_total;
}

}  // namespace

void pose_extract_files(const std::string& input, const std::string& dir, const PoseExtractOptions& opt, Log& log,
                        json& report) {
  check_options(opt);
  StageTimer read_timer(log, "read");
  const Asset asset(input, opt.mesh);
  read_timer.stop();
  warn_fanned(asset.fanned(), input, log);
  if (!opt.morph_targets && opt.animation.empty())
    fail_option("animation", "give --morph-targets or --animation (a clip's name or index): " + input + " holds " +
                                 poses_on_offer(asset));
  report["asset"] = asset.inventory();
  const Body body = read_body(asset, opt, input, log);
  std::vector<PoseRequest> requests = opt.morph_targets ? morph_requests(asset) : clip_requests(asset, opt, log);
  if (opt.select > 0) requests = select_frames(asset, body, requests, size_t(opt.select), input, log, report);
  write_poses(asset, body, requests, opt, input, dir, log, report);
  log.info(dir + ": rest + " + counted(requests.size(), "pose"));
  if (requests.size() + 1 > spx_max_poses())
    log.warn(dir + ": pose-map takes at most " + std::to_string(spx_max_poses() - 1) +
             " poses besides the rest (what a .spx holds); --select N keeps the N frames that best span the clip");
}

}  // namespace spx
