#include "posemap/harmonic_map.hpp"

#include <Eigen/Dense>
#include <Eigen/Sparse>
#include <tbb/parallel_for.h>
#include <algorithm>
#include <cmath>

#include "core/error.hpp"

namespace spx {

TetLocator::TetLocator(const TetMesh& mesh) : mesh_(mesh) {
  inverse_.resize(mesh.tets.size());
  double volume = 0;
  for (size_t t = 0; t < mesh.tets.size(); ++t) {
    const auto& v = mesh.tets[t];
    Eigen::Matrix3d d;
    d.col(0) = mesh.vertices[v[1]] - mesh.vertices[v[0]];
    d.col(1) = mesh.vertices[v[2]] - mesh.vertices[v[0]];
    d.col(2) = mesh.vertices[v[3]] - mesh.vertices[v[0]];
    volume += std::abs(d.determinant()) / 6;
    inverse_[t] = d.fullPivLu().isInvertible() ? Eigen::Matrix3d(d.inverse()) : Eigen::Matrix3d::Zero();
  }
  for (const auto& p : mesh.vertices) box_.extend(p);
  // Uniform grid of about one tet per cell, and never many more cells than tets: a posed tet
  // mesh may have a few vertices flung far out, whose box would otherwise ask for 512^3 cells.
  const double tets = double(std::max<size_t>(1, mesh.tets.size()));
  const Eigen::Vector3d sizes = box_.sizes().cwiseMax(1e-12 * box_.diagonal().norm());
  cell_ = std::max({std::cbrt(volume / tets) * 1.5, std::cbrt(sizes.prod() / (8 * tets)), 1e-12 * box_.diagonal().norm()});
  cells_ = ((box_.sizes() / cell_).array().floor() + 1).cast<int>().cwiseMin(512);
  cell_ = std::max(cell_, (box_.sizes().array() / cells_.cast<double>().array()).maxCoeff() * (1 + 1e-9));
  const size_t ncells = size_t(cells_.x()) * cells_.y() * cells_.z();
  auto cell_range = [&](const Eigen::AlignedBox3d& b, Eigen::Vector3i& lo, Eigen::Vector3i& hi) {
    lo = ((b.min() - box_.min()) / cell_).array().floor().cast<int>().max(0).min(cells_.array() - 1);
    hi = ((b.max() - box_.min()) / cell_).array().floor().cast<int>().max(0).min(cells_.array() - 1);
  };
  std::vector<int> count(ncells + 1, 0);
  for (int pass = 0; pass < 2; ++pass) {
    if (pass == 1) {
      cell_start_.assign(ncells + 1, 0);
      for (size_t c = 0; c < ncells; ++c) cell_start_[c + 1] = cell_start_[c] + count[c];
      cell_tets_.resize(size_t(cell_start_[ncells]));
      std::fill(count.begin(), count.end(), 0);
    }
    for (size_t t = 0; t < mesh.tets.size(); ++t) {
      Eigen::AlignedBox3d b;
      for (int k = 0; k < 4; ++k) b.extend(mesh.vertices[mesh.tets[t][k]]);
      Eigen::Vector3i lo, hi;
      cell_range(b, lo, hi);
      for (int i = lo.x(); i <= hi.x(); ++i)
        for (int j = lo.y(); j <= hi.y(); ++j)
          for (int k = lo.z(); k <= hi.z(); ++k) {
            const size_t c = size_t(i) + size_t(cells_.x()) * (size_t(j) + size_t(cells_.y()) * size_t(k));
            if (pass == 1) cell_tets_[size_t(cell_start_[c] + count[c])] = int(t);
            ++count[c];
          }
    }
  }
  TriMesh boundary;
  boundary.vertices = mesh.vertices;
  boundary.triangles = mesh.boundary_faces;
  boundary_ = std::make_unique<MeshQuery>(boundary);
}

TetLocator::~TetLocator() = default;

Eigen::Vector4d TetLocator::weights(int t, const Eigen::Vector3d& p) const {
  const Eigen::Vector3d b = inverse_[t] * (p - mesh_.vertices[mesh_.tets[t][0]]);
  return {1 - b.sum(), b.x(), b.y(), b.z()};
}

TetLocator::Location TetLocator::locate(const Eigen::Vector3d& p) const {
  Location best;
  double best_min = -std::numeric_limits<double>::infinity();
  if (box_.contains(p)) {
    const Eigen::Vector3i c = ((p - box_.min()) / cell_).array().floor().cast<int>().max(0).min(cells_.array() - 1);
    const size_t cell = size_t(c.x()) + size_t(cells_.x()) * (size_t(c.y()) + size_t(cells_.y()) * size_t(c.z()));
    for (int n = cell_start_[cell]; n < cell_start_[cell + 1]; ++n) {
      const int t = cell_tets_[size_t(n)];
      const Eigen::Vector4d w = weights(t, p);
      const double m = w.minCoeff();
      if (m > best_min || (m == best_min && t < best.tet)) {
        best_min = m;
        best.tet = t;
        best.weights = w;
      }
    }
  }
  if (best.tet >= 0 && best_min >= -1e-9) return best;
  const ClosestPoint face = boundary_->closest(p);
  Location out;
  out.tet = mesh_.boundary_face_tet[size_t(face.triangle)];
  out.weights = weights(out.tet, p);
  out.outside = face.distance;
  return out;
}

HarmonicMap::HarmonicMap(const TetMesh& tets, const TriMesh& rest, Log& log)
    : tets_(tets), rest_(rest), locator_(tets) {
  const size_t n = tets.vertices.size();
  // Typical edge length: surface points further out than this are not covered by the tets.
  double edge = 0;
  for (const auto& t : tets.tets) edge += (tets.vertices[t[0]] - tets.vertices[t[1]]).norm();
  edge /= double(std::max<size_t>(1, tets.tets.size()));

  // Data points: every rest surface vertex, and the closest surface point of every boundary
  // tet vertex (so each boundary vertex is pinned by the surface near it).
  auto add = [&](const Eigen::Vector3i& tri, const Eigen::Vector3d& w, const Eigen::Vector3d& p) {
    TetLocator::Location at = locator_.locate(p);
    if (at.outside > 2 * edge) {
      ++dropped_;
      return;
    }
    data_.push_back({tri, w, at});
  };
  for (size_t v = 0; v < rest.vertices.size(); ++v)
    add(Eigen::Vector3i(int(v), int(v), int(v)), Eigen::Vector3d(1, 0, 0), rest.vertices[v]);
  {
    const MeshQuery surface(rest);
    for (size_t v = 0; v < n; ++v) {
      if (!tets.on_boundary[v]) continue;
      const ClosestPoint c = surface.closest(tets.vertices[v]);
      add(rest.triangles[size_t(c.triangle)], c.barycentric, c.point);
    }
  }
  if (dropped_ > 0)
    log.warn(std::to_string(dropped_) + " rest surface points lie outside the tet mesh by more than two tet edges "
             "(features thinner than the tet size); they do not constrain the map");

  // Normal equations of the least-squares problem.
  using Triplet = Eigen::Triplet<double>;
  std::vector<Triplet> c_entries;
  for (size_t r = 0; r < data_.size(); ++r)
    for (int k = 0; k < 4; ++k) c_entries.emplace_back(int(r), tets.tets[data_[r].at.tet][k], data_[r].at.weights[k]);
  const int vars = static_cast<int>(n);
  Eigen::SparseMatrix<double> c(static_cast<int>(data_.size()), vars);
  c.setFromTriplets(c_entries.begin(), c_entries.end());

  std::vector<Triplet> k_entries;
  for (const auto& t : tets.tets) {
    Eigen::Matrix3d d;
    for (int k = 0; k < 3; ++k) d.col(k) = tets.vertices[t[k + 1]] - tets.vertices[t[0]];
    const double vol = d.determinant() / 6;
    if (!(vol > 0)) continue;
    const Eigen::Matrix3d inv = d.inverse();
    Eigen::Matrix<double, 4, 3> grad;
    grad.bottomRows<3>() = inv;
    grad.row(0) = -inv.colwise().sum();
    const Eigen::Matrix4d local = vol * grad * grad.transpose();
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b) k_entries.emplace_back(t[a], t[b], local(a, b));
  }
  Eigen::SparseMatrix<double> stiffness(vars, vars);
  stiffness.setFromTriplets(k_entries.begin(), k_entries.end());
  std::vector<Triplet> l_entries;
  int rows = 0;
  for (int v = 0; v < vars; ++v) {
    if (tets.on_boundary[size_t(v)]) continue;
    const double diag = stiffness.coeff(v, v);
    if (!(diag > 0)) continue;
    for (Eigen::SparseMatrix<double>::InnerIterator it(stiffness, v); it; ++it)
      l_entries.emplace_back(rows, int(it.row()), it.value() / diag);
    ++rows;
  }
  Eigen::SparseMatrix<double> l(rows, vars);
  l.setFromTriplets(l_entries.begin(), l_entries.end());

  Eigen::SparseMatrix<double> identity(vars, vars);
  identity.setIdentity();
  ct_ = c.transpose();
  const Eigen::SparseMatrix<double> a = ct_ * c + Eigen::SparseMatrix<double>(l.transpose() * l) + 1e-10 * identity;
  solver_.compute(a);
  if (solver_.info() != Eigen::Success) fail_input("", "the harmonic map's system could not be factorised");
}

std::vector<Eigen::Vector3d> HarmonicMap::deform(const TriMesh& pose) const {
  Eigen::MatrixXd d(Eigen::Index(data_.size()), 3);
  for (size_t r = 0; r < data_.size(); ++r) {
    Eigen::Vector3d disp = Eigen::Vector3d::Zero();
    for (int k = 0; k < 3; ++k) {
      const int v = data_[r].triangle[k];
      disp += data_[r].surface[k] * (pose.vertices[size_t(v)] - rest_.vertices[size_t(v)]);
    }
    d.row(Eigen::Index(r)) = disp.transpose();
  }
  const Eigen::MatrixXd u = solver_.solve(Eigen::MatrixXd(ct_ * d));
  std::vector<Eigen::Vector3d> out(tets_.vertices.size());
  for (size_t v = 0; v < out.size(); ++v) out[v] = tets_.vertices[v] + u.row(Eigen::Index(v)).transpose();
  return out;
}

Eigen::MatrixXd HarmonicMap::extend(const Eigen::MatrixXd& per_vertex) const {
  Eigen::MatrixXd d(Eigen::Index(data_.size()), per_vertex.cols());
  for (size_t r = 0; r < data_.size(); ++r) {
    d.row(Eigen::Index(r)).setZero();
    for (int k = 0; k < 3; ++k) d.row(Eigen::Index(r)) += data_[r].surface[k] * per_vertex.row(data_[r].triangle[k]);
  }
  return solver_.solve(Eigen::MatrixXd(ct_ * d));
}

Eigen::Vector3d HarmonicMap::map(const Eigen::Vector3d& p, const TetLocator::Location& at,
                                 const std::vector<Eigen::Vector3d>& deformed) const {
  // p plus the interpolated displacement: where nothing moves (a body that stays still, a pose
  // equal to the rest) the displacement is exactly zero and p comes back bit for bit.
  Eigen::Vector3d u = Eigen::Vector3d::Zero();
  for (int k = 0; k < 4; ++k) {
    const size_t v = size_t(tets_.tets[size_t(at.tet)][k]);
    u += at.weights[k] * (deformed[v] - tets_.vertices[v]);
  }
  return p + u;
}

std::vector<std::optional<Eigen::Vector3d>> undeform(const TetMesh& tets, const std::vector<Eigen::Vector3d>& deformed,
                                                     const std::vector<Eigen::Vector3d>& points) {
  TetMesh posed = tets;
  posed.vertices = deformed;
  const TetLocator inverse(posed);
  std::vector<std::optional<Eigen::Vector3d>> out(points.size());
  tbb::parallel_for(size_t(0), points.size(), [&](size_t n) {
    const TetLocator::Location at = inverse.locate(points[n]);
    if (at.outside > 0) return;
    Eigen::Vector3d x = Eigen::Vector3d::Zero();
    for (int k = 0; k < 4; ++k) x += at.weights[k] * tets.vertices[size_t(tets.tets[size_t(at.tet)][k])];
    out[n] = x;
  });
  return out;
}

SphereSet undeform_centres(const TetMesh& tets, const std::vector<Eigen::Vector3d>& deformed, const SphereSet& spheres,
                           const MeshQuery& rest, double max_radius, bool radii) {
  std::vector<Eigen::Vector3d> centers;
  for (const Sphere& s : spheres) centers.push_back(s.center);
  const std::vector<std::optional<Eigen::Vector3d>> back = undeform(tets, deformed, centers);
  SphereSet out(back.size(), Sphere{{0, 0, 0}, -1});  // radius -1: outside
  tbb::parallel_for(size_t(0), back.size(), [&](size_t n) {
    if (back[n] && rest.inside(*back[n])) out[n] = {*back[n], radii ? std::min(max_radius, rest.distance(*back[n])) : 0.0};
  });
  out.erase(std::remove_if(out.begin(), out.end(), [](const Sphere& s) { return s.radius < 0; }), out.end());
  return out;
}

}  // namespace spx
