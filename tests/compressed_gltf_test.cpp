// Compressed glTF: EXT_meshopt_compression (gltfpack -c and the web optimizers write it; the
// container decoded by core/gltf_meshopt) and KHR_draco_mesh_compression (gltf-pipeline,
// gltf-transform and Blender's exporter write it; decoded by mesh/gltf_draco), and the poses of
// assets so compressed.
#include <draco/compression/decode.h>
#include <draco/compression/encode.h>
#include <gtest/gtest.h>
#include <meshoptimizer.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <functional>
#include <map>
#include <set>
#include <sstream>

#include "core/atomic_file.hpp"
#include "core/error.hpp"
#include "core/gltf_file.hpp"
#include "extract/pose_extract_tool.hpp"
#include "io/pose_manifest.hpp"
#include "mesh/gltf_input.hpp"
#include "mesh/mesh.hpp"
#include "synthetic/sample_gen_tool.hpp"
#include "test_util.hpp"

namespace spx {
namespace {

constexpr const char* kExt = "EXT_meshopt_compression";

std::string bytes_of(const void* data, size_t size) { return std::string(static_cast<const char*>(data), size); }

// The stream of `data` (count elements of `stride` bytes) by the mode's encoder.
std::string encoded(const std::string& data, size_t stride, const std::string& mode) {
  const size_t count = data.size() / stride;
  std::vector<unsigned char> out;
  if (mode == "ATTRIBUTES") {
    out.resize(meshopt_encodeVertexBufferBound(count, stride));
    out.resize(meshopt_encodeVertexBuffer(out.data(), out.size(), data.data(), count, stride));
  } else {
    std::vector<unsigned> indices(count);
    for (size_t i = 0; i < count; ++i) {
      uint16_t s = 0;
      if (stride == 2) std::memcpy(&s, data.data() + 2 * i, 2);
      else std::memcpy(&indices[i], data.data() + 4 * i, 4);
      if (stride == 2) indices[i] = s;
    }
    const size_t vertices = indices.empty() ? 0 : *std::max_element(indices.begin(), indices.end()) + 1;
    if (mode == "TRIANGLES") {
      out.resize(meshopt_encodeIndexBufferBound(count, vertices));
      out.resize(meshopt_encodeIndexBuffer(out.data(), out.size(), indices.data(), count));
    } else {
      out.resize(meshopt_encodeIndexSequenceBound(count, vertices));
      out.resize(meshopt_encodeIndexSequence(out.data(), out.size(), indices.data(), count));
    }
  }
  EXPECT_FALSE(out.empty()) << mode;
  return bytes_of(out.data(), out.size());
}

// How a view is compressed: as a triangle list where a triangle primitive's indices read it,
// else as attributes of its accessors' element size (or its stride); "" where neither fits.
struct Way {
  std::string mode;
  size_t stride = 0;
};
Way way_for(const json& doc, size_t v) {
  const json& view = doc["bufferViews"][v];
  const size_t length = view["byteLength"].get<size_t>();
  std::set<size_t> indices;
  for (const json& mesh : doc.value("meshes", json::array()))
    for (const json& p : mesh["primitives"])
      if (p.contains("indices") && p.value("mode", 4) == 4) indices.insert(p["indices"].get<size_t>());
  size_t element = view.value("byteStride", size_t(0));
  for (size_t a = 0; a < doc["accessors"].size(); ++a) {
    const json& accessor = doc["accessors"][a];
    if (accessor.value("bufferView", size_t(-1)) != v) continue;
    const size_t c = accessor["componentType"].get<int>() == 5126 || accessor["componentType"].get<int>() == 5125 ? 4
                     : accessor["componentType"].get<int>() >= 5122                                                ? 2
                                                                                                                   : 1;
    if (indices.count(a)) return c >= 2 && (length / c) % 3 == 0 ? Way{"TRIANGLES", c} : Way{};
    const size_t n = std::map<std::string, size_t>{{"SCALAR", 1}, {"VEC2", 2}, {"VEC3", 3}, {"VEC4", 4}, {"MAT4", 16}}.at(
        accessor["type"].get<std::string>());
    if (!view.contains("byteStride")) element = element == 0 || element == n * c ? n * c : 1;
  }
  if (element == 0) element = 4;  // a view no accessor reads
  return element % 4 == 0 && element <= 256 && length % element == 0 ? Way{"ATTRIBUTES", element} : Way{};
}

// `file` as gltfpack -c writes it: every view it can be compressed in the GLB's buffer, with the
// filter `filters` gives it where its bytes are that filter's encoding; the views' uncompressed
// data in a placeholder buffer with no data (the extension required).
GltfFile compressed(const GltfFile& file, const std::map<size_t, std::string>& filters = {}) {
  GltfFile out;
  out.doc = file.doc;
  size_t placeholder = 0;
  for (size_t v = 0; v < file.doc["bufferViews"].size(); ++v) {
    json& view = out.doc["bufferViews"][v];
    const std::string data = file.bin.substr(view.value("byteOffset", size_t(0)), view["byteLength"].get<size_t>());
    const Way way = way_for(file.doc, v);
    while (out.bin.size() % 4) out.bin += '\0';
    if (way.mode.empty()) {
      view["byteOffset"] = out.bin.size();
      out.bin += data;
      continue;
    }
    const std::string stream = encoded(data, way.stride, way.mode);
    json ext = {{"buffer", 0},      {"byteOffset", out.bin.size()},        {"byteLength", stream.size()},
                {"byteStride", way.stride}, {"count", data.size() / way.stride}, {"mode", way.mode}};
    if (filters.count(v)) ext["filter"] = filters.at(v);
    out.bin += stream;
    view["buffer"] = 1;
    view["byteOffset"] = placeholder;
    view["extensions"][kExt] = ext;
    placeholder += (data.size() + 3) / 4 * 4;
  }
  out.doc["buffers"] = {{{"byteLength", out.bin.size()}}, {{"byteLength", placeholder}, {"extensions", {{kExt, {{"fallback", true}}}}}}};
  out.doc["extensionsUsed"].push_back(kExt);
  out.doc["extensionsRequired"].push_back(kExt);
  return out;
}

// Appends `data` as a view of its own; returns its index.
size_t append_view(GltfFile& file, const std::string& data) {
  while (file.bin.size() % 4) file.bin += '\0';
  file.doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", file.bin.size()}, {"byteLength", data.size()}});
  file.bin += data;
  return file.doc["bufferViews"].size() - 1;
}

std::string view_data(const GltfFile& file, size_t v) {
  const json& view = file.doc["bufferViews"][v];
  return file.bin.substr(view.value("byteOffset", size_t(0)), view["byteLength"].get<size_t>());
}

// A triangle list's indices (of `width` bytes), each triangle turned to begin at its least corner.
std::vector<std::array<uint32_t, 3>> corners_turned_first(const std::string& bytes, size_t width) {
  std::vector<std::array<uint32_t, 3>> out(bytes.size() / width / 3);
  for (size_t t = 0; t < out.size(); ++t) {
    for (size_t k = 0; k < 3; ++k) std::memcpy(&out[t][k], bytes.data() + (3 * t + k) * width, width);
    std::rotate(out[t].begin(), std::min_element(out[t].begin(), out[t].end()), out[t].end());
  }
  return out;
}

std::vector<float> floats_of(const std::string& bytes) {
  std::vector<float> out(bytes.size() / 4);
  std::memcpy(out.data(), bytes.data(), out.size() * 4);
  return out;
}

// An OBJ's vertex lines as written, and its faces' corners (vertex numbers) turned to begin at
// the least.
std::pair<std::vector<std::string>, std::vector<std::array<long, 3>>> obj_parts(const std::string& path) {
  std::pair<std::vector<std::string>, std::vector<std::array<long, 3>>> out;
  std::istringstream in(read_file(path));
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("v ", 0) == 0) out.first.push_back(line);
    if (line.rfind("f ", 0) != 0) continue;
    std::istringstream corners(line.substr(2));
    std::array<long, 3> f{};
    for (long& c : f) {
      std::string corner;
      corners >> corner;
      c = std::stol(corner);  // "7", "7/7" or "7//7": the vertex
    }
    std::rotate(f.begin(), std::min_element(f.begin(), f.end()), f.end());
    out.second.push_back(f);
  }
  EXPECT_GT(out.second.size(), 0u) << path;
  return out;
}

// One view of each mode and filter, their data known: a file with them compressed reads back as
// that data, exact where the codec is (the modes) and within the encoding's precision where a
// filter quantizes (unit vectors in 8 bits, quaternions in 12, floats with 15 bits of mantissa).
TEST(GltfMeshopt, EveryModeAndFilterDecodesToItsData) {
  GltfFile plain;
  plain.doc = {{"asset", {{"version", "2.0"}}}, {"bufferViews", json::array()}, {"accessors", json::array()}};
  std::vector<float> positions, normals, quats, scalars;
  std::vector<uint16_t> triangles;
  std::vector<uint32_t> sequence;
  for (int i = 0; i < 300; ++i) {
    const double a = 0.1 * i, b = 0.037 * i * i;
    for (double c : {std::cos(a), std::sin(a), 0.01 * i}) positions.push_back(float(c));
    for (double c : {std::cos(a) * std::sin(b), std::sin(a) * std::sin(b), std::cos(b), 0.0}) normals.push_back(float(c));
    const double n = std::sqrt(1 + std::sin(b) * std::sin(b) + 0.25 + a * a);
    for (double c : {1 / n, std::sin(b) / n, 0.5 / n, a / n}) quats.push_back(float(c));
    scalars.push_back(float(std::exp(0.05 * i) * (i % 2 ? -1 : 1)));
    sequence.push_back(uint32_t(7 * i % 1000));
  }
  for (uint16_t t = 0; t < 298; ++t)
    for (uint16_t k : {t, uint16_t(t + 1), uint16_t(t + 2)}) triangles.push_back(k);
  std::vector<int8_t> oct(4 * 300);
  std::vector<int16_t> quat(4 * 300);
  std::vector<uint32_t> exp(300);
  meshopt_encodeFilterOct(oct.data(), 300, 4, 8, normals.data());
  meshopt_encodeFilterQuat(quat.data(), 300, 8, 12, quats.data());
  meshopt_encodeFilterExp(exp.data(), 300, 4, 15, scalars.data());
  append_view(plain, bytes_of(positions.data(), positions.size() * 4));
  append_view(plain, bytes_of(triangles.data(), triangles.size() * 2));
  append_view(plain, bytes_of(sequence.data(), sequence.size() * 4));
  append_view(plain, bytes_of(oct.data(), oct.size()));
  append_view(plain, bytes_of(quat.data(), quat.size() * 2));
  append_view(plain, bytes_of(exp.data(), exp.size() * 4));
  plain.doc["accessors"] = {{{"bufferView", 0}, {"componentType", 5126}, {"type", "VEC3"}, {"count", 300}},
                            {{"bufferView", 3}, {"componentType", 5120}, {"type", "VEC4"}, {"count", 300}},
                            {{"bufferView", 4}, {"componentType", 5122}, {"type", "VEC4"}, {"count", 300}},
                            {{"bufferView", 5}, {"componentType", 5126}, {"type", "SCALAR"}, {"count", 300}}};
  plain.doc["meshes"] = {{{"primitives", {{{"attributes", {{"POSITION", 0}}}, {"indices", 4}}}}}};
  plain.doc["accessors"].push_back({{"bufferView", 1}, {"componentType", 5123}, {"type", "SCALAR"}, {"count", triangles.size()}});
  GltfFile packed = compressed(plain, {{3, "OCTAHEDRAL"}, {4, "QUATERNION"}, {5, "EXPONENTIAL"}});
  packed.doc["bufferViews"][2]["extensions"][kExt]["mode"] = "INDICES";
  packed.doc["bufferViews"][2]["extensions"][kExt]["byteOffset"] = packed.bin.size();
  const std::string sequence_stream = encoded(view_data(plain, 2), 4, "INDICES");
  packed.doc["bufferViews"][2]["extensions"][kExt]["byteLength"] = sequence_stream.size();
  packed.bin += sequence_stream;
  packed.doc["buffers"][0]["byteLength"] = packed.bin.size();
  for (size_t v = 0; v < 6; ++v)
    ASSERT_EQ(packed.doc["bufferViews"][v]["extensions"][kExt].value("mode", ""), v == 1 ? "TRIANGLES" : v == 2 ? "INDICES" : "ATTRIBUTES");

  const std::string dir = test::temp_dir("meshopt-modes");
  // As a GLB, and as a .gltf whose first buffer is a file beside it and whose fallback names one
  // that is not (a reader that decodes the views need not load it).
  write_file_atomic(dir + "/m.glb", encode_glb(packed));
  json document = packed.doc;
  document["buffers"][0]["uri"] = "m.bin";
  document["buffers"][1]["uri"] = "m-fallback.bin";
  write_file_atomic(dir + "/m.bin", packed.bin);
  write_file_atomic(dir + "/m.gltf", document.dump());
  for (const char* name : {"m.glb", "m.gltf"}) {
    const GltfFile read = read_gltf_file(dir + "/" + name);
    for (const json& view : read.doc["bufferViews"]) EXPECT_FALSE(view.contains("extensions")) << name;
    EXPECT_FALSE(read.doc.contains("extensionsUsed")) << name;
    EXPECT_FALSE(read.doc.contains("extensionsRequired")) << name;
    // Only the views' bytes, laid out as the plain file's: the compressed streams are not carried on.
    EXPECT_EQ(read.bin.size(), plain.bin.size()) << name;
    // Exact, but for where each triangle starts: the triangle codec may begin one at another corner.
    EXPECT_TRUE(view_data(read, 0) == view_data(plain, 0)) << name;
    EXPECT_TRUE(view_data(read, 2) == view_data(plain, 2)) << name;
    EXPECT_EQ(corners_turned_first(view_data(read, 1), 2), corners_turned_first(view_data(plain, 1), 2)) << name;
    const std::string o = view_data(read, 3), q = view_data(read, 4);
    const std::vector<float> e = floats_of(view_data(read, 5));
    double normal = 0, rotation = 0, scalar = 0;
    for (size_t i = 0; i < 300; ++i) {
      double dot = 0;
      for (size_t c = 0; c < 4; ++c) {
        normal = std::max(normal, std::abs(int8_t(o[4 * i + c]) / 127.0 - normals[4 * i + c]));
        int16_t s;
        std::memcpy(&s, q.data() + 8 * i + 2 * c, 2);
        dot += s / 32767.0 * quats[4 * i + c];
      }
      rotation = std::max(rotation, 1 - std::abs(dot));
      scalar = std::max(scalar, std::abs(double(e[i]) - scalars[i]) / std::abs(scalars[i]));
    }
    EXPECT_LT(normal, 0.02) << name;
    EXPECT_LT(rotation, 1e-4) << name;
    EXPECT_LT(scalar, 1e-4) << name;
  }
  // The encoded bytes themselves are far from the vectors they stand for: the filter was applied.
  EXPECT_GT(std::abs(quat[0] / 32767.0 - quats[0]) + std::abs(quat[1] / 32767.0 - quats[1]), 0.05);

  // Broken files: exit 2 naming the file, or 3 for a codec version this build does not read.
  const auto fails = [&](const std::function<void(GltfFile&)>& spoil, ExitCode code, const std::string& words) {
    GltfFile bad = packed;
    spoil(bad);
    write_file_atomic(dir + "/bad.glb", encode_glb(bad));
    try {
      read_gltf_file(dir + "/bad.glb");
      ADD_FAILURE() << "read: " << words;
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), code) << e.what();
      EXPECT_EQ(e.subject(), dir + "/bad.glb");
      EXPECT_NE(e.message().find(words), std::string::npos) << e.what();
    }
  };
  json& first = packed.doc["bufferViews"][0]["extensions"][kExt];
  const size_t at = first["byteOffset"].get<size_t>();
  fails([&](GltfFile& f) { f.doc["bufferViews"][0]["extensions"][kExt]["byteLength"] = first["byteLength"].get<size_t>() / 2; },
        ExitCode::bad_input, "does not decode");
  fails([&](GltfFile& f) { f.bin[at] = char(0xa1); }, ExitCode::unsupported, "version 1 of its codec");
  fails([&](GltfFile& f) { f.bin[at] = char(0x17); }, ExitCode::bad_input, "does not decode");
  fails([&](GltfFile& f) { f.doc["bufferViews"][0]["extensions"][kExt]["count"] = 299; }, ExitCode::bad_input,
        "count times byteStride is not the view's byteLength");
  fails([&](GltfFile& f) { f.doc["bufferViews"][0]["extensions"][kExt]["mode"] = "POINTS"; }, ExitCode::bad_input,
        "mode is not one it names");
  fails([&](GltfFile& f) { f.doc["bufferViews"][3]["extensions"][kExt]["filter"] = "QUATERNION"; }, ExitCode::bad_input,
        "QUATERNION needs a byteStride of 8");
  fails([&](GltfFile& f) { f.doc["bufferViews"][0]["extensions"][kExt]["buffer"] = 1; }, ExitCode::bad_input,
        "reads a buffer with no data");
  fails([&](GltfFile& f) { f.doc["bufferViews"][0]["extensions"][kExt]["byteOffset"] = f.bin.size(); }, ExitCode::bad_input,
        "runs past the end of its buffer");
  fails([&](GltfFile& f) { f.doc["bufferViews"][0]["extensions"].erase(kExt); }, ExitCode::bad_input,
        "a bufferView lies in a buffer with no data");
}

// A compressed asset gives the poses of the plain one it stands for, to the bit: the rigged
// elephant (its mesh, skin and clip; the clip's rotations as quaternion-filtered shorts and its
// translations exponent-filtered, as gltfpack writes clips) and the car's morph targets, every
// view compressed that can be. Before: exit 3, "requires the glTF extension EXT_meshopt_compression".
TEST(PoseExtract, MeshoptCompressedAssetsGiveTheirPlainTwinsPoses) {
  SPX_REQUIRE_SHARED_DATA();
  const std::string dir = test::temp_dir("meshopt");
  json report;
  sample_gen_files("car", dir + "/car", Log::silent(), report);
  for (const std::string name : {"elephant", "car"}) {
    const bool morph = name == "car";
    GltfFile twin = read_gltf_file(morph ? dir + "/car/car-morph.glb" : test::shared_data() + "/elephant/elephant-rigged.glb");
    GltfFile filtered = twin;  // the same, its filtered views' bytes as encoded
    std::map<size_t, std::string> filters;
    for (const json& channel : morph ? json::array() : twin.doc["animations"][0]["channels"]) {
      const size_t output = twin.doc["animations"][0]["samplers"][channel["sampler"].get<size_t>()]["output"].get<size_t>();
      json& accessor = twin.doc["accessors"][output];
      const size_t count = accessor["count"].get<size_t>();
      const json& view = twin.doc["bufferViews"][accessor["bufferView"].get<size_t>()];
      const std::vector<float> values = floats_of(twin.bin.substr(
          view.value("byteOffset", size_t(0)) + accessor.value("byteOffset", size_t(0)), count * (channel["target"]["path"] == "rotation" ? 16 : 12)));
      std::string coded;
      if (channel["target"]["path"] == "rotation") {
        std::vector<int16_t> q(4 * count);
        meshopt_encodeFilterQuat(q.data(), count, 8, 16, values.data());
        coded = bytes_of(q.data(), q.size() * 2);
        accessor["componentType"] = 5122;
        accessor["normalized"] = true;
      } else {
        std::vector<uint32_t> x(3 * count);
        meshopt_encodeFilterExp(x.data(), count, 12, 16, values.data());
        coded = bytes_of(x.data(), x.size() * 4);
      }
      std::string decoded = coded;
      if (channel["target"]["path"] == "rotation") meshopt_decodeFilterQuat(decoded.data(), count, 8);
      else meshopt_decodeFilterExp(decoded.data(), count, 12);
      accessor["bufferView"] = append_view(twin, decoded);
      accessor.erase("byteOffset");
      filtered.doc["accessors"][output] = accessor;
      append_view(filtered, coded);
      filters[accessor["bufferView"].get<size_t>()] = channel["target"]["path"] == "rotation" ? "QUATERNION" : "EXPONENTIAL";
    }
    const GltfFile packed = compressed(filtered, filters);
    size_t views = 0;
    for (const json& view : packed.doc["bufferViews"]) views += view.contains("extensions");
    EXPECT_GE(views, morph ? 5u : 50u) << name;
    write_file_atomic(dir + "/" + name + "-plain.glb", encode_glb(twin));
    write_file_atomic(dir + "/" + name + "-packed.glb", encode_glb(packed));
    EXPECT_LT(std::filesystem::file_size(dir + "/" + name + "-packed.glb"), std::filesystem::file_size(dir + "/" + name + "-plain.glb") * 3 / 4)
        << name;
    PoseExtractOptions opt;
    if (morph) {
      opt.morph_targets = true;
    } else {
      opt.animation = "0";
      opt.times = {0.5, 5.01, 10.3};
    }
    pose_extract_files(dir + "/" + name + "-plain.glb", dir + "/" + name + "-plain", opt, Log::silent(), report);
    pose_extract_files(dir + "/" + name + "-packed.glb", dir + "/" + name + "-packed", opt, Log::silent(), report);
    const PoseManifest ours = read_pose_manifest(dir + "/" + name + "-packed/poses.json");
    const PoseManifest theirs = read_pose_manifest(dir + "/" + name + "-plain/poses.json");
    ASSERT_EQ(ours.poses.size(), theirs.poses.size()) << name;
    ASSERT_GE(ours.poses.size(), 3u) << name;
    // The same vertices in the same order, to the bit, and the same triangles but for where each
    // begins (the triangle codec may begin one at another corner, which turns no face).
    EXPECT_EQ(obj_parts(dir + "/" + name + "-packed/" + ours.rest), obj_parts(dir + "/" + name + "-plain/" + theirs.rest)) << name;
    for (size_t k = 0; k < ours.poses.size(); ++k)
      EXPECT_EQ(obj_parts(dir + "/" + name + "-packed/" + ours.poses[k].file),
                obj_parts(dir + "/" + name + "-plain/" + theirs.poses[k].file))
          << name << " pose " << k;
  }
}

// The elephant's primitive as a Draco mesh: positions, joints and weights (normalized bytes, as
// exporters quantize them) for each vertex, and its triangles.
struct DracoAttributes {
  int position = -1, joints = -1, weights = -1;  // the encoded mesh's attribute ids
};
std::string draco_stream(const std::vector<float>& positions, const std::vector<uint16_t>& joints,
                         const std::vector<uint8_t>& weights, const std::vector<uint32_t>& indices, DracoAttributes& ids) {
  draco::Mesh mesh;
  const size_t n = positions.size() / 3;
  mesh.set_num_points(uint32_t(n));
  const auto add = [&](draco::GeometryAttribute::Type type, int components, draco::DataType data, bool normalized, int bytes,
                       const void* values) {
    draco::GeometryAttribute a;
    a.Init(type, nullptr, uint8_t(components), data, normalized, components * bytes, 0);
    const int id = mesh.AddAttribute(a, true, uint32_t(n));
    for (size_t i = 0; i < n; ++i)
      mesh.attribute(id)->SetAttributeValue(draco::AttributeValueIndex(uint32_t(i)),
                                            static_cast<const char*>(values) + i * size_t(components * bytes));
    return int(mesh.attribute(id)->unique_id());
  };
  ids.position = add(draco::GeometryAttribute::POSITION, 3, draco::DT_FLOAT32, false, 4, positions.data());
  ids.joints = add(draco::GeometryAttribute::GENERIC, 4, draco::DT_UINT16, false, 2, joints.data());
  ids.weights = add(draco::GeometryAttribute::GENERIC, 4, draco::DT_UINT8, true, 1, weights.data());
  for (size_t t = 0; t + 2 < indices.size(); t += 3)
    mesh.AddFace({draco::PointIndex(indices[t]), draco::PointIndex(indices[t + 1]), draco::PointIndex(indices[t + 2])});
  draco::Encoder encoder;
  encoder.SetSpeedOptions(5, 5);
  draco::EncoderBuffer buffer;
  EXPECT_TRUE(encoder.EncodeMeshToBuffer(mesh, &buffer).ok());
  return std::string(buffer.data(), buffer.size());
}

template <class T>
std::vector<T> values_of(const GltfFile& file, const json& accessor, size_t width) {
  const json& view = file.doc["bufferViews"][accessor["bufferView"].get<size_t>()];
  std::vector<T> out(accessor["count"].get<size_t>() * width);
  const size_t stride = view.value("byteStride", width * sizeof(T));
  for (size_t i = 0; i < out.size() / width; ++i)
    std::memcpy(&out[i * width], file.bin.data() + view.value("byteOffset", size_t(0)) + accessor.value("byteOffset", size_t(0)) + i * stride,
                width * sizeof(T));
  return out;
}

// A Draco-compressed skinned asset gives the poses of its plain twin (the stream decoded here,
// by the same library, into ordinary accessors: the encoder orders the vertices its own way), to
// the bit: the rigged elephant with its mesh in KHR_draco_mesh_compression, its weights as
// normalized bytes inside the stream (as exporters quantize them), its skin and clip plain.
TEST(PoseExtract, DracoCompressedSkinGivesItsPlainTwinsPoses) {
  SPX_REQUIRE_SHARED_DATA();
  const std::string dir = test::temp_dir("draco");
  const GltfFile file = read_gltf_file(test::shared_data() + "/elephant/elephant-rigged.glb");
  const json& primitive = file.doc["meshes"][0]["primitives"][0];
  const json& accessors = file.doc["accessors"];
  const std::vector<float> positions = values_of<float>(file, accessors[primitive["attributes"]["POSITION"].get<size_t>()], 3);
  const std::vector<uint16_t> joints = values_of<uint16_t>(file, accessors[primitive["attributes"]["JOINTS_0"].get<size_t>()], 4);
  const std::vector<float> weights = values_of<float>(file, accessors[primitive["attributes"]["WEIGHTS_0"].get<size_t>()], 4);
  const std::vector<uint32_t> indices = values_of<uint32_t>(file, accessors[primitive["indices"].get<size_t>()], 1);
  std::vector<uint8_t> bytes(weights.size());
  for (size_t i = 0; i < weights.size(); ++i) bytes[i] = uint8_t(std::lround(255 * weights[i]));
  DracoAttributes ids;
  const std::string stream = draco_stream(positions, joints, bytes, indices, ids);

  // The twin: the stream decoded, its points and faces as plain accessors.
  draco::DecoderBuffer in;
  in.Init(stream.data(), stream.size());
  draco::Decoder decoder;
  auto decoded = decoder.DecodeMeshFromBuffer(&in);
  ASSERT_TRUE(decoded.ok());
  const draco::Mesh& mesh = *decoded.value();
  const size_t n = mesh.num_points();
  std::string p(n * 12, '\0'), j(n * 8, '\0'), w(n * 4, '\0'), f(mesh.num_faces() * 12, '\0');
  for (size_t i = 0; i < n; ++i) {
    mesh.GetAttributeByUniqueId(uint32_t(ids.position))->GetMappedValue(draco::PointIndex(uint32_t(i)), &p[i * 12]);
    mesh.GetAttributeByUniqueId(uint32_t(ids.joints))->GetMappedValue(draco::PointIndex(uint32_t(i)), &j[i * 8]);
    mesh.GetAttributeByUniqueId(uint32_t(ids.weights))->GetMappedValue(draco::PointIndex(uint32_t(i)), &w[i * 4]);
  }
  for (uint32_t t = 0; t < mesh.num_faces(); ++t)
    for (int k = 0; k < 3; ++k) {
      const uint32_t v = mesh.face(draco::FaceIndex(t))[k].value();
      std::memcpy(&f[t * 12 + size_t(k) * 4], &v, 4);
    }
  GltfFile twin = file, packed = file;
  const auto point = [&](GltfFile& g, const json& attribute, const std::string& data, int type, size_t count) {
    json& a = g.doc["accessors"][attribute.get<size_t>()];
    a["componentType"] = type;
    a["count"] = count;
    a.erase("byteOffset");
    if (type == 5121) a["normalized"] = true;
    if (data.empty()) a.erase("bufferView");
    else a["bufferView"] = append_view(g, data);
  };
  const json& attributes = primitive["attributes"];
  for (GltfFile* g : {&twin, &packed}) {
    const bool plain = g == &twin;
    point(*g, attributes["POSITION"], plain ? p : "", 5126, n);
    point(*g, attributes["JOINTS_0"], plain ? j : "", 5123, n);
    point(*g, attributes["WEIGHTS_0"], plain ? w : "", 5121, n);
    point(*g, primitive["indices"], plain ? f : "", 5125, mesh.num_faces() * 3);
  }
  json& draco_primitive = packed.doc["meshes"][0]["primitives"][0];
  draco_primitive["extensions"]["KHR_draco_mesh_compression"] = {
      {"bufferView", append_view(packed, stream)},
      {"attributes", {{"POSITION", ids.position}, {"JOINTS_0", ids.joints}, {"WEIGHTS_0", ids.weights}}}};
  packed.doc["extensionsUsed"].push_back("KHR_draco_mesh_compression");
  packed.doc["extensionsRequired"].push_back("KHR_draco_mesh_compression");
  write_file_atomic(dir + "/plain.glb", encode_glb(twin));
  write_file_atomic(dir + "/draco.glb", encode_glb(packed));

  PoseExtractOptions opt;
  opt.animation = "0";
  opt.times = {0.5, 5.01, 10.3};
  json report;
  pose_extract_files(dir + "/plain.glb", dir + "/plain", opt, Log::silent(), report);
  pose_extract_files(dir + "/draco.glb", dir + "/draco", opt, Log::silent(), report);
  const PoseManifest ours = read_pose_manifest(dir + "/draco/poses.json");
  const PoseManifest theirs = read_pose_manifest(dir + "/plain/poses.json");
  ASSERT_EQ(ours.poses.size(), 3u);
  EXPECT_EQ(obj_parts(dir + "/draco/" + ours.rest), obj_parts(dir + "/plain/" + theirs.rest));
  for (size_t k = 0; k < ours.poses.size(); ++k)
    EXPECT_EQ(obj_parts(dir + "/draco/" + ours.poses[k].file), obj_parts(dir + "/plain/" + theirs.poses[k].file)) << "pose " << k;
  // Two primitives naming the same accessors (exporters share placeholder accessors so): each gets
  // accessors of its own, holding the same data.
  GltfFile twice = packed;
  twice.doc["meshes"][0]["primitives"].push_back(twice.doc["meshes"][0]["primitives"][0]);
  ASSERT_EQ(draco_primitives_decoded(twice, "twice.glb"), 2u);
  const json& first = twice.doc["meshes"][0]["primitives"][0];
  const json& second = twice.doc["meshes"][0]["primitives"][1];
  for (const json* slots : {&first["attributes"], &first}) {
    for (const char* name : {"POSITION", "JOINTS_0", "WEIGHTS_0", "indices"}) {
      if (!slots->contains(name)) continue;
      const size_t a = (*slots)[name].get<size_t>();
      const size_t b = (slots == &first ? second : second["attributes"])[name].get<size_t>();
      EXPECT_NE(a, b) << name;
      EXPECT_EQ(twice.doc["accessors"][a]["count"], twice.doc["accessors"][b]["count"]) << name;
      EXPECT_TRUE(view_data(twice, twice.doc["accessors"][a]["bufferView"].get<size_t>()) ==
                  view_data(twice, twice.doc["accessors"][b]["bufferView"].get<size_t>()))
          << name;
    }
  }
  EXPECT_FALSE(first.contains("extensions"));
  EXPECT_EQ(twice.doc.value("extensionsRequired", json::array()), json::array());

  // Its stream cut short: exit 2 naming the file and the primitive.
  const size_t view = draco_primitive["extensions"]["KHR_draco_mesh_compression"]["bufferView"].get<size_t>();
  packed.doc["bufferViews"][view]["byteLength"] = stream.size() / 3;
  write_file_atomic(dir + "/cut.glb", encode_glb(packed));
  try {
    pose_extract_files(dir + "/cut.glb", dir + "/cut", opt, Log::silent(), report);
    ADD_FAILURE() << "a cut Draco stream was read";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ExitCode::bad_input) << e.what();
    EXPECT_EQ(e.subject(), dir + "/cut.glb");
    EXPECT_NE(e.message().find("mesh 0's primitive 0's KHR_draco_mesh_compression's data does not decode"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace spx
