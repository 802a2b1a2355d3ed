#include "posemap/posemap.hpp"

#include <cmath>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include "core/cache_folder.hpp"
#include "core/error.hpp"
#include "core/format.hpp"
#include "posemap/gap_filling.hpp"
#include "posemap/pose_mapper.hpp"
#include "posemap/spheres_fit.hpp"

namespace spx {
namespace detail {

void PoseMapper::read_cached_tets() {
  if (opt_.cache_dir.empty() || !opt_.tet_file.empty()) return;
  make_cache_folder(opt_.cache_dir);
  tet_cache_key_ = tets_cache_key(rest_, opt_.tets);
  tet_cache_file_ = tets_cache_file(opt_.cache_dir, tet_cache_key_);
  cached_tets_ = read_tets_cache(tet_cache_file_, tet_cache_key_);
  log_.detail(tet_cache_file_ + (cached_tets_ ? ": the rest's tets from the cache"
                                              : ": no tets cached for this rest and tet size; meshing, then caching them"));
}

void PoseMapper::make_tets() {
  StageTimer t(log_, "tetrahedralize");
  struct Done {  // set however the tets end, a failure too: the listing beside them stops
    std::atomic<bool>& done;
    ~Done() { done = true; }
  } done{tets_done_};
  if (!opt_.tet_file.empty()) {
    tets_ = read_medit_tets(opt_.tet_file);
    check_tets_fit(tets_, *queries_[0], rest_source_, opt_.tet_file);  // made before the tets (check_rest_fits_spheres)
  } else if (cached_tets_) {
    tets_ = std::move(*cached_tets_);
  } else {
    tets_ = tetrahedralize(rest_, opt_.tets, log_);
    try {
      if (!tet_cache_file_.empty()) write_tets_cache(tet_cache_file_, tet_cache_key_, tets_);
    } catch (const Error& e) {  // the proxy does not need it
      log_.warn(std::string(e.what()) + ": the tets are not cached");
    }
  }
  log_.detail(std::to_string(tets_.tets.size()) + " tets, " + std::to_string(tets_.vertices.size()) + " vertices");
}

void PoseMapper::solve_map() {
  StageTimer t(log_, "harmonic");
  f_ = std::make_unique<HarmonicMap>(tets_, rest_, log_);
  if (skin_) skinned_ = std::make_unique<SkinnedMap>(*skin_, *f_);
  // A clip that also drives morph weights is more than its skin: its frames cannot be rebuilt.
  if (opt_.hold_over_clip && !skin_) fail_option("hold_over_clip", "needs poses with a rig (pose-extract --animation)");
  if (opt_.hold_over_blends && skin_)
    fail_option("hold_over_blends", "is for blended examples: a rigged body's proxy follows its skin (--hold-over-clip "
                                    "holds it over the clip)");
  if (opt_.hold_over_clip && skin_->clip.empty()) fail_option("hold_over_clip", "the skin has no clip (an older skin.json)");
  if (opt_.hold_over_clip && skin_->morph_channels > 0)
    log_.warn("the clip also drives morph weights: skinned radii hold at the poses, not between them");
  else if (opt_.hold_over_clip)
    clip_ = std::make_unique<ClipRadius>(*skin_, rest_, proxy_.max_radius, opt_.clip_overshoot);
  for (size_t i = 0; i < poses_.size(); ++i)
    deformed_.push_back(skinned_ ? skinned_->deform_tets(i + 1) : f_->deform(poses_[i].mesh));
}

void PoseMapper::check_poses_face_outward() const {
  if (!open_solid_)
    for (const PoseInput& input : poses_) check_pose_faces_outward(input.mesh, input.source);
}

void PoseMapper::check_rest_fits_spheres() {
  queries_.resize(1 + poses_.size());
  queries_[0] = std::make_unique<MeshQuery>(rest_);
  check_spheres_fit(*queries_[0], spheres_, rest_source_);
}

void PoseMapper::build_solids(Log& log) {
  const bool skinned = skin_ != nullptr;  // skinned_ is made beside this
  meshes_.push_back(&rest_);
  for (const PoseInput& input : poses_) meshes_.push_back(&input.mesh);
  // Pose by pose in parallel (each also parallel inside, where its steps allow).
  {
    StageTimer t(log, "pose-queries");  // the rest's is made (check_rest_fits_spheres)
    tbb::parallel_for(size_t(1), meshes_.size(), [&](size_t i) { queries_[i] = std::make_unique<MeshQuery>(*meshes_[i]); });
  }
  fields_.resize(meshes_.size());
  pose_cache_.resize(opt_.cache_dir.empty() ? 0 : meshes_.size());
  pose_cache_key_.resize(pose_cache_.size());
  pose_inscribed_.resize(poses_.size());
  // Open meshes: the fields bound radii across the holes. Skinned: they put floors under every
  // pose's radii, so that a sphere's one radius asks few poses.
  if (open_solid_ || skinned) {
    StageTimer t(log, "pose-fields");
    if (skinned) depths_.resize(meshes_.size());
    tbb::parallel_for(size_t(0), meshes_.size(), [&](size_t i) {
      if (skinned && pose_from_cache(i, true)) return;
      const DenseField& field = pose_field(i, skinned);
      if (!skinned) return;
      // Kept for floors as depths only; a frame's own candidates are listed now, while its
      // field is at hand (an open mesh's fields bound radii, and are kept whole).
      depths_[i] = depth_field(field);
      if (i > 0) pose_inscribed_[i - 1] = std::make_unique<CandidatesOnDemand>(field, candidate_options(pose_pack_options()));
      release_field(i);
    });
  }
  // Closed: one hierarchy refitted to every pose tells inside by its ray count (skinned: and
  // bounds radii).
  if (!open_solid_) {
    deforming_ = std::make_unique<DeformingQuery>(rest_);
    if (deforming_->closed())
      for (const TriMesh* m : meshes_) shapes_.push_back(deforming_->shape(m->vertices));
    // Every pose's inside by its ray count from now on (the frames' own candidates grow on
    // their queries): no winding number is built for a pose that has not been asked one yet.
    for (size_t i = 0; i < shapes_.size(); ++i) queries_[i]->tell_inside_by(&shapes_[i]);
  }
  for (size_t i = 0; i < meshes_.size(); ++i)
    solids_.push_back({queries_[i].get(), open_solid_ ? &pose_field(i) : nullptr, proxy_.max_radius,
                       skinned ? &depths_[i] : nullptr, shapes_.empty() ? nullptr : &shapes_[i]});
  // Under the joint selection every sphere is grown in every pose (a host can only skin a
  // skinned one). Its first step carries the file's candidates into every pose; into the rest
  // that needs no tets, so it is done here, while Mesh_3 keeps the other core.
  grow_ = !skinned && selects_jointly();
  if (grow_ && !spheres_.candidates.empty()) {
    StageTimer t(log, "rest-growth");
    rest_grown_ = carry(spheres_.candidates, 0);
  }
}

bool PoseMapper::selects_jointly() const { return spx::selects_jointly(opt_, spheres_); }

void PoseMapper::map_spheres(const SphereSet& rest_spheres) {
  if (proxy_.poses.empty()) {
    proxy_.poses.push_back({proxy_pose_name(0), rest_source_, {}, {}});
    for (const PoseInput& input : poses_) proxy_.poses.push_back({input.name, input.source, {}, {}});
    zero_radius_.assign(proxy_.poses.size(), {0, 0, 0, 0});
  }
  const size_t first = rest_centers_.size(), n = rest_spheres.size();
  for (auto& pose : proxy_.poses) pose.spheres.resize(first + n);
  if (skinned_) influences_.resize(first + n);
  std::vector<std::vector<char>> cause(proxy_.poses.size(), std::vector<char>(n, 0));
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 8), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t s = r.begin(); s != r.end(); ++s) {
      const auto spheres = in_poses(rest_spheres[s].center, true, skinned_ ? &influences_[first + s] : nullptr);
      for (size_t i = 0; i < proxy_.poses.size(); ++i) {
        proxy_.poses[i].spheres[first + s] = spheres[i].first;
        cause[i][s] = char(spheres[i].second);
      }
    }
  });
  hold_over_clip(first, n, cause);
  for (const auto& s : rest_spheres) rest_centers_.push_back(s.center);
  for (size_t i = 0; i < proxy_.poses.size(); ++i)
    for (size_t s = 0; s < n; ++s) {
      if (cause[i][s] == char(PoseSolid::Zero::none)) continue;
      ++zero_radius_[i][size_t(cause[i][s]) - 1];
      if (cause[i][s] == char(PoseSolid::Zero::outside)) proxy_.poses[i].outside.push_back(int(first + s));
    }
}

void PoseMapper::hold_over_clip(size_t first, size_t n, std::vector<std::vector<char>>& cause) {
  if (!clip_) return;
  const std::vector<SkinInfluence> influences(influences_.begin() + long(first), influences_.end());
  std::vector<double> radii(n);
  for (size_t s = 0; s < n; ++s) radii[s] = proxy_.poses[0].spheres[first + s].radius;
  const std::vector<double> held = held_over_clip(influences, radii);
  for (size_t s = 0; s < n; ++s) {
    if (!(held[s] < radii[s])) continue;
    ++clip_shrunk_;
    for (size_t i = 0; i < proxy_.poses.size(); ++i) {
      proxy_.poses[i].spheres[first + s].radius = held[s];
      if (held[s] == 0 && cause[i][s] == char(PoseSolid::Zero::none)) cause[i][s] = char(PoseSolid::Zero::another_pose);
    }
  }
}

GapFilling PoseMapper::fill_gaps() {
  StageTimer t(log_, "fill-gaps");
  GapFilling out;
  out.spheres_before = rest_centers_.size();
  out.errors_before = pose_errors();
  out.min_radius = opt_.fill_min_radius > 0 ? opt_.fill_min_radius : 0.75 * field_options().voxel_size;
  out.target = opt_.fill_tolerance > 0 ? opt_.fill_tolerance : spheres_.tolerance;
  if (!(out.target > 0)) out.target = out.errors_before[0].max;
  PackOptions pack = pose_pack_options();
  pack.min_radius = out.min_radius;
  for (size_t i = 0; i < poses_.size(); ++i) {
    DenseField field = pose_field(i + 1);
    release_field(i + 1);
    const PoseGaps gaps = pack_pose_gaps(std::move(field), proxy_.poses[i + 1].spheres, *queries_[i + 1], pack,
                                         out.target, opt_.fill_max_per_pose, poses_[i].source, log_);
    GapFilling::Pose pose;
    pose.target_met = gaps.target_met;
    pose.max_error_reached = gaps.max_error_reached;
    const SphereSet back = map_back_to_rest(i, gaps.spheres, &pose.lost_outside_rest);
    map_spheres(back);
    pose.added = back.size();
    out.poses.push_back(pose);
    log_.detail(poses_[i].name + ": " + std::to_string(back.size()) + " spheres fill its gaps");
  }
  out.spheres_after = rest_centers_.size();
  return out;
}

void PoseMapper::assign_blend_sites() {
  BlendSites b = blend_sites(tets_, rest_centers_);
  proxy_.sites = std::move(b.sites);
  proxy_.sphere_sites = std::move(b.of_point);
}

void PoseMapper::attach_skin() {
  if (skinned_) proxy_.skin = skinned_->proxy_skin(proxy_.poses[0].spheres, influences_);
}

BlendHold PoseMapper::hold_over_blends() {
  StageTimer t(log_, "blend-hold");
  std::vector<const TriMesh*> meshes{&rest_};
  for (const PoseInput& p : poses_) meshes.push_back(&p.mesh);
  return spx::hold_over_blends(proxy_, meshes, blends_to_hold(meshes.size(), opt_.morph_targets));
}

void PoseMapper::check_between_poses(PoseMapSummary& out) const {
  if (!skinned_ || clip_ || skin_->clip.empty() || skin_->morph_channels > 0) return;
  StageTimer t(log_, "clip-check");
  out.between = check_over_clip(*skin_, rest_, proxy_.max_radius, proxy_.poses[0].spheres, influences_, log_);
}

void PoseMapper::summarize(PoseMapSummary& out) const {
  for (size_t i = 0; i < proxy_.poses.size(); ++i) {
    const auto& [outside, holes, other, elsewhere] = zero_radius_[i];
    const auto get = [](size_t n) { return n == 1 ? " gets" : " get"; };
    if (outside > 0)
      log_.warn(proxy_.poses[i].source + ": " + counted(outside, "sphere centre") + (outside == 1 ? " lands" : " land") +
                " outside this pose; " + (outside == 1 ? "that sphere" : "those spheres") + get(outside) +
                " radius 0 in it");
    if (holes + other > 0)
      log_.warn(proxy_.poses[i].source + ": " + counted(holes + other, "sphere") + get(holes + other) +
                " radius 0 in this pose (" + std::to_string(holes) + " bounded by its holes, " +
                std::to_string(other) + " on its surface)");
    if (elsewhere > 0)
      log_.warn(proxy_.poses[i].source + ": " + counted(elsewhere, "skinned sphere") + get(elsewhere) +
                " radius 0 here because " + (elsewhere == 1 ? "it has" : "they have") + " it in another pose");
  }
  out.zero_radius = zero_radius_;
  out.errors = pose_errors();
  for (const auto& q : queries_) out.walls.emplace_back(q->internal_walls(), q->split_triangles());
  for (const auto& c : rest_centers_) out.centers_outside_tets += f_->locator().locate(c).outside > 0;
  out.tet_file = opt_.tet_file;
  out.tet_cache = tet_cache_file_;
  out.tets_from_cache = cached_tets_.has_value();
  out.pose_caches = pose_cache_;
  if (carry_cache_) out.carry_cache = {carry_cache_->file(), carry_cache_->read(), carry_cache_->made()};
  if (held_cache_) out.held_cache = {held_cache_->file(), held_cache_->read(), held_cache_->made()};
  out.tet_vertices = tets_.vertices.size();
  out.tetrahedra = tets_.tets.size();
  out.boundary_faces = tets_.boundary_faces.size();
  out.unmeshed_bodies = tets_.unmeshed_bodies;
  out.skinned = bool(skinned_);
  out.clip_times = clip_ ? clip_->time_count() : 0;
  out.clip_shrunk = clip_shrunk_;
  out.clip_overshoot = clip_ ? opt_.clip_overshoot : 0;
  out.joints = skin_ ? skin_->joints.size() : 0;
  out.data_points = f_->data_points();
  out.dropped_points = f_->dropped_points();
  out.open_solid = open_solid_;
}

}  // namespace detail

PoseMapResult pose_map(const TriMesh& rest, const std::string& rest_source, const std::vector<PoseInput>& poses,
                       const SpheresFile& spheres, const PoseMapOptions& opt, Log& log, const SkinFile* skin) {
  if (std::isnan(opt.max_radius) || opt.max_radius < 0) fail_option("max_radius", "must be a positive number");
  if (!(opt.min_radius >= 0) || !std::isfinite(opt.min_radius)) fail_option("min_radius", "must be a positive number");
  if (std::isnan(opt.fill_min_radius) || opt.fill_min_radius < 0) fail_option("fill_min_radius", "must be a positive number");
  if (!(opt.tolerance >= 0)) fail_option("tolerance", "must be a positive length");
  if (!(opt.fill_tolerance >= 0)) fail_option("fill_tolerance", "must be a positive length");
  PoseMapResult result;
  result.proxy.max_radius = opt.max_radius > 0 ? opt.max_radius : spheres.max_radius;
  const bool joint = selects_jointly(opt, spheres);
  // The selection's least radius past its largest: no candidate could be chosen.
  const double least = selection_min_radius(opt, spheres);
  if (joint && !spheres.candidates.empty() && least > result.proxy.max_radius) {
    if (opt.min_radius > 0) fail_option("min_radius", "is larger than the max radius (" + num(result.proxy.max_radius) + ")");
    fail_option("max_radius", "is smaller than the spheres file's min radius (" + num(least) + ", sphere-pack's --min-radius)");
  }
  detail::PoseMapper mapper(rest, rest_source, poses, spheres, opt, skin, result.proxy, log);
  mapper.check_poses_face_outward();
  mapper.check_rest_fits_spheres();
  mapper.read_cached_tets();
  // Mesh_3 keeps one core: the poses' solids (their queries and, skinned or open, fields) are
  // built on the other meanwhile.
  Log beside = log.fork();
  tbb::parallel_invoke([&] { mapper.make_tets(); mapper.solve_map(); },
                       [&] {
                         mapper.build_solids(beside);
                         mapper.list_pose_candidates_beside_tets(beside);
                       });
  log.join(beside);
  // What the selection asks needs the cover method's candidates (a greedy file's spheres are
  // mapped as given).
  if (joint && spheres.candidates.empty())
    fail_option(opt.max_spheres > 0 ? "max_spheres" : opt.tolerance > 0 ? "tolerance" : "min_radius",
                "needs a spheres file with candidates (sphere-pack's cover method)");
  {
    StageTimer t(log, "map");
    SphereSet rest_spheres = spheres.spheres;
    if (joint) {
      StageTimer s(log, "select");
      rest_spheres = mapper.select_jointly(spheres.candidates, result.summary);
    }
    mapper.map_spheres(rest_spheres);
  }
  if (opt.fill_gaps) result.summary.fill = mapper.fill_gaps();
  if (opt.hold_over_blends) result.summary.blend_hold = mapper.hold_over_blends();
  mapper.assign_blend_sites();
  mapper.attach_skin();
  mapper.check_between_poses(result.summary);
  mapper.save_caches();
  mapper.trim_cache(result.summary);
  mapper.summarize(result.summary);
  return result;
}

}  // namespace spx
