// The physics core of onedof_sim: a world of rigid-body models over a physics engine (ODE,
// Bullet: engineNames()), free of ROS.
//
// A test or the ROS layer drives it step by step. It is not thread-safe: the owner serialises
// calls (the ROS node holds one mutex between service callbacks and the step loop).
//
// Time is kept in integer nanoseconds so that effort-job windows (start <= t < start + duration)
// are exact and never depend on floating-point rounding of step sums.
#pragma once

#include <array>
#include <cstdint>
#include <iosfwd>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace onedof_sim {

namespace core {
struct ModelDescription;  // the core's own (src/core)
}  // namespace core
struct WorldFileModel;  // onedof_sim/world_file.h

struct Vec3 {
  double x = 0, y = 0, z = 0;
};

// Unit quaternion, w first.
struct Quat {
  double w = 1, x = 0, y = 0, z = 0;
};

struct Pose {
  Vec3 position;
  Quat orientation;
};

struct Twist {
  Vec3 linear;
  Vec3 angular;
};

// A force and a torque, the torque about a point the call that gives it names.
struct Wrench {
  Vec3 force;
  Vec3 torque;
};

// What a call that can fail on bad input found: a code and the fact that goes with it, never a
// text (the ROS layer words them as Gazebo does). On failure the world is unchanged.
enum class StatusCode {
  Ok,
  ModelNotFound,           // subject: the model name asked for
  LinkNotFound,            // subject: the link name asked for
  CollisionNotFound,       // subject: the collision name asked for
  JointNotFound,           // subject: the joint name asked for
  ReferenceFrameNotFound,  // subject: the frame name asked for
  ModelExists,             // subject: the model name
  EmptyModelName,
  NotFinite,               // subject: the argument, joint or PhysicsParams field
  ZeroQuaternion,          // a pose's orientation has no direction to normalise to (the ROS
                           // layer reads an all-zero one as the identity, as Gazebo does)
  QuaternionOverflow,      // a pose's orientation is finite but its norm is not (a component
                           // beyond ~1e154): it cannot be normalised
  ModelRejected,           // subject: why the XML makes no model (the parser's reason)
  JointIsFixed,            // subject: the joint name asked for; it takes no effort
  LinkAnchored,            // subject: the link name asked for; it has no body to move or push
  LengthMismatch,          // joint names and positions differ in count
  InvalidParameter,        // subject: the field out of its range (see setParams, setLinkProperties)
  // subject: the field ("twist.linear", "step", ...) or joint; [min, max] the accepted range, in
  // the field's unit. A finite value past what a simulation can mean: refused before an engine
  // overflows on it (see "Limits" in world.cpp).
  OutOfRange,
  InvalidModelName,        // subject: the name; it holds "::" or is "world" (scoped names)
  TooManyJobs,             // subject: the joint or link; max: the jobs it may have pending
  // subject: the internal error the physics engine reported (an assertion inside ODE) on a call
  // the world's checks let through; the world took the call back (see World::step and spawn).
  EngineFault,
  // subject: the internal error the physics engine reported inside a step, then the models in
  // touch in it if any ("...; models in touch: 'a', 'b'"): its fallback solver failed too, and
  // the engine cannot tell which model made it fail. Nothing was removed and nothing moved: the
  // world stands where the step started (see World::step).
  EngineFaultUnattributed,
};

struct Status {
  StatusCode code = StatusCode::Ok;
  std::string subject;
  // OutOfRange: the accepted range; TooManyJobs: max; InvalidParameter "quick_step": the most
  // moving joints a model may have with the exact solver.
  double min = 0, max = 0;
  bool ok() const { return code == StatusCode::Ok; }
};

// For logs and test failures: the code's name, then the subject quoted (ModelNotFound 'nope').
std::ostream& operator<<(std::ostream& out, StatusCode code);
std::ostream& operator<<(std::ostream& out, const Status& status);

// What an accepted effort or wrench job became, for the caller to report.
struct JobOutcome {
  bool queued = true;                // false: the duration was 0, so nothing was applied
  bool widened_to_one_step = false;  // 0 < duration < step: it acts for exactly one step
  std::optional<double> effort_limit;  // set when the effort was clamped to the joint's limit
  // Set when the job was clamped to the most its bodies take without the simulation blowing up
  // (see World::applyJointEffort): a joint's effort, or a wrench's |force| and |torque|.
  std::optional<double> safe_effort;
  struct WrenchBound {
    double force = 0, torque = 0;
  };
  std::optional<WrenchBound> safe_wrench;
};

// Solver settings; the ODE fields of gazebo_msgs/ODEPhysics plus step and gravity.
struct PhysicsParams {
  double step = 0.001;  // seconds, > 0
  Vec3 gravity{0, 0, -9.8};
  // false: dWorldStep (exact LCP); true: dWorldQuickStep. dWorldStep is the default: at the
  // 1 ms step both meet every core_test accuracy figure alike (pendulum period error 0.0006 %,
  // energy drift 0.17 % over 10 s), but a stack of three boxes (10 kg on top) sinks 0.4 mm with
  // dWorldStep and 2.4 mm with QuickStep (50 iterations), and an undamped 7-joint arm steps
  // about 3 times faster with dWorldStep (0.2 s vs 0.6 s per 10k steps on an idle machine). The
  // exact LCP's cubic cost would only show with many simultaneous contacts, which these scenes
  // lack.
  bool quick_step = false;
  bool auto_disable_bodies = false;
  uint32_t sor_pgs_precon_iters = 0;
  uint32_t sor_pgs_iters = 50;
  double sor_pgs_w = 1.3;
  double sor_pgs_rms_error_tol = 0.0;
  double contact_surface_layer = 0.001;
  double contact_max_correcting_vel = 100.0;
  double cfm = 0.0;
  double erp = 0.2;
  uint32_t max_contacts = 20;
};

enum class JointType { Revolute, Continuous, Prismatic, Fixed };

struct JointInfo {
  std::string model;  // owning model name
  std::string name;   // bare joint name
  JointType type = JointType::Revolute;
  bool has_damping = false;  // the URDF/SDF declared <dynamics damping>
  double damping = 0;
  double position = 0;  // rad or m; continuous joints are not wrapped
  double rate = 0;      // rad/s or m/s
  bool has_limits = false;  // revolute and prismatic: the URDF/SDF <limit> lower and upper
  double lower = 0, upper = 0;
};

struct LinkInfo {
  std::string model;
  std::string name;  // bare link name
  Pose com;          // centre of mass in the link frame (orientation of the inertial frame)
  double mass = 0;
  double ixx = 0, ixy = 0, ixz = 0, iyy = 0, iyz = 0, izz = 0;  // in the inertial frame
  bool gravity_mode = true;
};

struct ModelInfo {
  std::string name;
  std::string canonical_link;  // scoped "model::link"
  std::vector<std::string> links;      // scoped
  std::vector<std::string> geoms;      // collision names
  std::vector<std::string> joints;     // bare
  bool is_static = false;
};

// Mesh: a triangle mesh read from a file (STL, COLLADA), scaled.
enum class GeometryShape { Box, Cylinder, Sphere, Plane, Mesh };

// One collision shape in world coordinates, for visualisation (rviz MarkerArray).
struct CollisionShape {
  std::string model;
  std::string link;
  GeometryShape shape = GeometryShape::Box;
  Vec3 size;  // box: x y z; cylinder: radius, -, length; sphere: radius; mesh: its scale
  Pose pose;  // world pose of the shape's centre (a mesh's: of its file's origin)
  std::string mesh_file;  // mesh: the file it was read from (absolute)
};

// A colour as Gazebo's materials give it: red, green, blue, alpha in [0, 1].
struct Color {
  float r = 0, g = 0, b = 0, a = 1;
};

// A visual's material as its model states it, unresolved: Gazebo's named material (an SDF
// <material><script><name>, or a URDF link's <gazebo reference="LINK"><material>) and the
// colours given explicitly (SDF <ambient>, <diffuse>, <emissive>; a URDF <material><color> is
// the ambient and the diffuse colour, as Gazebo's URDF conversion makes it). The renderer
// resolves the name (src/render/materials.h).
struct VisualMaterial {
  std::string script;  // "Gazebo/Red"; empty: none
  std::optional<Color> ambient, diffuse, emissive;
};

// A triangle mesh read from a file, scaled: vertices in the frame of the shape that uses it,
// triangles wound counter-clockwise seen from outside.
struct TriangleMesh {
  std::string file;  // the file it was read from
  std::vector<Vec3> vertices;
  std::vector<std::array<uint32_t, 3>> triangles;
  Vec3 min, max;  // the vertices' bounds
};

// One visual of a link (<visual>) in world coordinates, for rendering: what the model gave at
// spawn, placed where its link is.
struct VisualShape {
  std::string model;
  std::string link;  // bare
  std::string name;  // the <visual>'s name (URDF: LINK_visual, LINK_visual_1, ... unnamed)
  GeometryShape shape = GeometryShape::Box;
  // box: x y z; cylinder: radius, -, length; sphere: radius; plane: x, y extent, -; mesh: its
  // scale
  Vec3 size;
  // World pose of the shape's centre (a mesh's: of its file's origin); a plane's normal is the
  // pose's z axis.
  Pose pose;
  std::string mesh_uri;   // mesh: the URI as the model gives it
  std::string mesh_file;  // mesh: the file it names (absolute); empty when none was found
  VisualMaterial material;
};

// Reads a visual's mesh file (VisualShape::mesh_file) with the loader the collision meshes use
// (assimp), scaled by `scale` (each component finite and non-zero). Refuses (ModelRejected, the
// reason) a file it cannot read, one without triangles, and one past kMaxVisualMeshTriangles.
constexpr size_t kMaxVisualMeshTriangles = 1000000;
Status readVisualMesh(const std::string& file, const Vec3& scale,
                      std::shared_ptr<const TriangleMesh>* out);

// A joint as a view draws it (Gazebo's View > Joints): where it is now, world coordinates.
struct JointAxis {
  std::string model;
  std::string name;  // bare
  JointType type = JointType::Fixed;
  Vec3 anchor;         // the joint's origin (URDF: its child link's frame origin)
  Vec3 axis{1, 0, 0};  // unit; a fixed joint's is its description's, meaningless
};

// A link's mass as a view draws it (Gazebo's View > Center of Mass, > Inertia): its inertial
// frame's world pose, its mass and its inertia in that frame. Links without mass are left out.
struct LinkMass {
  std::string model;
  std::string link;  // bare
  Pose inertial;     // world pose of the inertial frame (its origin: the centre of mass)
  double mass = 0;
  double ixx = 0, ixy = 0, ixz = 0, iyy = 0, iyz = 0, izz = 0;  // in the inertial frame
};

enum class ModelFormat { Urdf, Sdf };

// A ray segment in world coordinates: from `from` along `direction` (any length but zero) for
// `length` metres.
struct Ray {
  Vec3 from;
  Vec3 direction;
  double length = 0;
};

// A moving body the world takes though its inertia is implausible for its collision shapes: a
// push across a corner of a shape's bounding box turns that corner more than 1000 times as fast
// as it moves the body (uniform solids: 2 to 8). Gazebo spawns such bodies, and so does the world;
// an engine may fail on one (ODE's contact solver, from about 5e5) or let it sink through the
// ground (Bullet, from about 5e4), which the world contains as it contains any engine failure
// (see step). The owner tells its user.
struct InertiaWarning {
  std::string link;             // the body's reference link (bare name)
  double smallest_moment = 0;   // its smallest principal moment, kg m^2
  double least_moment = 0;      // the least its shapes make plausible, kg m^2
};

// One point where two collisions touched in a step (World::contacts).
struct ContactPoint {
  Vec3 position;      // world
  Vec3 normal;        // unit, world: the direction that moves collision1 out of collision2
  double depth = 0;   // how far the two overlap along the normal, m
  // What the contact put on each collision's link over the step, world axes: the force at
  // `position` (normal and friction; wrench2's is wrench1's opposite) and its torque about the
  // centre of mass of the body the link moves with (its links welded by fixed joints included);
  // for a link without a body (anchored, static: a ground plane's), about its own centre of mass.
  Wrench wrench1, wrench2;
};

// The touch between two collisions in a step: every point where they met.
struct Contact {
  std::string collision1, collision2;  // scoped "model::link::collision"
  std::vector<ContactPoint> points;
};

// A model read from its XML and checked against every limit that does not depend on a world
// (World::prepare), for World::spawn to add to one. Self-contained: made without a world, it can
// be parsed on one thread while another steps the world.
class PreparedModel {
 public:
  PreparedModel();
  ~PreparedModel();
  PreparedModel(PreparedModel&&) noexcept;
  PreparedModel& operator=(PreparedModel&&) noexcept;
  // Ok, or why the XML makes no model (ModelRejected with the reason).
  const Status& status() const;
  // Its bodies of implausible inertia, which it is spawned with.
  const std::vector<InertiaWarning>& warnings() const;
  // The collisions it is spawned without, as Gazebo spawns a model without a collision mesh it
  // cannot find: why, for each ("link 'l': collision 'c' is the mesh 'm', which is not found ...").
  const std::vector<std::string>& leftOut() const;

 private:
  friend class World;
  struct Content;
  std::unique_ptr<Content> content_;
};

class World {
 public:
  // The engines World can run on, in registry order; the first is the default.
  static std::vector<std::string> engineNames();

  // An empty world: no ground, as in Gazebo, where the ground is a model a world places (its
  // ground_plane, a static <plane> collision). Throws std::invalid_argument for an engine not in
  // engineNames().
  explicit World(const std::string& engine = engineNames().front(),
                 const PhysicsParams& params = PhysicsParams());
  ~World();
  World(const World&) = delete;
  World& operator=(const World&) = delete;

  // --- time and stepping -------------------------------------------------------------------
  // Advances one step of params().step: applies the effort jobs whose window covers the step's
  // start time, integrates, resolves contacts, then advances time. When the engine fails inside
  // the step (an assertion inside ODE), the world builds its engine again from the states before
  // the step and takes the step again with the engine's fallback solver (ODE's dWorldQuickStep
  // for its dWorldStep): Ok, every model kept, a warning (takeWarnings) saying so. When that
  // fails too: EngineFault, the model that made it fail removed (the models the failed step left
  // non-finite; failing those, the one model whose bodies were in its contacts) and the step
  // taken without it, the warnings naming the model and the engine's error; or, when the engine
  // cannot tell which model that is, EngineFaultUnattributed: no model removed, the step not
  // taken (time stands), the world where the step started.
  Status step();
  int64_t timeNs() const;
  double time() const;  // seconds
  uint64_t stepCount() const;
  // Sets the clock, as a saved world's <state> gives it (its <sim_time> and <iterations>) and
  // Gazebo's world takes it at load; reset_simulation takes it back to 0. Refuses (OutOfRange
  // "sim_time", [0, the end of ROS time] in s) a time the clock cannot show.
  Status setClock(int64_t time_ns, uint64_t step_count);

  const std::string& engineName() const;
  const PhysicsParams& params() const;
  // Refuses (subject: the field) a non-finite number (NotFinite), and (InvalidParameter) a step
  // under 1 ns, erp outside [0, 1], a negative cfm, contact_surface_layer,
  // contact_max_correcting_vel or sor_pgs_rms_error_tol, sor_pgs_w <= 0, sor_pgs_iters < 1,
  // max_contacts > 65535 (ODE takes it in 16 bits); and (InvalidParameter "quick_step", max: the
  // limit) the exact solver while a model has more moving joints than it steps in the budget.
  Status setParams(const PhysicsParams& params);

  // --- models ------------------------------------------------------------------------------
  // Model frames. Each model has a model frame, Gazebo's: an SDF model's frame, in which its
  // links' <pose>s are given, or a URDF's root link frame (where Gazebo's URDF conversion puts
  // it). It moves with the model's canonical link (SDF's, else its first link; a URDF's root),
  // keeping that link's pose in it, as Gazebo's model pose follows its canonical link. Every
  // model pose here is the model frame's: spawn, modelState and setModelState, resetWorld, and a
  // model named as a reference frame. A model's twist is its canonical link's (the velocity of
  // that link's origin and its angular velocity), as Gazebo's Model::WorldLinearVel and
  // WorldAngularVel give it.
  //
  // Parses xml (URDF with urdfdom, SDF with libsdformat), builds the model and places its model
  // frame at `pose` expressed in `reference_frame` ("" or "world", a model name, or
  // "model::link") composed with the model's own pose (an SDF model's <pose>, or a -database
  // request's <include> <pose>, taken in `pose`'s frame, as gazebo_ros' spawn services compose
  // them). Refuses, in this order: a non-finite or zero-quaternion pose, an empty or taken name,
  // an unknown reference frame (checkSpawn), XML that makes no model (ModelRejected with the
  // reason: prepare), a model too large for this world's solver (ModelRejected: see
  // spawn(PreparedModel)). The same as checkSpawn, prepare and spawn(PreparedModel) in a row.
  Status spawn(const std::string& name, const std::string& xml, ModelFormat format,
               const Pose& pose, const std::string& reference_frame = "");
  // The refusals of spawn that depend on this world (the name and the reference frame) and
  // precede reading the XML, in spawn's order.
  Status checkSpawn(const std::string& name, const Pose& pose,
                    const std::string& reference_frame) const;
  // Reads and checks xml without any world: its size and its counts of links, joints and
  // <include>s against the limits first (a quick pass, before the parser), then the parser, every
  // limit on what the model gives, and the plan of its bodies and joints. model_path: absolute
  // folders, as modelPath() gives them. Safe to call on any thread at any time.
  static PreparedModel prepare(const std::string& xml, ModelFormat format,
                               const std::vector<std::string>& model_path);
  // A model of a world file, from what readWorldFile read of it: the same model, limits and
  // refusals as prepare(model.sdf, ModelFormat::Sdf, model path), without reading its XML again.
  static PreparedModel prepare(const WorldFileModel& model);
  // Adds a prepared model (it is consumed; on a refusal too). Refuses, in this order: checkSpawn's
  // refusals, the prepared model's, (ModelRejected) a model with more moving joints than this
  // world's solver steps in the step-cost budget (ODE's exact dWorldStep: see "Limits"),
  // (OutOfRange "pose.position") a model frame that the model's own pose would put past the
  // Limits, and (EngineFault) a model the engine fails on as it takes it in: the world builds its
  // engine again without it, every other model where it was.
  Status spawn(const std::string& name, PreparedModel model, const Pose& pose,
               const std::string& reference_frame = "");
  // Folders where SDF's model://NAME URIs are looked up, in this order, as gzserver looks them
  // up in GAZEBO_MODEL_PATH: an <include>d model, a mesh. Relative folders are taken from the
  // current directory at the time of the call. Empty until set.
  void setModelPath(const std::vector<std::string>& folders);
  const std::vector<std::string>& modelPath() const;  // absolute
  Status deleteModel(const std::string& name);
  std::vector<std::string> modelNames() const;  // in spawn order

  Status modelProperties(const std::string& name, ModelInfo* out) const;
  // Pose of the model frame and the model's twist (see Model frames above), in reference_frame
  // ("" / "world" or entity): the pose in the entity's frame, the velocities relative to the
  // entity's in its axes, as Gazebo's get_model_state gives them.
  Status modelState(const std::string& name, const std::string& reference_frame, Pose* pose,
                    Twist* twist) const;
  // Puts the model frame at `pose` in reference_frame, the whole model moving rigidly with it
  // (its joints where they are), and gives the model `twist` (in reference_frame's axes): its
  // canonical link's origin moves at twist.linear and every body turns at twist.angular, rigidly,
  // so modelState gives the twist back. (Gazebo gives every link's centre of mass twist.linear:
  // the same when the angular velocity is zero; a turning model's joints are pulled apart there.)
  // Refuses a non-finite pose or twist before it looks the model up.
  Status setModelState(const std::string& name, const Pose& pose, const Twist& twist,
                       const std::string& reference_frame);
  // Sets joint positions with zero velocity, moving the links below each joint. Checks the
  // lengths and the numbers before the names.
  Status setModelConfiguration(const std::string& model, const std::vector<std::string>& joints,
                               const std::vector<double>& positions);

  // --- links (names scoped "model::link") ----------------------------------------------------
  Status linkProperties(const std::string& scoped_link, LinkInfo* out) const;
  // Pose of the link frame and its twist (its origin's velocity), in reference_frame as
  // modelState's (a model named there: its model frame).
  Status linkState(const std::string& scoped_link, const std::string& reference_frame,
                   Pose* pose, Twist* twist) const;
  // Refuses a non-finite pose or twist before it looks the link up; an anchored link (LinkAnchored)
  // moves only with its model.
  Status setLinkState(const std::string& scoped_link, const Pose& pose, const Twist& twist,
                      const std::string& reference_frame);
  std::vector<std::string> linkNames() const;  // all links of all models, scoped
  // The link's mass, centre of mass (com: the inertial frame in the link frame), inertia (in the
  // inertial frame) and gravity mode from now on, as its <inertial> would have given them; the
  // links keep their poses and velocities. A link welded to others changes their lumped body.
  // Refuses, leaving the world unchanged: a non-finite number (NotFinite "mass", "com" or
  // "inertia"), a zero com orientation (ZeroQuaternion), and (InvalidParameter) a negative mass
  // or a moving body left without mass ("mass"), an inertia no rigid body has ("inertia"), a
  // gravity mode that differs from the other links welded into its body ("gravity_mode"), and
  // (OutOfRange "inertia", [min, max] in kg m^2) principal moments out of the Limits. An inertia
  // implausible for the body's collision shapes is taken, and *warning (optional) says so.
  Status setLinkProperties(const std::string& scoped_link, const LinkInfo& properties,
                           std::optional<InertiaWarning>* warning = nullptr);

  // --- joints (name bare or scoped "model::joint"; the first model that has it wins) ---------
  Status jointInfo(const std::string& joint, JointInfo* out) const;
  // Viscous damping (N m s/rad or N s/m) from now on, as <dynamics damping> would have given it;
  // World applies it as an effort, implicitly (stable at any accepted value), so it acts alike on
  // every engine. Refuses a fixed joint (JointIsFixed), a non-finite (NotFinite), negative
  // (InvalidParameter "damping") or larger than 1e6 (OutOfRange) value.
  Status setJointDamping(const std::string& joint, double damping);

  // Effort jobs: start and duration in nanoseconds of sim time. A start before now means now.
  // duration < 0: until cleared; == 0: nothing is queued; 0 < duration < step: exactly one step.
  // Effort is clamped to the joint's effort limit, then to what takes the bodies below the joint
  // from rest to the speed cap in no fewer than 10 steps; non-finite effort is refused. *outcome
  // (optional) says which of these happened.
  Status applyJointEffort(const std::string& joint, double effort, int64_t start_ns,
                          int64_t duration_ns, JobOutcome* outcome = nullptr);
  // The effort a controller running inside the step loop commands for the next step() only,
  // on top of the joint's effort jobs; the owner sets it again before each step (a joint not
  // set has none). Clamped as an effort job is (*outcome says so); the refusals are
  // applyJointEffort's, bar the job count.
  Status setJointEffortCommand(const std::string& joint, double effort,
                               JobOutcome* outcome = nullptr);
  // A velocity motor on the joint for the next step() only, as a Gazebo joint's SetParam("vel")
  // with SetParam("fmax") (gazebo_ros_diff_drive drives its wheels so): the engine's solver
  // drives the joint's rate to `velocity` (rad/s or m/s) pushing with at most `max_effort`
  // (N m or N, held within the joint's effort limit), implicitly, so it is stable at any bound.
  // It acts beside the joint's efforts, in place of its friction; the owner sets it again before
  // each step. Refuses: JointNotFound, JointIsFixed, NotFinite ("velocity", "max_effort"),
  // InvalidParameter "max_effort" (negative), and OutOfRange "velocity" past the speed cap.
  Status setJointVelocityCommand(const std::string& joint, double velocity, double max_effort);
  // What the joint's constraint put on its child link in the last step, in world axes: the
  // force, and the torque about the joint's anchor (its origin; for URDF the child link's frame
  // origin). It is what holds the child to the parent side along the directions the joint does
  // not move in, and the joint's stops and its friction or velocity motor along the one it does;
  // efforts (jobs, commands, damping) are not in it. Zero before the model's first step and after
  // the engine is built again (see step). Refuses JointNotFound, and JointIsFixed for a joint
  // that holds nothing apart: a fixed joint welds its links into one body, and a static model's
  // joints are not simulated.
  Status jointConstraintWrench(const std::string& joint, Wrench* out) const;
  // Drops every pending job on joints of that bare name (any model).
  void clearJointForces(const std::string& joint);
  // Whether an effort job acts on the joint in the step that starts at t_ns; false for a joint
  // that does not exist, a deleted model's included. For the owner to see where a controller's
  // command runs out.
  bool jointEffortActive(const std::string& joint, int64_t t_ns) const;

  // Wrench on a link, force and torque in reference_frame's orientation, force applied at
  // reference_point (in reference_frame). Same job rules as joint efforts, the bound on this
  // body alone; non-finite numbers are refused before the names are looked up.
  Status applyBodyWrench(const std::string& scoped_link, const std::string& reference_frame,
                         const Vec3& reference_point, const Vec3& force, const Vec3& torque,
                         int64_t start_ns, int64_t duration_ns, JobOutcome* outcome = nullptr);
  void clearBodyWrenches(const std::string& scoped_link);

  // --- reset ---------------------------------------------------------------------------------
  // Every model back to its spawn pose (of its model frame) and configuration with zero velocity;
  // drops effort jobs.
  void resetWorld();
  // resetWorld() for one model: back to its spawn pose and configuration with zero velocity, its
  // effort jobs dropped.
  Status resetModel(const std::string& name);
  // resetWorld() and sim time back to 0, the engine's random numbers (and, where the engine
  // needs it, the engine itself) as a new world's: the same steps after it give the same states
  // bit for bit as they gave after the spawns.
  void resetSimulation();

  // --- introspection -------------------------------------------------------------------------
  std::vector<CollisionShape> collisionShapes() const;
  // Every spawned model's visuals, in spawn order, each link's in the order its model gives them.
  std::vector<VisualShape> visualShapes() const;
  // Every spawned model's joints, and its links' masses, each model's in its own order.
  std::vector<JointAxis> jointAxes() const;
  std::vector<LinkMass> linkMasses() const;

  // For each ray, the distance from its start to the first collision shape it meets within its
  // length (every model's, the sensor's own included, meshes and planes), found by
  // the engine's own collision detection; +infinity where it meets none. A ray does not meet a
  // box, sphere, cylinder or capsule that holds its start (inside or on its surface), as a GPU
  // laser does not see its own case: a lidar on a box link starts its rays on that box's face.
  // Refuses, with *distances empty: a non-finite number (NotFinite "ray"), a zero direction or a
  // negative length (InvalidParameter "ray"), and (EngineFault) a query the engine failed inside
  // (the world builds its engine again, every model where it was).
  Status castRays(const std::vector<Ray>& rays, std::vector<double>* distances);

  // The contacts the last step resolved, each point with the force the step's contact constraint
  // put through it, that involve one of `collisions` (scoped "model::link::collision"; a URDF's
  // unnamed collisions are LINK_collision, LINK_collision_1, ...; Gazebo's ground plane's is
  // ground_plane::link::collision): one Contact for each pair of collisions that touched, with
  // the named one as collision1 (the first named, when both are), in the engine's order. Empty
  // before the first step and after a model is deleted or the engine is built again, until the
  // next step. Refuses, with *out empty, a name that is no collision in the world
  // (CollisionNotFound, subject: the name).
  Status contacts(const std::vector<std::string>& collisions, std::vector<Contact>* out) const;
  // contacts() of every collision in the world, the ground's included.
  std::vector<Contact> allContacts() const;

  // What step() had to do on its own since the last call, for the owner to log: a model's speed
  // capped, a non-finite state undone. Drains the list (at most 100 kept between calls).
  std::vector<std::string> takeWarnings();

 private:
  friend struct WorldTestAccess;  // the tests' way to the engine under a world
  // What both prepares make of a model read and checked: its own pose checked, its bodies and
  // joints planned.
  static void plan(const core::ModelDescription& description, PreparedModel* prepared);
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace onedof_sim
