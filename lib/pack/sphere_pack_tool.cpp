#include "pack/sphere_pack_tool.hpp"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <cmath>
#include <memory>
#include <sstream>
#include <vector>

#include "core/error.hpp"
#include "core/format.hpp"
#include "core/subject.hpp"
#include "mesh/components.hpp"
#include "mesh/normals.hpp"
#include "mesh/union_distance.hpp"
#include "io/spheres_file.hpp"
#include "io/vdb_io.hpp"

namespace spx {

namespace {

// --mesh must be the mesh the field was built from: with a pose or another model, centers come
// from one shape and radii from another. Its bounds must match those sdf-build recorded, and
// the vertices of its solid's surface must lie on the field's zero level (distance is
// 1-Lipschitz: a voxel's |value| less its offset to the vertex bounds the vertex's own distance
// to the field's surface). Walls inside the solid, where parts overlap, are not on it.
void check_mesh_matches_field(const MeshQuery& query, const std::string& mesh_path, const LoadedSdf& sdf,
                              const std::string& sdf_path) {
  const TriMesh& mesh = query.mesh();
  const GridShape& g = sdf.field.shape;
  const double h = g.voxel_size;
  const auto source = sdf.metadata.find("spx_source_mesh");
  const std::string built_from = source == sdf.metadata.end() ? "" : " (built from " + source->second + ")";
  auto mismatch = [&](const std::string& how) {
    fail_input(mesh_path, "is not the mesh " + sdf_path + built_from + " was built from: " + how);
  };
  const std::vector<Eigen::Vector3d>& on_surface = query.surface().vertices;
  size_t off_surface = 0;
  for (const Eigen::Vector3d& p : on_surface) {
    const Eigen::Vector3i v = ((p / h).array().round().cast<int>() - g.origin.array()).matrix();
    if ((v.array() < 0).any() || (v.array() >= g.dims.array()).any()) {
      ++off_surface;
      continue;
    }
    const double value = std::abs(sdf.field.values[g.index(v.x(), v.y(), v.z())]);
    off_surface += value - (g.world(v.x(), v.y(), v.z()) - p).norm() > 2 * h;
  }
  if (off_surface > on_surface.size() / 100)
    mismatch(std::to_string(off_surface) + " of its solid's " + std::to_string(on_surface.size()) +
             " surface vertices lie more than 2 voxels off the field's surface (a pose, or another model?)");
  const auto recorded = sdf.metadata.find("spx_source_bounds");
  if (recorded != sdf.metadata.end()) {
    std::istringstream in(recorded->second);
    Eigen::Vector3d lo, hi;
    if (in >> lo.x() >> lo.y() >> lo.z() >> hi.x() >> hi.y() >> hi.z()) {
      const Eigen::AlignedBox3d b = mesh.bounds();
      const double off = std::max((b.min() - lo).cwiseAbs().maxCoeff(), (b.max() - hi).cwiseAbs().maxCoeff());
      if (off > 0.25 * h)
        mismatch("its bounding box differs from the field's mesh by " + num(off) + " (" + num(off / h) + " voxels)");
    }
  }
}

}  // namespace

namespace {

void warn_if_tolerance_is_huge(const Tolerance& tolerance, double diagonal, Log& log) {
  const double target = tolerance.length(diagonal);
  if (target >= 0.1 * diagonal)
    log.warn("tolerance " + num(tolerance.value) + (tolerance.percent ? "%" : "") + " is " +
             num(100 * target / diagonal) + "% of the mesh's bounding-box diagonal (" + num(diagonal) + ")" +
             (tolerance.percent ? "" : "; did you mean " + num(tolerance.value) + "%?"));
}

// The report's "tolerance": what was asked, whether the written spheres meet it, what decided.
json tolerance_report(const Tolerance& tolerance, double target, bool is_default, bool met, double max_error,
                      size_t spheres, const std::string& limited_by) {
  return {{"target", target}, {"given", tolerance.value}, {"percent", tolerance.percent}, {"default", is_default},
          {"met", met},       {"max_error", max_error},    {"spheres", spheres},             {"limited_by", limited_by}};
}

// The end of the tool's last line: the error measured, and what ended the selection (with the
// tolerance it met, which a default leaves unsaid otherwise).
std::string outcome_wording(const PackStats& stats, const Tolerance& in_force, double tolerance, double diagonal) {
  std::string out;
  if (stats.max_error >= 0 && diagonal > 0)
    out += ", max error " + num(stats.max_error) + " (" + num(100 * stats.max_error / diagonal) + "% of the diagonal)";
  out += stats.stop_is_limit ? "; limited by " + stats.stop_reason : "; " + stats.stop_reason;
  if (stats.met_tolerance)
    out += " " + (in_force.percent ? num(in_force.value) + "% (" + num(tolerance) + ")" : num(tolerance));
  return out;
}

// The paper's greedy packing; with a tolerance (`asked`, opt.tolerance as a length), the
// shortest prefix of the whole sequence that meets it.
SphereSet select_greedy(const LoadedSdf& sdf, const std::string& input, const MeshQuery* mesh,
                        const SpherePackOptions& opt, const Tolerance& asked, PackStats& stats, Log& log,
                        json& report) {
  PackOptions options = opt.pack;
  const double target = opt.tolerance;
  if (target > 0) {
    // Pack the whole greedy sequence down to a fine floor, then keep the shortest prefix.
    options.max_spheres = 0;
    if (!(opt.pack.min_radius > 0)) options.min_radius = sdf.field.shape.voxel_size;
  }
  PackResult packed;
  {
    StageTimer t(log, "pack");
    packed = about_file(input, [&] { return pack_spheres(sdf.field, options, mesh, log); });
  }
  if (packed.spheres.empty())
    fail_input(input, "no sphere fits: the largest interior distance is below the min radius " +
                          num(packed.stats.min_radius));
  if (target > 0) {
    StageTimer t(log, "tolerance");
    const ToleranceResult tr = fewest_spheres_within(mesh->surface(), packed.spheres, target);
    size_t keep = tr.count;
    std::string limit = tr.met ? "met the tolerance" : "the packing sequence ended before the tolerance was met";
    if (opt.pack.max_spheres > 0 && opt.pack.max_spheres < keep) {
      keep = opt.pack.max_spheres;
      limit = "max_spheres (tighter than the tolerance)";
      packed.stats.stop_is_limit = true;
    }
    packed.spheres.resize(keep);
    packed.stats.stop_reason = limit;  // the prefix, not the packing that made the sequence, decides
    const double reached = tr.max_error_by_count.empty() ? 0 : tr.max_error_by_count[keep - 1];
    packed.stats.max_error = reached;
    packed.stats.met_tolerance = tr.met && !packed.stats.stop_is_limit;
    if (!tr.met) {
      char msg[400];
      std::snprintf(msg, sizeof msg,
                    "tolerance %.4g not met: max error %.4g with all %zu spheres down to radius %.4g at voxel size "
                    "%.4g; use a finer resolution or a smaller min radius",
                    target, reached, keep, options.min_radius, sdf.field.shape.voxel_size);
      log.warn(msg);
    }
    report["tolerance"] = tolerance_report(asked, target, false, tr.met, reached, keep, limit);
    report["tolerance"]["sequence_length"] = tr.max_error_by_count.size();
  }
  stats = packed.stats;
  return packed.spheres;
}

// Cells along the longest side of the field's grid.
double field_resolution(const GridShape& g) { return double(g.dims.maxCoeff()); }

// Thin parts with no voxel centre deep enough inside: a sample's least gap to the candidates
// shrinks with the voxel, so the resolution that reaches it scales with gap / target (with a
// quarter to spare, in steps of 16 cells).
double resolution_reaching(double resolution, double gap, double target) {
  constexpr double kSpare = 1.25, kStep = 16;
  return std::ceil(resolution * std::max(1.0, gap / target) * kSpare / kStep) * kStep;
}

// The parts (the input mesh's edge-connected pieces) whose vertices on the solid's surface no
// candidate reaches within `target`: each named by its triangles and centre, with how many
// vertices, the farthest, how many of them have no solid beside them (an open or inward-facing
// part enclosing nothing there: no sphere touches them at any resolution), whether any candidate
// lies in its box at all, whether it is flat, and (given the field's `resolution`, where the
// field limits the candidates, not flat) the resolution that would reach those with the solid
// beside them. The surface's pieces of split triangles are on vertices of their own: each belongs
// to the part of the triangle it is cut from.
json parts_out_of_reach(const MeshQuery& query, const SphereSet& candidates, double target, double resolution) {
  const TriMesh& input = query.mesh();
  const TriMesh& surface = query.surface();
  const std::vector<double> gap = union_signed_distance(surface.vertices, candidates);
  const Components parts = edge_components(input);
  const SolidBoundary& boundary = query.boundary();
  std::vector<int> part_of(surface.vertices.size(), -1);  // each surface vertex's part
  for (size_t t = 0; t < surface.triangles.size(); ++t) {
    const int part = parts.of_triangle[boundary.whole() ? t : size_t(boundary.source[t])];
    for (int k = 0; k < 3; ++k) part_of[size_t(surface.triangles[t][k])] = part;
  }
  const std::vector<PieceShape> shapes = piece_shapes(input, parts);
  const std::vector<Eigen::Vector3d> normals = angle_weighted_normals(surface, face_normals(surface));
  std::vector<size_t> far(parts.count, 0), bare(parts.count, 0);
  std::vector<double> farthest(parts.count, 0), farthest_beside(parts.count, 0);
  for (size_t v = 0; v < part_of.size(); ++v) {
    if (part_of[v] < 0 || !(gap[v] > target)) continue;
    const size_t p = size_t(part_of[v]);
    ++far[p];
    farthest[p] = std::max(farthest[p], gap[v]);
    if (query.solid_beside(surface.vertices[v], normals[v]))
      farthest_beside[p] = std::max(farthest_beside[p], gap[v]);
    else
      ++bare[p];
  }
  json out = json::array();
  for (size_t p = 0; p < parts.count; ++p) {
    if (far[p] == 0) continue;
    bool holds_one = false;
    for (const Sphere& s : candidates) holds_one = holds_one || shapes[p].box.contains(s.center);
    const bool flat = shapes[p].flat;
    json part = {{"part", piece_name("part", p + 1, parts.count, shapes[p])},
                 {"vertices_out_of_reach", far[p]},
                 {"vertices_with_no_solid_beside", bare[p]},
                 {"farthest", farthest[p]},
                 {"holds_a_candidate", holds_one},
                 {"flat", flat}};
    if (resolution > 0 && !flat && bare[p] < far[p])
      part["resolution_needed"] = resolution_reaching(resolution, farthest_beside[p], target);
    out.push_back(part);
  }
  return out;
}

// The vertices out of reach with no solid beside them, said once.
std::string vertices_with_no_solid(size_t bare) {
  return std::to_string(bare) + (bare == 1 ? " vertex has" : " vertices have") + " no solid beside " +
         (bare == 1 ? "it" : "them") + " (" + kNoSolidBeside + "), which no sphere touches at any resolution";
}

// The parts out of reach warned about, the first few by name.
void warn_parts_out_of_reach(const json& parts, Log& log) {
  constexpr size_t kNamed = 5;
  for (size_t n = 0; n < parts.size() && n < kNamed; ++n) {
    const json& part = parts[n];
    const size_t far = part["vertices_out_of_reach"].get<size_t>();
    const size_t bare = part["vertices_with_no_solid_beside"].get<size_t>();
    std::string advice;
    if (part["flat"].get<bool>()) {
      advice = "; it is flat (every vertex in one plane) and encloses no volume at any resolution";
    } else {
      if (bare == far)
        advice = "; no solid lies beside them (see above), and no sphere touches them at any resolution";
      else if (bare > 0)
        advice = "; " + std::to_string(bare) + " of them have no solid beside them (see above)";
      if (part.contains("resolution_needed"))
        advice += std::string(part["holds_a_candidate"].get<bool>() ? "" : "; it holds no inscribed sphere at this resolution") +
                  "; about " + num(part["resolution_needed"].get<double>()) + " cells would reach " +
                  (bare > 0 ? "the others" : "them");
    }
    log.warn(part["part"].get<std::string>() + ": " + std::to_string(far) + " of its vertices out of reach" + advice);
  }
  if (parts.size() > kNamed) log.warn("and " + std::to_string(parts.size() - kNamed) + " more parts (the report lists them)");
}

}  // namespace

namespace {

// A tolerance out of reach: how many samples, how far, what would reach them (a finer field,
// or nothing where the field does not limit the candidates, or for flat parts and vertices with no
// solid beside them), and the parts they lie on; in the log and the report. Returns whether no
// resolution is named for any of them.
bool warn_out_of_reach(const LoadedSdf& sdf, const MeshQuery& mesh, const SpherePackOptions& opt,
                       const CoverSelection& sel, Log& log, json& report) {
  const CoverResult& cover = sel.cover;
  const double target = sel.target;
  const std::string out_of_reach = std::to_string(cover.uncoverable()) +
                                   " surface samples are farther than it from every inscribed sphere (the farthest " +
                                   num(cover.least_reachable) + ", as near as " +
                                   (sel.out_of_reach_added == 0 ? std::string("the cover's spheres bring")
                                    : sel.out_of_reach_added == 1 ? "1 more sphere brings"
                                                                  : std::to_string(sel.out_of_reach_added) + " more spheres bring") +
                                   " them)";
  // With every sample's own candidate only a sharp tip or edge under the least radius (or a
  // tolerance under float rounding) is out of reach, and no field helps: no resolution named.
  const bool field_limits = sel.limited_by != Limit::reach;
  const double resolution = field_limits ? field_resolution(sdf.field.shape) : 0;
  const json parts = parts_out_of_reach(mesh, sel.offered, target, resolution);
  // Flat parts and vertices with no solid beside them hold no sphere at any resolution: the
  // resolution named is the others' (the farthest sample would name a field that reaches no more).
  size_t flat = 0, bare = 0, others = 0;  // flat parts; vertices with no solid beside them, and the rest
  for (const json& part : parts) {
    flat += part["flat"].get<bool>();
    if (part["flat"].get<bool>()) continue;
    bare += part["vertices_with_no_solid_beside"].get<size_t>();
    others += part["vertices_out_of_reach"].get<size_t>() - part["vertices_with_no_solid_beside"].get<size_t>();
  }
  const std::string flat_parts = std::to_string(flat) + (flat == 1 ? " part is" : " parts are") +
                                 " flat (every vertex in one plane) and " + (flat == 1 ? "encloses" : "enclose") +
                                 " no volume";
  const std::string unreachable = flat > 0 && bare > 0 ? flat_parts + "; " + vertices_with_no_solid(bare)
                                  : flat > 0           ? flat_parts
                                                       : vertices_with_no_solid(bare);
  const bool none_by_field = !parts.empty() && others == 0;
  if (none_by_field && bare == 0) {
    log.warn("tolerance " + num(target) + " not met: " + out_of_reach +
             "; the parts whose vertices are out of reach are flat, and no resolution reaches them");
  } else if (none_by_field) {
    log.warn("tolerance " + num(target) + " not met: " + out_of_reach + "; " + unreachable +
             "; no resolution is named for them");
  } else if (field_limits) {
    const bool some_unreachable = flat + bare > 0;
    double needed = resolution_reaching(resolution, cover.least_reachable, target);
    if (some_unreachable) needed = resolution;
    for (const json& part : parts)
      if (part.contains("resolution_needed")) needed = std::max(needed, part["resolution_needed"].get<double>());
    log.warn("tolerance " + num(target) + " not met at this field's resolution (" + num(resolution) + " cells, voxel " +
             num(sdf.field.shape.voxel_size) + "): " + out_of_reach +
             (some_unreachable ? "; " + unreachable : std::string()) + "; a field of about " +
             num(needed) + " cells (sdf-build --resolution " + num(needed) + ") would reach " +
             (some_unreachable ? "the others" : "them"));
    report["resolution_needed"] = needed;
  } else {
    const std::string least = opt.pack.min_radius > 0 ? " of at least the least radius (" + num(opt.pack.min_radius) + ")"
                                                      : std::string();
    log.warn("tolerance " + num(target) + " not met: " + out_of_reach + "; " + std::to_string(sel.unreached_samples) +
             " samples have no inscribed sphere" + least + " that reaches them" +
             (flat + bare > 0 ? "; " + unreachable : std::string()));
  }
  warn_parts_out_of_reach(parts, log);
  report["parts_out_of_reach"] = parts;
  return none_by_field;
}

// select_by_cover, with its warnings and report; `in_force` is the tolerance opt.tolerance came
// from (the default where `is_default`).
SphereSet select_by_cover_reported(const LoadedSdf& sdf, const MeshQuery& mesh, const SpherePackOptions& opt,
                                   const Tolerance& in_force, bool is_default, PackStats& stats, SphereSet& pool,
                                   Log& log, json& report) {
  const CoverSelection sel = select_by_cover(sdf.field, mesh, opt, log);
  const SphereSet& spheres = sel.spheres;
  const CoverResult& cover = sel.cover;
  const double target = sel.target;
  pool = sel.pool;
  // The error as proxy-eval measures it, at the vertices.
  const ErrorStats error = vertex_error(mesh.surface(), spheres);
  const bool met = !(target > 0) || (cover.uncoverable() == 0 && error.max <= target * (1 + 1e-9));
  const bool flat = target > 0 && cover.uncoverable() > 0 && warn_out_of_reach(sdf, mesh, opt, sel, log, report);
  const Limit limited_by = flat ? Limit::flat
                           : sel.limited_by == Limit::tolerance && is_default ? Limit::default_tolerance
                                                                               : sel.limited_by;
  const std::string limit = limit_wording(limited_by);
  stats.radius_source = "mesh";
  stats.stop_reason = limit;
  stats.max_error = error.max;
  stats.met_tolerance = met_tolerance(limited_by);
  stats.stop_is_limit = !stats.met_tolerance;
  stats.min_radius = opt.pack.min_radius;
  stats.max_radius = opt.pack.max_radius;
  report["cover"] = {{"method", "inscribed candidates at near-medial voxels grown to the largest inscribed sphere "
                                "containing them, and at every surface sample the largest inscribed sphere tangent there; "
                                "set cover reduced, then greedy, shrunk and searched by row weighting; "
                                "spare budget and swaps toward the least total error; centres refined off the grid"},
                     {"candidates", sel.candidates},
                     {"candidates_from", {{"voxels", sel.voxel_candidates},
                                          {"samples", sel.candidates - sel.voxel_candidates},
                                          {"samples_needing_a_touching_ball", sel.touching_samples},
                                          {"samples_unreached", sel.unreached_samples}}},
                     {"chosen_from", {{"voxels", spheres.size() - sel.chosen_tangent - sel.chosen_refined},
                                      {"samples", sel.chosen_tangent},
                                      {"refined", sel.chosen_refined}}},
                     {"polished", sel.polished},
                     {"samples", sel.samples},
                     {"samples_covered", sel.cover_samples},
                     {"vertices_joined", sel.spaced_joined},
                     {"vertex_spacing", sel.vertex_spacing},
                     {"vertices", mesh.surface().vertices.size()},
                     {"internal_walls", mesh.internal_walls()},
                     {"split_triangles", mesh.split_triangles()},
                     {"delta", cover.delta},
                     {"least_max_delta", cover.least_max_delta > 0 ? json(cover.least_max_delta) : json(nullptr)},
                     {"lower_bound", cover.lower_bound},
                     {"uncoverable_samples", cover.uncoverable()},
                     {"spheres_for_uncoverable_samples", sel.out_of_reach_added},
                     {"least_reachable_delta", cover.least_reachable},
                     {"covers_solved", cover.evaluations},
                     {"max_error", error.max},
                     {"median_error", error.median},
                     {"limited_by", limit},
                     {"cache", sel.cache ? json{{"file", sel.cache->file},
                                                {"voxel_candidates_read", sel.cache->voxels_read},
                                                {"sample_balls_read", sel.cache->balls_read},
                                                {"sample_balls_made", sel.cache->balls_made}}
                                         : json(nullptr)}};
  report["cache_folder"] = cache_trim_json(sel.cache ? std::optional<CacheTrim>(sel.cache->folder) : std::nullopt);
  if (target > 0)
    report["tolerance"] = tolerance_report(in_force, target, is_default, met, error.max, spheres.size(), limit);
  return spheres;
}

}  // namespace

namespace {

// --mesh, or else the mesh sdf-build recorded in the field (the cover method and a tolerance
// need one); "" where neither is needed nor known.
std::string mesh_for_field(const std::string& given, const LoadedSdf& sdf, const std::string& input,
                           const SpherePackOptions& opt, bool tolerance_asked, Log& log) {
  const bool needed = opt.method == PackMethod::cover || tolerance_asked;
  if (!given.empty() || !needed) return given;
  const std::string why = opt.method == PackMethod::cover
                              ? "is needed by the cover method (inscribed spheres take exact distances to it)"
                              : "is needed by --tolerance (the error is measured at its vertices)";
  const auto recorded = sdf.metadata.find("spx_source_mesh");
  if (recorded == sdf.metadata.end())
    fail_option("mesh", why + ", and " + input + " does not record the mesh it was built from; pass it with --mesh");
  // Where the field lies, the mesh as sdf-build saw it from there: it holds from any working
  // folder and when both are moved together. Then the path as given to sdf-build (fields written
  // before the first was recorded, or a mesh left where it was when the field moved).
  std::vector<std::string> tried;
  const auto from_field = sdf.metadata.find("spx_source_mesh_from_field");
  if (from_field != sdf.metadata.end() && !from_field->second.empty()) {
    const std::filesystem::path beside = std::filesystem::path(input).parent_path() / from_field->second;
    tried.push_back(beside.lexically_normal().generic_string());
  }
  if (tried.empty() || tried.front() != recorded->second) tried.push_back(recorded->second);
  for (std::string path : tried) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec)) continue;
    // The same file as given to sdf-build (an absolute path, say) is named as it was given.
    if (path != recorded->second && std::filesystem::equivalent(path, recorded->second, ec)) path = recorded->second;
    log.info("using the mesh " + input + " was built from: " + path + " (--mesh not given)");
    return path;
  }
  fail_option("mesh", why + "; " + input + " was built from " + recorded->second + ", which is not there from this folder" +
                          (tried.size() > 1 ? " nor from the field's (" + tried.front() + ")" : "") + "; pass it with --mesh");
}

}  // namespace

void sphere_pack_files(const std::string& input, const std::string& given_mesh, const std::string& output,
                       const SpherePackOptions& user, const Tolerance& asked, Log& log, json& report) {
  check_radius_limits(user.pack, 0);
  SpherePackOptions opt = user;
  // The cover method with no size asked gives the fewest spheres within the default tolerance.
  const bool is_default = opt.method == PackMethod::cover && !asked.set() && opt.pack.max_spheres == 0;
  const Tolerance in_force = is_default ? Tolerance{kDefaultTolerancePercent, true} : asked;
  LoadedSdf sdf;
  {
    StageTimer t(log, "load");
    sdf = read_sdf_vdb(input);
  }
  const std::string mesh_path = mesh_for_field(given_mesh, sdf, input, opt, asked.set(), log);
  auto open = sdf.metadata.find("spx_open_solid");
  opt.pack.field_bounds_radius = open != sdf.metadata.end() && open->second == "yes";
  if (opt.pack.field_bounds_radius) log.detail("open mesh: radii are also bounded by the field across its holes");
  std::unique_ptr<MeshQuery> mesh;
  if (!mesh_path.empty()) {
    StageTimer t(log, "mesh");
    const LoadedMesh loaded = load_mesh(mesh_path);
    mesh = about_file(mesh_path, [&] { return std::make_unique<MeshQuery>(loaded.mesh); });
    check_mesh_matches_field(*mesh, mesh_path, sdf, input);
    if (asked.set()) warn_if_tolerance_is_huge(asked, loaded.mesh.diagonal(), log);
    // The tolerance becomes a length here, once, and travels down as one.
    if (in_force.set()) opt.tolerance = in_force.length(loaded.mesh.diagonal());
  } else {
    log.detail("no mesh: radii come from the field (voxel accuracy)");
  }
  PackStats stats;
  SphereSet pool;
  const SphereSet spheres =
      opt.method == PackMethod::greedy
          ? select_greedy(sdf, input, mesh.get(), opt, asked, stats, log, report)
          : about_file(input, [&] {
              return select_by_cover_reported(sdf, *mesh, opt, in_force, is_default, stats, pool, log, report);
            });
  stats.set_radius_range(spheres);
  SpheresFile file;
  file.spheres = spheres;
  file.candidates = pool;
  file.voxel_size = sdf.field.shape.voxel_size;
  file.min_radius = stats.min_radius > 0 ? stats.min_radius : stats.smallest;
  file.min_radius_asked = opt.pack.min_radius;
  file.max_radius = stats.max_radius;
  file.radius_source = stats.radius_source;
  file.tolerance = opt.tolerance;
  file.max_spheres = opt.pack.max_spheres;
  if (opt.method == PackMethod::cover) file.sampling = {opt.area_samples, opt.seed, !opt.spaced_vertices};
  file.sdf = input;
  file.mesh = mesh_path;
  write_json_atomic(output, spheres_to_json(file));

  std::vector<double> radii;
  for (const Sphere& s : spheres) radii.push_back(s.radius);
  report["tiny_spheres"] = mesh ? warn_tiny_spheres(radii, mesh->surface().diagonal(), "", log) : json(nullptr);
  log.info(output + ": " + counted(spheres.size(), "sphere") + ", radii " + num(stats.smallest) + ".." + num(stats.largest) +
           outcome_wording(stats, in_force, opt.tolerance, mesh ? mesh->surface().diagonal() : 0));
  report["input"] = input;
  report["output"] = output;
  report["method"] = opt.method == PackMethod::cover ? "cover" : "greedy";
  report["sphere_count"] = spheres.size();
  report["pack"] = stats.to_json();
  report.emplace("cache_folder", nullptr);  // greedy packing keeps no cache
}

}  // namespace spx
