// The last step's contacts (World::contacts) on every engine of the registry: a box resting on
// the ground is held up by m g through points on its bottom face with upward normals, and so is
// a cylinder of implausibly small inertia dropped on its end face; a box in the air touches
// nothing, a stack shares its weight out pair by pair, the collisions of links welded into one
// body keep their own names, and the refusals.
#include <gtest/gtest.h>

#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "../ground_plane.h"
#include "onedof_sim/pose_math.h"
#include "onedof_sim/world.h"

namespace onedof_sim {
namespace {

using testing_support::kGroundCollision;

constexpr double kGravity = 9.8;  // PhysicsParams' default

// A box of `mass` and `size` (x y z), its link "link" and collision "collision".
std::string boxSdf(const std::string& name, double mass, const Vec3& size) {
  std::ostringstream s;
  const double k = mass / 12;
  s << "<sdf version=\"1.6\"><model name=\"" << name << "\"><link name=\"link\"><inertial><mass>"
    << mass << "</mass><inertia><ixx>" << k * (size.y * size.y + size.z * size.z)
    << "</ixx><iyy>" << k * (size.x * size.x + size.z * size.z) << "</iyy><izz>"
    << k * (size.x * size.x + size.y * size.y) << "</izz></inertia></inertial>"
    << "<collision name=\"collision\"><geometry><box><size>" << size.x << " " << size.y << " "
    << size.z << "</size></box></geometry></collision></link></model></sdf>";
  return s.str();
}

Pose at(double x, double y, double z) {
  Pose p;
  p.position = {x, y, z};
  return p;
}

Vec3 totalForce(const Contact& contact, bool second = false) {
  Vec3 sum;
  for (const ContactPoint& point : contact.points)
    sum = sum + (second ? point.wrench2.force : point.wrench1.force);
  return sum;
}

class ContactReport : public ::testing::TestWithParam<std::string> {
 protected:
  void SetUp() override { testing_support::addGroundPlane(world_); }
  void spawn(const std::string& name, const std::string& xml, ModelFormat format, const Pose& pose) {
    const Status status = world_.spawn(name, xml, format, pose);
    ASSERT_TRUE(status.ok()) << status;
  }
  void steps(int count) {
    for (int i = 0; i < count; ++i) ASSERT_TRUE(world_.step().ok());
  }
  std::vector<Contact> contactsOf(const std::vector<std::string>& collisions) {
    std::vector<Contact> found;
    const Status status = world_.contacts(collisions, &found);
    EXPECT_TRUE(status.ok()) << status;
    return found;
  }
  World world_{GetParam()};
};

// A 2 kg box 0.2 x 0.3 x 0.1 m set on the ground and left 1 s to settle: one contact, with the
// ground, whose points carry m g upwards and no torque about the box's centre of mass, their
// normals up and their positions on the box's bottom face; seen from the ground, the same points
// the other way round.
TEST_P(ContactReport, ABoxRestingOnTheGroundIsHeldUpByItsWeightThroughItsBottomFace) {
  const double mass = 2;
  const Vec3 size{0.2, 0.3, 0.1};
  spawn("box", boxSdf("box", mass, size), ModelFormat::Sdf, at(0.5, -0.2, size.z / 2));
  steps(1000);
  const std::vector<Contact> contacts = contactsOf({"box::link::collision"});
  ASSERT_EQ(contacts.size(), 1u);
  const Contact& contact = contacts[0];
  EXPECT_EQ(contact.collision1, "box::link::collision");
  EXPECT_EQ(contact.collision2, kGroundCollision);
  ASSERT_GE(contact.points.size(), 3u);
  const Vec3 force = totalForce(contact);
  EXPECT_NEAR(force.z, mass * kGravity, 0.01 * mass * kGravity);
  EXPECT_NEAR(force.x, 0, 0.01 * mass * kGravity);
  EXPECT_NEAR(force.y, 0, 0.01 * mass * kGravity);

  Pose box;
  Twist unused;
  ASSERT_TRUE(world_.linkState("box::link", "", &box, &unused).ok());
  Vec3 torque;
  for (const ContactPoint& point : contact.points) {
    EXPECT_NEAR(point.normal.x, 0, 1e-6);
    EXPECT_NEAR(point.normal.y, 0, 1e-6);
    EXPECT_NEAR(point.normal.z, 1, 1e-6);
    EXPECT_GE(point.depth, 0);
    EXPECT_LT(point.depth, 0.002);
    // On the bottom face, in the box's frame: z at -size.z / 2 (within the overlap), x and y
    // within the face.
    const Vec3 local = transformPoint(inverse(box), point.position);
    EXPECT_NEAR(local.z, -size.z / 2, 0.002);
    EXPECT_LE(std::abs(local.x), size.x / 2 + 1e-3);
    EXPECT_LE(std::abs(local.y), size.y / 2 + 1e-3);
    EXPECT_NEAR(norm(point.wrench2.force + point.wrench1.force), 0, 1e-12);
    torque = torque + point.wrench1.torque;
    // The torque is the force's about the box's centre of mass (its centre).
    const Vec3 arm = point.position - box.position;
    EXPECT_NEAR(norm(point.wrench1.torque - cross(arm, point.wrench1.force)), 0, 1e-9);
  }
  // At rest: the contact forces' moment about the centre of mass balances (gravity has none).
  EXPECT_NEAR(norm(torque), 0, 0.01 * mass * kGravity * size.x);

  const std::vector<Contact> from_ground = contactsOf({kGroundCollision});
  ASSERT_EQ(from_ground.size(), 1u);
  EXPECT_EQ(from_ground[0].collision1, kGroundCollision);
  EXPECT_EQ(from_ground[0].collision2, "box::link::collision");
  ASSERT_EQ(from_ground[0].points.size(), contact.points.size());
  EXPECT_NEAR(totalForce(from_ground[0]).z, -force.z, 1e-9);
  EXPECT_NEAR(from_ground[0].points[0].normal.z, -1, 1e-6);
  // The same point, named from either side.
  EXPECT_EQ(norm(from_ground[0].points[0].position - contact.points[0].position), 0);
}

// The book's thin cylinder (learning_ros' exmpl_models add_cylinder): 2 m across and 1 m long,
// 10 kg, with moments of 0.01 kg m^2 some 300 times too small, dropped flat from 4 m. It lands on
// its end face and stays there, upright, still, held by m g with no torque about its centre of
// mass: a contact pushing at one rim point would set such a body spinning.
TEST_P(ContactReport, AThinInertiaCylinderDroppedOnItsEndFaceRestsOnIt) {
  const double mass = 10, length = 1, radius = 1;
  spawn("cylinder",
        "<sdf version=\"1.6\"><model name=\"cylinder\"><link name=\"link\"><inertial><mass>10"
        "</mass><inertia><ixx>0.01</ixx><iyy>0.01</iyy><izz>0.01</izz></inertia></inertial>"
        "<collision name=\"collision\"><geometry><cylinder><radius>1</radius><length>1</length>"
        "</cylinder></geometry></collision></link></model></sdf>",
        ModelFormat::Sdf, at(2.5, 0, 4));
  steps(3000);
  Pose landed, rested;
  Twist twist;
  ASSERT_TRUE(world_.modelState("cylinder", "", &landed, &twist).ok());
  steps(1000);
  ASSERT_TRUE(world_.modelState("cylinder", "", &rested, &twist).ok());
  for (const Pose& pose : {landed, rested}) {
    EXPECT_NEAR(pose.position.z, length / 2, 0.002);
    const Quat& q = pose.orientation;
    EXPECT_NEAR(1 - 2 * (q.x * q.x + q.y * q.y), 1, 1e-6) << "its axis off the vertical";
  }
  EXPECT_LT(norm(rested.position - landed.position), 1e-3);
  EXPECT_LT(norm(twist.linear), 1e-3);
  EXPECT_LT(norm(twist.angular), 1e-3);

  const std::vector<Contact> contacts = contactsOf({"cylinder::link::collision"});
  ASSERT_EQ(contacts.size(), 1u);
  const Vec3 force = totalForce(contacts[0]);
  EXPECT_NEAR(force.z, mass * kGravity, 0.01 * mass * kGravity);
  Vec3 torque;
  for (const ContactPoint& point : contacts[0].points) {
    // On the bottom face.
    const Vec3 local = transformPoint(inverse(rested), point.position);
    EXPECT_NEAR(local.z, -length / 2, 0.002);
    EXPECT_LE(std::hypot(local.x, local.y), radius + 1e-3);
    torque = torque + point.wrench1.torque;
  }
  EXPECT_NEAR(norm(torque), 0, 0.01 * mass * kGravity * radius);
}

TEST_P(ContactReport, ABoxInTheAirTouchesNothing) {
  spawn("box", boxSdf("box", 1, {0.2, 0.2, 0.2}), ModelFormat::Sdf, at(0, 0, 5));
  steps(100);
  EXPECT_TRUE(contactsOf({"box::link::collision", kGroundCollision}).empty());
}

// The ground is the ground plane model alone: deleted, the box that rested on it falls, touching
// nothing, and its collision is no longer in the world.
TEST_P(ContactReport, DeletingTheGroundPlaneLetsTheBoxOnItFall) {
  spawn("box", boxSdf("box", 1, {0.2, 0.2, 0.2}), ModelFormat::Sdf, at(0, 0, 0.1));
  steps(500);
  ASSERT_EQ(contactsOf({"box::link::collision"}).size(), 1u);
  ASSERT_TRUE(world_.deleteModel("ground_plane").ok());
  steps(500);
  EXPECT_TRUE(contactsOf({"box::link::collision"}).empty());
  Pose pose;
  Twist twist;
  ASSERT_TRUE(world_.modelState("box", "", &pose, &twist).ok());
  // Half a second of free fall: 1.2 m down at 4.9 m/s.
  EXPECT_NEAR(pose.position.z, 0.1 - kGravity * 0.5 * 0.5 / 2, 0.01);
  EXPECT_NEAR(twist.linear.z, -kGravity * 0.5, 0.01);
  std::vector<Contact> found;
  EXPECT_EQ(world_.contacts({kGroundCollision}, &found).code, StatusCode::CollisionNotFound);
}

// A 3 kg box on a 1 kg box on the ground: the lower box meets the ground, which holds both up,
// and the upper box, which presses down on it with its own weight.
TEST_P(ContactReport, AStackSharesItsWeightOutPairByPair) {
  spawn("lower", boxSdf("lower", 1, {0.4, 0.4, 0.1}), ModelFormat::Sdf, at(0, 0, 0.05));
  spawn("upper", boxSdf("upper", 3, {0.2, 0.2, 0.2}), ModelFormat::Sdf, at(0, 0, 0.2));
  steps(1500);
  const std::vector<Contact> contacts = contactsOf({"lower::link::collision"});
  ASSERT_EQ(contacts.size(), 2u);
  for (const Contact& contact : contacts) {
    EXPECT_EQ(contact.collision1, "lower::link::collision");
    const Vec3 force = totalForce(contact);
    if (contact.collision2 == kGroundCollision) {
      EXPECT_NEAR(force.z, 4 * kGravity, 0.01 * 4 * kGravity);
    } else {
      EXPECT_EQ(contact.collision2, "upper::link::collision");
      EXPECT_NEAR(force.z, -3 * kGravity, 0.01 * 3 * kGravity);
      for (const ContactPoint& point : contact.points) EXPECT_NEAR(point.normal.z, -1, 1e-6);
    }
  }
  // Both named: one contact between them, the first named as collision1.
  const std::vector<Contact> both = contactsOf({"upper::link::collision", "lower::link::collision"});
  ASSERT_EQ(both.size(), 2u);
  for (const Contact& contact : both) {
    if (contact.collision2 == kGroundCollision) {
      EXPECT_EQ(contact.collision1, "lower::link::collision");
    } else {
      EXPECT_EQ(contact.collision1, "upper::link::collision");
      EXPECT_EQ(contact.collision2, "lower::link::collision");
      EXPECT_NEAR(totalForce(contact).z, 3 * kGravity, 0.01 * 3 * kGravity);
    }
  }
}

// Two blocks welded side by side into one body (URDF, unnamed collisions), a box on the right
// one: each block's collision keeps its own name, and only the right one meets the box.
TEST_P(ContactReport, WeldedLinksKeepTheirCollisionsNames) {
  const std::string block =
      "<inertial><mass value=\"1\"/><inertia ixx=\"0.01\" ixy=\"0\" ixz=\"0\" iyy=\"0.01\" "
      "iyz=\"0\" izz=\"0.01\"/></inertial><collision><geometry><box size=\"0.2 0.2 0.1\"/>"
      "</geometry></collision>";
  const std::string urdf =
      "<robot name=\"pair\"><link name=\"left\">" + block +
      "</link><joint name=\"weld\" type=\"fixed\"><parent link=\"left\"/><child link=\"right\"/>"
      "<origin xyz=\"0.3 0 0\"/></joint><link name=\"right\">" + block + "</link></robot>";
  spawn("pair", urdf, ModelFormat::Urdf, at(0, 0, 0.05));
  spawn("box", boxSdf("box", 1, {0.1, 0.1, 0.1}), ModelFormat::Sdf, at(0.3, 0, 0.15));
  steps(1000);
  const std::vector<Contact> right = contactsOf({"pair::right::right_collision"});
  ASSERT_EQ(right.size(), 2u);
  for (const Contact& contact : right) {
    EXPECT_EQ(contact.collision1, "pair::right::right_collision");
    EXPECT_TRUE(contact.collision2 == kGroundCollision ||
                contact.collision2 == "box::link::collision")
        << contact.collision2;
  }
  const std::vector<Contact> left = contactsOf({"pair::left::left_collision"});
  ASSERT_EQ(left.size(), 1u);
  EXPECT_EQ(left[0].collision2, kGroundCollision);
  // The ground holds the pair and the box (3 kg) through both blocks.
  const Vec3 total = totalForce(left[0]) + totalForce(right[0]) + totalForce(right[1]);
  EXPECT_NEAR(total.z, 2 * kGravity, 0.01 * 3 * kGravity);
}

TEST_P(ContactReport, NoneBeforeTheFirstStepNorAfterADeletionUntilTheNextStep) {
  spawn("box", boxSdf("box", 1, {0.2, 0.2, 0.2}), ModelFormat::Sdf, at(0, 0, 0.1));
  EXPECT_TRUE(contactsOf({"box::link::collision"}).empty());
  steps(10);
  EXPECT_EQ(contactsOf({"box::link::collision"}).size(), 1u);
  spawn("other", boxSdf("other", 1, {0.2, 0.2, 0.2}), ModelFormat::Sdf, at(2, 0, 0.1));
  ASSERT_TRUE(world_.deleteModel("other").ok());
  EXPECT_TRUE(contactsOf({"box::link::collision"}).empty());
  steps(1);
  EXPECT_EQ(contactsOf({"box::link::collision"}).size(), 1u);
}

TEST_P(ContactReport, RefusesANameThatIsNoCollision) {
  spawn("box", boxSdf("box", 1, {0.2, 0.2, 0.2}), ModelFormat::Sdf, at(0, 0, 0.1));
  steps(10);
  for (const std::string name : {"box::link::nope", "box::link", "nope::link::collision", ""}) {
    std::vector<Contact> found(1);
    const Status status = world_.contacts({"box::link::collision", name}, &found);
    EXPECT_EQ(status.code, StatusCode::CollisionNotFound) << name;
    EXPECT_EQ(status.subject, name);
    EXPECT_TRUE(found.empty());
  }
}

INSTANTIATE_TEST_SUITE_P(Engines, ContactReport, ::testing::ValuesIn(World::engineNames()),
                         [](const auto& info) { return info.param; });

}  // namespace
}  // namespace onedof_sim
