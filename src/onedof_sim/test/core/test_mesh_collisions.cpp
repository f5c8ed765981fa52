// Mesh collisions on every engine of the registry: meshes read from files (STL, COLLADA), scaled,
// as static floors and on moving bodies, resting where their geometry says; and the refusals of
// meshes that cannot be read or are past the triangle limits.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "../ground_plane.h"
#include "onedof_sim/world.h"

namespace onedof_sim {
namespace {

// A box's 12 triangles as an ASCII STL, wound counter-clockwise seen from outside.
std::string boxStl(const Vec3& lo, const Vec3& hi) {
  const auto corner = [&](int i) {
    return Vec3{i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z};
  };
  const int faces[12][3] = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}, {0, 1, 5}, {0, 5, 4},
                            {2, 6, 7}, {2, 7, 3}, {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}};
  std::ostringstream s;
  s << "solid box\n";
  for (const auto& face : faces) {
    s << "facet normal 0 0 0\nouter loop\n";
    for (int i : face) {
      const Vec3 v = corner(i);
      s << "vertex " << v.x << " " << v.y << " " << v.z << "\n";
    }
    s << "endloop\nendfacet\n";
  }
  s << "endsolid box\n";
  return s.str();
}

// A binary STL of `triangles` small triangles (50 bytes each after an 84-byte header).
std::string manyTrianglesStl(uint32_t triangles) {
  std::string data(84 + 50 * static_cast<size_t>(triangles), '\0');
  std::memcpy(&data[80], &triangles, 4);
  for (uint32_t t = 0; t < triangles; ++t) {
    const float x = 0.001f * static_cast<float>(t % 1000), y = 0.001f * static_cast<float>(t / 1000);
    const float v[9] = {x, y, 0, x + 0.001f, y, 0, x, y + 0.001f, 0};
    std::memcpy(&data[84 + 50 * static_cast<size_t>(t) + 12], v, sizeof v);
  }
  return data;
}

// The unit block below as a binary STL, each face split into cells x cells squares: 12 cells^2
// triangles.
std::string subdividedBlockStl(int cells) {
  std::vector<float> triangles;  // 9 floats each
  const auto point = [](int axis, double side, double u, double v) {
    double c[3];
    c[axis] = side;
    c[(axis + 1) % 3] = u;
    c[(axis + 2) % 3] = v;
    return std::array<float, 3>{float(c[0]), float(c[1]), float(c[2] + 0.5)};
  };
  for (int axis = 0; axis < 3; ++axis)
    for (double side : {-0.5, 0.5})
      for (int i = 0; i < cells; ++i)
        for (int j = 0; j < cells; ++j) {
          const double u0 = -0.5 + double(i) / cells, u1 = -0.5 + double(i + 1) / cells;
          const double v0 = -0.5 + double(j) / cells, v1 = -0.5 + double(j + 1) / cells;
          std::array<float, 3> q[4] = {point(axis, side, u0, v0), point(axis, side, u1, v0),
                                       point(axis, side, u1, v1), point(axis, side, u0, v1)};
          if (side < 0) std::swap(q[1], q[3]);  // outward on the low side too
          for (int k : {0, 1, 2, 0, 2, 3}) triangles.insert(triangles.end(), q[k].begin(), q[k].end());
        }
  const uint32_t count = static_cast<uint32_t>(triangles.size() / 9);
  std::string data(84 + 50 * static_cast<size_t>(count), '\0');
  std::memcpy(&data[80], &count, 4);
  for (uint32_t t = 0; t < count; ++t)
    std::memcpy(&data[84 + 50 * static_cast<size_t>(t) + 12], &triangles[9 * t], 9 * sizeof(float));
  return data;
}

// A folder of mesh files (and model folders) in a fresh temporary folder.
class MeshFolder {
 public:
  MeshFolder() {
    std::string pattern = (std::filesystem::temp_directory_path() / "onedof_meshes_XXXXXX").string();
    root_ = mkdtemp(pattern.data());
  }
  ~MeshFolder() { std::filesystem::remove_all(root_); }
  const std::string& root() const { return root_; }
  std::string write(const std::string& relative, const std::string& data) const {
    const std::filesystem::path path = std::filesystem::path(root_) / relative;
    std::filesystem::create_directories(path.parent_path());
    std::ofstream(path, std::ios::binary) << data;
    return path.string();
  }

 private:
  std::string root_;
};

// A unit block spanning x and y -0.5..0.5 and z 0..1: its origin is the middle of its bottom.
const Vec3 kBlockLo{-0.5, -0.5, 0}, kBlockHi{0.5, 0.5, 1};

std::string meshElement(const std::string& uri, const Vec3& scale) {
  std::ostringstream s;
  s << "<mesh filename=\"" << uri << "\" scale=\"" << scale.x << " " << scale.y << " " << scale.z
    << "\"/>";
  return s.str();
}

// A link welded to the world whose collision is the mesh.
std::string staticMeshUrdf(const std::string& uri, const Vec3& scale) {
  return "<robot name=\"floor\"><link name=\"world\"/><joint name=\"glue\" type=\"fixed\">"
         "<parent link=\"world\"/><child link=\"floor\"/></joint><link name=\"floor\">"
         "<collision><geometry>" + meshElement(uri, scale) + "</geometry></collision></link></robot>";
}

// A free body of mass 1 whose collision is the mesh; inertia of a solid box of sides `sides`
// about its centre, `com` up from the link origin.
std::string movingMeshUrdf(const std::string& uri, const Vec3& scale, const Vec3& sides,
                           double com) {
  std::ostringstream s;
  s << "<robot name=\"body\"><link name=\"body\"><inertial><origin xyz=\"0 0 " << com
    << "\"/><mass value=\"1\"/><inertia ixx=\"" << (sides.y * sides.y + sides.z * sides.z) / 12
    << "\" ixy=\"0\" ixz=\"0\" iyy=\"" << (sides.x * sides.x + sides.z * sides.z) / 12
    << "\" iyz=\"0\" izz=\"" << (sides.x * sides.x + sides.y * sides.y) / 12
    << "\"/></inertial><collision><geometry>" << meshElement(uri, scale)
    << "</geometry></collision></link></robot>";
  return s.str();
}

std::string boxUrdf(double side) {
  const double i = side * side / 6;
  std::ostringstream s;
  s << "<robot name=\"box\"><link name=\"box\"><inertial><mass value=\"1\"/><inertia ixx=\"" << i
    << "\" ixy=\"0\" ixz=\"0\" iyy=\"" << i << "\" iyz=\"0\" izz=\"" << i
    << "\"/></inertial><collision><geometry><box size=\"" << side << " " << side << " " << side
    << "\"/></geometry></collision></link></robot>";
  return s.str();
}

Pose at(double x, double y, double z) {
  Pose p;
  p.position = {x, y, z};
  return p;
}

void stepFor(World* world, int steps) {
  for (int i = 0; i < steps; ++i) {
    const Status status = world->step();
    EXPECT_TRUE(status.ok()) << status;
  }
}

// The model's pose; *speed its speed.
Pose poseAndSpeed(World* world, const std::string& model, double* speed) {
  Pose pose;
  Twist twist;
  EXPECT_TRUE(world->modelState(model, "", &pose, &twist).ok());
  *speed = std::hypot(twist.linear.x, twist.linear.y, twist.linear.z);
  return pose;
}

// Steps 2 s and returns the model's pose; *speed its speed then.
Pose restingPose(World* world, const std::string& model, double* speed) {
  stepFor(world, 2000);
  return poseAndSpeed(world, model, speed);
}

// How far a body resting on a contact may sink into it or float above it: the box on the
// ground's own test allows 5 mm of sinking (ODE's contact layer and soft constraint, Bullet's
// slop and margin); a resting body's tilt stays below 1 degree.
constexpr double kSink = 0.005, kFloat = 0.001, kMaxTilt = 0.0175;

double tilt(const Pose& pose) {
  const Quat& q = pose.orientation;
  // The angle between the body's z axis and the world's.
  const double zz = 1 - 2 * (q.x * q.x + q.y * q.y);
  return std::acos(std::max(-1.0, std::min(1.0, zz)));
}

void expectRestsAt(const Pose& pose, double speed, double height, const char* what) {
  const double sink = height - pose.position.z;
  std::printf("[ figures  ] %s: sinks %.2f mm, tilt %.2f mrad, speed %.1e m/s\n", what,
              1000 * sink, 1000 * tilt(pose), speed);
  EXPECT_LT(sink, kSink) << what;
  EXPECT_GT(sink, -kFloat) << what;
  EXPECT_LT(tilt(pose), kMaxTilt) << what;
  EXPECT_LT(speed, 1e-3) << what;
}

class MeshCollisions : public ::testing::TestWithParam<std::string> {};

// A 2 m x 2 m x 0.3 m floor from the unit block scaled, its top at z 0.3; a 0.2 m box dropped
// on it rests with its centre at 0.4.
TEST_P(MeshCollisions, BoxRestsOnAStaticStlFloor) {
  MeshFolder folder;
  const std::string stl = folder.write("block.stl", boxStl(kBlockLo, kBlockHi));
  World world(GetParam());
  Status status = world.spawn("floor", staticMeshUrdf(stl, {2, 2, 0.3}), ModelFormat::Urdf, Pose());
  ASSERT_TRUE(status.ok()) << status;
  status = world.spawn("box", boxUrdf(0.2), ModelFormat::Urdf, at(0.3, -0.2, 0.6));
  ASSERT_TRUE(status.ok()) << status;
  double speed = 0;
  const Pose pose = restingPose(&world, "box", &speed);
  expectRestsAt(pose, speed, 0.4, "box on a static mesh floor");
  // Where it landed: Bullet collides the box with each triangle on its own, one new contact
  // point per triangle a step, so the landing's first impulses are off centre and the box slides
  // about 1 mm (on a box floor it stays within 0.01 mm); ODE's trimesh gives every point at once.
  EXPECT_NEAR(pose.position.x, 0.3, kSink);
  EXPECT_NEAR(pose.position.y, -0.2, kSink);
}

// Rays meet meshes where their triangles are: the unit block as a static floor (2 x 2 x 0.3 m,
// its top at z 0.3) from above and from the side, and on a free body two blocks side by side with
// a gap between them (a concave mesh), met on each block and passing through the gap.
TEST_P(MeshCollisions, RaysMeetMeshes) {
  MeshFolder folder;
  const std::string block = folder.write("block.stl", boxStl(kBlockLo, kBlockHi));
  const std::string pair = folder.write(
      "pair.stl", boxStl({-0.5, -0.5, 0}, {-0.1, 0.5, 1}) + boxStl({0.1, -0.5, 0}, {0.5, 0.5, 1}));
  World world(GetParam());
  Status status =
      world.spawn("floor", staticMeshUrdf(block, {2, 2, 0.3}), ModelFormat::Urdf, Pose());
  ASSERT_TRUE(status.ok()) << status;
  status = world.spawn("pair", movingMeshUrdf(pair, {1, 1, 1}, {1, 1, 1}, 0.5), ModelFormat::Urdf,
                       at(0, 5, 2));
  ASSERT_TRUE(status.ok()) << status;
  const std::vector<Ray> rays{
      {{0.2, 0.1, 2}, {0, 0, -1}, 5},    // onto the floor's top
      {{-3, 0.5, 0.1}, {1, 0, 0}, 5},    // into the floor's side
      {{-0.3, 3, 2.5}, {0, 1, 0}, 5},    // into the pair's left block
      {{0.3, 3, 2.5}, {0, 1, 0}, 5},     // into its right block
      {{0, 5, 4}, {0, 0, -1}, 1.9},      // down the gap, short of the floor of nothing
      {{0, 3, 2.5}, {0, 1, 0}, 5},       // through the gap, out the other side
  };
  std::vector<double> distances;
  status = world.castRays(rays, &distances);
  ASSERT_TRUE(status.ok()) << status;
  ASSERT_EQ(distances.size(), rays.size());
  // Bullet casts a ray at a convex hull (the floor) iteratively and stops 0.11 mm short of its
  // side; on triangles and on its primitives it is exact, as ODE is throughout.
  constexpr double kHullTolerance = 2e-4;
  EXPECT_NEAR(distances[0], 1.7, kHullTolerance);
  EXPECT_NEAR(distances[1], 2, kHullTolerance);
  EXPECT_NEAR(distances[2], 1.5, 1e-6);
  EXPECT_NEAR(distances[3], 1.5, 1e-6);
  if (GetParam() == "mujoco") {
    // MuJoCo takes a mesh as its convex hull, for rays as for contacts: the gap between the
    // pair's blocks is inside it, whose top is at z 3 and whose near side at y 4.5.
    EXPECT_NEAR(distances[4], 1, 1e-6);
    EXPECT_NEAR(distances[5], 1.5, 1e-6);
  } else {
    EXPECT_TRUE(std::isinf(distances[4])) << distances[4];
    EXPECT_TRUE(std::isinf(distances[5])) << distances[5];
  }
}

// The unit block as `data` in the file `name` (named as `uri_prefix` and its path), scaled to
// `sides` on a free body, its link origin at the middle of its bottom, dropped from `drop`: it
// rests on the ground with the origin at z 0, whatever height it fell from.
void expectBlockBodyRestsOnTheGround(const std::string& engine, const std::string& name,
                                     const std::string& data, const std::string& uri_prefix,
                                     const Vec3& sides, double drop, const char* what) {
  MeshFolder folder;
  const std::string file = folder.write(name, data);
  World world(engine);
  testing_support::addGroundPlane(world);
  const Status status = world.spawn(
      "body", movingMeshUrdf(uri_prefix + file, sides, sides, sides.z / 2), ModelFormat::Urdf,
      at(0, 0, drop));
  ASSERT_TRUE(status.ok()) << status;
  double speed = 0;
  expectRestsAt(restingPose(&world, "body", &speed), speed, 0, what);
}

// The block scaled to 0.2 x 0.3 x 0.1, named by a file:// URI.
TEST_P(MeshCollisions, MeshBodyRestsOnTheGround) {
  expectBlockBodyRestsOnTheGround(GetParam(), "block.stl", boxStl(kBlockLo, kBlockHi), "file://",
                                  {0.2, 0.3, 0.1}, 0.3, "mesh body on the ground");
}

// A dense mesh: the block of 19,200 triangles (a vertex every 5 mm) touches the ground at
// hundreds of points, of which an engine keeps a few; they must spread over its bottom.
TEST_P(MeshCollisions, DenseMeshBodyRestsOnTheGround) {
  expectBlockBodyRestsOnTheGround(GetParam(), "dense.stl", subdividedBlockStl(40), "",
                                  {0.2, 0.2, 0.2}, 0.05, "dense mesh body on the ground");
}

// Mesh on mesh: the body of MeshBodyRestsOnTheGround on the floor of the first test.
TEST_P(MeshCollisions, MeshBodyRestsOnAStaticMeshFloor) {
  MeshFolder folder;
  const std::string stl = folder.write("block.stl", boxStl(kBlockLo, kBlockHi));
  World world(GetParam());
  Status status = world.spawn("floor", staticMeshUrdf(stl, {2, 2, 0.3}), ModelFormat::Urdf, Pose());
  ASSERT_TRUE(status.ok()) << status;
  status = world.spawn("body", movingMeshUrdf(stl, {0.2, 0.3, 0.1}, {0.2, 0.3, 0.1}, 0.05),
                       ModelFormat::Urdf, at(0.1, 0.1, 0.5));
  ASSERT_TRUE(status.ok()) << status;
  double speed = 0;
  expectRestsAt(restingPose(&world, "body", &speed), speed, 0.3, "mesh body on a mesh floor");
}

// Steps 0.5 s for a dropped model to land, then checks that it rests at `height` every 0.25 s up
// to 2 s: a body whose contacts jitter hops off its rest between the checks.
void expectStaysAt(World* world, const std::string& model, double height,
                   const std::string& what) {
  stepFor(world, 500);
  for (int ms = 750; ms <= 2000; ms += 250) {
    stepFor(world, 250);
    double speed = 0;
    const Pose pose = poseAndSpeed(world, model, &speed);
    expectRestsAt(pose, speed, height, (what + " at " + std::to_string(ms) + " ms").c_str());
  }
}

// A closed mesh box collides as the box it is where its edges meet another shape's: a 0.2 m box
// dropped 2 mm off the middle of a static 0.2 x 0.2 x 0.3 mesh block, whose top it covers edge to
// edge, rests with its centre at 0.4.
TEST_P(MeshCollisions, BoxRestsOnAMeshBlockOfItsFootprint) {
  MeshFolder folder;
  const std::string stl = folder.write("block.stl", boxStl(kBlockLo, kBlockHi));
  World world(GetParam());
  Status status =
      world.spawn("block", staticMeshUrdf(stl, {0.2, 0.2, 0.3}), ModelFormat::Urdf, Pose());
  ASSERT_TRUE(status.ok()) << status;
  status = world.spawn("box", boxUrdf(0.2), ModelFormat::Urdf, at(0.002, 0, 0.5));
  ASSERT_TRUE(status.ok()) << status;
  expectStaysAt(&world, "box", 0.4, "box on a mesh block");
}

// The moving 0.2 x 0.2 x 0.3 mesh block rests on the ground at its height, and 0.2 higher on a
// 0.2 m box resting on the ground, whose top it covers edge to edge.
TEST_P(MeshCollisions, MeshBlockRestsOnTheGroundAndOnABox) {
  MeshFolder folder;
  const std::string stl = folder.write("block.stl", boxStl(kBlockLo, kBlockHi));
  const Vec3 sides{0.2, 0.2, 0.3};
  World world(GetParam());
  testing_support::addGroundPlane(world);
  Status status = world.spawn("on_ground", movingMeshUrdf(stl, sides, sides, 0.15),
                              ModelFormat::Urdf, at(1, 0, 0.05));
  ASSERT_TRUE(status.ok()) << status;
  status = world.spawn("box", boxUrdf(0.2), ModelFormat::Urdf, at(-1, 0, 0.1));
  ASSERT_TRUE(status.ok()) << status;
  status = world.spawn("on_box", movingMeshUrdf(stl, sides, sides, 0.15), ModelFormat::Urdf,
                       at(-1, 0, 0.25));
  ASSERT_TRUE(status.ok()) << status;
  expectStaysAt(&world, "on_ground", 0, "mesh block on the ground");
  expectStaysAt(&world, "on_box", 0.2, "mesh block on a box");
}

// The shape the world reports (and rviz draws): the file, its scale, its pose.
TEST_P(MeshCollisions, CollisionShapesNameTheFileAndScale) {
  MeshFolder folder;
  const std::string stl = folder.write("block.stl", boxStl(kBlockLo, kBlockHi));
  World world(GetParam());
  ASSERT_TRUE(world.spawn("floor", staticMeshUrdf(stl, {2, 2, 0.3}), ModelFormat::Urdf,
                          at(1, 0, 0)).ok());
  const std::vector<CollisionShape> shapes = world.collisionShapes();
  ASSERT_EQ(shapes.size(), 1u);
  EXPECT_EQ(shapes[0].shape, GeometryShape::Mesh);
  EXPECT_EQ(shapes[0].mesh_file, stl);
  EXPECT_EQ(shapes[0].size.x, 2);
  EXPECT_EQ(shapes[0].size.z, 0.3);
  EXPECT_EQ(shapes[0].pose.position.x, 1);
}

// model:// and package:// (which Gazebo's URDF conversion reads as model://) look in the model
// path; a mesh found nowhere leaves its collision out, as Gazebo does, naming the URI and the
// folders searched.
TEST_P(MeshCollisions, UrisResolveThroughTheModelPath) {
  MeshFolder folder;
  folder.write("blocks/meshes/block.stl", boxStl(kBlockLo, kBlockHi));
  World world(GetParam());
  world.setModelPath({"/nonexistent", folder.root()});
  for (const std::string scheme : {"model", "package"}) {
    const Status status =
        world.spawn(scheme, staticMeshUrdf(scheme + "://blocks/meshes/block.stl", {1, 1, 1}),
                    ModelFormat::Urdf, Pose());
    EXPECT_TRUE(status.ok()) << status;
  }
  PreparedModel missing = World::prepare(
      staticMeshUrdf("model://blocks/meshes/gone.stl", {1, 1, 1}), ModelFormat::Urdf,
      world.modelPath());
  ASSERT_TRUE(missing.status().ok()) << missing.status();
  ASSERT_EQ(missing.leftOut().size(), 1u);
  const std::string& why = missing.leftOut()[0];
  EXPECT_NE(why.find("'model://blocks/meshes/gone.stl', which is not found"), std::string::npos)
      << why;
  EXPECT_NE(why.find("/nonexistent, " + folder.root()), std::string::npos) << why;
  ASSERT_TRUE(world.spawn("missing", std::move(missing), Pose()).ok());
  ModelInfo info;
  ASSERT_TRUE(world.modelProperties("missing", &info).ok());
  EXPECT_TRUE(info.geoms.empty());
  EXPECT_EQ(world.modelNames().size(), 3u);
}

TEST_P(MeshCollisions, UnreadableMeshIsRefusedNamingTheFile) {
  MeshFolder folder;
  const std::string broken = folder.write("broken.dae", "<COLLADA/>");
  const std::string empty = folder.write("empty.stl", "solid nothing\nendsolid nothing\n");
  World world(GetParam());
  for (const std::string& file : {broken, empty}) {
    const Status status =
        world.spawn("floor", staticMeshUrdf(file, {1, 1, 1}), ModelFormat::Urdf, Pose());
    EXPECT_EQ(status.code, StatusCode::ModelRejected);
    EXPECT_NE(status.subject.find("link 'floor'"), std::string::npos) << status;
    EXPECT_NE(status.subject.find("the mesh file " + file), std::string::npos) << status;
  }
  const Status zero =
      world.spawn("floor", staticMeshUrdf(broken, {1, 0, 1}), ModelFormat::Urdf, Pose());
  EXPECT_NE(zero.subject.find("zero or non-finite scale"), std::string::npos) << zero;
  EXPECT_TRUE(world.modelNames().empty());
}

// Past 20000 triangles in one mesh, or 50000 in a model's meshes, a model is refused naming the
// limit; at the limits it is taken.
TEST_P(MeshCollisions, TriangleLimitsAreRefusedNamingTheLimit) {
  MeshFolder folder;
  const std::string at_limit = folder.write("at_limit.stl", manyTrianglesStl(20000));
  const std::string past = folder.write("past.stl", manyTrianglesStl(20001));
  World world(GetParam());
  Status status =
      world.spawn("past", staticMeshUrdf(past, {1, 1, 1}), ModelFormat::Urdf, at(0, 0, -1));
  EXPECT_EQ(status.code, StatusCode::ModelRejected);
  EXPECT_NE(status.subject.find("has 20001 triangles; at most 20000 are accepted per mesh"),
            std::string::npos) << status;
  // One file used by three collisions counts three times.
  std::string three = staticMeshUrdf(at_limit, {1, 1, 1});
  const std::string collision = "<collision><geometry>" + meshElement(at_limit, {1, 1, 1}) +
                                "</geometry></collision>";
  three.insert(three.find("</link></robot>"), collision + collision);
  status = world.spawn("three", three, ModelFormat::Urdf, at(0, 0, -1));
  EXPECT_EQ(status.code, StatusCode::ModelRejected);
  EXPECT_NE(status.subject.find("have 60000 triangles"), std::string::npos) << status;
  EXPECT_NE(status.subject.find("at most 50000 are accepted per model"), std::string::npos)
      << status;
  std::string two = staticMeshUrdf(at_limit, {1, 1, 1});
  two.insert(two.find("</link></robot>"), collision);
  status = world.spawn("two", two, ModelFormat::Urdf, at(0, 0, -1));
  EXPECT_TRUE(status.ok()) << status;
}

// The inertia check covers a mesh through the box bounding its vertices: a 1 m block on a body
// of 1 kg with a solid 1 cm cube's moments is warned of as a 1 m box would be, and spawned; one
// with a solid 1 m cube's moments is not warned of.
TEST_P(MeshCollisions, InertiaIsCheckedAgainstTheMeshBounds) {
  MeshFolder folder;
  const std::string stl = folder.write("block.stl", boxStl(kBlockLo, kBlockHi));
  World world(GetParam());
  PreparedModel thin = World::prepare(movingMeshUrdf(stl, {1, 1, 1}, {0.01, 0.01, 0.01}, 0.5),
                                      ModelFormat::Urdf, {});
  ASSERT_TRUE(thin.status().ok()) << thin.status();
  ASSERT_EQ(thin.warnings().size(), 1u);
  EXPECT_EQ(thin.warnings()[0].link, "body");
  EXPECT_NEAR(thin.warnings()[0].smallest_moment, 0.0002 / 12, 1e-9);
  EXPECT_GT(thin.warnings()[0].least_moment, 10 * thin.warnings()[0].smallest_moment);
  EXPECT_TRUE(world.spawn("thin", std::move(thin), at(0, 0, 1)).ok());
  PreparedModel solid =
      World::prepare(movingMeshUrdf(stl, {1, 1, 1}, {1, 1, 1}, 0.5), ModelFormat::Urdf, {});
  ASSERT_TRUE(solid.status().ok()) << solid.status();
  EXPECT_TRUE(solid.warnings().empty());
  EXPECT_TRUE(world.spawn("solid", std::move(solid), at(3, 0, 1)).ok());
}

INSTANTIATE_TEST_SUITE_P(Engines, MeshCollisions, ::testing::ValuesIn(World::engineNames()),
                         [](const auto& info) { return info.param; });

}  // namespace
}  // namespace onedof_sim
