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
// those) add their noise to each rate and acceleration component (sensor_noise.h).
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
#include <random>
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

// The sensor's noise models, one a component: rates x, y, z, then accelerations x, y, z.
struct ImuNoiseParams {
  NoiseParams rate[3], acceleration[3];
  bool any() const {
    for (int i = 0; i < 3; ++i)
      if (rate[i].on || acceleration[i].on) return true;
    return false;
  }
};

// The sensor's <imu> noise elements. SDF 1.4's <imu><noise> (<type>, <rate> and <accel> with
// mean, stddev, bias_mean, bias_stddev) stands for the same noise on each axis, as sdformat's
// conversion makes it; the per-axis elements, when there are any, win.
bool readImuNoise(const std::string& sensor_xml, ImuNoiseParams* params, std::string* error) {
  tinyxml2::XMLDocument doc;
  if (doc.Parse(sensor_xml.c_str(), sensor_xml.size()) != tinyxml2::XML_SUCCESS) {
    *error = "the <sensor> is not XML";
    return false;
  }
  *params = {};
  const tinyxml2::XMLElement* imu = doc.RootElement()->FirstChildElement("imu");
  if (!imu) return true;
  if (const tinyxml2::XMLElement* old = imu->FirstChildElement("noise")) {
    // <type> applies to both groups: copy it into each as the converted SDF has it.
    const tinyxml2::XMLElement* type = old->FirstChildElement("type");
    const std::string type_text = type && type->GetText() ? type->GetText() : "gaussian";
    for (const auto& [group, out] : {std::pair{"rate", params->rate},
                                     std::pair{"accel", params->acceleration}}) {
      tinyxml2::XMLDocument copy;
      tinyxml2::XMLElement* noise = copy.NewElement("noise");
      copy.InsertEndChild(noise);
      noise->SetAttribute("type", type_text.c_str());
      if (const tinyxml2::XMLElement* values = old->FirstChildElement(group))
        for (auto* child = values->FirstChildElement(); child; child = child->NextSiblingElement())
          noise->InsertEndChild(child->DeepClone(&copy));
      NoiseParams axis;
      if (!readNoise(noise, "<imu><noise><" + std::string(group) + ">", &axis, error))
        return false;
      for (int i = 0; i < 3; ++i) out[i] = axis;
    }
  }
  const char* axes[3] = {"x", "y", "z"};
  for (const auto& [group, out] : {std::pair{"angular_velocity", params->rate},
                                   std::pair{"linear_acceleration", params->acceleration}}) {
    const tinyxml2::XMLElement* element = imu->FirstChildElement(group);
    if (!element) continue;
    for (int i = 0; i < 3; ++i) {
      const tinyxml2::XMLElement* axis = element->FirstChildElement(axes[i]);
      const tinyxml2::XMLElement* noise = axis ? axis->FirstChildElement("noise") : nullptr;
      if (!noise) continue;
      if (!readNoise(noise, "<imu><" + std::string(group) + "><" + axes[i] + "><noise>", &out[i],
                     error))
        return false;
    }
  }
  return true;
}

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
        random_(seedOf(context.plugin.model + "::" + context.sensor.link + "::" +
                       context.sensor.name)),
        white_(params.gaussian_noise),
        node_(params.robot_namespace) {
    for (int i = 0; i < 3; ++i) {
      rate_noise_[i] = Noise(params_.noise.rate[i], random_);
      acceleration_noise_[i] = Noise(params_.noise.acceleration[i], random_);
    }
    {
      std::unique_lock<std::mutex> lock = context.plugin.lock_world();
      const World& world = *context.plugin.world;
      imu_.restart(world, world.timeNs());
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
    // The sensor's own noise, at every measurement, as Gazebo's ImuSensor adds it.
    Vec3& w = reading.angular_velocity;
    Vec3& a = reading.linear_acceleration;
    w = {rate_noise_[0].apply(w.x, random_), rate_noise_[1].apply(w.y, random_),
         rate_noise_[2].apply(w.z, random_)};
    a = {acceleration_noise_[0].apply(a.x, random_), acceleration_noise_[1].apply(a.y, random_),
         acceleration_noise_[2].apply(a.z, random_)};

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
  }

  std::vector<Publication> takePublications() override { return publications_.take(); }

 private:
  ImuSensorParams params_;
  std::string label_;
  SensorGate gate_;
  ImuMeasurement imu_;
  Quat reference_;  // the world's orientation the published one is relative to
  std::mt19937_64 random_;
  Noise rate_noise_[3], acceleration_noise_[3];
  WhiteNoise white_;
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
