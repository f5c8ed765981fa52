// libgazebo_ros_laser.so on a `ray` sensor and libgazebo_ros_gpu_laser.so on a `gpu_ray` sensor
// (gazebo_plugins' GazeboRosLaser and its GPU twin, which publish alike): the sensor's scans as
// sensor_msgs/LaserScan on <topicName> (default "/world"; empty: nothing published) in
// <frameName> (default "/world", under the tf_prefix, else the robot namespace), in the plugin's
// <robotNamespace>, stamped at the sim time of the step the scan was taken after, at the
// sensor's <update_rate>, while anyone subscribes (Gazebo's laser sensors measure only then).
// Ranges: see RayScanner; intensities all 0 (no collision sets a laser_retro here, Gazebo's
// default); time_increment and scan_time 0, as Gazebo sends them.
//
// The noise's generator is seeded with the sensor's scoped name, where Gazebo seeds it at random,
// so that two runs in lock-step publish the same scans.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <ros/console.h>
#include <sensor_msgs/LaserScan.h>

#include "model_plugin.h"
#include "plugin_params.h"
#include "sensor_plugin.h"
#include "sensors/ray_sensor.h"
#include "sensors/sensor_noise.h"

namespace onedof_sim::plugins {
namespace {

class GazeboRosLaser : public ModelPlugin {
 public:
  GazeboRosLaser(const SensorPluginContext& context, const RayConfig& config,
                 const std::string& robot_namespace, const std::string& topic,
                 const std::string& frame)
      : label_(context.plugin.filename + " of sensor '" + context.sensor.name + "' (model '" +
               context.plugin.model + "')"),
        scanner_(config, context.plugin.model + "::" + context.sensor.link, context.sensor.pose,
                 sensorSeed(context)),
        gate_(context.sensor.update_rate),
        node_(robot_namespace.empty() ? "/" : robot_namespace) {
    std::string prefix = tfPrefix(node_);
    if (prefix.empty()) {
      prefix = robot_namespace;
      while (!prefix.empty() && prefix.back() == '/') prefix.pop_back();
    }
    frame_id_ = resolveTfFrame(prefix, frame);
    if (!topic.empty()) publisher_ = node_.advertise<sensor_msgs::LaserScan>(topic, 1);
    if (config.noise.on)
      ROS_INFO_STREAM(label_ << ": its Gaussian noise is drawn from a generator seeded with the "
                      << "sensor's name (Gazebo seeds it at random), so runs repeat their scans");
  }

  void afterStep(World& /*world*/, const StepTime& at) override {
    if (!publisher_ || publisher_.getNumSubscribers() == 0 || !gate_.due(at.time_ns)) return;
    const int64_t time_ns = at.time_ns;
    publications_.addWork(measurementWork(&scanner_, label_, "scan", &failed_,
                                          [this, time_ns] { addScan(time_ns); }));
  }

  void reset(World& /*world*/) override { gate_.reset(); }

  std::vector<std::shared_ptr<SensorWork>> takeSensorWork() override {
    return publications_.takeWork();
  }
  std::vector<Publication> takePublications() override { return publications_.take(); }

 private:
  // The scan just measured, stamped at time_ns, queued.
  void addScan(int64_t time_ns) {
    sensor_msgs::LaserScan msg;
    scanner_.scan(&msg.ranges);
    const RayConfig& c = scanner_.config();
    msg.header.stamp.fromNSec(static_cast<uint64_t>(time_ns));
    msg.header.frame_id = frame_id_;
    msg.angle_min = static_cast<float>(c.min_angle);
    msg.angle_max = static_cast<float>(c.max_angle);
    msg.angle_increment = static_cast<float>(c.angleIncrement());
    msg.time_increment = 0;
    msg.scan_time = 0;
    msg.range_min = static_cast<float>(c.range_min);
    msg.range_max = static_cast<float>(c.range_max);
    msg.intensities.assign(msg.ranges.size(), 0.0f);
    publications_.add(publisher_, msg);
  }

  std::string label_;
  RayScanner scanner_;
  SensorGate gate_;
  ros::NodeHandle node_;
  std::string frame_id_;
  ros::Publisher publisher_;
  PublicationQueue publications_;
  bool failed_ = false;  // logged once
};

}  // namespace

std::unique_ptr<ModelPlugin> makeGazeboRosLaser(const SensorPluginContext& context,
                                                std::string* error) {
  const PluginParams params(context.plugin.plugin_xml,
                            context.plugin.filename + " (" + context.plugin.model + ")");
  RayConfig config;
  if (!readRayConfig(context.sensor.xml, &config, error)) return nullptr;
  // gazebo_ros's GetRobotNamespace: an empty <robotNamespace> means the model's name.
  std::string robot_namespace = context.plugin.robot_namespace;
  if (params.has("robotNamespace") && robot_namespace.empty())
    robot_namespace = context.plugin.model;
  return std::make_unique<GazeboRosLaser>(context, config, robot_namespace,
                                          params.text("topicName", "/world"),
                                          params.text("frameName", "/world"));
}

}  // namespace onedof_sim::plugins
