// A camera lens's distortion as SDF's <camera><distortion> gives it (k1, k2, k3, p1, p2 and the
// <center>), applied to a rendered pinhole frame on the CPU with a remap table made once per
// camera.
//
// The model is Brown-Conrady's, as Gazebo's Distortion and OpenCV write it: a point at
// normalised image coordinates x = (pixel - centre) / f, r^2 = x^2 + y^2, is seen at
//   x_d = x (1 + k1 r^2 + k2 r^4 + k3 r^6) + 2 p1 x y + p2 (r^2 + 2 x^2)
//   y_d = y (1 + k1 r^2 + k2 r^4 + k3 r^6) + p1 (r^2 + 2 y^2) + 2 p2 x y
// with f the pinhole focal length in pixels, width / (2 tan(hfov / 2)), and the centre at
// <center> (fractions of the width and height; 0.5 0.5: the image's middle). Normalised by f, as
// Gazebo 11 does outside its legacy mode and OpenCV always does, the coefficients are those a
// calibration finds: OpenCV's undistort with K = (f, centre) and D = (k1, k2, p1, p2, k3) (the
// D gazebo_ros_camera_utils publishes) gives the pinhole image back. Gazebo's legacy mode
// normalises by the image's width instead; both agree where f is the width (hfov 2 atan(1/2),
// the field of view of Gazebo's own distortion tests).
//
// Each pixel of the distorted image looks where the inverse of the model sends it, found by
// Newton's method; its colour is the pinhole render's there, interpolated bilinearly. Where the
// lens sees past the camera's field of view (barrel distortion's corners) the pinhole frame is
// rendered wider by a margin of pixels around it, at the same focal length, so those pixels see
// what a real lens would, not Gazebo's black border; the margin is bounded (at most half the
// image on each side, and the render's pixels at most a given count). A pixel whose ray is still
// outside, or that no point reaches (past the fold of a strong barrel distortion), is black.
// The depth image is not distorted, as Gazebo's depth cameras' is not: it is the pinhole
// frame's own, cut from the middle of the wider render.
#pragma once

#include <cstdint>
#include <vector>

#include "renderer.h"

namespace onedof_sim {
namespace render {

struct DistortionCoefficients {
  double k1 = 0, k2 = 0, k3 = 0, p1 = 0, p2 = 0;
  double center_x = 0.5, center_y = 0.5;  // fractions of the width and the height
  // True when every coefficient is 0: the lens is a pinhole and nothing is done.
  bool none() const { return k1 == 0 && k2 == 0 && k3 == 0 && p1 == 0 && p2 == 0; }
};

// The point the lens shows at normalised coordinates (x, y): the model above.
void distortNormalised(const DistortionCoefficients& lens, double x, double y, double* x_d,
                       double* y_d);

class LensDistortion {
 public:
  // For a width x height image with focal length focal_pixels; the wider render has at most
  // max_render_pixels pixels.
  LensDistortion(const DistortionCoefficients& lens, int width, int height, double focal_pixels,
                 long max_render_pixels);

  // The pinhole render to make: its size (the image's and the margins) and field of view.
  int renderWidth() const { return width_ + 2 * margin_x_; }
  int renderHeight() const { return height_ + 2 * margin_y_; }
  double renderHorizontalFov() const;
  // How many of the image's pixels are black (no point of the render reaches them).
  long blackPixels() const { return black_pixels_; }

  // The distorted frame (the image's size; rgb or rgb16, whichever `rendered` has, and depth)
  // from a render of renderWidth() x renderHeight().
  void apply(const Frame& rendered, Frame* out) const;

 private:
  template <class Channel>
  void remap(const std::vector<Channel>& from, std::vector<Channel>* to) const;

  int width_, height_;
  double focal_;
  int margin_x_ = 0, margin_y_ = 0;
  long black_pixels_ = 0;
  // For each pixel of the image: the render's pixel at the top left of the four it is
  // interpolated from (-1: black), and its weights towards the right and the bottom, in
  // 1/kWeightOne (fixed point: the per-frame remap is integer arithmetic).
  struct Source {
    int32_t pixel = -1;
    uint16_t weight_x = 0, weight_y = 0;
  };
  static constexpr uint32_t kWeightOne = 256;
  std::vector<Source> sources_;
};

}  // namespace render
}  // namespace onedof_sim
