// The mass x shape x size x inertia sweep, on every engine: no body the world accepts may abort
// the process. Each combination is spawned twice, as a free body dropped on the ground and as a
// wheel on a continuous joint at the side of a free base, driven by an effort; every accepted one
// is stepped for two seconds and must stay finite and near where it fell. A refusal must give the
// reason. Each case runs in a child process, so that an engine aborting (an assertion inside ODE)
// fails that case and is counted, instead of ending the test binary.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <iomanip>
#include <sstream>
#include <string>
#include <vector>

#include "onedof_sim/world.h"

namespace onedof_sim {
namespace {

enum class Shape { Box, Cylinder, ThinWheel, Sphere };
enum class Mount { FreeBody, WheelOnBase };

const char* shapeName(Shape shape) {
  switch (shape) {
    case Shape::Box: return "box";
    case Shape::Cylinder: return "cylinder";
    case Shape::ThinWheel: return "thin_wheel";
    case Shape::Sphere: return "sphere";
  }
  return "?";
}

struct SweepCase {
  Mount mount;
  double mass;    // kg
  Shape shape;
  double radius;  // m: half the box's side, the cylinder's and the sphere's radius
  double factor;  // the moments are this times those of the solid shape of that mass
};

std::string describe(const SweepCase& c) {
  std::ostringstream s;
  s << (c.mount == Mount::FreeBody ? "free " : "wheel ") << shapeName(c.shape) << " r=" << c.radius
    << " m=" << c.mass << " I=" << c.factor << "*solid";
  return s.str();
}

// The shape's <geometry> and its solid moments (about x, y, z of the shape) for mass m.
struct ShapeFigures {
  std::string geometry;
  double ixx, iyy, izz;
};

ShapeFigures figures(Shape shape, double r, double m) {
  std::ostringstream g;
  g << std::setprecision(17);
  switch (shape) {
    case Shape::Box: {
      const double side = 2 * r, i = m * side * side / 6;
      g << "<box size=\"" << side << " " << side << " " << side << "\"/>";
      return {g.str(), i, i, i};
    }
    case Shape::Cylinder:
    case Shape::ThinWheel: {
      // A thin wheel: a quarter of its radius wide (0.1 m radius, 0.025 m wide).
      const double length = shape == Shape::Cylinder ? 2 * r : r / 4;
      const double across = m * (3 * r * r + length * length) / 12;
      g << "<cylinder radius=\"" << r << "\" length=\"" << length << "\"/>";
      return {g.str(), across, across, m * r * r / 2};
    }
    case Shape::Sphere: {
      const double i = 0.4 * m * r * r;
      g << "<sphere radius=\"" << r << "\"/>";
      return {g.str(), i, i, i};
    }
  }
  return {};
}

std::string inertial(double m, double ixx, double iyy, double izz) {
  std::ostringstream s;
  s << std::setprecision(17) << "<inertial><mass value=\"" << m << "\"/><inertia ixx=\"" << ixx
    << "\" ixy=\"0\" ixz=\"0\" iyy=\"" << iyy << "\" iyz=\"0\" izz=\"" << izz << "\"/></inertial>";
  return s.str();
}

// The swept body as link "body"; for a wheel, its axis (the shape's z) along the base's y.
std::string sweptLink(const SweepCase& c) {
  const ShapeFigures f = figures(c.shape, c.radius, c.mass);
  std::ostringstream s;
  s << std::setprecision(17) << "<link name=\"body\">"
    << inertial(c.mass, c.factor * f.ixx, c.factor * f.iyy, c.factor * f.izz)
    << "<collision><geometry>" << f.geometry << "</geometry></collision></link>";
  return s.str();
}

// The wheel's link frame has its z along the joint axis; the joint turns it to the base's y.
std::string urdf(const SweepCase& c) {
  std::ostringstream s;
  s << std::setprecision(17) << "<robot name=\"swept\">";
  if (c.mount == Mount::FreeBody) {
    s << sweptLink(c) << "</robot>";
    return s.str();
  }
  const double r = c.radius;
  // The base: a box 4r long, 2r wide and r high, as heavy as the wheel, its wheel at the side.
  s << "<link name=\"base\">"
    << inertial(c.mass, c.mass * (4 * r * r + r * r) / 12, c.mass * (16 * r * r + r * r) / 12,
                c.mass * (16 * r * r + 4 * r * r) / 12)
    << "<collision><geometry><box size=\"" << 4 * r << " " << 2 * r << " " << r
    << "\"/></geometry></collision></link>"
    << "<joint name=\"axle\" type=\"continuous\"><parent link=\"base\"/><child link=\"body\"/>"
    << "<origin xyz=\"" << r << " " << 2.5 * r << " 0\" rpy=\"-1.5707963267948966 0 0\"/>"
    << "<axis xyz=\"0 0 1\"/></joint>" << sweptLink(c) << "</robot>";
  return s.str();
}

// What a case came to, as the child's exit code.
enum Outcome { kSimulated = 10, kRefused = 11, kUnbounded = 12, kUnexpected = 13 };

constexpr double kDropHeight = 2;  // in radii above resting, so that it falls and lands
constexpr int kSteps = 2000;

Outcome run(const std::string& engine, const SweepCase& c) {
  World world(engine);
  const double start_z = (kDropHeight + 1) * c.radius;
  Pose pose;
  pose.position.z = start_z;
  const Status status = world.spawn("swept", urdf(c), ModelFormat::Urdf, pose);
  if (!status.ok()) {
    if (status.code == StatusCode::ModelRejected && !status.subject.empty()) return kRefused;
    std::fprintf(stderr, "%s: unexpected refusal %s\n", describe(c).c_str(),
                 (std::ostringstream() << status).str().c_str());
    return kUnexpected;
  }
  if (c.mount == Mount::WheelOnBase &&
      !world.applyJointEffort("axle", c.mass * 9.8 * c.radius, 0, -1).ok())
    return kUnexpected;
  for (int i = 0; i < kSteps; ++i) world.step();
  // Bounded: finite, above the ground by less than where it started, and within a metre plus
  // ten radii of where it fell (a wheel driven for two seconds rolls a few metres at most).
  const double reach = 1 + 10 * c.radius;
  for (const std::string& link : world.linkNames()) {
    Pose p;
    Twist t;
    if (!world.linkState(link, "", &p, &t).ok()) return kUnexpected;
    const Vec3& x = p.position;
    const bool bounded = std::isfinite(x.x) && std::isfinite(x.y) && std::isfinite(x.z) &&
                         std::hypot(x.x, x.y) < reach + 3 && x.z > -reach && x.z < start_z + reach;
    if (!bounded) {
      std::fprintf(stderr, "%s: %s ended at %g %g %g\n", describe(c).c_str(), link.c_str(), x.x,
                   x.y, x.z);
      return kUnbounded;
    }
  }
  return kSimulated;
}

std::vector<SweepCase> sweep() {
  std::vector<SweepCase> cases;
  for (Mount mount : {Mount::FreeBody, Mount::WheelOnBase})
    for (double mass : {1e-3, 0.1, 10.0, 1e3})
      for (Shape shape : {Shape::Box, Shape::Cylinder, Shape::ThinWheel, Shape::Sphere})
        for (double radius : {1e-3, 1e-2, 0.1, 1.0})
          for (double factor : {1e-6, 1e-4, 1e-3, 1e-1, 1.0, 1e3})
            cases.push_back({mount, mass, shape, radius, factor});
  return cases;
}

class InertiaSweep : public ::testing::TestWithParam<std::string> {};

TEST_P(InertiaSweep, NoBodyAbortsTheProcessAndEveryAcceptedOneStaysBounded) {
  int counts[4] = {0, 0, 0, 0};  // simulated, refused, unbounded or unexpected, aborted
  std::vector<std::string> failures;
  const std::vector<SweepCase> cases = sweep();
  for (const SweepCase& c : cases) {
    std::fflush(nullptr);
    const pid_t child = fork();
    ASSERT_GE(child, 0);
    if (child == 0) _exit(run(GetParam(), c));
    int wait_status = 0;
    ASSERT_EQ(waitpid(child, &wait_status, 0), child);
    if (WIFEXITED(wait_status) && WEXITSTATUS(wait_status) == kSimulated) {
      ++counts[0];
    } else if (WIFEXITED(wait_status) && WEXITSTATUS(wait_status) == kRefused) {
      ++counts[1];
    } else if (WIFEXITED(wait_status)) {
      ++counts[2];
      failures.push_back(describe(c) + ": " +
                         (WEXITSTATUS(wait_status) == kUnbounded ? "unbounded" : "unexpected"));
    } else {
      ++counts[3];
      failures.push_back(describe(c) + ": killed by signal " +
                         std::to_string(WTERMSIG(wait_status)));
    }
  }
  std::printf("[ figures  ] %s: %zu cases, %d simulated, %d refused, %d unbounded, %d aborted\n",
              GetParam().c_str(), cases.size(), counts[0], counts[1], counts[2], counts[3]);
  std::string list;
  for (const std::string& failure : failures) list += "\n  " + failure;
  EXPECT_TRUE(failures.empty()) << failures.size() << " cases failed:" << list;
}

// The refusal names the link, its moment and the least it needs; the book's drive wheel (0.1 m
// radius, 0.05 m wide, 1 to 5 kg, solid) is accepted; set_link_properties holds the same rule.
TEST_P(InertiaSweep, InertiaFarBelowTheShapeIsRefusedNamingTheLeastMoment) {
  World world(GetParam());
  const SweepCase tiny{Mount::FreeBody, 1e-3, Shape::Box, 0.1, 1e-6};
  const Status refused = world.spawn("tiny", urdf(tiny), ModelFormat::Urdf, Pose());
  ASSERT_EQ(refused.code, StatusCode::ModelRejected) << refused;
  EXPECT_NE(refused.subject.find("link 'body'"), std::string::npos) << refused.subject;
  EXPECT_NE(refused.subject.find("6.66667e-12 kg m^2"), std::string::npos) << refused.subject;
  EXPECT_NE(refused.subject.find("at least 3e-08 kg m^2"), std::string::npos) << refused.subject;
  EXPECT_TRUE(world.modelNames().empty());
  for (double mass : {1.0, 5.0}) {
    const std::string wheel =
        "<robot name=\"w\"><link name=\"body\">" +
        inertial(mass, mass * (3 * 0.01 + 0.0025) / 12, mass * (3 * 0.01 + 0.0025) / 12,
                 mass * 0.01 / 2) +
        "<collision><geometry><cylinder radius=\"0.1\" length=\"0.05\"/></geometry>"
        "</collision></link></robot>";
    const std::string name = "wheel" + std::to_string(int(mass));
    ASSERT_TRUE(world.spawn(name, wheel, ModelFormat::Urdf, Pose()).ok()) << mass;
  }
  LinkInfo properties;
  ASSERT_TRUE(world.linkProperties("wheel1::body", &properties).ok());
  properties.ixx = properties.iyy = properties.izz = 1e-9;
  const Status status = world.setLinkProperties("wheel1::body", properties);
  EXPECT_EQ(status.code, StatusCode::OutOfRange) << status;
  EXPECT_EQ(status.subject, "inertia");
  EXPECT_GT(status.min, 1e-9);
  EXPECT_LT(status.min, 1e-3);
}

INSTANTIATE_TEST_SUITE_P(Engines, InertiaSweep, ::testing::ValuesIn(World::engineNames()),
                         [](const auto& info) { return info.param; });

}  // namespace
}  // namespace onedof_sim
