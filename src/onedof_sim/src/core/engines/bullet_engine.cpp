// Bullet 3 (double precision) behind the engine seam: maximal coordinates, that is rigid bodies
// held together by btHingeConstraint and btSliderConstraint, stepped by the sequential-impulse
// (PGS) solver of bullet_solver.h.
//
// PhysicsParams: gravity, sor_pgs_iters (iterations), sor_pgs_w (SOR, Bullet applies it to
// contacts only), erp (joints and contacts), cfm and contact_surface_layer (Bullet's linear
// slop: the same allowed penetration) map onto the solver. Ignored: quick_step (Bullet has one
// solver), auto_disable_bodies (bodies never sleep here, as in ODE's default), max_contacts
// (Bullet keeps at most four points per pair of objects), sor_pgs_precon_iters,
// sor_pgs_rms_error_tol, and contact_max_correcting_vel (btContactSolverInfo::m_maxErrorReduction
// looks like it but the sequential-impulse solver never reads it).
//
// Bullet wants the inertia tensor diagonal, so each btRigidBody sits in its body's principal
// axes and the adapter turns poses back into the BodySpec frame; twists and forces are in world
// axes about the centre of mass and need no conversion.
//
// Bullet never ends the process on its own: btAssert is empty unless DEBUG, _DEBUG or BT_DEBUG is
// defined (none is, here or in Debian's release build, whose libBullet* and libLinearMath import
// neither __assert_fail nor abort), so it throws no EngineFault; what it does with a body it
// cannot step is a non-finite state, which the world's rollback takes back (World::stepEngine).
//
// Friction is isotropic: a contact uses the smaller mu of its two shapes and mu2 is ignored.
//
// A cylinder lying on the ground touches it along a line, which each engine resolves by its middle
// (contact_rules.h). Bullet's convex-plane collision finds one deepest point a step, which for a
// line is one end of it, and its manifold keeps the points of the last steps: a wheel's contact
// stays at one rim, so a two-wheeled base turns on a narrower track than its wheels' and turns
// faster than they command. Two points on the line do not cure it: the sequential-impulse solver
// gives the whole load of two points that the body cannot tilt about to the one it resolves first
// (a base's wheels: each on its inner point, the track 3.5 cm narrower). CylinderPlane gives the
// line's middle from the cylinder's pose, at the line's depth there.
//
// A cylinder standing on an end face touches the ground with a disc, of which Bullet's collision
// likewise finds one rim point a step. Pushed at its rim, a body turns more the smaller its
// inertia: the book's thin cylinder (moments 300 times too small for its size) landing flat was
// spun and thrown up by its first rim point, and rim points all round do not hold it either (the
// sequential-impulse solver, resolving one rim point after another, barely stops the fall of a
// body that turns a hundred times more than it moves). CylinderPlane gives the face's middle,
// which carries its weight without turning it and holds the face's friction about the normal
// (an evenly pressed disc's, as Bullet's spinning friction), and while the face tilts, the rim's
// lowest point, which rights it. Any other pose of a cylinder on the ground is Bullet's own
// collision.
#include <BulletCollision/CollisionDispatch/btConvexPlaneCollisionAlgorithm.h>
#include <BulletCollision/CollisionDispatch/btManifoldResult.h>
#include <BulletCollision/Gimpact/btGImpactCollisionAlgorithm.h>
#include <BulletCollision/Gimpact/btGImpactShape.h>
#include <LinearMath/btAabbUtil2.h>
#include <LinearMath/btConvexHullComputer.h>
#include <btBulletDynamicsCommon.h>

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <stdexcept>
#include <unordered_set>

#include "bullet_convert.h"
#include "bullet_solver.h"
#include "contact_rules.h"
#include "engine.h"
#include "onedof_sim/pose_math.h"

namespace onedof_sim {
namespace core {
namespace {

// Bullet's default 4 cm margin rounds a box's edges and corners by as much; contact angles are
// checked against the geometry within a few mrad. Boxes and cylinders keep their outer extents
// whatever the margin (it is taken from the inside), and a sphere's margin is its radius.
constexpr double kMargin = 0.0005;

// A cylinder stands on an end face when its axis is along the ground's normal within kLyingTilt
// (the sine of the angle between them); the face is flat, with no lowest rim point, within this.
constexpr double kFlatTilt = 1e-9;
// Two positions the collision pass computed alike (m).
constexpr double kSamePoint = 1e-9;
// A rolling friction coefficient (m) too small to act: Bullet's spinning friction comes with one.
constexpr double kNoRollingFriction = 1e-12;

// A frame at `origin` whose column `axis_column` (0 = x, 2 = z) is `axis`.
btTransform jointFrame(const Vec3& origin, const Vec3& axis, int axis_column) {
  const btVector3 n = toBt(axis);
  btVector3 p, q;
  btPlaneSpace1(n, p, q);  // q = n x p: (p, q, n) and (n, p, q) are right-handed
  btMatrix3x3 basis;
  if (axis_column == 2)
    basis.setValue(p.x(), q.x(), n.x(), p.y(), q.y(), n.y(), p.z(), q.z(), n.z());
  else
    basis.setValue(n.x(), p.x(), q.x(), n.y(), p.y(), q.y(), n.z(), p.z(), q.z());
  return btTransform(basis, toBt(origin));
}

// A mesh's triangles as Bullet reads them, over the mesh's own arrays (held here).
class MeshArrays : public btTriangleIndexVertexArray {
 public:
  explicit MeshArrays(std::shared_ptr<const TriangleMesh> mesh) : mesh_(std::move(mesh)) {
    static_assert(sizeof(Vec3) == 3 * sizeof(double), "vertices are handed over as they are");
    btIndexedMesh part;
    part.m_numTriangles = static_cast<int>(mesh_->triangles.size());
    part.m_triangleIndexBase = reinterpret_cast<const unsigned char*>(mesh_->triangles.data());
    part.m_triangleIndexStride = sizeof(mesh_->triangles[0]);
    part.m_numVertices = static_cast<int>(mesh_->vertices.size());
    part.m_vertexBase = reinterpret_cast<const unsigned char*>(mesh_->vertices.data());
    part.m_vertexStride = sizeof(Vec3);
    part.m_indexType = PHY_INTEGER;
    part.m_vertexType = PHY_DOUBLE;
    addIndexedMesh(part, PHY_INTEGER);
  }

 private:
  std::shared_ptr<const TriangleMesh> mesh_;
};

// Relative difference between a mesh's volume and its convex hull's under which the mesh is
// taken as convex: the float rounding of a file's vertices, not a dent.
constexpr double kConvexVolumeTolerance = 1e-4;

// The volume a closed mesh wound counter-clockwise from outside encloses (the divergence
// theorem over its triangles); an open mesh's figure depends on the origin and matches nothing.
double enclosedVolume(const TriangleMesh& mesh) {
  double six_volume = 0;
  for (const auto& t : mesh.triangles)
    six_volume += dot(mesh.vertices[t[0]], cross(mesh.vertices[t[1]], mesh.vertices[t[2]]));
  return six_volume / 6;
}

// The volume of a convex hull, from its faces (a fan of triangles each).
double hullVolume(const btConvexHullComputer& hull) {
  double six_volume = 0;
  for (int f = 0; f < hull.faces.size(); ++f) {
    const btConvexHullComputer::Edge* first = &hull.edges[hull.faces[f]];
    const btVector3& a = hull.vertices[first->getSourceVertex()];
    for (const btConvexHullComputer::Edge* e = first->getNextEdgeOfFace();
         e->getTargetVertex() != first->getSourceVertex(); e = e->getNextEdgeOfFace())
      six_volume += a.dot(hull.vertices[e->getSourceVertex()].cross(
          hull.vertices[e->getTargetVertex()]));
  }
  return six_volume / 6;
}

// A closed convex mesh (a box, a wheel) as the convex shape it is, its faces
// moved in by the margin that Bullet adds around a hull, so that its surface is the mesh's; null
// for any other mesh. Bullet collides a triangle mesh one triangle at a time, each a plate as
// thick as the margin, touched from either side, with at most four points kept per pair of
// objects: where another shape's edges meet the mesh's (a 0.2 m box on a 0.2 x 0.2 m block's
// top) the side triangles' plates touch the flush sides 0.5 mm deep with sideways normals, and
// each triangle's deepest point, a corner, crowds the face's support out of the four. A box so
// placed hops 10 mm on landing and, nudged 2 mm, for about a second; a mesh block on a box tips
// over. As a hull it collides as Bullet's box does, face on face.
std::unique_ptr<btConvexHullShape> convexHullShape(const TriangleMesh& mesh) {
  btConvexHullComputer hull;
  const int count = static_cast<int>(mesh.vertices.size());
  hull.compute(&mesh.vertices[0].x, sizeof(Vec3), count, 0, 0);
  const double volume = std::fabs(hullVolume(hull));
  if (!(volume > 0) ||
      std::fabs(enclosedVolume(mesh) - volume) > kConvexVolumeTolerance * volume)
    return nullptr;
  btConvexHullComputer shrunk;
  shrunk.compute(&mesh.vertices[0].x, sizeof(Vec3), count, kMargin, 0);
  auto shape = std::make_unique<btConvexHullShape>();
  for (int v = 0; v < shrunk.vertices.size(); ++v) shape->addPoint(shrunk.vertices[v], false);
  shape->recalcLocalAabb();
  shape->setMargin(kMargin);
  // Face-on-face contacts clip the faces (several points at once), as for a box.
  shape->initializePolyhedralFeatures();
  return shape;
}

// A collision shape; a concave mesh's also needs its arrays (*arrays), which must outlive the
// shape. A convex mesh is its hull (convexHullShape). A concave mesh on the static environment is
// a btBvhTriangleMeshShape (a tree of its triangles, built once); on a moving body a
// btGImpactMeshShape, which collides as the triangles it is, concave parts included, with every
// shape and with the static meshes. Gazebo's Bullet takes every mesh as the convex hull of its
// triangles (btConvexTriangleMeshShape) instead.
std::unique_ptr<btCollisionShape> makeShape(const ShapeSpec& spec, bool moving,
                                            std::unique_ptr<MeshArrays>* arrays) {
  const Vec3& s = spec.size;
  std::unique_ptr<btCollisionShape> shape;
  switch (spec.shape) {
    case GeometryShape::Mesh:
      if (auto hull = convexHullShape(*spec.mesh)) return hull;
      *arrays = std::make_unique<MeshArrays>(spec.mesh);
      if (moving) {
        auto gimpact = std::make_unique<btGImpactMeshShape>(arrays->get());
        gimpact->setMargin(kMargin);
        gimpact->updateBound();
        return gimpact;
      }
      shape = std::make_unique<btBvhTriangleMeshShape>(arrays->get(), true);
      break;
    case GeometryShape::Box:
      shape = std::make_unique<btBoxShape>(btVector3(s.x / 2, s.y / 2, s.z / 2));
      break;
    case GeometryShape::Cylinder:
      shape = std::make_unique<btCylinderShapeZ>(btVector3(s.x, s.x, s.z / 2));
      break;
    case GeometryShape::Sphere:
      return std::make_unique<btSphereShape>(s.x);
    case GeometryShape::Plane:  // anchored only: the plane z = 0 of its object's transform
      return std::make_unique<btStaticPlaneShape>(btVector3(0, 0, 1), 0);
    default:
      throw std::invalid_argument(
          "Bullet engine: a model shape must be a box, cylinder, sphere, plane or mesh");
  }
  shape->setMargin(kMargin);
  return shape;
}

// What a collision object is (its user pointer points here): a model's body, a compound whose
// child shapes are its BodySpec's shapes in order; or one of a model's anchored shapes.
struct ObjectTag {
  const EngineModel* model = nullptr;
  int body = -1;           // -1: not a body
  int anchored = 0;        // not a body: the anchored shape's index
  std::vector<double> mu;  // a body's: per child shape
};

// The shape a contact's side is: the object's, and for a body the child shape that touched.
ShapeRef shapeOf(const btCollisionObject* object, int child) {
  const auto* tag = static_cast<const ObjectTag*>(object->getUserPointer());
  if (!tag) return {};
  if (tag->body < 0) return {tag->model, -1, tag->anchored};
  return {tag->model, tag->body,
          child >= 0 && child < static_cast<int>(tag->mu.size()) ? child : 0};
}

// A body's contact reports which child shape touched, so friction follows the shape as in
// Gazebo. Anything else (an anchored shape, the ground's plane among them) carries its mu as the object's friction.
double shapeMu(const btCollisionObjectWrapper* wrapper, int child) {
  const btCollisionObject* object = wrapper->getCollisionObject();
  const auto* tag = static_cast<const ObjectTag*>(object->getUserPointer());
  if (tag && tag->body >= 0 && child >= 0 && child < static_cast<int>(tag->mu.size()))
    return tag->mu[child];
  return object->getFriction();
}

// The child of the object's own shape that a contact's shape belongs to: a contact on a mesh
// reports its triangle's wrapper and index, a level below the compound's child.
int childIndex(const btCollisionObjectWrapper* wrapper, int index) {
  while (wrapper->m_parent && wrapper->m_parent->m_parent) wrapper = wrapper->m_parent;
  return wrapper->m_parent ? wrapper->m_index : index;
}

// Called for each point a collision pass adds or refreshes, `a` being the manifold's first
// object: the point's friction, and the child shapes it is between, kept in its indices (read by
// nothing else here) for the contacts the engine reports.
bool onContactAdded(btManifoldPoint& point, const btCollisionObjectWrapper* a, int, int child_a,
                    const btCollisionObjectWrapper* b, int, int child_b) {
  point.m_index0 = childIndex(a, child_a);
  point.m_index1 = childIndex(b, child_b);
  point.m_combinedFriction = std::min(shapeMu(a, point.m_index0), shapeMu(b, point.m_index1));
  return true;
}

// A cylinder against the ground plane: the middle of its contact line when it lies on it, the
// middle of its end face (and the rim's lowest point) when it stands on one (see the top of the
// file), Bullet's convex-plane collision otherwise, on one manifold.
class CylinderPlane : public btCollisionAlgorithm {
 public:
  CylinderPlane(const btCollisionAlgorithmConstructionInfo& info,
                     const btCollisionObjectWrapper* a, const btCollisionObjectWrapper* b,
                     bool swapped)
      : btCollisionAlgorithm(info), general_(nullptr, info, a, b, swapped, 1, 0),
        swapped_(swapped) {}

  void processCollision(const btCollisionObjectWrapper* a, const btCollisionObjectWrapper* b,
                        const btDispatcherInfo& dispatch, btManifoldResult* result) override {
    const btCollisionObjectWrapper* cylinder_object = swapped_ ? b : a;
    const btCollisionObjectWrapper* plane_object = swapped_ ? a : b;
    const auto* cylinder =
        static_cast<const btCylinderShape*>(cylinder_object->getCollisionShape());
    const auto* plane = static_cast<const btStaticPlaneShape*>(plane_object->getCollisionShape());
    const btTransform& plane_pose = plane_object->getWorldTransform();
    const btTransform& cylinder_pose = cylinder_object->getWorldTransform();
    const btVector3 normal = plane_pose.getBasis() * plane->getPlaneNormal();
    const int up = cylinder->getUpAxis();
    const btVector3 axis = cylinder_pose.getBasis().getColumn(up);
    const btScalar across = axis.dot(normal);
    btManifoldArray manifolds;
    general_.getAllContactManifolds(manifolds);
    const bool lying = liesOn(fromBt(axis), fromBt(normal));
    const bool standing = 1 - across * across <= kLyingTilt * kLyingTilt;
    if ((!lying && !standing) || manifolds.size() == 0) {
      general_.processCollision(a, b, dispatch, result);
      return;
    }
    btPersistentManifold* manifold = manifolds[0];
    result->setPersistentManifold(manifold);
    const btVector3 on_plane = plane_pose * (plane->getPlaneNormal() * plane->getPlaneConstant());
    // Adds `point` of the cylinder where it is within the manifold's reach of the plane.
    const auto touch = [&](const btVector3& point) {
      const btScalar distance = normal.dot(point - on_plane);
      if (distance < manifold->getContactBreakingThreshold())
        result->addContactPoint(normal, point - distance * normal, distance);
    };
    if (lying) {
      touch(toBt(lineMiddle(fromBt(cylinder_pose.getOrigin()), fromBt(axis), cylinder->getRadius(),
                            fromBt(normal))));
    } else {
      // The middle of the face towards the plane, and the rim's lowest point where it tilts.
      const btScalar half_length = cylinder->getHalfExtentsWithMargin()[up];
      const btVector3 face = cylinder_pose.getOrigin() - (across > 0 ? 1 : -1) * half_length * axis;
      touch(face);
      holdSpin(manifold, face, cylinder->getRadius());
      const btVector3 tilt = normal - across * axis;  // the normal off the axis, in the face
      const btScalar tilt_sine = tilt.length();
      if (tilt_sine > kFlatTilt) touch(face - cylinder->getRadius() / tilt_sine * tilt);
    }
    result->refreshContactPoints();
  }

  // The face's friction about the normal, which its middle point alone would not have: Coulomb's
  // for a disc of `radius` pressed evenly, 2/3 mu N radius, as Bullet's spinning friction of the
  // manifold's point at `middle` (just added: on the cylinder's side or the plane's). Bullet
  // takes a spinning friction only with a rolling friction, given here too small to act, and
  // bounds its impulse by the coefficient itself as well: below Coulomb's once the normal
  // impulse passes 1 N s a step (1000 N at a 1 ms step).
  static void holdSpin(btPersistentManifold* manifold, const btVector3& middle, btScalar radius) {
    for (int p = 0; p < manifold->getNumContacts(); ++p) {
      btManifoldPoint& point = manifold->getContactPoint(p);
      if (point.getPositionWorldOnA().distance(middle) > kSamePoint &&
          point.getPositionWorldOnB().distance(middle) > kSamePoint)
        continue;
      point.m_combinedSpinningFriction = btScalar(2) / 3 * point.m_combinedFriction * radius;
      point.m_combinedRollingFriction = kNoRollingFriction;
    }
  }

  btScalar calculateTimeOfImpact(btCollisionObject*, btCollisionObject*, const btDispatcherInfo&,
                                 btManifoldResult*) override {
    return 1;  // no continuous collision detection, as for Bullet's convex-plane pair
  }

  void getAllContactManifolds(btManifoldArray& manifolds) override {
    general_.getAllContactManifolds(manifolds);
  }

  struct CreateFunc : btCollisionAlgorithmCreateFunc {
    btCollisionAlgorithm* CreateCollisionAlgorithm(btCollisionAlgorithmConstructionInfo& info,
                                                   const btCollisionObjectWrapper* a,
                                                   const btCollisionObjectWrapper* b) override {
      // Outside the dispatcher's pool, whose element size is that of Bullet's own algorithms;
      // the dispatcher frees memory that is not from its pool with btAlignedFree.
      void* memory = btAlignedAlloc(sizeof(CylinderPlane), 16);
      return new (memory) CylinderPlane(info, a, b, m_swapped);
    }
  };

 private:
  btConvexPlaneCollisionAlgorithm general_;  // owns the manifold
  bool swapped_;  // the plane is the first object
};

// Objects carry their model's id as user index; one model never collides with
// itself, whatever was added or removed before.
struct ModelFilter : btOverlapFilterCallback {
  bool needBroadphaseCollision(btBroadphaseProxy* a, btBroadphaseProxy* b) const override {
    if (!(a->m_collisionFilterGroup & b->m_collisionFilterMask) ||
        !(b->m_collisionFilterGroup & a->m_collisionFilterMask))
      return false;
    const int model_a = static_cast<const btCollisionObject*>(a->m_clientObject)->getUserIndex();
    const int model_b = static_cast<const btCollisionObject*>(b->m_clientObject)->getUserIndex();
    return model_a < 0 || model_a != model_b;
  }
};

// A hinge's motor: joint friction (a motor that wants zero speed and may push at most
// `friction`) or, while one is set, a velocity motor (setMotor). The hinge takes the motor bound
// as an impulse, so it is set from the step the solver is running.
class MotorHinge : public btHingeConstraint {
 public:
  MotorHinge(btRigidBody& a, btRigidBody& b, const btTransform& frame_a,
             const btTransform& frame_b, double friction)
      : btHingeConstraint(a, b, frame_a, frame_b), friction_(friction) {
    setMotor(0, 0);
  }
  // max_effort 0: back to the friction.
  void setMotor(double velocity, double max_effort) {
    const bool on = max_effort > 0;
    max_effort_ = on ? max_effort : friction_;
    enableAngularMotor(max_effort_ > 0, on ? velocity : 0, 0);
  }
  void getInfo2(btConstraintInfo2* info) override {
    setMaxMotorImpulse(max_effort_ / info->fps);
    btHingeConstraint::getInfo2(info);
  }

 private:
  double friction_;
  double max_effort_ = 0;
};

class BulletModel : public EngineModel {
 public:
  BulletModel(btDiscreteDynamicsWorld* world, int id, const ModelSpec& spec) : world_(world) {
    for (const BodySpec& spec_body : spec.bodies) {
      bodies_.emplace_back();
      Body& body = bodies_.back();
      body.tag.model = this;
      body.tag.body = static_cast<int>(bodies_.size()) - 1;
      body.compound = std::make_unique<btCompoundShape>();
      for (const ShapeSpec& shape : spec_body.shapes) {
        body.arrays.emplace_back();
        body.shapes.push_back(makeShape(shape, true, &body.arrays.back()));
        body.compound->addChildShape(btTransform::getIdentity(), body.shapes.back().get());
        body.tag.mu.push_back(shape.mu);
      }
      btRigidBody::btRigidBodyConstructionInfo info(spec_body.mass, nullptr, body.compound.get());
      info.m_linearDamping = info.m_angularDamping = 0;
      info.m_restitution = 0;
      body.rigid = std::make_unique<btRigidBody>(info);
      setBodyMass(static_cast<int>(bodies_.size()) - 1, spec_body);
      btRigidBody& rigid = *body.rigid;
      rigid.setActivationState(DISABLE_DEACTIVATION);
      rigid.setCollisionFlags(rigid.getCollisionFlags() |
                              btCollisionObject::CF_CUSTOM_MATERIAL_CALLBACK);
      rigid.setUserIndex(id);
      rigid.setUserPointer(&body.tag);
      world_->addRigidBody(&rigid);
    }
    for (const ShapeSpec& shape : spec.anchored_shapes) {
      anchored_.emplace_back();
      Anchored& anchored = anchored_.back();
      anchored.tag.model = this;
      anchored.tag.anchored = static_cast<int>(anchored_.size()) - 1;
      anchored.shape = makeShape(shape, false, &anchored.arrays);
      anchored.object = std::make_unique<btCollisionObject>();
      anchored.object->setCollisionShape(anchored.shape.get());
      anchored.object->setWorldTransform(toBt(shape.pose));
      anchored.object->setFriction(shape.mu);
      anchored.object->setRestitution(0);
      anchored.object->setUserIndex(id);
      anchored.object->setUserPointer(&anchored.tag);
      world_->addCollisionObject(anchored.object.get(), btBroadphaseProxy::StaticFilter,
                                 btBroadphaseProxy::AllFilter ^ btBroadphaseProxy::StaticFilter);
    }
    joints_.resize(spec.joints.size());
    for (size_t j = 0; j < joints_.size(); ++j) joints_[j].spec = spec.joints[j];
  }

  ~BulletModel() override {
    removeConstraints();
    for (Body& body : bodies_) world_->removeRigidBody(body.rigid.get());
    for (Anchored& anchored : anchored_) world_->removeCollisionObject(anchored.object.get());
  }

  void attachJoints(const std::vector<Pose>& zero_poses,
                    const std::vector<JointFrame>& frames) override {
    removeConstraints();
    for (size_t b = 0; b < bodies_.size(); ++b) setPose(static_cast<int>(b), zero_poses[b]);
    for (size_t j = 0; j < joints_.size(); ++j) {
      Joint& joint = joints_[j];
      const JointSpec& spec = joint.spec;
      const Pose parent_pose = spec.parent < 0 ? Pose() : zero_poses[spec.parent];
      const Pose& child_pose = zero_poses[spec.child];
      const Pose parent_inverse = inverse(parent_pose);
      joint.axis_in_parent = rotate(parent_inverse.orientation, frames[j].axis);
      joint.anchor_in_parent = transformPoint(parent_inverse, frames[j].anchor);
      joint.anchor_in_child = transformPoint(inverse(child_pose), frames[j].anchor);
      joint.zero_relative = multiply(parent_inverse.orientation, child_pose.orientation);

      // The static world is Bullet's fixed body, at the origin: the single-body constructors
      // would do the same, except that btHingeConstraint's takes the world frame's axes as the
      // body's (right only for an unrotated body).
      btRigidBody& child = *bodies_[spec.child].rigid;
      btRigidBody& parent =
          spec.parent < 0 ? btTypedConstraint::getFixedBody() : *bodies_[spec.parent].rigid;
      const btTransform world_frame =
          jointFrame(frames[j].anchor, frames[j].axis, spec.prismatic ? 0 : 2);
      const btTransform in_child = child.getCenterOfMassTransform().inverse() * world_frame;
      const btTransform in_parent = parent.getCenterOfMassTransform().inverse() * world_frame;
      const bool limited = spec.has_limits && spec.lower <= spec.upper;
      if (spec.prismatic) {
        // The slider moves frame B along frame A's x: child as B, so positive moves the child.
        // Its rotation about the axis stays locked (angular limits 0, 0 by default).
        auto slider = std::make_unique<btSliderConstraint>(parent, child, in_parent, in_child, true);
        if (limited) {
          slider->setLowerLinLimit(spec.lower);
          slider->setUpperLinLimit(spec.upper);
        }
        joint.constraint = std::move(slider);
        setJointMotor(static_cast<int>(j), 0, 0);
      } else {
        // getHingeAngle is A's rotation relative to B about the axis: child as A.
        auto hinge =
            std::make_unique<MotorHinge>(child, parent, in_child, in_parent, spec.friction);
        if (limited) {
          // As ODE, which ignores stops outside [-pi, pi]. Bias 1: the stop is corrected at the
          // world's erp like every other constraint; relaxation 0: Bullet uses it as the
          // stop's restitution, which ODE's default stops do not have.
          hinge->setLimit(std::max(spec.lower, -M_PI), std::min(spec.upper, M_PI), 0.9, 1.0, 0.0);
        }
        joint.constraint = std::move(hinge);
      }
      const btVector3 zero(0, 0, 0);
      joint.feedback.m_appliedForceBodyA = joint.feedback.m_appliedForceBodyB = zero;
      joint.feedback.m_appliedTorqueBodyA = joint.feedback.m_appliedTorqueBodyB = zero;
      joint.constraint->setJointFeedback(&joint.feedback);
      joint.constraint->enableFeedback(true);
      world_->addConstraint(joint.constraint.get());  // the model filter keeps them apart
    }
  }

  Pose bodyPose(int body) const override {
    const Body& b = bodies_[body];
    return fromBt(b.rigid->getCenterOfMassTransform() * btTransform(b.principal).inverse());
  }

  Twist bodyTwist(int body) const override {
    const btRigidBody& rigid = *bodies_[body].rigid;
    return {fromBt(rigid.getLinearVelocity()), fromBt(rigid.getAngularVelocity())};
  }

  void setBodyState(int body, const Pose& pose, const Twist& twist) override {
    setPose(body, pose);
    btRigidBody& rigid = *bodies_[body].rigid;
    rigid.setLinearVelocity(toBt(twist.linear));
    rigid.setAngularVelocity(toBt(twist.angular));
  }

  void setAnchoredShapePose(int shape, const Pose& world_pose) override {
    btCollisionObject* object = anchored_[shape].object.get();
    object->setWorldTransform(toBt(world_pose));
    world_->updateSingleAabb(object);
  }

  // Bullet keeps the inertia diagonal: the btRigidBody sits in the principal axes, which a new
  // inertia may turn, and its compound's children are placed in those axes.
  void setBodyMass(int body, const BodySpec& spec) override {
    Body& b = bodies_[body];
    btMatrix3x3 inertia(spec.ixx, spec.ixy, spec.ixz, spec.ixy, spec.iyy, spec.iyz, spec.ixz,
                        spec.iyz, spec.izz);
    btMatrix3x3 principal;  // columns: the principal axes in the BodySpec frame
    inertia.diagonalize(principal, SIMD_EPSILON, 100);
    principal.getRotation(b.principal);
    const btTransform from_principal = btTransform(b.principal).inverse();
    for (size_t s = 0; s < spec.shapes.size(); ++s)
      b.compound->updateChildTransform(static_cast<int>(s), from_principal * toBt(spec.shapes[s].pose));
    btRigidBody& rigid = *b.rigid;
    rigid.setMassProps(spec.mass, btVector3(inertia[0][0], inertia[1][1], inertia[2][2]));
    rigid.updateInertiaTensor();
    // World gravity reaches the bodies without BT_DISABLE_WORLD_GRAVITY (addRigidBody, and
    // setParams through btDiscreteDynamicsWorld::setGravity).
    rigid.setFlags(BT_ENABLE_GYROSCOPIC_FORCE_IMPLICIT_BODY |
                   (spec.gravity ? 0 : BT_DISABLE_WORLD_GRAVITY));
    rigid.setGravity(spec.gravity ? world_->getGravity() : btVector3(0, 0, 0));
  }

  double jointPosition(int joint) const override {
    const Joint& j = joints_[joint];
    const Pose parent = parentPose(j);
    const Pose child = bodyPose(j.spec.child);
    if (j.spec.prismatic) {
      const Vec3 offset = transformPoint(child, j.anchor_in_child) -
                          transformPoint(parent, j.anchor_in_parent);
      return dot(rotate(parent.orientation, j.axis_in_parent), offset);
    }
    // The child's rotation relative to the parent since the zero configuration is a pure
    // rotation about the axis (up to the constraint error, which this ignores).
    Quat turn = multiply(multiply(conjugate(parent.orientation), child.orientation),
                         conjugate(j.zero_relative));
    if (turn.w < 0) turn = {-turn.w, -turn.x, -turn.y, -turn.z};
    const double angle = 2 * std::atan2(dot({turn.x, turn.y, turn.z}, j.axis_in_parent), turn.w);
    return angle <= -M_PI ? angle + 2 * M_PI : angle;
  }

  double jointRate(int joint) const override {
    const Joint& j = joints_[joint];
    const Pose parent = parentPose(j);
    const Twist parent_twist = j.spec.parent < 0 ? Twist() : bodyTwist(j.spec.parent);
    const Twist child_twist = bodyTwist(j.spec.child);
    const Vec3 axis = rotate(parent.orientation, j.axis_in_parent);
    if (!j.spec.prismatic) return dot(axis, child_twist.angular - parent_twist.angular);
    // The derivative of jointPosition: both anchor points move, and the axis turns with the
    // parent.
    const Pose child = bodyPose(j.spec.child);
    const Vec3 child_arm = rotate(child.orientation, j.anchor_in_child);
    const Vec3 parent_arm = rotate(parent.orientation, j.anchor_in_parent);
    const Vec3 offset = (child.position + child_arm) - (parent.position + parent_arm);
    const Vec3 relative_velocity = (child_twist.linear + cross(child_twist.angular, child_arm)) -
                                   (parent_twist.linear + cross(parent_twist.angular, parent_arm));
    return dot(axis, relative_velocity) + dot(cross(parent_twist.angular, axis), offset);
  }

  // The solver sums each row's impulse over the step into the feedback, as forces and torques
  // about the bodies' centres of mass. The child is the hinge's body A and the slider's B.
  Wrench jointConstraintWrench(int joint) const override {
    const Joint& j = joints_[joint];
    const btJointFeedback& f = j.feedback;
    if (j.spec.prismatic) return {fromBt(f.m_appliedForceBodyB), fromBt(f.m_appliedTorqueBodyB)};
    return {fromBt(f.m_appliedForceBodyA), fromBt(f.m_appliedTorqueBodyA)};
  }

  void addJointEffort(int joint, double effort) override {
    const Joint& j = joints_[joint];
    btRigidBody& child = *bodies_[j.spec.child].rigid;
    btRigidBody* parent = j.spec.parent < 0 ? nullptr : bodies_[j.spec.parent].rigid.get();
    const btVector3 axis =
        effort * toBt(rotate(parentPose(j).orientation, j.axis_in_parent));
    if (!j.spec.prismatic) {
      child.applyTorque(axis);
      if (parent) parent->applyTorque(-axis);
      return;
    }
    child.applyCentralForce(axis);
    if (!parent) return;
    parent->applyCentralForce(-axis);
    // The two forces act along parallel lines through the two centres of mass: a couple unless
    // those lie on one line. Cancel it, half on each body, as ODE's dJointAddSliderForce does.
    const btVector3 couple = (child.getCenterOfMassPosition() - parent->getCenterOfMassPosition())
                                 .cross(axis);
    child.applyTorque(-0.5 * couple);
    parent->applyTorque(-0.5 * couple);
  }

  // The joint's motor: friction (vel 0, bound `friction`) unless a velocity motor is on.
  void setJointMotor(int joint, double velocity, double max_effort) override {
    Joint& j = joints_[joint];
    if (!j.constraint) return;
    const bool on = max_effort > 0;
    if (!j.spec.prismatic) {
      static_cast<MotorHinge&>(*j.constraint).setMotor(velocity, max_effort);
      return;
    }
    auto& slider = static_cast<btSliderConstraint&>(*j.constraint);
    const double bound = on ? max_effort : j.spec.friction;
    slider.setPoweredLinMotor(bound > 0);
    slider.setTargetLinMotorVelocity(on ? velocity : 0);
    slider.setMaxLinMotorForce(bound);  // a force: Bullet divides by the rate
  }

  void addBodyWrench(int body, const Vec3& force, const Vec3& world_point,
                     const Vec3& torque) override {
    btRigidBody& rigid = *bodies_[body].rigid;
    rigid.applyForce(toBt(force), toBt(world_point) - rigid.getCenterOfMassPosition());
    rigid.applyTorque(toBt(torque));
  }

 private:
  struct Body {
    std::vector<std::unique_ptr<MeshArrays>> arrays;  // per shape: a mesh's, else empty
    std::vector<std::unique_ptr<btCollisionShape>> shapes;
    std::unique_ptr<btCompoundShape> compound;
    std::unique_ptr<btRigidBody> rigid;
    btQuaternion principal;  // the btRigidBody's axes in the BodySpec frame
    ObjectTag tag;           // the btRigidBody's user pointer
  };
  struct Anchored {
    ObjectTag tag;  // the object's user pointer
    std::unique_ptr<MeshArrays> arrays;  // a mesh's
    std::unique_ptr<btCollisionShape> shape;
    std::unique_ptr<btCollisionObject> object;
  };
  struct Joint {
    JointSpec spec;
    // The joint line in the parent's frame (the world for parent -1) and the child's, and the
    // child's orientation relative to the parent, all in the zero configuration.
    Vec3 axis_in_parent, anchor_in_parent, anchor_in_child;
    Quat zero_relative;
    std::unique_ptr<btTypedConstraint> constraint;
    btJointFeedback feedback;  // the constraint points at it
  };

  Pose parentPose(const Joint& joint) const {
    return joint.spec.parent < 0 ? Pose() : bodyPose(joint.spec.parent);
  }

  void setPose(int body, const Pose& pose) {
    Body& b = bodies_[body];
    b.rigid->setCenterOfMassTransform(toBt(pose) * btTransform(b.principal));
  }

  void removeConstraints() {
    for (Joint& joint : joints_) {
      if (!joint.constraint) continue;
      world_->removeConstraint(joint.constraint.get());
      static_cast<BulletSolver*>(world_->getConstraintSolver())->forget(joint.constraint.get());
      joint.constraint.reset();
    }
  }

  btDiscreteDynamicsWorld* world_;
  std::deque<Body> bodies_;  // never moves a Body: its collision object points at its tag
  std::deque<Anchored> anchored_;  // likewise
  std::vector<Joint> joints_;
};

class BulletEngine : public Engine {
 public:
  BulletEngine() {
    btGImpactCollisionAlgorithm::registerAlgorithm(&dispatcher_);
    gContactAddedCallback = &onContactAdded;
    world_.getPairCache()->setOverlapFilterCallback(&filter_);
    btContactSolverInfo& solver = world_.getSolverInfo();
    // ODE's friction pyramid has two directions; Bullet's default, one along the sliding
    // velocity, lets a body at rest creep sideways under a steady push. Both are fixed in the
    // contact plane, as ODE's: along a sliding velocity they turn from step to step, and the
    // friction impulses the solver starts each step from (warm starting) then push along the
    // last step's directions. A two-wheeled base yawed 2.5 % faster than its wheels turned.
    // BulletSolver sets each point's directions (SOLVER_ENABLE_FRICTION_DIRECTION_CACHING
    // has the solver take them), turned to the slip where a point slides.
    solver.m_solverMode |= SOLVER_USE_2_FRICTION_DIRECTIONS |
                           SOLVER_DISABLE_VELOCITY_DEPENDENT_FRICTION_DIRECTION |
                           SOLVER_ENABLE_FRICTION_DIRECTION_CACHING;
    plane_cylinder_.m_swapped = true;
    dispatcher_.registerCollisionCreateFunc(CYLINDER_SHAPE_PROXYTYPE, STATIC_PLANE_PROXYTYPE,
                                            &cylinder_plane_);
    dispatcher_.registerCollisionCreateFunc(STATIC_PLANE_PROXYTYPE, CYLINDER_SHAPE_PROXYTYPE,
                                            &plane_cylinder_);
  }

  void setParams(const PhysicsParams& p) override {
    world_.setGravity(toBt(p.gravity));
    btContactSolverInfo& solver = world_.getSolverInfo();
    solver.m_numIterations = static_cast<int>(p.sor_pgs_iters);
    solver.m_sor = p.sor_pgs_w;
    solver.m_erp = p.erp;   // joints
    solver.m_erp2 = p.erp;  // contacts
    solver.m_globalCfm = p.cfm;
    solver.m_linearSlop = p.contact_surface_layer;
  }

  std::unique_ptr<EngineModel> addModel(const ModelSpec& spec) override {
    return std::make_unique<BulletModel>(&world_, next_model_id_++, spec);
  }

  // Sequential impulses: iterative, linear in the joints.
  bool exactSolver(const PhysicsParams&) const override { return false; }

  // maxSubSteps 0: exactly one step of dt, no fixed-step interpolation. Bullet reports no
  // solver trouble, so *solver_message is left alone. It has one solver and throws no
  // EngineFault (see the top of the file): a retake is a step, and no fault names bodies.
  void step(double dt, std::string*, bool) override {
    solver_.startStep();
    world_.stepSimulation(dt, 0);
    last_step_ = dt;
  }
  bool retakesFailedSteps(const PhysicsParams&) const override { return false; }
  std::vector<BodyRef> contactBodies() const override { return {}; }

  // The manifolds' points the last step's solver took (all within the contact processing
  // threshold, which is Bullet's default, infinite) that touch or carried an impulse: the impulses
  // the solver left on each (along the normal and the two friction directions, on the first
  // object) over the step's time. Bullet's split impulse, which pushes a deep penetration apart
  // beside the velocity solve, is no force and is left out.
  void contacts(std::vector<EngineContact>* out) const override {
    out->clear();
    if (!(last_step_ > 0)) return;
    for (int m = 0; m < dispatcher_.getNumManifolds(); ++m) {
      const btPersistentManifold* manifold = dispatcher_.getManifoldByIndexInternal(m);
      for (int p = 0; p < manifold->getNumContacts(); ++p) {
        const btManifoldPoint& point = manifold->getContactPoint(p);
        const double impulse = point.getAppliedImpulse();
        if (point.getDistance() > manifold->getContactProcessingThreshold() ||
            !(point.getDistance() <= 0 || impulse != 0))
          continue;
        const btVector3 total = impulse * point.m_normalWorldOnB +
                                point.m_appliedImpulseLateral1 * point.m_lateralFrictionDir1 +
                                point.m_appliedImpulseLateral2 * point.m_lateralFrictionDir2;
        out->push_back({shapeOf(manifold->getBody0(), point.m_index0),
                        shapeOf(manifold->getBody1(), point.m_index1),
                        fromBt(point.getPositionWorldOnA()), fromBt(point.m_normalWorldOnB),
                        -point.getDistance(), fromBt(total / last_step_)});
      }
    }
  }

  // Bullet's own ray test with the closest hit, as Gazebo's Bullet ray shape casts: the
  // broadphase's ray traversal finds the objects whose bounds a ray crosses, and each of their
  // shapes (a compound's children one by one, those whose bounds it crosses) is cast against as
  // btCollisionWorld::rayTest does, with rayTestSingle, but for boxes. A box is met where
  // Bullet's slab test (btRayAabb, in the box's frame) meets it: the GJK cast rayTestSingle
  // makes converges to the same face (to within its epsilon, 5e-8 m in double precision) in up
  // to 64 iterations, most of a scan's time among walls. As the cast does, a box that holds the
  // ray's start (inside or on its surface) is not met: the cast's distance is within its epsilon
  // there and the hit it returns has no normal, which rayTestSingle drops (a lidar on a box
  // link, as the book's mobot carries it, starts every ray on that box's face). Bodies set to a
  // state since the last step have stale bounding boxes in the broadphase: they are brought up
  // to date first.
  void castRays(const std::vector<Ray>& rays, std::vector<double>* distances) override {
    distances->assign(rays.size(), std::numeric_limits<double>::infinity());
    world_.updateAabbs();
    for (size_t i = 0; i < rays.size(); ++i) {
      const Ray& ray = rays[i];
      if (!(ray.length > 0)) continue;
      const btVector3 from = toBt(ray.from);
      const btVector3 to = from + toBt(ray.direction) * ray.length;
      RayCast cast(from, to);
      broadphase_.rayTest(from, to, cast);
      if (cast.closest.hasHit()) (*distances)[i] = cast.closest.m_closestHitFraction * ray.length;
    }
  }

 private:
  // One ray through the broadphase: each object it reaches, cast against as rayTest does.
  struct RayCast : btBroadphaseRayCallback {
    RayCast(const btVector3& from_point, const btVector3& to_point)
        : from(btTransform::getIdentity()), to(btTransform::getIdentity()),
          closest(from_point, to_point) {
      from.setOrigin(from_point);
      to.setOrigin(to_point);
      const btVector3 direction = (to_point - from_point).normalized();
      for (int axis = 0; axis < 3; ++axis) {
        m_rayDirectionInverse[axis] =
            direction[axis] == 0 ? btScalar(BT_LARGE_FLOAT) : 1 / direction[axis];
        m_signs[axis] = m_rayDirectionInverse[axis] < 0;
      }
      m_lambda_max = direction.dot(to_point - from_point);
    }

    bool process(const btBroadphaseProxy* proxy) override {
      if (closest.m_closestHitFraction == 0) return false;  // nothing can be nearer
      auto* object = static_cast<btCollisionObject*>(proxy->m_clientObject);
      if (!closest.needsCollision(object->getBroadphaseHandle())) return true;
      const btCollisionShape* shape = object->getCollisionShape();
      if (!shape->isCompound()) {
        castShape(object, shape, object->getWorldTransform());
        return true;
      }
      const auto* compound = static_cast<const btCompoundShape*>(shape);
      for (int child = 0; child < compound->getNumChildShapes(); ++child) {
        const btTransform pose = object->getWorldTransform() * compound->getChildTransform(child);
        const btCollisionShape* child_shape = compound->getChildShape(child);
        btVector3 low, high, normal;
        child_shape->getAabb(pose, low, high);
        btScalar fraction = 1;
        if (btRayAabb(from.getOrigin(), to.getOrigin(), low, high, fraction, normal))
          castShape(object, child_shape, pose);
      }
      return true;
    }

    void castShape(btCollisionObject* object, const btCollisionShape* shape,
                   const btTransform& pose) {
      if (shape->getShapeType() != BOX_SHAPE_PROXYTYPE) {
        btCollisionWorld::rayTestSingle(from, to, object, shape, pose, closest);
        return;
      }
      const btVector3 start = pose.invXform(from.getOrigin());
      const btVector3 end = pose.invXform(to.getOrigin());
      const btVector3 half = static_cast<const btBoxShape*>(shape)->getHalfExtentsWithMargin();
      constexpr btScalar kOnSurface = 1e-9;
      if (std::fabs(start.x()) <= half.x() + kOnSurface &&
          std::fabs(start.y()) <= half.y() + kOnSurface &&
          std::fabs(start.z()) <= half.z() + kOnSurface)
        return;
      btScalar fraction = closest.m_closestHitFraction;
      btVector3 normal;
      if (!btRayAabb(start, end, -half, half, fraction, normal) ||
          !(fraction < closest.m_closestHitFraction))
        return;
      btCollisionWorld::LocalRayResult hit(object, nullptr, pose.getBasis() * normal, fraction);
      closest.addSingleResult(hit, true);
    }

    btTransform from, to;
    btCollisionWorld::ClosestRayResultCallback closest;
  };

  // Declared in construction order; the world goes first on destruction.
  btDefaultCollisionConfiguration configuration_;
  CylinderPlane::CreateFunc cylinder_plane_, plane_cylinder_;
  btCollisionDispatcher dispatcher_{&configuration_};
  btDbvtBroadphase broadphase_;
  BulletSolver solver_;
  ModelFilter filter_;
  btDiscreteDynamicsWorld world_{&dispatcher_, &broadphase_, &solver_, &configuration_};
  int next_model_id_ = 0;
  double last_step_ = 0;  // s, the last step's (contacts)
};

}  // namespace

std::unique_ptr<Engine> makeBulletEngine() { return std::make_unique<BulletEngine>(); }

}  // namespace core
}  // namespace onedof_sim
