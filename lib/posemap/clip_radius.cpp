#include "posemap/clip_radius.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <tbb/parallel_for.h>

#include "core/format.hpp"
#include "core/tolerance.hpp"
#include "mesh/near_boundary.hpp"

namespace spx {
ClipRadius::ClipRadius(const SkinFile& skin, const TriMesh& rest, double max_radius, double overshoot, bool sweep)
    : overshoot_(overshoot),
      sweep_(sweep),
      clip_(skin.clip),
      rest_(rest),
      max_radius_(max_radius),
      margin_(1e-9 * rest.diagonal()),
      vertices_(skin, rest.vertices),
      deforming_(rest) {}

TriMesh ClipRadius::mesh_at(size_t k) const { return {vertices_.all(clip_.matrices[k]), rest_.triangles}; }

// A few times skinned at once: their meshes built in parallel, one sweep over them per sphere,
// then those it does not settle walk them in order. A sweep costs about one time's search; over
// more times the parts move too far for it to settle (the walk's 4 frames held over its clip:
// 2, 4, 8 and 16 times took 56, 55, 62 and 71 s).
constexpr size_t kTimesAtOnce = 4;

struct ClipRadius::Time {
  std::optional<DeformingQuery::Shape> shape;  // a closed mesh
  std::unique_ptr<NearBoundaryQuery> query;    // another
};

double ClipRadius::least_at(const Time& time, const Eigen::Vector3d& c, double r, double moved) const {
  if (time.query) {
    if (!time.query->inside(c)) return 0.0;
    // A surface r or farther leaves r as it is: only what is nearer is looked for.
    const double d = time.query->distance_below(c, r);
    return std::isfinite(d) ? std::min(r, d + overshoot_) : r;
  }
  // Only a surface nearer than r less the overshoot lowers r: the search looks no farther.
  const double bound = r - overshoot_;
  const double d = bound > 0 ? time.shape->signed_distance_within(c, bound) : std::numeric_limits<double>::infinity();
  if (d < 0) return -d + overshoot_;
  // Nothing nearer, and nothing was at the time before: going straight from there, each point of
  // the surface stays at least bound - moved / 2 from the centre (least_distance_over_step), so
  // never reaches it, and the centre stays inside.
  if (!std::isfinite(d) && moved < 2 * (bound - margin_)) return r;
  // Otherwise the centre may be inside or out (a jump between times). Or the closest surface
  // says outside, which where parts of the body pass through each other (legs in a stride) can
  // be a wall inside the solid. The winding number decides.
  if (!time.shape->inside(c)) return 0.0;
  return std::isfinite(d) ? d + overshoot_ : r;
}

void ClipRadius::walk(size_t first, const std::vector<Eigen::Vector3d>* before,
                      const std::vector<std::vector<Eigen::Vector3d>>& meshes, const std::vector<uint32_t>& todo,
                      const std::vector<SkinInfluence>& influences, std::vector<double>& radius) const {
  if (todo.empty()) return;
  std::vector<Time> block(meshes.size());
  // Each time's farthest vertex move from the time before (none before the clip's first).
  std::vector<double> step(meshes.size(), std::numeric_limits<double>::infinity());
  tbb::parallel_for(size_t(0), meshes.size(), [&](size_t t) {
    if (deforming_.closed())
      block[t].shape.emplace(deforming_.shape(meshes[t]));
    else
      block[t].query = std::make_unique<NearBoundaryQuery>(deforming_, TriMesh{meshes[t], rest_.triangles});
    const std::vector<Eigen::Vector3d>* last = t > 0 ? &meshes[t - 1] : before;
    if (!last || !deforming_.closed()) return;  // least_at asks it of a closed mesh alone
    double most = 0;
    for (size_t v = 0; v < meshes[t].size(); ++v) most = std::max(most, (meshes[t][v] - (*last)[v]).squaredNorm());
    step[t] = std::sqrt(most);
  });
  tbb::parallel_for(size_t(0), todo.size(), [&](size_t n) {
    double& r = radius[todo[n]];
    const SkinInfluence& s = influences[todo[n]];
    Eigen::Vector3d last = before ? skin_point(s, clip_.matrices[first - 1]) : Eigen::Vector3d::Zero();
    for (size_t t = 0; t < meshes.size() && r > 0; ++t) {
      const Eigen::Vector3d c = skin_point(s, clip_.matrices[first + t]);
      r = least_at(block[t], c, r, step[t] + (c - last).norm());
      last = c;
    }
  });
}

namespace {
// A joint's matrix, inverted, with how far it is from distance-preserving (singular values within
// 1 -+ `stretch`; a rig's rotations in float are a hair off).
struct Inverse {
  Eigen::Matrix3d linear;
  Eigen::Vector3d offset;
  double stretch = 0;
  Eigen::Vector3d operator()(const Eigen::Vector3d& p) const { return linear * p + offset; }
};
Inverse inverse_of(const Eigen::Matrix4d& m) {
  const Eigen::Matrix3d r = m.topLeftCorner<3, 3>();
  Inverse out;
  out.linear = r.inverse();
  out.offset = -out.linear * m.topRightCorner<3, 1>();
  out.stretch = (r.transpose() * r - Eigen::Matrix3d::Identity()).norm();  // bounds |sigma^2 - 1|
  if (!out.linear.allFinite() || !(r.determinant() > 0)) out.stretch = 1;  // no reflection: the sides stay
  return out;
}
// Past this, a joint's frame is not asked (the sweep's bound would be loose, or wrong).
constexpr double kMostStretch = 1e-3;
// A sphere the sweep finds more triangles near than this walks the block (on the walk's 4 frames
// held over its clip, 32, 128 and 256 took as long or longer).
constexpr size_t kMostNear = 64;
// Spheres of one joint near one another searched together (see unsettled).
constexpr size_t kGroup = 16;

// Whether each of the `near` triangles stays at least `least` from the centre through the block,
// in the joint's frame (`inverse`: time first - 1, then the block's), each corner and the centre
// going in straight lines from time to time, so their difference too. The sweep bounds a
// triangle's motion and the centre's apart; near a sphere whose surface moves with it (a ball
// tangent where the skin blends joints) the difference barely moves.
bool stays_farther(const std::vector<Eigen::Vector3i>& triangles, const std::vector<int>& near,
                   const std::vector<Eigen::Vector3d>& before, const std::vector<std::vector<Eigen::Vector3d>>& meshes,
                   const std::vector<Inverse>& inverse, const Eigen::Vector3d* centre, double least) {
  for (int t : near) {
    const Eigen::Vector3i& f = triangles[size_t(t)];
    auto corners = [&](size_t k) {  // the triangle's corners less the centre at step k
      Corners u;
      for (size_t c = 0; c < 3; ++c)
        u[c] = inverse[k](k == 0 ? before[size_t(f[int(c)])] : meshes[k - 1][size_t(f[int(c)])]) - centre[k];
      return u;
    };
    Corners last = corners(0);
    double last_distance = distance_to_origin(last);
    for (size_t k = 1; k <= meshes.size(); ++k) {
      const Corners now = corners(k);
      const double distance = distance_to_origin(now);
      if (least_distance_over_step(last, last_distance, now, distance) < least) return false;
      last = now;
      last_distance = distance;
    }
  }
  return true;
}

// Sphere indices by heaviest joint, then along a Morton curve through their bind points (a
// joint's spheres near one another in the asset are near in its frame at every time), ties by index.
std::vector<uint32_t> by_joint_then_place(const std::vector<SkinInfluence>& influences) {
  Eigen::AlignedBox3d box;
  for (const SkinInfluence& s : influences) box.extend(s.bind);
  const Eigen::Vector3d scale = 1023.0 / box.sizes().cwiseMax(1e-300).array();
  auto spread = [](uint64_t x) {  // 10 bits to every third of 30
    x = (x | (x << 16)) & 0x030000FFull;
    x = (x | (x << 8)) & 0x0300F00Full;
    x = (x | (x << 4)) & 0x030C30C3ull;
    return (x | (x << 2)) & 0x09249249ull;
  };
  std::vector<std::pair<uint64_t, uint32_t>> keyed(influences.size());
  for (size_t i = 0; i < influences.size(); ++i) {
    const Eigen::Vector3d c = (influences[i].bind - box.min()).cwiseProduct(scale);
    uint64_t code = 0;
    for (int a = 0; a < 3; ++a) code |= spread(uint64_t(std::clamp(c[a], 0.0, 1023.0))) << a;
    keyed[i] = {(uint64_t(uint32_t(influences[i].joint[0])) << 32) | code, uint32_t(i)};
  }
  std::sort(keyed.begin(), keyed.end());
  std::vector<uint32_t> out(keyed.size());
  for (size_t i = 0; i < keyed.size(); ++i) out[i] = keyed[i].second;
  return out;
}

// Of `todo` (in joint and then spatial order), runs [begin, end) of up to kGroup on one joint.
std::vector<std::pair<size_t, size_t>> runs_of(const std::vector<uint32_t>& todo,
                                               const std::vector<SkinInfluence>& influences) {
  std::vector<std::pair<size_t, size_t>> out;
  for (size_t n = 0; n < todo.size();) {
    const int joint = influences[todo[n]].joint[0];
    size_t end = n + 1;
    while (end < todo.size() && end - n < kGroup && influences[todo[end]].joint[0] == joint) ++end;
    out.emplace_back(n, end);
    n = end;
  }
  return out;
}
}  // namespace

std::vector<uint32_t> ClipRadius::unsettled(size_t first, const std::vector<Eigen::Vector3d>& before,
                                            const std::vector<std::vector<Eigen::Vector3d>>& meshes,
                                            const std::vector<uint32_t>& todo,
                                            const std::vector<SkinInfluence>& influences,
                                            const std::vector<double>& radius) const {
  const size_t joints = clip_.matrices[first].size(), count = meshes.size();
  // A joint's sweep costs about what 64 spheres' walks through a block save (the walk's 4 frames
  // held over its clip): a joint followed by fewer leaves them to walk.
  std::vector<size_t> followers(joints, 0);
  for (uint32_t i : todo) ++followers[size_t(influences[i].joint[0])];
  std::vector<char> used(joints, 0);
  for (size_t j = 0; j < joints; ++j) used[j] = followers[j] > 0 && 64 * followers[j] >= before.size();
  // Per joint: the times' inverses (time first - 1, then the block's), and the sweep in its frame:
  // the mesh at time first - 1, each vertex inflated by the farthest it goes in the block.
  std::vector<std::vector<Inverse>> inverse(joints);
  std::vector<std::optional<DeformingQuery::Shape>> sweep(joints);
  std::vector<double> shrink(joints, 0);  // a world distance is at least this times the frame's
  tbb::parallel_for(size_t(0), joints, [&](size_t j) {
    if (!used[j]) return;
    double stretch = 0;
    for (size_t t = 0; t <= count; ++t) {
      inverse[j].push_back(inverse_of(clip_.matrices[first + t - 1][j]));
      stretch = std::max(stretch, inverse[j].back().stretch);
    }
    if (!(stretch < kMostStretch)) return;
    shrink[j] = 1 - stretch;  // sigma >= sqrt(1 - stretch) >= 1 - stretch
    std::vector<Eigen::Vector3d> at(before.size());
    std::vector<double> moves(before.size(), 0.0);
    for (size_t v = 0; v < before.size(); ++v) {
      at[v] = inverse[j][0](before[v]);
      for (size_t t = 0; t < count; ++t) moves[v] = std::max(moves[v], (inverse[j][t + 1](meshes[t][v]) - at[v]).norm());
    }
    sweep[j].emplace(deforming_.swept(std::move(at), std::move(moves)));
  });
  // Runs of spheres on one joint near one another share the sweep's descent from its root: the
  // leaves near any of them, then each its own.
  const std::vector<std::pair<size_t, size_t>> groups = runs_of(todo, influences);
  std::vector<char> settled(todo.size(), 0);
  tbb::parallel_for(size_t(0), groups.size(), [&](size_t g) {
    const auto [begin, end] = groups[g];
    const size_t j = size_t(influences[todo[begin]].joint[0]);
    if (!sweep[j]) return;
    struct Ask {
      Eigen::Vector3d centre[kTimesAtOnce + 1];
      double least = 0, reach = 0;
    };
    std::array<Ask, kGroup> ask;
    Eigen::AlignedBox3d region;
    for (size_t n = begin; n < end; ++n) {
      Ask& a = ask[n - begin];
      const SkinInfluence& s = influences[todo[n]];
      // The centre in the joint's frame at time first - 1 and the block's, and the farthest it goes.
      double drift = 0;
      for (size_t t = 0; t <= count; ++t) {
        a.centre[t] = inverse[j][t](skin_point(s, clip_.matrices[first + t - 1]));
        drift = std::max(drift, (a.centre[t] - a.centre[0]).norm());
      }
      // Through the block the surface must stay farther than `least` in the frame, so than
      // shrink * least in the world: the radius there at least that plus the overshoot. And never
      // reaching the centre, the surface leaves it inside, as it was at time first - 1.
      a.least = std::max((radius[todo[n]] - overshoot_) / shrink[j], 0.0) + margin_;
      // Each vertex and the centre go from time to time in straight lines in the frame. A
      // triangle the sweep finds no nearer than least plus the centre's drift and its vertices'
      // inflation stays farther than least throughout.
      a.reach = a.least + drift;
      region.extend(a.centre[0] - Eigen::Vector3d::Constant(a.reach));
      region.extend(a.centre[0] + Eigen::Vector3d::Constant(a.reach));
    }
    thread_local std::vector<int> leaves, near;
    sweep[j]->leaves_near(region, leaves);
    for (size_t n = begin; n < end; ++n) {
      const Ask& a = ask[n - begin];
      if (sweep[j]->inflated_triangles_nearer_than(a.centre[0], a.reach, kMostNear, near, leaves))
        settled[n] = near.empty() || stays_farther(rest_.triangles, near, before, meshes, inverse[j], a.centre, a.least);
    }
  });
  std::vector<uint32_t> out;
  for (size_t n = 0; n < todo.size(); ++n)
    if (!settled[n]) out.push_back(todo[n]);
  return out;
}

std::vector<double> ClipRadius::least(const std::vector<SkinInfluence>& influences, const std::vector<double>& radius,
                                      const Log* log, Tally* tally) const {
  std::vector<double> out(radius);
  for (double& r : out) r = r > 0 ? std::min(r, max_radius_) : 0.0;
  if (out.empty() || time_count() == 0) return out;
  // A percentage where the walk takes seconds: a million spheres times times.
  if (out.size() * time_count() < size_t(1000000)) log = nullptr;
  const std::string stage = "holding " + std::to_string(out.size()) + " spheres over the clip's " +
                            std::to_string(time_count()) + " times";
  // Each sphere's times are its own, so any order gives the same radii: this one groups a joint's
  // spheres near one another for the sweep (unsettled).
  const std::vector<uint32_t> order = by_joint_then_place(influences);
  auto alive = [&] {
    std::vector<uint32_t> todo;
    for (uint32_t i : order)
      if (out[i] > 0) todo.push_back(i);
    return todo;
  };
  // The first time asked of every sphere; then blocks, each swept from the time before it.
  std::vector<std::vector<Eigen::Vector3d>> meshes{vertices_.all(clip_.matrices[0])};
  walk(0, nullptr, meshes, alive(), influences, out);
  const size_t blocks = (time_count() - 1 + kTimesAtOnce - 1) / kTimesAtOnce;
  for (size_t first = 1; first < time_count(); first += kTimesAtOnce) {
    if (log) log->progress(stage.c_str(), (first - 1) / kTimesAtOnce, blocks);
    const std::vector<Eigen::Vector3d> before = std::move(meshes.back());
    meshes.assign(std::min(kTimesAtOnce, time_count() - first), {});
    tbb::parallel_for(size_t(0), meshes.size(),
                      [&](size_t t) { meshes[t] = vertices_.all(clip_.matrices[first + t]); });
    std::vector<uint32_t> todo = alive();
    const size_t asked = todo.size();
    if (sweep_ && deforming_.closed()) todo = unsettled(first, before, meshes, todo, influences, out);
    if (tally) tally->blocks += asked, tally->settled += asked - todo.size();
    walk(first, &before, meshes, todo, influences, out);
  }
  if (log) log->progress(stage.c_str(), blocks, blocks);
  return out;
}

ClipOvershoot check_over_clip(const SkinFile& skin, const TriMesh& rest, double max_radius, const SphereSet& spheres,
                              const std::vector<SkinInfluence>& influences, Log& log) {
  std::vector<double> radii;
  for (const Sphere& s : spheres) radii.push_back(s.radius);
  const std::vector<double> held = ClipRadius(skin, rest, max_radius).least(influences, radii, &log);
  const double rounding = 1e-6 * rest.diagonal();  // past float rounding of the exact distance
  ClipOvershoot out{skin.clip.times.size()};
  for (size_t i = 0; i < radii.size(); ++i) {
    if (!(radii[i] > 0) || held[i] >= std::min(radii[i], max_radius) - rounding) continue;
    ++out.spheres_out;
    out.centres_outside += held[i] == 0;
    out.worst = std::max(out.worst, radii[i] - held[i]);
  }
  // Counted past rounding; said past a thousandth of the diagonal, or where a centre leaves the body.
  if (out.centres_outside > 0 || out.worst > 1e-3 * rest.diagonal())
    log.warn(between_poses_warning(out, radii.size(), rest.diagonal()));
  return out;
}

std::string between_poses_warning(const ClipOvershoot& out, size_t sphere_count, double diagonal) {
  const std::string centres = out.centres_outside == 0 ? ""
                              : "; " + counted(out.centres_outside, "centre") +
                                    (out.centres_outside == 1 ? " leaves" : " leave") + " it";
  return "between the poses given, " + std::to_string(out.spheres_out) + " of " + std::to_string(sphere_count) +
         " spheres " + (out.spheres_out == 1 ? "pokes" : "poke") + " out of the body at some of the clip's " +
         std::to_string(out.times) + " times (by up to " +
         num(out.worst) + ", " + num(100 * out.worst / diagonal) + " % of the diagonal" + centres +
         "): --hold-over-clip holds them within " + num(kDefaultClipOvershootPercent) +
         " % of the diagonal (--clip-overshoot), and more of the clip's frames in the chain (pose-extract --select, "
         "--every) bring it down";
}

}  // namespace spx
