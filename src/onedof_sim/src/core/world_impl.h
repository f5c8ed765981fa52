// World's private parts, shared by the files that implement it. Private to the core.
//
//   world.cpp             the lifecycle: engine and parameters, spawn and delete, reset, the step
//   world_models.cpp      building a model's records and engine spec, and placing it
//   world_state.cpp       lookups, and the state and property getters and setters
//   world_jobs.cpp        effort and wrench jobs: their bounds, windows and application
//   world_damping.cpp     joint damping, applied implicitly
//   world_inertia.cpp     lumping the links welded into one body
//   world_validation.cpp  the checks of parameters, poses and states; Status formatting
//   world_engine_fault.cpp  an engine that fails inside a call: a new engine, the world going on
//   world_rays.cpp        ray queries through the engine's collision detection
//   world_contacts.cpp    the last step's contacts, named and with their wrenches
//
// Frames. Every link has a link frame (URDF/SDF) and, if it moves, an engine body. Bodies sit at
// the centre of mass of their links with the axes of their reference link, and each link keeps
// the exact link-frame pose in its body frame. Links joined by fixed joints share one body (their
// masses lumped here): a rigid weld is exact that way, where an engine's fixed joint would only
// be held by error correction and drift. Links fixed to `world` (and all links of a static model)
// have no body: their collision shapes are anchored to the environment, and joints to them attach
// to it.
//
// Every model has a model frame (SDF's; a URDF's is its root link's frame), in which its links'
// poses are given (LinkDescription::pose). It moves with the model's canonical link: its world
// pose is that link's times the inverse of the link's pose in it (modelFramePose), as Gazebo's
// Model::WorldPose follows its canonical link. `frame_pose` is where the model frame was when the
// model was last placed: where its joints to `world` are anchored.
//
// Placing a model always goes through the zero configuration first (the engine attaches the
// joints there, so that they read zero there), then to the wanted joint positions by forward
// kinematics; see placeModel().
#pragma once

#include <algorithm>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "engine.h"
#include "model_description.h"
#include "onedof_sim/pose_math.h"
#include "onedof_sim/world.h"

namespace onedof_sim {
namespace core {

constexpr int64_t kForever = std::numeric_limits<int64_t>::max();
// Above this a link crosses 0.1 m per default step: contacts tunnel and the state means nothing,
// so it is a blow-up being born, not motion. Nothing in a robot arm gets near it.
constexpr double kMaxLinearSpeed = 100;
// At most this many step warnings are kept between two takeWarnings() calls; a stuck model would
// otherwise fill memory at the step rate.
constexpr size_t kMaxWarnings = 100;
// The step: below 1 us a second of sim time takes a million steps, hours of wall time for motion
// no robot has; above 0.1 s the angular speed cap (0.1 rad per step) falls to 1 rad/s, too slow
// for the tutorial's pendulum to swing.
constexpr double kMinStep = 1e-6, kMaxStep = 0.1;  // s
// Pending effort jobs per joint and wrench jobs per link. A controller keeps one or two pending
// (the book's: 10 ms jobs at 100 Hz); 1000 leave room for a queued sequence, while each step
// looks at every job, so an endless queue (50000 jobs: real-time factor 0.59) slows the world.
constexpr size_t kMaxPendingJobs = 1000;

// Engines integrate rotation linearly, so a link turning by more than about 0.1 rad per step
// leaves its joints visibly apart (the chord error is r * angle^2 / 2 per step, and error
// correction only removes a fifth of it per step). 0.1 rad per step is 100 rad/s at 1 kHz, well
// above any robot joint. It also keeps the joint unwrapping (which adds wrap(raw - last_raw) each
// step) far from its limit of pi per step.
inline double maxAngularSpeed(double step) { return 0.1 / step; }
// A joint effort or body wrench may take its bodies from rest to the speed caps in no fewer steps
// than this: past that the caps would clip every step and the joints come apart. A real actuator
// is orders of magnitude weaker.
constexpr double kStepsToSpeedCap = 10;

struct LinkRecord {
  LinkDescription desc;
  int parent_joint = -1;
  int body = -1;                  // -1: anchored to the static environment
  bool sets_body_pose = false;    // the reference link of its body: the one that places it
  Pose link_in_body;              // exact link frame in the body (COM) frame
  Pose anchored_pose;             // world pose, when anchored
  int first_anchored_shape = -1;  // its anchored collisions' index in ModelSpec::anchored_shapes
};

struct JointRecord {
  JointDescription desc;
  int parent = -1;        // link index; -1: the static environment (`world`)
  int child = -1;
  int engine_joint = -1;  // -1 for fixed joints: those are welded bodies or anchored links
  double position = 0;    // unwrapped
  double last_raw = 0;    // the engine's wrapped reading at the last update
  std::vector<int> moved_bodies;  // the bodies below the joint
};

struct ModelRecord {
  std::string name;
  bool is_static = false;
  std::vector<LinkRecord> links;  // parents before children
  std::vector<JointRecord> joints;
  std::vector<BodySpec> bodies;   // mass and inertia, for the effort bounds
  // The engine's spec as spawned, to build the model again in a new engine (rebuildEngine); its
  // bodies are `bodies`, which follow setLinkProperties.
  ModelSpec spec;
  std::unique_ptr<EngineModel> engine_model;
  size_t canonical = 0;
  Pose frame_pose;  // world pose of the model frame when last placed: joints to `world` anchor here
  Pose spawn_pose;  // world pose of the model frame at spawn, and after a reset
  bool velocity_capped = false;  // warned already, until a step passes without capping
  bool blown_up = false;  // the last step left it non-finite: held, its jobs not applied
  int64_t last_blow_up_warning_ns = -1;
};

struct JointEffortJob {
  const ModelRecord* model;
  size_t joint;
  double effort;
  int64_t start_ns, end_ns;  // window [start, end)
};

// An effort for the coming step alone (World::setJointEffortCommand), already clamped.
struct JointEffortCommand {
  const ModelRecord* model;
  size_t joint;
  double effort;
};

// A velocity motor for the coming step alone (World::setJointVelocityCommand), its bound held
// within the joint's effort limit.
struct JointMotorCommand {
  const ModelRecord* model;
  size_t joint;
  double velocity, max_effort;
};

// The effort the jobs and commands of one step put on a joint, after clamping.
struct JointEffortSum {
  const ModelRecord* model;
  size_t joint;
  double effort;
};

struct BodyWrenchJob {
  const ModelRecord* model;
  size_t link;
  std::string reference_frame;
  Vec3 point, force, torque;
  int64_t start_ns, end_ns;
};

struct BodyState {
  EngineModel* model;
  int body;
  Pose pose;
  Twist twist;
};

// --- world.cpp -----------------------------------------------------------------------------

// The registry's entry; throws std::invalid_argument naming the known engines.
const EngineEntry& findEngine(const std::string& name);

// --- world_models.cpp ------------------------------------------------------------------------

ShapeSpec shapeSpec(const CollisionDescription& collision);
// Whether a link's collision stays on the static environment: every collision of an anchored
// link, and a plane on any link (a plane is not placed on a body: it stays where its link was put,
// as in Gazebo).
bool isAnchored(const LinkRecord& link, const CollisionDescription& collision);
// Everything about a model that can fail, checked before any engine sees it (so that a refused
// spawn leaves the world as it was) and without a world: fills the link and joint records and the
// engine's spec, and *warnings with its bodies of implausible inertia.
Status planModel(const ModelDescription& desc, ModelRecord* model, ModelSpec* spec,
                 std::vector<InertiaWarning>* warnings);
// The link that places a moving body: the first of the links welded into it.
const LinkRecord& referenceLink(const ModelRecord& model, int body);

// --- world_inertia.cpp -----------------------------------------------------------------------

// u^T I u for a unit axis u given in the tensor's frame.
double momentAbout(const BodySpec& body, const Vec3& u);

// Why the links welded into a body make no rigid body (Limits).
enum class LumpFault { None, NoMass, NotPositiveDefinite, MomentOutOfRange };

// The body's smallest principal moment and the range it had to be in (MomentOutOfRange), kg m^2;
// and, where its collision shapes make it implausible (kMaxLeverRatio), the least moment they
// imply (else 0).
struct MomentBounds {
  double smallest = 0, min = 0, max = 0;
  double least_for_shapes = 0;
};

// One body from the inertials of the links welded into it: the lumped mass, the inertia about the
// lumped centre of mass in the reference link's axes, the reference link's gravity mode and every
// link's collisions on it. On success, also places each of its links in the new body frame
// (link_in_body); on a fault, changes nothing but *bounds (optional).
LumpFault lumpBody(ModelRecord* model, int body, BodySpec* out, MomentBounds* bounds = nullptr);
// What a lumped body's bounds say of it, when its inertia is implausible for its shapes.
std::optional<InertiaWarning> inertiaWarning(const ModelRecord& model, int body,
                                             const MomentBounds& bounds);

// --- world_validation.cpp --------------------------------------------------------------------

bool isFinite(const Twist& t);
// OutOfRange for the field, with the accepted range.
Status outOfRange(std::string field, double min, double max);
// The refusals of World::setParams.
Status validateParams(const PhysicsParams& p);
// Each coordinate within kMaxPosition.
bool withinPosition(const Vec3& v);
// A pose the world can place something at.
Status checkPose(const Pose& pose);
// A pose and twist to set a model or link to: speeds up to the caps the step holds every model
// to (guardStates), which a larger one would only meet clipped.
Status checkState(const Pose& pose, const Twist& twist, double step);

}  // namespace core

// A model planned without a world (World::prepare): its records, no engine model yet, and the
// engine's spec; or the refusal.
struct PreparedModel::Content {
  Status status;
  core::ModelRecord record;
  core::ModelSpec spec;
  Pose model_pose;  // ModelDescription::pose: the model frame in the spawn pose's frame
  std::vector<InertiaWarning> warnings;
  std::vector<std::string> left_out;
};

// World's parts are written against the core's private types (every file that includes this
// one implements World).
using namespace core;

struct World::Impl {
  std::string engine_name;
  std::unique_ptr<Engine> engine;
  PhysicsParams params;
  int64_t step_ns = 0;
  int64_t time_ns = 0;
  uint64_t steps = 0;
  std::vector<std::unique_ptr<ModelRecord>> models;  // spawn order; records never move
  std::vector<JointEffortJob> joint_jobs;
  std::vector<JointEffortCommand> joint_commands;  // for the next step only
  std::vector<JointMotorCommand> joint_motors;     // for the next step only
  std::vector<BodyWrenchJob> wrench_jobs;
  std::vector<std::string> warnings;
  std::vector<BodyState> saved_states;
  int64_t last_retake_warning_ns = -1;  // a failed step taken again (stepContained)
  // The engine's contacts are the last step's and name living models only (Engine::contacts):
  // false from a model's deletion or the engine's rebuilding until the next step.
  bool contacts_current = false;
  bool engine_struggled = false;  // warned already, until a step passes without a solver message
  bool time_ended = false;        // warned already that sim time reached kEndOfTimeNs
  std::vector<std::string> model_path;  // absolute

  Impl(const std::string& name, const PhysicsParams& p);
  ~Impl();

  // --- lifecycle and stepping (world.cpp) ----------------------------------------------------

  void applyParams(const PhysicsParams& p);
  void warn(const std::string& text);
  void destroyModel(size_t index);

  template <typename Predicate>
  void dropJobs(Predicate on_model) {
    joint_jobs.erase(std::remove_if(joint_jobs.begin(), joint_jobs.end(),
                                    [&](const JointEffortJob& j) { return on_model(j.model); }),
                     joint_jobs.end());
    joint_commands.erase(
        std::remove_if(joint_commands.begin(), joint_commands.end(),
                       [&](const JointEffortCommand& c) { return on_model(c.model); }),
        joint_commands.end());
    joint_motors.erase(
        std::remove_if(joint_motors.begin(), joint_motors.end(),
                       [&](const JointMotorCommand& c) { return on_model(c.model); }),
        joint_motors.end());
    wrench_jobs.erase(std::remove_if(wrench_jobs.begin(), wrench_jobs.end(),
                                     [&](const BodyWrenchJob& j) { return on_model(j.model); }),
                      wrench_jobs.end());
  }

  void saveStates();
  bool isBlownUp(const ModelRecord& model) const;

  // One engine step from the saved states. A non-finite state is unrecoverable for an engine,
  // and a step moves all models at once, so a step that blows a model up is undone and redone
  // with that model at rest and its jobs left out: the rest of the world runs on. A model the
  // step leaves non-finite is held where the step started, at rest, and takes part in the next
  // step again (as at first: a model that blew up once is usually only too fast); the first
  // finite step releases it. Logged at most once per model per second of sim time: a model that
  // keeps blowing up would otherwise log at the step rate.
  // retake: see Engine::step.
  void stepEngine(bool retake = false);
  void holdAtSavedState(const ModelRecord& model);

  // After the engine step (stepEngine): every model's speed is capped (see kMaxLinearSpeed and
  // maxAngularSpeed), scaling all its bodies alike so that its joints stay consistent.
  void guardStates();
  Status step();

  // stepEngine, with an engine that fails inside it (EngineFault) taken back: see World::step.
  // Ok, EngineFault (a model removed) or EngineFaultUnattributed (nothing stepped).
  Status stepContained();
  // The models a step that threw EngineFault involves: those it left non-finite, else those
  // whose bodies were in its contacts. Indices into models.
  std::vector<size_t> faultedModels() const;

  // After an engine call threw EngineFault: a new engine with the world's parameters,
  // and every model in it again, its bodies at `states` (saveStates' records, made before the
  // failed call on the old engine) and its joints where they were. saved_states is left empty.
  void rebuildEngine(const std::vector<BodyState>& states);

  // --- state of links and joints, lookups (world_state.cpp) ----------------------------------

  Pose linkWorldPose(const ModelRecord& model, const LinkRecord& link) const;
  // The model frame's world pose, following the canonical link (see Frames above).
  Pose modelFramePose(const ModelRecord& model) const;
  Twist linkWorldTwist(const ModelRecord& model, const LinkRecord& link) const;
  double jointRate(const ModelRecord& model, const JointRecord& joint) const;

  // The joint's anchor and axis in the world as the child sits now.
  JointFrame jointFrame(const ModelRecord& model, const JointRecord& joint) const;
  void updateJointPositions(ModelRecord* model);
  ModelRecord* findModel(const std::string& name) const;

  // "model::link"; nested SDF link names contain "::" too, so match the model name as a prefix.
  bool findLink(const std::string& scoped, ModelRecord** model, size_t* link) const;

  // Scoped "model::joint" first, then the bare name in spawn order.
  bool findJoint(const std::string& name, ModelRecord** model, size_t* joint) const;

  // World pose and twist of an entity used as a reference frame: "" or "world", a model (its
  // model frame, with its canonical link's twist: World::modelState) or a scoped link.
  bool resolveFrame(const std::string& name, Pose* pose, Twist* twist) const;

  // --- contacts (world_contacts.cpp) --------------------------------------------------------

  // The engine shape of "model::link::collision"; false when there is none.
  bool findCollision(const std::string& scoped, ShapeRef* shape) const;
  // The scoped name of an engine shape and the point its contact torques are about (World::
  // contacts); false for a shape of no model in the world.
  bool describeShape(const ShapeRef& shape, std::string* name, Vec3* centre) const;

  // --- building and placing (world_models.cpp) ----------------------------------------------

  // World poses of all links at joint positions q, with joints to `world` anchored at the model
  // frame pose and each free root link (no parent joint) at root_poses[link].
  std::vector<Pose> forwardKinematics(const ModelRecord& model, const Pose& frame_pose,
                                      const std::vector<Pose>& root_poses,
                                      const std::vector<double>& q) const;

  // The bodies' poses for the links' poses; anchored links take theirs (and their shapes) now.
  std::vector<Pose> placeLinks(ModelRecord* model, const std::vector<Pose>& poses);

  // Puts the model at joint positions q (fixed joints ignored) with zero velocity.
  void placeModel(ModelRecord* model, const Pose& frame_pose, const std::vector<Pose>& root_poses,
                  const std::vector<double>& q);
  std::vector<Pose> currentLinkPoses(const ModelRecord& model) const;

  // Gives a moving link a new inertial and its body the new lump; the links keep their poses and
  // velocities, the body frame (at the new centre of mass) moves under them. *warning: set when
  // the new lump's inertia is implausible for its shapes, else reset.
  Status reweighLink(ModelRecord* model, size_t index, const LinkDescription& desc,
                     std::optional<InertiaWarning>* warning);
  std::vector<double> currentPositions(const ModelRecord& model) const;
  void resetModel(ModelRecord* model);

  // --- jobs (world_jobs.cpp) -----------------------------------------------------------------

  // The largest effort that, on the bodies below the joint taken as one rigid body, reaches the
  // speed cap from rest in kStepsToSpeedCap steps. The real (articulated) inertia can only be
  // smaller, so this is not a guarantee; the per-step speed cap and the non-finite rollback catch
  // the rest.
  double safeEffortBound(const ModelRecord& model, const JointRecord& joint) const;

  // Overlapping jobs on a joint sum; the sum is held to what one job may be (applyJointEffort):
  // the joint's effort limit and the bound on its bodies. Blown-up models are held (guardStates).
  // Returns the effort put on each joint that has any.
  std::vector<JointEffortSum> applyJobs(int64_t t);
  void dropExpiredJobs(int64_t next_step_start);

  // --- motors (world_motors.cpp) ------------------------------------------------------------

  // Puts the velocity motors commanded for the coming step on their joints (a blown-up model's
  // are left out, as its jobs are); releaseMotors, once the step is done, turns them off.
  void applyMotors();
  void releaseMotors();

  // --- damping (world_damping.cpp) -----------------------------------------------------------

  // Each damped joint's viscous effort for the coming step, taken implicitly (backward Euler on
  // the joint's own coordinate) so that no damping can reverse or amplify the joint's motion:
  // -b (I qdot + dt Q) / (I + b dt), with I a lower bound of the inertia the joint moves
  // (dampingInertia) and Q the generalized force known before the step: gravity on the bodies
  // below the joint and the joint's own effort (`efforts`, from applyJobs). For b dt << I it is
  // -b qdot; for any b the joint's speed under Q tends to Q / b, as a damper's does.
  void applyDamping(const std::vector<JointEffortSum>& efforts);

  // A lower bound of the joint's effective inertia (kg m^2 about a hinge's axis, kg along a
  // slider) with every other joint free: the child's body alone, about the axis through the
  // anchor when the parent side is the static environment; the reduced inertia of the child's
  // and the parent's bodies each about its centre of mass (masses, for a slider) when the parent
  // side moves too. More bodies and more joints only add to it.
  double dampingInertia(const ModelRecord& model, const JointRecord& joint) const;

  // The generalized force of gravity on the joint's coordinate: on every body below the joint,
  // its torque about the axis (a hinge) or its force along it (a slider).
  double gravityOnJoint(const ModelRecord& model, const JointRecord& joint) const;

  // The joint an effort job or command is for, or why it cannot have one.
  Status effortTarget(const std::string& joint_name, double effort, ModelRecord** model,
                      size_t* index) const;

  // What one job or command may be: the joint's effort limit, then the bound on its bodies.
  double clampEffort(const ModelRecord& model, const JointRecord& joint, double effort,
                     JobOutcome* done) const;

  // The job window for the contract's rules, or false for a zero duration (outcome->queued).
  bool jobWindow(int64_t start_ns, int64_t duration_ns, int64_t* start, int64_t* end,
                 JobOutcome* outcome) const;
};

}  // namespace onedof_sim
