// The friction of a sliding contact over a step's solves (src/core/engines/mujoco_sliding.h),
// against stand-in solves written here: a normal force that falls with the friction applied, as a
// caster's or a driven wheel's does, and a slip that the friction brings to rest.
#include <gtest/gtest.h>

#include <algorithm>
#include <functional>

#include "engines/mujoco_sliding.h"

namespace onedof_sim {
namespace core {
namespace {

constexpr double kStep = 0.001;  // s
constexpr int kPasses = 6;       // as mujoco_engine.cpp's kSlidingPasses

// A solve with friction f applied: its normal force, and the slip at the step's end.
struct Solve {
  std::function<double(double)> normal;
  std::function<double(double)> slip_at_end;
};

// The friction after kPasses solves, the first without friction.
double afterPasses(SlidingFriction* law, const Solve& solve) {
  double f = 0;
  for (int pass = 0; pass < kPasses; ++pass)
    f = law->next(solve.normal(f), solve.slip_at_end(f), kStep);
  return f;
}

// A slide that goes on past the step: the friction is Coulomb's, mu times the normal force it
// leaves, for a normal force that falls steeply with it (a driven wheel of mu 2, lifted by 600 N
// of friction) and gently (a caster's drag moving a third of its load off it).
TEST(SlidingFriction, ASlideThatGoesOnTakesMuTimesTheNormalForceItsFrictionLeaves) {
  for (const auto& [mu, n0, fall] : {std::tuple{2.0, 300.0, 0.5}, std::tuple{1.0, 100.0, 0.33}}) {
    SlidingFriction law(mu, 2.0);
    const Solve solve{[n0 = n0, fall = fall](double f) { return std::max(0.0, n0 - fall * f); },
                      [](double f) { return 1.0 - 1e-5 * f; }};
    const double expected = mu * n0 / (1 + mu * fall);  // f = mu (n0 - fall f)
    EXPECT_NEAR(afterPasses(&law, solve), expected, 0.005 * expected) << "mu " << mu;
  }
}

// A slide the friction ends within the step ends at rest: the friction is what brings the slip
// to 0 by the step's end, below mu N, the slip answering it ten times less than J M^-1 J^T says
// (the joints' motors and other contacts take the rest).
TEST(SlidingFriction, ASlideThatEndsWithinTheStepEndsAtRest) {
  const double compliance = 2.0;  // 1/kg
  SlidingFriction law(2.0, compliance);
  const double slip = 0.02;
  const Solve solve{[](double) { return 300.0; },
                    [&](double f) { return slip - 0.1 * kStep * compliance * f; }};
  const double f = afterPasses(&law, solve);
  EXPECT_LT(f, 2.0 * 300.0);
  EXPECT_NEAR(solve.slip_at_end(f), 0.0, 1e-3 * slip);
}

// No normal force, no friction; and friction never pushes along the slip.
TEST(SlidingFriction, NoNormalForceNoFrictionAndNeverAlongTheSlip) {
  SlidingFriction apart(1.0, 2.0);
  EXPECT_EQ(afterPasses(&apart, {[](double) { return 0.0; }, [](double) { return 1.0; }}), 0.0);
  SlidingFriction past_rest(1.0, 2.0);
  EXPECT_EQ(afterPasses(&past_rest, {[](double) { return 100.0; }, [](double) { return -0.5; }}),
            0.0);
}

}  // namespace
}  // namespace core
}  // namespace onedof_sim
