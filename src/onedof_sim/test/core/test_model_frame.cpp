// Model frames (world.h, "Model frames"), on every engine of the registry: a model's pose is its
// model frame's, its links keep their poses in it; a spawned model's own <pose> is taken in the
// requested pose; a pioneer2dx shaped as Gazebo's (its chassis 0.16 m above its model frame) set
// at (3, 3, 0) rests on its wheels and drives.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

#include "../ground_plane.h"
#include "onedof_sim/world.h"
#include "onedof_sim/pose_math.h"

namespace onedof_sim {
namespace {

constexpr double kRoundTrip = 1e-9;
constexpr double kStep = 0.001;

std::string workspaceFile(const std::string& relative) {
  std::ifstream file(ONEDOF_SOURCE_DIR "/" + relative);
  std::stringstream text;
  text << file.rdbuf();
  return text.str();
}

// tests/robots/pioneer2dx.sdf: chassis at (0, 0, 0.16), wheels at (0.1, +-0.17, 0.11) in the
// model frame, the model's own <pose> zero.
std::string pioneerSdf() { return workspaceFile("tests/robots/pioneer2dx.sdf"); }
constexpr double kChassisHeight = 0.16, kAxleHeight = 0.11;

// A static 0.2 x 2 x 1 m wall whose own pose is `pose` (SDF: x y z roll pitch yaw), its link
// at the model frame.
std::string wallSdf(const std::string& pose) {
  return "<?xml version=\"1.0\"?><sdf version=\"1.6\"><model name=\"wall\"><static>true</static>"
         "<pose>" + pose + "</pose><link name=\"link\"><collision name=\"collision\"><geometry>"
         "<box><size>0.2 2 1</size></box></geometry></collision></link></model></sdf>";
}

Pose at(double x, double y, double z, const Quat& orientation = Quat()) {
  Pose p;
  p.position = {x, y, z};
  p.orientation = orientation;
  return p;
}

Quat aboutZ(double angle) { return {std::cos(angle / 2), 0, 0, std::sin(angle / 2)}; }

void expectNear(const Vec3& got, const Vec3& want, double tolerance) {
  EXPECT_NEAR(got.x, want.x, tolerance);
  EXPECT_NEAR(got.y, want.y, tolerance);
  EXPECT_NEAR(got.z, want.z, tolerance);
}

// The same rotation: q and -q are.
void expectNear(const Quat& got, const Quat& want, double tolerance) {
  const double sign = got.w * want.w + got.x * want.x + got.y * want.y + got.z * want.z < 0 ? -1 : 1;
  EXPECT_NEAR(sign * got.w, want.w, tolerance);
  EXPECT_NEAR(sign * got.x, want.x, tolerance);
  EXPECT_NEAR(sign * got.y, want.y, tolerance);
  EXPECT_NEAR(sign * got.z, want.z, tolerance);
}

void expectNear(const Pose& got, const Pose& want, double tolerance) {
  expectNear(got.position, want.position, tolerance);
  expectNear(got.orientation, want.orientation, tolerance);
}

// What World::modelState or World::linkState gives of `name` in `frame`: the pose, and the twist
// into *twist when asked; the call is expected to succeed.
using StateGetter = Status (World::*)(const std::string&, const std::string&, Pose*, Twist*) const;
Pose stateOf(const World& world, StateGetter getter, const std::string& name,
             const std::string& frame, Twist* twist) {
  Pose pose;
  Twist unused;
  const Status status = (world.*getter)(name, frame, &pose, twist ? twist : &unused);
  EXPECT_TRUE(status.ok()) << name << ": " << status;
  return pose;
}

class ModelFrames : public ::testing::TestWithParam<std::string> {
 protected:
  Pose modelPose(const World& world, const std::string& model, const std::string& frame = "",
                 Twist* twist = nullptr) {
    return stateOf(world, &World::modelState, model, frame, twist);
  }
  Pose linkPose(const World& world, const std::string& link, const std::string& frame = "",
                Twist* twist = nullptr) {
    return stateOf(world, &World::linkState, link, frame, twist);
  }
};

PhysicsParams withoutGravity() {
  PhysicsParams params;
  params.gravity = {0, 0, 0};
  return params;
}

TEST_P(ModelFrames, TheModelsPoseIsItsFramesNotItsChassiss) {
  World world(GetParam());
  ASSERT_TRUE(world.spawn("pioneer2dx", pioneerSdf(), ModelFormat::Sdf, at(1, 2, 0)).ok());
  expectNear(modelPose(world, "pioneer2dx"), at(1, 2, 0), 1e-12);
  expectNear(linkPose(world, "pioneer2dx::chassis"), at(1, 2, kChassisHeight), 1e-12);
  expectNear(linkPose(world, "pioneer2dx::left_wheel").position, {1.1, 2.17, kAxleHeight}, 1e-12);
  // A link in its model's frame: its pose in the model.
  expectNear(linkPose(world, "pioneer2dx::chassis", "pioneer2dx"), at(0, 0, kChassisHeight), 1e-12);
  // Spawned in the model's frame: at its model frame, not at its chassis.
  ASSERT_TRUE(world.spawn("beside", pioneerSdf(), ModelFormat::Sdf, at(0, 1, 0), "pioneer2dx").ok());
  expectNear(modelPose(world, "beside"), at(1, 3, 0), 1e-12);
}

TEST_P(ModelFrames, SetAndGetRoundTripWithLinksOffsetFromTheModelFrame) {
  World world(GetParam(), withoutGravity());
  ASSERT_TRUE(world.spawn("pioneer2dx", pioneerSdf(), ModelFormat::Sdf, at(0, 0, 1)).ok());
  // Turned 0.8 rad about an oblique axis (2, -1, 2) / 3.
  const double s = std::sin(0.4);
  const Pose target = at(1.5, -2, 0.7, {std::cos(0.4), s * 2 / 3, -s / 3, s * 2 / 3});
  Twist twist;
  twist.linear = {0.3, -0.2, 0.1};
  twist.angular = {0.1, 0.2, -0.3};
  ASSERT_TRUE(world.setModelState("pioneer2dx", target, twist, "").ok());
  Twist got;
  expectNear(modelPose(world, "pioneer2dx", "", &got), target, kRoundTrip);
  expectNear(got.linear, twist.linear, kRoundTrip);
  expectNear(got.angular, twist.angular, kRoundTrip);
  // The links keep their poses in the model frame; the model's twist is its chassis' (the
  // canonical link), every link moving rigidly with it.
  Twist chassis, wheel;
  expectNear(linkPose(world, "pioneer2dx::chassis", "", &chassis),
             compose(target, at(0, 0, kChassisHeight)), kRoundTrip);
  const Pose wheel_pose = linkPose(world, "pioneer2dx::right_wheel", "", &wheel);
  expectNear(wheel_pose.position, compose(target, at(0.1, -0.17, kAxleHeight)).position, kRoundTrip);
  expectNear(chassis.linear, twist.linear, kRoundTrip);
  const Vec3 lever = wheel_pose.position - compose(target, at(0, 0, kChassisHeight)).position;
  expectNear(wheel.linear, twist.linear + cross(twist.angular, lever), kRoundTrip);
  expectNear(wheel.angular, twist.angular, kRoundTrip);

  // In another model's frame: a wall turned a quarter about z, its frame 1 m up.
  ASSERT_TRUE(world.spawn("wall", wallSdf("0 0 1 0 0 1.5707963267948966"), ModelFormat::Sdf,
                          at(2, 0, 0)).ok());
  const Pose wall = at(2, 0, 1, aboutZ(M_PI / 2));
  expectNear(modelPose(world, "wall"), wall, 1e-12);
  ASSERT_TRUE(world.setModelState("pioneer2dx", target, twist, "wall").ok());
  expectNear(modelPose(world, "pioneer2dx", "wall", &got), target, kRoundTrip);
  expectNear(got.linear, twist.linear, kRoundTrip);
  expectNear(got.angular, twist.angular, kRoundTrip);
  expectNear(modelPose(world, "pioneer2dx"), compose(wall, target), kRoundTrip);
  expectNear(linkPose(world, "pioneer2dx::chassis", "wall"),
             compose(target, at(0, 0, kChassisHeight)), kRoundTrip);
  // And back in the world.
  ASSERT_TRUE(world.setModelState("pioneer2dx", target, twist, "world").ok());
  expectNear(modelPose(world, "pioneer2dx"), target, kRoundTrip);
}

TEST_P(ModelFrames, ASpawnedModelsOwnPoseIsTakenInTheRequestedPose) {
  World world(GetParam());
  // No pose asked for: the model sits at its own.
  ASSERT_TRUE(world.spawn("wall", wallSdf("2.1 0 0.5 0 0 0"), ModelFormat::Sdf, Pose()).ok());
  expectNear(modelPose(world, "wall"), at(2.1, 0, 0.5), 1e-12);
  expectNear(linkPose(world, "wall::link"), at(2.1, 0, 0.5), 1e-12);
  // At x 1: its own pose taken from there, as gazebo_ros' spawn services compose them.
  ASSERT_TRUE(world.spawn("moved", wallSdf("2.1 0 0.5 0 0 0"), ModelFormat::Sdf, at(1, 0, 0)).ok());
  expectNear(modelPose(world, "moved"), at(3.1, 0, 0.5), 1e-12);
  // Turned a quarter about z: so is its own pose.
  ASSERT_TRUE(world.spawn("turned", wallSdf("2.1 0 0.5 0 0 0.3"), ModelFormat::Sdf,
                          at(1, 0, 0, aboutZ(M_PI / 2))).ok());
  expectNear(modelPose(world, "turned"), at(1, 2.1, 0.5, aboutZ(M_PI / 2 + 0.3)), 1e-12);
  // In another model's frame: that frame, the request, the model's own pose.
  ASSERT_TRUE(world.spawn("stacked", wallSdf("2.1 0 0.5 0 0 0"), ModelFormat::Sdf,
                          at(0, 1, 0), "wall").ok());
  expectNear(modelPose(world, "stacked"), at(4.2, 1, 1), 1e-12);
  // A reset puts a model back where it was spawned, its own pose included.
  ASSERT_TRUE(world.setModelState("turned", at(0, 0, 3), Twist(), "").ok());
  world.resetWorld();
  expectNear(modelPose(world, "turned"), at(1, 2.1, 0.5, aboutZ(M_PI / 2 + 0.3)), 1e-12);
}

// gazebo_ros' -database request: a <world> whose one <include> names the model, the include's
// <pose> the model's own.
TEST_P(ModelFrames, ADatabaseRequestsIncludePoseIsTheModelsOwn) {
  World world(GetParam());
  world.setModelPath({ONEDOF_SOURCE_DIR "/src/onedof_sim/models"});
  const std::string request =
      "<sdf version=\"1.4\"><world name=\"default\"><include><uri>model://cafe_table</uri>"
      "<name>cafe_table</name><pose>0 0 0.5 0 0 0</pose></include></world></sdf>";
  ASSERT_TRUE(world.spawn("cafe_table", request, ModelFormat::Sdf, at(1, 0, 0)).ok());
  expectNear(modelPose(world, "cafe_table"), at(1, 0, 0.5), 1e-12);
}

TEST_P(ModelFrames, AUrdfModelsFrameIsItsRootLink) {
  World world(GetParam());
  const std::string urdf =
      "<robot name=\"box\"><link name=\"body\"><inertial><mass value=\"1\"/><inertia ixx=\"0.01\" "
      "ixy=\"0\" ixz=\"0\" iyy=\"0.01\" iyz=\"0\" izz=\"0.01\"/></inertial><collision><geometry>"
      "<box size=\"0.2 0.2 0.2\"/></geometry></collision></link></robot>";
  const Pose spawned = at(0.5, -1, 2, aboutZ(0.4));
  ASSERT_TRUE(world.spawn("box", urdf, ModelFormat::Urdf, spawned).ok());
  expectNear(modelPose(world, "box"), spawned, 1e-12);
  expectNear(linkPose(world, "box::body"), spawned, 1e-12);
}

TEST_P(ModelFrames, AnOwnPosePastTheLimitsIsRefused) {
  World world(GetParam());
  const Status far = world.spawn("far", wallSdf("2e6 0 0 0 0 0"), ModelFormat::Sdf, Pose());
  EXPECT_EQ(far.code, StatusCode::ModelRejected) << far;
  EXPECT_NE(far.subject.find("own <pose>"), std::string::npos) << far;
  // Each within the limits, the two together past them.
  const Status sum = world.spawn("sum", wallSdf("9e5 0 0 0 0 0"), ModelFormat::Sdf, at(9e5, 0, 0));
  EXPECT_EQ(sum.code, StatusCode::OutOfRange) << sum;
  EXPECT_EQ(sum.subject, "pose.position");
  EXPECT_TRUE(world.modelNames().empty());
}

// Upstream's set_model_state_test world: its pioneer2dx set at (3, 3, 0) stands on its wheels,
// its chassis 0.16 m up, and drives on. (Set with its chassis at (3, 3, 0), its wheels were
// buried and the engine threw it 21 m up.) ODE keeps it on its wheels throughout; on Bullet it is
// kicked now and then (up to about 1 m/s, a wheel 2 cm up, on its wheels again within a second),
// whether or not it was set: Bullet's solver over-relaxes friction by sor_pgs_w (1.3; at 1.0 the
// kicks are a tenth), and Gazebo's pioneer2dx wheels have a friction coefficient of 100 against
// the ground. The bounds hold on both engines; the figures are printed.
TEST_P(ModelFrames, PioneerSetAtThreeThreeRestsOnItsWheelsAndDrives) {
  PhysicsParams params;
  params.step = kStep;
  World world(GetParam(), params);
  testing_support::addGroundPlane(world);
  ASSERT_TRUE(world.spawn("pioneer2dx", pioneerSdf(), ModelFormat::Sdf, Pose()).ok());
  for (int i = 0; i < 300; ++i) ASSERT_TRUE(world.step().ok());
  const double heading = 0.7;
  ASSERT_TRUE(world.setModelState("pioneer2dx", at(3, 3, 0, aboutZ(heading)), Twist(), "").ok());
  expectNear(linkPose(world, "pioneer2dx::chassis").position, {3, 3, kChassisHeight}, kRoundTrip);
  // The wheels where their joints have turned them since the spawn: Gazebo's model pitches them
  // by 1.5707, so their axles pass 3 um from their origins.
  for (const char* wheel : {"pioneer2dx::left_wheel", "pioneer2dx::right_wheel"})
    EXPECT_NEAR(linkPose(world, wheel).position.z, kAxleHeight, 1e-6) << wheel;
  // Over each run: the chassis' highest point and fastest speed, and the steps that ended with
  // both wheels on the ground (their axles within 2 mm of their radius up).
  struct Run {
    double highest = 0, fastest = 0;
    int steps = 0, on_the_ground = 0;
  };
  auto run = [&](int count, double wheel_rate) {
    Run r;
    for (int i = 0; i < count; ++i) {
      if (wheel_rate != 0)
        for (const char* joint : {"left_wheel_hinge", "right_wheel_hinge"})
          EXPECT_TRUE(world.setJointVelocityCommand(joint, wheel_rate, 5).ok());
      EXPECT_TRUE(world.step().ok());
      Twist twist;
      r.highest = std::max(r.highest, linkPose(world, "pioneer2dx::chassis", "", &twist).position.z);
      r.fastest = std::max(r.fastest, norm(twist.linear));
      const double left = linkPose(world, "pioneer2dx::left_wheel").position.z;
      const double right = linkPose(world, "pioneer2dx::right_wheel").position.z;
      ++r.steps;
      r.on_the_ground += std::abs(left - kAxleHeight) < 0.002 && std::abs(right - kAxleHeight) < 0.002;
    }
    return r;
  };
  const Run rest = run(1000, 0);
  const Pose rested = modelPose(world, "pioneer2dx");
  std::printf("[ figures  ] %s: set at (3, 3, 0), 1 s at rest: at (%.4f, %.4f, %.4f), chassis "
              "highest at %.4f m, fastest %.3f m/s, both wheels on the ground %d of %d steps\n",
              GetParam().c_str(), rested.position.x, rested.position.y, rested.position.z,
              rest.highest, rest.fastest, rest.on_the_ground, rest.steps);
  EXPECT_NEAR(rested.position.x, 3, 0.05);
  EXPECT_NEAR(rested.position.y, 3, 0.05);
  EXPECT_LT(rest.highest, kChassisHeight + 0.03);
  EXPECT_LT(rest.fastest, 1.5);
  EXPECT_GE(rest.on_the_ground, rest.steps * 0.9);
  // 2 s with the wheels at 5 rad/s (0.55 m/s at their rim): along the heading, on the ground.
  const Run drive = run(2000, 5);
  const Pose driven = modelPose(world, "pioneer2dx");
  const Vec3 moved = driven.position - rested.position;
  const double along = moved.x * std::cos(heading) + moved.y * std::sin(heading);
  const double across = -moved.x * std::sin(heading) + moved.y * std::cos(heading);
  std::printf("[ figures  ] %s: driven 2 s: %.4f m along its heading, %.4f m across, chassis "
              "highest at %.4f m, both wheels on the ground %d of %d steps\n",
              GetParam().c_str(), along, across, drive.highest, drive.on_the_ground, drive.steps);
  EXPECT_GT(along, 0.9);
  EXPECT_LT(along, 1.12);
  EXPECT_LT(std::abs(across), 0.3);
  EXPECT_NEAR(driven.position.z, 0, 0.02);
  EXPECT_LT(drive.highest, kChassisHeight + 0.03);
  EXPECT_LT(drive.fastest, 1.5);
  EXPECT_GE(drive.on_the_ground, drive.steps * 0.75);
}

INSTANTIATE_TEST_SUITE_P(Engines, ModelFrames, ::testing::ValuesIn(World::engineNames()),
                         [](const auto& info) { return info.param; });

}  // namespace
}  // namespace onedof_sim
