// Where controllers read their configuration: the parameter server in the node, a map in tests.
#pragma once

#include <string>

namespace onedof_sim::control {

class ParamSource {
 public:
  virtual ~ParamSource() = default;
  // Keys are full parameter names ("/one_DOF_robot/joint1_position_controller/pid/p").
  virtual bool has(const std::string& key) const = 0;
  // False when missing or of another type (an int reads as a double, as roscpp reads it).
  virtual bool getDouble(const std::string& key, double* value) const = 0;
  virtual bool getBool(const std::string& key, bool* value) const = 0;
  virtual bool getString(const std::string& key, std::string* value) const = 0;
};

}  // namespace onedof_sim::control
