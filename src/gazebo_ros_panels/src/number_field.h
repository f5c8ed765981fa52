// The tabs' number fields: a spin box of a range, decimals and unit that reports a typed value
// once typing ends (Enter or leaving the field), not at each key.
#pragma once

#include <QDoubleSpinBox>

namespace gazebo_ros_panels {

inline QDoubleSpinBox* numberField(double low, double high, int decimals, const char* suffix) {
  auto* box = new QDoubleSpinBox;
  box->setRange(low, high);
  box->setDecimals(decimals);
  box->setSuffix(suffix);
  box->setKeyboardTracking(false);
  return box;
}

}  // namespace gazebo_ros_panels
