#include "crash_host.hpp"

#include <BulletCollision/Gimpact/btGImpactCollisionAlgorithm.h>
#include <BulletCollision/Gimpact/btGImpactShape.h>
#include <btBulletDynamicsCommon.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <memory>
#include <set>

#include "core/error.hpp"
#include "core/hash.hpp"
#include "core/random.hpp"
#include "mesh/winding_number.hpp"
#include "mesh/union_distance.hpp"
#include "spx_bullet.hpp"

namespace spx::crash {
namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

btVector3 bt(const Eigen::Vector3d& v) { return {btScalar(v.x()), btScalar(v.y()), btScalar(v.z())}; }
Eigen::Vector3d eig(const btVector3& v) { return {v.x(), v.y(), v.z()}; }

// Deterministic jitter in [-1, 1] for (seed, car, channel): the first draw of the project's
// generator keyed by them.
double jitter(uint32_t seed, int car, int channel) {
  SplitMix rng{(uint64_t(seed) << 32) ^ (uint64_t(car) << 8) ^ uint64_t(channel)};
  return rng.uniform() * 2 - 1;
}

Eigen::Vector3d volume_centroid(const TriMesh& m) {
  double volume = 0;
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (const auto& t : m.triangles) {
    const auto &a = m.vertices[t[0]], &b = m.vertices[t[1]], &d = m.vertices[t[2]];
    const double v = a.dot(b.cross(d)) / 6;
    volume += v;
    c += v * (a + b + d) / 4;
  }
  return c / volume;
}

Dent dent_of(const TriMesh& rest, const TriMesh& pose) {
  double largest = 0;
  for (size_t v = 0; v < rest.vertices.size(); ++v)
    largest = std::max(largest, (pose.vertices[v] - rest.vertices[v]).norm());
  Dent dent;
  double total = 0;
  for (size_t v = 0; v < rest.vertices.size(); ++v) {
    const Eigen::Vector3d d = pose.vertices[v] - rest.vertices[v];
    if (d.norm() < 0.2 * largest) continue;  // the dent itself, not the small drift around it
    dent.center += d.norm() * rest.vertices[v];
    dent.direction += d;
    total += d.norm();
  }
  if (total > 0) dent.center /= total;
  if (dent.direction.norm() > 0) dent.direction.normalize();
  return dent;
}

// The ground: Bullet's plane test (GImpact has a fast path for it), over a finite slab (10 km
// across: a car launched at twice the speed slides for hundreds of metres). Bullet's
// own plane reports an infinite box, which defeats a compound's child culling: every sphere of
// every car would be tested against the ground every step.
class GroundPlane : public btStaticPlaneShape {
 public:
  explicit GroundPlane(double half_extent) : btStaticPlaneShape(btVector3(0, 0, 1), 0), half_(btScalar(half_extent)) {}
  void getAabb(const btTransform& t, btVector3& lo, btVector3& hi) const override {
    btTransformAabb(btVector3(-half_, -half_, -1), btVector3(half_, half_, 0), 0, t, lo, hi);
  }

 private:
  btScalar half_;
};

// One car in the world: its body, its collision shape and its plastic state.
struct Car {
  std::unique_ptr<btCollisionShape> shape;       // bullet::SphereSetShape or btGImpactMeshShape
  std::vector<btScalar> vertices;                // GImpact vertex buffer, body frame
  std::unique_ptr<btTriangleIndexVertexArray> mesh_array;
  std::unique_ptr<btRigidBody> body;
  std::vector<float> weights;                    // site-major, pose_count per site
  bool dirty = false;
};

// Impulses one car received from one other object during a step.
struct Hit {
  int car = -1;
  const btCollisionObject* other = nullptr;
  double impulse = 0;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();  // impulse-weighted, world
  Eigen::Vector3d push = Eigen::Vector3d::Zero();   // impulse-weighted direction, world
};

class World {
 public:
  World(const CarAsset& asset, const SceneOptions& options) : asset_(asset), opt_(options) {
    dispatcher_ = std::make_unique<btCollisionDispatcher>(&config_);
    btGImpactCollisionAlgorithm::registerAlgorithm(dispatcher_.get());
    if (asset.spheres && asset.sphere_set) bullet::register_sphere_set_algorithms(*dispatcher_);
    world_ = std::make_unique<btDiscreteDynamicsWorld>(dispatcher_.get(), &broadphase_, &solver_, &config_);
    world_->setGravity(btVector3(0, 0, btScalar(-gravity_)));
    for (const auto& t : asset.rest.triangles) indices_.insert(indices_.end(), {t[0], t[1], t[2]});
    add_ground_and_ramps();
    for (int i = 0; i < opt_.cars; ++i) add_car(i);
  }

  ~World() {
    for (auto& car : cars_) world_->removeRigidBody(car.body.get());
    for (auto& body : statics_) world_->removeRigidBody(body.get());
  }

  RunStats run() {
    RunStats stats;
    const int steps = int(std::lround(opt_.seconds / opt_.dt));
    if (opt_.monitor) {
      initial_energy_ = energy();
      stats.error.resize(cars_.size());
      stats.path.resize(cars_.size());
    }
    std::vector<std::vector<char>> tunnelled(cars_.size(), std::vector<char>(cars_.size(), 0));
    for (int step = 0; step < steps; ++step) {
      auto t0 = Clock::now();
      world_->stepSimulation(btScalar(opt_.dt), 1, btScalar(opt_.dt));
      stats.sim_ms += ms_since(t0);
      t0 = Clock::now();
      stats.contacts += apply_impulses();
      for (auto& car : cars_)
        if (car.dirty) {
          update_shape(car);
          ++stats.reblends;
        }
      stats.deform_ms += ms_since(t0);
      if (opt_.monitor) monitor(step, stats, tunnelled);
    }
    stats.steps = steps;
    uint64_t hash = spx::kFnvOffset;
    for (const auto& car : cars_) {
      const btTransform& t = car.body->getWorldTransform();
      btScalar m[16];
      t.getOpenGLMatrix(m);
      hash = spx::fnv1a(hash, m, sizeof m);
      hash = spx::fnv1a(hash, car.weights.data(), car.weights.size() * sizeof(float));
      const size_t p = asset_.poses.size();
      for (size_t s = 0; s * p < car.weights.size(); ++s) {
        stats.max_weight_moved = std::max(stats.max_weight_moved, 1.0 - car.weights[s * p]);
        double sum = 0;
        for (size_t k = 0; k < p; ++k) {
          sum += car.weights[s * p + k];
          stats.simplex_error = std::max(stats.simplex_error, -double(car.weights[s * p + k]));
        }
        stats.simplex_error = std::max(stats.simplex_error, std::abs(sum - 1));
      }
    }
    stats.state_hash = hash;
    if (opt_.monitor)
      for (size_t i = 0; i < cars_.size(); ++i)
        for (size_t j = 0; j < cars_.size(); ++j) stats.car_tunnels += tunnelled[i][j];
    return stats;
  }

 private:
  void add_static(std::unique_ptr<btCollisionShape> shape, const btTransform& where) {
    btRigidBody::btRigidBodyConstructionInfo info(0, nullptr, shape.get());
    info.m_startWorldTransform = where;
    info.m_friction = 0.3f;
    info.m_restitution = 0.1f;
    statics_.push_back(std::make_unique<btRigidBody>(info));
    world_->addRigidBody(statics_.back().get());
    static_shapes_.push_back(std::move(shape));
  }

  // Ground (the plane z = 0) and two wedge ramps facing each other across the middle; cars from
  // -x and +x ride up them and meet in the air above x = 0.
  void add_ground_and_ramps() {
    btTransform t;
    t.setIdentity();
    // A plane, not a box: GImpact tests a plane against vertices, a box against every triangle,
    // and the baseline deserves its fast path.
    add_static(std::make_unique<GroundPlane>(5000.0), t);
    // Ramps: boxes tilted about y, the top face rising from below the ground to ramp_height_
    // at ramp_gap_ from the middle.
    const double pitch = std::atan2(ramp_height_, ramp_length_), thickness = 0.6, overrun = 0.6;
    const double top_length = std::hypot(ramp_length_, ramp_height_) + overrun;
    for (int side : {-1, 1}) {
      // Middle of the top face, then half the thickness down along the face's normal.
      const double along = top_length / 2;
      const Eigen::Vector3d high(side * ramp_gap_, 0, ramp_height_);
      const Eigen::Vector3d down_slope(side * std::cos(pitch), 0, -std::sin(pitch));
      const Eigen::Vector3d normal(side * std::sin(pitch), 0, std::cos(pitch));
      t.setIdentity();
      t.setRotation(btQuaternion(btVector3(0, 1, 0), btScalar(side * pitch)));
      t.setOrigin(bt(high + along * down_slope - thickness / 2 * normal));
      add_static(std::make_unique<btBoxShape>(btVector3(btScalar(top_length / 2), btScalar(ramp_width_ / 2),
                                                        btScalar(thickness / 2))),
                 t);
    }
  }

  void add_car(int index) {
    Car car;
    const size_t p = asset_.poses.size(), sites = asset_.proxy->site_count();
    car.weights.assign(sites * p, 0.0f);
    for (size_t s = 0; s < sites; ++s) car.weights[s * p] = 1;  // the rest pose everywhere
    if (asset_.spheres) {
      // The same shape for both proxy configurations; only the sphere-set one registers
      // spx::bullet's algorithms, so the other collides through Bullet's compound algorithms.
      car.shape = std::make_unique<bullet::SphereSetShape>(asset_.proxy->sphere_count());
    } else {
      car.vertices.resize(3 * asset_.rest.vertices.size());
      car.mesh_array = std::make_unique<btTriangleIndexVertexArray>(
          int(asset_.rest.triangles.size()), indices_.data(), int(3 * sizeof(int)), int(asset_.rest.vertices.size()),
          car.vertices.data(), int(3 * sizeof(btScalar)));
      car.shape = std::make_unique<btGImpactMeshShape>(car.mesh_array.get());
      car.shape->setMargin(0.02f);
    }
    update_shape(car);

    // Lanes across y; even cars start on the -x side heading +x, odd ones face them from +x.
    const int lane = index / 2, lanes = (opt_.cars + 1) / 2;
    const int side = index % 2 == 0 ? -1 : 1;
    const double y = (lane - (lanes - 1) / 2.0) * lane_spacing_ + 0.45 * jitter(opt_.seed, index, 0);
    const double yaw = (side < 0 ? 0 : M_PI) + 0.06 * jitter(opt_.seed, index, 1);
    const double speed = opt_.speed_scale * (launch_speed_ + 1.0 * jitter(opt_.seed, index, 2));
    const double rest_height = asset_.com.z() - asset_.rest.bounds().min().z();
    btTransform start;
    start.setIdentity();
    start.setRotation(btQuaternion(btVector3(0, 0, 1), btScalar(yaw)));
    start.setOrigin(btVector3(btScalar(side * start_distance_), btScalar(y), btScalar(rest_height + 0.02)));
    btRigidBody::btRigidBodyConstructionInfo info(btScalar(asset_.mass), nullptr, car.shape.get(), bt(asset_.inertia));
    info.m_startWorldTransform = start;
    info.m_friction = 0.6f;
    info.m_restitution = 0.1f;
    car.body = std::make_unique<btRigidBody>(info);
    car.body->setLinearVelocity(btVector3(btScalar(speed * std::cos(yaw)), btScalar(speed * std::sin(yaw)), 0));
    car.body->setUserIndex(index);
    world_->addRigidBody(car.body.get());
    cars_.push_back(std::move(car));
  }

  // Body-frame mesh of a car for its current weights (the baseline's collision mesh, and the
  // reference the error is measured against).
  void blend_vertices(const Car& car, float* out) const {
    const size_t p = asset_.poses.size();
    for (size_t v = 0; v < asset_.rest.vertices.size(); ++v) {
      const float* w = &car.weights[asset_.vertex_site[v] * p];
      Eigen::Vector3d x = -asset_.com;
      for (size_t k = 0; k < p; ++k)
        if (w[k] != 0) x += double(w[k]) * asset_.poses[k].vertices[v];
      out[3 * v] = float(x.x());
      out[3 * v + 1] = float(x.y());
      out[3 * v + 2] = float(x.z());
    }
  }

  void update_shape(Car& car) {
    car.dirty = false;
    if (!asset_.spheres) {
      blend_vertices(car, car.vertices.data());
      auto* mesh = static_cast<btGImpactMeshShape*>(car.shape.get());
      mesh->postUpdate();
      mesh->updateBound();  // refit the GImpact box tree
      return;
    }
    bullet::blend_local(*static_cast<bullet::SphereSetShape*>(car.shape.get()), *asset_.proxy, car.weights.data(),
                        car.weights.size(), bt(asset_.com));
  }

  // A car's spheres in its body frame, as its collision shape holds them.
  SphereSet body_spheres(const Car& car) const {
    SphereSet out;
    const auto& shape = *static_cast<const bullet::SphereSetShape*>(car.shape.get());
    for (int j = 0; j < int(shape.sphere_count()); ++j)
      out.push_back({eig(shape.center(j)), double(shape.radius(j))});
    return out;
  }

  // The plastic rule: per car and per object it touched, the step's impulses are summed; above
  // the threshold, the sites near the impulse-weighted contact point move their weights toward
  // the example whose dent matches the push. Returns the contact points seen.
  uint64_t apply_impulses() {
    uint64_t contacts = 0;
    hits_.clear();
    const int manifolds = dispatcher_->getNumManifolds();
    for (int m = 0; m < manifolds; ++m) {
      const btPersistentManifold* manifold = dispatcher_->getManifoldByIndexInternal(m);
      const int points = manifold->getNumContacts();
      if (points == 0) continue;
      contacts += uint64_t(points);
      const btCollisionObject* objects[2] = {manifold->getBody0(), manifold->getBody1()};
      for (int a = 0; a < 2; ++a) {
        const int car = objects[a]->getUserIndex();
        if (car < 0) continue;
        Hit* hit = find_hit(car, objects[1 - a]);
        for (int c = 0; c < points; ++c) {
          const btManifoldPoint& pt = manifold->getContactPoint(c);
          const double j = pt.getAppliedImpulse();
          if (j <= 0) continue;
          // The normal points from body 1 to body 0: it pushes body 0 along +n, body 1 along -n.
          const Eigen::Vector3d n = eig(pt.m_normalWorldOnB) * (a == 0 ? 1.0 : -1.0);
          hit->impulse += j;
          hit->point += j * eig(a == 0 ? pt.getPositionWorldOnA() : pt.getPositionWorldOnB());
          hit->push += j * n;
        }
      }
    }
    for (const Hit& hit : hits_)
      if (hit.impulse > opt_.impulse_threshold) dent(cars_[size_t(hit.car)], hit);
    return contacts;
  }

  Hit* find_hit(int car, const btCollisionObject* other) {
    for (Hit& h : hits_)
      if (h.car == car && h.other == other) return &h;
    hits_.push_back(Hit{car, other});
    return &hits_.back();
  }

  void dent(Car& car, const Hit& hit) {
    const btTransform& frame = car.body->getWorldTransform();
    const Eigen::Vector3d point = eig(frame.invXform(bt(hit.point / hit.impulse))) + asset_.com;
    const Eigen::Vector3d push = eig(frame.getBasis().transpose() * bt(hit.push));
    const int pose = match_dent(asset_.dents, point, push, asset_.length);
    if (pose == 0) return;
    const double strength = std::min(1.0, (hit.impulse - opt_.impulse_threshold) / opt_.impulse_scale);
    const size_t p = asset_.poses.size();
    const float* sites = asset_.proxy->site_positions();
    for (size_t s = 0; s < asset_.proxy->site_count(); ++s) {
      const double d = (Eigen::Vector3d(sites[3 * s], sites[3 * s + 1], sites[3 * s + 2]) - point).norm();
      if (d >= opt_.dent_radius) continue;
      const double falloff = (1 - d / opt_.dent_radius) * (1 - d / opt_.dent_radius);
      const float a = float(std::min(opt_.max_step, strength * falloff));
      // A convex step toward the example: weights stay non-negative and sum to one.
      float* w = &car.weights[s * p];
      for (size_t k = 0; k < p; ++k) w[k] = (1 - a) * w[k] + (k == size_t(pose) ? a : 0.0f);
    }
    car.dirty = true;
  }

  double energy() const {
    double e = 0;
    for (const auto& car : cars_) {
      const btRigidBody& b = *car.body;
      const Eigen::Vector3d v = eig(b.getLinearVelocity()), w = eig(b.getAngularVelocity());
      const btMatrix3x3& r = b.getWorldTransform().getBasis();
      const Eigen::Vector3d w_local = eig(r.transpose() * bt(w));
      e += 0.5 * asset_.mass * v.squaredNorm() + 0.5 * w_local.dot(asset_.inertia.cwiseProduct(w_local)) +
           asset_.mass * gravity_ * b.getWorldTransform().getOrigin().z();
    }
    return e;
  }

  TriMesh deformed_mesh(const Car& car) const {
    std::vector<float> xyz(3 * asset_.rest.vertices.size());
    blend_vertices(car, xyz.data());
    TriMesh mesh;
    mesh.triangles = asset_.rest.triangles;
    for (size_t v = 0; v < asset_.rest.vertices.size(); ++v) mesh.vertices.emplace_back(xyz[3 * v], xyz[3 * v + 1], xyz[3 * v + 2]);
    return mesh;
  }

  // What a person watching would check, measured outside the timed regions.
  void monitor(int step, RunStats& stats, std::vector<std::vector<char>>& tunnelled) {
    for (int m = 0; m < dispatcher_->getNumManifolds(); ++m) {
      const btPersistentManifold* manifold = dispatcher_->getManifoldByIndexInternal(m);
      for (int c = 0; c < manifold->getNumContacts(); ++c)
        stats.max_contact_penetration =
            std::max(stats.max_contact_penetration, -double(manifold->getContactPoint(c).getDistance()));
    }
    const double e = energy();
    stats.energy_finite = stats.energy_finite && std::isfinite(e);
    stats.max_energy_ratio = std::max(stats.max_energy_ratio, e / initial_energy_);

    std::vector<TriMesh> meshes;
    for (const auto& car : cars_) meshes.push_back(deformed_mesh(car));
    for (size_t i = 0; i < cars_.size(); ++i) {
      const btTransform& frame = cars_[i].body->getWorldTransform();
      for (const auto& v : meshes[i].vertices)
        stats.max_ground_penetration = std::max(stats.max_ground_penetration, -double((frame * bt(v)).z()));
      if (frame.getOrigin().z() < 0 && !below_ground_.count(i)) {
        below_ground_.insert(i);
        ++stats.ground_tunnels;
      }
    }
    for (size_t i = 0; i < cars_.size(); ++i)
      for (size_t j = 0; j < cars_.size(); ++j) {
        if (i == j || tunnelled[i][j]) continue;
        btVector3 lo_i, hi_i, lo_j, hi_j;
        cars_[i].body->getAabb(lo_i, hi_i);
        cars_[j].body->getAabb(lo_j, hi_j);
        if (!TestAabbAgainstAabb2(lo_i, hi_i, lo_j, hi_j)) continue;
        const btVector3 center_in_j = cars_[j].body->getWorldTransform().invXform(cars_[i].body->getWorldTransform().getOrigin());
        if (winding_number_exact(meshes[j], eig(center_in_j)) > 0.5) tunnelled[i][j] = 1;
      }
    if (step % opt_.sample_every != 0) return;
    stats.sample_times.push_back((step + 1) * opt_.dt);
    for (size_t i = 0; i < cars_.size(); ++i) stats.path[i].push_back(eig(cars_[i].body->getWorldTransform().getOrigin()));
    if (asset_.spheres) {
      for (size_t i = 0; i < cars_.size(); ++i) {
        const Car& car = cars_[i];
        const ErrorStats err = vertex_error(meshes[i], body_spheres(car));
        stats.error[i].median.push_back(err.median);
        stats.error[i].max.push_back(err.max);
      }
    }
  }

  const CarAsset& asset_;
  const SceneOptions opt_;
  const double gravity_ = 9.81;
  const double ramp_gap_ = 12, ramp_length_ = 8, ramp_height_ = 2.2, ramp_width_ = 20;
  const double lane_spacing_ = 4, start_distance_ = 28, launch_speed_ = 18;

  btDefaultCollisionConfiguration config_;
  std::unique_ptr<btCollisionDispatcher> dispatcher_;
  btDbvtBroadphase broadphase_;
  btSequentialImpulseConstraintSolver solver_;
  std::unique_ptr<btDiscreteDynamicsWorld> world_;
  std::vector<int> indices_;
  std::vector<std::unique_ptr<btCollisionShape>> static_shapes_;
  std::vector<std::unique_ptr<btRigidBody>> statics_;
  std::vector<Car> cars_;
  std::vector<Hit> hits_;
  std::set<size_t> below_ground_;
  double initial_energy_ = 1;
};

}  // namespace

int match_dent(const std::vector<Dent>& dents, const Eigen::Vector3d& point, const Eigen::Vector3d& direction,
               double length_scale) {
  if (direction.norm() == 0) return 0;
  const Eigen::Vector3d push = direction.normalized();
  int best = 0;
  double best_score = -1e300;
  for (size_t k = 1; k < dents.size(); ++k) {
    const double along = dents[k].direction.dot(push);
    if (along < 0.5) continue;  // this example dents another way
    const double score = along - (point - dents[k].center).norm() / length_scale;
    if (score > best_score) {
      best_score = score;
      best = int(k);
    }
  }
  return best;
}

CarAsset make_car_asset(std::string name, bool spheres, const Proxy& proxy, const std::vector<TriMesh>& poses) {
  if (proxy.empty()) fail_usage(name, "the proxy is empty");
  if (poses.size() != proxy.pose_count())
    fail_input(name, "the proxy has " + std::to_string(proxy.pose_count()) + " poses but " +
                         std::to_string(poses.size()) + " meshes were given (rest + examples)");
  for (const auto& pose : poses)
    if (pose.vertices.size() != poses[0].vertices.size() || pose.triangles != poses[0].triangles)
      fail_input(name, "the pose meshes do not share the rest mesh's topology");
  CarAsset a;
  a.name = std::move(name);
  a.spheres = spheres;
  a.proxy = &proxy;
  a.rest = poses[0];
  a.poses = poses;
  a.com = volume_centroid(a.rest);
  const Eigen::Vector3d size = a.rest.bounds().sizes();
  a.length = size.maxCoeff();
  a.inertia = a.mass / 12 * Eigen::Vector3d(size.y() * size.y() + size.z() * size.z(),
                                            size.x() * size.x() + size.z() * size.z(),
                                            size.x() * size.x() + size.y() * size.y());
  const float* sites = proxy.site_positions();
  for (const auto& v : a.rest.vertices) {
    uint32_t best = 0;
    double best_d = 1e300;
    for (uint32_t s = 0; s < proxy.site_count(); ++s) {
      const double d = (Eigen::Vector3d(sites[3 * s], sites[3 * s + 1], sites[3 * s + 2]) - v).squaredNorm();
      if (d < best_d) {
        best_d = d;
        best = s;
      }
    }
    a.vertex_site.push_back(best);
  }
  a.dents.resize(poses.size());
  for (size_t k = 1; k < poses.size(); ++k) a.dents[k] = dent_of(a.rest, poses[k]);
  return a;
}

RunStats run_scene(const CarAsset& asset, const SceneOptions& options) {
  World world(asset, options);
  return world.run();
}

}  // namespace spx::crash
