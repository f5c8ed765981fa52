// The joints as controllers see them, after hardware_interface: a JointStateHandle reads a joint,
// an EffortJointHandle reads it and commands its effort. The state behind them (SimJoint) is
// RobotHwSim's: it reads the world into it before the controllers run and writes the commanded
// efforts into the world after.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <onedof_sim/world.h>

namespace onedof_sim::control {

// hardware_interface's joint interfaces, as a <transmission>'s <hardwareInterface> names them.
enum class JointInterface { Effort, Position, Velocity };

// One transmission joint: what the world said at the last read, and this control period's
// effort command.
struct SimJoint {
  std::string name;         // bare, as controllers name it
  std::string world_name;   // "model::joint", unambiguous in the world
  std::vector<JointInterface> interfaces;
  JointType type = JointType::Revolute;
  bool has_limits = false;
  double lower = 0, upper = 0;
  double position = 0, velocity = 0;
  double effort = 0;  // what acted in the last step (JointState's effort)
  std::optional<double> effort_command;  // this control period's; none: no effort
};

// Reads one joint; valid as long as the RobotHwSim it came from.
class JointStateHandle {
 public:
  explicit JointStateHandle(const SimJoint& joint) : joint_(&joint) {}

  const std::string& name() const { return joint_->name; }
  JointType type() const { return joint_->type; }
  bool hasLimits() const { return joint_->has_limits; }
  double lower() const { return joint_->lower; }
  double upper() const { return joint_->upper; }
  double position() const { return joint_->position; }
  double velocity() const { return joint_->velocity; }
  double effort() const { return joint_->effort; }

 private:
  const SimJoint* joint_;
};

// Reads one joint and commands the effort it gets in the coming steps of this control period.
class EffortJointHandle : public JointStateHandle {
 public:
  explicit EffortJointHandle(SimJoint& joint) : JointStateHandle(joint), joint_(&joint) {}

  void setCommand(double effort) { joint_->effort_command = effort; }

 private:
  SimJoint* joint_;
};

}  // namespace onedof_sim::control
