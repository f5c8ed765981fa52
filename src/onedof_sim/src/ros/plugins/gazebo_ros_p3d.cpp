// libgazebo_ros_p3d.so (gazebo_plugins' GazeboRosP3D): a link's ground truth as nav_msgs/Odometry
// on <topicName>: its pose and twist in <frameName> ("world" or "map", the default "world", or
// another link of the model), moved by <xyzOffset> and turned by <rpyOffset>, the twist with
// Gaussian noise of <gaussianNoise> (standard deviation), at <updateRate> of sim time (0: every
// step), stamped in sim time, while anyone subscribes. Relative to a link, pose and twist are as
// get_link_state gives them in that link's frame.
//
// Where it differs from Gazebo: the noise comes from a generator seeded with the plugin's name
// (pluginSeed; Gazebo's seeds it at random), so that two runs in lock-step publish the same
// numbers.
#include <nav_msgs/Odometry.h>
#include <onedof_sim/pose_math.h>
#include <ros/console.h>

#include "conversions.h"
#include "model_plugin.h"
#include "plugin_params.h"
#include "sensors/sensor_noise.h"
#include "sensors/update_gate.h"

namespace onedof_sim::plugins {
namespace {

struct P3dParams {
  std::string body;              // <bodyName>, a link of the model
  std::string topic;             // <topicName>
  std::string frame = "world";   // <frameName>
  std::string reference;         // the World's reference frame: "" or "model::link"
  Vec3 xyz_offset;
  Quat rpy_offset;
  double gaussian_noise = 0;
  double update_rate = 0;
};

class GazeboRosP3d : public ModelPlugin {
 public:
  GazeboRosP3d(const ModelPluginContext& context, const P3dParams& params)
      : model_(context.model),
        params_(params),
        node_(context.node),
        random_(pluginSeed(context)),
        noise_(whiteNoise(params.gaussian_noise), random_) {
    frame_id_ = resolveTfFrame(tfPrefix(node_), params_.frame);
    {
      std::unique_lock<std::mutex> lock = context.lock_world();
      update_gate_ = UpdateGate(params_.update_rate, context.world->timeNs());
    }
    publisher_ = node_.advertise<nav_msgs::Odometry>(params_.topic, 1);
  }

  void beforeStep(World& world, const StepTime& at) override {
    if (!update_gate_.due(at.time_ns) || publisher_.getNumSubscribers() == 0) return;
    Pose pose;
    Twist twist;
    if (!world.linkState(model_ + "::" + params_.body, params_.reference, &pose, &twist).ok())
      return;
    pose.position = {pose.position.x + params_.xyz_offset.x, pose.position.y + params_.xyz_offset.y,
                     pose.position.z + params_.xyz_offset.z};
    pose.orientation = multiply(params_.rpy_offset, pose.orientation);
    nav_msgs::Odometry msg;
    msg.header.stamp.fromNSec(static_cast<uint64_t>(at.time_ns));
    msg.header.frame_id = frame_id_;
    msg.child_frame_id = params_.body;
    msg.pose.pose = toMsg(pose);
    const double sigma = params_.gaussian_noise;
    msg.twist.twist.linear.x = noise_.apply(twist.linear.x, random_);
    msg.twist.twist.linear.y = noise_.apply(twist.linear.y, random_);
    msg.twist.twist.linear.z = noise_.apply(twist.linear.z, random_);
    msg.twist.twist.angular.x = noise_.apply(twist.angular.x, random_);
    msg.twist.twist.angular.y = noise_.apply(twist.angular.y, random_);
    msg.twist.twist.angular.z = noise_.apply(twist.angular.z, random_);
    for (int i : {0, 7, 14, 21, 28, 35})
      msg.pose.covariance[i] = msg.twist.covariance[i] = sigma * sigma;
    publications_.add(publisher_, msg);
  }

  std::vector<Publication> takePublications() override { return publications_.take(); }

 private:
  std::string model_;
  P3dParams params_;
  ros::NodeHandle node_;
  std::string frame_id_;
  ros::Publisher publisher_;
  UpdateGate update_gate_;
  NoiseRandom random_;
  NoiseModel noise_;  // <gaussianNoise>
  PublicationQueue publications_;
};

}  // namespace

std::unique_ptr<ModelPlugin> makeGazeboRosP3d(const ModelPluginContext& context,
                                              std::string* error) {
  const PluginParams params(context.plugin_xml, "gazebo_ros_p3d (" + context.model + ")");
  P3dParams p;
  if (!params.has("bodyName")) {
    *error = "missing <bodyName>";
    return nullptr;
  }
  if (!params.has("topicName")) {
    *error = "missing <topicName>";
    return nullptr;
  }
  p.body = params.text("bodyName", "");
  p.topic = params.text("topicName", "");
  p.frame = params.text("frameName", p.frame);
  Vec3 rpy;
  if (!params.vector("xyzOffset", &p.xyz_offset, error) ||
      !params.vector("rpyOffset", &rpy, error) ||
      !params.number("gaussianNoise", 0, &p.gaussian_noise, error) ||
      !params.number("updateRate", 0, &p.update_rate, error))
    return nullptr;
  if (p.gaussian_noise < 0) {
    *error = "<gaussianNoise> is negative";
    return nullptr;
  }
  p.rpy_offset = fromRpy(rpy);
  const bool world_frame =
      p.frame == "world" || p.frame == "/world" || p.frame == "map" || p.frame == "/map";
  if (!world_frame) p.reference = context.model + "::" + p.frame;
  {
    std::unique_lock<std::mutex> lock = context.lock_world();
    LinkInfo info;
    if (!context.world->linkProperties(context.model + "::" + p.body, &info).ok()) {
      *error = "bodyName: " + p.body + " does not exist";
      return nullptr;
    }
    if (!world_frame && !context.world->linkProperties(p.reference, &info).ok()) {
      *error = "frameName: " + p.frame + " does not exist";
      return nullptr;
    }
  }
  return std::make_unique<GazeboRosP3d>(context, p);
}

}  // namespace onedof_sim::plugins
