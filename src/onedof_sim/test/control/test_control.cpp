// The in-simulator controllers without ROS: control_toolbox's Pid formulas, the transmissions
// and plugin tag, and the tutorial arm held by effort_controllers/JointPositionController on the
// World (closed form: with i = 0 the P-D static balance; with the integral, the command).
#include <gtest/gtest.h>

#include <cmath>

#include "onedof_sim/world.h"
#include "controllers.h"
#include "pid.h"
#include "robot_hw_sim.h"
#include "control_test_support.h"

namespace onedof_sim::control {
namespace {

using namespace testing_support;

constexpr double kDt = 0.001;

TEST(Pid, ProportionalIntegralDerivativeAsControlToolbox) {
  PidGains gains;
  gains.p = 2;
  gains.i = 3;
  gains.d = 0.5;
  gains.i_max = 100;
  gains.i_min = -100;
  Pid pid(gains);
  // First call: the derivative of the error from 0; the integral dt * e.
  EXPECT_DOUBLE_EQ(pid.computeCommand(1.0, kDt), 2 * 1.0 + 3 * (kDt * 1.0) + 0.5 * (1.0 / kDt));
  // Second: integral sums dt * e, derivative (e - e_last) / dt.
  EXPECT_DOUBLE_EQ(pid.computeCommand(0.5, kDt),
                   2 * 0.5 + 3 * (kDt * 1.5) + 0.5 * ((0.5 - 1.0) / kDt));
  // dt 0 and non-finite errors command nothing and keep the state.
  EXPECT_EQ(pid.computeCommand(1.0, 0.0), 0.0);
  EXPECT_EQ(pid.computeCommand(NAN, kDt), 0.0);
  EXPECT_DOUBLE_EQ(pid.integralError(), kDt * 1.5);
  pid.reset();
  EXPECT_EQ(pid.integralError(), 0.0);
}

TEST(Pid, IntegralTermClampedWithoutAntiwindupIntegralClampedWith) {
  PidGains gains;
  gains.i = 10;
  gains.i_max = 1;
  gains.i_min = -1;
  Pid plain(gains);
  for (int k = 0; k < 1000; ++k) plain.computeCommand(1.0, kDt);
  EXPECT_DOUBLE_EQ(plain.computeCommand(1.0, kDt), 1.0);  // the term at its clamp
  EXPECT_NEAR(plain.integralError(), 1.001, 1e-9);        // the integral wound up
  gains.antiwindup = true;
  Pid held(gains);
  for (int k = 0; k < 1000; ++k) held.computeCommand(1.0, kDt);
  EXPECT_DOUBLE_EQ(held.integralError(), 0.1);  // i_max / |i|
}

TEST(Pid, GainsReadAsPidInit) {
  MapParams params;
  PidGains gains;
  std::string error;
  EXPECT_FALSE(readPidGains(params, "/r/c/pid", &gains, &error));
  EXPECT_NE(error.find("No p gain specified for pid"), std::string::npos) << error;
  params.numbers = {{"/r/c/pid/p", 10}, {"/r/c/pid/i_clamp", 4}};
  ASSERT_TRUE(readPidGains(params, "/r/c/pid", &gains, &error)) << error;
  EXPECT_EQ(gains.i, 0);
  EXPECT_EQ(gains.d, 0);
  EXPECT_EQ(gains.i_max, 4);
  EXPECT_EQ(gains.i_min, -4);
  // i_clamp_min/max over i_clamp, signs forced.
  params.numbers["/r/c/pid/i_clamp_min"] = 2;
  params.numbers["/r/c/pid/i_clamp_max"] = -3;
  ASSERT_TRUE(readPidGains(params, "/r/c/pid", &gains, &error));
  EXPECT_EQ(gains.i_min, -2);
  EXPECT_EQ(gains.i_max, 3);
}

TEST(PositionError, ShortestWayForContinuousWithinLimitsForRevolute) {
  SimJoint joint;
  const JointStateHandle handle(joint);
  joint.type = JointType::Continuous;
  joint.position = 3.0;
  EXPECT_NEAR(positionError(handle, -3.0), 2 * M_PI - 6.0, 1e-12);
  joint.type = JointType::Revolute;
  joint.has_limits = true;
  joint.lower = -3.1;
  joint.upper = 3.1;
  EXPECT_NEAR(positionError(handle, -3.0), -6.0, 1e-12);  // the short way crosses the limit
  joint.type = JointType::Prismatic;
  EXPECT_DOUBLE_EQ(positionError(handle, -3.0), -6.0);
}

TEST(RobotControlSpec, PluginTagAndTransmissions) {
  RobotControlSpec spec;
  std::string error;
  EXPECT_FALSE(readRobotControlSpec(tutorialUrdf(), "arm", &spec, &error));
  ASSERT_TRUE(readRobotControlSpec(controlledUrdf(), "arm", &spec, &error));
  EXPECT_TRUE(error.empty()) << error;
  EXPECT_EQ(spec.robot_namespace, "/one_DOF_robot");
  EXPECT_FALSE(spec.control_period);
  ASSERT_EQ(spec.joints.size(), 1u);
  EXPECT_EQ(spec.joints[0].joint, "joint1");
  EXPECT_EQ(spec.joints[0].interfaces, std::vector<JointInterface>{JointInterface::Effort});
  // robotNamespace defaults to the model's name.
  ASSERT_TRUE(readRobotControlSpec(controlledUrdf("<controlPeriod>0.002</controlPeriod>"), "arm",
                                   &spec, &error));
  EXPECT_EQ(spec.robot_namespace, "/arm");
  EXPECT_EQ(spec.control_period.value_or(0), 0.002);
}

// The tutorial arm under one controller of `type`, run as the node runs it: read, update, write
// before every step.
struct ArmUnderController {
  World world;
  RobotControlSpec spec;
  std::unique_ptr<RobotHwSim> robot;
  std::unique_ptr<Controller> controller;

  ArmUnderController(const std::string& type, const MapParams& params,
                     const std::string& engine = World::engineNames().front(),
                     bool gravity = true)
      : world(engine) {
    if (!gravity) {
      PhysicsParams physics;
      physics.gravity = {0, 0, 0};
      EXPECT_TRUE(world.setParams(physics).ok());
    }
    std::string error;
    EXPECT_TRUE(readRobotControlSpec(controlledUrdf(), "one_DOF_robot", &spec, &error));
    EXPECT_TRUE(world.spawn("one_DOF_robot", controlledUrdf(), ModelFormat::Urdf, Pose()).ok());
    std::vector<std::string> warnings;
    robot = std::make_unique<RobotHwSim>(world, "one_DOF_robot", spec, &warnings);
    EXPECT_TRUE(warnings.empty());
    controller = findControllerType(type)->make(*robot, params, "/one_DOF_robot/c", &error);
    EXPECT_TRUE(controller) << error;
    controller->starting(world.timeNs());
  }

  // Returns joint1's position after that many seconds.
  double run(double seconds) {
    const int64_t step_ns = std::llround(world.params().step * 1e9);
    for (int64_t k = 0; k < std::llround(seconds / world.params().step); ++k) {
      robot->read(world);
      robot->clearCommands();
      controller->update(world.timeNs(), step_ns);
      robot->write(world);
      world.step();
    }
    robot->read(world);
    return robot->jointState("joint1")->position();
  }
};

constexpr const char* kPositionController = "effort_controllers/JointPositionController";

MapParams bookParams(double i) {
  MapParams params;
  params.strings["/one_DOF_robot/c/joint"] = "joint1";
  params.numbers = {{"/one_DOF_robot/c/pid/p", 10.0},      {"/one_DOF_robot/c/pid/i", i},
                    {"/one_DOF_robot/c/pid/d", 10.0},      {"/one_DOF_robot/c/pid/i_clamp_min", -10.0},
                    {"/one_DOF_robot/c/pid/i_clamp_max", 10.0}};
  return params;
}

class ControlledArmTest : public ::testing::TestWithParam<std::string> {};

// Kp (c - q) + m g d sin q = 0 at rest (m = 1 kg, d = 0.5 m): solved by Newton's method.
double staticBalance(double kp, double command) {
  const double mgd = 1.0 * 9.8 * 0.5;
  double q = command;
  for (int k = 0; k < 50; ++k) q -= (kp * (command - q) + mgd * std::sin(q)) / (-kp + mgd * std::cos(q));
  return q;
}

TEST_P(ControlledArmTest, WithoutIntegralSettlesAtThePdStaticBalance) {
  ArmUnderController arm(kPositionController, bookParams(0.0), GetParam());
  arm.controller->setCommand(1.0);
  EXPECT_NEAR(arm.run(30.0), staticBalance(10.0, 1.0), 1e-3);
}

TEST_P(ControlledArmTest, WithIntegralSettlesAtTheCommand) {
  ArmUnderController arm(kPositionController, bookParams(10.0), GetParam());
  arm.controller->setCommand(1.0);
  EXPECT_NEAR(arm.run(30.0), 1.0, 1e-3);
  arm.controller->setCommand(2.0);
  EXPECT_NEAR(arm.run(30.0), 2.0, 1e-3);
}

TEST_P(ControlledArmTest, StartingHoldsWhereTheJointIs) {
  ArmUnderController arm(kPositionController, bookParams(10.0), GetParam());
  EXPECT_NEAR(arm.run(10.0), 0.0, 1e-3);  // upright, unstable without the controller
}

INSTANTIATE_TEST_SUITE_P(Engines, ControlledArmTest, ::testing::ValuesIn(World::engineNames()),
                         [](const auto& info) { return info.param; });

TEST(JointVelocityController, HoldsTheCommandedRate) {
  MapParams params = bookParams(0.0);
  // No d: on a rate, d acts on the acceleration, and the book's 10 over a 1 ms step is a loop
  // gain of 10 / 0.001 / 0.35 kg m^2, unstable.
  params.numbers["/one_DOF_robot/c/pid/d"] = 0.0;
  ArmUnderController arm("effort_controllers/JointVelocityController", params,
                         World::engineNames().front(), false);
  arm.controller->setCommand(1.5);
  // 1 s: 30 time constants (0.35 kg m^2 / p), and the link still clear of the ground.
  arm.run(1.0);
  EXPECT_NEAR(arm.robot->jointState("joint1")->velocity(), 1.5, 1e-3);
}

TEST(JointEffortController, TheCommandIsTheEffort) {
  MapParams params;
  params.strings["/one_DOF_robot/c/joint"] = "joint1";
  ArmUnderController arm("effort_controllers/JointEffortController", params,
                         World::engineNames().front(), false);
  arm.controller->setCommand(1.0);
  arm.run(1.0);
  // 1 N m on the link's inertia about the joint (Iyy + m d^2) for 1 s.
  EXPECT_NEAR(arm.robot->jointState("joint1")->velocity(), 1.0 / (0.1 + 1.0 * 0.5 * 0.5), 1e-3);
  EXPECT_DOUBLE_EQ(arm.robot->jointState("joint1")->effort(), 1.0);
}

TEST(JointStateController, PublishesAtItsRateOfSimTime) {
  MapParams params;
  params.numbers["/one_DOF_robot/c/publish_rate"] = 50;
  ArmUnderController arm("joint_state_controller/JointStateController", params,
                         World::engineNames().front(), false);
  std::vector<int64_t> stamps;
  arm.controller->publish_joint_states = [&](const JointStatesFacts& facts) {
    stamps.push_back(facts.stamp_ns);
    EXPECT_EQ(facts.names, std::vector<std::string>{"joint1"});
  };
  arm.run(1.0);
  ASSERT_EQ(stamps.size(), 49u);  // the first a whole period after starting, strictly
  for (size_t k = 1; k < stamps.size(); ++k) EXPECT_EQ(stamps[k] - stamps[k - 1], 20000000);
}

TEST(ControllerTypes, BadConfigurationRefusedWithTheReason) {
  World world;
  RobotControlSpec spec;
  std::string error;
  ASSERT_TRUE(readRobotControlSpec(controlledUrdf(), "one_DOF_robot", &spec, &error));
  ASSERT_TRUE(world.spawn("one_DOF_robot", controlledUrdf(), ModelFormat::Urdf, Pose()).ok());
  std::vector<std::string> warnings;
  RobotHwSim robot(world, "one_DOF_robot", spec, &warnings);
  const ControllerType* position = findControllerType("effort_controllers/JointPositionController");
  ASSERT_TRUE(position);
  MapParams params = bookParams(0);
  params.strings.clear();
  EXPECT_FALSE(position->make(robot, params, "/one_DOF_robot/c", &error));
  EXPECT_NE(error.find("No joint given"), std::string::npos) << error;
  params.strings["/one_DOF_robot/c/joint"] = "joint7";
  EXPECT_FALSE(position->make(robot, params, "/one_DOF_robot/c", &error));
  EXPECT_NE(error.find("joint7"), std::string::npos) << error;
  params = bookParams(0);
  params.numbers.erase("/one_DOF_robot/c/pid/p");
  EXPECT_FALSE(position->make(robot, params, "/one_DOF_robot/c", &error));
  EXPECT_NE(error.find("No p gain"), std::string::npos) << error;
  EXPECT_FALSE(findControllerType("effort_controllers/NoSuchController"));
  EXPECT_FALSE(findControllerType("position_controllers/JointPositionController")
                   ->make(robot, bookParams(0), "/one_DOF_robot/c", &error));
  EXPECT_NE(error.find("effort only"), std::string::npos) << error;
}

TEST(World, EffortCommandActsForOneStepOnly) {
  World world;
  ASSERT_TRUE(world.spawn("one_DOF_robot", tutorialUrdf(), ModelFormat::Urdf, Pose()).ok());
  EXPECT_EQ(world.setJointEffortCommand("nope", 1.0).code, StatusCode::JointNotFound);
  EXPECT_EQ(world.setJointEffortCommand("joint1", NAN).code, StatusCode::NotFinite);
  ASSERT_TRUE(world.setJointEffortCommand("one_DOF_robot::joint1", -5.0).ok());
  world.step();
  JointInfo after_push;
  ASSERT_TRUE(world.jointInfo("joint1", &after_push).ok());
  EXPECT_LT(after_push.rate, 0);
  // Upright and at rest but for that push: the next step without a command changes the rate by
  // gravity's tiny pull alone, not by another push.
  world.step();
  JointInfo next;
  ASSERT_TRUE(world.jointInfo("joint1", &next).ok());
  EXPECT_NEAR(next.rate, after_push.rate, std::abs(after_push.rate) * 0.05);
}

}  // namespace
}  // namespace onedof_sim::control

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
