// libgazebo_ros_block_laser.so on a `ray` sensor (gazebo_plugins' GazeboRosBlockLaser): the
// sensor's scan, rows and columns, as a sensor_msgs/PointCloud on <topicName> (default /world;
// empty: nothing published) in <frameName> (default /world, under the tf_prefix), in the
// plugin's <robotNamespace>, stamped at the sim time of the step the sensor measured after, at
// the sensor's <update_rate> while anyone subscribes (Gazebo's plugin keeps its sensor inactive
// otherwise; its own <updateRate> is read and applied to nothing, as upstream).
//
// One point for each range of the scan (row after row, each from min_angle to max_angle): the
// range as Gazebo's ray shape gives it (from the sensor, range_max where a ray meets nothing,
// without the <ray><noise>), interpolated between the rays around it where <resolution> asks
// for more ranges than rays. So a ray that meets nothing gives a point at exactly range_max, and
// one whose start (range_min out) lies past or inside what it meets reports what lies beyond:
// every point is between range_min and range_max, upstream's clipping; a range below range_min
// would be -inf and one above range_max +inf (REP 117), as upstream writes it, and neither
// arises. Points not at range_max get N(0, <gaussianNoise>) (default 0) added to x, y and z.
// One channel, unnamed as upstream's: the intensity, the mean laser_retro of the four rays around
// the point (no collision sets one here: 0, Gazebo's default) with N(0, <gaussianNoise>) added.
// <hokuyoMinIntensity> is read and used for nothing, as upstream.
//
// Where it differs from Gazebo: each point lies along the direction its range was measured in
// (Gazebo puts it at the mean angle of the rays its range is interpolated from, half a ray off
// when there are as many ranges as rays), so that it lies on the surface the ray met; the noise
// comes from a generator seeded with the sensor's name (Gazebo's from rand()), so that two runs
// in lock-step publish the same clouds.
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include <geometry_msgs/Point32.h>
#include <ros/console.h>
#include <sensor_msgs/ChannelFloat32.h>
#include <sensor_msgs/PointCloud.h>

#include "model_plugin.h"
#include "plugin_params.h"
#include "sensor_plugin.h"
#include "sensors/ray_sensor.h"
#include "sensors/sensor_noise.h"
#include "sensors/update_gate.h"

namespace onedof_sim::plugins {
namespace {

// Upstream's test of a point at range_max, which gets no noise.
constexpr double kAtMaxRange = 1e-6;

class GazeboRosBlockLaser : public ModelPlugin {
 public:
  GazeboRosBlockLaser(const SensorPluginContext& context, const RayConfig& config,
                      const std::string& topic, const std::string& frame, double gaussian_noise)
      : label_(context.plugin.filename + " of sensor '" + context.sensor.name + "' (model '" +
               context.plugin.model + "')"),
        scanner_(config, context.plugin.model + "::" + context.sensor.link, context.sensor.pose,
                 sensorSeed(context)),
        gate_(context.sensor.update_rate),
        random_(sensorSeed(context)),
        noise_(whiteNoise(std::abs(gaussian_noise)), random_),
        node_(context.plugin.node),
        frame_id_(resolveTfFrame(tfPrefix(node_), frame)) {
    if (!topic.empty()) publisher_ = node_.advertise<sensor_msgs::PointCloud>(topic, 1);
    if (noise_.on())
      ROS_INFO_STREAM(label_ << ": its Gaussian noise is drawn from a generator seeded with the "
                      << "sensor's name (Gazebo's from rand()), so runs repeat their clouds");
  }

  void afterStep(World& /*world*/, const StepTime& at) override {
    if (!publisher_ || publisher_.getNumSubscribers() == 0 || !gate_.due(at.time_ns)) return;
    const int64_t time_ns = at.time_ns;
    publications_.addWork(measurementWork(&scanner_, label_, "scan", &failed_,
                                          [this, time_ns] { addMeasurement(time_ns); }));
  }

  std::vector<std::shared_ptr<SensorWork>> takeSensorWork() override {
    return publications_.takeWork();
  }

  // The message of the measurement just made, stamped at time_ns, queued.
  void addMeasurement(int64_t time_ns) {
    const RayConfig& c = scanner_.config();
    const int rows = c.verticalRangeCount(), columns = c.rangeCount();
    auto cloud = boost::make_shared<sensor_msgs::PointCloud>();
    cloud->header.frame_id = frame_id_;
    cloud->header.stamp.fromNSec(static_cast<uint64_t>(time_ns));
    cloud->points.reserve(static_cast<size_t>(rows) * columns);
    cloud->channels.resize(1);
    std::vector<float>& intensities = cloud->channels[0].values;
    intensities.reserve(cloud->points.capacity());
    for (int row = 0; row < rows; ++row) {
      const double pitch = c.rangePitch(row);
      for (int column = 0; column < columns; ++column) {
        double range = scanner_.range(row, column);
        if (range < c.range_min)
          range = -std::numeric_limits<double>::infinity();
        else if (range > c.range_max)
          range = std::numeric_limits<double>::infinity();
        const double yaw = c.rangeYaw(column);
        double x = range * std::cos(pitch) * std::cos(yaw);
        double y = range * std::cos(pitch) * std::sin(yaw);
        double z = range * std::sin(pitch);
        if (std::fabs(c.range_max - range) > kAtMaxRange) {
          x = noise_.apply(x, random_);
          y = noise_.apply(y, random_);
          z = noise_.apply(z, random_);
        }
        geometry_msgs::Point32 point;
        point.x = static_cast<float>(x);
        point.y = static_cast<float>(y);
        point.z = static_cast<float>(z);
        cloud->points.push_back(point);
        intensities.push_back(static_cast<float>(noise_.apply(0.0, random_)));
      }
    }
    publications_.add(publisher_, cloud);
  }

  void reset(World& /*world*/) override { gate_.reset(); }

  std::vector<Publication> takePublications() override { return publications_.take(); }

 private:
  std::string label_;
  RayScanner scanner_;
  SensorGate gate_;
  NoiseRandom random_;
  NoiseModel noise_;  // drawn from random_
  ros::NodeHandle node_;
  std::string frame_id_;
  ros::Publisher publisher_;
  PublicationQueue publications_;
  bool failed_ = false;  // logged once
};

}  // namespace

std::unique_ptr<ModelPlugin> makeGazeboRosBlockLaser(const SensorPluginContext& context,
                                                     std::string* error) {
  const PluginParams params(context.plugin.plugin_xml,
                            context.plugin.filename + " (" + context.plugin.model + ")");
  RayConfig config;
  if (!readRayConfig(context.sensor.xml, &config, error)) return nullptr;
  double gaussian_noise = 0, unused = 0;
  if (!params.number("gaussianNoise", 0, &gaussian_noise, error) ||
      !params.number("hokuyoMinIntensity", 101, &unused, error) ||
      !params.number("updateRate", 0, &unused, error))
    return nullptr;
  return std::make_unique<GazeboRosBlockLaser>(context, config, params.text("topicName", "/world"),
                                               params.text("frameName", "/world"),
                                               gaussian_noise);
}

}  // namespace onedof_sim::plugins
