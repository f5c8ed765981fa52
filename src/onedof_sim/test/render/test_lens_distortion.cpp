// The lens distortion's remap, on frames made here whose pixels carry their own coordinates
// (a bilinear interpolation of a linear ramp is exact): each pixel of the distorted image shows
// the pinhole point the Brown-Conrady model sends to it, the wider render covers barrel
// distortion's corners, pincushion needs no margin, a strong barrel's fold is black, and the
// depth is the pinhole's own.
#include <gtest/gtest.h>

#include <cmath>

#include "lens_distortion.h"

namespace onedof_sim {
namespace render {
namespace {

constexpr int kWidth = 160, kHeight = 120;
constexpr double kFocal = 150;
constexpr double kScale = 64;  // a pixel's coordinates are stored times this, in 16 bits

// A render of the lens's size whose pixel (x, y) holds (x, y) * kScale and its depth x + y.
Frame coordinateFrame(const LensDistortion& lens) {
  Frame frame;
  frame.width = lens.renderWidth();
  frame.height = lens.renderHeight();
  for (int y = 0; y < frame.height; ++y)
    for (int x = 0; x < frame.width; ++x) {
      frame.rgb16.push_back(static_cast<uint16_t>(x * kScale));
      frame.rgb16.push_back(static_cast<uint16_t>(y * kScale));
      frame.rgb16.push_back(1);
      frame.depth.push_back(static_cast<float>(x + y));
    }
  return frame;
}

// Every pixel that is not black shows the point the model sends to it, to within the stored
// coordinates' rounding; returns how many are black.
long checkEveryPixel(const DistortionCoefficients& coefficients, long budget = 1L << 30) {
  const LensDistortion lens(coefficients, kWidth, kHeight, kFocal, budget);
  Frame out;
  lens.apply(coordinateFrame(lens), &out);
  EXPECT_EQ(out.width, kWidth);
  EXPECT_EQ(out.height, kHeight);
  EXPECT_TRUE(out.rgb.empty());
  const double margin_x = (lens.renderWidth() - kWidth) / 2.0;
  const double margin_y = (lens.renderHeight() - kHeight) / 2.0;
  const double cx = coefficients.center_x * kWidth - 0.5;
  const double cy = coefficients.center_y * kHeight - 0.5;
  long black = 0;
  for (int row = 0; row < kHeight; ++row)
    for (int col = 0; col < kWidth; ++col) {
      const uint16_t* p = &out.rgb16[(static_cast<size_t>(row) * kWidth + col) * 3];
      if (p[2] == 0) {
        ++black;
        continue;
      }
      const double x = (p[0] / kScale - margin_x - cx) / kFocal;
      const double y = (p[1] / kScale - margin_y - cy) / kFocal;
      double x_d, y_d;
      distortNormalised(coefficients, x, y, &x_d, &y_d);
      EXPECT_NEAR(cx + kFocal * x_d, col, 0.05) << row << " " << col;
      EXPECT_NEAR(cy + kFocal * y_d, row, 0.05) << row << " " << col;
      // The depth is the pinhole render's, from its middle.
      EXPECT_EQ(out.depth[static_cast<size_t>(row) * kWidth + col],
                static_cast<float>(col + margin_x + row + margin_y));
    }
  EXPECT_EQ(black, lens.blackPixels());
  return black;
}

TEST(LensDistortion, NoCoefficientsIsAPinhole) {
  EXPECT_TRUE(DistortionCoefficients().none());
  DistortionCoefficients lens;
  lens.p2 = 1e-3;
  EXPECT_FALSE(lens.none());
}

TEST(LensDistortion, BarrelDistortionSeesPastThePinholeAndLeavesNoBlackCorner) {
  DistortionCoefficients barrel;
  barrel.k1 = -0.25, barrel.k2 = 0.05, barrel.p1 = 0.002, barrel.p2 = -0.001;
  const LensDistortion lens(barrel, kWidth, kHeight, kFocal, 1L << 30);
  EXPECT_GT(lens.renderWidth(), kWidth);
  EXPECT_GT(lens.renderHeight(), kHeight);
  EXPECT_NEAR(lens.renderHorizontalFov(), 2 * std::atan(lens.renderWidth() / (2 * kFocal)),
              1e-15);
  EXPECT_EQ(checkEveryPixel(barrel), 0);
}

TEST(LensDistortion, PincushionDistortionNeedsNoMargin) {
  DistortionCoefficients pincushion;
  pincushion.k1 = 0.2, pincushion.k3 = 0.05;
  pincushion.center_x = 0.45, pincushion.center_y = 0.55;
  const LensDistortion lens(pincushion, kWidth, kHeight, kFocal, 1L << 30);
  EXPECT_EQ(lens.renderWidth(), kWidth);
  EXPECT_EQ(lens.renderHeight(), kHeight);
  EXPECT_EQ(checkEveryPixel(pincushion), 0);
}

TEST(LensDistortion, PastAStrongBarrelsFoldThePixelsAreBlack) {
  // r (1 + k1 r^2) is largest at r = 1 / sqrt(-3 k1), where it is 2 / (3 sqrt(-3 k1)): the lens
  // shows nothing farther from the centre than that, and the pixels there are black.
  DistortionCoefficients fold;
  fold.k1 = -0.6;
  const double reach = kFocal * 2 / (3 * std::sqrt(-3 * fold.k1));
  long beyond = 0;
  for (int row = 0; row < kHeight; ++row)
    for (int col = 0; col < kWidth; ++col)
      beyond += std::hypot(col - (kWidth - 1) / 2.0, row - (kHeight - 1) / 2.0) > reach;
  ASSERT_GT(beyond, 1000);
  // Newton's method may give up on the odd pixel at the fold itself, where the lens flattens.
  EXPECT_NEAR(checkEveryPixel(fold), beyond, 20);
}

TEST(LensDistortion, TheWiderRenderKeepsWithinItsBudget) {
  DistortionCoefficients barrel;
  barrel.k1 = -0.25;
  const LensDistortion lens(barrel, kWidth, kHeight, kFocal, kWidth * kHeight + 2000);
  EXPECT_LE(static_cast<long>(lens.renderWidth()) * lens.renderHeight(),
            kWidth * kHeight + 2000);
  // With too small a margin, the corners are black.
  EXPECT_GT(checkEveryPixel(barrel, kWidth * kHeight + 2000), 0);
}

}  // namespace
}  // namespace render
}  // namespace onedof_sim
