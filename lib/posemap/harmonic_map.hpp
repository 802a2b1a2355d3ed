#pragma once
// The map f from the rest shape into each pose: the surface motion carried into the interior
// by a harmonic extension on the tets, evaluated by barycentric interpolation (the paper's f).
//
// Displacements u at tet vertices minimise  |C u - d|^2 + |L u|^2  where each row of C puts a
// rest surface point (a mesh vertex, or the closest surface point of a boundary tet vertex) in
// its tet with barycentric weights, d is that point's known displacement in the pose, and L are
// the FEM Laplacian rows of interior tet vertices, each scaled to a unit diagonal. Both terms
// vanish on affine motions, so affine poses map exactly; the factorisation is shared by poses.
#include <Eigen/Core>
#include <Eigen/SparseCholesky>
#include <memory>
#include <optional>
#include <vector>

#include "core/log.hpp"
#include "core/sphere.hpp"
#include "mesh/mesh.hpp"
#include "mesh/mesh_query.hpp"
#include "posemap/tet_mesh.hpp"

namespace spx {

// Point location in a tet mesh; points just outside use the tet of the nearest boundary face
// (extrapolated barycentric weights, still exact for affine functions).
class TetLocator {
 public:
  explicit TetLocator(const TetMesh& mesh);
  ~TetLocator();
  struct Location {
    int tet = -1;
    Eigen::Vector4d weights = Eigen::Vector4d::Zero();
    double outside = 0;  // distance to the tet mesh, 0 when inside
  };

  Location locate(const Eigen::Vector3d& p) const;
  const TetMesh& mesh() const { return mesh_; }

 private:
  Eigen::Vector4d weights(int tet, const Eigen::Vector3d& p) const;
  const TetMesh& mesh_;
  std::vector<Eigen::Matrix3d> inverse_;  // per tet: inverse of [x1-x0, x2-x0, x3-x0]
  Eigen::AlignedBox3d box_;
  double cell_ = 1;
  Eigen::Vector3i cells_;
  std::vector<int> cell_start_, cell_tets_;
  std::unique_ptr<MeshQuery> boundary_;
};

// Points in a deformed copy of `tets` (its vertices `deformed`) taken back to `tets`:
// barycentric in the deformed tet that holds each; nullopt where none does.
std::vector<std::optional<Eigen::Vector3d>> undeform(const TetMesh& tets, const std::vector<Eigen::Vector3d>& deformed,
                                                     const std::vector<Eigen::Vector3d>& points);
// The centres of `spheres` taken back so, those that land inside `rest` (in order), each with its
// radius there: the distance to `rest`, at most `max_radius`; or 0 where `radii` is false, for a
// caller that finds the radii itself (a skinned body's carry, over the whole clip).
SphereSet undeform_centres(const TetMesh& tets, const std::vector<Eigen::Vector3d>& deformed, const SphereSet& spheres,
                           const MeshQuery& rest, double max_radius, bool radii = true);

class HarmonicMap {
 public:
  HarmonicMap(const TetMesh& tets, const TriMesh& rest, Log& log = Log::silent());

  // Tet-vertex positions in a pose whose surface vertices are `pose.vertices`.
  std::vector<Eigen::Vector3d> deform(const TriMesh& pose) const;
  // Any per-vertex quantity of the rest surface (a row per vertex) carried into the interior by
  // the same extension: a row per tet vertex. Linear, so rows summing to 1 stay so.
  Eigen::MatrixXd extend(const Eigen::MatrixXd& per_vertex) const;
  // f(p) in a pose given by deform()'s result; `at` is locator().locate(p).
  Eigen::Vector3d map(const Eigen::Vector3d& p, const TetLocator::Location& at,
                      const std::vector<Eigen::Vector3d>& deformed) const;

  const TetLocator& locator() const { return locator_; }
  size_t data_points() const { return data_.size(); }
  size_t dropped_points() const { return dropped_; }

 private:
  struct DataPoint {
    Eigen::Vector3i triangle;   // rest surface vertices it is interpolated from
    Eigen::Vector3d surface;    // their weights
    TetLocator::Location at;    // where it sits in the tets
  };
  const TetMesh& tets_;
  const TriMesh& rest_;
  TetLocator locator_;
  std::vector<DataPoint> data_;
  size_t dropped_ = 0;
  Eigen::SparseMatrix<double> ct_;  // C^T
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver_;
};

}  // namespace spx
