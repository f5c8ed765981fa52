// What the control gtests share: parameters from a map, and the tutorial robot's URDFs.
#pragma once

#include <fstream>
#include <map>
#include <sstream>
#include <string>

#include "param_source.h"

namespace onedof_sim::control::testing_support {

class MapParams : public ParamSource {
 public:
  std::map<std::string, double> numbers;
  std::map<std::string, std::string> strings;
  bool has(const std::string& key) const override {
    return numbers.count(key) || strings.count(key);
  }
  bool getDouble(const std::string& key, double* value) const override {
    auto found = numbers.find(key);
    if (found == numbers.end()) return false;
    *value = found->second;
    return true;
  }
  bool getBool(const std::string& key, bool* value) const override {
    double number;
    if (!getDouble(key, &number)) return false;
    *value = number != 0;
    return true;
  }
  bool getString(const std::string& key, std::string* value) const override {
    auto found = strings.find(key);
    if (found == strings.end()) return false;
    *value = found->second;
    return true;
  }
};

inline std::string tutorialUrdf() {
  std::ifstream file(ONEDOF_SOURCE_DIR "/src/minimal_robot_description/minimal_robot_description.urdf");
  std::stringstream text;
  text << file.rdbuf();
  return text.str();
}

// The book's variant of the tutorial robot: an effort transmission on joint1 and
// gazebo_ros_control's tag; plugin_body, if given, replaces what the tag holds.
inline std::string controlledUrdf(const std::string& plugin_body = "") {
  std::ifstream file(ONEDOF_SOURCE_DIR
                     "/src/minimal_robot_description/minimal_robot_description_w_jnt_ctl.urdf");
  std::stringstream text;
  text << file.rdbuf();
  std::string urdf = text.str();
  if (!plugin_body.empty()) {
    const std::string open = "<robotNamespace>", close = "</robotNamespace>";
    const size_t start = urdf.find(open);
    urdf.replace(start, urdf.find(close) + close.size() - start, plugin_body);
  }
  return urdf;
}

}  // namespace onedof_sim::control::testing_support
