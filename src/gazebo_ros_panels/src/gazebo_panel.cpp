#include "gazebo_panel.h"

#include <QDockWidget>
#include <QMainWindow>
#include <QScrollArea>
#include <QTabWidget>
#include <QVBoxLayout>
#include <pluginlib/class_list_macros.hpp>
#include <rviz/visualization_manager.h>
#include <rviz/tool.h>
#include <rviz/tool_manager.h>

#include <chrono>

#include "gazebo_client.h"
#include "gui_thread.h"
#include "insert_tab.h"
#include "time_tab.h"
#include "world_tab.h"

namespace gazebo_ros_panels {
namespace {

const QString kInsertHereTool = "gazebo_ros_panels/InsertHere";  // plugin_description.xml

// A tab's content in a scroll area: the panel fits whatever height rviz's dock leaves it.
QScrollArea* scrollable(QWidget* content) {
  auto* area = new QScrollArea;
  area->setWidget(content);
  area->setWidgetResizable(true);
  area->setFrameShape(QFrame::NoFrame);
  return area;
}

}  // namespace

GazeboPanel::GazeboPanel(QWidget* parent) : rviz::Panel(parent) {}

GazeboPanel::~GazeboPanel() {
  // The client's worker hands outcomes to the tabs: it stops before they go.
  client_.reset();
}

void GazeboPanel::onInitialize() {
  client_ = std::make_unique<GazeboClient>();
  auto report = [this](const QString& text) { this->report(text); };
  auto physics_changed = [this] { askForPhysics(); };
  time_ = new TimeTab(client_.get(), report, physics_changed);
  insert_ = new InsertTab(client_.get(), report, [this] { chooseInsertPoint(); });
  world_ = new WorldTab(client_.get(), report, physics_changed);
  auto* tabs = new QTabWidget;
  // Each button and tab has an Alt mnemonic of its own, none of rviz's menus' (F, P, H).
  tabs->addTab(scrollable(time_), "Ti&me");
  tabs->addTab(scrollable(insert_), "&Insert");
  tabs->addTab(scrollable(world_), "&World");
  status_ = new QLabel;
  status_->setWordWrap(true);
  status_->setTextInteractionFlags(Qt::TextSelectableByMouse);
  auto* layout = new QVBoxLayout(this);
  layout->addWidget(status_);
  layout->addWidget(tabs, 1);

  connect(&refresh_timer_, &QTimer::timeout, this, &GazeboPanel::refresh);
  connect(&physics_timer_, &QTimer::timeout, this, &GazeboPanel::askForPhysics);
  refresh_timer_.start(200);
  physics_timer_.start(1000);
  insert_->refresh();
  askForPhysics();
  shareTheDisplaysPlace();
  ROS_INFO("gazebo_ros_panels: the Gazebo panel is up (Time, Insert, World)");
}

void GazeboPanel::shareTheDisplaysPlace() {
  auto* dock = qobject_cast<QDockWidget*>(parentWidget());
  auto* window = dock ? qobject_cast<QMainWindow*>(dock->parentWidget()) : nullptr;
  if (!window) return;  // floating, or not in rviz's window
  for (QDockWidget* other : window->findChildren<QDockWidget*>()) {
    if (other != dock && other->windowTitle() == "Displays" &&
        window->dockWidgetArea(other) == window->dockWidgetArea(dock)) {
      window->tabifyDockWidget(other, dock);
      dock->raise();
      return;
    }
  }
}

void GazeboPanel::chooseInsertPoint() {
  rviz::ToolManager* tools = vis_manager_->getToolManager();
  rviz::Tool* insert_here = nullptr;
  for (int i = 0; i < tools->numTools() && !insert_here; ++i)
    if (tools->getTool(i)->getClassId() == kInsertHereTool) insert_here = tools->getTool(i);
  if (!insert_here) insert_here = tools->addTool(kInsertHereTool);
  if (insert_here) tools->setCurrentTool(insert_here);
}

void GazeboPanel::report(const QString& text) {
  status_->setText(text);
  if (!text.isEmpty()) ROS_INFO_STREAM("gazebo_ros_panels: " << text.toStdString());
}

void GazeboPanel::refresh() {
  const int64_t now = std::chrono::duration_cast<std::chrono::nanoseconds>(
                          std::chrono::steady_clock::now().time_since_epoch())
                          .count();
  time_->showClock(client_->clock(), now);
  world_->showModelStates(client_->modelStates());
}

void GazeboPanel::askForPhysics() {
  if (physics_pending_) return;
  physics_pending_ = true;
  client_->physics([this](const Outcome& outcome, const PhysicsState& state) {
    onGuiThread(this, [this, outcome, state] {
      physics_pending_ = false;
      if (!outcome.ok) {
        // Said once, not every second while the simulator is away.
        const QString text = QString::fromStdString(outcome.text);
        if (text != last_physics_error_) report(text);
        last_physics_error_ = text;
        return;
      }
      if (!last_physics_error_.isEmpty()) report("simulator found");
      last_physics_error_.clear();
      time_->showPhysics(state);
      world_->showPhysics(state);
    });
  });
}

}  // namespace gazebo_ros_panels

PLUGINLIB_EXPORT_CLASS(gazebo_ros_panels::GazeboPanel, rviz::Panel)
