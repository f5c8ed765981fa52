#include "camera_sensor.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <random>
#include <sstream>
#include <utility>

#include <onedof_sim/pose_math.h>
#include <onedof_sim/trim.h>
#include <ros/console.h>
#include <tinyxml2.h>

#include "sensor_thread.h"
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

// The process's renderer, made on the first call (on the sensor thread, where every frame is
// rendered: sensor_thread.h); null when it cannot be made, said once. The loop reads `tried`
// only while the sensor thread waits for work (noRenderer).
bool renderer_tried = false;
render::Renderer* renderer = nullptr;  // kept for the process's life

render::Renderer* sharedRenderer() {
  if (renderer_tried) return renderer;
  renderer_tried = true;
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

// Whether the renderer was tried and cannot be made: no frame is to be had.
bool noRenderer() { return renderer_tried && !renderer; }

}  // namespace

const char* encodingOf(PixelFormat format) {
  switch (format) {
    case PixelFormat::Rgb8: return "rgb8";
    case PixelFormat::Bgr8: return "bgr8";
    case PixelFormat::Mono8: return "mono8";
    case PixelFormat::Rgb16: return "rgb16";
    case PixelFormat::Mono16: return "mono16";
    case PixelFormat::BayerRggb8: return "bayer_rggb8";
    case PixelFormat::BayerBggr8: return "bayer_bggr8";
    case PixelFormat::BayerGbrg8: return "bayer_gbrg8";
    case PixelFormat::BayerGrbg8: return "bayer_grbg8";
  }
  return "";
}

int bytesPerPixel(PixelFormat format) {
  switch (format) {
    case PixelFormat::Rgb8:
    case PixelFormat::Bgr8: return 3;
    case PixelFormat::Rgb16: return 6;
    case PixelFormat::Mono16: return 2;
    default: return 1;
  }
}

bool sixteenBits(PixelFormat format) {
  return format == PixelFormat::Rgb16 || format == PixelFormat::Mono16;
}

namespace {

// ITU-R BT.601's luma, rounded.
template <class Channel>
uint32_t luma(const Channel* rgb) {
  return (299u * rgb[0] + 587u * rgb[1] + 114u * rgb[2] + 500u) / 1000u;
}

// Which channel each pixel of a Bayer pattern keeps: [row % 2][column % 2].
using BayerPattern = int[2][2];
const BayerPattern& bayerPattern(PixelFormat format) {
  static const BayerPattern rggb = {{0, 1}, {1, 2}}, bggr = {{2, 1}, {1, 0}},
                            gbrg = {{1, 2}, {0, 1}}, grbg = {{1, 0}, {2, 1}};
  switch (format) {
    case PixelFormat::BayerBggr8: return bggr;
    case PixelFormat::BayerGbrg8: return gbrg;
    case PixelFormat::BayerGrbg8: return grbg;
    default: return rggb;
  }
}

}  // namespace

void encodePixels(PixelFormat format, const render::Frame& frame, uint8_t* out) {
  const size_t pixels = static_cast<size_t>(frame.width) * frame.height;
  const uint8_t* rgb = frame.rgb.data();
  const uint16_t* rgb16 = frame.rgb16.data();
  const auto put16 = [](uint32_t value, uint8_t* to) {
    to[0] = static_cast<uint8_t>(value & 0xff);
    to[1] = static_cast<uint8_t>(value >> 8);
  };
  switch (format) {
    case PixelFormat::Rgb8:
      std::copy_n(rgb, pixels * 3, out);
      return;
    case PixelFormat::Bgr8:
      for (size_t i = 0; i < pixels; ++i, rgb += 3, out += 3)
        out[0] = rgb[2], out[1] = rgb[1], out[2] = rgb[0];
      return;
    case PixelFormat::Mono8:
      for (size_t i = 0; i < pixels; ++i, rgb += 3) out[i] = static_cast<uint8_t>(luma(rgb));
      return;
    case PixelFormat::Rgb16:
      for (size_t i = 0; i < pixels * 3; ++i) put16(rgb16[i], out + 2 * i);
      return;
    case PixelFormat::Mono16:
      for (size_t i = 0; i < pixels; ++i, rgb16 += 3) put16(luma(rgb16), out + 2 * i);
      return;
    default: {
      const BayerPattern& pattern = bayerPattern(format);
      for (int row = 0; row < frame.height; ++row)
        for (int col = 0; col < frame.width; ++col, rgb += 3)
          *out++ = rgb[pattern[row % 2][col % 2]];
    }
  }
}

double CameraConfig::focalPixels() const { return width / (2 * std::tan(horizontal_fov / 2)); }

namespace {

// Gazebo's format names (rendering::Camera's), by the format each is.
bool readPixelFormat(const std::string& name, PixelFormat* format) {
  static const std::pair<const char*, PixelFormat> names[] = {
      {"R8G8B8", PixelFormat::Rgb8},         {"RGB_INT8", PixelFormat::Rgb8},
      {"B8G8R8", PixelFormat::Bgr8},         {"BGR_INT8", PixelFormat::Bgr8},
      {"L8", PixelFormat::Mono8},            {"L_INT8", PixelFormat::Mono8},
      {"R16G16B16", PixelFormat::Rgb16},     {"RGB_INT16", PixelFormat::Rgb16},
      {"RGB_UINT16", PixelFormat::Rgb16},    {"L16", PixelFormat::Mono16},
      {"L_INT16", PixelFormat::Mono16},      {"L_UINT16", PixelFormat::Mono16},
      {"BAYER_RGGB8", PixelFormat::BayerRggb8}, {"BAYER_BGGR8", PixelFormat::BayerBggr8},
      {"BAYER_GBRG8", PixelFormat::BayerGbrg8}, {"BAYER_GRBG8", PixelFormat::BayerGrbg8}};
  for (const auto& [known, value] : names)
    if (name == known) {
      *format = value;
      return true;
    }
  return false;
}

bool readDistortion(const tinyxml2::XMLElement* distortion, render::DistortionCoefficients* lens,
                    std::string* error) {
  if (!distortion) return true;
  render::DistortionCoefficients d;
  for (const auto& [tag, value] : {std::pair{"k1", &d.k1}, std::pair{"k2", &d.k2},
                                   std::pair{"k3", &d.k3}, std::pair{"p1", &d.p1},
                                   std::pair{"p2", &d.p2}})
    if (!readSensorNumber(distortion, tag, "distortion", value, error)) return false;
  if (const auto* center = distortion->FirstChildElement("center")) {
    std::istringstream in(text(center));
    std::string rest;
    if (!(in >> d.center_x >> d.center_y) || (in >> rest) ||
        !std::isfinite(d.center_x + d.center_y)) {
      *error = "<distortion><center> is '" + text(center) + "', not two numbers";
      return false;
    }
  }
  *lens = d;
  return true;
}

// One <camera> element.
bool readCamera(const tinyxml2::XMLElement* camera, CameraConfig* config, std::string* error) {
  CameraConfig c;
  if (const char* name = camera->Attribute("name")) c.name = name;
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
    std::ostringstream what;
    what << "<clip> is near " << c.near_clip << " far " << c.far_clip
         << ": it needs 0 < near < far";
    *error = what.str();
    return false;
  }
  if (const auto* format = sensorPath(image, {"format"})) c.format = text(format);
  if (!readPixelFormat(c.format, &c.pixel_format)) {
    *error = "<image><format> is '" + c.format + "': gazebo_ros's cameras publish R8G8B8, "
             "B8G8R8, L8, R16G16B16, L16 and BAYER_RGGB8, _BGGR8, _GBRG8, _GRBG8 images";
    return false;
  }
  if (const auto* pose = camera->FirstChildElement("pose")) {
    if (!readPoseText(text(pose), &c.pose)) {
      *error = "<camera><pose> is '" + text(pose) + "', not six numbers";
      return false;
    }
  }
  if (!readNoise(camera->FirstChildElement("noise"), "<camera><noise>", &c.noise, error) ||
      !readDistortion(camera->FirstChildElement("distortion"), &c.distortion, error))
    return false;
  *config = c;
  return true;
}

}  // namespace

bool readCameraConfig(const std::string& sensor_xml, CameraConfig* config, std::string* error) {
  tinyxml2::XMLDocument doc;
  const tinyxml2::XMLElement* camera = requiredSensorChild(sensor_xml, "camera", &doc, error);
  return camera && readCamera(camera, config, error);
}

bool readCameraConfigs(const std::string& sensor_xml, std::vector<CameraConfig>* configs,
                       std::string* error) {
  tinyxml2::XMLDocument doc;
  configs->clear();
  for (const tinyxml2::XMLElement* camera = requiredSensorChild(sensor_xml, "camera", &doc, error);
       camera;
       camera = camera->NextSiblingElement("camera")) {
    CameraConfig config;
    if (!readCamera(camera, &config, error)) {
      const char* name = camera->Attribute("name");
      *error = "camera '" + std::string(name ? name : config.name) + "': " + *error;
      configs->clear();
      return false;
    }
    configs->push_back(config);
  }
  return !configs->empty();
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
  spec_.channel_bits = sixteenBits(config.pixel_format) ? 16 : 8;
  if (!config.distortion.none()) {
    lens_ = std::make_unique<render::LensDistortion>(config.distortion, config.width,
                                                     config.height, config.focalPixels(),
                                                     kMaxPixels);
    spec_.width = lens_->renderWidth();
    spec_.height = lens_->renderHeight();
    spec_.horizontal_fov = lens_->renderHorizontalFov();
    ROS_INFO_STREAM(label_ << ": its lens distortion is applied to a pinhole render of "
                    << spec_.width << " x " << spec_.height << " pixels"
                    << (lens_->blackPixels() > 0
                            ? ", " + std::to_string(lens_->blackPixels()) +
                                  " of the image's pixels black where the lens sees past it"
                            : std::string()));
  }
  const NoiseParams& noise = config.noise;
  if (noise.on && (noise.stddev > 0 || noise.mean != 0)) {
    const double full_scale = spec_.channel_bits == 16 ? 65535 : 255;
    NoiseRandom random(seed);
    NoiseModel model(noise, random);
    noise_table_.resize(kNoiseTable);
    for (float& value : noise_table_) value = static_cast<float>(model.white(random) * full_scale);
    ROS_INFO_STREAM(label_ << ": its image noise is drawn from a generator seeded with the "
                    << "sensor's name (Gazebo seeds it at random), so runs repeat their images");
  }
}

namespace {

// Adds one value of `noise` a pixel to its three channels, clamped to the channel's range.
template <class Channel, class Draw>
void addPixelNoise(std::vector<Channel>* rgb, Draw draw) {
  constexpr long kTop = std::numeric_limits<Channel>::max();
  Channel* c = rgb->data();
  for (size_t pixel = 0; pixel + 2 < rgb->size(); pixel += 3, c += 3) {
    const float noise = draw();
    for (int k = 0; k < 3; ++k)
      c[k] = static_cast<Channel>(std::clamp(std::lround(c[k] + noise), 0L, kTop));
  }
}

}  // namespace

void CameraView::addNoise() {
  const auto draw = [this] {
    // xorshift64*: the table's index from the generator's top bits.
    noise_state_ ^= noise_state_ >> 12;
    noise_state_ ^= noise_state_ << 25;
    noise_state_ ^= noise_state_ >> 27;
    return noise_table_[(noise_state_ * 2685821657736338717ull) >> (64 - kNoiseBits)];
  };
  if (spec_.channel_bits == 16)
    addPixelNoise(&frame_.rgb16, draw);
  else
    addPixelNoise(&frame_.rgb, draw);
}

bool CameraView::capture(const World& world) {
  if (noRenderer()) return false;
  Pose link_pose;
  Twist unused;
  const Status status = world.linkState(link_, "", &link_pose, &unused);
  if (!status.ok()) {
    std::ostringstream text;
    text << status;
    if (!failed_) ROS_ERROR_STREAM(label_ << " rendered no frame: its link's pose: " << text.str());
    failed_ = true;
    return false;
  }
  spec_.pose = compose(link_pose, pose_);
  scene_ = world.visualShapes();
  return true;
}

bool CameraView::renderCaptured() {
  render::Renderer* renderer = sharedRenderer();
  if (!renderer) return false;  // said once, by sharedRenderer
  std::string why;
  if (renderer->render(scene_, spec_, lens_ ? &rendered_ : &frame_, &why)) {
    if (lens_) lens_->apply(rendered_, &frame_);
    if (!noise_table_.empty()) addNoise();
    for (const std::string& problem : renderer->takeProblems())
      ROS_WARN_STREAM("cameras: " << problem);
    return true;
  }
  if (!failed_) ROS_ERROR_STREAM(label_ << " rendered no frame: " << why);
  failed_ = true;
  return false;
}

namespace {

class FrameWork : public SensorWork {
 public:
  FrameWork(std::shared_ptr<CameraView> view, bool render,
            std::function<void(const render::Frame*, PublicationQueue*)> publish)
      : view_(std::move(view)), render_(render), publish_(std::move(publish)) {}

  // The render and the messages' making (the image's encoding) on the sensor thread; their
  // publishing is left to the loop, at the process's priority: publishing takes roscpp's topic
  // lock, which its network thread takes too, and a low-priority holder would keep it waiting.
  std::vector<Publication> withoutWorld() override {
    PublicationQueue out;
    onSensorThread([this, &out] {
      const bool rendered = render_ && view_->renderCaptured();
      publish_(rendered ? &view_->frame() : nullptr, &out);
    });
    return out.take();
  }

 private:
  std::shared_ptr<CameraView> view_;
  bool render_;
  std::function<void(const render::Frame*, PublicationQueue*)> publish_;
};

}  // namespace

std::shared_ptr<SensorWork> frameWork(
    std::shared_ptr<CameraView> view, bool render,
    std::function<void(const render::Frame* frame, PublicationQueue* out)> publish) {
  return std::make_shared<FrameWork>(std::move(view), render, std::move(publish));
}

}  // namespace onedof_sim::plugins
