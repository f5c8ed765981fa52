// libgazebo_ros_imu.so (gazebo_plugins' GazeboRosIMU): an IMU on a link as sensor_msgs/Imu on
// <topicName> (default /default_imu; empty: none), at <updateRate> of sim time (0: every step),
// stamped in sim time, frame <frameName> (default <bodyName>, taken as written, as that plugin
// does), while anyone subscribes; <serviceName> (default /default_imu) is its calibrate service
// (std_srvs/Empty), which succeeds at once: a simulated IMU has no bias to learn.
//
// What it reads, as GazeboRosIMU computes it: the orientation is the link's in the world turned
// by <rpyOffset> (offset * link), with no noise; the angular velocity is the link's; the linear
// acceleration is the change of the link frame origin's velocity since the last update over the
// sim time between them (the first update differences from the plugin's start); the
// measurement is the one the `imu` sensor makes too (imu_measurement.h). <gaussianNoise>
// (standard deviation) is added to each rate and acceleration component and makes the diagonal
// of all three covariances (its square). <xyzOffset> is read and, as in GazeboRosIMU, used for
// nothing published.
//
// Where it differs from GazeboRosIMU (said once in the log): the linear acceleration is what an
// accelerometer feels, the acceleration minus gravity (at rest it reads |g| up, where
// GazeboRosIMU reads 0); the rates and the acceleration are in the sensor's axes (the world's
// vectors turned back by the published orientation; GazeboRosIMU turns them forward by it,
// which is the same only while the link is not turned); the velocity is sampled at every update
// whether or not anyone subscribes (GazeboRosIMU samples only while publishing), so that what
// is published does not depend on when a subscriber came; and the noise comes from a generator
// seeded with the plugin's name (pluginSeed), so that two runs publish the same numbers.
#include <onedof_sim/pose_math.h>
#include <ros/console.h>
#include <sensor_msgs/Imu.h>
#include <std_srvs/Empty.h>

#include "imu_message.h"
#include "model_plugin.h"
#include "plugin_params.h"
#include "sensors/imu_measurement.h"
#include "sensors/sensor_noise.h"
#include "sensors/update_gate.h"

namespace onedof_sim::plugins {
namespace {

struct ImuParams {
  std::string link;     // scoped "model::link"
  std::string topic = "/default_imu";
  std::string service = "/default_imu";
  std::string frame;
  Vec3 xyz_offset;
  Quat rpy_offset;
  double gaussian_noise = 0;
  double update_rate = 0;
};

class GazeboRosImu : public ModelPlugin {
 public:
  GazeboRosImu(const ModelPluginContext& context, const ImuParams& params)
      : params_(params),
        node_(context.node),
        imu_(params.link, Pose{}, params.rpy_offset),
        random_(pluginSeed(context)),
        noise_(whiteNoise(params.gaussian_noise), random_) {
    {
      std::unique_lock<std::mutex> lock = context.lock_world();
      update_gate_ = UpdateGate(params_.update_rate, context.world->timeNs());
      imu_.restart(*context.world, context.world->timeNs());
    }
    if (params_.topic.empty()) return;
    // A queue of a second's worth at 100 Hz: stepped flat out (step_simulation), a queue of 1
    // (Gazebo's) drops most messages before they are written out.
    publisher_ = node_.advertise<sensor_msgs::Imu>(params_.topic, 100);
    calibrate_ = node_.advertiseService(params_.service, &GazeboRosImu::calibrate, this);
  }

  void afterStep(World& world, const StepTime& at) override {
    if (!update_gate_.due(at.time_ns)) return;
    ImuReading reading;
    if (!imu_.measure(world, at.time_ns, &reading)) return;
    if (params_.topic.empty() || publisher_.getNumSubscribers() == 0) return;
    // Gazebo's plugin adds its noise to the rates, then to the accelerations; the orientation has
    // none.
    const Vec3 rate = reading.angular_velocity, felt = reading.linear_acceleration;
    reading.angular_velocity = {noise_.apply(rate.x, random_), noise_.apply(rate.y, random_),
                                noise_.apply(rate.z, random_)};
    reading.linear_acceleration = {noise_.apply(felt.x, random_), noise_.apply(felt.y, random_),
                                   noise_.apply(felt.z, random_)};
    publications_.add(publisher_,
                      imuMessage(reading, at.time_ns, params_.frame,
                                 params_.gaussian_noise * params_.gaussian_noise));
  }

  // The world jumped (reset_world, reset_simulation): differences start again from there.
  void reset(World& world) override {
    update_gate_.restart(world.timeNs());
    imu_.restart(world, world.timeNs());
  }

  std::vector<Publication> takePublications() override { return publications_.take(); }

 private:
  bool calibrate(std_srvs::Empty::Request&, std_srvs::Empty::Response&) { return true; }

  ImuParams params_;
  ros::NodeHandle node_;
  ros::Publisher publisher_;
  ros::ServiceServer calibrate_;
  UpdateGate update_gate_;
  ImuMeasurement imu_;
  NoiseRandom random_;
  NoiseModel noise_;  // <gaussianNoise>
  PublicationQueue publications_;
};

}  // namespace

std::unique_ptr<ModelPlugin> makeGazeboRosImu(const ModelPluginContext& context,
                                              std::string* error) {
  const PluginParams params(context.plugin_xml, "gazebo_ros_imu (" + context.model + ")");
  ImuParams p;
  if (!params.has("bodyName")) {
    *error = "missing <bodyName>";
    return nullptr;
  }
  const std::string body = params.text("bodyName", "");
  p.topic = params.text("topicName", p.topic);
  p.service = params.text("serviceName", p.service);
  p.frame = params.text("frameName", body);
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
  {
    // GazeboRosIMU finds <bodyName> among the world's entities: a scoped name as given, else a
    // link of this model.
    std::unique_lock<std::mutex> lock = context.lock_world();
    LinkInfo info;
    if (body.find("::") != std::string::npos && context.world->linkProperties(body, &info).ok())
      p.link = body;
    else if (context.world->linkProperties(context.model + "::" + body, &info).ok())
      p.link = context.model + "::" + body;
    else {
      *error = "bodyName: " + body + " does not exist";
      return nullptr;
    }
  }
  static bool told = false;
  if (!told) {
    told = true;
    ROS_INFO_STREAM(
        "gazebo_ros_imu: linear_acceleration is the link's acceleration minus gravity, as a real "
        "IMU reads it (|g| up at rest; Gazebo's plugin leaves gravity out and reads 0), and "
        "angular_velocity and linear_acceleration are in the sensor's axes (Gazebo's plugin "
        "turns the world's vectors the other way, which differs once the link is turned)");
  }
  return std::make_unique<GazeboRosImu>(context, p);
}

}  // namespace onedof_sim::plugins
