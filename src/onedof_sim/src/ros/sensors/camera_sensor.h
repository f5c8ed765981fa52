// Gazebo's camera, multicamera and depth sensors (`camera`, `multicamera`, `depth`): the
// <camera> elements of a <sensor>, and their frames rendered from the world's visuals with the
// process's one renderer (src/render/), through the lens's distortion when it has one. The
// camera plugins (gazebo_ros_camera.cpp, _multicamera.cpp, _triggered_camera.cpp,
// _openni_kinect.cpp) publish what they see.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <onedof_sim/world.h>

#include "lens_distortion.h"
#include "plugins/model_plugin.h"
#include "renderer.h"
#include "sensor_noise.h"

namespace onedof_sim::plugins {

// The <image><format>s of Gazebo's cameras that gazebo_ros_camera_utils publishes, by the
// image it becomes.
enum class PixelFormat {
  Rgb8,    // R8G8B8, RGB_INT8
  Bgr8,    // B8G8R8, BGR_INT8
  Mono8,   // L8, L_INT8
  Rgb16,   // R16G16B16, RGB_INT16, RGB_UINT16
  Mono16,  // L16, L_INT16, L_UINT16
  BayerRggb8, BayerBggr8, BayerGbrg8, BayerGrbg8,  // BAYER_RGGB8, ...
};

// Its sensor_msgs encoding (sensor_msgs/image_encodings.h's name), bytes a pixel, and whether it
// is rendered with 16 bits a channel.
const char* encodingOf(PixelFormat format);
int bytesPerPixel(PixelFormat format);
bool sixteenBits(PixelFormat format);

// The frame's pixels (Frame::rgb, or rgb16 for a 16-bit format) in the format's encoding, row
// after row, bytesPerPixel(format) * width a row, 16-bit values little-endian: mono the luma
// (ITU-R BT.601's weights), Bayer each pixel's one channel of its 2 x 2 pattern as the encoding
// names it (bayer_rggb8: red at row 0, column 0).
void encodePixels(PixelFormat format, const render::Frame& frame, uint8_t* out);

// A <camera>, with SDF's defaults.
struct CameraConfig {
  std::string name = "__default__";  // <camera name="...">
  double horizontal_fov = 1.047;  // rad
  int width = 320, height = 240;  // <image>
  std::string format = "R8G8B8";  // <image><format>, as given
  PixelFormat pixel_format = PixelFormat::Rgb8;
  double near_clip = 0.1, far_clip = 100;  // <clip>
  Pose pose;  // <camera><pose>, on the sensor's
  // <noise>, in [0, 1] of a channel: its mean and stddev, as Gazebo's image noise takes them
  // (no bias nor precision).
  NoiseParams noise;
  render::DistortionCoefficients distortion;  // <distortion>; none(): a pinhole

  // The focal length in pixels: width / (2 tan(hfov / 2)).
  double focalPixels() const;
};

// Reads the first <camera> of a <sensor> element (its XML text); false, with *error naming what
// is wrong, when it is malformed or cannot be rendered here.
bool readCameraConfig(const std::string& sensor_xml, CameraConfig* config, std::string* error);
// Every <camera> of a <sensor> (a multicamera's), in document order; the error names the camera.
bool readCameraConfigs(const std::string& sensor_xml, std::vector<CameraConfig>* configs,
                       std::string* error);

// One camera's view: renders its frame where its link is, through the renderer the process
// shares (made on the sensor thread at the first frame, kept for the process's life, as every
// frame is rendered on that thread: sensor_thread.h). When the renderer cannot be made (no EGL),
// that is logged once for all cameras and no camera renders.
class CameraView {
 public:
  // link: scoped "model::link"; pose: the sensor's on it; label: the camera in what is logged;
  // seed: its image noise's.
  CameraView(const CameraConfig& config, std::string link, const Pose& pose, std::string label,
             uint64_t seed);

  // Takes the world's visuals and the camera's pose as they are now, world locked; false when
  // no frame can be rendered (no renderer, or the link's pose is not to be had; logged once).
  bool capture(const World& world);
  // Renders what capture took into frame() (rgb, or rgb16 for a 16-bit format), through its
  // lens, its image noise added, the world unlocked, on the sensor thread; false when it cannot
  // (logged once).
  bool renderCaptured();

  const render::Frame& frame() const { return frame_; }
  const CameraConfig& config() const { return config_; }

 private:
  CameraConfig config_;
  std::string link_;
  Pose pose_;  // the camera frame on the link: the sensor's pose and <camera><pose>
  std::string label_;
  render::CameraSpec spec_;  // the pinhole render: the image's, or the lens's wider one
  std::vector<VisualShape> scene_;  // what capture took
  std::unique_ptr<render::LensDistortion> lens_;  // null: a pinhole
  render::Frame rendered_;  // the lens's wider pinhole render
  render::Frame frame_;  // reused: the renderer resizes it only when the size changes
  bool failed_ = false;  // logged once
  // Gazebo's image noise: one value a pixel a frame, N(mean, stddev), added to its three
  // channels and clamped, as Gazebo's GaussianNoise compositor adds it. Drawn from a table of
  // deviates the noise model (NoiseModel::white) makes once from the seed (in channel units),
  // indexed by a xorshift generator: a table lookup a pixel, where drawing each afresh would
  // cost more than the frame. After the lens, as a sensor's noise is its pixels'.
  std::vector<float> noise_table_;
  uint64_t noise_state_ = 0;
  void addNoise();
};

// A camera's frame as sensor work (model_plugin.h): the view captured by the plugin's hook, or
// not (render false: no image wanted, or none to be had), is rendered unlocked; then `publish`
// queues the messages, with the frame or null. What publish uses it holds (not the plugin).
std::shared_ptr<SensorWork> frameWork(
    std::shared_ptr<CameraView> view, bool render,
    std::function<void(const render::Frame* frame, PublicationQueue* out)> publish);

}  // namespace onedof_sim::plugins
