#pragma once
// spx_bullet.hpp - sphere-union proxies as Bullet collision shapes.
//
// Depends on Bullet and spx_runtime.h only. A host:
//   spx::bullet::register_sphere_set_algorithms(dispatcher);        // once per dispatcher
//   spx::bullet::SphereSetShape shape(proxy.sphere_count());        // one per body
//   spx::bullet::blend_global(shape, proxy, weights, n, com);       // whenever weights change
//   spx::bullet::blend_local(shape, proxy, site_weights, count, com);
//   spx::bullet::blend_morph(shape, proxy, morph_weights, n - 1, com);   // a morph-target body
//
// SphereSetShape is a btCompoundShape of btSphereShape children that the registered
// algorithms recognise by its name. Against a static plane every sphere is tested in one flat
// pass; against a static box the compound's AABB tree culls the spheres by the box's faces;
// against another sphere set, the spheres inside the other's box query this one's tree. Each
// surviving pair is tested in closed form, and the contacts go into one manifold per body pair,
// reduced as Bullet reduces a manifold to 4 points: the deepest always kept, the others spanning
// the contact. Any other compound in the world, and any other shape pair, goes through Bullet's
// own algorithms.
//
// Thread safety: the shape is written by the blend calls only; Bullet reads it during
// stepSimulation. Do not blend a shape while its world steps.
#include <BulletCollision/CollisionDispatch/btCollisionDispatcher.h>
#include <BulletCollision/CollisionShapes/btCompoundShape.h>
#include <BulletCollision/CollisionShapes/btSphereShape.h>

#include <vector>

#include "spx_runtime.h"

namespace spx {
namespace bullet {

class SphereSetShape : public btCompoundShape {
 public:
  // `sphere_count` unit spheres at the origin; blend_global/blend_local (or set_spheres) place them.
  explicit SphereSetShape(uint32_t sphere_count);
  SphereSetShape(const SphereSetShape&) = delete;
  SphereSetShape& operator=(const SphereSetShape&) = delete;

  const char* getName() const override { return kName; }
  static bool is_sphere_set(const btCollisionShape* shape);

  uint32_t sphere_count() const { return uint32_t(balls_.size()); }
  // Whether sphere i takes part in contacts (a blend can give a sphere radius 0: absent).
  bool active(int i) const { return radii_[size_t(i)] > 0; }
  // Sphere i in the shape's frame, in a compact copy the algorithms read (radius 0: inactive).
  const btVector3& center(int i) const { return centers_[i]; }
  btScalar radius(int i) const { return radii_[size_t(i)]; }

  // Centres (xyz per sphere) and radii in the proxy's frame; `origin` (the body's centre of
  // mass in that frame) is subtracted. A radius <= 0 parks the sphere, inactive, at the origin.
  // Refits the children's boxes, the tree and the compound's box.
  void set_spheres(const float* centers, const float* radii, const btVector3& origin = btVector3(0, 0, 0));
  // The same from x y z r per sphere (the runtime's xyzr layout).
  void set_spheres_xyzr(const float* xyzr, const btVector3& origin = btVector3(0, 0, 0));

  static constexpr const char* kName = "spx::SphereSet";

 private:
  void place(const float* centers, size_t center_stride, const float* radii, size_t radius_stride, const btVector3& origin);
  std::vector<btSphereShape> balls_;  // children point into it: sized once, never reallocated
  btAlignedObjectArray<btVector3> centers_;  // aligned: btVector3 may use SSE
  std::vector<btScalar> radii_;
};

// The runtime's blends written into the shape (status SPX_OK, or the blend's own status with the
// shape left as it was). The blend's scratch buffers are per thread.
Status blend_global(SphereSetShape& shape, const Proxy& proxy, const float* weights, uint32_t weight_count,
                    const btVector3& origin = btVector3(0, 0, 0));
Status blend_local(SphereSetShape& shape, const Proxy& proxy, const float* site_weights, size_t weight_count,
                   const btVector3& origin = btVector3(0, 0, 0));
Status blend_morph(SphereSetShape& shape, const Proxy& proxy, const float* morph_weights, uint32_t weight_count,
                   const btVector3& origin = btVector3(0, 0, 0));
// A rigged body's spheres skinned by the frame's joint matrices (spx::skin) into the shape.
Status skin(SphereSetShape& shape, const Proxy& proxy, const float* joint_matrices, int joint_count,
            const btVector3& origin = btVector3(0, 0, 0));

// Sphere set against static plane, box and sphere set, both orders. Pairs that are not sphere
// sets fall back to the dispatcher's configuration (Bullet's own algorithms).
void register_sphere_set_algorithms(btCollisionDispatcher& dispatcher);

}  // namespace bullet
}  // namespace spx
