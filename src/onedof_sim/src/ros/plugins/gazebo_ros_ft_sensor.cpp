// libgazebo_ros_ft_sensor.so (gazebo_plugins' GazeboRosFT): the wrench a joint transmits as
// geometry_msgs/WrenchStamped on <topicName>, at <updateRate> of sim time (0: every step),
// stamped in sim time, while anyone subscribes, with Gaussian noise of <gaussianNoise> (standard
// deviation) on each component.
//
// As Gazebo's joint GetForceTorque gives it to that plugin: the wrench the child link puts on the
// parent side through the joint (the negative of what the joint's constraint puts on the child),
// in the child link's axes, the torque about the joint's origin; frame_id is the child link's
// name under tf_prefix. A load hanging from the sensor reads its weight downward in the child's
// axes (force.z = -m g for an unturned child).
//
// Where it differs (said once in the log): the wrench is the joint's constraint alone, stops and
// friction included; Gazebo's also takes in the effort commanded on the joint itself. A fixed
// joint cannot carry the sensor: its links are one rigid body here, and Gazebo's URDF loading
// lumps it away too (the plugin then finds no such joint); the book's own xacro makes it a
// prismatic joint with both limits at 0 for that reason, which works here. The noise comes from
// a generator seeded with the plugin's name (pluginSeed), so that two runs publish the same
// numbers.
#include <geometry_msgs/WrenchStamped.h>
#include <onedof_sim/pose_math.h>
#include <ros/console.h>

#include "model_plugin.h"
#include "plugin_params.h"
#include "sensors/sensor_noise.h"
#include "sensors/update_gate.h"

namespace onedof_sim::plugins {
namespace {

struct FtParams {
  std::string joint;  // scoped "model::joint"
  std::string child;  // scoped "model::link"
  std::string topic;
  double gaussian_noise = 0;
  double update_rate = 0;
};

class GazeboRosFt : public ModelPlugin {
 public:
  GazeboRosFt(const ModelPluginContext& context, const FtParams& params, const std::string& frame)
      : params_(params),
        node_(context.node),
        random_(pluginSeed(context)),
        noise_(whiteNoise(params.gaussian_noise), random_) {
    frame_id_ = resolveTfFrame(tfPrefix(node_), frame);
    {
      std::unique_lock<std::mutex> lock = context.lock_world();
      update_gate_ = UpdateGate(params_.update_rate, context.world->timeNs());
    }
    // A queue of a second's worth at 100 Hz: stepped flat out (step_simulation), a queue of 1
    // (Gazebo's) drops most messages before they are written out.
    publisher_ = node_.advertise<geometry_msgs::WrenchStamped>(params_.topic, 100);
  }

  void afterStep(World& world, const StepTime& at) override {
    if (!update_gate_.due(at.time_ns) || publisher_.getNumSubscribers() == 0) return;
    Wrench on_child;
    Pose child;
    Twist twist;
    if (!world.jointConstraintWrench(params_.joint, &on_child).ok() ||
        !world.linkState(params_.child, "", &child, &twist).ok())
      return;
    const Vec3 force = inFrame(child.orientation, {-on_child.force.x, -on_child.force.y,
                                                   -on_child.force.z});
    const Vec3 torque = inFrame(child.orientation, {-on_child.torque.x, -on_child.torque.y,
                                                    -on_child.torque.z});
    geometry_msgs::WrenchStamped msg;
    msg.header.stamp.fromNSec(static_cast<uint64_t>(at.time_ns));
    msg.header.frame_id = frame_id_;
    msg.wrench.force.x = noise_.apply(force.x, random_);
    msg.wrench.force.y = noise_.apply(force.y, random_);
    msg.wrench.force.z = noise_.apply(force.z, random_);
    msg.wrench.torque.x = noise_.apply(torque.x, random_);
    msg.wrench.torque.y = noise_.apply(torque.y, random_);
    msg.wrench.torque.z = noise_.apply(torque.z, random_);
    publications_.add(publisher_, msg);
  }

  void reset(World& world) override { update_gate_.restart(world.timeNs()); }

  std::vector<Publication> takePublications() override { return publications_.take(); }

 private:
  FtParams params_;
  ros::NodeHandle node_;
  std::string frame_id_;
  ros::Publisher publisher_;
  UpdateGate update_gate_;
  NoiseRandom random_;
  NoiseModel noise_;  // <gaussianNoise>
  PublicationQueue publications_;
};

}  // namespace

std::unique_ptr<ModelPlugin> makeGazeboRosFtSensor(const ModelPluginContext& context,
                                                   std::string* error) {
  const PluginParams params(context.plugin_xml, "gazebo_ros_ft_sensor (" + context.model + ")");
  FtParams p;
  if (!params.has("jointName")) {
    *error = "missing <jointName>";
    return nullptr;
  }
  if (!params.has("topicName")) {
    *error = "missing <topicName>";
    return nullptr;
  }
  const std::string joint = params.text("jointName", "");
  p.topic = params.text("topicName", "");
  if (!params.number("gaussianNoise", 0, &p.gaussian_noise, error) ||
      !params.number("updateRate", 0, &p.update_rate, error))
    return nullptr;
  if (p.gaussian_noise < 0) {
    *error = "<gaussianNoise> is negative";
    return nullptr;
  }
  std::string parent, child;
  if (!jointLinks(context, joint, &parent, &child)) {
    *error = "jointName: " + joint + " does not exist";
    return nullptr;
  }
  p.joint = context.model + "::" + joint;
  p.child = context.model + "::" + child;
  {
    std::unique_lock<std::mutex> lock = context.lock_world();
    Wrench wrench;
    const Status status = context.world->jointConstraintWrench(p.joint, &wrench);
    if (status.code == StatusCode::JointIsFixed) {
      *error = "jointName: " + joint +
               " is a fixed joint: its links are one rigid body here, with nothing between them "
               "to measure (Gazebo's URDF loading lumps a fixed joint away too); make it a "
               "prismatic joint with lower and upper limits 0";
      return nullptr;
    }
    if (!status.ok()) {
      *error = "jointName: " + joint + " does not exist";
      return nullptr;
    }
  }
  static bool told = false;
  if (!told) {
    told = true;
    ROS_INFO_STREAM("gazebo_ros_ft_sensor: the wrench is the joint's constraint alone (stops and "
                    "friction included); Gazebo's plugin also takes in the effort commanded on "
                    "the joint");
  }
  ROS_INFO_STREAM(params.label() << ": reporting the wrench of joint " << joint
                                 << " in frame [" << child << "] on " << p.topic);
  return std::make_unique<GazeboRosFt>(context, p, child);
}

}  // namespace onedof_sim::plugins
