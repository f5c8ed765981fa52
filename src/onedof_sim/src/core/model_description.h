// A parsed model, independent of its file format: what the world needs to build ODE objects.
// Every pose is in the model frame with all joints at zero, so that URDF (poses chained through
// joints) and SDF (poses relative to arbitrary frames) reduce to the same thing. Private to the core.
#pragma once

#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "mesh_loader.h"
#include "onedof_sim/world.h"

namespace onedof_sim {
namespace core {

// The parent name of a joint attached to the static environment (URDF's `world` link, SDF's
// reserved frame name).
constexpr const char* kWorldLink = "world";

// Limits: what the world accepts, from the physics of robots; the rest is refused up front (a
// model with ModelRejected, a call with OutOfRange and the range). Every engine computes in
// doubles, so a finite but absurd number (1e308) overflows inside the step, where ODE aborts the
// process on the non-finite quaternion it makes.
//
// Positions, lengths and joint positions: 1000 km (or rad) from the origin. A double still
// resolves 1e-10 there, far below the 1 mm contact layer, and the products an engine forms
// (lever arm times force) stay far from overflow; no robot needs more room.
constexpr double kMaxPosition = 1e6;
// A collision shape's size, per dimension: a building or a field. A 1e6 m box on a 1 kg body
// makes ODE's contact solver abort the process (dxLDLTRemove).
constexpr double kMaxShapeSize = 1e3;  // m
// A link's mass: 0 (a massless link, carried by the link it is welded to) or 1 mg to 1000 t, a
// small sensor part to a heavy machine; outside, the mass ratios at a joint leave the solver
// without precision.
constexpr double kMinMass = 1e-6, kMaxMass = 1e6;  // kg
// Principal moments of inertia of a moving body: those of the masses above at 1 mm to 30 m
// (m r^2). A vanishing moment gives an infinite angular acceleration.
constexpr double kMinMoment = 1e-12, kMaxMoment = 1e9;  // kg m^2
// A moving body's inertia against its collision shapes: a force at a corner of a shape's bounding
// box, across the line from the centre of mass, may move that corner by turning the body at most
// this many times as fast as by moving the body (uniform solids: 2 to 8; a heavy core in a light
// shell: tens). Far beyond it the contact solver's matrix loses its precision: ODE aborts the
// process in dxLDLTRemove or dxNormalize4 from about 5e5, and Bullet lets the body fall through
// the ground from about 5e4 (a 0.1 m box of 1e-4 of its solid moments). Gazebo's advice is the
// same: give links realistic inertia.
constexpr double kMaxLeverRatio = 1e3;
// Viscous damping and Coulomb friction of a joint (N m s/rad or N s/m; N m or N). The world
// applies damping implicitly, stable at any value; a stiffer damper than 1e6 holds a joint still
// for longer than any simulation runs.
constexpr double kMaxJointDamping = 1e6, kMaxJointFriction = 1e6;
// Links per model. A humanoid has about 50, a long snake robot a few hundred; the world's
// per-model bookkeeping grows with links times joints, and walking a 20000-link URDF takes 20000
// nested calls, past what the stack holds.
constexpr size_t kMaxModelLinks = 1000;
// Checked on the XML before it is parsed, so that a model past a limit is refused in
// milliseconds: libsdformat takes seconds for a thousand links. The XML's size: a 1000-link URDF
// with visuals and collisions is about 1 MB. <include>s of an SDF (each one a model file read from
// the model path): a robot is built from a handful.
constexpr size_t kMaxModelXmlBytes = 10000000;
constexpr size_t kMaxModelIncludes = 100;
// Models a document's <include>s place in all, an include nested in an included file counted
// each time that file is placed: a world's worth.
constexpr size_t kMaxIncludedModels = 1000;
// Models a world file places (its <model>s and <include>s; a world file has at most
// kMaxModelXmlBytes too): each is a spawn at start-up, and a large scene has hundreds.
constexpr size_t kMaxWorldModels = 1000;
// Moving joints (the 1-DOF joints the engine steps) per model with an exact solver, whose step
// cost grows as joints^2.8 (ODE's dWorldStep: 50 joints about 1 ms a step on 2 cores, 100 about
// 8 ms, 200 about 70 ms, 1000 seconds). The iterative solvers (ODE's quick_step, Bullet) grow
// linearly, about 10 us a joint, so the link limit bounds them at about 10 ms a step.
constexpr size_t kMaxExactSolverJoints = 50;
// Triangles of one collision mesh and of all the collision meshes of a model. A robot's
// collision meshes have hundreds to a few thousand triangles each (the book's irb120: 270 to 2,150
// a link, 8,700 in all; its building floor 2,700). Dense meshes cost steps and contact quality:
// 0.2 m blocks of about 19,000 triangles rest where they should on both engines (a box on a
// 2 m floor of 20,000 triangles steps in about 0.2 ms on ODE and 1 to 2 ms on Bullet, the block
// on that floor, mesh on coplanar mesh, in 0.4 ms on ODE and 15 to 30 ms on Bullet's GImpact, on
// 2 busy cores), while at 50,000 Bullet's GImpact throws the block off the ground and at 100,000
// ODE throws it off the floor.
constexpr size_t kMaxMeshTriangles = 20000;
constexpr size_t kMaxModelMeshTriangles = 50000;
// A mesh file's size, checked before it is read, so that the read itself is bounded: an ASCII
// STL of kMaxMeshTriangles is about 5 MB, a COLLADA file with normals and texture coordinates
// somewhat less.
constexpr size_t kMaxMeshFileBytes = 20000000;
// A mesh file's node hierarchy, measured before assimp reads it (mesh_precheck.h): the nodes
// and geometry instances it places, each placement of an instanced node counted (a robot's CAD
// export places hundreds; assimp spends about 1 kB on each), and how deep its nodes nest,
// instances followed (a robot's: tens; assimp builds it by recursion, and the XML reader
// refuses elements nested deeper than 100 anyway).
constexpr size_t kMaxMeshPlacements = 20000;
constexpr size_t kMaxMeshDepth = 100;

// Sim time ends where ROS time does (32-bit seconds): /clock and every stamp would overflow.
constexpr int64_t kEndOfTimeNs = int64_t(0xffffffff) * 1000000000;

struct CollisionDescription {
  std::string name;
  GeometryShape shape = GeometryShape::Box;
  Vec3 size;  // as CollisionShape::size
  std::shared_ptr<const TriangleMesh> mesh;  // Mesh: scaled by size
  Pose pose;  // in the link frame
  // Gazebo's defaults for a model surface; a contact uses the smaller value of the two geoms.
  double mu = 1, mu2 = 1;
};

// A link's <visual>, as World::visualShapes gives it, its pose in the link frame. Never a reason
// to refuse a model: a visual only shows it.
struct VisualDescription {
  std::string name;
  GeometryShape shape = GeometryShape::Box;
  Vec3 size;  // as VisualShape::size
  Pose pose;  // in the link frame
  std::string mesh_uri, mesh_file;
  VisualMaterial material;
};

struct LinkDescription {
  std::string name;
  Pose pose;  // link frame in the model frame, all joints at zero
  // URDF links may have no <inertial>; they can only ride on a moving link through a fixed joint.
  bool has_inertial = false;
  double mass = 0;
  Pose com;  // inertial frame in the link frame
  double ixx = 0, ixy = 0, ixz = 0, iyy = 0, iyz = 0, izz = 0;  // in the inertial frame
  bool gravity = true;
  std::vector<CollisionDescription> collisions;
  std::vector<VisualDescription> visuals;
};

struct JointDescription {
  std::string name;
  JointType type = JointType::Fixed;
  std::string parent;  // a link name, or kWorldLink
  std::string child;
  Vec3 anchor;       // in the model frame, all joints at zero
  Vec3 axis{1, 0, 0};  // unit, in the model frame
  bool has_limits = false;
  double lower = 0, upper = 0;
  double effort_limit = std::numeric_limits<double>::infinity();
  bool has_damping = false;
  double damping = 0;
  double friction = 0;
};

struct ModelDescription {
  bool is_static = false;
  // The model frame in the frame the model is placed in (World::spawn's pose composed with it):
  // an SDF model's own <pose>, or a -database request's <include> <pose>; the identity for URDF,
  // whose model frame is its root link's frame (Gazebo's URDF conversion puts it there).
  Pose pose;
  std::vector<LinkDescription> links;  // parents before children
  std::vector<JointDescription> joints;
  std::string canonical_link;
  // The collisions left out, as Gazebo leaves out a mesh it cannot find: why, for each.
  std::vector<std::string> left_out;
};

// A model the world cannot build, and why (the reason names the link, joint or parser error).
inline Status rejected(std::string reason) {
  return {StatusCode::ModelRejected, std::move(reason)};
}

// The limits that can be checked on the XML itself before a parser reads it: its size, and its
// counts of links, joints and <include>s (those an SDF's includes bring are counted after the
// parse). Ok for XML that is not well-formed: the parser then says why.
Status precheckModelXml(const std::string& xml, ModelFormat format);

// Both fill `out` only on success; else ModelRejected with the reason. model_path: absolute
// folders where model://NAME URIs are looked up, in order (an <include>'s model, a mesh file:
// resolveMeshUri). An SDF may also be gazebo_ros' -database request, a <world> whose one
// <include> names the model; the include's <pose> is then the model's own (ModelDescription::pose).
Status parseUrdf(const std::string& xml, const std::vector<std::string>& model_path,
                 ModelDescription* out);
Status parseSdf(const std::string& xml, const std::vector<std::string>& model_path,
                ModelDescription* out);

}  // namespace core
}  // namespace onedof_sim
