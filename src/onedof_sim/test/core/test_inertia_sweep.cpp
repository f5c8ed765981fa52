// The mass x shape x size x inertia sweep, on every engine: no body may abort the process or
// leave the world stepping on non-finite values. Each combination is spawned twice, as a free
// body dropped on the ground and as a wheel on a continuous joint at the side of a free base,
// driven by an effort, and stepped for two seconds. A body of plausible inertia for its shape
// must stay finite and near where it fell. One whose inertia is implausibly small for its shape
// is spawned with a warning, as Gazebo spawns it; the engine may fail on it, and the world
// contains that: the step is taken again, or the model removed, and the rest stays finite (a body
// Bullet lets sink through the ground is finite, and may end anywhere below). A refusal must
// give the reason. Each case runs in a child process, so that an engine aborting (an assertion
// inside ODE) fails that case and is counted, instead of ending the test binary.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <exception>
#include <iomanip>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "../ground_plane.h"
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
enum Outcome {
  kSimulated = 10,  // finite and near where it fell
  kRefused = 11,
  kUnbounded = 12,  // plausible inertia, yet far from where it fell: a failure
  kUnexpected = 13,
  kNonFinite = 14,  // a failure
  kWarnedAndFarOff = 15,  // implausible inertia, finite, far from where it fell
  kWarnedAndRemoved = 16,  // implausible inertia, removed by the world after an engine failure
};

constexpr double kDropHeight = 2;  // in radii above resting, so that it falls and lands
constexpr int kSteps = 2000;

// `ground`: the ground plane read once for every case (testing_support::preparedGroundPlane).
Outcome run(const std::string& engine, const SweepCase& c, PreparedModel ground) {
  World world(engine);
  testing_support::addGroundPlane(world, std::move(ground));
  const double start_z = (kDropHeight + 1) * c.radius;
  Pose pose;
  pose.position.z = start_z;
  PreparedModel prepared = World::prepare(urdf(c), ModelFormat::Urdf, {});
  const bool warned = !prepared.warnings().empty();
  const Status status = world.spawn("swept", std::move(prepared), pose);
  if (!status.ok()) {
    if (status.code == StatusCode::ModelRejected && !status.subject.empty()) return kRefused;
    std::fprintf(stderr, "%s: unexpected refusal %s\n", describe(c).c_str(),
                 (std::ostringstream() << status).str().c_str());
    return kUnexpected;
  }
  if (c.mount == Mount::WheelOnBase &&
      !world.applyJointEffort("axle", c.mass * 9.8 * c.radius, 0, -1).ok())
    return kUnexpected;
  for (int i = 0; i < kSteps; ++i) {
    const Status stepped = world.step();
    if (!stepped.ok() && !(warned && stepped.code == StatusCode::EngineFault)) {
      std::fprintf(stderr, "%s: step %d: %s\n", describe(c).c_str(), i,
                   (std::ostringstream() << stepped).str().c_str());
      return kUnexpected;
    }
  }
  if (world.modelNames().empty()) return warned ? kWarnedAndRemoved : kUnexpected;
  // Bounded: above the ground by less than where it started, and within a metre plus ten radii
  // of where it fell (a wheel driven for two seconds rolls a few metres at most).
  const double reach = 1 + 10 * c.radius;
  bool bounded = true;
  for (const std::string& link : world.linkNames()) {
    Pose p;
    Twist t;
    if (!world.linkState(link, "", &p, &t).ok()) return kUnexpected;
    const Vec3& x = p.position;
    if (!(std::isfinite(x.x) && std::isfinite(x.y) && std::isfinite(x.z))) {
      std::fprintf(stderr, "%s: %s is not finite\n", describe(c).c_str(), link.c_str());
      return kNonFinite;
    }
    if (!(std::hypot(x.x, x.y) < reach + 3 && x.z > -reach && x.z < start_z + reach)) {
      if (!warned)
        std::fprintf(stderr, "%s: %s ended at %g %g %g\n", describe(c).c_str(), link.c_str(),
                     x.x, x.y, x.z);
      bounded = false;
    }
  }
  if (bounded) return kSimulated;
  return warned ? kWarnedAndFarOff : kUnbounded;
}

std::vector<SweepCase> sweep(Mount mount) {
  std::vector<SweepCase> cases;
  for (double mass : {1e-3, 0.1, 10.0, 1e3})
    for (Shape shape : {Shape::Box, Shape::Cylinder, Shape::ThinWheel, Shape::Sphere})
      for (double radius : {1e-3, 1e-2, 0.1, 1.0})
        for (double factor : {1e-6, 1e-4, 1e-3, 1e-1, 1.0, 1e3})
          cases.push_back({mount, mass, shape, radius, factor});
  return cases;
}

class InertiaSweep : public ::testing::TestWithParam<std::string> {};

// Each mount's sweep, one process per case: no body aborts the process and every plausible one
// stays bounded. Two cases per engine, so that a runner takes them side by side.
void sweepMount(const std::string& engine, Mount mount) {
  // simulated, refused, warned and far off, warned and removed, failed, aborted
  int counts[6] = {0, 0, 0, 0, 0, 0};
  std::vector<std::string> failures;
  const std::vector<SweepCase> cases = sweep(mount);
  // The ground plane, read once: each child spawns its own copy of the parent's. Read on a thread
  // of its own, so that what libsdformat allocates and frees reading it stays in that thread's
  // malloc arena: left in the main arena, the first allocation of every child would sort those
  // scattered free chunks, copying several megabytes of the parent's heap page by page.
  PreparedModel ground;
  std::exception_ptr unread;
  std::thread([&] {
    try {
      ground = testing_support::preparedGroundPlane();
    } catch (...) {
      unread = std::current_exception();
    }
  }).join();
  if (unread) std::rethrow_exception(unread);
  for (const SweepCase& c : cases) {
    std::fflush(nullptr);
    const pid_t child = fork();
    ASSERT_GE(child, 0);
    if (child == 0) _exit(run(engine, c, std::move(ground)));
    int wait_status = 0;
    ASSERT_EQ(waitpid(child, &wait_status, 0), child);
    const int outcome = WIFEXITED(wait_status) ? WEXITSTATUS(wait_status) : -1;
    if (outcome == kSimulated) {
      ++counts[0];
    } else if (outcome == kRefused) {
      ++counts[1];
    } else if (outcome == kWarnedAndFarOff) {
      ++counts[2];
    } else if (outcome == kWarnedAndRemoved) {
      ++counts[3];
    } else if (WIFEXITED(wait_status)) {
      ++counts[4];
      failures.push_back(describe(c) + ": " +
                         (outcome == kUnbounded   ? "unbounded"
                          : outcome == kNonFinite ? "non-finite"
                                                  : "unexpected"));
    } else {
      ++counts[5];
      failures.push_back(describe(c) + ": killed by signal " +
                         std::to_string(WTERMSIG(wait_status)));
    }
  }
  std::printf("[ figures  ] %s, %s: %zu cases, %d simulated, %d refused, %d of implausible inertia "
              "far off, %d of implausible inertia removed after an engine failure, %d failed, "
              "%d aborted\n",
              engine.c_str(), mount == Mount::FreeBody ? "free bodies" : "wheels on a base",
              cases.size(), counts[0], counts[1], counts[2], counts[3],
              counts[4], counts[5]);
  std::string list;
  for (const std::string& failure : failures) list += "\n  " + failure;
  EXPECT_TRUE(failures.empty()) << failures.size() << " cases failed:" << list;
}

TEST_P(InertiaSweep, NoFreeBodyAbortsTheProcessAndEveryPlausibleOneStaysBounded) {
  sweepMount(GetParam(), Mount::FreeBody);
}

TEST_P(InertiaSweep, NoWheelOnABaseAbortsTheProcessAndEveryPlausibleOneStaysBounded) {
  sweepMount(GetParam(), Mount::WheelOnBase);
}

// The warning names the link, its moment and the least its shape makes plausible, and the body
// is spawned; the book's drive wheel (0.1 m radius, 0.05 m wide, 1 to 5 kg, solid) is not warned
// of; set_link_properties takes an implausible inertia with the same warning.
TEST_P(InertiaSweep, InertiaFarBelowTheShapeIsWarnedOfNamingTheLeastMoment) {
  World world(GetParam());
  const SweepCase tiny{Mount::FreeBody, 1e-3, Shape::Box, 0.1, 1e-6};
  PreparedModel prepared = World::prepare(urdf(tiny), ModelFormat::Urdf, {});
  ASSERT_TRUE(prepared.status().ok()) << prepared.status();
  ASSERT_EQ(prepared.warnings().size(), 1u);
  const InertiaWarning warning = prepared.warnings()[0];
  EXPECT_EQ(warning.link, "body");
  EXPECT_NEAR(warning.smallest_moment, 6.66667e-12, 1e-16);
  EXPECT_NEAR(warning.least_moment, 3e-08, 3e-11);
  ASSERT_TRUE(world.spawn("tiny", std::move(prepared), Pose()).ok());
  for (double mass : {1.0, 5.0}) {
    const std::string wheel =
        "<robot name=\"w\"><link name=\"body\">" +
        inertial(mass, mass * (3 * 0.01 + 0.0025) / 12, mass * (3 * 0.01 + 0.0025) / 12,
                 mass * 0.01 / 2) +
        "<collision><geometry><cylinder radius=\"0.1\" length=\"0.05\"/></geometry>"
        "</collision></link></robot>";
    PreparedModel solid = World::prepare(wheel, ModelFormat::Urdf, {});
    EXPECT_TRUE(solid.warnings().empty()) << mass;
    const std::string name = "wheel" + std::to_string(int(mass));
    ASSERT_TRUE(world.spawn(name, std::move(solid), Pose()).ok()) << mass;
  }
  LinkInfo properties;
  ASSERT_TRUE(world.linkProperties("wheel1::body", &properties).ok());
  std::optional<InertiaWarning> set_warning;
  ASSERT_TRUE(world.setLinkProperties("wheel1::body", properties, &set_warning).ok());
  EXPECT_FALSE(set_warning.has_value());
  properties.ixx = properties.iyy = properties.izz = 1e-9;
  ASSERT_TRUE(world.setLinkProperties("wheel1::body", properties, &set_warning).ok());
  ASSERT_TRUE(set_warning.has_value());
  EXPECT_EQ(set_warning->link, "body");
  EXPECT_NEAR(set_warning->smallest_moment, 1e-9, 1e-15);
  EXPECT_GT(set_warning->least_moment, 1e-9);
  EXPECT_LT(set_warning->least_moment, 1e-3);
  LinkInfo after;
  ASSERT_TRUE(world.linkProperties("wheel1::body", &after).ok());
  EXPECT_EQ(after.ixx, 1e-9);
  properties.ixx = properties.iyy = properties.izz = 1e-13;  // below the Limits' range
  const Status refused = world.setLinkProperties("wheel1::body", properties);
  EXPECT_EQ(refused.code, StatusCode::OutOfRange) << refused;
  EXPECT_EQ(refused.subject, "inertia");
}

INSTANTIATE_TEST_SUITE_P(Engines, InertiaSweep, ::testing::ValuesIn(World::engineNames()),
                         [](const auto& info) { return info.param; });

}  // namespace
}  // namespace onedof_sim
