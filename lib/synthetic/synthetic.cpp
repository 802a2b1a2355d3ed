#include "synthetic/synthetic.hpp"

#include <cmath>
#include <map>

#include "core/error.hpp"
#include "io/gltf_morph.hpp"
#include "io/gltf_rig.hpp"

namespace spx {
namespace {

double smoothstep(double t) {
  t = std::clamp(t, 0.0, 1.0);
  return t * t * (3 - 2 * t);
}
// Integral of smoothstep from 0 to t.
double smoothstep_integral(double t) {
  if (t <= 0) return 0;
  if (t >= 1) return 0.5 + (t - 1);
  return t * t * t - 0.5 * t * t * t * t;
}
double gauss(double a) { return std::exp(-a * a); }

// Closed quad lattice on the surface of a box, split into outward triangles; vertices
// carry their position in [-1,1]^3.
TriMesh box_lattice(int nx, int ny, int nz) {
  TriMesh m;
  std::map<std::array<int, 3>, int> index;
  auto vertex = [&](int i, int j, int k) {
    auto [it, fresh] = index.emplace(std::array<int, 3>{i, j, k}, int(m.vertices.size()));
    if (fresh) m.vertices.emplace_back(2.0 * i / nx - 1, 2.0 * j / ny - 1, 2.0 * k / nz - 1);
    return it->second;
  };
  const int n[3] = {nx, ny, nz};
  for (int axis = 0; axis < 3; ++axis) {
    const int a = (axis + 1) % 3, b = (axis + 2) % 3;
    for (int side = 0; side < 2; ++side)
      for (int u = 0; u < n[a]; ++u)
        for (int v = 0; v < n[b]; ++v) {
          int q[4];
          const int du[4] = {0, 1, 1, 0}, dv[4] = {0, 0, 1, 1};
          for (int c = 0; c < 4; ++c) {
            std::array<int, 3> ijk;
            ijk[axis] = side * n[axis];
            ijk[a] = u + du[c];
            ijk[b] = v + dv[c];
            q[c] = vertex(ijk[0], ijk[1], ijk[2]);
          }
          // (a, b, axis) is right-handed, so (q0,q1,q2) faces +axis; flip on the low side.
          if (side == 1) {
            m.triangles.emplace_back(q[0], q[1], q[2]);
            m.triangles.emplace_back(q[0], q[2], q[3]);
          } else {
            m.triangles.emplace_back(q[0], q[2], q[1]);
            m.triangles.emplace_back(q[0], q[3], q[2]);
          }
        }
  }
  return m;
}

// The box lattice without its side `side` (0: low, 1: high) across `axis`: an open box, the
// unused vertices dropped.
TriMesh open_box(int nx, int ny, int nz, int axis, int side) {
  const TriMesh box = box_lattice(nx, ny, nz);
  const double wall = side ? 1.0 : -1.0;
  TriMesh m;
  std::vector<int> index(box.vertices.size(), -1);
  for (const auto& t : box.triangles) {
    bool open = true;
    for (int c = 0; c < 3; ++c) open = open && box.vertices[size_t(t[c])][axis] == wall;
    if (open) continue;
    Eigen::Vector3i u;
    for (int c = 0; c < 3; ++c) {
      int& i = index[size_t(t[c])];
      if (i < 0) i = int(m.vertices.size()), m.vertices.push_back(box.vertices[size_t(t[c])]);
      u[c] = i;
    }
    m.triangles.push_back(u);
  }
  return m;
}

// A tube along y from y0 down to y1 (open at both ends, outward normals).
TriMesh tube(double radius, double y0, double y1, int sectors, int rings) {
  TriMesh m;
  for (int r = 0; r <= rings; ++r)
    for (int s = 0; s < sectors; ++s) {
      const double a = 2 * M_PI * s / sectors, y = y0 + (y1 - y0) * r / rings;
      m.vertices.emplace_back(radius * std::cos(a), y, radius * std::sin(a));
    }
  auto at = [&](int r, int s) { return r * sectors + (s % sectors); };
  for (int r = 0; r < rings; ++r)
    for (int s = 0; s < sectors; ++s) {
      m.triangles.emplace_back(at(r, s), at(r + 1, s), at(r + 1, s + 1));
      m.triangles.emplace_back(at(r, s), at(r + 1, s + 1), at(r, s + 1));
    }
  // As listed the normals face the axis when the tube goes down (y1 < y0): flip them then.
  if (y1 < y0)
    for (auto& t : m.triangles) std::swap(t[1], t[2]);
  return m;
}

TriMesh placed(TriMesh m, const Eigen::Vector3d& half_size, const Eigen::Vector3d& center) {
  for (auto& p : m.vertices) p = center + p.cwiseProduct(half_size);
  return m;
}

}  // namespace

TriMesh SampleAsset::pose(size_t index) const {
  TriMesh m = rest;
  for (auto& v : m.vertices) v = deform(index, v);
  return m;
}

SampleAsset make_car() {
  SampleAsset car;
  car.name = "car";
  constexpr double half_length = 2.625, half_width = 0.9;
  car.rest = box_lattice(22, 9, 6);
  for (auto& p : car.rest.vertices) {
    // Rounded box (superellipsoid, exponent 4), then a car's profile: hood, cabin, trunk.
    const double s = std::pow(std::pow(std::abs(p.x()), 4) + std::pow(std::abs(p.y()), 4) + std::pow(std::abs(p.z()), 4), -0.25);
    const Eigen::Vector3d q = s * p;
    const double xn = q.x();
    const double cabin = smoothstep((xn + 0.6) / 0.3) * smoothstep((0.35 - xn) / 0.3);
    const double up = std::max(q.z(), 0.0);
    const double x = half_length * q.x();
    const double y = half_width * q.y() * (1 - 0.18 * cabin * up * up);
    const double z = q.z() < 0 ? 0.65 + 0.3 * q.z() : 0.65 + q.z() * (0.3 + 0.55 * cabin);
    p = Eigen::Vector3d(x, y, z);
  }
  // The rounded box stops just short of its ends: scale to exactly 5.25 m, centered.
  const Eigen::AlignedBox3d box = car.rest.bounds();
  const double stretch = 2 * half_length / box.sizes().x(), mid = box.center().x();
  for (auto& p : car.rest.vertices) p.x() = (p.x() - mid) * stretch;
  car.pose_names = {"front", "rear", "side", "roof"};
  car.deform = [](size_t pose, const Eigen::Vector3d& p) -> Eigen::Vector3d {
    Eigen::Vector3d q = p;
    switch (pose) {
      case 0: {  // front crumple: the nose compresses (more at the center), the hood buckles up
        const double x0 = 1.2, span = half_length - x0;
        const double t = (p.x() - x0) / span;
        const double k = 0.3 + 0.15 * gauss(p.y() / 0.5);
        q.x() = p.x() - k * span * smoothstep_integral(t);
        q.z() = p.z() + 0.12 * (t > 0 && t < 1 ? std::sin(M_PI * t) : 0.0) * smoothstep((p.z() - 0.6) / 0.3);
        break;
      }
      case 1: {  // rear crumple
        const double x0 = -1.4, span = half_length + x0;
        const double t = (x0 - p.x()) / span;
        q.x() = p.x() + 0.3 * span * smoothstep_integral(t);
        q.z() = p.z() - 0.08 * (t > 0 && t < 1 ? std::sin(M_PI * t) : 0.0) * smoothstep((p.z() - 0.6) / 0.3);
        break;
      }
      case 2:  // side impact on the right (+y) door
        q.y() = p.y() - 0.35 * gauss((p.x() - 0.3) / 0.7) * gauss((p.z() - 0.75) / 0.35) * smoothstep((p.y() + 0.2) / 1.1);
        break;
      case 3:  // roof crushed from above
        q.z() = p.z() - 0.3 * gauss((p.x() + 0.2) / 0.9) * gauss(p.y() / 0.6) * smoothstep((p.z() - 0.4) / 1.1);
        break;
    }
    return q;
  };
  return car;
}

TriMesh lathe(const std::vector<std::pair<double, double>>& profile, double bottom, double top, int sectors) {
  TriMesh m;
  m.vertices.emplace_back(0, 0, bottom);
  for (const auto& [r, z] : profile)
    for (int s = 0; s < sectors; ++s) {
      const double a = 2 * M_PI * s / sectors;
      m.vertices.emplace_back(r * std::cos(a), r * std::sin(a), z);
    }
  m.vertices.emplace_back(0, 0, top);
  const int rings = int(profile.size()), top_pole = int(m.vertices.size()) - 1;
  auto at = [&](int ring, int s) { return 1 + ring * sectors + (s % sectors); };
  for (int s = 0; s < sectors; ++s) m.triangles.emplace_back(0, at(0, s + 1), at(0, s));
  for (int ring = 0; ring + 1 < rings; ++ring)
    for (int s = 0; s < sectors; ++s) {
      m.triangles.emplace_back(at(ring, s), at(ring, s + 1), at(ring + 1, s + 1));
      m.triangles.emplace_back(at(ring, s), at(ring + 1, s + 1), at(ring + 1, s));
    }
  for (int s = 0; s < sectors; ++s) m.triangles.emplace_back(top_pole, at(rings - 1, s), at(rings - 1, s + 1));
  return m;
}

SampleAsset make_barrel() {
  SampleAsset barrel;
  barrel.name = "barrel";
  constexpr double height = 0.72, radius = 0.29;
  constexpr int sectors = 32;
  // Profile from the bottom pole to the top pole: lid rings, rounded rims, bulged side.
  std::vector<std::pair<double, double>> profile;  // (r, z)
  for (double f : {0.33, 0.66, 0.9}) profile.emplace_back(f * radius, 0.0);
  profile.emplace_back(0.98 * radius, 0.005);
  const int side = 12;
  for (int i = 0; i <= side; ++i) {
    const double t = double(i) / side;
    const double z = 0.02 + t * (height - 0.04);
    profile.emplace_back(radius * (1 + 0.07 * (1 - (2 * t - 1) * (2 * t - 1))), z);
  }
  profile.emplace_back(0.98 * radius, height - 0.005);
  for (double f : {0.9, 0.66, 0.33}) profile.emplace_back(f * radius, height);

  barrel.rest = lathe(profile, 0, height, sectors);

  barrel.pose_names = {"dent", "squash", "top"};
  barrel.deform = [](size_t pose, const Eigen::Vector3d& p) -> Eigen::Vector3d {
    Eigen::Vector3d q = p;
    switch (pose) {
      case 0:  // a dent in the side facing +x
        q.x() = p.x() - 0.09 * gauss((p.z() - 0.45) / 0.12) * gauss(p.y() / 0.12) * smoothstep((p.x() + 0.1) / 0.4);
        break;
      case 1: {  // squashed from above: 15% shorter, bulging out
        const double bulge = 1 + 0.1 * std::sin(M_PI * std::clamp(p.z() / height, 0.0, 1.0));
        q = Eigen::Vector3d(p.x() * bulge, p.y() * bulge, 0.85 * p.z());
        break;
      }
      case 2:  // the lid pushed in at its center
        q.z() = p.z() - 0.08 * gauss(std::hypot(p.x(), p.y()) / 0.14) * smoothstep((p.z() - 0.3) / 0.42);
        break;
    }
    return q;
  };
  return barrel;
}

RigAsset make_robot() {
  RigAsset robot;
  robot.name = "robot";
  constexpr int keys = 24;
  for (int k = 0; k < keys; ++k) robot.times.push_back(k / 24.0);
  // Each joint's rotation about one axis, as a function of the walk's phase.
  auto joint = [&](const std::string& name, int parent, Eigen::Vector3d at, Eigen::Vector3d axis,
                   std::function<double(double)> angle) {
    RigJoint j{name, parent, at, {}};
    for (int k = 0; k < keys; ++k)
      j.rotations.emplace_back(Eigen::AngleAxisd(angle(2 * M_PI * k / keys), axis.normalized()));
    robot.joints.push_back(j);
    return int(robot.joints.size()) - 1;
  };
  auto part = [&](const std::string& name, int on, TriMesh mesh) { robot.parts.push_back({name, on, std::move(mesh)}); };
  const Eigen::Vector3d X = Eigen::Vector3d::UnitX(), Y = Eigen::Vector3d::UnitY();
  const int hips = joint("hips", -1, {0, 1.0, 0}, Y, [](double p) { return 0.12 * std::sin(p); });
  const int spine = joint("spine", hips, {0, 0.08, 0}, Y, [](double p) { return -0.15 * std::sin(p); });
  const int neck = joint("neck", spine, {0, 0.56, 0}, Y, [](double p) { return 0.35 * std::sin(p); });
  // Open boxes: the pelvis open at the top, inside the torso open at the bottom (they overlap).
  part("pelvis", hips, placed(open_box(6, 3, 4, 1, 1), {0.18, 0.1, 0.11}, {0, -0.02, 0}));
  part("torso", spine, placed(open_box(7, 9, 4, 1, 0), {0.22, 0.28, 0.13}, {0, 0.26, 0}));
  part("head", neck, placed(open_box(4, 4, 4, 1, 0), {0.12, 0.13, 0.12}, {0, 0.16, 0}));
  for (int side : {-1, 1}) {
    const std::string lr = side < 0 ? "r_" : "l_";
    const double swing = side;
    const int shoulder = joint(lr + "shoulder", spine, {side * 0.28, 0.46, 0}, X,
                               [=](double p) { return 0.5 * swing * std::sin(p); });
    const int elbow = joint(lr + "elbow", shoulder, {0, -0.3, 0}, X,
                            [=](double p) { return -0.35 - 0.25 * swing * std::sin(p); });
    const int hip = joint(lr + "hip", hips, {side * 0.11, -0.06, 0}, X,
                          [=](double p) { return -0.45 * swing * std::sin(p); });
    const int knee = joint(lr + "knee", hip, {0, -0.44, 0}, X,
                           [=](double p) { return 0.55 * std::max(0.0, swing * std::cos(p)); });
    const int ankle = joint(lr + "ankle", knee, {0, -0.44, 0}, X, [=](double p) { return 0.2 * swing * std::sin(p); });
    // Tubes open at both ends, the upper arm reaching into the torso; open-topped feet.
    part(lr + "upper_arm", shoulder, tube(0.06, 0.04, -0.3, 12, 8));
    part(lr + "forearm", elbow, tube(0.05, 0.0, -0.3, 12, 8));
    part(lr + "thigh", hip, tube(0.08, 0.02, -0.44, 14, 10));
    part(lr + "shin", knee, tube(0.065, 0.0, -0.44, 14, 10));
    part(lr + "foot", ankle, placed(open_box(3, 2, 5, 1, 1), {0.07, 0.04, 0.13}, {0, -0.05, 0.05}));
  }
  return robot;
}

SampleAsset make_sample(const std::string& name) {
  if (name == "car") return make_car();
  if (name == "barrel") return make_barrel();
  fail_usage(name, "unknown sample (use car, barrel or robot)");
}

MorphAsset morph_asset(const SampleAsset& asset) {
  MorphAsset m;
  m.name = asset.name;
  m.base = asset.rest;
  m.target_names = asset.pose_names;
  for (size_t i = 0; i < asset.pose_names.size(); ++i) m.targets.push_back(asset.pose(i).vertices);
  return m;
}

}  // namespace spx
