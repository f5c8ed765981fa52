// MuJoCo 2.2 (Debian's libmujoco) behind the engine seam: generalised coordinates. Each model's
// bodies form kinematic trees: a body that is no joint's child is a root with a free joint, a
// joint's child hangs below its parent (the world for parent -1) on a hinge or a slide. A body
// that is the child of two joints (a closed loop) is refused at spawn.
//
// MuJoCo compiles a whole model at once (MJCF text, mj_loadXML) and MuJoCo 2.2 cannot edit a
// compiled one, so adding or removing a model, attaching a model's joints or changing a body's
// mass recompiles the world's model, at most once between two steps (lazily, at the next step or
// ray cast); the models that stay carry their joint positions and rates over (qpos, qvel) bit
// for bit. A spawn costs one compile of the world, linear in its size. Each new model is first
// compiled on its own (addModel), so that what MuJoCo cannot take (a flat mesh, an inertia that
// breaks the triangle inequality) refuses the spawn with MuJoCo's own message as EngineFault,
// before it reaches the world's model.
//
// Each body's frame is its centre of mass with the BodySpec's axes; the body frames in the MJCF
// are the zero configuration (attachJoints), so that every joint reads 0 there. setBodyState
// turns body states into joint coordinates: a root's free joint takes the pose and twist, a
// hinge the child's rotation relative to its parent about the axis, a slide the displacement of
// the child's anchor along it (what does not fit the joint is dropped: the joint holds it).
//
// The step is MuJoCo's forward pipeline and its semi-implicit Euler step (mj_step without the
// checks that reset a diverging state: the world rolls non-finite states back itself), opened up
// at three places:
// - after collision: contacts between two shapes of one model are dropped (MuJoCo's contype
//   bits cannot tell models apart); each contact takes the smaller friction of its two shapes
//   (MuJoCo takes the larger); a cylinder lying on a plane gets its line's middle
//   (lyingCylinder); a contact sliding faster than kSlidingSpeed (contact_rules.h) leaves the solve
//   without friction and takes Coulomb's, mu N against its slip, as an applied force
//   (slidingFriction);
// - after the velocity stage: a joint's friction and its velocity motor are MuJoCo's friction
//   loss row of the joint's degree of freedom (bounded by the friction or the motor's effort),
//   whose reference is moved from rate 0 to the motor's velocity;
// - after the constraint solve: each joint's constraint wrench (cfrc_int) and the contacts'
//   forces are taken, before the step integrates.
// MuJoCo's constraints are soft. Contacts and joint limits here take a time constant of four
// steps, critically damped, at an impedance of 0.99 (a box at rest sinks about 2 micrometres at a
// 1 ms step); the rows that hold a joint's rate take the stiffest reference MuJoCo's refsafe
// allows (two steps) at its largest impedance, so that a velocity motor reaches its speed within
// a step but for 1e-4 of the difference.
//
// PhysicsParams: gravity; the step; sor_pgs_iters is Newton's iteration bound (100 at least).
// MuJoCo has no counterpart for erp, cfm, contact_surface_layer, contact_max_correcting_vel,
// quick_step, sor_pgs_w, max_contacts (its collision functions give up to 8 points a pair) or
// auto_disable_bodies. Friction is an elliptic cone (mu along MuJoCo's first contact tangent, mu2
// along the second). Shapes: boxes, spheres, cylinders, planes (anchored) and meshes, which
// MuJoCo collides, and rays meet, as their convex hulls (a flat mesh as a thin plate). Convex
// pairs that MuJoCo 2.2 collides at one point a step (a cylinder or a mesh against a box, a
// cylinder or a mesh) get the rest of their patch from multiPoint. The seam has no capsules.
#include <mujoco/mujoco.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <optional>

#include "contact_rules.h"
#include "engine.h"
#include "mujoco_mjcf.h"
#include "mujoco_rays.h"
#include "mujoco_sliding.h"
#include "onedof_sim/pose_math.h"

namespace onedof_sim {
namespace core {
namespace {

// The impedance of the two ends of a lying cylinder's line (lyingCylinder): their compliance
// 10^4 times the middle's.
constexpr double kSupportImpedance = 0.01;
// The solves of a step with sliding contacts after the first (slidingFriction).
constexpr int kSlidingPasses = 6;
// MuJoCo's smallest useful friction coefficient of a frictional contact: a contact both of whose
// coefficients are 0 is frictionless (one row).
constexpr double kMinFriction = 1e-5;
// The largest mu in MuJoCo's own cone (a contact that does not slide): its relaxation pushes a
// contact apart by mu times its slip, lifting a wheel rolling at mu 2 and more so that its base
// barely moves. Pushed harder than mu 1 times its load, a contact slides (slidingFriction).
constexpr double kMaxConeFriction = 1.0;
// The most links below one another in a model: each is an MJCF body element inside its
// parent's, and Debian's TinyXML2, MuJoCo's XML reader, refuses elements nested more than 100
// deep (TINYXML2_MAX_ELEMENT_DEPTH).
constexpr size_t kMaxTreeDepth = 95;
// The gap between two stops at one position (rad or m), which MuJoCo cannot take.
constexpr double kMeetingStops = 1e-9;
// MuJoCo's warnings (a full contact buffer) go to the stepping engine's message; its errors
// (mju_error, which would end the process) throw EngineFault out of the MuJoCo call.
thread_local std::string* stepping_message = nullptr;

void collectWarning(const char* text) {
  if (stepping_message && stepping_message->empty())
    *stepping_message = std::string("MuJoCo: ") + text;
  else if (!stepping_message) std::fprintf(stderr, "MuJoCo warning: %s\n", text);
}

void throwError(const char* text) { throw EngineFault(std::string("MuJoCo error: ") + text); }

// MuJoCo's own collision function of each pair of geom types, before multiPoint replaces it.
mjfCollision single_point[mjNGEOMTYPES][mjNGEOMTYPES];

// A pair of convex shapes without a dedicated routine (a cylinder or a mesh against a box, a
// cylinder or a mesh) gets one point from MuJoCo 2.2's MPR: a box resting on a mesh's face rocks
// on that point as it moves about the face. multiPoint finds the rest of the patch: it collides
// the pair again with the second shape tilted by kPatchTilt about the first point, about each
// of kPatchTilts axes square to the normal, so that MPR finds the patch's rim in that direction;
// each point found is tilted back, its depth less what the tilt moved the shape along the first
// point's normal, and kept when it touches and is not one found already.
constexpr double kPatchTilt = 1e-3;
constexpr int kPatchTilts = 8;

int multiPoint(const mjModel* m, const mjData* d, mjContact* con, int g1, int g2, mjtNum margin) {
  const mjfCollision collide = single_point[m->geom_type[g1]][m->geom_type[g2]];
  const int found = collide(m, d, con, g1, g2, margin);
  if (found != 1) return found;
  const Vec3 normal = {con[0].frame[0], con[0].frame[1], con[0].frame[2]};
  const Vec3 origin = {con[0].pos[0], con[0].pos[1], con[0].pos[2]};
  Vec3 across = cross(normal, std::fabs(normal.x) < 0.9 ? Vec3{1, 0, 0} : Vec3{0, 1, 0});
  across = (1 / norm(across)) * across;
  const Vec3 other = cross(normal, across);
  auto* data = const_cast<mjData*>(d);
  mjtNum* pos = data->geom_xpos + 3 * g2;
  mjtNum* mat = data->geom_xmat + 9 * g2;
  mjtNum saved_pos[3], saved_mat[9];
  std::copy(pos, pos + 3, saved_pos);
  std::copy(mat, mat + 9, saved_mat);
  const double unique = 1e-3 * m->geom_rbound[g2] + 1e-9;  // m: points closer are one
  int count = 1;
  for (int k = 0; k < kPatchTilts && count < mjMAXCONPAIR; ++k) {
    const double angle = 2 * M_PI * k / kPatchTilts;
    const Quat tilt = axisAngle(std::cos(angle) * across + std::sin(angle) * other, kPatchTilt);
    const Vec3 centre =
        origin + rotate(tilt, Vec3{saved_pos[0], saved_pos[1], saved_pos[2]} - origin);
    const double q[4] = {tilt.w, tilt.x, tilt.y, tilt.z};
    mjtNum turn[9];
    mju_quat2Mat(turn, q);
    mju_mulMatMat(mat, turn, saved_mat, 3, 3, 3);
    pos[0] = centre.x, pos[1] = centre.y, pos[2] = centre.z;
    mjContact& tilted = con[count];
    if (collide(m, d, &tilted, g1, g2, margin) != 1) continue;
    const Vec3 found_at = {tilted.pos[0], tilted.pos[1], tilted.pos[2]};
    const Vec3 point = origin + inFrame(tilt, found_at - origin);
    // The tilt moved the second shape's surface there by found_at - point.
    const double dist = tilted.dist - dot(found_at - point, normal);
    bool known = dist > margin;
    for (int i = 0; i < count && !known; ++i)
      known = norm(point - Vec3{con[i].pos[0], con[i].pos[1], con[i].pos[2]}) < unique;
    if (known) continue;
    tilted = con[0];
    tilted.pos[0] = point.x, tilted.pos[1] = point.y, tilted.pos[2] = point.z;
    tilted.dist = dist;
    ++count;
  }
  std::copy(saved_pos, saved_pos + 3, pos);
  std::copy(saved_mat, saved_mat + 9, mat);
  return count;
}

// Puts multiPoint in MuJoCo's table of collision functions (one for the process) for the convex
// pairs MPR alone collides, once.
void useMultiPoint() {
  static const bool done = [] {
    std::copy(&mjCOLLISIONFUNC[0][0], &mjCOLLISIONFUNC[0][0] + mjNGEOMTYPES * mjNGEOMTYPES,
              &single_point[0][0]);
    const int pairs[5][2] = {{mjGEOM_CYLINDER, mjGEOM_CYLINDER}, {mjGEOM_CYLINDER, mjGEOM_BOX},
                             {mjGEOM_CYLINDER, mjGEOM_MESH}, {mjGEOM_BOX, mjGEOM_MESH},
                             {mjGEOM_MESH, mjGEOM_MESH}};
    for (const auto& pair : pairs) mjCOLLISIONFUNC[pair[0]][pair[1]] = &multiPoint;
    return true;
  }();
  (void)done;
}

struct BodyState {
  Pose pose;
  Twist twist;
};

// The rotation angle of `turn` about the unit `axis`, in (-pi, pi].
double angleAbout(Quat turn, const Vec3& axis) {
  if (turn.w < 0) turn = {-turn.w, -turn.x, -turn.y, -turn.z};
  const double angle = 2 * std::atan2(dot({turn.x, turn.y, turn.z}, axis), turn.w);
  return angle <= -M_PI ? angle + 2 * M_PI : angle;
}

class MujocoEngine;

class MujocoModel : public EngineModel {
 public:
  MujocoModel(MujocoEngine* engine, int id, const ModelSpec& spec);
  ~MujocoModel() override;

  void attachJoints(const std::vector<Pose>& zero_poses,
                    const std::vector<JointFrame>& frames) override;
  Pose bodyPose(int body) const override { return state(body).pose; }
  Twist bodyTwist(int body) const override { return state(body).twist; }
  void setBodyState(int body, const Pose& pose, const Twist& twist) override {
    if (pending_.empty()) pending_.resize(spec_.bodies.size());
    pending_[body] = BodyState{pose, twist};
  }
  void setAnchoredShapePose(int shape, const Pose& world_pose) override;
  void setBodyMass(int body, const BodySpec& spec) override;
  double jointPosition(int joint) const override;
  double jointRate(int joint) const override;
  Wrench jointConstraintWrench(int joint) const override { return joints_[joint].wrench; }
  void addJointEffort(int joint, double effort) override { joints_[joint].effort += effort; }
  void setJointMotor(int joint, double velocity, double max_effort) override {
    joints_[joint].motor_velocity = max_effort > 0 ? velocity : 0;
    joints_[joint].motor_effort = std::max(0.0, max_effort);
  }
  void addBodyWrench(int body, const Vec3& force, const Vec3& world_point,
                     const Vec3& torque) override {
    Body& b = bodies_[body];
    b.force = b.force + force;
    b.torque = b.torque + torque + cross(world_point - bodyPose(body).position, force);
  }

  // For the engine.
  int id() const { return id_; }
  bool attached() const { return attached_; }
  // The model's bodies (under the world body) and anchored shapes (on it) as MJCF, and their
  // meshes; alone: every body free at its zero pose (set or not), without its joints.
  void writeMjcf(std::string* bodies, std::string* anchored, std::string* assets,
                 bool alone = false) const;
  // Binds to a newly compiled model: `carried` the model's qpos and qvel from the last compile
  // (empty: it starts in its zero configuration).
  void bind(const mjModel* m, mjData* d, const std::vector<double>& carried);
  std::vector<double> carriedState() const;
  bool applyPending();                       // writes pending body states into qpos, qvel
  void loadForces(const mjModel* m, mjData* d);  // efforts, wrenches, gravity, friction rows
  void motorTargets(std::vector<double>* target) const;
  void takeWrenches(const mjModel* m, const mjData* d);
  ShapeRef anchoredShape(int shape) const { return {this, -1, shape}; }
  const ModelSpec& spec() const { return spec_; }

 private:
  struct Body {
    int id = -1;               // MuJoCo's body, in the current compile
    int parent_joint = -1;     // the joint whose child it is
    Pose zero;                 // in the zero configuration
    Vec3 force, torque;        // for the coming step, about the centre of mass
  };
  struct Joint {
    JointSpec spec;
    Vec3 axis_in_parent, anchor_in_parent, anchor_in_child;
    Quat zero_relative;        // the child's orientation in the parent's at zero
    int qpos = -1, dof = -1;   // in the current compile
    double effort = 0;
    double motor_velocity = 0, motor_effort = 0;
    Wrench wrench;
  };

  BodyState state(int body) const;
  BodyState compiledState(int body) const;
  Pose parentPose(const Joint& joint, const std::vector<BodyState>& states) const {
    return joint.spec.parent < 0 ? Pose() : states[joint.spec.parent].pose;
  }
  std::vector<BodyState> targets() const;
  double hingeAngle(const Joint& joint, const std::vector<BodyState>& states) const;
  double slideOffset(const Joint& joint, const std::vector<BodyState>& states) const;
  double jointRateOf(const Joint& joint, const std::vector<BodyState>& states) const;
  void writeBody(int body, const std::vector<std::vector<int>>& children, std::string* out,
                 std::string* assets, bool alone) const;

  MujocoEngine* engine_;
  int id_;
  ModelSpec spec_;
  std::vector<Body> bodies_;
  std::vector<Joint> joints_;
  std::vector<Pose> anchored_poses_;
  std::vector<int> anchored_geoms_;    // MuJoCo's geom per anchored shape, current compile
  std::vector<Pose> anchored_offsets_;  // MuJoCo's geom frame in the shape's (a mesh's centre)
  bool attached_ = false;
  bool bound_ = false;  // in the current compile, with its current structure
  const mjModel* m_ = nullptr;
  const mjData* d_ = nullptr;
  std::vector<std::optional<BodyState>> pending_;  // set since the last step, not yet written
};

class MujocoEngine : public Engine {
 public:
  MujocoEngine() {
    mju_user_warning = &collectWarning;
    mju_user_error = &throwError;
    useMultiPoint();
  }
  ~MujocoEngine() override { release(); }

  // A new step size changes the contacts' reference (kContactSteps): the model is compiled anew.
  void setParams(const PhysicsParams& params) override {
    if (params.step != params_.step) changed();
    params_ = params;
    if (!m_) return;
    m_->opt.timestep = params.step;
    for (int k = 0; k < 3; ++k) m_->opt.gravity[k] = (&params.gravity.x)[k];
    m_->opt.iterations =
        std::max<int>(mjcf::kMinIterations, static_cast<int>(params.sor_pgs_iters));
  }

  std::unique_ptr<EngineModel> addModel(const ModelSpec& spec) override {
    auto model = std::make_unique<MujocoModel>(this, next_id_++, spec);
    models_.push_back(model.get());
    changed();
    return model;
  }

  bool exactSolver(const PhysicsParams&) const override { return false; }
  bool retakesFailedSteps(const PhysicsParams&) const override { return false; }
  std::vector<BodyRef> contactBodies() const override { return {}; }
  // The solver starts each step from the last one's accelerations (warm start), which a state
  // put back does not put back: reset_simulation builds the engine anew.
  bool repeatsWhenPutBack() const override { return false; }

  void contacts(std::vector<EngineContact>* out) const override { *out = contacts_; }

  void step(double dt, std::string* solver_message, bool) override;
  void castRays(const std::vector<Ray>& rays, std::vector<double>* distances) override;

  // For the models.
  const PhysicsParams& params() const { return params_; }
  void changed() { compiled_ = false; contacts_.clear(); }
  void remove(MujocoModel* model) {
    models_.erase(std::find(models_.begin(), models_.end(), model));
    changed();
  }

 private:
  void release() {
    if (d_) mj_deleteData(d_);
    if (m_) mj_deleteModel(m_);
    d_ = nullptr, m_ = nullptr;
  }
  void compile();
  void sync();  // compiled, every pending state written, the kinematics current
  void updateKinematics() {
    mj_kinematics(m_, d_);
    mj_comPos(m_, d_);
    mj_comVel(m_, d_);
  }
  void filterContacts();
  void lyingCylinder(int first);
  void slidingFriction();
  void takeContacts();
  Vec3 pointVelocity(int body, const mjtNum* point) const;
  double slipRow(const mjContact& c, const Vec3& direction, std::vector<mjtNum>* row);
  std::pair<double, double> contactMu(const mjContact& c) const {  // the smaller of each
    return {std::min(geom_mu_[c.geom1].first, geom_mu_[c.geom2].first),
            std::min(geom_mu_[c.geom1].second, geom_mu_[c.geom2].second)};
  }

  PhysicsParams params_;
  std::vector<MujocoModel*> models_;
  int next_id_ = 0;
  mjModel* m_ = nullptr;
  mjData* d_ = nullptr;
  bool compiled_ = false;
  // Per geom of the current compile: its shape, and its friction.
  std::vector<ShapeRef> geom_shapes_;
  std::vector<std::pair<double, double>> geom_mu_;
  std::vector<double> motor_target_;  // per degree of freedom
  std::vector<EngineContact> contacts_;
  // This step's contacts that slide (filterContacts): the contact, the unit slip of geom2's side
  // over geom1's, its friction over the solves (its mu along the slip) and the friction force on
  // geom2's side.
  struct Sliding {
    int contact;
    Vec3 slip;
    std::vector<mjtNum> row;  // slipRow's J
    SlidingFriction law;
    Vec3 friction;
  };
  std::vector<Sliding> sliding_;
  std::vector<mjtNum> applied_;  // xfrc_applied before the sliding friction
  std::vector<mjtNum> jacobian_, solved_;  // slipRow's work space, kept between steps
};

MujocoModel::MujocoModel(MujocoEngine* engine, int id, const ModelSpec& spec)
    : engine_(engine), id_(id), spec_(spec), bodies_(spec.bodies.size()),
      joints_(spec.joints.size()), anchored_poses_(spec.anchored_shapes.size()) {
  for (size_t j = 0; j < joints_.size(); ++j) {
    joints_[j].spec = spec.joints[j];
    Body& child = bodies_[spec.joints[j].child];
    if (child.parent_joint >= 0)
      throw EngineFault("mujoco: closed kinematic loop not supported (a body is the child of "
                        "two joints)");
    child.parent_joint = static_cast<int>(j);
  }
  // Every body must reach a root (a body no joint holds) going up its parents, within the
  // nesting the model's text can hold.
  for (size_t b = 0; b < bodies_.size(); ++b) {
    int at = static_cast<int>(b);
    for (size_t up = 0; at >= 0 && bodies_[at].parent_joint >= 0; ++up) {
      if (up > bodies_.size())
        throw EngineFault("mujoco: closed kinematic loop not supported (joints in a cycle)");
      if (up >= kMaxTreeDepth)
        throw EngineFault("mujoco: a chain of more than " + std::to_string(kMaxTreeDepth) +
                          " links below one another not supported (MuJoCo's model text nests "
                          "each link in its parent, and its XML reader stops at 100 levels)");
      at = joints_[bodies_[at].parent_joint].spec.parent;
    }
  }
  for (size_t s = 0; s < anchored_poses_.size(); ++s)
    anchored_poses_[s] = spec.anchored_shapes[s].pose;
  // Compiled on its own, each body a free body at the origin: what MuJoCo refuses, it refuses
  // here, at the spawn.
  std::string bodies, anchored, assets;
  writeMjcf(&bodies, &anchored, &assets, true);
  std::string error;
  mjModel* alone = mjcf::compile(mjcf::head(engine->params(), 100) + "<asset>" + assets +
                                   "</asset><worldbody>" + anchored + bodies +
                                   "</worldbody></mujoco>",
                               &error);
  if (!alone) throw EngineFault("mujoco: the model cannot be compiled: " + error);
  mj_deleteModel(alone);
}

MujocoModel::~MujocoModel() { engine_->remove(this); }

void MujocoModel::attachJoints(const std::vector<Pose>& zero_poses,
                               const std::vector<JointFrame>& frames) {
  for (size_t b = 0; b < bodies_.size(); ++b) bodies_[b].zero = zero_poses[b];
  for (size_t j = 0; j < joints_.size(); ++j) {
    Joint& joint = joints_[j];
    const Pose parent = joint.spec.parent < 0 ? Pose() : zero_poses[joint.spec.parent];
    const Pose& child = zero_poses[joint.spec.child];
    joint.axis_in_parent = inFrame(parent.orientation, frames[j].axis);
    joint.anchor_in_parent = transformPoint(inverse(parent), frames[j].anchor);
    joint.anchor_in_child = transformPoint(inverse(child), frames[j].anchor);
    joint.zero_relative = multiply(conjugate(parent.orientation), child.orientation);
  }
  attached_ = true;
  bound_ = false;
  pending_.clear();
  engine_->changed();
}

void MujocoModel::setAnchoredShapePose(int shape, const Pose& world_pose) {
  anchored_poses_[shape] = world_pose;
  if (!bound_) return;
  // A static geom's pose is the model's own (geom_pos, geom_quat on the world body).
  const int geom = anchored_geoms_[shape];
  const Pose placed = compose(world_pose, anchored_offsets_[shape]);
  auto* m = const_cast<mjModel*>(m_);
  for (int k = 0; k < 3; ++k) m->geom_pos[3 * geom + k] = (&placed.position.x)[k];
  const Quat& q = placed.orientation;
  const double values[4] = {q.w, q.x, q.y, q.z};
  std::copy(values, values + 4, m->geom_quat + 4 * geom);
}

void MujocoModel::setBodyMass(int body, const BodySpec& spec) {
  spec_.bodies[body] = spec;
  bound_ = false;
  engine_->changed();
}

// A body, its inertia, its shapes, its joint and the bodies below it, in its parent's frame.
void MujocoModel::writeBody(int body, const std::vector<std::vector<int>>& children,
                            std::string* out, std::string* assets, bool alone) const {
  const Body& b = bodies_[body];
  const BodySpec& spec = spec_.bodies[body];
  const std::string name = "m" + std::to_string(id_) + "b" + std::to_string(body);
  Pose in_parent = b.zero;
  if (!alone && b.parent_joint >= 0) {
    const Joint& joint = joints_[b.parent_joint];
    if (joint.spec.parent >= 0)
      in_parent = compose(inverse(bodies_[joint.spec.parent].zero), b.zero);
  }
  *out += "<body name=\"" + name + "\"" + mjcf::placement(in_parent) + ">";
  if (alone || b.parent_joint < 0) {
    *out += "<freejoint/>";
  } else {
    const Joint& joint = joints_[b.parent_joint];
    const Vec3 axis = inFrame(joint.zero_relative, joint.axis_in_parent);
    *out += std::string("<joint type=\"") + (joint.spec.prismatic ? "slide" : "hinge") +
            "\" pos=\"" + mjcf::vector(joint.anchor_in_child) + "\" axis=\"" +
            mjcf::vector(axis) + "\"";
    if (joint.spec.has_limits && joint.spec.lower <= joint.spec.upper) {
      // MuJoCo wants lower < upper: stops that meet (a joint held at one position) are opened
      // by kMeetingStops.
      const double open = joint.spec.lower < joint.spec.upper ? 0 : kMeetingStops / 2;
      *out += " limited=\"true\" range=\"" + mjcf::number(joint.spec.lower - open) + " " +
              mjcf::number(joint.spec.upper + open) + "\"";
    }
    *out += "/>";
  }
  *out += "<inertial pos=\"0 0 0\" mass=\"" + mjcf::number(spec.mass) + "\" " +
          mjcf::inertia(spec) + "/>";
  for (size_t s = 0; s < spec.shapes.size(); ++s) {
    const std::string geom = name + "g" + std::to_string(s);
    *out += "<geom name=\"" + geom + "\" " + mjcf::geom(spec.shapes[s], geom, assets) +
            mjcf::placement(spec.shapes[s].pose) + "/>";
  }
  if (!alone)
    for (int child : children[body]) writeBody(child, children, out, assets, false);
  *out += "</body>";
}

void MujocoModel::writeMjcf(std::string* bodies, std::string* anchored, std::string* assets,
                            bool alone) const {
  std::vector<std::vector<int>> children(bodies_.size());
  for (size_t b = 0; b < bodies_.size(); ++b) {
    const int joint = bodies_[b].parent_joint;
    if (joint >= 0 && joints_[joint].spec.parent >= 0)
      children[joints_[joint].spec.parent].push_back(static_cast<int>(b));
  }
  for (size_t b = 0; b < bodies_.size(); ++b) {
    const int joint = bodies_[b].parent_joint;
    if (alone || joint < 0 || joints_[joint].spec.parent < 0)
      writeBody(static_cast<int>(b), children, bodies, assets, alone);
  }
  for (size_t s = 0; s < spec_.anchored_shapes.size(); ++s) {
    const std::string geom = "m" + std::to_string(id_) + "a" + std::to_string(s);
    *anchored += "<geom name=\"" + geom + "\" " +
                 mjcf::geom(spec_.anchored_shapes[s], geom, assets) +
                 mjcf::placement(anchored_poses_[s]) +
                 "/>";
  }
}

std::vector<double> MujocoModel::carriedState() const {
  std::vector<double> state;
  if (!bound_) return state;
  for (const Body& body : bodies_) {
    const int joint = m_->body_jntadr[body.id];
    const int nq = body.parent_joint < 0 ? 7 : 1, nv = body.parent_joint < 0 ? 6 : 1;
    const mjtNum* q = d_->qpos + m_->jnt_qposadr[joint];
    const mjtNum* v = d_->qvel + m_->jnt_dofadr[joint];
    state.insert(state.end(), q, q + nq);
    state.insert(state.end(), v, v + nv);
  }
  return state;
}

void MujocoModel::bind(const mjModel* m, mjData* d, const std::vector<double>& carried) {
  m_ = m, d_ = d;
  const std::string prefix = "m" + std::to_string(id_);
  for (size_t b = 0; b < bodies_.size(); ++b)
    bodies_[b].id = mj_name2id(m, mjOBJ_BODY, (prefix + "b" + std::to_string(b)).c_str());
  for (Joint& joint : joints_) {
    const int jnt = m->body_jntadr[bodies_[joint.spec.child].id];
    joint.qpos = m->jnt_qposadr[jnt];
    joint.dof = m->jnt_dofadr[jnt];
  }
  anchored_geoms_.resize(anchored_poses_.size());
  anchored_offsets_.resize(anchored_poses_.size());
  for (size_t s = 0; s < anchored_poses_.size(); ++s) {
    const int geom = mj_name2id(m, mjOBJ_GEOM, (prefix + "a" + std::to_string(s)).c_str());
    anchored_geoms_[s] = geom;
    const mjtNum* p = m->geom_pos + 3 * geom;
    const mjtNum* q = m->geom_quat + 4 * geom;
    anchored_offsets_[s] =
        compose(inverse(anchored_poses_[s]), {{p[0], p[1], p[2]}, {q[0], q[1], q[2], q[3]}});
  }
  size_t at = 0;
  for (const Body& body : bodies_) {
    if (carried.empty()) break;
    const int joint = m->body_jntadr[body.id];
    const int nq = body.parent_joint < 0 ? 7 : 1, nv = body.parent_joint < 0 ? 6 : 1;
    std::copy(&carried[at], &carried[at] + nq, d->qpos + m->jnt_qposadr[joint]);
    std::copy(&carried[at + nq], &carried[at + nq] + nv, d->qvel + m->jnt_dofadr[joint]);
    at += nq + nv;
  }
  bound_ = true;
}

// The body's state as MuJoCo's data has it (its kinematics current).
BodyState MujocoModel::compiledState(int body) const {
  const int id = bodies_[body].id;
  const mjtNum* p = d_->xpos + 3 * id;
  const mjtNum* q = d_->xquat + 4 * id;
  mjtNum velocity[6];  // angular, linear, at the centre of mass, world axes
  mj_objectVelocity(m_, d_, mjOBJ_BODY, id, velocity, 0);
  return {{{p[0], p[1], p[2]}, {q[0], q[1], q[2], q[3]}},
          {{velocity[3], velocity[4], velocity[5]}, {velocity[0], velocity[1], velocity[2]}}};
}

// A pending state, else the compiled one, else (not compiled yet) the zero configuration at rest.
BodyState MujocoModel::state(int body) const {
  if (!pending_.empty() && pending_[body]) return *pending_[body];
  if (bound_) return compiledState(body);
  return {bodies_[body].zero, Twist()};
}

std::vector<BodyState> MujocoModel::targets() const {
  std::vector<BodyState> states;
  for (size_t b = 0; b < bodies_.size(); ++b) states.push_back(state(static_cast<int>(b)));
  return states;
}

double MujocoModel::hingeAngle(const Joint& joint, const std::vector<BodyState>& states) const {
  const Quat relative =
      multiply(conjugate(parentPose(joint, states).orientation),
               states[joint.spec.child].pose.orientation);
  return angleAbout(multiply(relative, conjugate(joint.zero_relative)), joint.axis_in_parent);
}

double MujocoModel::slideOffset(const Joint& joint, const std::vector<BodyState>& states) const {
  const Pose parent = parentPose(joint, states);
  const Vec3 moved = transformPoint(states[joint.spec.child].pose, joint.anchor_in_child) -
                     transformPoint(parent, joint.anchor_in_parent);
  return dot(rotate(parent.orientation, joint.axis_in_parent), moved);
}

double MujocoModel::jointRateOf(const Joint& joint, const std::vector<BodyState>& states) const {
  const Pose parent = parentPose(joint, states);
  const Twist parent_twist = joint.spec.parent < 0 ? Twist() : states[joint.spec.parent].twist;
  const BodyState& child = states[joint.spec.child];
  const Vec3 axis = rotate(parent.orientation, joint.axis_in_parent);
  if (!joint.spec.prismatic) return dot(axis, child.twist.angular - parent_twist.angular);
  // d/dt of slideOffset: the child's anchor point moving relative to the parent's, along the
  // axis, and the axis turning with the parent.
  const Vec3 child_arm = rotate(child.pose.orientation, joint.anchor_in_child);
  const Vec3 parent_arm = rotate(parent.orientation, joint.anchor_in_parent);
  const Vec3 apart = (child.pose.position + child_arm) - (parent.position + parent_arm);
  const Vec3 closing = (child.twist.linear + cross(child.twist.angular, child_arm)) -
                       (parent_twist.linear + cross(parent_twist.angular, parent_arm));
  return dot(axis, closing) + dot(cross(parent_twist.angular, axis), apart);
}

double MujocoModel::jointPosition(int joint) const {
  const Joint& j = joints_[joint];
  if (bound_ && pending_.empty()) {
    const double q = d_->qpos[j.qpos];
    if (j.spec.prismatic) return q;
    const double wrapped = std::remainder(q, 2 * M_PI);
    return wrapped <= -M_PI ? wrapped + 2 * M_PI : wrapped;
  }
  const std::vector<BodyState> states = targets();
  return j.spec.prismatic ? slideOffset(j, states) : hingeAngle(j, states);
}

double MujocoModel::jointRate(int joint) const {
  const Joint& j = joints_[joint];
  if (bound_ && pending_.empty()) return d_->qvel[j.dof];
  return jointRateOf(j, targets());
}

bool MujocoModel::applyPending() {
  if (pending_.empty()) return false;
  const std::vector<BodyState> states = targets();
  pending_.clear();
  mjtNum* qpos = const_cast<mjData*>(d_)->qpos;
  mjtNum* qvel = const_cast<mjData*>(d_)->qvel;
  for (size_t b = 0; b < bodies_.size(); ++b) {
    if (bodies_[b].parent_joint >= 0) continue;
    const BodyState& s = states[b];
    const int joint = m_->body_jntadr[bodies_[b].id];
    mjtNum* q = qpos + m_->jnt_qposadr[joint];
    mjtNum* v = qvel + m_->jnt_dofadr[joint];
    const Quat& o = s.pose.orientation;
    const Vec3 local = inFrame(o, s.twist.angular);  // a free joint's rate is in body axes
    const double values[13] = {s.pose.position.x, s.pose.position.y, s.pose.position.z, o.w, o.x,
                               o.y, o.z, s.twist.linear.x, s.twist.linear.y, s.twist.linear.z,
                               local.x, local.y, local.z};
    std::copy(values, values + 7, q);
    std::copy(values + 7, values + 13, v);
  }
  for (const Joint& joint : joints_) {
    double q;
    if (joint.spec.prismatic) {
      q = slideOffset(joint, states);
    } else {
      // The turn nearest the hinge's present angle: MuJoCo's hinge angles are not wrapped.
      const double now = qpos[joint.qpos];
      q = hingeAngle(joint, states);
      q += 2 * M_PI * std::round((now - q) / (2 * M_PI));
    }
    qpos[joint.qpos] = q;
    qvel[joint.dof] = jointRateOf(joint, states);
  }
  return true;
}

void MujocoModel::loadForces(const mjModel* m, mjData* d) {
  auto* model = const_cast<mjModel*>(m);
  for (Joint& joint : joints_) {
    d->qfrc_applied[joint.dof] += joint.effort;
    model->dof_frictionloss[joint.dof] =
        joint.motor_effort > 0 ? joint.motor_effort : joint.spec.friction;
  }
  for (size_t b = 0; b < bodies_.size(); ++b) {
    Body& body = bodies_[b];
    mjtNum* frc = d->xfrc_applied + 6 * body.id;
    Vec3 force = body.force;
    if (!spec_.bodies[b].gravity) force = force - spec_.bodies[b].mass * engine_->params().gravity;
    const double values[6] = {force.x,       force.y,       force.z,
                              body.torque.x, body.torque.y, body.torque.z};
    for (int k = 0; k < 6; ++k) frc[k] += values[k];
    body.force = body.torque = Vec3();
  }
}

void MujocoModel::motorTargets(std::vector<double>* target) const {
  for (const Joint& joint : joints_) (*target)[joint.dof] = joint.motor_velocity;
}

// cfrc_int: the force and torque (about the tree's centre of mass, subtree_com of its root) the
// parent put on the child through the joint, the joint's own effort along its axis included.
void MujocoModel::takeWrenches(const mjModel* m, const mjData* d) {
  for (Joint& joint : joints_) {
    const int id = bodies_[joint.spec.child].id;
    const mjtNum* c = d->cfrc_int + 6 * id;
    const mjtNum* ref = d->subtree_com + 3 * m->body_rootid[id];
    const mjtNum* com = d->xipos + 3 * id;
    const mjtNum* axis = d->xaxis + 3 * m->body_jntadr[id];
    const Vec3 arm = {ref[0] - com[0], ref[1] - com[1], ref[2] - com[2]};
    Vec3 force = {c[3], c[4], c[5]};
    Vec3 torque = Vec3{c[0], c[1], c[2]} + cross(arm, force);
    const Vec3 effort = joint.effort * Vec3{axis[0], axis[1], axis[2]};
    if (joint.spec.prismatic) force = force - effort;
    else torque = torque - effort;
    joint.wrench = {force, torque};
    joint.effort = 0;
  }
}

void MujocoEngine::compile() {
  std::vector<std::vector<double>> carried;
  std::string bodies, anchored, assets;
  int moving_geoms = 0, dofs = 0;
  for (const MujocoModel* model : models_) {
    carried.push_back(model->carriedState());
    if (!model->attached()) continue;
    model->writeMjcf(&bodies, &anchored, &assets);
    for (const BodySpec& body : model->spec().bodies)
      moving_geoms += static_cast<int>(body.shapes.size());
    dofs += 6 * static_cast<int>(model->spec().bodies.size());
  }
  // Room for the constraint rows: up to 8 contacts a moving shape, 3 rows each.
  const int njmax = std::min(3000, 150 + dofs + 24 * moving_geoms);
  std::string error;
  mjModel* m = mjcf::compile(mjcf::head(params_, njmax) + "<asset>" + assets +
                                 "</asset><worldbody>" +
                               anchored + bodies + "</worldbody></mujoco>",
                           &error);
  if (!m) throw EngineFault("mujoco: the world's model cannot be compiled: " + error);
  release();
  m_ = m;
  d_ = mj_makeData(m_);
  for (size_t i = 0; i < models_.size(); ++i)
    if (models_[i]->attached()) models_[i]->bind(m_, d_, carried[i]);
  geom_shapes_.assign(m_->ngeom, ShapeRef());
  geom_mu_.assign(m_->ngeom, {1.0, 1.0});
  std::map<int, const MujocoModel*> by_id;
  for (const MujocoModel* model : models_) by_id[model->id()] = model;
  for (int g = 0; g < m_->ngeom; ++g) {
    int id, body, shape;
    const char* name = m_->names + m_->name_geomadr[g];
    const MujocoModel* model = nullptr;
    if (std::sscanf(name, "m%db%dg%d", &id, &body, &shape) == 3) {
      model = by_id[id];
      geom_shapes_[g] = {model, body, shape};
      const ShapeSpec& s = model->spec().bodies[body].shapes[shape];
      geom_mu_[g] = {s.mu, s.mu2};
    } else if (std::sscanf(name, "m%da%d", &id, &shape) == 2) {
      model = by_id[id];
      geom_shapes_[g] = model->anchoredShape(shape);
      const ShapeSpec& s = model->spec().anchored_shapes[shape];
      geom_mu_[g] = {s.mu, s.mu2};
    }
  }
  motor_target_.assign(m_->nv, 0.0);
  compiled_ = true;
  updateKinematics();
}

void MujocoEngine::sync() {
  if (!compiled_) compile();
  bool moved = false;
  for (MujocoModel* model : models_)
    if (model->attached()) moved = model->applyPending() || moved;
  if (moved) updateKinematics();
}

// Drops contacts between two shapes of one model; sets the rest's friction; gives a cylinder lying
// on a plane its line's middle (lyingCylinder); takes sliding contacts' friction out of the solve.
void MujocoEngine::filterContacts() {
  sliding_.clear();
  int kept = 0;
  for (int i = 0; i < d_->ncon; ++i) {
    mjContact& c = d_->contact[i];
    const ShapeRef& a = geom_shapes_[c.geom1];
    const ShapeRef& b = geom_shapes_[c.geom2];
    if (a.model && a.model == b.model) continue;
    const auto [mu, mu2] = contactMu(c);
    c.dim = mu <= 0 && mu2 <= 0 ? 1 : 3;
    c.friction[0] = std::clamp(mu, kMinFriction, kMaxConeFriction);
    c.friction[1] = std::clamp(mu2, kMinFriction, kMaxConeFriction);
    d_->contact[kept++] = c;
  }
  d_->ncon = kept;
  for (int i = 0; i + 1 < kept; ++i) lyingCylinder(i);
  for (int i = 0; i < d_->ncon; ++i) {
    mjContact& c = d_->contact[i];
    if (c.dim == 1) continue;
    const Vec3 normal = {c.frame[0], c.frame[1], c.frame[2]};
    Vec3 slip;
    if (!slides(pointVelocity(m_->geom_bodyid[c.geom2], c.pos) -
                    pointVelocity(m_->geom_bodyid[c.geom1], c.pos),
                normal, &slip))
      continue;
    const double speed = norm(slip);
    // The coefficient along the slip of the friction ellipse (mu along the first tangent, mu2
    // along the second).
    const double along1 = dot(slip, {c.frame[3], c.frame[4], c.frame[5]}) / speed;
    const double along2 = dot(slip, {c.frame[6], c.frame[7], c.frame[8]}) / speed;
    const auto [mu, mu2] = contactMu(c);
    const double slip_mu =
        1 / std::hypot(along1 / std::max(mu, kMinFriction), along2 / std::max(mu2, kMinFriction));
    const Vec3 direction = (1 / speed) * slip;
    std::vector<mjtNum> row;
    const double compliance = slipRow(c, direction, &row);
    sliding_.push_back({i, direction, std::move(row), SlidingFriction(slip_mu, compliance), Vec3()});
    c.dim = 1;
  }
}

// A cylinder lying on a plane touches it along a line, of which MuJoCo gives the two ends
// (contacts `first` and the next); each engine resolves it by its middle (contact_rules.h): a
// contact there, and the two ends kept as supports without friction and so soft
// (kSupportImpedance) that the middle carries nearly all the load, which bounds its friction.
void MujocoEngine::lyingCylinder(int first) {
  mjContact& p = d_->contact[first];
  mjContact& q = d_->contact[first + 1];
  if (p.geom1 != q.geom1 || p.geom2 != q.geom2 || d_->ncon >= m_->nconmax) return;
  const int plane = m_->geom_type[p.geom1] == mjGEOM_PLANE ? p.geom1 : p.geom2;
  const int cylinder = plane == p.geom1 ? p.geom2 : p.geom1;
  if (m_->geom_type[plane] != mjGEOM_PLANE || m_->geom_type[cylinder] != mjGEOM_CYLINDER ||
      p.dim == 1)
    return;
  const mjtNum* mat = d_->geom_xmat + 9 * cylinder;
  const Vec3 axis = {mat[2], mat[5], mat[8]};
  // MuJoCo's dist is the depth's negative.
  const auto touch = [](const mjContact& c) {
    return TouchPoint{
        {c.pos[0], c.pos[1], c.pos[2]}, {c.frame[0], c.frame[1], c.frame[2]}, -c.dist};
  };
  const TouchPoint ends[2] = {touch(p), touch(q)};
  if (!areLineEnds(axis, ends[0], ends[1])) return;
  const TouchPoint line_middle = pointOnLine(ends[0], ends[1], 0.5);
  mjContact middle = p;
  middle.pos[0] = line_middle.position.x;
  middle.pos[1] = line_middle.position.y;
  middle.pos[2] = line_middle.position.z;
  middle.dist = -line_middle.depth;
  for (mjContact* end : {&p, &q}) {
    end->dim = 1;
    end->solimp[0] = end->solimp[1] = kSupportImpedance;
  }
  d_->contact[d_->ncon++] = middle;
}

// The velocity of a body's material point, world axes (the world body's: 0).
Vec3 MujocoEngine::pointVelocity(int body, const mjtNum* point) const {
  if (body == 0) return {};
  mjtNum velocity[6];  // angular, linear at the centre of mass
  mj_objectVelocity(m_, d_, mjOBJ_BODY, body, velocity, 0);
  const mjtNum* com = d_->xipos + 3 * body;
  return Vec3{velocity[3], velocity[4], velocity[5]} +
         cross({velocity[0], velocity[1], velocity[2]},
               {point[0] - com[0], point[1] - com[1], point[2] - com[2]});
}

// The slip's speed along `direction` over the joints' velocities (J: geom2's material point's
// velocity over geom1's) into *row; returns J M^-1 J^T, the speed 1 N s against the slip takes.
double MujocoEngine::slipRow(const mjContact& c, const Vec3& direction, std::vector<mjtNum>* row) {
  const int nv = m_->nv;
  jacobian_.resize(3 * nv);
  solved_.resize(nv);
  row->assign(nv, 0.0);
  const double along[3] = {direction.x, direction.y, direction.z};
  for (int side = 0; side < 2; ++side) {
    const int body = m_->geom_bodyid[side == 0 ? c.geom2 : c.geom1];
    if (body == 0) continue;
    mj_jac(m_, d_, jacobian_.data(), nullptr, c.pos, body);
    const double sign = side == 0 ? 1.0 : -1.0;
    for (int k = 0; k < 3; ++k)
      for (int v = 0; v < nv; ++v) (*row)[v] += sign * along[k] * jacobian_[k * nv + v];
  }
  mj_solveM(m_, d_, solved_.data(), row->data(), 1);
  double compliance = 0;
  for (int v = 0; v < nv; ++v) compliance += (*row)[v] * solved_[v];
  return compliance;
}

// A sliding contact is frictionless in the solve; its friction, against the slip, is applied to
// its two bodies and the solve taken again (kSlidingPasses), as SlidingFriction sets it from each
// solve. MuJoCo's own friction cone, a convex relaxation, pushes a sliding contact apart by mu
// times its slip: a sliding caster hops along the ground.
void MujocoEngine::slidingFriction() {
  applied_.assign(d_->xfrc_applied, d_->xfrc_applied + 6 * m_->nbody);
  for (int pass = 0; pass < kSlidingPasses; ++pass) {
    std::copy(applied_.begin(), applied_.end(), d_->xfrc_applied);
    for (Sliding& s : sliding_) {
      const mjContact& c = d_->contact[s.contact];
      double slip_at_end = 0;
      for (int v = 0; v < m_->nv; ++v)
        slip_at_end += s.row[v] * (d_->qvel[v] + m_->opt.timestep * d_->qacc[v]);
      const double magnitude =
          s.law.next(d_->efc_force[c.efc_address], slip_at_end, m_->opt.timestep);
      s.friction = -magnitude * s.slip;
      for (int side = 0; side < 2; ++side) {
        const int body = m_->geom_bodyid[side == 0 ? c.geom2 : c.geom1];
        if (body == 0) continue;
        const Vec3 force = side == 0 ? s.friction : -s.friction;
        const mjtNum* com = d_->xipos + 3 * body;
        const Vec3 torque = cross({c.pos[0] - com[0], c.pos[1] - com[1], c.pos[2] - com[2]}, force);
        mjtNum* applied = d_->xfrc_applied + 6 * body;
        const double values[6] = {force.x, force.y, force.z, torque.x, torque.y, torque.z};
        for (int k = 0; k < 6; ++k) applied[k] += values[k];
      }
    }
    mj_fwdAcceleration(m_, d_);
    mj_fwdConstraint(m_, d_);
  }
}

// The contact frame's first row is the normal, from geom1 to geom2; mj_contactForce gives the
// force on geom2 in that frame.
void MujocoEngine::takeContacts() {
  contacts_.clear();
  for (int i = 0; i < d_->ncon; ++i) {
    const mjContact& c = d_->contact[i];
    if (c.efc_address < 0) continue;
    mjtNum local[6];
    mj_contactForce(m_, d_, i, local);
    Vec3 force;
    for (int row = 0; row < std::min(c.dim, 3); ++row)
      force = force +
              local[row] * Vec3{c.frame[3 * row], c.frame[3 * row + 1], c.frame[3 * row + 2]};
    for (const Sliding& s : sliding_)
      if (s.contact == i) force = force + s.friction;
    contacts_.push_back({geom_shapes_[c.geom2], geom_shapes_[c.geom1],
                         {c.pos[0], c.pos[1], c.pos[2]},
                         {c.frame[0], c.frame[1], c.frame[2]}, -c.dist, force});
  }
}

void MujocoEngine::step(double dt, std::string* solver_message, bool) {
  stepping_message = solver_message;
  struct Clear {
    ~Clear() { stepping_message = nullptr; }
  } clear;
  sync();
  m_->opt.timestep = dt;
  mju_zero(d_->qfrc_applied, m_->nv);
  mju_zero(d_->xfrc_applied, 6 * m_->nbody);
  std::fill(motor_target_.begin(), motor_target_.end(), 0.0);
  for (MujocoModel* model : models_)
    if (model->attached()) {
      model->loadForces(m_, d_);
      model->motorTargets(&motor_target_);
    }
  // mj_fwdPosition, with the contacts filtered between collision and the constraints.
  mj_kinematics(m_, d_);
  mj_comPos(m_, d_);
  mj_camlight(m_, d_);
  mj_tendon(m_, d_);
  mj_crb(m_, d_);
  mj_factorM(m_, d_);
  mj_collision(m_, d_);
  filterContacts();
  mj_makeConstraint(m_, d_);
  mj_transmission(m_, d_);
  mj_projectConstraint(m_, d_);
  mj_fwdVelocity(m_, d_);
  // Friction rows: from rate 0 to the motor's velocity (aref = -B (v - target)).
  for (int i = d_->ne; i < d_->ne + d_->nf; ++i)
    if (d_->efc_type[i] == mjCNSTR_FRICTION_DOF)
      d_->efc_aref[i] += d_->efc_KBIP[4 * i + 1] * motor_target_[d_->efc_id[i]];
  mj_fwdActuation(m_, d_);
  mj_fwdAcceleration(m_, d_);
  mj_fwdConstraint(m_, d_);
  if (!sliding_.empty()) slidingFriction();
  mj_rnePostConstraint(m_, d_);
  for (MujocoModel* model : models_)
    if (model->attached()) model->takeWrenches(m_, d_);
  takeContacts();
  mj_Euler(m_, d_);
  updateKinematics();
}

void MujocoEngine::castRays(const std::vector<Ray>& rays, std::vector<double>* distances) {
  sync();
  mujoco_rays::cast(m_, d_, rays, distances);
}

}  // namespace

std::unique_ptr<Engine> makeMujocoEngine() { return std::make_unique<MujocoEngine>(); }

}  // namespace core
}  // namespace onedof_sim
