#include "metrics/motion_eval_tool.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

#include "core/atomic_file.hpp"
#include "core/error.hpp"
#include "core/format.hpp"
#include "extract/asset.hpp"
#include "io/pose_manifest.hpp"
#include "mesh/pose_match.hpp"
#include "metrics/motion_chart.hpp"
#include "metrics/motion_eval.hpp"
#include "metrics/rest_match.hpp"
#include "runtime/spx_runtime.h"

namespace spx {
namespace {

struct ClipTimes {
  std::vector<double> time;
  std::vector<char> between;
};

// The times asked for, in order, with `between` times evenly between consecutive ones.
ClipTimes clip_times(const AssetClip& clip, const MotionToolOptions& opt) {
  if (opt.every < 1) fail_option("every", "must be at least 1");
  if (opt.between < 0) fail_option("between", "must not be negative");
  std::vector<double> asked = opt.times;
  if (asked.empty())
    for (size_t f = 0; f < clip.frames.size(); f += size_t(opt.every)) asked.push_back(clip.frames[f]);
  for (double t : asked)
    if (!std::isfinite(t) || t < 0 || t > clip.end + 1e-9)
      fail_option("times", std::to_string(t) + " s is outside the clip '" + clip.name + "' (0 to " +
                               std::to_string(clip.end) + " s)");
  std::sort(asked.begin(), asked.end());
  asked.erase(std::unique(asked.begin(), asked.end()), asked.end());
  if (asked.empty()) fail_option("animation", "the clip '" + clip.name + "' has no frames");
  ClipTimes out;
  for (size_t i = 0; i < asked.size(); ++i) {
    for (int k = 1; i > 0 && k <= opt.between; ++k) {
      out.time.push_back(asked[i - 1] + (asked[i] - asked[i - 1]) * k / (opt.between + 1));
      out.between.push_back(1);
    }
    out.time.push_back(asked[i]), out.between.push_back(0);
  }
  return out;
}

// The clip asked for; without --animation, the one the manifest's poses (`posed`) came from (by
// its index and name), else the asset's only clip.
size_t clip_to_measure(const Asset& asset, const MotionToolOptions& opt, const std::vector<ManifestPose>& posed,
                       Log& log) {
  if (!opt.animation.empty()) return asset.find_clip(opt.animation);
  const std::vector<AssetClip>& clips = asset.clips();
  size_t clip = clips.size();
  std::string why = "the asset's only clip";
  for (const ManifestPose& p : posed) {
    const int i = p.source.value("clip_index", -1);
    if (p.source.value("kind", "") == "animation" && i >= 0 && size_t(i) < clips.size() &&
        clips[size_t(i)].name == p.source.value("clip", "")) {
      clip = size_t(i), why = "the clip " + opt.manifest + "'s poses came from";
      break;
    }
  }
  if (clip == clips.size() && clips.size() == 1) clip = 0;
  if (clip == clips.size()) {
    if (clips.empty()) return asset.find_clip("");  // names the asset: it has none
    fail_option("animation", "names the clip to measure: " + asset.path() + " has " + counted(clips.size(), "clip") +
                                 " (" + one_line(quoted_names(asset.clip_labels()), 200) + ")");
  }
  const std::string label = asset.clip_labels()[clip];
  const std::string named = clips[clip].name.empty() ? label : "'" + label + "'";
  log.info("clip " + named + " (" + why + "; --animation names another)");
  return clip;
}

// The times of the clip's frames the proxy was made from, from its poses.json's poses (`posed`).
std::vector<double> seen_times(const std::vector<ManifestPose>& posed, size_t clip) {
  std::vector<double> seen;
  for (const ManifestPose& p : posed)
    if (p.source.value("kind", "") == "animation" && p.source.value("clip_index", -1) == int(clip))
      seen.push_back(p.source.value("time", -1.0));
  return seen;
}

// The asset's welded vertex of each example vertex: the examples are read back from OBJ in their
// own order, matched to the asset's by their triangles (mesh/pose_match). Examples given must be
// the asset's own welded rest and poses.
// `hint` ends the message (which mesh the poses may be of).
std::vector<size_t> example_order(const std::vector<TriMesh>& examples, const WeldedBody& body, const std::string& asset,
                                  const std::string& hint) {
  const auto& rest = body.rest.vertices;
  std::vector<size_t> order(rest.size());
  for (size_t v = 0; v < order.size(); ++v) order[v] = v;
  if (examples.empty()) return order;
  const auto& given = examples[0].vertices;
  if (given.size() != rest.size())
    fail_input(asset, "has " + std::to_string(rest.size()) + " welded vertices, the rest mesh " +
                          std::to_string(given.size()) + ": not the asset the poses came from" + hint);
  const std::vector<int> to_example = match_pose_vertices(examples[0], body.rest, asset);
  double worst = 0;
  for (size_t v = 0; v < rest.size(); ++v) {
    order[size_t(to_example[v])] = v;
    worst = std::max(worst, (given[size_t(to_example[v])] - rest[v]).norm());
  }
  if (worst > 1e-5 * body.rest.diagonal())
    fail_input(asset, "its bind pose is not the rest mesh (a vertex " + std::to_string(worst) +
                          " away): not the asset the poses came from" + hint);
  return order;
}

json frame_error_json(const FrameError& e) {
  return {{"median", e.median}, {"max", e.max}, {"overshoot", e.overshoot}, {"centers_outside", e.outside},
          {"zero_radius", e.zero}};
}

// Per runtime and group of frames: how many, the max error's median and worst, the worst
// overshoot and the frames with a centre outside.
json group_summary_json(const MotionResult& r, int runtime, const std::function<bool(const MotionRow&)>& in_group,
                  double diagonal, double tolerance) {
  std::vector<double> maxima;
  double overshoot = 0;
  size_t outside = 0;
  for (const MotionRow& row : r.rows) {
    if (!in_group(row)) continue;
    const FrameError& e = row.error[size_t(runtime)];
    maxima.push_back(e.max);
    overshoot = std::max(overshoot, e.overshoot);
    outside += e.outside > 0;
  }
  json j = {{"frames", maxima.size()}};
  if (maxima.empty()) return j;
  std::sort(maxima.begin(), maxima.end());
  const double median = maxima[maxima.size() / 2], worst = maxima.back();
  j.update({{"max_error_median", median}, {"max_error_worst", worst}, {"overshoot_worst", overshoot},
            {"frames_with_centers_outside", outside},
            {"percent_of_diagonal", {{"max_error_median", 100 * median / diagonal}, {"max_error_worst", 100 * worst / diagonal},
                                     {"overshoot_worst", 100 * overshoot / diagonal}}}});
  if (tolerance > 0) j["worst_over_tolerance"] = worst / tolerance;
  return j;
}

void log_summary(const json& s, const char* runtime, const char* group, Log& log) {
  if (s["frames"].get<size_t>() == 0) return;
  const json& p = s["percent_of_diagonal"];
  char line[320];
  const size_t frames = s["frames"].get<size_t>();
  std::snprintf(line, sizeof line, "%-15s %-15s %4zu %-7s max error median %.3f%% worst %.3f%%, overshoot %.3f%%, %zu with centres outside",
                runtime, group, frames, frames == 1 ? "frame:" : "frames:", p["max_error_median"].get<double>(),
                p["max_error_worst"].get<double>(), p["overshoot_worst"].get<double>(),
                s["frames_with_centers_outside"].get<size_t>());
  log.info(line);
}

}  // namespace

std::vector<size_t> example_targets(const ProxyModel& proxy, const Asset& asset) {
  if (!proxy.skin.empty()) return {};
  const std::vector<std::string>& targets = asset.morph_targets();
  std::map<std::string, size_t> taken;  // per name, how many examples took one already
  std::vector<size_t> out;
  for (size_t i = 1; i < proxy.poses.size(); ++i) {
    const std::string& name = proxy.poses[i].name;
    size_t nth = taken[name]++, k = 0;
    for (; k < targets.size(); ++k)
      if (targets[k] == name && nth-- == 0) break;
    if (k == targets.size())
      fail_option("asset", "the proxy has no skin and its example '" + name + "' is no morph target of " + asset.path() +
                               " (" + (targets.empty() ? std::string("it has none")
                                                       : counted(targets.size(), "target") + ": " +
                                                             one_line(quoted_names(targets), 200)) +
                               "): --asset measures a rigged body's proxy, or a morph-target body's "
                               "(pose-extract --morph-targets), over a clip");
    out.push_back(k);
  }
  return out;
}

namespace {

// A morph-target body's weights at each time: the clip's, of every target of the asset. Exit 2
// naming the asset where the runtime would refuse them (not finite, or adding up past 2^24).
std::vector<std::vector<double>> clip_morph_weights(const Asset& asset, size_t clip, const ClipTimes& times) {
  std::vector<std::vector<double>> out;
  for (double t : times.time) {
    out.push_back(asset.morph_weights(clip, t));
    std::vector<float> w(out.back().begin(), out.back().end()), full(w.size() + 1);
    if (!detail::morph_to_full(w.data(), uint32_t(full.size()), full.data()))
      fail_input(asset.path(), "clip '" + asset.clips()[clip].name + "' at " + std::to_string(t) +
                                   " s weighs its morph targets (" + one_line(json(out.back()).dump(), 120) +
                                   ") past what a host's blend can add: a weight not finite, or adding up past 2^24");
  }
  return out;
}

// The targets the clip weighs (anywhere past 1e-6) that have no example in the proxy, named in a
// warning: there the mesh moves and the proxy cannot follow.
std::vector<std::string> warn_targets_without_examples(const Asset& asset, const std::vector<size_t>& examples,
                                                       const std::vector<std::vector<double>>& weights, Log& log) {
  std::vector<std::string> out;
  for (size_t k = 0; k < asset.morph_targets().size(); ++k) {
    const bool weighed = std::any_of(weights.begin(), weights.end(), [&](const auto& w) { return std::abs(w[k]) > 1e-6; });
    if (weighed && std::find(examples.begin(), examples.end(), k) == examples.end())
      out.push_back(asset.morph_targets()[k]);
  }
  if (!out.empty())
    log.warn(asset.path() + ": the clip weighs " + counted(out.size(), "morph target") + " the proxy has no example of (" +
             one_line(quoted_names(out), 200) + "): the mesh moves there and the proxy cannot follow");
  return out;
}

json row_json(const MotionResult& r, const MotionRow& row) {
  json j = {{"time", row.time}, {"seen", row.seen}, {"between", row.between}};
  for (int k : r.runtimes) j[motion_runtime_name(k)] = frame_error_json(row.error[size_t(k)]);
  return j;
}

// Per runtime measured and group of frames, summarised and logged.
json summary_json(const MotionResult& r, double diagonal, double tolerance, Log& log) {
  const std::pair<const char*, std::function<bool(const MotionRow&)>> groups[] = {
      {"frames_seen", [](const MotionRow& row) { return row.seen; }},
      {"frames_unseen", [](const MotionRow& row) { return !row.seen && !row.between; }},
      {"between_frames", [](const MotionRow& row) { return row.between; }},
      {"all", [](const MotionRow&) { return true; }}};
  json summary;
  for (int k : r.runtimes)
    for (const auto& g : groups) {
      summary[motion_runtime_name(k)][g.first] = group_summary_json(r, k, g.second, diagonal, tolerance);
      log_summary(summary[motion_runtime_name(k)][g.first], motion_runtime_name(k), g.first, log);
    }
  if (!r.measured(kBestBlend)) log.info("best-fit blend not measured: give the examples (--manifest) to compare with it");
  return summary;
}

// The rest as pose-extract writes and checks it: a clip's (the default morph weights), or with
// every morph target at 0 where the examples are the targets.
WeldedBody checked_rest(const Asset& asset, bool skinned, const std::string& path) {
  check_rest_not_collapsed(asset, path);
  WeldedBody body = weld_body(asset, skinned);
  check_rest_finite(body, path);
  return body;
}

// A frame the proxy was made from: the rest (every weight 0) or one of its examples (its target
// at 1, every other 0).
bool is_example(const std::vector<double>& w, const std::vector<size_t>& examples) {
  size_t ones = 0, at = 0;
  for (size_t k = 0; k < w.size(); ++k) {
    if (w[k] == 1.0) ++ones, at = k;
    else if (w[k] != 0.0) return false;
  }
  return ones == 0 || (ones == 1 && std::find(examples.begin(), examples.end(), at) != examples.end());
}

}  // namespace

json proxy_motion_report(const ProxyModel& proxy, const Asset& asset, const std::vector<TriMesh>& examples,
                         const MotionToolOptions& opt, Log& log) {
  const bool skinned = !proxy.skin.empty();
  const std::vector<size_t> targets = example_targets(proxy, asset);
  // The manifest's poses, read once: which clip they came from, and its frames the proxy saw.
  const std::vector<ManifestPose> posed = opt.manifest.empty() ? std::vector<ManifestPose>{}
                                                               : read_pose_manifest(opt.manifest).poses;
  const size_t clip = clip_to_measure(asset, opt, posed, log);
  const std::vector<std::string> uncovered = warn_meshes_without_spheres(proxy, asset, "their error is measured", log);
  const WeldedBody body = checked_rest(asset, skinned, opt.asset);
  size_t used = 0;
  for (const AssetMesh& m : asset.meshes()) used += m.used;
  const std::string hint = opt.mesh.empty() && used > 1 ? " (its " + std::to_string(used) +
                                                               " meshes merged: poses of one mesh, pose-extract --mesh, "
                                                               "need the same --mesh here)"
                                                             : "";
  const std::vector<size_t> order_of_vertices = example_order(examples, body, opt.asset, hint);
  const TriMesh& layout = examples.empty() ? body.rest : examples[0];
  const std::vector<size_t> order = skinned ? asset.joints_named(proxy.skin.joints) : std::vector<size_t>{};
  const ClipTimes times = clip_times(asset.clips()[clip], opt);
  const std::vector<double> seen = seen_times(posed, clip);
  const std::vector<std::vector<double>> weights = skinned ? std::vector<std::vector<double>>{}
                                                           : clip_morph_weights(asset, clip, times);
  const std::vector<std::string> unfollowed = skinned ? std::vector<std::string>{}
                                                      : warn_targets_without_examples(asset, targets, weights, log);
  const double diagonal = body.rest.diagonal(), seam = 1e-7 * diagonal;
  const auto frame = [&](size_t i) {
    MotionFrame f;
    f.time = times.time[i];
    f.between = times.between[i];
    size_t opened = 0;
    const std::string what = "clip '" + asset.clips()[clip].name + "' at " + std::to_string(f.time) + " s";
    std::vector<Eigen::Vector3d> positions;
    if (skinned) {
      f.seen = std::any_of(seen.begin(), seen.end(), [&](double t) { return std::abs(t - f.time) < 1e-4; });
      positions = asset.at_time(clip, f.time);
      const std::vector<Eigen::Matrix4d> all = asset.joint_matrices(clip, f.time);
      for (size_t j : order) f.joints.push_back(all[j]);
    } else {
      f.seen = is_example(weights[i], targets);
      positions = asset.morphed(weights[i]);
      for (size_t k : targets) f.morph_weights.push_back(float(weights[i][k]));
    }
    const TriMesh welded = welded_pose(body, positions, seam, opened, what, opt.asset);
    f.mesh.triangles = layout.triangles;
    for (size_t v : order_of_vertices) f.mesh.vertices.push_back(welded.vertices[v]);
    return f;
  };
  const MotionResult r = evaluate_motion(proxy, times.time.size(), frame, examples, log, opt.asset);

  const double tolerance = opt.tolerance.length(diagonal);
  json rows = json::array();
  for (size_t i = 0; i < r.rows.size(); ++i) {
    rows.push_back(row_json(r, r.rows[i]));
    if (!skinned) rows.back()["morph_weights"] = weights[i];
  }
  json out = {{"asset", opt.asset}, {"mesh", opt.mesh.empty() ? json(nullptr) : json(opt.mesh)},
              {"clip", asset.clips()[clip].name}, {"clip_index", clip},
              {"times", times.time.size()}, {"diagonal", diagonal}, {"spheres", proxy.sphere_count()},
              {"summary", summary_json(r, diagonal, tolerance, log)}, {"frames", rows},
              {"meshes_without_spheres", uncovered}};
  if (skinned) {
    out["joints"] = proxy.skin.joints.size();
    out["runtime"] = {{"skin_us_median", r.host_us}};
  } else {
    json named = json::array();
    for (size_t k : targets) named.push_back(asset.morph_targets()[k]);
    out["morph_targets"] = named;
    out["morph_targets_without_examples"] = unfollowed;
    out["runtime"] = {{"blend_morph_us_median", r.host_us}};
  }
  if (tolerance > 0) out["tolerance"] = tolerance;
  if (!opt.chart.empty()) {
    write_file_atomic(opt.chart, motion_chart_svg(r, diagonal, tolerance, asset.clips()[clip].name));
    out["chart"] = opt.chart;
  }
  return out;
}

}  // namespace spx
