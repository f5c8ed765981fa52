// The model selected in the simulator's rviz window, one per process (rviz's), as Gazebo's scene
// and World tab share one selection: the Select Model tool sets it from a click in the view, the
// World tab from its tree, and each hears the other's. The Select Model tool publishes it on
// kSelectedModelTopic for the model handles.
#pragma once

#include <QObject>
#include <QString>

namespace gazebo_ros_panels {

class Selection : public QObject {
  Q_OBJECT
 public:
  static Selection& hub();

  QString model() const { return model_; }  // empty: none
  // Selects `model` (empty: none); `changed` is emitted when that is a change.
  void select(const QString& model);

 Q_SIGNALS:
  void changed(const QString& model);

 private:
  QString model_;
};

}  // namespace gazebo_ros_panels
