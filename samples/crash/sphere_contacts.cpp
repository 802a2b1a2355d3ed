#include "sphere_contacts.hpp"

#include <BulletCollision/BroadphaseCollision/btDbvt.h>
#include <BulletCollision/CollisionDispatch/btCollisionObjectWrapper.h>
#include <BulletCollision/CollisionDispatch/btManifoldResult.h>
#include <BulletCollision/CollisionShapes/btBoxShape.h>
#include <BulletCollision/CollisionShapes/btCompoundShape.h>
#include <BulletCollision/CollisionShapes/btSphereShape.h>
#include <BulletCollision/CollisionShapes/btStaticPlaneShape.h>

#include <initializer_list>

namespace spx::crash {
namespace {

// A sphere's contact with the static shape, all in world space: `normal` points from the
// static shape toward the sphere, `on_static` is the closest point of the static shape, and
// `distance` is negative when they overlap.
struct Contact {
  btVector3 normal, on_static;
  btScalar distance;
};

Contact plane_contact(const btStaticPlaneShape& plane, const btTransform& frame, const btVector3& c, btScalar r) {
  const btVector3 n = frame.getBasis() * plane.getPlaneNormal();
  const btScalar offset = plane.getPlaneConstant() + n.dot(frame.getOrigin());
  const btScalar above = n.dot(c) - offset;
  return {n, c - n * above, above - r};
}

Contact box_contact(const btBoxShape& box, const btTransform& frame, const btVector3& c, btScalar r) {
  const btVector3 h = box.getHalfExtentsWithMargin();
  const btVector3 local = frame.invXform(c);
  btVector3 closest = local;
  bool inside = true;
  for (int a = 0; a < 3; ++a) {
    if (closest[a] > h[a]) closest[a] = h[a], inside = false;
    if (closest[a] < -h[a]) closest[a] = -h[a], inside = false;
  }
  if (!inside) {
    const btVector3 d = local - closest;
    const btScalar len = d.length();
    return {frame.getBasis() * (d / len), frame * closest, len - r};
  }
  // Centre inside the box: leave through the nearest face.
  int axis = 0;
  btScalar depth = h[0] - btFabs(local[0]);
  for (int a = 1; a < 3; ++a)
    if (h[a] - btFabs(local[a]) < depth) depth = h[a] - btFabs(local[a]), axis = a;
  btVector3 n(0, 0, 0);
  n[axis] = local[axis] < 0 ? -1 : 1;
  closest[axis] = n[axis] * h[axis];
  return {frame.getBasis() * n, frame * closest, -depth - r};
}

struct Cull : btDbvt::ICollide {
  btAlignedObjectArray<int>* hits;
  void Process(const btDbvtNode* leaf) override { hits->push_back(leaf->dataAsInt); }
};

}  // namespace

SphereSetStaticAlgorithm::SphereSetStaticAlgorithm(const btCollisionAlgorithmConstructionInfo& ci,
                                                   const btCollisionObjectWrapper* body0,
                                                   const btCollisionObjectWrapper* body1, bool swapped)
    : btActivatingCollisionAlgorithm(ci, body0, body1), swapped_(swapped) {
  manifold_ = m_dispatcher->getNewManifold(body0->getCollisionObject(), body1->getCollisionObject());
}

SphereSetStaticAlgorithm::~SphereSetStaticAlgorithm() {
  if (manifold_) m_dispatcher->releaseManifold(manifold_);
}

// Bullet's btDbvt::Classify switch leaves its corners unset on paths it never takes.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
void SphereSetStaticAlgorithm::processCollision(const btCollisionObjectWrapper* body0,
                                                const btCollisionObjectWrapper* body1, const btDispatcherInfo&,
                                                btManifoldResult* result) {
  const btCollisionObjectWrapper* set = swapped_ ? body1 : body0;
  const btCollisionObjectWrapper* other = swapped_ ? body0 : body1;
  const auto* compound = static_cast<const btCompoundShape*>(set->getCollisionShape());
  const btCollisionShape* shape = other->getCollisionShape();
  const btTransform& set_frame = set->getWorldTransform();
  const btTransform& other_frame = other->getWorldTransform();
  result->setPersistentManifold(manifold_);
  const btScalar reach = manifold_->getContactBreakingThreshold();

  // Children whose boxes reach the static shape, culled by the compound's tree against the
  // shape's own faces (half-spaces in the compound's frame, grown by the contact reach); an
  // axis-aligned box around a tilted plane or box would keep nearly every sphere.
  const bool plane = shape->getShapeType() == STATIC_PLANE_PROXYTYPE;
  const btTransform relative = set_frame.inverseTimes(other_frame);
  btVector3 normals[6];
  btScalar offsets[6];
  int faces = 0;
  if (plane) {
    const auto* p = static_cast<const btStaticPlaneShape*>(shape);
    const btVector3 n = relative.getBasis() * p->getPlaneNormal();
    // Keep n.y <= c + reach, Bullet's form: normal.y + offset >= 0.
    normals[faces] = -n;
    offsets[faces++] = p->getPlaneConstant() + n.dot(relative.getOrigin()) + reach;
  } else {
    const btVector3 h = static_cast<const btBoxShape*>(shape)->getHalfExtentsWithMargin();
    for (int axis = 0; axis < 3; ++axis)
      for (btScalar side : {btScalar(-1), btScalar(1)}) {
        const btVector3 u = relative.getBasis().getColumn(axis);
        normals[faces] = -side * u;
        offsets[faces++] = h[axis] + reach + side * u.dot(relative.getOrigin());
      }
  }
  static thread_local btAlignedObjectArray<int> hits;
  hits.resize(0);
  if (const btDbvt* tree = compound->getDynamicAabbTree()) {
    Cull cull;
    cull.hits = &hits;
    btDbvt::collideKDOP(tree->m_root, normals, offsets, faces, cull);
  } else {
    for (int i = 0; i < compound->getNumChildShapes(); ++i) hits.push_back(i);
  }

  for (int k = 0; k < hits.size(); ++k) {
    const int i = hits[k];
    const auto* sphere = static_cast<const btSphereShape*>(compound->getChildShape(i));
    const btVector3 c = set_frame * compound->getChildTransform(i).getOrigin();
    const btScalar r = sphere->getRadius();
    const Contact hit = plane ? plane_contact(*static_cast<const btStaticPlaneShape*>(shape), other_frame, c, r)
                              : box_contact(*static_cast<const btBoxShape*>(shape), other_frame, c, r);
    if (hit.distance > reach) continue;
    // Bullet wants the normal on body 1 pointing toward body 0, and the point on body 1.
    if (!swapped_)
      result->addContactPoint(hit.normal, hit.on_static, hit.distance);
    else
      result->addContactPoint(-hit.normal, c - hit.normal * r, hit.distance);
  }
  result->refreshContactPoints();
}
#pragma GCC diagnostic pop

btCollisionAlgorithm* SphereSetStaticAlgorithm::CreateFunc::CreateCollisionAlgorithm(
    btCollisionAlgorithmConstructionInfo& ci, const btCollisionObjectWrapper* body0,
    const btCollisionObjectWrapper* body1) {
  void* memory = ci.m_dispatcher1->allocateCollisionAlgorithm(sizeof(SphereSetStaticAlgorithm));
  return new (memory) SphereSetStaticAlgorithm(ci, body0, body1, m_swapped);
}

void register_sphere_set_algorithms(btCollisionDispatcher& dispatcher) {
  static SphereSetStaticAlgorithm::CreateFunc set_first, static_first;
  static_first.m_swapped = true;
  for (int other : {STATIC_PLANE_PROXYTYPE, BOX_SHAPE_PROXYTYPE}) {
    dispatcher.registerCollisionCreateFunc(COMPOUND_SHAPE_PROXYTYPE, other, &set_first);
    dispatcher.registerCollisionCreateFunc(other, COMPOUND_SHAPE_PROXYTYPE, &static_first);
  }
}

}  // namespace spx::crash
