// DART 6.12 behind the engine seam: generalized coordinates. Each model is a dart Skeleton whose
// bodies form trees: a body that is the child of a joint hangs from that joint's parent (the
// world for parent -1) on a RevoluteJoint or PrismaticJoint; a body that is no joint's child is a
// tree's root on a FreeJoint. Each of the model's anchored shapes is a root of its own on a
// WeldJoint, placed by its weld. Featherstone's articulated-body algorithm steps the trees (cost
// linear in the joints, the joints exact: no joint drifts apart), and DART's boxed LCP (Dantzig,
// PGS where Dantzig fails) resolves contacts, joint stops, joint friction and velocity motors
// together, as Gazebo's DART engine does.
//
// What DART cannot do is refused at spawn (addModel throws EngineFault before it touches the
// engine, which World reports as the model's refusal): a body that is the child of two joints
// (a closed kinematic loop), which a tree of generalized coordinates cannot hold.
//
// Collision: DART's ODE collision detector (dart-collision-ode), the only one of DART's four
// that collides every shape the seam has: boxes, spheres, cylinders, planes and triangle meshes,
// against each other, with ODE's own box-box and cylinder-plane manifolds, as the ode engine
// collides (DART's own detector has no cylinders or meshes, and DART's Bullet detector would bring
// Bullet's single-precision libraries into a process that holds the bullet engine's
// double-precision ones under the same symbols; FCL, DART's default, was not tried). Bodies of one model
// never collide (one skeleton, self-collision off), nor two anchored shapes (ModelFilter).
// Friction follows Coulomb's law (CoulombContact, CoulombSolver): along the slip at a sliding
// contact, within mu times the normal force the step ends with everywhere.
//
// Rays: DART's ODE detector casts none; the rays go through ODE's ray collision against the
// detector's own ODE space (ode_rays.h), the geoms DART's contacts are made from.
//
// PhysicsParams: gravity; erp, cfm (at least DART's floor, 1e-9), contact_surface_layer (the
// allowed penetration) and contact_max_correcting_vel map onto DART's contact constraints, erp and
// cfm onto its joint stops. DART keeps these per process (static members of its constraint
// classes): each step sets them from its own engine's parameters. Ignored: quick_step (DART's
// solver is Dantzig's, PGS where it fails), sor_pgs_* (PGS's own defaults), auto_disable_bodies
// (nothing sleeps). max_contacts: the deepest of a pair of shapes' points that the solve takes.
//
// DART's boxed LCP solver is a copy of ODE's (dart::external::ode), whose failed assertions (a
// singular factorisation on a body of implausible inertia) end the process once their handler
// returns. Inside a step its handler throws EngineFault instead (the engine can then only be read
// and destroyed; World builds a new one and takes out a model the step's contacts involve). A
// body DART otherwise cannot step comes out non-finite, which the world's rollback takes back
// (World::stepEngine).
#include <assimp/scene.h>

#include <dart/collision/CollisionFilter.hpp>
#include <dart/collision/CollisionObject.hpp>
#include <dart/collision/ode/OdeCollisionDetector.hpp>
#include <dart/collision/ode/OdeCollisionGroup.hpp>
#include <dart/constraint/BoxedLcpConstraintSolver.hpp>
#include <dart/constraint/ConstrainedGroup.hpp>
#include <dart/constraint/ConstraintSolver.hpp>
#include <dart/constraint/ContactConstraint.hpp>
#include <dart/constraint/JointLimitConstraint.hpp>
#include <dart/dynamics/BodyNode.hpp>
#include <dart/dynamics/BoxShape.hpp>
#include <dart/dynamics/CylinderShape.hpp>
#include <dart/dynamics/FreeJoint.hpp>
#include <dart/dynamics/MeshShape.hpp>
#include <dart/dynamics/PlaneShape.hpp>
#include <dart/dynamics/PrismaticJoint.hpp>
#include <dart/dynamics/RevoluteJoint.hpp>
#include <dart/dynamics/ShapeNode.hpp>
#include <dart/dynamics/Skeleton.hpp>
#include <dart/dynamics/SphereShape.hpp>
#include <dart/dynamics/WeldJoint.hpp>
#include <dart/simulation/World.hpp>

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <limits>
#include <string>
#include <unordered_map>
#include <unordered_set>

#include "contact_rules.h"
#include "engine.h"
#include "ode_rays.h"
#include "onedof_sim/pose_math.h"

// The handlers of DART's copy of ODE's LCP solver (dart/external/odelcpsolver/error.h, whose
// include guard is ODE's own error.h's, so that it is not read after <ode/ode.h>).
namespace dart {
namespace external {
namespace ode {
typedef void dMessageFunction(int errnum, const char* msg, va_list ap);
void dSetErrorHandler(dMessageFunction* fn);
void dSetDebugHandler(dMessageFunction* fn);
}  // namespace ode
}  // namespace external
}  // namespace dart

namespace onedof_sim {
namespace core {
namespace {

namespace dd = dart::dynamics;

// Inside a step: an LCP solver's failed assertion throws EngineFault (see the top of the file).
thread_local int stepping = 0;

void throwLcpError(int number, const char* format, va_list args) {
  faultFromErrorHandler("DART's LCP solver", stepping > 0, number, format, args);
}

// DART's smallest constraint force mixing (ContactConstraint and JointLimitConstraint warn on
// less and take this).
constexpr double kMinCfm = 1e-9;

Eigen::Vector3d toEigen(const Vec3& v) { return {v.x, v.y, v.z}; }
Vec3 fromEigen(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

Eigen::Isometry3d toEigen(const Pose& pose) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  const Quat q = normalized(pose.orientation);
  t.linear() = Eigen::Quaterniond(q.w, q.x, q.y, q.z).toRotationMatrix();
  t.translation() = toEigen(pose.position);
  return t;
}

Pose fromEigen(const Eigen::Isometry3d& t) {
  const Eigen::Quaterniond q(t.linear());
  return {fromEigen(t.translation()), {q.w(), q.x(), q.y(), q.z()}};
}

// The protected parts of DART's ODE collision group that the rays need: its ODE space, and the
// update that moves its geoms to their shape frames. Named through a class that makes them public;
// the pointers are to OdeCollisionGroup's own members.
struct OdeGroupAccess : dart::collision::OdeCollisionGroup {
  using OdeCollisionGroup::getOdeSpaceId;
  using CollisionGroup::updateEngineData;
};
constexpr dSpaceID (dart::collision::OdeCollisionGroup::*kOdeSpace)() const =
    &OdeGroupAccess::getOdeSpaceId;
constexpr void (dart::collision::CollisionGroup::*kMoveGeoms)() = &OdeGroupAccess::updateEngineData;

// A mesh as DART takes it: an assimp scene of one triangle mesh (float vertices, as assimp keeps
// them). The MeshShape that takes it deletes it (aiReleaseImport on a scene no importer made).
// DART's ODE detector hands the scene's vertex normals to ODE as its face normals (triangle t's
// at index t): each triangle gets three vertices of its own, so that there are more vertices
// than triangles, and vertex t's normal is triangle t's.
const aiScene* sceneOf(const TriangleMesh& mesh) {
  const unsigned triangles = static_cast<unsigned>(mesh.triangles.size());
  auto* part = new aiMesh;
  part->mPrimitiveTypes = aiPrimitiveType_TRIANGLE;
  part->mNumVertices = 3 * triangles;
  part->mVertices = new aiVector3D[part->mNumVertices];
  part->mNormals = new aiVector3D[part->mNumVertices];
  part->mNumFaces = triangles;
  part->mFaces = new aiFace[triangles];
  const auto toAi = [](const Vec3& v) {
    return aiVector3D(static_cast<ai_real>(v.x), static_cast<ai_real>(v.y),
                      static_cast<ai_real>(v.z));
  };
  for (unsigned t = 0; t < triangles; ++t) {
    aiFace& face = part->mFaces[t];
    face.mNumIndices = 3;
    face.mIndices = new unsigned[3];
    for (unsigned k = 0; k < 3; ++k) {
      face.mIndices[k] = 3 * t + k;
      part->mVertices[3 * t + k] = toAi(mesh.vertices[mesh.triangles[t][k]]);
    }
    const Vec3& a = mesh.vertices[mesh.triangles[t][0]];
    const Vec3 normal =
        cross(mesh.vertices[mesh.triangles[t][1]] - a, mesh.vertices[mesh.triangles[t][2]] - a);
    const double length = norm(normal);
    part->mNormals[t] = length > 0 ? toAi((1 / length) * normal) : aiVector3D(0, 0, 0);
  }
  auto* scene = new aiScene;
  scene->mNumMeshes = 1;
  scene->mMeshes = new aiMesh*[1]{part};
  scene->mNumMaterials = 1;
  scene->mMaterials = new aiMaterial*[1]{new aiMaterial};
  scene->mRootNode = new aiNode;
  scene->mRootNode->mNumMeshes = 1;
  scene->mRootNode->mMeshes = new unsigned[1]{0};
  return scene;
}

dd::ShapePtr makeShape(const ShapeSpec& spec) {
  const Vec3& s = spec.size;
  switch (spec.shape) {
    case GeometryShape::Box:
      return std::make_shared<dd::BoxShape>(toEigen(s));
    case GeometryShape::Cylinder:
      return std::make_shared<dd::CylinderShape>(s.x, s.z);
    case GeometryShape::Sphere:
      return std::make_shared<dd::SphereShape>(s.x);
    case GeometryShape::Plane:  // anchored only: the plane z = 0 of its weld's frame
      return std::make_shared<dd::PlaneShape>(Eigen::Vector3d::UnitZ(), 0.0);
    case GeometryShape::Mesh:
      return std::make_shared<dd::MeshShape>(Eigen::Vector3d::Ones(), sceneOf(*spec.mesh));
  }
  throw EngineFault("dart: unknown collision shape");
}

// A shape on a body, colliding, with its friction.
dd::ShapeNode* attachShape(dd::BodyNode* body, const ShapeSpec& spec) {
  dd::ShapeNode* node =
      body->createShapeNodeWith<dd::CollisionAspect, dd::DynamicsAspect>(makeShape(spec));
  dd::DynamicsAspect* dynamics = node->getDynamicsAspect();
  dynamics->setFrictionCoeff(spec.mu);
  dynamics->setSecondaryFrictionCoeff(spec.mu2);
  dynamics->setRestitutionCoeff(0);
  return node;
}

// Two shapes of one model never collide (one skeleton, self-collision off), nor two that neither
// moves (anchored shapes, a static model's).
struct ModelFilter : dart::collision::CollisionFilter {
  bool ignoresCollision(const dart::collision::CollisionObject* a,
                        const dart::collision::CollisionObject* b) const override {
    const dd::ShapeNode* node_a = a->getShapeFrame()->asShapeNode();
    const dd::ShapeNode* node_b = b->getShapeFrame()->asShapeNode();
    if (!node_a || !node_b) return true;
    const dd::BodyNode* body_a = node_a->getBodyNodePtr().get();
    const dd::BodyNode* body_b = node_b->getBodyNodePtr().get();
    return body_a->getSkeleton() == body_b->getSkeleton() ||
           (!body_a->isReactive() && !body_b->isReactive());
  }
};

// What the engine keeps of each collision shape: which one it is (contacts), and its friction
// across the first direction (CoulombContact takes it away at a sliding contact).
struct ShapeInfo {
  ShapeRef ref;
  double mu2 = 1;
};
using ShapeRefs = std::unordered_map<const dd::ShapeFrame*, ShapeInfo>;

// At most this many solves of a constrained group a step, and the relative change (with a floor,
// N s) of every contact's normal impulse from one to the next under which they agree
// (CoulombSolver).
constexpr int kFrictionPasses = 10;
constexpr double kNormalImpulseTolerance = 1e-3;
constexpr double kNormalImpulseFloor = 1e-9;

// A contact held to Coulomb's law (contact_rules.h). Sliding faster than kSlidingSpeed, its one
// friction row is along the slip, bounded by mu N (DART's first friction direction, taken from its
// first shape's dynamics when it is built, set to the slip, and that shape's mu2 to 0 for its
// second row); slower, DART's pyramid, its directions fixed in the contact plane.
// fixFrictionBounds then bounds its friction rows by a normal impulse of its own instead of the
// one the solve finds.
class CoulombContact : public dart::constraint::ContactConstraint {
 public:
  CoulombContact(dart::collision::Contact& contact, double dt, const ShapeRefs& shapes)
      : ContactConstraint(frictionAlongSlip(contact, shapes), dt), contact_(&contact) {}

  const dart::collision::Contact& contact() const { return *contact_; }

  // A normal impulse below 0 (rounding) or not finite bounds the friction at 0: the boxed LCP
  // takes no bounds on the wrong side of 0.
  void fixFrictionBounds(double normal_impulse) {
    fixed_ = true;
    normal_impulse_ = normal_impulse > 0 && std::isfinite(normal_impulse) ? normal_impulse : 0;
  }
  double normalImpulse(double dt) const {
    return contact_->force.dot(contact_->normal) * dt;
  }

 protected:
  void getInformation(dart::constraint::ConstraintInfo* info) override {
    ContactConstraint::getInformation(info);
    if (!fixed_ || getDimension() < 3) return;
    for (int row = 1; row < 3; ++row) {  // mu and mu2 times the normal impulse, fixed
      info->findex[row] = -1;
      info->lo[row] *= normal_impulse_;
      info->hi[row] *= normal_impulse_;
    }
  }

 private:
  // Sets the contact's shapes' friction dynamics for DART's ContactConstraint to read.
  static dart::collision::Contact& frictionAlongSlip(dart::collision::Contact& contact,
                                                     const ShapeRefs& shapes) {
    const dd::ShapeFrame* frames[2] = {contact.collisionObject1->getShapeFrame(),
                                       contact.collisionObject2->getShapeFrame()};
    Eigen::Vector3d slip = Eigen::Vector3d::Zero();
    for (int side = 0; side < 2; ++side) {
      const dd::BodyNode* body = frames[side]->asShapeNode()->getBodyNodePtr().get();
      const Eigen::Vector3d velocity =
          body->getLinearVelocity() +
          body->getAngularVelocity().cross(contact.point - body->getWorldTransform().translation());
      slip += side == 0 ? velocity : -velocity;
    }
    Vec3 in_plane;
    const bool sliding = slides(fromEigen(slip), fromEigen(contact.normal), &in_plane);
    for (int side = 0; side < 2; ++side) {
      auto* node = const_cast<dd::ShapeFrame*>(frames[side])->asShapeNode();
      dd::DynamicsAspect* dynamics = node->getDynamicsAspect();
      const auto info = shapes.find(frames[side]);
      const bool along_slip = sliding && side == 0;
      dynamics->setFirstFrictionDirectionFrame(along_slip ? dd::Frame::World() : nullptr);
      dynamics->setFirstFrictionDirection(along_slip ? toEigen(in_plane).normalized()
                                                     : Eigen::Vector3d::Zero().eval());
      dynamics->setSecondaryFrictionCoeff(along_slip || info == shapes.end() ? 0.0
                                                                            : info->second.mu2);
    }
    return contact;
  }

  dart::collision::Contact* contact_;  // the solver's collision result's
  bool fixed_ = false;
  double normal_impulse_ = 0;
};

// DART's boxed-LCP solver (Dantzig, PGS where it fails) with Coulomb's law at every contact: its
// Dantzig solver, as ODE's, bounds each friction row by the normal impulse its contact had when
// the row was reached, not the one the solve ends with (a base whose wheel motors push against a
// sliding caster loads the caster with the motors' reaction, and crawls). So a group with contacts
// is solved again, from the same velocities, with each contact's friction bounded by mu times the
// normal impulse of the last solve, until those impulses agree from one solve to the next.
class CoulombSolver : public dart::constraint::BoxedLcpConstraintSolver {
 public:
  explicit CoulombSolver(const ShapeRefs* shapes) : shapes_(shapes) {}
  void setMaxContacts(int max_contacts) { max_contacts_ = max_contacts; }
  // The contacts the solves since forgetSolved took in.
  bool solved(const dart::collision::Contact* contact) const { return solved_.count(contact); }
  void forgetSolved() {
    solved_.clear();
    middles_.clear();
  }

 protected:
  void solveConstrainedGroup(dart::constraint::ConstrainedGroup& group) override {
    namespace dc = dart::constraint;
    const auto contact_of = contactsOfConstraints();
    std::vector<dc::ConstraintBasePtr> constraints;
    std::vector<std::shared_ptr<CoulombContact>> contacts;
    for (size_t i = 0; i < group.getNumConstraints(); ++i) {
      dc::ConstraintBasePtr constraint = group.getConstraint(i);
      const auto contact = contact_of.find(constraint.get());
      if (contact != contact_of.end()) {
        if (!kept(*contact->second) || !lineMiddle(contact->second)) continue;
        solved_.insert(contact->second);
        auto coulomb = std::make_shared<CoulombContact>(*contact->second, mTimeStep, *shapes_);
        static_cast<dc::ConstraintBase&>(*coulomb).update();
        contacts.push_back(coulomb);
        constraint = coulomb;
      }
      constraints.push_back(constraint);
    }
    group.removeAllConstraints();
    for (const dc::ConstraintBasePtr& constraint : constraints) group.addConstraint(constraint);
    BoxedLcpConstraintSolver::solveConstrainedGroup(group);
    std::vector<double> normals(contacts.size());
    for (size_t k = 0; k < contacts.size(); ++k) normals[k] = contacts[k]->normalImpulse(mTimeStep);
    for (int pass = 0; pass < kFrictionPasses && !contacts.empty(); ++pass) {
      for (size_t k = 0; k < contacts.size(); ++k) contacts[k]->fixFrictionBounds(normals[k]);
      for (const auto& contact : contacts)
        for (const dart::collision::CollisionObject* object :
             {contact->contact().collisionObject1, contact->contact().collisionObject2})
          std::const_pointer_cast<dd::Skeleton>(
              object->getShapeFrame()->asShapeNode()->getBodyNodePtr()->getSkeleton())
              ->clearConstraintImpulses();
      BoxedLcpConstraintSolver::solveConstrainedGroup(group);
      bool agree = true;
      for (size_t k = 0; k < contacts.size(); ++k) {
        const double normal = contacts[k]->normalImpulse(mTimeStep);
        if (std::fabs(normal - normals[k]) >
            kNormalImpulseTolerance * std::fabs(normal) + kNormalImpulseFloor)
          agree = false;
        normals[k] = normal;
      }
      if (agree) break;
    }
  }


 private:
  // A cylinder lying on a face touches it along a line, of which ODE's collision gives the two
  // end points on the rims; each engine resolves it by its middle (contact_rules.h). The line's
  // first end becomes its middle, carrying the whole line's load and friction; false for its
  // second end, which leaves the solve. A cylinder lying within kLyingTilt with one rim a little
  // higher than the other gets the lower rim's point alone, which becomes the middle of the line
  // from it to the other end (otherLineEnd), as the ode engine takes it: else the contact jumps
  // from the middle to a rim and back as the cylinder rocks by microradians (a turning base's
  // wheels and casters do), and a caster held at its rim drags its base.
  bool lineMiddle(dart::collision::Contact* contact) {
    const dart::collision::Contact* ends[2] = {nullptr, nullptr};
    int count = 0;
    for (size_t i = 0; i < mCollisionResult.getNumContacts(); ++i) {
      const dart::collision::Contact& other = mCollisionResult.getContact(i);
      if (other.collisionObject1 != contact->collisionObject1 ||
          other.collisionObject2 != contact->collisionObject2)
        continue;
      if (count < 2) ends[count] = &other;
      ++count;
    }
    if (count != 1 && count != 2) return true;
    TouchPoint points[2] = {touchPoint(*ends[0]), {}};
    if (count == 2) points[1] = touchPoint(*ends[1]);
    for (const dart::collision::CollisionObject* object :
         {contact->collisionObject1, contact->collisionObject2}) {
      if (!object->getShape()->is<dd::CylinderShape>()) continue;
      const Eigen::Isometry3d& pose = object->getTransform();
      const Vec3 axis = fromEigen(pose.linear().col(2).eval());
      if (count == 1) {
        const Vec3 centre = fromEigen(pose.translation());
        // The normal's way that points out of the face towards the cylinder.
        const Vec3 into_cylinder = dot(centre - points[0].position, points[0].normal) >= 0
                                       ? points[0].normal
                                       : -points[0].normal;
        const double length = static_cast<const dd::CylinderShape&>(*object->getShape()).getHeight();
        if (!otherLineEnd(centre, axis, length, into_cylinder, points[0], &points[1])) continue;
      } else if (!areLineEnds(axis, points[0], points[1])) {
        continue;
      }
      if (contact == ends[1]) return false;
      if (middles_.insert(contact).second) {  // once a step: the group may be solved again
        const TouchPoint middle = pointOnLine(points[0], points[1], 0.5);
        contact->point = toEigen(middle.position);
        contact->penetrationDepth = middle.depth;
      }
      return true;
    }
    return true;
  }

  static TouchPoint touchPoint(const dart::collision::Contact& contact) {
    return {fromEigen(contact.point), fromEigen(contact.normal), contact.penetrationDepth};
  }

  // Whether the contact is among the max_contacts deepest of its pair of shapes (a dense mesh
  // touches the ground at hundreds of points, ODE's collision gives them all, and the boxed LCP's
  // cost grows as their cube), as the ode engine keeps them.
  bool kept(const dart::collision::Contact& contact) const {
    int deeper = 0;
    for (size_t i = 0; i < mCollisionResult.getNumContacts(); ++i) {
      const dart::collision::Contact& other = mCollisionResult.getContact(i);
      if (other.collisionObject1 == contact.collisionObject1 &&
          other.collisionObject2 == contact.collisionObject2 &&
          (other.penetrationDepth > contact.penetrationDepth ||
           (other.penetrationDepth == contact.penetrationDepth && &other < &contact)))
        ++deeper;
    }
    return deeper < max_contacts_;
  }

  // The contact each of this step's contact constraints was made from. DART 6.12's
  // ConstraintSolver::updateConstraints makes one, in order, for each contact of the collision
  // result with a nonzero normal (no shape here is soft); where the counts disagree, none is
  // matched and DART's own contacts stand.
  std::unordered_map<const dart::constraint::ConstraintBase*, dart::collision::Contact*>
  contactsOfConstraints() {
    std::vector<dart::collision::Contact*> made;
    for (size_t i = 0; i < mCollisionResult.getNumContacts(); ++i) {
      dart::collision::Contact& contact = mCollisionResult.getContact(i);
      if (!dart::collision::Contact::isZeroNormal(contact.normal)) made.push_back(&contact);
    }
    std::unordered_map<const dart::constraint::ConstraintBase*, dart::collision::Contact*> out;
    if (made.size() != mContactConstraints.size()) return out;
    for (size_t k = 0; k < made.size(); ++k) out[mContactConstraints[k].get()] = made[k];
    return out;
  }

  const ShapeRefs* shapes_;
  int max_contacts_ = 20;
  std::unordered_set<const dart::collision::Contact*> solved_;
  std::unordered_set<const dart::collision::Contact*> middles_;  // lines' ends made their middles
};

class DartModel : public EngineModel {
 public:
  // models: the engine's list of its models, which this one joins while it lives.
  DartModel(dart::simulation::World* world, ShapeRefs* shape_refs, std::vector<DartModel*>* models,
            int id, const ModelSpec& spec)
      : world_(world), shape_refs_(shape_refs), models_(models) {
    const int body_count = static_cast<int>(spec.bodies.size());
    parent_joint_.assign(body_count, -1);
    for (size_t j = 0; j < spec.joints.size(); ++j) {
      const JointSpec& joint = spec.joints[j];
      if (parent_joint_[joint.child] >= 0)
        throw EngineFault(
            "dart: a link that is the child of two joints (a closed kinematic loop) is not "
            "supported");
      parent_joint_[joint.child] = static_cast<int>(j);
    }
    order_ = treeOrder(spec);
    skeleton_ = dd::Skeleton::create("model_" + std::to_string(id));
    skeleton_->disableSelfCollisionCheck();
    bodies_.assign(body_count, nullptr);
    body_shapes_.resize(body_count);
    joints_.resize(spec.joints.size());
    for (int b : order_) {
      const int j = parent_joint_[b];
      dd::BodyNode* parent = j < 0 || spec.joints[j].parent < 0 ? nullptr
                                                                : bodies_[spec.joints[j].parent];
      dd::BodyNode::Properties body_properties;
      body_properties.mName = "body_" + std::to_string(b);
      if (j < 0) {
        dd::FreeJoint::Properties root;
        root.mName = "root_" + std::to_string(b);
        bodies_[b] =
            skeleton_->createJointAndBodyNodePair<dd::FreeJoint>(nullptr, root, body_properties)
                .second;
      } else {
        joints_[j].spec = spec.joints[j];
        joints_[j].joint = createJoint(parent, spec.joints[j], "joint_" + std::to_string(j),
                                       body_properties, &bodies_[b]);
      }
      for (size_t s = 0; s < spec.bodies[b].shapes.size(); ++s) {
        body_shapes_[b].push_back(attachShape(bodies_[b], spec.bodies[b].shapes[s]));
        (*shape_refs_)[body_shapes_[b].back()] = {{this, b, static_cast<int>(s)},
                                                  spec.bodies[b].shapes[s].mu2};
      }
      setBodyMass(b, spec.bodies[b]);
    }
    for (size_t s = 0; s < spec.anchored_shapes.size(); ++s) {
      dd::BodyNode::Properties body_properties;
      body_properties.mName = "anchored_" + std::to_string(s);
      dd::WeldJoint::Properties weld;
      weld.mName = "anchor_" + std::to_string(s);
      auto pair =
          skeleton_->createJointAndBodyNodePair<dd::WeldJoint>(nullptr, weld, body_properties);
      anchored_.push_back(pair.first);
      const dd::ShapeNode* node = attachShape(pair.second, spec.anchored_shapes[s]);
      (*shape_refs_)[node] = {{this, -1, static_cast<int>(s)}, spec.anchored_shapes[s].mu2};
      setAnchoredShapePose(static_cast<int>(s), spec.anchored_shapes[s].pose);
    }
    pending_poses_.resize(body_count);
    pending_twists_.resize(body_count);
    world_->addSkeleton(skeleton_);
    models_->push_back(this);
  }

  ~DartModel() override {
    models_->erase(std::find(models_->begin(), models_->end(), this));
    world_->removeSkeleton(skeleton_);
    for (auto it = shape_refs_->begin(); it != shape_refs_->end();)
      it = it->second.ref.model == this ? shape_refs_->erase(it) : std::next(it);
  }

  // The joints' frames in their bodies: each joint's frame is at the anchor with the world's
  // axes in the zero configuration, the axis given in it.
  void attachJoints(const std::vector<Pose>& zero_poses,
                    const std::vector<JointFrame>& frames) override {
    for (size_t j = 0; j < joints_.size(); ++j) {
      Joint& joint = joints_[j];
      Eigen::Isometry3d frame = Eigen::Isometry3d::Identity();
      frame.translation() = toEigen(frames[j].anchor);
      const Eigen::Isometry3d parent =
          joint.spec.parent < 0 ? Eigen::Isometry3d::Identity() : toEigen(zero_poses[joint.spec.parent]);
      joint.joint->setTransformFromParentBodyNode(parent.inverse() * frame);
      joint.joint->setTransformFromChildBodyNode(toEigen(zero_poses[joint.spec.child]).inverse() * frame);
      const Eigen::Vector3d axis = toEigen(frames[j].axis);
      if (joint.spec.prismatic)
        static_cast<dd::PrismaticJoint*>(joint.joint)->setAxis(axis);
      else
        static_cast<dd::RevoluteJoint*>(joint.joint)->setAxis(axis);
    }
    for (size_t b = 0; b < bodies_.size(); ++b) {
      pending_poses_[b] = zero_poses[b];
      pending_twists_[b] = Twist();
    }
    pending_ = true;
  }

  Pose bodyPose(int body) const override {
    applyPending();
    return fromEigen(bodies_[body]->getWorldTransform());
  }

  Twist bodyTwist(int body) const override {
    applyPending();
    return {fromEigen(bodies_[body]->getLinearVelocity()),
            fromEigen(bodies_[body]->getAngularVelocity())};
  }

  // Kept until the model is next read or stepped, when every body's state set since goes into
  // the generalized coordinates at once (applyPending): a joint's position comes from its two
  // bodies' poses, whichever of them was set first.
  void setBodyState(int body, const Pose& pose, const Twist& twist) override {
    if (!pending_) {
      for (size_t b = 0; b < bodies_.size(); ++b) {
        pending_poses_[b] = fromEigen(bodies_[b]->getWorldTransform());
        pending_twists_[b] = {fromEigen(bodies_[b]->getLinearVelocity()),
                              fromEigen(bodies_[b]->getAngularVelocity())};
      }
      pending_ = true;
    }
    pending_poses_[body] = pose;
    pending_twists_[body] = twist;
  }

  void setAnchoredShapePose(int shape, const Pose& world_pose) override {
    anchored_[shape]->setTransformFromParentBodyNode(toEigen(world_pose));
  }

  void setBodyMass(int body, const BodySpec& spec) override {
    dd::BodyNode* node = bodies_[body];
    node->setMass(spec.mass);
    node->setMomentOfInertia(spec.ixx, spec.iyy, spec.izz, spec.ixy, spec.ixz, spec.iyz);
    node->setLocalCOM(Eigen::Vector3d::Zero());
    node->setGravityMode(spec.gravity);
    for (size_t s = 0; s < spec.shapes.size(); ++s)
      body_shapes_[body][s]->setRelativeTransform(toEigen(spec.shapes[s].pose));
  }

  double jointPosition(int joint) const override {
    applyPending();
    const Joint& j = joints_[joint];
    const double position = j.joint->getPosition(0);
    if (j.spec.prismatic) return position;
    const double wrapped = std::remainder(position, 2 * M_PI);
    return wrapped <= -M_PI ? wrapped + 2 * M_PI : wrapped;
  }

  double jointRate(int joint) const override {
    applyPending();
    return joints_[joint].joint->getVelocity(0);
  }

  // What the joint put on its child in the last step, about the child's centre of mass, in world
  // axes: DART's transmitted wrench (the constraint impulses of the step included), which is what
  // the child puts on the joint, turned round. Joint efforts reach the bodies as external forces
  // (addJointEffort), so none is in it.
  Wrench jointConstraintWrench(int joint) const override {
    if (!stepped_) return {};
    const Joint& j = joints_[joint];
    const dd::BodyNode* child = bodies_[j.spec.child];
    const Eigen::Vector6d wrench = j.joint->getWrenchToChildBodyNode(child);
    const Eigen::Matrix3d rotation = child->getWorldTransform().linear();
    return {fromEigen(-rotation * wrench.tail<3>()), fromEigen(-rotation * wrench.head<3>())};
  }

  // As a torque (hinge) or a force along the joint's line through the child's centre of mass
  // (slider) on the child, and its opposite on the parent: DART's passive and servo joints take
  // no joint force.
  void addJointEffort(int joint, double effort) override {
    applyPending();
    const Joint& j = joints_[joint];
    dd::BodyNode* child = bodies_[j.spec.child];
    dd::BodyNode* parent = j.spec.parent < 0 ? nullptr : bodies_[j.spec.parent];
    const Eigen::Vector3d push = effort * jointAxis(j);
    if (!j.spec.prismatic) {
      child->addExtTorque(push, false);
      if (parent) parent->addExtTorque(-push, false);
      return;
    }
    const Eigen::Vector3d at = child->getWorldTransform().translation();
    child->addExtForce(push, at, false, false);
    if (parent) parent->addExtForce(-push, at, false, false);
  }

  // DART's servo motor (ServoMotorConstraint: the joint's rate driven to the command, its
  // impulse within the force limits) while one is on; a passive joint with its Coulomb friction
  // otherwise.
  void setJointMotor(int joint, double velocity, double max_effort) override {
    Joint& j = joints_[joint];
    dd::Joint* dart_joint = j.joint;
    const bool on = max_effort > 0;
    const double bound = on ? max_effort : std::numeric_limits<double>::infinity();
    dart_joint->setActuatorType(on ? dd::Joint::SERVO : dd::Joint::PASSIVE);
    dart_joint->setForceLowerLimit(0, -bound);
    dart_joint->setForceUpperLimit(0, bound);
    dart_joint->setCommand(0, on ? velocity : 0);
    dart_joint->setCoulombFriction(0, on ? 0 : j.spec.friction);
  }

  void addBodyWrench(int body, const Vec3& force, const Vec3& world_point,
                     const Vec3& torque) override {
    applyPending();
    bodies_[body]->addExtForce(toEigen(force), toEigen(world_point), false, false);
    bodies_[body]->addExtTorque(toEigen(torque), false);
  }

  // The states set since the last read or step, into the generalized coordinates: roots
  // first, each joint's position and rate from its bodies' poses and twists (projected onto the
  // joint's freedom where they do not keep to it).
  void applyPending() const {
    if (!pending_) return;
    pending_ = false;
    for (int b : order_) {
      const Pose& pose = pending_poses_[b];
      const Twist& twist = pending_twists_[b];
      const int j = parent_joint_[b];
      if (j < 0) {
        auto* root = static_cast<dd::FreeJoint*>(bodies_[b]->getParentJoint());
        const Eigen::Isometry3d transform = toEigen(pose);
        root->setPositions(dd::FreeJoint::convertToPositions(transform));
        Eigen::Vector6d velocity;  // the body's own axes: angular, then its origin's linear
        velocity << transform.linear().transpose() * toEigen(twist.angular),
            transform.linear().transpose() * toEigen(twist.linear);
        root->setVelocities(velocity);
        continue;
      }
      const Joint& joint = joints_[j];
      const int parent = joint.spec.parent;
      const Eigen::Isometry3d parent_pose =
          parent < 0 ? Eigen::Isometry3d::Identity() : toEigen(pending_poses_[parent]);
      const Twist parent_twist = parent < 0 ? Twist() : pending_twists_[parent];
      // The child's joint frame in the parent's: a turn about, or a shift along, the axis.
      const Eigen::Isometry3d relative =
          (parent_pose * joint.joint->getTransformFromParentBodyNode()).inverse() *
          toEigen(pose) * joint.joint->getTransformFromChildBodyNode();
      const Eigen::Vector3d axis = localAxis(joint);
      const Eigen::Vector3d world_axis = parent_pose.linear() *
                                         joint.joint->getTransformFromParentBodyNode().linear() *
                                         axis;
      // Both bodies' velocities at the child's joint frame origin.
      const Eigen::Vector3d at = (toEigen(pose) * joint.joint->getTransformFromChildBodyNode()).translation();
      const Eigen::Vector3d child_velocity =
          toEigen(twist.linear) + toEigen(twist.angular).cross(at - toEigen(pose.position));
      const Eigen::Vector3d parent_velocity =
          toEigen(parent_twist.linear) +
          toEigen(parent_twist.angular).cross(at - parent_pose.translation());
      double position, rate;
      if (joint.spec.prismatic) {
        position = axis.dot(relative.translation());
        rate = world_axis.dot(child_velocity - parent_velocity);
      } else {
        const Eigen::Matrix3d& r = relative.linear();
        const Eigen::Vector3d skew(r(2, 1) - r(1, 2), r(0, 2) - r(2, 0), r(1, 0) - r(0, 1));
        position = std::atan2(axis.dot(skew) / 2, (r.trace() - axis.dot(r * axis)) / 2);
        rate = world_axis.dot(toEigen(twist.angular) - toEigen(parent_twist.angular));
      }
      joint.joint->setPosition(0, position);
      joint.joint->setVelocity(0, rate);
    }
  }

  void markStepped() { stepped_ = true; }

 private:
  struct Joint {
    JointSpec spec;
    dd::Joint* joint = nullptr;
  };

  // Bodies in an order where each comes after its joint's parent; a chain of parents that comes
  // back to a body on it is a loop.
  std::vector<int> treeOrder(const ModelSpec& spec) const {
    std::vector<int> order;
    std::vector<int> state(spec.bodies.size(), 0);  // 0 new, 1 on the chain being followed, 2 placed
    for (size_t start = 0; start < spec.bodies.size(); ++start) {
      std::vector<int> chain;
      for (int b = static_cast<int>(start); state[b] != 2;) {
        if (state[b] == 1)
          throw EngineFault("dart: a closed kinematic loop of joints is not supported");
        state[b] = 1;
        chain.push_back(b);
        const int j = parent_joint_[b];
        if (j < 0 || spec.joints[j].parent < 0) break;
        b = spec.joints[j].parent;
      }
      for (auto it = chain.rbegin(); it != chain.rend(); ++it) {
        order.push_back(*it);
        state[*it] = 2;
      }
    }
    return order;
  }

  dd::Joint* createJoint(dd::BodyNode* parent, const JointSpec& spec, const std::string& name,
                         const dd::BodyNode::Properties& body_properties, dd::BodyNode** child) {
    dd::Joint* joint;
    if (spec.prismatic) {
      dd::PrismaticJoint::Properties properties;
      properties.mName = name;
      auto pair = skeleton_->createJointAndBodyNodePair<dd::PrismaticJoint>(parent, properties,
                                                                            body_properties);
      joint = pair.first;
      *child = pair.second;
    } else {
      dd::RevoluteJoint::Properties properties;
      properties.mName = name;
      auto pair = skeleton_->createJointAndBodyNodePair<dd::RevoluteJoint>(parent, properties,
                                                                           body_properties);
      joint = pair.first;
      *child = pair.second;
    }
    if (spec.has_limits && spec.lower <= spec.upper) {
      joint->setPositionLowerLimit(0, spec.lower);
      joint->setPositionUpperLimit(0, spec.upper);
      joint->setLimitEnforcement(true);
    }
    joint->setActuatorType(dd::Joint::PASSIVE);
    joint->setCoulombFriction(0, spec.friction);
    return joint;
  }

  static Eigen::Vector3d localAxis(const Joint& joint) {
    return joint.spec.prismatic ? static_cast<const dd::PrismaticJoint*>(joint.joint)->getAxis()
                                : static_cast<const dd::RevoluteJoint*>(joint.joint)->getAxis();
  }

  // The axis in world coordinates, as the parent carries it.
  Eigen::Vector3d jointAxis(const Joint& joint) const {
    const Eigen::Isometry3d parent = joint.spec.parent < 0
                                         ? Eigen::Isometry3d::Identity()
                                         : bodies_[joint.spec.parent]->getWorldTransform();
    return parent.linear() * joint.joint->getTransformFromParentBodyNode().linear() *
           localAxis(joint);
  }

  dart::simulation::World* world_;
  ShapeRefs* shape_refs_;
  std::vector<DartModel*>* models_;
  dd::SkeletonPtr skeleton_;
  std::vector<int> parent_joint_;  // per body: the joint it is the child of, -1 for a root
  std::vector<int> order_;         // bodies, each after its joint's parent
  std::vector<dd::BodyNode*> bodies_;
  std::vector<std::vector<dd::ShapeNode*>> body_shapes_;  // per body, in its BodySpec's order
  std::vector<dd::Joint*> anchored_;                      // per anchored shape, its weld
  std::vector<Joint> joints_;
  mutable bool pending_ = false;  // states set and not yet in the generalized coordinates
  std::vector<Pose> pending_poses_;
  std::vector<Twist> pending_twists_;
  bool stepped_ = false;  // a step has run since the model was added
};

class DartEngine : public Engine {
 public:
  DartEngine() : world_(std::make_shared<dart::simulation::World>()) {
    dart::external::ode::dSetDebugHandler(&throwLcpError);
    dart::external::ode::dSetErrorHandler(&throwLcpError);
    auto coulomb = std::make_unique<CoulombSolver>(&shape_refs_);
    solver_ = coulomb.get();
    world_->setConstraintSolver(std::move(coulomb));
    dart::constraint::ConstraintSolver* solver = world_->getConstraintSolver();
    solver->setCollisionDetector(dart::collision::OdeCollisionDetector::create());
    solver->getCollisionOption().collisionFilter = std::make_shared<ModelFilter>();
  }

  void setParams(const PhysicsParams& p) override {
    params_ = p;
    world_->setGravity(toEigen(p.gravity));
    solver_->setMaxContacts(static_cast<int>(p.max_contacts));
  }

  std::unique_ptr<EngineModel> addModel(const ModelSpec& spec) override {
    return std::make_unique<DartModel>(world_.get(), &shape_refs_, &models_, next_model_id_++,
                                       spec);
  }

  // Featherstone's algorithm: linear in the joints; the LCP holds contacts, stops and motors.
  bool exactSolver(const PhysicsParams&) const override { return false; }
  bool retakesFailedSteps(const PhysicsParams&) const override { return false; }
  // The bodies of the last collision pass's contacts: those a step that faulted can involve.
  std::vector<BodyRef> contactBodies() const override {
    std::vector<BodyRef> out;
    const auto& result = world_->getConstraintSolver()->getLastCollisionResult();
    for (const dart::collision::Contact& contact : result.getContacts())
      for (const dart::collision::CollisionObject* object :
           {contact.collisionObject1, contact.collisionObject2}) {
        const auto shape = shape_refs_.find(object->getShapeFrame());
        if (shape == shape_refs_.end() || shape->second.ref.body < 0) continue;
        const BodyRef body{shape->second.ref.model, shape->second.ref.body};
        if (std::find(out.begin(), out.end(), body) == out.end()) out.push_back(body);
      }
    return out;
  }

  void step(double dt, std::string*, bool) override {
    for (DartModel* model : models_) model->applyPending();
    setConstraintParams();
    solver_->forgetSolved();
    world_->setTimeStep(dt);
    ++stepping;
    try {
      world_->step(false);  // keeps the servo motors' commands
    } catch (const EngineFault&) {
      --stepping;
      throw;
    }
    --stepping;
    for (DartModel* model : models_) model->markStepped();
    for (size_t s = 0; s < world_->getNumSkeletons(); ++s)
      world_->getSkeleton(s)->clearExternalForces();
    stepped_ = true;
  }

  // The last collision pass's contacts that its solve took in, with the force DART's contact
  // constraint stored on each (on its first shape's body).
  void contacts(std::vector<EngineContact>* out) const override {
    out->clear();
    if (!stepped_) return;
    const auto& result = world_->getConstraintSolver()->getLastCollisionResult();
    for (const dart::collision::Contact& contact : result.getContacts()) {
      if (!solver_->solved(&contact)) continue;
      const auto a = shape_refs_.find(contact.collisionObject1->getShapeFrame());
      const auto b = shape_refs_.find(contact.collisionObject2->getShapeFrame());
      if (a == shape_refs_.end() || b == shape_refs_.end()) continue;
      out->push_back({a->second.ref, b->second.ref, fromEigen(contact.point), fromEigen(contact.normal),
                      contact.penetrationDepth, fromEigen(contact.force)});
    }
  }

  void castRays(const std::vector<Ray>& rays, std::vector<double>* distances) override {
    for (DartModel* model : models_) model->applyPending();
    auto* group = static_cast<dart::collision::OdeCollisionGroup*>(
        world_->getConstraintSolver()->getCollisionGroup().get());
    group->update();
    (group->*kMoveGeoms)();
    if (!rays_) rays_ = std::make_unique<OdeRays>();
    rays_->cast((group->*kOdeSpace)(), rays, distances);
  }

 private:
  // DART keeps these per process: set from this engine's parameters before each of its steps.
  void setConstraintParams() const {
    namespace dc = dart::constraint;
    const double cfm = std::max(params_.cfm, kMinCfm);
    dc::ContactConstraint::setErrorReductionParameter(params_.erp);
    dc::ContactConstraint::setConstraintForceMixing(cfm);
    dc::ContactConstraint::setErrorAllowance(params_.contact_surface_layer);
    dc::ContactConstraint::setMaxErrorReductionVelocity(params_.contact_max_correcting_vel);
    dc::JointLimitConstraint::setErrorReductionParameter(params_.erp);
    dc::JointLimitConstraint::setConstraintForceMixing(cfm);
  }

  PhysicsParams params_;
  std::shared_ptr<dart::simulation::World> world_;
  CoulombSolver* solver_;  // the world's
  ShapeRefs shape_refs_;  // every collision shape's ShapeRef (contacts)
  std::vector<DartModel*> models_;
  // castRays', made at its first call; destroyed before the world's collision detector closes ODE.
  std::unique_ptr<OdeRays> rays_;
  int next_model_id_ = 0;
  bool stepped_ = false;
};

}  // namespace

std::unique_ptr<Engine> makeDartEngine() { return std::make_unique<DartEngine>(); }

}  // namespace core
}  // namespace onedof_sim
