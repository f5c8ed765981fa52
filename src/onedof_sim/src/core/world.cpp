// World: everything about a simulated world that does not depend on the physics engine.
//
// Frames. Every link has a link frame (URDF/SDF) and, if it moves, an engine body. Bodies sit at
// the centre of mass of their links with the axes of their reference link, and each link keeps
// the exact link-frame pose in its body frame. Links joined by fixed joints share one body (their
// masses lumped here): a rigid weld is exact that way, where an engine's fixed joint would only
// be held by error correction and drift. Links fixed to `world` (and all links of a static model)
// have no body: their collision shapes are anchored to the environment, and joints to them attach
// to it.
//
// Placing a model always goes through the zero configuration first (the engine attaches the
// joints there, so that they read zero there), then to the wanted joint positions by forward
// kinematics; see placeModel().
#include "onedof_sim/world.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <ostream>
#include <sstream>
#include <stdexcept>

#include "engine.h"
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
// At most this many step warnings are kept between two takeWarnings() calls; a stuck model would
// otherwise fill memory at the step rate.
constexpr size_t kMaxWarnings = 100;
// The step: below 1 us a second of sim time takes a million steps, hours of wall time for motion
// no robot has; above 0.1 s the angular speed cap (0.1 rad per step) falls to 1 rad/s and the
// tutorial's pendulum could no longer swing.
constexpr double kMinStep = 1e-6, kMaxStep = 0.1;  // s
// Sim time ends where ROS time does (32-bit seconds): /clock and every stamp would overflow.
constexpr int64_t kEndOfTimeNs = int64_t(0xffffffff) * 1000000000;
// Pending effort jobs per joint and wrench jobs per link. A controller keeps one or two pending
// (the book's: 10 ms jobs at 100 Hz); 1000 leave room for a queued sequence, while each step
// looks at every job, so an endless queue (50000 jobs: real-time factor 0.59) slows the world.
constexpr size_t kMaxPendingJobs = 1000;

// Engines integrate rotation linearly, so a link turning by more than about 0.1 rad per step
// leaves its joints visibly apart (the chord error is r * angle^2 / 2 per step, and error
// correction only removes a fifth of it per step). 0.1 rad per step is 100 rad/s at 1 kHz, well
// above any robot joint. It also keeps the joint unwrapping (which adds wrap(raw - last_raw) each
// step) far from its limit of pi per step.
double maxAngularSpeed(double step) { return 0.1 / step; }
// A joint effort or body wrench may take its bodies from rest to the speed caps in no fewer steps
// than this: past that the caps would clip every step and the joints come apart. A real actuator
// is orders of magnitude weaker.
constexpr double kStepsToSpeedCap = 10;

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

// A symmetric 3x3 inertia tensor, for lumping welded links into one body.
using Matrix3 = std::array<std::array<double, 3>, 3>;

Matrix3 rotationMatrix(const Quat& q) {
  Matrix3 r;
  const Vec3 columns[3] = {rotate(q, {1, 0, 0}), rotate(q, {0, 1, 0}), rotate(q, {0, 0, 1})};
  for (int c = 0; c < 3; ++c) {
    r[0][c] = columns[c].x;
    r[1][c] = columns[c].y;
    r[2][c] = columns[c].z;
  }
  return r;
}

// R I R^T: a tensor given in a frame rotated by q, expressed in the outer frame.
Matrix3 rotateTensor(const Quat& q, const Matrix3& inertia) {
  const Matrix3 r = rotationMatrix(q);
  Matrix3 out{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k)
        for (int l = 0; l < 3; ++l) out[i][j] += r[i][k] * inertia[k][l] * r[j][l];
  return out;
}

// Parallel axes: the tensor of a point mass m at offset d, about the origin.
Matrix3 pointMassTensor(double m, const Vec3& d) {
  const double v[3] = {d.x, d.y, d.z};
  Matrix3 out{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) out[i][j] = m * ((i == j ? dot(d, d) : 0) - v[i] * v[j]);
  return out;
}

// The smallest eigenvalue of a symmetric matrix (the trigonometric closed form).
double smallestEigenvalue(const Matrix3& m) {
  const double off = m[0][1] * m[0][1] + m[0][2] * m[0][2] + m[1][2] * m[1][2];
  if (off == 0) return std::min({m[0][0], m[1][1], m[2][2]});
  const double mean = (m[0][0] + m[1][1] + m[2][2]) / 3;
  const double a = m[0][0] - mean, b = m[1][1] - mean, c = m[2][2] - mean;
  const double p = std::sqrt((a * a + b * b + c * c + 2 * off) / 6);
  const double det = a * (b * c - m[1][2] * m[1][2]) - m[0][1] * (m[0][1] * c - m[1][2] * m[0][2]) +
                     m[0][2] * (m[0][1] * m[1][2] - b * m[0][2]);
  const double r = std::clamp(det / (2 * p * p * p), -1.0, 1.0);
  return mean + 2 * p * std::cos(std::acos(r) / 3 + 2 * M_PI / 3);
}

// Sylvester's criterion: what no rigid body violates.
bool isPositiveDefinite(const Matrix3& m) {
  const double minor2 = m[0][0] * m[1][1] - m[0][1] * m[1][0];
  const double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
                     m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                     m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
  return m[0][0] > 0 && minor2 > 0 && det > 0;
}

// u^T I u for a unit axis u given in the tensor's frame.
double momentAbout(const BodySpec& body, const Vec3& u) {
  return body.ixx * u.x * u.x + body.iyy * u.y * u.y + body.izz * u.z * u.z +
         2 * (body.ixy * u.x * u.y + body.ixz * u.x * u.z + body.iyz * u.y * u.z);
}

struct LinkRecord {
  LinkDescription desc;
  int parent_joint = -1;
  int body = -1;                  // -1: anchored to the static environment
  bool sets_body_pose = false;    // the reference link of its body: the one that places it
  Pose link_in_body;              // exact link frame in the body (COM) frame
  Pose anchored_pose;             // world pose, when anchored
  int first_anchored_shape = -1;  // its collisions' index in ModelSpec::anchored_shapes
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
  std::unique_ptr<EngineModel> engine_model;
  size_t canonical = 0;
  Pose frame_pose;  // world pose of the model frame, where joints to `world` are anchored
  Pose spawn_pose;
  bool velocity_capped = false;  // warned already, until a step passes without capping
  bool blown_up = false;  // the last step left it non-finite: held, its jobs not applied
  int64_t last_blow_up_warning_ns = -1;
};

ShapeSpec shapeSpec(const CollisionDescription& collision) {
  return {collision.shape, collision.size, collision.pose, collision.mu, collision.mu2};
}

// The link that places a moving body: the first of the links welded into it.
const LinkRecord& referenceLink(const ModelRecord& model, int body) {
  for (const LinkRecord& link : model.links)
    if (link.body == body && link.sets_body_pose) return link;
  throw std::logic_error("body without a reference link");
}

// Why the links welded into a body make no rigid body, or none the engines can step (Limits).
enum class LumpFault { None, NoMass, NotPositiveDefinite, MomentOutOfRange };

// One body from the inertials of the links welded into it: the lumped mass, the inertia about the
// lumped centre of mass in the reference link's axes, the reference link's gravity mode and every
// link's collisions. On success, also places each of its links in the new body frame
// (link_in_body); on a fault, changes nothing.
LumpFault lumpBody(ModelRecord* model, int body, BodySpec* out) {
  const LinkRecord& reference = referenceLink(*model, body);
  double mass = 0;
  Vec3 moment;
  Matrix3 tensor{};  // about the reference link's origin
  for (const LinkRecord& link : model->links) {
    const LinkDescription& d = link.desc;
    if (link.body != body || !d.has_inertial || d.mass == 0) continue;
    const Pose inertial = compose(compose(inverse(reference.desc.pose), d.pose), d.com);
    const Matrix3 own{{{d.ixx, d.ixy, d.ixz}, {d.ixy, d.iyy, d.iyz}, {d.ixz, d.iyz, d.izz}}};
    const Matrix3 rotated = rotateTensor(inertial.orientation, own);
    const Matrix3 offset = pointMassTensor(d.mass, inertial.position);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) tensor[i][j] += rotated[i][j] + offset[i][j];
    mass += d.mass;
    moment = moment + d.mass * inertial.position;
  }
  if (!(mass > 0)) return LumpFault::NoMass;
  const Vec3 com = (1 / mass) * moment;
  const Matrix3 to_com = pointMassTensor(mass, com);
  Matrix3 inertia;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) inertia[i][j] = tensor[i][j] - to_com[i][j];
  if (!isPositiveDefinite(inertia)) return LumpFault::NotPositiveDefinite;
  const double largest = std::max({inertia[0][0], inertia[1][1], inertia[2][2]});
  if (smallestEigenvalue(inertia) < kMinMoment || largest > kMaxMoment)
    return LumpFault::MomentOutOfRange;
  BodySpec spec;
  spec.mass = mass;
  spec.ixx = inertia[0][0], spec.iyy = inertia[1][1], spec.izz = inertia[2][2];
  spec.ixy = inertia[0][1], spec.ixz = inertia[0][2], spec.iyz = inertia[1][2];
  spec.gravity = reference.desc.gravity;
  // Body frame: at the COM, axes of the reference link.
  const Pose reference_inverse = inverse(reference.desc.pose);
  for (LinkRecord& link : model->links) {
    if (link.body != body) continue;
    const Pose link_in_reference = compose(reference_inverse, link.desc.pose);
    link.link_in_body = {link_in_reference.position - com, link_in_reference.orientation};
    for (const CollisionDescription& collision : link.desc.collisions) {
      ShapeSpec shape = shapeSpec(collision);
      shape.pose = compose(link.link_in_body, collision.pose);
      spec.shapes.push_back(shape);
    }
  }
  *out = spec;
  return LumpFault::None;
}

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

bool isFinite(const Twist& t) { return core::isFinite(t.linear) && core::isFinite(t.angular); }

Status outOfRange(std::string field, double min, double max) {
  Status status{StatusCode::OutOfRange, std::move(field)};
  status.min = min;
  status.max = max;
  return status;
}

Status validateParams(const PhysicsParams& p) {
  using Field = std::pair<const char*, double>;
  const Field numbers[] = {{"step", p.step},
                           {"gravity", p.gravity.x},
                           {"gravity", p.gravity.y},
                           {"gravity", p.gravity.z},
                           {"sor_pgs_w", p.sor_pgs_w},
                           {"sor_pgs_rms_error_tol", p.sor_pgs_rms_error_tol},
                           {"contact_surface_layer", p.contact_surface_layer},
                           {"contact_max_correcting_vel", p.contact_max_correcting_vel},
                           {"cfm", p.cfm},
                           {"erp", p.erp}};
  for (const auto& [field, value] : numbers)
    if (!std::isfinite(value)) return {StatusCode::NotFinite, field};
  struct Range {
    const char* field;
    double value, min, max;
  };
  // Besides the step (kMinStep), gazebo_ros' own ranges (its dynamic_reconfigure Physics.cfg),
  // narrowed where a value means nothing: erp is a fraction of the error corrected per step; SOR
  // converges only for a relaxation in (0, 2) and barely moves below 0.01; a step runs every
  // solver iteration, so a billion of them would freeze the world; ODE's dCollide takes the
  // contact count in 16 bits. Gravity: 10 g, beyond any planet a robot works on. cfm 10 already
  // makes every constraint a soft spring; 1e308 makes the solver's matrix infinite.
  const Range ranges[] = {
      {"step", p.step, kMinStep, kMaxStep},
      {"gravity", p.gravity.x, -100, 100},
      {"gravity", p.gravity.y, -100, 100},
      {"gravity", p.gravity.z, -100, 100},
      {"erp", p.erp, 0, 1},
      {"cfm", p.cfm, 0, 10},
      {"contact_surface_layer", p.contact_surface_layer, 0, 10},
      {"contact_max_correcting_vel", p.contact_max_correcting_vel, 0, 1e7},
      {"sor_pgs_w", p.sor_pgs_w, 0.01, 5},
      {"sor_pgs_rms_error_tol", p.sor_pgs_rms_error_tol, 0, 1e4},
      {"sor_pgs_iters", double(p.sor_pgs_iters), 1, 1e4},
      {"sor_pgs_precon_iters", double(p.sor_pgs_precon_iters), 0, 1e4},
      {"max_contacts", double(p.max_contacts), 0, 0xffff}};
  for (const Range& range : ranges)
    if (!(range.value >= range.min && range.value <= range.max))
      return outOfRange(range.field, range.min, range.max);
  return {};
}

bool withinPosition(const Vec3& v) {
  return std::abs(v.x) <= kMaxPosition && std::abs(v.y) <= kMaxPosition &&
         std::abs(v.z) <= kMaxPosition;
}

// A pose the world can place something at.
Status checkPose(const Pose& pose) {
  if (!core::isFinite(pose)) return {StatusCode::NotFinite, "pose"};
  if (quatNorm(pose.orientation) < 1e-9) return {StatusCode::ZeroQuaternion, "pose"};
  if (!withinPosition(pose.position))
    return outOfRange("pose.position", -kMaxPosition, kMaxPosition);
  return {};
}

// A pose and twist to set a model or link to: speeds up to the caps the step holds every model
// to (guardStates), which a larger one would only meet clipped.
Status checkState(const Pose& pose, const Twist& twist, double step) {
  const Status status = checkPose(pose);
  if (!status.ok()) return status;
  if (!isFinite(twist)) return {StatusCode::NotFinite, "twist"};
  if (norm(twist.linear) > kMaxLinearSpeed) return outOfRange("twist.linear", 0, kMaxLinearSpeed);
  if (norm(twist.angular) > maxAngularSpeed(step))
    return outOfRange("twist.angular", 0, maxAngularSpeed(step));
  return {};
}

const EngineEntry& findEngine(const std::string& name) {
  for (const EngineEntry& entry : engineRegistry())
    if (entry.name == name) return entry;
  std::string known;
  for (const EngineEntry& entry : engineRegistry()) known += (known.empty() ? "" : ", ") + entry.name;
  throw std::invalid_argument("unknown physics engine '" + name + "' (known: " + known + ")");
}

}  // namespace

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
  std::vector<BodyWrenchJob> wrench_jobs;
  std::vector<std::string> warnings;
  std::vector<BodyState> saved_states;
  bool engine_struggled = false;  // warned already, until a step passes without a solver message
  bool time_ended = false;        // warned already that sim time reached kEndOfTimeNs
  std::vector<std::string> model_path;  // absolute

  Impl(const std::string& name, const PhysicsParams& p)
      : engine_name(name), engine(findEngine(name).make()) {
    engine->addGroundPlane(kGroundMu, kGroundMu2);
    // A constructor cannot report: invalid parameters fall back to the defaults.
    applyParams(validateParams(p).ok() ? p : PhysicsParams());
  }

  ~Impl() {
    models.clear();  // before the engine they live in
  }

  void applyParams(const PhysicsParams& p) {
    params = p;
    step_ns = std::llround(p.step * 1e9);
    engine->setParams(p);
  }

  void warn(const std::string& text) {
    if (warnings.size() < kMaxWarnings) warnings.push_back(text);
  }

  // --- state of links and joints -----------------------------------------------------------

  Pose linkWorldPose(const ModelRecord& model, const LinkRecord& link) const {
    return link.body >= 0 ? compose(model.engine_model->bodyPose(link.body), link.link_in_body)
                          : link.anchored_pose;
  }

  Twist linkWorldTwist(const ModelRecord& model, const LinkRecord& link) const {
    if (link.body < 0) return Twist();
    const Pose body_pose = model.engine_model->bodyPose(link.body);
    const Twist body = model.engine_model->bodyTwist(link.body);
    const Vec3 origin = transformPoint(body_pose, link.link_in_body.position);
    return {body.linear + cross(body.angular, origin - body_pose.position), body.angular};
  }

  double jointRate(const ModelRecord& model, const JointRecord& joint) const {
    return joint.engine_joint < 0 ? 0 : model.engine_model->jointRate(joint.engine_joint);
  }

  // The joint's anchor and axis in the world as the child sits now.
  JointFrame jointFrame(const ModelRecord& model, const JointRecord& joint) const {
    const LinkRecord& child = model.links[joint.child];
    const Pose mapping = compose(linkWorldPose(model, child), inverse(child.desc.pose));
    return {transformPoint(mapping, joint.desc.anchor), rotate(mapping.orientation, joint.desc.axis)};
  }

  void updateJointPositions(ModelRecord* model) {
    for (JointRecord& joint : model->joints) {
      if (joint.engine_joint < 0) continue;
      const double raw = model->engine_model->jointPosition(joint.engine_joint);
      joint.position = joint.desc.type == JointType::Prismatic
                           ? raw
                           : joint.position + std::remainder(raw - joint.last_raw, 2 * M_PI);
      joint.last_raw = raw;
    }
  }

  // The largest effort that, on the bodies below the joint taken as one rigid body, reaches the
  // speed cap from rest in kStepsToSpeedCap steps. The real (articulated) inertia can only be
  // smaller, so this is not a guarantee; the per-step speed cap and the non-finite rollback catch
  // the rest.
  double safeEffortBound(const ModelRecord& model, const JointRecord& joint) const {
    const bool prismatic = joint.desc.type == JointType::Prismatic;
    const JointFrame frame = jointFrame(model, joint);
    double inertia = 0;
    for (int body : joint.moved_bodies) {
      const BodySpec& mass = model.bodies[body];
      if (prismatic) {
        inertia += mass.mass;
        continue;
      }
      const Pose pose = model.engine_model->bodyPose(body);
      inertia += momentAbout(mass, rotate(conjugate(pose.orientation), frame.axis));
      const Vec3 arm = pose.position - frame.anchor;
      inertia += mass.mass * (dot(arm, arm) - dot(arm, frame.axis) * dot(arm, frame.axis));
    }
    const double speed = prismatic ? kMaxLinearSpeed : maxAngularSpeed(params.step);
    return inertia * speed / (kStepsToSpeedCap * params.step);
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
    *pose = linkWorldPose(*model, model->links[link]);
    *twist = linkWorldTwist(*model, model->links[link]);
    return true;
  }

  // --- building ------------------------------------------------------------------------------

  // Everything that can fail is checked here, before the engine sees the model, so that a
  // refused spawn leaves the world as it was. Fills the link/joint records and the engine's spec.
  Status planModel(const ModelDescription& desc, ModelRecord* model, ModelSpec* spec) const {
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
    // `world` (or in a static model) is anchored. The first link of a body is its reference.
    int body_count = 0;
    for (LinkRecord& link : model->links) {
      if (model->is_static) continue;
      if (link.parent_joint >= 0 && model->joints[link.parent_joint].desc.type == JointType::Fixed) {
        const int parent = model->joints[link.parent_joint].parent;
        link.body = parent < 0 ? -1 : model->links[parent].body;
        continue;
      }
      link.body = body_count++;
      link.sets_body_pose = true;
    }
    for (const LinkRecord& link : model->links) {
      const LinkDescription& d = link.desc;
      const double values[] = {d.mass, d.ixx, d.ixy, d.ixz, d.iyy, d.iyz, d.izz};
      for (double v : values)
        if (!std::isfinite(v)) return rejected("link '" + d.name + "' has a non-finite inertial");
      if (link.body >= 0 && d.has_inertial && d.mass < 0)
        return rejected("link '" + d.name + "' has a negative mass");
    }
    for (int body = 0; body < body_count; ++body) {
      BodySpec spec_body;
      const LumpFault fault = lumpBody(model, body, &spec_body);
      const std::string& name = referenceLink(*model, body).desc.name;
      if (fault == LumpFault::NoMass)
        return rejected("link '" + name + "' moves but has no mass (give it an <inertial>)");
      if (fault == LumpFault::NotPositiveDefinite)
        return rejected("link '" + name + "' has an inertia that no rigid body can have");
      if (fault == LumpFault::MomentOutOfRange) {
        std::ostringstream why;
        why << "link '" << name << "' (with the links welded to it) has a principal moment of "
            << "inertia outside [" << kMinMoment << ", " << kMaxMoment << "] kg m^2";
        return rejected(why.str());
      }
      spec->bodies.push_back(spec_body);
    }
    for (LinkRecord& link : model->links) {
      if (link.body >= 0) continue;
      link.first_anchored_shape = static_cast<int>(spec->anchored_shapes.size());
      for (const CollisionDescription& collision : link.desc.collisions)
        spec->anchored_shapes.push_back(shapeSpec(collision));
    }
    for (JointRecord& joint : model->joints) {
      const int child_body = model->links[joint.child].body;
      if (joint.desc.type == JointType::Fixed || child_body < 0) continue;
      joint.engine_joint = static_cast<int>(spec->joints.size());
      JointSpec spec_joint;
      spec_joint.prismatic = joint.desc.type == JointType::Prismatic;
      spec_joint.parent = joint.parent < 0 ? -1 : model->links[joint.parent].body;
      spec_joint.child = child_body;
      spec_joint.has_limits = joint.desc.has_limits;
      spec_joint.lower = joint.desc.lower;
      spec_joint.upper = joint.desc.upper;
      spec_joint.friction = joint.desc.friction;
      spec->joints.push_back(spec_joint);
    }
    // The bodies each joint moves: every body below it in the tree.
    for (const LinkRecord& link : model->links) {
      if (link.body < 0 || !link.sets_body_pose) continue;
      for (int j = link.parent_joint; j >= 0;
           j = model->joints[j].parent < 0 ? -1 : model->links[model->joints[j].parent].parent_joint)
        if (model->joints[j].engine_joint >= 0) model->joints[j].moved_bodies.push_back(link.body);
    }
    model->bodies = spec->bodies;
    return {};
  }

  void destroyModel(size_t index) {
    ModelRecord* model = models[index].get();
    dropJobs([model](const ModelRecord* m) { return m == model; });
    models.erase(models.begin() + index);
  }

  template <typename Predicate>
  void dropJobs(Predicate on_model) {
    joint_jobs.erase(std::remove_if(joint_jobs.begin(), joint_jobs.end(),
                                    [&](const JointEffortJob& j) { return on_model(j.model); }),
                     joint_jobs.end());
    joint_commands.erase(
        std::remove_if(joint_commands.begin(), joint_commands.end(),
                       [&](const JointEffortCommand& c) { return on_model(c.model); }),
        joint_commands.end());
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

  // The bodies' poses for the links' poses; anchored links take theirs (and their shapes) now.
  std::vector<Pose> placeLinks(ModelRecord* model, const std::vector<Pose>& poses) {
    std::vector<Pose> body_poses(model->bodies.size());
    for (size_t i = 0; i < model->links.size(); ++i) {
      LinkRecord& link = model->links[i];
      if (link.body >= 0) {
        if (link.sets_body_pose) body_poses[link.body] = compose(poses[i], inverse(link.link_in_body));
        continue;
      }
      link.anchored_pose = poses[i];
      for (size_t c = 0; c < link.desc.collisions.size(); ++c)
        model->engine_model->setAnchoredShapePose(link.first_anchored_shape + static_cast<int>(c),
                                                  compose(poses[i], link.desc.collisions[c].pose));
    }
    return body_poses;
  }

  // Puts the model at joint positions q (fixed joints ignored) with zero velocity.
  void placeModel(ModelRecord* model, const Pose& frame_pose, const std::vector<Pose>& root_poses,
                  const std::vector<double>& q) {
    model->frame_pose = frame_pose;
    const std::vector<Pose> zero_poses =
        forwardKinematics(*model, frame_pose, root_poses, std::vector<double>(q.size(), 0.0));
    const std::vector<Pose> zero_body_poses = placeLinks(model, zero_poses);
    std::vector<JointFrame> frames;
    for (const JointRecord& joint : model->joints) {
      if (joint.engine_joint < 0) continue;
      const LinkRecord& child = model->links[joint.child];
      const Pose mapping = compose(zero_poses[joint.child], inverse(child.desc.pose));
      frames.push_back({transformPoint(mapping, joint.desc.anchor),
                        rotate(mapping.orientation, joint.desc.axis)});
    }
    model->engine_model->attachJoints(zero_body_poses, frames);
    const std::vector<Pose> body_poses =
        placeLinks(model, forwardKinematics(*model, frame_pose, root_poses, q));
    for (size_t body = 0; body < body_poses.size(); ++body)
      model->engine_model->setBodyState(static_cast<int>(body), body_poses[body], Twist());
    for (size_t j = 0; j < model->joints.size(); ++j) {
      JointRecord& joint = model->joints[j];
      joint.position = joint.engine_joint >= 0 ? q[j] : 0;
      if (joint.engine_joint >= 0)
        joint.last_raw = model->engine_model->jointPosition(joint.engine_joint);
    }
    model->velocity_capped = false;
    model->blown_up = false;
  }

  std::vector<Pose> currentLinkPoses(const ModelRecord& model) const {
    std::vector<Pose> poses;
    for (const LinkRecord& link : model.links) poses.push_back(linkWorldPose(model, link));
    return poses;
  }

  // Gives a moving link a new inertial and its body the new lump; the links keep their poses and
  // velocities, the body frame (at the new centre of mass) moves under them.
  Status reweighLink(ModelRecord* model, size_t index, const LinkDescription& desc) {
    LinkRecord& link = model->links[index];
    const int body = link.body;
    const std::vector<Pose> poses = currentLinkPoses(*model);
    std::vector<Twist> twists;
    for (const LinkRecord& l : model->links) twists.push_back(linkWorldTwist(*model, l));
    const std::vector<double> q = currentPositions(*model);
    const LinkDescription previous = link.desc;
    link.desc = desc;
    BodySpec spec;
    const LumpFault fault = lumpBody(model, body, &spec);
    if (fault != LumpFault::None) {
      link.desc = previous;
      if (fault == LumpFault::MomentOutOfRange) return outOfRange("inertia", kMinMoment, kMaxMoment);
      return {StatusCode::InvalidParameter, fault == LumpFault::NoMass ? "mass" : "inertia"};
    }
    model->bodies[body] = spec;
    model->engine_model->setBodyMass(body, spec);
    placeModel(model, model->frame_pose, poses, q);
    // placeModel leaves the model at rest: each body takes back the motion of its reference link.
    for (size_t i = 0; i < model->links.size(); ++i) {
      const LinkRecord& reference = model->links[i];
      if (reference.body < 0 || !reference.sets_body_pose) continue;
      const Pose body_pose = model->engine_model->bodyPose(reference.body);
      const Vec3 v = twists[i].linear + cross(twists[i].angular, body_pose.position - poses[i].position);
      model->engine_model->setBodyState(reference.body, body_pose, {v, twists[i].angular});
    }
    return {};
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

  // Overlapping jobs on a joint sum; the sum is held to what one job may be (applyJointEffort):
  // the joint's effort limit and the bound on its bodies. Blown-up models are held (guardStates).
  void applyJobs(int64_t t) {
    struct JointSum {
      const ModelRecord* model;
      size_t joint;
      double effort;
      int jobs;
    };
    std::vector<JointSum> sums;
    for (const JointEffortJob& job : joint_jobs) {
      if (job.start_ns > t || t >= job.end_ns || job.model->blown_up) continue;
      auto sum = std::find_if(sums.begin(), sums.end(), [&](const JointSum& s) {
        return s.model == job.model && s.joint == job.joint;
      });
      if (sum == sums.end()) sums.push_back({job.model, job.joint, job.effort, 1});
      else sum->effort += job.effort, ++sum->jobs;
    }
    for (const JointEffortCommand& command : joint_commands) {
      if (command.model->blown_up) continue;
      auto sum = std::find_if(sums.begin(), sums.end(), [&](const JointSum& s) {
        return s.model == command.model && s.joint == command.joint;
      });
      if (sum == sums.end()) sums.push_back({command.model, command.joint, command.effort, 1});
      else sum->effort += command.effort, ++sum->jobs;
    }
    for (const JointSum& sum : sums) {
      const JointRecord& joint = sum.model->joints[sum.joint];
      double effort = sum.effort;
      if (sum.jobs > 1) {  // a single job was clamped when it was queued
        const double bound =
            std::min(joint.desc.effort_limit, safeEffortBound(*sum.model, joint));
        if (std::abs(effort) > bound) effort = std::copysign(bound, effort);
      }
      sum.model->engine_model->addJointEffort(joint.engine_joint, effort);
    }
    for (const BodyWrenchJob& job : wrench_jobs) {
      if (job.start_ns > t || t >= job.end_ns || job.model->blown_up) continue;
      Pose frame;
      Twist unused;
      if (!resolveFrame(job.reference_frame, &frame, &unused)) continue;  // reference deleted
      job.model->engine_model->addBodyWrench(job.model->links[job.link].body,
                                             rotate(frame.orientation, job.force),
                                             transformPoint(frame, job.point),
                                             rotate(frame.orientation, job.torque));
    }
  }

  void applyDamping() {
    for (const auto& model : models)
      for (const JointRecord& joint : model->joints)
        if (joint.engine_joint >= 0 && joint.desc.damping != 0)
          model->engine_model->addJointEffort(joint.engine_joint,
                                              -joint.desc.damping * jointRate(*model, joint));
  }

  void saveStates() {
    saved_states.clear();
    for (const auto& model : models)
      for (size_t body = 0; body < model->bodies.size(); ++body) {
        const int b = static_cast<int>(body);
        saved_states.push_back({model->engine_model.get(), b, model->engine_model->bodyPose(b),
                                model->engine_model->bodyTwist(b)});
      }
  }

  bool isBlownUp(const ModelRecord& model) const {
    for (size_t body = 0; body < model.bodies.size(); ++body) {
      const int b = static_cast<int>(body);
      if (!isFinite(model.engine_model->bodyPose(b)) || !isFinite(model.engine_model->bodyTwist(b)))
        return true;
    }
    return false;
  }

  // One engine step from the saved states. A non-finite state is unrecoverable for an engine,
  // and a step moves all models at once, so a step that blows a model up is undone and redone
  // with that model at rest and its jobs left out: the rest of the world runs on. A model the
  // step leaves non-finite is held where the step started, at rest, and takes part in the next
  // step again (as at first: a model that blew up once is usually only too fast); the first
  // finite step releases it. Logged at most once per model per second of sim time: a model that
  // keeps blowing up would otherwise log at the step rate.
  void stepEngine() {
    std::string solver_message;
    applyJobs(time_ns);
    applyDamping();
    engine->step(params.step, &solver_message);
    std::vector<ModelRecord*> newly_blown;
    for (const auto& model : models)
      if (!model->blown_up && isBlownUp(*model)) newly_blown.push_back(model.get());
    if (!newly_blown.empty()) {
      for (const BodyState& s : saved_states) s.model->setBodyState(s.body, s.pose, s.twist);
      for (ModelRecord* model : newly_blown) {
        model->blown_up = true;
        holdAtSavedState(*model);
      }
      applyJobs(time_ns);
      applyDamping();
      engine->step(params.step, &solver_message);
    }
    if (!solver_message.empty() && !engine_struggled) warn(solver_message);
    engine_struggled = !solver_message.empty();
    for (const auto& model : models) {
      const bool blown = isBlownUp(*model);
      if (blown) holdAtSavedState(*model);
      const bool stopped =
          blown || std::count(newly_blown.begin(), newly_blown.end(), model.get()) > 0;
      if (stopped && (model->last_blow_up_warning_ns < 0 ||
                      time_ns - model->last_blow_up_warning_ns >= 1000000000)) {
        warn("model '" + model->name +
             "' reached a non-finite state: it was stopped where the step started while the "
             "rest of the world ran on");
        model->last_blow_up_warning_ns = time_ns;
      }
      model->blown_up = blown;
    }
  }

  void holdAtSavedState(const ModelRecord& model) {
    for (const BodyState& s : saved_states)
      if (s.model == model.engine_model.get()) s.model->setBodyState(s.body, s.pose, Twist());
  }

  // After the engine step (stepEngine): every model's speed is capped (see kMaxLinearSpeed and maxAngularSpeed), scaling all its
  // bodies alike so that its joints stay consistent.
  void guardStates() {
    const double max_angular = maxAngularSpeed(params.step);
    for (const auto& model : models) {
      EngineModel& engine_model = *model->engine_model;
      const int body_count = static_cast<int>(model->bodies.size());
      double scale = 1;
      for (int body = 0; body < body_count; ++body) {
        const Twist twist = engine_model.bodyTwist(body);
        const double linear = norm(twist.linear);
        const double angular = norm(twist.angular);
        if (linear > kMaxLinearSpeed) scale = std::min(scale, kMaxLinearSpeed / linear);
        if (angular > max_angular) scale = std::min(scale, max_angular / angular);
      }
      if (scale < 1) {
        for (int body = 0; body < body_count; ++body) {
          const Twist twist = engine_model.bodyTwist(body);
          engine_model.setBodyState(body, engine_model.bodyPose(body),
                                    {scale * twist.linear, scale * twist.angular});
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
    if (time_ns > kEndOfTimeNs - step_ns) {
      if (!time_ended)
        warn("sim time reached the end of ROS time (2^32 s): the world stands still until "
             "reset_simulation");
      time_ended = true;
      return;
    }
    saveStates();
    stepEngine();
    guardStates();
    for (const auto& model : models) updateJointPositions(model.get());
    time_ns += step_ns;
    ++steps;
    dropExpiredJobs(time_ns);
    joint_commands.clear();
  }

  // --- jobs ----------------------------------------------------------------------------------

  // The joint an effort job or command is for, or why it cannot have one.
  Status effortTarget(const std::string& joint_name, double effort, ModelRecord** model,
                      size_t* index) const {
    if (!findJoint(joint_name, model, index)) return {StatusCode::JointNotFound, joint_name};
    if ((*model)->joints[*index].engine_joint < 0) return {StatusCode::JointIsFixed, joint_name};
    if (!std::isfinite(effort)) return {StatusCode::NotFinite, "effort"};
    return {};
  }

  // What one job or command may be: the joint's effort limit, then the bound on its bodies.
  double clampEffort(const ModelRecord& model, const JointRecord& joint, double effort,
                     JobOutcome* done) const {
    if (std::abs(effort) > joint.desc.effort_limit) {
      effort = std::copysign(joint.desc.effort_limit, effort);
      done->effort_limit = joint.desc.effort_limit;
    }
    const double safe = safeEffortBound(model, joint);
    if (std::abs(effort) > safe) {
      effort = std::copysign(safe, effort);
      done->safe_effort = safe;
    }
    return effort;
  }

  // The job window for the contract's rules, or false for a zero duration (outcome->queued).
  bool jobWindow(int64_t start_ns, int64_t duration_ns, int64_t* start, int64_t* end,
                 JobOutcome* outcome) const {
    if (duration_ns == 0) {
      outcome->queued = false;
      return false;
    }
    *start = std::max(start_ns, time_ns);
    if (duration_ns < 0) {
      *end = kForever;
    } else if (duration_ns < step_ns) {
      // [start, start + step) holds exactly one step start, wherever start falls.
      *end = *start + step_ns;
      outcome->widened_to_one_step = true;
    } else {
      *end = saturatingAdd(*start, duration_ns);
    }
    return true;
  }
};

std::ostream& operator<<(std::ostream& out, StatusCode code) {
  switch (code) {
    case StatusCode::Ok: return out << "Ok";
    case StatusCode::ModelNotFound: return out << "ModelNotFound";
    case StatusCode::LinkNotFound: return out << "LinkNotFound";
    case StatusCode::JointNotFound: return out << "JointNotFound";
    case StatusCode::ReferenceFrameNotFound: return out << "ReferenceFrameNotFound";
    case StatusCode::ModelExists: return out << "ModelExists";
    case StatusCode::EmptyModelName: return out << "EmptyModelName";
    case StatusCode::NotFinite: return out << "NotFinite";
    case StatusCode::ZeroQuaternion: return out << "ZeroQuaternion";
    case StatusCode::ModelRejected: return out << "ModelRejected";
    case StatusCode::JointIsFixed: return out << "JointIsFixed";
    case StatusCode::LinkAnchored: return out << "LinkAnchored";
    case StatusCode::LengthMismatch: return out << "LengthMismatch";
    case StatusCode::InvalidParameter: return out << "InvalidParameter";
    case StatusCode::OutOfRange: return out << "OutOfRange";
    case StatusCode::InvalidModelName: return out << "InvalidModelName";
    case StatusCode::TooManyJobs: return out << "TooManyJobs";
  }
  return out << "StatusCode(" << static_cast<int>(code) << ")";
}

std::ostream& operator<<(std::ostream& out, const Status& status) {
  out << status.code;
  if (!status.subject.empty()) out << " '" << status.subject << "'";
  if (status.code == StatusCode::OutOfRange) out << " [" << status.min << ", " << status.max << "]";
  if (status.code == StatusCode::TooManyJobs) out << " (at most " << status.max << ")";
  return out;
}

std::vector<std::string> World::engineNames() {
  std::vector<std::string> names;
  for (const EngineEntry& entry : engineRegistry()) names.push_back(entry.name);
  return names;
}

World::World(const std::string& engine, const PhysicsParams& params)
    : impl_(new Impl(engine, params)) {}
World::~World() = default;

void World::step() { impl_->step(); }
int64_t World::timeNs() const { return impl_->time_ns; }
double World::time() const { return impl_->time_ns * 1e-9; }
uint64_t World::stepCount() const { return impl_->steps; }
const std::string& World::engineName() const { return impl_->engine_name; }
const PhysicsParams& World::params() const { return impl_->params; }

Status World::setParams(const PhysicsParams& params) {
  Status status = validateParams(params);
  if (status.ok()) impl_->applyParams(params);
  return status;
}

std::vector<std::string> World::takeWarnings() {
  std::vector<std::string> warnings;
  warnings.swap(impl_->warnings);
  return warnings;
}

Status World::spawn(const std::string& name, const std::string& xml, ModelFormat format,
                    const Pose& pose, const std::string& reference_frame) {
  Status status = checkPose(pose);
  if (!status.ok()) return status;
  if (name.empty()) return {StatusCode::EmptyModelName, {}};
  // Scoped names ("model::link") and reference frames must say one thing: a model called
  // "robot::link2" would take over robot's link2 as a frame, one called "world" the world.
  if (name.find("::") != std::string::npos || name == kWorldLink)
    return {StatusCode::InvalidModelName, name};
  if (impl_->findModel(name)) return {StatusCode::ModelExists, name};
  Pose frame;
  Twist unused;
  if (!impl_->resolveFrame(reference_frame, &frame, &unused))
    return {StatusCode::ReferenceFrameNotFound, reference_frame};
  ModelDescription desc;
  status = format == ModelFormat::Urdf ? parseUrdf(xml, &desc)
                                       : parseSdf(xml, impl_->model_path, &desc);
  if (!status.ok()) return status;

  auto model = std::make_unique<ModelRecord>();
  model->name = name;
  model->is_static = desc.is_static;
  ModelSpec spec;
  status = impl_->planModel(desc, model.get(), &spec);
  if (!status.ok()) return status;
  model->engine_model = impl_->engine->addModel(spec);
  model->spawn_pose = compose(frame, {pose.position, normalized(pose.orientation)});
  impl_->resetModel(model.get());
  impl_->models.push_back(std::move(model));
  return {};
}

void World::setModelPath(const std::vector<std::string>& folders) {
  // libsdformat would try a relative folder against its own install first.
  impl_->model_path.clear();
  for (const std::string& folder : folders)
    if (!folder.empty())
      impl_->model_path.push_back(std::filesystem::absolute(folder).lexically_normal().string());
}

Status World::deleteModel(const std::string& name) {
  for (size_t i = 0; i < impl_->models.size(); ++i)
    if (impl_->models[i]->name == name) {
      impl_->destroyModel(i);
      return {};
    }
  return {StatusCode::ModelNotFound, name};
}

std::vector<std::string> World::modelNames() const {
  std::vector<std::string> names;
  for (const auto& model : impl_->models) names.push_back(model->name);
  return names;
}

Status World::modelProperties(const std::string& name, ModelInfo* out) const {
  const ModelRecord* model = impl_->findModel(name);
  if (!model) return {StatusCode::ModelNotFound, name};
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
  return {};
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
  if (!model) return {StatusCode::ModelNotFound, name};
  Pose frame;
  Twist frame_twist;
  if (!impl_->resolveFrame(reference_frame, &frame, &frame_twist))
    return {StatusCode::ReferenceFrameNotFound, reference_frame};
  const LinkRecord& root = model->links[model->canonical];
  *pose = impl_->linkWorldPose(*model, root);
  *twist = impl_->linkWorldTwist(*model, root);
  makeRelative(frame, frame_twist, pose, twist);
  return {};
}

Status World::setModelState(const std::string& name, const Pose& pose, const Twist& twist,
                            const std::string& reference_frame) {
  const Status state = checkState(pose, twist, impl_->params.step);
  if (!state.ok()) return state;
  ModelRecord* model = impl_->findModel(name);
  if (!model) return {StatusCode::ModelNotFound, name};
  Pose frame;
  Twist unused;
  if (!impl_->resolveFrame(reference_frame, &frame, &unused))
    return {StatusCode::ReferenceFrameNotFound, reference_frame};
  const Pose target = compose(frame, {pose.position, normalized(pose.orientation)});
  // The whole model moves rigidly with its root link.
  const Pose motion =
      compose(target, inverse(impl_->linkWorldPose(*model, model->links[model->canonical])));
  std::vector<Pose> root_poses = impl_->currentLinkPoses(*model);
  for (Pose& p : root_poses) p = compose(motion, p);
  impl_->placeModel(model, compose(motion, model->frame_pose), root_poses,
                    impl_->currentPositions(*model));
  const Vec3 linear = rotate(frame.orientation, twist.linear);
  const Vec3 angular = rotate(frame.orientation, twist.angular);
  for (size_t body = 0; body < model->bodies.size(); ++body) {
    const Pose body_pose = model->engine_model->bodyPose(body);
    const Vec3 v = linear + cross(angular, body_pose.position - target.position);
    model->engine_model->setBodyState(body, body_pose, {v, angular});
  }
  return {};
}

Status World::setModelConfiguration(const std::string& model_name,
                                    const std::vector<std::string>& joints,
                                    const std::vector<double>& positions) {
  if (joints.size() != positions.size()) return {StatusCode::LengthMismatch, {}};
  for (size_t i = 0; i < joints.size(); ++i) {
    if (!std::isfinite(positions[i])) return {StatusCode::NotFinite, joints[i]};
    // Joint positions are kept unwrapped: past kMaxPosition a step's motion is lost in rounding.
    if (std::abs(positions[i]) > kMaxPosition)
      return outOfRange(joints[i], -kMaxPosition, kMaxPosition);
  }
  ModelRecord* model = impl_->findModel(model_name);
  if (!model) return {StatusCode::ModelNotFound, model_name};
  std::vector<double> q = impl_->currentPositions(*model);
  for (size_t i = 0; i < joints.size(); ++i) {
    auto joint = std::find_if(model->joints.begin(), model->joints.end(),
                              [&](const JointRecord& j) { return j.desc.name == joints[i]; });
    if (joint == model->joints.end()) return {StatusCode::JointNotFound, joints[i]};
    q[joint - model->joints.begin()] = positions[i];
  }
  impl_->placeModel(model, model->frame_pose, impl_->currentLinkPoses(*model), q);
  return {};
}

Status World::linkProperties(const std::string& scoped_link, LinkInfo* out) const {
  ModelRecord* model;
  size_t index;
  if (!impl_->findLink(scoped_link, &model, &index))
    return {StatusCode::LinkNotFound, scoped_link};
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
  return {};
}

Status World::linkState(const std::string& scoped_link, const std::string& reference_frame,
                        Pose* pose, Twist* twist) const {
  ModelRecord* model;
  size_t index;
  if (!impl_->findLink(scoped_link, &model, &index))
    return {StatusCode::LinkNotFound, scoped_link};
  Pose frame;
  Twist frame_twist;
  if (!impl_->resolveFrame(reference_frame, &frame, &frame_twist))
    return {StatusCode::ReferenceFrameNotFound, reference_frame};
  *pose = impl_->linkWorldPose(*model, model->links[index]);
  *twist = impl_->linkWorldTwist(*model, model->links[index]);
  makeRelative(frame, frame_twist, pose, twist);
  return {};
}

Status World::setLinkState(const std::string& scoped_link, const Pose& pose, const Twist& twist,
                           const std::string& reference_frame) {
  const Status state = checkState(pose, twist, impl_->params.step);
  if (!state.ok()) return state;
  ModelRecord* model;
  size_t index;
  if (!impl_->findLink(scoped_link, &model, &index))
    return {StatusCode::LinkNotFound, scoped_link};
  const LinkRecord& link = model->links[index];
  if (link.body < 0) return {StatusCode::LinkAnchored, scoped_link};
  Pose frame;
  Twist unused;
  if (!impl_->resolveFrame(reference_frame, &frame, &unused))
    return {StatusCode::ReferenceFrameNotFound, reference_frame};
  // As Gazebo: only this link's body moves; its joints pull it back in the next steps.
  const Pose target = compose(frame, {pose.position, normalized(pose.orientation)});
  const Pose body_pose = compose(target, inverse(link.link_in_body));
  const Vec3 linear = rotate(frame.orientation, twist.linear);
  const Vec3 angular = rotate(frame.orientation, twist.angular);
  const Vec3 v = linear + cross(angular, body_pose.position - target.position);
  model->engine_model->setBodyState(link.body, body_pose, {v, angular});
  impl_->updateJointPositions(model);
  return {};
}

Status World::setLinkProperties(const std::string& scoped_link, const LinkInfo& properties) {
  const Status com = checkPose(properties.com);
  if (!com.ok()) return {com.code, "com"};
  if (!std::isfinite(properties.mass)) return {StatusCode::NotFinite, "mass"};
  const double moments[] = {properties.ixx, properties.ixy, properties.ixz,
                            properties.iyy, properties.iyz, properties.izz};
  for (double moment : moments)
    if (!std::isfinite(moment)) return {StatusCode::NotFinite, "inertia"};
  if (properties.mass < 0) return {StatusCode::InvalidParameter, "mass"};
  if (properties.mass != 0 && (properties.mass < kMinMass || properties.mass > kMaxMass))
    return outOfRange("mass", kMinMass, kMaxMass);
  for (double moment : moments)
    if (std::abs(moment) > kMaxMoment) return outOfRange("inertia", kMinMoment, kMaxMoment);
  if (!withinPosition(properties.com.position))
    return outOfRange("com.position", -kMaxPosition, kMaxPosition);
  ModelRecord* model;
  size_t index;
  if (!impl_->findLink(scoped_link, &model, &index))
    return {StatusCode::LinkNotFound, scoped_link};
  LinkRecord& link = model->links[index];
  LinkDescription desc = link.desc;
  desc.has_inertial = true;
  desc.mass = properties.mass;
  desc.com = {properties.com.position, normalized(properties.com.orientation)};
  desc.ixx = properties.ixx, desc.ixy = properties.ixy, desc.ixz = properties.ixz;
  desc.iyy = properties.iyy, desc.iyz = properties.iyz, desc.izz = properties.izz;
  desc.gravity = properties.gravity_mode;
  if (link.body < 0) {  // anchored: nothing it carries moves
    link.desc = desc;
    return {};
  }
  // An engine body has one gravity mode.
  for (const LinkRecord& other : model->links)
    if (&other != &link && other.body == link.body && other.desc.gravity != desc.gravity)
      return {StatusCode::InvalidParameter, "gravity_mode"};
  return impl_->reweighLink(model, index, desc);
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
    return {StatusCode::JointNotFound, joint_name};
  const JointRecord& joint = model->joints[index];
  JointInfo info;
  info.model = model->name;
  info.name = joint.desc.name;
  info.type = joint.desc.type;
  info.has_damping = joint.desc.has_damping;
  info.damping = joint.desc.damping;
  info.position = joint.position;
  info.rate = impl_->jointRate(*model, joint);
  info.has_limits = joint.desc.has_limits;
  info.lower = joint.desc.lower;
  info.upper = joint.desc.upper;
  *out = info;
  return {};
}

Status World::setJointDamping(const std::string& joint_name, double damping) {
  ModelRecord* model;
  size_t index;
  if (!impl_->findJoint(joint_name, &model, &index))
    return {StatusCode::JointNotFound, joint_name};
  JointRecord& joint = model->joints[index];
  if (joint.engine_joint < 0) return {StatusCode::JointIsFixed, joint_name};
  if (!std::isfinite(damping)) return {StatusCode::NotFinite, "damping"};
  if (damping < 0) return {StatusCode::InvalidParameter, "damping"};
  if (damping > kMaxJointDamping) return outOfRange("damping", 0, kMaxJointDamping);
  joint.desc.damping = damping;
  joint.desc.has_damping = true;
  return {};
}

Status World::applyJointEffort(const std::string& joint_name, double effort, int64_t start_ns,
                               int64_t duration_ns, JobOutcome* outcome) {
  ModelRecord* model;
  size_t index;
  const Status takes = impl_->effortTarget(joint_name, effort, &model, &index);
  if (!takes.ok()) return takes;
  const JointRecord& joint = model->joints[index];
  const size_t pending = std::count_if(
      impl_->joint_jobs.begin(), impl_->joint_jobs.end(),
      [&](const JointEffortJob& job) { return job.model == model && job.joint == index; });
  if (pending >= kMaxPendingJobs) {
    Status full{StatusCode::TooManyJobs, model->name + "::" + joint.desc.name};
    full.max = kMaxPendingJobs;
    return full;
  }
  JobOutcome done;
  int64_t start = 0, end = 0;
  if (impl_->jobWindow(start_ns, duration_ns, &start, &end, &done)) {
    effort = impl_->clampEffort(*model, joint, effort, &done);
    impl_->joint_jobs.push_back({model, index, effort, start, end});
  }
  if (outcome) *outcome = done;
  return {};
}

Status World::setJointEffortCommand(const std::string& joint_name, double effort,
                                    JobOutcome* outcome) {
  ModelRecord* model;
  size_t index;
  const Status takes = impl_->effortTarget(joint_name, effort, &model, &index);
  if (!takes.ok()) return takes;
  const JointRecord& joint = model->joints[index];
  JobOutcome done;
  effort = impl_->clampEffort(*model, joint, effort, &done);
  auto& commands = impl_->joint_commands;
  auto same = std::find_if(commands.begin(), commands.end(), [&](const JointEffortCommand& c) {
    return c.model == model && c.joint == index;
  });
  if (same == commands.end()) commands.push_back({model, index, effort});
  else same->effort = effort;  // the latest command for the step replaces the earlier one
  if (outcome) *outcome = done;
  return {};
}

bool World::jointEffortActive(const std::string& joint_name, int64_t t_ns) const {
  ModelRecord* model;
  size_t index;
  if (!impl_->findJoint(joint_name, &model, &index)) return false;
  for (const JointEffortJob& job : impl_->joint_jobs)
    if (job.model == model && job.joint == index && job.start_ns <= t_ns && t_ns < job.end_ns)
      return true;
  return false;
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
                              int64_t start_ns, int64_t duration_ns, JobOutcome* outcome) {
  if (!isFinite(reference_point)) return {StatusCode::NotFinite, "reference_point"};
  if (!isFinite(force)) return {StatusCode::NotFinite, "force"};
  if (!isFinite(torque)) return {StatusCode::NotFinite, "torque"};
  if (!withinPosition(reference_point))
    return outOfRange("reference_point", -kMaxPosition, kMaxPosition);
  ModelRecord* model;
  size_t index;
  if (!impl_->findLink(scoped_link, &model, &index))
    return {StatusCode::LinkNotFound, scoped_link};
  const int body = model->links[index].body;
  if (body < 0) return {StatusCode::LinkAnchored, scoped_link};
  Pose frame;
  Twist unused;
  if (!impl_->resolveFrame(reference_frame, &frame, &unused))
    return {StatusCode::ReferenceFrameNotFound, reference_frame};
  const size_t pending = std::count_if(
      impl_->wrench_jobs.begin(), impl_->wrench_jobs.end(),
      [&](const BodyWrenchJob& job) { return job.model == model && job.link == index; });
  if (pending >= kMaxPendingJobs) {
    Status full{StatusCode::TooManyJobs, scoped_link};
    full.max = kMaxPendingJobs;
    return full;
  }
  JobOutcome done;
  int64_t start = 0, end = 0;
  if (impl_->jobWindow(start_ns, duration_ns, &start, &end, &done)) {
    // The same safety bound as for joint efforts, on this body alone.
    const BodySpec& mass = model->bodies[body];
    const double step = impl_->params.step;
    const double max_force = mass.mass * kMaxLinearSpeed / (kStepsToSpeedCap * step);
    const double max_torque = std::min({mass.ixx, mass.iyy, mass.izz}) * maxAngularSpeed(step) /
                              (kStepsToSpeedCap * step);
    Vec3 f = force, t = torque;
    if (norm(f) > max_force) f = (max_force / norm(f)) * f;
    if (norm(t) > max_torque) t = (max_torque / norm(t)) * t;
    if (norm(f) < norm(force) || norm(t) < norm(torque))
      done.safe_wrench = JobOutcome::WrenchBound{max_force, max_torque};
    impl_->wrench_jobs.push_back({model, index, reference_frame, reference_point, f, t, start, end});
  }
  if (outcome) *outcome = done;
  return {};
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
  impl_->time_ended = false;
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
      for (const CollisionDescription& collision : link.desc.collisions) {
        CollisionShape shape;
        shape.model = model->name;
        shape.link = link.desc.name;
        shape.shape = collision.shape;
        shape.size = collision.size;
        shape.pose = compose(impl_->linkWorldPose(*model, link), collision.pose);
        shapes.push_back(shape);
      }
  return shapes;
}

}  // namespace onedof_sim
