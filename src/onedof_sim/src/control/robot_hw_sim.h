// gazebo_ros_control's side of the model (Noetic, DefaultRobotHWSim): what the URDF's
// <gazebo><plugin filename="libgazebo_ros_control.so"> and <transmission>s say, and the joints
// it offers controllers (joint_handles.h) over the World. Free of ROS.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <onedof_sim/world.h>

#include "joint_handles.h"

namespace onedof_sim::control {

// "hardware_interface::EffortJointInterface", as controller_manager reports a claim.
std::string interfaceTypeName(JointInterface interface);

struct TransmissionJoint {
  std::string transmission;  // the <transmission name>
  std::string joint;         // bare
  std::vector<JointInterface> interfaces;
  // Read for the record: DefaultRobotHWSim commands the joint itself and ignores it, so do we.
  double mechanical_reduction = 1;
};

// The plugin tag's settings and the robot's transmissions.
struct RobotControlSpec {
  std::string robot_namespace;  // "/one_DOF_robot"; the model name when the tag has none
  std::optional<double> control_period;  // s; the physics step when absent
  std::vector<TransmissionJoint> joints;
  std::vector<std::string> warnings;  // transmissions left out, and why (gazebo_ros_control's)
};

// Whether the URDF carries the gazebo_ros_control plugin, and what it says. False for no tag (or
// no URDF: an SDF model has no transmissions); *error is set when the tag or a transmission is
// malformed (then the spec is unusable).
bool readRobotControlSpec(const std::string& urdf, const std::string& model_name,
                          RobotControlSpec* spec, std::string* error);

// The transmission joints of one model over the World (the RobotHW of gazebo_ros_control).
class RobotHwSim {
 public:
  // Joints of the transmissions that the world has (as movable joints): the others are left out
  // with a warning in *warnings, as DefaultRobotHWSim skips them.
  RobotHwSim(const World& world, const std::string& model, const RobotControlSpec& spec,
             std::vector<std::string>* warnings);

  // The handles point into this object: it is neither copied nor moved.
  RobotHwSim(const RobotHwSim&) = delete;
  RobotHwSim& operator=(const RobotHwSim&) = delete;

  // hardware_interface's JointStateInterface: every joint, read-only, in transmission order.
  std::vector<JointStateHandle> jointStates() const;
  std::optional<JointStateHandle> jointState(const std::string& name) const;
  // EffortJointInterface: the joint, when its transmission offers that interface.
  std::optional<EffortJointHandle> effortJoint(const std::string& name);

  // readSim: positions and rates from the world. Commands of the last period are dropped: a
  // controller that is not running commands nothing.
  void read(const World& world);
  void clearCommands();
  // writeSim: every commanded effort acts in the coming step.
  void write(World& world);

 private:
  std::vector<SimJoint> joints_;
};

}  // namespace onedof_sim::control
