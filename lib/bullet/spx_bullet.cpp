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

SphereSetShape::SphereSetShape(uint32_t n) : btCompoundShape(true, int(n)), radii_(n, 0) {
  balls_.reserve(n);
  centers_.resize(int(n), btVector3(0, 0, 0));
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
  place(centers, 3, radii, 1, origin);
}

void SphereSetShape::set_spheres_xyzr(const float* xyzr, const btVector3& origin) { place(xyzr, 4, xyzr + 3, 4, origin); }

void SphereSetShape::place(const float* centers, size_t center_stride, const float* radii, size_t radius_stride,
                           const btVector3& origin) {
  // A parked sphere: tiny, at the body's origin, where it never sticks out.
  constexpr btScalar kParked = btScalar(1e-4);
  btTransform t;
  t.setIdentity();
  for (size_t j = 0; j < balls_.size(); ++j) {
    const float r = radii[j * radius_stride];
    const float* c = centers + j * center_stride;
    const bool on = r > 0;
    radii_[j] = on ? r : 0;
    balls_[j].setUnscaledRadius(on ? r : kParked);
    t.setOrigin(on ? btVector3(c[0], c[1], c[2]) - origin : btVector3(0, 0, 0));
    updateChildTransform(int(j), t, false);
    centers_[int(j)] = t.getOrigin();
  }
  recalculateLocalAabb();
}

namespace {

thread_local std::vector<float> scratch_centers, scratch_radii, scratch_xyzr;

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

// The contacts of one body pair, reduced before the manifold sees them. Bullet keeps at most 4
// points per manifold: the deepest, and those spanning the largest area. Handing it dozens
// (a car on the ground touches with many spheres) costs a cache search and an area sort each;
// so only the contacts that can matter go in: the extremes along two directions across the
// deepest contact's normal, then the deepest itself, last, so that it always stays (a new
// point replaces a cached one near it). Closest-point queries get every contact.
struct PendingContact {
  btVector3 normal, point;
  btScalar distance;
};
void add_contacts(const std::vector<PendingContact>& contacts, bool reduce, btManifoldResult* result) {
  const int n = int(contacts.size());
  if (!reduce) {  // a query (contactTest) sees every contact
    for (const PendingContact& c : contacts) result->addContactPoint(c.normal, c.point, c.distance);
  } else if (n > 0) {
    int deepest = 0;
    for (int i = 1; i < n; ++i)
      if (contacts[size_t(i)].distance < contacts[size_t(deepest)].distance) deepest = i;
    int chosen[5];
    int count = 0;
    if (n > 1) {
      btVector3 u, v;
      btPlaneSpace1(contacts[size_t(deepest)].normal, u, v);
      int lo_u = 0, hi_u = 0, lo_v = 0, hi_v = 0;
      for (int i = 1; i < n; ++i) {
        const btScalar a = contacts[size_t(i)].point.dot(u), b = contacts[size_t(i)].point.dot(v);
        if (a < contacts[size_t(lo_u)].point.dot(u)) lo_u = i;
        if (a > contacts[size_t(hi_u)].point.dot(u)) hi_u = i;
        if (b < contacts[size_t(lo_v)].point.dot(v)) lo_v = i;
        if (b > contacts[size_t(hi_v)].point.dot(v)) hi_v = i;
      }
      for (int i : {lo_u, hi_u, lo_v, hi_v})
        if (i != deepest && std::find(chosen, chosen + count, i) == chosen + count) chosen[count++] = i;
    }
    chosen[count++] = deepest;
    for (int k = 0; k < count; ++k) {
      const PendingContact& c = contacts[size_t(chosen[k])];
      result->addContactPoint(c.normal, c.point, c.distance);
    }
  }
  result->refreshContactPoints();
}
thread_local std::vector<PendingContact> pending;

// The leaves of a tree whose boxes reach into every half-space n.x + d >= 0 (`faces` of them,
// btDbvt::collideKDOP's convention): a plain recursion, where collideKDOP allocates its stack on
// every call.
struct FaceCull {
  const btVector3* normals;
  const btScalar* offsets;
  int faces;
  std::vector<int>* hits;

  void collide(const btDbvtNode* node) const {
    const btVector3 c = node->volume.Center(), e = node->volume.Extents();
    for (int f = 0; f < faces; ++f)
      if (normals[f].dot(c) + e.dot(normals[f].absolute()) + offsets[f] < 0) return;  // box wholly outside
    if (node->isleaf()) {
      hits->push_back(node->dataAsInt);
      return;
    }
    collide(node->childs[0]);
    collide(node->childs[1]);
  }
};

// The leaves of a tree whose boxes overlap `box` (same frame).
void leaves_in_box(const btDbvtNode* node, const btDbvtVolume& box, std::vector<int>& out) {
  if (!Intersect(node->volume, box)) return;
  if (node->isleaf()) {
    out.push_back(node->dataAsInt);
    return;
  }
  leaves_in_box(node->childs[0], box, out);
  leaves_in_box(node->childs[1], box, out);
}

// A box carried through a rigid transform (the box around the moved box).
btDbvtVolume moved_box(const btDbvtVolume& v, const btTransform& t, btScalar grow) {
  const btVector3 e = t.getBasis().absolute() * v.Extents() + btVector3(grow, grow, grow);
  return btDbvtVolume::FromCE(t * v.Center(), e);
}

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

  // Thread-local scratch, looked up once (each access to a thread_local costs a call in PIC code).
  static thread_local std::vector<int> hits_storage;
  std::vector<int>& hits = hits_storage;
  std::vector<PendingContact>& contacts = pending;
  hits.clear();
  contacts.clear();
  const bool plane = shape->getShapeType() == STATIC_PLANE_PROXYTYPE;
  const btTransform relative = set_frame.inverseTimes(other_frame);
  if (plane) {
    // Every sphere against the plane in the set's own frame: a flat pass over the compact copy
    // costs less than a tree walk when a whole underside rests on the ground.
    const auto* p = static_cast<const btStaticPlaneShape*>(shape);
    const btVector3 n = relative.getBasis() * p->getPlaneNormal();
    const btScalar offset = p->getPlaneConstant() + n.dot(relative.getOrigin());
    for (int i = 0; i < int(compound->sphere_count()); ++i) {
      const btScalar r = compound->radius(i);
      if (r > 0 && n.dot(compound->center(i)) - offset - r <= reach) hits.push_back(i);
    }
  } else {
    // Children whose boxes reach the box, culled by the compound's tree against the box's faces
    // (half-spaces in the compound's frame, grown by the reach); an axis-aligned box around a
    // tilted box would keep nearly every sphere.
    btVector3 normals[6];
    btScalar offsets[6];
    int faces = 0;
    const btVector3 h = static_cast<const btBoxShape*>(shape)->getHalfExtentsWithMargin();
    for (int axis = 0; axis < 3; ++axis)
      for (btScalar side : {btScalar(-1), btScalar(1)}) {
        const btVector3 u = relative.getBasis().getColumn(axis);
        normals[faces] = -side * u;
        offsets[faces++] = h[axis] + reach + side * u.dot(relative.getOrigin());
      }
    const FaceCull cull{normals, offsets, faces, &hits};
    cull.collide(compound->getDynamicAabbTree()->m_root);
  }

  for (const int i : hits) {
    const btScalar r = compound->radius(i);
    if (r <= 0) continue;
    const btVector3 c = set_frame * compound->center(i);
    const Contact hit = plane ? plane_contact(*static_cast<const btStaticPlaneShape*>(shape), other_frame, c, r)
                              : box_contact(*static_cast<const btBoxShape*>(shape), other_frame, c, r);
    if (hit.distance > reach) continue;
    // Bullet wants the normal on body 1 pointing toward body 0, and the point on body 1.
    if (!swapped_)
      contacts.push_back({hit.normal, hit.on_other, hit.distance});
    else
      contacts.push_back({-hit.normal, c - hit.normal * r, hit.distance});
  }
  add_contacts(contacts, !closest_, result);
}

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
    // Only B's spheres inside A's box (grown by the reach) can touch: a car meets another along
    // a strip. Each of them, carried into A's frame, queries A's tree with its own box.
    static thread_local std::vector<int> near_storage, hits_storage;
    std::vector<int>& near_b = near_storage;
    std::vector<int>& hits = hits_storage;
    std::vector<PendingContact>& contacts = pending;
    near_b.clear(), contacts.clear();
    const btTransform b_to_a = fa.inverseTimes(fb);
    const btDbvtNode* root_a = a->getDynamicAabbTree()->m_root;
    const btDbvtNode* root_b = b->getDynamicAabbTree()->m_root;
    leaves_in_box(root_b, moved_box(root_a->volume, b_to_a.inverse(), reach), near_b);
    for (const int j : near_b) {
      const btScalar rb = b->radius(j);
      if (rb <= 0) continue;
      const btVector3 cb = b_to_a * b->center(j);  // in A's frame
      hits.clear();
      leaves_in_box(root_a, btDbvtVolume::FromCR(cb, rb + reach), hits);
      for (const int i : hits) {
        const btScalar ra = a->radius(i);
        if (ra <= 0) continue;
        const btVector3& ca = a->center(i);
        const btVector3 d = ca - cb;
        const btScalar limit = ra + rb + reach;
        if (d.length2() > limit * limit) continue;
        const btScalar len = d.length();
        // Coincident centres: any direction separates them; Bullet's sphere-sphere picks +x.
        const btVector3 n = fa.getBasis() * (len > SIMD_EPSILON ? d / len : btVector3(1, 0, 0));
        contacts.push_back({n, fa * cb + n * rb, len - ra - rb});  // normal on B toward A, point on B
      }
    }
    add_contacts(contacts, !closest_, result);
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

Status skin(SphereSetShape& shape, const Proxy& proxy, const float* joint_matrices, int joint_count,
            const btVector3& origin) {
  if (proxy.sphere_count() != shape.sphere_count()) return SPX_ERR_INVALID_ARGUMENT;
  scratch_xyzr.resize(4 * size_t(proxy.sphere_count()));
  const Status s = spx::skin(proxy, joint_matrices, joint_count, scratch_xyzr.data());
  if (s == SPX_OK) shape.set_spheres_xyzr(scratch_xyzr.data(), origin);
  return s;
}

Status blend_local(SphereSetShape& shape, const Proxy& proxy, const float* site_weights, size_t weight_count,
                   const btVector3& origin) {
  return blend_into(shape, proxy, origin, [&](float* c, float* r) {
    return spx::blend_local(proxy, site_weights, weight_count, c, r);
  });
}

Status blend_morph(SphereSetShape& shape, const Proxy& proxy, const float* morph_weights, uint32_t weight_count,
                   const btVector3& origin) {
  return blend_into(shape, proxy, origin, [&](float* c, float* r) {
    return spx::blend_morph(proxy, morph_weights, weight_count, c, r);
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
