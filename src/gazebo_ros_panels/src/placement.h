// Where a click in rviz's 3D view asks for a model to be inserted: InsertHereTool says it,
// the Insert tab inserts its chosen model there. One per process (rviz's).
#pragma once

#include <QObject>

namespace gazebo_ros_panels {

class Placement : public QObject {
  Q_OBJECT
 public:
  static Placement& hub();

 Q_SIGNALS:
  void chosen(double x, double y, double z);  // a point of the fixed frame (world)
};

}  // namespace gazebo_ros_panels
