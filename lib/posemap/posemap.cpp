#include "posemap/posemap.hpp"

#include <cmath>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/error.hpp"
#include "mesh/mesh_query.hpp"
#include "metrics/union_error.hpp"
#include "posemap/harmonic_map.hpp"

namespace spx {

PoseMapResult pose_map(const TriMesh& rest, const std::string& rest_source, const std::vector<PoseInput>& poses,
                       const SpheresFile& spheres, const PoseMapOptions& opt, Log& log) {
  PoseMapResult result;
  ProxyModel& proxy = result.proxy;
  proxy.max_radius = opt.max_radius > 0 ? opt.max_radius : spheres.max_radius;
  if (std::isnan(opt.max_radius) || opt.max_radius < 0) fail_usage("--max-radius", "must be a positive number");

  TetMesh tets;
  {
    StageTimer t(log, "tetrahedralize");
    tets = opt.tet_file.empty() ? tetrahedralize(rest, opt.tets, log) : read_medit_tets(opt.tet_file);
  }
  log.detail(std::to_string(tets.tets.size()) + " tets, " + std::to_string(tets.vertices.size()) + " vertices");

  StageTimer harmonic_timer(log, "harmonic");
  const HarmonicMap f(tets, rest, log);
  harmonic_timer.stop();

  const size_t n = spheres.spheres.size();
  std::vector<TetLocator::Location> where(n);
  for (size_t s = 0; s < n; ++s) where[s] = f.locator().locate(spheres.spheres[s].center);

  // Rest pose: S_0 as packed.
  ProxyPose rest_pose{stem_of(rest_source), rest_source, spheres.spheres, {}};
  proxy.poses.push_back(rest_pose);

  nlohmann::json pose_reports = nlohmann::json::array();
  auto report_pose = [&](const ProxyPose& pose, const TriMesh& mesh) {
    pose_reports.push_back({{"name", pose.name},
                            {"source", pose.source},
                            {"outside", pose.outside},
                            {"error", vertex_error(mesh, pose.spheres).to_json()}});
  };
  report_pose(proxy.poses.front(), rest);

  for (const PoseInput& input : poses) {
    StageTimer t(log, "pose " + input.name);
    const std::vector<Eigen::Vector3d> deformed = f.deform(input.mesh);
    const MeshQuery query(input.mesh);
    ProxyPose pose{input.name, input.source, SphereSet(n), {}};
    std::vector<char> outside(n, 0);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 16), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t s = r.begin(); s != r.end(); ++s) {
        Sphere& sphere = pose.spheres[s];
        sphere.center = f.map(where[s], deformed);
        if (!query.inside(sphere.center)) {
          outside[s] = 1;
          sphere.radius = 0;
        } else {
          sphere.radius = std::min(proxy.max_radius, query.distance(sphere.center));
        }
      }
    });
    for (size_t s = 0; s < n; ++s)
      if (outside[s]) pose.outside.push_back(int(s));
    if (!pose.outside.empty())
      log.warn(input.source + ": " + std::to_string(pose.outside.size()) +
               " sphere centers land outside this pose; those spheres get radius 0 in it");
    report_pose(pose, input.mesh);
    proxy.poses.push_back(std::move(pose));
  }

  // Blend sites: the nearest rest tet vertex of each sphere (the paper's local blend).
  std::vector<int> nearest(n, -1);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 16), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t s = r.begin(); s != r.end(); ++s) {
      double best = std::numeric_limits<double>::infinity();
      for (size_t v = 0; v < tets.vertices.size(); ++v) {
        const double d = (tets.vertices[v] - spheres.spheres[s].center).squaredNorm();
        if (d < best) {
          best = d;
          nearest[s] = int(v);
        }
      }
    }
  });
  std::vector<int> site_of_vertex(tets.vertices.size(), -1);
  std::vector<int> used(nearest);
  std::sort(used.begin(), used.end());
  used.erase(std::unique(used.begin(), used.end()), used.end());
  for (int v : used) {
    site_of_vertex[size_t(v)] = int(proxy.sites.size());
    proxy.sites.push_back(tets.vertices[size_t(v)]);
  }
  for (size_t s = 0; s < n; ++s) proxy.sphere_sites.push_back(site_of_vertex[size_t(nearest[s])]);

  size_t outside_points = 0;
  for (const auto& w : where) outside_points += w.outside > 0;
  result.report = {{"tets",
                    {{"method", opt.tet_file.empty() ? "CGAL Mesh_3 on the winding-number domain" : "user tets"},
                     {"source", opt.tet_file},
                     {"vertices", tets.vertices.size()},
                     {"tetrahedra", tets.tets.size()},
                     {"boundary_faces", tets.boundary_faces.size()}}},
                   {"map",
                    {{"method", "harmonic extension of the surface motion (least squares), barycentric in tets"},
                     {"data_points", f.data_points()},
                     {"dropped_points", f.dropped_points()},
                     {"centers_outside_tets", outside_points}}},
                   {"sphere_count", n},
                   {"site_count", proxy.sites.size()},
                   {"poses", pose_reports}};
  return result;
}

}  // namespace spx
