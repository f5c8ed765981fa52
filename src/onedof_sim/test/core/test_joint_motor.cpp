// World::setJointVelocityCommand, on every engine of the registry: the engine's joint motor
// drives a joint's rate to the command with at most the bound (held within the joint's effort
// limit), for the step it was set for only.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "onedof_sim/world.h"

namespace onedof_sim {
namespace {

constexpr double kStep = 0.001;

// A disc (10 kg, radius 0.3 m: 0.45 kg m^2 about its axis) on a vertical continuous joint, and a
// 2 kg box on a horizontal slider, both on a base welded to the world. `effort_limit` is the
// disc joint's <limit effort>.
std::string motorRig(double effort_limit) {
  return R"(<robot name="rig">
  <link name="world"/>
  <link name="base"><inertial><mass value="1"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
  <joint name="weld" type="fixed"><parent link="world"/><child link="base"/>
    <origin xyz="0 0 1"/></joint>
  <link name="disc">
    <collision><geometry><cylinder radius="0.3" length="0.05"/></geometry></collision>
    <inertial><mass value="10"/>
      <inertia ixx="0.227" ixy="0" ixz="0" iyy="0.227" iyz="0" izz="0.45"/></inertial></link>
  <joint name="spin" type="continuous"><parent link="base"/><child link="disc"/>
    <axis xyz="0 0 1"/><limit effort=")" + std::to_string(effort_limit) + R"(" velocity="100"/></joint>
  <link name="block">
    <collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision>
    <inertial><mass value="2"/>
      <inertia ixx="0.0034" ixy="0" ixz="0" iyy="0.0034" iyz="0" izz="0.0034"/></inertial></link>
  <joint name="slide" type="prismatic"><parent link="base"/><child link="block"/>
    <origin xyz="0 1 0"/><axis xyz="1 0 0"/>
    <limit lower="-100" upper="100" effort="1000" velocity="100"/></joint>
</robot>)";
}

class JointMotor : public ::testing::TestWithParam<std::string> {
 protected:
  void SetUp() override {
    PhysicsParams params;
    params.step = kStep;
    world_ = std::make_unique<World>(GetParam(), params);
  }
  void spawnRig(double effort_limit = 1000) {
    ASSERT_TRUE(world_->spawn("rig", motorRig(effort_limit), ModelFormat::Urdf, Pose()).ok());
  }
  double rate(const std::string& joint) {
    JointInfo info;
    EXPECT_TRUE(world_->jointInfo(joint, &info).ok());
    return info.rate;
  }
  // `steps` steps, the motor set before each.
  void drive(const std::string& joint, double velocity, double max_effort, int steps) {
    for (int i = 0; i < steps; ++i) {
      ASSERT_TRUE(world_->setJointVelocityCommand(joint, velocity, max_effort).ok());
      world_->step();
    }
  }
  std::unique_ptr<World> world_;
};

TEST_P(JointMotor, ReachesTheCommandedRateWhenItsBoundSuffices) {
  spawnRig();
  drive("spin", 2.0, 100, 10);
  EXPECT_NEAR(rate("spin"), 2.0, 1e-3);
  drive("slide", -0.3, 1000, 10);
  EXPECT_NEAR(rate("slide"), -0.3, 1e-3);
  EXPECT_NEAR(rate("spin"), 2.0, 1e-3);  // a motor released coasts: no friction in this rig
}

TEST_P(JointMotor, PushesWithNoMoreThanItsBound) {
  spawnRig();
  // 0.45 N m on 0.45 kg m^2: 1 rad/s^2, so 0.5 rad/s after 0.5 s on the way to 5 rad/s.
  drive("spin", 5.0, 0.45, 500);
  EXPECT_NEAR(rate("spin"), 0.5, 0.01);
  // 4 N on 2 kg: 2 m/s^2 towards -1 m/s.
  drive("slide", -1.0, 4, 250);
  EXPECT_NEAR(rate("slide"), -0.5, 0.01);
}

TEST_P(JointMotor, BoundIsHeldWithinTheJointsEffortLimit) {
  spawnRig(0.45);
  drive("spin", 5.0, 100, 500);
  EXPECT_NEAR(rate("spin"), 0.5, 0.01);
}

TEST_P(JointMotor, ActsForTheStepItWasSetForOnly) {
  spawnRig();
  drive("spin", 1.0, 0.45, 200);  // 0.2 rad/s
  const double released = rate("spin");
  for (int i = 0; i < 200; ++i) world_->step();
  EXPECT_NEAR(rate("spin"), released, 1e-6);
  EXPECT_NEAR(released, 0.2, 0.01);
}

TEST_P(JointMotor, StopsAJointAgainstAnEffort) {
  spawnRig();
  drive("spin", 2.0, 100, 10);
  // A motor at 0 with a bound above the effort stops the joint (a brake): (10 - 5) N m on
  // 0.45 kg m^2 takes 2 rad/s to rest in 0.18 s, and holds it there.
  for (int i = 0; i < 300; ++i) {
    ASSERT_TRUE(world_->setJointEffortCommand("spin", 5.0).ok());
    ASSERT_TRUE(world_->setJointVelocityCommand("spin", 0.0, 10).ok());
    world_->step();
  }
  EXPECT_NEAR(rate("spin"), 0.0, 1e-3);
}

TEST_P(JointMotor, RefusesWhatNoMotorCanBe) {
  spawnRig();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(world_->setJointVelocityCommand("nope", 1, 1).code, StatusCode::JointNotFound);
  EXPECT_EQ(world_->setJointVelocityCommand("weld", 1, 1).code, StatusCode::JointIsFixed);
  Status status = world_->setJointVelocityCommand("spin", nan, 1);
  EXPECT_EQ(status.code, StatusCode::NotFinite);
  EXPECT_EQ(status.subject, "velocity");
  status = world_->setJointVelocityCommand("spin", 1, nan);
  EXPECT_EQ(status.code, StatusCode::NotFinite);
  EXPECT_EQ(status.subject, "max_effort");
  status = world_->setJointVelocityCommand("spin", 1, -1);
  EXPECT_EQ(status.code, StatusCode::InvalidParameter);
  EXPECT_EQ(status.subject, "max_effort");
  status = world_->setJointVelocityCommand("spin", 1e6, 1);
  EXPECT_EQ(status.code, StatusCode::OutOfRange);
  EXPECT_EQ(status.subject, "velocity");
  status = world_->setJointVelocityCommand("slide", 1e6, 1);
  EXPECT_EQ(status.code, StatusCode::OutOfRange);
  // Nothing refused acted: the joints are at rest after a step.
  world_->step();
  EXPECT_EQ(rate("spin"), 0.0);
}

INSTANTIATE_TEST_SUITE_P(Engines, JointMotor, ::testing::ValuesIn(World::engineNames()),
                         [](const auto& info) { return info.param; });

}  // namespace
}  // namespace onedof_sim
