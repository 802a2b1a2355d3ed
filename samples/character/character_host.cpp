#include "character_host.hpp"

#include <btBulletDynamicsCommon.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <random>

#include "core/error.hpp"
#include "extract/asset.hpp"
#include "mesh/mesh_query.hpp"
#include "spx_bullet.hpp"

namespace spx::character {
namespace {

double ms_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::nth_element(v.begin(), v.begin() + long(v.size() / 2), v.end());
  return v[v.size() / 2];
}

// The asset's joint for each of the proxy's skin joints, as a host binds its skeleton: by name.
std::vector<size_t> joint_order(const Asset& asset, const Proxy& proxy) {
  std::vector<std::string> names;
  for (uint32_t j = 0; j < proxy.joint_count(); ++j) names.emplace_back(proxy.joint_name(j));
  return asset.joints_named(names);
}

class Scene {
 public:
  Scene(const Asset& asset, const Proxy& proxy, const SceneOptions& opt)
      : asset_(asset), proxy_(proxy), opt_(opt), order_(joint_order(asset, proxy)), shape_(proxy.sphere_count()) {
    if (!proxy.has_skin()) fail_usage("proxy", "has no skin: make it from poses with a rig (pose-extract --animation)");
    if (opt.clip >= asset.clips().size()) fail_usage("--animation", "the asset has no such clip");
    clip_seconds_ = asset.clips()[opt.clip].end;
    // Metres: the body (at rest) opt.body_height tall along +Y, glTF's up.
    Eigen::AlignedBox3d box;
    for (const auto& v : asset.rest()) box.extend(v);
    scale_ = opt.body_height / std::max(box.sizes().y(), 1e-12);
    dispatcher_ = std::make_unique<btCollisionDispatcher>(&config_);
    bullet::register_sphere_set_algorithms(*dispatcher_);
    world_ = std::make_unique<btDiscreteDynamicsWorld>(dispatcher_.get(), &broadphase_, &solver_, &config_);
    world_->setGravity(btVector3(0, -9.81f, 0));
    add_ground(btScalar(box.min().y() * scale_));
    add_body();
  }

  ~Scene() {
    for (auto& b : bodies_) world_->removeRigidBody(b.get());
  }

  RunStats run() {
    RunStats stats;
    stats.clip_seconds = clip_seconds_;
    std::mt19937 rng(opt_.seed);
    const int frames = int(std::lround(opt_.seconds / opt_.dt));
    const int drop_every = std::max(1, int(std::lround(opt_.drop_every / opt_.dt)));
    std::vector<double> to_mesh, animate, skin, step;
    for (int f = 0; f < frames; ++f) {
      const double t = clip_seconds_ > 0 ? std::fmod(f * opt_.dt, clip_seconds_) : 0.0;
      auto start = std::chrono::steady_clock::now();
      matrices_at(t);
      animate.push_back(ms_since(start));
      start = std::chrono::steady_clock::now();
      skin_body();
      skin.push_back(ms_since(start));
      if (f % drop_every == 0 && stats.objects_dropped < opt_.objects) drop_object(stats.objects_dropped++, rng);
      start = std::chrono::steady_clock::now();
      world_->stepSimulation(btScalar(opt_.dt), 1, btScalar(opt_.dt));
      step.push_back(ms_since(start));
      const size_t before = to_mesh.size();
      const bool check = opt_.check_every > 0 && f % opt_.check_every == 0;
      const uint64_t points = body_contacts(check ? &to_mesh : nullptr, t);
      stats.body_contacts += points;
      stats.frames_with_contact += points > 0;
      stats.contacts_checked += to_mesh.size() - before;
    }
    stats.frames = frames;
    stats.animate_ms = median(animate), stats.skin_ms = median(skin), stats.step_ms = median(step);
    count_objects(stats);
    stats.contact_to_mesh_median = median(to_mesh);
    stats.contact_to_mesh_max = to_mesh.empty() ? 0.0 : *std::max_element(to_mesh.begin(), to_mesh.end());
    for (uint32_t i = 0; i < shape_.sphere_count(); ++i) stats.zero_radius_spheres += !shape_.active(int(i));
    return stats;
  }

 private:
  // The host's animation system: the clip's joint matrices at t, in the skin's joint order.
  void matrices_at(double t) {
    const std::vector<Eigen::Matrix4d> all = asset_.joint_matrices(opt_.clip, t);
    matrices_.resize(16 * order_.size());
    for (size_t j = 0; j < order_.size(); ++j)
      for (int k = 0; k < 16; ++k) matrices_[16 * j + size_t(k)] = float(all[order_[j]](k % 4, k / 4));
  }

  // The spheres skinned by those matrices, in metres, into the kinematic body's shape.
  void skin_body() {
    xyzr_.resize(4 * size_t(proxy_.sphere_count()));
    if (const Status s = spx::skin(proxy_, matrices_.data(), int(order_.size()), xyzr_.data()); s != SPX_OK)
      fail_input(asset_.path(), std::string("its clip's joint matrices do not skin the proxy: ") + status_string(s));
    for (float& x : xyzr_) x *= float(scale_);
    shape_.set_spheres_xyzr(xyzr_.data());
    world_->updateSingleAabb(body_);
  }

  void add_ground(btScalar height) {
    ground_shape_ = std::make_unique<btStaticPlaneShape>(btVector3(0, 1, 0), height);
    add_rigid(0, ground_shape_.get(), btVector3(0, 0, 0));
  }

  void add_body() {
    body_ = add_rigid(0, &shape_, btVector3(0, 0, 0));
    body_->setCollisionFlags(body_->getCollisionFlags() | btCollisionObject::CF_KINEMATIC_OBJECT);
    body_->setActivationState(DISABLE_DEACTIVATION);
  }

  btRigidBody* add_rigid(btScalar mass, btCollisionShape* shape, const btVector3& at) {
    btVector3 inertia(0, 0, 0);
    if (mass > 0) shape->calculateLocalInertia(mass, inertia);
    btTransform pose;
    pose.setIdentity();
    pose.setOrigin(at);
    auto body = std::make_unique<btRigidBody>(mass, nullptr, shape, inertia);
    body->setWorldTransform(pose);
    body->setFriction(0.6f);
    world_->addRigidBody(body.get());
    bodies_.push_back(std::move(body));
    return bodies_.back().get();
  }

  // A box or a ball, 10 to 25 cm, dropped from above the body's spheres at a random place over them.
  void drop_object(int n, std::mt19937& rng) {
    btVector3 lo, hi;
    shape_.getAabb(body_->getWorldTransform(), lo, hi);
    std::uniform_real_distribution<double> u(0, 1), size(0.1, 0.25);
    const btScalar s = btScalar(size(rng) / 2);
    const btVector3 at(btScalar(lo.x() + u(rng) * (hi.x() - lo.x())), hi.y() + btScalar(1.0),
                       btScalar(lo.z() + u(rng) * (hi.z() - lo.z())));
    if (n % 2) {
      object_shapes_.push_back(std::make_unique<btBoxShape>(btVector3(s, s, s)));
    } else {
      object_shapes_.push_back(std::make_unique<btSphereShape>(s));
    }
    objects_.push_back(add_rigid(btScalar(8 * s * s * s * 500), object_shapes_.back().get(), at));
  }

  // Contact points between the body and the objects this frame; with `to_mesh`, each point's
  // distance to the body's skinned mesh at t (in metres).
  uint64_t body_contacts(std::vector<double>* to_mesh, double t) {
    uint64_t points = 0;
    std::unique_ptr<MeshQuery> mesh;
    btDispatcher* d = world_->getDispatcher();
    for (int m = 0; m < d->getNumManifolds(); ++m) {
      const btPersistentManifold* manifold = d->getManifoldByIndexInternal(m);
      const bool first = manifold->getBody0() == body_;
      if (!first && manifold->getBody1() != body_) continue;
      for (int p = 0; p < manifold->getNumContacts(); ++p) {
        const btManifoldPoint& point = manifold->getContactPoint(p);
        if (point.getDistance() > 0) continue;
        ++points;
        if (!to_mesh) continue;
        if (!mesh) mesh = std::make_unique<MeshQuery>(TriMesh{asset_.at_time(opt_.clip, t), asset_.triangles()});
        const btVector3& on_body = first ? point.getPositionWorldOnA() : point.getPositionWorldOnB();
        const Eigen::Vector3d q(on_body.x(), on_body.y(), on_body.z());
        to_mesh->push_back(mesh->distance(q / scale_) * scale_);
      }
    }
    return points;
  }

  // At the end: objects resting on the body (touching it), and those that fell to the ground.
  void count_objects(RunStats& stats) const {
    btDispatcher* d = world_->getDispatcher();
    for (const btRigidBody* object : objects_) {
      bool on_body = false;
      for (int m = 0; m < d->getNumManifolds(); ++m) {
        const btPersistentManifold* manifold = d->getManifoldByIndexInternal(m);
        const bool pair = (manifold->getBody0() == object && manifold->getBody1() == body_) ||
                          (manifold->getBody1() == object && manifold->getBody0() == body_);
        if (pair && manifold->getNumContacts() > 0) on_body = true;
      }
      stats.objects_on_body += on_body;
      stats.objects_fell_off += !on_body;
    }
  }

  const Asset& asset_;
  const Proxy& proxy_;
  const SceneOptions& opt_;
  std::vector<size_t> order_;
  double clip_seconds_ = 0, scale_ = 1;
  std::vector<float> matrices_, xyzr_;
  btDefaultCollisionConfiguration config_;
  std::unique_ptr<btCollisionDispatcher> dispatcher_;
  btDbvtBroadphase broadphase_;
  btSequentialImpulseConstraintSolver solver_;
  std::unique_ptr<btDiscreteDynamicsWorld> world_;
  bullet::SphereSetShape shape_;
  std::unique_ptr<btStaticPlaneShape> ground_shape_;
  std::vector<std::unique_ptr<btCollisionShape>> object_shapes_;
  std::vector<std::unique_ptr<btRigidBody>> bodies_;
  std::vector<btRigidBody*> objects_;
  btRigidBody* body_ = nullptr;
};

}  // namespace

RunStats run_scene(const Asset& asset, const Proxy& proxy, const SceneOptions& options) {
  return Scene(asset, proxy, options).run();
}

}  // namespace spx::character
