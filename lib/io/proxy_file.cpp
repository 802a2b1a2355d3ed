#include "io/proxy_file.hpp"

#include <cmath>

#include "core/error.hpp"
#include "core/version.hpp"
#include "io/skin_file.hpp"
#include "io/spheres_file.hpp"

namespace spx {

namespace {

json skin_to_json(const ProxySkin& skin) {
  json joints = json::array(), spheres = json::array();
  for (size_t j = 0; j < skin.joints.size(); ++j) joints.push_back({{"name", skin.joints[j]}, {"parent", skin.parents[j]}});
  for (const auto& s : skin.spheres)
    spheres.push_back({{"joints", s.joint}, {"weights", s.weight}, {"center", {s.center.x(), s.center.y(), s.center.z()}},
                       {"radius", s.radius}});
  return {{"joints", joints}, {"spheres", spheres}};
}

ProxySkin skin_from_json(const json& j, size_t sphere_count, const std::string& path) {
  ProxySkin skin;
  const json& joints = require(j, "joints", path);
  if (!joints.is_array() || joints.empty()) fail_input(path, "skin.joints is not a non-empty array");
  for (const json& joint : joints) {
    skin.joints.push_back(require_string(joint, "name", path));
    const json& parent = require(joint, "parent", path);
    if (!parent.is_number_integer() || parent.get<long long>() < -1 || parent.get<long long>() >= (long long)joints.size())
      fail_input(path, "skin.joints: a parent is not -1 or a joint");
    skin.parents.push_back(parent.get<int>());
  }
  require_joint_tree(skin.parents, "skin.joints", path);
  const json& spheres = require(j, "spheres", path);
  if (!spheres.is_array() || spheres.size() != sphere_count)
    fail_input(path, "skin.spheres must have one entry per sphere (" + std::to_string(sphere_count) + ")");
  for (size_t i = 0; i < spheres.size(); ++i) {
    const std::string what = "skin.spheres[" + std::to_string(i) + "]";
    SkinnedSphere s;
    const json& js = require(spheres[i], "joints", path);
    const json& ws = require(spheres[i], "weights", path);
    const json& c = require(spheres[i], "center", path);
    if (!js.is_array() || js.size() != 4 || !ws.is_array() || ws.size() != 4 || !c.is_array() || c.size() != 3)
      fail_input(path, what + " needs 4 joints, 4 weights and a center [x, y, z]");
    for (size_t k = 0; k < 4; ++k) {
      if (!js[k].is_number_integer() || js[k].get<long long>() < 0 || js[k].get<long long>() >= (long long)joints.size())
        fail_input(path, what + ".joints holds an index that is not a joint");
      s.joint[k] = js[k].get<int>();
      s.weight[k] = float(as_finite_number(ws[k], what + ".weights", path));
      if (s.weight[k] < 0) fail_input(path, what + ".weights holds a negative weight");
    }
    // As the runtime: a sphere no joint weighs cannot be skinned.
    if (!(s.weight[0] + s.weight[1] + s.weight[2] + s.weight[3] > 0))
      fail_input(path, what + ".weights has no positive weight");
    for (int k = 0; k < 3; ++k) s.center[k] = as_finite_number(c[size_t(k)], what + ".center", path);
    s.radius = require_number(spheres[i], "radius", path);
    if (s.radius < 0) fail_input(path, what + ".radius is negative");
    skin.spheres.push_back(s);
  }
  return skin;
}

}  // namespace

json proxy_to_plain_json(const ProxyModel& p) {
  json poses = json::array();
  for (const auto& pose : p.poses) poses.push_back({{"name", pose.name}, {"spheres", sphere_array_to_json(pose.spheres)}});
  json sites = json::array();
  for (const auto& s : p.sites) sites.push_back({s.x(), s.y(), s.z()});
  json out = {{"poses", poses}, {"sphere_sites", p.sphere_sites}, {"sites", sites}};
  if (!p.skin.empty()) out["skin"] = skin_to_json(p.skin);
  return out;
}

json proxy_to_json(const ProxyModel& p) {
  json j = proxy_to_plain_json(p);
  j["format"] = "spx-proxy";
  j["version"] = 1;
  j["generator"] = std::string("spx ") + version_string();
  j["max_radius"] = std::isfinite(p.max_radius) ? json(p.max_radius) : json(nullptr);
  for (size_t i = 0; i < p.poses.size(); ++i) {
    j["poses"][i]["source"] = p.poses[i].source;
    j["poses"][i]["outside"] = p.poses[i].outside;
  }
  return j;
}

ProxyModel proxy_from_json(const json& j, const std::string& path) {
  // The same rules as schemas/proxy.schema.json (tests/data/json holds documents both judge).
  require_header(j, "spx-proxy", "proxy", 1, path);
  ProxyModel p;
  const json& max_r = require(j, "max_radius", path);
  if (!max_r.is_null()) p.max_radius = as_finite_number(max_r, "field 'max_radius'", path);
  if (!(p.max_radius > 0)) fail_input(path, "field 'max_radius' is not positive");
  const json& poses = require(j, "poses", path);
  if (!poses.is_array() || poses.empty()) fail_input(path, "field 'poses' must be a non-empty array");
  for (size_t i = 0; i < poses.size(); ++i) {
    const std::string what = "poses[" + std::to_string(i) + "]";
    ProxyPose pose;
    const json& name = require(poses[i], "name", path);
    if (!name.is_string()) fail_input(path, what + ".name is not a string");
    pose.name = name;
    pose.source = require_string(poses[i], "source", path);
    pose.spheres = sphere_array_from_json(require(poses[i], "spheres", path), what + ".spheres", path, true);
    const json& outside = require(poses[i], "outside", path);
    if (!outside.is_array()) fail_input(path, what + ".outside is not an array");
    for (const json& v : outside) {
      if (!v.is_number_integer() || v.get<long long>() < 0 || v.get<long long>() >= (long long)pose.spheres.size())
        fail_input(path, what + ".outside holds an index that is not a sphere");
      pose.outside.push_back(v.get<int>());
    }
    if (i > 0 && pose.spheres.size() != p.poses.front().spheres.size())
      fail_input(path, what + " has " + std::to_string(pose.spheres.size()) + " spheres, the rest pose has " +
                           std::to_string(p.poses.front().spheres.size()));
    p.poses.push_back(std::move(pose));
  }
  const json& sites = require(j, "sites", path);
  if (!sites.is_array()) fail_input(path, "field 'sites' is not an array");
  for (size_t i = 0; i < sites.size(); ++i) {
    const std::string what = "sites[" + std::to_string(i) + "]";
    if (!sites[i].is_array() || sites[i].size() != 3) fail_input(path, what + " is not [x, y, z]");
    Eigen::Vector3d s;
    for (int k = 0; k < 3; ++k) s[k] = as_finite_number(sites[i][k], what, path);
    p.sites.push_back(s);
  }
  const json& ss = require(j, "sphere_sites", path);
  if (!ss.is_array() || ss.size() != p.sphere_count())
    fail_input(path, "field 'sphere_sites' must have one entry per sphere");
  for (const auto& v : ss) {
    if (!v.is_number_integer() || v.get<long long>() < 0 || v.get<long long>() >= (long long)p.sites.size())
      fail_input(path, "field 'sphere_sites' holds an index that is not a site");
    p.sphere_sites.push_back(v.get<int>());
  }
  if (j.contains("skin")) p.skin = skin_from_json(j["skin"], p.sphere_count(), path);
  return p;
}

ProxyModel read_proxy_file(const std::string& path) {
  return read_json_document(path, "proxy", [&](const json& j) { return proxy_from_json(j, path); });
}

}  // namespace spx
