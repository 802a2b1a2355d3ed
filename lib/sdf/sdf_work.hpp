#pragma once
// sdf internals: what build_sdf's stages share (sdf.cpp runs them; sign.cpp is stage 2).
#include <tbb/parallel_for.h>

#include <cstdint>
#include <vector>

#include "io/dense_field.hpp"
#include "mesh/mesh.hpp"
#include "sdf/sdf.hpp"

namespace spx::detail {

// One byte of state per voxel (one array instead of one per state).
enum VoxelFlag : uint8_t {
  kLayer = 1,    // within a voxel of the surface: exact distance and triangle from the rasterizer
  kInside = 2,   // inside the solid
  kWanted = 4,   // gets a distance: inside, or outside within the band
  kChanged = 8,  // its triangle changed in the last refine sweep
  kSeen = 16,    // reached by the region flood
};

inline void set_flag(uint8_t& flags, VoxelFlag flag, bool on) { flags = on ? uint8_t(flags | flag) : uint8_t(flags & ~flag); }

// The indices i in [0, n) where pred(i) holds, ascending (gathered in parallel chunks).
template <class Pred>
std::vector<size_t> indices_where(size_t n, Pred&& pred) {
  const size_t chunks = 256;
  std::vector<std::vector<size_t>> part(chunks);
  tbb::parallel_for(size_t(0), chunks, [&](size_t c) {
    for (size_t i = n * c / chunks, end = n * (c + 1) / chunks; i < end; ++i)
      if (pred(i)) part[c].push_back(i);
  });
  std::vector<size_t> all;
  size_t count = 0;
  for (const auto& p : part) count += p.size();
  all.reserve(count);
  for (const auto& p : part) all.insert(all.end(), p.begin(), p.end());
  return all;
}

// What the SDF's stages share: the mesh in spatial order, the grid, each voxel's distance
// (unsigned until the sign is applied), closest triangle and flags, and the surface layer.
struct SdfWork {
  const TriMesh& mesh;
  const GridShape& shape;
  DenseField& field;
  SdfStats& stats;
  GridVector<int32_t> tri;
  GridVector<uint8_t> flags;
  std::vector<size_t> layer_list;
  SdfWork(const TriMesh& m, const GridShape& g, DenseField& f, SdfStats& st)
      : mesh(m), shape(g), field(f), stats(st), tri(g.count()), flags(g.count()) {}
};

// 2. The sign of every voxel (kInside): by pseudo-normals in the surface layer and one winding
//    number per enclosed region for one closed, manifold, consistently oriented surface;
//    otherwise by winding numbers block by block (`every_voxel`: each voxel, the reference).
void sign_closed_surface(SdfWork& w);
void sign_by_winding_numbers(SdfWork& w, bool every_voxel);

}  // namespace spx::detail
