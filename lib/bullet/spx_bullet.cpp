#include "spx_bullet.hpp"

#include <BulletCollision/BroadphaseCollision/btDbvt.h>
#include <BulletCollision/CollisionDispatch/btActivatingCollisionAlgorithm.h>
#include <BulletCollision/CollisionDispatch/btCollisionConfiguration.h>
#include <BulletCollision/CollisionDispatch/btCollisionCreateFunc.h>
#include <BulletCollision/CollisionDispatch/btCollisionObjectWrapper.h>
#include <BulletCollision/CollisionDispatch/btManifoldResult.h>
#include <BulletCollision/CollisionShapes/btBoxShape.h>
#include <BulletCollision/CollisionShapes/btStaticPlaneShape.h>

#include <algorithm>
#include <cstring>
#include <list>
#include <mutex>

namespace spx {
namespace bullet {

SphereSetShape::SphereSetShape(uint32_t n) : btCompoundShape(true, int(n)), active_(n, 0) {
  balls_.reserve(n);
  btTransform t;
  t.setIdentity();
  for (uint32_t i = 0; i < n; ++i) {
    balls_.emplace_back(btScalar(1));
    addChildShape(t, &balls_.back());
  }
}

bool SphereSetShape::is_sphere_set(const btCollisionShape* shape) {
  if (shape->getShapeType() != COMPOUND_SHAPE_PROXYTYPE) return false;
  const char* name = shape->getName();
  return name == kName || std::strcmp(name, kName) == 0;
}

void SphereSetShape::set_spheres(const float* centers, const float* radii, const btVector3& origin) {
  // A parked sphere: tiny, at the body's origin, where it never sticks out.
  constexpr btScalar kParked = btScalar(1e-4);
  btTransform t;
  t.setIdentity();
  for (size_t j = 0; j < balls_.size(); ++j) {
    const bool on = radii[j] > 0;
    active_[j] = on;
    balls_[j].setUnscaledRadius(on ? radii[j] : kParked);
    t.setOrigin(on ? btVector3(centers[3 * j], centers[3 * j + 1], centers[3 * j + 2]) - origin : btVector3(0, 0, 0));
    updateChildTransform(int(j), t, false);
  }
  recalculateLocalAabb();
}

namespace {

thread_local std::vector<float> scratch_centers, scratch_radii;

template <class Blend>
Status blend_into(SphereSetShape& shape, const Proxy& proxy, const btVector3& origin, Blend&& blend) {
  if (proxy.sphere_count() != shape.sphere_count()) return SPX_ERR_INVALID_ARGUMENT;
  scratch_centers.resize(3 * size_t(proxy.sphere_count()));
  scratch_radii.resize(proxy.sphere_count());
  const Status s = blend(scratch_centers.data(), scratch_radii.data());
  if (s == SPX_OK) shape.set_spheres(scratch_centers.data(), scratch_radii.data(), origin);
  return s;
}

// ---------------------------------------------------------------------------------------------
// Contacts in closed form, all in world space: `normal` points from the other shape toward the
// sphere, `on_other` is the other shape's closest point, `distance` < 0 when they overlap.
struct Contact {
  btVector3 normal, on_other;
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

// The contacts of one pair, handed to the manifold shallowest first: a new point replaces a cached
// one near it, so the deepest, added last, is always kept (as Bullet keeps it when it reduces
// a manifold to 4 points).
struct PendingContact {
  btVector3 normal, point;
  btScalar distance;
  int order;  // ties keep the order found: the same contacts in the same order every run
};
void add_contacts(std::vector<PendingContact>& contacts, btManifoldResult* result) {
  std::sort(contacts.begin(), contacts.end(), [](const PendingContact& a, const PendingContact& b) {
    return a.distance != b.distance ? a.distance > b.distance : a.order < b.order;
  });
  for (const PendingContact& c : contacts) result->addContactPoint(c.normal, c.point, c.distance);
  result->refreshContactPoints();
}
thread_local std::vector<PendingContact> pending;

struct Cull : btDbvt::ICollide {
  btAlignedObjectArray<int>* hits;
  void Process(const btDbvtNode* leaf) override { hits->push_back(leaf->dataAsInt); }
};

// The pairs of leaves of two compounds' trees whose boxes (B's carried into A's frame, grown by
// `reach`) overlap: descend the larger node first.
struct PairCull {
  btTransform b_to_a;
  btMatrix3x3 abs_basis;
  btScalar reach;
  btAlignedObjectArray<int>* pairs;  // a, b, a, b, ...

  btDbvtVolume in_a(const btDbvtVolume& v) const {
    const btVector3 e = abs_basis * v.Extents() + btVector3(reach, reach, reach);
    return btDbvtVolume::FromCE(b_to_a * v.Center(), e);
  }
  // `b_box` is b's volume in A's frame, carried down while A's side is the one descended.
  void collide(const btDbvtNode* a, const btDbvtNode* b, const btDbvtVolume& b_box) const {
    if (!Intersect(a->volume, b_box)) return;
    if (a->isleaf() && b->isleaf()) {
      pairs->push_back(a->dataAsInt);
      pairs->push_back(b->dataAsInt);
    } else if (b->isleaf() || (!a->isleaf() && a->volume.Lengths().length2() >= b->volume.Lengths().length2())) {
      collide(a->childs[0], b, b_box);
      collide(a->childs[1], b, b_box);
    } else {
      collide(a, b->childs[0], in_a(b->childs[0]->volume));
      collide(a, b->childs[1], in_a(b->childs[1]->volume));
    }
  }
};

// One persistent manifold per body pair.
class SphereSetAlgorithm : public btActivatingCollisionAlgorithm {
 public:
  SphereSetAlgorithm(const btCollisionAlgorithmConstructionInfo& ci, const btCollisionObjectWrapper* body0,
                     const btCollisionObjectWrapper* body1, bool closest)
      : btActivatingCollisionAlgorithm(ci, body0, body1), closest_(closest) {
    manifold_ = m_dispatcher->getNewManifold(body0->getCollisionObject(), body1->getCollisionObject());
  }
  ~SphereSetAlgorithm() override {
    if (manifold_) m_dispatcher->releaseManifold(manifold_);
  }
  btScalar calculateTimeOfImpact(btCollisionObject*, btCollisionObject*, const btDispatcherInfo&,
                                 btManifoldResult*) override {
    return 1;
  }
  void getAllContactManifolds(btManifoldArray& manifolds) override {
    if (manifold_) manifolds.push_back(manifold_);
  }

 protected:
  // How far apart a contact is still reported: the manifold's breaking threshold in simulation,
  // the query's own distance in closest-point queries (contactTest, contactPairTest).
  btScalar reach(const btManifoldResult* result) const {
    return closest_ ? result->m_closestPointDistanceThreshold : manifold_->getContactBreakingThreshold();
  }

  btPersistentManifold* manifold_ = nullptr;
  bool closest_;
};

// A sphere set against a static plane or box.
class StaticAlgorithm : public SphereSetAlgorithm {
 public:
  StaticAlgorithm(const btCollisionAlgorithmConstructionInfo& ci, const btCollisionObjectWrapper* body0,
                  const btCollisionObjectWrapper* body1, bool closest, bool swapped)
      : SphereSetAlgorithm(ci, body0, body1, closest), swapped_(swapped) {}

  void processCollision(const btCollisionObjectWrapper* body0, const btCollisionObjectWrapper* body1,
                        const btDispatcherInfo&, btManifoldResult* result) override;

 private:
  bool swapped_;  // body0 is the static shape, body1 the sphere set
};

// Bullet's btDbvt::Classify switch leaves its corners unset on paths it never takes.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
void StaticAlgorithm::processCollision(const btCollisionObjectWrapper* body0, const btCollisionObjectWrapper* body1,
                                       const btDispatcherInfo&, btManifoldResult* result) {
  const btCollisionObjectWrapper* set = swapped_ ? body1 : body0;
  const btCollisionObjectWrapper* other = swapped_ ? body0 : body1;
  const auto* compound = static_cast<const SphereSetShape*>(set->getCollisionShape());
  const btCollisionShape* shape = other->getCollisionShape();
  const btTransform& set_frame = set->getWorldTransform();
  const btTransform& other_frame = other->getWorldTransform();
  result->setPersistentManifold(manifold_);
  const btScalar reach = this->reach(result);

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
    normals[faces] = -n;  // keep n.y <= c + reach, Bullet's form: normal.y + offset >= 0
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
  Cull cull;
  cull.hits = &hits;
  btDbvt::collideKDOP(compound->getDynamicAabbTree()->m_root, normals, offsets, faces, cull);
  pending.clear();

  for (int k = 0; k < hits.size(); ++k) {
    const int i = hits[k];
    if (!compound->active(i)) continue;
    const btVector3 c = set_frame * compound->getChildTransform(i).getOrigin();
    const btScalar r = static_cast<const btSphereShape*>(compound->getChildShape(i))->getRadius();
    const Contact hit = plane ? plane_contact(*static_cast<const btStaticPlaneShape*>(shape), other_frame, c, r)
                              : box_contact(*static_cast<const btBoxShape*>(shape), other_frame, c, r);
    if (hit.distance > reach) continue;
    // Bullet wants the normal on body 1 pointing toward body 0, and the point on body 1.
    const int order = int(pending.size());
    if (!swapped_)
      pending.push_back({hit.normal, hit.on_other, hit.distance, order});
    else
      pending.push_back({-hit.normal, c - hit.normal * r, hit.distance, order});
  }
  add_contacts(pending, result);
}
#pragma GCC diagnostic pop

// Two sphere sets (two deforming bodies).
class PairAlgorithm : public SphereSetAlgorithm {
 public:
  using SphereSetAlgorithm::SphereSetAlgorithm;
  void processCollision(const btCollisionObjectWrapper* body0, const btCollisionObjectWrapper* body1,
                        const btDispatcherInfo&, btManifoldResult* result) override {
    const auto* a = static_cast<const SphereSetShape*>(body0->getCollisionShape());
    const auto* b = static_cast<const SphereSetShape*>(body1->getCollisionShape());
    const btTransform& fa = body0->getWorldTransform();
    const btTransform& fb = body1->getWorldTransform();
    result->setPersistentManifold(manifold_);
    const btScalar reach = this->reach(result);
    static thread_local btAlignedObjectArray<int> pairs;
    pairs.resize(0);
    PairCull cull;
    cull.b_to_a = fa.inverseTimes(fb);
    cull.abs_basis = cull.b_to_a.getBasis().absolute();
    cull.reach = reach;
    cull.pairs = &pairs;
    const btDbvtNode* root_b = b->getDynamicAabbTree()->m_root;
    cull.collide(a->getDynamicAabbTree()->m_root, root_b, cull.in_a(root_b->volume));
    pending.clear();
    for (int k = 0; k < pairs.size(); k += 2) {
      const int i = pairs[k], j = pairs[k + 1];
      if (!a->active(i) || !b->active(j)) continue;
      const btVector3 ca = fa * a->getChildTransform(i).getOrigin();
      const btVector3 cb = fb * b->getChildTransform(j).getOrigin();
      const btScalar ra = static_cast<const btSphereShape*>(a->getChildShape(i))->getRadius();
      const btScalar rb = static_cast<const btSphereShape*>(b->getChildShape(j))->getRadius();
      const btVector3 d = ca - cb;
      const btScalar len = d.length();
      const btScalar distance = len - ra - rb;
      if (distance > reach) continue;
      // Coincident centres: any direction separates them; Bullet's sphere-sphere picks +x.
      const btVector3 n = len > SIMD_EPSILON ? d / len : btVector3(1, 0, 0);
      pending.push_back({n, cb + n * rb, distance, int(pending.size())});  // normal on body 1 toward body 0, point on body 1
    }
    add_contacts(pending, result);
  }
};

// Creates our algorithm for sphere sets and hands anything else to the configuration's own.
struct CreateFunc : btCollisionAlgorithmCreateFunc {
  btCollisionAlgorithmCreateFunc* fallback = nullptr;
  bool pair = false;     // sphere set against sphere set (else against a static shape)
  bool closest = false;  // registered for closest-point queries

  btCollisionAlgorithm* CreateCollisionAlgorithm(btCollisionAlgorithmConstructionInfo& ci,
                                                 const btCollisionObjectWrapper* body0,
                                                 const btCollisionObjectWrapper* body1) override {
    const bool first = SphereSetShape::is_sphere_set(body0->getCollisionShape());
    const bool second = SphereSetShape::is_sphere_set(body1->getCollisionShape());
    if (pair ? !(first && second) : !(m_swapped ? second : first))
      return fallback->CreateCollisionAlgorithm(ci, body0, body1);
    if (pair) {
      void* memory = ci.m_dispatcher1->allocateCollisionAlgorithm(sizeof(PairAlgorithm));
      return new (memory) PairAlgorithm(ci, body0, body1, closest);
    }
    void* memory = ci.m_dispatcher1->allocateCollisionAlgorithm(sizeof(StaticAlgorithm));
    return new (memory) StaticAlgorithm(ci, body0, body1, closest, m_swapped);
  }
};

}  // namespace

Status blend_global(SphereSetShape& shape, const Proxy& proxy, const float* weights, uint32_t weight_count,
                    const btVector3& origin) {
  return blend_into(shape, proxy, origin, [&](float* c, float* r) {
    return spx::blend_global(proxy, weights, weight_count, c, r);
  });
}

Status blend_local(SphereSetShape& shape, const Proxy& proxy, const float* site_weights, size_t weight_count,
                   const btVector3& origin) {
  return blend_into(shape, proxy, origin, [&](float* c, float* r) {
    return spx::blend_local(proxy, site_weights, weight_count, c, r);
  });
}

void register_sphere_set_algorithms(btCollisionDispatcher& dispatcher) {
  // The functions must outlive every dispatcher they are registered with.
  static std::mutex mutex;
  static std::list<CreateFunc> funcs;
  const std::lock_guard<std::mutex> lock(mutex);
  btCollisionConfiguration* config = dispatcher.getCollisionConfiguration();
  auto add = [&](int type0, int type1, bool pair, bool swapped) {
    for (bool closest : {false, true}) {
      funcs.emplace_back();
      CreateFunc& f = funcs.back();
      f.fallback = closest ? config->getClosestPointsAlgorithmCreateFunc(type0, type1)
                           : config->getCollisionAlgorithmCreateFunc(type0, type1);
      f.pair = pair;
      f.closest = closest;
      f.m_swapped = swapped;
      if (closest)
        dispatcher.registerClosestPointsCreateFunc(type0, type1, &f);
      else
        dispatcher.registerCollisionCreateFunc(type0, type1, &f);
    }
  };
  for (int other : {STATIC_PLANE_PROXYTYPE, BOX_SHAPE_PROXYTYPE}) {
    add(COMPOUND_SHAPE_PROXYTYPE, other, false, false);
    add(other, COMPOUND_SHAPE_PROXYTYPE, false, true);
  }
  add(COMPOUND_SHAPE_PROXYTYPE, COMPOUND_SHAPE_PROXYTYPE, true, false);
}

}  // namespace bullet
}  // namespace spx
