// The ROS layer's wording of the core's codes (src/ros/status_text.h), no roscore: Gazebo's texts
// where Gazebo refuses the same input, ours (the service's name first) where it would not, and
// the notes and log lines of jobs, step requests and lock-step.
#include <gtest/gtest.h>

#include <chrono>
#include <string>
#include <vector>

#include "status_text.h"

namespace onedof_sim {
namespace {

Status status(StatusCode code, const std::string& subject = "", double min = 0, double max = 0) {
  Status s;
  s.code = code;
  s.subject = subject;
  s.min = min;
  s.max = max;
  return s;
}

TEST(StatusText, SuccessAndLookupsAreGazebosTexts) {
  EXPECT_EQ(statusText(kSpawnModel, {}), "SpawnModel: Successfully spawned entity");
  EXPECT_EQ(statusText(kSetPhysicsProperties, {}), "physics engine updated");
  EXPECT_EQ(statusText(kSpawnModel, status(StatusCode::ModelExists, "m")),
            "SpawnModel: Failure - entity already exists.");
  EXPECT_EQ(statusText(kApplyBodyWrench, status(StatusCode::LinkNotFound, "m::l")),
            "ApplyBodyWrench: body does not exist");
  EXPECT_EQ(statusText(kGetLinkState, status(StatusCode::ReferenceFrameNotFound, "x")),
            "GetLinkState: reference reference_frame not found, did you forget to scope the link "
            "by model name?");
  // A service with no text of Gazebo's for it: the common one, after the service's name.
  EXPECT_EQ(statusText(kGetJointProperties, status(StatusCode::JointNotFound, "j")),
            "GetJointProperties: joint not found");
  EXPECT_EQ(statusText(kGetModelProperties, status(StatusCode::ModelNotFound, "m")),
            "GetModelProperties: model does not exist");
  EXPECT_EQ(statusText(kDeleteModel, status(StatusCode::ReferenceFrameNotFound, "f")),
            "DeleteModel: reference frame 'f' not found");
}

TEST(StatusText, OurRefusalsNameTheServiceAndTheField) {
  EXPECT_EQ(statusText(kApplyJointEffort, status(StatusCode::NotFinite, "effort")),
            "ApplyJointEffort: effort is not finite");
  EXPECT_EQ(statusText(kSetModelState, status(StatusCode::NotFinite)),
            "SetModelState: pose and twist must be finite");
  EXPECT_EQ(statusText(kApplyJointEffort, status(StatusCode::JointIsFixed, "m::j")),
            "ApplyJointEffort: joint 'm::j' is fixed and takes no effort");
  EXPECT_EQ(statusText(kSetPhysicsProperties, status(StatusCode::OutOfRange, "step", 1e-6, 0.1)),
            "SetPhysicsProperties: time_step must be in [1e-06, 0.1] s");
  EXPECT_EQ(statusText(kSetModelState, status(StatusCode::OutOfRange, "twist.angular", 0, 500)),
            "SetModelState: the speed |twist.angular| must be at most 500 rad/s, the most the "
            "world lets a model move at this time_step");
  EXPECT_EQ(statusText(kSetLinkProperties, status(StatusCode::InvalidParameter, "damping")),
            "SetLinkProperties: damping must be >= 0");
  EXPECT_EQ(statusText(kSpawnModel, status(StatusCode::InvalidModelName, "a::b")),
            "SpawnModel: model name 'a::b' is refused: a name may not hold \"::\" (it scopes a "
            "link: model::link) nor be \"world\" (the world frame)");
  EXPECT_EQ(statusText(kApplyJointEffort, status(StatusCode::TooManyJobs, "m::j", 0, 1000)),
            "ApplyJointEffort: 'm::j' already has 1000 jobs pending, the most it takes; clear "
            "them or wait until some end");
  EXPECT_EQ(wrenchText(status(StatusCode::LinkAnchored, "m::base")),
            "ApplyBodyWrench: body 'm::base' is anchored to the world");
  EXPECT_EQ(configurationText(status(StatusCode::JointNotFound, "j9")),
            "SetModelConfiguration: joint 'j9' not found in model");
  EXPECT_EQ(configurationText(status(StatusCode::OutOfRange, "j1", -1, 1)),
            "SetModelConfiguration: the position of joint 'j1' must be in [-1, 1] (rad or m)");
}

TEST(StatusText, JobNotesSayWhatBecameOfTheJob) {
  JobOutcome nothing;
  nothing.queued = false;
  EXPECT_EQ(jobNotes(nothing), "; duration is 0, so nothing was applied");
  EXPECT_EQ(jobNotes(JobOutcome{}), "");
  JobOutcome clamped;
  clamped.widened_to_one_step = true;
  clamped.effort_limit = 10;
  EXPECT_EQ(jobNotes(clamped),
            "; duration is shorter than the step, so it acts for exactly one step; clamped to the "
            "joint's effort limit 10");
  JobOutcome wrench;
  wrench.safe_wrench = JobOutcome::WrenchBound{100, 5};
  EXPECT_EQ(jobNotes(wrench, std::make_pair(Vec3{0, 0, 500}, Vec3{1, 0, 0})),
            "; force clamped to |force| 100 N (same direction), the most this body takes without "
            "the simulation blowing up");
  EXPECT_EQ(jobNotes(wrench, std::make_pair(Vec3{0, 0, 500}, Vec3{0, 0, 6})),
            "; force clamped to |force| 100 N and torque clamped to |torque| 5 N m (same "
            "direction), the most this body takes without the simulation blowing up");
}

TEST(StatusText, StepRequestsAndLockStepLines) {
  EXPECT_EQ(simSeconds(1234567890), "1.235 s");
  EXPECT_EQ(stepsOverLimitText(2000000, 1000000, 0.001),
            "StepSimulation: steps is 2000000, more than the 1000000 one request takes (1000 s of "
            "sim time at this time_step); ask again for the rest, or unpause_physics");
  EXPECT_EQ(stepsEndedText("pause_physics", 3, 10, 5000000),
            "StepSimulation: pause_physics ended the request after 3 of 10 steps, at sim time "
            "0.005 s");
  EXPECT_EQ(lockstepJoinText("arm::joint1", "/controller"),
            "lock-step: arm::joint1 is commanded by /controller; from now on the world stops "
            "where its effort runs out and waits for its next apply_joint_effort");
  const std::vector<Lockstep::Awaited> awaited{{"a::j1", "/c1"}, {"a::j2", "/c2"}};
  EXPECT_EQ(lockstepTimeoutText(awaited, 2500000000, std::chrono::seconds(5)),
            "lock-step: the world waited 5 s (wall) at sim time 2.500 s for apply_joint_effort "
            "on a::j1 (last commanded by /c1) a::j2 (last commanded by /c2); going on without "
            "them until commanded again (~lockstep_timeout sets the wait)");
  EXPECT_EQ(lockstepPeriodOverNote(10000000),
            "; lock-step: its period (start_time + duration) was over at sim time 0.010 s, where "
            "the world is, so nothing was applied; the world waits for the command of the period "
            "under way");
  const std::string stopped =
      engineStoppedText(status(StatusCode::EngineFaultUnattributed, "dxJoint"));
  EXPECT_NE(stopped.find("(dxJoint)"), std::string::npos) << stopped;
  EXPECT_NE(stopped.find("physics is paused where that step started"), std::string::npos);
  EXPECT_EQ(statusText(kSpawnModel, status(StatusCode::EngineFaultUnattributed, "dxJoint")),
            stopped);
}

}  // namespace
}  // namespace onedof_sim
