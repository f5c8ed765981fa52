// libgazebo_ros_range.so on a `ray` sensor (gazebo_plugins' GazeboRosRange): a sonar or infrared
// range finder, sensor_msgs/Range on <topicName> (default /range; empty: nothing published) in
// <frameName> (default /world, under the tf_prefix), in the plugin's <robotNamespace>, stamped
// at the sim time of the step the sensor measured after.
//
// The sensor measures at its <update_rate> of sim time while anyone subscribes (Gazebo's plugin
// keeps its sensor inactive otherwise), and the plugin publishes a measurement once at least a
// period of its own <updateRate> (default 0: every one) has passed since the last it published.
// The range is the shortest of the sensor's rays (every ray of every row), each as Gazebo's ray
// shape gives it: from the sensor, range_max where it meets nothing, without the <ray><noise>.
// Nothing met: exactly max_range. Otherwise N(0, <gaussianNoise>) is added (default 0; a negative
// deviation draws as its absolute value, as in Gazebo) and the sum held at most max_range, as
// upstream does (and not at least min_range). min_range and max_range are the sensor's
// <ray><range>; field_of_view is <fov> (default 0.05 rad) as written, whatever the rays span;
// radiation_type is ULTRASOUND for <radiation> ultrasound (the default), INFRARED for anything
// else.
//
// The noise comes from a generator seeded with the sensor's name (Gazebo seeds it at random), so
// that two runs in lock-step publish the same ranges.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include <ros/console.h>
#include <sensor_msgs/Range.h>

#include "model_plugin.h"
#include "plugin_params.h"
#include "sensor_plugin.h"
#include "sensors/ray_sensor.h"
#include "sensors/sensor_noise.h"
#include "sensors/update_gate.h"

namespace onedof_sim::plugins {
namespace {

struct RangeParams {
  std::string topic = "/range";
  std::string frame = "/world";
  bool ultrasound = true;
  double fov = 0.05;
  double gaussian_noise = 0;
  double update_rate = 0;
};

class GazeboRosRange : public ModelPlugin {
 public:
  GazeboRosRange(const SensorPluginContext& context, const RayConfig& config,
                 const RangeParams& params)
      : label_(context.plugin.filename + " of sensor '" + context.sensor.name + "' (model '" +
               context.plugin.model + "')"),
        scanner_(config, context.plugin.model + "::" + context.sensor.link, context.sensor.pose,
                 sensorSeed(context)),
        gate_(context.sensor.update_rate),
        throttle_(params.update_rate),
        random_(sensorSeed(context)),
        noise_(whiteNoise(std::abs(params.gaussian_noise)), random_),
        node_(context.plugin.node) {
    message_.header.frame_id = resolveTfFrame(tfPrefix(node_), params.frame);
    message_.radiation_type =
        params.ultrasound ? sensor_msgs::Range::ULTRASOUND : sensor_msgs::Range::INFRARED;
    message_.field_of_view = static_cast<float>(params.fov);
    message_.min_range = static_cast<float>(config.range_min);
    message_.max_range = static_cast<float>(config.range_max);
    if (!params.topic.empty()) publisher_ = node_.advertise<sensor_msgs::Range>(params.topic, 1);
    if (noise_.on())
      ROS_INFO_STREAM(label_ << ": its Gaussian noise is drawn from a generator seeded with the "
                      << "sensor's name (Gazebo seeds it at random), so runs repeat their ranges");
  }

  void afterStep(World& /*world*/, const StepTime& at) override {
    if (!publisher_ || publisher_.getNumSubscribers() == 0 || !gate_.due(at.time_ns) ||
        !throttle_.due(at.time_ns))
      return;
    const int64_t time_ns = at.time_ns;
    publications_.addWork(measurementWork(&scanner_, label_, "range", &failed_,
                                          [this, time_ns] { addMeasurement(time_ns); }));
  }

  std::vector<std::shared_ptr<SensorWork>> takeSensorWork() override {
    return publications_.takeWork();
  }

  // The message of the measurement just made, stamped at time_ns, queued.
  void addMeasurement(int64_t time_ns) {
    const RayConfig& c = scanner_.config();
    float range = std::numeric_limits<float>::max();
    for (int row = 0; row < c.vertical_samples; ++row)
      for (int column = 0; column < c.samples; ++column)
        range = std::min(range, static_cast<float>(scanner_.rayRange(row, column)));
    if (range < message_.max_range)
      range = static_cast<float>(std::min(noise_.apply(range, random_), c.range_max));
    message_.range = range;
    message_.header.stamp.fromNSec(static_cast<uint64_t>(time_ns));
    publications_.add(publisher_, message_);
  }

  void reset(World& /*world*/) override {
    gate_.reset();
    throttle_.reset();
  }

  std::vector<Publication> takePublications() override { return publications_.take(); }

 private:
  std::string label_;
  RayScanner scanner_;
  SensorGate gate_;
  PublishThrottle throttle_;
  NoiseRandom random_;
  NoiseModel noise_;  // drawn from random_
  ros::NodeHandle node_;
  ros::Publisher publisher_;
  sensor_msgs::Range message_;
  PublicationQueue publications_;
  bool failed_ = false;  // logged once
};

}  // namespace

std::unique_ptr<ModelPlugin> makeGazeboRosRange(const SensorPluginContext& context,
                                                std::string* error) {
  const PluginParams params(context.plugin.plugin_xml,
                            context.plugin.filename + " (" + context.plugin.model + ")");
  RayConfig config;
  if (!readRayConfig(context.sensor.xml, &config, error)) return nullptr;
  RangeParams range;
  range.topic = params.text("topicName", range.topic);
  range.frame = params.text("frameName", range.frame);
  if (!params.has("radiation"))
    ROS_WARN_STREAM(params.label() << ": Range plugin missing <radiation>, defaults to ultrasound");
  range.ultrasound = params.text("radiation", "ultrasound") == "ultrasound";
  if (!params.has("fov"))
    ROS_WARN_STREAM(params.label() << ": Range plugin missing <fov>, defaults to 0.05");
  if (!params.number("fov", range.fov, &range.fov, error) ||
      !params.number("gaussianNoise", 0, &range.gaussian_noise, error) ||
      !params.number("updateRate", 0, &range.update_rate, error))
    return nullptr;
  return std::make_unique<GazeboRosRange>(context, config, range);
}

}  // namespace onedof_sim::plugins
