#include "posemap/posemap.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <optional>
#include <tuple>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include "core/error.hpp"
#include "core/tolerance.hpp"
#include "mesh/mesh_query.hpp"
#include "mesh/defects.hpp"
#include "mesh/union_distance.hpp"
#include "pack/candidates.hpp"
#include "pack/pack.hpp"
#include "posemap/gap_filling.hpp"
#include "posemap/harmonic_map.hpp"
#include "posemap/joint_selection.hpp"
#include "posemap/pose_solid.hpp"
#include "posemap/skinned_map.hpp"
#include "posemap/spheres_fit.hpp"
#include "sdf/sdf.hpp"

namespace spx {
namespace {

// Skinned: a frame's own candidate within this many voxels (at rest) of one offered is not (at 48
// frames of the elephant's walk, a quarter as many candidates and no more spheres).
constexpr double kFrameCandidateSpacing = 0.5;

// pose-map's steps, in the order pose_map() takes them, and the state they share: the tets and
// the map f, each pose's tet vertices and solid, and the proxy as it grows.
class PoseMapper {
 public:
  PoseMapper(const TriMesh& rest, const std::string& rest_source, const std::vector<PoseInput>& poses,
             const SpheresFile& spheres, const PoseMapOptions& opt, const SkinFile* skin, ProxyModel& proxy, Log& log)
      : rest_(rest), rest_source_(rest_source), poses_(poses), spheres_(spheres), opt_(opt), skin_(skin), proxy_(proxy),
        log_(log) {}

  // The paper's tet mesh of M_0: CGAL Mesh_3, or the user's.
  void make_tets() {
    StageTimer t(log_, "tetrahedralize");
    tets_ = opt_.tet_file.empty() ? tetrahedralize(rest_, opt_.tets, log_) : read_medit_tets(opt_.tet_file);
    log_.detail(std::to_string(tets_.tets.size()) + " tets, " + std::to_string(tets_.vertices.size()) + " vertices");
  }

  // f: the surface motion of every pose carried to the tet vertices; for a rigged body the skin,
  // its weights carried in by the same extension, and the tets skinned (for the inverse map).
  void solve_map() {
    StageTimer t(log_, "harmonic");
    f_ = std::make_unique<HarmonicMap>(tets_, rest_, log_);
    if (skin_) skinned_ = std::make_unique<SkinnedMap>(*skin_, *f_);
    // A clip that also drives morph weights is more than its skin: its frames cannot be rebuilt.
    if (opt_.hold_over_clip && !skin_) fail_option("hold_over_clip", "needs poses with a rig (pose-extract --animation)");
    if (opt_.hold_over_clip && skin_->clip.empty()) fail_option("hold_over_clip", "the skin has no clip (an older skin.json)");
    if (opt_.hold_over_clip && skin_->morph_channels > 0)
      log_.warn("the clip also drives morph weights: skinned radii hold at the poses, not between them");
    else if (opt_.hold_over_clip)
      clip_ = std::make_unique<ClipRadius>(*skin_, rest_, proxy_.max_radius, opt_.clip_overshoot);
    for (size_t i = 0; i < poses_.size(); ++i)
      deformed_.push_back(skinned_ ? skinned_->deform_tets(i + 1) : f_->deform(poses_[i].mesh));
  }

  // Each pose's solid, the rest's included: exact distances and, for open meshes (whose solid
  // also ends across the holes, where there are no triangles), the pose's own field at the
  // spheres' voxel size. One rule then sets every radius. Needs the poses alone, not the tets.
  void build_solids(Log& log) {
    const bool skinned = skin_ != nullptr;  // skinned_ is made beside this
    meshes_.push_back(&rest_);
    for (const PoseInput& input : poses_) meshes_.push_back(&input.mesh);
    // Pose by pose in parallel (each also parallel inside, where its steps allow).
    queries_.resize(meshes_.size());
    {
      StageTimer t(log, "pose-queries");
      tbb::parallel_for(size_t(0), meshes_.size(), [&](size_t i) { queries_[i] = std::make_unique<MeshQuery>(*meshes_[i]); });
    }
    // Before anything is built at the spheres' voxel size.
    check_spheres_fit(*queries_[0], spheres_, rest_source_);
    open_solid_ = !find_defects(rest_).watertight();
    fields_.resize(meshes_.size());
    // Open meshes: the fields bound radii across the holes. Skinned: they put floors under every
    // pose's radii, so that a sphere's one radius asks few poses.
    if (open_solid_ || skinned) {
      StageTimer t(log, "pose-fields");
      if (skinned) depths_.resize(meshes_.size()), pose_inscribed_.resize(poses_.size());
      tbb::parallel_for(size_t(0), meshes_.size(), [&](size_t i) {
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

  // The joint selection runs (rather than the file's spheres mapped as given).
  bool selects_jointly() const {
    return !opt_.map_given && (opt_.tolerance > 0 || opt_.max_spheres > 0 || !spheres_.candidates.empty());
  }

  // One sphere set for the rest and every pose (posemap/joint_selection.hpp), recorded in the
  // summary. Returns the chosen candidates (rest pose).
  SphereSet select_jointly(const SphereSet& file_candidates, PoseMapSummary& summary) {
    JointSelectionOptions options;
    std::tie(options.target, options.budget) = selection_size();
    options.reach = options.target > 0 ? options.target : default_tolerance(rest_.diagonal());
    // Not on open parts: half a voxel is much of a wall there (the robot's walk lost 50 samples).
    options.spacing = open_solid_ ? 0.0 : kFrameCandidateSpacing * field_options().voxel_size;
    options.field_bounds_radii = open_solid_;
    options.area_samples = opt_.area_samples;
    options.seed = opt_.seed;
    options.refine_step = clip_ ? 0.0 : 0.5 * field_options().voxel_size;  // as sphere-pack; not a held clip's radii
    options.polish_rounds = opt_.polish_rounds >= 0 ? opt_.polish_rounds : skinned_ ? 0 : 1;
    Frames frames(*this);
    const JointSelection selection = spx::select_jointly(frames, file_candidates, options, log_);
    const std::string why = out_of_reach_wording(selection, options, bool(skinned_));
    const bool missed = !(options.target > 0) || selection.vertices_out_of_reach > 0;
    if (selection.out_of_reach() > 0) missed ? log_.warn(why) : log_.detail(why);
    summary.selection = selection;
    summary.selection_target = options.target;
    return selection.chosen;
  }

  // S_1..S_e: appends rest spheres to every pose, centers through f, and in every pose (the
  // rest too) the radius by the one rule of PoseSolid.
  void map_spheres(const SphereSet& rest_spheres) {
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

  // Skinned: the spheres just mapped (from `first`) keep their one radius over the whole clip,
  // in every pose (as the selection held its candidates: the same radii, bit for bit).
  void hold_over_clip(size_t first, size_t n, std::vector<std::vector<char>>& cause) {
    if (!clip_) return;
    const std::vector<SkinInfluence> influences(influences_.begin() + long(first), influences_.end());
    std::vector<double> radii(n);
    for (size_t s = 0; s < n; ++s) radii[s] = proxy_.poses[0].spheres[first + s].radius;
    const std::vector<double> held = clip_->least(influences, radii, &log_);
    for (size_t s = 0; s < n; ++s) {
      if (!(held[s] < radii[s])) continue;
      ++clip_shrunk_;
      for (size_t i = 0; i < proxy_.poses.size(); ++i) {
        proxy_.poses[i].spheres[first + s].radius = held[s];
        if (held[s] == 0 && cause[i][s] == char(PoseSolid::Zero::none)) cause[i][s] = char(PoseSolid::Zero::another_pose);
      }
    }
  }

  // The paper's future work: pack what each pose's mapped spheres leave uncovered, and map the
  // new spheres back to the rest pose through the inverse map.
  GapFilling fill_gaps() {
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

  // Blend sites: the nearest rest tet vertex of each sphere (the paper's local blend).
  void assign_blend_sites() {
    BlendSites b = blend_sites(tets_, rest_centers_);
    proxy_.sites = std::move(b.sites);
    proxy_.sphere_sites = std::move(b.of_point);
  }

  // A rigged body's proxy carries each sphere's influence and its one radius.
  void attach_skin() {
    if (skinned_) proxy_.skin = skinned_->proxy_skin(proxy_.poses[0].spheres, influences_);
  }

  // Skinned, radii not held over the clip: the spheres checked at its other times, which a host
  // plays (the poses given say nothing of them).
  void check_between_poses(PoseMapSummary& out) const {
    if (!skinned_ || clip_ || skin_->clip.empty() || skin_->morph_channels > 0) return;
    StageTimer t(log_, "clip-check");
    out.between = check_over_clip(*skin_, rest_, proxy_.max_radius, proxy_.poses[0].spheres, influences_, log_);
  }

  // Warnings for every radius 0, and the summary's tets, map, per-pose errors and zero radii.
  void summarize(PoseMapSummary& out) const {
    for (size_t i = 0; i < proxy_.poses.size(); ++i) {
      const auto& [outside, holes, other, elsewhere] = zero_radius_[i];
      if (outside > 0)
        log_.warn(proxy_.poses[i].source + ": " + std::to_string(outside) +
                  " sphere centers land outside this pose; those spheres get radius 0 in it");
      if (holes + other > 0)
        log_.warn(proxy_.poses[i].source + ": " + std::to_string(holes + other) + " spheres get radius 0 in this pose (" +
                  std::to_string(holes) + " bounded by its holes, " + std::to_string(other) + " on its surface)");
      if (elsewhere > 0)
        log_.warn(proxy_.poses[i].source + ": " + std::to_string(elsewhere) +
                  " skinned spheres get radius 0 here because they have it in another pose");
    }
    out.zero_radius = zero_radius_;
    out.errors = pose_errors();
    for (const auto& q : queries_) out.walls.emplace_back(q->internal_walls(), q->split_triangles());
    for (const auto& c : rest_centers_) out.centers_outside_tets += f_->locator().locate(c).outside > 0;
    out.tet_file = opt_.tet_file;
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

 private:
  // The tolerance (as a length, 0: none) and budget asked here, or else what sphere-pack was
  // asked, or else the default tolerance.
  std::pair<double, size_t> selection_size() const {
    if (opt_.tolerance > 0) return {opt_.tolerance, opt_.max_spheres};
    if (opt_.max_spheres > 0) return {0.0, opt_.max_spheres};
    if (spheres_.tolerance > 0 || spheres_.max_spheres > 0) return {spheres_.tolerance, spheres_.max_spheres};
    return {default_tolerance(rest_.diagonal()), 0};
  }

  // The map as the joint selection sees it.
  class Frames : public SelectionFrames {
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
      return m_.clip_ ? m_.clip_->least(in, r, &m_.log_) : r;
    }
    SkinnedMap::Carried carry_skinned(const SphereSet& rest) const override { return m_.skinned_->carry(rest, m_.solids_); }
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

  std::string proxy_pose_name(size_t f) const { return f == 0 ? stem_of(rest_source_) : poses_[f - 1].name; }

  // Not skinned: rest spheres carried into frame f (0: the rest) by in_pose.
  SphereSet carry(const SphereSet& rest, size_t f) const {
    SphereSet out(rest.size());
    tbb::parallel_for(tbb::blocked_range<size_t>(0, rest.size(), 16), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t s = r.begin(); s != r.end(); ++s) {
        const Eigen::Vector3d& c = rest[s].center;
        out[s] = in_pose(c, f > 0 ? f_->locator().locate(c) : TetLocator::Location(), f, false).first;
      }
    });
    return out;
  }

  static bool same_spheres(const SphereSet& a, const SphereSet& b) {
    return std::equal(a.begin(), a.end(), b.begin(), b.end(), [](const Sphere& x, const Sphere& y) {
      return x.center == y.center && x.radius == y.radius;
    });
  }

  // Not skinned: rest center c (at `at` in the tets) in pose i (0: the rest): its center through
  // f, its radius by the pose's rule (then grown, under joint selection), and why it is 0 if it is.
  std::pair<Sphere, PoseSolid::Zero> in_pose(const Eigen::Vector3d& c, const TetLocator::Location& at, size_t i,
                                             bool cause) const {
    const Eigen::Vector3d center = i == 0 ? c : f_->map(c, at, deformed_[i - 1]);
    if (grow_) return solids_[i].grown(center, cause);
    const PoseSolid::Radius radius = solids_[i].radius(center, cause);
    return {{center, radius.value}, radius.zero};
  }

  // The spheres a rest center c becomes in every pose (0: the rest), each by in_pose; a skinned
  // sphere keeps the least of its radii in every pose.
  std::vector<std::pair<Sphere, PoseSolid::Zero>> in_poses(const Eigen::Vector3d& c, bool cause,
                                                           SkinInfluence* followed) const {
    const TetLocator::Location at = f_->locator().locate(c);
    if (skinned_) return skinned_->spheres(c, at, solids_, cause, followed);
    std::vector<std::pair<Sphere, PoseSolid::Zero>> out;
    for (size_t i = 0; i < solids_.size(); ++i) out.push_back(in_pose(c, at, i, cause));
    return out;
  }

  // Packing in a pose's own field: the proxy's max radius, and the field bounding radii across
  // an open mesh's holes.
  PackOptions pose_pack_options() const {
    PackOptions pack;
    pack.max_radius = proxy_.max_radius;
    pack.field_bounds_radius = open_solid_;
    return pack;
  }

  // Pose i's own field (0: the rest) at the spheres' voxel size, built once when first asked.
  // `inside_only`: for the inside's depths and medial voxels alone (released before other use).
  const DenseField& pose_field(size_t i, bool inside_only = false) {
    if (!fields_[i]) try {
        fields_[i] = std::make_unique<DenseField>(
            build_sdf(*meshes_[i], field_options(inside_only), Log::silent(), &queries_[i]->boundary()).field);
      } catch (const GridTooLarge& e) {
        fail_field_too_fine(e, spheres_, i == 0 ? rest_source_ : poses_[i - 1].source);
      }
    return *fields_[i];
  }
  // An open mesh's fields bound every radius to the end; otherwise each is asked once (a skinned
  // body's floors are kept as its depths).
  void release_field(size_t i) {
    if (!open_solid_) fields_[i].reset();
  }

  SdfOptions field_options(bool inside_only = false) const {
    SdfOptions o;
    o.inside_only = inside_only && !open_solid_;  // an open mesh's fields bound radii past the layer
    o.voxel_size = spheres_.voxel_size > 0 ? spheres_.voxel_size : rest_.diagonal() / 128;
    return o;
  }

  std::vector<ErrorStats> pose_errors() const {
    std::vector<ErrorStats> out;
    for (size_t i = 0; i < proxy_.poses.size(); ++i) out.push_back(vertex_error(queries_[i]->surface(), proxy_.poses[i].spheres));
    return out;
  }

  // Pose i's own inscribed candidates that come within `reach` of any of `points` (samples of
  // that pose no mapped candidate reaches) and were not offered before, in pose coordinates.
  SphereSet pose_candidates_near(size_t i, const std::vector<Eigen::Vector3d>& points, double reach) {
    if (pose_inscribed_.size() < poses_.size()) pose_inscribed_.resize(poses_.size());
    if (!pose_inscribed_[i]) {
      pose_inscribed_[i] = std::make_unique<CandidatesOnDemand>(pose_field(i + 1, true), candidate_options(pose_pack_options()));
      release_field(i + 1);
    }
    return pose_inscribed_[i]->offer_near(points, reach, *queries_[i + 1]);
  }

  // Through the inverse map (barycentric in pose i's deformed tets); those that land outside
  // the rest are counted in `lost`. Without `radii` (skinned candidates, whose carry finds each
  // radius over the clip from the centre alone) every radius is 0.
  SphereSet map_back_to_rest(size_t i, const SphereSet& in_pose, size_t* lost = nullptr, bool radii = true) const {
    SphereSet back = undeform_centres(tets_, deformed_[i], in_pose, *queries_[0], proxy_.max_radius, radii);
    if (lost) *lost = in_pose.size() - back.size();
    return back;
  }

  const TriMesh& rest_;
  const std::string& rest_source_;
  const std::vector<PoseInput>& poses_;
  const SpheresFile& spheres_;
  const PoseMapOptions& opt_;
  const SkinFile* skin_;  // the poses' rig, or null
  ProxyModel& proxy_;
  Log& log_;
  TetMesh tets_;
  std::unique_ptr<HarmonicMap> f_;
  std::unique_ptr<SkinnedMap> skinned_;  // f for a rigged body
  std::vector<SkinInfluence> influences_;  // skinned: the influence each written sphere follows
  std::unique_ptr<ClipRadius> clip_;     // its clip between the poses, where the skin has it
  size_t clip_shrunk_ = 0;               // written spheres the clip shrank
  std::vector<std::vector<Eigen::Vector3d>> deformed_;  // per pose: tet vertices
  std::vector<const TriMesh*> meshes_;                  // rest, then the poses
  std::vector<std::unique_ptr<MeshQuery>> queries_;
  bool open_solid_ = false;
  std::vector<std::unique_ptr<DenseField>> fields_;  // per pose, built when first asked
  std::vector<DepthField> depths_;                   // skinned, per pose: its field's depths (floors)
  std::vector<PoseSolid> solids_;
  std::unique_ptr<DeformingQuery> deforming_;    // skinned, closed: one hierarchy refitted to each frame
  std::vector<DeformingQuery::Shape> shapes_;
  std::vector<std::unique_ptr<CandidatesOnDemand>> pose_inscribed_;  // per pose: its own candidates
  std::vector<Eigen::Vector3d> rest_centers_;            // for the blend sites
  std::vector<std::array<size_t, 4>> zero_radius_;       // per pose, by cause
  bool grow_ = false;                                    // spheres grown in every pose (joint selection)
  std::optional<SphereSet> rest_grown_;                  // the file's candidates carried into the rest (grown)
};

}  // namespace

PoseMapResult pose_map(const TriMesh& rest, const std::string& rest_source, const std::vector<PoseInput>& poses,
                       const SpheresFile& spheres, const PoseMapOptions& opt, Log& log, const SkinFile* skin) {
  if (std::isnan(opt.max_radius) || opt.max_radius < 0) fail_option("max_radius", "must be a positive number");
  if (std::isnan(opt.fill_min_radius) || opt.fill_min_radius < 0) fail_option("fill_min_radius", "must be a positive number");
  if (!(opt.tolerance >= 0)) fail_option("tolerance", "must be a positive length");
  if (!(opt.fill_tolerance >= 0)) fail_option("fill_tolerance", "must be a positive length");
  PoseMapResult result;
  result.proxy.max_radius = opt.max_radius > 0 ? opt.max_radius : spheres.max_radius;
  PoseMapper mapper(rest, rest_source, poses, spheres, opt, skin, result.proxy, log);
  // Mesh_3 keeps one core: the poses' solids (their queries and, skinned or open, fields) are
  // built on the other meanwhile.
  Log beside = log.fork();
  tbb::parallel_invoke([&] { mapper.make_tets(); mapper.solve_map(); }, [&] { mapper.build_solids(beside); });
  log.join(beside);
  const bool joint = mapper.selects_jointly();
  if (joint && spheres.candidates.empty())
    fail_option(opt.max_spheres > 0 ? "max_spheres" : "tolerance",
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
  mapper.assign_blend_sites();
  mapper.attach_skin();
  mapper.check_between_poses(result.summary);
  mapper.summarize(result.summary);
  return result;
}

}  // namespace spx
