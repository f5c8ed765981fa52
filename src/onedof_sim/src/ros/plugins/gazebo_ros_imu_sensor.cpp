// libgazebo_ros_imu_sensor.so (gazebo_plugins' GazeboRosImuSensor) on an `imu` sensor (Gazebo's
// ImuSensor): sensor_msgs/Imu on <topicName> (default imu_data) in <robotNamespace> (default the
// model's name), frame <frameName> as written (required: without it the plugin is not started,
// as in Gazebo), stamped at the sim time the sensor measured, while anyone subscribes.
//
// The sensor measures at its <update_rate> of sim time (0: every step), at its <pose> on its
// link (imu_measurement.h): the orientation of the sensor's frame in the world (REP 145; with
// <initialOrientationAsReference> true, relative to the frame's orientation at spawn), its
// angular velocity and the specific force (gravity's reaction included: at rest 9.81 m/s^2 up),
// both in the sensor's axes. <imu><angular_velocity> and <linear_acceleration> <x>/<y>/<z>
// <noise> (and SDF 1.4's <imu><noise> with <rate> and <accel>, which sdformat turns into
// those) add their noise to each rate and acceleration component (sensor_noise.h); a dynamic
// bias drifts over the sim time between measurements.
//
// The plugin publishes a measurement once at least a period of <updateRateHZ> (default 1 Hz)
// has passed since the last one it took, turns the orientation by <rpyOffset> (offset *
// orientation; rates and acceleration stay in the sensor's axes) and adds N(0, <gaussianNoise>)
// to the orientation's four components (not normalized again, as in Gazebo), to each
// acceleration and each rate, the diagonals of the three covariances being its square.
// <xyzOffset> is read and used for nothing, as in Gazebo.
//
// Where it differs from Gazebo (said once in the log): the noise comes from a generator seeded
// with the sensor's name (Gazebo seeds it at random), drawn whether or not anyone subscribes, so
// that two runs in lock-step publish the same numbers; with <updateRateHZ> 0 or less each
// measurement is published once (Gazebo's plugin publishes the last one again at every world
// step); after reset_simulation the plugin's rate starts again from time 0.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <onedof_sim/pose_math.h>
#include <ros/console.h>
#include <sensor_msgs/Imu.h>
#include <tinyxml2.h>

#include "imu_message.h"
#include "model_plugin.h"
#include "plugin_params.h"
#include "sensor_plugin.h"
#include "sensors/imu_measurement.h"
#include "sensors/sensor_noise.h"

namespace onedof_sim::plugins {
namespace {

struct ImuSensorParams {
  std::string robot_namespace;  // "/" when it names none
  std::string topic = "imu_data";
  std::string frame;
  double update_rate = 1.0;  // <updateRateHZ>
  double gaussian_noise = 0;
  Quat rpy_offset;
  bool initial_orientation_as_reference = false;
  ImuNoiseParams noise;
};

class GazeboRosImuSensor : public ModelPlugin {
 public:
  GazeboRosImuSensor(const SensorPluginContext& context, const ImuSensorParams& params)
      : params_(params),
        label_(context.plugin.filename + " of sensor '" + context.sensor.name + "' (model '" +
               context.plugin.model + "')"),
        gate_(context.sensor.update_rate),
        imu_(context.plugin.model + "::" + context.sensor.link, context.sensor.pose),
        random_(sensorSeed(context)),
        white_(whiteNoise(params.gaussian_noise), random_),
        node_(params.robot_namespace) {
    for (int i = 0; i < 3; ++i) {
      rate_noise_[i] = NoiseModel(params_.noise.rate[i], random_);
      acceleration_noise_[i] = NoiseModel(params_.noise.acceleration[i], random_);
    }
    {
      std::unique_lock<std::mutex> lock = context.plugin.lock_world();
      const World& world = *context.plugin.world;
      imu_.restart(world, world.timeNs());
      last_measured_ns_ = world.timeNs();
      ImuReading now;
      if (params_.initial_orientation_as_reference && imu_.measure(world, world.timeNs(), &now))
        reference_ = now.orientation;
    }
    // A queue of a second's worth at 100 Hz: stepped flat out (step_simulation), a queue of 1
    // (Gazebo's) drops most messages before they are written out.
    publisher_ = node_.advertise<sensor_msgs::Imu>(params_.topic, 100);
    if (params_.noise.any() || params_.gaussian_noise > 0)
      ROS_INFO_STREAM(label_ << ": its Gaussian noise is drawn from a generator seeded with the "
                      << "sensor's name (Gazebo seeds it at random), so runs repeat their "
                      << "numbers");
    if (params_.noise.drifts())
      ROS_INFO_STREAM(label_ << ": the bias of its noise drifts by <dynamic_bias_stddev> and "
                      << "<dynamic_bias_correlation_time>, as SDF describes them and gz-sensors "
                      << "applies them (Gazebo classic reads them and applies nothing)");
    if (params_.update_rate <= 0)
      ROS_INFO_STREAM(label_ << ": <updateRateHZ> " << params_.update_rate << ": each "
                      << "measurement is published once (Gazebo's plugin publishes the last one "
                      << "again at every world step)");
  }

  void afterStep(World& world, const StepTime& at) override {
    if (!gate_.due(at.time_ns)) return;
    ImuReading reading;
    if (!imu_.measure(world, at.time_ns, &reading)) {
      if (!failed_) ROS_ERROR_STREAM(label_ << " measured nothing: its link is gone");
      failed_ = true;
      return;
    }
    // The sensor's own noise, at every measurement, as Gazebo's ImuSensor adds it; a dynamic
    // bias drifts over the sim time since the last measurement.
    const double elapsed_s = 1e-9 * static_cast<double>(at.time_ns - last_measured_ns_);
    last_measured_ns_ = at.time_ns;
    Vec3& w = reading.angular_velocity;
    Vec3& a = reading.linear_acceleration;
    w = {rate_noise_[0].apply(w.x, random_, elapsed_s),
         rate_noise_[1].apply(w.y, random_, elapsed_s),
         rate_noise_[2].apply(w.z, random_, elapsed_s)};
    a = {acceleration_noise_[0].apply(a.x, random_, elapsed_s),
         acceleration_noise_[1].apply(a.y, random_, elapsed_s),
         acceleration_noise_[2].apply(a.z, random_, elapsed_s)};

    if (at.time_ns < last_published_ns_) last_published_ns_ = 0;
    if (params_.update_rate > 0 &&
        1e-9 * static_cast<double>(at.time_ns - last_published_ns_) < 1.0 / params_.update_rate)
      return;
    last_published_ns_ = at.time_ns;

    const Quat o =
        multiply(params_.rpy_offset, multiply(conjugate(reference_), reading.orientation));
    // Gazebo's plugin adds its <gaussianNoise> to the orientation (x, y, z, w), then to the
    // accelerations, then to the rates.
    ImuReading noisy;
    noisy.orientation.x = white_.apply(o.x, random_);
    noisy.orientation.y = white_.apply(o.y, random_);
    noisy.orientation.z = white_.apply(o.z, random_);
    noisy.orientation.w = white_.apply(o.w, random_);
    noisy.linear_acceleration = {white_.apply(a.x, random_), white_.apply(a.y, random_),
                                 white_.apply(a.z, random_)};
    noisy.angular_velocity = {white_.apply(w.x, random_), white_.apply(w.y, random_),
                              white_.apply(w.z, random_)};
    if (publisher_.getNumSubscribers() > 0)
      publications_.add(publisher_, imuMessage(noisy, at.time_ns, params_.frame,
                                               params_.gaussian_noise * params_.gaussian_noise));
  }

  // reset_world, reset_simulation: the sensor's rate and the differences start again there.
  void reset(World& world) override {
    gate_.reset();
    imu_.restart(world, world.timeNs());
    last_measured_ns_ = world.timeNs();
  }

  std::vector<Publication> takePublications() override { return publications_.take(); }

 private:
  ImuSensorParams params_;
  std::string label_;
  SensorGate gate_;
  ImuMeasurement imu_;
  Quat reference_;  // the world's orientation the published one is relative to
  NoiseRandom random_;
  NoiseModel white_;  // <gaussianNoise>
  NoiseModel rate_noise_[3], acceleration_noise_[3];
  int64_t last_measured_ns_ = 0;  // the sim time a dynamic bias drifts from
  int64_t last_published_ns_ = 0;
  ros::NodeHandle node_;
  ros::Publisher publisher_;
  PublicationQueue publications_;
  bool failed_ = false;  // logged once
};

}  // namespace

std::unique_ptr<ModelPlugin> makeGazeboRosImuSensor(const SensorPluginContext& context,
                                                    std::string* error) {
  const PluginParams params(context.plugin.plugin_xml,
                            context.plugin.filename + " (" + context.plugin.model + ")");
  ImuSensorParams p;
  // GazeboRosImuSensor: <robotNamespace> as given, else the model's name.
  std::string ns = params.has("robotNamespace") ? params.text("robotNamespace", "")
                                                : "/" + context.plugin.model;
  while (!ns.empty() && ns.back() == '/') ns.pop_back();
  p.robot_namespace = ns.empty() ? "/" : ns;
  if (!params.has("frameName")) {
    *error = "missing <frameName>, which it needs";
    return nullptr;
  }
  p.frame = params.text("frameName", "");
  p.topic = params.text("topicName", p.topic);
  Vec3 xyz, rpy;
  if (!params.number("updateRateHZ", p.update_rate, &p.update_rate, error) ||
      !params.number("gaussianNoise", 0, &p.gaussian_noise, error) ||
      !params.vector("xyzOffset", &xyz, error) || !params.vector("rpyOffset", &rpy, error) ||
      !readImuNoise(context.sensor.xml, &p.noise, error))
    return nullptr;
  if (p.gaussian_noise < 0) {
    *error = "<gaussianNoise> is negative";
    return nullptr;
  }
  if (p.topic.empty()) {
    *error = "<topicName> is empty";
    return nullptr;
  }
  p.rpy_offset = fromRpy(rpy);
  p.initial_orientation_as_reference = params.flag("initialOrientationAsReference", false);
  return std::make_unique<GazeboRosImuSensor>(context, p);
}

}  // namespace onedof_sim::plugins
