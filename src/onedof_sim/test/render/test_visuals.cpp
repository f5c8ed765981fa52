// The world's visuals (World::visualShapes) as spawned models give them, URDF and SDF, and a
// frame rendered from them.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <unistd.h>

#include "onedof_sim/world.h"
#include "renderer.h"

namespace onedof_sim {
namespace {

// A red box (Gazebo's named material, as the book's URDFs give it) over a link whose visual
// is offset, and a second link with an rviz colour and a mesh not to be found.
const char* kUrdf = R"(<robot name="r">
  <link name="base">
    <inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
    <visual><origin xyz="0 0 0.1"/><geometry><box size="0.2 0.4 0.3"/></geometry></visual>
    <collision><geometry><box size="0.2 0.4 0.3"/></geometry></collision>
  </link>
  <link name="top">
    <inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
    <visual name="shade"><geometry><cylinder radius="0.05" length="0.1"/></geometry>
      <material name="blue"><color rgba="0 0 1 1"/></material></visual>
    <visual><geometry><mesh filename="file:///nowhere/part.stl" scale="2 2 2"/></geometry></visual>
  </link>
  <joint name="j" type="fixed"><parent link="base"/><child link="top"/><origin xyz="0 0 1"/></joint>
  <gazebo reference="base"><material>Gazebo/Red</material></gazebo>
</robot>)";

const char* kSdf = R"(<sdf version="1.6"><model name="ground">
  <static>true</static>
  <link name="link">
    <visual name="visual">
      <geometry><plane><normal>0 0 1</normal><size>100 100</size></plane></geometry>
      <material><ambient>0.8 0.8 0.8 1</ambient><diffuse>0.8 0.8 0.8 1</diffuse></material>
    </visual>
    <visual name="marker"><pose>1 0 0 0 0 0</pose>
      <geometry><sphere><radius>0.1</radius></sphere></geometry>
      <material><script><uri>file://media/materials/scripts/gazebo.material</uri>
        <name>Gazebo/Blue</name></script></material>
    </visual>
  </link>
</model></sdf>)";

Pose at(double x, double y, double z) {
  Pose pose;
  pose.position = {x, y, z};
  return pose;
}

TEST(Visuals, WorldKeepsEachLinksVisualsAndMaterials) {
  World world;
  ASSERT_TRUE(world.spawn("robot", kUrdf, ModelFormat::Urdf, at(2, 0, 0.5)).ok());
  ASSERT_TRUE(world.spawn("ground", kSdf, ModelFormat::Sdf, at(0, 0, 0)).ok());
  const std::vector<VisualShape> visuals = world.visualShapes();
  ASSERT_EQ(visuals.size(), 5u);
  const VisualShape& box = visuals[0];
  EXPECT_EQ(box.model, "robot");
  EXPECT_EQ(box.link, "base");
  EXPECT_EQ(box.name, "base_visual");
  EXPECT_EQ(box.shape, GeometryShape::Box);
  EXPECT_DOUBLE_EQ(box.size.y, 0.4);
  EXPECT_NEAR(box.pose.position.x, 2, 1e-9);
  EXPECT_NEAR(box.pose.position.z, 0.6, 1e-9);
  EXPECT_EQ(box.material.script, "Gazebo/Red");
  EXPECT_FALSE(box.material.diffuse);
  const VisualShape& shade = visuals[1];
  EXPECT_EQ(shade.name, "shade");
  EXPECT_EQ(shade.shape, GeometryShape::Cylinder);
  EXPECT_NEAR(shade.pose.position.z, 1.5, 1e-9);
  ASSERT_TRUE(shade.material.diffuse);
  EXPECT_EQ(shade.material.diffuse->b, 1.0f);
  ASSERT_TRUE(shade.material.ambient);
  EXPECT_TRUE(shade.material.script.empty());
  const VisualShape& mesh = visuals[2];
  EXPECT_EQ(mesh.name, "top_visual_1");
  EXPECT_EQ(mesh.shape, GeometryShape::Mesh);
  EXPECT_EQ(mesh.mesh_uri, "file:///nowhere/part.stl");
  EXPECT_TRUE(mesh.mesh_file.empty());
  EXPECT_DOUBLE_EQ(mesh.size.x, 2);
  const VisualShape& plane = visuals[3];
  EXPECT_EQ(plane.shape, GeometryShape::Plane);
  EXPECT_DOUBLE_EQ(plane.size.x, 100);
  ASSERT_TRUE(plane.material.ambient);
  EXPECT_FLOAT_EQ(plane.material.ambient->r, 0.8f);
  EXPECT_EQ(visuals[4].material.script, "Gazebo/Blue");
  EXPECT_NEAR(visuals[4].pose.position.x, 1, 1e-9);
  // The visuals follow their link.
  ASSERT_TRUE(world.setModelState("robot", at(3, 0, 0.5), Twist(), "").ok());
  EXPECT_NEAR(world.visualShapes()[1].pose.position.x, 3, 1e-9);
  ASSERT_TRUE(world.deleteModel("robot").ok());
  EXPECT_EQ(world.visualShapes().size(), 2u);
}

TEST(Visuals, PlaneNormalTurnsThePlane) {
  const char* sdf = R"(<sdf version="1.6"><model name="wall"><static>true</static><link name="l">
    <visual name="v"><geometry><plane><normal>1 0 0</normal><size>2 3</size></plane></geometry>
    </visual></link></model></sdf>)";
  World world;
  ASSERT_TRUE(world.spawn("wall", sdf, ModelFormat::Sdf, at(0, 0, 0)).ok());
  const VisualShape plane = world.visualShapes().at(0);
  // The pose's z axis is the normal, +x.
  const Quat& q = plane.pose.orientation;
  const double zx = 2 * (q.x * q.z + q.w * q.y);
  EXPECT_NEAR(zx, 1, 1e-9);
}

TEST(Visuals, RenderedFromTheWorld) {
  World world;
  ASSERT_TRUE(world.spawn("robot", kUrdf, ModelFormat::Urdf, at(2, 0.0, 0.5)).ok());
  std::string error;
  auto renderer = render::Renderer::create(&error);
  ASSERT_TRUE(renderer) << error;
  render::CameraSpec camera;
  camera.pose = at(0, -0.1, 0.6);  // level with the box's centre, the box 0.1 m to its left
  camera.width = 320, camera.height = 240;
  camera.horizontal_fov = 1.047;
  render::Frame frame;
  ASSERT_TRUE(renderer->render(world.visualShapes(), camera, &frame, &error)) << error;
  const size_t centre = static_cast<size_t>(120) * 320 + 160;
  EXPECT_NEAR(frame.depth[centre], 1.9, 0.01);
  EXPECT_EQ(frame.rgb[centre * 3 + 0], 102);
  EXPECT_EQ(frame.rgb[centre * 3 + 1], 0);
  EXPECT_EQ(frame.rgb[centre * 3 + 2], 0);
  const std::vector<std::string> problems = renderer->takeProblems();
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_NE(problems[0].find("robot::top::top_visual_1: not drawn: its mesh"), std::string::npos)
      << problems[0];
}

TEST(Visuals, MeshVisualIsReadAndDrawn) {
  // A tetrahedron-free test mesh: one square of two triangles facing -x, 1 m wide, in an ASCII
  // STL written here, scaled by 0.5 in the visual.
  const std::filesystem::path folder =
      std::filesystem::temp_directory_path() / ("onedof_render_" + std::to_string(::getpid()));
  std::filesystem::create_directories(folder);
  const std::filesystem::path file = folder / "square.stl";
  std::ofstream(file) << "solid s\n"
                         "facet normal -1 0 0\nouter loop\nvertex 0 -1 -1\nvertex 0 -1 1\n"
                         "vertex 0 1 1\nendloop\nendfacet\n"
                         "facet normal -1 0 0\nouter loop\nvertex 0 -1 -1\nvertex 0 1 1\n"
                         "vertex 0 1 -1\nendloop\nendfacet\nendsolid s\n";
  const std::string sdf = R"(<sdf version="1.6"><model name="m"><static>true</static><link name="l">
    <visual name="v"><geometry><mesh><uri>)" + file.string() +
                          R"(</uri><scale>0.5 0.5 0.5</scale></mesh></geometry>
      <material><script><uri>file://media/materials/scripts/gazebo.material</uri><name>Gazebo/Green</name></script></material></visual></link></model></sdf>)";
  World world;
  const Status spawned = world.spawn("m", sdf, ModelFormat::Sdf, at(3, 0, 0));
  ASSERT_TRUE(spawned.ok()) << spawned;
  ASSERT_EQ(world.visualShapes().at(0).mesh_file, file.string());
  std::string error;
  auto renderer = render::Renderer::create(&error);
  ASSERT_TRUE(renderer) << error;
  render::CameraSpec camera;
  camera.width = 64, camera.height = 48;
  render::Frame frame;
  ASSERT_TRUE(renderer->render(world.visualShapes(), camera, &frame, &error)) << error;
  const size_t centre = static_cast<size_t>(24) * 64 + 32;
  EXPECT_NEAR(frame.depth[centre], 3, 0.01);
  EXPECT_EQ(frame.rgb[centre * 3 + 0], 0);
  EXPECT_EQ(frame.rgb[centre * 3 + 1], 102);
  // The square is 1 m wide at 3 m: tan(half) = 0.5 / 3 of tan(fov / 2) = 0.577 across 32 pixels.
  int green = 0;
  for (int u = 0; u < 64; ++u) green += frame.rgb[(static_cast<size_t>(24) * 64 + u) * 3 + 1] == 102;
  EXPECT_NEAR(green, 2 * 32 * (0.5 / 3) / std::tan(1.047 / 2), 1.0);
  EXPECT_TRUE(renderer->takeProblems().empty());
  std::filesystem::remove_all(folder);
}

}  // namespace
}  // namespace onedof_sim
