// A diff-drive base driven into a low step on the ground (a cafe table's base plate), with other
// models in the world, and into a wall it was spawned across.
#include <gtest/gtest.h>
#include <ode/misc.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "onedof_sim/world.h"

namespace onedof_sim {
namespace {

std::string readFile(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

const std::string kModels = ONEDOF_SOURCE_DIR "/src/onedof_sim/models/";

Pose at(double x, double y, double yaw) {
  Pose pose;
  pose.position = {x, y, 0};
  pose.orientation = {std::cos(yaw / 2), 0, 0, std::sin(yaw / 2)};
  return pose;
}

class DriveIntoStep : public ::testing::TestWithParam<std::string> {};

// The models of the scene, as files: the book's mobot (tests/robots/drive_base.urdf: a box
// chassis, two wheels on velocity motors, two swivel casters), a starting pen, a cafe table on a
// 4 cm base plate and a can of beer.
struct Scene {
  std::string base = readFile(ONEDOF_SOURCE_DIR "/tests/robots/drive_base.urdf");
  std::string pen = readFile(kModels + "starting_pen/model.sdf");
  std::string table = readFile(kModels + "cafe_table/model.sdf");
  std::string beer = readFile(kModels + "beer/model.sdf");
};

// Drives the mobot spawned at `mobot` at `speed` for `steps` steps among the pen at `pen`, the
// table at `table` and the beer: every step succeeds and no model is lost. Returns how many
// warnings said a step was taken again, printing each.
int drive(const std::string& engine, const Scene& scene, const Pose& pen, const Pose& table,
          const Pose& mobot, double speed, int steps, const std::string& run) {
  const std::vector<std::string> names{"starting_pen", "cafe_table", "beer", "mobot"};
  World world(engine);
  EXPECT_TRUE(world.spawn("starting_pen", scene.pen, ModelFormat::Sdf, pen).ok());
  EXPECT_TRUE(world.spawn("cafe_table", scene.table, ModelFormat::Sdf, table).ok());
  EXPECT_TRUE(world.spawn("beer", scene.beer, ModelFormat::Sdf, at(1, 2, 0)).ok());
  const Status spawned = world.spawn("mobot", scene.base, ModelFormat::Urdf, mobot);
  EXPECT_TRUE(spawned.ok()) << spawned;
  if (::testing::Test::HasFailure()) return 0;
  int retaken = 0;
  for (int i = 0; i < steps; ++i) {
    for (const char* joint : {"left_wheel_joint", "right_wheel_joint"}) {
      const Status commanded = world.setJointVelocityCommand(joint, speed / 0.1651, 100);
      EXPECT_TRUE(commanded.ok()) << run << " at " << world.time() << " s: " << commanded;
      if (!commanded.ok()) return retaken;
    }
    const Status status = world.step();
    EXPECT_TRUE(status.ok()) << run << " at " << world.time() << " s: " << status;
    if (!status.ok()) break;
    for (const std::string& warning : world.takeWarnings())
      if (warning.find("taken again") != std::string::npos) {
        ++retaken;
        std::printf("%s at %g s: %s\n", run.c_str(), world.time(), warning.c_str());
      }
  }
  EXPECT_EQ(world.modelNames(), names) << run;
  return retaken;
}

// The mobot driven into the base plate of the cafe table, both on the starting pen's floor (the
// pen at 0 -5, its floor under the drive and its walls clear of it), the beer nearby:
// at several speeds, head-on and askew. It starts 0.5 m short of the plate and is driven 2 s: it
// meets the plate within 1.3 s at the lowest speed and then climbs it, stalls against the
// table's pole or glances off. Whatever the engine does inside a step, no model is lost and the
// world never stops; a step ODE's exact solver fails is printed as the warning that says it was
// taken again.
TEST_P(DriveIntoStep, NoModelIsLostWhenTheBaseDrivesIntoAStep) {
  const Scene scene;
  int retaken = 0;
  for (double speed : {0.5, 1.0, 2.0})
    for (double offset : {0.0, 0.25})
      for (double yaw : {0.0, 0.3}) {
        char run[64];
        std::snprintf(run, sizeof run, "speed %g offset %g yaw %g", speed, offset, yaw);
        retaken += drive(GetParam(), scene, at(0, -5, 0), at(2, offset, 0), at(1.05, 0, yaw),
                         speed, 2000, run);
      }
  std::printf("%s: %d steps taken again\n", GetParam().c_str(), retaken);
}

// The mobot spawned across the pen's south wall (the pen at the origin) and driven: the wall,
// the pen's floor and the mobot's wheels and chassis, pressed together by the overlap, touch at
// dozens of points that hold the same motions many times over. With a CFM floor on every contact
// row, friction rows included (ode_engine.cpp), ODE's exact solver factorises every step of it
// without an internal error (dxLDLTAddTL's assertion on a singular pivot): no step is taken again
// and no model is lost. A real internal error and its containment: test_engine_fault.cpp. ODE's
// solvers draw from one random number generator per process: it is seeded as a process starts,
// so that the steps are the same whatever ran before in this process.
TEST_P(DriveIntoStep, NoModelIsLostAndNoStepFailsWithTheBaseInAWall) {
  dRandSetSeed(0);
  const Scene scene;
  const int retaken = drive(GetParam(), scene, at(0, 0, 0), at(2, 0, 0), at(0, 0, 0), 0.5, 500,
                            "in the wall");
  EXPECT_EQ(retaken, 0);
}

INSTANTIATE_TEST_SUITE_P(Engines, DriveIntoStep, ::testing::ValuesIn(World::engineNames()),
                         [](const auto& info) { return info.param; });

}  // namespace
}  // namespace onedof_sim
