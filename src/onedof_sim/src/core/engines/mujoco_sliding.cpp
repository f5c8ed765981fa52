#include "mujoco_sliding.h"

#include <algorithm>
#include <cmath>

namespace onedof_sim {
namespace core {

double SlidingFriction::next(double normal, double slip_at_end, double dt) {
  const double excess = mu_ * std::max(0.0, normal) - magnitude_;
  if (excess >= 0) {
    if (last_side_ > 0) beyond_.second *= 0.5;
    within_ = {magnitude_, excess};
    last_side_ = 1;
  } else {
    if (last_side_ < 0) within_.second *= 0.5;
    beyond_ = {magnitude_, excess};
    last_side_ = -1;
  }
  const double bound = beyond_.first < 0
                           ? within_.first + within_.second
                           : within_.first + within_.second * (beyond_.first - within_.first) /
                                                 (within_.second - beyond_.second);
  // The slip's answer to the friction, m/s per N: as the last two solves show it, else as
  // J M^-1 J^T says (more than it answers: the joints' motors and other contacts take a part).
  const double shown =
      previous_ < 0 ? 0 : (slip_at_end - slip_at_end_) / (magnitude_ - previous_);
  if (std::isfinite(shown) && shown < 0) {
    answer_ = shown;
  } else if (answer_ == 0 && compliance_ > 0) {
    answer_ = -dt * compliance_;
  }
  const double at_rest = answer_ < 0 ? magnitude_ - slip_at_end / answer_ : bound;
  previous_ = magnitude_;
  slip_at_end_ = slip_at_end;
  magnitude_ = std::clamp(at_rest, 0.0, bound);
  return magnitude_;
}

}  // namespace core
}  // namespace onedof_sim
