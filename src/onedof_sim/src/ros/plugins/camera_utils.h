// What gazebo_plugins' GazeboRosCameraUtils is to its camera plugins: the <plugin>'s parameters,
// the node in <robotNamespace>/<cameraName>, the image and camera_info publishers, CameraInfo as
// Gazebo computes it, and the depth image and point cloud its depth plugins fill from a frame.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include <boost/shared_ptr.hpp>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud2.h>

#include "model_plugin.h"
#include "sensor_plugin.h"
#include "sensors/camera_sensor.h"
#include "sensors/update_gate.h"

namespace onedof_sim::plugins {

// GazeboRosCameraUtils' parameters and publishers for one camera sensor.
class CameraUtils {
 public:
  // Reads the <plugin> (its image and camera_info topics defaulting to image_raw and
  // camera_info) and advertises them; false, with *error, when a parameter is malformed.
  // name_suffix follows <cameraName> in the topics' namespace and hack_baseline, when given,
  // stands for <hackBaseline> (a multicamera's left and right cameras: "/left", 0).
  bool load(const SensorPluginContext& context, const CameraConfig& camera, std::string* error,
            const std::string& name_suffix = "",
            std::optional<double> hack_baseline = std::nullopt);

  // The sensor's gate: its <update_rate>, or where that is 0 (Gazebo then renders as fast as
  // its render loop goes, a wall-clock rate) the plugin's <updateRate>, else 30 Hz; said once.
  SensorGate sensorGate(const SensorPluginContext& context) const;

  ros::NodeHandle& node() { return node_; }
  const std::string& label() const { return label_; }
  double updateRate() const { return update_rate_; }
  bool imageWanted() const { return image_publisher_.getNumSubscribers() > 0; }
  bool infoWanted() const { return info_publisher_.getNumSubscribers() > 0; }

  // The frame as the image message in the camera's format's encoding, stamped, queued.
  void addImage(const render::Frame& frame, int64_t time_ns, PublicationQueue* out);
  // CameraInfo stamped at time_ns, queued on `publisher` (the camera's, or a depth one's).
  void addInfo(const ros::Publisher& publisher, int64_t time_ns, PublicationQueue* out) const;
  const ros::Publisher& infoPublisher() const { return info_publisher_; }
  const std::string& cameraName() const { return camera_name_; }

  // Gazebo's depth plugins' outputs from a frame: depth in metres (32FC1) and the point cloud in
  // the optical frame (x y z, rgb from the image's bytes), NaN at depths not within
  // (cutoff, cutoff_max).
  // millimetres: 16UC1, 0 outside the cutoffs (Gazebo's <useDepth16UC1Format>).
  void addDepthImage(const ros::Publisher& publisher, const render::Frame& frame, double cutoff,
                     double cutoff_max, bool millimetres, int64_t time_ns, PublicationQueue* out);
  void addPointCloud(const ros::Publisher& publisher, const render::Frame& frame, double cutoff,
                     double cutoff_max, int64_t time_ns, PublicationQueue* out);

 private:
  std::string label_;
  std::string camera_name_;  // <cameraName> and the suffix
  ros::NodeHandle node_;
  std::string frame_id_;
  double update_rate_ = 0;
  PixelFormat format_ = PixelFormat::Rgb8;
  double horizontal_fov_ = 1.047;
  sensor_msgs::CameraInfo info_;
  ros::Publisher image_publisher_, info_publisher_;
  // The last messages sent, filled again in place once the publisher has let them go.
  boost::shared_ptr<sensor_msgs::Image> image_, depth_image_;
  boost::shared_ptr<sensor_msgs::PointCloud2> cloud_;
};

}  // namespace onedof_sim::plugins
