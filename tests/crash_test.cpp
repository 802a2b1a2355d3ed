// The Bullet crash host: dents matched to impacts, plastic weights kept on the simplex, runs
// repeatable to the bit, no tunnelling at the default step, error over time bounded.
#include <gtest/gtest.h>

#include "core/error.hpp"
#include "crash_host.hpp"
#include "io/spx_writer.hpp"
#include "posemap/posemap.hpp"
#include "synthetic/synthetic.hpp"
#include "test_util.hpp"

using namespace spx;
using namespace spx::crash;

namespace {

struct CarProxy {
  std::vector<TriMesh> meshes;  // rest + examples
  Proxy proxy;
};

// The car sample through the library's own chain, capped at `max_spheres`.
const CarProxy& car_proxy() {
  static const CarProxy car = [] {
    const SampleAsset asset = make_car();
    PackOptions popt;
    popt.max_spheres = 100;
    const SpheresFile spheres = test::pack_file(asset.rest, 64, popt);
    std::vector<PoseInput> poses;
    for (size_t i = 0; i < asset.pose_names.size(); ++i) poses.push_back({asset.pose_names[i], "", asset.pose(i)});
    const std::string bytes = encode_spx(pose_map(asset.rest, "rest", poses, spheres, {}).proxy);
    CarProxy out;
    out.meshes.push_back(asset.rest);
    for (size_t i = 0; i < asset.pose_names.size(); ++i) out.meshes.push_back(asset.pose(i));
    EXPECT_EQ(load_memory(bytes.data(), bytes.size(), &out.proxy), SPX_OK);
    return out;
  }();
  return car;
}

}  // namespace

TEST(CrashHost, ImpactsPickTheExampleDentedThatWay) {
  const CarProxy& car = car_proxy();
  const CarAsset a = make_car_asset("spheres", true, car.proxy, car.meshes);
  ASSERT_EQ(a.dents.size(), 5u);  // rest + front, rear, side, roof
  const Eigen::Vector3d lo = a.rest.bounds().min(), hi = a.rest.bounds().max(), mid = a.rest.bounds().center();
  EXPECT_EQ(match_dent(a.dents, {hi.x(), mid.y(), mid.z()}, {-1, 0, 0}, a.length), 1);  // nose pushed back
  EXPECT_EQ(match_dent(a.dents, {lo.x(), mid.y(), mid.z()}, {1, 0, 0}, a.length), 2);   // tail pushed forward
  EXPECT_EQ(match_dent(a.dents, {mid.x(), hi.y(), mid.z()}, {0, -1, 0}, a.length), 3);  // right door pushed in
  EXPECT_EQ(match_dent(a.dents, {mid.x(), mid.y(), hi.z()}, {0, 0, -1}, a.length), 4);  // roof pushed down
  EXPECT_EQ(match_dent(a.dents, {mid.x(), mid.y(), lo.z()}, {0, 0, 1}, a.length), 0);   // no example dents upward
  EXPECT_EQ(match_dent(a.dents, {mid.x(), lo.y(), mid.z()}, {0, 1, 0}, a.length), 0);   // nor the left side
}

TEST(CrashHost, VerticesTakeTheirNearestSite) {
  const CarProxy& car = car_proxy();
  const CarAsset a = make_car_asset("spheres", true, car.proxy, car.meshes);
  const float* sites = car.proxy.site_positions();
  for (size_t v = 0; v < a.rest.vertices.size(); v += 17) {
    auto dist = [&](uint32_t s) {
      return (Eigen::Vector3d(sites[3 * s], sites[3 * s + 1], sites[3 * s + 2]) - a.rest.vertices[v]).norm();
    };
    for (uint32_t s = 0; s < car.proxy.site_count(); ++s) EXPECT_LE(dist(a.vertex_site[v]), dist(s) + 1e-12);
  }
}

TEST(CrashHost, MismatchedPosesAreRejected) {
  const CarProxy& car = car_proxy();
  std::vector<TriMesh> fewer(car.meshes.begin(), car.meshes.end() - 1);
  EXPECT_THROW(make_car_asset("spheres", true, car.proxy, fewer), Error);
  std::vector<TriMesh> other = car.meshes;
  std::swap(other[2].triangles[0][0], other[2].triangles[0][1]);
  EXPECT_THROW(make_car_asset("spheres", true, car.proxy, other), Error);
}

// The crash happens in the air at about 1.6 s; 2.5 s covers it and the landing.
void expect_sane_crash(bool spheres, bool sphere_set = false) {
  const CarProxy& car = car_proxy();
  CarAsset a = make_car_asset(spheres ? "spheres" : "triangle-mesh", spheres, car.proxy, car.meshes);
  a.sphere_set = sphere_set;
  SceneOptions opt;
  opt.seconds = 2.5;
  opt.monitor = true;
  const RunStats first = run_scene(a, opt);
  opt.monitor = false;
  const RunStats second = run_scene(a, opt);
  EXPECT_EQ(first.state_hash, second.state_hash) << "same inputs, same bits";
  EXPECT_EQ(first.steps, 150);
  EXPECT_GT(first.contacts, 0u);
  EXPECT_GT(first.reblends, 0u) << "the crash must dent the cars";
  EXPECT_GT(first.max_weight_moved, 0.1);
  EXPECT_LT(first.simplex_error, 1e-5) << "weights stay non-negative and sum to one";
  EXPECT_EQ(first.ground_tunnels, 0);
  EXPECT_EQ(first.car_tunnels, 0);
  EXPECT_FALSE(first.energy_blew_up()) << first.max_energy_ratio;
  EXPECT_LT(first.max_ground_penetration, 0.3);
  if (spheres) {
    ASSERT_EQ(first.error.size(), 8u);
    for (const auto& trace : first.error) {
      ASSERT_EQ(trace.median.size(), first.sample_times.size());
      for (size_t i = 0; i < trace.median.size(); ++i) {
        EXPECT_LT(trace.median[i], 0.1) << "median vertex-to-union error, m";
        EXPECT_LT(trace.max[i], 0.5) << "max vertex-to-union error, m";
      }
    }
  }
}

TEST(CrashHost, SphereProxiesCrashRepeatablyWithoutTunnelling) { expect_sane_crash(true); }
TEST(CrashHost, SphereSetProxiesCrashRepeatablyWithoutTunnelling) { expect_sane_crash(true, true); }
TEST(CrashHost, TriangleMeshesCrashRepeatablyWithoutTunnelling) { expect_sane_crash(false); }

// spx::bullet's sphere set against brute force and against Bullet's own compound algorithm:
// a random sphere set dropped into a tilted box and onto a plane, in many placements; the
// deepest contact must be the deepest sphere, and a contact must exist exactly when a sphere
// comes within reach.
#include <BulletCollision/CollisionDispatch/btCollisionWorld.h>
#include <btBulletCollisionCommon.h>

#include <random>

#include "io/proxy_file.hpp"
#include "io/spx_writer.hpp"
#include "spx_bullet.hpp"

namespace {

double deepest(btCollisionWorld& world) {
  world.performDiscreteCollisionDetection();
  double best = 1e9;
  btDispatcher* d = world.getDispatcher();
  for (int m = 0; m < d->getNumManifolds(); ++m) {
    const btPersistentManifold* manifold = d->getManifoldByIndexInternal(m);
    for (int c = 0; c < manifold->getNumContacts(); ++c)
      best = std::min(best, double(manifold->getContactPoint(c).getDistance()));
  }
  return best;
}

}  // namespace

TEST(SphereSet, DeepestContactMatchesBruteForceAndBulletsCompound) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-1, 1);
  std::vector<btSphereShape> balls;
  balls.reserve(40);
  btCompoundShape compound;
  std::vector<btVector3> centers;
  for (int i = 0; i < 40; ++i) {
    balls.emplace_back(0.1f + 0.2f * std::abs(u(rng)));
    btTransform t;
    t.setIdentity();
    centers.emplace_back(u(rng), 0.5f * u(rng), 0.3f * u(rng));
    t.setOrigin(centers.back());
    compound.addChildShape(t, &balls.back());
  }
  spx::bullet::SphereSetShape set(40);
  {
    std::vector<float> c, r;
    for (int i = 0; i < 40; ++i) {
      for (int a = 0; a < 3; ++a) c.push_back(centers[size_t(i)][a]);
      r.push_back(balls[size_t(i)].getRadius());
    }
    set.set_spheres(c.data(), r.data());
  }
  btBoxShape box(btVector3(2, 1.5f, 0.4f));
  btStaticPlaneShape plane(btVector3(0.1f, -0.2f, 1).normalized(), 0.3f);
  int compared = 0, touching = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const bool use_plane = trial % 2 == 1;
    btCollisionShape* other = use_plane ? static_cast<btCollisionShape*>(&plane) : &box;
    btTransform where_set, where_other;
    where_set.setIdentity();
    where_set.setRotation(btQuaternion(btVector3(u(rng), u(rng), u(rng)).normalized(), 3 * u(rng)));
    where_set.setOrigin(btVector3(0.6f * u(rng), 0.6f * u(rng), 0.9f + 0.9f * u(rng)));
    where_other.setIdentity();
    where_other.setRotation(btQuaternion(btVector3(0.3f, 1, 0.2f).normalized(), 0.4f * u(rng)));

    // Brute force: the smallest signed distance from any sphere to the other shape.
    double brute = 1e9;
    for (size_t i = 0; i < centers.size(); ++i) {
      const btVector3 c = where_set * centers[i];
      const double r = balls[i].getRadius();
      if (use_plane) {
        const btVector3 n = where_other.getBasis() * plane.getPlaneNormal();
        brute = std::min(brute, double(n.dot(c) - plane.getPlaneConstant() - n.dot(where_other.getOrigin())) - r);
      } else {
        const btVector3 p = where_other.invXform(c), h = box.getHalfExtentsWithMargin();
        btVector3 q = p;
        q.setMax(-h);
        q.setMin(h);
        const bool inside = q == p;
        double d = (p - q).length();
        if (inside) {
          d = 1e9;
          for (int a = 0; a < 3; ++a) d = std::min(d, double(h[a] - std::abs(p[a])));
          d = -d;
        }
        brute = std::min(brute, d - r);
      }
    }

    double ours = 1e9, bullets = 1e9;
    for (int kind = 0; kind < 2; ++kind) {
      btDefaultCollisionConfiguration config;
      btCollisionDispatcher dispatcher(&config);
      // Registered for both: the plain compound must still take Bullet's own path.
      spx::bullet::register_sphere_set_algorithms(dispatcher);
      btDbvtBroadphase broadphase;
      btCollisionWorld world(&dispatcher, &broadphase, &config);
      btCollisionObject a, b;
      a.setCollisionShape(kind == 0 ? static_cast<btCollisionShape*>(&set) : &compound);
      a.setWorldTransform(where_set);
      b.setCollisionShape(other);
      b.setWorldTransform(where_other);
      world.addCollisionObject(&a);
      world.addCollisionObject(&b);
      (kind == 0 ? ours : bullets) = deepest(world);
      world.removeCollisionObject(&a);
      world.removeCollisionObject(&b);
    }
    if (brute < -0.05) {  // clearly touching: both must report the deepest sphere
      ++touching;
      EXPECT_NEAR(ours, brute, 1e-4) << "trial " << trial;
      if (bullets < 1e8) {
        EXPECT_NEAR(ours, bullets, 2e-3) << "trial " << trial;
        ++compared;
      }
    } else if (brute > 0.05) {
      EXPECT_GT(ours, 1e8) << "no contact when every sphere is clear, trial " << trial;
    }
  }
  EXPECT_GT(touching, 40);
  EXPECT_GT(compared, 40);
}

namespace {

// A random sphere set: centres in a box of half sizes `extent`, radii 0.1..0.3.
void random_set(std::mt19937& rng, int n, const btVector3& extent, std::vector<float>& c, std::vector<float>& r) {
  std::uniform_real_distribution<float> u(-1, 1);
  c.clear();
  r.clear();
  for (int i = 0; i < n; ++i) {
    for (int a = 0; a < 3; ++a) c.push_back(extent[a] * u(rng));
    r.push_back(0.1f + 0.2f * std::abs(u(rng)));
  }
}

btTransform random_frame(std::mt19937& rng, float spread) {
  std::uniform_real_distribution<float> u(-1, 1);
  btTransform t;
  t.setIdentity();
  t.setRotation(btQuaternion(btVector3(u(rng), u(rng), u(rng) + 0.01f).normalized(), 3 * u(rng)));
  t.setOrigin(btVector3(spread * u(rng), spread * u(rng), spread * u(rng)));
  return t;
}

// Every contact an algorithm reports before the manifold reduces them.
struct AllContacts : btCollisionWorld::ContactResultCallback {
  int count = 0;
  double deepest = 1e9;
  btScalar addSingleResult(btManifoldPoint& p, const btCollisionObjectWrapper*, int, int, const btCollisionObjectWrapper*,
                           int, int) override {
    ++count;
    deepest = std::min(deepest, double(p.getDistance()));
    return 0;
  }
};

}  // namespace

// Two deforming bodies: sphere set against sphere set. A closest-point query reports every pair
// within its distance (against brute force over all pairs); in simulation one manifold holds at
// most 4 points and keeps the deepest; Bullet's compound-compound path agrees on the depth.
TEST(SphereSet, PairContactsMatchBruteForceAndBulletsCompound) {
  std::mt19937 rng(5);
  int touching = 0, compared = 0;
  for (int trial = 0; trial < 150; ++trial) {
    std::vector<float> ca, ra, cb, rb;
    random_set(rng, 30, btVector3(1.2f, 0.6f, 0.4f), ca, ra);
    random_set(rng, 25, btVector3(1.0f, 0.5f, 0.5f), cb, rb);
    spx::bullet::SphereSetShape sa(30), sb(25);
    sa.set_spheres(ca.data(), ra.data());
    sb.set_spheres(cb.data(), rb.data());
    // The same spheres as plain compounds for Bullet's own algorithm.
    std::vector<btSphereShape> balls;
    balls.reserve(55);
    btCompoundShape pa, pb;
    for (int k = 0; k < 55; ++k) {
      const bool first = k < 30;
      const int i = first ? k : k - 30;
      const float* c = first ? &ca[3 * size_t(i)] : &cb[3 * size_t(i)];
      balls.emplace_back(first ? ra[size_t(i)] : rb[size_t(i)]);
      btTransform t;
      t.setIdentity();
      t.setOrigin(btVector3(c[0], c[1], c[2]));
      (first ? pa : pb).addChildShape(t, &balls.back());
    }
    const btTransform fa = random_frame(rng, 0.2f), fb = random_frame(rng, 1.4f);

    btDefaultCollisionConfiguration config;
    btCollisionDispatcher dispatcher(&config);
    spx::bullet::register_sphere_set_algorithms(dispatcher);
    btDbvtBroadphase broadphase;
    btCollisionWorld world(&dispatcher, &broadphase, &config);
    // A closest-point query reports pairs within its own distance; the simulation keeps contacts
    // within the manifold's breaking threshold.
    const btScalar query = 0.05f;
    const btScalar reach = std::min(sa.getContactBreakingThreshold(gContactBreakingThreshold),
                                    sb.getContactBreakingThreshold(gContactBreakingThreshold));
    double brute = 1e9;
    int within = 0;
    for (int i = 0; i < 30; ++i)
      for (int j = 0; j < 25; ++j) {
        const btVector3 a = fa * btVector3(ca[3 * i], ca[3 * i + 1], ca[3 * i + 2]);
        const btVector3 b = fb * btVector3(cb[3 * j], cb[3 * j + 1], cb[3 * j + 2]);
        const double d = double((a - b).length() - ra[size_t(i)] - rb[size_t(j)]);
        brute = std::min(brute, d);
        within += d <= query;
      }
    btCollisionObject a, b;
    a.setWorldTransform(fa);
    b.setWorldTransform(fb);
    auto run = [&](btCollisionShape* x, btCollisionShape* y) {
      a.setCollisionShape(x);
      b.setCollisionShape(y);
      world.addCollisionObject(&a);
      world.addCollisionObject(&b);
      const double d = deepest(world);
      int manifolds = 0, points = 0;
      for (int m = 0; m < dispatcher.getNumManifolds(); ++m) {
        ++manifolds;
        points = std::max(points, dispatcher.getManifoldByIndexInternal(m)->getNumContacts());
      }
      world.removeCollisionObject(&a);
      world.removeCollisionObject(&b);
      return std::make_tuple(d, manifolds, points);
    };
    const auto [ours, manifolds, points] = run(&sa, &sb);
    EXPECT_LE(manifolds, 1) << "trial " << trial;
    EXPECT_LE(points, 4) << "trial " << trial;
    AllContacts all;
    all.m_closestDistanceThreshold = query;
    a.setCollisionShape(&sa);
    b.setCollisionShape(&sb);
    world.contactPairTest(&a, &b, all);
    EXPECT_EQ(all.count, within) << "trial " << trial;
    if (brute < -0.02) {
      ++touching;
      EXPECT_NEAR(ours, brute, 1e-5) << "trial " << trial;
      EXPECT_NEAR(all.deepest, brute, 1e-5) << "trial " << trial;
      const double bullets = std::get<0>(run(&pa, &pb));
      if (bullets < 1e8) {
        EXPECT_NEAR(ours, bullets, 2e-3) << "trial " << trial;
        ++compared;
      }
    } else if (brute > reach) {
      EXPECT_GT(ours, 1e8) << "no contact when every pair is clear, trial " << trial;
    }
  }
  EXPECT_GT(touching, 40);
  EXPECT_GT(compared, 40);
}

// Any other compound in the world keeps Bullet's algorithm: a compound holding a box (which the
// sphere-set code would misread as spheres) still rests on the plane at the box's depth.
TEST(SphereSet, OtherCompoundsFallBackToBullet) {
  btDefaultCollisionConfiguration config;
  btCollisionDispatcher dispatcher(&config);
  spx::bullet::register_sphere_set_algorithms(dispatcher);
  btDbvtBroadphase broadphase;
  btCollisionWorld world(&dispatcher, &broadphase, &config);
  btBoxShape child(btVector3(0.5f, 0.5f, 0.5f));
  btCompoundShape compound;
  btTransform t;
  t.setIdentity();
  compound.addChildShape(t, &child);
  btStaticPlaneShape plane(btVector3(0, 0, 1), 0);
  btCollisionObject a, b;
  a.setCollisionShape(&compound);
  t.setOrigin(btVector3(0, 0, 0.45f));  // 5 cm into the plane
  a.setWorldTransform(t);
  b.setCollisionShape(&plane);
  world.addCollisionObject(&a);
  world.addCollisionObject(&b);
  EXPECT_NEAR(deepest(world), -0.05, 1e-3);
  world.removeCollisionObject(&a);
  world.removeCollisionObject(&b);
  EXPECT_FALSE(spx::bullet::SphereSetShape::is_sphere_set(&compound));
}

// The body helper writes the runtime's blend into the shape: centres less the origin, radii, and
// a sphere a blend leaves out (radius 0) parked and inactive.
TEST(SphereSet, BlendWritesTheRuntimeResult) {
  spx::ProxyModel model;
  for (int pose = 0; pose < 2; ++pose) {
    spx::ProxyPose p;
    p.name = pose ? "dent" : "rest";
    for (int s = 0; s < 5; ++s)
      p.spheres.push_back({Eigen::Vector3d(s, 0.5 * pose, 1), s == 4 && pose == 1 ? 0.0 : 0.2 + 0.1 * s});
    model.poses.push_back(p);
  }
  model.sites = {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(4, 0, 0)};
  model.sphere_sites = {0, 0, 0, 1, 1};
  const std::string bytes = spx::encode_spx(model);
  spx::Proxy proxy;
  ASSERT_EQ(spx::load_memory(bytes.data(), bytes.size(), &proxy), spx::SPX_OK);
  spx::bullet::SphereSetShape shape(proxy.sphere_count());
  const float w[2] = {0.25f, 0.75f};
  const btVector3 origin(1, 0, 0);
  ASSERT_EQ(spx::bullet::blend_global(shape, proxy, w, 2, origin), spx::SPX_OK);
  std::vector<float> c(15), r(5);
  ASSERT_EQ(spx::blend_global(proxy, w, 2, c.data(), r.data()), spx::SPX_OK);
  for (int s = 0; s < 5; ++s) {
    const btVector3 o = shape.getChildTransform(s).getOrigin();
    if (r[size_t(s)] > 0) {
      EXPECT_TRUE(shape.active(s));
      EXPECT_EQ(o, btVector3(c[3 * size_t(s)], c[3 * size_t(s) + 1], c[3 * size_t(s) + 2]) - origin);
      EXPECT_EQ(static_cast<const btSphereShape*>(shape.getChildShape(s))->getRadius(), r[size_t(s)]);
    } else {
      EXPECT_FALSE(shape.active(s));
    }
  }
  // Local blend: site 1 entirely in the dent pose, which drops sphere 4.
  const float local[4] = {1, 0, 0, 1};
  ASSERT_EQ(spx::bullet::blend_local(shape, proxy, local, 4), spx::SPX_OK);
  EXPECT_FALSE(shape.active(4));
  EXPECT_TRUE(shape.active(3));
  btVector3 lo, hi;
  shape.getAabb(btTransform::getIdentity(), lo, hi);
  EXPECT_NEAR(hi.x(), 3 + 0.5, 1e-5) << "the compound's box follows the spheres";
  // A weight vector of the wrong length leaves the shape as it was.
  EXPECT_EQ(spx::bullet::blend_global(shape, proxy, w, 1), spx::SPX_ERR_WEIGHT_COUNT);
  EXPECT_FALSE(shape.active(4));
  EXPECT_EQ(spx::bullet::blend_morph(shape, proxy, w, 2), spx::SPX_ERR_WEIGHT_COUNT) << "no weight for the rest";
  EXPECT_FALSE(shape.active(4));
  // The morph blend: the dent at 0.5 moves the spheres half-way and keeps sphere 4 (half its radius).
  const float half[1] = {0.5f};
  ASSERT_EQ(spx::bullet::blend_morph(shape, proxy, half, 1, origin), spx::SPX_OK);
  ASSERT_EQ(spx::blend_morph(proxy, half, 1, c.data(), r.data()), spx::SPX_OK);
  for (int s = 0; s < 5; ++s) {
    EXPECT_TRUE(shape.active(s));
    EXPECT_EQ(shape.getChildTransform(s).getOrigin(),
              btVector3(c[3 * size_t(s)], c[3 * size_t(s) + 1], c[3 * size_t(s) + 2]) - origin);
    EXPECT_EQ(static_cast<const btSphereShape*>(shape.getChildShape(s))->getRadius(), r[size_t(s)]);
  }
  EXPECT_FLOAT_EQ(c[1], 0.25f);
}
