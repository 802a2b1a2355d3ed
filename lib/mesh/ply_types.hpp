#pragma once
// PLY's property types as a header names them (by name or by alias): what the checks before
// assimp (mesh/file_checks) and the PLY made ready for assimp (mesh/ply_input) both read.
#include <string_view>

namespace spx {

struct PlyType {
  int size = 0;  // bytes; 0: no PLY type of that name
  bool is_signed = false, is_float = false;
};

inline PlyType ply_type(std::string_view name) {
  static const struct {
    const char *name, *alias;
    PlyType type;
  } types[] = {{"char", "int8", {1, true, false}},    {"uchar", "uint8", {1, false, false}},
               {"short", "int16", {2, true, false}},  {"ushort", "uint16", {2, false, false}},
               {"int", "int32", {4, true, false}},    {"uint", "uint32", {4, false, false}},
               {"float", "float32", {4, true, true}}, {"double", "float64", {8, true, true}}};
  for (const auto& t : types)
    if (name == t.name || name == t.alias) return t.type;
  return {};
}

}  // namespace spx
