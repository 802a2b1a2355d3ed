#pragma once
// The solid's boundary (the solid: winding number > 1/2). Where parts overlap (a limb's open
// tube reaching into the pelvis, two closed pieces pressed together) a triangle with the solid
// on both sides bounds nothing, and a sphere may cross it; a triangle that passes out of another
// part bounds only where it is out. Distances for radii are taken to the boundary alone
// (MeshQuery, the field), and errors are measured and samples drawn on it.
#include <array>
#include <cstdint>
#include <vector>

#include "mesh/mesh.hpp"
#include "mesh/winding_number.hpp"

namespace spx {

// Probes sit this share of the bounding-box diagonal off a triangle, on the side its normal points to.
constexpr double kWallProbe = 1e-5;
// A triangle whose probes disagree is split in 4 (edge midpoints), down to this many times.
constexpr int kWallSplitDepth = 3;

// The points a triangle is probed at: its centroid, the points half-way from it to each corner
// and to each edge's midpoint, and those 7/8 of the way to each corner (10 in all). A probe bounds where either side of it is outside.
// Crossing a triangle against its normal raises the winding number by 1 (its own solid angle
// turns from -1/2 to +1/2, the others' go on), so the side its normal points to is the lower:
// that side alone is asked.
std::vector<Eigen::Vector3d> wall_probes(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c);

struct SolidBoundary {
  // The triangles that bound: whole where every probe bounds (the input's own vertices), in
  // pieces where the probes disagree (the bounding pieces, on vertices of their own, appended),
  // left out where none does. Pieces still split at the last depth are kept. Empty where the
  // boundary is whole: the input itself.
  TriMesh mesh;
  std::vector<int> source;  // per triangle of `mesh`: the input triangle it is, or is part of
  size_t internal = 0;      // input triangles left out whole
  size_t split = 0;         // input triangles kept in pieces
  bool whole() const { return internal == 0 && split == 0; }
};

// Each input triangle's bounding part, one at a time, as solid_boundary decides it: for a mesh
// asked near a few points only (a clip's times, each skinned afresh), where deciding every
// triangle costs more than the queries. Safe to ask from several threads.
class BoundaryParts {
 public:
  using Corners = std::array<Eigen::Vector3d, 3>;
  struct Part {
    enum { whole, none, pieces } kind = whole;
    std::vector<Corners> bounding;  // pieces only
  };
  BoundaryParts(const TriMesh& mesh, const WindingNumber& wn);
  // A single closed surface: every triangle bounds whole, nothing is probed.
  bool whole() const { return probed_.empty(); }
  Part part(size_t t) const;

 private:
  const TriMesh& mesh_;
  const WindingNumber& wn_;
  double diagonal_, offset_;
  std::vector<uint8_t> probed_;  // empty where whole()
};

// A single closed surface bounds everywhere: `mesh` itself, nothing probed. Only triangles
// near another edge-connected piece are probed (a piece alone is taken to bound everywhere);
// degenerate triangles (no normal to probe along) are kept whole.
SolidBoundary solid_boundary(const TriMesh& mesh, const WindingNumber& wn);

// The boundary as a surface to measure on: `boundary.mesh` with only the vertices its triangles
// use, in their order; `mesh` itself where the boundary is whole.
TriMesh solid_surface(const TriMesh& mesh, const SolidBoundary& boundary);
// The same, finding the boundary first.
TriMesh solid_surface(const TriMesh& mesh);

}  // namespace spx
