#pragma once
// Signed distance fields on disk as OpenVDB .vdb files (Houdini and Blender open them).
#include <map>
#include <string>

#include "io/dense_field.hpp"

namespace spx {

// Writes `field` as a FloatGrid named "sdf" (level-set class, interior voxels all active).
// `metadata` lands in the grid's metadata as strings. Atomic and byte-deterministic.
void write_sdf_vdb(const std::string& path, const DenseField& field, const std::map<std::string, std::string>& metadata);

struct LoadedSdf {
  DenseField field;  // covers the active voxels; the rest is background
  std::map<std::string, std::string> metadata;
};

// Reads the grid named "sdf" (or the only float grid). Throws Error naming `path`.
LoadedSdf read_sdf_vdb(const std::string& path);

}  // namespace spx
