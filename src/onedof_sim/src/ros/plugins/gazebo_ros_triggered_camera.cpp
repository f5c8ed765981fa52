// libgazebo_ros_triggered_camera.so on a `camera` sensor (gazebo_plugins'
// GazeboRosTriggeredCamera): the camera of libgazebo_ros_camera.so (its topics, frame, formats
// and CameraInfo; see gazebo_ros_camera.cpp) that renders only when told to. Each std_msgs/Empty
// on <robotNamespace>/<cameraName>/<triggerTopicName> (default image_trigger) makes one frame,
// rendered after the next step whatever the sensor's <update_rate>, as Gazebo enables the sensor
// for one frame a trigger: two triggers before a step make two frames, after it and the one
// after (Gazebo may lose one of two that arrive together; here none is). The image goes out
// while anyone subscribes to it, the CameraInfo (thinned to the plugin's <updateRate>) while
// anyone subscribes to that; a trigger nobody watches is used up.
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <std_msgs/Empty.h>

#include "camera_utils.h"
#include "model_plugin.h"
#include "plugin_params.h"
#include "sensor_plugin.h"
#include "sensors/camera_sensor.h"

namespace onedof_sim::plugins {
namespace {

constexpr uint32_t kTriggerQueue = 100;

class GazeboRosTriggeredCamera : public ModelPlugin {
 public:
  GazeboRosTriggeredCamera(const SensorPluginContext& context, const CameraConfig& camera,
                           std::shared_ptr<CameraUtils> utils, const std::string& trigger_topic)
      : utils_(std::move(utils)),
        view_(std::make_shared<CameraView>(camera,
                                           context.plugin.model + "::" + context.sensor.link,
                                           context.sensor.pose, utils_->label(),
                                           sensorSeed(context))),
        info_throttle_(utils_->updateRate()) {
    // Gazebo's queue holds one trigger, so of two that arrive together one can be lost, as
    // its callback thread happens to run; here each is kept, up to kTriggerQueue unserved.
    trigger_subscriber_ = utils_->node().subscribe<std_msgs::Empty>(
        trigger_topic, kTriggerQueue, [this](const std_msgs::Empty::ConstPtr&) {
          std::lock_guard<std::mutex> lock(trigger_mutex_);
          ++triggers_;
        });
  }

  void afterStep(World& world, const StepTime& at) override {
    {
      std::lock_guard<std::mutex> lock(trigger_mutex_);
      if (triggers_ == 0) return;
      --triggers_;
    }
    // No frame (no renderer, logged once): the CameraInfo still goes out.
    const bool render = utils_->imageWanted() && view_->capture(world);
    const bool info = utils_->infoWanted() && info_throttle_.due(at.time_ns);
    publications_.addWork(frameWork(
        view_, render,
        [utils = utils_, info, t = at.time_ns](const render::Frame* frame, PublicationQueue* out) {
          if (frame) utils->addImage(*frame, t, out);
          if (info) utils->addInfo(utils->infoPublisher(), t, out);
        }));
  }

  void reset(World& /*world*/) override { info_throttle_.reset(); }

  std::vector<std::shared_ptr<SensorWork>> takeSensorWork() override {
    return publications_.takeWork();
  }

 private:
  std::shared_ptr<CameraUtils> utils_;
  std::shared_ptr<CameraView> view_;
  PublishThrottle info_throttle_;
  PublicationQueue publications_;
  std::mutex trigger_mutex_;
  int triggers_ = 0;  // frames asked for and not yet made, guarded by trigger_mutex_
  ros::Subscriber trigger_subscriber_;  // last: gone before what its callback touches
};

}  // namespace

std::unique_ptr<ModelPlugin> makeGazeboRosTriggeredCamera(const SensorPluginContext& context,
                                                          std::string* error) {
  CameraConfig camera;
  if (!readCameraConfig(context.sensor.xml, &camera, error)) return nullptr;
  auto utils = std::make_shared<CameraUtils>();
  if (!utils->load(context, camera, error)) return nullptr;
  const PluginParams params(context.plugin.plugin_xml, utils->label());
  const std::string trigger_topic = params.text("triggerTopicName", "image_trigger");
  return std::make_unique<GazeboRosTriggeredCamera>(context, camera, std::move(utils),
                                                    trigger_topic);
}

}  // namespace onedof_sim::plugins
