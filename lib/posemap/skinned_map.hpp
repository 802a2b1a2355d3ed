#pragma once
// f for a rigged body: the skin itself, as the paper skins its tets. A point's joint weights
// inside the body are the surface's weights carried in by the harmonic extension, the 4
// heaviest kept and renormalised (as engines do, and in float, as the runtime holds them); its
// place in a pose is linear blend skinning with that pose's joint matrices. The point is first
// taken to the asset's own space (the host's) by the inverse of its blended rest matrix, so
// that the host's joint matrices skin it as they skin its mesh.
// Where parts overlap or weights jump (a robot's rigid parts, each on its own joint), the
// extension blends joints that no vertex near the point blends, and a sphere there drifts out of
// its part: such a sphere takes its closest surface point's weights instead when they keep it
// larger over the poses (choose()).
#include <array>
#include <Eigen/Core>
#include <vector>

#include "io/proxy_file.hpp"
#include "io/skin_file.hpp"
#include "posemap/harmonic_map.hpp"
#include "posemap/pose_solid.hpp"

namespace spx {

// Up to 4 joints of a point (weight 0 past the last), and the point in the asset's space.
struct SkinInfluence {
  std::array<int, 4> joint{{0, 0, 0, 0}};
  std::array<float, 4> weight{{0, 0, 0, 0}};
  Eigen::Vector3d bind = Eigen::Vector3d::Zero();
};

// The 4 heaviest of `weights` (one per joint; ties to the lower joint), negatives dropped,
// renormalised and rounded to float, as the runtime holds them.
SkinInfluence heaviest_four(const Eigen::VectorXd& weights);

// sum_j w_j M_j x, in double.
Eigen::Vector3d skin_point(const SkinInfluence& s, const JointMatrices& m);

// A mesh's vertices as the skin moves them, every weight kept (as pose-extract skins the asset):
// each rest vertex is taken back to the asset's space by the inverse of its blended rest matrix,
// then blended by any pose's matrices. A vertex no joint weighs, or whose blended rest matrix is
// singular, is not bound and stays where it is.
class SkinnedVertices {
 public:
  // `skin`'s vertex weights are `rest`'s, one list per vertex.
  SkinnedVertices(const SkinFile& skin, const std::vector<Eigen::Vector3d>& rest);
  bool bound(size_t v) const { return bound_[v]; }
  Eigen::Vector3d at(size_t v, const JointMatrices& m) const;
  std::vector<Eigen::Vector3d> all(const JointMatrices& m) const;

 private:
  const std::vector<JointWeights>& weights_;
  std::vector<Eigen::Vector3d> bind_;
  std::vector<char> bound_;
};

// A rigged rest split at its edges' midpoints `times` over (split_at_midpoints), its skin with it
// (append_midpoint_weights; `skin`'s vertex weights are `rest`'s, one list per vertex) and each of
// the skin's poses skinned afresh, so that the poses are what the skin makes of the split rest: a
// rigged body of a scan's density made from a shared one, for the benchmarks and tests.
struct SplitSkinned {
  TriMesh rest;
  SkinFile skin;                // vertex weights and positions the split rest's
  std::vector<TriMesh> poses;   // one per skin.poses
};
SplitSkinned split_skinned(const TriMesh& rest, SkinFile skin, int times);

class SkinnedMap {
 public:
  // `skin`'s vertex weights are the rest mesh's (one list per vertex of `f`'s rest mesh).
  SkinnedMap(const SkinFile& skin, const HarmonicMap& f);

  // The harmonic influence of rest point p, at `at` in the tets.
  SkinInfluence influence(const Eigen::Vector3d& p, const TetLocator::Location& at) const;
  // The influence of rest point p's closest point on the rest mesh (`rest`): `closest`,
  // rest.closest(p), which the caller asks (choose() asks it once for the rest radius too).
  SkinInfluence surface_influence(const Eigen::Vector3d& p, const MeshQuery& rest, const ClosestPoint& closest) const;
  // The influence a sphere centred at rest point c follows, and its one radius (the least of its
  // radii by `solids`, one per pose, over every pose): the harmonic influence, or the surface's
  // where that keeps a larger radius (the rest's radius bounds both, so a harmonic sphere that
  // keeps it is final).
  struct Choice {
    SkinInfluence influence;
    double radius = 0;
  };
  // `kept`, where given, gets per pose a radius it surely keeps (0 where choose did not ask it).
  Choice choose(const Eigen::Vector3d& c, const TetLocator::Location& at, const std::vector<PoseSolid>& solids,
                std::vector<double>* kept = nullptr) const;
  // Rest point c (of influence s) in pose i (0: the rest, c itself).
  Eigen::Vector3d center(const SkinInfluence& s, const Eigen::Vector3d& c, size_t i) const {
    return i == 0 ? c : skin_point(s, matrices(i));
  }
  // Pose i's joint matrices (0: the rest).
  const JointMatrices& matrices(size_t i) const { return i == 0 ? skin_.rest : skin_.poses[i - 1].matrices; }
  // The spheres rest center c (at `at`) becomes in every pose (0: the rest): skinned by choose(),
  // each with its one radius; why a radius is 0 if it is (`cause`: tell an outside centre from a
  // hole's bound); `followed` gets the influence chosen.
  std::vector<std::pair<Sphere, PoseSolid::Zero>> spheres(const Eigen::Vector3d& c, const TetLocator::Location& at,
                                                          const std::vector<PoseSolid>& solids, bool cause,
                                                          SkinInfluence* followed) const;
  // Rest centres carried into every pose ([pose][centre]; pose 0: the rest) by choose(), each
  // with its one radius, as spheres() gives them. `rest`'s radii are unused.
  struct Carried {
    std::vector<std::vector<Eigen::Vector3d>> centers;
    std::vector<double> radii;
    std::vector<SkinInfluence> influences;
  };
  Carried carry(const SphereSet& rest, const std::vector<PoseSolid>& solids) const;
  // carry() in its two steps (so that pose-map's cache can keep the first): each centre's
  // choice, then the centres in each of `poses` poses by it.
  std::vector<Choice> choices(const SphereSet& rest, const std::vector<PoseSolid>& solids) const;
  Carried carried(const SphereSet& rest, const std::vector<Choice>& chosen, size_t poses) const;
  // The proxy's skin: the joints, and each of `rest`'s spheres (its radius the one radius) with
  // the influence it follows (one per sphere, as spheres() chose them).
  ProxySkin proxy_skin(const SphereSet& rest, const std::vector<SkinInfluence>& influences) const;
  // Every tet vertex skinned into pose i (i >= 1) by its own influence.
  std::vector<Eigen::Vector3d> deform_tets(size_t i) const;

 private:
  const SkinFile& skin_;
  const HarmonicMap& f_;
  Eigen::MatrixXd vertex_weights_;  // a row per rest vertex, a column per joint
  Eigen::MatrixXd tet_weights_;     // a row per tet vertex, a column per joint
};

}  // namespace spx
