#include "io/vdb_io.hpp"

#include <openvdb/openvdb.h>
#include <openvdb/tools/Dense.h>

#include <cstdio>
#include <filesystem>
#include <sstream>

#include "core/atomic_file.hpp"
#include "core/error.hpp"
#include "core/file_kind.hpp"
#include "core/hash.hpp"

namespace spx {
namespace {

using DenseZYX = openvdb::tools::Dense<float, openvdb::tools::LayoutZYX>;

openvdb::CoordBBox bbox_of(const GridShape& s) {
  const openvdb::Coord lo(s.origin.x(), s.origin.y(), s.origin.z());
  return {lo, lo + openvdb::Coord(s.dims.x() - 1, s.dims.y() - 1, s.dims.z() - 1)};
}

// OpenVDB stamps each file with a random UUID (bytes 21..56, "not currently used" by readers).
// Replace it with one derived from the file's content, so equal fields give equal bytes.
void make_uuid_deterministic(std::string& bytes) {
  constexpr size_t kAt = 21, kLen = 36;
  if (bytes.size() < kAt + kLen || bytes[kAt + 8] != '-') return;
  // The seed is not FNV's own offset basis, but every .vdb written so far used it: keep it.
  constexpr uint64_t kSeed = 1469598103934665603ull;
  const uint64_t h1 = fnv1a(fnv1a(kSeed, bytes.data(), kAt), bytes.data() + kAt + kLen, bytes.size() - kAt - kLen);
  uint64_t h2 = 0x9E3779B97F4A7C15ull;  // a second, independent mix for the other half of the id
  for (size_t i = 0; i < bytes.size(); ++i) {
    if (i >= kAt && i < kAt + kLen) continue;
    const auto c = static_cast<unsigned char>(bytes[i]);
    h2 = (h2 + c) * 0xBF58476D1CE4E5B9ull;
    h2 ^= h2 >> 31;
  }
  char uuid[40];
  std::snprintf(uuid, sizeof uuid, "%08x-%04x-4%03x-8%03x-%012llx", unsigned(h1 >> 32), unsigned(h1 >> 16) & 0xffff,
                unsigned(h1) & 0xfff, unsigned(h2 >> 52) & 0xfff, (unsigned long long)(h2 & 0xffffffffffffull));
  bytes.replace(kAt, kLen, uuid, kLen);
}

// The bytes openvdb::io::File::write puts in a file, made in memory: File writes through an
// ofstream whose errors it never checks, so a full disk left a cut .vdb and no error.
// write_file_atomic then checks every write (exit 4 naming the file).
class ArchiveInMemory : public openvdb::io::Archive {
 public:
  std::string bytes_of(const openvdb::GridCPtrVec& grids) const {
    std::ostringstream out(std::ios::binary);
    Archive::write(out, grids, /*seekable=*/true);  // what File::write calls
    return out.str();
  }
};

std::string vdb_bytes(const openvdb::GridCPtrVec& grids) { return ArchiveInMemory().bytes_of(grids); }

}  // namespace

void write_sdf_vdb(const std::string& path, const DenseField& field,
                   const std::map<std::string, std::string>& metadata) {
  openvdb::initialize();
  auto grid = openvdb::FloatGrid::create(field.background);
  grid->setName("sdf");
  grid->setGridClass(openvdb::GRID_LEVEL_SET);
  grid->setTransform(openvdb::math::Transform::createLinearTransform(field.shape.voxel_size));
  DenseZYX dense(bbox_of(field.shape), const_cast<float*>(field.values.data()));
  openvdb::tools::copyFromDense(dense, *grid, 0.0f);
  for (const auto& [key, value] : metadata) grid->insertMeta(key, openvdb::StringMetadata(value));

  std::string bytes = vdb_bytes({grid});
  make_uuid_deterministic(bytes);
  write_file_atomic(path, bytes);
}

LoadedSdf read_sdf_vdb(const std::string& path) {
  openvdb::initialize();
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) fail_no_such_file(path);
  openvdb::GridPtrVecPtr grids;
  try {
    openvdb::io::File file(path);
    file.open(false);
    grids = file.getGrids();
    file.close();
  } catch (const openvdb::Exception& e) {
    const FileKind kind = file_kind(path, read_file(path));
    if (kind == FileKind::mesh) fail_input(path, "is a mesh, not a field: sdf-build makes the field from it");
    if (kind != FileKind::unknown && kind != FileKind::vdb && kind != FileKind::binary)
      fail_input(path, "is " + describe(kind) + ", not a field (.vdb from sdf-build)");
    fail_input(path, std::string("not a readable OpenVDB file: ") + e.what());
  }
  if (!grids || grids->empty()) fail_input(path, "holds no grid");

  openvdb::FloatGrid::Ptr grid;
  for (const auto& g : *grids)
    if (g->getName() == "sdf") grid = openvdb::gridPtrCast<openvdb::FloatGrid>(g);
  if (!grid && grids->size() == 1) grid = openvdb::gridPtrCast<openvdb::FloatGrid>(grids->front());
  if (!grid) {
    const auto& g = grids->front();
    fail_input(path, "holds a " + g->valueType() + " grid named '" + g->getName() +
                         "'; expected a float signed distance grid named 'sdf'");
  }
  const auto& xform = grid->transform();
  if (!xform.isLinear() || !xform.hasUniformScale())
    fail_unsupported(path, "grid transform is not a uniform linear scale");
  const openvdb::Vec3d origin = xform.indexToWorld(openvdb::Vec3d(0, 0, 0));
  if (origin.length() > 1e-9 * xform.voxelSize()[0])
    fail_unsupported(path, "grid transform has a translation; expected index (0,0,0) at the world origin");
  const openvdb::CoordBBox box = grid->evalActiveVoxelBoundingBox();
  if (box.empty()) fail_input(path, "grid has no active voxels");
  const float background = grid->background();
  if (!(background > 0) || !std::isfinite(background))
    fail_input(path, "grid background is not a positive distance (not a signed distance field)");

  LoadedSdf out;
  GridShape& shape = out.field.shape;
  shape.voxel_size = xform.voxelSize()[0];
  shape.origin = Eigen::Vector3i(box.min().x(), box.min().y(), box.min().z());
  const openvdb::Coord dim = box.dim();
  shape.dims = Eigen::Vector3i(dim.x(), dim.y(), dim.z());
  if (double(dim.x()) * dim.y() * dim.z() > 2.0e9) fail_unsupported(path, "grid is too large to load densely");
  out.field.background = background;
  out.field.values.assign(shape.count(), background);
  DenseZYX dense(box, out.field.values.data());
  openvdb::tools::copyToDense(*grid, dense);
  for (const float v : out.field.values)
    if (!std::isfinite(v)) fail_input(path, "grid holds a non-finite value");
  for (auto it = grid->beginMeta(); it != grid->endMeta(); ++it) out.metadata[it->first] = it->second->str();
  return out;
}

}  // namespace spx
