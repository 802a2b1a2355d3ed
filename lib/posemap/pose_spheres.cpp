// PoseMapper's spheres in the poses: carried and grown there, offered by a pose's own field and
// mapped back to the rest; and the poses as the joint selection sees them.
#include <algorithm>
#include <optional>
#include <tuple>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/cache_folder.hpp"
#include "core/error.hpp"
#include "core/format.hpp"
#include "core/hash.hpp"
#include "core/pick.hpp"
#include "core/subject.hpp"
#include "core/tolerance.hpp"
#include "mesh/normals.hpp"
#include "mesh/union_distance.hpp"
#include "posemap/joint_selection.hpp"
#include "posemap/pose_cache.hpp"
#include "posemap/pose_mapper.hpp"
#include "posemap/spheres_fit.hpp"

namespace spx::detail {

// Skinned: a frame's own candidate within this many voxels (at rest) of one offered is not (at 48
// frames of the elephant's walk, a quarter as many candidates and no more spheres).
constexpr double kFrameCandidateSpacing = 0.5;

// The map as the joint selection sees it.
class PoseMapper::Frames : public SelectionFrames {
 public:
  explicit Frames(PoseMapper& m) : m_(m) {}
  size_t frame_count() const override { return m_.meshes_.size(); }
  const TriMesh& frame_mesh(size_t f) const override { return *m_.meshes_[f]; }
  const TriMesh& frame_surface(size_t f) const override { return m_.queries_[f]->surface(); }
  SphereSet spheres_in(const SphereSet& rest, size_t f) const override {
    // The file's candidates at rest were carried beside the tets (build_solids).
    if (f == 0 && m_.rest_grown_ && same_spheres(rest, m_.spheres_.candidates)) return *m_.rest_grown_;
    return m_.carry(rest, f);
  }
  bool one_radius() const override { return bool(m_.skinned_); }
  std::vector<double> over_clip(const std::vector<SkinInfluence>& in, const std::vector<double>& r) const override {
    return m_.clip_ ? m_.held_over_clip(in, r) : r;
  }
  SkinnedMap::Carried carry_skinned(const SphereSet& rest) const override { return m_.carry_skinned(rest); }
  double exact_radius(const Eigen::Vector3d& c, size_t f) const override { return m_.solids_[f].exact_radius(c, false).value; }
  // The spheres map_spheres writes (skinned: one radius, exact in every frame); false where one is 0.
  bool spheres_at(const Eigen::Vector3d& c, std::vector<Sphere>& in_frames) const override {
    in_frames.clear();
    for (const auto& [sphere, zero] : m_.in_poses(c, false, nullptr)) in_frames.push_back(sphere);
    return std::all_of(in_frames.begin(), in_frames.end(), [](const Sphere& s) { return s.radius > 0; });
  }
  SphereSet frame_candidates(size_t f, const std::vector<Eigen::Vector3d>& points, double reach) override {
    return m_.map_back_to_rest(f - 1, m_.pose_candidates_near(f - 1, points, reach), nullptr, !one_radius());
  }
  // Skinned, nested balls down to half of delta: a sphere with one radius over the clip keeps more of those;
  // `around`, the balls around each sample instead.
  SphereSet touching_candidates(size_t f, const SurfaceSamples& drawn, const std::vector<uint32_t>& which,
                                double delta, bool around) override {
    const MeshQuery& q = *m_.queries_[f];
    const DenseField* field = m_.open_solid_ ? &m_.pose_field(f) : nullptr;
    const double start = std::min(m_.proxy_.max_radius, 0.5 * q.surface().diagonal());
    const CandidateOptions o = candidate_options(m_.pose_pack_options());
    const SphereSet balls = around ? balls_around_samples(q, drawn, which, field, start, o, delta)
                                   : balls_through(q, drawn, which, field, start, o, m_.skinned_ ? 0.5 * delta : 0);
    return f == 0 ? balls : m_.map_back_to_rest(f - 1, balls, nullptr, !one_radius());
  }
 private:
  PoseMapper& m_;
};

SphereSet PoseMapper::select_jointly(const SphereSet& file_candidates, PoseMapSummary& summary) {
  JointSelectionOptions options;
  std::tie(options.target, options.budget) = selection_size();
  options.reach = options.target > 0 ? options.target : default_tolerance(rest_.diagonal());
  // Not on open parts: half a voxel is much of a wall there (the robot's walk lost 50 samples).
  options.spacing = open_solid_ ? 0.0 : kFrameCandidateSpacing * field_options().voxel_size;
  options.field_bounds_radii = open_solid_;
  const CoverSampling sampling = selection_sampling(opt_, spheres_);
  options.area_samples = sampling.area_samples;
  options.seed = sampling.seed;
  options.spaced_vertices = !sampling.every_vertex;
  options.refine_step = clip_ ? 0.0 : 0.5 * field_options().voxel_size;  // as sphere-pack; not a held clip's radii
  options.polish_rounds = opt_.polish_rounds >= 0 ? opt_.polish_rounds : skinned_ ? 0 : 1;
  options.min_radius = selection_min_radius(opt_, spheres_);
  Frames frames(*this);
  JointSelection selection = spx::select_jointly(frames, file_candidates, options, log_);
  if (selection.chosen.empty() && selection.below_min_radius > 0)
    fail_option("min_radius", num(options.min_radius) + " leaves no sphere: every candidate is smaller at rest (the "
                              "largest " + num(selection.largest_below_min) + ")");
  if (open_solid_ && selection.vertices_out_of_reach > 0) {
    selection.vertices_with_no_solid =
        std::min(selection.vertices_out_of_reach,
                 vertices_with_no_solid(frames, selection.chosen, options.target > 0 ? options.target : selection.cover.delta));
    // Where none of them has the solid beside it, no field reaches them.
    if (selection.vertices_with_no_solid == selection.vertices_out_of_reach && selection.limited_by == Limit::resolution)
      selection.limited_by = Limit::flat;
  }
  const std::string why = out_of_reach_wording(selection, options, bool(skinned_));
  const bool missed = !(options.target > 0) || selection.vertices_out_of_reach > 0;
  if (selection.out_of_reach() > 0) missed ? log_.warn(why) : log_.detail(why);
  summary.selection = selection;
  summary.selection_target = options.target;
  summary.selection_min_radius = options.min_radius;
  summary.selection_sampling = sampling;
  return selection.chosen;
}

size_t PoseMapper::vertices_with_no_solid(const SelectionFrames& frames, const SphereSet& chosen, double target) const {
  const std::vector<SphereSet> in_frames = spheres_in_frames(frames, chosen);
  size_t out = 0;
  for (size_t f = 0; f < in_frames.size(); ++f) {
    const MeshQuery& q = *queries_[f];
    const TriMesh& surface = q.surface();
    const std::vector<double> gap = union_signed_distance(surface.vertices, in_frames[f]);
    const std::vector<Eigen::Vector3d> normals = angle_weighted_normals(surface, face_normals(surface));
    for (size_t v = 0; v < gap.size(); ++v)
      out += gap[v] > target && !q.solid_beside(surface.vertices[v], normals[v]);
  }
  return out;
}

std::pair<double, size_t> PoseMapper::selection_size() const {
  if (opt_.tolerance > 0) return {opt_.tolerance, opt_.max_spheres};
  if (opt_.max_spheres > 0) return {0.0, opt_.max_spheres};
  if (spheres_.tolerance > 0 || spheres_.max_spheres > 0) return {spheres_.tolerance, spheres_.max_spheres};
  return {default_tolerance(rest_.diagonal()), 0};
}

SphereSet PoseMapper::carry(const SphereSet& rest, size_t f) const {
  SphereSet out(rest.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, rest.size(), 16), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t s = r.begin(); s != r.end(); ++s) {
      const Eigen::Vector3d& c = rest[s].center;
      out[s] = in_pose(c, f > 0 ? f_->locator().locate(c) : TetLocator::Location(), f, false).first;
    }
  });
  return out;
}

bool PoseMapper::same_spheres(const SphereSet& a, const SphereSet& b) {
  return std::equal(a.begin(), a.end(), b.begin(), b.end(), [](const Sphere& x, const Sphere& y) {
    return x.center == y.center && x.radius == y.radius;
  });
}

std::pair<Sphere, PoseSolid::Zero> PoseMapper::in_pose(const Eigen::Vector3d& c, const TetLocator::Location& at,
                                                       size_t i, bool cause) const {
  const Eigen::Vector3d center = i == 0 ? c : f_->map(c, at, deformed_[i - 1]);
  if (grow_) return solids_[i].grown(center, cause);
  const PoseSolid::Radius radius = solids_[i].radius(center, cause);
  return {{center, radius.value}, radius.zero};
}

std::vector<std::pair<Sphere, PoseSolid::Zero>> PoseMapper::in_poses(const Eigen::Vector3d& c, bool cause,
                                                                     SkinInfluence* followed) const {
  const TetLocator::Location at = f_->locator().locate(c);
  if (skinned_) return skinned_->spheres(c, at, solids_, cause, followed);
  std::vector<std::pair<Sphere, PoseSolid::Zero>> out;
  for (size_t i = 0; i < solids_.size(); ++i) out.push_back(in_pose(c, at, i, cause));
  return out;
}

PackOptions PoseMapper::pose_pack_options() const {
  PackOptions pack;
  pack.max_radius = proxy_.max_radius;
  pack.field_bounds_radius = open_solid_;
  return pack;
}

const DenseField& PoseMapper::pose_field(size_t i, bool inside_only) {
  if (fields_[i]) return *fields_[i];
  const std::string& source = i == 0 ? rest_source_ : poses_[i - 1].source;
  // A pose that encloses no volume (flattened, or mirrored so that it faces inward) is named.
  fields_[i] = about_file(source, [&] {
    try {
      return std::make_unique<DenseField>(
          build_sdf(*meshes_[i], field_options(inside_only), Log::silent(), &queries_[i]->boundary()).field);
    } catch (const GridTooLarge& e) {
      fail_field_too_fine(e, spheres_, source);
    }
  });
  return *fields_[i];
}

void PoseMapper::release_field(size_t i) {
  if (!open_solid_) fields_[i].reset();
}

SdfOptions PoseMapper::field_options(bool inside_only) const {
  SdfOptions o;
  o.inside_only = inside_only && !open_solid_;  // an open mesh's fields bound radii past the layer
  o.voxel_size = spheres_.voxel_size > 0 ? spheres_.voxel_size : rest_.diagonal() / 128;
  return o;
}

std::vector<ErrorStats> PoseMapper::pose_errors() const {
  std::vector<ErrorStats> out;
  for (size_t i = 0; i < proxy_.poses.size(); ++i) out.push_back(vertex_error(queries_[i]->surface(), proxy_.poses[i].spheres));
  return out;
}

bool PoseMapper::pose_from_cache(size_t i, bool skinned) {
  if (opt_.cache_dir.empty() || open_solid_) return false;  // an open body's fields are kept whole
  PoseCacheUse& use = pose_cache_[i];
  pose_cache_key_[i] = pose_cache_key(*meshes_[i], rest_, field_options(true), candidate_options(pose_pack_options()));
  use.file = pose_cache_file(opt_.cache_dir, pose_cache_key_[i]);
  std::optional<CachedPoseField> cached = read_pose_cache(use.file, pose_cache_key_[i]);
  if (!cached || (skinned && !cached->depths) || (i > 0 && !cached->voxels)) return false;
  if (skinned) depths_[i] = std::move(*cached->depths);
  if (i > 0) {
    pose_inscribed_[i - 1] = std::make_unique<CandidatesOnDemand>(std::move(*cached->voxels), cached->voxel_size,
                                                                  candidate_options(pose_pack_options()));
    pose_inscribed_[i - 1]->give_grown(cached->grown);
    use.grown_read = cached->grown.size();
  }
  use.read = true;
  return true;
}

std::string PoseMapper::carry_cache_key(bool held) const {
  uint64_t h = cache_key_start();
  for (const TriMesh* m : meshes_) h = fnv1a_values(fnv1a_values(h, m->vertices), m->triangles);
  h = fnv1a_values(h, skin_to_json(*skin_).dump());
  h = fnv1a_values(fnv1a_values(h, tets_.vertices), tets_.tets);
  const double numbers[4] = {field_options(true).voxel_size, proxy_.max_radius, open_solid_ ? 1.0 : 0.0,
                             double(meshes_.size())};
  h = fnv1a(h, numbers, sizeof numbers);
  if (held) h = fnv1a(h, &opt_.clip_overshoot, sizeof opt_.clip_overshoot);
  return cache_key_text(h);
}

SkinnedMap::Carried PoseMapper::carry_skinned(const SphereSet& rest) {
  if (opt_.cache_dir.empty()) return skinned_->carry(rest, solids_);
  if (!carry_cache_) {
    const std::string key = carry_cache_key(false);
    carry_cache_ = std::make_unique<CarryCache>(cache_file(opt_.cache_dir, "carry", key, "bin"), "carries", key);
  }
  std::vector<CarryCache::Key> keys;
  for (const Sphere& s : rest) keys.push_back(carry_key(s.center));
  const auto make = [&](const std::vector<size_t>& missing) { return skinned_->choices(pick(rest, missing), solids_); };
  return skinned_->carried(rest, carry_cache_->values(keys, make), solids_.size());
}

std::vector<double> PoseMapper::held_over_clip(const std::vector<SkinInfluence>& in, const std::vector<double>& r) {
  if (opt_.cache_dir.empty()) return clip_->least(in, r, &log_);
  if (!held_cache_) {
    const std::string key = carry_cache_key(true);
    held_cache_ = std::make_unique<HeldCache>(cache_file(opt_.cache_dir, "held", key, "bin"), "held radii", key);
  }
  std::vector<HeldCache::Key> keys;
  for (size_t s = 0; s < in.size(); ++s) keys.push_back(held_key(in[s], r[s]));
  const auto make = [&](const std::vector<size_t>& missing) { return clip_->least(pick(in, missing), pick(r, missing), &log_); };
  return held_cache_->values(keys, make);
}

namespace {
// A BitsCache's file written where this run added to it; one that cannot be written is a warning
// naming `what` it holds (the proxy does not need it).
template <class Cache>
void save_or_warn(const std::unique_ptr<Cache>& cache, const char* what, Log& log) {
  if (!cache) return;
  try {
    cache->save();
  } catch (const Error& e) {
    log.warn(std::string(e.what()) + ": " + what + " are not cached");
  }
}
}  // namespace

void PoseMapper::save_caches() {
  save_or_warn(carry_cache_, "the carries", log_);
  save_or_warn(held_cache_, "the radii held over the clip", log_);
  size_t unwritten = 0;
  std::string first_failure;
  for (size_t i = 0; i < pose_cache_.size(); ++i) {
    PoseCacheUse& use = pose_cache_[i];
    if (use.file.empty()) continue;
    CachedPoseField cached;
    if (!depths_.empty()) cached.depths = depths_[i];
    if (i > 0 && pose_inscribed_[i - 1]) {
      cached.voxels = pose_inscribed_[i - 1]->voxels();
      cached.voxel_size = pose_inscribed_[i - 1]->voxel_size();
      cached.grown = pose_inscribed_[i - 1]->grown();
    }
    use.grown_made = cached.grown.size() - use.grown_read;
    if (use.read && use.grown_made == 0) continue;
    try {
      write_pose_cache(use.file, pose_cache_key_[i], cached);
    } catch (const Error& e) {  // the proxy does not need it
      if (unwritten++ == 0) first_failure = e.what();
    }
  }
  if (unwritten > 0)
    log_.warn(first_failure + ": " + (unwritten == 1 ? "a pose's field is" : counted(unwritten, "pose") + "' fields are") +
              " not cached");
}

void PoseMapper::trim_cache(PoseMapSummary& out) {
  if (opt_.cache_dir.empty()) return;
  std::vector<std::string> in_use{tet_cache_file_};
  if (carry_cache_) in_use.push_back(carry_cache_->file());
  if (held_cache_) in_use.push_back(held_cache_->file());
  for (const PoseCacheUse& use : pose_cache_)
    if (!use.file.empty()) in_use.push_back(use.file);
  out.cache_folder = keep_cache_under(opt_.cache_dir, opt_.cache_limit, in_use, log_);
}

CandidatesOnDemand& PoseMapper::pose_inscribed(size_t i) {
  if (!pose_inscribed_[i] && !pose_from_cache(i + 1, false)) {
    pose_inscribed_[i] = std::make_unique<CandidatesOnDemand>(pose_field(i + 1, true), candidate_options(pose_pack_options()));
    release_field(i + 1);
  }
  return *pose_inscribed_[i];
}

SphereSet PoseMapper::pose_candidates_near(size_t i, const std::vector<Eigen::Vector3d>& points, double reach) {
  return pose_inscribed(i).offer_near(points, reach, *queries_[i + 1]);
}

void PoseMapper::list_pose_candidates_beside_tets(Log& log) {
  // Skinned: listed with its fields; mapped as given: never asked. With a cache folder the poses
  // asked are what the cache (and the report) records, whatever the tets' pace: none ahead.
  if (!grow_ || !opt_.cache_dir.empty()) return;
  std::optional<StageTimer> t;  // recorded where some pose was listed ahead
  for (size_t f : spanning_frames(meshes_, JointSelectionOptions().first_frames)) {
    if (tets_done_) return;
    if (f == 0) continue;
    if (!t) t.emplace(log, "own-candidates-beside-tets");
    try {
      pose_inscribed(f - 1);
    } catch (const Error&) {
      // A pose whose field fails (flat at this voxel size, say) fails the run only if the
      // selection asks it: it is asked again then, and its error named there.
      release_field(f);
    }
  }
}

SphereSet PoseMapper::map_back_to_rest(size_t i, const SphereSet& in_pose, size_t* lost, bool radii) const {
  SphereSet back = undeform_centres(tets_, deformed_[i], in_pose, *queries_[0], proxy_.max_radius, radii);
  if (lost) *lost = in_pose.size() - back.size();
  return back;
}

}  // namespace spx::detail
