// A diff-drive base driven into a low step on the ground (a cafe table's base plate), with other
// models in the world.
#include <gtest/gtest.h>

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

// The book's mobot (tests/robots/drive_base.urdf: a box chassis, two wheels on velocity motors,
// two swivel casters) driven into the 4 cm base plate of a cafe table standing on a starting
// pen's floor, a can of beer nearby: at several speeds, head-on and askew. Whatever the engine
// does inside a step, no model is lost and the world never stops; a step ODE's exact solver fails
// is printed as the warning that says it was taken again.
TEST_P(DriveIntoStep, NoModelIsLostWhenTheBaseDrivesIntoAStep) {
  const std::string base = readFile(ONEDOF_SOURCE_DIR "/tests/robots/drive_base.urdf");
  const std::string table = readFile(kModels + "cafe_table/model.sdf");
  const std::string pen = readFile(kModels + "starting_pen/model.sdf");
  const std::string beer = readFile(kModels + "beer/model.sdf");
  const std::vector<std::string> names{"starting_pen", "cafe_table", "beer", "mobot"};
  int retaken = 0;
  for (double speed : {0.5, 1.0, 2.0})
    for (double offset : {0.0, 0.25})
      for (double yaw : {0.0, 0.3}) {
        World world(GetParam());
        ASSERT_TRUE(world.spawn("starting_pen", pen, ModelFormat::Sdf, at(0, 0, 0)).ok());
        ASSERT_TRUE(world.spawn("cafe_table", table, ModelFormat::Sdf, at(2, offset, 0)).ok());
        ASSERT_TRUE(world.spawn("beer", beer, ModelFormat::Sdf, at(1, 2, 0)).ok());
        const Status spawned = world.spawn("mobot", base, ModelFormat::Urdf, at(0, 0, yaw));
        ASSERT_TRUE(spawned.ok()) << spawned;
        for (int i = 0; i < 5000; ++i) {
          for (const char* joint : {"left_wheel_joint", "right_wheel_joint"})
            ASSERT_TRUE(world.setJointVelocityCommand(joint, speed / 0.1651, 100).ok());
          const Status status = world.step();
          ASSERT_TRUE(status.ok()) << "speed " << speed << " offset " << offset << " yaw " << yaw
                                   << " at " << world.time() << " s: " << status;
          for (const std::string& warning : world.takeWarnings())
            if (warning.find("taken again") != std::string::npos) {
              ++retaken;
              std::printf("speed %g offset %g yaw %g at %g s: %s\n", speed, offset, yaw,
                          world.time(), warning.c_str());
            }
        }
        EXPECT_EQ(world.modelNames(), names);
      }
  std::printf("%s: %d steps taken again\n", GetParam().c_str(), retaken);
}

INSTANTIATE_TEST_SUITE_P(Engines, DriveIntoStep, ::testing::ValuesIn(World::engineNames()),
                         [](const auto& info) { return info.param; });

}  // namespace
}  // namespace onedof_sim
