#pragma once
// S_0..S_e with blend sites: what pose-map writes and proxy-export reads
// (OUT.proxy.json, schemas/proxy.schema.json).
#include <array>
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

// A rigged body's spheres follow its skin (pose-map given a skin): per sphere up to 4 joints and
// weights (0 past the last), its center in the asset's space (where the host's joint matrices
// act), and one radius for every frame. Empty `joints`: the proxy has no skin.
struct SkinnedSphere {
  std::array<int, 4> joint{{0, 0, 0, 0}};
  std::array<float, 4> weight{{0, 0, 0, 0}};
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  double radius = 0;
};
struct ProxySkin {
  std::vector<std::string> joints;
  std::vector<int> parents;
  std::vector<SkinnedSphere> spheres;
  bool empty() const { return joints.empty(); }
};

struct ProxyModel {
  std::vector<ProxyPose> poses;
  std::vector<int> sphere_sites;            // per sphere: index into sites
  std::vector<Eigen::Vector3d> sites;       // blend sites (rest tet vertices), rest positions
  double max_radius = std::numeric_limits<double>::infinity();
  ProxySkin skin;

  size_t sphere_count() const { return poses.empty() ? 0 : poses.front().spheres.size(); }
};

json proxy_to_json(const ProxyModel& proxy);
ProxyModel proxy_from_json(const json& j, const std::string& path);
ProxyModel read_proxy_file(const std::string& path);

// The plain dump proxy-export writes for OUT.json.
json proxy_to_plain_json(const ProxyModel& proxy);

}  // namespace spx
