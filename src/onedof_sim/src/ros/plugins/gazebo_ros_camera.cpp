// libgazebo_ros_camera.so on a `camera` sensor (gazebo_plugins' GazeboRosCamera over
// GazeboRosCameraUtils): the sensor's frames as sensor_msgs/Image (rgb8; bgr8 for B8G8R8) on
// <imageTopicName> (default image_raw) and sensor_msgs/CameraInfo on <cameraInfoTopicName>
// (default camera_info), in <robotNamespace>/<cameraName>, in <frameName> under the tf_prefix,
// stamped at the sim time of the step the frame was rendered after. Rendered at the sensor's
// <update_rate>, thinned to the plugin's <updateRate> (0: every sensor update), while anyone
// subscribes to either topic, as Gazebo's camera is active only then.
#include <memory>
#include <string>
#include <vector>

#include "camera_utils.h"
#include "model_plugin.h"
#include "sensor_plugin.h"
#include "sensors/camera_sensor.h"

namespace onedof_sim::plugins {
namespace {

class GazeboRosCamera : public ModelPlugin {
 public:
  GazeboRosCamera(const SensorPluginContext& context, const CameraConfig& camera,
                  std::shared_ptr<CameraUtils> utils)
      : utils_(std::move(utils)),
        view_(std::make_shared<CameraView>(camera,
                                           context.plugin.model + "::" + context.sensor.link,
                                           context.sensor.pose, utils_->label(),
                                           sensorSeed(context))),
        gate_(utils_->sensorGate(context)),
        throttle_(utils_->updateRate()) {}

  void afterStep(World& world, const StepTime& at) override {
    const bool image = utils_->imageWanted(), info = utils_->infoWanted();
    if ((!image && !info) || !gate_.due(at.time_ns) || !throttle_.due(at.time_ns)) return;
    // No frame (no renderer, logged once): the CameraInfo still goes out.
    const bool render = image && view_->capture(world);
    publications_.addWork(frameWork(
        view_, render,
        [utils = utils_, info, t = at.time_ns](const render::Frame* frame, PublicationQueue* out) {
          if (frame) utils->addImage(*frame, t, out);
          if (info) utils->addInfo(utils->infoPublisher(), t, out);
        }));
  }

  void reset(World& /*world*/) override {
    gate_.reset();
    throttle_.reset();
  }

  std::vector<std::shared_ptr<SensorWork>> takeSensorWork() override {
    return publications_.takeWork();
  }

 private:
  std::shared_ptr<CameraUtils> utils_;
  std::shared_ptr<CameraView> view_;
  SensorGate gate_;
  PublishThrottle throttle_;
  PublicationQueue publications_;
};

}  // namespace

std::unique_ptr<ModelPlugin> makeGazeboRosCamera(const SensorPluginContext& context,
                                                 std::string* error) {
  CameraConfig camera;
  if (!readCameraConfig(context.sensor.xml, &camera, error)) return nullptr;
  auto utils = std::make_shared<CameraUtils>();
  if (!utils->load(context, camera, error)) return nullptr;
  return std::make_unique<GazeboRosCamera>(context, camera, std::move(utils));
}

}  // namespace onedof_sim::plugins
