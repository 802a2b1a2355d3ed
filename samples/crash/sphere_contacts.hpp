#pragma once
// Collision between a sphere proxy (a btCompoundShape whose children are all btSphereShape)
// and a static plane or box: one narrow-phase algorithm for the whole sphere set.
//
// Bullet's btCompoundCollisionAlgorithm treats every child as a general shape: a child
// algorithm and a manifold per child, child AABBs recomputed, and a pass over every child each
// step. Profiles of the crash scene put about 30% of a proxy's simulation time there, and only
// 7% in the sphere tests themselves. Here the compound's own AABB tree culls the children, each
// surviving sphere is tested in closed form, and all contacts go into one manifold per pair
// (Bullet keeps the 4 that span the contact best).
#include <BulletCollision/CollisionDispatch/btActivatingCollisionAlgorithm.h>
#include <BulletCollision/CollisionDispatch/btCollisionCreateFunc.h>
#include <BulletCollision/CollisionDispatch/btCollisionDispatcher.h>

namespace spx::crash {

class SphereSetStaticAlgorithm : public btActivatingCollisionAlgorithm {
 public:
  SphereSetStaticAlgorithm(const btCollisionAlgorithmConstructionInfo& ci, const btCollisionObjectWrapper* body0,
                           const btCollisionObjectWrapper* body1, bool swapped);
  ~SphereSetStaticAlgorithm() override;

  void processCollision(const btCollisionObjectWrapper* body0, const btCollisionObjectWrapper* body1,
                        const btDispatcherInfo& info, btManifoldResult* result) override;
  btScalar calculateTimeOfImpact(btCollisionObject*, btCollisionObject*, const btDispatcherInfo&,
                                 btManifoldResult*) override {
    return 1;
  }
  void getAllContactManifolds(btManifoldArray& manifolds) override {
    if (manifold_) manifolds.push_back(manifold_);
  }

  struct CreateFunc : public btCollisionAlgorithmCreateFunc {
    btCollisionAlgorithm* CreateCollisionAlgorithm(btCollisionAlgorithmConstructionInfo& ci,
                                                   const btCollisionObjectWrapper* body0,
                                                   const btCollisionObjectWrapper* body1) override;
  };

 private:
  btPersistentManifold* manifold_ = nullptr;
  bool swapped_;  // body0 is the static shape, body1 the sphere set
};

// Registers the algorithm for sphere-set compounds against static planes and boxes (both
// orders). Every compound in that world must hold only spheres.
void register_sphere_set_algorithms(btCollisionDispatcher& dispatcher);

}  // namespace spx::crash
