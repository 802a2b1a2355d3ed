#include "core/json_io.hpp"

#include <cmath>

#include "core/atomic_file.hpp"
#include "core/error.hpp"
#include "core/file_kind.hpp"

namespace spx {

json read_json_file(const std::string& path) {
  const std::string text = read_file(path);
  const FileKind kind = file_kind(path, text);
  if (kind == FileKind::spx) fail_input(path, "is " + describe(kind) + ", not JSON; give the .proxy.json pose-map wrote");
  if (kind != FileKind::unknown && kind != FileKind::json) fail_input(path, "is " + describe(kind) + ", not JSON");
  try {
    return json::parse(text);
  } catch (const json::exception& e) {
    fail_input(path, std::string("not valid JSON: ") + e.what());
  }
}

void throw_malformed(const std::string& path, const char* what, const char* detail) {
  fail_input(path, std::string("malformed ") + what + ": " + detail);
}

// A file name need not be UTF-8 (a Latin-1 name from an old archive): its bytes that are not
// become U+FFFD in the document, which JSON requires, instead of failing the run.
std::string dump_json(const json& j) { return j.dump(1, ' ', false, json::error_handler_t::replace) + "\n"; }

void write_json_atomic(const std::string& path, const json& j) { write_file_atomic(path, dump_json(j)); }

const json& require(const json& j, const char* key, const std::string& file) {
  if (!j.is_object()) fail_input(file, "expected a JSON object");
  auto it = j.find(key);
  if (it == j.end()) fail_input(file, std::string("missing field '") + key + "'");
  return *it;
}

double as_finite_number(const json& v, const std::string& what, const std::string& file) {
  if (!v.is_number()) fail_input(file, what + " is not a number");
  double d = v.get<double>();
  if (!std::isfinite(d)) fail_input(file, what + " is not finite");
  return d;
}

double require_number(const json& j, const char* key, const std::string& file) {
  return as_finite_number(require(j, key, file), std::string("field '") + key + "'", file);
}

std::string require_string(const json& j, const char* key, const std::string& file) {
  const json& v = require(j, key, file);
  if (!v.is_string()) fail_input(file, std::string("field '") + key + "' is not a string");
  return v.get<std::string>();
}

namespace {

// The "version" field: an integer >= 1; newer than `newest` is exit 3 (unsupported), anything
// else that is not a version this format ever had is exit 2.
int require_version(const json& j, const std::string& what, int newest, const std::string& file) {
  const json& v = require(j, "version", file);
  if (!v.is_number_integer() || v.get<long long>() < 1)
    fail_input(file, "field 'version' is not a " + what + " format version (an integer from 1)");
  if (v.get<long long>() > newest)
    fail_unsupported(file, what + " format version " + std::to_string(v.get<long long>()) + " is newer than this tool (" +
                               std::to_string(newest) + ")");
  return int(v.get<long long>());
}

// Whether j is an object whose "format" is the string `format`.
bool has_format(const json& j, const char* format) {
  return j.is_object() && j.contains("format") && j["format"].is_string() && j["format"] == format;
}

// Another of the chain's files given where `format` is read: what it is and where it goes.
std::string which_file_it_is(const json& j) {
  if (!j.is_object() || !j.contains("format") || !j["format"].is_string()) return "";
  const std::string f = j["format"].get<std::string>();
  if (f == "spx-spheres") return "; it is sphere-pack's spheres file, which pose-map makes a proxy of with the poses";
  if (f == "spx-proxy") return "; it is pose-map's proxy, which proxy-export and proxy-eval read";
  if (f == "spx.poses") return "; it is pose-extract's pose manifest, which pose-map and proxy-eval take as --manifest";
  if (f == "spx.skin") return "; it is pose-extract's skin file, which pose-map takes as --skin";
  return "";
}

}  // namespace

void require_header(const json& j, const char* format, const std::string& what, int newest, const std::string& file,
                    bool generator_required) {
  if (!has_format(j, format))
    fail_input(file, "is not a " + what + " file (expected \"format\": \"" + format + "\")" + which_file_it_is(j));
  require_version(j, what, newest, file);
  // What wrote the file is for a person reading it: a manifest written by hand or by another
  // tool need not say.
  if (generator_required || j.contains("generator")) require_string(j, "generator", file);
}

}  // namespace spx
