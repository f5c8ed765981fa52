#include "insert_tab.h"

#include <QFormLayout>
#include <QHBoxLayout>
#include <QLabel>
#include <QPushButton>
#include <QVBoxLayout>

#include <cmath>

#include "gui_thread.h"
#include "number_field.h"
#include "placement.h"

namespace gazebo_ros_panels {
InsertTab::InsertTab(GazeboClient* client, std::function<void(const QString&)> report,
                     std::function<void()> choose_point, QWidget* parent)
    : QWidget(parent),
      client_(client),
      report_(std::move(report)),
      choose_point_(std::move(choose_point)) {
  list_ = new QListWidget;
  x_ = numberField(-1e4, 1e4, 3, " m");
  y_ = numberField(-1e4, 1e4, 3, " m");
  z_ = numberField(-1e4, 1e4, 3, " m");
  yaw_ = numberField(-180, 180, 1, " deg");
  auto* refresh = new QPushButton("Refre&sh");
  auto* insert = new QPushButton("I&nsert");
  insert->setToolTip("insert the chosen model at the position typed below");
  auto* click = new QPushButton("Insert by &clicking");
  click->setToolTip("the next left click in the 3D view inserts the chosen model there "
                    "(rviz's Insert Here tool, key N)");

  auto* where = new QFormLayout;
  where->addRow("x", x_);
  where->addRow("y", y_);
  where->addRow("z", z_);
  where->addRow("yaw", yaw_);
  auto* buttons = new QHBoxLayout;
  buttons->addWidget(refresh);
  buttons->addWidget(insert);
  buttons->addWidget(click);
  auto* models = new QLabel("Mo&dels");
  models->setBuddy(list_);
  auto* layout = new QVBoxLayout(this);
  layout->addWidget(models);
  layout->addWidget(list_, 1);
  layout->addLayout(where);
  layout->addLayout(buttons);

  connect(refresh, &QPushButton::clicked, this, &InsertTab::refresh);
  connect(insert, &QPushButton::clicked, this, &InsertTab::insertChosen);
  connect(list_, &QListWidget::itemDoubleClicked, this, &InsertTab::insertChosen);
  connect(click, &QPushButton::clicked, this, [this] {
    if (list_->currentRow() < 0) {
      report_("choose a model to insert");
      return;
    }
    choose_point_();
    report_("click in the 3D view where " + list_->currentItem()->text() + " goes");
  });
  connect(&Placement::hub(), &Placement::chosen, this, [this](double x, double y, double z) {
    geometry_msgs::Pose pose;
    pose.position.x = x;
    pose.position.y = y;
    pose.position.z = z;
    insertAt(pose);
  });
}

void InsertTab::refresh() {
  client_->catalog([this](const std::vector<CatalogModel>& models) {
    onGuiThread(this, [this, models] {
      const QString chosen = list_->currentItem() ? list_->currentItem()->text() : QString();
      models_ = models;
      list_->clear();
      for (const CatalogModel& model : models_) {
        auto* item = new QListWidgetItem(QString::fromStdString(model.name), list_);
        item->setToolTip(QString::fromStdString(
            model.shape.empty() ? "model://" + model.uri_name + " (" + model.sdf_path + ")"
                                : model.uri_name));
        if (item->text() == chosen) list_->setCurrentItem(item);
      }
      report_(QString("Insert: %1 models on the model path and %2 shapes")
                  .arg(models_.size() - simpleShapes().size())
                  .arg(simpleShapes().size()));
    });
  });
}

void InsertTab::insertChosen() {
  geometry_msgs::Pose pose;
  pose.position.x = x_->value();
  pose.position.y = y_->value();
  pose.position.z = z_->value();
  insertAt(pose);
}

void InsertTab::insertAt(const geometry_msgs::Pose& position) {
  const int row = list_->currentRow();
  if (row < 0 || row >= static_cast<int>(models_.size())) {
    report_("choose a model to insert");
    return;
  }
  geometry_msgs::Pose pose = position;
  const double half_yaw = yaw_->value() * M_PI / 360.0;
  pose.orientation.z = std::sin(half_yaw);
  pose.orientation.w = std::cos(half_yaw);
  client_->insert(models_[static_cast<size_t>(row)], pose, reportOnGui(this, report_));
}

}  // namespace gazebo_ros_panels
