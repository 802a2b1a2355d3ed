// The welded body of an asset (extract/asset.hpp declares it): file vertices welded by
// position, as pose-extract writes the rest and its poses, and the checks of its rest.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <set>

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

void check_rest_not_collapsed(const Asset& asset, const std::string& input) {
  const std::vector<Eigen::Matrix4d> rest = asset.rest_joint_matrices();
  std::vector<char> flat(rest.size(), 0);
  for (size_t j = 0; j < rest.size(); ++j) {
    const Eigen::Matrix3d m = rest[j].topLeftCorner<3, 3>();
    const double size = m.colwise().norm().maxCoeff();
    flat[j] = !(std::abs(m.determinant()) > 1e-9 * size * size * size) || !std::isfinite(m.determinant());
  }
  if (std::none_of(flat.begin(), flat.end(), [](char f) { return f; })) return;
  size_t collapsed = 0;
  std::set<size_t> named;
  for (const auto& weights : asset.vertex_joints()) {
    const bool all_flat = !weights.empty() && std::all_of(weights.begin(), weights.end(), [&](const auto& jw) {
      return jw.second == 0 || flat[size_t(jw.first)];
    });
    if (!all_flat) continue;
    ++collapsed;
    for (const auto& [j, w] : weights)
      if (w != 0) named.insert(size_t(j));
  }
  if (collapsed == 0) return;
  std::string joints = named.size() > 1 ? "joints " : "joint ";
  for (size_t j : named) joints += (j == *named.begin() ? "'" : ", '") + asset.joints()[j].name + "'";
  fail_input(input, "the rest (the nodes' own transforms, the asset without a clip) collapses " +
                        std::to_string(collapsed) + (collapsed == 1 ? " vertex: " : " vertices: ") + joints +
                        " scaled to nothing or past a number's range there (a node's scale of 0 or of 1e300, or an "
                        "inverse bind matrix of zeros); the rest is the body the proxy is packed in, and must show all "
                        "of it");
}

void check_rest_finite(const WeldedBody& body, const std::string& input) {
  const auto& v = body.rest.vertices;
  for (size_t i = 0; i < v.size(); ++i)
    if (!v[i].allFinite())
      fail_input(input, "the rest (the nodes' own transforms, the asset without a clip): vertex " + std::to_string(i) +
                            " is not finite (a node's transform or an inverse bind matrix past a number's range)");
}

}  // namespace spx
