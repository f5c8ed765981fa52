#include "selection.h"

namespace gazebo_ros_panels {

Selection& Selection::hub() {
  static Selection selection;
  return selection;
}

void Selection::select(const QString& model) {
  if (model == model_) return;
  model_ = model;
  Q_EMIT changed(model_);
}

}  // namespace gazebo_ros_panels
