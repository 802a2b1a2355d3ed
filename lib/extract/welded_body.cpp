// The welded body of an asset (extract/asset.hpp declares it): file vertices welded by
// position, as pose-extract writes the rest and its poses.
#include <cmath>
#include <cstdint>

#include "core/error.hpp"
#include "extract/asset.hpp"

namespace spx {

WeldedBody weld_body(const Asset& asset, bool at_default_weights) {
  WeldedBody body;
  body.weld = weld_by_position(asset.rest(at_default_weights), body.rest.vertices);
  for (const auto& t : asset.triangles()) body.rest.triangles.emplace_back(body.weld[t[0]], body.weld[t[1]], body.weld[t[2]]);
  body.repeated = read_triangles_once(body.rest);
  return body;
}

std::vector<size_t> first_file_vertices(const WeldedBody& body) {
  std::vector<size_t> first(body.rest.vertices.size(), SIZE_MAX);
  for (size_t v = 0; v < body.weld.size(); ++v)
    if (first[size_t(body.weld[v])] == SIZE_MAX) first[size_t(body.weld[v])] = v;
  return first;
}

TriMesh welded_pose(const WeldedBody& body, const std::vector<Eigen::Vector3d>& file_positions, double tolerance,
                    size_t& opened, const std::string& what, const std::string& input) {
  TriMesh pose;
  pose.triangles = body.rest.triangles;
  pose.vertices.assign(body.rest.vertices.size(), Eigen::Vector3d::Constant(std::nan("")));
  std::vector<char> set(pose.vertices.size(), 0);
  opened = 0;
  for (size_t i = 0; i < file_positions.size(); ++i) {
    const Eigen::Vector3d& p = file_positions[i];
    if (!p.allFinite())
      fail_input(input, what + ": vertex " + std::to_string(i) + " is not finite (broken skin, keys or morph weights)");
    const size_t v = size_t(body.weld[i]);
    if (!set[v]) {
      pose.vertices[v] = p;
      set[v] = 1;
    } else if ((pose.vertices[v] - p).norm() > tolerance) {
      ++opened;
    }
  }
  return pose;
}

}  // namespace spx
