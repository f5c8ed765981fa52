// The ODE world behind World: model building, stepping, effort jobs, state access.
//
// Frames. Every link has a link frame (URDF/SDF) and, if it moves, an ODE body. ODE requires the
// body origin at the centre of mass, so a body frame sits at the COM of its links with the axes
// of its reference link, and each link keeps the exact link-frame pose in its body frame.
// Links joined by fixed joints share one body (their masses lumped with dMassAdd): a rigid weld
// is exact that way, where an ODE fixed joint would only be held by ERP and drift. Links fixed to
// `world` (and all links of a static model) have no body: their geoms are static geoms of the
// environment, and joints to them attach to ODE's static environment (body 0).
//
// Joint zero. ODE takes a hinge's or slider's zero from the body poses at the moment the axis is
// set. So placing a model always goes through the zero configuration first (set the axes there),
// then to the wanted joint positions by forward kinematics; see placeModel().
#include "onedof_sim/world.h"

#include <ode/ode.h>

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <limits>
#include <map>
#include <sstream>

#include "model_description.h"
#include "pose_math.h"

namespace onedof_sim {

using namespace core;

namespace {

constexpr int64_t kForever = std::numeric_limits<int64_t>::max();
constexpr const char* kGroundModel = "ground_plane";
// Gazebo's ground plane surface.
constexpr double kGroundMu = 100, kGroundMu2 = 50;
// Above this a link crosses 0.1 m per default step: contacts tunnel and the state means nothing,
// so it is a blow-up being born, not motion. Nothing in a robot arm gets near it.
constexpr double kMaxLinearSpeed = 100;
// Several contact points constraining the same motion (a cylinder end on the ground gives four)
// make dWorldStep's Dantzig LCP singular with Gazebo's CFM of 0: it fails a pivot ("LCP internal
// error") in the tutorial's own scenes, the arm lying on the ground or pressing the table. ODE's
// own double-precision default CFM, 1e-10 (a compliance of 0.1 nm per N), regularises that and
// removed every such failure in those scenes; it is a floor for contacts only, so joints and the
// reported cfm stay exact.
constexpr double kMinContactCfm = 1e-10;
// At most this many step warnings are kept between two takeWarnings() calls; a stuck model would
// otherwise fill memory at the step rate.
constexpr size_t kMaxWarnings = 100;

// ODE integrates rotation linearly, so a link turning by more than about 0.1 rad per step leaves
// its joints visibly apart (the chord error is r * angle^2 / 2 per step, and ERP only removes a
// fifth of it per step). 0.1 rad per step is 100 rad/s at 1 kHz, well above any robot joint. It
// also keeps the joint unwrapping (which adds wrap(raw - last_raw) each step) far from its limit
// of pi per step.
double maxAngularSpeed(double step) { return 0.1 / step; }
// A joint effort or body wrench may take its bodies from rest to the speed caps in no fewer steps
// than this: past that the caps would clip every step and the joints come apart. A real actuator
// is orders of magnitude weaker.
constexpr double kStepsToSpeedCap = 10;

Vec3 toVec3(const dReal* v) { return {v[0], v[1], v[2]}; }
Quat toQuat(const dReal* q) { return {q[0], q[1], q[2], q[3]}; }  // ODE is also w first
void toOde(const Quat& q, dQuaternion out) {
  out[0] = q.w, out[1] = q.x, out[2] = q.y, out[3] = q.z;
}

int64_t saturatingAdd(int64_t a, int64_t b) {
  return b > kForever - a ? kForever : a + b;
}

std::string formatNumber(double value) {
  std::ostringstream text;
  text << value;
  return text.str();
}

// A rigid motion of the model frame for a joint at position q: a rotation about the axis through
// the anchor, or a translation along the axis.
Pose jointMotion(const JointDescription& joint, double q) {
  switch (joint.type) {
    case JointType::Revolute:
    case JointType::Continuous: {
      const Quat r = axisAngle(joint.axis, q);
      return {joint.anchor - rotate(r, joint.anchor), r};
    }
    case JointType::Prismatic: return {q * joint.axis, Quat()};
    case JointType::Fixed: break;
  }
  return Pose();
}

struct ModelRecord;

// What the contact callback needs to know about a geom (dGeomSetData points here).
struct GeomRecord {
  const ModelRecord* model = nullptr;  // null: the ground plane
  double mu = 1, mu2 = 1;
};

struct LinkRecord {
  LinkDescription desc;
  int parent_joint = -1;
  dBodyID body = nullptr;  // null: anchored to the static environment
  bool sets_body_pose = false;  // the reference link of its body: the one that places it
  Pose link_in_body;            // exact link frame in the body (COM) frame
  Pose anchored_pose;           // world pose, when body is null
  std::vector<GeomRecord> geom_records;  // parallel to desc.collisions
  std::vector<dGeomID> geoms;            // parallel to desc.collisions
};

struct JointRecord {
  JointDescription desc;
  int parent = -1;  // link index; -1: the static environment (`world`)
  int child = -1;
  dJointID ode = nullptr;    // null for fixed joints: those are welded bodies or anchored links
  double position = 0;       // unwrapped
  double last_raw = 0;       // ODE's wrapped reading at the last update
  std::vector<dBodyID> moved_bodies;  // the bodies below the joint
};

struct ModelRecord {
  std::string name;
  bool is_static = false;
  dSpaceID space = nullptr;  // one space per model: its geoms are never tested against each other
  std::vector<LinkRecord> links;  // parents before children
  std::vector<JointRecord> joints;
  std::vector<dBodyID> bodies;
  size_t canonical = 0;
  Pose frame_pose;  // world pose of the model frame, where joints to `world` are anchored
  Pose spawn_pose;
  bool velocity_capped = false;  // warned already, until a step passes without capping
};

struct JointEffortJob {
  const ModelRecord* model;
  size_t joint;
  double effort;
  int64_t start_ns, end_ns;  // window [start, end)
};

struct BodyWrenchJob {
  const ModelRecord* model;
  size_t link;
  std::string reference_frame;
  Vec3 point, force, torque;
  int64_t start_ns, end_ns;
};

// ODE reports solver trouble (typically "LCP internal error" while deep interpenetration is being
// pushed apart) through one process-wide message handler that prints to stderr, once per step it
// happens: thousands of lines for one bad spawn. step() points this at its world so that the
// messages become one warning per episode instead; outside step() they still go to stderr.
struct OdeMessages {
  int count = 0;
  std::string first;
};
thread_local OdeMessages* stepping_world_messages = nullptr;

void collectOdeMessage(int, const char* format, va_list args) {
  if (!stepping_world_messages) {
    std::vfprintf(stderr, format, args);
    std::fputc('\n', stderr);
    return;
  }
  if (stepping_world_messages->count++ == 0) {
    char text[256];
    std::vsnprintf(text, sizeof text, format, args);
    stepping_world_messages->first = text;
  }
}

struct BodyState {
  dBodyID body;
  dVector3 position, linear, angular;
  dQuaternion orientation;
};

bool isFiniteBody(dBodyID body) {
  const dReal* values[] = {dBodyGetPosition(body), dBodyGetQuaternion(body),
                           dBodyGetLinearVel(body), dBodyGetAngularVel(body)};
  for (const dReal* v : values)
    for (int i = 0; i < 3; ++i)
      if (!std::isfinite(v[i])) return false;
  return std::isfinite(dBodyGetQuaternion(body)[3]);
}

Pose bodyPose(dBodyID body) {
  return {toVec3(dBodyGetPosition(body)), toQuat(dBodyGetQuaternion(body))};
}

void setBodyPose(dBodyID body, const Pose& pose) {
  dBodySetPosition(body, pose.position.x, pose.position.y, pose.position.z);
  dQuaternion q;
  toOde(pose.orientation, q);
  dBodySetQuaternion(body, q);
}

Pose linkWorldPose(const LinkRecord& link) {
  return link.body ? compose(bodyPose(link.body), link.link_in_body) : link.anchored_pose;
}

Twist linkWorldTwist(const LinkRecord& link) {
  Twist twist;
  if (!link.body) return twist;
  const Vec3 origin = linkWorldPose(link).position;
  dVector3 velocity;
  dBodyGetPointVel(link.body, origin.x, origin.y, origin.z, velocity);
  twist.linear = toVec3(velocity);
  twist.angular = toVec3(dBodyGetAngularVel(link.body));
  return twist;
}

// ODE hinges report (-pi, pi]; sliders report the position itself.
double rawPosition(const JointRecord& joint) {
  return dJointGetType(joint.ode) == dJointTypeHinge ? dJointGetHingeAngle(joint.ode)
                                                     : dJointGetSliderPosition(joint.ode);
}

double jointRate(const JointRecord& joint) {
  if (!joint.ode) return 0;
  return dJointGetType(joint.ode) == dJointTypeHinge ? dJointGetHingeAngleRate(joint.ode)
                                                     : dJointGetSliderPositionRate(joint.ode);
}

void updateJointPositions(ModelRecord* model) {
  for (JointRecord& joint : model->joints) {
    if (!joint.ode) continue;
    const double raw = rawPosition(joint);
    joint.position = dJointGetType(joint.ode) == dJointTypeHinge
                         ? joint.position + std::remainder(raw - joint.last_raw, 2 * M_PI)
                         : raw;
    joint.last_raw = raw;
  }
}

// Adds a generalised force along a joint: + on the child (body 0), - on the parent.
void addJointEffort(const JointRecord& joint, double effort) {
  for (int i = 0; i < 2; ++i)
    if (dBodyID body = dJointGetBody(joint.ode, i)) dBodyEnable(body);
  if (dJointGetType(joint.ode) == dJointTypeHinge)
    dJointAddHingeTorque(joint.ode, effort);
  else
    dJointAddSliderForce(joint.ode, effort);
}

// The largest effort that, on the bodies below the joint taken as one rigid body, reaches the
// speed cap from rest in kStepsToSpeedCap steps. The real (articulated) inertia can only be smaller, so this is
// not a guarantee; the per-step speed cap and the non-finite rollback catch the rest.
double safeEffortBound(const JointRecord& joint, double step) {
  const bool hinge = dJointGetType(joint.ode) == dJointTypeHinge;
  dVector3 axis, anchor{0, 0, 0, 0};
  if (hinge) {
    dJointGetHingeAxis(joint.ode, axis);
    dJointGetHingeAnchor(joint.ode, anchor);
  } else {
    dJointGetSliderAxis(joint.ode, axis);
  }
  const Vec3 u = toVec3(axis), a = toVec3(anchor);
  double inertia = 0;
  for (dBodyID body : joint.moved_bodies) {
    dMass mass;
    dBodyGetMass(body, &mass);
    if (!hinge) {
      inertia += mass.mass;
      continue;
    }
    const dReal* r = dBodyGetRotation(body);
    const Vec3 u_body{r[0] * u.x + r[4] * u.y + r[8] * u.z, r[1] * u.x + r[5] * u.y + r[9] * u.z,
                      r[2] * u.x + r[6] * u.y + r[10] * u.z};
    const double c[3] = {u_body.x, u_body.y, u_body.z};
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) inertia += c[i] * mass.I[i * 4 + j] * c[j];
    const Vec3 arm = toVec3(dBodyGetPosition(body)) - a;
    inertia += mass.mass * (dot(arm, arm) - dot(arm, u) * dot(arm, u));
  }
  const double speed = hinge ? maxAngularSpeed(step) : kMaxLinearSpeed;
  return inertia * speed / (kStepsToSpeedCap * step);
}

Status validateParams(const PhysicsParams& p) {
  const double numbers[] = {p.step,      p.gravity.x, p.gravity.y, p.gravity.z,
                            p.sor_pgs_w, p.sor_pgs_rms_error_tol,   p.contact_surface_layer,
                            p.contact_max_correcting_vel,           p.cfm,
                            p.erp};
  for (double n : numbers)
    if (!std::isfinite(n)) return Status::Error("SetPhysicsProperties: values must be finite");
  if (p.step <= 0 || std::llround(p.step * 1e9) < 1)
    return Status::Error("SetPhysicsProperties: time_step must be at least 1 ns");
  if (p.erp < 0 || p.erp > 1) return Status::Error("SetPhysicsProperties: erp must be in [0, 1]");
  if (p.cfm < 0 || p.contact_surface_layer < 0 || p.contact_max_correcting_vel < 0 ||
      p.sor_pgs_rms_error_tol < 0 || p.sor_pgs_w <= 0)
    return Status::Error(
        "SetPhysicsProperties: cfm, contact_surface_layer, contact_max_correcting_vel and "
        "sor_pgs_rms_error_tol must be >= 0, sor_pgs_w > 0");
  if (p.sor_pgs_iters < 1) return Status::Error("SetPhysicsProperties: sor_pgs_iters must be >= 1");
  // dCollide takes the contact count in 16 bits.
  if (p.max_contacts > 0xffff) return Status::Error("SetPhysicsProperties: max_contacts must be <= 65535");
  return Status::Ok();
}

}  // namespace

struct World::Impl {
  PhysicsParams params;
  int64_t step_ns = 0;
  int64_t time_ns = 0;
  uint64_t steps = 0;
  dWorldID world = nullptr;
  dSpaceID space = nullptr;
  dJointGroupID contact_group = nullptr;
  dGeomID ground = nullptr;
  GeomRecord ground_record{nullptr, kGroundMu, kGroundMu2};
  std::vector<dContact> contact_buffer;
  std::vector<std::unique_ptr<ModelRecord>> models;  // spawn order; records never move
  std::vector<JointEffortJob> joint_jobs;
  std::vector<BodyWrenchJob> wrench_jobs;
  std::vector<std::string> warnings;
  std::vector<BodyState> saved_states;
  OdeMessages ode_messages;
  bool ode_struggled = false;  // warned already, until a step passes without an ODE message

  explicit Impl(const PhysicsParams& p) {
    dInitODE2(0);
    dSetMessageHandler(&collectOdeMessage);
    world = dWorldCreate();
    space = dSimpleSpaceCreate(nullptr);
    contact_group = dJointGroupCreate(0);
    ground = dCreatePlane(space, 0, 0, 1, 0);
    dGeomSetData(ground, &ground_record);
    // A constructor cannot report: invalid parameters fall back to the defaults.
    applyParams(validateParams(p).ok ? p : PhysicsParams());
  }

  ~Impl() {
    while (!models.empty()) destroyModel(models.size() - 1);
    dJointGroupDestroy(contact_group);
    dSpaceDestroy(space);  // destroys the ground plane with it
    dWorldDestroy(world);
    dCloseODE();
  }

  void applyParams(const PhysicsParams& p) {
    params = p;
    step_ns = std::llround(p.step * 1e9);
    dWorldSetGravity(world, p.gravity.x, p.gravity.y, p.gravity.z);
    dWorldSetERP(world, p.erp);
    dWorldSetCFM(world, p.cfm);
    dWorldSetContactSurfaceLayer(world, p.contact_surface_layer);
    dWorldSetContactMaxCorrectingVel(world, p.contact_max_correcting_vel);
    dWorldSetQuickStepNumIterations(world, static_cast<int>(p.sor_pgs_iters));
    dWorldSetQuickStepW(world, p.sor_pgs_w);
    dWorldSetAutoDisableFlag(world, p.auto_disable_bodies ? 1 : 0);
    // sor_pgs_precon_iters and sor_pgs_rms_error_tol have no ODE 0.16 counterpart: they are kept
    // only so that get_physics_properties returns what was set.
    contact_buffer.resize(p.max_contacts);
  }

  void warn(const std::string& text) {
    if (warnings.size() < kMaxWarnings) warnings.push_back(text);
  }

  // --- lookups -------------------------------------------------------------------------------

  ModelRecord* findModel(const std::string& name) const {
    for (const auto& model : models)
      if (model->name == name) return model.get();
    return nullptr;
  }

  // "model::link"; nested SDF link names contain "::" too, so match the model name as a prefix.
  bool findLink(const std::string& scoped, ModelRecord** model, size_t* link) const {
    for (const auto& m : models) {
      const std::string prefix = m->name + "::";
      if (scoped.compare(0, prefix.size(), prefix) != 0) continue;
      const std::string bare = scoped.substr(prefix.size());
      for (size_t i = 0; i < m->links.size(); ++i)
        if (m->links[i].desc.name == bare) {
          *model = m.get();
          *link = i;
          return true;
        }
    }
    return false;
  }

  // Scoped "model::joint" first, then the bare name in spawn order.
  bool findJoint(const std::string& name, ModelRecord** model, size_t* joint) const {
    for (bool scoped : {true, false})
      for (const auto& m : models) {
        const std::string prefix = m->name + "::";
        if (scoped && name.compare(0, prefix.size(), prefix) != 0) continue;
        const std::string bare = scoped ? name.substr(prefix.size()) : name;
        for (size_t i = 0; i < m->joints.size(); ++i)
          if (m->joints[i].desc.name == bare) {
            *model = m.get();
            *joint = i;
            return true;
          }
      }
    return false;
  }

  // World pose and twist of an entity used as a reference frame: "" or "world", a model (its
  // canonical link frame) or a scoped link.
  bool resolveFrame(const std::string& name, Pose* pose, Twist* twist) const {
    *pose = Pose();
    *twist = Twist();
    if (name.empty() || name == kWorldLink) return true;
    ModelRecord* model = findModel(name);
    size_t link = 0;
    if (model) {
      link = model->canonical;
    } else if (!findLink(name, &model, &link)) {
      return false;
    }
    *pose = linkWorldPose(model->links[link]);
    *twist = linkWorldTwist(model->links[link]);
    return true;
  }

  // --- building ------------------------------------------------------------------------------

  // Everything that can fail is checked here, before any ODE object exists, so that a refused
  // spawn leaves the world as it was. Fills the link/joint records and the body masses.
  Status planModel(const ModelDescription& desc, ModelRecord* model,
                   std::vector<int>* body_of_link, std::vector<dMass>* body_masses) const {
    std::map<std::string, int> index;
    for (const LinkDescription& link : desc.links) {
      index[link.name] = static_cast<int>(model->links.size());
      LinkRecord record;
      record.desc = link;
      model->links.push_back(record);
    }
    model->canonical = index.at(desc.canonical_link);
    for (const JointDescription& joint : desc.joints) {
      JointRecord record;
      record.desc = joint;
      record.parent = joint.parent == kWorldLink ? -1 : index.at(joint.parent);
      record.child = index.at(joint.child);
      model->links[record.child].parent_joint = static_cast<int>(model->joints.size());
      model->joints.push_back(record);
    }
    // Bodies: a link welded by a fixed joint to a moving parent shares its body; a link welded to
    // `world` (or in a static model) is anchored (-1).
    std::vector<int> reference_link;  // per body
    body_of_link->assign(model->links.size(), -1);
    for (size_t i = 0; i < model->links.size(); ++i) {
      const int parent_joint = model->links[i].parent_joint;
      if (model->is_static) continue;
      if (parent_joint >= 0 && model->joints[parent_joint].desc.type == JointType::Fixed) {
        const int parent = model->joints[parent_joint].parent;
        (*body_of_link)[i] = parent < 0 ? -1 : (*body_of_link)[parent];
        continue;
      }
      (*body_of_link)[i] = static_cast<int>(reference_link.size());
      reference_link.push_back(static_cast<int>(i));
    }
    body_masses->assign(reference_link.size(), dMass());
    for (dMass& mass : *body_masses) dMassSetZero(&mass);
    for (size_t i = 0; i < model->links.size(); ++i) {
      const int body = (*body_of_link)[i];
      const LinkDescription& link = model->links[i].desc;
      const double values[] = {link.mass, link.ixx, link.ixy, link.ixz, link.iyy, link.iyz, link.izz};
      for (double v : values)
        if (!std::isfinite(v)) return Status::Error("link '" + link.name + "' has a non-finite inertial");
      if (body < 0 || !link.has_inertial || link.mass == 0) continue;
      if (link.mass < 0) return Status::Error("link '" + link.name + "' has a negative mass");
      // The link's inertia about its COM in its inertial frame, turned into the body's reference
      // link frame: rotate about the origin first (c is still 0), then move to the COM.
      const Pose link_in_reference =
          compose(inverse(model->links[reference_link[body]].desc.pose), link.pose);
      const Pose inertial = compose(link_in_reference, link.com);
      dMass mass;
      dMassSetParameters(&mass, link.mass, 0, 0, 0, link.ixx, link.iyy, link.izz, link.ixy,
                         link.ixz, link.iyz);
      dMatrix3 rotation;
      dQuaternion q;
      toOde(inertial.orientation, q);
      dQtoR(q, rotation);
      dMassRotate(&mass, rotation);
      dMassTranslate(&mass, inertial.position.x, inertial.position.y, inertial.position.z);
      dMassAdd(&(*body_masses)[body], &mass);
    }
    for (size_t body = 0; body < reference_link.size(); ++body) {
      dMass& mass = (*body_masses)[body];
      const LinkRecord& reference = model->links[reference_link[body]];
      if (!(mass.mass > 0))
        return Status::Error("link '" + reference.desc.name +
                             "' moves but has no mass (give it an <inertial>)");
      const Vec3 com{mass.c[0], mass.c[1], mass.c[2]};
      dMassTranslate(&mass, -com.x, -com.y, -com.z);
      if (!dMassCheck(&mass))
        return Status::Error("link '" + reference.desc.name +
                             "' has an inertia that no rigid body can have");
      // Body frame: at the COM, axes of the reference link.
      for (size_t i = 0; i < model->links.size(); ++i) {
        if ((*body_of_link)[i] != static_cast<int>(body)) continue;
        const Pose link_in_reference =
            compose(inverse(reference.desc.pose), model->links[i].desc.pose);
        model->links[i].link_in_body = {link_in_reference.position - com,
                                        link_in_reference.orientation};
      }
      model->links[reference_link[body]].sets_body_pose = true;
    }
    return Status::Ok();
  }

  void createOdeObjects(ModelRecord* model, const std::vector<int>& body_of_link,
                        const std::vector<dMass>& body_masses) {
    model->space = dSimpleSpaceCreate(space);
    for (const dMass& mass : body_masses) {
      dBodyID body = dBodyCreate(world);
      dBodySetMass(body, &mass);
      model->bodies.push_back(body);
    }
    for (size_t i = 0; i < model->links.size(); ++i) {
      LinkRecord& link = model->links[i];
      if (body_of_link[i] >= 0) {
        link.body = model->bodies[body_of_link[i]];
        if (link.sets_body_pose) dBodySetGravityMode(link.body, link.desc.gravity ? 1 : 0);
      }
      for (const CollisionDescription& collision : link.desc.collisions)
        link.geom_records.push_back({model, collision.mu, collision.mu2});
      for (size_t c = 0; c < link.desc.collisions.size(); ++c) {
        const CollisionDescription& collision = link.desc.collisions[c];
        const Vec3& s = collision.size;
        dGeomID geom = collision.shape == GeometryShape::Box
                           ? dCreateBox(model->space, s.x, s.y, s.z)
                       : collision.shape == GeometryShape::Cylinder
                           ? dCreateCylinder(model->space, s.x, s.z)
                           : dCreateSphere(model->space, s.x);
        dGeomSetData(geom, &link.geom_records[c]);
        if (link.body) {
          dGeomSetBody(geom, link.body);
          const Pose offset = compose(link.link_in_body, collision.pose);
          dGeomSetOffsetPosition(geom, offset.position.x, offset.position.y, offset.position.z);
          dQuaternion q;
          toOde(offset.orientation, q);
          dGeomSetOffsetQuaternion(geom, q);
        }
        link.geoms.push_back(geom);
      }
    }
    for (JointRecord& joint : model->joints) {
      const JointDescription& d = joint.desc;
      if (d.type == JointType::Fixed || !model->links[joint.child].body) continue;
      const bool hinge = d.type != JointType::Prismatic;
      joint.ode = hinge ? dJointCreateHinge(world, nullptr) : dJointCreateSlider(world, nullptr);
      auto set = [&](int parameter, double value) {
        hinge ? dJointSetHingeParam(joint.ode, parameter, value)
              : dJointSetSliderParam(joint.ode, parameter, value);
      };
      if (d.has_limits && d.lower <= d.upper) {
        // ODE ignores hinge stops outside [-pi, pi].
        set(dParamLoStop, hinge ? std::max(d.lower, -M_PI) : d.lower);
        set(dParamHiStop, hinge ? std::min(d.upper, M_PI) : d.upper);
      }
      if (d.friction > 0) {
        // Coulomb friction: a motor that wants zero speed and can push at most `friction`.
        set(dParamVel, 0);
        set(dParamFMax, d.friction);
      }
    }
    // The bodies each joint moves: every body below it in the tree.
    for (size_t i = 0; i < model->links.size(); ++i) {
      dBodyID body = model->links[i].body;
      if (!body || !model->links[i].sets_body_pose) continue;
      for (int j = model->links[i].parent_joint; j >= 0;
           j = model->joints[j].parent < 0 ? -1 : model->links[model->joints[j].parent].parent_joint)
        if (model->joints[j].ode) model->joints[j].moved_bodies.push_back(body);
    }
  }

  void destroyModel(size_t index) {
    ModelRecord* model = models[index].get();
    for (JointRecord& joint : model->joints)
      if (joint.ode) dJointDestroy(joint.ode);
    dSpaceSetCleanup(model->space, 1);  // destroys its geoms
    dSpaceDestroy(model->space);
    for (dBodyID body : model->bodies) dBodyDestroy(body);
    dropJobs([model](const ModelRecord* m) { return m == model; });
    models.erase(models.begin() + index);
  }

  template <typename Predicate>
  void dropJobs(Predicate on_model) {
    joint_jobs.erase(std::remove_if(joint_jobs.begin(), joint_jobs.end(),
                                    [&](const JointEffortJob& j) { return on_model(j.model); }),
                     joint_jobs.end());
    wrench_jobs.erase(std::remove_if(wrench_jobs.begin(), wrench_jobs.end(),
                                     [&](const BodyWrenchJob& j) { return on_model(j.model); }),
                      wrench_jobs.end());
  }

  // --- placing -------------------------------------------------------------------------------

  // World poses of all links at joint positions q, with joints to `world` anchored at the model
  // frame pose and each free root link (no parent joint) at root_poses[link].
  std::vector<Pose> forwardKinematics(const ModelRecord& model, const Pose& frame_pose,
                                      const std::vector<Pose>& root_poses,
                                      const std::vector<double>& q) const {
    std::vector<Pose> poses(model.links.size());
    for (size_t i = 0; i < model.links.size(); ++i) {
      const int j = model.links[i].parent_joint;
      if (j < 0) {
        poses[i] = root_poses[i];
        continue;
      }
      const JointRecord& joint = model.joints[j];
      // Maps model-frame (zero configuration) coordinates to the world as the parent sits now.
      const Pose parent_mapping =
          joint.parent < 0 ? frame_pose
                           : compose(poses[joint.parent], inverse(model.links[joint.parent].desc.pose));
      poses[i] = compose(compose(parent_mapping, jointMotion(joint.desc, q[j])),
                         model.links[i].desc.pose);
    }
    return poses;
  }

  void setLinkPoses(ModelRecord* model, const std::vector<Pose>& poses) {
    for (size_t i = 0; i < model->links.size(); ++i) {
      LinkRecord& link = model->links[i];
      if (link.body) {
        if (link.sets_body_pose) setBodyPose(link.body, compose(poses[i], inverse(link.link_in_body)));
        continue;
      }
      link.anchored_pose = poses[i];
      for (size_t c = 0; c < link.geoms.size(); ++c) {
        const Pose pose = compose(poses[i], link.desc.collisions[c].pose);
        dGeomSetPosition(link.geoms[c], pose.position.x, pose.position.y, pose.position.z);
        dQuaternion q;
        toOde(pose.orientation, q);
        dGeomSetQuaternion(link.geoms[c], q);
      }
    }
  }

  // Puts the model at joint positions q (fixed joints ignored) with zero velocity. The joints
  // are re-attached in the zero configuration, because ODE takes their zero from the body poses
  // when the axis is set; the anchors of joints to the environment follow frame_pose that way.
  void placeModel(ModelRecord* model, const Pose& frame_pose, const std::vector<Pose>& root_poses,
                  const std::vector<double>& q) {
    model->frame_pose = frame_pose;
    const std::vector<Pose> zero_poses =
        forwardKinematics(*model, frame_pose, root_poses, std::vector<double>(q.size(), 0.0));
    setLinkPoses(model, zero_poses);
    for (JointRecord& joint : model->joints) {
      if (!joint.ode) continue;
      const LinkRecord& child = model->links[joint.child];
      dBodyID parent = joint.parent < 0 ? nullptr : model->links[joint.parent].body;
      dJointAttach(joint.ode, child.body, parent);  // child first: positive moves the child
      const Pose mapping = compose(zero_poses[joint.child], inverse(child.desc.pose));
      const Vec3 anchor = transformPoint(mapping, joint.desc.anchor);
      const Vec3 axis = rotate(mapping.orientation, joint.desc.axis);
      if (dJointGetType(joint.ode) == dJointTypeHinge) {
        dJointSetHingeAnchor(joint.ode, anchor.x, anchor.y, anchor.z);
        dJointSetHingeAxis(joint.ode, axis.x, axis.y, axis.z);
      } else {
        dJointSetSliderAxis(joint.ode, axis.x, axis.y, axis.z);
      }
    }
    setLinkPoses(model, forwardKinematics(*model, frame_pose, root_poses, q));
    for (dBodyID body : model->bodies) {
      dBodySetLinearVel(body, 0, 0, 0);
      dBodySetAngularVel(body, 0, 0, 0);
      dBodyEnable(body);
    }
    for (size_t j = 0; j < model->joints.size(); ++j) {
      JointRecord& joint = model->joints[j];
      joint.position = joint.ode ? q[j] : 0;
      if (joint.ode) joint.last_raw = rawPosition(joint);
    }
    model->velocity_capped = false;
  }

  std::vector<Pose> currentLinkPoses(const ModelRecord& model) const {
    std::vector<Pose> poses;
    for (const LinkRecord& link : model.links) poses.push_back(linkWorldPose(link));
    return poses;
  }

  std::vector<double> currentPositions(const ModelRecord& model) const {
    std::vector<double> q;
    for (const JointRecord& joint : model.joints) q.push_back(joint.position);
    return q;
  }

  void resetModel(ModelRecord* model) {
    std::vector<Pose> root_poses;
    for (const LinkRecord& link : model->links)
      root_poses.push_back(compose(model->spawn_pose, link.desc.pose));
    placeModel(model, model->spawn_pose, root_poses,
               std::vector<double>(model->joints.size(), 0.0));
  }

  // --- stepping ------------------------------------------------------------------------------

  static void nearCallback(void* data, dGeomID a, dGeomID b) {
    if (dGeomIsSpace(a) || dGeomIsSpace(b)) {
      // Two models, or a model and the ground: test their geoms against each other. A model's
      // space is never collided with itself, which is what keeps a model from self-colliding.
      dSpaceCollide2(a, b, data, &nearCallback);
      return;
    }
    static_cast<Impl*>(data)->addContacts(a, b);
  }

  void addContacts(dGeomID a, dGeomID b) {
    dBodyID body_a = dGeomGetBody(a), body_b = dGeomGetBody(b);
    // Static against static or against the ground. Links joined by a joint are in one model,
    // and a model is never collided with itself (nearCallback), so they never get here.
    if ((!body_a && !body_b) || contact_buffer.empty()) return;
    const auto* record_a = static_cast<const GeomRecord*>(dGeomGetData(a));
    const auto* record_b = static_cast<const GeomRecord*>(dGeomGetData(b));
    const int count = dCollide(a, b, static_cast<int>(contact_buffer.size()),
                               &contact_buffer[0].geom, sizeof(dContact));
    for (int i = 0; i < count; ++i) {
      dContact& contact = contact_buffer[i];
      contact.surface.mode = dContactApprox1 | dContactMu2 | dContactSoftERP | dContactSoftCFM;
      contact.surface.mu = std::min(record_a->mu, record_b->mu);
      contact.surface.mu2 = std::min(record_a->mu2, record_b->mu2);
      contact.surface.soft_erp = params.erp;
      contact.surface.soft_cfm = std::max(params.cfm, kMinContactCfm);
      dJointID joint = dJointCreateContact(world, contact_group, &contact);
      dJointAttach(joint, body_a, body_b);
    }
  }

  void applyJobs(int64_t t) {
    for (const JointEffortJob& job : joint_jobs)
      if (job.start_ns <= t && t < job.end_ns)
        addJointEffort(job.model->joints[job.joint], job.effort);
    for (const BodyWrenchJob& job : wrench_jobs) {
      if (job.start_ns > t || t >= job.end_ns) continue;
      Pose frame;
      Twist unused;
      if (!resolveFrame(job.reference_frame, &frame, &unused)) continue;  // reference deleted
      const Vec3 force = rotate(frame.orientation, job.force);
      const Vec3 torque = rotate(frame.orientation, job.torque);
      const Vec3 point = transformPoint(frame, job.point);
      dBodyID body = job.model->links[job.link].body;
      dBodyEnable(body);
      dBodyAddForceAtPos(body, force.x, force.y, force.z, point.x, point.y, point.z);
      dBodyAddTorque(body, torque.x, torque.y, torque.z);
    }
  }

  void applyDamping() {
    for (const auto& model : models)
      for (const JointRecord& joint : model->joints)
        if (joint.ode && joint.desc.damping != 0)
          addJointEffort(joint, -joint.desc.damping * jointRate(joint));
  }

  void saveStates() {
    saved_states.clear();
    for (const auto& model : models)
      for (dBodyID body : model->bodies) {
        BodyState s;
        s.body = body;
        std::copy_n(dBodyGetPosition(body), 3, s.position);
        std::copy_n(dBodyGetQuaternion(body), 4, s.orientation);
        std::copy_n(dBodyGetLinearVel(body), 3, s.linear);
        std::copy_n(dBodyGetAngularVel(body), 3, s.angular);
        saved_states.push_back(s);
      }
  }

  // A non-finite state is unrecoverable for ODE, so the whole step is undone and the models that
  // blew up are stopped; then every model's speed is capped (see kMaxLinearSpeed and
  // maxAngularSpeed), scaling all its bodies alike so that its joints stay consistent.
  void guardStates() {
    std::vector<ModelRecord*> blown_up;
    for (const auto& model : models)
      for (dBodyID body : model->bodies)
        if (!isFiniteBody(body)) {
          blown_up.push_back(model.get());
          break;
        }
    if (!blown_up.empty()) {
      for (const BodyState& s : saved_states) {
        dBodySetPosition(s.body, s.position[0], s.position[1], s.position[2]);
        dBodySetQuaternion(s.body, s.orientation);
        dBodySetLinearVel(s.body, s.linear[0], s.linear[1], s.linear[2]);
        dBodySetAngularVel(s.body, s.angular[0], s.angular[1], s.angular[2]);
      }
      for (ModelRecord* model : blown_up) {
        for (dBodyID body : model->bodies) {
          dBodySetLinearVel(body, 0, 0, 0);
          dBodySetAngularVel(body, 0, 0, 0);
        }
        warn("model '" + model->name +
             "' reached a non-finite state: the step was undone and the model stopped");
      }
    }
    const double max_angular = maxAngularSpeed(params.step);
    for (const auto& model : models) {
      double scale = 1;
      for (dBodyID body : model->bodies) {
        const double linear = norm(toVec3(dBodyGetLinearVel(body)));
        const double angular = norm(toVec3(dBodyGetAngularVel(body)));
        if (linear > kMaxLinearSpeed) scale = std::min(scale, kMaxLinearSpeed / linear);
        if (angular > max_angular) scale = std::min(scale, max_angular / angular);
      }
      if (scale < 1) {
        for (dBodyID body : model->bodies) {
          const Vec3 v = scale * toVec3(dBodyGetLinearVel(body));
          const Vec3 w = scale * toVec3(dBodyGetAngularVel(body));
          dBodySetLinearVel(body, v.x, v.y, v.z);
          dBodySetAngularVel(body, w.x, w.y, w.z);
        }
        if (!model->velocity_capped)
          warn("model '" + model->name + "' exceeded " + formatNumber(kMaxLinearSpeed) +
               " m/s or " + formatNumber(max_angular) + " rad/s: its speed is being capped");
      }
      model->velocity_capped = scale < 1;
    }
  }

  void dropExpiredJobs(int64_t next_step_start) {
    joint_jobs.erase(std::remove_if(joint_jobs.begin(), joint_jobs.end(),
                                    [&](const JointEffortJob& j) { return j.end_ns <= next_step_start; }),
                     joint_jobs.end());
    wrench_jobs.erase(std::remove_if(wrench_jobs.begin(), wrench_jobs.end(),
                                     [&](const BodyWrenchJob& j) { return j.end_ns <= next_step_start; }),
                      wrench_jobs.end());
  }

  void step() {
    applyJobs(time_ns);
    applyDamping();
    saveStates();
    ode_messages = OdeMessages();
    stepping_world_messages = &ode_messages;
    dSpaceCollide(space, this, &nearCallback);
    if (params.quick_step)
      dWorldQuickStep(world, params.step);
    else
      dWorldStep(world, params.step);
    stepping_world_messages = nullptr;
    if (ode_messages.count > 0 && !ode_struggled)
      warn("ODE: " + ode_messages.first);
    ode_struggled = ode_messages.count > 0;
    dJointGroupEmpty(contact_group);
    guardStates();
    for (const auto& model : models) updateJointPositions(model.get());
    time_ns += step_ns;
    ++steps;
    dropExpiredJobs(time_ns);
  }

  // --- jobs ----------------------------------------------------------------------------------

  // The job window for the contract's rules, or false for a zero duration; `note` gets the
  // explanation the status message carries.
  bool jobWindow(int64_t start_ns, int64_t duration_ns, int64_t* start, int64_t* end,
                 std::string* note) const {
    if (duration_ns == 0) {
      *note = "; duration is 0, so nothing was applied";
      return false;
    }
    *start = std::max(start_ns, time_ns);
    if (duration_ns < 0) {
      *end = kForever;
    } else if (duration_ns < step_ns) {
      // [start, start + step) holds exactly one step start, wherever start falls.
      *end = *start + step_ns;
      *note += "; duration is shorter than the step, so it acts for exactly one step";
    } else {
      *end = saturatingAdd(*start, duration_ns);
    }
    return true;
  }
};

World::World(const PhysicsParams& params) : impl_(new Impl(params)) {}
World::~World() = default;

void World::step() { impl_->step(); }
int64_t World::timeNs() const { return impl_->time_ns; }
double World::time() const { return impl_->time_ns * 1e-9; }
uint64_t World::stepCount() const { return impl_->steps; }
const PhysicsParams& World::params() const { return impl_->params; }

Status World::setParams(const PhysicsParams& params) {
  Status status = validateParams(params);
  if (!status.ok) return status;
  impl_->applyParams(params);
  return Status::Ok("SetPhysicsProperties: physics parameters set");
}

std::vector<std::string> World::takeWarnings() {
  std::vector<std::string> warnings;
  warnings.swap(impl_->warnings);
  return warnings;
}

Status World::spawn(const std::string& name, const std::string& xml, ModelFormat format,
                    const Pose& pose, const std::string& reference_frame) {
  if (name.empty()) return Status::Error("SpawnModel: the model name is empty");
  if (impl_->findModel(name))
    return Status::Error("SpawnModel: a model named '" + name + "' already exists");
  if (!isFinite(pose) || quatNorm(pose.orientation) < 1e-9)
    return Status::Error("SpawnModel: the initial pose is not finite or its quaternion is zero");
  Pose frame;
  Twist unused;
  if (!impl_->resolveFrame(reference_frame, &frame, &unused))
    return Status::Error("SpawnModel: reference frame '" + reference_frame + "' not found");
  ModelDescription desc;
  Status status = format == ModelFormat::Urdf ? parseUrdf(xml, &desc) : parseSdf(xml, &desc);
  if (!status.ok) return Status::Error("SpawnModel: " + status.message);

  auto model = std::make_unique<ModelRecord>();
  model->name = name;
  model->is_static = desc.is_static;
  std::vector<int> body_of_link;
  std::vector<dMass> body_masses;
  status = impl_->planModel(desc, model.get(), &body_of_link, &body_masses);
  if (!status.ok) return Status::Error("SpawnModel: " + status.message);
  impl_->createOdeObjects(model.get(), body_of_link, body_masses);
  model->spawn_pose = compose(frame, {pose.position, normalized(pose.orientation)});
  impl_->resetModel(model.get());
  impl_->models.push_back(std::move(model));
  return Status::Ok("SpawnModel: Successfully spawned entity");
}

Status World::deleteModel(const std::string& name) {
  for (size_t i = 0; i < impl_->models.size(); ++i)
    if (impl_->models[i]->name == name) {
      impl_->destroyModel(i);
      return Status::Ok("DeleteModel: successfully deleted model");
    }
  return Status::Error("DeleteModel: model does not exist");
}

std::vector<std::string> World::modelNames() const {
  std::vector<std::string> names;
  for (const auto& model : impl_->models) names.push_back(model->name);
  return names;
}

bool World::hasModel(const std::string& name) const { return impl_->findModel(name) != nullptr; }

Status World::modelProperties(const std::string& name, ModelInfo* out) const {
  const ModelRecord* model = impl_->findModel(name);
  if (!model) return Status::Error("GetModelProperties: model does not exist");
  ModelInfo info;
  info.name = model->name;
  info.canonical_link = model->name + "::" + model->links[model->canonical].desc.name;
  for (const LinkRecord& link : model->links) {
    info.links.push_back(model->name + "::" + link.desc.name);
    for (const CollisionDescription& collision : link.desc.collisions)
      info.geoms.push_back(collision.name);
  }
  for (const JointRecord& joint : model->joints) info.joints.push_back(joint.desc.name);
  info.is_static = model->is_static;
  *out = info;
  return Status::Ok("GetModelProperties: got properties");
}

// Gazebo's convention for a state relative to an entity: pose in the entity frame, velocities
// relative to the entity's and expressed in its axes.
static void makeRelative(const Pose& frame, const Twist& frame_twist, Pose* pose, Twist* twist) {
  const Quat to_frame = conjugate(frame.orientation);
  *pose = compose(inverse(frame), *pose);
  twist->linear = rotate(to_frame, twist->linear - frame_twist.linear);
  twist->angular = rotate(to_frame, twist->angular - frame_twist.angular);
}

Status World::modelState(const std::string& name, const std::string& reference_frame, Pose* pose,
                         Twist* twist) const {
  const ModelRecord* model = impl_->findModel(name);
  if (!model) return Status::Error("GetModelState: model does not exist");
  Pose frame;
  Twist frame_twist;
  if (!impl_->resolveFrame(reference_frame, &frame, &frame_twist))
    return Status::Error("GetModelState: reference frame '" + reference_frame + "' not found");
  const LinkRecord& root = model->links[model->canonical];
  *pose = linkWorldPose(root);
  *twist = linkWorldTwist(root);
  makeRelative(frame, frame_twist, pose, twist);
  return Status::Ok("GetModelState: got properties");
}

Status World::setModelState(const std::string& name, const Pose& pose, const Twist& twist,
                            const std::string& reference_frame) {
  ModelRecord* model = impl_->findModel(name);
  if (!model) return Status::Error("SetModelState: model does not exist");
  if (!isFinite(pose) || !isFinite(twist.linear) || !isFinite(twist.angular) ||
      quatNorm(pose.orientation) < 1e-9)
    return Status::Error("SetModelState: the pose or twist is not finite, or the quaternion is zero");
  Pose frame;
  Twist unused;
  if (!impl_->resolveFrame(reference_frame, &frame, &unused))
    return Status::Error("SetModelState: reference frame '" + reference_frame + "' not found");
  const Pose target = compose(frame, {pose.position, normalized(pose.orientation)});
  // The whole model moves rigidly with its root link.
  const Pose motion = compose(target, inverse(linkWorldPose(model->links[model->canonical])));
  std::vector<Pose> root_poses = impl_->currentLinkPoses(*model);
  for (Pose& p : root_poses) p = compose(motion, p);
  impl_->placeModel(model, compose(motion, model->frame_pose), root_poses,
                    impl_->currentPositions(*model));
  const Vec3 linear = rotate(frame.orientation, twist.linear);
  const Vec3 angular = rotate(frame.orientation, twist.angular);
  for (dBodyID body : model->bodies) {
    const Vec3 v = linear + cross(angular, toVec3(dBodyGetPosition(body)) - target.position);
    dBodySetLinearVel(body, v.x, v.y, v.z);
    dBodySetAngularVel(body, angular.x, angular.y, angular.z);
  }
  return Status::Ok("SetModelState: set model state done");
}

Status World::setModelConfiguration(const std::string& model_name,
                                    const std::vector<std::string>& joints,
                                    const std::vector<double>& positions) {
  ModelRecord* model = impl_->findModel(model_name);
  if (!model) return Status::Error("SetModelConfiguration: model does not exist");
  if (joints.size() != positions.size())
    return Status::Error("SetModelConfiguration: joint_names and joint_positions differ in length");
  std::vector<double> q = impl_->currentPositions(*model);
  for (size_t i = 0; i < joints.size(); ++i) {
    auto joint = std::find_if(model->joints.begin(), model->joints.end(),
                              [&](const JointRecord& j) { return j.desc.name == joints[i]; });
    if (joint == model->joints.end())
      return Status::Error("SetModelConfiguration: joint '" + joints[i] + "' not found in model");
    if (!std::isfinite(positions[i]))
      return Status::Error("SetModelConfiguration: position of '" + joints[i] + "' is not finite");
    q[joint - model->joints.begin()] = positions[i];
  }
  impl_->placeModel(model, model->frame_pose, impl_->currentLinkPoses(*model), q);
  return Status::Ok("SetModelConfiguration: success");
}

Status World::linkProperties(const std::string& scoped_link, LinkInfo* out) const {
  ModelRecord* model;
  size_t index;
  if (!impl_->findLink(scoped_link, &model, &index))
    return Status::Error("GetLinkProperties: link not found");
  const LinkDescription& link = model->links[index].desc;
  LinkInfo info;
  info.model = model->name;
  info.name = link.name;
  info.com = link.com;
  info.mass = link.mass;
  info.ixx = link.ixx, info.ixy = link.ixy, info.ixz = link.ixz;
  info.iyy = link.iyy, info.iyz = link.iyz, info.izz = link.izz;
  info.gravity_mode = link.gravity;
  *out = info;
  return Status::Ok("GetLinkProperties: got properties");
}

Status World::linkState(const std::string& scoped_link, const std::string& reference_frame,
                        Pose* pose, Twist* twist) const {
  ModelRecord* model;
  size_t index;
  if (!impl_->findLink(scoped_link, &model, &index))
    return Status::Error(
        "GetLinkState: link not found, did you forget to scope the link by model name?");
  Pose frame;
  Twist frame_twist;
  if (!impl_->resolveFrame(reference_frame, &frame, &frame_twist))
    return Status::Error("GetLinkState: reference frame '" + reference_frame + "' not found");
  *pose = linkWorldPose(model->links[index]);
  *twist = linkWorldTwist(model->links[index]);
  makeRelative(frame, frame_twist, pose, twist);
  return Status::Ok("GetLinkState: got state");
}

Status World::setLinkState(const std::string& scoped_link, const Pose& pose, const Twist& twist,
                           const std::string& reference_frame) {
  ModelRecord* model;
  size_t index;
  if (!impl_->findLink(scoped_link, &model, &index))
    return Status::Error("SetLinkState: link not found");
  const LinkRecord& link = model->links[index];
  if (!link.body)
    return Status::Error("SetLinkState: link '" + scoped_link +
                         "' is anchored to the world; move its model with set_model_state");
  if (!isFinite(pose) || !isFinite(twist.linear) || !isFinite(twist.angular) ||
      quatNorm(pose.orientation) < 1e-9)
    return Status::Error("SetLinkState: the pose or twist is not finite, or the quaternion is zero");
  Pose frame;
  Twist unused;
  if (!impl_->resolveFrame(reference_frame, &frame, &unused))
    return Status::Error("SetLinkState: reference frame '" + reference_frame + "' not found");
  // As Gazebo: only this link's body moves; its joints pull it back in the next steps.
  const Pose target = compose(frame, {pose.position, normalized(pose.orientation)});
  setBodyPose(link.body, compose(target, inverse(link.link_in_body)));
  const Vec3 linear = rotate(frame.orientation, twist.linear);
  const Vec3 angular = rotate(frame.orientation, twist.angular);
  const Vec3 v = linear + cross(angular, toVec3(dBodyGetPosition(link.body)) - target.position);
  dBodySetLinearVel(link.body, v.x, v.y, v.z);
  dBodySetAngularVel(link.body, angular.x, angular.y, angular.z);
  dBodyEnable(link.body);
  updateJointPositions(model);
  return Status::Ok("SetLinkState: success");
}

std::vector<std::string> World::linkNames() const {
  std::vector<std::string> names;
  for (const auto& model : impl_->models)
    for (const LinkRecord& link : model->links) names.push_back(model->name + "::" + link.desc.name);
  return names;
}

Status World::jointInfo(const std::string& joint_name, JointInfo* out) const {
  ModelRecord* model;
  size_t index;
  if (!impl_->findJoint(joint_name, &model, &index))
    return Status::Error("GetJointProperties: joint not found");
  const JointRecord& joint = model->joints[index];
  JointInfo info;
  info.model = model->name;
  info.name = joint.desc.name;
  info.type = joint.desc.type;
  info.has_damping = joint.desc.has_damping;
  info.damping = joint.desc.damping;
  info.position = joint.position;
  info.rate = jointRate(joint);
  *out = info;
  return Status::Ok("GetJointProperties: got properties");
}

Status World::applyJointEffort(const std::string& joint_name, double effort, int64_t start_ns,
                               int64_t duration_ns) {
  ModelRecord* model;
  size_t index;
  if (!impl_->findJoint(joint_name, &model, &index))
    return Status::Error("ApplyJointEffort: joint not found");
  const JointRecord& joint = model->joints[index];
  if (!joint.ode)
    return Status::Error("ApplyJointEffort: joint '" + joint_name + "' is fixed and takes no effort");
  if (!std::isfinite(effort)) return Status::Error("ApplyJointEffort: effort is not finite");
  int64_t start = 0, end = 0;
  std::string note;
  if (!impl_->jobWindow(start_ns, duration_ns, &start, &end, &note))
    return Status::Ok("ApplyJointEffort: effort set" + note);
  const double safe = safeEffortBound(joint, impl_->params.step);
  if (std::abs(effort) > joint.desc.effort_limit) {
    effort = std::copysign(joint.desc.effort_limit, effort);
    note += "; clamped to the joint's effort limit " + formatNumber(joint.desc.effort_limit);
  }
  if (std::abs(effort) > safe) {
    effort = std::copysign(safe, effort);
    note += "; clamped to " + formatNumber(safe) +
            ", the most this joint takes without the simulation blowing up";
  }
  impl_->joint_jobs.push_back({model, index, effort, start, end});
  return Status::Ok("ApplyJointEffort: effort set" + note);
}

void World::clearJointForces(const std::string& joint_name) {
  auto& jobs = impl_->joint_jobs;
  jobs.erase(std::remove_if(jobs.begin(), jobs.end(),
                            [&](const JointEffortJob& job) {
                              const std::string& bare = job.model->joints[job.joint].desc.name;
                              return bare == joint_name ||
                                     job.model->name + "::" + bare == joint_name;
                            }),
             jobs.end());
}

Status World::applyBodyWrench(const std::string& scoped_link, const std::string& reference_frame,
                              const Vec3& reference_point, const Vec3& force, const Vec3& torque,
                              int64_t start_ns, int64_t duration_ns) {
  ModelRecord* model;
  size_t index;
  if (!impl_->findLink(scoped_link, &model, &index))
    return Status::Error("ApplyBodyWrench: body does not exist");
  dBodyID body = model->links[index].body;
  if (!body)
    return Status::Error("ApplyBodyWrench: body '" + scoped_link + "' is anchored to the world");
  Pose frame;
  Twist unused;
  if (!impl_->resolveFrame(reference_frame, &frame, &unused))
    return Status::Error("ApplyBodyWrench: reference frame '" + reference_frame + "' not found");
  if (!isFinite(reference_point) || !isFinite(force) || !isFinite(torque))
    return Status::Error("ApplyBodyWrench: wrench or reference point is not finite");
  int64_t start = 0, end = 0;
  std::string note;
  if (!impl_->jobWindow(start_ns, duration_ns, &start, &end, &note))
    return Status::Ok("ApplyBodyWrench: wrench set" + note);
  // The same safety bound as for joint efforts, on this body alone.
  dMass mass;
  dBodyGetMass(body, &mass);
  const double step = impl_->params.step;
  const double max_force = mass.mass * kMaxLinearSpeed / (kStepsToSpeedCap * step);
  const double max_torque = std::min({mass.I[0], mass.I[5], mass.I[10]}) * maxAngularSpeed(step) /
                            (kStepsToSpeedCap * step);
  Vec3 f = force, t = torque;
  if (norm(f) > max_force) f = (max_force / norm(f)) * f;
  if (norm(t) > max_torque) t = (max_torque / norm(t)) * t;
  if (norm(f) < norm(force) || norm(t) < norm(torque))
    note += "; clamped to |force| " + formatNumber(max_force) + ", |torque| " +
            formatNumber(max_torque) + ", the most this body takes without the simulation blowing up";
  impl_->wrench_jobs.push_back({model, index, reference_frame, reference_point, f, t, start, end});
  return Status::Ok("ApplyBodyWrench: wrench set" + note);
}

void World::clearBodyWrenches(const std::string& scoped_link) {
  auto& jobs = impl_->wrench_jobs;
  jobs.erase(std::remove_if(jobs.begin(), jobs.end(),
                            [&](const BodyWrenchJob& job) {
                              return job.model->name + "::" + job.model->links[job.link].desc.name ==
                                     scoped_link;
                            }),
             jobs.end());
}

void World::resetWorld() {
  for (const auto& model : impl_->models) impl_->resetModel(model.get());
  impl_->dropJobs([](const ModelRecord*) { return true; });
}

void World::resetSimulation() {
  resetWorld();
  impl_->time_ns = 0;
  impl_->steps = 0;
}

std::vector<CollisionShape> World::collisionShapes() const {
  std::vector<CollisionShape> shapes;
  CollisionShape ground;
  ground.model = kGroundModel;
  ground.link = "link";
  ground.shape = GeometryShape::Plane;
  shapes.push_back(ground);
  for (const auto& model : impl_->models)
    for (const LinkRecord& link : model->links)
      for (size_t c = 0; c < link.geoms.size(); ++c) {
        CollisionShape shape;
        shape.model = model->name;
        shape.link = link.desc.name;
        shape.shape = link.desc.collisions[c].shape;
        shape.size = link.desc.collisions[c].size;
        dQuaternion q;
        dGeomGetQuaternion(link.geoms[c], q);
        shape.pose = {toVec3(dGeomGetPosition(link.geoms[c])), toQuat(q)};
        shapes.push_back(shape);
      }
  return shapes;
}

}  // namespace onedof_sim
