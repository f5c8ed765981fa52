// World::jointConstraintWrench, on every engine of the registry: what a moving joint's constraint
// puts on its child link under a static load, the torque taken about the joint's anchor.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>

#include "onedof_sim/world.h"

namespace onedof_sim {
namespace {

constexpr double kStep = 0.001;
constexpr double kG = 9.81;

// On a base welded to the world at z 2: a 2 kg bob hanging 0.5 m below a horizontal hinge
// ("swing"), and a 3 kg block on a vertical slider whose stops hold it at 0 ("hold", as the
// book's force-torque joint), its centre of mass 0.2 m off the slider's line along x.
const char* kRig = R"(<robot name="rig">
  <link name="world"/>
  <link name="base"><inertial><mass value="1"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
  <joint name="weld" type="fixed"><parent link="world"/><child link="base"/>
    <origin xyz="0 0 2"/></joint>
  <link name="bob"><inertial><origin xyz="0 0 -0.5"/><mass value="2"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
  <joint name="swing" type="revolute"><parent link="base"/><child link="bob"/>
    <axis xyz="1 0 0"/><limit lower="-3" upper="3" effort="100" velocity="10"/></joint>
  <link name="block"><inertial><origin xyz="0.2 0 0"/><mass value="3"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
  <joint name="hold" type="prismatic"><parent link="base"/><child link="block"/>
    <origin xyz="0 1 0"/><axis xyz="0 0 1"/>
    <limit lower="0" upper="0" effort="100" velocity="0.01"/></joint>
</robot>)";

class JointWrench : public ::testing::TestWithParam<std::string> {
 protected:
  void SetUp() override {
    PhysicsParams params;
    params.step = kStep;
    params.gravity = {0, 0, -kG};
    world_ = std::make_unique<World>(GetParam(), params);
    ASSERT_TRUE(world_->spawn("rig", kRig, ModelFormat::Urdf, Pose()).ok());
  }
  Wrench wrench(const std::string& joint) {
    Wrench out;
    const Status status = world_->jointConstraintWrench(joint, &out);
    EXPECT_TRUE(status.ok()) << status;
    return out;
  }
  void run(int steps) {
    for (int i = 0; i < steps; ++i) ASSERT_TRUE(world_->step().ok());
  }
  std::unique_ptr<World> world_;
};

TEST_P(JointWrench, IsZeroBeforeTheFirstStep) {
  const Wrench w = wrench("swing");
  EXPECT_EQ(w.force.z, 0.0);
  EXPECT_EQ(w.torque.x, 0.0);
}

TEST_P(JointWrench, AHingeHoldsTheWeightHangingBelowItWithNoTorqueAboutItsAnchor) {
  run(500);
  const Wrench w = wrench("swing");
  const double weight = 2 * kG;
  EXPECT_NEAR(w.force.z, weight, 0.01 * weight);
  EXPECT_NEAR(w.force.x, 0, 1e-3 * weight);
  EXPECT_NEAR(w.force.y, 0, 1e-3 * weight);
  EXPECT_NEAR(std::hypot(w.torque.x, w.torque.y, w.torque.z), 0, 1e-3 * weight);
}

TEST_P(JointWrench, ASliderAtItsStopsHoldsTheWeightAndItsMomentAboutTheAnchor) {
  run(500);
  const Wrench w = wrench("hold");
  const double weight = 3 * kG;
  EXPECT_NEAR(w.force.z, weight, 0.01 * weight);
  EXPECT_NEAR(std::hypot(w.force.x, w.force.y), 0, 1e-3 * weight);
  // Gravity at 0.2 m along x turns the block about +y; the constraint holds it back about -y.
  EXPECT_NEAR(w.torque.y, -0.2 * weight, 0.01 * 0.2 * weight);
  EXPECT_NEAR(w.torque.x, 0, 1e-3 * weight);
  EXPECT_NEAR(w.torque.z, 0, 1e-3 * weight);
}

TEST_P(JointWrench, TwoWorldsGiveTheSameWrenchBitForBit) {
  run(200);
  World other(GetParam(), world_->params());
  ASSERT_TRUE(other.spawn("rig", kRig, ModelFormat::Urdf, Pose()).ok());
  for (int i = 0; i < 200; ++i) ASSERT_TRUE(other.step().ok());
  Wrench a = wrench("hold"), b;
  ASSERT_TRUE(other.jointConstraintWrench("hold", &b).ok());
  EXPECT_EQ(a.force.z, b.force.z);
  EXPECT_EQ(a.torque.y, b.torque.y);
}

TEST_P(JointWrench, RefusesAJointThatHoldsNothingApartAndOneThatIsNotThere) {
  Wrench out;
  EXPECT_EQ(world_->jointConstraintWrench("weld", &out).code, StatusCode::JointIsFixed);
  EXPECT_EQ(world_->jointConstraintWrench("nope", &out).code, StatusCode::JointNotFound);
  EXPECT_TRUE(world_->jointConstraintWrench("rig::swing", &out).ok());
}

INSTANTIATE_TEST_SUITE_P(Engines, JointWrench, ::testing::ValuesIn(World::engineNames()),
                         [](const auto& info) { return info.param; });

}  // namespace
}  // namespace onedof_sim
