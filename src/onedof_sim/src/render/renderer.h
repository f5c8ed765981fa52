// The camera renderer: draws the world's visuals (World::visualShapes) as a camera sees them,
// into an RGB image and a depth image, headless and free of ROS, for the camera and depth-camera
// plugins.
//
// Why OpenGL through Mesa's EGL and not OGRE 1.12 (Gazebo's renderer): both are Debian's and
// both rasterise on the CPU with Mesa's llvmpipe where there is no GPU, at the same cost (a bare
// 640x480 frame drawn and read back in about half a millisecond either way); but Debian
// bookworm's OGRE 1.12 render systems (RenderSystem_GL, _GL3Plus, _GLES2) are built against GLX
// and link libX11: without an X display OGRE stops at "Couldn't open X display", so it would
// need Xvfb on CI and on a user's headless machine, which the simulator otherwise never needs.
// OSMesa (libosmesa6-dev) is headless too, but Mesa's legacy off-screen interface, with its own
// context API beside EGL's; EGL is the one Mesa keeps for this. Mesa's EGL has the
// surfaceless platform (EGL_MESA_platform_surfaceless, EGL_KHR_surfaceless_context): an OpenGL
// 4.5 core context with no display and no window, rendering into a framebuffer object. What the
// camera needs (flat-shaded boxes, cylinders, spheres, planes and meshes with Gazebo's colours,
// a float depth) is a few hundred lines of plain OpenGL; OGRE would bring its plugin and resource
// system and Gazebo's material scripts to keep. Debian packages: libegl-dev, libopengl-dev,
// libgl-dev (headers), libegl-mesa0 and libgl1-mesa-dri (the EGL driver and llvmpipe).
//
// Conventions, as Gazebo's cameras:
// - The camera frame is Gazebo's camera link: it looks along its +x, +y to the image's left, +z
//   up. The optical frame (ROS's, for CameraInfo and the point cloud: +z forward, +x right, +y
//   down) is that frame turned by roll -pi/2, yaw -pi/2 (rpy(-pi/2, 0, -pi/2) from the link).
// - The horizontal field of view spans the image's width; the vertical one follows from the
//   aspect ratio: tan(vfov / 2) = tan(hfov / 2) * height / width. Pixel (u, v) (column, row, row 0
//   at the top) has its centre at the direction (1, -(u + 0.5 - width / 2) / f, -(v + 0.5 -
//   height / 2) / f) in the camera frame, f = width / (2 tan(hfov / 2)).
// - Depth: metres along the optical axis (the z distance, not the ray's length), as Gazebo's
//   DepthCamera gives it (its shader writes the clip-space w). Where nothing is drawn between the
//   near and the far clip the depth is the far clip distance, as Gazebo's DepthCamera clears its
//   target; gazebo_ros_openni_kinect then publishes NaN for depths outside its cutoffs.
// - Colour: each visual flat-lit by Gazebo's default world light and scene: ambient 0.4 on the
//   material's ambient colour, and the sun (diffuse 0.8, direction (-0.5, 0.1, -0.9)) on its
//   diffuse colour, plus its emissive colour; specular highlights and shadows are not drawn.
//   The background is Gazebo's default scene background, 0.7 grey.
// - Boxes, cylinders and spheres show their outside only (OGRE's default back-face culling, as in
//   Gazebo: a camera inside its own case sees out of it); planes and meshes show both sides.
//
// Not thread-safe: one thread at a time renders (each call makes its context current on the
// calling thread). Deterministic: the same scene and camera give the same bytes.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "onedof_sim/world.h"

namespace onedof_sim {
namespace render {

struct CameraSpec {
  Pose pose;                   // the camera frame (Gazebo's camera link) in the world
  double horizontal_fov = 1.047;  // rad, in (0, pi)
  int width = 320, height = 240;  // pixels, at least 1
  double near_clip = 0.1, far_clip = 100;  // m, 0 < near < far
  int channel_bits = 8;  // the colour image's bits a channel: 8 (Frame::rgb) or 16 (rgb16)
};

struct Frame {
  int width = 0, height = 0;
  std::vector<uint8_t> rgb;  // 8 bits a channel: r g b, row 0 at the top, width * 3 a row
  std::vector<uint16_t> rgb16;  // 16 bits a channel, likewise; each filled as the camera asks
  std::vector<float> depth;  // metres, row 0 at the top (see "Depth" above)
};

class Renderer {
 public:
  // The widest and the highest image it renders: the largest renderbuffer llvmpipe makes.
  static constexpr int kMaxSide = 16384;

  // A renderer on Mesa's surfaceless EGL platform; null and *error saying why when EGL or
  // OpenGL 3.3 is not to be had.
  static std::unique_ptr<Renderer> create(std::string* error);
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  // Draws `visuals` as `camera` sees them into *frame. False and *error for a camera out of its
  // ranges (naming the field). A visual that cannot be drawn (a mesh file not found or not
  // readable, a non-positive size) is left out and named in problems() once.
  bool render(const std::vector<VisualShape>& visuals, const CameraSpec& camera, Frame* frame,
              std::string* error);

  // What was left out of the frames so far and why, each visual ("model::link::visual") once;
  // drained by the call.
  std::vector<std::string> takeProblems();

  // The renderer's GL_RENDERER and GL_VERSION, e.g. "llvmpipe (LLVM 15.0.6, 256 bits); 4.5 (Core
  // Profile) Mesa 22.3.6".
  std::string description() const;

 private:
  struct Impl;
  explicit Renderer(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace render
}  // namespace onedof_sim
