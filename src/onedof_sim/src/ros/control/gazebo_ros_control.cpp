#include "gazebo_ros_control.h"

#include <algorithm>
#include <cmath>

#include <ros/console.h>

namespace onedof_sim::control {

namespace {

void logWarnings(const RobotControlSpec& spec, const std::string& model) {
  for (const std::string& warning : spec.warnings)
    ROS_WARN_STREAM("gazebo_ros_control (" << model << "): " << warning);
}

RobotHwSim lockedRobot(const World& world, const std::string& model, RobotControlSpec* spec,
                       const LockWorld& lock_world) {
  std::unique_lock<std::mutex> lock = lock_world();
  return RobotHwSim(world, model, *spec, &spec->warnings);
}

}  // namespace

GazeboRosControl::GazeboRosControl(const World& world, const std::string& model,
                                   const RobotControlSpec& spec, LockWorld lock_world)
    : model_(model),
      spec_(spec),
      robot_(lockedRobot(world, model, &spec_, lock_world)),
      manager_(spec.robot_namespace, robot_, lock_world) {
  logWarnings(spec_, model);
  ROS_INFO_STREAM("gazebo_ros_control: model '" << model << "', controller_manager in "
                  << spec_.robot_namespace << ", " << robot_.jointStates().size()
                  << " transmission joint(s)");
}

void GazeboRosControl::beforeStep(World& world) {
  const int64_t now_ns = world.timeNs();
  const double period_s = spec_.control_period.value_or(world.params().step);
  // Never shorter than the physics step, as gazebo_ros_control makes it.
  const int64_t period_ns = std::max<int64_t>(std::llround(period_s * 1e9),
                                              std::llround(world.params().step * 1e9));
  const int64_t elapsed_ns = now_ns - last_update_ns_;
  if (elapsed_ns >= period_ns || reset_controllers_) {
    robot_.read(world);
    robot_.clearCommands();
    manager_.update(now_ns, elapsed_ns, reset_controllers_);
    reset_controllers_ = false;
    last_update_ns_ = now_ns;
  }
  robot_.write(world);
}

void GazeboRosControl::reset() {
  last_update_ns_ = 0;
  reset_controllers_ = true;
}

}  // namespace onedof_sim::control
