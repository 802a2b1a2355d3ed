#pragma once
// Exact Euclidean feature transform on a voxel grid: for every voxel, the nearest seed voxel.
// Separable lower-envelope algorithm of Felzenszwalb & Huttenlocher (2012), carrying the argmin;
// linear in the number of voxels and parallel over grid lines.
#include <cstdint>
#include <vector>

#include "io/dense_field.hpp"

namespace spx {

// `seed[idx] & bits` nonzero marks a seed. Returns, per voxel, the flat index of a nearest seed
// (Euclidean distance between voxel centers) or -1 when there is no seed at all.
GridVector<int32_t> nearest_seed_transform(const GridShape& shape, const uint8_t* seed, uint8_t bits = 0xff);
inline GridVector<int32_t> nearest_seed_transform(const GridShape& shape, const std::vector<uint8_t>& seed) {
  return nearest_seed_transform(shape, seed.data());
}

}  // namespace spx
