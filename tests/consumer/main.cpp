// Loads a .spx, blends the rest pose, and (with spx::bullet) fills a sphere-set compound and
// rests it on a plane. Prints "ok" and exits 0 when everything agrees.
#include <cstdio>
#include <vector>

#include "spx_runtime.h"
#ifdef WITH_BULLET
#include <btBulletCollisionCommon.h>

#include "spx_bullet.hpp"
#endif

int main(int argc, char** argv) {
  if (argc != 2) return 2;
  spx::Proxy proxy;
  if (spx::load_file(argv[1], &proxy) != spx::SPX_OK) return std::puts("load failed"), 1;
  const uint32_t n = proxy.sphere_count(), p = proxy.pose_count();
  std::vector<float> w(p, 0.0f), c(3 * n), r(n);
  w[0] = 1;
  if (spx::blend_global(proxy, w.data(), p, c.data(), r.data()) != spx::SPX_OK) return std::puts("blend failed"), 1;
#ifdef WITH_BULLET
  spx::bullet::SphereSetShape shape(n);
  if (spx::bullet::blend_global(shape, proxy, w.data(), p) != spx::SPX_OK) return std::puts("shape blend failed"), 1;
  float lowest = 1e30f;
  for (uint32_t i = 0; i < n; ++i) {
    const btVector3 o = shape.getChildTransform(int(i)).getOrigin();
    if (r[i] > 0 && (o != btVector3(c[3 * i], c[3 * i + 1], c[3 * i + 2]) ||
                     static_cast<const btSphereShape*>(shape.getChildShape(int(i)))->getRadius() != r[i]))
      return std::printf("sphere %u differs from the header's blend\n", i), 1;
    if (r[i] > 0 && c[3 * i + 2] - r[i] < lowest) lowest = c[3 * i + 2] - r[i];
  }
  btDefaultCollisionConfiguration config;
  btCollisionDispatcher dispatcher(&config);
  spx::bullet::register_sphere_set_algorithms(dispatcher);
  btDbvtBroadphase broadphase;
  btCollisionWorld world(&dispatcher, &broadphase, &config);
  btStaticPlaneShape ground(btVector3(0, 0, 1), lowest + 0.01f);  // 1 cm above the lowest sphere
  btCollisionObject body, floor;
  body.setCollisionShape(&shape);
  floor.setCollisionShape(&ground);
  world.addCollisionObject(&body);
  world.addCollisionObject(&floor);
  world.performDiscreteCollisionDetection();
  int contacts = 0;
  for (int m = 0; m < dispatcher.getNumManifolds(); ++m) contacts += dispatcher.getManifoldByIndexInternal(m)->getNumContacts();
  world.removeCollisionObject(&body);
  world.removeCollisionObject(&floor);
  if (contacts < 1 || contacts > 4) return std::printf("%d contacts with the ground\n", contacts), 1;
  std::printf("ok: %u spheres, %u poses, %d contacts\n", n, p, contacts);
#else
  std::printf("ok: %u spheres, %u poses (header only)\n", n, p);
#endif
  return 0;
}
