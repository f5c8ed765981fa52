#include "status_text.h"

#include <chrono>
#include <cmath>
#include <cstring>
#include <sstream>

#include "conversions.h"

namespace onedof_sim {
namespace {

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
    text << "the principal moments of inertia of the link's body must be in ";
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

}  // namespace

std::string inertiaWarningText(const InertiaWarning& warning) {
  std::ostringstream text;
  text << "link '" << warning.link << "' (with the links welded to it) has a smallest principal "
       << "moment of inertia of " << warning.smallest_moment << " kg m^2, implausibly small for "
       << "its collision shape (realistic: at least " << warning.least_moment
       << " kg m^2): a push at its edge turns it more than 1000 times as fast as it moves it, "
          "which a physics engine may fail on (ODE) or let sink through the ground (Bullet); a "
          "step that fails is taken again, and failing that the model is removed (give the link "
          "realistic inertia)";
  return text.str();
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
    case StatusCode::CollisionNotFound:
      text = "collision '" + subject + "' not found (a collision is scoped model::link::collision)";
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
    // Not reached over ROS: toCore reads an all-zero quaternion as the identity, as Gazebo does.
    case StatusCode::ZeroQuaternion: text = "the orientation quaternion is zero"; break;
    case StatusCode::QuaternionOverflow:
      text = "the orientation quaternion cannot be normalised: its norm is not finite (a component "
             "is too large; the sum of its squares overflows a double)";
      break;
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
    case StatusCode::EngineFault:
      text = "the physics engine failed (" + subject + "); the request was taken back and the "
             "world goes on without it";
      break;
    case StatusCode::EngineFaultUnattributed: return engineStoppedText(status);
  }
  return std::string(wording.service) + ": " + text;
}

std::string wrenchText(const Status& status) {
  if (status.code == StatusCode::LinkAnchored)
    return "ApplyBodyWrench: body '" + status.subject + "' is anchored to the world";
  return statusText(kApplyBodyWrench, status);
}

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

std::string jobNotes(const JobOutcome& job,
                     const std::optional<std::pair<Vec3, Vec3>>& requested_wrench) {
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

std::string lockstepPeriodOverNote(int64_t now_ns) {
  return "; lock-step: its period (start_time + duration) was over at sim time " +
         simSeconds(now_ns) + ", where the world is, so nothing was applied; the world waits for "
         "the command of the period under way";
}

std::string lockstepBusyText(const std::string& caller, int pid, Lockstep::Clock::duration waited) {
  std::ostringstream text;
  text << "lock-step: the process of " << caller << " (pid " << pid << ") did not rest for "
       << std::chrono::duration<double>(waited).count()
       << " s (wall) after its command (a thread of it never blocks); its stops' clock goes out "
          "without waiting for it to sleep, so on a busy machine it may sleep past a stop";
  return text.str();
}

std::string lockstepExitedText(const std::string& caller, int pid,
                               const std::vector<Lockstep::Awaited>& joints, int64_t t_ns) {
  std::ostringstream text;
  text << "lock-step: the process of " << caller << " (pid " << pid
       << ") has exited; the world goes on at sim time " << simSeconds(t_ns) << " without";
  for (const Lockstep::Awaited& joint : joints) text << " " << joint.joint;
  text << " until commanded again";
  return text.str();
}

std::string lockstepUnwatchedExitText(const std::string& caller, int pid, int error,
                                      Lockstep::Clock::duration timeout) {
  std::ostringstream text;
  text << "lock-step: cannot watch the process of " << caller << " (pid " << pid
       << ") for its exit (pidfd_open: " << std::strerror(error)
       << "); if it exits, the world waits for it "
       << std::chrono::duration<double>(timeout).count() << " s (wall, ~lockstep_timeout)";
  return text.str();
}

std::string stepsOverLimitText(uint64_t asked, uint64_t most, double time_step) {
  std::ostringstream text;
  text << "StepSimulation: steps is " << asked << ", more than the " << most
       << " one request takes (" << double(most) * time_step
       << " s of sim time at this time_step); ask again for the rest, or unpause_physics";
  return text.str();
}

std::string engineStoppedText(const Status& status) {
  return "the physics engine failed inside a step, with its fallback solver too (" +
         status.subject + "), and cannot tell which model made it fail: no model was removed, "
         "and physics is paused where that step started. Move or delete the model that ran into "
         "trouble, or reset the world, then unpause physics";
}

std::string stepsEndedText(const char* ended_by, uint64_t taken, uint64_t asked, int64_t time_ns) {
  std::ostringstream text;
  text << "StepSimulation: " << ended_by << " ended the request after " << taken << " of " << asked
       << " steps, at sim time " << simSeconds(time_ns);
  return text.str();
}

}  // namespace onedof_sim
