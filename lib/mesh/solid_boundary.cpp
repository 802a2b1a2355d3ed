#include "mesh/solid_boundary.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>

#include "mesh/components.hpp"
#include "mesh/defects.hpp"

namespace spx {

std::vector<Eigen::Vector3d> wall_probes(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const Eigen::Vector3d m = (a + b + c) / 3;
  return {m,
          0.5 * (m + a),
          0.5 * (m + b),
          0.5 * (m + c),
          0.5 * (m + 0.5 * (a + b)),
          0.5 * (m + 0.5 * (b + c)),
          0.5 * (m + 0.5 * (c + a)),
          (m + 7 * a) / 8,
          (m + 7 * b) / 8,
          (m + 7 * c) / 8};
}

namespace {

using Corners = BoundaryParts::Corners;
constexpr int kProbes = 10, kPieceProbes = 4;

// How many of triangle t's probes bound (either side outside): of kProbes for an input
// triangle, of kPieceProbes (its centroid and near its corners) for a piece.
int bounding_probes(const Corners& t, const Eigen::Vector3d& n, double offset, const WindingNumber& wn, bool piece) {
  const std::vector<Eigen::Vector3d> probes = wall_probes(t[0], t[1], t[2]);
  int count = 0;
  for (size_t k = 0; k < probes.size(); ++k)
    if (!piece || k == 0 || k >= 7) count += !wn.inside(probes[k] + offset * n);
  return count;
}

// The bounding pieces of t: kept whole where every probe bounds (or at the last depth), left
// out where none does, split in 4 where they disagree.
void bounding_pieces(const Corners& t, const Eigen::Vector3d& n, double offset, const WindingNumber& wn, int depth,
                     int probes, std::vector<Corners>& out) {
  if (probes == 0) return;
  if (probes == (depth == 0 ? kProbes : kPieceProbes) || depth == kWallSplitDepth) {
    out.push_back(t);
    return;
  }
  const Eigen::Vector3d ab = 0.5 * (t[0] + t[1]), bc = 0.5 * (t[1] + t[2]), ca = 0.5 * (t[2] + t[0]);
  for (const Corners& child : {Corners{t[0], ab, ca}, Corners{ab, t[1], bc}, Corners{ca, bc, t[2]}, Corners{ab, bc, ca}})
    bounding_pieces(child, n, offset, wn, depth + 1, bounding_probes(child, n, offset, wn, true), out);
}

// The triangles worth probing: those whose box meets another piece's (edge-connected
// component's). The rest keep the rule of one piece alone, every triangle bounding (a piece that
// folds into itself keeps its walls: more is kept, never less). Past kMaxPieces pieces (a soup
// of loose triangles) every triangle is probed.
constexpr size_t kMaxPieces = 256;
std::vector<uint8_t> near_another_piece(const TriMesh& mesh, double margin) {
  const Components pieces = edge_components(mesh);
  std::vector<uint8_t> out(mesh.triangles.size(), pieces.count > kMaxPieces);
  if (pieces.count < 2 || pieces.count > kMaxPieces) return out;
  auto box_of = [&](size_t t) {
    Eigen::AlignedBox3d box;
    for (int k = 0; k < 3; ++k) box.extend(mesh.vertices[size_t(mesh.triangles[t][k])]);
    return box;
  };
  std::vector<Eigen::AlignedBox3d> boxes(pieces.count);
  for (size_t t = 0; t < mesh.triangles.size(); ++t) boxes[size_t(pieces.of_triangle[t])].extend(box_of(t));
  for (auto& b : boxes) b = Eigen::AlignedBox3d(b.min().array() - margin, b.max().array() + margin);
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const Eigen::AlignedBox3d box = box_of(t);
    for (size_t p = 0; p < boxes.size() && !out[t]; ++p)
      out[t] = int(p) != pieces.of_triangle[t] && boxes[p].intersects(box);
  }
  return out;
}

}  // namespace

BoundaryParts::BoundaryParts(const TriMesh& mesh, const WindingNumber& wn)
    : mesh_(mesh), wn_(wn), diagonal_(mesh.diagonal()), offset_(kWallProbe * diagonal_) {
  const MeshDefects defects = find_defects(mesh);
  if (!(defects.watertight() && defects.components == 1)) probed_ = near_another_piece(mesh, 2 * offset_);
}

BoundaryParts::Part BoundaryParts::part(size_t t) const {
  Part out;
  if (probed_.empty() || !probed_[t] || is_degenerate(mesh_, int(t), diagonal_)) return out;
  const auto& f = mesh_.triangles[t];
  const Corners c{mesh_.vertices[size_t(f[0])], mesh_.vertices[size_t(f[1])], mesh_.vertices[size_t(f[2])]};
  const Eigen::Vector3d n = (c[1] - c[0]).cross(c[2] - c[0]).normalized();
  const int probes = bounding_probes(c, n, offset_, wn_, false);
  if (probes == kProbes) return out;
  out.kind = probes == 0 ? Part::none : Part::pieces;
  bounding_pieces(c, n, offset_, wn_, 0, probes, out.bounding);
  return out;
}

SolidBoundary solid_boundary(const TriMesh& mesh, const WindingNumber& wn) {
  SolidBoundary out;
  const BoundaryParts parts_of(mesh, wn);
  if (parts_of.whole()) return out;
  std::vector<BoundaryParts::Part> parts(mesh.triangles.size());
  tbb::parallel_for(size_t(0), mesh.triangles.size(), [&](size_t t) { parts[t] = parts_of.part(t); });
  using Part = BoundaryParts::Part;
  if (std::all_of(parts.begin(), parts.end(), [](const Part& p) { return p.kind == Part::whole; })) return out;
  out.mesh.vertices = mesh.vertices;
  for (size_t t = 0; t < parts.size(); ++t) {
    if (parts[t].kind == Part::whole) {
      out.mesh.triangles.push_back(mesh.triangles[t]);
      out.source.push_back(int(t));
      continue;
    }
    ++(parts[t].kind == Part::none ? out.internal : out.split);
    for (const Corners& piece : parts[t].bounding) {
      const int first = int(out.mesh.vertices.size());
      out.mesh.vertices.insert(out.mesh.vertices.end(), piece.begin(), piece.end());
      out.mesh.triangles.emplace_back(first, first + 1, first + 2);
      out.source.push_back(int(t));
    }
  }
  return out;
}

TriMesh solid_surface(const TriMesh& mesh, const SolidBoundary& boundary) {
  if (boundary.whole()) return mesh;
  const TriMesh& b = boundary.mesh;
  std::vector<int> renumber(b.vertices.size(), -1);
  for (const auto& f : b.triangles)
    for (int k = 0; k < 3; ++k) renumber[size_t(f[k])] = 0;
  TriMesh out;
  for (size_t v = 0; v < b.vertices.size(); ++v)
    if (renumber[v] == 0) {
      renumber[v] = int(out.vertices.size());
      out.vertices.push_back(b.vertices[v]);
    }
  for (const auto& f : b.triangles)
    out.triangles.emplace_back(renumber[size_t(f[0])], renumber[size_t(f[1])], renumber[size_t(f[2])]);
  return out;
}

// The winding number is built only where pieces are probed (not for a single closed surface).
TriMesh solid_surface(const TriMesh& mesh) {
  return solid_surface(mesh, solid_boundary(mesh, WindingNumber::on_first_use(mesh)));
}

}  // namespace spx
