// bench_render_frame: the camera renderer's bare frame time, without ROS: one frame drawn and read
// back (RGB and depth) in a loop, for the camera plugins' cost per frame to be set against.
//
//   bench_render_frame [WIDTH HEIGHT [FRAMES]]   (default 640 480 200)
// prints the renderer (GL_RENDERER; GL_VERSION) and, for an empty scene and for a scene of a
// ground plane, a box, a cylinder and a sphere, "SCENE: MEAN_MS ms a frame (min MIN_MS)".
#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <iostream>
#include <string>
#include <vector>

#include "renderer.h"

namespace {

using onedof_sim::GeometryShape;
using onedof_sim::VisualShape;

VisualShape shape(GeometryShape kind, onedof_sim::Vec3 size, onedof_sim::Vec3 at,
                  const std::string& material) {
  VisualShape visual;
  visual.model = "bench";
  visual.shape = kind;
  visual.size = size;
  visual.pose.position = at;
  visual.material.script = material;
  return visual;
}

void measure(onedof_sim::render::Renderer& renderer, const std::string& name,
             const std::vector<VisualShape>& scene, const onedof_sim::render::CameraSpec& camera,
             int frames) {
  onedof_sim::render::Frame frame;
  std::string error;
  for (int i = 0; i < 5; ++i) renderer.render(scene, camera, &frame, &error);  // warm up
  double total = 0, least = 1e9;
  for (int i = 0; i < frames; ++i) {
    const auto start = std::chrono::steady_clock::now();
    if (!renderer.render(scene, camera, &frame, &error)) {
      std::cerr << "bench_render_frame: " << error << std::endl;
      std::exit(1);
    }
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    total += ms;
    least = std::min(least, ms);
  }
  std::cout << name << ": " << total / frames << " ms a frame (min " << least << ")" << std::endl;
}

}  // namespace

int main(int argc, char** argv) {
  onedof_sim::render::CameraSpec camera;
  camera.width = argc > 2 ? std::atoi(argv[1]) : 640;
  camera.height = argc > 2 ? std::atoi(argv[2]) : 480;
  const int frames = argc > 3 ? std::atoi(argv[3]) : 200;
  camera.pose.position = {0, 0, 0.5};
  std::string error;
  auto renderer = onedof_sim::render::Renderer::create(&error);
  if (!renderer) {
    std::cerr << "bench_render_frame: " << error << std::endl;
    return 1;
  }
  std::cout << renderer->description() << "; " << camera.width << "x" << camera.height << ", "
            << frames << " frames" << std::endl;
  measure(*renderer, "empty", {}, camera, frames);
  const std::vector<VisualShape> scene = {
      shape(GeometryShape::Plane, {100, 100, 0}, {0, 0, 0}, "Gazebo/Grey"),
      shape(GeometryShape::Box, {0.5, 0.5, 0.5}, {3, 0.5, 0.25}, "Gazebo/Red"),
      shape(GeometryShape::Cylinder, {0.2, 0, 1}, {4, -1, 0.5}, "Gazebo/Blue"),
      shape(GeometryShape::Sphere, {0.3, 0, 0}, {2.5, -0.4, 0.3}, "Gazebo/Green")};
  measure(*renderer, "ground, box, cylinder, sphere", scene, camera, frames);
  return 0;
}
