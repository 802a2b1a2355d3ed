#pragma once
// pose-map's joint selection: one sphere set for the rest and every frame, chosen from rest
// candidates mapped into the frames, as one set cover. A clip's frames are alike, so it does not
// pay for each: it selects on a few frames that span the motion, checks every frame with the
// spheres chosen, adds what they leave bare, and selects again until nothing is (constraint
// generation). What is added: a frame whole, where each sphere has its own radius in each frame
// (grown there, which costs a query per candidate); for a skinned body, whose spheres have one
// radius and cost nothing to carry into a frame, only the bare samples; and then (tolerance
// mode) the problem keeps from round to round only the samples its reduction kept, so a round
// costs what the clip's hard samples cost, not what all its frames do. A clip's alike frames
// offer much the same candidates: one per place is kept (`spacing`). A skinned candidate's one
// radius is held over the whole clip (over_clip) as it is offered, before any cover sees it.
// Where every frame is selected on in the first round, that is the one cover over all of them.
// At a tolerance, a vertex no candidate reaches in some frame is offered balls through it there
// and, skinned, where the skin folds and cuts every ball through it in some frame, small balls
// around it; so that only what none of them reaches (a fold no ball beside the vertex stays
// inside through, an open part at its field's resolution, a sharp feature) leaves the tolerance
// unmet, and the report says which.
// Budget mode checks the other frames once (a round is a whole budget cover there), then refines
// the chosen centres over every frame's samples.
#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "core/log.hpp"
#include "core/sphere.hpp"
#include "mesh/mesh.hpp"
#include "pack/candidates.hpp"
#include "pack/cover.hpp"
#include "pack/select.hpp"
#include "posemap/skinned_map.hpp"

namespace spx {

// What the selection asks of pose-map's map. Frame 0 is the rest.
class SelectionFrames {
 public:
  virtual ~SelectionFrames() = default;
  virtual size_t frame_count() const = 0;
  virtual const TriMesh& frame_mesh(size_t frame) const = 0;
  // Where the frame's samples are drawn: its mesh less walls inside the solid (solid_surface).
  virtual const TriMesh& frame_surface(size_t frame) const { return frame_mesh(frame); }
  // Not skinned: each rest centre's sphere in `frame` by that frame's own rule (grown there).
  virtual SphereSet spheres_in(const SphereSet& rest, size_t frame) const = 0;
  // A skinned body: one radius per sphere, the least of its radii over every frame.
  virtual bool one_radius() const = 0;
  // Skinned: each rest centre carried into every frame, and its one radius.
  virtual SkinnedMap::Carried carry_skinned(const SphereSet& rest) const = 0;
  // Skinned: the radius at `center` in `frame`, exact (carry_skinned's radii skip frames by
  // estimates; the chosen ones are checked against this in every frame).
  virtual double exact_radius(const Eigen::Vector3d& center, size_t frame) const = 0;
  // Skinned: the least of each radius and its radius over the whole clip (ClipRadius; the
  // radii as given without a clip).
  virtual std::vector<double> over_clip(const std::vector<SkinInfluence>&, const std::vector<double>& radius) const {
    return radius;
  }
  // The spheres a rest centre becomes in every frame, every frame filled (spheres_in's; skinned:
  // its one radius, exact in every frame, which the default cannot give); false where one of them
  // has radius 0.
  virtual bool spheres_at(const Eigen::Vector3d& rest_center, std::vector<Sphere>& in_frames) const;
  // `frame`'s own inscribed spheres within `reach` of `points` (its samples no candidate
  // reaches), mapped back to the rest; each of them offered once. With one radius (skinned) only
  // the centres count: carry_skinned finds the radius over the clip, and the rest's is not asked.
  virtual SphereSet frame_candidates(size_t frame, const std::vector<Eigen::Vector3d>& points, double reach) = 0;
  // `frame`'s balls touching each of its samples `which` (indices into `drawn`, sample_surface of
  // frame_surface), which nothing else reaches within `delta`: the largest inscribed ball tangent
  // there and (one radius) balls nested in it down to half of delta, mapped back to the rest.
  // `around` (one radius, for the samples even those leave out of reach): balls around each
  // sample within delta of it instead (balls_around), mapped back to the rest (one radius: the
  // centres, as frame_candidates').
  virtual SphereSet touching_candidates(size_t frame, const SurfaceSamples& drawn, const std::vector<uint32_t>& which,
                                        double delta, bool around) = 0;
};

struct JointSelectionOptions {
  double target = 0;         // a length; 0: none (budget only)
  size_t budget = 0;         // 0: none
  double reach = 0;          // frame candidates are offered within this of a bare sample
  double spacing = 0;        // skinned: a frame candidate within this of one offered (at rest) is not
  bool field_bounds_radii = false;  // an open mesh: its fields bound every radius across its holes
  size_t area_samples = kDefaultAreaSamples;
  uint64_t seed = 1;
  // Tolerance mode: a frame selected on whose vertices lie much closer together than the
  // tolerance is covered on those kCoverSpacing x it apart, then every vertex checked (false:
  // every vertex from the start).
  bool spaced_vertices = true;
  size_t first_frames = 6;   // poses selected on in the first round (those farthest apart)
  size_t frames_per_round = 4;
  // Budget mode: the chosen rest centres then move off the candidates (from this step down to an
  // eighth of it) where that lowers every frame's largest vertex error, then their total and
  // median (refine_jointly; each move's spheres by spheres_at); 0: they stay.
  double refine_step = 0;
  // Budget mode, after the refinement: the refined spheres join the candidates, and the budget is
  // covered and refined again this many times (sphere-pack's polish, over every frame); a set
  // whose worst frame's max is no higher and whose product of it and the frames' mean median is
  // lower is kept.
  int polish_rounds = 1;
  // No sphere chosen smaller than this at rest (skinned: its one radius), as sphere-pack's
  // --min-radius keeps its own; a candidate smaller is withdrawn (counted), a refinement's move
  // that would make one refused. 0: none.
  double min_radius = 0;
};

struct JointSelection {
  SphereSet chosen;  // rest spheres, largest first (skinned: each with its one radius)
  CoverResult cover;
  Limit limited_by = Limit::tolerance;
  size_t candidates = 0, from_frames = 0, mostly_absent = 0, samples = 0;
  size_t below_min_radius = 0;     // candidates withdrawn, smaller at rest than min_radius,
  double largest_below_min = 0;    // the largest of them
  size_t touched = 0, from_touching = 0;  // tolerance: samples out of reach offered balls touching them, and those balls
  size_t around = 0, from_around = 0;      // skinned: those still out of reach offered balls around them
  std::vector<size_t> frames;   // the frames selected on, ascending (0: the rest)
  size_t rounds = 0;
  size_t spaced_frames = 0;     // frames selected on whose vertices were spaced (spaced_vertices),
  double vertex_spacing = 0;    // that far apart (0: none was)
  size_t spaced_joined = 0;     // of their vertices left out, those a cover left near or past the tolerance, then joined
  size_t samples_elsewhere = 0; // samples of the other frames in the problem (skinned)
  size_t bare_elsewhere = 0;    // samples of the other frames no candidate reaches at the cover's delta
  size_t vertices_out_of_reach = 0;  // of those and the cover's uncoverable, the vertices
  size_t vertices_with_no_solid = 0; // open bodies: of those, the ones with no solid beside them in their pose
  size_t out_of_reach_added = 0;     // not skinned: spheres that bring those vertices as near as any candidate comes,
  double out_of_reach_delta = 0;     // the least delta that reaches them all (0: none)
  size_t out_of_reach() const { return cover.uncoverable() + bare_elsewhere; }  // samples, over every frame
  size_t clip_shrunk = 0;       // skinned: candidates whose one radius the clip lowered
  size_t radii_checked = 0;     // skinned: chosen candidates whose one radius was checked in every frame
  size_t radii_lowered = 0;     // of those, the radii the check lowered (each lowering covers again)
  size_t covers_redone = 0;     // skinned: covers of the same problem again, a chosen radius lowered
  size_t candidates_checked = 0;  // skinned: candidates checked at once, lowered twice in a row (check_every_radius)
  size_t candidates_lowered = 0;  // of those, the radii it lowered
  size_t refined_moves = 0;     // the chosen centres' moves off the candidates (refine_step)
  int polish_rounds = 0;        // budget mode: the polish rounds run
  size_t polished = 0;          // budget mode: the polish round whose set was kept (0: the first refinement's)
};

JointSelection select_jointly(SelectionFrames& frames, const SphereSet& candidates, const JointSelectionOptions& options,
                              Log& log = Log::silent());

// The report's words for the selection's samples out of reach: how many, and why (at a
// tolerance the vertices among them were offered balls through them).
std::string out_of_reach_wording(const JointSelection& selection, const JointSelectionOptions& options, bool skinned);

// Each of `chosen`'s rest centres in every frame (spheres_at): per frame, in `chosen`'s order.
std::vector<SphereSet> spheres_in_frames(const SelectionFrames& frames, const SphereSet& chosen);

// Every frame's `samples` (each frame's vertices first) against `chosen` carried there, as a
// refinement's move carries it: the worst frame's max and largest gap, and the frames' mean
// median (the polish keeps a set by these).
UnionGaps frame_gaps(const SelectionFrames& frames, const std::vector<std::vector<Eigen::Vector3d>>& samples,
                     const SphereSet& chosen);

// The first round's frames: the rest, then up to `count` poses, each the farthest (largest
// vertex displacement) from those already taken; ascending.
std::vector<size_t> spanning_frames(const SelectionFrames& frames, size_t count);
// The same over the frames' meshes (the rest first), before any map is made.
std::vector<size_t> spanning_frames(const std::vector<const TriMesh*>& meshes, size_t count);

}  // namespace spx
