// Gazebo's Insert tab: the models of the model path by name and the simple shapes; the chosen
// one inserted at a typed position as a new copy (cafe_table_0, cafe_table_1, ...).
#pragma once

#include <QDoubleSpinBox>
#include <QListWidget>
#include <QWidget>

#include <functional>
#include <vector>

#include "gazebo_client.h"

namespace gazebo_ros_panels {

class InsertTab : public QWidget {
  Q_OBJECT
 public:
  // choose_point: rviz's Insert Here tool made current (the next click in the view inserts).
  InsertTab(GazeboClient* client, std::function<void(const QString&)> report,
            std::function<void()> choose_point, QWidget* parent = nullptr);
  void refresh();  // lists the model path again (models added to it since appear)

 private:
  void insertChosen();
  void insertAt(const geometry_msgs::Pose& pose);

  GazeboClient* client_;
  std::function<void(const QString&)> report_;
  std::function<void()> choose_point_;
  std::vector<CatalogModel> models_;
  QListWidget* list_;
  QDoubleSpinBox* x_;
  QDoubleSpinBox* y_;
  QDoubleSpinBox* z_;
  QDoubleSpinBox* yaw_;
};

}  // namespace gazebo_ros_panels
