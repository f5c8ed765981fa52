// The engine seam: what World asks of a physics engine. Private to the core.
//
// World does everything that does not depend on the engine: parsing, the model registry and
// scoped names, reference frames, welding links joined by fixed joints into one rigid body and
// lumping their masses, forward kinematics, effort and wrench jobs, the speed caps and the
// non-finite rollback. An engine only ever sees rigid bodies (frame at the centre of mass, full
// inertia tensor about it), collision shapes on them or anchored to the environment, and 1-DOF
// joints between two bodies or a body and the environment.
//
// Adding an engine: one adapter file in engines/ implementing Engine and EngineModel, and one
// entry in engines/registry.cpp. The contact rules every engine applies alike (a lying
// cylinder's line, Coulomb's friction at a sliding contact) are engines/contact_rules.h's.
#pragma once

#include <cstdarg>
#include <cstdio>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "mesh_loader.h"
#include "onedof_sim/world.h"

namespace onedof_sim {
namespace core {

// An engine library's internal error (ODE's assertions, which end in dDebug, and its dError), thrown
// out of the engine call it happened in instead of ending the process. The engine and every
// model in it can afterwards only be read (bodyPose, bodyTwist) and destroyed: World builds a new
// engine from its own records and the states from before the call.
class EngineFault : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// For an engine library's error handler (a printf format and its arguments): inside an engine
// call, throws EngineFault with `library`'s words; outside one, prints them to stderr, and the
// library ends the process when its handler returns, as it would without one.
inline void faultFromErrorHandler(const char* library, bool inside_call, int number,
                                  const char* format, va_list args) {
  char text[512];
  std::vsnprintf(text, sizeof text, format, args);
  if (inside_call) throw EngineFault(std::string(library) + ": " + text);
  std::fprintf(stderr, "%s, error %d: %s\n", library, number, text);
}

struct ShapeSpec {
  // Box, Cylinder (along z), Sphere or Mesh; Plane (the plane z = 0 of its pose, unbounded) only
  // among a model's anchored shapes: a world's ground is a model's plane (Gazebo's ground_plane).
  GeometryShape shape = GeometryShape::Box;
  Vec3 size;   // as CollisionShape::size
  Pose pose;   // in the body frame; for an anchored shape, set by setAnchoredShapePose
  // A contact uses the smaller value of its two shapes; an engine with isotropic friction
  // (Bullet) uses mu only.
  double mu = 1, mu2 = 1;
  // Mesh: the triangles, already scaled, in the shape's frame. The engine may keep pointers into
  // it while it holds this pointer.
  std::shared_ptr<const TriangleMesh> mesh;
};

struct BodySpec {
  double mass = 0;  // > 0
  // Inertia about the centre of mass in the body's axes (the body frame's origin is the COM).
  double ixx = 0, iyy = 0, izz = 0, ixy = 0, ixz = 0, iyz = 0;
  bool gravity = true;
  std::vector<ShapeSpec> shapes;
};

struct JointSpec {
  bool prismatic = false;  // else a hinge
  int parent = -1;         // body index; -1: the static environment
  int child = 0;           // body index
  bool has_limits = false;
  double lower = 0, upper = 0;  // rad or m, from the zero configuration
  double friction = 0;          // Coulomb friction, N m or N
};

struct ModelSpec {
  std::vector<BodySpec> bodies;
  std::vector<ShapeSpec> anchored_shapes;  // on the static environment, placed by the world
  std::vector<JointSpec> joints;
};

// A joint's line in world coordinates.
struct JointFrame {
  Vec3 anchor;
  Vec3 axis;  // unit; positive motion moves the child along / about it
};

// One model inside an engine; destroying it removes it from the engine. Any call but the readers
// may throw EngineFault.
class EngineModel {
 public:
  virtual ~EngineModel() = default;

  // Puts every body at zero_poses (the zero configuration) and attaches each joint along its
  // frame, so that the joint reads 0 there. World then moves the bodies with setBodyState.
  virtual void attachJoints(const std::vector<Pose>& zero_poses,
                            const std::vector<JointFrame>& frames) = 0;

  virtual Pose bodyPose(int body) const = 0;    // the COM frame in the world
  virtual Twist bodyTwist(int body) const = 0;  // linear velocity of the COM, angular, world axes
  virtual void setBodyState(int body, const Pose& pose, const Twist& twist) = 0;
  virtual void setAnchoredShapePose(int shape, const Pose& world_pose) = 0;
  // A body's new mass, inertia and gravity mode, and its shapes' poses in the new body frame
  // (the same shapes in the same order: a moved centre of mass moves the frame under them).
  // Joints keep their anchors in body coordinates, so World calls attachJoints and setBodyState
  // for the model afterwards.
  virtual void setBodyMass(int body, const BodySpec& spec) = 0;

  // Hinges: the child's angle about the axis relative to the parent, wrapped to (-pi, pi];
  // sliders: the child's displacement along the axis. World unwraps hinges.
  virtual double jointPosition(int joint) const = 0;
  virtual double jointRate(int joint) const = 0;
  // What the joint's constraint (its rows, stops and motor included) put on the child body in
  // the last step, world axes, the torque about the child body's centre of mass; zero before the
  // first step. Efforts added with addJointEffort are not in it.
  virtual Wrench jointConstraintWrench(int joint) const = 0;

  // Forces for the coming step only: the engine clears them when it has stepped.
  virtual void addJointEffort(int joint, double effort) = 0;  // + on the child, - on the parent
  // A velocity motor in the joint's constraint, until set again: the solver drives the joint's
  // rate (as jointRate reads it) to `velocity` pushing with at most `max_effort` (> 0), within
  // the step, as ODE's dParamVel and dParamFMax do. max_effort 0 turns it off and gives the
  // joint back its JointSpec friction.
  virtual void setJointMotor(int joint, double velocity, double max_effort) = 0;
  virtual void addBodyWrench(int body, const Vec3& force, const Vec3& world_point,
                             const Vec3& torque) = 0;
};

// One body of one model inside an engine.
struct BodyRef {
  const EngineModel* model = nullptr;
  int body = 0;
  bool operator==(const BodyRef& other) const { return model == other.model && body == other.body; }
};

// One collision shape inside an engine: shape `shape` of a model's body `body` (in its BodySpec's
// shapes), or the model's anchored shape `shape` (body -1: in its ModelSpec's anchored_shapes).
struct ShapeRef {
  const EngineModel* model = nullptr;
  int body = -1;
  int shape = 0;
  bool operator==(const ShapeRef& other) const {
    return model == other.model && body == other.body && shape == other.shape;
  }
};

// A point where two shapes touched in the last step, and what the step's contact constraint
// there put through it.
struct EngineContact {
  ShapeRef a, b;
  Vec3 position;      // world
  Vec3 normal;        // unit, world: the direction that moves a out of b
  double depth = 0;   // how far the shapes overlap along the normal, m
  Vec3 force;         // on a, at `position`, world axes, N (normal and friction); b takes -force
};

class Engine {
 public:
  virtual ~Engine() = default;

  // Only valid parameters arrive here (World validates). Parameters an engine has no counterpart
  // for are kept by World for get_physics_properties and ignored here.
  // Any call may throw EngineFault.
  virtual void setParams(const PhysicsParams& params) = 0;
  // Bodies of one model never collide with each other.
  virtual std::unique_ptr<EngineModel> addModel(const ModelSpec& spec) = 0;
  // Whether the solver under these parameters is exact, its step cost growing faster than
  // linearly in a model's joints (ODE's dWorldStep), so that World holds a model to
  // kMaxExactSolverJoints; an iterative solver's cost grows linearly.
  virtual bool exactSolver(const PhysicsParams& params) const = 0;
  // One step of dt seconds with the forces added since the last one. Solver trouble the engine
  // reports during the step and could not work around (ODE retakes a step whose exact LCP fails
  // with its iterative solver) goes to *solver_message, first one only. retake: the step is
  // taken again, from where the one that threw EngineFault started, on a new engine: the engine
  // takes it the way it takes a step its solver failed (ODE: dWorldQuickStep).
  virtual void step(double dt, std::string* solver_message, bool retake = false) = 0;
  // Whether step(..., retake = true) takes a step another way than a plain step under these
  // parameters does, so that retaking one that threw EngineFault is worth a new engine.
  virtual bool retakesFailedSteps(const PhysicsParams& params) const = 0;
  // The bodies in touch in the last step (the contacts it resolved, anchored shapes' included),
  // each once: the bodies an EngineFault inside that step can involve. Readable after a fault.
  // Empty when the engine cannot tell.
  virtual std::vector<BodyRef> contactBodies() const = 0;
  // The contact points the last step resolved (those it met in its collision pass and took
  // into its solve), with the force each carried over the step; empty before the first step.
  // Valid until the engine's models change: a ShapeRef names a model only while it lives.
  virtual void contacts(std::vector<EngineContact>* out) const = 0;
  // For each ray (a unit direction, a length >= 0), the distance along it to the first
  // collision shape it meets, a model's plane included, through the engine's own collision
  // detection, as the bodies stand now; +infinity where it meets none. Every shape counts: a
  // model's own bodies are not left out.
  virtual void castRays(const std::vector<Ray>& rays, std::vector<double>* distances) = 0;
  // Puts the random numbers the engine's solver draws (ODE's quickstep orders its constraints
  // with ODE's one generator per process) back where a new world starts them, so that a world
  // run again from its start, in this process or another, takes the same steps bit for bit.
  virtual void reseed() {}
  // Whether bodies put back where they started (reset) take the same steps again, bit for bit,
  // as they did from there. ODE's do not: its collision spaces keep geoms in the order they last
  // moved, which orders the contacts; reset_simulation builds such an engine anew.
  virtual bool repeatsWhenPutBack() const { return true; }
};

struct EngineEntry {
  std::string name;  // as ~physics and physics:= take it
  std::function<std::unique_ptr<Engine>()> make;
};

// The one list of engines (engines/registry.cpp).
const std::vector<EngineEntry>& engineRegistry();

}  // namespace core
}  // namespace onedof_sim
