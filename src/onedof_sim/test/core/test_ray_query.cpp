// Ray queries (World::castRays) on every engine of the registry: boxes, spheres and cylinders on
// free bodies and welded to the world, the ground plane model (and no ground without it), rays
// that meet nothing, one batch in order, and the refusals. Meshes: test_mesh_collisions.cpp (RaysMeetMeshes).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "../ground_plane.h"
#include "onedof_sim/world.h"

namespace onedof_sim {
namespace {

// A free link of mass 1 with one collision `geometry` (URDF), or welded to the world.
std::string shapeUrdf(const std::string& name, const std::string& geometry, bool welded) {
  std::ostringstream s;
  s << "<robot name=\"" << name << "\">";
  if (welded)
    s << "<link name=\"world\"/><joint name=\"glue\" type=\"fixed\"><parent link=\"world\"/>"
         "<child link=\"" << name << "\"/></joint>";
  s << "<link name=\"" << name << "\"><inertial><mass value=\"1\"/><inertia ixx=\"0.1\" ixy=\"0\""
       " ixz=\"0\" iyy=\"0.1\" iyz=\"0\" izz=\"0.1\"/></inertial><collision><geometry>"
    << geometry << "</geometry></collision></link></robot>";
  return s.str();
}

Pose at(double x, double y, double z) {
  Pose p;
  p.position = {x, y, z};
  return p;
}

class RayQuery : public ::testing::TestWithParam<std::string> {
 protected:
  void spawn(const std::string& name, const std::string& geometry, const Pose& pose,
             bool welded = false) {
    const Status status =
        world_.spawn(name, shapeUrdf(name, geometry, welded), ModelFormat::Urdf, pose);
    ASSERT_TRUE(status.ok()) << status;
  }
  std::vector<double> cast(const std::vector<Ray>& rays) {
    std::vector<double> distances;
    const Status status = world_.castRays(rays, &distances);
    EXPECT_TRUE(status.ok()) << status;
    EXPECT_EQ(distances.size(), rays.size());
    distances.resize(rays.size(), -1);
    return distances;
  }
  World world_{GetParam()};
};

// A 0.4 m box centred 2 m ahead, a sphere of radius 0.3 2 m to the left, a cylinder of radius
// 0.2 (its axis vertical) 2 m behind, all 1 m up and not stepped: each ray from the origin at
// that height meets the surface facing it. Then the same shapes welded to the world.
TEST_P(RayQuery, RaysMeetPrimitivesOnBodiesAndAnchored) {
  for (const bool welded : {false, true}) {
    const std::string tag = welded ? "_welded" : "";
    const double z = welded ? 3 : 1;
    spawn("box" + tag, "<box size=\"0.4 0.4 0.4\"/>", at(2, 0, z), welded);
    spawn("sphere" + tag, "<sphere radius=\"0.3\"/>", at(0, 2, z), welded);
    spawn("cylinder" + tag, "<cylinder radius=\"0.2\" length=\"0.6\"/>", at(-2, 0, z), welded);
    const std::vector<double> d = cast({{{0, 0, z}, {1, 0, 0}, 10},
                                        {{0, 0, z}, {0, 1, 0}, 10},
                                        {{0, 0, z}, {-1, 0, 0}, 10},
                                        // off centre: the sphere's surface at y = 2 - sqrt(0.09 - 0.04)
                                        {{0.2, 0, z}, {0, 1, 0}, 10},
                                        // a direction of any length
                                        {{0, 0, z}, {5, 0, 0}, 10}});
    EXPECT_NEAR(d[0], 1.8, 1e-6) << tag;
    EXPECT_NEAR(d[1], 1.7, 1e-6) << tag;
    EXPECT_NEAR(d[2], 1.8, 1e-6) << tag;
    EXPECT_NEAR(d[3], 2 - std::sqrt(0.05), 1e-6) << tag;
    EXPECT_NEAR(d[4], 1.8, 1e-6) << tag;
  }
}

// The ground plane model's plane z = 0, straight down and slanting; a ray upward, one too short
// to reach the box, one beside it and one of length 0 meet nothing.
TEST_P(RayQuery, GroundAndMisses) {
  testing_support::addGroundPlane(world_);
  spawn("box", "<box size=\"0.4 0.4 0.4\"/>", at(2, 0, 1));
  const double inf = std::numeric_limits<double>::infinity();
  const std::vector<double> d = cast({{{5, 5, 1}, {0, 0, -1}, 10},
                                      {{5, 5, 1}, {1, 0, -1}, 10},
                                      {{0, 0, 1}, {0, 0, 1}, 10},
                                      {{0, 0, 1}, {1, 0, 0}, 1.7},
                                      {{0, 0.3, 1}, {1, 0, 0}, 10},
                                      {{0, 0, 1}, {1, 0, 0}, 0}});
  EXPECT_NEAR(d[0], 1, 1e-6);
  EXPECT_NEAR(d[1], std::sqrt(2.0), 1e-6);
  EXPECT_EQ(d[2], inf);
  EXPECT_EQ(d[3], inf);
  EXPECT_EQ(d[4], inf);
  EXPECT_EQ(d[5], inf);
}

// A world has the ground it places, as in Gazebo: without the ground plane model rays down meet
// nothing; with it, its plane; with it deleted, nothing again.
TEST_P(RayQuery, TheGroundIsTheGroundPlaneModelAlone) {
  const double inf = std::numeric_limits<double>::infinity();
  const std::vector<Ray> down = {{{5, 5, 0.8}, {0, 0, -1}, 1}, {{0, 0, 0.8}, {1, 0, -1}, 10}};
  EXPECT_EQ(cast(down), std::vector<double>({inf, inf}));
  testing_support::addGroundPlane(world_);
  const std::vector<double> d = cast(down);
  EXPECT_NEAR(d[0], 0.8, 1e-9);
  EXPECT_NEAR(d[1], 0.8 * std::sqrt(2.0), 1e-9);
  ASSERT_TRUE(world_.deleteModel("ground_plane").ok());
  EXPECT_EQ(cast(down), std::vector<double>({inf, inf}));
}

// Rays see bodies where the last step or state left them: the box moved by setModelState.
TEST_P(RayQuery, RaysFollowMovedBodies) {
  spawn("box", "<box size=\"0.4 0.4 0.4\"/>", at(2, 0, 1));
  ASSERT_TRUE(world_.setModelState("box", at(3, 0, 1), Twist(), "").ok());
  EXPECT_NEAR(cast({{{0, 0, 1}, {1, 0, 0}, 10}})[0], 2.8, 1e-6);
  ASSERT_TRUE(world_.step().ok());  // the box falls by g dt^2 at most: still in the ray
  EXPECT_NEAR(cast({{{0, 0, 1}, {1, 0, 0}, 10}})[0], 2.8, 1e-6);
}

// A lidar inside its own 0.2 m box (the book's mobot's), a wall 3 m ahead: rays starting on the
// box's face (the laser's minimum range, 0.1 m from the centre) and inside it, and likewise in a
// sphere and a cylinder, meet the wall, not the shape that holds their start. A ray starting
// just outside the box, pointing at it, still meets it.
TEST_P(RayQuery, AShapeHoldingTheStartIsNotMet) {
  spawn("case", "<box size=\"0.2 0.2 0.2\"/>", at(0, 0, 1), true);
  spawn("ball", "<sphere radius=\"0.1\"/>", at(0, 1, 1), true);
  spawn("can", "<cylinder radius=\"0.1\" length=\"0.2\"/>", at(0, 2, 1), true);
  spawn("wall", "<box size=\"0.2 6 2\"/>", at(3.1, 1, 1), true);
  const std::vector<double> d = cast({{{0.1, 0, 1}, {1, 0, 0}, 10},     // on the box's face
                                      {{0.05, 0, 1}, {1, 0, 0}, 10},    // inside the box
                                      {{0, 0.1, 1}, {1, 0, 0}, 10},     // on its side face
                                      {{0.1, 1, 1}, {1, 0, 0}, 10},     // on the sphere
                                      {{0.1, 2, 1}, {1, 0, 0}, 10},     // on the cylinder
                                      {{0.3, 0, 1}, {-1, 0, 0}, 10}});  // outside, facing it
  EXPECT_NEAR(d[0], 2.9, 1e-6);
  EXPECT_NEAR(d[1], 2.95, 1e-6);
  EXPECT_NEAR(d[2], 3, 1e-6);
  EXPECT_NEAR(d[3], 2.9, 1e-6);
  EXPECT_NEAR(d[4], 2.9, 1e-6);
  EXPECT_NEAR(d[5], 0.2, 1e-6);
}

TEST_P(RayQuery, RefusesBadRays) {
  std::vector<double> d{1};
  const double nan = std::numeric_limits<double>::quiet_NaN();
  Status status = world_.castRays({{{0, 0, 1}, {0, 0, 0}, 1}}, &d);
  EXPECT_EQ(status.code, StatusCode::InvalidParameter) << status;
  EXPECT_TRUE(d.empty());
  status = world_.castRays({{{0, 0, 1}, {1, 0, 0}, -1}}, &d);
  EXPECT_EQ(status.code, StatusCode::InvalidParameter) << status;
  status = world_.castRays({{{nan, 0, 1}, {1, 0, 0}, 1}}, &d);
  EXPECT_EQ(status.code, StatusCode::NotFinite) << status;
  status = world_.castRays({{{0, 0, 1}, {1, 0, 0}, std::numeric_limits<double>::infinity()}}, &d);
  EXPECT_EQ(status.code, StatusCode::NotFinite) << status;
}

INSTANTIATE_TEST_SUITE_P(Engines, RayQuery, ::testing::ValuesIn(World::engineNames()),
                         [](const auto& info) { return info.param; });

}  // namespace
}  // namespace onedof_sim
