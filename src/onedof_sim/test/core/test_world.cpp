// The contract of the physics core, against closed-form physics: every test runs once per engine
// of the registry (World::engineNames()), so each rule is asserted once for all engines. Each
// drives a World step by step; the figures they print (period, energy drift, penetration) are
// quoted in the README.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <utility>
#include <vector>

#include <tinyxml2.h>

#include "../ground_plane.h"
#include "onedof_sim/world.h"

namespace onedof_sim {
namespace {

constexpr double kG = 9.8;
constexpr double kStep = 0.001;
constexpr int64_t kMs = 1000000;  // ns
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string tutorialUrdf() {
  std::ifstream file(ONEDOF_SOURCE_DIR "/src/minimal_robot_description/minimal_robot_description.urdf");
  std::stringstream text;
  text << file.rdbuf();
  return text.str();
}

// The tutorial robot's figures for the closed forms, read from its URDF, their one source: link2's
// mass, the distance of its COM from joint1's axis (the arm), its moment of inertia about the
// axis through its COM, and the height of joint1 above the model frame (link1 is welded to
// `world` at the model frame). Read with tinyxml2, apart from the loader under test.
struct TutorialRobotFigures {
  double mass = 0, arm = 0, inertia_about_com = 0, joint_height = 0;
  double inertiaAboutJoint() const { return inertia_about_com + mass * arm * arm; }
};

const tinyxml2::XMLElement& child(const tinyxml2::XMLElement& parent, const char* tag,
                                  const char* name = nullptr) {
  for (const tinyxml2::XMLElement* e = parent.FirstChildElement(tag); e;
       e = e->NextSiblingElement(tag))
    if (!name || (e->Attribute("name") && std::string(e->Attribute("name")) == name)) return *e;
  throw std::runtime_error(std::string("the tutorial URDF has no <") + tag + "> " +
                           (name ? name : "") + " in <" + parent.Name() + ">");
}

double number(const tinyxml2::XMLElement& element, const char* attribute) {
  double value = 0;
  if (element.QueryDoubleAttribute(attribute, &value) != tinyxml2::XML_SUCCESS)
    throw std::runtime_error(std::string("the tutorial URDF's <") + element.Name() + "> has no " +
                             attribute);
  return value;
}

Vec3 triple(const tinyxml2::XMLElement& element, const char* attribute) {
  const char* text = element.Attribute(attribute);
  std::istringstream in(text ? text : "0 0 0");
  Vec3 v;
  in >> v.x >> v.y >> v.z;
  return v;
}

TutorialRobotFigures readTutorialRobot() {
  const std::string urdf = tutorialUrdf();
  tinyxml2::XMLDocument document;
  if (document.Parse(urdf.c_str()) != tinyxml2::XML_SUCCESS || !document.RootElement())
    throw std::runtime_error("the tutorial URDF does not parse");
  const tinyxml2::XMLElement& robot = *document.RootElement();
  const tinyxml2::XMLElement& joint = child(robot, "joint", "joint1");
  const tinyxml2::XMLElement& inertial = child(child(robot, "link", "link2"), "inertial");
  const tinyxml2::XMLElement& inertia = child(inertial, "inertia");
  const Vec3 joint_rpy = triple(child(joint, "origin"), "rpy");
  const Vec3 com_rpy = triple(child(inertial, "origin"), "rpy");
  // The closed forms below take joint1's axis and link2's inertia in the model frame's axes.
  if (joint_rpy.x != 0 || joint_rpy.y != 0 || joint_rpy.z != 0 || com_rpy.x != 0 ||
      com_rpy.y != 0 || com_rpy.z != 0)
    throw std::runtime_error("the tutorial URDF turns joint1's origin or link2's inertial frame");
  const Vec3 axis = triple(child(joint, "axis"), "xyz");  // unit, in link2's frame
  const Vec3 com = triple(child(inertial, "origin"), "xyz");  // from joint1, in link2's frame
  const double along = com.x * axis.x + com.y * axis.y + com.z * axis.z;
  const Vec3 across{com.x - along * axis.x, com.y - along * axis.y, com.z - along * axis.z};
  TutorialRobotFigures figures;
  figures.mass = number(child(inertial, "mass"), "value");
  figures.arm = std::hypot(across.x, across.y, across.z);
  // u^T I u for the joint's unit axis u.
  figures.inertia_about_com =
      number(inertia, "ixx") * axis.x * axis.x + number(inertia, "iyy") * axis.y * axis.y +
      number(inertia, "izz") * axis.z * axis.z +
      2 * (number(inertia, "ixy") * axis.x * axis.y + number(inertia, "ixz") * axis.x * axis.z +
           number(inertia, "iyz") * axis.y * axis.z);
  figures.joint_height = triple(child(joint, "origin"), "xyz").z;
  return figures;
}

const TutorialRobotFigures& tutorialRobot() {
  static const TutorialRobotFigures figures = readTutorialRobot();
  return figures;
}

// The tutorial robot with joint1 turned into a revolute joint with these limits.
std::string limitedTutorialUrdf(double lower, double upper) {
  std::string urdf = tutorialUrdf();
  const std::string from = "type=\"continuous\">";
  urdf.replace(urdf.find(from), from.size(),
               "type=\"revolute\"><limit lower=\"" + std::to_string(lower) + "\" upper=\"" +
                   std::to_string(upper) + "\" effort=\"100\" velocity=\"10\"/>");
  return urdf;
}

std::string inertial(double mass, double ixx, double iyy, double izz, const std::string& xyz = "0 0 0",
                     const std::string& rpy = "0 0 0") {
  std::ostringstream s;
  s << "<inertial><origin xyz=\"" << xyz << "\" rpy=\"" << rpy << "\"/><mass value=\"" << mass
    << "\"/><inertia ixx=\"" << ixx << "\" ixy=\"0\" ixz=\"0\" iyy=\"" << iyy
    << "\" iyz=\"0\" izz=\"" << izz << "\"/></inertial>";
  return s.str();
}

// A free box of side `side` and mass 1 (link frame at its centre).
std::string boxUrdf(double side) {
  const double i = side * side / 6;
  std::ostringstream s;
  s << "<robot name=\"box\"><link name=\"box\">" << inertial(1, i, i, i)
    << "<collision><geometry><box size=\"" << side << " " << side << " " << side
    << "\"/></geometry></collision></link></robot>";
  return s.str();
}

// A rotor on a joint about z to the world: inertia `izz` about the axis, effort limit optional.
std::string rotorUrdf(double izz, double effort_limit = 0) {
  std::ostringstream s;
  s << "<robot name=\"rotor\"><link name=\"world\"/><joint name=\"spin\" type=\"continuous\">"
    << "<parent link=\"world\"/><child link=\"rotor\"/><axis xyz=\"0 0 1\"/>";
  if (effort_limit > 0) s << "<limit effort=\"" << effort_limit << "\" velocity=\"100\"/>";
  s << "</joint><link name=\"rotor\">" << inertial(1, 1, 1, izz) << "</link></robot>";
  return s.str();
}

std::string cafeTableSdf() {
  auto box = [](const char* name, const char* size, double z) {
    std::ostringstream s;
    s << "<collision name=\"" << name << "\"><pose>0 0 " << z << " 0 0 0</pose><geometry><box><size>"
      << size << "</size></box></geometry></collision>";
    return s.str();
  };
  return "<?xml version=\"1.0\"?><sdf version=\"1.6\"><model name=\"cafe_table\"><static>true</static>"
         "<link name=\"link\">" +
         box("surface", "0.913 0.913 0.04", 0.755) + box("column", "0.042 0.042 0.74", 0.37) +
         box("base", "0.56 0.56 0.04", 0.02) + "</link></model></sdf>";
}

Pose at(double x, double y, double z) {
  Pose p;
  p.position = {x, y, z};
  return p;
}

double jointPosition(const World& world, const std::string& joint) {
  JointInfo info;
  EXPECT_TRUE(world.jointInfo(joint, &info).ok());
  return info.position;
}

double jointRate(const World& world, const std::string& joint) {
  JointInfo info;
  EXPECT_TRUE(world.jointInfo(joint, &info).ok());
  return info.rate;
}

void steps(World* world, int count) {
  for (int i = 0; i < count; ++i) world->step();
}

PhysicsParams withoutGravity() {
  PhysicsParams params;
  params.gravity = {0, 0, 0};
  return params;
}

// The tutorial robot lifted kLift so that link2 hanging down clears the ground.
constexpr double kLift = 0.5;
void spawnLiftedRobot(World* world) {
  ASSERT_TRUE(world->spawn("one_DOF_robot", tutorialUrdf(), ModelFormat::Urdf, at(0, 0, kLift)).ok());
}

// One fixture per suite, each instantiated for every engine (see the end of the file).
class BodyWrench : public ::testing::TestWithParam<std::string> {};
class Contacts : public ::testing::TestWithParam<std::string> {};
class Errors : public ::testing::TestWithParam<std::string> {};
class Joints : public ::testing::TestWithParam<std::string> {};
class LinkProperties : public ::testing::TestWithParam<std::string> {};
class Models : public ::testing::TestWithParam<std::string> {};
class Robustness : public ::testing::TestWithParam<std::string> {};
class BadInput : public ::testing::TestWithParam<std::string> {};
class PreparedModels : public ::testing::TestWithParam<std::string> {};
class State : public ::testing::TestWithParam<std::string> {};
class TutorialRobot : public ::testing::TestWithParam<std::string> {};

TEST_P(TutorialRobot, SpawnsLikeTheTutorialSays) {
  World world(GetParam());
  const Status status =
      world.spawn("one_DOF_robot", tutorialUrdf(), ModelFormat::Urdf, Pose());
  ASSERT_TRUE(status.ok()) << status;
  JointInfo info;
  ASSERT_TRUE(world.jointInfo("joint1", &info).ok());
  EXPECT_EQ(info.type, JointType::Continuous);
  EXPECT_FALSE(info.has_damping);
  EXPECT_EQ(info.position, 0.0);
  EXPECT_EQ(info.rate, 0.0);
  EXPECT_TRUE(world.jointInfo("one_DOF_robot::joint1", &info).ok());
  ModelInfo model;
  ASSERT_TRUE(world.modelProperties("one_DOF_robot", &model).ok());
  EXPECT_EQ(model.canonical_link, "one_DOF_robot::link1");
  EXPECT_EQ(model.links, (std::vector<std::string>{"one_DOF_robot::link1", "one_DOF_robot::link2"}));
  EXPECT_EQ(model.joints, (std::vector<std::string>{"glue_robot_to_world", "joint1"}));
}

// The period of a small swing of the tutorial robot's joint1 about the lowest point (q = pi),
// from the joint's upward crossings over five periods.
double smallSwingPeriod(World* world) {
  EXPECT_TRUE(world->setModelConfiguration("one_DOF_robot", {"joint1"}, {M_PI - 0.01}).ok());
  std::vector<double> upward_crossings;  // times where q - pi goes from < 0 to >= 0
  double previous = jointPosition(*world, "joint1") - M_PI;
  while (upward_crossings.size() < 6 && world->time() < 60) {
    world->step();
    const double offset = jointPosition(*world, "joint1") - M_PI;
    if (previous < 0 && offset >= 0)
      upward_crossings.push_back(world->time() - kStep * offset / (offset - previous));
    previous = offset;
  }
  EXPECT_EQ(upward_crossings.size(), 6u) << "no small swing within 60 s";
  return upward_crossings.size() < 6 ? 0 : (upward_crossings.back() - upward_crossings.front()) / 5;
}

// The compound pendulum: T = 2 pi sqrt(I_pivot / (m g d)), I_pivot = I_com + m d^2.
double compoundPendulumPeriod(double mass, double inertia_about_com, double arm) {
  return 2 * M_PI * std::sqrt((inertia_about_com + mass * arm * arm) / (mass * kG * arm));
}

// 1. Small swing about the lowest point: T = 2 pi sqrt(I / (m g d)).
TEST_P(TutorialRobot, SmallSwingHasTheCompoundPendulumPeriod) {
  World world(GetParam());
  spawnLiftedRobot(&world);
  const double period = smallSwingPeriod(&world);
  const TutorialRobotFigures& robot = tutorialRobot();
  const double expected =
      2 * M_PI * std::sqrt(robot.inertiaAboutJoint() / (robot.mass * kG * robot.arm));
  std::printf("[ figures  ] period %.5f s, expected %.5f s, error %.4f %%\n", period, expected,
              100 * (period / expected - 1));
  EXPECT_NEAR(period, expected, 0.005 * expected);
}

// 2. Undamped large swing: energy (above the lowest COM height) stays within 1 %.
TEST_P(TutorialRobot, UndampedSwingKeepsItsEnergy) {
  World world(GetParam());
  spawnLiftedRobot(&world);
  ASSERT_TRUE(world.setModelConfiguration("one_DOF_robot", {"joint1"}, {1.0}).ok());
  // COM height above its lowest point is d (1 + cos q).
  const TutorialRobotFigures& robot = tutorialRobot();
  auto energy = [&] {
    const double q = jointPosition(world, "joint1"), w = jointRate(world, "joint1");
    return 0.5 * robot.inertiaAboutJoint() * w * w +
           robot.mass * kG * robot.arm * (1 + std::cos(q));
  };
  const double initial = energy();
  double worst = 0;
  for (int i = 0; i < 10000; ++i) {
    world.step();
    worst = std::max(worst, std::abs(energy() / initial - 1));
  }
  std::printf("[ figures  ] energy drift over 10 s: worst %.4f %%, final %.4f %%\n", 100 * worst,
              100 * (energy() / initial - 1));
  EXPECT_LT(worst, 0.01);
}

// 3. Sign convention (axis +y): q > 0 tilts link2 toward +x, gravity's torque about +y is
// +m g d sin q, so the effort that holds it at q is -m g d sin q.
TEST_P(TutorialRobot, ConstantEffortHoldsTheLinkWhereItBalancesGravity) {
  const TutorialRobotFigures& robot = tutorialRobot();
  const double hold = 2.0;
  const double effort = -robot.mass * kG * robot.arm * std::sin(hold);
  for (double sign : {1.0, -1.0}) {
    World world(GetParam());
    spawnLiftedRobot(&world);
    ASSERT_TRUE(world.setModelConfiguration("one_DOF_robot", {"joint1"}, {hold}).ok());
    Pose pose;
    Twist twist;
    ASSERT_TRUE(world.linkState("one_DOF_robot::link2", "", &pose, &twist).ok());
    ASSERT_TRUE(world.applyJointEffort("joint1", sign * effort, 0, -1).ok());
    double worst = 0;
    for (int i = 0; i < 3000; ++i) {
      world.step();
      worst = std::max(worst, std::abs(jointPosition(world, "joint1") - hold));
    }
    if (sign > 0) {
      std::printf("[ figures  ] held at q = %.1f within %.2e rad\n", hold, worst);
      EXPECT_LT(worst, 0.005);
    } else {
      EXPECT_GT(worst, 0.1) << "the opposite effort must not hold it";
    }
  }
  // And without effort, gravity makes q grow at q = 2 (toward the bottom at pi).
  World world(GetParam());
  spawnLiftedRobot(&world);
  ASSERT_TRUE(world.setModelConfiguration("one_DOF_robot", {"joint1"}, {hold}).ok());
  world.step();
  EXPECT_NEAR(jointRate(world, "joint1"),
              kStep * robot.mass * kG * robot.arm * std::sin(hold) / robot.inertiaAboutJoint(), 1e-6);
}

// Joint damping on the tutorial link, at the top of the accepted range (setJointDamping refuses
// more than 1e6 N m s/rad) and below. The world applies it implicitly: an explicit -b qdot
// reverses the joint with a growing speed past b = 2 I / dt (700 N m s/rad here).
constexpr double kTopDamping = 1e6;

double balancingEffort(double q) {
  const TutorialRobotFigures& robot = tutorialRobot();
  return -robot.mass * kG * robot.arm * std::sin(q);
}

// The robot at joint position q, at rest, with damping and an endless constant effort.
void dampedRobot(World* world, double q, double damping, double effort) {
  spawnLiftedRobot(world);
  ASSERT_TRUE(world->setModelConfiguration("one_DOF_robot", {"joint1"}, {q}).ok());
  ASSERT_TRUE(world->setJointDamping("joint1", damping).ok());
  ASSERT_TRUE(world->applyJointEffort("joint1", effort, 0, -1).ok());
}

// Where the effort balances gravity the link stays, on the upright side (a balance gravity alone
// would tip over) and on the hanging side; released there at 2 rad/s it stops after I w0 / b.
TEST_P(TutorialRobot, TopDampingHoldsTheLinkWhereItsEffortBalancesGravity) {
  const double inertia = tutorialRobot().inertiaAboutJoint();
  for (double balance : {0.51, 2.5}) {
    for (double speed : {0.0, 2.0}) {
      World world(GetParam());
      dampedRobot(&world, balance, kTopDamping, balancingEffort(balance));
      Pose pose;
      Twist twist;
      ASSERT_TRUE(world.linkState("one_DOF_robot::link2", "", &pose, &twist).ok());
      // link2's frame sits on joint1's axis: turning about it moves its origin not at all.
      twist = Twist();
      twist.angular.y = speed;
      ASSERT_TRUE(world.setLinkState("one_DOF_robot::link2", pose, twist, "").ok());
      const double travel = inertia * speed / kTopDamping;
      double worst = 0;
      for (int i = 0; i < 3000; ++i) {
        world.step();
        worst = std::max(worst, std::abs(jointPosition(world, "joint1") - balance));
      }
      std::printf("[ figures  ] damping %g at q = %.2f from %.0f rad/s: within %.2e rad of it "
                  "(a damper: %.2e), rate %.1e rad/s\n",
                  kTopDamping, balance, speed, worst, travel, jointRate(world, "joint1"));
      EXPECT_LT(worst, travel + 1e-7);
      EXPECT_LT(std::abs(jointRate(world, "joint1")), 1e-6);
    }
  }
}

// Off the balance, a damping far above the link's own swing makes it creep toward the balance on
// the overdamped law: the offset decays as exp(-k t / b), k = m g d |cos q| (the slow root of
// I s^2 + b s + k; the fast one, -b / I, is gone within a step), never overshooting. Both values
// are past the explicit law's limit.
TEST_P(TutorialRobot, TopDampingCreepsToTheBalanceOnTheOverdampedLaw) {
  const TutorialRobotFigures& robot = tutorialRobot();
  const double balance = M_PI, offset = 0.05;  // hanging straight down, no effort
  const double stiffness = robot.mass * kG * robot.arm;
  for (double damping : {1000.0, kTopDamping}) {
    World world(GetParam());
    dampedRobot(&world, balance + offset, damping, 0);
    const int count = 100000;  // 100 s
    double previous = offset;
    bool monotonic = true;
    for (int i = 0; i < count; ++i) {
      world.step();
      const double now = jointPosition(world, "joint1") - balance;
      monotonic = monotonic && now <= previous && now > 0;
      previous = now;
    }
    const double expected = offset * std::exp(-stiffness * count * kStep / damping);
    std::printf("[ figures  ] damping %g: offset %.6e rad after 100 s, overdamped law %.6e\n",
                damping, previous, expected);
    EXPECT_TRUE(monotonic);
    EXPECT_NEAR(offset - previous, offset - expected, 0.01 * (offset - expected));
  }
}

// A light damping b: the swing's amplitude decays as exp(-b t / (2 I)).
TEST_P(TutorialRobot, LightDampingDecaysAsTheClosedForm) {
  const double damping = 0.05, amplitude = 0.05;
  const double inertia = tutorialRobot().inertiaAboutJoint();
  World world(GetParam());
  dampedRobot(&world, M_PI + amplitude, damping, 0);
  std::vector<std::pair<double, double>> peaks;  // (t, offset) at each maximum
  double before = amplitude, last = amplitude;
  for (int i = 1; i <= 20000; ++i) {
    world.step();
    const double now = jointPosition(world, "joint1") - M_PI;
    if (last > before && last >= now) peaks.push_back({(i - 1) * kStep, last});
    before = last;
    last = now;
  }
  ASSERT_GE(peaks.size(), 5u);
  const double span = peaks.back().first - peaks.front().first;
  const double ratio = peaks.back().second / peaks.front().second;
  const double expected = std::exp(-damping * span / (2 * inertia));
  std::printf("[ figures  ] damping %g: amplitude ratio %.5f over %.2f s, closed form %.5f\n",
              damping, ratio, span, expected);
  EXPECT_NEAR(ratio, expected, 0.005 * expected);
}

// 4. A free prismatic joint along z under gravity: q = -g t^2 / 2. ODE integrates semi-implicitly
// (v first, then x with the new v), so after n steps q = -g dt^2 n (n + 1) / 2 exactly, which is
// the closed form minus g t dt / 2.
TEST_P(Joints, PrismaticFallsFreely) {
  World world(GetParam());
  const std::string urdf =
      "<robot name=\"lift\"><link name=\"world\"/><joint name=\"slide\" type=\"prismatic\">"
      "<parent link=\"world\"/><child link=\"carriage\"/><axis xyz=\"0 0 1\"/>"
      "<limit lower=\"-100\" upper=\"100\" effort=\"100\" velocity=\"100\"/></joint>"
      "<link name=\"carriage\">" + inertial(2, 0.1, 0.1, 0.1) + "</link></robot>";
  ASSERT_TRUE(world.spawn("lift", urdf, ModelFormat::Urdf, at(0, 0, 10)).ok());
  double worst = 0;
  for (int n = 1; n <= 1000; ++n) {
    world.step();
    const double t = n * kStep;
    const double q = jointPosition(world, "slide");
    worst = std::max(worst, std::abs(q + kG * t * t / 2));
    ASSERT_NEAR(q, -kG * kStep * kStep * n * (n + 1) / 2, 1e-9);
    ASSERT_NEAR(jointRate(world, "slide"), -kG * t, 1e-9);
  }
  std::printf("[ figures  ] prismatic fall, worst |q + g t^2/2| over 1 s: %.3e m\n", worst);
  EXPECT_LE(worst, kG * 1.0 * kStep / 2 + 1e-9);
}

// 5. link2 falls from 0.3 toward +q and is stopped by the upper limit 0.5.
TEST_P(Joints, RevoluteLimitStopsTheJoint) {
  World world(GetParam());
  ASSERT_TRUE(world.spawn("robot", limitedTutorialUrdf(-0.5, 0.5), ModelFormat::Urdf, Pose()).ok());
  ASSERT_TRUE(world.setModelConfiguration("robot", {"joint1"}, {0.3}).ok());
  double highest = 0;
  for (int i = 0; i < 2000; ++i) {
    world.step();
    highest = std::max(highest, jointPosition(world, "joint1"));
  }
  std::printf("[ figures  ] revolute limit 0.5: highest q %.4f, final q %.4f\n", highest,
              jointPosition(world, "joint1"));
  EXPECT_LT(highest, 0.52);
  EXPECT_NEAR(jointPosition(world, "joint1"), 0.5, 0.01);
  EXPECT_NEAR(jointRate(world, "joint1"), 0, 0.01);
}

TEST_P(Joints, ContinuousJointIsNotWrapped) {
  World world(GetParam(), withoutGravity());
  ASSERT_TRUE(world.spawn("rotor", rotorUrdf(0.5), ModelFormat::Urdf, Pose()).ok());
  ASSERT_TRUE(world.applyJointEffort("spin", 1.0, 0, -1).ok());
  double previous = 0;
  for (int i = 0; i < 4000; ++i) {  // q = t^2 reaches 16 rad
    world.step();
    const double q = jointPosition(world, "spin");
    ASSERT_GE(q, previous);
    previous = q;
  }
  EXPECT_NEAR(previous, 16.0, 0.01);
  ASSERT_TRUE(world.setModelConfiguration("rotor", {"spin"}, {7.0}).ok());
  EXPECT_DOUBLE_EQ(jointPosition(world, "spin"), 7.0);
  world.step();
  EXPECT_NEAR(jointPosition(world, "spin"), 7.0, 1e-5);
}

TEST_P(Joints, ViscousDampingSlowsTheJoint) {
  World world(GetParam(), withoutGravity());
  std::string urdf = rotorUrdf(0.5);
  urdf.replace(urdf.find("</joint>"), 8, "<dynamics damping=\"0.5\"/></joint>");
  ASSERT_TRUE(world.spawn("rotor", urdf, ModelFormat::Urdf, Pose()).ok());
  JointInfo info;
  ASSERT_TRUE(world.jointInfo("spin", &info).ok());
  EXPECT_TRUE(info.has_damping);
  EXPECT_EQ(info.damping, 0.5);
  // Terminal speed under a constant effort: tau / d.
  ASSERT_TRUE(world.applyJointEffort("spin", 1.0, 0, -1).ok());
  steps(&world, 10000);
  EXPECT_NEAR(jointRate(world, "spin"), 2.0, 1e-3);
}

// 6.
TEST_P(Contacts, FallingBoxRestsOnTheGround) {
  World world(GetParam());
  testing_support::addGroundPlane(world);
  const double side = 0.2;
  ASSERT_TRUE(world.spawn("box", boxUrdf(side), ModelFormat::Urdf, at(0, 0, 0.5)).ok());
  steps(&world, 2000);
  Pose pose;
  Twist twist;
  ASSERT_TRUE(world.modelState("box", "", &pose, &twist).ok());
  const double penetration = side / 2 - pose.position.z;
  std::printf("[ figures  ] box at rest on the ground: penetration %.2f mm, speed %.1e m/s\n",
              1000 * penetration, std::hypot(twist.linear.x, twist.linear.y, twist.linear.z));
  EXPECT_LT(penetration, 0.005);
  EXPECT_GT(penetration, -0.001);
  EXPECT_LT(std::hypot(twist.linear.x, twist.linear.y, twist.linear.z), 1e-3);
}

// 7. Effort jobs, on a rotor of inertia 0.5 without gravity: its speed after the steps a job
// covered is effort * steps * dt / I.
class EffortJobs : public ::testing::TestWithParam<std::string> {
 protected:
  static constexpr double kInertia = 0.5;
  void SetUp() override {
    ASSERT_TRUE(world.spawn("rotor", rotorUrdf(kInertia, 2.0), ModelFormat::Urdf, Pose()).ok());
  }
  double speedAfter(double effort, int covered_steps) const {
    return effort * covered_steps * kStep / kInertia;
  }
  World world{GetParam(), withoutGravity()};
};

TEST_P(EffortJobs, TenMillisecondJobActsOnExactlyTenSteps) {
  JobOutcome job;
  ASSERT_TRUE(world.applyJointEffort("spin", 1.0, 0, 10 * kMs, &job).ok());
  EXPECT_TRUE(job.queued);
  EXPECT_FALSE(job.widened_to_one_step);
  EXPECT_FALSE(job.effort_limit || job.safe_effort || job.safe_wrench);
  steps(&world, 30);
  EXPECT_NEAR(jointRate(world, "spin"), speedAfter(1.0, 10), 1e-12);
}

TEST_P(EffortJobs, BackToBackJobsGiveAConstantEffort) {
  for (int job = 0; job < 5; ++job)
    ASSERT_TRUE(world.applyJointEffort("spin", 1.0, job * 10 * kMs, 10 * kMs).ok());
  for (int n = 1; n <= 60; ++n) {
    world.step();
    ASSERT_NEAR(jointRate(world, "spin"), speedAfter(1.0, std::min(n, 50)), 1e-12) << "step " << n;
  }
}

TEST_P(EffortJobs, StartInThePastMeansNowAndFutureStartsWait) {
  steps(&world, 5);
  ASSERT_TRUE(world.applyJointEffort("spin", 1.0, 0, 10 * kMs).ok());  // covers steps 5..14
  ASSERT_TRUE(world.applyJointEffort("spin", 1.0, 20 * kMs, 3 * kMs).ok());  // steps 20..22
  steps(&world, 15);
  EXPECT_NEAR(jointRate(world, "spin"), speedAfter(1.0, 10), 1e-12);
  steps(&world, 10);
  EXPECT_NEAR(jointRate(world, "spin"), speedAfter(1.0, 13), 1e-12);
}

TEST_P(EffortJobs, ForeverUntilCleared) {
  ASSERT_TRUE(world.applyJointEffort("spin", 1.0, 0, -1).ok());
  steps(&world, 30);
  world.clearJointForces("spin");
  steps(&world, 10);
  EXPECT_NEAR(jointRate(world, "spin"), speedAfter(1.0, 30), 1e-12);
}

TEST_P(EffortJobs, JobsOnOneJointSum) {
  ASSERT_TRUE(world.applyJointEffort("spin", 0.5, 0, 10 * kMs).ok());
  ASSERT_TRUE(world.applyJointEffort("spin", 1.0, 0, 10 * kMs).ok());
  steps(&world, 20);
  EXPECT_NEAR(jointRate(world, "spin"), speedAfter(1.5, 10), 1e-12);
}

TEST_P(EffortJobs, ZeroDurationAppliesNothing) {
  JobOutcome job;
  ASSERT_TRUE(world.applyJointEffort("spin", 1.0, 0, 0, &job).ok());
  EXPECT_FALSE(job.queued);
  steps(&world, 10);
  EXPECT_EQ(jointRate(world, "spin"), 0.0);
}

TEST_P(EffortJobs, DurationShorterThanTheStepActsForExactlyOneStep) {
  steps(&world, 3);
  JobOutcome job;
  ASSERT_TRUE(world.applyJointEffort("spin", 1.0, world.timeNs() + kMs / 2, kMs / 3, &job).ok());
  EXPECT_TRUE(job.widened_to_one_step);
  steps(&world, 10);
  EXPECT_NEAR(jointRate(world, "spin"), speedAfter(1.0, 1), 1e-12);
}

TEST_P(EffortJobs, EffortIsClampedToTheLimit) {
  JobOutcome job;
  ASSERT_TRUE(world.applyJointEffort("spin", -5.0, 0, 10 * kMs, &job).ok());
  EXPECT_EQ(job.effort_limit, 2.0);
  EXPECT_FALSE(job.safe_effort);
  steps(&world, 10);
  EXPECT_NEAR(jointRate(world, "spin"), speedAfter(-2.0, 10), 1e-12);
}

TEST_P(EffortJobs, NonFiniteEffortIsRefused) {
  for (double effort : {kNaN, std::numeric_limits<double>::infinity()}) {
    const Status status = world.applyJointEffort("spin", effort, 0, -1);
    EXPECT_EQ(status.code, StatusCode::NotFinite);
    EXPECT_EQ(status.subject, "effort");
  }
  steps(&world, 5);
  EXPECT_EQ(jointRate(world, "spin"), 0.0);
}

TEST_P(BodyWrench, ForceAtTheCentreForTenMilliseconds) {
  World world(GetParam(), withoutGravity());
  ASSERT_TRUE(world.spawn("box", boxUrdf(0.2), ModelFormat::Urdf, at(0, 0, 1)).ok());
  ASSERT_TRUE(world.applyBodyWrench("box::box", "", {0, 0, 1}, {2, 0, 0}, {0, 0, 0}, 0, 10 * kMs).ok());
  steps(&world, 20);
  Pose pose;
  Twist twist;
  ASSERT_TRUE(world.linkState("box::box", "", &pose, &twist).ok());
  EXPECT_NEAR(twist.linear.x, 2 * 10 * kStep / 1.0, 1e-12);
  EXPECT_NEAR(twist.angular.y, 0, 1e-12);
  // A force off the centre also turns it: torque = r x F about the centre.
  ASSERT_TRUE(world.applyBodyWrench("box::box", "box::box", {0, 0, 0.1}, {1, 0, 0}, {0, 0, 0}, 0,
                                    kMs).ok());
  world.step();
  ASSERT_TRUE(world.linkState("box::box", "", &pose, &twist).ok());
  EXPECT_NEAR(twist.angular.y, 0.1 * kStep / (0.04 / 6), 1e-7);
  world.clearBodyWrenches("box::box");
  JobOutcome job;
  ASSERT_TRUE(world.applyBodyWrench("box::box", "", {}, {1e9, 0, 0}, {}, 0, kMs, &job).ok());
  ASSERT_TRUE(job.safe_wrench);
  EXPECT_LT(job.safe_wrench->force, 1e9);
}

// 8. Every refused call leaves the world as it was.
std::string snapshot(const World& world) {
  std::ostringstream s;
  s.precision(17);
  s << world.timeNs() << " " << world.params().step << ";";
  for (const std::string& model : world.modelNames()) {
    Pose pose;
    Twist twist;
    world.modelState(model, "", &pose, &twist);
    s << model << " " << pose.position.x << " " << pose.position.y << " " << pose.position.z << " "
      << pose.orientation.w << ";";
  }
  for (const std::string& link : world.linkNames()) {
    Pose pose;
    Twist twist;
    world.linkState(link, "", &pose, &twist);
    s << link << " " << pose.position.x << " " << pose.position.z << ";";
  }
  s << world.collisionShapes().size();
  return s.str();
}

TEST_P(Errors, RefusedCallsLeaveTheWorldUnchanged) {
  World world(GetParam());
  ASSERT_TRUE(world.spawn("one_DOF_robot", tutorialUrdf(), ModelFormat::Urdf, Pose()).ok());
  ASSERT_TRUE(world.setModelConfiguration("one_DOF_robot", {"joint1"}, {0.4}).ok());
  const std::string before = snapshot(world);
  auto refused = [&](const Status& status, StatusCode code, const std::string& subject) {
    EXPECT_EQ(status.code, code) << status;
    EXPECT_EQ(status.subject, subject) << status;
    EXPECT_EQ(snapshot(world), before) << status;
  };
  refused(world.spawn("one_DOF_robot", boxUrdf(0.1), ModelFormat::Urdf, Pose()),
          StatusCode::ModelExists, "one_DOF_robot");
  refused(world.spawn("box", boxUrdf(0.1), ModelFormat::Urdf, Pose(), "nowhere::link"),
          StatusCode::ReferenceFrameNotFound, "nowhere::link");
  refused(world.spawn("box", boxUrdf(0.1), ModelFormat::Urdf, at(kNaN, 0, 0)),
          StatusCode::NotFinite, "pose");
  Pose no_rotation;
  no_rotation.orientation = {0, 0, 0, 0};
  refused(world.spawn("box", boxUrdf(0.1), ModelFormat::Urdf, no_rotation),
          StatusCode::ZeroQuaternion, "pose");
  refused(world.spawn("", boxUrdf(0.1), ModelFormat::Urdf, Pose()), StatusCode::EmptyModelName, "");
  refused(world.deleteModel("nope"), StatusCode::ModelNotFound, "nope");
  JointInfo joint;
  refused(world.jointInfo("nope", &joint), StatusCode::JointNotFound, "nope");
  Pose pose;
  Twist twist;
  refused(world.modelState("one_DOF_robot", "nowhere", &pose, &twist),
          StatusCode::ReferenceFrameNotFound, "nowhere");
  refused(world.linkState("link2", "", &pose, &twist), StatusCode::LinkNotFound, "link2");
  refused(world.setModelState("nope", at(0, kNaN, 0), Twist(), ""), StatusCode::NotFinite, "pose");
  twist.angular.y = kNaN;
  refused(world.setLinkState("one_DOF_robot::link2", Pose(), twist, ""), StatusCode::NotFinite,
          "twist");
  refused(world.setLinkState("one_DOF_robot::link1", Pose(), Twist(), ""),
          StatusCode::LinkAnchored, "one_DOF_robot::link1");
  refused(world.setModelConfiguration("nope", {"joint1"}, {}), StatusCode::LengthMismatch, "");
  refused(world.setModelConfiguration("nope", {"joint1"}, {kNaN}), StatusCode::NotFinite, "joint1");
  refused(world.setModelConfiguration("one_DOF_robot", {"nope"}, {1}), StatusCode::JointNotFound,
          "nope");
  refused(world.applyJointEffort("glue_robot_to_world", 1, 0, -1), StatusCode::JointIsFixed,
          "glue_robot_to_world");
  refused(world.applyBodyWrench("nope::link", "", {}, {kNaN, 0, 0}, {}, 0, -1),
          StatusCode::NotFinite, "force");
  refused(world.applyBodyWrench("one_DOF_robot::link1", "", {}, {}, {}, 0, -1),
          StatusCode::LinkAnchored, "one_DOF_robot::link1");
  ModelInfo model;
  refused(world.modelProperties("nope", &model), StatusCode::ModelNotFound, "nope");
  LinkInfo link;
  refused(world.linkProperties("one_DOF_robot::nope", &link), StatusCode::LinkNotFound,
          "one_DOF_robot::nope");
  for (double step : {0.0, -0.001, 1e-10}) {
    PhysicsParams params;
    params.step = step;
    refused(world.setParams(params), StatusCode::OutOfRange, "step");
  }
  PhysicsParams params;
  params.gravity.z = std::numeric_limits<double>::infinity();
  refused(world.setParams(params), StatusCode::NotFinite, "gravity");
  params = PhysicsParams();
  params.sor_pgs_w = 0;
  refused(world.setParams(params), StatusCode::OutOfRange, "sor_pgs_w");
  params = PhysicsParams();
  params.max_contacts = 0x10000;
  refused(world.setParams(params), StatusCode::OutOfRange, "max_contacts");
}

TEST_P(Errors, UnsupportedContentIsRefused) {
  World world(GetParam());
  const std::string massless =
      "<robot name=\"r\"><link name=\"a\"/><link name=\"b\"/><joint name=\"j\" type=\"continuous\">"
      "<parent link=\"a\"/><child link=\"b\"/></joint></robot>";
  const auto rejectedFor = [&](const std::string& xml, ModelFormat format, const std::string& why) {
    const Status status = world.spawn("r", xml, format, Pose());
    EXPECT_EQ(status.code, StatusCode::ModelRejected) << status;
    EXPECT_NE(status.subject.find(why), std::string::npos) << status;
  };
  rejectedFor("<robot name=\"x\"><link", ModelFormat::Urdf, "invalid URDF");
  rejectedFor(cafeTableSdf(), ModelFormat::Urdf, "robot");
  rejectedFor("<sdf version=\"1.6\"><model", ModelFormat::Sdf, "invalid SDF");
  rejectedFor(massless, ModelFormat::Urdf, "no mass");
  const std::string mesh =
      "<robot name=\"r\"><link name=\"a\">" + inertial(1, 1, 1, 1) +
      "<collision><geometry><mesh filename=\"x.stl\"/></geometry></collision></link></robot>";
  EXPECT_TRUE(world.modelNames().empty());
  // A mesh found nowhere leaves its collision out, as Gazebo does: the model is spawned.
  PreparedModel without_mesh = World::prepare(mesh, ModelFormat::Urdf, {});
  ASSERT_TRUE(without_mesh.status().ok()) << without_mesh.status();
  ASSERT_EQ(without_mesh.leftOut().size(), 1u);
  EXPECT_NE(without_mesh.leftOut()[0].find("the mesh 'x.stl', which is not found"),
            std::string::npos);
}

// 9. A 7-joint arm (alternating axes y and x, 0.3 m links) hangs down under gravity.
std::string sevenJointArmUrdf() {
  std::ostringstream s;
  s << "<robot name=\"arm\"><link name=\"world\"/><joint name=\"base_joint\" type=\"fixed\">"
       "<parent link=\"world\"/><child link=\"base\"/></joint><link name=\"base\">"
    << inertial(5, 0.1, 0.1, 0.1, "0 0 0.05")
    << "<collision><origin xyz=\"0 0 0.05\"/><geometry><box size=\"0.2 0.2 0.1\"/></geometry>"
       "</collision></link>";
  std::string parent = "base";
  for (int i = 1; i <= 7; ++i) {
    const std::string link = "link" + std::to_string(i);
    s << "<joint name=\"joint" << i << "\" type=\"revolute\"><parent link=\"" << parent
      << "\"/><child link=\"" << link << "\"/><origin xyz=\"0 0 " << (i == 1 ? 0.1 : 0.3)
      << "\"/><axis xyz=\"" << (i % 2 ? "0 1 0" : "1 0 0")
      << "\"/><limit lower=\"-2.9\" upper=\"2.9\" effort=\"100\" velocity=\"5\"/>"
         "<dynamics damping=\"0.05\"/></joint><link name=\""
      << link << "\">" << inertial(1, 0.0085, 0.0085, 0.0013, "0 0 0.15")
      << "<collision><origin xyz=\"0 0 0.15\"/><geometry><cylinder radius=\"0.04\" length=\"0.26\"/>"
         "</geometry></collision></link>";
    parent = link;
  }
  s << "</robot>";
  return s.str();
}

TEST_P(Models, SevenJointArmLoadsAndMoves) {
  World world(GetParam());
  ASSERT_TRUE(world.spawn("arm", sevenJointArmUrdf(), ModelFormat::Urdf, at(0, 0, 0.5)).ok());
  std::vector<std::string> joints;
  std::vector<double> start;
  for (int i = 1; i <= 7; ++i) {
    joints.push_back("joint" + std::to_string(i));
    start.push_back(0.2);
  }
  ASSERT_TRUE(world.setModelConfiguration("arm", joints, start).ok());
  for (int i = 1; i <= 7; ++i) EXPECT_NEAR(jointPosition(world, joints[i - 1]), 0.2, 1e-12);
  Pose tip_before;
  Twist twist;
  ASSERT_TRUE(world.linkState("arm::link7", "", &tip_before, &twist).ok());
  steps(&world, 2000);
  Pose tip;
  ASSERT_TRUE(world.linkState("arm::link7", "", &tip, &twist).ok());
  EXPECT_LT(tip.position.z, tip_before.position.z - 0.3) << "the arm folds down under gravity";
  for (const std::string& joint : joints) EXPECT_TRUE(std::isfinite(jointPosition(world, joint)));
  const std::vector<std::string> warnings = world.takeWarnings();
  EXPECT_TRUE(warnings.empty()) << warnings.front();
}

// The static cafe table alone in the world, at x: its geoms and boxes.
void expectCafeTableAt(const World& world, double x) {
  ModelInfo info;
  ASSERT_TRUE(world.modelProperties("cafe_table", &info).ok());
  EXPECT_TRUE(info.is_static);
  EXPECT_EQ(info.geoms, (std::vector<std::string>{"surface", "column", "base"}));
  const std::vector<CollisionShape> shapes = world.collisionShapes();
  ASSERT_EQ(shapes.size(), 3u);
  EXPECT_NEAR(shapes[0].pose.position.x, x, 1e-12);
  EXPECT_NEAR(shapes[0].pose.position.z, 0.755, 1e-12);
  EXPECT_NEAR(shapes[2].size.x, 0.56, 1e-12);
}

TEST_P(Models, CafeTableIsStaticAndHoldsABox) {
  World world(GetParam());
  const Status table = world.spawn("cafe_table", cafeTableSdf(), ModelFormat::Sdf, at(1, 0, 0));
  ASSERT_TRUE(table.ok()) << table;
  expectCafeTableAt(world, 1.0);
  const double side = 0.1;
  ASSERT_TRUE(world.spawn("box", boxUrdf(side), ModelFormat::Urdf, at(1.1, 0.1, 1.2)).ok());
  steps(&world, 2000);
  Pose pose, table_pose;
  Twist twist;
  ASSERT_TRUE(world.modelState("box", "", &pose, &twist).ok());
  std::printf("[ figures  ] box on the table: bottom at z %.4f (top 0.775)\n", pose.position.z - side / 2);
  EXPECT_NEAR(pose.position.z - side / 2, 0.775, 0.005);
  ASSERT_TRUE(world.modelState("cafe_table", "", &table_pose, &twist).ok());
  EXPECT_NEAR(table_pose.position.x, 1.0, 1e-12);
  EXPECT_NEAR(table_pose.position.z, 0.0, 1e-12);
}

// What gazebo_ros' spawn_model sends for -database NAME (its MODEL_DATABASE_TEMPLATE); Gazebo's
// spawn service adds <name> and, from initial_pose, <pose> to the include, which `extra` stands for.
std::string databaseRequestSdf(const std::string& name, const std::string& extra = "") {
  return "<sdf version=\"1.4\"><world name=\"default\"><include><uri>model://" + name +
         "</uri>" + extra + "</include></world></sdf>";
}

TEST_P(Models, DatabaseIncludeResolvesThroughTheModelPath) {
  World world(GetParam());
  const Status unresolved =
      world.spawn("cafe_table", databaseRequestSdf("cafe_table"), ModelFormat::Sdf, at(0.85, 0, 0));
  EXPECT_EQ(unresolved.code, StatusCode::ModelRejected) << unresolved;
  EXPECT_NE(unresolved.subject.find("model://cafe_table is not in the model path"),
            std::string::npos) << unresolved;

  world.setModelPath({"/nonexistent", ONEDOF_SOURCE_DIR "/src/onedof_sim/models"});
  const Status table =
      world.spawn("cafe_table", databaseRequestSdf("cafe_table"), ModelFormat::Sdf, at(0.85, 0, 0));
  ASSERT_TRUE(table.ok()) << table;
  expectCafeTableAt(world, 0.85);

  const Status missing = world.spawn("chair", databaseRequestSdf("chair"), ModelFormat::Sdf, Pose());
  EXPECT_EQ(missing.code, StatusCode::ModelRejected) << missing;
  EXPECT_NE(missing.subject.find("(/nonexistent, /"), std::string::npos)
      << "names the folders searched: " << missing;
}

// A model folder NAME/ (model.config, model.sdf, meshes/) in a fresh temporary folder.
class ModelFolder {
 public:
  ModelFolder() {
    std::string pattern = (std::filesystem::temp_directory_path() / "onedof_models_XXXXXX").string();
    root_ = mkdtemp(pattern.data());
  }
  ~ModelFolder() { std::filesystem::remove_all(root_); }
  const std::string& root() const { return root_; }
  void write(const std::string& relative, const std::string& text) const {
    const std::filesystem::path path = std::filesystem::path(root_) / relative;
    std::filesystem::create_directories(path.parent_path());
    std::ofstream(path) << text;
  }
  void addModel(const std::string& name, const std::string& link_content) const {
    write(name + "/model.config", "<?xml version=\"1.0\"?><model><name>" + name +
                                      "</name><sdf version=\"1.6\">model.sdf</sdf></model>");
    write(name + "/model.sdf", "<?xml version=\"1.0\"?><sdf version=\"1.6\"><model name=\"" +
                                   name + "\"><static>true</static><link name=\"link\">" +
                                   link_content + "</link></model></sdf>");
  }

 private:
  std::string root_;
};

std::string meshGeometry(const std::string& uri, const std::string& scale = "1 1 1") {
  return "<geometry><mesh><uri>" + uri + "</uri><scale>" + scale + "</scale></mesh></geometry>";
}

TEST_P(Models, MeshCollisionsAreTheirScaledMeshAndVisualsAreIgnored) {
  ModelFolder folder;
  folder.write("block/meshes/block.stl",
               "solid block\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 0.2 0.4 0.1\n"
               "vertex 0 0.4 0\nendloop\nendfacet\nendsolid block\n");
  folder.addModel("block", "<collision name=\"hull\">" +
                               meshGeometry("model://block/meshes/block.stl", "2 1 1") +
                               "</collision><visual name=\"look\">" +
                               meshGeometry("model://block/meshes/block.dae") + "</visual>");
  World world(GetParam());
  world.setModelPath({folder.root()});
  // The include's pose (what Gazebo's spawn service writes there) is composed under initial_pose.
  const Status block = world.spawn(
      "block", databaseRequestSdf("block", "<name>block</name><pose>0 0 0.5 0 0 0</pose>"),
      ModelFormat::Sdf, at(1, 0, 0));
  ASSERT_TRUE(block.ok()) << block;
  const std::vector<CollisionShape> shapes = world.collisionShapes();
  ASSERT_EQ(shapes.size(), 1u);
  EXPECT_EQ(shapes[0].shape, GeometryShape::Mesh);
  EXPECT_EQ(shapes[0].mesh_file, folder.root() + "/block/meshes/block.stl");
  EXPECT_NEAR(shapes[0].size.x, 2, 1e-12);
  EXPECT_NEAR(shapes[0].size.y, 1, 1e-12);
  EXPECT_NEAR(shapes[0].pose.position.x, 1, 1e-12);
  EXPECT_NEAR(shapes[0].pose.position.z, 0.5, 1e-12);
}

// A collision mesh that cannot be read refuses the model, naming the link and the mesh; one
// found nowhere is left out, as Gazebo leaves it out, and the model spawns with the reason.
TEST_P(Models, UnreadableMeshIsRefusedAndMissingMeshLeftOutNamingLinkAndMesh) {
  ModelFolder folder;
  folder.write("dae_table/meshes/table.dae", "<COLLADA/>");
  folder.addModel("dae_table", "<collision name=\"top\">" +
                                   meshGeometry("model://dae_table/meshes/table.dae") +
                                   "</collision>");
  folder.addModel("lost_mesh", "<collision name=\"top\">" +
                                   meshGeometry("model://lost_mesh/meshes/gone.stl") +
                                   "</collision>");
  World world(GetParam());
  world.setModelPath({folder.root()});
  const Status unreadable = world.spawn("dae_table", databaseRequestSdf("dae_table"),
                                        ModelFormat::Sdf, Pose());
  EXPECT_EQ(unreadable.code, StatusCode::ModelRejected) << unreadable;
  EXPECT_NE(unreadable.subject.find("link 'link'"), std::string::npos) << unreadable;
  EXPECT_NE(unreadable.subject.find("cannot read the mesh file " + folder.root() +
                                    "/dae_table/meshes/table.dae"),
            std::string::npos) << unreadable;
  EXPECT_TRUE(world.modelNames().empty());

  PreparedModel lost = World::prepare(databaseRequestSdf("lost_mesh"), ModelFormat::Sdf,
                                      {folder.root()});
  ASSERT_TRUE(lost.status().ok()) << lost.status();
  ASSERT_EQ(lost.leftOut().size(), 1u);
  EXPECT_NE(lost.leftOut()[0].find("model://lost_mesh/meshes/gone.stl"), std::string::npos)
      << lost.leftOut()[0];
  EXPECT_TRUE(world.spawn("lost_mesh", std::move(lost), Pose()).ok());
  EXPECT_EQ(world.modelNames(), std::vector<std::string>{"lost_mesh"});
  EXPECT_TRUE(world.collisionShapes().empty());  // its one collision left out
}

// An SDF pendulum: a base welded to `world` at z 1, an arm hanging from a revolute joint about y
// (limits +-1), its COM 0.5 m below the joint. Spawned 0.6 m up so that it clears the ground.
std::string sdfPendulum() {
  const std::string inertia =
      "<inertia><ixx>0.1</ixx><ixy>0</ixy><ixz>0</ixz><iyy>0.1</iyy><iyz>0</iyz><izz>0.005</izz>"
      "</inertia>";
  return "<sdf version=\"1.6\"><model name=\"pendulum\">"
         "<link name=\"base\"><pose>0 0 1 0 0 0</pose><inertial><mass>1</mass>" + inertia +
         "</inertial></link>"
         "<joint name=\"glue\" type=\"fixed\"><parent>world</parent><child>base</child></joint>"
         "<link name=\"arm\"><pose>0 0 1 0 0 0</pose><inertial><pose>0 0 -0.5 0 0 0</pose>"
         "<mass>1</mass>" + inertia + "</inertial><collision name=\"rod\"><pose>0 0 -0.5 0 0 0</pose>"
         "<geometry><cylinder><radius>0.05</radius><length>1</length></cylinder></geometry>"
         "</collision></link>"
         "<joint name=\"hinge\" type=\"revolute\"><parent>base</parent><child>arm</child>"
         "<axis><xyz>0 1 0</xyz><limit><lower>-1</lower><upper>1</upper></limit></axis></joint>"
         "</model></sdf>";
}

TEST_P(Models, SdfJointsLinkPosesAndLimits) {
  World world(GetParam());
  const Status status = world.spawn("pendulum", sdfPendulum(), ModelFormat::Sdf, at(0, 0, 0.6));
  ASSERT_TRUE(status.ok()) << status;
  JointInfo info;
  ASSERT_TRUE(world.jointInfo("hinge", &info).ok());
  EXPECT_EQ(info.type, JointType::Revolute);
  ASSERT_TRUE(world.setModelConfiguration("pendulum", {"hinge"}, {0.5}).ok());
  Pose pose;
  Twist twist;
  ASSERT_TRUE(world.linkState("pendulum::arm", "", &pose, &twist).ok());
  EXPECT_NEAR(pose.position.z, 1.6, 1e-12);
  EXPECT_NEAR(pose.orientation.y, std::sin(0.25), 1e-12);
  // Released at 0.5 it swings to about -0.5 and back, never past the limits.
  double lowest = 0;
  for (int i = 0; i < 2000; ++i) {
    world.step();
    lowest = std::min(lowest, jointPosition(world, "hinge"));
  }
  EXPECT_NEAR(lowest, -0.5, 0.01);
  // Pushed hard toward +q, it stops at the upper limit.
  ASSERT_TRUE(world.applyJointEffort("hinge", 20, 0, -1).ok());
  steps(&world, 2000);
  EXPECT_NEAR(jointPosition(world, "hinge"), 1.0, 0.01);
}

// Two boxes welded by a fixed joint, with a massless tool frame on the second, fall as one body.
TEST_P(Models, FixedJointWeldsMovingLinks) {
  World world(GetParam());
  testing_support::addGroundPlane(world);
  const std::string box =
      "<collision><geometry><box size=\"0.2 0.2 0.2\"/></geometry></collision>";
  const std::string urdf =
      "<robot name=\"pair\"><link name=\"a\">" + inertial(1, 0.0067, 0.0067, 0.0067) + box +
      "</link><joint name=\"weld\" type=\"fixed\"><parent link=\"a\"/><child link=\"b\"/>"
      "<origin xyz=\"0.3 0 0\"/></joint><link name=\"b\">" + inertial(1, 0.0067, 0.0067, 0.0067) +
      box + "</link><joint name=\"tool_joint\" type=\"fixed\"><parent link=\"b\"/>"
      "<child link=\"tool\"/><origin xyz=\"0 0 0.1\"/></joint><link name=\"tool\"/></robot>";
  const Status status = world.spawn("pair", urdf, ModelFormat::Urdf, at(0, 0, 0.5));
  ASSERT_TRUE(status.ok()) << status;
  JointInfo info;
  ASSERT_TRUE(world.jointInfo("weld", &info).ok());
  EXPECT_EQ(info.type, JointType::Fixed);
  steps(&world, 2000);
  // Where the pair rests is the contact solver's (level within nrad); where b and tool are
  // relative to a is the weld's, exact.
  Pose a, b_in_a, tool_in_b;
  Twist twist;
  ASSERT_TRUE(world.linkState("pair::a", "", &a, &twist).ok());
  ASSERT_TRUE(world.linkState("pair::b", "pair::a", &b_in_a, &twist).ok());
  ASSERT_TRUE(world.linkState("pair::tool", "pair::b", &tool_in_b, &twist).ok());
  EXPECT_NEAR(a.position.z, 0.1, 0.005);
  EXPECT_NEAR(b_in_a.position.x, 0.3, 1e-9);
  EXPECT_NEAR(b_in_a.position.y, 0, 1e-9);
  EXPECT_NEAR(b_in_a.position.z, 0, 1e-9);
  EXPECT_NEAR(tool_in_b.position.x, 0, 1e-9);
  EXPECT_NEAR(tool_in_b.position.y, 0, 1e-9);
  EXPECT_NEAR(tool_in_b.position.z, 0.1, 1e-9);
}

// The lifted robot swung from 1 rad under a lasting effort job, and a box dropped from (2, 0, 1):
// 300 steps on.
void swingAndDrop(World* world) {
  spawnLiftedRobot(world);
  ASSERT_TRUE(world->spawn("box", boxUrdf(0.2), ModelFormat::Urdf, at(2, 0, 1)).ok());
  ASSERT_TRUE(world->setModelConfiguration("one_DOF_robot", {"joint1"}, {1.0}).ok());
  ASSERT_TRUE(world->applyJointEffort("joint1", 3.0, 0, -1).ok());
  steps(world, 300);
}

// 10.
TEST_P(State, ResetPutsModelsBackAndDropsJobs) {
  World world(GetParam());
  swingAndDrop(&world);
  world.resetWorld();
  EXPECT_EQ(world.timeNs(), 300 * kMs);
  EXPECT_EQ(jointPosition(world, "joint1"), 0.0);
  EXPECT_EQ(jointRate(world, "joint1"), 0.0);
  Pose pose;
  Twist twist;
  ASSERT_TRUE(world.modelState("box", "", &pose, &twist).ok());
  EXPECT_NEAR(pose.position.z, 1.0, 1e-12);
  // The job is gone: hanging at pi, link2 stays put.
  ASSERT_TRUE(world.setModelConfiguration("one_DOF_robot", {"joint1"}, {M_PI}).ok());
  steps(&world, 100);
  EXPECT_NEAR(jointPosition(world, "joint1"), M_PI, 1e-6);
  world.resetSimulation();
  EXPECT_EQ(world.timeNs(), 0);
  EXPECT_EQ(world.stepCount(), 0u);
}

// 10, for one model: reset_model.
TEST_P(State, ResetModelPutsThatModelAloneBackAndDropsItsJobs) {
  World world(GetParam());
  swingAndDrop(&world);
  Pose pose;
  Twist twist;
  ASSERT_TRUE(world.modelState("box", "", &pose, &twist).ok());
  ASSERT_LT(pose.position.z, 0.9);  // fallen
  const double swung = jointPosition(world, "joint1");

  // The box back where it was spawned, at rest; the robot as it was.
  ASSERT_TRUE(world.resetModel("box").ok());
  ASSERT_TRUE(world.modelState("box", "", &pose, &twist).ok());
  EXPECT_NEAR(pose.position.x, 2.0, 1e-12);
  EXPECT_NEAR(pose.position.z, 1.0, 1e-12);
  EXPECT_EQ(twist.linear.z, 0.0);
  EXPECT_EQ(jointPosition(world, "joint1"), swung);
  EXPECT_EQ(world.timeNs(), 300 * kMs);

  // The robot back at its spawn configuration, at rest, its effort job gone: hanging at pi,
  // link2 stays put.
  ASSERT_TRUE(world.resetModel("one_DOF_robot").ok());
  EXPECT_EQ(jointPosition(world, "joint1"), 0.0);
  EXPECT_EQ(jointRate(world, "joint1"), 0.0);
  ASSERT_TRUE(world.setModelConfiguration("one_DOF_robot", {"joint1"}, {M_PI}).ok());
  steps(&world, 100);
  EXPECT_NEAR(jointPosition(world, "joint1"), M_PI, 1e-6);

  const Status unknown = world.resetModel("nope");
  EXPECT_EQ(unknown.code, StatusCode::ModelNotFound);
  EXPECT_EQ(unknown.subject, "nope");
}

// Boxes tumbling onto each other under the iterative solver (ODE's quickstep orders its
// constraints with random numbers, and its collision space orders contacts by the geoms last
// moved), beside the tutorial's arm swinging on its joint (Bullet's solver starts a joint's rows
// from what they ended the last step with): reset_simulation and the same steps again give the
// same states bit for bit, as a new world would.
TEST_P(State, ResetSimulationRepeatsTheRunBitForBit) {
  PhysicsParams params;
  params.quick_step = true;
  World world(GetParam(), params);
  for (int i = 0; i < 4; ++i) {
    Pose pose = at(0.05 * i, 0.03 * i, 0.15 + 0.25 * i);
    pose.orientation = {std::cos(0.2 * i), std::sin(0.2 * i), 0, 0};
    ASSERT_TRUE(world.spawn("box" + std::to_string(i), boxUrdf(0.2), ModelFormat::Urdf, pose).ok());
  }
  ASSERT_TRUE(world.spawn("one_DOF_robot", tutorialUrdf(), ModelFormat::Urdf, at(3, 0, kLift)).ok());
  auto run = [&world] {
    std::vector<double> states;
    EXPECT_TRUE(world.applyJointEffort("joint1", 3.0, 0, -1).ok());  // swung up from its rest
    for (int step = 0; step < 600; ++step) {
      world.step();
      states.push_back(jointPosition(world, "joint1"));
      for (int i = 0; i < 4; ++i) {
        Pose pose;
        Twist twist;
        EXPECT_TRUE(world.modelState("box" + std::to_string(i), "", &pose, &twist).ok());
        states.insert(states.end(), {pose.position.x, pose.position.y, pose.position.z,
                                     pose.orientation.w, pose.orientation.x, twist.angular.z});
      }
    }
    return states;
  };
  const std::vector<double> first = run();
  EXPECT_GT(std::fabs(jointPosition(world, "joint1")), 0.1);
  world.resetSimulation();
  const std::vector<double> second = run();
  ASSERT_EQ(first.size(), second.size());
  size_t differing = 0;
  for (size_t i = 0; i < first.size(); ++i) differing += first[i] != second[i];
  EXPECT_EQ(differing, 0u);
}

TEST_P(State, ModelAndLinkStateRoundTrip) {
  World world(GetParam(), withoutGravity());
  ASSERT_TRUE(world.spawn("box", boxUrdf(0.2), ModelFormat::Urdf, at(0, 0, 1)).ok());
  Pose target = at(1, 2, 3);
  target.orientation = {std::cos(0.3), 0, 0, std::sin(0.3)};  // 0.6 rad about z
  Twist twist;
  twist.linear = {0.5, 0, 0};
  twist.angular = {0, 0, 0.2};
  ASSERT_TRUE(world.setModelState("box", target, twist, "").ok());
  Pose pose;
  Twist got;
  ASSERT_TRUE(world.modelState("box", "", &pose, &got).ok());
  EXPECT_NEAR(pose.position.y, 2, 1e-12);
  EXPECT_NEAR(pose.orientation.z, std::sin(0.3), 1e-12);
  EXPECT_NEAR(got.linear.x, 0.5, 1e-12);
  EXPECT_NEAR(got.angular.z, 0.2, 1e-12);
  // Relative to itself: identity pose, no motion.
  ASSERT_TRUE(world.linkState("box::box", "box", &pose, &got).ok());
  EXPECT_NEAR(pose.position.x, 0, 1e-12);
  EXPECT_NEAR(pose.orientation.w, 1, 1e-12);
  EXPECT_NEAR(got.linear.x, 0, 1e-12);
  // Set in a reference frame: 1 m along the box's own x (rotated 0.6 rad).
  ASSERT_TRUE(world.setLinkState("box::box", at(1, 0, 0), Twist(), "box").ok());
  ASSERT_TRUE(world.linkState("box::box", "", &pose, &got).ok());
  EXPECT_NEAR(pose.position.x, 1 + std::cos(0.6), 1e-12);
  EXPECT_NEAR(pose.position.y, 2 + std::sin(0.6), 1e-12);
}

TEST_P(State, SetModelStateMovesTheWholeModel) {
  World world(GetParam());
  ASSERT_TRUE(world.spawn("one_DOF_robot", tutorialUrdf(), ModelFormat::Urdf, Pose()).ok());
  ASSERT_TRUE(world.setModelConfiguration("one_DOF_robot", {"joint1"}, {M_PI}).ok());
  ASSERT_TRUE(world.setModelState("one_DOF_robot", at(1, 0, 0.5), Twist(), "").ok());
  EXPECT_NEAR(jointPosition(world, "joint1"), M_PI, 1e-12);
  steps(&world, 100);
  Pose pose;
  Twist twist;
  ASSERT_TRUE(world.linkState("one_DOF_robot::link2", "", &pose, &twist).ok());
  EXPECT_NEAR(pose.position.x, 1, 1e-6);
  EXPECT_NEAR(pose.position.z, 0.5 + tutorialRobot().joint_height, 1e-6);
  EXPECT_NEAR(jointPosition(world, "joint1"), M_PI, 1e-6);
}

TEST_P(State, SetModelConfigurationPutsTheJointAtTheAngle) {
  World world(GetParam());
  ASSERT_TRUE(world.spawn("one_DOF_robot", tutorialUrdf(), ModelFormat::Urdf, Pose()).ok());
  ASSERT_TRUE(world.setModelConfiguration("one_DOF_robot", {"joint1"}, {2.5}).ok());
  EXPECT_EQ(jointPosition(world, "joint1"), 2.5);
  EXPECT_EQ(jointRate(world, "joint1"), 0.0);
  Pose pose;
  Twist twist;
  ASSERT_TRUE(world.linkState("one_DOF_robot::link2", "", &pose, &twist).ok());
  EXPECT_NEAR(pose.position.z, tutorialRobot().joint_height, 1e-12);
  EXPECT_NEAR(pose.orientation.w, std::cos(1.25), 1e-12);
  EXPECT_NEAR(pose.orientation.y, std::sin(1.25), 1e-12);
}

// A link whose COM is off its origin and whose inertial frame is turned by 90 degrees about z:
// its principal moments (1, 2, 3) become (2, 1, 3) about the link axes.
TEST_P(State, InertialOffsetAndRotationAreExact) {
  World world(GetParam(), withoutGravity());
  const std::string urdf = "<robot name=\"odd\"><link name=\"odd\">" +
                           inertial(2, 1, 2, 3, "0.1 0.2 0.3", "0 0 1.5707963267948966") +
                           "</link></robot>";
  Pose spawn_pose = at(1, 2, 3);
  spawn_pose.orientation = {std::cos(0.2), std::sin(0.2), 0, 0};
  ASSERT_TRUE(world.spawn("odd", urdf, ModelFormat::Urdf, spawn_pose).ok());
  LinkInfo info;
  ASSERT_TRUE(world.linkProperties("odd::odd", &info).ok());
  EXPECT_EQ(info.com.position.y, 0.2);
  EXPECT_EQ(info.mass, 2);
  Pose pose;
  Twist twist;
  ASSERT_TRUE(world.linkState("odd::odd", "", &pose, &twist).ok());
  EXPECT_NEAR(pose.position.x, 1, 1e-12);
  EXPECT_NEAR(pose.position.z, 3, 1e-12);
  EXPECT_NEAR(pose.orientation.x, std::sin(0.2), 1e-12);
  // A torque about the link's x axis: angular acceleration 1 / 2, about the COM.
  ASSERT_TRUE(world.applyBodyWrench("odd::odd", "odd::odd", {0.1, 0.2, 0.3}, {}, {1, 0, 0}, 0, kMs).ok());
  world.step();
  ASSERT_TRUE(world.linkState("odd::odd", "", &pose, &twist).ok());
  const double w = kStep * 1.0 / 2;
  EXPECT_NEAR(twist.angular.x, w, 1e-12);
  EXPECT_NEAR(twist.angular.y, 0, 1e-12);
  // The link origin turns about the COM: its velocity is w x (origin - COM), in the world.
  const double c = std::cos(0.4), s = std::sin(0.4);  // link rotation: 0.4 rad about x
  const double com_y = 2 + c * 0.2 - s * 0.3, com_z = 3 + s * 0.2 + c * 0.3;
  EXPECT_NEAR(twist.linear.y, -w * (3 - com_z), 1e-9);
  EXPECT_NEAR(twist.linear.z, w * (2 - com_y), 1e-9);
}

// 11. The simulator survives what it is asked to do.
TEST_P(Robustness, HugeEffortNeverProducesNaN) {
  World world(GetParam());
  spawnLiftedRobot(&world);
  JobOutcome job;
  ASSERT_TRUE(world.applyJointEffort("joint1", 1e12, 0, -1, &job).ok());
  ASSERT_TRUE(job.safe_effort);
  EXPECT_LT(*job.safe_effort, 1e12);
  for (int i = 0; i < 3000; ++i) {
    world.step();
    ASSERT_TRUE(std::isfinite(jointPosition(world, "joint1")));
    ASSERT_TRUE(std::isfinite(jointRate(world, "joint1")));
  }
  Pose pose;
  Twist twist;
  ASSERT_TRUE(world.linkState("one_DOF_robot::link2", "", &pose, &twist).ok());
  // Still on its joint: link2's frame is at the joint, (0, 0, kLift + joint height).
  const double joint_z = kLift + tutorialRobot().joint_height;
  std::printf("[ figures  ] after 3 s of effort 1e12: joint error %.2e m, rate %.1f rad/s\n",
              std::hypot(pose.position.x, pose.position.y, pose.position.z - joint_z),
              jointRate(world, "joint1"));
  EXPECT_LT(std::hypot(pose.position.x, pose.position.y, pose.position.z - joint_z), 0.05);
  EXPECT_FALSE(world.takeWarnings().empty());
}

TEST_P(Robustness, TableSpawnedThroughTheArmSeparatesWithoutBlowingUp) {
  World world(GetParam());
  ASSERT_TRUE(world.spawn("one_DOF_robot", tutorialUrdf(), ModelFormat::Urdf, Pose()).ok());
  ASSERT_TRUE(world.setModelConfiguration("one_DOF_robot", {"joint1"}, {2.0}).ok());
  ASSERT_TRUE(world.spawn("cafe_table", cafeTableSdf(), ModelFormat::Sdf, at(0.85, 0, 0)).ok());
  for (int i = 0; i < 3000; ++i) {
    world.step();
    ASSERT_TRUE(std::isfinite(jointPosition(world, "joint1")));
  }
  std::printf("[ figures  ] arm spawned through the table at q 2.0 ends at q %.3f\n",
              jointPosition(world, "joint1"));
  EXPECT_LT(std::abs(jointRate(world, "joint1")), 20);
}

// --- set_link_properties ------------------------------------------------------------------

LinkInfo link2Properties(const World& world) {
  LinkInfo link;
  EXPECT_TRUE(world.linkProperties("one_DOF_robot::link2", &link).ok());
  return link;
}

// Within 10 um: a body re-placed from its joint positions loses the joints' constraint error.
void expectSamePose(const Pose& a, const Pose& b) {
  EXPECT_NEAR(a.position.x, b.position.x, 1e-5);
  EXPECT_NEAR(a.position.y, b.position.y, 1e-5);
  EXPECT_NEAR(a.position.z, b.position.z, 1e-5);
  EXPECT_NEAR(std::abs(a.orientation.w * b.orientation.w + a.orientation.x * b.orientation.x +
                       a.orientation.y * b.orientation.y + a.orientation.z * b.orientation.z),
              1, 1e-9);
}

TEST_P(LinkProperties, DoubledMassGivesTheClosedFormPeriod) {
  const TutorialRobotFigures& robot = tutorialRobot();
  World world(GetParam());
  spawnLiftedRobot(&world);
  LinkInfo link = link2Properties(world);
  link.mass = 2 * robot.mass;
  const Status set = world.setLinkProperties("one_DOF_robot::link2", link);
  ASSERT_TRUE(set.ok()) << set;
  EXPECT_EQ(link2Properties(world).mass, 2 * robot.mass);
  const double period = smallSwingPeriod(&world);
  const double expected = compoundPendulumPeriod(2 * robot.mass, link.iyy, robot.arm);
  std::printf("[ figures  ] period with link2 at 2 kg %.5f s, expected %.5f s\n", period, expected);
  EXPECT_NEAR(period, expected, 0.005 * expected);
  // The closed form moves by more than the tolerance: the mass did change the swing.
  EXPECT_GT(std::abs(expected - compoundPendulumPeriod(robot.mass, link.iyy, robot.arm)),
            0.02 * expected);
}

TEST_P(LinkProperties, MovedCentreOfMassKeepsTheLinksAndGivesTheNewPeriod) {
  World world(GetParam());
  spawnLiftedRobot(&world);
  ASSERT_TRUE(world.setModelConfiguration("one_DOF_robot", {"joint1"}, {2.5}).ok());
  steps(&world, 200);  // swinging, so that velocities must carry over too
  Pose before_pose, after_pose;
  Twist before_twist, after_twist;
  ASSERT_TRUE(world.linkState("one_DOF_robot::link2", "", &before_pose, &before_twist).ok());
  const double rate_before = jointRate(world, "joint1");
  const double position_before = jointPosition(world, "joint1");
  LinkInfo link = link2Properties(world);
  const TutorialRobotFigures& robot = tutorialRobot();
  const double arm = 0.8;  // the COM slides along the link, further from joint1
  link.com.position.z += arm - robot.arm;
  const Status set = world.setLinkProperties("one_DOF_robot::link2", link);
  ASSERT_TRUE(set.ok()) << set;
  ASSERT_TRUE(world.linkState("one_DOF_robot::link2", "", &after_pose, &after_twist).ok());
  expectSamePose(after_pose, before_pose);
  EXPECT_NEAR(after_twist.angular.y, before_twist.angular.y, 1e-9);
  EXPECT_NEAR(after_twist.linear.x, before_twist.linear.x, 1e-5);
  EXPECT_NEAR(after_twist.linear.z, before_twist.linear.z, 1e-5);
  EXPECT_NEAR(jointPosition(world, "joint1"), position_before, 1e-9);
  EXPECT_NEAR(jointRate(world, "joint1"), rate_before, 1e-9);
  const double period = smallSwingPeriod(&world);
  const double expected = compoundPendulumPeriod(robot.mass, link.iyy, arm);
  std::printf("[ figures  ] period with link2's COM at %.1f m %.5f s, expected %.5f s\n", arm, period,
              expected);
  EXPECT_NEAR(period, expected, 0.005 * expected);
}

TEST_P(LinkProperties, GravityModeOffFloats) {
  World world(GetParam());
  spawnLiftedRobot(&world);
  ASSERT_TRUE(world.setModelConfiguration("one_DOF_robot", {"joint1"}, {M_PI / 2}).ok());
  LinkInfo link = link2Properties(world);
  link.gravity_mode = false;
  ASSERT_TRUE(world.setLinkProperties("one_DOF_robot::link2", link).ok());
  EXPECT_FALSE(link2Properties(world).gravity_mode);
  steps(&world, 1000);
  EXPECT_NEAR(jointPosition(world, "joint1"), M_PI / 2, 1e-6);  // horizontal, and it stays
  link.gravity_mode = true;
  ASSERT_TRUE(world.setLinkProperties("one_DOF_robot::link2", link).ok());
  steps(&world, 200);
  EXPECT_GT(jointPosition(world, "joint1"), M_PI / 2 + 0.05);  // falls again, towards q = pi
}

TEST_P(LinkProperties, RefusedValuesLeaveTheWorldUnchanged) {
  World world(GetParam()), twin(GetParam());
  spawnLiftedRobot(&world);
  spawnLiftedRobot(&twin);
  for (World* w : {&world, &twin})
    ASSERT_TRUE(w->setModelConfiguration("one_DOF_robot", {"joint1"}, {2.0}).ok());
  const LinkInfo original = link2Properties(world);
  const auto refused = [&](LinkInfo change, StatusCode code, const std::string& subject) {
    const Status status = world.setLinkProperties("one_DOF_robot::link2", change);
    EXPECT_EQ(status.code, code) << status;
    EXPECT_EQ(status.subject, subject);
  };
  LinkInfo bad = original;
  bad.mass = 0;  // link2 is a body of its own
  refused(bad, StatusCode::InvalidParameter, "mass");
  bad.mass = -1;
  refused(bad, StatusCode::InvalidParameter, "mass");
  bad = original;
  bad.ixx = -1;
  refused(bad, StatusCode::InvalidParameter, "inertia");
  bad = original;
  bad.ixy = 10;  // symmetric but indefinite
  refused(bad, StatusCode::InvalidParameter, "inertia");
  bad = original;
  bad.mass = kNaN;
  refused(bad, StatusCode::NotFinite, "mass");
  bad = original;
  bad.izz = std::numeric_limits<double>::infinity();
  refused(bad, StatusCode::NotFinite, "inertia");
  bad = original;
  bad.com.position.x = kNaN;
  refused(bad, StatusCode::NotFinite, "com");
  bad = original;
  bad.com.orientation = {0, 0, 0, 0};
  refused(bad, StatusCode::ZeroQuaternion, "com");
  EXPECT_EQ(world.setLinkProperties("one_DOF_robot::nope", original).code,
            StatusCode::LinkNotFound);

  const LinkInfo after = link2Properties(world);
  EXPECT_EQ(after.mass, original.mass);
  EXPECT_EQ(after.ixx, original.ixx);
  EXPECT_EQ(after.ixy, original.ixy);
  EXPECT_EQ(after.com.position.x, original.com.position.x);
  EXPECT_EQ(after.gravity_mode, original.gravity_mode);
  steps(&world, 500);
  steps(&twin, 500);
  EXPECT_EQ(jointPosition(world, "joint1"), jointPosition(twin, "joint1"));
}

TEST_P(LinkProperties, WeldedLinksChangeTheirLumpedBodyAndShareOneGravityMode) {
  // link2 carries a 1 kg tip welded 1 m out along x; moving the tip's mass to 3 kg moves the
  // lumped COM, which the free fall cannot show but the tip's pose and a wrench's reply can: the
  // links stay where they are and the tip keeps its gravity mode only with link2's.
  World world(GetParam(), withoutGravity());
  const std::string urdf =
      "<robot name=\"welded\"><link name=\"base\">" + inertial(1, 0.1, 0.1, 0.1) +
      "</link><joint name=\"weld\" type=\"fixed\"><parent link=\"base\"/><child link=\"tip\"/>"
      "<origin xyz=\"1 0 0\"/></joint><link name=\"tip\">" + inertial(1, 0.1, 0.1, 0.1) +
      "</link></robot>";
  ASSERT_TRUE(world.spawn("welded", urdf, ModelFormat::Urdf, at(0, 0, 2)).ok());
  LinkInfo tip;
  ASSERT_TRUE(world.linkProperties("welded::tip", &tip).ok());
  tip.mass = 3;
  ASSERT_TRUE(world.setLinkProperties("welded::tip", tip).ok());
  Pose base, tip_pose;
  Twist unused;
  ASSERT_TRUE(world.linkState("welded::base", "", &base, &unused).ok());
  ASSERT_TRUE(world.linkState("welded::tip", "", &tip_pose, &unused).ok());
  expectSamePose(base, at(0, 0, 2));
  expectSamePose(tip_pose, at(1, 0, 2));
  // A force through the lumped COM (0.75 m out, 4 kg) only translates the pair.
  ASSERT_TRUE(world.applyBodyWrench("welded::base", "", {0.75, 0, 2}, {0, 0, 4}, {0, 0, 0}, 0,
                                    100 * kMs).ok());
  steps(&world, 100);
  ASSERT_TRUE(world.linkState("welded::base", "", &base, &unused).ok());
  ASSERT_TRUE(world.linkState("welded::tip", "", &tip_pose, &unused).ok());
  EXPECT_NEAR(base.position.z - 2, 0.5 * 1 * 0.1 * 0.1, 1e-4);  // a = F / m = 1 m/s^2
  EXPECT_NEAR(tip_pose.position.z, base.position.z, 1e-6);      // no turn
  tip.gravity_mode = false;
  const Status split = world.setLinkProperties("welded::tip", tip);
  EXPECT_EQ(split.code, StatusCode::InvalidParameter) << split;
  EXPECT_EQ(split.subject, "gravity_mode");
}

// --- bad input: refused up front with the range, never a crash -------------------------------

// A chain of `links` links welded by fixed joints: one rigid body.
std::string fixedChainUrdf(int links) {
  std::ostringstream s;
  s << "<robot name=\"chain\"><link name=\"l0\">" << inertial(1, 1, 1, 1) << "</link>";
  for (int i = 1; i < links; ++i)
    s << "<link name=\"l" << i << "\"/><joint name=\"j" << i << "\" type=\"fixed\"><parent link=\"l"
      << i - 1 << "\"/><child link=\"l" << i << "\"/><origin xyz=\"0 0 0.001\"/></joint>";
  s << "</robot>";
  return s.str();
}

// The tutorial robot with link2's inertial replaced.
std::string tutorialUrdfWithLink2Inertial(const std::string& replacement) {
  std::string urdf = tutorialUrdf();
  const size_t link2 = urdf.find("<link name=\"link2\">");
  const size_t begin = urdf.find("<inertial>", link2);
  const size_t end = urdf.find("</inertial>", begin) + std::string("</inertial>").size();
  urdf.replace(begin, end - begin, replacement);
  return urdf;
}

void expectOutOfRange(const Status& status, const std::string& subject, double min, double max) {
  EXPECT_EQ(status.code, StatusCode::OutOfRange) << status;
  EXPECT_EQ(status.subject, subject) << status;
  EXPECT_EQ(status.min, min) << status;
  EXPECT_EQ(status.max, max) << status;
}

void expectRejected(const Status& status, const std::string& why) {
  EXPECT_EQ(status.code, StatusCode::ModelRejected) << status;
  EXPECT_NE(status.subject.find(why), std::string::npos) << status;
}

// The world still steps, finite, and the robot still swings.
void expectStillRunning(World* world) {
  const double before = jointPosition(*world, "joint1");
  steps(world, 200);
  EXPECT_TRUE(std::isfinite(jointPosition(*world, "joint1")));
  EXPECT_NE(jointPosition(*world, "joint1"), before);
}

// 1e308 in a twist, a position, a reference point or an inertia is finite, yet overflows inside
// the step, where ODE aborts the process.
TEST_P(BadInput, HugeButFiniteStatesAndInertialsAreRefusedNamingTheRange) {
  World world(GetParam());
  spawnLiftedRobot(&world);
  ASSERT_TRUE(world.setModelConfiguration("one_DOF_robot", {"joint1"}, {0.3}).ok());
  const std::string before = snapshot(world);
  Twist fast;
  fast.linear.x = 1e308;
  expectOutOfRange(world.setModelState("one_DOF_robot", Pose(), fast, ""), "twist.linear", 0, 100);
  expectOutOfRange(world.setLinkState("one_DOF_robot::link2", Pose(), fast, ""), "twist.linear",
                   0, 100);
  Twist spinning;
  spinning.angular.z = 1e308;
  expectOutOfRange(world.setLinkState("one_DOF_robot::link2", Pose(), spinning, ""),
                   "twist.angular", 0, 0.1 / kStep);
  expectOutOfRange(world.setLinkState("one_DOF_robot::link2", at(0, 1e308, 0), Twist(), ""),
                   "pose.position", -1e6, 1e6);
  expectOutOfRange(world.setModelState("one_DOF_robot", at(0, 0, 1e308), Twist(), ""),
                   "pose.position", -1e6, 1e6);
  expectOutOfRange(world.spawn("box", boxUrdf(0.1), ModelFormat::Urdf, at(1e308, 0, 0)),
                   "pose.position", -1e6, 1e6);
  expectOutOfRange(world.applyBodyWrench("one_DOF_robot::link2", "", {1e308, 0, 0}, {0, 0, 1},
                                         {}, 0, -1),
                   "reference_point", -1e6, 1e6);
  expectRejected(world.spawn("heavy", tutorialUrdfWithLink2Inertial(inertial(1, 1e308, 1, 1)),
                             ModelFormat::Urdf, Pose()),
                 "inertia component of 1e+308");
  expectRejected(world.spawn("thin", tutorialUrdfWithLink2Inertial(inertial(1, 1e-300, 0.1, 0.1)),
                             ModelFormat::Urdf, Pose()),
                 "principal moment of inertia outside [1e-12, 1e+09]");
  EXPECT_EQ(snapshot(world), before);
  expectStillRunning(&world);
  // The edge of each range is accepted and steps finite.
  Twist edge;
  edge.linear.x = 100;
  ASSERT_TRUE(world.setLinkState("one_DOF_robot::link2", Pose(), edge, "").ok());
  ASSERT_TRUE(world.applyBodyWrench("one_DOF_robot::link2", "", {1e6, 0, 0}, {0, 0, 1e200}, {}, 0,
                                    -1).ok());
  expectStillRunning(&world);
}

// A 20000-link fixed chain takes 20000 nested calls to walk and would overflow the stack.
TEST_P(BadInput, ModelSizeIsLimitedAndRefusedBeyond) {
  World world(GetParam());
  expectRejected(world.spawn("chain", fixedChainUrdf(20000), ModelFormat::Urdf, Pose()),
                 "the model has 20000 links; at most 1000 are accepted");
  EXPECT_TRUE(world.modelNames().empty());
  const Status largest = world.spawn("chain", fixedChainUrdf(1000), ModelFormat::Urdf, at(0, 0, 2));
  ASSERT_TRUE(largest.ok()) << largest;
  steps(&world, 10);
}

// A time_step of 1e6 runs sim time past ROS time's 32-bit seconds, and 1e10 overflows the
// nanosecond count: both are refused with the step's range, as are steps too small.
TEST_P(BadInput, StepOutsideItsRangeIsRefusedWithTheRange) {
  World world(GetParam());
  for (double step : {1e6, 1e10, 1e-7, 0.0}) {
    PhysicsParams params;
    params.step = step;
    expectOutOfRange(world.setParams(params), "step", 1e-6, 0.1);
  }
  PhysicsParams params;
  params.step = 0.1;
  ASSERT_TRUE(world.setParams(params).ok());
  EXPECT_EQ(world.params().step, 0.1);
}

// A force of 1e200: |force| must not overflow to infinity, which would scale the clamped force to
// nothing; it is applied at its bound, as a merely large force is.
TEST_P(BadInput, HugeWrenchIsClampedToItsBoundAndApplied) {
  const auto risesAfter = [&](double force, JobOutcome* job) {
    World world(GetParam(), withoutGravity());
    EXPECT_TRUE(world.spawn("box", boxUrdf(0.2), ModelFormat::Urdf, at(0, 0, 1)).ok());
    EXPECT_TRUE(world.applyBodyWrench("box::box", "", {}, {0, 0, force}, {}, 0, kMs, job).ok());
    world.step();
    Pose pose;
    Twist twist;
    EXPECT_TRUE(world.linkState("box::box", "", &pose, &twist).ok());
    return twist.linear.z;
  };
  JobOutcome huge, large;
  const double huge_speed = risesAfter(1e200, &huge);
  const double large_speed = risesAfter(1e9, &large);
  ASSERT_TRUE(huge.safe_wrench && large.safe_wrench);
  EXPECT_EQ(huge.safe_wrench->force, large.safe_wrench->force);
  // The bound takes the box to 100 m/s in 10 steps: 10 m/s after one.
  EXPECT_NEAR(huge_speed, huge.safe_wrench->force * kStep / 1.0, 1e-9);
  EXPECT_NEAR(huge_speed, 10, 1e-9);
  EXPECT_EQ(huge_speed, large_speed);
}

// joint1 = 1e17: past 1e6 a step's motion is lost in rounding, and the joint would read 1e17 for
// ever while the link swings.
TEST_P(BadInput, JointPositionOutOfRangeIsRefused) {
  World world(GetParam());
  spawnLiftedRobot(&world);
  const std::string before = snapshot(world);
  expectOutOfRange(world.setModelConfiguration("one_DOF_robot", {"joint1"}, {1e17}), "joint1",
                   -1e6, 1e6);
  EXPECT_EQ(snapshot(world), before);
  ASSERT_TRUE(world.setModelConfiguration("one_DOF_robot", {"joint1"}, {1000.5}).ok());
  EXPECT_EQ(jointPosition(world, "joint1"), 1000.5);
  steps(&world, 100);
  EXPECT_NE(jointPosition(world, "joint1"), 1000.5);
}

// A link of mass 1e308 (or z 1e308, cfm 1e308) would make every step non-finite, and every step
// undone would freeze the whole world.
TEST_P(BadInput, InputThatWouldFreezeTheWorldIsRefused) {
  World world(GetParam());
  spawnLiftedRobot(&world);
  expectRejected(world.spawn("heavy", tutorialUrdfWithLink2Inertial(inertial(1e308, 1, 1, 1)),
                             ModelFormat::Urdf, at(3, 0, 0)),
                 "link 'link2' has a mass of 1e+308 kg; a mass must be 0 or in [1e-06, 1e+06] kg");
  PhysicsParams params;
  params.cfm = 1e308;
  expectOutOfRange(world.setParams(params), "cfm", 0, 10);
  LinkInfo link = link2Properties(world);
  link.mass = 1e308;
  expectOutOfRange(world.setLinkProperties("one_DOF_robot::link2", link), "mass", 1e-6, 1e6);
  link = link2Properties(world);
  link.ixx = 1e-14;  // positive: a body, but one a torque would spin up without bound
  expectOutOfRange(world.setLinkProperties("one_DOF_robot::link2", link), "inertia", 1e-12, 1e9);
  expectOutOfRange(world.setJointDamping("joint1", 1e308), "damping", 0, 1e6);
  ASSERT_TRUE(world.setModelConfiguration("one_DOF_robot", {"joint1"}, {0.3}).ok());
  expectStillRunning(&world);
  EXPECT_TRUE(world.takeWarnings().empty());
}

// What the parsers drop or only print is refused with the reason.
TEST_P(BadInput, ParserGapsAreRefusedWithTheReason) {
  World world(GetParam());
  const std::string body = inertial(1, 1, 1, 1);
  struct Case {
    std::string xml;
    ModelFormat format;
    std::string reason;
  };
  std::vector<Case> cases = {
      {"<robot name=\"r\"><link name=\"a\">" + body + "</link><link name=\"b\">" + body +
           "</link><joint name=\"j\" type=\"continuous\"><parent link=\"b\"/><child link=\"b\"/>"
           "<axis xyz=\"0 0 1\"/></joint></robot>",
       ModelFormat::Urdf, "joint 'j' has link 'b' as both its parent and its child"},
      {"<robot name=\"r\"><link name=\"a\">" + body +
           "<collision><geometry><box size=\"nan 1 1\"/></geometry></collision></link></robot>",
       ModelFormat::Urdf, "Could not parse collision element for Link [a]"},
      {"<robot name=\"r\"><link name=\"a\">" + body +
           "<collision><geometry><box size=\"1e6 1 1\"/></geometry></collision></link></robot>",
       ModelFormat::Urdf, "link 'a': collision 'a_collision' is larger than 1000 m"},
      {"<robot name=\"r\"><link name=\"a\">" + body + "</link><gazebo reference=\"a\">"
           "<mu1>grippy</mu1></gazebo></robot>",
       ModelFormat::Urdf, "link 'a': <gazebo reference> <mu1> 'grippy' is not a number"},
      {"<sdf version=\"99\"><model name=\"m\"><link name=\"l\"/></model></sdf>", ModelFormat::Sdf,
       "version '99' is not one this libsdformat reads"},
  };
  for (const char* version : {"99", "2.0", "abc"}) {
    cases.push_back({std::string("<sdf version=\"") + version +
                         "\"><model name=\"m\"><link name=\"l\"/></model></sdf>",
                     ModelFormat::Sdf, "invalid SDF"});
  }
  for (const Case& bad : cases) expectRejected(world.spawn("r", bad.xml, bad.format, Pose()), bad.reason);
  EXPECT_TRUE(world.modelNames().empty());
  ASSERT_TRUE(world.spawn("r", "<sdf version=\"1.6\"><model name=\"m\"><link name=\"l\"/></model></sdf>",
                          ModelFormat::Sdf, at(0, 0, 1)).ok());
}

// A model named "one_DOF_robot::link2" would take over that frame for other requests.
TEST_P(BadInput, ModelNamesThatMakeScopedNamesAmbiguousAreRefused) {
  World world(GetParam());
  spawnLiftedRobot(&world);
  for (const std::string name : {"one_DOF_robot::link2", "a::b", "world"}) {
    const Status status = world.spawn(name, boxUrdf(0.1), ModelFormat::Urdf, at(5, 0, 1));
    EXPECT_EQ(status.code, StatusCode::InvalidModelName) << status;
    EXPECT_EQ(status.subject, name);
  }
  EXPECT_EQ(world.modelNames(), std::vector<std::string>{"one_DOF_robot"});
}

// Jobs are bounded in number per joint, and jobs each clamped to the limit are held to it as a
// sum (500 of them would sum far past it).
TEST_P(EffortJobs, PendingJobsAreBoundedPerJoint) {
  for (int i = 0; i < 1000; ++i)
    ASSERT_TRUE(world.applyJointEffort("spin", 0.001, 1000 * kMs, -1).ok()) << i;
  const Status full = world.applyJointEffort("spin", 0.001, 1000 * kMs, -1);
  EXPECT_EQ(full.code, StatusCode::TooManyJobs) << full;
  EXPECT_EQ(full.subject, "rotor::spin");
  EXPECT_EQ(full.max, 1000);
  world.clearJointForces("spin");
  ASSERT_TRUE(world.applyJointEffort("spin", 0.001, 0, kMs).ok());
}

TEST_P(EffortJobs, TheEffortLimitHoldsTheSumOfOverlappingJobs) {
  for (int i = 0; i < 500; ++i) ASSERT_TRUE(world.applyJointEffort("spin", 3.5, 0, 10 * kMs).ok());
  steps(&world, 20);
  EXPECT_NEAR(jointRate(world, "spin"), speedAfter(2.0, 10), 1e-12);
}

TEST_P(BodyWrench, PendingJobsAreBoundedPerLink) {
  World world(GetParam(), withoutGravity());
  ASSERT_TRUE(world.spawn("box", boxUrdf(0.2), ModelFormat::Urdf, at(0, 0, 1)).ok());
  for (int i = 0; i < 1000; ++i)
    ASSERT_TRUE(world.applyBodyWrench("box::box", "", {}, {1, 0, 0}, {}, 1000 * kMs, -1).ok()) << i;
  const Status full = world.applyBodyWrench("box::box", "", {}, {1, 0, 0}, {}, 1000 * kMs, -1);
  EXPECT_EQ(full.code, StatusCode::TooManyJobs) << full;
  EXPECT_EQ(full.subject, "box::box");
}

// --- prepared models: read and checked without a world, then added to one --------------------

// A chain of `joints` links, each on a revolute joint under the one before, hanging from a base
// fixed to the world.
std::string revoluteChainUrdf(int joints) {
  std::ostringstream s;
  s << "<robot name=\"chain\"><link name=\"world\"/><joint name=\"anchor\" type=\"fixed\">"
    << "<parent link=\"world\"/><child link=\"l0\"/><origin xyz=\"0 0 " << 0.1 * joints + 1
    << "\"/></joint><link name=\"l0\">" << inertial(1, 0.01, 0.01, 0.01) << "</link>";
  for (int i = 1; i <= joints; ++i)
    s << "<joint name=\"j" << i << "\" type=\"revolute\"><parent link=\"l" << i - 1
      << "\"/><child link=\"l" << i << "\"/><origin xyz=\"0 0 -0.1\"/><axis xyz=\"0 1 0\"/>"
      << "<limit lower=\"-3\" upper=\"3\" effort=\"100\" velocity=\"10\"/></joint><link name=\"l"
      << i << "\">" << inertial(0.1, 0.001, 0.001, 0.001, "0 0 -0.05") << "</link>";
  s << "</robot>";
  return s.str();
}

// `count` copies of `element` in a URDF or SDF model with one link besides.
std::string urdfWith(int count, const std::string& element) {
  std::string urdf = "<robot name=\"many\"><link name=\"a\">" + inertial(1, 1, 1, 1) + "</link>";
  for (int i = 0; i < count; ++i) urdf += element;
  return urdf + "</robot>";
}
std::string sdfWith(int count, const std::string& element) {
  std::string sdf = "<sdf version=\"1.6\"><model name=\"many\"><link name=\"a\"/>";
  for (int i = 0; i < count; ++i) sdf += element;
  return sdf + "</model></sdf>";
}

TEST_P(PreparedModels, AModelPreparedWithoutAWorldSpawnsAsSpawnFromXmlDoes) {
  PreparedModel prepared = World::prepare(tutorialUrdf(), ModelFormat::Urdf, {});
  ASSERT_TRUE(prepared.status().ok()) << prepared.status();
  World world(GetParam());
  const Status spawned = world.spawn("one_DOF_robot", std::move(prepared), at(0, 0, kLift));
  ASSERT_TRUE(spawned.ok()) << spawned;
  World direct(GetParam());
  spawnLiftedRobot(&direct);
  ASSERT_TRUE(world.setModelConfiguration("one_DOF_robot", {"joint1"}, {0.4}).ok());
  ASSERT_TRUE(direct.setModelConfiguration("one_DOF_robot", {"joint1"}, {0.4}).ok());
  steps(&world, 300);
  steps(&direct, 300);
  EXPECT_EQ(snapshot(world), snapshot(direct));
}

TEST_P(PreparedModels, TheWorldsRefusalsComeFirstAndLeaveItUnchanged) {
  World world(GetParam());
  spawnLiftedRobot(&world);
  const std::string before = snapshot(world);
  const auto bad = [] { return World::prepare("<robot name=\"r\"/>", ModelFormat::Urdf, {}); };
  EXPECT_EQ(bad().status().code, StatusCode::ModelRejected);
  EXPECT_EQ(world.checkSpawn("one_DOF_robot", Pose(), "").code, StatusCode::ModelExists);
  EXPECT_EQ(world.spawn("one_DOF_robot", bad(), Pose()).code, StatusCode::ModelExists);
  EXPECT_EQ(world.spawn("other", bad(), Pose(), "nowhere").code,
            StatusCode::ReferenceFrameNotFound);
  Pose zero;
  zero.orientation = {0, 0, 0, 0};
  EXPECT_EQ(world.spawn("other", bad(), zero).code, StatusCode::ZeroQuaternion);
  EXPECT_EQ(world.spawn("other", bad(), Pose()).code, StatusCode::ModelRejected);
  EXPECT_EQ(snapshot(world), before);
  EXPECT_EQ(world.modelNames(), std::vector<std::string>{"one_DOF_robot"});
}

// The counts are taken before a parser reads the XML: models the parsers would refuse for
// another reason (duplicate names, includes not found) are refused for the count.
TEST_P(PreparedModels, CountsPastTheLimitsAreRefusedBeforeTheParserReadsTheModel) {
  expectRejected(World::prepare(urdfWith(3000, "<link name=\"l\"/>"), ModelFormat::Urdf, {}).status(),
                 "the model has 3001 links; at most 1000 are accepted");
  expectRejected(World::prepare(sdfWith(3000, "<link name=\"l\"/>"), ModelFormat::Sdf, {}).status(),
                 "the model has 3001 links; at most 1000 are accepted");
  const std::string urdf_joint =
      "<joint name=\"j\" type=\"fixed\"><parent link=\"a\"/><child link=\"a\"/></joint>";
  expectRejected(World::prepare(urdfWith(1001, urdf_joint), ModelFormat::Urdf, {}).status(),
                 "the model has 1001 joints; at most 1000 are accepted");
  const std::string sdf_joint =
      "<joint name=\"j\" type=\"fixed\"><parent>a</parent><child>a</child></joint>";
  expectRejected(World::prepare(sdfWith(1001, sdf_joint), ModelFormat::Sdf, {}).status(),
                 "the model has 1001 joints; at most 1000 are accepted");
  expectRejected(World::prepare(sdfWith(101, "<include><uri>model://none</uri></include>"),
                                ModelFormat::Sdf, {}).status(),
                 "the model has 101 <include>s; at most 100 are accepted");
  const std::string padded = urdfWith(1, "<!--" + std::string(10000000, ' ') + "-->");
  expectRejected(World::prepare(padded, ModelFormat::Urdf, {}).status(),
                 "the model XML has " + std::to_string(padded.size()) +
                     " bytes; at most 10000000 are accepted");
  // At the limits: the parsers' own refusals, or none.
  expectRejected(World::prepare(sdfWith(100, "<include><uri>model://none</uri></include>"),
                                ModelFormat::Sdf, {}).status(),
                 "model://none is not in the model path");
  const PreparedModel largest = World::prepare(fixedChainUrdf(1000), ModelFormat::Urdf, {});
  EXPECT_TRUE(largest.status().ok()) << largest.status();
}

// ODE's exact solver (its default) costs about 1 ms a step at 50 moving joints and grows as
// joints^2.8; the iterative solvers grow linearly and take any model within the link limit.
TEST_P(PreparedModels, TheExactSolverTakesModelsOfAtMostFiftyMovingJoints) {
  World world(GetParam());
  const Status largest = world.spawn("chain50", revoluteChainUrdf(50), ModelFormat::Urdf, Pose());
  ASSERT_TRUE(largest.ok()) << largest;
  const bool exact = GetParam() == "ode";
  const Status over = world.spawn("chain51", revoluteChainUrdf(51), ModelFormat::Urdf, at(3, 0, 0));
  if (!exact) {
    ASSERT_TRUE(over.ok()) << over;
    steps(&world, 10);
    return;
  }
  expectRejected(over, "the model has 51 moving joints; at most 50 are accepted with the exact "
                       "solver (ODE's dWorldStep, quick_step false)");
  EXPECT_NE(over.subject.find("with quick_step (the node's ~quick_step"), std::string::npos)
      << over;
  EXPECT_EQ(world.modelNames(), std::vector<std::string>{"chain50"});
  PhysicsParams quick = world.params();
  quick.quick_step = true;
  ASSERT_TRUE(world.setParams(quick).ok());
  const Status quick_spawn =
      world.spawn("chain51", revoluteChainUrdf(51), ModelFormat::Urdf, at(3, 0, 0));
  ASSERT_TRUE(quick_spawn.ok()) << quick_spawn;
  steps(&world, 10);
  PhysicsParams back = quick;
  back.quick_step = false;
  const Status refused = world.setParams(back);
  EXPECT_EQ(refused.code, StatusCode::InvalidParameter) << refused;
  EXPECT_EQ(refused.subject, "quick_step");
  EXPECT_EQ(refused.max, 50);
  EXPECT_TRUE(world.params().quick_step);
  ASSERT_TRUE(world.deleteModel("chain51").ok());
  EXPECT_TRUE(world.setParams(back).ok());
}

INSTANTIATE_TEST_SUITE_P(Engines, PreparedModels, ::testing::ValuesIn(World::engineNames()),
                         [](const auto& info) { return info.param; });
INSTANTIATE_TEST_SUITE_P(Engines, BadInput, ::testing::ValuesIn(World::engineNames()),
                         [](const auto& info) { return info.param; });
INSTANTIATE_TEST_SUITE_P(Engines, BodyWrench, ::testing::ValuesIn(World::engineNames()),
                         [](const auto& info) { return info.param; });
INSTANTIATE_TEST_SUITE_P(Engines, Contacts, ::testing::ValuesIn(World::engineNames()),
                         [](const auto& info) { return info.param; });
INSTANTIATE_TEST_SUITE_P(Engines, Errors, ::testing::ValuesIn(World::engineNames()),
                         [](const auto& info) { return info.param; });
INSTANTIATE_TEST_SUITE_P(Engines, Joints, ::testing::ValuesIn(World::engineNames()),
                         [](const auto& info) { return info.param; });
INSTANTIATE_TEST_SUITE_P(Engines, LinkProperties, ::testing::ValuesIn(World::engineNames()),
                         [](const auto& info) { return info.param; });
INSTANTIATE_TEST_SUITE_P(Engines, Models, ::testing::ValuesIn(World::engineNames()),
                         [](const auto& info) { return info.param; });
INSTANTIATE_TEST_SUITE_P(Engines, Robustness, ::testing::ValuesIn(World::engineNames()),
                         [](const auto& info) { return info.param; });
INSTANTIATE_TEST_SUITE_P(Engines, State, ::testing::ValuesIn(World::engineNames()),
                         [](const auto& info) { return info.param; });
INSTANTIATE_TEST_SUITE_P(Engines, TutorialRobot, ::testing::ValuesIn(World::engineNames()),
                         [](const auto& info) { return info.param; });
INSTANTIATE_TEST_SUITE_P(Engines, EffortJobs, ::testing::ValuesIn(World::engineNames()),
                         [](const auto& info) { return info.param; });

}  // namespace
}  // namespace onedof_sim

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
