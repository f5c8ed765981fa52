// libgazebo_ros_multicamera.so on a `multicamera` sensor (gazebo_plugins' GazeboRosMultiCamera,
// a stereo pair): one camera view for each <camera> of the sensor, each where the sensor's pose
// and its own <pose> put it. As Gazebo names them, a camera whose name has "left" in it publishes
// in <robotNamespace>/<cameraName>/left, one with "right" in <cameraName>/right (sensor_msgs/Image
// on <imageTopicName>, default image_raw, and CameraInfo on <cameraInfoTopicName>, default
// camera_info), both in <frameName>; the right camera's CameraInfo carries the stereo baseline,
// P[3] = -fx <hackBaseline> (the left's, 0), as gazebo_ros_camera_utils writes it for
// stereo_image_proc. Every camera renders after the same step, so a pair's images and
// CameraInfos carry one stamp. Rendered at the sensor's <update_rate>, thinned to the plugin's
// <updateRate>; a camera renders while anyone subscribes to its image, its CameraInfo goes out
// while anyone subscribes to that.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <ros/console.h>

#include "camera_utils.h"
#include "model_plugin.h"
#include "sensor_plugin.h"
#include "sensors/camera_sensor.h"
#include "sensors/sensor_noise.h"

namespace onedof_sim::plugins {
namespace {

struct StereoCamera {
  std::shared_ptr<CameraUtils> utils;
  std::shared_ptr<CameraView> view;
  PublishThrottle throttle;
};

class GazeboRosMultiCamera : public ModelPlugin {
 public:
  GazeboRosMultiCamera(SensorGate gate, std::vector<StereoCamera> cameras)
      : gate_(gate), cameras_(std::move(cameras)) {}

  void afterStep(World& world, const StepTime& at) override {
    bool wanted = false;
    for (const StereoCamera& camera : cameras_)
      wanted = wanted || camera.utils->imageWanted() || camera.utils->infoWanted();
    if (!wanted || !gate_.due(at.time_ns)) return;
    for (StereoCamera& camera : cameras_) {
      CameraUtils& utils = *camera.utils;
      const bool image = utils.imageWanted(), info = utils.infoWanted();
      if ((!image && !info) || !camera.throttle.due(at.time_ns)) continue;
      // No frame (no renderer, logged once): the CameraInfo still goes out.
      const bool render = image && camera.view->capture(world);
      publications_.addWork(frameWork(
          camera.view, render,
          [utils = camera.utils, info, t = at.time_ns](const render::Frame* frame,
                                                       PublicationQueue* out) {
            if (frame) utils->addImage(*frame, t, out);
            if (info) utils->addInfo(utils->infoPublisher(), t, out);
          }));
    }
  }

  void reset(World& /*world*/) override {
    gate_.reset();
    for (StereoCamera& camera : cameras_) camera.throttle.reset();
  }

  std::vector<std::shared_ptr<SensorWork>> takeSensorWork() override {
    return publications_.takeWork();
  }

 private:
  SensorGate gate_;
  std::vector<StereoCamera> cameras_;
  PublicationQueue publications_;
};

}  // namespace

std::unique_ptr<ModelPlugin> makeGazeboRosMultiCamera(const SensorPluginContext& context,
                                                      std::string* error) {
  std::vector<CameraConfig> configs;
  if (!readCameraConfigs(context.sensor.xml, &configs, error)) return nullptr;
  const std::string label = context.plugin.filename + " of sensor '" + context.sensor.name +
                            "' (model '" + context.plugin.model + "')";
  std::vector<StereoCamera> cameras;
  std::string left, right;  // the cameras publishing as left and right
  for (const CameraConfig& config : configs) {
    // Gazebo's choice: "left" anywhere in the name first, then "right"; any other camera has no
    // topics and is not rendered.
    const bool is_left = config.name.find("left") != std::string::npos;
    const bool is_right = !is_left && config.name.find("right") != std::string::npos;
    if (!is_left && !is_right) {
      ROS_WARN_STREAM(label << ": camera '" << config.name << "' has neither 'left' nor 'right' "
                      << "in its name, which are how Gazebo's multicamera plugin names its "
                      << "topics; it publishes nothing, as in Gazebo");
      continue;
    }
    std::string& taken = is_left ? left : right;
    if (!taken.empty()) {
      *error = "cameras '" + taken + "' and '" + config.name + "' would both publish as " +
               (is_left ? "left" : "right") + " (Gazebo's multicamera plugin names a camera's "
               "topics by 'left' or 'right' in its name)";
      return nullptr;
    }
    taken = config.name;
    auto utils = std::make_shared<CameraUtils>();
    // The right camera's baseline is the plugin's <hackBaseline>, the left's 0.
    if (!utils->load(context, config, error, is_left ? "/left" : "/right",
                     is_left ? std::optional<double>(0.0) : std::nullopt))
      return nullptr;
    const std::string camera_label = utils->label() + " camera '" + config.name + "'";
    const uint64_t seed = seedOf(context.plugin.model + "::" + context.sensor.link + "::" +
                                 context.sensor.name + "::" + config.name);
    auto view = std::make_shared<CameraView>(
        config, context.plugin.model + "::" + context.sensor.link, context.sensor.pose,
        camera_label, seed);
    const double rate = utils->updateRate();
    cameras.push_back({std::move(utils), std::move(view), PublishThrottle(rate)});
  }
  if (cameras.empty()) {
    *error = "none of its cameras has 'left' or 'right' in its name, which are how Gazebo's "
             "multicamera plugin names its topics";
    return nullptr;
  }
  const SensorGate gate = cameras.front().utils->sensorGate(context);
  return std::make_unique<GazeboRosMultiCamera>(gate, std::move(cameras));
}

}  // namespace onedof_sim::plugins
