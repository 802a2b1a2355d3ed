#include "posemap/tet_mesh.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <limits>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Labeled_mesh_domain_3.h>
#include <CGAL/Mesh_complex_3_in_triangulation_3.h>
#include <CGAL/Mesh_criteria_3.h>
#include <CGAL/Mesh_triangulation_3.h>
#include <CGAL/make_mesh_3.h>
#include <CGAL/version.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <optional>
#include <sstream>

#include "core/atomic_file.hpp"
#include "core/cache_folder.hpp"
#include "core/error.hpp"
#include "core/hash.hpp"
#include "core/format.hpp"
#include "mesh/components.hpp"
#include "mesh/deforming_query.hpp"
#include "mesh/winding_number.hpp"

namespace spx {
namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Domain = CGAL::Labeled_mesh_domain_3<K>;
using Tr = CGAL::Mesh_triangulation_3<Domain, CGAL::Default, CGAL::Sequential_tag>::type;
using C3t3 = CGAL::Mesh_complex_3_in_triangulation_3<Tr>;
using Criteria = CGAL::Mesh_criteria_3<Tr>;

// Mesh_3 finds its first surface points by shooting rays from one centre, so a body the rays
// miss (the second animal of an OBJ holding two, a car's wheel) gets no tets at all, and one
// that a single ray hits is not refined either. This domain adds crossings of the level set
// spread over each body's own triangles.
class SeededDomain : public Domain {
 public:
  struct Body {
    std::vector<K::Segment_3> seeds;  // short segments across its triangles
  };
  SeededDomain(Domain domain, std::vector<Body> bodies) : Domain(std::move(domain)), bodies_(std::move(bodies)) {}

  struct Construct_initial_points {
    const SeededDomain& d;
    template <class Out>
    Out operator()(Out out, int n = 12) const {
      std::vector<std::pair<K::Point_3, Index>> points;
      d.Domain::construct_initial_points_object()(std::back_inserter(points), n);
      // One body: the rays find it (and the tets stay as they always were). Several: seed
      // them all, since a body that only one ray hit would not be refined either.
      size_t solids = 0;
      for (const Body& body : d.bodies_) solids += !body.seeds.empty();
      if (solids > 1)
        for (const Body& body : d.bodies_)
          for (const K::Segment_3& s : body.seeds)
            if (const auto patch = d.do_intersect_surface_object()(s))
              points.emplace_back(std::get<0>(d.construct_intersection_object()(s)),
                                  d.index_from_surface_patch_index(*patch));
      return std::copy(points.begin(), points.end(), out);
    }
  };
  Construct_initial_points construct_initial_points_object() const { return {*this}; }

 private:
  std::vector<Body> bodies_;
};

// Up to 48 segments across triangles of each part where the level set {winding = 1/2}
// crosses: parts with none (open flaps of a soup) bound no solid of their own.
std::vector<SeededDomain::Body> seed_bodies(const TriMesh& surface, const Components& parts,
                                           const std::function<double(const K::Point_3&)>& level) {
  std::vector<std::vector<int>> triangles(parts.count);
  for (size_t t = 0; t < surface.triangles.size(); ++t) triangles[size_t(parts.of_triangle[t])].push_back(int(t));
  std::vector<SeededDomain::Body> bodies(parts.count);
  auto point = [](const Eigen::Vector3d& p) { return K::Point_3(p.x(), p.y(), p.z()); };
  for (size_t b = 0; b < parts.count; ++b) {
    const std::vector<int>& tris = triangles[b];
    const size_t tries = std::min<size_t>(tris.size(), 128), stride = std::max<size_t>(1, tris.size() / tries);
    for (size_t k = 0; k < tris.size() && bodies[b].seeds.size() < 48; k += stride) {
      const Eigen::Vector3i& f = surface.triangles[size_t(tris[k])];
      const Eigen::Vector3d &a = surface.vertices[size_t(f[0])], &p1 = surface.vertices[size_t(f[1])],
                            &p2 = surface.vertices[size_t(f[2])];
      const Eigen::Vector3d n = (p1 - a).cross(p2 - a);
      const double shortest = std::min({(p1 - a).norm(), (p2 - p1).norm(), (a - p2).norm()});
      if (!(n.norm() > 0) || !(shortest > 0)) continue;
      const Eigen::Vector3d c = (a + p1 + p2) / 3, step = 0.1 * shortest * n.normalized();
      const K::Point_3 from = point(c - step), to = point(c + step);
      if ((level(from) < 0) != (level(to) < 0)) bodies[b].seeds.emplace_back(from, to);
    }
  }
  return bodies;
}

// Faces used by exactly one tet, with that tet; fills boundary_* and on_boundary.
void find_tet_boundary(TetMesh& m) {
  struct Face { std::array<int, 3> key; int tet; int opposite; };
  std::vector<Face> faces;
  faces.reserve(m.tets.size() * 4);
  for (size_t t = 0; t < m.tets.size(); ++t)
    for (int o = 0; o < 4; ++o) {
      std::array<int, 3> k;
      for (int s = 0, n = 0; s < 4; ++s)
        if (s != o) k[n++] = m.tets[t][s];
      std::sort(k.begin(), k.end());
      faces.push_back({k, int(t), o});
    }
  std::sort(faces.begin(), faces.end(), [](const Face& a, const Face& b) {
    return a.key != b.key ? a.key < b.key : a.tet < b.tet;
  });
  m.boundary_faces.clear();
  m.boundary_face_tet.clear();
  m.on_boundary.assign(m.vertices.size(), 0);
  for (size_t i = 0; i < faces.size();) {
    size_t j = i;
    while (j < faces.size() && faces[j].key == faces[i].key) ++j;
    if (j - i == 1) {
      // Outward orientation: the face seen from outside, opposite vertex behind it.
      const Eigen::Vector4i& t = m.tets[faces[i].tet];
      static const int kFace[4][3] = {{1, 3, 2}, {0, 2, 3}, {0, 3, 1}, {0, 1, 2}};
      const int* f = kFace[faces[i].opposite];
      m.boundary_faces.emplace_back(t[f[0]], t[f[1]], t[f[2]]);
      m.boundary_face_tet.push_back(faces[i].tet);
      for (int v : faces[i].key) m.on_boundary[v] = 1;
    }
    i = j;
  }
}

void orient(TetMesh& m) {
  for (auto& t : m.tets) {
    const Eigen::Vector3d& a = m.vertices[t[0]];
    const double det = (m.vertices[t[1]] - a).cross(m.vertices[t[2]] - a).dot(m.vertices[t[3]] - a);
    if (det < 0) std::swap(t[2], t[3]);
  }
}

// A body that bounds a solid (its triangles cross the level set) must have tet vertices
// near its seeds; otherwise its spheres would follow another body's motion. Returns the
// bodies that have none.
std::vector<size_t> unmeshed_bodies(const TetMesh& tets, const std::vector<SeededDomain::Body>& bodies,
                                    const std::vector<double>& size) {
  std::vector<size_t> out;
  for (size_t b = 0; b < bodies.size(); ++b) {
    if (bodies[b].seeds.empty()) continue;
    double nearest = std::numeric_limits<double>::infinity();
    for (const K::Segment_3& s : bodies[b].seeds) {
      const Eigen::Vector3d p(s.source().x(), s.source().y(), s.source().z());
      for (const auto& v : tets.vertices) nearest = std::min(nearest, (v - p).squaredNorm());
    }
    if (std::sqrt(nearest) > 2 * size[b]) out.push_back(b);
  }
  return out;
}

// Mesh_3's sizing field: the tet size asked for, smaller inside the boxes of bodies too thin
// for it.
struct BodySizing {
  using FT = K::FT;
  double size;
  std::vector<std::pair<Eigen::AlignedBox3d, double>> finer;
  template <class Index>
  FT operator()(const K::Point_3& p, const int, const Index&) const {
    const Eigen::Vector3d q(p.x(), p.y(), p.z());
    double out = size;
    for (const auto& [box, s] : finer)
      if (box.contains(q)) out = std::min(out, s);
    return out;
  }
};

// One run of Mesh_3 (sequential and seeded: the same input gives the same tets), as a TetMesh.
TetMesh mesh_domain(const SeededDomain& domain, const BodySizing& sizing, Log& log) {
  namespace params = CGAL::parameters;
  const double size = sizing.size;
  Criteria criteria(params::facet_angle = 25, params::facet_size = sizing, params::facet_distance = size / 10,
                    params::cell_radius_edge_ratio = 3, params::cell_size = sizing);
  CGAL::get_default_random() = CGAL::Random(0);  // perturbation and exudation draw from it
  log.detail("meshing the interior with tets of size " + std::to_string(size));
  // Exudation runs to its end: its default time limit is the refinement's own time, which made
  // the tets depend on the machine's speed once refinement got fast.
  C3t3 c3t3 = CGAL::make_mesh_3<C3t3>(domain, criteria, params::no_perturb(), params::exude(params::time_limit = 0));
  TetMesh out;
  std::map<Tr::Vertex_handle, int> ids;
  for (auto cell = c3t3.cells_in_complex_begin(); cell != c3t3.cells_in_complex_end(); ++cell) {
    Eigen::Vector4i t;
    for (int k = 0; k < 4; ++k) {
      auto v = cell->vertex(k);
      auto [it, fresh] = ids.emplace(v, int(out.vertices.size()));
      if (fresh) {
        const auto& p = v->point().point();
        out.vertices.emplace_back(p.x(), p.y(), p.z());
      }
      t[k] = it->second;
    }
    out.tets.push_back(t);
  }
  if (out.tets.empty()) return out;
  orient(out);
  find_tet_boundary(out);
  return out;
}

}  // namespace

TetMesh tetrahedralize(const TriMesh& surface, const TetOptions& opt, Log& log) {
  const Eigen::AlignedBox3d box = surface.bounds();
  const double diag = box.diagonal().norm();
  const double size = opt.size > 0 ? opt.size : diag / 30.0;
  if (!(size > 0) || !std::isfinite(size)) fail_option("tet_size", "must be a positive number");
  if (diag / size > 400) fail_option("tet_size", "is too small for this mesh (over 400 tets across)");
  if (size > diag)
    fail_option("tet_size", num(size) + " is larger than the body (its bounding box's diagonal is " + num(diag) +
                                "; the default is a 30th of it)");

  // Mesh_3 asks only the sign (inside: below 0), thousands of times per tet along segments it
  // bisects. On a closed mesh the winding number is the signed count of a ray's crossings, which
  // the hierarchy counts in a third of the time of the winding number's expansions: the same
  // sign off the surface. On it (a flat face meets a bisection's midpoint exactly) either answer
  // is a rounding's: there the expansions are asked as before.
  const WindingNumber wn(surface);
  const RayInside rays(surface, !opt.winding_expansions);
  std::function<double(const K::Point_3&)> level = [&](const K::Point_3& p) {
    const Eigen::Vector3d q(p.x(), p.y(), p.z());
    if (const std::optional<bool> in = rays(q)) return *in ? -0.5 : 0.5;
    return 0.5 - wn(q);
  };
  const Eigen::Vector3d c = box.center();
  const double radius = 0.5 * diag + 2 * size;
  namespace params = CGAL::parameters;
  const Components parts = edge_components(surface);
  std::vector<SeededDomain::Body> bodies = seed_bodies(surface, parts, level);
  const std::vector<PieceShape> shapes = piece_shapes(surface, parts);
  SeededDomain domain(
      Domain::create_implicit_mesh_domain(
          params::function = level,
          params::bounding_object = K::Sphere_3(K::Point_3(c.x(), c.y(), c.z()), radius * radius),
          params::relative_error_bound = 1e-6),
      bodies);
  // Bodies too thin for the tet size get no tets: mesh again with them halved in their boxes
  // (a sizing field), up to kRefinements times; the others keep the size asked for.
  constexpr int kRefinements = 3;
  std::vector<double> body_size(bodies.size(), size);
  BodySizing sizing{size, {}};
  for (int attempt = 0;; ++attempt) {
    TetMesh out = mesh_domain(domain, sizing, log);
    if (out.tets.empty())
      fail_input("", "the rest shape produced no tetrahedra (is it closed, or thinner than the tet size?)");
    const std::vector<size_t> thin = unmeshed_bodies(out, bodies, body_size);
    if (thin.empty()) return out;
    if (attempt == kRefinements) {
      size_t solids = 0;
      for (const auto& body : bodies) solids += !body.seeds.empty();
      for (size_t b : thin) {
        size_t solid = 0;
        for (size_t k = 0; k <= b; ++k) solid += !bodies[k].seeds.empty();
        out.unmeshed_bodies.push_back(piece_name("body", solid, solids, shapes[b]));
        log.warn(out.unmeshed_bodies.back() + " produced no tetrahedra, even with tets of size " +
                 num(body_size[b]) + " there: its spheres follow the tets nearby");
      }
      return out;
    }
    for (size_t b : thin) {
      body_size[b] /= 2;
      Eigen::AlignedBox3d box = shapes[b].box;
      box.extend(box.min() - Eigen::Vector3d::Constant(body_size[b]));
      box.extend(box.max() + Eigen::Vector3d::Constant(body_size[b]));
      sizing.finer.emplace_back(box, body_size[b]);
    }
    log.detail(std::to_string(thin.size()) + " bodies got no tets: meshing again with finer tets in them");
  }
}

namespace {

// A MEDIT file's tets; its comment lines (after the '#', without the leading blank) in `comments`.
TetMesh read_medit(const std::string& path, std::vector<std::string>* comments) {
  std::ifstream in(path);
  if (!in) fail_input(path, "cannot open");
  std::error_code ec;
  const auto bytes = std::filesystem::file_size(path, ec);
  TetMesh m;
  std::string word;
  // A vertex line takes at least 8 bytes ("0 0 0 0\n"), a tet line 10: a count the file cannot
  // hold is a corrupt file, not a reason to allocate.
  auto read_count = [&](const char* section, size_t min_line) {
    long n = -1;
    if (!(in >> n) || n < 0) fail_input(path, std::string("bad count in section ") + section);
    if (!ec && size_t(n) > bytes / min_line)
      fail_input(path, std::string("section ") + section + " claims " + std::to_string(n) + " entries; the file has " +
                           std::to_string(bytes) + " bytes");
    return n;
  };
  while (in >> word) {
    if (word[0] == '#') {
      std::string rest;
      std::getline(in, rest);
      const std::string line = word.substr(1) + rest;
      if (comments) comments->push_back(line.substr(std::min(line.find_first_not_of(' '), line.size())));
    } else if (word == "Vertices") {
      const long n = read_count("Vertices", 8);
      m.vertices.resize(size_t(n));
      for (auto& v : m.vertices) {
        int ref;
        if (!(in >> v.x() >> v.y() >> v.z() >> ref) || !v.allFinite()) fail_input(path, "bad vertex");
      }
    } else if (word == "Tetrahedra") {
      const long n = read_count("Tetrahedra", 10);
      m.tets.resize(size_t(n));
      for (auto& t : m.tets) {
        int ref;
        if (!(in >> t[0] >> t[1] >> t[2] >> t[3] >> ref)) fail_input(path, "bad tetrahedron");
        t.array() -= 1;
        if ((t.array() < 0).any() || (t.array() >= int(m.vertices.size())).any())
          fail_input(path, "tetrahedron refers to a missing vertex");
      }
    } else if (word == "End") {
      break;
    }
  }
  if (m.tets.empty()) fail_input(path, "holds no tetrahedra");
  orient(m);
  find_tet_boundary(m);
  return m;
}

// The cache's first comment, before its key; each body that got no tets is a comment after it.
constexpr const char* kCacheTag = "spx tets cache ";
constexpr const char* kUnmeshedTag = "unmeshed: ";

}  // namespace

TetMesh read_medit_tets(const std::string& path) { return read_medit(path, nullptr); }

void check_tets_fit(const TetMesh& tets, const MeshQuery& rest, const std::string& rest_name, const std::string& path) {
  std::vector<size_t> boundary;
  for (size_t v = 0; v < tets.vertices.size(); ++v)
    if (tets.on_boundary[v]) boundary.push_back(v);
  if (boundary.empty()) return;
  std::vector<double> gap(boundary.size());
  tbb::parallel_for(size_t(0), boundary.size(), [&](size_t n) { gap[n] = rest.distance(tets.vertices[boundary[n]]); });
  const auto half = gap.begin() + std::ptrdiff_t(gap.size() / 2);
  std::nth_element(gap.begin(), half, gap.end());
  const double diagonal = rest.mesh().diagonal();
  if (*half <= diagonal / 20) return;
  Eigen::AlignedBox3d box;
  for (const Eigen::Vector3d& v : tets.vertices) box.extend(v);
  const auto spans = [](const Eigen::AlignedBox3d& b) {
    return num(b.sizes().x()) + " x " + num(b.sizes().y()) + " x " + num(b.sizes().z());
  };
  fail_input(path, "does not fit the rest mesh " + rest_name + ": half its boundary's vertices lie farther than " +
                       num(*half) + " from its surface (" + num(100 * *half / diagonal) + " % of its diagonal; the tets span " +
                       spans(box) + ", the rest " + spans(rest.mesh().bounds()) + "): tets of another body, moved, or in another unit?");
}

std::string tets_cache_key(const TriMesh& rest, const TetOptions& options) {
  const std::string cgal = std::string(" CGAL ") + CGAL_VERSION_STR;
  uint64_t h = fnv1a(cache_key_start(), cgal.data(), cgal.size());
  h = fnv1a_values(h, rest.vertices);
  h = fnv1a_values(h, rest.triangles);
  h = fnv1a(h, &options.size, sizeof options.size);
  const char expansions = options.winding_expansions;
  return cache_key_text(fnv1a(h, &expansions, 1));
}

std::string tets_cache_file(const std::string& dir, const std::string& key) {
  return cache_file(dir, "tets", key, "mesh");
}

std::optional<TetMesh> read_tets_cache(const std::string& path, const std::string& key) {
  std::ifstream in(path);
  std::string first;
  if (!in || !std::getline(in, first) || first != std::string("# ") + kCacheTag + key) return std::nullopt;
  in.close();
  std::vector<std::string> comments;
  TetMesh m;
  try {
    m = read_medit(path, &comments);
  } catch (const Error&) {
    return std::nullopt;  // a cache is never a reason to fail
  }
  for (const std::string& c : comments)
    if (c.rfind(kUnmeshedTag, 0) == 0) m.unmeshed_bodies.push_back(c.substr(std::string(kUnmeshedTag).size()));
  mark_cache_file_used(path);
  return m;
}

void write_tets_cache(const std::string& path, const std::string& key, const TetMesh& tets) {
  std::string text = std::string("# ") + kCacheTag + key + "\n";
  for (const std::string& body : tets.unmeshed_bodies) text += std::string("# ") + kUnmeshedTag + body + "\n";
  text += "MeshVersionFormatted 2\nDimension 3\nVertices\n" + std::to_string(tets.vertices.size()) + "\n";
  char line[128];
  for (const auto& v : tets.vertices) {  // every bit: the map from cached tets is the map from fresh ones
    std::snprintf(line, sizeof line, "%.17g %.17g %.17g 0\n", v.x(), v.y(), v.z());
    text += line;
  }
  text += "Tetrahedra\n" + std::to_string(tets.tets.size()) + "\n";
  for (const auto& t : tets.tets) {
    std::snprintf(line, sizeof line, "%d %d %d %d 0\n", t[0] + 1, t[1] + 1, t[2] + 1, t[3] + 1);
    text += line;
  }
  write_file_atomic(path, text + "End\n");
}

namespace {
// For each point, the index of the nearest tet vertex.
std::vector<int> nearest_tet_vertices(const TetMesh& tets, const std::vector<Eigen::Vector3d>& points) {
  std::vector<int> nearest(points.size(), -1);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, points.size(), 16), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t s = r.begin(); s != r.end(); ++s) {
      double best = std::numeric_limits<double>::infinity();
      for (size_t v = 0; v < tets.vertices.size(); ++v) {
        const double d = (tets.vertices[v] - points[s]).squaredNorm();
        if (d < best) {
          best = d;
          nearest[s] = int(v);
        }
      }
    }
  });
  return nearest;
}
}  // namespace

BlendSites blend_sites(const TetMesh& tets, const std::vector<Eigen::Vector3d>& points) {
  const std::vector<int> nearest = nearest_tet_vertices(tets, points);
  std::vector<int> used(nearest), site_of_vertex(tets.vertices.size(), -1);
  std::sort(used.begin(), used.end());
  used.erase(std::unique(used.begin(), used.end()), used.end());
  BlendSites out;
  for (int v : used) {
    site_of_vertex[size_t(v)] = int(out.sites.size());
    out.sites.push_back(tets.vertices[size_t(v)]);
  }
  for (int v : nearest) out.of_point.push_back(site_of_vertex[size_t(v)]);
  return out;
}

}  // namespace spx
