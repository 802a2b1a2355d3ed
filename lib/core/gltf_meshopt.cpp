#include "core/gltf_meshopt.hpp"

#include <meshoptimizer.h>

#include "core/error.hpp"
#include "core/gltf_file.hpp"

namespace spx {
namespace {

// A codec's stream gives at most this many bytes per byte of it (the attribute codec's least,
// a 2-bit header per 16 bytes; a triangle takes a byte, an index too): a count past it is no
// stream's, and is refused before a buffer of that size is made.
constexpr size_t kMostBytesPerStreamByte = 64;

// One view's extension, its rules checked (the extension's "JSON schema updates").
struct Compressed {
  size_t buffer = 0, offset = 0, length = 0, stride = 0, count = 0;
  std::string mode, filter = "NONE";
};

std::string one_of(const json& ext, const char* key, std::initializer_list<const char*> names, const std::string& at,
                   const std::string& path) {
  const json& v = ext[key];
  for (const char* name : names)
    if (v.is_string() && v.get<std::string>() == name) return name;
  fail_input(path, at + "'s " + key + " is not one it names (" + v.dump() + ")");
}

Compressed compressed_view(const json& view, const json& ext, const std::string& at, const std::string& path) {
  if (!ext.is_object()) fail_input(path, at + " is not an object");
  for (const char* key : {"buffer", "byteLength", "byteStride", "count", "mode"})
    if (!ext.contains(key)) fail_input(path, at + " has no '" + key + "'");
  Compressed c;
  c.buffer = gltf_whole_number(ext, "buffer", 0, path, at.c_str());
  c.offset = gltf_whole_number(ext, "byteOffset", 0, path, at.c_str());
  c.length = gltf_whole_number(ext, "byteLength", 0, path, at.c_str());
  c.stride = gltf_whole_number(ext, "byteStride", 0, path, at.c_str());
  c.count = gltf_whole_number(ext, "count", 0, path, at.c_str());
  c.mode = one_of(ext, "mode", {"ATTRIBUTES", "TRIANGLES", "INDICES"}, at, path);
  if (ext.contains("filter")) c.filter = one_of(ext, "filter", {"NONE", "OCTAHEDRAL", "QUATERNION", "EXPONENTIAL"}, at, path);
  const auto rule = [&](bool holds, const std::string& what) {
    if (!holds) fail_input(path, at + ": " + what);
  };
  const size_t length = gltf_whole_number(view, "byteLength", 0, path, "a bufferView");
  rule(c.stride > 0 && c.count <= length / c.stride && c.count * c.stride == length,
       "count times byteStride is not the view's byteLength");
  rule(!view.contains("byteStride") || gltf_whole_number(view, "byteStride", 0, path, "a bufferView") == c.stride,
       "byteStride is not the view's");
  if (c.mode == "ATTRIBUTES") {
    rule(c.stride % 4 == 0 && c.stride <= 256, "ATTRIBUTES need a byteStride of a multiple of 4 up to 256");
  } else {
    rule(c.stride == 2 || c.stride == 4, c.mode + " need a byteStride of 2 or 4");
    rule(c.filter == "NONE", c.mode + " take no filter");
    rule(c.mode == "INDICES" || c.count % 3 == 0, "TRIANGLES need a count divisible by 3");
  }
  rule(c.filter != "OCTAHEDRAL" || c.stride == 4 || c.stride == 8, "OCTAHEDRAL needs a byteStride of 4 or 8");
  rule(c.filter != "QUATERNION" || c.stride == 8, "QUATERNION needs a byteStride of 8");
  rule((c.count * c.stride + kMostBytesPerStreamByte - 1) / kMostBytesPerStreamByte <= c.length,
       "its " + std::to_string(c.length) + " bytes cannot hold " + std::to_string(c.count * c.stride));
  return c;
}

// The view's data: the stream decoded by its mode, then its filter applied in place.
std::string decoded(const Compressed& c, const BufferBytes& source, const std::string& at, const std::string& path) {
  if (!source) fail_input(path, at + " reads a buffer with no data");
  if (c.offset > source->size() || c.length > source->size() - c.offset) fail_input(path, at + " runs past the end of its buffer");
  if (c.count == 0) return {};
  const auto* stream = reinterpret_cast<const unsigned char*>(source->data()) + c.offset;
  std::vector<unsigned char> out(c.count * c.stride);  // allocated, so aligned as the filters need
  int status = 0;
  if (c.mode == "ATTRIBUTES") status = meshopt_decodeVertexBuffer(out.data(), c.count, c.stride, stream, c.length);
  else if (c.mode == "TRIANGLES") status = meshopt_decodeIndexBuffer(out.data(), c.count, c.stride, stream, c.length);
  else status = meshopt_decodeIndexSequence(out.data(), c.count, c.stride, stream, c.length);
  // The header byte's high half names the codec, its low half the codec's version.
  const unsigned char header = c.length > 0 ? stream[0] : 0;
  const unsigned char codec = c.mode == "ATTRIBUTES" ? 0xa0 : c.mode == "TRIANGLES" ? 0xe0 : 0xd0;
  if (status != 0 && (header & 0xf0) == codec && (header & 0x0f) > 0)
    fail_unsupported(path, at + "'s data is of version " + std::to_string(header & 0x0f) +
                               " of its codec, which this build's meshoptimizer does not read");
  if (status != 0) fail_input(path, at + "'s data does not decode (cut short or not meshopt data)");
  if (c.filter == "OCTAHEDRAL") meshopt_decodeFilterOct(out.data(), c.count, c.stride);
  if (c.filter == "QUATERNION") meshopt_decodeFilterQuat(out.data(), c.count, c.stride);
  if (c.filter == "EXPONENTIAL") meshopt_decodeFilterExp(out.data(), c.count, c.stride);
  return std::string(out.begin(), out.end());
}

}  // namespace

size_t decode_meshopt_views(json& doc, std::vector<BufferBytes>& buffers, const std::string& path) {
  if (!doc.contains("bufferViews")) return 0;
  std::string data;  // the decoded views, each at a multiple of 4 bytes (as accessors need)
  size_t changed = 0;
  json& views = doc["bufferViews"];
  for (size_t v = 0; v < views.size(); ++v) {
    json& view = views[v];
    const json* ext = extension_of(view, kMeshoptCompression);
    if (!ext) continue;
    const std::string at = "bufferView " + std::to_string(v) + "'s " + kMeshoptCompression;
    const Compressed c = compressed_view(view, *ext, at, path);
    if (c.buffer >= buffers.size()) fail_input(path, at + " names a buffer that does not exist");
    while (data.size() % 4) data += '\0';
    view["buffer"] = buffers.size();
    view["byteOffset"] = data.size();
    data += decoded(c, buffers[c.buffer], at, path);
    remove_extension_of(view, kMeshoptCompression);
    ++changed;
  }
  drop_extension(doc, kMeshoptCompression);
  if (changed == 0) return 0;
  doc["buffers"].push_back({{"byteLength", data.size()}});
  buffers.push_back(std::move(data));
  return changed;
}

}  // namespace spx
