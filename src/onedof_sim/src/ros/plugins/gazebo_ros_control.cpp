// libgazebo_ros_control.so (gazebo_ros_control's model plugin, Noetic): ros_control inside the
// simulator for a URDF with <transmission>s. The robot's transmission joints (RobotHwSim) and its
// controller_manager in <robotNamespace> (default: the model's name), updated before the step
// whenever <controlPeriod> (default: the physics step) is due. Its controllers never wait for
// anyone: lock-step waits only for apply_joint_effort's clients.
#include <algorithm>
#include <cmath>
#include <map>
#include <mutex>

#include <ros/console.h>

#include "control/controller_manager.h"
#include "model_plugin.h"
#include "robot_hw_sim.h"

namespace onedof_sim::plugins {
namespace {

// One controller_manager per namespace: which model holds each (their services would collide).
class NamespaceOwners {
 public:
  // False, with the model that holds it, if `robot_namespace` is taken.
  bool claim(const std::string& robot_namespace, const std::string& model, std::string* holder) {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto [found, inserted] = owners_.emplace(robot_namespace, model);
    *holder = found->second;
    return inserted;
  }
  void release(const std::string& robot_namespace) {
    std::lock_guard<std::mutex> lock(mutex_);
    owners_.erase(robot_namespace);
  }

 private:
  std::mutex mutex_;
  std::map<std::string, std::string> owners_;
};

NamespaceOwners& namespaceOwners() {
  static NamespaceOwners owners;
  return owners;
}

// The robot's joints, read under the world lock.
control::RobotHwSim lockedRobot(const ModelPluginContext& context, control::RobotControlSpec* spec) {
  std::unique_lock<std::mutex> lock = context.lock_world();
  return control::RobotHwSim(*context.world, context.model, *spec, &spec->warnings);
}

class GazeboRosControl : public ModelPlugin {
 public:
  // Unlocked: it takes the world lock for the joints' first reading, and advertises the
  // controller_manager's services.
  GazeboRosControl(const ModelPluginContext& context, const control::RobotControlSpec& spec)
      : spec_(spec),
        robot_(lockedRobot(context, &spec_)),
        manager_(spec_.robot_namespace, robot_, context.lock_world) {
    for (const std::string& warning : spec_.warnings)
      ROS_WARN_STREAM("gazebo_ros_control (" << context.model << "): " << warning);
    ROS_INFO_STREAM("gazebo_ros_control: model '" << context.model << "', controller_manager in "
                    << spec_.robot_namespace << ", " << robot_.jointStates().size()
                    << " transmission joint(s)");
  }
  ~GazeboRosControl() override {
    stopped_.clear();
    namespaceOwners().release(spec_.robot_namespace);
  }

  // The controllers' update when a control period is due (read the joints, controller_manager's
  // update), then their efforts for this step.
  void beforeStep(World& world, const StepTime& at) override {
    const double period_s = spec_.control_period.value_or(world.params().step);
    // Never shorter than the physics step, as gazebo_ros_control makes it.
    const int64_t period_ns = std::max<int64_t>(std::llround(period_s * 1e9),
                                                std::llround(world.params().step * 1e9));
    const int64_t elapsed_ns = at.time_ns - last_update_ns_;
    if (elapsed_ns >= period_ns || reset_controllers_) {
      robot_.read(world);
      robot_.clearCommands();
      manager_.update(at.time_ns, elapsed_ns, reset_controllers_);
      reset_controllers_ = false;
      last_update_ns_ = at.time_ns;
    }
    robot_.write(world);
  }

  // The running controllers restart at the next update (gazebo_ros_control's Reset).
  void reset(World&) override {
    last_update_ns_ = 0;
    reset_controllers_ = true;
  }

  void stop(World& world) override { stopped_ = manager_.unloadAll(world.timeNs()); }
  std::vector<Publication> takePublications() override { return manager_.takePublications(); }

 private:
  control::RobotControlSpec spec_;
  control::RobotHwSim robot_;
  control::ControllerManager manager_;
  int64_t last_update_ns_ = 0;
  bool reset_controllers_ = false;
  std::vector<std::shared_ptr<void>> stopped_;  // the stopped controllers' parts, freed unlocked
};

}  // namespace

std::unique_ptr<ModelPlugin> makeGazeboRosControl(const ModelPluginContext& context,
                                                  std::string* error) {
  if (context.format != ModelFormat::Urdf) {
    *error = "it reads the robot's <transmission>s from a URDF, and this model is SDF";
    return nullptr;
  }
  control::RobotControlSpec spec;
  if (!control::readRobotControlSpec(context.model_xml, context.model, &spec, error) ||
      !error->empty())
    return nullptr;
  std::string holder;
  if (!namespaceOwners().claim(spec.robot_namespace, context.model, &holder)) {
    *error = "model '" + holder + "' already has the controller_manager in " +
             spec.robot_namespace + "; give this one its own <robotNamespace>";
    return nullptr;
  }
  return std::make_unique<GazeboRosControl>(context, spec);
}

}  // namespace onedof_sim::plugins
