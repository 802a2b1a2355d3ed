#include "posemap/posemap.hpp"

#include <array>
#include <cmath>
#include <memory>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/error.hpp"
#include "core/format.hpp"
#include "mesh/mesh_query.hpp"
#include "mesh/defects.hpp"
#include "metrics/union_error.hpp"
#include "pack/pack.hpp"
#include "posemap/harmonic_map.hpp"
#include "sdf/sdf.hpp"

namespace spx {
namespace {

// The one rule for a sphere's radius in any pose, the rest included: min(max radius, exact
// distance to the pose's mesh and, for open meshes, a bound from the pose's own field across
// its holes); 0 where the center is outside, with the cause counted for the report.
struct PoseSolid {
  const MeshQuery* mesh;
  const DenseField* holes;  // null for closed meshes
  double max_radius;

  enum class Zero : char { none, outside, hole_bound, other };
  struct Radius {
    double value = 0;
    Zero zero = Zero::none;
  };

  Radius radius(const Eigen::Vector3d& c) const {
    if (!mesh->inside(c)) return {0, Zero::outside};
    const double exact = std::min(max_radius, mesh->distance(c));
    const double r = std::min(exact, hole_bound(c));
    if (r > 0) return {r, Zero::none};
    return {0, exact > 0 ? Zero::hole_bound : Zero::other};
  }

  // Distance is 1-Lipschitz: a voxel's depth less its offset to c bounds the depth at c; the
  // best of the 8 voxels around c, less the field's own error margin.
  double hole_bound(const Eigen::Vector3d& c) const {
    if (!holes) return std::numeric_limits<double>::infinity();
    const GridShape& g = holes->shape;
    const Eigen::Vector3d at = c / g.voxel_size - g.origin.cast<double>();
    const Eigen::Vector3i lo = at.array().floor().cast<int>();
    double best = 0;
    for (int corner = 0; corner < 8; ++corner) {
      const Eigen::Vector3i v = lo + Eigen::Vector3i(corner & 1, (corner >> 1) & 1, corner >> 2);
      if ((v.array() < 0).any() || (v.array() >= g.dims.array()).any()) continue;
      const double depth = -holes->values[g.index(v.x(), v.y(), v.z())];
      best = std::max(best, depth - (g.world(v.x(), v.y(), v.z()) - c).norm());
    }
    return std::max(0.0, best - 0.1 * g.voxel_size);
  }
};

// Sets the field to 0 (not a candidate center) wherever a sphere already covers it.
void clear_covered(DenseField& field, const SphereSet& spheres) {
  for (const auto& s : spheres)
    if (s.radius > 0) clear_inside(field.values, field.shape, s.center, s.radius);
}

}  // namespace

PoseMapResult pose_map(const TriMesh& rest, const std::string& rest_source, const std::vector<PoseInput>& poses,
                       const SpheresFile& spheres, const PoseMapOptions& opt, Log& log) {
  PoseMapResult result;
  ProxyModel& proxy = result.proxy;
  if (std::isnan(opt.max_radius) || opt.max_radius < 0) fail_usage("--max-radius", "must be a positive number");
  if (std::isnan(opt.fill_min_radius) || opt.fill_min_radius < 0) fail_usage("--fill-min-radius", "must be a positive number");
  proxy.max_radius = opt.max_radius > 0 ? opt.max_radius : spheres.max_radius;

  TetMesh tets;
  {
    StageTimer t(log, "tetrahedralize");
    tets = opt.tet_file.empty() ? tetrahedralize(rest, opt.tets, log) : read_medit_tets(opt.tet_file);
  }
  log.detail(std::to_string(tets.tets.size()) + " tets, " + std::to_string(tets.vertices.size()) + " vertices");

  StageTimer harmonic_timer(log, "harmonic");
  const HarmonicMap f(tets, rest, log);
  std::vector<std::vector<Eigen::Vector3d>> deformed;
  for (const PoseInput& input : poses) deformed.push_back(f.deform(input.mesh));
  harmonic_timer.stop();

  std::vector<std::unique_ptr<MeshQuery>> queries;
  queries.push_back(std::make_unique<MeshQuery>(rest));
  for (const PoseInput& input : poses) queries.push_back(std::make_unique<MeshQuery>(input.mesh));
  std::vector<const TriMesh*> meshes{&rest};
  for (const PoseInput& input : poses) meshes.push_back(&input.mesh);

  // Open meshes: a solid also ends across its holes, where the mesh has no triangles. Every
  // pose, the rest included, gets its own field at the spheres' voxel size, so one rule sets
  // every radius.
  const bool open_solid = !find_defects(rest).watertight();
  std::vector<DenseField> hole_fields;
  if (open_solid) {
    StageTimer t(log, "open-fields");
    SdfOptions o;
    o.voxel_size = spheres.voxel_size > 0 ? spheres.voxel_size : rest.diagonal() / 128;
    for (const TriMesh* mesh : meshes) hole_fields.push_back(build_sdf(*mesh, o).field);
  }
  std::vector<PoseSolid> solids;
  for (size_t i = 0; i < meshes.size(); ++i)
    solids.push_back({queries[i].get(), open_solid ? &hole_fields[i] : nullptr, proxy.max_radius});

  // The rest spheres must fit the rest mesh; if they do not, the inputs do not belong together.
  {
    const double slack = 1e-4 * rest.diagonal();
    size_t misfits = 0;
    for (const auto& s : spheres.spheres)
      if (!queries[0]->inside(s.center) || queries[0]->distance(s.center) < s.radius - slack) ++misfits;
    if (misfits > 0)
      fail_input(rest_source, std::to_string(misfits) + " of " + std::to_string(spheres.spheres.size()) +
                                  " spheres do not fit inside this rest mesh (packed from another mesh, or are --rest "
                                  "and a --pose swapped?)");
  }
  proxy.poses.push_back({stem_of(rest_source), rest_source, {}, {}});
  for (const PoseInput& input : poses) proxy.poses.push_back({input.name, input.source, {}, {}});
  std::vector<Eigen::Vector3d> rest_centers;  // for the blend sites

  // Appends rest spheres to every pose: centers through f, and in every pose (the rest too)
  // the radius by the one rule of PoseSolid.
  std::vector<std::array<size_t, 3>> zero_radius(proxy.poses.size(), {0, 0, 0});  // by cause
  auto add_spheres = [&](const SphereSet& rest_spheres) {
    const size_t first = rest_centers.size(), n = rest_spheres.size();
    for (auto& pose : proxy.poses) pose.spheres.resize(first + n);
    std::vector<std::vector<char>> cause(proxy.poses.size(), std::vector<char>(n, 0));
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 8), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t s = r.begin(); s != r.end(); ++s) {
        const Eigen::Vector3d& c = rest_spheres[s].center;
        const TetLocator::Location at = f.locator().locate(c);
        for (size_t i = 0; i < proxy.poses.size(); ++i) {
          Sphere& sphere = proxy.poses[i].spheres[first + s];
          sphere.center = i == 0 ? c : f.map(c, at, deformed[i - 1]);
          const PoseSolid::Radius radius = solids[i].radius(sphere.center);
          sphere.radius = radius.value;
          cause[i][s] = char(radius.zero);
        }
      }
    });
    for (const auto& s : rest_spheres) rest_centers.push_back(s.center);
    for (size_t i = 0; i < proxy.poses.size(); ++i)
      for (size_t s = 0; s < n; ++s) {
        if (cause[i][s] == char(PoseSolid::Zero::none)) continue;
        ++zero_radius[i][size_t(cause[i][s]) - 1];
        if (cause[i][s] == char(PoseSolid::Zero::outside)) proxy.poses[i].outside.push_back(int(first + s));
      }
  };
  {
    StageTimer t(log, "map");
    add_spheres(spheres.spheres);
  }

  auto pose_errors = [&] {
    nlohmann::json out = nlohmann::json::array();
    for (size_t i = 0; i < proxy.poses.size(); ++i)
      out.push_back(vertex_error(*meshes[i], proxy.poses[i].spheres).to_json());
    return out;
  };
  const size_t mapped_count = rest_centers.size();
  nlohmann::json errors_before_fill;
  nlohmann::json fill_report = nullptr;

  if (opt.fill_gaps) {
    StageTimer t(log, "fill-gaps");
    errors_before_fill = pose_errors();
    SdfOptions field_options;
    field_options.voxel_size = spheres.voxel_size > 0 ? spheres.voxel_size : rest.diagonal() / 128;
    const double min_radius = opt.fill_min_radius > 0 ? opt.fill_min_radius : 0.75 * field_options.voxel_size;
    double target = opt.fill_tolerance.set() ? opt.fill_tolerance.length(rest.diagonal()) : spheres.tolerance;
    if (!(target > 0)) target = errors_before_fill[0]["max"].get<double>();
    nlohmann::json per_pose = nlohmann::json::array();
    for (size_t i = 0; i < poses.size(); ++i) {
      // The pose's own interior, minus what its spheres already cover.
      SdfResult sdf = build_sdf(poses[i].mesh, field_options);
      clear_covered(sdf.field, proxy.poses[i + 1].spheres);
      PackOptions pack;
      pack.min_radius = min_radius;
      pack.max_radius = proxy.max_radius;
      pack.field_bounds_radius = open_solid;
      PackResult found = pack_spheres(sdf.field, pack, queries[i + 1].get());
      // The fewest of them that bring this pose within the target (as sphere-pack --tolerance).
      ToleranceResult enough = fewest_spheres_within(poses[i].mesh, found.spheres, target, proxy.poses[i + 1].spheres);
      if (!enough.met) {
        // Out of reach at this voxel size: keep only the spheres that lower the max error.
        const ToleranceResult best = fewest_spheres_within(poses[i].mesh, found.spheres, enough.max_error * (1 + 1e-9),
                                                           proxy.poses[i + 1].spheres);
        enough.count = best.count;
      }
      size_t keep = enough.count;
      if (opt.fill_max_per_pose > 0) keep = std::min(keep, opt.fill_max_per_pose);
      found.spheres.resize(keep);
      if (!enough.met)
        log.warn(poses[i].source + ": gap filling reaches max error " + num(enough.max_error) +
                 ", not the target " + num(target) + " (try a finer sdf-build --resolution)");

      // Back to the rest pose through the inverse map: barycentric in the deformed tets.
      TetMesh posed = tets;
      posed.vertices = deformed[i];
      const TetLocator inverse(posed);
      SphereSet back;
      size_t lost = 0;
      for (const Sphere& s : found.spheres) {
        const TetLocator::Location at = inverse.locate(s.center);
        Eigen::Vector3d x = Eigen::Vector3d::Zero();
        for (int k = 0; k < 4; ++k) x += at.weights[k] * tets.vertices[size_t(tets.tets[size_t(at.tet)][k])];
        if (at.outside > 0 || !queries[0]->inside(x)) {
          ++lost;
          continue;
        }
        back.push_back({x, std::min(proxy.max_radius, queries[0]->distance(x))});
      }
      add_spheres(back);
      per_pose.push_back({{"pose", poses[i].name}, {"added", back.size()}, {"lost_outside_rest", lost},
                          {"target_met", enough.met}, {"max_error_reached", enough.max_error}});
      log.detail(poses[i].name + ": " + std::to_string(back.size()) + " spheres fill its gaps");
    }
    fill_report = {{"min_radius", min_radius}, {"target", target}, {"poses", per_pose}, {"spheres_before", mapped_count},
                   {"spheres_after", rest_centers.size()}, {"errors_before", errors_before_fill}};
  }

  // Blend sites: the nearest rest tet vertex of each sphere (the paper's local blend).
  const size_t n = rest_centers.size();
  std::vector<int> nearest(n, -1);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 16), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t s = r.begin(); s != r.end(); ++s) {
      double best = std::numeric_limits<double>::infinity();
      for (size_t v = 0; v < tets.vertices.size(); ++v) {
        const double d = (tets.vertices[v] - rest_centers[s]).squaredNorm();
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

  for (size_t i = 0; i < proxy.poses.size(); ++i) {
    const auto& [outside, holes, other] = zero_radius[i];
    if (outside > 0)
      log.warn(proxy.poses[i].source + ": " + std::to_string(outside) +
               " sphere centers land outside this pose; those spheres get radius 0 in it");
    if (holes + other > 0)
      log.warn(proxy.poses[i].source + ": " + std::to_string(holes + other) + " spheres get radius 0 in this pose (" +
               std::to_string(holes) + " bounded by its holes, " + std::to_string(other) + " on its surface)");
  }

  const nlohmann::json errors = pose_errors();
  nlohmann::json pose_reports = nlohmann::json::array();
  for (size_t i = 0; i < proxy.poses.size(); ++i)
    pose_reports.push_back({{"name", proxy.poses[i].name},
                            {"source", proxy.poses[i].source},
                            {"outside", proxy.poses[i].outside},
                            {"zero_radius",
                             {{"total", zero_radius[i][0] + zero_radius[i][1] + zero_radius[i][2]},
                              {"center_outside", zero_radius[i][0]},
                              {"hole_bound", zero_radius[i][1]},
                              {"other", zero_radius[i][2]}}},
                            {"error", errors[i]}});
  size_t outside_points = 0;
  for (const auto& c : rest_centers) outside_points += f.locator().locate(c).outside > 0;
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
                   {"open_solid", open_solid},
                   {"radius_source", open_solid ? "exact distance to each pose's mesh, bounded across its holes by "
                                                  "that pose's own field"
                                                : "exact distance to each pose's mesh"},
                   {"sphere_count", n},
                   {"site_count", proxy.sites.size()},
                   {"poses", pose_reports},
                   {"fill_gaps", fill_report}};
  return result;
}

}  // namespace spx
