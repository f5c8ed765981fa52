// Gazebo's bottom bar figures from clock readings: sim time, real time (running on while
// paused), the real-time factor over the last second (0 once the clock stops), the iterations in
// steps, and a reset (the clock going back) starting real time and iterations again.
#include <gtest/gtest.h>

#include "time_figures.h"

using gazebo_ros_panels::gazeboTimeText;
using gazebo_ros_panels::TimeFigures;

namespace {
constexpr int64_t kMs = 1000000;
constexpr int64_t kS = 1000000000;
}  // namespace

TEST(TimeFigures, NothingBeforeTheFirstReading) {
  TimeFigures figures;
  EXPECT_FALSE(figures.seen());
  EXPECT_EQ(figures.realSeconds(5 * kS), 0);
  EXPECT_EQ(figures.realTimeFactor(5 * kS), 0);
  EXPECT_EQ(figures.iterations(), 0u);
}

TEST(TimeFigures, HalfRealTimeCountsItsStepsAndItsFactor) {
  TimeFigures figures;
  figures.stepSize(0.001);
  const int64_t wall0 = 100 * kS;
  for (int i = 0; i <= 300; ++i) figures.clock(i * 10 * kMs, wall0 + i * 20 * kMs);
  EXPECT_DOUBLE_EQ(figures.simSeconds(), 3.0);
  EXPECT_EQ(figures.iterations(), 3000u);
  EXPECT_NEAR(figures.realTimeFactor(wall0 + 6 * kS), 0.5, 1e-9);
  EXPECT_NEAR(figures.realSeconds(wall0 + 6 * kS), 6.0, 1e-9);
}

TEST(TimeFigures, PausedTheFactorIsZeroAndRealTimeRunsOn) {
  TimeFigures figures;
  figures.stepSize(0.001);
  figures.clock(0, 0);
  figures.clock(100 * kMs, 100 * kMs);
  EXPECT_NEAR(figures.realTimeFactor(150 * kMs), 1.0, 1e-9);
  EXPECT_EQ(figures.realTimeFactor(1100 * kMs), 0);  // no reading for a second
  EXPECT_NEAR(figures.realSeconds(10 * kS), 10.0, 1e-9);
  EXPECT_EQ(figures.iterations(), 100u);
}

TEST(TimeFigures, AResetStartsRealTimeAndIterationsAgain) {
  TimeFigures figures;
  figures.stepSize(0.01);
  figures.clock(5 * kS, 1 * kS);
  figures.clock(6 * kS, 2 * kS);
  figures.clock(20 * kMs, 3 * kS);
  EXPECT_EQ(figures.iterations(), 2u);
  EXPECT_NEAR(figures.realSeconds(4 * kS), 1.0, 1e-9);
  EXPECT_EQ(figures.realTimeFactor(3 * kS), 0);  // one reading since the reset
}

TEST(TimeFigures, AStepSizeLearntLateCountsTheStepsAlreadyRun) {
  TimeFigures figures;
  figures.clock(2 * kS, 0);
  EXPECT_EQ(figures.iterations(), 0u);
  figures.stepSize(0.001);
  EXPECT_EQ(figures.iterations(), 2000u);
  figures.stepSize(0.002);  // set_physics_properties: the new step counts from here on
  figures.clock(3 * kS, 1 * kS);
  EXPECT_EQ(figures.iterations(), 2500u);
}

TEST(TimeFigures, GazebosTimeText) {
  EXPECT_EQ(gazeboTimeText(0), "00 00:00:00.000");
  EXPECT_EQ(gazeboTimeText(3723.4567), "00 01:02:03.457");
  EXPECT_EQ(gazeboTimeText(90000), "01 01:00:00.000");
  EXPECT_EQ(gazeboTimeText(-1), "00 00:00:00.000");
}
