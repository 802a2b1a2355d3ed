#include "io/spheres_file.hpp"

#include <cmath>

#include "core/error.hpp"
#include "core/version.hpp"

namespace spx {

json sphere_array_to_json(const SphereSet& spheres) {
  json a = json::array();
  for (const auto& s : spheres) a.push_back({s.center.x(), s.center.y(), s.center.z(), s.radius});
  return a;
}

SphereSet sphere_array_from_json(const json& array, const std::string& what, const std::string& file,
                                 bool allow_zero_radius) {
  if (!array.is_array()) fail_input(file, what + " is not an array");
  SphereSet out;
  out.reserve(array.size());
  for (size_t i = 0; i < array.size(); ++i) {
    const json& s = array[i];
    const std::string name = what + "[" + std::to_string(i) + "]";
    if (!s.is_array() || s.size() != 4) fail_input(file, name + " is not [x, y, z, r]");
    Sphere sphere;
    for (int k = 0; k < 3; ++k) sphere.center[k] = as_finite_number(s[k], name, file);
    sphere.radius = as_finite_number(s[3], name, file);
    if (sphere.radius < 0 || (!allow_zero_radius && sphere.radius == 0))
      fail_input(file, name + " has a radius that is not positive");
    out.push_back(sphere);
  }
  return out;
}

json spheres_to_json(const SpheresFile& f) {
  json j;
  j["format"] = "spx-spheres";
  j["version"] = 1;
  j["generator"] = std::string("spx ") + version_string();
  j["source"] = {{"sdf", f.sdf}, {"mesh", f.mesh.empty() ? json(nullptr) : json(f.mesh)}};
  j["voxel_size"] = f.voxel_size;
  j["min_radius"] = f.min_radius;
  if (f.min_radius_asked > 0) j["min_radius_asked"] = f.min_radius_asked;
  j["max_radius"] = std::isfinite(f.max_radius) ? json(f.max_radius) : json(nullptr);
  j["radius_source"] = f.radius_source;
  j["tolerance"] = f.tolerance > 0 ? json(f.tolerance) : json(nullptr);
  if (f.max_spheres > 0) j["max_spheres"] = f.max_spheres;
  if (!f.sampling.is_default())
    j["sampling"] = {{"area_samples", f.sampling.area_samples}, {"seed", f.sampling.seed},
                     {"every_vertex", f.sampling.every_vertex}};
  j["spheres"] = sphere_array_to_json(f.spheres);
  if (!f.candidates.empty()) j["candidates"] = sphere_array_to_json(f.candidates);
  return j;
}

SpheresFile read_spheres_file(const std::string& path) {
  return read_json_document(path, "spheres file", [&](const json& j) { return spheres_from_json(j, path); });
}

SpheresFile spheres_from_json(const json& j, const std::string& path) {
  // The same rules as schemas/spheres.schema.json (tests/data/json holds documents both judge).
  require_header(j, "spx-spheres", "spheres", 1, path);
  SpheresFile f;
  auto positive = [&](const char* key) {
    const double v = require_number(j, key, path);
    if (!(v > 0)) fail_input(path, std::string("field '") + key + "' is not positive");
    return v;
  };
  f.voxel_size = positive("voxel_size");
  f.min_radius = positive("min_radius");
  if (j.contains("min_radius_asked") && !j["min_radius_asked"].is_null()) f.min_radius_asked = positive("min_radius_asked");
  const json& max_r = require(j, "max_radius", path);
  if (!max_r.is_null()) f.max_radius = as_finite_number(max_r, "field 'max_radius'", path);
  if (!(f.max_radius > 0)) fail_input(path, "field 'max_radius' is not positive");
  f.radius_source = require_string(j, "radius_source", path);
  if (f.radius_source != "mesh" && f.radius_source != "field")
    fail_input(path, "field 'radius_source' is neither \"mesh\" nor \"field\"");
  if (j.contains("tolerance") && !j["tolerance"].is_null()) {
    f.tolerance = as_finite_number(j["tolerance"], "field 'tolerance'", path);
    if (!(f.tolerance > 0)) fail_input(path, "field 'tolerance' is not positive");
  }
  if (j.contains("max_spheres") && !j["max_spheres"].is_null()) {
    const json& m = j["max_spheres"];
    if (!m.is_number_integer() || m.get<long long>() < 1) fail_input(path, "field 'max_spheres' is not a positive integer");
    f.max_spheres = size_t(m.get<long long>());
  }
  if (j.contains("sampling")) {
    const json& s = j["sampling"];
    if (!s.is_object()) fail_input(path, "field 'sampling' is not an object");
    const json& area = require(s, "area_samples", path), &seed = require(s, "seed", path);
    const json& every = require(s, "every_vertex", path);
    if (!area.is_number_unsigned() || area.get<uint64_t>() > 1000000)
      fail_input(path, "field 'sampling.area_samples' is not an integer from 0 to 1000000");
    if (!seed.is_number_unsigned()) fail_input(path, "field 'sampling.seed' is not a non-negative integer");
    if (!every.is_boolean()) fail_input(path, "field 'sampling.every_vertex' is not true or false");
    f.sampling = {size_t(area.get<uint64_t>()), seed.get<uint64_t>(), every.get<bool>()};
  }
  const json& source = require(j, "source", path);
  f.sdf = require_string(source, "sdf", path);
  const json& mesh = require(source, "mesh", path);
  if (!mesh.is_null() && !mesh.is_string()) fail_input(path, "field 'source.mesh' is neither a string nor null");
  if (mesh.is_string()) f.mesh = mesh.get<std::string>();
  f.spheres = sphere_array_from_json(require(j, "spheres", path), "spheres", path, false);
  if (j.contains("candidates")) f.candidates = sphere_array_from_json(j["candidates"], "candidates", path, false);
  if (f.spheres.empty()) fail_input(path, "holds no sphere");
  return f;
}

}  // namespace spx
