// control_toolbox::Pid as ros_controllers use it (Noetic): the gains and their parameters as
// Pid::init reads them, the integral and its clamp, the derivative from the error's change.
// Free of ROS: time steps in seconds; the parameters through ParamSource.
#pragma once

#include <string>

#include "param_source.h"

namespace onedof_sim::control {

struct PidGains {
  double p = 0, i = 0, d = 0;
  double i_max = 0, i_min = 0;  // i_min <= 0 <= i_max, as Pid::init makes them
  bool antiwindup = false;
};

// Reads `p` (required), `i` and `d` (default 0), `i_clamp` (both bounds, default 0), then
// `i_clamp_min` / `i_clamp_max` over it (signs forced as Pid::init forces them), `antiwindup`
// (default false), from the pid's namespace. False and *error (naming the namespace) when p is
// missing or a value is not a number.
bool readPidGains(const ParamSource& params, const std::string& ns, PidGains* gains,
                  std::string* error);

class Pid {
 public:
  explicit Pid(const PidGains& gains = PidGains()) : gains_(gains) {}

  const PidGains& gains() const { return gains_; }

  // The errors back to zero (starting() of every controller that holds a Pid).
  void reset();

  // error = set point - process value; the derivative is the error's change over dt. dt <= 0
  // or a non-finite error commands 0 and changes nothing, as control_toolbox does.
  double computeCommand(double error, double dt);
  // With the error's derivative given (a velocity error).
  double computeCommand(double error, double error_dot, double dt);

  double integralError() const { return i_error_; }

 private:
  PidGains gains_;
  double p_error_last_ = 0, p_error_ = 0, i_error_ = 0, d_error_ = 0;
};

}  // namespace onedof_sim::control
