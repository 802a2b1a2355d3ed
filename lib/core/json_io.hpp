#pragma once
// JSON files between the tools: parsing with file-naming errors, typed field access, atomic writes.
#include <nlohmann/json.hpp>
#include <string>

namespace spx {

using json = nlohmann::json;

json read_json_file(const std::string& path);
[[noreturn]] void throw_malformed(const std::string& path, const char* what, const char* detail);
// parse(read_json_file(path)), with the JSON library's own errors named as `what` in `path`.
template <class Parse>
auto read_json_document(const std::string& path, const char* what, Parse&& parse) -> decltype(parse(json())) {
  const json j = read_json_file(path);
  try {
    return parse(j);
  } catch (const json::exception& e) {
    throw_malformed(path, what, e.what());
  }
}

// Deterministic text (keys sorted by nlohmann's std::map, shortest round-trip doubles); bytes of a
// string that are not UTF-8 (a file name's) written as U+FFFD.
std::string dump_json(const json& j);
void write_json_atomic(const std::string& path, const json& j);

// Field access that names the file and the field on failure (exit code 2).
const json& require(const json& j, const char* key, const std::string& file);
double require_number(const json& j, const char* key, const std::string& file);
double as_finite_number(const json& v, const std::string& what, const std::string& file);
// A string field that must be there.
std::string require_string(const json& j, const char* key, const std::string& file);
// The header every file between tools has: "format" (this one), "version" (up to `newest`)
// and "generator" (a string; needed where `generator_required`: not in a file a person or
// another tool may write, the pose manifest).
void require_header(const json& j, const char* format, const std::string& what, int newest, const std::string& file,
                    bool generator_required = true);

}  // namespace spx
