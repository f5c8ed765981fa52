// libgazebo_ros_joint_state_publisher.so (gazebo_plugins' GazeboRosJointStatePublisher):
// sensor_msgs/JointState of the joints in <jointName> (a comma-separated list, spaces ignored) on
// joint_states in the plugin's namespace, at <updateRate> (default 100 Hz) of sim time, stamped
// in sim time: names, positions and velocities, as Gazebo fills them.
#include <algorithm>
#include <cctype>
#include <sstream>

#include <ros/console.h>
#include <sensor_msgs/JointState.h>

#include "model_plugin.h"
#include "plugin_params.h"
#include "sensors/update_gate.h"

namespace onedof_sim::plugins {
namespace {

std::vector<std::string> jointNames(std::string list) {
  list.erase(std::remove_if(list.begin(), list.end(), [](unsigned char c) { return std::isspace(c); }),
             list.end());
  std::vector<std::string> names;
  std::stringstream in(list);
  std::string name;
  while (std::getline(in, name, ','))
    if (!name.empty()) names.push_back(name);
  return names;
}

class GazeboRosJointStatePublisher : public ModelPlugin {
 public:
  GazeboRosJointStatePublisher(const ModelPluginContext& context, std::vector<std::string> joints,
                               double update_rate)
      : model_(context.model), joints_(std::move(joints)), node_(context.node) {
    {
      std::unique_lock<std::mutex> lock = context.lock_world();
      update_gate_ = UpdateGate(update_rate, context.world->timeNs());
    }
    publisher_ = node_.advertise<sensor_msgs::JointState>("joint_states", 1000);
    ROS_INFO_STREAM("gazebo_ros_joint_state_publisher (" << model_ << "): " << joints_.size()
                    << " joint(s) on " << publisher_.getTopic() << " at " << update_rate
                    << " Hz");
  }

  // At the start of the step, as Gazebo's OnUpdate (ConnectWorldUpdateBegin).
  void beforeStep(World& world, const StepTime& at) override {
    if (!update_gate_.due(at.time_ns)) return;
    sensor_msgs::JointState state;
    state.header.stamp.fromNSec(static_cast<uint64_t>(at.time_ns));
    for (const std::string& joint : joints_) {
      JointInfo info;
      if (!world.jointInfo(model_ + "::" + joint, &info).ok()) continue;
      state.name.push_back(info.name);
      state.position.push_back(info.position);
      state.velocity.push_back(info.rate);
    }
    publications_.add(publisher_, state);
  }

  std::vector<Publication> takePublications() override { return publications_.take(); }

 private:
  std::string model_;
  std::vector<std::string> joints_;
  ros::NodeHandle node_;
  ros::Publisher publisher_;
  UpdateGate update_gate_;
  PublicationQueue publications_;
};

}  // namespace

std::unique_ptr<ModelPlugin> makeGazeboRosJointStatePublisher(const ModelPluginContext& context,
                                                              std::string* error) {
  const PluginParams params(context.plugin_xml,
                            "gazebo_ros_joint_state_publisher (" + context.model + ")");
  if (!params.has("jointName")) {
    *error = "missing <jointName>";
    return nullptr;
  }
  const std::vector<std::string> joints = jointNames(params.text("jointName", ""));
  if (!params.has("updateRate"))
    ROS_WARN_STREAM(params.label() << ": missing <updateRate>, defaults to 100");
  double update_rate = 100;
  if (!params.number("updateRate", 100, &update_rate, error)) return nullptr;
  {
    std::unique_lock<std::mutex> lock = context.lock_world();
    for (const std::string& joint : joints) {
      JointInfo info;
      if (!context.world->jointInfo(context.model + "::" + joint, &info).ok()) {
        *error = "joint " + joint + " does not exist";
        return nullptr;
      }
    }
  }
  return std::make_unique<GazeboRosJointStatePublisher>(context, joints, update_rate);
}

}  // namespace onedof_sim::plugins
