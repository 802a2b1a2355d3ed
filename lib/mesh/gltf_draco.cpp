// KHR_draco_mesh_compression decoded into plain accessors (declared in mesh/gltf_input.hpp).
#include <draco/compression/decode.h>

#include <cstring>
#include <map>
#include <memory>
#include <set>
#include <string>

#include "core/error.hpp"
#include "mesh/gltf_accessors.hpp"
#include "mesh/gltf_input.hpp"

namespace spx {

using namespace detail;

namespace {

constexpr const char* kDraco = "KHR_draco_mesh_compression";

// Appends `data` as a view of its own at a multiple of 4 bytes; returns its index.
size_t append_view(GltfFile& file, const std::string& data) {
  while (file.bin.size() % 4) file.bin += '\0';
  file.doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", file.bin.size()}, {"byteLength", data.size()}});
  file.bin += data;
  return file.doc["bufferViews"].size() - 1;
}

// The stream of the primitive's extension, decoded: a triangle mesh, or a point cloud.
std::unique_ptr<draco::PointCloud> decoded_stream(const GltfFile& file, const json& ext, const std::string& at,
                                                  const std::string& path) {
  const json& views = file.doc["bufferViews"];
  const size_t v = gltf_whole_number(ext, "bufferView", SIZE_MAX, path, at.c_str());
  if (v >= views.size()) fail_input(path, at + " names a bufferView that does not exist");
  const size_t begin = gltf_whole_number(views[v], "byteOffset", 0, path, "a bufferView");
  const size_t length = gltf_whole_number(views[v], "byteLength", 0, path, "a bufferView");
  if (gltf_whole_number(views[v], "buffer", 0, path, "a bufferView") != 0 || begin > file.bin.size() ||
      length > file.bin.size() - begin)
    fail_input(path, at + "'s bufferView runs past the end of its buffer");
  draco::DecoderBuffer buffer;
  buffer.Init(file.bin.data() + begin, length);
  const auto type = draco::Decoder::GetEncodedGeometryType(&buffer);
  draco::Decoder decoder;
  std::unique_ptr<draco::PointCloud> out;
  std::string error;
  if (type.ok() && type.value() == draco::TRIANGULAR_MESH) {
    auto mesh = decoder.DecodeMeshFromBuffer(&buffer);
    if (mesh.ok()) out = std::move(mesh).value();
    else error = mesh.status().error_msg_string();
  } else if (type.ok() && type.value() == draco::POINT_CLOUD) {
    auto cloud = decoder.DecodePointCloudFromBuffer(&buffer);
    if (cloud.ok()) out = std::move(cloud).value();
    else error = cloud.status().error_msg_string();
  } else {
    error = type.ok() ? "neither a mesh nor a point cloud" : type.status().error_msg_string();
  }
  if (!out) fail_input(path, at + "'s data does not decode (" + error + ")");
  return out;
}

// The attribute's value at every point, as `count` components of T each.
template <class T>
std::string point_values(const draco::PointAttribute& attribute, size_t points, size_t count) {
  std::string out(points * count * sizeof(T), '\0');
  std::vector<T> value(count);
  for (uint32_t p = 0; p < points; ++p) {
    attribute.ConvertValue<T>(attribute.mapped_index(draco::PointIndex(p)), int8_t(count), value.data());
    std::memcpy(&out[p * count * sizeof(T)], value.data(), count * sizeof(T));
  }
  return out;
}

// The attribute's values in the accessor's component type and type.
std::string accessor_data(const draco::PointAttribute& attribute, const json& accessor, size_t points,
                          const std::string& at, const std::string& path) {
  const size_t n = components(accessor);
  const size_t type = gltf_whole_number(accessor, "componentType", 0, path, "an accessor");
  if (n == 0) fail_input(path, at + " names an accessor that is no SCALAR or vector");
  switch (type) {
    case 5120: return point_values<int8_t>(attribute, points, n);
    case 5121: return point_values<uint8_t>(attribute, points, n);
    case 5122: return point_values<int16_t>(attribute, points, n);
    case 5123: return point_values<uint16_t>(attribute, points, n);
    case 5125: return point_values<uint32_t>(attribute, points, n);
    case kFloat: return point_values<float>(attribute, points, n);
  }
  fail_input(path, at + " names an accessor whose componentType is not glTF's (" + std::to_string(type) + ")");
}

// The mesh's triangles' corners in the index type `type` (5121, 5123 or 5125).
std::string triangle_corners(const draco::Mesh& mesh, int type, const std::string& at, const std::string& path) {
  const size_t width = type == 5121 ? 1 : type == 5123 ? 2 : type == 5125 ? 4 : 0;
  if (width == 0) fail_input(path, at + ": its indices accessor is not of unsigned bytes, shorts or ints");
  std::string out;
  out.reserve(size_t(mesh.num_faces()) * 3 * width);
  for (uint32_t f = 0; f < mesh.num_faces(); ++f)
    for (int k = 0; k < 3; ++k) {
      const uint32_t corner = mesh.face(draco::FaceIndex(f))[k].value();
      if (width < 4 && corner >> (8 * width)) fail_input(path, at + ": a corner does not fit its indices accessor's type");
      out.append(reinterpret_cast<const char*>(&corner), width);  // little-endian
    }
  return out;
}

// The accessor `slot` names; exit 2 where there is none.
const json& named_accessor(const json& doc, const json& slot, const std::string& at, const std::string& path) {
  const auto accessors = doc.find("accessors");
  if (!is_index(slot) || accessors == doc.end() || !accessors->is_array() || slot.get<size_t>() >= accessors->size() ||
      !(*accessors)[slot.get<size_t>()].is_object())
    fail_input(path, at + " names an accessor that does not exist");
  return (*accessors)[slot.get<size_t>()];
}

// Points `slot` (an attribute's accessor, or the indices') at an accessor holding `data`: its
// own, or a copy where an earlier primitive's decoding filled it.
void fill_accessor(GltfFile& file, json& slot, const std::string& data, size_t count, std::set<size_t>& filled) {
  json& accessors = file.doc["accessors"];
  size_t a = slot.get<size_t>();
  if (filled.count(a)) {
    accessors.push_back(accessors[a]);
    a = accessors.size() - 1;
    slot = a;
  }
  filled.insert(a);
  json& accessor = accessors[a];
  accessor["bufferView"] = append_view(file, data);
  accessor["count"] = count;
  for (const char* gone : {"byteOffset", "sparse"}) accessor.erase(gone);
}

}  // namespace

size_t draco_primitives_decoded(GltfFile& file, const std::string& path) {
  json& doc = file.doc;
  if (!doc.contains("meshes") || !doc["meshes"].is_array()) return 0;
  std::set<size_t> filled;  // accessors decoded into so far
  size_t changed = 0;
  for (size_t m = 0; m < doc["meshes"].size(); ++m) {
    json& mesh = doc["meshes"][m];
    if (!mesh.contains("primitives") || !mesh["primitives"].is_array()) continue;
    for (size_t p = 0; p < mesh["primitives"].size(); ++p) {
      json& primitive = mesh["primitives"][p];
      if (!extension_of(primitive, kDraco)) continue;
      const std::string at = "mesh " + std::to_string(m) + "'s primitive " + std::to_string(p) + "'s " + kDraco;
      const json ext = *extension_of(primitive, kDraco);  // a copy: the primitive changes below
      if (!ext.is_object() || !ext.contains("attributes") || !ext["attributes"].is_object())
        fail_input(path, at + " has no attributes");
      const std::unique_ptr<draco::PointCloud> stream = decoded_stream(file, ext, at, path);
      for (const auto& [name, id] : ext["attributes"].items()) {
        if (!primitive.contains("attributes") || !primitive["attributes"].is_object() || !primitive["attributes"].contains(name))
          fail_input(path, at + " names attribute " + name + ", which the primitive does not have");
        const draco::PointAttribute* attribute =
            is_index(id) ? stream->GetAttributeByUniqueId(uint32_t(id.get<size_t>())) : nullptr;
        if (!attribute) fail_input(path, at + "'s " + name + " is no attribute of its data (" + id.dump() + ")");
        json& slot = primitive["attributes"][name];
        const std::string data = accessor_data(*attribute, named_accessor(doc, slot, at, path), stream->num_points(), at + "'s " + name, path);
        fill_accessor(file, slot, data, stream->num_points(), filled);
      }
      if (const auto* triangles = dynamic_cast<const draco::Mesh*>(stream.get())) {
        if (!primitive.contains("indices")) {  // the points are no triangle list by themselves
          doc["accessors"].push_back({{"componentType", 5125}, {"type", "SCALAR"}, {"count", 0}});
          primitive["indices"] = doc["accessors"].size() - 1;
        }
        json& slot = primitive["indices"];
        const size_t type = gltf_whole_number(named_accessor(doc, slot, at, path), "componentType", 0, path, "an accessor");
        fill_accessor(file, slot, triangle_corners(*triangles, int(type), at, path), size_t(triangles->num_faces()) * 3, filled);
      }
      remove_extension_of(primitive, kDraco);
      ++changed;
    }
  }
  if (changed > 0) drop_extension(doc, kDraco);
  return changed;
}

}  // namespace spx
