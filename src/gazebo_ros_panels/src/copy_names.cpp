#include "copy_names.h"

#include <algorithm>

namespace gazebo_ros_panels {

std::string copyName(const std::string& base, const std::vector<std::string>& existing) {
  for (unsigned long n = 0;; ++n) {
    const std::string name = base + "_" + std::to_string(n);
    if (std::find(existing.begin(), existing.end(), name) == existing.end()) return name;
  }
}

}  // namespace gazebo_ros_panels
