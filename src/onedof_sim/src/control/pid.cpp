#include "pid.h"

#include <algorithm>
#include <cmath>

namespace onedof_sim::control {

namespace {

// A parameter that is there must be a number; one that is not there keeps the default.
bool readOptional(const ParamSource& params, const std::string& key, double* value,
                  std::string* error) {
  if (!params.has(key) || params.getDouble(key, value)) return true;
  *error = "parameter '" + key + "' is not a number";
  return false;
}

}  // namespace

bool readPidGains(const ParamSource& params, const std::string& ns, PidGains* gains,
                  std::string* error) {
  PidGains read;
  if (!params.getDouble(ns + "/p", &read.p)) {
    *error = params.has(ns + "/p") ? "parameter '" + ns + "/p' is not a number"
                                   : "No p gain specified for pid.  Namespace: " + ns;
    return false;
  }
  double i_clamp = 0;
  if (!readOptional(params, ns + "/i", &read.i, error) ||
      !readOptional(params, ns + "/d", &read.d, error) ||
      !readOptional(params, ns + "/i_clamp", &i_clamp, error))
    return false;
  read.i_max = std::abs(i_clamp);
  read.i_min = -std::abs(i_clamp);
  if (!readOptional(params, ns + "/i_clamp_min", &read.i_min, error) ||
      !readOptional(params, ns + "/i_clamp_max", &read.i_max, error))
    return false;
  read.i_min = -std::abs(read.i_min);
  read.i_max = std::abs(read.i_max);
  if (params.has(ns + "/antiwindup") && !params.getBool(ns + "/antiwindup", &read.antiwindup)) {
    *error = "parameter '" + ns + "/antiwindup' is not a bool";
    return false;
  }
  if (!std::isfinite(read.p) || !std::isfinite(read.i) || !std::isfinite(read.d) ||
      !std::isfinite(read.i_min) || !std::isfinite(read.i_max)) {
    *error = "the pid gains and clamps in '" + ns + "' must be finite";
    return false;
  }
  *gains = read;
  return true;
}

void Pid::reset() { p_error_last_ = p_error_ = i_error_ = d_error_ = 0; }

double Pid::computeCommand(double error, double dt) {
  if (!(dt > 0) || !std::isfinite(error)) return 0;
  const double error_dot = (error - p_error_last_) / dt;
  p_error_last_ = error;
  return computeCommand(error, error_dot, dt);
}

double Pid::computeCommand(double error, double error_dot, double dt) {
  if (!(dt > 0) || !std::isfinite(error) || !std::isfinite(error_dot)) return 0;
  p_error_ = error;
  d_error_ = error_dot;
  i_error_ += dt * p_error_;
  if (gains_.antiwindup && gains_.i != 0) {
    // The integral itself held so that its term stays within the clamp.
    i_error_ = std::clamp(i_error_, gains_.i_min / std::abs(gains_.i), gains_.i_max / std::abs(gains_.i));
  }
  double i_term = gains_.i * i_error_;
  if (!gains_.antiwindup) i_term = std::clamp(i_term, gains_.i_min, gains_.i_max);
  return gains_.p * p_error_ + i_term + gains_.d * d_error_;
}

}  // namespace onedof_sim::control
