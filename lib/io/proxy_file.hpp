#pragma once
// S_0..S_e with blend sites: what pose-map writes and proxy-export reads
// (OUT.proxy.json, schemas/proxy.schema.json).
#include <limits>
#include <string>
#include <vector>

#include "core/json_io.hpp"
#include "core/sphere.hpp"

namespace spx {

struct ProxyPose {
  std::string name;            // pose 0 is the rest pose
  std::string source;          // mesh file it was made from
  SphereSet spheres;           // same count in every pose; radius 0 = absent in this pose
  std::vector<int> outside;    // spheres whose mapped center fell outside this pose's mesh
};

struct ProxyModel {
  std::vector<ProxyPose> poses;
  std::vector<int> sphere_sites;            // per sphere: index into sites
  std::vector<Eigen::Vector3d> sites;       // blend sites (rest tet vertices), rest positions
  double max_radius = std::numeric_limits<double>::infinity();

  size_t sphere_count() const { return poses.empty() ? 0 : poses.front().spheres.size(); }
};

json proxy_to_json(const ProxyModel& proxy);
ProxyModel proxy_from_json(const json& j, const std::string& path);
ProxyModel read_proxy_file(const std::string& path);

// The plain dump proxy-export writes for OUT.json.
json proxy_to_plain_json(const ProxyModel& proxy);

}  // namespace spx
