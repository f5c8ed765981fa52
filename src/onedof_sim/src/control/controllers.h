// ros_controllers' joint controllers (Noetic), run inside the step loop: the laws, their
// configuration as ros_controllers reads it, and their publishing cadence. Free of ROS: the
// ROS layer (controller_manager.h) feeds commands in through setCommand and turns the facts
// they hand out (JointControllerStateFacts, JointStatesFacts) into messages.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "param_source.h"
#include "pid.h"
#include "robot_hw_sim.h"

namespace onedof_sim::control {

// control_msgs/JointControllerState's content.
struct JointControllerStateFacts {
  int64_t stamp_ns = 0;
  double set_point = 0, process_value = 0, process_value_dot = 0, error = 0, time_step = 0,
         command = 0;
  PidGains gains;
};

// sensor_msgs/JointState's content.
struct JointStatesFacts {
  int64_t stamp_ns = 0;
  std::vector<std::string> names;
  std::vector<double> position, velocity, effort;
};

// A hardware interface and the joints a controller claims through it (controller_manager's
// claimed_resources).
struct ClaimedResources {
  std::string hardware_interface;
  std::vector<std::string> resources;
};

class Controller {
 public:
  virtual ~Controller() = default;
  virtual void starting(int64_t /*time_ns*/) {}
  virtual void update(int64_t time_ns, int64_t period_ns) = 0;
  virtual void stopping(int64_t /*time_ns*/) {}
  virtual ClaimedResources claims() const = 0;
  // The `command` topic's value (std_msgs/Float64); controllers without one ignore it. Called
  // from the ROS spinner while the step loop runs: the latest value is read at the next update.
  virtual bool takesCommand() const { return false; }
  void setCommand(double value) { command_.store(value); }

  // Where the controller hands out what it publishes (set by the owner; unset: nothing).
  std::function<void(const JointControllerStateFacts&)> publish_state;
  std::function<void(const JointStatesFacts&)> publish_joint_states;

 protected:
  std::atomic<double> command_{0.0};
};

// The controller types, by their pluginlib names; each builds itself from the parameters under
// `ns` (the controller's namespace, "/one_DOF_robot/joint1_position_controller") on the robot's
// joints, or refuses with *error saying what is wrong.
struct ControllerType {
  std::string name;        // "effort_controllers/JointPositionController"
  std::string base_class;  // controller_manager's list_controller_types base_classes
  std::function<std::unique_ptr<Controller>(RobotHwSim&, const ParamSource&, const std::string&,
                                            std::string*)>
      make;
};

// The built-in types (ros_controllers' that the simulator runs).
const std::vector<ControllerType>& controllerTypes();
// The type of that name among `types`; null if none.
const ControllerType* findControllerType(const std::string& name,
                                         const std::vector<ControllerType>& types =
                                             controllerTypes());

// ros_controllers' error of a position command: the shortest angular distance for continuous
// joints and, within the limits, for revolute ones (angles::shortest_angular_distance_with_large_
// limits); the plain difference for prismatic joints.
double positionError(const JointStateHandle& joint, double command);

}  // namespace onedof_sim::control
