// libgazebo_ros_openni_kinect.so and libgazebo_ros_depth_camera.so on a `depth` sensor
// (gazebo_plugins' GazeboRosOpenniKinect and GazeboRosDepthCamera, the same code but for the
// far cutoff): in <robotNamespace>/<cameraName>, in <frameName> under the tf_prefix, stamped at
// the sim time of the step the frame was rendered after, at the sensor's <update_rate>:
// - the colour image (sensor_msgs/Image, rgb8) on <imageTopicName> (default image_raw) and its
//   CameraInfo on <cameraInfoTopicName> (default camera_info);
// - the depth image (32FC1, metres along the optical axis; 16UC1 millimetres with
//   <useDepth16UC1Format>) on <depthImageTopicName> (default depth/image_raw) and its CameraInfo
//   on <depthImageCameraInfoTopicName> (default depth/camera_info);
// - the point cloud (sensor_msgs/PointCloud2, x y z rgb in the optical frame) on
//   <pointCloudTopicName> (default points).
// Depths not above <pointCloudCutoff> (default 0.4 m) and, for the Kinect, not below
// <pointCloudCutoffMax> (default 5 m) are NaN in the depth image and the cloud (0 in 16UC1).
// Each topic is published while anyone subscribes to it; the CameraInfos are thinned to the
// plugin's <updateRate>, the images and the cloud are not, as in Gazebo.
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include <ros/console.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud2.h>

#include "camera_utils.h"
#include "model_plugin.h"
#include "plugin_params.h"
#include "sensor_plugin.h"
#include "sensors/camera_sensor.h"

namespace onedof_sim::plugins {
namespace {

struct DepthOutputs {
  std::string depth_topic = "depth/image_raw", depth_info_topic = "depth/camera_info",
              cloud_topic = "points";
  double cutoff = 0.4;
  double cutoff_max = std::numeric_limits<double>::infinity();
  bool depth_16uc1 = false;
};

class GazeboRosDepthCamera : public ModelPlugin {
 public:
  GazeboRosDepthCamera(const SensorPluginContext& context, const CameraConfig& camera,
                       std::shared_ptr<CameraUtils> utils, const DepthOutputs& outputs)
      : utils_(std::move(utils)),
        outputs_(outputs),
        view_(std::make_shared<CameraView>(camera,
                                           context.plugin.model + "::" + context.sensor.link,
                                           context.sensor.pose, utils_->label(),
                                           sensorSeed(context))),
        gate_(utils_->sensorGate(context)),
        info_throttle_(utils_->updateRate()),
        depth_info_throttle_(utils_->updateRate()) {
    ros::NodeHandle& node = utils_->node();
    depth_publisher_ = node.advertise<sensor_msgs::Image>(outputs.depth_topic, 1);
    depth_info_publisher_ = node.advertise<sensor_msgs::CameraInfo>(outputs.depth_info_topic, 1);
    cloud_publisher_ = node.advertise<sensor_msgs::PointCloud2>(outputs.cloud_topic, 1);
  }

  void afterStep(World& world, const StepTime& at) override {
    const bool image = utils_->imageWanted(), info = utils_->infoWanted();
    const bool depth = depth_publisher_.getNumSubscribers() > 0;
    const bool depth_info = depth_info_publisher_.getNumSubscribers() > 0;
    const bool cloud = cloud_publisher_.getNumSubscribers() > 0;
    if (!(image || info || depth || depth_info || cloud) || !gate_.due(at.time_ns)) return;
    const int64_t t = at.time_ns;
    // No frame (no renderer, logged once): the CameraInfos still go out.
    const bool render = (image || depth || cloud) && view_->capture(world);
    const bool info_due = info && info_throttle_.due(t);
    const bool depth_info_due = depth_info && depth_info_throttle_.due(t);
    publications_.addWork(frameWork(
        view_, render,
        [utils = utils_, outputs = outputs_, depth_publisher = depth ? depth_publisher_ : ros::Publisher(),
         cloud_publisher = cloud ? cloud_publisher_ : ros::Publisher(), image, info_due,
         depth_info_publisher = depth_info_due ? depth_info_publisher_ : ros::Publisher(),
         t](const render::Frame* frame, PublicationQueue* out) {
          if (frame && image) utils->addImage(*frame, t, out);
          if (frame && depth_publisher)
            utils->addDepthImage(depth_publisher, *frame, outputs.cutoff, outputs.cutoff_max,
                                 outputs.depth_16uc1, t, out);
          if (frame && cloud_publisher)
            utils->addPointCloud(cloud_publisher, *frame, outputs.cutoff, outputs.cutoff_max, t,
                                 out);
          if (info_due) utils->addInfo(utils->infoPublisher(), t, out);
          if (depth_info_publisher) utils->addInfo(depth_info_publisher, t, out);
        }));
  }

  void reset(World& /*world*/) override {
    gate_.reset();
    info_throttle_.reset();
    depth_info_throttle_.reset();
  }

  std::vector<std::shared_ptr<SensorWork>> takeSensorWork() override {
    return publications_.takeWork();
  }

 private:
  std::shared_ptr<CameraUtils> utils_;
  DepthOutputs outputs_;
  std::shared_ptr<CameraView> view_;
  SensorGate gate_;
  PublishThrottle info_throttle_, depth_info_throttle_;
  ros::Publisher depth_publisher_, depth_info_publisher_, cloud_publisher_;
  PublicationQueue publications_;
};

std::unique_ptr<ModelPlugin> makeDepthCamera(const SensorPluginContext& context, bool kinect,
                                             std::string* error) {
  CameraConfig camera;
  if (!readCameraConfig(context.sensor.xml, &camera, error)) return nullptr;
  if (camera.pixel_format != PixelFormat::Rgb8 && camera.pixel_format != PixelFormat::Bgr8) {
    *error = "<image><format> is '" + camera.format + "': the depth cameras here render "
             "R8G8B8 and B8G8R8 colour images";
    return nullptr;
  }
  auto utils = std::make_shared<CameraUtils>();
  if (!utils->load(context, camera, error)) return nullptr;
  const PluginParams params(context.plugin.plugin_xml, utils->label());
  DepthOutputs outputs;
  outputs.depth_topic = params.text("depthImageTopicName", outputs.depth_topic);
  outputs.depth_info_topic = params.text("depthImageCameraInfoTopicName", outputs.depth_info_topic);
  outputs.cloud_topic = params.text("pointCloudTopicName", outputs.cloud_topic);
  outputs.depth_16uc1 = params.flag("useDepth16UC1Format", false);
  if (!params.number("pointCloudCutoff", 0.4, &outputs.cutoff, error)) return nullptr;
  if (kinect && !params.number("pointCloudCutoffMax", 5.0, &outputs.cutoff_max, error))
    return nullptr;
  if (!kinect)
    ROS_INFO_STREAM(utils->label() << ": publishes its CameraInfo topics, which Gazebo's "
                    << "GazeboRosDepthCamera on Noetic advertises but never publishes");
  return std::make_unique<GazeboRosDepthCamera>(context, camera, std::move(utils), outputs);
}

}  // namespace

std::unique_ptr<ModelPlugin> makeGazeboRosOpenniKinect(const SensorPluginContext& context,
                                                       std::string* error) {
  return makeDepthCamera(context, true, error);
}

std::unique_ptr<ModelPlugin> makeGazeboRosDepthCamera(const SensorPluginContext& context,
                                                      std::string* error) {
  return makeDepthCamera(context, false, error);
}

}  // namespace onedof_sim::plugins
