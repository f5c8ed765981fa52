#include "camera_sensor.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <sstream>
#include <utility>

#include <onedof_sim/pose_math.h>
#include <onedof_sim/trim.h>
#include <ros/console.h>
#include <tinyxml2.h>

#include "sensor_xml.h"

namespace onedof_sim::plugins {
namespace {

// The most pixels a camera may have (4096 x 4096): its frame, read back each update, stays tens
// of megabytes.
constexpr long kMaxPixels = 4096L * 4096L;
// The image noise's table of normal deviates: 2^16 of them.
constexpr int kNoiseBits = 16;
constexpr size_t kNoiseTable = size_t{1} << kNoiseBits;

std::string text(const tinyxml2::XMLElement* element) {
  return trimmed(element ? element->GetText() : nullptr);
}

bool readSize(const tinyxml2::XMLElement* image, const char* tag, int* value, std::string* error) {
  double number = *value;
  if (!readSensorNumber(image, tag, "image", &number, error)) return false;
  if (number < 1 || number != std::floor(number) || number > 16384) {
    *error = "<image><" + std::string(tag) + "> is " + text(image->FirstChildElement(tag)) +
             ", not a count of pixels from 1 to 16384";
    return false;
  }
  *value = static_cast<int>(number);
  return true;
}

// The process's renderer, made on the first call (on the loop's thread); null when it cannot be
// made, said once.
render::Renderer* sharedRenderer() {
  static bool tried = false;
  static render::Renderer* renderer = nullptr;  // kept for the process's life
  if (tried) return renderer;
  tried = true;
  std::string why;
  std::unique_ptr<render::Renderer> made = render::Renderer::create(&why);
  if (!made) {
    ROS_ERROR_STREAM("cameras: no renderer can be made here (" << why << "); camera, depth and "
                     "Kinect sensors publish no images, and everything else runs as before");
    return nullptr;
  }
  ROS_INFO_STREAM("cameras: rendering with OpenGL on " << made->description());
  renderer = made.release();
  return renderer;
}

}  // namespace

bool readCameraConfig(const std::string& sensor_xml, CameraConfig* config, std::string* error) {
  tinyxml2::XMLDocument doc;
  const tinyxml2::XMLElement* camera = requiredSensorChild(sensor_xml, "camera", &doc, error);
  if (!camera) return false;
  CameraConfig c;
  const auto* image = camera->FirstChildElement("image");
  const auto* clip = camera->FirstChildElement("clip");
  if (!readSensorNumber(camera, "horizontal_fov", "camera", &c.horizontal_fov, error) ||
      !readSize(image, "width", &c.width, error) || !readSize(image, "height", &c.height, error) ||
      !readSensorNumber(clip, "near", "clip", &c.near_clip, error) ||
      !readSensorNumber(clip, "far", "clip", &c.far_clip, error))
    return false;
  if (!(c.horizontal_fov > 0 && c.horizontal_fov < M_PI)) {
    *error = "<camera><horizontal_fov> is " + text(camera->FirstChildElement("horizontal_fov")) +
             " rad: a camera is rendered here with a field of view in (0, pi) rad";
    return false;
  }
  if (static_cast<long>(c.width) * c.height > kMaxPixels) {
    *error = "<image> is " + std::to_string(c.width) + " x " + std::to_string(c.height) +
             " pixels, more than the " + std::to_string(kMaxPixels) + " a camera may have";
    return false;
  }
  if (!(c.near_clip > 0 && c.far_clip > c.near_clip)) {
    *error = "<clip> is near " + text(sensorPath(clip, {"near"})) + " far " +
             text(sensorPath(clip, {"far"})) + ": it needs 0 < near < far";
    return false;
  }
  if (const auto* format = sensorPath(image, {"format"})) c.format = text(format);
  if (c.format == "B8G8R8" || c.format == "BGR_INT8") {
    c.bgr = true;
  } else if (c.format != "R8G8B8" && c.format != "RGB_INT8") {
    *error = "<image><format> is '" + c.format + "': the cameras here render R8G8B8 (rgb8) and "
             "B8G8R8 (bgr8) images only";
    return false;
  }
  if (const auto* pose = camera->FirstChildElement("pose")) {
    if (!readPoseText(text(pose), &c.pose)) {
      *error = "<camera><pose> is '" + text(pose) + "', not six numbers";
      return false;
    }
  }
  if (!readNoise(camera->FirstChildElement("noise"), "<camera><noise>", &c.noise, error))
    return false;
  *config = c;
  return true;
}

CameraView::CameraView(const CameraConfig& config, std::string link, const Pose& pose,
                       std::string label, uint64_t seed)
    : config_(config), link_(std::move(link)), pose_(compose(pose, config.pose)),
      label_(std::move(label)), noise_state_(seed | 1) {
  spec_.horizontal_fov = config.horizontal_fov;
  spec_.width = config.width;
  spec_.height = config.height;
  spec_.near_clip = config.near_clip;
  spec_.far_clip = config.far_clip;
  if (config.noise.on && (config.noise.stddev > 0 || config.noise.mean != 0)) {
    NoiseRandom random(seed);
    NoiseModel noise(config.noise, random);
    noise_table_.resize(kNoiseTable);
    for (float& value : noise_table_) value = static_cast<float>(noise.white(random) * 255);
    ROS_INFO_STREAM(label_ << ": its image noise is drawn from a generator seeded with the "
                    << "sensor's name (Gazebo seeds it at random), so runs repeat their images");
  }
}

void CameraView::addNoise() {
  std::vector<uint8_t>& rgb = frame_.rgb;
  for (size_t pixel = 0; pixel + 2 < rgb.size(); pixel += 3) {
    // xorshift64*: the table's index from the generator's top bits.
    noise_state_ ^= noise_state_ >> 12;
    noise_state_ ^= noise_state_ << 25;
    noise_state_ ^= noise_state_ >> 27;
    const float noise = noise_table_[(noise_state_ * 2685821657736338717ull) >> (64 - kNoiseBits)];
    for (size_t c = pixel; c < pixel + 3; ++c)
      rgb[c] = static_cast<uint8_t>(std::clamp(std::lround(rgb[c] + noise), 0L, 255L));
  }
}

bool CameraView::render(const World& world) {
  render::Renderer* renderer = sharedRenderer();
  if (!renderer) return false;
  Pose link_pose;
  Twist unused;
  const Status status = world.linkState(link_, "", &link_pose, &unused);
  std::string why;
  if (!status.ok()) {
    std::ostringstream text;
    text << status;
    why = "its link's pose: " + text.str();
  } else {
    spec_.pose = compose(link_pose, pose_);
    if (renderer->render(world.visualShapes(), spec_, &frame_, &why)) {
      if (!noise_table_.empty()) addNoise();
      for (const std::string& problem : renderer->takeProblems())
        ROS_WARN_STREAM("cameras: " << problem);
      return true;
    }
  }
  if (!failed_) ROS_ERROR_STREAM(label_ << " rendered no frame: " << why);
  failed_ = true;
  return false;
}

}  // namespace onedof_sim::plugins
