#include "camera_utils.h"

#include <cmath>
#include <cstring>
#include <limits>

#include <boost/make_shared.hpp>
#include <ros/console.h>
#include <sensor_msgs/PointField.h>
#include <sensor_msgs/image_encodings.h>

#include "plugin_params.h"

namespace onedof_sim::plugins {
namespace {

// A sensor with no <update_rate> and a plugin with no <updateRate>: a camera's usual rate.
constexpr double kDefaultCameraRate = 30;

// The message in `slot` to fill: the last one sent when the publisher has let it go (no per-frame
// allocation of megabytes), else a new one.
template <class Message>
Message& reusable(boost::shared_ptr<Message>& slot) {
  if (!slot || slot.use_count() > 1) slot = boost::make_shared<Message>();
  return *slot;
}

void stamp(std_msgs::Header* header, const std::string& frame_id, int64_t time_ns) {
  header->frame_id = frame_id;
  header->stamp.fromNSec(static_cast<uint64_t>(time_ns));
}

}  // namespace

bool CameraUtils::load(const SensorPluginContext& context, const CameraConfig& camera,
                       std::string* error, const std::string& name_suffix,
                       std::optional<double> hack_baseline) {
  label_ = context.plugin.filename + " of sensor '" + context.sensor.name + "' (model '" +
           context.plugin.model + "')";
  const PluginParams params(context.plugin.plugin_xml, label_);
  // gazebo_ros's GetRobotNamespace: an empty <robotNamespace> means the model's name.
  std::string robot_namespace = context.plugin.robot_namespace;
  if (params.has("robotNamespace") && robot_namespace.empty())
    robot_namespace = context.plugin.model;
  camera_name_ = params.text("cameraName", "") + name_suffix;
  double baseline = 0, focal_length = 0, cx = 0, cy = 0, cx_prime = 0;
  double k1 = 0, k2 = 0, k3 = 0, t1 = 0, t2 = 0;
  if (!params.number("updateRate", 0, &update_rate_, error) ||
      !params.number("hackBaseline", 0, &baseline, error) ||
      !params.number("focalLength", 0, &focal_length, error) ||
      !params.number("Cx", 0, &cx, error) || !params.number("Cy", 0, &cy, error) ||
      !params.number("CxPrime", 0, &cx_prime, error) ||
      !params.number("distortionK1", 0, &k1, error) ||
      !params.number("distortionK2", 0, &k2, error) ||
      !params.number("distortionK3", 0, &k3, error) ||
      !params.number("distortionT1", 0, &t1, error) ||
      !params.number("distortionT2", 0, &t2, error))
    return false;
  if (hack_baseline) baseline = *hack_baseline;
  if (update_rate_ < 0) {
    *error = "<updateRate> is " + std::to_string(update_rate_) + ", not a rate >= 0";
    return false;
  }
  // <autoDistortion>: CameraInfo's D from the lens's <distortion>, where the image's
  // distortion comes from, instead of the distortion parameters.
  if (params.flag("autoDistortion", false)) {
    const render::DistortionCoefficients& lens = camera.distortion;
    k1 = lens.k1, k2 = lens.k2, k3 = lens.k3, t1 = lens.p1, t2 = lens.p2;
  }
  if (camera.distortion.k1 < 0 && params.flag("borderCrop", true))
    ROS_INFO_STREAM(label_ << ": its barrel distortion's image is not cropped and scaled "
                    << "(<borderCrop>, Gazebo's in its legacy distortion mode): the lens sees "
                    << "past the pinhole's field of view, as a real one does, and CameraInfo's "
                    << "K and D describe the image");
  node_ = ros::NodeHandle(robot_namespace + "/" + camera_name_);
  frame_id_ = resolveTfFrame(tfPrefix(node_), params.text("frameName", ""));
  format_ = camera.pixel_format;
  horizontal_fov_ = camera.horizontal_fov;

  // Gazebo's CameraInfo: the focal length from the field of view and the width (fx = fy), the
  // principal point at ((width + 1) / 2, (height + 1) / 2) unless given, plumb_bob distortion
  // as given (not applied to the image), no rectification, and the baseline in P[3].
  const double computed_focal = camera.width / (2 * std::tan(camera.horizontal_fov / 2));
  if (focal_length == 0) {
    focal_length = computed_focal;
  } else if (std::abs(focal_length - computed_focal) > 1e-6) {
    ROS_WARN_STREAM(label_ << ": <focalLength> " << focal_length << " is inconsistent with the "
                    << "image width " << camera.width << " and horizontal_fov "
                    << camera.horizontal_fov << " (width / (2 tan(hfov / 2)) = " << computed_focal
                    << "); CameraInfo carries the one given, the image is rendered from the "
                    << "field of view, as in Gazebo");
  }
  if (cx == 0) cx = (camera.width + 1.0) / 2;
  if (cy == 0) cy = (camera.height + 1.0) / 2;
  (void)cx_prime;  // read as Gazebo reads it; its CameraInfo uses Cx for both matrices
  info_.header.frame_id = frame_id_;
  info_.width = static_cast<uint32_t>(camera.width);
  info_.height = static_cast<uint32_t>(camera.height);
  info_.distortion_model = "plumb_bob";
  info_.D = {k1, k2, t1, t2, k3};
  info_.K = {focal_length, 0, cx, 0, focal_length, cy, 0, 0, 1};
  info_.R = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  info_.P = {focal_length, 0, cx, -focal_length * baseline, 0, focal_length, cy, 0, 0, 0, 1, 0};

  image_publisher_ = node_.advertise<sensor_msgs::Image>(
      params.text("imageTopicName", "image_raw"), 2);
  info_publisher_ = node_.advertise<sensor_msgs::CameraInfo>(
      params.text("cameraInfoTopicName", "camera_info"), 2);
  return true;
}

SensorGate CameraUtils::sensorGate(const SensorPluginContext& context) const {
  if (context.sensor.update_rate > 0) return SensorGate(context.sensor.update_rate);
  const double rate = update_rate_ > 0 ? update_rate_ : kDefaultCameraRate;
  ROS_INFO_STREAM(label_ << ": the sensor has no <update_rate> (Gazebo renders it as often as "
                  << "its render loop runs, in wall time); it renders at " << rate
                  << " Hz of sim time here, " << (update_rate_ > 0 ? "the plugin's <updateRate>"
                                                                   : "a camera's usual rate"));
  return SensorGate(rate);
}

void CameraUtils::addImage(const render::Frame& frame, int64_t time_ns, PublicationQueue* out) {
  sensor_msgs::Image& image = reusable(image_);
  stamp(&image.header, frame_id_, time_ns);
  image.height = static_cast<uint32_t>(frame.height);
  image.width = static_cast<uint32_t>(frame.width);
  image.encoding = encodingOf(format_);
  image.is_bigendian = 0;
  image.step = static_cast<uint32_t>(frame.width * bytesPerPixel(format_));
  image.data.resize(static_cast<size_t>(image.step) * frame.height);
  encodePixels(format_, frame, image.data.data());
  out->add(image_publisher_, image_);
}

void CameraUtils::addInfo(const ros::Publisher& publisher, int64_t time_ns,
                          PublicationQueue* out) const {
  sensor_msgs::CameraInfo info = info_;
  info.header.stamp.fromNSec(static_cast<uint64_t>(time_ns));
  out->add(publisher, info);
}

void CameraUtils::addDepthImage(const ros::Publisher& publisher, const render::Frame& frame,
                                double cutoff, double cutoff_max, bool millimetres,
                                int64_t time_ns, PublicationQueue* out) {
  sensor_msgs::Image& image = reusable(depth_image_);
  stamp(&image.header, frame_id_, time_ns);
  image.height = static_cast<uint32_t>(frame.height);
  image.width = static_cast<uint32_t>(frame.width);
  image.encoding = millimetres ? sensor_msgs::image_encodings::TYPE_16UC1
                               : sensor_msgs::image_encodings::TYPE_32FC1;
  image.is_bigendian = 0;
  const size_t bytes = millimetres ? sizeof(uint16_t) : sizeof(float);
  image.step = static_cast<uint32_t>(frame.width * bytes);
  image.data.resize(frame.depth.size() * bytes);
  if (millimetres) {
    uint16_t* to = reinterpret_cast<uint16_t*>(image.data.data());
    for (size_t i = 0; i < frame.depth.size(); ++i) {
      const float depth = frame.depth[i];
      // Gazebo's conversion: the metres times 1000, truncated to an integer.
      to[i] = depth > cutoff && depth < cutoff_max ? static_cast<uint16_t>(depth * 1000.0) : 0;
    }
  } else {
    float* to = reinterpret_cast<float*>(image.data.data());
    const float nan = std::numeric_limits<float>::quiet_NaN();
    for (size_t i = 0; i < frame.depth.size(); ++i) {
      const float depth = frame.depth[i];
      to[i] = depth > cutoff && depth < cutoff_max ? depth : nan;
    }
  }
  out->add(publisher, depth_image_);
}

void CameraUtils::addPointCloud(const ros::Publisher& publisher, const render::Frame& frame,
                                double cutoff, double cutoff_max, int64_t time_ns,
                                PublicationQueue* out) {
  // Gazebo's layout (PointCloud2Modifier's "xyz", "rgb"): x, y, z as float32 at 0, 4, 8, four
  // bytes of padding, rgb at 16 holding the image message's three bytes in its order (R, G, B
  // for rgb8: the float PCL reads as B, G, R, so rviz shows Gazebo's R8G8B8 clouds with red and
  // blue swapped), then twelve bytes of padding: 32 bytes a point.
  constexpr uint32_t kPointStep = 32;
  sensor_msgs::PointCloud2& cloud = reusable(cloud_);
  stamp(&cloud.header, frame_id_, time_ns);
  if (cloud.fields.size() != 4) {
    cloud.fields.resize(4);
    const char* names[] = {"x", "y", "z", "rgb"};
    const uint32_t offsets[] = {0, 4, 8, 16};
    for (int i = 0; i < 4; ++i) {
      cloud.fields[i].name = names[i];
      cloud.fields[i].offset = offsets[i];
      cloud.fields[i].datatype = sensor_msgs::PointField::FLOAT32;
      cloud.fields[i].count = 1;
    }
  }
  const int width = frame.width, height = frame.height;
  cloud.height = static_cast<uint32_t>(height);
  cloud.width = static_cast<uint32_t>(width);
  cloud.is_bigendian = false;
  cloud.point_step = kPointStep;
  cloud.row_step = kPointStep * cloud.width;
  // Padding stays zero: a reused cloud's padding bytes were never written.
  cloud.data.resize(static_cast<size_t>(cloud.row_step) * cloud.height);
  cloud.is_dense = true;
  // Gazebo's rays: pixel (i, j) looks along (tan yAngle, tan pAngle, 1) in the optical frame,
  // with yAngle = atan2(i - (width - 1) / 2, f) and pAngle likewise down the rows; f from the
  // field of view, as the frame was rendered.
  const double f = width / (2 * std::tan(horizontal_fov_ / 2));
  const float nan = std::numeric_limits<float>::quiet_NaN();
  uint8_t* point = cloud.data.data();
  for (int j = 0; j < height; ++j) {
    const double down = height > 1 ? (j - 0.5 * (height - 1)) / f : 0;
    for (int i = 0; i < width; ++i, point += kPointStep) {
      const double right = width > 1 ? (i - 0.5 * (width - 1)) / f : 0;
      const size_t pixel = static_cast<size_t>(j) * width + i;
      const double depth = frame.depth[pixel];
      float xyz[3];
      if (depth > cutoff && depth < cutoff_max) {
        xyz[0] = static_cast<float>(depth * right);
        xyz[1] = static_cast<float>(depth * down);
        xyz[2] = static_cast<float>(depth);
      } else {
        xyz[0] = xyz[1] = xyz[2] = nan;
        cloud.is_dense = false;
      }
      std::memcpy(point, xyz, sizeof(xyz));
      const uint8_t* rgb = &frame.rgb[pixel * 3];
      const bool bgr = format_ == PixelFormat::Bgr8;
      point[16] = bgr ? rgb[2] : rgb[0];
      point[17] = rgb[1];
      point[18] = bgr ? rgb[0] : rgb[2];
    }
  }
  out->add(publisher, cloud_);
}

}  // namespace onedof_sim::plugins
