// Gazebo's wording (gazebo_ros_api_plugin.cpp) of what the world says: the core returns codes
// and facts, this is where they become the texts a service answers and the node logs.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <ros/console.h>

#include <onedof_sim/world.h>

#include "lockstep.h"

namespace onedof_sim {

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

inline const Wording kGetJointProperties{"GetJointProperties", "GetJointProperties: got properties"};
inline const Wording kSetJointProperties{"SetJointProperties", "SetJointProperties: properties set"};
inline const Wording kApplyJointEffort{"ApplyJointEffort", "ApplyJointEffort: effort set",
                                "effort is not finite"};
// Gazebo answers "" on success: ours says what became of the job.
inline const Wording kApplyBodyWrench{"ApplyBodyWrench", "ApplyBodyWrench: wrench set",
                               "reference_point and wrench must be finite",
                               "ApplyBodyWrench: body does not exist",
                               "ApplyBodyWrench: reference_frame not found"};
inline const Wording kGetLinkState{
    "GetLinkState", "GetLinkState: got state", "values must be finite", nullptr,
    "GetLinkState: reference reference_frame not found, did you forget to scope the link by "
    "model name?"};
inline const Wording kSetLinkState{"SetLinkState", "SetLinkState: success",
                            "pose and twist must be finite", "SetLinkState: link does not exist",
                            "SetLinkState: failed"};
inline const Wording kGetLinkProperties{"GetLinkProperties", "GetLinkProperties: got properties"};
inline const Wording kSetLinkProperties{"SetLinkProperties", "SetLinkProperties: properties set",
                                 "mass, com and the inertia must be finite"};
inline const Wording kSpawnModel{
    "SpawnModel", "SpawnModel: Successfully spawned entity", "initial_pose must be finite",
    nullptr,
    "SpawnModel: reference reference_frame not found, did you forget to scope the link by model "
    "name?"};
inline const Wording kDeleteModel{"DeleteModel", "DeleteModel: successfully deleted model"};
// Ours (srv/ResetModel.srv): no Gazebo service resets one model.
inline const Wording kResetModel{"ResetModel", "ResetModel: model back at its spawn pose"};
inline const Wording kGetModelState{
    "GetModelState", "GetModelState: got properties", "values must be finite", nullptr,
    "GetModelState: reference relative_entity_name not found, did you forget to scope the body "
    "by model name?"};
inline const Wording kSetModelState{"SetModelState", "SetModelState: set model state done",
                             "pose and twist must be finite", nullptr,
                             "SetModelState: specified reference frame entity does not exist"};
inline const Wording kSetModelConfiguration{"SetModelConfiguration", "SetModelConfiguration: success",
                                     "joint_positions must be finite"};
inline const Wording kGetModelProperties{"GetModelProperties", "GetModelProperties: got properties"};
inline const Wording kSetPhysicsProperties{"SetPhysicsProperties", "physics engine updated"};

// Gazebo's answer to model_xml that is neither URDF nor SDF (not even XML); the node logs why.
inline const char* const kNotUrdfOrSdf =
    "GazeboRosApiPlugin SpawnModel Failure: input model_xml not SDF or URDF, or cannot be "
    "converted to Gazebo compatible format.";

std::string statusText(const Wording& wording, const Status& status);
// A body taken with an inertia implausible for its shapes (spawn, set_link_properties): the
// warning the reply carries after its success text and the node logs.
std::string inertiaWarningText(const InertiaWarning& warning);
// ApplyBodyWrench calls a link a body.
std::string wrenchText(const Status& status);
// Gazebo sets the joints it finds and ignores the others; we refuse, naming the joint.
std::string configurationText(const Status& status);

// What a job became, after the service's "effort set" or "wrench set". For a wrench, the force
// and torque asked for (requested_wrench): each is named only if it was clamped.
std::string jobNotes(const JobOutcome& job,
                     const std::optional<std::pair<Vec3, Vec3>>& requested_wrench = {});

// The step loop's log line when the world stopped on an engine failure it could not pin on a
// model (StatusCode::EngineFaultUnattributed).
std::string engineStoppedText(const Status& status);

// step_simulation's refusal of more steps than a request takes, and its answer when another
// request (pause_physics, ...) ended it after `taken` of `asked` steps.
std::string stepsOverLimitText(uint64_t asked, uint64_t most, double time_step);
std::string stepsEndedText(const char* ended_by, uint64_t taken, uint64_t asked, int64_t time_ns);

// Sim time for a log line: "1.234 s".
std::string simSeconds(int64_t ns);
std::string lockstepJoinText(const std::string& joint, const std::string& caller);
std::string lockstepTimeoutText(const std::vector<Lockstep::Awaited>& awaited, int64_t t_ns,
                                Lockstep::Clock::duration timeout);
// A lock-stepped command whose period had ended where the world is (at now_ns).
std::string lockstepPeriodOverNote(int64_t now_ns);
std::string lockstepBusyText(const std::string& caller, int pid, Lockstep::Clock::duration waited);
std::string lockstepExitedText(const std::string& caller, int pid,
                               const std::vector<Lockstep::Awaited>& joints, int64_t t_ns);
std::string lockstepUnwatchedExitText(const std::string& caller, int pid, int error,
                                      Lockstep::Clock::duration timeout);

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

}  // namespace onedof_sim
