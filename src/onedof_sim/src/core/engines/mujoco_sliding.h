// The friction of one sliding contact over a step's solves (mujoco_engine.cpp's slidingFriction):
// MuJoCo solves the step with the contact frictionless, the friction is applied to its two bodies
// as a force against the slip, and the step is solved again, a few times. Private to the core.
//
// Coulomb's bound, mu N, is of the normal force the friction itself leaves: a caster's drag moves
// load off it, and a driven wheel's large mu, applied at the normal force of the solve without it,
// lifts the wheel in the next solve (MuJoCo's soft normal answers the friction's moment). So the
// bound is the friction f where mu N(f) = f, N(f) being the normal force of a solve with f
// applied, found by false position (Illinois) between the largest friction known to be within it
// and the smallest known to be beyond it. A friction that would turn the slip back by the step's
// end is lessened to end the step at rest (an explicit mu N past rest flings a light body back),
// by the slip's answer to the friction as the last two solves show it (a secant).
#pragma once

#include <utility>

namespace onedof_sim {
namespace core {

class SlidingFriction {
 public:
  // mu along the slip; compliance: J M^-1 J^T of the slip's row, 1/kg (<= 0: unknown).
  SlidingFriction(double mu, double compliance) : mu_(mu), compliance_(compliance) {}

  // The friction's magnitude for the next solve, N, from the solve just made (the first time, the
  // one without friction): its normal force (N) and the slip along the step's starting slip at
  // the step's end (m/s); dt the step (s).
  double next(double normal, double slip_at_end, double dt);

  double magnitude() const { return magnitude_; }

 private:
  double mu_;
  double compliance_;
  double magnitude_ = 0;    // applied in the solve just made
  double previous_ = -1;    // applied in the solve before it (< 0: none)
  double slip_at_end_ = 0;  // of the solve just made, m/s
  double answer_ = 0;       // d(slip at the end) / d(friction), m/s per N (0: not known yet)
  // (f, mu N - f) of the largest friction found within the bound and of the smallest found
  // beyond it (f < 0: none yet), and which of the two the last solve gave (1, -1; 0 none).
  std::pair<double, double> within_{0.0, 0.0}, beyond_{-1.0, 0.0};
  int last_side_ = 0;
};

}  // namespace core
}  // namespace onedof_sim
