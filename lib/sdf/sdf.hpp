#pragma once
// sdf-build: a signed distance field with distances through the whole interior.
#include <nlohmann/json.hpp>
#include <string>

#include "core/error.hpp"
#include "core/log.hpp"
#include "mesh/defects.hpp"
#include "mesh/mesh.hpp"
#include "mesh/solid_boundary.hpp"
#include "io/dense_field.hpp"

namespace spx {

struct SdfOptions {
  int resolution = 128;        // voxels along the longest side of the bounding box
  double voxel_size = 0;       // overrides resolution when > 0
  int band = 3;                // exterior narrow band, in voxels
  double memory_limit_gib = 16;  // refuse grids whose working set would exceed this
  // A mesh that is not one closed surface is signed by winding numbers block by block (see
  // sdf.cpp); this evaluates every voxel instead, the reference the tests compare against.
  bool sign_every_voxel = false;
  // Only the inside and the surface layer get distances (the rest of the band keeps the
  // background): the same grid, and the same inside to the bit, for less work.
  bool inside_only = false;
};

struct SdfStats {
  MeshDefects defects;
  std::string sign_method;
  size_t surface_voxels = 0, interior_voxels = 0, winding_evaluations = 0;  // surface: within a voxel of the mesh
  size_t internal_walls = 0;   // triangles with the solid on both sides: no distance is taken to them
  size_t split_triangles = 0;  // triangles partly inside the solid: distances to their bounding pieces
  double estimated_memory_gib = 0;
  bool bounded_by_holes = false;  // not watertight: distances also bounded across the holes
  nlohmann::json to_json() const;
};

// The grid the options ask for would not fit in memory (unsupported). `grid()` is the estimate
// alone ("a 512 x 300 x 200 grid needs about 40 GiB of memory, over the 16 GiB limit"), for a
// caller whose advice differs from sdf-build's (a coarser --resolution).
class GridTooLarge : public Error {
 public:
  GridTooLarge(const std::string& grid, const std::string& advice)
      : Error(ExitCode::unsupported, "", grid + "; " + advice), grid_(grid) {}
  const std::string& grid() const { return grid_; }

 private:
  std::string grid_;
};

struct SdfResult {
  DenseField field;
  SdfStats stats;
};

// The voxel build_sdf gives `mesh` (0 where it has no extent).
double voxel_size_for(const TriMesh& mesh, const SdfOptions& options);

// `boundary`: the mesh's solid boundary where already found (MeshQuery::boundary()), or null.
SdfResult build_sdf(const TriMesh& mesh, const SdfOptions& options, Log& log = Log::silent(),
                    const SolidBoundary* boundary = nullptr);

}  // namespace spx
