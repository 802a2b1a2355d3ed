#include "core/json_io.hpp"

#include <cmath>

#include "core/atomic_file.hpp"
#include "core/error.hpp"

namespace spx {

json read_json_file(const std::string& path) {
  const std::string text = read_file(path);
  try {
    return json::parse(text);
  } catch (const json::exception& e) {
    fail_input(path, std::string("not valid JSON: ") + e.what());
  }
}

std::string dump_json(const json& j) { return j.dump(1) + "\n"; }

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

std::string optional_string(const json& j, const char* key, const std::string& fallback, const std::string& file) {
  if (!j.is_object() || !j.contains(key) || j[key].is_null()) return fallback;
  if (!j[key].is_string()) fail_input(file, std::string("field '") + key + "' is not a string");
  return j[key].get<std::string>();
}

bool has_format(const json& j, const char* format) {
  return j.is_object() && j.contains("format") && j["format"].is_string() && j["format"] == format;
}

}  // namespace spx
