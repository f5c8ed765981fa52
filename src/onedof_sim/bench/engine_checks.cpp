// engine_checks: the cross-validation's experiments beyond the tutorial's arm, on the core with one
// engine, in-process and deterministic (python -m onedof_sim.reference.cross_validation drives
// it). No ROS and no plugin: the world calls each plugin makes, made here directly.
//
//   engine_checks drive --physics NAME --ground F --urdf F --left J --right J --radius R
//                       --separation S --torque T --linear V --angular W --seconds S
//     A differential-drive base (F: a URDF whose left and right wheel joints J turn it forward
//     at positive rates) driven as gazebo_ros_diff_drive drives it: each step, each wheel's
//     velocity motor at (V -+ W S / 2) / R, bounded by T. After 1 s to reach the speed, the
//     base's mean speed along its heading and mean turn rate over S s. Prints CSV linear,angular.
//   engine_checks hold --physics NAME --ground F --mass M
//     A block of M kg on a vertical slider whose stops hold it (the book's force-torque joint),
//     under a base welded to the world: the slider constraint's force along z on the block,
//     averaged over the last 0.1 s of 1 s. Prints CSV force_z.
//   engine_checks scan --physics NAME --ground F --urdf F --lidar-x X --lidar-z Z --pen-half H
//                      --samples N
//     The base of F at the origin in a pen of four walls whose inner faces are H from the
//     origin, settled for 0.5 s; then N horizontal rays over -pi/2..pi/2 of its heading from
//     the lidar's place on it (X ahead of the model frame, Z up), 80 m long. Prints CSV
//     x,y,angle,distance per ray (x, y: where the rays start; angle in the world's axes).
//   engine_checks arm --physics NAME --ground F --urdf F --joints J,... --pose Q,... --p P,...
//                     --i I,... --d D,... --seconds S
//     A serial arm (F: its base welded to the world, joints J in order from the base, each
//     joint's child the next link) put at rest at the pose Q and held there by one
//     effort_controllers/JointPositionController per joint with gains P, I, D (control_toolbox's
//     Pid, each step, as gazebo_ros_control runs them at the physics rate) for S s. Prints CSV
//     command,position,droop per joint: the mean position over the last 0.5 s, and the droop
//     the P terms leave, the pose where each joint's P term holds gravity's torque on the arm
//     beyond it (the integral terms take the droop away over time, the D terms none of it).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <onedof_sim/world.h>

#include "pid.h"
#include "tool_options.h"

namespace {

// Options, UsageError, readFile, check, addGround.
using namespace onedof_sim::tools;

constexpr const char* kBase = "base";

const char* const kUsage =
    "usage: engine_checks drive --physics NAME --ground F --urdf F --left J --right J "
    "--radius R --separation S --torque T --linear V --angular W --seconds S\n"
    "       engine_checks hold --physics NAME --ground F --mass M\n"
    "       engine_checks scan --physics NAME --ground F --urdf F --lidar-x X --lidar-z Z "
    "--pen-half H --samples N\n"
    "       engine_checks arm --physics NAME --ground F --urdf F --joints J,... --pose Q,... "
    "--p P,... --i I,... --d D,... --seconds S";

double yawOf(const onedof_sim::Quat& q) {
  return std::atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z));
}

onedof_sim::Pose basePose(const onedof_sim::World& world) {
  onedof_sim::Pose pose;
  onedof_sim::Twist twist;
  check(world.modelState(kBase, "", &pose, &twist), "the base's state");
  return pose;
}

void spawnBase(onedof_sim::World& world, const Options& options) {
  check(world.spawn(kBase, readFile(options.text("urdf")), onedof_sim::ModelFormat::Urdf,
                    onedof_sim::Pose()),
        "spawn the base");
}

int drive(const Options& options) {
  onedof_sim::World world(options.text("physics"));
  addGround(world, options);
  spawnBase(world, options);
  const double radius = options.number("radius"), separation = options.number("separation");
  const double torque = options.number("torque");
  const double linear = options.number("linear"), angular = options.number("angular");
  const double left = (linear - angular * separation / 2) / radius;
  const double right = (linear + angular * separation / 2) / radius;
  auto run = [&](double seconds) {
    const int64_t until = world.timeNs() + std::llround(seconds * 1e9);
    while (world.timeNs() < until) {
      check(world.setJointVelocityCommand(options.text("left"), left, torque), "left wheel");
      check(world.setJointVelocityCommand(options.text("right"), right, torque), "right wheel");
      check(world.step(), "step");
    }
  };
  run(1.0);
  // The path and the turn summed over 10 ms pieces: the base's mean speed along its path and
  // its mean turn rate, whatever its heading.
  const double seconds = options.number("seconds");
  const int pieces = static_cast<int>(std::lround(seconds / 0.01));
  if (pieces < 1) throw UsageError{"--seconds must be at least 0.01"};
  onedof_sim::Pose previous = basePose(world);
  double path = 0, turned = 0;
  for (int piece = 0; piece < pieces; ++piece) {
    run(seconds / pieces);
    const onedof_sim::Pose pose = basePose(world);
    const double dx = pose.position.x - previous.position.x;
    const double dy = pose.position.y - previous.position.y;
    const double heading = yawOf(previous.orientation);
    path += dx * std::cos(heading) + dy * std::sin(heading);
    turned += std::remainder(yawOf(pose.orientation) - heading, 2 * M_PI);
    previous = pose;
  }
  std::printf("linear,angular\n%.17g,%.17g\n", path / seconds, turned / seconds);
  return 0;
}

int hold(const Options& options) {
  const double mass = options.number("mass");
  std::ostringstream rig;
  rig << R"(<robot name="rig"><link name="world"/>
  <link name="frame"><inertial><mass value="1"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
  <joint name="frame_weld" type="fixed"><parent link="world"/><child link="frame"/>
    <origin xyz="0 0 1.5"/></joint>
  <link name="load"><inertial><mass value=")"
      << mass << R"("/>
    <inertia ixx="0.02" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.02"/></inertial></link>
  <joint name="sensor_joint" type="prismatic"><parent link="frame"/><child link="load"/>
    <origin xyz="0 0 -0.3"/><axis xyz="0 0 1"/>
    <limit lower="0" upper="0" effort="1000" velocity="0.01"/></joint></robot>)";
  onedof_sim::World world(options.text("physics"));
  addGround(world, options);
  check(world.spawn(kBase, rig.str(), onedof_sim::ModelFormat::Urdf, onedof_sim::Pose()),
        "spawn the rig");
  double sum = 0;
  int samples = 0;
  while (world.timeNs() < 1000000000) {
    check(world.step(), "step");
    if (world.timeNs() > 900000000) {
      onedof_sim::Wrench wrench;
      check(world.jointConstraintWrench("sensor_joint", &wrench), "the joint's wrench");
      sum += wrench.force.z;
      ++samples;
    }
  }
  std::printf("force_z\n%.17g\n", sum / samples);
  return 0;
}

// Four walls 0.1 m thick and 1.5 m high, their inner faces `half` from the origin.
std::string pen(double half) {
  std::ostringstream sdf;
  sdf << R"(<sdf version="1.6"><model name="pen"><static>true</static><link name="walls">)";
  const double middle = half + 0.05, length = 2 * half + 0.2;
  const struct {
    double x, y, size_x, size_y;
  } walls[] = {{middle, 0, 0.1, length}, {-middle, 0, 0.1, length},
               {0, middle, length, 0.1}, {0, -middle, length, 0.1}};
  int index = 0;
  for (const auto& wall : walls) {
    sdf << "<collision name=\"wall_" << index++ << "\"><pose>" << wall.x << " " << wall.y
        << " 0.75 0 0 0</pose><geometry><box><size>" << wall.size_x << " " << wall.size_y
        << " 1.5</size></box></geometry></collision>";
  }
  sdf << "</link></model></sdf>";
  return sdf.str();
}

int scan(const Options& options) {
  onedof_sim::World world(options.text("physics"));
  addGround(world, options);
  check(world.spawn("pen", pen(options.number("pen-half")), onedof_sim::ModelFormat::Sdf,
                    onedof_sim::Pose()),
        "spawn the pen");
  spawnBase(world, options);
  while (world.timeNs() < 500000000) check(world.step(), "step");
  const onedof_sim::Pose base = basePose(world);
  const double heading = yawOf(base.orientation);
  const double ahead = options.number("lidar-x");
  const double x = base.position.x + ahead * std::cos(heading);
  const double y = base.position.y + ahead * std::sin(heading);
  const int samples = static_cast<int>(options.number("samples"));
  if (samples < 2) throw UsageError{"--samples must be at least 2"};
  std::vector<onedof_sim::Ray> rays;
  std::vector<double> angles;
  for (int i = 0; i < samples; ++i) {
    const double angle = heading - M_PI / 2 + M_PI * i / (samples - 1);
    angles.push_back(angle);
    onedof_sim::Ray ray;
    ray.from = {x, y, base.position.z + options.number("lidar-z")};
    ray.direction = {std::cos(angle), std::sin(angle), 0};
    ray.length = 80;
    rays.push_back(ray);
  }
  std::vector<double> distances;
  check(world.castRays(rays, &distances), "cast the rays");
  std::printf("x,y,angle,distance\n");
  for (int i = 0; i < samples; ++i)
    std::printf("%.17g,%.17g,%.17g,%.17g\n", x, y, angles[i], distances[i]);
  return 0;
}

// The arm's joints in `joints`' order, and its links with mass in the chain's order (the base
// first: joint k's child is link k + 1).
struct ArmFrames {
  std::vector<onedof_sim::JointAxis> axes;
  std::vector<onedof_sim::LinkMass> masses;
};

ArmFrames armFrames(const onedof_sim::World& world, const std::vector<std::string>& joints) {
  ArmFrames arm;
  const auto axes = world.jointAxes();
  for (const std::string& joint : joints) {
    const auto found = std::find_if(axes.begin(), axes.end(), [&](const auto& axis) {
      return axis.model == kBase && axis.name == joint;
    });
    if (found == axes.end()) throw UsageError{"the arm has no joint " + joint};
    arm.axes.push_back(*found);
  }
  for (const auto& mass : world.linkMasses())
    if (mass.model == kBase) arm.masses.push_back(mass);
  if (arm.masses.size() != joints.size() + 1)
    throw UsageError{"the arm is a base and one link with mass per joint of --joints"};
  return arm;
}

// Gravity's torque about each joint's axis on the links beyond it, as the arm stands now.
std::vector<double> gravityTorques(const onedof_sim::World& world,
                                   const std::vector<std::string>& joints) {
  const ArmFrames arm = armFrames(world, joints);
  const onedof_sim::Vec3 g = world.params().gravity;
  std::vector<double> torques;
  for (size_t joint = 0; joint < joints.size(); ++joint) {
    const onedof_sim::Vec3& anchor = arm.axes[joint].anchor;
    const onedof_sim::Vec3& axis = arm.axes[joint].axis;
    double torque = 0;
    for (size_t link = joint + 1; link < arm.masses.size(); ++link) {
      const double m = arm.masses[link].mass;
      const onedof_sim::Vec3& com = arm.masses[link].inertial.position;
      const onedof_sim::Vec3 r{com.x - anchor.x, com.y - anchor.y, com.z - anchor.z};
      const onedof_sim::Vec3 f{m * g.x, m * g.y, m * g.z};
      const onedof_sim::Vec3 moment{r.y * f.z - r.z * f.y, r.z * f.x - r.x * f.z,
                                    r.x * f.y - r.y * f.x};
      torque += moment.x * axis.x + moment.y * axis.y + moment.z * axis.z;
    }
    torques.push_back(torque);
  }
  return torques;
}

// Where the P terms hold the arm: q = command + torque(q) / p for every joint, found by
// iterating from the command (the arm's own kinematics, through the world, at each try). P terms
// too weak for the arm's weight at the pose leave no such pose near it: the iteration wanders.
std::vector<double> droops(onedof_sim::World& world, const std::vector<std::string>& joints,
                           const std::vector<double>& command, const std::vector<double>& p) {
  std::vector<double> q = command;
  double change = 0;
  for (int iteration = 0; iteration < 200; ++iteration) {
    check(world.setModelConfiguration(kBase, joints, q), "pose the arm at its droop");
    const std::vector<double> torques = gravityTorques(world, joints);
    change = 0;
    for (size_t j = 0; j < joints.size(); ++j) {
      const double next = command[j] + torques[j] / p[j];
      change = std::max(change, std::abs(next - q[j]));
      q[j] = next;
    }
    if (change < 1e-12) break;
  }
  if (!(change < 1e-12))
    throw std::runtime_error("the P terms hold the arm at no pose near the command (--p too weak)");
  std::vector<double> out;
  for (size_t j = 0; j < joints.size(); ++j) out.push_back(q[j] - command[j]);
  return out;
}

int arm(const Options& options) {
  onedof_sim::World world(options.text("physics"));
  addGround(world, options);
  spawnBase(world, options);
  const std::vector<std::string> joints = options.texts("joints");
  const std::vector<double> command = options.numbers("pose");
  const std::vector<double> p = options.numbers("p"), i = options.numbers("i"),
                            d = options.numbers("d");
  for (const auto* list : {&command, &p, &i, &d})
    if (list->size() != joints.size())
      throw UsageError{"--pose, --p, --i and --d want one number per joint of --joints"};
  for (const double gain : p)
    if (gain <= 0) throw UsageError{"--p wants gains > 0"};
  const std::vector<double> droop = droops(world, joints, command, p);
  check(world.setModelConfiguration(kBase, joints, command), "pose the arm");
  std::vector<onedof_sim::control::Pid> pids;
  for (size_t j = 0; j < joints.size(); ++j) {
    onedof_sim::control::PidGains gains;
    gains.p = p[j];
    gains.i = i[j];
    gains.d = d[j];
    pids.emplace_back(gains);
  }
  const double dt = world.params().step;
  const int64_t end = std::llround(options.number("seconds") * 1e9);
  const int64_t mean_from = end - 500000000;
  // The joints' positions as the last step left them: the controllers' input for the next.
  std::vector<double> positions(joints.size());
  const auto read = [&] {
    for (size_t j = 0; j < joints.size(); ++j) {
      onedof_sim::JointInfo info;
      check(world.jointInfo(joints[j], &info), "read " + joints[j]);
      positions[j] = info.position;
    }
  };
  read();
  std::vector<double> sum(joints.size(), 0.0);
  int samples = 0;
  while (world.timeNs() < end) {
    for (size_t j = 0; j < joints.size(); ++j)
      check(world.setJointEffortCommand(
                joints[j], pids[j].computeCommand(command[j] - positions[j], dt)),
            "command " + joints[j]);
    check(world.step(), "step");
    read();
    if (world.timeNs() > mean_from) {
      for (size_t j = 0; j < joints.size(); ++j) sum[j] += positions[j];
      ++samples;
    }
  }
  if (samples == 0) throw UsageError{"--seconds must be more than 0.5"};
  std::printf("command,position,droop\n");
  for (size_t j = 0; j < joints.size(); ++j)
    std::printf("%.17g,%.17g,%.17g\n", command[j], sum[j] / samples, droop[j]);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return onedof_sim::tools::runMode(
      argc, argv, "engine_checks", kUsage,
      {{"arm", arm}, {"drive", drive}, {"hold", hold}, {"scan", scan}});
}
