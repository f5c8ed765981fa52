#include "gazebo_api.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <thread>
#include <utility>

#include <dynamic_reconfigure/ConfigDescription.h>
#include <rosgraph_msgs/Clock.h>
#include <tinyxml2.h>
#include <visualization_msgs/MarkerArray.h>

#include <gazebo_msgs/LinkStates.h>
#include <gazebo_msgs/ModelStates.h>

namespace onedof_sim {
namespace {

constexpr int64_t kNsPerS = 1000000000;
// If the paced loop falls further behind than this, it drops the backlog instead of racing.
constexpr std::chrono::milliseconds kMaxPacingLag(100);
constexpr std::chrono::milliseconds kPacingSlice(50);
constexpr double kCollisionMarkersFrequency = 10.0;  // Hz of sim time
// A client's two clock readings after a call are microseconds apart; a millisecond leaves them
// room on a busy machine and bounds a lock-stepped 1 kHz controller to real time, about what
// roscpp's sim-time sleep (it polls every millisecond) allows anyway.
constexpr std::chrono::milliseconds kLockstepClockDelay(1);
// How long a stopped world waits for a controller's command before it shows the clock ahead to
// wake one that slept past the stop (awaitControllers): well beyond a live controller's answer.
constexpr std::chrono::milliseconds kLockstepWakeAfter(500);
// In lock-step, how long a request may wait for the world to reach a stop (WorldLock).
constexpr std::chrono::seconds kStopWaitLimit(1);
constexpr std::chrono::milliseconds kStopWaitSlice(50);
constexpr double kGroundMarkerSize = 10.0;           // m, the plane drawn as a thin square

// --- conversions between ROS messages and the core's types -------------------------------------

Vec3 toCore(const geometry_msgs::Vector3& v) { return {v.x, v.y, v.z}; }
Vec3 toCore(const geometry_msgs::Point& p) { return {p.x, p.y, p.z}; }

// Normalises the quaternion as Gazebo does; an all-zero one (an unset message field) is identity.
// A non-finite one stays non-finite, for the world to refuse.
Pose toCore(const geometry_msgs::Pose& p) {
  Pose pose;
  pose.position = toCore(p.position);
  const auto& q = p.orientation;
  const double norm = std::sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z);
  if (!(norm <= 1e-12)) pose.orientation = {q.w / norm, q.x / norm, q.y / norm, q.z / norm};
  return pose;
}

Twist toCore(const geometry_msgs::Twist& t) { return {toCore(t.linear), toCore(t.angular)}; }

geometry_msgs::Vector3 toVector3(const Vec3& v) {
  geometry_msgs::Vector3 m;
  m.x = v.x;
  m.y = v.y;
  m.z = v.z;
  return m;
}

geometry_msgs::Pose toMsg(const Pose& p) {
  geometry_msgs::Pose m;
  m.position.x = p.position.x;
  m.position.y = p.position.y;
  m.position.z = p.position.z;
  m.orientation.w = p.orientation.w;
  m.orientation.x = p.orientation.x;
  m.orientation.y = p.orientation.y;
  m.orientation.z = p.orientation.z;
  return m;
}

geometry_msgs::Twist toMsg(const Twist& t) {
  geometry_msgs::Twist m;
  m.linear = toVector3(t.linear);
  m.angular = toVector3(t.angular);
  return m;
}

// ROS time and duration to nanoseconds; sec/nsec are widened first so nothing overflows.
int64_t toNs(const ros::Time& t) { return int64_t(t.sec) * kNsPerS + int64_t(t.nsec); }
int64_t toNs(const ros::Duration& d) { return int64_t(d.sec) * kNsPerS + int64_t(d.nsec); }

std::string bareName(const std::string& scoped) {
  const auto pos = scoped.rfind("::");
  return pos == std::string::npos ? scoped : scoped.substr(pos + 2);
}

// --- status texts: Gazebo's wording (gazebo_ros_api_plugin.cpp) of what the world says ----------

// How one service words the world's codes, in Gazebo's texts where Gazebo refuses the same input:
// success, and the lookups it words per service, are full texts; every other refusal is ours
// (Gazebo would accept that input and misbehave), starts with the service's name and, for
// non-finite input, names the request's fields.
struct Wording {
  const char* service;
  const char* done;
  const char* not_finite = "values must be finite";
  const char* not_found = nullptr;        // a model, link or joint; else the common text
  const char* frame_not_found = nullptr;  // else ours, which names the frame
};

const Wording kGetJointProperties{"GetJointProperties", "GetJointProperties: got properties"};
const Wording kSetJointProperties{"SetJointProperties", "SetJointProperties: properties set"};
const Wording kApplyJointEffort{"ApplyJointEffort", "ApplyJointEffort: effort set",
                                "effort is not finite"};
// Gazebo answers "" on success: ours says what became of the job.
const Wording kApplyBodyWrench{"ApplyBodyWrench", "ApplyBodyWrench: wrench set",
                               "reference_point and wrench must be finite",
                               "ApplyBodyWrench: body does not exist",
                               "ApplyBodyWrench: reference_frame not found"};
const Wording kGetLinkState{
    "GetLinkState", "GetLinkState: got state", "values must be finite", nullptr,
    "GetLinkState: reference reference_frame not found, did you forget to scope the link by "
    "model name?"};
const Wording kSetLinkState{"SetLinkState", "SetLinkState: success",
                            "pose and twist must be finite", "SetLinkState: link does not exist",
                            "SetLinkState: failed"};
const Wording kGetLinkProperties{"GetLinkProperties", "GetLinkProperties: got properties"};
const Wording kSetLinkProperties{"SetLinkProperties", "SetLinkProperties: properties set",
                                 "mass, com and the inertia must be finite"};
const Wording kSpawnModel{
    "SpawnModel", "SpawnModel: Successfully spawned entity", "initial_pose must be finite",
    nullptr,
    "SpawnModel: reference reference_frame not found, did you forget to scope the link by model "
    "name?"};
const Wording kDeleteModel{"DeleteModel", "DeleteModel: successfully deleted model"};
const Wording kGetModelState{
    "GetModelState", "GetModelState: got properties", "values must be finite", nullptr,
    "GetModelState: reference relative_entity_name not found, did you forget to scope the body "
    "by model name?"};
const Wording kSetModelState{"SetModelState", "SetModelState: set model state done",
                             "pose and twist must be finite", nullptr,
                             "SetModelState: specified reference frame entity does not exist"};
const Wording kSetModelConfiguration{"SetModelConfiguration", "SetModelConfiguration: success",
                                     "joint_positions must be finite"};
const Wording kGetModelProperties{"GetModelProperties", "GetModelProperties: got properties"};
const Wording kSetPhysicsProperties{"SetPhysicsProperties", "physics engine updated"};

// Gazebo's answer to model_xml that is neither URDF nor SDF (not even XML); the node logs why.
const char* const kNotUrdfOrSdf =
    "GazeboRosApiPlugin SpawnModel Failure: input model_xml not SDF or URDF, or cannot be "
    "converted to Gazebo compatible format.";

// The range World enforces on a field (OutOfRange: [min, max] from the world), in the request's
// names: PhysicsParams' in ODEPhysics' names, a state's pose and twist, a link's inertial.
std::string outOfRangeText(const Status& status) {
  const std::string& field = status.subject;
  std::ostringstream text;
  const auto range = [&] { text << "[" << status.min << ", " << status.max << "]"; };
  if (field == "step") {
    text << "time_step must be in ";
    range();
    text << " s";
  } else if (field == "gravity") {
    text << "each gravity component must be in ";
    range();
    text << " m/s^2";
  } else if (field == "twist.linear" || field == "twist.angular") {
    text << "the speed |" << field << "| must be at most " << status.max
         << (field == "twist.linear" ? " m/s" : " rad/s")
         << ", the most the world lets a model move at this time_step";
  } else if (field == "pose.position" || field == "com.position" || field == "reference_point") {
    text << "each " << field << " component must be in ";
    range();
    text << " m";
  } else if (field == "mass") {
    text << "mass must be 0 (a link carried by the one it is welded to) or in ";
    range();
    text << " kg";
  } else if (field == "inertia") {
    text << "the principal moments of inertia must be in ";
    range();
    text << " kg m^2";
  } else {
    text << field << " must be in ";
    range();
  }
  return text.str();
}

// The rule World enforces on a field besides its range: a joint's damping, a link's inertial.
std::string parameterRange(const std::string& field) {
  if (field == "damping") return "damping must be >= 0";
  if (field == "mass") return "mass must be >= 0, and > 0 for a link that moves (welded links: in sum)";
  if (field == "inertia")
    return "the inertia must be positive definite, as a rigid body's is (ixx, iyy, izz > 0 and the "
           "products small enough)";
  if (field == "gravity_mode")
    return "links welded together by fixed joints move as one body and share one gravity_mode";
  return field + " is invalid";
}

std::string statusText(const Wording& wording, const Status& status) {
  const std::string& subject = status.subject;
  std::string text;
  switch (status.code) {
    case StatusCode::Ok: return wording.done;
    case StatusCode::ModelNotFound:
      if (wording.not_found) return wording.not_found;
      text = "model does not exist";
      break;
    case StatusCode::LinkNotFound:
      if (wording.not_found) return wording.not_found;
      text = "link not found, did you forget to scope the link by model name?";
      break;
    case StatusCode::JointNotFound:
      if (wording.not_found) return wording.not_found;
      text = "joint not found";
      break;
    case StatusCode::ReferenceFrameNotFound:
      if (wording.frame_not_found) return wording.frame_not_found;
      text = "reference frame '" + subject + "' not found";
      break;
    case StatusCode::ModelExists: text = "Failure - entity already exists."; break;
    case StatusCode::EmptyModelName: text = "the model name is empty"; break;
    case StatusCode::NotFinite: text = wording.not_finite; break;
    case StatusCode::ZeroQuaternion: text = "the orientation quaternion is zero"; break;
    case StatusCode::ModelRejected: text = subject; break;
    case StatusCode::JointIsFixed:
      text = "joint '" + subject + "' is fixed and takes no effort";
      break;
    case StatusCode::LinkAnchored:
      text = "link '" + subject + "' is anchored to the world; move its model with set_model_state";
      break;
    case StatusCode::LengthMismatch:
      text = "joint name and position list have different lengths";
      break;
    case StatusCode::InvalidParameter: text = parameterRange(subject); break;
    case StatusCode::OutOfRange: text = outOfRangeText(status); break;
    case StatusCode::InvalidModelName:
      text = "model name '" + subject + "' is refused: a name may not hold \"::\" (it scopes a "
             "link: model::link) nor be \"world\" (the world frame)";
      break;
    case StatusCode::TooManyJobs: {
      std::ostringstream jobs;
      jobs << "'" << subject << "' already has " << status.max
           << " jobs pending, the most it takes; clear them or wait until some end";
      text = jobs.str();
      break;
    }
  }
  return std::string(wording.service) + ": " + text;
}

// ApplyBodyWrench calls a link a body.
std::string wrenchText(const Status& status) {
  if (status.code == StatusCode::LinkAnchored)
    return "ApplyBodyWrench: body '" + status.subject + "' is anchored to the world";
  return statusText(kApplyBodyWrench, status);
}

// Gazebo sets the joints it finds and ignores the others; we refuse, naming the joint.
std::string configurationText(const Status& status) {
  if (status.code == StatusCode::JointNotFound)
    return "SetModelConfiguration: joint '" + status.subject + "' not found in model";
  if (status.code == StatusCode::OutOfRange) {
    std::ostringstream text;
    text << "SetModelConfiguration: the position of joint '" << status.subject << "' must be in ["
         << status.min << ", " << status.max << "] (rad or m)";
    return text.str();
  }
  return statusText(kSetModelConfiguration, status);
}

// --- dynamic_reconfigure: gazebo_ros' PhysicsConfig (cfg/Physics.cfg) ---------------------------

// What the physics setters take: the world's parameters and the node's pace.
struct PhysicsSettings {
  PhysicsParams params;
  double max_update_rate = 0;
};

// One parameter of PhysicsConfig, in gazebo_ros' order, with the range a dynamic_reconfigure
// server clamps to: gazebo_ros' range, narrowed where World refuses more (erp, sor_pgs_iters,
// sor_pgs_rms_error_tol, max_contacts).
struct PhysicsField {
  const char* name;
  const char* type;  // "double", "bool" or "int"
  const char* description;
  double min, max;
  double (*get)(const PhysicsSettings&);
  void (*set)(PhysicsSettings*, double);
};

// clang-format off
const PhysicsField kPhysicsFields[] = {
  {"time_step", "double", "physics step, s", 0, 10,
   [](const PhysicsSettings& s) { return s.params.step; },
   [](PhysicsSettings* s, double v) { s->params.step = v; }},
  {"max_update_rate", "double", "steps per wall second; 0 = as fast as possible", 0, 1e6,
   [](const PhysicsSettings& s) { return s.max_update_rate; },
   [](PhysicsSettings* s, double v) { s->max_update_rate = v; }},
  {"gravity_x", "double", "gravity along x, m/s^2", -100, 100,
   [](const PhysicsSettings& s) { return s.params.gravity.x; },
   [](PhysicsSettings* s, double v) { s->params.gravity.x = v; }},
  {"gravity_y", "double", "gravity along y, m/s^2", -100, 100,
   [](const PhysicsSettings& s) { return s.params.gravity.y; },
   [](PhysicsSettings* s, double v) { s->params.gravity.y = v; }},
  {"gravity_z", "double", "gravity along z, m/s^2", -100, 100,
   [](const PhysicsSettings& s) { return s.params.gravity.z; },
   [](PhysicsSettings* s, double v) { s->params.gravity.z = v; }},
  {"auto_disable_bodies", "bool", "let bodies at rest sleep (ODE)", 0, 1,
   [](const PhysicsSettings& s) { return s.params.auto_disable_bodies ? 1.0 : 0.0; },
   [](PhysicsSettings* s, double v) { s->params.auto_disable_bodies = v != 0; }},
  {"sor_pgs_precon_iters", "int", "preconditioning iterations of the SOR PGS solver", 0, 10000,
   [](const PhysicsSettings& s) { return double(s.params.sor_pgs_precon_iters); },
   [](PhysicsSettings* s, double v) { s->params.sor_pgs_precon_iters = uint32_t(v); }},
  {"sor_pgs_iters", "int", "iterations of the SOR PGS solver", 1, 10000,
   [](const PhysicsSettings& s) { return double(s.params.sor_pgs_iters); },
   [](PhysicsSettings* s, double v) { s->params.sor_pgs_iters = uint32_t(v); }},
  {"sor_pgs_w", "double", "SOR relaxation of the PGS solver", 0, 5,
   [](const PhysicsSettings& s) { return s.params.sor_pgs_w; },
   [](PhysicsSettings* s, double v) { s->params.sor_pgs_w = v; }},
  {"sor_pgs_rms_error_tol", "double", "RMS error tolerance of the SOR PGS solver", 0, 10000,
   [](const PhysicsSettings& s) { return s.params.sor_pgs_rms_error_tol; },
   [](PhysicsSettings* s, double v) { s->params.sor_pgs_rms_error_tol = v; }},
  {"cfm", "double", "constraint force mixing", 0, 10,
   [](const PhysicsSettings& s) { return s.params.cfm; },
   [](PhysicsSettings* s, double v) { s->params.cfm = v; }},
  {"erp", "double", "error reduction parameter", 0, 1,
   [](const PhysicsSettings& s) { return s.params.erp; },
   [](PhysicsSettings* s, double v) { s->params.erp = v; }},
  {"contact_surface_layer", "double", "penetration allowed before contacts push back, m", 0, 10,
   [](const PhysicsSettings& s) { return s.params.contact_surface_layer; },
   [](PhysicsSettings* s, double v) { s->params.contact_surface_layer = v; }},
  {"contact_max_correcting_vel", "double", "fastest a contact corrects penetration, m/s", 0, 1e7,
   [](const PhysicsSettings& s) { return s.params.contact_max_correcting_vel; },
   [](PhysicsSettings* s, double v) { s->params.contact_max_correcting_vel = v; }},
  {"max_contacts", "int", "most contact points between two geoms", 0, 65535,
   [](const PhysicsSettings& s) { return double(s.params.max_contacts); },
   [](PhysicsSettings* s, double v) { s->params.max_contacts = uint32_t(v); }},
};
// clang-format on

constexpr int kDefaultGroupId = 0;  // dynamic_reconfigure's top-level group, "Default"

dynamic_reconfigure::Config toConfig(const PhysicsSettings& settings) {
  dynamic_reconfigure::Config config;
  for (const PhysicsField& field : kPhysicsFields) {
    const double value = field.get(settings);
    if (std::string(field.type) == "bool") {
      dynamic_reconfigure::BoolParameter p;
      p.name = field.name;
      p.value = value != 0;
      config.bools.push_back(p);
    } else if (std::string(field.type) == "int") {
      dynamic_reconfigure::IntParameter p;
      p.name = field.name;
      p.value = static_cast<int32_t>(value);
      config.ints.push_back(p);
    } else {
      dynamic_reconfigure::DoubleParameter p;
      p.name = field.name;
      p.value = value;
      config.doubles.push_back(p);
    }
  }
  dynamic_reconfigure::GroupState group;
  group.name = "Default";
  group.state = true;
  group.id = group.parent = kDefaultGroupId;
  config.groups.push_back(group);
  return config;
}

// The value a Reconfigure request gives the field, if it names it (in the list of its type, as
// dynamic_reconfigure's own servers read it), clamped to the field's range as they clamp.
std::optional<double> requested(const dynamic_reconfigure::Config& config,
                                const PhysicsField& field) {
  std::optional<double> value;
  for (const auto& p : config.doubles)
    if (p.name == field.name && std::string(field.type) == "double") value = p.value;
  for (const auto& p : config.ints)
    if (p.name == field.name && std::string(field.type) == "int") value = p.value;
  for (const auto& p : config.bools)
    if (p.name == field.name && std::string(field.type) == "bool") value = p.value ? 1 : 0;
  if (value && !std::isnan(*value)) value = std::clamp(*value, field.min, field.max);
  return value;
}

dynamic_reconfigure::ConfigDescription physicsDescription(const PhysicsSettings& defaults) {
  dynamic_reconfigure::ConfigDescription description;
  dynamic_reconfigure::Group group;
  group.name = "Default";
  group.id = group.parent = kDefaultGroupId;
  PhysicsSettings min, max;
  for (const PhysicsField& field : kPhysicsFields) {
    dynamic_reconfigure::ParamDescription param;
    param.name = field.name;
    param.type = field.type;
    param.level = 1;
    param.description = field.description;
    group.parameters.push_back(param);
    field.set(&min, field.min);
    field.set(&max, field.max);
  }
  description.groups.push_back(group);
  description.min = toConfig(min);
  description.max = toConfig(max);
  description.dflt = toConfig(defaults);
  return description;
}

// What a job became, after the service's "effort set" or "wrench set". For a wrench, the force
// and torque asked for (requested_wrench): each is named only if it was clamped.
std::string jobNotes(const JobOutcome& job,
                     const std::optional<std::pair<Vec3, Vec3>>& requested_wrench = {}) {
  if (!job.queued) return "; duration is 0, so nothing was applied";
  std::ostringstream notes;
  if (job.widened_to_one_step)
    notes << "; duration is shorter than the step, so it acts for exactly one step";
  if (job.effort_limit) notes << "; clamped to the joint's effort limit " << *job.effort_limit;
  if (job.safe_effort) {
    notes << "; clamped to " << *job.safe_effort
          << ", the most this joint takes without the simulation blowing up";
  }
  if (job.safe_wrench && requested_wrench) {
    const auto magnitude = [](const Vec3& v) { return std::hypot(v.x, v.y, v.z); };
    const bool force = magnitude(requested_wrench->first) > job.safe_wrench->force;
    const bool torque = magnitude(requested_wrench->second) > job.safe_wrench->torque;
    notes << "; ";
    if (force) notes << "force clamped to |force| " << job.safe_wrench->force << " N";
    if (force && torque) notes << " and ";
    if (torque) notes << "torque clamped to |torque| " << job.safe_wrench->torque << " N m";
    notes << " (same direction), the most this body takes without the simulation blowing up";
  }
  return notes.str();
}

// Bad input: the call succeeds with success False and the reason, and the node says it too.
template <class Response>
bool refuse(Response& res, const std::string& text) {
  res.success = false;
  res.status_message = text;
  ROS_WARN_STREAM(text);
  return true;
}

template <class Response>
bool succeed(Response& res, const std::string& text) {
  res.success = true;
  res.status_message = text;
  return true;
}

template <class Response>
bool answer(Response& res, const Status& status, const std::string& text) {
  return status.ok() ? succeed(res, text) : refuse(res, text);
}

// Whether a throttled output is due at sim time now_ns (frequency <= 0: every step). Time going
// back (reset_simulation) makes it due at once.
bool isDue(int64_t now_ns, int64_t last_ns, double frequency) {
  if (frequency <= 0 || last_ns < 0 || now_ns < last_ns) return true;
  return double(now_ns - last_ns) >= 1e9 / frequency;
}

// Which format model_xml is, from its root element; Gazebo accepts either on both spawn services.
// Else ModelRejected with the reason, as the world's parsers say it.
Status detectModelFormat(const std::string& xml, ModelFormat* format) {
  tinyxml2::XMLDocument doc;
  if (doc.Parse(xml.c_str(), xml.size()) != tinyxml2::XML_SUCCESS) {
    const char* detail = doc.ErrorStr();
    return {StatusCode::ModelRejected,
            std::string("model_xml is not well-formed XML: ") + (detail ? detail : "parse error")};
  }
  const tinyxml2::XMLElement* root = doc.RootElement();
  const std::string root_name = root ? root->Name() : "";
  if (root_name == "robot") {
    *format = ModelFormat::Urdf;
  } else if (root_name == "sdf") {
    *format = ModelFormat::Sdf;
  } else {
    return {StatusCode::ModelRejected, "model_xml has root element <" + root_name +
                                           ">, expected <robot> (URDF) or <sdf> (SDF)"};
  }
  return {};
}

uint8_t toJointTypeConstant(JointType type) {
  switch (type) {
    case JointType::Prismatic:
      return gazebo_msgs::GetJointProperties::Response::PRISMATIC;
    case JointType::Fixed:
      return gazebo_msgs::GetJointProperties::Response::FIXED;
    case JointType::Revolute:
    case JointType::Continuous:
      break;
  }
  return gazebo_msgs::GetJointProperties::Response::REVOLUTE;
}

visualization_msgs::Marker toMarker(const CollisionShape& shape, int id) {
  visualization_msgs::Marker marker;
  marker.header.frame_id = "world";
  // One namespace per model: one checkbox per model in rviz's MarkerArray display, so our rviz
  // view shows the world (the table) and leaves the robot, which its RobotModel already draws,
  // off until asked for.
  marker.ns = shape.model;
  marker.id = id;
  marker.action = visualization_msgs::Marker::ADD;
  marker.pose = toMsg(shape.pose);
  marker.color.r = marker.color.g = marker.color.b = 0.6f;
  marker.color.a = 0.8f;
  switch (shape.shape) {
    case GeometryShape::Box:
      marker.type = visualization_msgs::Marker::CUBE;
      marker.scale = toVector3(shape.size);
      break;
    case GeometryShape::Cylinder:
      marker.type = visualization_msgs::Marker::CYLINDER;
      marker.scale.x = marker.scale.y = 2 * shape.size.x;
      marker.scale.z = shape.size.z;
      break;
    case GeometryShape::Sphere:
      marker.type = visualization_msgs::Marker::SPHERE;
      marker.scale.x = marker.scale.y = marker.scale.z = 2 * shape.size.x;
      break;
    case GeometryShape::Plane:
      marker.type = visualization_msgs::Marker::CUBE;
      marker.scale.x = marker.scale.y = kGroundMarkerSize;
      marker.scale.z = 0.001;
      marker.color.a = 0.3f;
      break;
  }
  return marker;
}

// --- lock-step texts -------------------------------------------------------------------------

std::string simSeconds(int64_t ns) {
  std::ostringstream text;
  text.setf(std::ios::fixed);
  text.precision(3);
  text << double(ns) / kNsPerS << " s";
  return text.str();
}

std::string lockstepJoinText(const std::string& joint, const std::string& caller) {
  return "lock-step: " + joint + " is commanded by " + caller +
         "; from now on the world stops where its effort runs out and waits for its next "
         "apply_joint_effort";
}

std::string lockstepTimeoutText(const std::vector<Lockstep::Awaited>& awaited, int64_t t_ns,
                                Lockstep::Clock::duration timeout) {
  std::ostringstream text;
  text << "lock-step: the world waited "
       << std::chrono::duration<double>(timeout).count() << " s (wall) at sim time "
       << simSeconds(t_ns) << " for apply_joint_effort on";
  for (const Lockstep::Awaited& joint : awaited)
    text << " " << joint.joint << " (last commanded by " << joint.caller << ")";
  text << "; going on without " << (awaited.size() > 1 ? "them" : "it")
       << " until commanded again (~lockstep_timeout sets the wait)";
  return text.str();
}

// --- start-up parameters --------------------------------------------------------------------

// Reads ~name into *value when set; a value of the wrong type is an error, not a silent default.
template <class T>
bool readParam(const ros::NodeHandle& nh, const std::string& name, T* value, std::string* error) {
  if (!nh.hasParam(name) || nh.getParam(name, *value)) return true;
  *error = "parameter " + nh.resolveName(name) + " has the wrong type";
  return false;
}

bool readCount(const ros::NodeHandle& nh, const std::string& name, uint32_t* value,
               std::string* error) {
  int count = int(*value);
  if (!readParam(nh, name, &count, error)) return false;
  if (count < 0) {
    *error = "parameter " + nh.resolveName(name) + " must be >= 0";
    return false;
  }
  *value = uint32_t(count);
  return true;
}

// Pacing below one step per wall second leaves the clock crawling (0.01: a step every 100 s, with
// nothing to see); pause_physics is what stops the world.
constexpr double kMinPacedRate = 1.0;

// Empty if the node can pace at max_update_rate, else why not.
std::string maxUpdateRateError(double rate) {
  if (std::isfinite(rate) && (rate == 0 || rate >= kMinPacedRate)) return "";
  std::ostringstream text;
  text << "max_update_rate must be 0 (as fast as possible) or at least " << kMinPacedRate
       << " step per wall second (pause_physics stops the world), got " << rate;
  return text.str();
}

bool readRate(const ros::NodeHandle& nh, const std::string& name, double* value,
              std::string* error) {
  if (!readParam(nh, name, value, error)) return false;
  if (!std::isfinite(*value) || *value < 0) {
    *error = "parameter " + nh.resolveName(name) + " must be finite and >= 0";
    return false;
  }
  return true;
}

bool readMaxUpdateRate(const ros::NodeHandle& nh, double* value, std::string* error) {
  if (!readRate(nh, "max_update_rate", value, error)) return false;
  const std::string why = maxUpdateRateError(*value);
  if (!why.empty()) *error = "parameter " + nh.resolveName("max_update_rate") + ": " + why;
  return why.empty();
}

bool readLockstep(const ros::NodeHandle& nh, Lockstep::Options* lockstep, std::string* error) {
  double timeout = std::chrono::duration<double>(lockstep->timeout).count();
  if (!readParam(nh, "lockstep", &lockstep->enabled, error) ||
      !readParam(nh, "lockstep_timeout", &timeout, error)) {
    return false;
  }
  if (!(timeout > 0) || !std::isfinite(timeout)) {
    *error = "parameter " + nh.resolveName("lockstep_timeout") + " must be a finite number of seconds > 0";
    return false;
  }
  lockstep->timeout = std::chrono::duration_cast<Lockstep::Clock::duration>(
      std::chrono::duration<double>(timeout));
  return true;
}

// ~gravity as a list [x, y, z] (rosparam, launch files) or a string "x y z" / "[x, y, z]" (what
// _gravity:=... on the rosrun command line gives, as roscpp does not parse lists there).
bool readGravity(const ros::NodeHandle& nh, Vec3* gravity, std::string* error) {
  if (!nh.hasParam("gravity")) return true;
  std::vector<double> values;
  std::string text;
  if (!nh.getParam("gravity", values) && nh.getParam("gravity", text)) {
    for (char& c : text) {
      if (c == '[' || c == ']' || c == ',') c = ' ';
    }
    std::istringstream in(text);
    double value;
    while (in >> value) values.push_back(value);
    if (!in.eof()) values.clear();
  }
  if (values.size() != 3) {
    *error = "parameter " + nh.resolveName("gravity") + " must be three numbers [x, y, z]";
    return false;
  }
  *gravity = {values[0], values[1], values[2]};
  return true;
}

// The master's parameter server, by the parameter's global name with no remapping applied.
bool masterHasParam(const std::string& name) {
  XmlRpc::XmlRpcValue request, response, has;
  request[0] = ros::this_node::getName();
  request[1] = name;
  return ros::master::execute("hasParam", request, response, has, false) && bool(has);
}

void masterSetParam(const std::string& name, bool value) {
  XmlRpc::XmlRpcValue request, response, unused;
  request[0] = ros::this_node::getName();
  request[1] = name;
  request[2] = value;
  ros::master::execute("setParam", request, response, unused, false);
}

}  // namespace


// Private start-up parameters (all optional; set them before starting the node, on the command
// line as _name:=value, or in a launch file):
//   ~physics (the engine: World::engineNames(), the first by default; gzserver's -e does the same;
//     World refuses an unknown one, naming the known ones)
//   ~time_step (s, 0.001)  ~max_update_rate (steps per wall second, 1000; 0 = as fast as possible)
//   ~paused (false; gzserver's -u / --pause flag does the same)  ~gravity ([0, 0, -9.8], or "0 0 -9.8")
//   ~quick_step (false: dWorldStep; true: dWorldQuickStep)
//   ODE solver settings named as the fields of ODEPhysics: ~auto_disable_bodies,
//   ~sor_pgs_precon_iters, ~sor_pgs_iters, ~sor_pgs_w, ~sor_pgs_rms_error_tol,
//   ~contact_surface_layer, ~contact_max_correcting_vel, ~cfm, ~erp, ~max_contacts
//   ~states_publish_frequency (Hz of sim time for model_states/link_states; 0 = every step)
//   ~lockstep (false; see lockstep.h)
//   ~lockstep_timeout (wall s a stopped world waits for a controller's command, 5)
// and, read while running, ~pub_clock_frequency (Hz of sim time; unset or <= 0 = every step).
bool readNodeOptions(const ros::NodeHandle& nh, const std::vector<std::string>& args,
                     NodeOptions* options, std::string* error) {
  PhysicsParams& p = options->physics;
  if (!readParam(nh, "physics", &options->engine, error) ||
      !readParam(nh, "time_step", &p.step, error) ||
      !readMaxUpdateRate(nh, &options->max_update_rate, error) ||
      !readParam(nh, "paused", &options->paused, error) ||
      !readGravity(nh, &p.gravity, error) ||
      !readParam(nh, "quick_step", &p.quick_step, error) ||
      !readParam(nh, "auto_disable_bodies", &p.auto_disable_bodies, error) ||
      !readCount(nh, "sor_pgs_precon_iters", &p.sor_pgs_precon_iters, error) ||
      !readCount(nh, "sor_pgs_iters", &p.sor_pgs_iters, error) ||
      !readParam(nh, "sor_pgs_w", &p.sor_pgs_w, error) ||
      !readParam(nh, "sor_pgs_rms_error_tol", &p.sor_pgs_rms_error_tol, error) ||
      !readParam(nh, "contact_surface_layer", &p.contact_surface_layer, error) ||
      !readParam(nh, "contact_max_correcting_vel", &p.contact_max_correcting_vel, error) ||
      !readParam(nh, "cfm", &p.cfm, error) || !readParam(nh, "erp", &p.erp, error) ||
      !readCount(nh, "max_contacts", &p.max_contacts, error) ||
      !readRate(nh, "states_publish_frequency", &options->states_publish_frequency, error) ||
      !readLockstep(nh, &options->lockstep, error)) {
    return false;
  }
  // gzserver's flags, as launch files pass them (-u/--pause, -e ode, --verbose, a world file).
  for (size_t i = 0; i < args.size(); ++i) {
    if (args[i] == "-u" || args[i] == "--pause") {
      options->paused = true;
    } else if (args[i] == "-e" && i + 1 < args.size()) {
      options->engine = args[++i];
    } else {
      ROS_WARN_STREAM("ignoring command-line argument '" << args[i] << "'");
    }
  }
  return true;
}

// --- the node ---------------------------------------------------------------------------------

struct GazeboApi::StepOutput {
  bool stepped = false;
  bool on_request = false;     // a step of step_simulation: not paced
  bool publish_clock = false;  // whatever pub_clock_frequency says: the world stops here
  bool hold_clock = false;     // lock-stepped controllers' efforts run: only stops are published
  Lockstep::Clock::time_point clock_not_before;  // of a lock-step stop (see stepOnce)
  bool resumed = false;  // the pacing must restart (after a pause or a rate change)
  int64_t time_ns = 0;
  double max_update_rate = 0;
  bool has_model_states = false;
  bool has_link_states = false;
  bool has_markers = false;
  gazebo_msgs::ModelStates model_states;
  gazebo_msgs::LinkStates link_states;
  std::vector<CollisionShape> shapes;
  std::vector<std::string> warnings;  // what the world had to do on its own during the step
  std::vector<control::Publication> control_publications;  // the in-sim controllers' messages
};

GazeboApi::WorldLock::WorldLock(GazeboApi& api) {
  ++api.waiting_callbacks_;
  lock_ = std::unique_lock<std::mutex>(api.mutex_);
  --api.waiting_callbacks_;
  // In lock-step a request lands where the world stops, never inside a controller's period: a
  // controller that slept past a stop and was woken (awaitControllers) sends the next period's
  // request at once, and must find the world at that period's start, as it would have on time.
  // Bounded, so that a world paced very slowly still answers.
  const auto limit = std::chrono::steady_clock::now() + kStopWaitLimit;
  while (api.between_stops_ && !api.paused_ && ros::ok() &&
         std::chrono::steady_clock::now() < limit)
    api.at_stop_.wait_for(lock_, kStopWaitSlice);
}

GazeboApi::GazeboApi(const NodeOptions& options)
    : private_nh_("~"),
      world_(options.engine),
      paused_(options.paused),
      max_update_rate_(options.max_update_rate),
      lockstep_(options.lockstep),
      states_publish_frequency_(options.states_publish_frequency),
      spinner_(2),
      step_spinner_(1, &step_queue_) {
  const Status params = world_.setParams(options.physics);
  if (!params.ok()) throw std::invalid_argument(statusText(kSetPhysicsProperties, params));
  world_.setModelPath(options.model_path);

  // Through the master, not the node handle: this node remaps /use_sim_time for itself (main.cpp).
  if (!masterHasParam(kUseSimTime)) masterSetParam(kUseSimTime, true);

  // Latched: a node started while the world is paused learns the time at once, instead of
  // running on time 0 (no valid time to roscpp and rospy) until the world moves.
  clock_pub_ = nh_.advertise<rosgraph_msgs::Clock>("/clock", 100, true);
  model_states_pub_ = private_nh_.advertise<gazebo_msgs::ModelStates>("model_states", 1);
  link_states_pub_ = private_nh_.advertise<gazebo_msgs::LinkStates>("link_states", 1);
  markers_pub_ = private_nh_.advertise<visualization_msgs::MarkerArray>("collision_markers", 1);
  parameter_descriptions_pub_ = private_nh_.advertise<dynamic_reconfigure::ConfigDescription>(
      "parameter_descriptions", 1, true);
  parameter_updates_pub_ =
      private_nh_.advertise<dynamic_reconfigure::Config>("parameter_updates", 1, true);
  // The start-up settings are the defaults a client resets to.
  parameter_descriptions_pub_.publish(
      physicsDescription({world_.params(), max_update_rate_}));
  parameter_updates_pub_.publish(physicsConfig());

  ros::AdvertiseServiceOptions step_options;
  step_options.init<StepSimulation::Request, StepSimulation::Response>(
      "step_simulation", [this](StepSimulation::Request& req, StepSimulation::Response& res) {
        return stepSimulation(req, res);
      });
  step_options.callback_queue = &step_queue_;
  step_service_ = private_nh_.advertiseService(step_options);
  auto& n = private_nh_;
  services_ = {
      n.advertiseService("get_joint_properties", &GazeboApi::getJointProperties, this),
      n.advertiseService("apply_joint_effort", &GazeboApi::applyJointEffort, this),
      n.advertiseService("clear_joint_forces", &GazeboApi::clearJointForces, this),
      n.advertiseService("apply_body_wrench", &GazeboApi::applyBodyWrench, this),
      n.advertiseService("clear_body_wrenches", &GazeboApi::clearBodyWrenches, this),
      n.advertiseService("spawn_urdf_model", &GazeboApi::spawnUrdfModel, this),
      n.advertiseService("spawn_sdf_model", &GazeboApi::spawnSdfModel, this),
      n.advertiseService("delete_model", &GazeboApi::deleteModel, this),
      n.advertiseService("get_model_state", &GazeboApi::getModelState, this),
      n.advertiseService("set_model_state", &GazeboApi::setModelState, this),
      n.advertiseService("get_link_state", &GazeboApi::getLinkState, this),
      n.advertiseService("set_link_state", &GazeboApi::setLinkState, this),
      n.advertiseService("set_model_configuration", &GazeboApi::setModelConfiguration, this),
      n.advertiseService("get_model_properties", &GazeboApi::getModelProperties, this),
      n.advertiseService("get_world_properties", &GazeboApi::getWorldProperties, this),
      n.advertiseService("get_link_properties", &GazeboApi::getLinkProperties, this),
      n.advertiseService("set_link_properties", &GazeboApi::setLinkProperties, this),
      n.advertiseService("set_joint_properties", &GazeboApi::setJointProperties, this),
      n.advertiseService("get_light_properties", &GazeboApi::getLightProperties, this),
      n.advertiseService("set_light_properties", &GazeboApi::setLightProperties, this),
      n.advertiseService("delete_light", &GazeboApi::deleteLight, this),
      n.advertiseService("get_physics_properties", &GazeboApi::getPhysicsProperties, this),
      n.advertiseService("set_physics_properties", &GazeboApi::setPhysicsProperties, this),
      n.advertiseService("set_parameters", &GazeboApi::setParameters, this),
      n.advertiseService("pause_physics", &GazeboApi::pausePhysics, this),
      n.advertiseService("reset_simulation", &GazeboApi::resetSimulation, this),
      n.advertiseService("reset_world", &GazeboApi::resetWorld, this),
      // Last on purpose: clients (and our tests) take it as the sign that every service is up.
      n.advertiseService("unpause_physics", &GazeboApi::unpausePhysics, this),
  };
  subscribers_ = {
      n.subscribe("set_model_state", 10, &GazeboApi::setModelStateTopic, this),
      n.subscribe("set_link_state", 10, &GazeboApi::setLinkStateTopic, this),
  };
  step_spinner_.start();
  spinner_.start();
  const std::string lockstep_note = lockstep_.enabled() ? ", lock-step" : "";
  ROS_INFO("onedof_sim, standing in for Gazebo: serving the Gazebo API under %s (step %g s, max_update_rate %g Hz%s%s)",
           private_nh_.getNamespace().c_str(), options.physics.step, max_update_rate_,
           paused_ ? ", paused" : "", lockstep_note.c_str());
}

GazeboApi::~GazeboApi() {
  spinner_.stop();
  step_spinner_.stop();
  wake_loop_.notify_all();
  steps_done_.notify_all();
}

void GazeboApi::run() {
  bool was_stepping = false;
  double paced_rate = -1;
  while (ros::ok()) {
    StepOutput out;
    stepOnce(&out);
    for (const auto& warning : out.warnings) ROS_WARN_STREAM(warning);
    if (!out.stepped) {
      was_stepping = false;
      publishHeldClock();
      continue;
    }
    publish(out);
    if (out.on_request) continue;  // step_simulation runs its steps as fast as it can
    out.resumed = !was_stepping || out.max_update_rate != paced_rate;
    was_stepping = true;
    paced_rate = out.max_update_rate;
    pace(out.max_update_rate, out.resumed);
  }
}

void GazeboApi::stepOnce(StepOutput* out) {
  const bool want_model_states = model_states_pub_.getNumSubscribers() > 0;
  const bool want_link_states = link_states_pub_.getNumSubscribers() > 0;
  const bool want_markers = markers_pub_.getNumSubscribers() > 0;

  // Let waiting service callbacks in first; they hold the lock only for one world call.
  while (waiting_callbacks_.load() > 0) std::this_thread::yield();
  std::unique_lock<std::mutex> lock(mutex_);
  const bool requested = step_request_.remaining > 0;
  const bool request_ending = step_request_.active && !requested;
  if (paused_ && !requested && !request_ending) {
    // Wakes on unpause or a step request; the timeout lets run() notice a shutdown.
    wake_loop_.wait_for(lock, std::chrono::milliseconds(50));
    return;
  }
  if (lockstep_.enabled() && !awaitControllers(lock, out)) return;
  if (request_ending) {
    step_request_.active = false;
    steps_done_.notify_all();
    return;
  }
  // In-sim controllers act at the step's start time, as gazebo_ros_control does at the world's
  // update begin, and never wait: lock-step waits only for apply_joint_effort's clients.
  for (auto& entry : robot_controls_) {
    entry.second->beforeStep(world_);
    for (auto& publication : entry.second->takePublications())
      out->control_publications.push_back(std::move(publication));
  }
  world_.step();
  if (requested) --step_request_.remaining;
  out->stepped = true;
  out->on_request = requested;
  const std::vector<std::string> world_warnings = world_.takeWarnings();
  out->warnings.insert(out->warnings.end(), world_warnings.begin(), world_warnings.end());
  out->time_ns = world_.timeNs();
  out->max_update_rate = max_update_rate_;
  // Where the world stops (the last requested step, or a controller's effort running out in
  // lock-step), its time must reach the clients even when /clock is throttled: they wait for it.
  // While lock-stepped controllers' efforts run, only those stops are published: roscpp's and
  // rospy's rates read the clock twice (sleep for a remainder counted from the second reading),
  // and a clock that moves between the two readings puts their wake-up past the stop they are
  // waited for at. Held still between stops, it cannot move there.
  const bool stop = (requested && step_request_.remaining == 0) ||
                    (lockstep_.enabled() && !lockstep_.awaited(world_, out->time_ns).empty());
  out->publish_clock = stop;
  out->hold_clock = !stop && lockstep_.enabled() && lockstep_.running(world_, out->time_ns);
  between_stops_ = out->hold_clock;
  if (!between_stops_) at_stop_.notify_all();
  // After a wake-up clock (awaitControllers) the clients' time is ahead of the world's: nothing
  // earlier goes out, clocks never move back.
  if (clock_ahead_ns_ >= 0 && out->time_ns < clock_ahead_ns_) {
    out->publish_clock = false;
    out->hold_clock = true;
  } else {
    clock_ahead_ns_ = -1;
  }
  // And a stop's clock goes out no sooner than kLockstepClockDelay after the latest command: a
  // roscpp client reads the clock twice right after its call returns, and the next stop's clock
  // must not land between the two readings (as fast as possible it would, about once in a few
  // hundred 1 kHz periods, and the client would sleep past the stop).
  if (stop && lockstep_.enabled()) out->clock_not_before = last_command_at_ + kLockstepClockDelay;

  const bool states_due = isDue(out->time_ns, last_states_ns_, states_publish_frequency_);
  if (states_due && (want_model_states || want_link_states)) last_states_ns_ = out->time_ns;
  if (states_due && want_model_states) {
    out->has_model_states = true;
    for (const auto& name : world_.modelNames()) {
      Pose pose;
      Twist twist;
      if (!world_.modelState(name, "", &pose, &twist).ok()) continue;
      out->model_states.name.push_back(name);
      out->model_states.pose.push_back(toMsg(pose));
      out->model_states.twist.push_back(toMsg(twist));
    }
  }
  if (states_due && want_link_states) {
    out->has_link_states = true;
    for (const auto& name : world_.linkNames()) {
      Pose pose;
      Twist twist;
      if (!world_.linkState(name, "", &pose, &twist).ok()) continue;
      out->link_states.name.push_back(name);
      out->link_states.pose.push_back(toMsg(pose));
      out->link_states.twist.push_back(toMsg(twist));
    }
  }
  if (want_markers && isDue(out->time_ns, last_markers_ns_, kCollisionMarkersFrequency)) {
    last_markers_ns_ = out->time_ns;
    out->has_markers = true;
    out->shapes = world_.collisionShapes();
  }
}

// Lock-step: holds the world until every lock-stepped joint has an effort acting in the coming
// step, giving up (and saying so once) on those silent for the timeout. Returns false when the wait
// ends for another reason (paused meanwhile, shutdown): the caller starts over.
bool GazeboApi::awaitControllers(std::unique_lock<std::mutex>& lock, StepOutput* out) {
  const auto began = Lockstep::Clock::now();
  const auto deadline = began + lockstep_.timeout();
  bool woken = false;
  for (;;) {
    const std::vector<Lockstep::Awaited> awaited = lockstep_.awaited(world_, world_.timeNs());
    if (awaited.empty()) return true;
    const auto now = Lockstep::Clock::now();
    if (now >= deadline) {
      lockstep_.giveUp(awaited);
      out->warnings.push_back(lockstepTimeoutText(awaited, world_.timeNs(), lockstep_.timeout()));
      return true;
    }
    // Woken when the awaited controllers have sent nothing for a while, here or before: one
    // still at work on its period (it asked for the joint) is left to finish it.
    const auto wake_at = std::max(began, lockstep_.lastRequest(awaited)) + kLockstepWakeAfter;
    if (!woken && now >= wake_at) {
      woken = true;
      showWakeUpClock(awaited);
    }
    // In slices, to notice a shutdown.
    auto until = std::min(deadline, now + std::chrono::milliseconds(50));
    if (!woken) until = std::min(until, wake_at);
    wake_loop_.wait_until(lock, until);
    if (!ros::ok()) return false;
    if (paused_ && !step_request_.active) return false;
  }
}

// roscpp's Rate (the book's C++ loop) and rospy's read the clock twice, before and after their
// sleep's start, and sleep for the remainder counted from the second reading. When the stop's
// clock lands between the two readings (a client preempted there, on a busy machine), or a
// command is lost in transport, the client sleeps one period past the stop, where the world waits
// for it: the clock is then shown at the next period's earliest end, the world staying where it
// is. The client wakes and commands for the stop (its job starts at the world's time, also when it
// names the time shown: applyJointEffort), then asks for the next period at once: that request
// waits for the next stop (WorldLock). The run is as if the client had woken on time.
void GazeboApi::showWakeUpClock(const std::vector<Lockstep::Awaited>& awaited) {
  const std::optional<int64_t> wake_ns = lockstep_.wakeTime(world_, world_.timeNs());
  if (!wake_ns || *wake_ns <= last_clock_ns_) return;
  publishClock(*wake_ns);
  clock_ahead_ns_ = *wake_ns;
  ROS_DEBUG_STREAM("lock-step: nothing from " << awaited.front().caller << " for "
                   << std::chrono::duration<double>(kLockstepWakeAfter).count()
                   << " s (wall) at sim time " << simSeconds(world_.timeNs())
                   << "; showing the clock at " << simSeconds(*wake_ns)
                   << " to wake a controller that slept past the stop");
}

void GazeboApi::publishClock(int64_t time_ns) {
  last_clock_ns_ = time_ns;
  held_clock_ns_ = -1;
  rosgraph_msgs::Clock clock;
  clock.clock.fromNSec(uint64_t(time_ns));
  clock_pub_.publish(clock);
}

void GazeboApi::publishHeldClock() {
  if (held_clock_ns_ >= 0) publishClock(held_clock_ns_);
}

void GazeboApi::publish(const StepOutput& out) {
  refreshClockFrequency();
  if (out.publish_clock) std::this_thread::sleep_until(out.clock_not_before);
  if (out.publish_clock ||
      (!out.hold_clock && isDue(out.time_ns, last_clock_ns_, clock_frequency_))) {
    // Latched, so roscpp wakes its poll thread for every message, subscribers or not: with
    // none, the latest time is only kept, and goes out where the loop stops (publishHeldClock).
    if (out.publish_clock || clock_pub_.getNumSubscribers() > 0) {
      publishClock(out.time_ns);
    } else {
      held_clock_ns_ = out.time_ns;
    }
  }
  for (const auto& publication : out.control_publications) publication();
  if (out.has_model_states) model_states_pub_.publish(out.model_states);
  if (out.has_link_states) link_states_pub_.publish(out.link_states);
  if (out.has_markers) {
    visualization_msgs::MarkerArray markers;
    // Clear first, so shapes of deleted models disappear.
    visualization_msgs::Marker clear;
    clear.header.frame_id = "world";
    clear.action = visualization_msgs::Marker::DELETEALL;
    markers.markers.push_back(clear);
    for (size_t i = 0; i < out.shapes.size(); ++i) {
      markers.markers.push_back(toMarker(out.shapes[i], int(i)));
    }
    markers_pub_.publish(markers);
  }
}

// pub_clock_frequency may be changed while running; reading it at every step would cost more
// than the step, so it is re-read ten times per wall second.
void GazeboApi::refreshClockFrequency() {
  const auto now = std::chrono::steady_clock::now();
  if (now < next_param_refresh_) return;
  next_param_refresh_ = now + std::chrono::milliseconds(100);
  double frequency = 0;
  if (!private_nh_.getParamCached("pub_clock_frequency", frequency) || !std::isfinite(frequency)) {
    frequency = 0;
  }
  clock_frequency_ = frequency;
}

// Sleeps until this step's absolute deadline (no drift: deadlines are origin + n periods).
void GazeboApi::pace(double max_update_rate, bool resumed) {
  using std::chrono::steady_clock;
  const auto now = steady_clock::now();
  if (max_update_rate <= 0) return;
  if (resumed) deadline_ = now;
  deadline_ += std::chrono::duration_cast<steady_clock::duration>(
      std::chrono::duration<double>(1.0 / max_update_rate));
  if (deadline_ > now) {
    // In slices: a new max_update_rate takes effect at once (run() re-paces from the next step),
    // and a shutdown (SIGINT) is noticed, however long the period.
    while (ros::ok() && steady_clock::now() < deadline_) {
      std::this_thread::sleep_until(std::min(deadline_, steady_clock::now() + kPacingSlice));
      std::lock_guard<std::mutex> lock(mutex_);
      if (max_update_rate_ != max_update_rate) return;
    }
  } else if (now - deadline_ > kMaxPacingLag) {
    deadline_ = now;  // far behind (a loaded machine): run on from now rather than race
  }
}

// --- joints ---------------------------------------------------------------------------------

bool GazeboApi::getJointProperties(
    ros::ServiceEvent<gazebo_msgs::GetJointProperties::Request, gazebo_msgs::GetJointProperties::Response>& event) {
  const auto& req = event.getRequest();
  auto& res = event.getResponse();
  JointInfo joint;
  Status found;
  {
    WorldLock lock(*this);
    found = world_.jointInfo(req.joint_name, &joint);
    if (lockstep_.enabled()) lockstep_.heardFrom(event.getCallerName(), Lockstep::Clock::now());
  }
  if (found.ok()) {
    res.type = toJointTypeConstant(joint.type);
    if (joint.has_damping) res.damping.push_back(joint.damping);
    res.position.push_back(joint.position);
    res.rate.push_back(joint.rate);
  }
  return answer(res, found, statusText(kGetJointProperties, found));
}

bool GazeboApi::applyJointEffort(
    ros::ServiceEvent<gazebo_msgs::ApplyJointEffort::Request, gazebo_msgs::ApplyJointEffort::Response>& event) {
  const auto& req = event.getRequest();
  auto& res = event.getResponse();
  JobOutcome job;
  Status applied;
  bool joined = false;
  {
    WorldLock lock(*this);
    if (lockstep_.enabled()) lockstep_.heardFrom(event.getCallerName(), Lockstep::Clock::now());
    // Under a wake-up clock a client's "now" is the time shown, ahead of the world's: it means
    // the world's.
    int64_t start_ns = toNs(req.start_time);
    if (clock_ahead_ns_ >= 0 && start_ns > world_.timeNs() && start_ns <= clock_ahead_ns_)
      start_ns = world_.timeNs();
    applied = world_.applyJointEffort(req.joint_name, req.effort, start_ns,
                                      toNs(req.duration), &job);
    if (applied.ok() && job.queued) {
      last_command_at_ = Lockstep::Clock::now();
      joined = lockstep_.heard(req.joint_name, event.getCallerName(),
                               req.duration < ros::Duration(0), world_.timeNs(),
                               toNs(req.duration));
      // The last awaited command: the world moves on, and the next request waits for the next
      // stop (WorldLock) even when it comes before the loop has taken its first step.
      const int64_t now_ns = world_.timeNs();
      if (!paused_ && lockstep_.running(world_, now_ns) && lockstep_.awaited(world_, now_ns).empty())
        between_stops_ = true;
    }
  }
  if (lockstep_.enabled()) wake_loop_.notify_all();
  if (joined) ROS_INFO_STREAM(lockstepJoinText(req.joint_name, event.getCallerName()));
  const std::string text = statusText(kApplyJointEffort, applied);
  return answer(res, applied, applied.ok() ? text + jobNotes(job) : text);
}

// Damping is served: World applies it as an effort, alike on every engine. The other fields are
// joint limits and ODE joint parameters, which the engines set when the model is spawned: a
// request that sets one is refused, naming it, and changes nothing.
bool GazeboApi::setJointProperties(gazebo_msgs::SetJointProperties::Request& req,
                                   gazebo_msgs::SetJointProperties::Response& res) {
  const auto& config = req.ode_joint_config;
  const std::pair<const char*, const std::vector<double>*> set_at_spawn[] = {
      {"hiStop", &config.hiStop},     {"loStop", &config.loStop},
      {"erp", &config.erp},           {"cfm", &config.cfm},
      {"stop_erp", &config.stop_erp}, {"stop_cfm", &config.stop_cfm},
      {"fudge_factor", &config.fudge_factor}, {"fmax", &config.fmax},
      {"vel", &config.vel}};
  JointInfo joint;
  Status status;
  {
    WorldLock lock(*this);
    status = world_.jointInfo(req.joint_name, &joint);
  }
  if (!status.ok()) return refuse(res, statusText(kSetJointProperties, status));
  for (const auto& field : set_at_spawn) {
    if (!field.second->empty()) {
      return refuse(res, std::string("SetJointProperties: ") + field.first +
                             " cannot be changed: the engines set joint limits and ODE joint "
                             "parameters when the model is spawned (damping can be changed)");
    }
  }
  if (config.damping.size() > 1) {
    std::ostringstream text;
    text << "SetJointProperties: damping has " << config.damping.size()
         << " values but joint '" << req.joint_name << "' has one axis";
    return refuse(res, text.str());
  }
  if (config.damping.empty()) return succeed(res, kSetJointProperties.done);
  {
    WorldLock lock(*this);
    status = world_.setJointDamping(req.joint_name, config.damping[0]);
  }
  if (status.code == StatusCode::JointIsFixed) {
    return refuse(res, "SetJointProperties: joint '" + status.subject + "' is fixed and has no "
                       "damping");
  }
  return answer(res, status, statusText(kSetJointProperties, status));
}

bool GazeboApi::clearJointForces(gazebo_msgs::JointRequest::Request& req, gazebo_msgs::JointRequest::Response&) {
  WorldLock lock(*this);
  world_.clearJointForces(req.joint_name);
  return true;
}

// --- links ----------------------------------------------------------------------------------

bool GazeboApi::applyBodyWrench(gazebo_msgs::ApplyBodyWrench::Request& req, gazebo_msgs::ApplyBodyWrench::Response& res) {
  JobOutcome job;
  Status applied;
  {
    WorldLock lock(*this);
    applied = world_.applyBodyWrench(req.body_name, req.reference_frame,
                                     toCore(req.reference_point), toCore(req.wrench.force),
                                     toCore(req.wrench.torque), toNs(req.start_time),
                                     toNs(req.duration), &job);
  }
  const std::string text = wrenchText(applied);
  return answer(res, applied,
                applied.ok() ? text + jobNotes(job, std::make_pair(toCore(req.wrench.force),
                                                                   toCore(req.wrench.torque)))
                             : text);
}

bool GazeboApi::clearBodyWrenches(gazebo_msgs::BodyRequest::Request& req, gazebo_msgs::BodyRequest::Response&) {
  WorldLock lock(*this);
  world_.clearBodyWrenches(req.body_name);
  return true;
}

bool GazeboApi::getLinkState(gazebo_msgs::GetLinkState::Request& req, gazebo_msgs::GetLinkState::Response& res) {
  Status state;
  Pose pose;
  Twist twist;
  {
    WorldLock lock(*this);
    state = world_.linkState(req.link_name, req.reference_frame, &pose, &twist);
  }
  if (state.ok()) {
    res.link_state.link_name = req.link_name;
    res.link_state.reference_frame = req.reference_frame;
    res.link_state.pose = toMsg(pose);
    res.link_state.twist = toMsg(twist);
  }
  return answer(res, state, statusText(kGetLinkState, state));
}

Status GazeboApi::applyLinkState(const gazebo_msgs::LinkState& state) {
  WorldLock lock(*this);
  return world_.setLinkState(state.link_name, toCore(state.pose), toCore(state.twist),
                             state.reference_frame);
}

bool GazeboApi::setLinkState(gazebo_msgs::SetLinkState::Request& req, gazebo_msgs::SetLinkState::Response& res) {
  const Status status = applyLinkState(req.link_state);
  return answer(res, status, statusText(kSetLinkState, status));
}

void GazeboApi::setLinkStateTopic(const gazebo_msgs::LinkState::ConstPtr& msg) {
  const Status status = applyLinkState(*msg);
  if (!status.ok()) ROS_WARN_STREAM(statusText(kSetLinkState, status));
}

bool GazeboApi::getLinkProperties(gazebo_msgs::GetLinkProperties::Request& req,
                                  gazebo_msgs::GetLinkProperties::Response& res) {
  LinkInfo link;
  Status found;
  {
    WorldLock lock(*this);
    found = world_.linkProperties(req.link_name, &link);
  }
  if (found.ok()) {
    res.com = toMsg(link.com);
    res.gravity_mode = link.gravity_mode;
    res.mass = link.mass;
    res.ixx = link.ixx;
    res.ixy = link.ixy;
    res.ixz = link.ixz;
    res.iyy = link.iyy;
    res.iyz = link.iyz;
    res.izz = link.izz;
  }
  return answer(res, found, statusText(kGetLinkProperties, found));
}

bool GazeboApi::setLinkProperties(gazebo_msgs::SetLinkProperties::Request& req,
                                  gazebo_msgs::SetLinkProperties::Response& res) {
  LinkInfo link;
  link.com = toCore(req.com);
  link.mass = req.mass;
  link.ixx = req.ixx, link.ixy = req.ixy, link.ixz = req.ixz;
  link.iyy = req.iyy, link.iyz = req.iyz, link.izz = req.izz;
  link.gravity_mode = req.gravity_mode;
  Status set;
  {
    WorldLock lock(*this);
    set = world_.setLinkProperties(req.link_name, link);
  }
  return answer(res, set, statusText(kSetLinkProperties, set));
}

// --- lights ---------------------------------------------------------------------------------

// There is no renderer, so the world has no lights: every name is one that does not exist, and
// the answer is Gazebo's for that case.
bool GazeboApi::getLightProperties(gazebo_msgs::GetLightProperties::Request& req,
                                   gazebo_msgs::GetLightProperties::Response& res) {
  return refuse(res, "getLightProperties: Requested light " + req.light_name + " not found!");
}

bool GazeboApi::setLightProperties(gazebo_msgs::SetLightProperties::Request& req,
                                   gazebo_msgs::SetLightProperties::Response& res) {
  return refuse(res, "setLightProperties: Requested light " + req.light_name + " not found!");
}

bool GazeboApi::deleteLight(gazebo_msgs::DeleteLight::Request& req,
                            gazebo_msgs::DeleteLight::Response& res) {
  return refuse(res, "DeleteLight: Requested light " + req.light_name + " not found!");
}

// --- models ---------------------------------------------------------------------------------

bool GazeboApi::spawnUrdfModel(gazebo_msgs::SpawnModel::Request& req, gazebo_msgs::SpawnModel::Response& res) {
  return spawnModel(ModelFormat::Urdf, req, res);
}

bool GazeboApi::spawnSdfModel(gazebo_msgs::SpawnModel::Request& req, gazebo_msgs::SpawnModel::Response& res) {
  return spawnModel(ModelFormat::Sdf, req, res);
}

// Gazebo's spawn services both take URDF or SDF (it converts URDF to SDF); so do we, by the
// root element. `requested` only names the service in log lines.
bool GazeboApi::spawnModel(ModelFormat requested, gazebo_msgs::SpawnModel::Request& req,
                           gazebo_msgs::SpawnModel::Response& res) {
  ModelFormat format = requested;
  const Status detected = detectModelFormat(req.model_xml, &format);
  if (!detected.ok()) {
    ROS_WARN_STREAM("SpawnModel: " << detected.subject);
    return refuse(res, kNotUrdfOrSdf);
  }
  Status spawned;
  {
    WorldLock lock(*this);
    spawned = world_.spawn(req.model_name, req.model_xml, format, toCore(req.initial_pose),
                           req.reference_frame);
  }
  if (spawned.ok()) {
    ROS_INFO_STREAM("spawned model '" << req.model_name << "' ("
                    << (format == ModelFormat::Urdf ? "URDF" : "SDF") << ") via "
                    << (requested == ModelFormat::Urdf ? "spawn_urdf_model" : "spawn_sdf_model"));
    if (format == ModelFormat::Urdf) startRobotControl(req.model_name, req.model_xml);
  }
  return answer(res, spawned, statusText(kSpawnModel, spawned));
}

control::LockWorld GazeboApi::lockWorld() {
  return [this] {
    WorldLock lock(*this);
    return std::move(lock.held());
  };
}

// The URDF is the spawned one, where gazebo_ros_control reads robot_description: the same robot
// when both come from one file, and no parameter to have set first.
void GazeboApi::startRobotControl(const std::string& model, const std::string& urdf) {
  control::RobotControlSpec spec;
  std::string error;
  if (!control::readRobotControlSpec(urdf, model, &spec, &error)) return;
  if (!error.empty()) {
    ROS_ERROR_STREAM("gazebo_ros_control for model '" << model << "' not started: " << error);
    return;
  }
  {
    WorldLock lock(*this);
    for (const auto& [other, running] : robot_controls_)
      if (running->robotNamespace() == spec.robot_namespace) {
        ROS_ERROR_STREAM("gazebo_ros_control for model '"
                         << model << "' not started: model '" << other
                         << "' already has the controller_manager in " << spec.robot_namespace
                         << "; give this one its own <robotNamespace>");
        return;
      }
  }
  // Its services are advertised unlocked (they talk to the master); it joins the step loop
  // only if the model is still there.
  auto control = std::make_unique<control::GazeboRosControl>(world_, model, spec, lockWorld());
  WorldLock lock(*this);
  ModelInfo unused;
  if (world_.modelProperties(model, &unused).ok()) robot_controls_[model] = std::move(control);
  else lock.held().unlock();  // deleted meanwhile: its services go, unlocked
}

bool GazeboApi::deleteModel(gazebo_msgs::DeleteModel::Request& req, gazebo_msgs::DeleteModel::Response& res) {
  Status deleted;
  std::unique_ptr<control::GazeboRosControl> control;
  std::vector<std::shared_ptr<void>> stopped;
  {
    WorldLock lock(*this);
    deleted = world_.deleteModel(req.model_name);
    auto found = robot_controls_.find(req.model_name);
    if (deleted.ok() && found != robot_controls_.end()) {
      stopped = found->second->stop(world_.timeNs());
      control = std::move(found->second);
      robot_controls_.erase(found);
    }
  }
  // Unlocked: its services and subscribers wait for their callbacks in flight, which may be
  // waiting for the world.
  stopped.clear();
  control.reset();
  return answer(res, deleted, statusText(kDeleteModel, deleted));
}

bool GazeboApi::getModelState(gazebo_msgs::GetModelState::Request& req, gazebo_msgs::GetModelState::Response& res) {
  Status state;
  Pose pose;
  Twist twist;
  int64_t now_ns = 0;
  {
    WorldLock lock(*this);
    now_ns = world_.timeNs();
    state = world_.modelState(req.model_name, req.relative_entity_name, &pose, &twist);
  }
  if (state.ok()) {
    res.header.stamp.fromNSec(uint64_t(now_ns));
    res.header.frame_id = req.relative_entity_name;
    res.pose = toMsg(pose);
    res.twist = toMsg(twist);
  }
  return answer(res, state, statusText(kGetModelState, state));
}

Status GazeboApi::applyModelState(const gazebo_msgs::ModelState& state) {
  WorldLock lock(*this);
  return world_.setModelState(state.model_name, toCore(state.pose), toCore(state.twist),
                              state.reference_frame);
}

bool GazeboApi::setModelState(gazebo_msgs::SetModelState::Request& req, gazebo_msgs::SetModelState::Response& res) {
  const Status status = applyModelState(req.model_state);
  return answer(res, status, statusText(kSetModelState, status));
}

void GazeboApi::setModelStateTopic(const gazebo_msgs::ModelState::ConstPtr& msg) {
  const Status status = applyModelState(*msg);
  if (!status.ok()) ROS_WARN_STREAM(statusText(kSetModelState, status));
}

// urdf_param_name is ignored, as Gazebo does: the model already knows its joints.
bool GazeboApi::setModelConfiguration(gazebo_msgs::SetModelConfiguration::Request& req,
                                      gazebo_msgs::SetModelConfiguration::Response& res) {
  Status set;
  {
    WorldLock lock(*this);
    set = world_.setModelConfiguration(req.model_name, req.joint_names, req.joint_positions);
  }
  return answer(res, set, configurationText(set));
}

bool GazeboApi::getModelProperties(gazebo_msgs::GetModelProperties::Request& req,
                                   gazebo_msgs::GetModelProperties::Response& res) {
  ModelInfo model;
  Status found;
  {
    WorldLock lock(*this);
    found = world_.modelProperties(req.model_name, &model);
  }
  if (found.ok()) {
    // Bare link names, as Gazebo answers (its srv comment says scoped, its code says bare).
    res.canonical_body_name = bareName(model.canonical_link);
    for (const auto& link : model.links) res.body_names.push_back(bareName(link));
    res.geom_names = model.geoms;
    res.joint_names = model.joints;
    res.is_static = model.is_static;
  }
  return answer(res, found, statusText(kGetModelProperties, found));
}

bool GazeboApi::getWorldProperties(gazebo_msgs::GetWorldProperties::Request&,
                                   gazebo_msgs::GetWorldProperties::Response& res) {
  {
    WorldLock lock(*this);
    res.sim_time = world_.time();
    res.model_names = world_.modelNames();
  }
  res.rendering_enabled = false;  // there is no renderer
  return succeed(res, "GetWorldProperties: got properties");
}

// --- physics --------------------------------------------------------------------------------

bool GazeboApi::getPhysicsProperties(gazebo_msgs::GetPhysicsProperties::Request&,
                                     gazebo_msgs::GetPhysicsProperties::Response& res) {
  PhysicsParams p;
  {
    WorldLock lock(*this);
    p = world_.params();
    res.pause = paused_;
    res.max_update_rate = max_update_rate_;
  }
  res.time_step = p.step;
  res.gravity = toVector3(p.gravity);
  auto& ode = res.ode_config;
  ode.auto_disable_bodies = p.auto_disable_bodies;
  ode.sor_pgs_precon_iters = p.sor_pgs_precon_iters;
  ode.sor_pgs_iters = p.sor_pgs_iters;
  ode.sor_pgs_w = p.sor_pgs_w;
  ode.sor_pgs_rms_error_tol = p.sor_pgs_rms_error_tol;
  ode.contact_surface_layer = p.contact_surface_layer;
  ode.contact_max_correcting_vel = p.contact_max_correcting_vel;
  ode.cfm = p.cfm;
  ode.erp = p.erp;
  ode.max_contacts = p.max_contacts;
  // The message has no engine field: the status names the engine.
  return succeed(res, "GetPhysicsProperties: got properties (engine: " + world_.engineName() + ")");
}

Status GazeboApi::applyPhysics(const PhysicsParams& params, double max_update_rate,
                               std::string* text) {
  const std::string rate_error = maxUpdateRateError(max_update_rate);
  if (!rate_error.empty()) {
    *text = "SetPhysicsProperties: " + rate_error;
    return {StatusCode::InvalidParameter, "max_update_rate"};
  }
  Status set;
  {
    WorldLock lock(*this);
    set = world_.setParams(params);
    if (set.ok()) max_update_rate_ = max_update_rate;
  }
  *text = statusText(kSetPhysicsProperties, set);
  if (set.ok()) parameter_updates_pub_.publish(physicsConfig());
  return set;
}

bool GazeboApi::setPhysicsProperties(gazebo_msgs::SetPhysicsProperties::Request& req,
                                     gazebo_msgs::SetPhysicsProperties::Response& res) {
  PhysicsParams p;
  {
    WorldLock lock(*this);
    p = world_.params();  // keeps what ODEPhysics can't say (quick_step)
  }
  p.step = req.time_step;
  p.gravity = toCore(req.gravity);
  const auto& ode = req.ode_config;
  p.auto_disable_bodies = ode.auto_disable_bodies;
  p.sor_pgs_precon_iters = ode.sor_pgs_precon_iters;
  p.sor_pgs_iters = ode.sor_pgs_iters;
  p.sor_pgs_w = ode.sor_pgs_w;
  p.sor_pgs_rms_error_tol = ode.sor_pgs_rms_error_tol;
  p.contact_surface_layer = ode.contact_surface_layer;
  p.contact_max_correcting_vel = ode.contact_max_correcting_vel;
  p.cfm = ode.cfm;
  p.erp = ode.erp;
  p.max_contacts = ode.max_contacts;
  std::string text;
  const Status set = applyPhysics(p, req.max_update_rate, &text);
  return answer(res, set, text);
}

dynamic_reconfigure::Config GazeboApi::physicsConfig() {
  WorldLock lock(*this);
  return toConfig({world_.params(), max_update_rate_});
}

// The parameters the request names change, the others keep their values; the reply is the
// configuration in force afterwards. Reconfigure has no status field, so a refusal (the same
// checks as set_physics_properties) is logged and the reply shows nothing changed.
bool GazeboApi::setParameters(dynamic_reconfigure::Reconfigure::Request& req,
                              dynamic_reconfigure::Reconfigure::Response& res) {
  PhysicsSettings settings;
  {
    WorldLock lock(*this);
    settings = {world_.params(), max_update_rate_};
  }
  for (const PhysicsField& field : kPhysicsFields)
    if (const std::optional<double> value = requested(req.config, field)) field.set(&settings, *value);
  std::string text;
  if (!applyPhysics(settings.params, settings.max_update_rate, &text).ok())
    ROS_WARN_STREAM("set_parameters: " << text);
  res.config = physicsConfig();
  return true;
}

bool GazeboApi::pausePhysics(std_srvs::Empty::Request&, std_srvs::Empty::Response&) {
  WorldLock lock(*this);
  paused_ = true;
  return true;
}

bool GazeboApi::unpausePhysics(std_srvs::Empty::Request&, std_srvs::Empty::Response&) {
  {
    WorldLock lock(*this);
    paused_ = false;
  }
  wake_loop_.notify_all();
  return true;
}

bool GazeboApi::stepSimulation(StepSimulation::Request& req, StepSimulation::Response& res) {
  WorldLock lock(*this);
  paused_ = true;
  step_request_ = {true, req.steps};
  wake_loop_.notify_all();
  while (step_request_.active && ros::ok())
    steps_done_.wait_for(lock.held(), std::chrono::milliseconds(100));
  res.sim_time.fromNSec(uint64_t(world_.timeNs()));
  res.iterations = world_.stepCount();
  if (step_request_.active) {
    step_request_ = {};
    return refuse(res, "StepSimulation: the simulator is shutting down");
  }
  std::ostringstream text;
  text << "StepSimulation: stepped " << req.steps << " steps to sim time " << simSeconds(world_.timeNs())
       << "; paused";
  return succeed(res, text.str());
}

bool GazeboApi::resetSimulation(std_srvs::Empty::Request&, std_srvs::Empty::Response&) {
  {
    WorldLock lock(*this);
    world_.resetSimulation();
    lockstep_.reset();
    between_stops_ = false;
    clock_ahead_ns_ = -1;
    for (auto& entry : robot_controls_) entry.second->reset();
  }
  wake_loop_.notify_all();
  return true;
}

bool GazeboApi::resetWorld(std_srvs::Empty::Request&, std_srvs::Empty::Response&) {
  WorldLock lock(*this);
  world_.resetWorld();
  for (auto& entry : robot_controls_) entry.second->reset();
  return true;
}

}  // namespace onedof_sim
