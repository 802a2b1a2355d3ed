#include "core/gltf_file.hpp"

#include <algorithm>
#include <cctype>
#include <cstring>
#include <filesystem>

#include "core/atomic_file.hpp"
#include "core/base64.hpp"
#include "core/error.hpp"
#include "core/gltf_meshopt.hpp"

namespace spx {
namespace {

uint32_t get32(const std::string& s, size_t at) {
  uint32_t v = 0;
  for (int i = 0; i < 4; ++i) v |= uint32_t(static_cast<unsigned char>(s[at + size_t(i)])) << (8 * i);
  return v;
}

void put32(std::string& s, uint32_t v) {
  for (int i = 0; i < 4; ++i) s += char((v >> (8 * i)) & 0xff);
}

// The members this reader follows, checked for their types first: a glTF that names a buffer by
// a string or lists its views in an object is not one, and says so (never a JSON type error).
void require_objects(const json& doc, const char* list, const std::string& path) {
  if (!doc.contains(list)) return;
  const json& items = doc[list];
  if (!items.is_array() || !std::all_of(items.begin(), items.end(), [](const json& e) { return e.is_object(); }))
    fail_input(path, std::string("not a glTF 2.0 asset: its '") + list + "' is not a list of objects");
}

// A relative URI's path: "%20" is a space (a Blender export of "My Body.gltf" writes its buffer as
// "My%20Body.bin"). A '%' not followed by two hex digits stays as it is.
std::string percent_decoded(const std::string& uri) {
  const auto hex = [](char c) { return std::isxdigit(static_cast<unsigned char>(c)) != 0; };
  std::string out;
  for (size_t i = 0; i < uri.size(); ++i) {
    if (uri[i] == '%' && i + 2 < uri.size() && hex(uri[i + 1]) && hex(uri[i + 2])) {
      out += char(std::stoi(uri.substr(i + 1, 2), nullptr, 16));
      i += 2;
    } else {
      out += uri[i];
    }
  }
  return out;
}

// A URI as a message quotes it: its first 60 characters.
std::string shortened(const std::string& uri) { return uri.size() <= 60 ? uri : uri.substr(0, 60) + "..."; }

// A .gltf buffer's bytes: a data: URI, or a file beside the document.
std::string buffer_bytes(const json& buffer, const std::string& path) {
  if (buffer.contains("uri") && !buffer["uri"].is_string()) fail_input(path, "not a glTF 2.0 asset: a buffer's 'uri' is not a string");
  const std::string uri = buffer.value("uri", "");
  if (uri.empty()) fail_input(path, "a buffer has no uri (only a GLB's first buffer may)");
  if (uri.rfind("data:", 0) == 0) {
    const size_t comma = uri.find(',');
    if (comma == std::string::npos || uri.substr(0, comma).find(";base64") == std::string::npos)
      fail_unsupported(path, "a buffer's data: URI is not base64");
    const std::optional<std::string> bytes = decode_base64(uri.substr(comma + 1));
    if (!bytes) fail_input(path, "a buffer's data: URI is not base64");
    return *bytes;
  }
  const std::string file = (std::filesystem::path(path).parent_path() / percent_decoded(uri)).string();
  std::error_code ec;  // a name too long for the file system is not there either
  if (!std::filesystem::exists(file, ec)) fail_input(path, "its buffer '" + shortened(uri) + "' is not beside it");
  return read_file(file);
}

// Whether `doc` lists extension `name`, or one of its views carries it.
bool uses_extension(const json& doc, const char* name) {
  for (const char* list : {"extensionsUsed", "extensionsRequired"}) {
    const json names = doc.value(list, json::array());
    if (names.is_array() && std::find(names.begin(), names.end(), json(name)) != names.end()) return true;
  }
  const json& views = doc["bufferViews"];
  return std::any_of(views.begin(), views.end(), [&](const json& view) { return extension_of(view, name) != nullptr; });
}

// A buffer EXT_meshopt_compression marks as its fallback: the compressed views' data uncompressed,
// which a reader that decodes them need not load.
bool meshopt_fallback(const json& buffer) {
  const json* ext = extension_of(buffer, kMeshoptCompression);
  return ext && ext->is_object() && ext->contains("fallback") && (*ext)["fallback"] == true;
}

// Each buffer's bytes: a GLB's first, with no uri, is its BIN chunk; the others are their uri's,
// or none where a file that uses EXT_meshopt_compression gives no uri or marks the buffer its
// fallback (the data the compressed views stand for).
std::vector<BufferBytes> buffer_list(const json& doc, const std::string* glb_bin, const std::string& path) {
  std::vector<BufferBytes> out;
  const bool meshopt = uses_extension(doc, kMeshoptCompression);
  for (const json& buffer : doc.value("buffers", json::array())) {
    if (glb_bin && out.empty() && !buffer.contains("uri")) {
      out.push_back(*glb_bin);
    } else if (meshopt && (!buffer.contains("uri") || meshopt_fallback(buffer))) {
      out.push_back(std::nullopt);
    } else {
      std::string bytes = buffer_bytes(buffer, path);
      if (bytes.size() < gltf_whole_number(buffer, "byteLength", 0, path, "a buffer")) fail_input(path, "a buffer is shorter than its byteLength");
      out.push_back(std::move(bytes));
    }
  }
  return out;
}

// The buffers as one: each appended at a multiple of 8 bytes, its views moved with it.
GltfFile merge_buffers(json doc, const std::vector<BufferBytes>& buffers, const std::string& path) {
  GltfFile out;
  std::vector<size_t> base;
  for (const BufferBytes& bytes : buffers) {
    while (out.bin.size() % 8) out.bin += '\0';
    base.push_back(out.bin.size());
    if (bytes) out.bin += *bytes;
  }
  for (json& view : doc["bufferViews"]) {
    const size_t b = gltf_whole_number(view, "buffer", 0, path, "a bufferView");
    if (b >= base.size()) fail_input(path, "a bufferView names a buffer that does not exist");
    if (!buffers[b]) fail_input(path, "a bufferView lies in a buffer with no data (no uri, and not decoded from EXT_meshopt_compression)");
    view["buffer"] = 0;
    view["byteOffset"] = gltf_whole_number(view, "byteOffset", 0, path, "a bufferView") + base[b];
  }
  if (!base.empty()) doc["buffers"] = json::array({{{"byteLength", out.bin.size()}}});
  out.doc = std::move(doc);
  return out;
}

// The bytes the views read, each view's at a multiple of 4 bytes: the compressed streams a file
// held beside them are not carried on (into the GLB assimp reads, or the one proxy-export writes).
void keep_views_bytes_only(GltfFile& file, const std::string& path) {
  std::string bin;
  for (json& view : file.doc["bufferViews"]) {
    const size_t offset = gltf_whole_number(view, "byteOffset", 0, path, "a bufferView");
    const size_t length = gltf_whole_number(view, "byteLength", 0, path, "a bufferView");
    if (offset > file.bin.size() || length > file.bin.size() - offset) fail_input(path, "a bufferView runs past the end of its buffer");
    while (bin.size() % 4) bin += '\0';
    view["byteOffset"] = bin.size();
    bin.append(file.bin, offset, length);
  }
  file.bin = std::move(bin);
  file.doc["buffers"] = json::array({{{"byteLength", file.bin.size()}}});
}

// The document and its buffers as a GltfFile: compressed views decoded, the buffers merged.
GltfFile plain_file(json doc, const std::string* glb_bin, const std::string& path) {
  std::vector<BufferBytes> buffers = buffer_list(doc, glb_bin, path);
  const size_t decoded = decode_meshopt_views(doc, buffers, path);
  GltfFile out = merge_buffers(std::move(doc), buffers, path);
  out.decoded_views = decoded;
  if (decoded > 0) keep_views_bytes_only(out, path);
  return out;
}

// asset.version ("2.0" in a glTF 2.0 asset); empty where it is missing or not a string.
std::string asset_version(const json& doc) {
  const json* asset = doc.is_object() && doc.contains("asset") ? &doc["asset"] : nullptr;
  if (!asset || !asset->is_object() || !asset->contains("version") || !(*asset)["version"].is_string()) return "";
  return (*asset)["version"].get<std::string>();
}

json parse_document(const std::string& text, const std::string& path) {
  json doc;
  try {
    doc = json::parse(text);
  } catch (const json::exception& e) {
    fail_input(path, std::string("not a glTF: its JSON does not parse (") + e.what() + ")");
  }
  if (asset_version(doc).rfind("2.", 0) != 0) fail_input(path, "not a glTF 2.0 asset (no asset.version 2.x)");
  for (const char* list : {"buffers", "bufferViews", "meshes", "nodes", "scenes"}) require_objects(doc, list, path);
  if (!doc.contains("bufferViews")) doc["bufferViews"] = json::array();
  return doc;
}

}  // namespace

size_t gltf_whole_number(const json& object, const char* key, size_t otherwise, const std::string& path, const char* of) {
  if (!object.contains(key)) return otherwise;
  const json& v = object[key];
  if (!v.is_number_integer() || v.get<int64_t>() < 0)
    fail_input(path, std::string("not a glTF 2.0 asset: ") + of + "'s '" + key + "' is not a whole number 0 or above (" +
                         v.dump() + ")");
  return size_t(v.get<int64_t>());
}

GltfFile read_gltf_file(const std::string& path) { return gltf_from_bytes(read_file(path), path); }

GltfFile gltf_from_bytes(const std::string& bytes, const std::string& path) {
  if (bytes.size() < 4 || bytes.compare(0, 4, "glTF") != 0) {
    // A glTF document is a JSON object (after a byte order mark, which readers may meet):
    // anything else is not one, and its bytes are not quoted back.
    const size_t first = bytes.find_first_not_of(" \t\r\n", bytes.compare(0, 3, "\xef\xbb\xbf") == 0 ? 3 : 0);
    if (first == std::string::npos || bytes[first] != '{') fail_input(path, "not a glTF (neither GLB nor JSON)");
    return plain_file(parse_document(bytes, path), nullptr, path);
  }
  if (bytes.size() < 20 || get32(bytes, 4) != 2) fail_input(path, "not a GLB of glTF 2.0");
  if (get32(bytes, 8) > bytes.size()) fail_input(path, "truncated: its header says " + std::to_string(get32(bytes, 8)) + " bytes");
  GltfFile out;
  size_t at = 12;
  bool seen_json = false;
  while (at + 8 <= bytes.size()) {
    const size_t length = get32(bytes, at);
    const std::string type = bytes.substr(at + 4, 4);
    if (at + 8 + length > bytes.size()) fail_input(path, "truncated: a chunk runs past the end of the file");
    if (type == "JSON") out.doc = parse_document(bytes.substr(at + 8, length), path), seen_json = true;
    else if (type == std::string("BIN\0", 4)) out.bin = bytes.substr(at + 8, length);
    at += 8 + length;
  }
  if (!seen_json) fail_input(path, "a GLB without its JSON chunk");
  // The usual GLB, one buffer and nothing compressed, is taken as it is.
  if (out.doc.value("buffers", json::array()).size() <= 1 && !uses_extension(out.doc, kMeshoptCompression)) return out;
  return plain_file(std::move(out.doc), &out.bin, path);
}

const json* extension_of(const json& object, const char* name) {
  if (!object.is_object()) return nullptr;
  const auto extensions = object.find("extensions");
  if (extensions == object.end() || !extensions->is_object()) return nullptr;
  const auto ext = extensions->find(name);
  return ext == extensions->end() ? nullptr : &*ext;
}

void remove_extension_of(json& object, const char* name) {
  if (!extension_of(object, name)) return;
  object["extensions"].erase(name);
  if (object["extensions"].empty()) object.erase("extensions");
}

void drop_extension(json& doc, const std::string& name) {
  for (const char* list : {"extensionsUsed", "extensionsRequired"}) {
    if (!doc.contains(list) || !doc[list].is_array()) continue;
    json& names = doc[list];
    names.erase(std::remove(names.begin(), names.end(), json(name)), names.end());
    if (names.empty()) doc.erase(list);
  }
}

std::string encode_glb(const GltfFile& file) {
  std::string bin = file.bin;
  while (bin.size() % 4) bin += '\0';
  json doc = file.doc;
  if (!bin.empty()) {
    if (!doc.contains("buffers") || doc["buffers"].empty()) doc["buffers"] = json::array({json::object()});
    doc["buffers"][0]["byteLength"] = bin.size();
    doc["buffers"][0].erase("uri");
  }
  std::string text = doc.dump();
  while (text.size() % 4) text += ' ';
  std::string out = "glTF";
  put32(out, 2);
  put32(out, uint32_t(12 + 8 + text.size() + (bin.empty() ? 0 : 8 + bin.size())));
  put32(out, uint32_t(text.size()));
  out += "JSON";
  out += text;
  if (!bin.empty()) {
    put32(out, uint32_t(bin.size()));
    out.append("BIN\0", 4);
    out += bin;
  }
  return out;
}

}  // namespace spx
