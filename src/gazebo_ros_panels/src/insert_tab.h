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
  InsertTab(GazeboClient* client, std::function<void(const QString&)> report,
            QWidget* parent = nullptr);
  void refresh();  // lists the model path again (models added to it since appear)

 private:
  void insertChosen();

  GazeboClient* client_;
  std::function<void(const QString&)> report_;
  std::vector<CatalogModel> models_;
  QListWidget* list_;
  QDoubleSpinBox* x_;
  QDoubleSpinBox* y_;
  QDoubleSpinBox* z_;
  QDoubleSpinBox* yaw_;
};

}  // namespace gazebo_ros_panels
