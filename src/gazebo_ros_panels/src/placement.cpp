#include "placement.h"

namespace gazebo_ros_panels {

Placement& Placement::hub() {
  static Placement placement;
  return placement;
}

}  // namespace gazebo_ros_panels
