// Gazebo's camera and depth sensors (`camera`, `depth`): the <camera> element of a <sensor>, and
// its frames rendered from the world's visuals with the process's one renderer (src/render/).
// The camera plugins (gazebo_ros_camera.cpp, gazebo_ros_openni_kinect.cpp) publish what it sees.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <onedof_sim/world.h>

#include "renderer.h"
#include "sensor_noise.h"

namespace onedof_sim::plugins {

// <camera>, with SDF's defaults.
struct CameraConfig {
  double horizontal_fov = 1.047;  // rad
  int width = 320, height = 240;  // <image>
  std::string format = "R8G8B8";  // <image><format>
  bool bgr = false;               // the format's bytes are blue, green, red (B8G8R8)
  double near_clip = 0.1, far_clip = 100;  // <clip>
  Pose pose;  // <camera><pose>, on the sensor's
  // <noise>, in [0, 1] of a channel: its mean and stddev, as Gazebo's image noise takes them
  // (no bias nor precision).
  NoiseParams noise;
};

// Reads the <camera> of a <sensor> element (its XML text); false, with *error naming what is
// wrong, when it is malformed or cannot be rendered here.
bool readCameraConfig(const std::string& sensor_xml, CameraConfig* config, std::string* error);

// One camera's view: renders its frame where its link is, through the renderer the process
// shares (made on the loop's thread at the first frame, kept for the process's life, as every
// frame is rendered on that thread). When the renderer cannot be made (no EGL), that is logged
// once for all cameras and no camera renders.
class CameraView {
 public:
  // link: scoped "model::link"; pose: the sensor's on it; label: the camera in what is logged;
  // seed: its image noise's.
  CameraView(const CameraConfig& config, std::string link, const Pose& pose, std::string label,
             uint64_t seed);

  // Renders the world as the camera sees it now into frame(), its image noise added; false when
  // it cannot (no renderer, or the link's pose is not to be had; logged once).
  bool render(const World& world);

  const render::Frame& frame() const { return frame_; }
  const CameraConfig& config() const { return config_; }

 private:
  CameraConfig config_;
  std::string link_;
  Pose pose_;  // the camera frame on the link: the sensor's pose and <camera><pose>
  std::string label_;
  render::CameraSpec spec_;
  render::Frame frame_;  // reused: the renderer resizes it only when the size changes
  bool failed_ = false;  // logged once
  // Gazebo's image noise: one value a pixel a frame, N(mean, stddev), added to its three
  // channels and clamped, as Gazebo's GaussianNoise compositor adds it. Drawn from a table of
  // deviates the noise model (NoiseModel::white) makes once from the seed (in channel units),
  // indexed by a xorshift generator: a table lookup a pixel, where drawing each afresh would
  // cost more than the frame.
  std::vector<float> noise_table_;
  uint64_t noise_state_ = 0;
  void addNoise();
};

}  // namespace onedof_sim::plugins
