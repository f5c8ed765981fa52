// gazebo_ros_control's model plugin (Noetic), for a spawned URDF that carries it: the robot's
// transmission joints (RobotHwSim) and its controller_manager, run at every control period
// inside the step loop. A controller here never waits for anyone: lock-step (lockstep.h) waits
// only for apply_joint_effort's clients.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <onedof_sim/world.h>

#include "controller_manager.h"
#include "robot_hw_sim.h"

namespace onedof_sim::control {

class GazeboRosControl {
 public:
  // Call unlocked: it takes lock_world for the joints' first reading, and advertises the
  // controller_manager's services.
  GazeboRosControl(const World& world, const std::string& model, const RobotControlSpec& spec,
                   LockWorld lock_world);

  const std::string& robotNamespace() const { return spec_.robot_namespace; }

  // Before each world.step(), world locked: the controllers' update when a control period is
  // due (readSim, controller_manager update), then their efforts for this step (writeSim).
  void beforeStep(World& world);
  std::vector<Publication> takePublications() { return manager_.takePublications(); }

  // reset_world / reset_simulation: the running controllers restart at the next update.
  void reset();

  // Before deletion, world locked: stops the controllers; destroy it unlocked.
  std::vector<std::shared_ptr<void>> stop(int64_t time_ns) { return manager_.unloadAll(time_ns); }

 private:
  std::string model_;
  RobotControlSpec spec_;
  RobotHwSim robot_;
  ControllerManager manager_;
  int64_t last_update_ns_ = 0;
  bool reset_controllers_ = false;
};

}  // namespace onedof_sim::control
