// The name a new copy of a model gets, as Gazebo names copies: base_0, base_1, ... the first
// one no model of the world has. No ROS, no Qt.
#pragma once

#include <string>
#include <vector>

namespace gazebo_ros_panels {

std::string copyName(const std::string& base, const std::vector<std::string>& existing);

}  // namespace gazebo_ros_panels
