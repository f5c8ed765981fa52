// The world view's markers (src/ros/view_markers.h), no roscore: each shape at its size and pose,
// visuals in their materials' colours, meshes as file:// URIs, a joint's axis as an arrow, a
// link's inertia box with the sides of the box of its mass and inertia whatever its axes.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>

#include <onedof_sim/pose_math.h>

#include "view_markers.h"

namespace onedof_sim {
namespace {

using visualization_msgs::Marker;

TEST(ViewMarkers, CollisionMarkersDrawEachShapeAtItsSize) {
  CollisionShape cylinder;
  cylinder.model = "robot";
  cylinder.shape = GeometryShape::Cylinder;
  cylinder.size = {0.1, 0, 0.5};
  cylinder.pose = {{1, 2, 3}, {}};
  const Marker m = collisionMarker(cylinder, 7);
  EXPECT_EQ(m.ns, "robot");
  EXPECT_EQ(m.id, 7);
  EXPECT_EQ(m.header.frame_id, "world");
  EXPECT_EQ(m.type, Marker::CYLINDER);
  EXPECT_EQ(m.scale.x, 0.2);
  EXPECT_EQ(m.scale.z, 0.5);
  EXPECT_EQ(m.pose.position.z, 3);
  CollisionShape sphere;
  sphere.shape = GeometryShape::Sphere;
  sphere.size = {0.3, 0, 0};
  EXPECT_EQ(collisionMarker(sphere, 0).scale.y, 0.6);
  CollisionShape mesh;
  mesh.shape = GeometryShape::Mesh;
  mesh.mesh_file = "/m/part.stl";
  mesh.size = {1, 2, 3};
  const Marker mesh_marker = collisionMarker(mesh, 0);
  EXPECT_EQ(mesh_marker.type, Marker::MESH_RESOURCE);
  EXPECT_EQ(mesh_marker.mesh_resource, "file:///m/part.stl");
  EXPECT_EQ(mesh_marker.scale.z, 3);
}

VisualShape box(const VisualMaterial& material) {
  VisualShape visual;
  visual.model = "m";
  visual.shape = GeometryShape::Box;
  visual.size = {1, 2, 3};
  visual.material = material;
  return visual;
}

std::array<float, 4> rgba(const Marker& m) { return {m.color.r, m.color.g, m.color.b, m.color.a}; }

TEST(ViewMarkers, VisualsAreDrawnInTheirMaterialsDiffuseColour) {
  Marker m;
  std::string why;
  ASSERT_TRUE(visualMarker(box({"Gazebo/Blue", {}, {}, {}}), 0, &m, &why));
  EXPECT_EQ(rgba(m), (std::array<float, 4>{0, 0, 1, 1}));
  EXPECT_EQ(why, "");
  // Given colours over the named material's; an unnamed <material>'s diffuse.
  ASSERT_TRUE(visualMarker(box({"Gazebo/Blue", {}, Color{0.2f, 0.4f, 0.6f, 1}, {}}), 0, &m, &why));
  EXPECT_EQ(rgba(m), (std::array<float, 4>{0.2f, 0.4f, 0.6f, 1}));
  // No material: Gazebo's white.
  ASSERT_TRUE(visualMarker(box({}), 0, &m, &why));
  EXPECT_EQ(rgba(m), (std::array<float, 4>{1, 1, 1, 1}));
  // A name Gazebo does not have: drawn white, and said so.
  ASSERT_TRUE(visualMarker(box({"Gazebo/Nonesuch", {}, {}, {}}), 0, &m, &why));
  EXPECT_EQ(rgba(m), (std::array<float, 4>{1, 1, 1, 1}));
  EXPECT_NE(why.find("Gazebo/Nonesuch"), std::string::npos) << why;
}

TEST(ViewMarkers, MeshVisualsAreTheirFilesAndAMissingFileIsNotDrawn) {
  VisualShape mesh = box({});
  mesh.shape = GeometryShape::Mesh;
  mesh.mesh_uri = "model://thing/meshes/part.dae";
  mesh.mesh_file = "/models/thing/meshes/part.dae";
  Marker m;
  std::string why;
  ASSERT_TRUE(visualMarker(mesh, 0, &m, &why));
  EXPECT_EQ(m.type, Marker::MESH_RESOURCE);
  EXPECT_EQ(m.mesh_resource, "file:///models/thing/meshes/part.dae");
  EXPECT_EQ(m.scale.y, 2);
  // Without a material: the file's own materials, untinted.
  EXPECT_TRUE(m.mesh_use_embedded_materials);
  EXPECT_EQ(rgba(m), (std::array<float, 4>{0, 0, 0, 0}));
  mesh.material.script = "Gazebo/Red";
  ASSERT_TRUE(visualMarker(mesh, 0, &m, &why));
  EXPECT_FALSE(m.mesh_use_embedded_materials);
  EXPECT_EQ(rgba(m), (std::array<float, 4>{1, 0, 0, 1}));
  mesh.mesh_file.clear();
  EXPECT_FALSE(visualMarker(mesh, 0, &m, &why));
  EXPECT_NE(why.find("model://thing/meshes/part.dae"), std::string::npos) << why;
}

TEST(ViewMarkers, AJointIsItsOriginAndAMovingJointItsAxis) {
  JointAxis joint;
  joint.model = "arm";
  joint.type = JointType::Revolute;
  joint.anchor = {1, 2, 3};
  joint.axis = {0, 1, 0};
  const std::vector<Marker> markers = jointMarkers(joint, 4);
  ASSERT_EQ(markers.size(), 2u);
  EXPECT_EQ(markers[0].type, Marker::SPHERE);
  EXPECT_EQ(markers[0].id, 4);
  EXPECT_EQ(markers[0].pose.position.z, 3);
  EXPECT_EQ(markers[1].type, Marker::ARROW);
  EXPECT_EQ(markers[1].id, 5);
  ASSERT_EQ(markers[1].points.size(), 2u);
  EXPECT_EQ(markers[1].points[0].y, 2);
  EXPECT_GT(markers[1].points[1].y, 2);
  EXPECT_EQ(markers[1].points[1].x, 1);
  joint.type = JointType::Fixed;
  EXPECT_EQ(jointMarkers(joint, 0).size(), 1u);
}

// A 3 kg box of 0.2 x 0.4 x 0.6 m, its inertia given in a frame turned 30 degrees about z from
// its principal axes: its inertia box has the box's sides, turned back onto the principal axes.
TEST(ViewMarkers, AnInertiaBoxHasTheSidesOfTheBoxOfTheLinksMassAndInertia) {
  const double m = 3, x = 0.2, y = 0.4, z = 0.6;
  const double ix = m / 12 * (y * y + z * z), iy = m / 12 * (x * x + z * z),
               iz = m / 12 * (x * x + y * y);
  const double c = std::cos(M_PI / 6), s = std::sin(M_PI / 6);
  LinkMass mass;
  mass.model = "m";
  mass.mass = m;
  mass.inertial.position = {1, 2, 3};
  // R diag(ix, iy, iz) R^T for R a turn of 30 degrees about z.
  mass.ixx = c * c * ix + s * s * iy;
  mass.iyy = s * s * ix + c * c * iy;
  mass.ixy = c * s * (ix - iy);
  mass.izz = iz;
  const Marker box = inertiaMarker(mass, 0);
  std::array<double, 3> sides{box.scale.x, box.scale.y, box.scale.z};
  std::sort(sides.begin(), sides.end());
  EXPECT_NEAR(sides[0], x, 1e-9);
  EXPECT_NEAR(sides[1], y, 1e-9);
  EXPECT_NEAR(sides[2], z, 1e-9);
  EXPECT_EQ(box.pose.position.y, 2);
  // The side of length x lies along the turned x axis (cos 30, sin 30, 0).
  const Quat q{box.pose.orientation.w, box.pose.orientation.x, box.pose.orientation.y,
               box.pose.orientation.z};
  const Vec3 axes[] = {rotate(q, {1, 0, 0}), rotate(q, {0, 1, 0}), rotate(q, {0, 0, 1})};
  const double scales[] = {box.scale.x, box.scale.y, box.scale.z};
  for (int i = 0; i < 3; ++i)
    if (std::abs(scales[i] - x) < 1e-6) EXPECT_NEAR(std::abs(dot(axes[i], {c, s, 0})), 1, 1e-9);

  // The centre of mass: a sphere of lead of the mass.
  const Marker com = comMarker(mass, 0);
  EXPECT_NEAR(com.scale.x, 2 * std::cbrt(3 * m / (4 * M_PI * 11340)), 1e-12);
}

TEST(ViewMarkers, ContactsAreTheirPointsAndNormals) {
  EXPECT_TRUE(contactMarkers({}).empty());
  Contact contact;
  ContactPoint point;
  point.position = {1, 0, 0};
  point.normal = {0, 0, 1};
  contact.points = {point, point};
  const std::vector<Marker> markers = contactMarkers({contact});
  ASSERT_EQ(markers.size(), 2u);
  EXPECT_EQ(markers[0].type, Marker::SPHERE_LIST);
  EXPECT_EQ(markers[0].points.size(), 2u);
  EXPECT_EQ(markers[1].type, Marker::LINE_LIST);
  ASSERT_EQ(markers[1].points.size(), 4u);
  EXPECT_GT(markers[1].points[1].z, 0);
}

}  // namespace
}  // namespace onedof_sim
