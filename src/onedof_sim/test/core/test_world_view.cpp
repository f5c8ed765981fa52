// What a view of the world draws (World::jointAxes, linkMasses, allContacts) on every engine of
// the registry: a joint's origin and axis and a link's centre of mass follow the links as the
// joint turns, and a box resting on the ground has contacts whose normals point up out of it.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "../ground_plane.h"
#include "onedof_sim/pose_math.h"
#include "onedof_sim/world.h"

namespace onedof_sim {
namespace {

// A base and an arm on a revolute joint about y at 0.5 m above the base's origin; the arm's
// centre of mass 0.2 m along z from the joint.
const char* kArmUrdf = R"(<robot name="arm">
  <link name="base"><inertial><mass value="2"/>
    <inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial>
    <collision><geometry><box size="0.2 0.2 0.2"/></geometry></collision></link>
  <link name="arm"><inertial><origin xyz="0 0 0.2"/><mass value="0.5"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.001"/></inertial></link>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="arm"/>
    <origin xyz="0 0 0.5"/><axis xyz="0 1 0"/>
    <limit lower="-3" upper="3" effort="10" velocity="1"/></joint>
</robot>)";

const char* kBoxSdf = R"(<sdf version="1.6"><model name="box"><link name="link">
  <inertial><mass>1</mass><inertia><ixx>0.00667</ixx><iyy>0.00667</iyy><izz>0.00667</izz>
  </inertia></inertial>
  <collision name="collision"><geometry><box><size>0.2 0.2 0.2</size></box></geometry></collision>
</link></model></sdf>)";

Pose at(double x, double y, double z) {
  Pose p;
  p.position = {x, y, z};
  return p;
}

void expectNear(const Vec3& a, const Vec3& b) {
  EXPECT_NEAR(a.x, b.x, 1e-9);
  EXPECT_NEAR(a.y, b.y, 1e-9);
  EXPECT_NEAR(a.z, b.z, 1e-9);
}

class WorldView : public ::testing::TestWithParam<std::string> {
 protected:
  World world_{GetParam()};
};

TEST_P(WorldView, JointAxesAndCentresOfMassFollowTheLinks) {
  ASSERT_TRUE(world_.spawn("arm", kArmUrdf, ModelFormat::Urdf, at(1, 2, 0)).ok());
  std::vector<JointAxis> axes = world_.jointAxes();
  ASSERT_EQ(axes.size(), 1u);
  EXPECT_EQ(axes[0].model, "arm");
  EXPECT_EQ(axes[0].name, "shoulder");
  EXPECT_EQ(axes[0].type, JointType::Revolute);
  expectNear(axes[0].anchor, {1, 2, 0.5});
  expectNear(axes[0].axis, {0, 1, 0});

  // Turned a quarter turn about y: the arm's centre of mass swings from above the joint to +x.
  ASSERT_TRUE(world_.setModelConfiguration("arm", {"shoulder"}, {M_PI / 2}).ok());
  axes = world_.jointAxes();
  expectNear(axes[0].anchor, {1, 2, 0.5});
  expectNear(axes[0].axis, {0, 1, 0});
  const std::vector<LinkMass> masses = world_.linkMasses();
  ASSERT_EQ(masses.size(), 2u);
  EXPECT_EQ(masses[0].link, "base");
  EXPECT_EQ(masses[1].link, "arm");
  EXPECT_DOUBLE_EQ(masses[1].mass, 0.5);
  EXPECT_DOUBLE_EQ(masses[1].izz, 0.001);
  expectNear(masses[0].inertial.position, {1, 2, 0});
  expectNear(masses[1].inertial.position, {1.2, 2, 0.5});
}

TEST_P(WorldView, ABoxRestingOnTheGroundHasContactsWithNormalsUpOutOfTheGround) {
  testing_support::addGroundPlane(world_);
  EXPECT_TRUE(world_.allContacts().empty());  // before a step
  ASSERT_TRUE(world_.spawn("box", kBoxSdf, ModelFormat::Sdf, at(0.5, -0.5, 0.1)).ok());
  for (int i = 0; i < 500; ++i) ASSERT_TRUE(world_.step().ok());
  const std::vector<Contact> contacts = world_.allContacts();
  ASSERT_EQ(contacts.size(), 1u);
  EXPECT_EQ(contacts[0].collision1, "box::link::collision");
  EXPECT_EQ(contacts[0].collision2, testing_support::kGroundCollision);
  ASSERT_FALSE(contacts[0].points.empty());
  for (const ContactPoint& point : contacts[0].points) {
    EXPECT_NEAR(point.normal.z, 1, 1e-6);
    EXPECT_NEAR(point.position.z, 0, 0.01);
    EXPECT_LE(std::abs(point.position.x - 0.5), 0.11);
    EXPECT_LE(std::abs(point.position.y + 0.5), 0.11);
  }
}

INSTANTIATE_TEST_SUITE_P(Engines, WorldView, ::testing::ValuesIn(World::engineNames()),
                         [](const auto& info) { return info.param; });

}  // namespace
}  // namespace onedof_sim
