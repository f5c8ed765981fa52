// The camera renderer on scenes made here: where a box lands in the image for the field of view,
// its colour, its depth along the optical axis, an empty frame, and repeatability. Headless:
// Mesa's surfaceless EGL, no X server.
#include <gtest/gtest.h>

#include <cmath>

#include "renderer.h"

namespace onedof_sim {
namespace render {
namespace {

constexpr int kWidth = 640, kHeight = 480;
constexpr double kFov = 1.047, kFar = 10;

std::unique_ptr<Renderer> makeRenderer() {
  std::string error;
  auto renderer = Renderer::create(&error);
  EXPECT_TRUE(renderer) << error;
  return renderer;
}

CameraSpec camera() {
  CameraSpec spec;
  spec.horizontal_fov = kFov;
  spec.width = kWidth;
  spec.height = kHeight;
  spec.near_clip = 0.1;
  spec.far_clip = kFar;
  return spec;
}

// A box 0.2 deep, 0.4 wide, 0.3 high, its near face 1.9 m ahead, spanning y in [-0.1, 0.3]:
// more of it to the camera's left (+y).
VisualShape redBox() {
  VisualShape box;
  box.model = "box";
  box.link = "link";
  box.name = "visual";
  box.shape = GeometryShape::Box;
  box.size = {0.2, 0.4, 0.3};
  box.pose.position = {2.0, 0.1, 0.0};
  box.material.script = "Gazebo/Red";
  return box;
}

double focalPixels() { return kWidth / (2 * std::tan(kFov / 2)); }

// The column of the image a point at lateral offset y (+y: left) and distance x ahead projects to.
double columnOf(double y, double x) { return kWidth / 2.0 - focalPixels() * y / x; }

struct RedSpan {
  int first = -1, last = -1;
};

RedSpan redColumns(const Frame& frame, int row) {
  RedSpan span;
  for (int u = 0; u < frame.width; ++u) {
    const uint8_t* p = &frame.rgb[(static_cast<size_t>(row) * frame.width + u) * 3];
    if (p[0] > 50 && p[1] == 0 && p[2] == 0) {
      if (span.first < 0) span.first = u;
      span.last = u;
    }
  }
  return span;
}

TEST(Renderer, BoxLandsInTheColumnsItsAngularExtentPredicts) {
  auto renderer = makeRenderer();
  ASSERT_TRUE(renderer);
  Frame frame;
  std::string error;
  ASSERT_TRUE(renderer->render({redBox()}, camera(), &frame, &error)) << error;
  ASSERT_EQ(frame.width, kWidth);
  ASSERT_EQ(frame.height, kHeight);
  // The near face (x = 1.9) bounds the silhouette; a pixel is covered where its centre is.
  const double left_edge = columnOf(0.3, 1.9), right_edge = columnOf(-0.1, 1.9);
  const RedSpan span = redColumns(frame, kHeight / 2);
  ASSERT_GE(span.first, 0) << "no red pixel in the middle row";
  EXPECT_NEAR(span.first, std::ceil(left_edge - 0.5), 1.0);
  EXPECT_NEAR(span.last, std::floor(right_edge - 0.5), 1.0);
  // +y is the image's left: the box reaches farther left of the centre than right of it.
  EXPECT_GT(kWidth / 2 - span.first, 2 * (span.last - kWidth / 2));
}

TEST(Renderer, ACameraInsideItsOwnCaseSeesOutOfIt) {
  auto renderer = makeRenderer();
  ASSERT_TRUE(renderer);
  // The book's camera: its lens at the centre of a 0.1 x 0.02 x 0.02 m case, near clip 0.01 m.
  VisualShape case_box;
  case_box.model = "camera";
  case_box.link = "camera_link";
  case_box.name = "case";
  case_box.shape = GeometryShape::Box;
  case_box.size = {0.1, 0.02, 0.02};
  case_box.material.script = "Gazebo/Blue";
  CameraSpec spec = camera();
  spec.near_clip = 0.01;
  Frame frame, without_case;
  std::string error;
  ASSERT_TRUE(renderer->render({case_box, redBox()}, spec, &frame, &error)) << error;
  ASSERT_TRUE(renderer->render({redBox()}, spec, &without_case, &error)) << error;
  EXPECT_EQ(frame.rgb, without_case.rgb);
  EXPECT_EQ(frame.depth, without_case.depth);
}

TEST(Renderer, BoxIsRedAndTheBackgroundGrey) {
  auto renderer = makeRenderer();
  ASSERT_TRUE(renderer);
  Frame frame;
  std::string error;
  ASSERT_TRUE(renderer->render({redBox()}, camera(), &frame, &error)) << error;
  const int u = static_cast<int>(columnOf(0.1, 1.9)), v = kHeight / 2;
  const uint8_t* p = &frame.rgb[(static_cast<size_t>(v) * kWidth + u) * 3];
  // The face towards the camera is away from the sun: Gazebo/Red's ambient 1 0 0 under the
  // scene's ambient 0.4.
  EXPECT_EQ(p[0], 102);
  EXPECT_EQ(p[1], 0);
  EXPECT_EQ(p[2], 0);
  const uint8_t* corner = &frame.rgb[0];
  EXPECT_EQ(corner[0], 178);  // Gazebo's background, 0.7 grey: 178.49 rounded
  EXPECT_EQ(corner[1], 178);
  EXPECT_EQ(corner[2], 178);
}

TEST(Renderer, SixteenBitsAChannelAreTheEightBitColoursFiner) {
  auto renderer = makeRenderer();
  ASSERT_TRUE(renderer);
  Frame narrow, deep;
  std::string error;
  ASSERT_TRUE(renderer->render({redBox()}, camera(), &narrow, &error)) << error;
  CameraSpec spec = camera();
  spec.channel_bits = 16;
  ASSERT_TRUE(renderer->render({redBox()}, spec, &deep, &error)) << error;
  ASSERT_TRUE(deep.rgb.empty());
  ASSERT_EQ(deep.rgb16.size(), narrow.rgb.size());
  EXPECT_EQ(deep.depth, narrow.depth);
  // The same colours, each rounded to 16 bits instead of 8: 0.4 red is 26214 (102 x 257 = 26214),
  // the 0.7 grey background 45874.5 rounded (178 x 257 = 45746).
  const int u = static_cast<int>(columnOf(0.1, 1.9)), v = kHeight / 2;
  const size_t red = (static_cast<size_t>(v) * kWidth + u) * 3;
  EXPECT_NEAR(deep.rgb16[red], 26214, 1);
  EXPECT_EQ(deep.rgb16[red + 1], 0);
  EXPECT_NEAR(deep.rgb16[0], 45875, 1);
  for (size_t i = 0; i < narrow.rgb.size(); ++i)
    ASSERT_LE(std::abs(deep.rgb16[i] / 257.0 - narrow.rgb[i]), 0.5 + 1.0 / 257) << i;
}

TEST(Renderer, DepthIsTheDistanceAlongTheOpticalAxis) {
  auto renderer = makeRenderer();
  ASSERT_TRUE(renderer);
  Frame frame;
  std::string error;
  ASSERT_TRUE(renderer->render({redBox()}, camera(), &frame, &error)) << error;
  const RedSpan span = redColumns(frame, kHeight / 2);
  ASSERT_GE(span.first, 0);
  const auto depthAt = [&](int u) { return frame.depth[(kHeight / 2) * kWidth + u]; };
  EXPECT_NEAR(depthAt(static_cast<int>(columnOf(0.1, 1.9))), 1.9, 0.01);
  // At the box's left edge the ray is 0.16 rad off the axis: its length would be 1.92 m; the
  // depth stays the face's distance along the axis.
  EXPECT_NEAR(depthAt(span.first), 1.9, 0.001);
  EXPECT_FLOAT_EQ(depthAt(0), static_cast<float>(kFar));
}

TEST(Renderer, EmptyFrameIsBackgroundAndFarClip) {
  auto renderer = makeRenderer();
  ASSERT_TRUE(renderer);
  Frame frame;
  std::string error;
  ASSERT_TRUE(renderer->render({}, camera(), &frame, &error)) << error;
  for (float depth : frame.depth) ASSERT_EQ(depth, static_cast<float>(kFar));
  for (uint8_t channel : frame.rgb) ASSERT_EQ(channel, 178);
  // Beyond the far clip is nothing too.
  VisualShape far_box = redBox();
  far_box.pose.position.x = kFar + 1;
  ASSERT_TRUE(renderer->render({far_box}, camera(), &frame, &error)) << error;
  for (float depth : frame.depth) ASSERT_EQ(depth, static_cast<float>(kFar));
}

TEST(Renderer, CameraPoseTurnsTheView) {
  auto renderer = makeRenderer();
  ASSERT_TRUE(renderer);
  // The camera a quarter turn to the left (yaw +pi/2) sees along +y; a box 2 m out on +y, the
  // camera 1 m up and the box too: at the image's centre.
  CameraSpec spec = camera();
  spec.pose.position = {0, 0, 1};
  spec.pose.orientation = {std::cos(M_PI / 4), 0, 0, std::sin(M_PI / 4)};
  VisualShape box = redBox();
  box.pose.position = {0, 2, 1};
  Frame frame;
  std::string error;
  ASSERT_TRUE(renderer->render({box}, spec, &frame, &error)) << error;
  const RedSpan span = redColumns(frame, kHeight / 2);
  ASSERT_GE(span.first, 0);
  EXPECT_NEAR((span.first + span.last) / 2.0, kWidth / 2.0, 1.5);
  // The box is 0.4 m along x, seen across: its near face at 2 - 0.2.
  EXPECT_NEAR(frame.depth[(kHeight / 2) * kWidth + kWidth / 2], 1.8, 0.01);
}

TEST(Renderer, SameSceneGivesTheSameBytes) {
  auto renderer = makeRenderer();
  ASSERT_TRUE(renderer);
  VisualShape sphere;
  sphere.model = "ball";
  sphere.shape = GeometryShape::Sphere;
  sphere.size = {0.3, 0, 0};
  sphere.pose.position = {3, -0.5, 0.2};
  sphere.material.diffuse = Color{0, 0.5f, 1, 1};
  VisualShape ground;
  ground.model = "ground_plane";
  ground.shape = GeometryShape::Plane;
  ground.size = {100, 100, 0};
  ground.pose.position = {0, 0, -0.5};
  ground.material.script = "Gazebo/Grey";
  const std::vector<VisualShape> scene = {ground, redBox(), sphere};
  Frame first, second, other;
  std::string error;
  ASSERT_TRUE(renderer->render(scene, camera(), &first, &error)) << error;
  ASSERT_TRUE(renderer->render(scene, camera(), &second, &error)) << error;
  auto another = makeRenderer();
  ASSERT_TRUE(another);
  ASSERT_TRUE(another->render(scene, camera(), &other, &error)) << error;
  EXPECT_TRUE(first.rgb == second.rgb);
  EXPECT_TRUE(first.depth == second.depth);
  EXPECT_TRUE(first.rgb == other.rgb);
  EXPECT_TRUE(first.depth == other.depth);
  // The ground is drawn: the bottom row sees it 0.5 m below the camera.
  const float bottom = first.depth[static_cast<size_t>(kHeight - 1) * kWidth + kWidth / 2];
  EXPECT_LT(bottom, kFar);
  EXPECT_GT(bottom, 0.5f);
}

TEST(Renderer, RefusesABadCameraAndReportsWhatItCannotDraw) {
  auto renderer = makeRenderer();
  ASSERT_TRUE(renderer);
  Frame frame;
  std::string error;
  CameraSpec spec = camera();
  spec.horizontal_fov = 4;
  EXPECT_FALSE(renderer->render({}, spec, &frame, &error));
  EXPECT_NE(error.find("horizontal_fov"), std::string::npos) << error;
  spec = camera();
  spec.near_clip = 2, spec.far_clip = 1;
  EXPECT_FALSE(renderer->render({}, spec, &frame, &error));
  VisualShape mesh;
  mesh.model = "m", mesh.link = "l", mesh.name = "v";
  mesh.shape = GeometryShape::Mesh;
  mesh.size = {1, 1, 1};
  mesh.mesh_uri = "model://nowhere/mesh.stl";
  VisualShape flat = redBox();
  flat.size.z = 0;
  VisualShape unknown = redBox();
  unknown.material.script = "Gazebo/NoSuchColour";
  ASSERT_TRUE(renderer->render({mesh, flat, unknown}, camera(), &frame, &error)) << error;
  ASSERT_TRUE(renderer->render({mesh, flat, unknown}, camera(), &frame, &error)) << error;
  const std::vector<std::string> problems = renderer->takeProblems();
  ASSERT_EQ(problems.size(), 3u);  // each once, however many frames
  EXPECT_NE(problems[0].find("m::l::v: not drawn: its mesh 'model://nowhere/mesh.stl' is not found"),
            std::string::npos)
      << problems[0];
  EXPECT_NE(problems[1].find("size"), std::string::npos) << problems[1];
  EXPECT_NE(problems[2].find("Gazebo/NoSuchColour"), std::string::npos) << problems[2];
  EXPECT_TRUE(renderer->takeProblems().empty());
}

}  // namespace
}  // namespace render
}  // namespace onedof_sim

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
