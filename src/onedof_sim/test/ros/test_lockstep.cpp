// Lock-step's rule (src/ros/lockstep.h) over a World, no roscore: which joints join, when the world
// waits for them, where the clock may be shown ahead, who is given up on, and the controllers'
// processes a stop's clock waits for.
#include <gtest/gtest.h>

#include <chrono>
#include <optional>
#include <string>
#include <vector>

#include "lockstep.h"

namespace onedof_sim {
namespace {

constexpr int64_t kMs = 1000000;  // ns

std::string link(const std::string& name) {
  return "<link name='" + name + "'><inertial><mass value='1'/><inertia ixx='0.01' iyy='0.01' "
         "izz='0.01' ixy='0' ixz='0' iyz='0'/></inertial></link>";
}

std::string joint(const std::string& name, const std::string& parent, const std::string& child) {
  return "<joint name='" + name + "' type='revolute'><parent link='" + parent +
         "'/><child link='" + child + "'/><axis xyz='0 0 1'/><limit lower='-3' upper='3' "
         "effort='100' velocity='10'/></joint>";
}

class LockstepTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string urdf = "<robot name='arm'>" + link("base") + link("l1") + link("l2") +
                             joint("j1", "base", "l1") + joint("j2", "l1", "l2") + "</robot>";
    const Status spawned = world_.spawn("arm", urdf, ModelFormat::Urdf, Pose{});
    ASSERT_TRUE(spawned.ok()) << spawned;
  }

  // A controller's command: an effort job of `period_ns` from `now_ns`, told to lock-step.
  bool command(Lockstep* lockstep, const std::string& joint, const std::string& caller,
               int64_t now_ns, int64_t period_ns) {
    EXPECT_TRUE(world_.applyJointEffort(joint, 1.0, now_ns, period_ns).ok());
    return lockstep->heard(joint, caller, false, now_ns, period_ns);
  }

  static std::vector<std::string> joints(const std::vector<Lockstep::Awaited>& awaited) {
    std::vector<std::string> out;
    for (const Lockstep::Awaited& a : awaited) out.push_back(a.joint + " by " + a.caller);
    return out;
  }

  World world_;
  Lockstep lockstep_{Lockstep::Options{true, std::chrono::seconds(5)}};
};

TEST_F(LockstepTest, OffItNeitherJoinsNorWaits) {
  Lockstep off(Lockstep::Options{});
  EXPECT_FALSE(off.enabled());
  EXPECT_FALSE(command(&off, "arm::j1", "/c", 10 * kMs, 10 * kMs));
  EXPECT_TRUE(off.awaited(world_, 30 * kMs).empty());
  EXPECT_FALSE(off.wakeTime(world_, 30 * kMs));
}

TEST_F(LockstepTest, AJointJoinsWithItsFirstCommandAfterTimeZeroAndIsWaitedForWhereItsEffortEnds) {
  // A command at time 0 does not make the world wait: ROS clients sleep a whole period first.
  EXPECT_FALSE(command(&lockstep_, "arm::j1", "/c1", 0, 10 * kMs));
  EXPECT_TRUE(lockstep_.awaited(world_, 10 * kMs).empty());
  // The next one joins (said once), and the world waits where its effort runs out.
  EXPECT_TRUE(command(&lockstep_, "arm::j1", "/c1", 20 * kMs, 10 * kMs));
  EXPECT_FALSE(command(&lockstep_, "arm::j1", "/c1", 20 * kMs, 10 * kMs));
  EXPECT_TRUE(lockstep_.running(world_, 25 * kMs));
  EXPECT_TRUE(lockstep_.awaited(world_, 25 * kMs).empty());
  EXPECT_EQ(joints(lockstep_.awaited(world_, 30 * kMs)),
            std::vector<std::string>{"arm::j1 by /c1"});
  EXPECT_FALSE(lockstep_.running(world_, 30 * kMs));
  // A job that lasts until cleared never runs out: it does not join.
  EXPECT_FALSE(lockstep_.heard("arm::j2", "/c2", true, 20 * kMs, -1));
  EXPECT_EQ(lockstep_.awaited(world_, 30 * kMs).size(), 1u);
}

TEST_F(LockstepTest, EachJointIsWaitedForOnItsOwnAndTheClockMayRunAheadByTheShortestPeriod) {
  command(&lockstep_, "arm::j1", "/c1", 10 * kMs, 10 * kMs);  // 100 Hz
  command(&lockstep_, "arm::j2", "/c2", 10 * kMs, 1 * kMs);   // 1 kHz
  EXPECT_EQ(joints(lockstep_.awaited(world_, 11 * kMs)),
            std::vector<std::string>{"arm::j2 by /c2"});
  // j1's controller is asleep until 20 ms: showing the clock ahead would wake it early.
  EXPECT_FALSE(lockstep_.wakeTime(world_, 11 * kMs));
  EXPECT_EQ(lockstep_.awaited(world_, 20 * kMs).size(), 2u);
  EXPECT_EQ(lockstep_.wakeTime(world_, 20 * kMs), std::optional<int64_t>(21 * kMs));
}

TEST_F(LockstepTest, AJointGivenUpOnIsLeftOutUntilItsNextCommand) {
  command(&lockstep_, "arm::j1", "/c1", 10 * kMs, 10 * kMs);
  lockstep_.giveUp(lockstep_.awaited(world_, 20 * kMs));
  EXPECT_TRUE(lockstep_.awaited(world_, 20 * kMs).empty());
  EXPECT_FALSE(lockstep_.wakeTime(world_, 20 * kMs));
  EXPECT_TRUE(command(&lockstep_, "arm::j1", "/c1", 25 * kMs, 10 * kMs));  // joins again
  EXPECT_EQ(lockstep_.awaited(world_, 35 * kMs).size(), 1u);
  // reset_simulation: every joint leaves.
  lockstep_.reset();
  EXPECT_TRUE(lockstep_.awaited(world_, 35 * kMs).empty());
}

TEST_F(LockstepTest, AJointOfNoModelInTheWorldHoldsNothingUp) {
  EXPECT_TRUE(lockstep_.heard("gone::j", "/c", false, 10 * kMs, 10 * kMs));
  EXPECT_TRUE(lockstep_.awaited(world_, 30 * kMs).empty());
  EXPECT_FALSE(lockstep_.wakeTime(world_, 30 * kMs));
  command(&lockstep_, "arm::j1", "/c1", 10 * kMs, 10 * kMs);
  ASSERT_TRUE(world_.deleteModel("arm").ok());
  EXPECT_TRUE(lockstep_.awaited(world_, 30 * kMs).empty());
}

TEST_F(LockstepTest, KeepsTheControllersProcessesAndTheirLatestRequests) {
  command(&lockstep_, "arm::j1", "/c1", 10 * kMs, 10 * kMs);
  command(&lockstep_, "arm::j2", "/c2", 10 * kMs, 10 * kMs);
  const ProcessRuns runs{{4242, 17}, {4243, 5}};
  lockstep_.commandedFrom("/c1", 4242, runs);
  lockstep_.commandedFrom("/c2", std::nullopt, {});  // on another machine
  const std::vector<Lockstep::Watched> watched = lockstep_.watched(world_);
  ASSERT_EQ(watched.size(), 1u);
  EXPECT_EQ(watched[0].caller, "/c1");
  EXPECT_EQ(watched[0].pid, 4242);
  ASSERT_EQ(watched[0].runs_at_command.size(), 2u);
  EXPECT_EQ(watched[0].runs_at_command[0].tid, 4242);
  EXPECT_EQ(watched[0].runs_at_command[0].runs, 17u);
  EXPECT_EQ(watched[0].runs_at_command[1].runs, 5u);
  EXPECT_TRUE(lockstep_.someUnwatched(world_));
  EXPECT_EQ(lockstep_.pidOf("/c1"), std::optional<int>(4242));
  EXPECT_FALSE(lockstep_.pidOf("/nobody"));
  lockstep_.commandedFrom("/c2", 4242, {{4242, 3}});  // one process, two joints: watched once
  EXPECT_EQ(lockstep_.watched(world_).size(), 1u);
  EXPECT_FALSE(lockstep_.someUnwatched(world_));

  const Lockstep::Clock::time_point t0 = Lockstep::Clock::now();
  lockstep_.heardFrom("/c1", t0);
  lockstep_.heardFrom("/c2", t0 + std::chrono::milliseconds(5));
  const auto awaited = lockstep_.awaited(world_, 20 * kMs);
  EXPECT_EQ(lockstep_.lastRequest(awaited), t0 + std::chrono::milliseconds(5));
  EXPECT_EQ(lockstep_.lastRequest({{"arm::j1", "/c1"}}), t0);
  EXPECT_EQ(lockstep_.lastRequest({}), Lockstep::Clock::time_point());
}

}  // namespace
}  // namespace onedof_sim
