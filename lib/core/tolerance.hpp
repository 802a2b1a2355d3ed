#pragma once
// A length given as mesh units or as a percentage of the mesh's bounding-box diagonal, and the
// default every tool falls back to.
namespace spx {

// With neither a tolerance nor a sphere budget, selection gives the fewest spheres within this
// share of the mesh's bounding-box diagonal ("model no more than a scene needs").
constexpr double kDefaultTolerancePercent = 2.0;

// pose-map --hold-over-clip: between the poses, at the clip's other times, a sphere may poke out
// by this share of the diagonal (at the poses themselves, not at all). Radii that hold exactly at
// every time of a fast clip leave folding joints (a trunk, a knee) to the smallest spheres.
constexpr double kDefaultClipOvershootPercent = 0.25;

// A field's distances may exceed the exact ones by a small fraction of a voxel (the interior
// transform picks the best of nearby triangles, and depths between voxels are bounded by
// Lipschitz steps): a radius bounded by a field keeps this many voxels clear.
constexpr double kFieldMargin = 0.1;

struct Tolerance {
  double value = 0;
  bool percent = false;
  bool set() const { return value > 0; }
  double length(double diagonal) const { return percent ? value / 100 * diagonal : value; }
};

// The default tolerance as a length, for a mesh of this bounding-box diagonal.
inline double default_tolerance(double diagonal) { return Tolerance{kDefaultTolerancePercent, true}.length(diagonal); }

}  // namespace spx
