// ODE 0.16 behind the engine seam.
//
// Each model gets its own collision space, and spaces are collided with each other but never
// with themselves: that is what keeps a model from colliding with itself. ODE takes a hinge's or
// slider's zero from the body poses at the moment its axis is set, which is why attachJoints
// re-attaches every joint in the zero configuration.
//
// ODE reports an internal error (a failed assertion, dIASSERT and dUASSERT: dxNormalize4 on a
// non-finite quaternion, the LDLT factorisation of a singular contact matrix) through dDebug, and
// a fatal one through dError; both end the process once their handler returns. Their handlers
// here throw EngineFault out of the ODE call instead, when that call is inside an engine call
// (OdeTrap). ODE's state is then inconsistent: the step's threading job list keeps the jobs the
// throw skipped, a space stays locked by an unfinished collision pass, and ODE's own teardown
// asserts on both. So a faulted engine never calls ODE again, bar the state readers: its world,
// spaces, bodies and threading implementation are left allocated, and World builds a new engine,
// on which it takes the step again from where it started (step's retake) with dWorldQuickStep,
// as after a failed LCP below. The contacts of the failed step name the bodies it can involve
// (contactBodies).
// Each world steps on a threading implementation of its own rather than ODE's process-wide
// default, so that the jobs a fault leaves behind cannot reach another world.
//
// dWorldStep's Dantzig LCP with friction can fail to solve a well-posed step ("LCP internal
// error, s <= 0") and keeps the failed, partial solution: contact rows that hold the same motion
// many times over make its matrix singular. With Gazebo's CFM of 0 on the friction rows, the
// diff-drive base of tests/test_diff_drive.py fails about one step in ten, even with every joint
// welded, one rigid body on four sphere contacts; the CFM floor (kMinContactCfm) on every contact
// row takes those failures away there. Such a step is taken again, from the state it started
// in, with dWorldQuickStep (ODE's iterative solver, Gazebo's default), and only trouble that
// solver reports too reaches the world.
//
// A cylinder lying on a flat face touches it along a line, of which dCollide gives the two end
// points on the rims; each engine resolves it by its middle (contact_rules.h). lineContact
// replaces the ends by three points: those at a quarter and three quarters of the line steady the
// cylinder and have no friction; the line's middle carries nearly all its load (kLineSupportCfm)
// and its friction, bounded by the whole line's normal force (exactStep), with the first friction
// direction along the cylinder's axis, so that the friction pyramid's sides are the wheel's
// lateral and rolling directions whatever its heading. A cylinder tilted within kLyingTilt with
// one rim clear of the face gives that rim's point alone; rimContact adds the line's other end.
//
// Friction follows Coulomb's law, which dWorldStep alone does not: its Dantzig solver bounds
// each friction force by mu times the normal force its contact had before any friction was
// solved (ODE's lcp.cpp sets the bounds at the first friction row), not the one the step ends
// with. A base whose wheel motors push against a sliding caster loads the caster with the
// motors' reaction until the wheels' traction takes it off again: the caster's friction comes to
// 1.5 mu N, as much as the motors can push, and the base stands still. exactStep checks the law at
// every contact with the normal forces the step ended with (dJointFeedback), and where it
// fails takes the step again from its start with those bounds fixed (box friction), until it
// holds: each retake's normal forces are closer (5 or 6 retakes a step while that base
// accelerates, hardly any at a steady speed). A contact sliding faster than kSlidingSpeed
// (contact_rules.h) gets one friction row, along its slip: Coulomb's cone. ODE's pyramid, its
// directions fixed in the contact plane, brakes a dragged caster along one of them and holds it
// across the other, which pins the base's tail: it cannot turn.
#include <ode/ode.h>

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <deque>
#include <exception>
#include <limits>

#include "contact_rules.h"
#include "engine.h"
#include "ode_rays.h"
#include "onedof_sim/pose_math.h"

namespace onedof_sim {
namespace core {
namespace {

// Several contact points constraining the same motion (a cylinder end on the ground gives four)
// make dWorldStep's Dantzig LCP singular with Gazebo's CFM of 0: it fails a pivot ("LCP internal
// error") in the tutorial's own scenes, the arm lying on the ground or pressing the table. ODE's
// own double-precision default CFM, 1e-10 (a compliance of 0.1 nm per N), regularises that and
// removed every such failure in those scenes; it is a floor for contacts only, so joints and the
// reported cfm stay exact. Friction rows take it too (ODE's slip1 and slip2, a creep of 0.1 nm/s
// per N): with Gazebo's 0 there, the exact solve of the book's mobot fails about one step in ten
// (its wheels' and casters' rows across their lines), and none with it.
constexpr double kMinContactCfm = 1e-10;

// The CFM of the two points that steady a lying cylinder's line (lineContact): 10^4 times its
// middle's, so that the middle, which carries the line's friction, carries nearly all its load
// too and ODE's friction bound from that load (dContactApprox1) is the line's from the first
// solve; at ODE's default ERP and a 1 ms step they still push back at 2e8 N/m, so that a
// cylinder that tips about its middle is held level to microradians.
constexpr double kLineSupportCfm = 1e-6;

// Coulomb's law at a contact, as exactStep holds the step to it: a friction force within this
// fraction (and kFrictionForceFloor newtons) of mu times its normal force counts as at that
// bound; a contact slides along a friction direction faster than kSlipFloor (m/s). At most
// kFrictionPasses retakes of a step.
constexpr double kFrictionTolerance = 1e-3;
constexpr double kFrictionForceFloor = 1e-6;
constexpr double kSlipFloor = 1e-6;
constexpr int kFrictionPasses = 10;

double dot3(const dReal* a, const dReal* b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

Vec3 toVec3(const dReal* v) { return {v[0], v[1], v[2]}; }
TouchPoint toTouch(const dContactGeom& geom) {
  return {toVec3(geom.pos), toVec3(geom.normal), geom.depth};
}
// `geom` at `point`'s position and depth.
void placeGeom(const TouchPoint& point, dContactGeom* geom) {
  geom->pos[0] = point.position.x, geom->pos[1] = point.position.y, geom->pos[2] = point.position.z;
  geom->depth = point.depth;
}

// The axis of `cylinder` (its z), world.
Vec3 cylinderAxis(dGeomID cylinder) {
  const dReal* rotation = dGeomGetRotation(cylinder);
  return {rotation[2], rotation[6], rotation[10]};
}

// The two contacts of `cylinder` (cylinder against a flat face) when they are the ends of a side
// line (areLineEnds). Replaces them by the line's quarter points, adds its middle as points[2]
// (points has room for three), and sets `axis` to the first friction direction: the cylinder's
// axis in the contact plane.
bool lineContact(dGeomID cylinder, dContactGeom* points, dVector3 axis) {
  if (dGeomGetClass(cylinder) != dCylinderClass) return false;
  const Vec3 z = cylinderAxis(cylinder);
  const TouchPoint ends[2] = {toTouch(points[0]), toTouch(points[1])};
  if (!areLineEnds(z, ends[0], ends[1])) return false;
  const dContactGeom first_end = points[0];
  const double at[3] = {0.25, 0.75, 0.5};
  for (int i = 0; i < 3; ++i) {
    points[i] = first_end;
    placeGeom(pointOnLine(ends[0], ends[1], at[i]), &points[i]);
  }
  const Vec3 in_plane = axisInPlane(z, ends[0].normal);
  axis[0] = in_plane.x, axis[1] = in_plane.y, axis[2] = in_plane.z;
  return true;
}

// A cylinder lying within kLyingTilt with one rim a little higher than the other: dCollide gives
// the lower rim's point alone. Adds, as points[1], the other end of the side line it lies on
// (otherLineEnd), so that lineContact takes the two as it takes a lying cylinder's.
bool rimContact(dGeomID cylinder, dContactGeom* points) {
  if (dGeomGetClass(cylinder) != dCylinderClass) return false;
  dReal radius, length;
  dGeomCylinderGetParams(cylinder, &radius, &length);
  const dContactGeom& p = points[0];
  // The normal points into the contact's first geom: out of the face towards the cylinder when
  // the cylinder is that geom.
  const Vec3 into_cylinder = (p.g1 == cylinder ? 1.0 : -1.0) * toVec3(p.normal);
  TouchPoint other;
  if (!otherLineEnd(toVec3(dGeomGetPosition(cylinder)), cylinderAxis(cylinder), length,
                    into_cylinder, toTouch(p), &other))
    return false;
  points[1] = p;
  placeGeom(other, &points[1]);
  return true;
}

// A trimesh gives a contact for each of its vertices or triangles in touch, in the mesh's order,
// and dCollide stops when the buffer is full: a dense mesh's first max_contacts points can all lie
// along one edge of what touches, and the rest of it sinks in (a 0.2 m box of 19,200 triangles on
// the ground sank 75 mm with 20). As Gazebo's ODE collides (MAX_COLLIDE_RETURNS), up to this many
// points are asked for and the max_contacts deepest kept.
constexpr int kMeshContactCandidates = 250;

void toOde(const Quat& q, dQuaternion out) { out[0] = q.w, out[1] = q.x, out[2] = q.y, out[3] = q.z; }

void setGeomPose(dGeomID geom, const Pose& pose, bool as_offset) {
  if (dGeomGetClass(geom) == dPlaneClass) {
    // A plane is not placed: it is the plane z = 0 of `pose`, as n . p = d in the world.
    const Vec3 n = rotate(pose.orientation, {0, 0, 1});
    dGeomPlaneSetParams(geom, n.x, n.y, n.z, dot(n, pose.position));
    return;
  }
  dQuaternion q;
  toOde(pose.orientation, q);
  if (as_offset) {
    dGeomSetOffsetPosition(geom, pose.position.x, pose.position.y, pose.position.z);
    dGeomSetOffsetQuaternion(geom, q);
  } else {
    dGeomSetPosition(geom, pose.position.x, pose.position.y, pose.position.z);
    dGeomSetQuaternion(geom, q);
  }
}

// What the contact callback needs of a geom (dGeomSetData points here): its friction, and which
// shape it is (for the contacts the engine reports).
struct GeomInfo {
  double mu = 1, mu2 = 1;
  ShapeRef shape;
};

// ODE reports solver trouble through one process-wide message handler that prints to stderr,
// once per step it happens: thousands of lines for one bad spawn. step() points this at the
// stepping engine's message, so that the world can make it one warning per episode; outside a
// step it still goes to stderr.
thread_local std::string* stepping_message = nullptr;
thread_local bool stepping_message_set = false;

void collectOdeMessage(int, const char* format, va_list args) {
  if (!stepping_message) {
    std::vfprintf(stderr, format, args);
    std::fputc('\n', stderr);
    return;
  }
  if (!stepping_message_set) {
    char text[256];
    std::vsnprintf(text, sizeof text, format, args);
    *stepping_message = std::string("ODE: ") + text;
    stepping_message_set = true;
  }
}

// Inside an engine call: ODE's internal errors throw EngineFault (see the top of the file).
thread_local int trap_depth = 0;

void throwOdeError(int number, const char* format, va_list args) {
  faultFromErrorHandler("ODE internal error", trap_depth > 0, number, format, args);
}

// Marks an engine call: an ODE internal error inside it throws EngineFault, and marks the
// engine faulted on its way out.
class OdeTrap {
 public:
  explicit OdeTrap(bool* faulted) : faulted_(faulted), exceptions_(std::uncaught_exceptions()) {
    if (*faulted_) throw EngineFault("ODE: the engine faulted before and takes no more calls");
    ++trap_depth;
  }
  ~OdeTrap() {
    --trap_depth;
    if (std::uncaught_exceptions() > exceptions_) *faulted_ = true;
  }
  OdeTrap(const OdeTrap&) = delete;
  OdeTrap& operator=(const OdeTrap&) = delete;

 private:
  bool* faulted_;
  int exceptions_;
};

class OdeModel : public EngineModel {
 public:
  // faulted: the engine's flag (OdeTrap), which outlives the model; all_bodies: the engine's list
  // of every body in its world, which this model's bodies join while it lives.
  OdeModel(dWorldID world, dSpaceID parent_space, const ModelSpec& spec, bool* faulted,
           std::vector<dBodyID>* all_bodies)
      : faulted_(faulted), all_bodies_(all_bodies) {
    OdeTrap trap(faulted_);
    space_ = dSimpleSpaceCreate(parent_space);
    for (const BodySpec& spec_body : spec.bodies) {
      dBodyID body = dBodyCreate(world);
      body_refs_.push_back({this, static_cast<int>(bodies_.size())});
      dBodySetData(body, &body_refs_.back());  // for the contacts to name the body
      bodies_.push_back(body);
      all_bodies_->push_back(body);
      body_geoms_.emplace_back();
      for (const ShapeSpec& shape : spec_body.shapes) {
        const int body_index = static_cast<int>(bodies_.size()) - 1;
        dGeomID geom = createGeom(shape, {this, body_index, static_cast<int>(body_geoms_.back().size())});
        dGeomSetBody(geom, body);
        body_geoms_.back().push_back(geom);
      }
      setMass(static_cast<int>(bodies_.size()) - 1, spec_body);
    }
    for (const ShapeSpec& shape : spec.anchored_shapes)
      anchored_.push_back(createGeom(shape, {this, -1, static_cast<int>(anchored_.size())}));
    for (const JointSpec& spec_joint : spec.joints) {
      const bool hinge = !spec_joint.prismatic;
      dJointID joint = hinge ? dJointCreateHinge(world, nullptr) : dJointCreateSlider(world, nullptr);
      auto set = [&](int parameter, double value) {
        hinge ? dJointSetHingeParam(joint, parameter, value)
              : dJointSetSliderParam(joint, parameter, value);
      };
      if (spec_joint.has_limits && spec_joint.lower <= spec_joint.upper) {
        // ODE ignores hinge stops outside [-pi, pi].
        set(dParamLoStop, hinge ? std::max(spec_joint.lower, -M_PI) : spec_joint.lower);
        set(dParamHiStop, hinge ? std::min(spec_joint.upper, M_PI) : spec_joint.upper);
      }
      if (spec_joint.friction > 0) {
        // Coulomb friction: a motor that wants zero speed and can push at most `friction`.
        set(dParamVel, 0);
        set(dParamFMax, spec_joint.friction);
      }
      feedback_.push_back(dJointFeedback{});  // ODE fills it in every step from now on
      dJointSetFeedback(joint, &feedback_.back());
      joints_.push_back({joint, spec_joint.parent, spec_joint.child, hinge, spec_joint.friction});
    }
  }

  ~OdeModel() override {
    if (*faulted_) return;  // left to the faulted world (see the top of the file)
    for (const Joint& joint : joints_) dJointDestroy(joint.id);
    dSpaceSetCleanup(space_, 1);  // destroys its geoms
    dSpaceDestroy(space_);
    for (dTriMeshDataID data : mesh_data_) dGeomTriMeshDataDestroy(data);  // after their geoms
    for (dBodyID body : bodies_) {
      all_bodies_->erase(std::find(all_bodies_->begin(), all_bodies_->end(), body));
      dBodyDestroy(body);
    }
  }

  void attachJoints(const std::vector<Pose>& zero_poses,
                    const std::vector<JointFrame>& frames) override {
    OdeTrap trap(faulted_);
    for (size_t b = 0; b < bodies_.size(); ++b) setPose(bodies_[b], zero_poses[b]);
    for (size_t j = 0; j < joints_.size(); ++j) {
      const Joint& joint = joints_[j];
      dBodyID parent = joint.parent < 0 ? nullptr : bodies_[joint.parent];
      dJointAttach(joint.id, bodies_[joint.child], parent);  // child first: positive moves it
      const Vec3& anchor = frames[j].anchor;
      const Vec3& axis = frames[j].axis;
      if (joint.hinge) {
        dJointSetHingeAnchor(joint.id, anchor.x, anchor.y, anchor.z);
        dJointSetHingeAxis(joint.id, axis.x, axis.y, axis.z);
      } else {
        dJointSetSliderAxis(joint.id, axis.x, axis.y, axis.z);
      }
    }
  }

  Pose bodyPose(int body) const override {
    const dReal* q = dBodyGetQuaternion(bodies_[body]);
    return {toVec3(dBodyGetPosition(bodies_[body])), {q[0], q[1], q[2], q[3]}};
  }

  Twist bodyTwist(int body) const override {
    return {toVec3(dBodyGetLinearVel(bodies_[body])), toVec3(dBodyGetAngularVel(bodies_[body]))};
  }

  void setBodyState(int body, const Pose& pose, const Twist& twist) override {
    OdeTrap trap(faulted_);
    dBodyID id = bodies_[body];
    setPose(id, pose);
    dBodySetLinearVel(id, twist.linear.x, twist.linear.y, twist.linear.z);
    dBodySetAngularVel(id, twist.angular.x, twist.angular.y, twist.angular.z);
    dBodyEnable(id);
  }

  void setAnchoredShapePose(int shape, const Pose& world_pose) override {
    OdeTrap trap(faulted_);
    setGeomPose(anchored_[shape], world_pose, false);
  }

  void setBodyMass(int body, const BodySpec& spec) override {
    OdeTrap trap(faulted_);
    setMass(body, spec);
  }

  double jointPosition(int joint) const override {
    const Joint& j = joints_[joint];
    return j.hinge ? dJointGetHingeAngle(j.id) : dJointGetSliderPosition(j.id);
  }

  double jointRate(int joint) const override {
    const Joint& j = joints_[joint];
    return j.hinge ? dJointGetHingeAngleRate(j.id) : dJointGetSliderPositionRate(j.id);
  }

  // The child is the joint's first body (attachJoints): f1 and t1, the torque about its centre.
  Wrench jointConstraintWrench(int joint) const override {
    const dJointFeedback& f = feedback_[joint];
    return {{f.f1[0], f.f1[1], f.f1[2]}, {f.t1[0], f.t1[1], f.t1[2]}};
  }

  void addJointEffort(int joint, double effort) override {
    OdeTrap trap(faulted_);
    const Joint& j = joints_[joint];
    dBodyEnable(bodies_[j.child]);
    if (j.parent >= 0) dBodyEnable(bodies_[j.parent]);
    if (j.hinge)
      dJointAddHingeTorque(j.id, effort);
    else
      dJointAddSliderForce(j.id, effort);
  }

  // ODE's joint motor, the one joint friction uses: a motor replaces the friction while it is on.
  void setJointMotor(int joint, double velocity, double max_effort) override {
    const Joint& j = joints_[joint];
    const bool on = max_effort > 0;
    const double vel = on ? velocity : 0, fmax = on ? max_effort : j.friction;
    if (j.hinge) {
      dJointSetHingeParam(j.id, dParamVel, vel);
      dJointSetHingeParam(j.id, dParamFMax, fmax);
    } else {
      dJointSetSliderParam(j.id, dParamVel, vel);
      dJointSetSliderParam(j.id, dParamFMax, fmax);
    }
    if (!on) return;
    dBodyEnable(bodies_[j.child]);
    if (j.parent >= 0) dBodyEnable(bodies_[j.parent]);
  }

  void addBodyWrench(int body, const Vec3& force, const Vec3& point, const Vec3& torque) override {
    OdeTrap trap(faulted_);
    dBodyID id = bodies_[body];
    dBodyEnable(id);
    dBodyAddForceAtPos(id, force.x, force.y, force.z, point.x, point.y, point.z);
    dBodyAddTorque(id, torque.x, torque.y, torque.z);
  }

 private:
  struct Joint {
    dJointID id;
    int parent, child;
    bool hinge;
    double friction;  // Coulomb friction, the motor's bound while no velocity motor is on
  };

  void setMass(int body, const BodySpec& spec) {
    dMass mass;
    dMassSetParameters(&mass, spec.mass, 0, 0, 0, spec.ixx, spec.iyy, spec.izz, spec.ixy, spec.ixz,
                       spec.iyz);
    dBodySetMass(bodies_[body], &mass);
    dBodySetGravityMode(bodies_[body], spec.gravity ? 1 : 0);
    for (size_t g = 0; g < spec.shapes.size(); ++g)
      setGeomPose(body_geoms_[body][g], spec.shapes[g].pose, true);
  }

  dGeomID createGeom(const ShapeSpec& shape, const ShapeRef& ref) {
    const Vec3& s = shape.size;
    dGeomID geom = shape.shape == GeometryShape::Box        ? dCreateBox(space_, s.x, s.y, s.z)
                   : shape.shape == GeometryShape::Cylinder ? dCreateCylinder(space_, s.x, s.z)
                   : shape.shape == GeometryShape::Mesh     ? createTriMesh(*shape.mesh)
                   : shape.shape == GeometryShape::Plane    ? dCreatePlane(space_, 0, 0, 1, 0)
                                                            : dCreateSphere(space_, s.x);
    if (shape.mesh) meshes_.push_back(shape.mesh);
    geom_info_.push_back({shape.mu, shape.mu2, ref});
    dGeomSetData(geom, &geom_info_.back());  // a deque: never moves
    return geom;
  }

  // A dGeomTriMesh over the mesh's own arrays (ODE copies neither: meshes_ keeps them). ODE 0.16
  // with OPCODE collides a trimesh with spheres, boxes, capsules, cylinders, planes, rays and
  // other trimeshes; trimesh against convex hulls and heightfields would need libccd, and no
  // shape here is either.
  dGeomID createTriMesh(const TriangleMesh& mesh) {
    static_assert(sizeof(Vec3) == 3 * sizeof(double) && sizeof(dTriIndex) == sizeof(uint32_t),
                  "the mesh's arrays are handed to ODE as they are");
    dTriMeshDataID data = dGeomTriMeshDataCreate();
    mesh_data_.push_back(data);
    dGeomTriMeshDataBuildDouble(data, mesh.vertices.data(), sizeof(Vec3),
                                static_cast<int>(mesh.vertices.size()), mesh.triangles.data(),
                                static_cast<int>(3 * mesh.triangles.size()),
                                sizeof(mesh.triangles[0]));
    return dCreateTriMesh(space_, data, nullptr, nullptr, nullptr);
  }

  static void setPose(dBodyID body, const Pose& pose) {
    dBodySetPosition(body, pose.position.x, pose.position.y, pose.position.z);
    dQuaternion q;
    toOde(pose.orientation, q);
    dBodySetQuaternion(body, q);
  }

  bool* faulted_;
  std::vector<dBodyID>* all_bodies_;
  dSpaceID space_ = nullptr;
  std::vector<dBodyID> bodies_;
  std::deque<BodyRef> body_refs_;  // per body, what its dBodyGetData points to
  std::vector<std::vector<dGeomID>> body_geoms_;  // per body, in its BodySpec's shape order
  std::vector<dGeomID> anchored_;
  std::vector<Joint> joints_;
  std::deque<dJointFeedback> feedback_;  // per joint; a deque: ODE keeps pointers into it
  std::deque<GeomInfo> geom_info_;
  std::vector<dTriMeshDataID> mesh_data_;
  std::vector<std::shared_ptr<const TriangleMesh>> meshes_;  // what mesh_data_ points into
};

class OdeEngine : public Engine {
 public:
  OdeEngine() {
    dInitODE2(0);
    dSetMessageHandler(&collectOdeMessage);
    dSetDebugHandler(&throwOdeError);
    dSetErrorHandler(&throwOdeError);
    world_ = dWorldCreate();
    threading_ = dThreadingAllocateSelfThreadedImplementation();
    dWorldSetStepThreadingImplementation(world_, dThreadingImplementationGetFunctions(threading_),
                                         threading_);
    space_ = dSimpleSpaceCreate(nullptr);
    contact_group_ = dJointGroupCreate(0);
  }

  ~OdeEngine() override {
    if (faulted_) rays_.release();  // left allocated with the rest (see the top of the file)
    if (!faulted_) {
      rays_.reset();
      dJointGroupDestroy(contact_group_);
      dSpaceDestroy(space_);
      dWorldDestroy(world_);
      dThreadingFreeImplementation(threading_);  // after the world, which frees its waits in it
    }
    dCloseODE();
  }

  void reseed() override { dRandSetSeed(0); }
  bool repeatsWhenPutBack() const override { return false; }

  void setParams(const PhysicsParams& p) override {
    OdeTrap trap(&faulted_);
    params_ = p;
    dWorldSetGravity(world_, p.gravity.x, p.gravity.y, p.gravity.z);
    dWorldSetERP(world_, p.erp);
    dWorldSetCFM(world_, p.cfm);
    dWorldSetContactSurfaceLayer(world_, p.contact_surface_layer);
    dWorldSetContactMaxCorrectingVel(world_, p.contact_max_correcting_vel);
    dWorldSetQuickStepNumIterations(world_, static_cast<int>(p.sor_pgs_iters));
    dWorldSetQuickStepW(world_, p.sor_pgs_w);
    dWorldSetAutoDisableFlag(world_, p.auto_disable_bodies ? 1 : 0);
    // sor_pgs_precon_iters and sor_pgs_rms_error_tol have no ODE 0.16 counterpart.
    contact_buffer_.resize(p.max_contacts);
  }

  std::unique_ptr<EngineModel> addModel(const ModelSpec& spec) override {
    return std::make_unique<OdeModel>(world_, space_, spec, &faulted_, &bodies_);
  }

  bool exactSolver(const PhysicsParams& params) const override { return !params.quick_step; }

  bool retakesFailedSteps(const PhysicsParams& params) const override { return !params.quick_step; }

  std::vector<BodyRef> contactBodies() const override { return contact_bodies_; }

  // The last step's contacts, with the forces their joints' feedback gave: feedback.f1 is the
  // force on the joint's first body, body_a's where it has one (dJointAttach with a null body_a
  // makes body_b first). Made when asked: the step keeps its contact records until the next.
  void contacts(std::vector<EngineContact>* out) const override {
    out->clear();
    out->reserve(contacts_.size());
    for (const StepContact& c : contacts_) {
      const dContactGeom& geom = c.contact.geom;
      const double sign = c.body_a ? 1 : -1;
      const dReal* f = c.feedback.f1;
      out->push_back({c.shape_a, c.shape_b, toVec3(geom.pos), toVec3(geom.normal), geom.depth,
                      {sign * f[0], sign * f[1], sign * f[2]}});
    }
  }

  // Through ODE's own ray collision, against the world's space (ode_rays.h).
  void castRays(const std::vector<Ray>& rays, std::vector<double>* distances) override {
    OdeTrap trap(&faulted_);
    if (!rays_) rays_ = std::make_unique<OdeRays>();
    rays_->cast(space_, rays, distances);
  }

  // A step the exact solver failed is taken again from where it started with the iterative one:
  // after an LCP failure (a message), from the bodies restored here; after an internal error
  // (EngineFault), on a new engine the world builds at the step's start (retake).
  void step(double dt, std::string* solver_message, bool retake) override {
    OdeTrap trap(&faulted_);
    stepping_message = solver_message;
    stepping_message_set = false;
    contact_bodies_.clear();
    contacts_.clear();
    try {
      dSpaceCollide(space_, this, &nearCallback);
      bool quick = params_.quick_step || retake;
      if (!quick) {
        saveBodies();
        if (!exactStep(dt)) {  // the exact solve failed: see the top of the file
          restoreBodies();
          solver_message->clear();
          stepping_message_set = false;
          quick = true;
        }
      }
      if (quick) dWorldQuickStep(world_, dt);
    } catch (const EngineFault&) {
      stepping_message = nullptr;
      contacts_.clear();
      throw;
    }
    stepping_message = nullptr;
    dJointGroupEmpty(contact_group_);  // the records in contacts_ stay, for contacts()
  }

 private:
  static void nearCallback(void* data, dGeomID a, dGeomID b) {
    if (dGeomIsSpace(a) || dGeomIsSpace(b)) {
      // Two models: test their geoms against each other. A model's
      // space is never collided with itself.
      dSpaceCollide2(a, b, data, &nearCallback);
      return;
    }
    static_cast<OdeEngine*>(data)->addContacts(a, b);
  }

  void addContacts(dGeomID a, dGeomID b) {
    dBodyID body_a = dGeomGetBody(a), body_b = dGeomGetBody(b);
    // Anchored against anchored (a static model on the ground plane).
    if ((!body_a && !body_b) || contact_buffer_.empty()) return;
    const auto* surface_a = static_cast<const GeomInfo*>(dGeomGetData(a));
    const auto* surface_b = static_cast<const GeomInfo*>(dGeomGetData(b));
    int count = collide(a, b);
    // A lying cylinder's line: its quarter points steady it (no friction), its middle carries
    // its load and friction (see the top of the file).
    dContactGeom line[3];
    dVector3 axis;
    bool lying = false;
    if ((count == 2 || count == 1) && contact_buffer_.size() >= 3) {
      line[0] = contact_buffer_[0].geom, line[1] = contact_buffer_[1].geom;
      const bool ends = count == 2 || rimContact(a, line) || rimContact(b, line);
      lying = ends && (lineContact(a, line, axis) || lineContact(b, line, axis));
      if (lying) {
        for (int i = 0; i < 3; ++i) contact_buffer_[i].geom = line[i];
        count = 3;
      }
    }
    const int first = static_cast<int>(contacts_.size());
    for (int i = 0; i < count; ++i) {
      dContact& contact = contact_buffer_[i];
      contact.surface.mode = dContactApprox1 | dContactMu2 | dContactSoftERP | dContactSoftCFM |
                             dContactSlip1 | dContactSlip2;
      const bool support = lying && i < 2;
      if (lying) {
        contact.surface.mode |= dContactFDir1;
        for (int k = 0; k < 3; ++k) contact.fdir1[k] = axis[k];
      }
      contact.surface.mu = support ? 0 : std::min(surface_a->mu, surface_b->mu);
      contact.surface.mu2 = support ? 0 : std::min(surface_a->mu2, surface_b->mu2);
      contact.surface.soft_erp = params_.erp;
      contact.surface.soft_cfm = std::max(params_.cfm, support ? kLineSupportCfm : kMinContactCfm);
      contact.surface.slip1 = contact.surface.slip2 = contact.surface.soft_cfm;
      dVector3 slip_direction;
      if (!support && contact.surface.mu == contact.surface.mu2 &&
          slidingDirection(body_a, body_b, contact.geom, slip_direction)) {
        contact.surface.mode |= dContactFDir1;
        for (int k = 0; k < 3; ++k) contact.fdir1[k] = slip_direction[k];
        contact.surface.mu2 = 0;  // one friction row, along the slip
      }
      const bool carries_line = lying && i == 2;
      contacts_.push_back({contact, body_a, body_b, {}, carries_line ? first : -1, {},
                           surface_a->shape, surface_b->shape});
      StepContact& recorded = contacts_.back();
      for (int b = 0; b < 2; ++b)
        if (dBodyID body = b == 0 ? body_a : body_b)
          for (int k = 0; k < 3; ++k)
            recorded.arm[b][k] = contact.geom.pos[k] - dBodyGetPosition(body)[k];
      attachContact(&recorded, contact);
    }
    if (count > 0)
      for (dBodyID body : {body_a, body_b})
        if (body) {
          const BodyRef& ref = *static_cast<const BodyRef*>(dBodyGetData(body));
          if (std::find(contact_bodies_.begin(), contact_bodies_.end(), ref) == contact_bodies_.end())
            contact_bodies_.push_back(ref);
        }
  }

  // A contact of the step: the dContact its joint is made from (surface.mu and mu2 the friction
  // coefficients), the bodies it is attached to, and what the step put on the first of them.
  struct StepContact {
    dContact contact;
    dBodyID body_a, body_b;
    dVector3 arm[2];  // from body_a's and body_b's centres at the step's start to the contact
    int line;         // the middle of a side line: the first of its three points, else -1
    dJointFeedback feedback;
    ShapeRef shape_a, shape_b;  // the geoms' shapes, for the contacts the engine reports
  };

  // The joint of `step_contact` made from `contact` (its own, or with other friction bounds).
  void attachContact(StepContact* step_contact, const dContact& contact) {
    dJointID joint = dJointCreateContact(world_, contact_group_, &contact);
    dJointAttach(joint, step_contact->body_a, step_contact->body_b);
    dJointSetFeedback(joint, &step_contact->feedback);
  }

  // dWorldStep, with Coulomb's law at every contact (see the top of the file): where a friction
  // force of the step departs from mu times the normal force the step ended with, the step is
  // taken again from its start with each contact's friction bounded by mu times that force
  // (pressingForce), until the law holds. False when the solver failed; the contacts' joints are
  // then the ones collision made.
  bool exactStep(double dt) {
    dWorldStep(world_, dt);
    if (stepping_message_set) return false;
    for (int pass = 0; pass < kFrictionPasses && !frictionFollowsCoulomb(); ++pass) {
      restoreBodies();
      dJointGroupEmpty(contact_group_);
      for (size_t i = 0; i < contacts_.size(); ++i) {
        dContact bounded = contacts_[i].contact;
        bounded.surface.mode &= ~dContactApprox1;
        bounded.surface.mu = friction_bounds_[i].first;
        bounded.surface.mu2 = friction_bounds_[i].second;
        attachContact(&contacts_[i], bounded);
      }
      dWorldStep(world_, dt);
      if (stepping_message_set) {
        dJointGroupEmpty(contact_group_);
        for (StepContact& contact : contacts_) attachContact(&contact, contact.contact);
        return false;
      }
    }
    return true;
  }

  // Whether each contact's friction forces in the step just taken hold to Coulomb's law, in
  // ODE's friction pyramid: within mu times the normal force along each friction direction,
  // and at that bound where the contact slides along it. Sets friction_bounds_ to those bounds.
  bool frictionFollowsCoulomb() {
    friction_bounds_.resize(contacts_.size());
    bool holds = true;
    for (size_t i = 0; i < contacts_.size(); ++i) {
      const StepContact& c = contacts_[i];
      const dSurfaceParameters& surface = c.contact.surface;
      // The joint's first body is body_a, or body_b when body_a is none; its normal points into
      // that body, and feedback.f1 is the force on it.
      const double into_first = c.body_a ? 1 : -1;
      dVector3 normal, t1, t2;
      for (int k = 0; k < 3; ++k) normal[k] = into_first * c.contact.geom.normal[k];
      if (surface.mode & dContactFDir1) {
        for (int k = 0; k < 3; ++k) t1[k] = c.contact.fdir1[k];
        dCalcVectorCross3(t2, normal, t1);
      } else {
        dPlaneSpace(normal, t1, t2);
      }
      // An infinite coefficient is a row without bound, as ODE makes it.
      const double pressing = pressingForce(c);
      const double coefficient[2] = {surface.mu, surface.mu2};
      double bound[2];
      for (int row = 0; row < 2; ++row)
        bound[row] = std::isinf(coefficient[row]) ? coefficient[row] : coefficient[row] * pressing;
      friction_bounds_[i] = {bound[0], bound[1]};
      // The friction rows ODE gives the contact (dxJointContact::getInfo1): one per positive
      // coefficient, along fdir1 first, bounded by mu and then mu2.
      const int rows = (surface.mu > 0) + (surface.mu2 > 0);
      dVector3 slip;
      contactSlip(c, slip);
      const dReal* direction[2] = {t1, t2};
      for (int row = 0; row < rows; ++row) {
        const double limit = bound[row];
        if (std::isinf(limit)) continue;
        const double force = std::fabs(dot3(c.feedback.f1, direction[row]));
        const double margin = kFrictionTolerance * limit + kFrictionForceFloor;
        // A row that holds its contact still creeps at slip times its force (ODE's slip1, slip2).
        const double creep = (row == 0 ? surface.slip1 : surface.slip2) * force;
        const bool slides = std::fabs(dot3(slip, direction[row])) > kSlipFloor + 2 * creep;
        if (force > limit + margin || (slides && force < limit - margin)) holds = false;
      }
    }
    return holds;
  }

  // The normal force a contact's friction is bounded by: its own, or for the middle of a side
  // line the whole line's (its three points').
  double pressingForce(const StepContact& contact) const {
    auto normalForce = [](const StepContact& c) {
      const double into_first = c.body_a ? 1 : -1;  // feedback.f1 is on the joint's first body
      return std::max(0.0, into_first * dot3(c.feedback.f1, c.contact.geom.normal));
    };
    if (contact.line < 0) return normalForce(contact);
    double line = 0;
    for (int i = contact.line; i < contact.line + 3; ++i) line += normalForce(contacts_[i]);
    return line;
  }

  // Whether the bodies slide over each other at the contact at the step's start (slides), and
  // along which unit direction (body_a's way).
  static bool slidingDirection(dBodyID body_a, dBodyID body_b, const dContactGeom& geom,
                               dVector3 direction) {
    dVector3 va = {0, 0, 0}, vb = {0, 0, 0};
    if (body_a) dBodyGetPointVel(body_a, geom.pos[0], geom.pos[1], geom.pos[2], va);
    if (body_b) dBodyGetPointVel(body_b, geom.pos[0], geom.pos[1], geom.pos[2], vb);
    Vec3 slip;
    if (!slides(toVec3(va) - toVec3(vb), toVec3(geom.normal), &slip)) return false;
    const double speed = std::sqrt(dot(slip, slip));
    direction[0] = slip.x / speed, direction[1] = slip.y / speed, direction[2] = slip.z / speed;
    return true;
  }

  // The velocity of the contact's first body relative to its second (none: the static
  // environment) at the contact after the step, about the centres the bodies had before it, as
  // the step's constraint rows measure it.
  static void contactSlip(const StepContact& contact, dVector3 slip) {
    for (int k = 0; k < 3; ++k) slip[k] = 0;
    const dBodyID bodies[2] = {contact.body_a, contact.body_b};
    for (int b = 0; b < 2; ++b) {
      if (!bodies[b]) continue;
      const dReal* v = dBodyGetLinearVel(bodies[b]);
      const dReal* w = dBodyGetAngularVel(bodies[b]);
      dVector3 spin;
      dCalcVectorCross3(spin, w, contact.arm[b]);
      const double sign = b == 0 || !contact.body_a ? 1 : -1;  // the first body's way
      for (int k = 0; k < 3; ++k) slip[k] += sign * (v[k] + spin[k]);
    }
  }

  // The bodies' state before a dWorldStep, for taking the step again: with the forces and
  // torques added for it, which the step clears.
  struct SavedBody {
    dBodyID id;
    dVector3 position, linear, angular, force, torque;
    dQuaternion orientation;
  };

  void saveBodies() {
    saved_.resize(bodies_.size());
    auto copy = [](dReal* out, const dReal* in, int n) { std::copy(in, in + n, out); };
    for (size_t i = 0; i < bodies_.size(); ++i) {
      SavedBody& saved = saved_[i];
      const dBodyID body = saved.id = bodies_[i];
      copy(saved.position, dBodyGetPosition(body), 3);
      copy(saved.orientation, dBodyGetQuaternion(body), 4);
      copy(saved.linear, dBodyGetLinearVel(body), 3);
      copy(saved.angular, dBodyGetAngularVel(body), 3);
      copy(saved.force, dBodyGetForce(body), 3);
      copy(saved.torque, dBodyGetTorque(body), 3);
    }
  }

  void restoreBodies() {
    for (const SavedBody& s : saved_) {
      dBodySetPosition(s.id, s.position[0], s.position[1], s.position[2]);
      dBodySetQuaternion(s.id, s.orientation);
      dBodySetLinearVel(s.id, s.linear[0], s.linear[1], s.linear[2]);
      dBodySetAngularVel(s.id, s.angular[0], s.angular[1], s.angular[2]);
      dBodySetForce(s.id, s.force[0], s.force[1], s.force[2]);
      dBodySetTorque(s.id, s.torque[0], s.torque[1], s.torque[2]);
    }
  }

  // dCollide into contact_buffer_: at most its size, a trimesh pair's deepest.
  int collide(dGeomID a, dGeomID b) {
    const int wanted = static_cast<int>(contact_buffer_.size());
    if (dGeomGetClass(a) != dTriMeshClass && dGeomGetClass(b) != dTriMeshClass)
      return dCollide(a, b, wanted, &contact_buffer_[0].geom, sizeof(dContact));
    mesh_candidates_.resize(kMeshContactCandidates);
    int count = dCollide(a, b, kMeshContactCandidates, mesh_candidates_.data(), sizeof(dContactGeom));
    if (count > wanted) {
      std::partial_sort(mesh_candidates_.begin(), mesh_candidates_.begin() + wanted,
                        mesh_candidates_.begin() + count,
                        [](const dContactGeom& x, const dContactGeom& y) { return x.depth > y.depth; });
      count = wanted;
    }
    for (int i = 0; i < count; ++i) contact_buffer_[i].geom = mesh_candidates_[i];
    return count;
  }

  PhysicsParams params_;
  bool faulted_ = false;  // an ODE internal error left the objects below inconsistent (OdeTrap)
  std::vector<dBodyID> bodies_;  // every model's, in the world
  std::vector<SavedBody> saved_;
  std::vector<BodyRef> contact_bodies_;  // in the contacts of the last step (contactBodies)
  dWorldID world_ = nullptr;
  dThreadingImplementationID threading_ = nullptr;
  dSpaceID space_ = nullptr;
  dJointGroupID contact_group_ = nullptr;
  std::vector<dContact> contact_buffer_;
  std::deque<StepContact> contacts_;  // the step's; a deque: ODE keeps pointers to the feedback
  std::vector<std::pair<double, double>> friction_bounds_;  // per contact: along fdir1, fdir2
  std::vector<dContactGeom> mesh_candidates_;
  std::unique_ptr<OdeRays> rays_;  // castRays', made at its first call
};

}  // namespace

std::unique_ptr<Engine> makeOdeEngine() { return std::make_unique<OdeEngine>(); }

}  // namespace core
}  // namespace onedof_sim
