// tutorial_scenario: the tutorial's runs on the core with one engine, in-process and deterministic,
// for the cross-validation of the engines (python -m onedof_sim.reference.cross_validation drives
// it and runs the same on pybullet with its own loaders). No ROS: what differs between the engines
// is physics only.
//
//   tutorial_scenario scenario --physics NAME --ground F --urdf F --table F --table-x X
//                              --table-phase N --kp KP --kv KV --phase-seconds S
//                              --commands C1,C2,...
//     The tutorial's controller law every 10 ms of sim time (read q, qdot; an effort job of
//     Kp wrap(c - q) - Kv qdot for 10 ms from now), one phase per command, each S long; the table
//     spawned at (X, 0, 0) when phase N (0-based) starts. Prints CSV t,q,qdot,torque per tick.
//   tutorial_scenario release --physics NAME --ground F --urdf F --z Z --q Q --effort E
//                             --seconds S
//     The robot spawned Z above the origin, joint1 at rest at Q, a constant effort E on it from
//     the start. Prints CSV t,q,qdot after every step (t = 0 first).
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <onedof_sim/world.h>

#include "tool_options.h"

namespace {

// Options, UsageError, readFile, check, addGround.
using namespace onedof_sim::tools;

constexpr int64_t kControlPeriodNs = 10000000;  // the controller's 100 Hz
constexpr const char* kRobot = "one_DOF_robot";
constexpr const char* kJoint = "joint1";

const char* const kUsage =
    "usage: tutorial_scenario scenario --physics NAME --ground F --urdf F --table F --table-x X "
    "--table-phase N --kp KP --kv KV --phase-seconds S --commands C1,C2,...\n"
    "       tutorial_scenario release --physics NAME --ground F --urdf F --z Z --q Q --effort E "
    "--seconds S";

onedof_sim::JointInfo joint1(const onedof_sim::World& world) {
  onedof_sim::JointInfo info;
  check(world.jointInfo(kJoint, &info), "joint1");
  return info;
}

onedof_sim::Pose at(double x, double z) {
  onedof_sim::Pose pose;
  pose.position.x = x;
  pose.position.z = z;
  return pose;
}

int scenario(const Options& options) {
  const std::string table = readFile(options.text("table"));
  const double table_x = options.number("table-x");
  const double kp = options.number("kp"), kv = options.number("kv");
  const std::vector<double> commands = options.numbers("commands");
  const int table_phase = static_cast<int>(options.number("table-phase"));
  const int64_t phase_ticks =
      std::llround(options.number("phase-seconds") * 1e9 / kControlPeriodNs);
  if (phase_ticks < 1) throw UsageError{"--phase-seconds must be at least 0.01"};

  onedof_sim::World world(options.text("physics"));
  addGround(world, options);
  check(world.spawn(kRobot, readFile(options.text("urdf")), onedof_sim::ModelFormat::Urdf,
                    at(0, 0)),
        "spawn the robot");
  std::printf("t,q,qdot,torque\n");
  for (size_t phase = 0; phase < commands.size(); ++phase) {
    if (static_cast<int>(phase) == table_phase)
      check(world.spawn("cafe_table", table, onedof_sim::ModelFormat::Sdf, at(table_x, 0)),
            "spawn the table");
    for (int64_t tick = 0; tick < phase_ticks; ++tick) {
      const onedof_sim::JointInfo info = joint1(world);
      // The law of minimal_joint_controller.control_law.pd_torque (no torque limit given).
      const double torque =
          kp * std::remainder(commands[phase] - info.position, 2 * M_PI) - kv * info.rate;
      check(world.applyJointEffort(kJoint, torque, world.timeNs(), kControlPeriodNs), "effort");
      std::printf("%.3f,%.17g,%.17g,%.17g\n", world.time(), info.position, info.rate, torque);
      const int64_t until = world.timeNs() + kControlPeriodNs;
      while (world.timeNs() < until) world.step();
    }
  }
  return 0;
}

int release(const Options& options) {
  onedof_sim::World world(options.text("physics"));
  addGround(world, options);
  check(world.spawn(kRobot, readFile(options.text("urdf")), onedof_sim::ModelFormat::Urdf,
                    at(0, options.number("z"))),
        "spawn the robot");
  check(world.setModelConfiguration(kRobot, {kJoint}, {options.number("q")}), "set q");
  const double effort = options.number("effort");
  if (effort != 0) check(world.applyJointEffort(kJoint, effort, 0, -1), "effort");
  const int64_t until = std::llround(options.number("seconds") * 1e9);
  std::printf("t,q,qdot\n");
  for (;;) {
    const onedof_sim::JointInfo info = joint1(world);
    std::printf("%.3f,%.17g,%.17g\n", world.time(), info.position, info.rate);
    if (world.timeNs() >= until) break;
    world.step();
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return onedof_sim::tools::runMode(argc, argv, "tutorial_scenario", kUsage,
                                    {{"scenario", scenario}, {"release", release}});
}
