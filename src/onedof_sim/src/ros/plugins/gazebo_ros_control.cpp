// libgazebo_ros_control.so: ros_control inside the simulator for a URDF with <transmission>s
// (control::GazeboRosControl: the robot's joints and its controller_manager in <robotNamespace>,
// default the model's name), updated before the step whenever its controlPeriod is due. Its
// controllers never wait for anyone: lock-step waits only for apply_joint_effort's clients.
#include <map>
#include <mutex>

#include "../control/gazebo_ros_control.h"
#include "model_plugin.h"

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

class GazeboRosControlPlugin : public ModelPlugin {
 public:
  GazeboRosControlPlugin(const ModelPluginContext& context, const control::RobotControlSpec& spec)
      : robot_namespace_(spec.robot_namespace),
        control_(*context.world, context.model, spec, context.lock_world) {}
  ~GazeboRosControlPlugin() override {
    stopped_.clear();
    namespaceOwners().release(robot_namespace_);
  }

  void beforeStep(World& world, const StepTime&) override { control_.beforeStep(world); }
  void reset(World&) override { control_.reset(); }
  void stop(World& world) override { stopped_ = control_.stop(world.timeNs()); }
  std::vector<Publication> takePublications() override { return control_.takePublications(); }

 private:
  std::string robot_namespace_;
  control::GazeboRosControl control_;
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
  return std::make_unique<GazeboRosControlPlugin>(context, spec);
}

}  // namespace onedof_sim::plugins
