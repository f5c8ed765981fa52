#include "gazebo_panel.h"

#include <QDockWidget>
#include <QMainWindow>
#include <QScrollArea>
#include <QTabWidget>
#include <QVBoxLayout>
#include <OGRE/OgreRenderWindow.h>
#include <pluginlib/class_list_macros.hpp>
#include <rviz/display.h>
#include <rviz/display_group.h>
#include <rviz/render_panel.h>
#include <rviz/visualization_manager.h>
#include <rviz/tool.h>
#include <rviz/tool_manager.h>

#include <chrono>

#include "gazebo_client.h"
#include "gui_thread.h"
#include "insert_tab.h"
#include "menu_bar.h"
#include "time_tab.h"
#include "view_focus.h"
#include "world_tab.h"

namespace gazebo_ros_panels {
namespace {

const QString kInsertHereTool = "gazebo_ros_panels/InsertHere";  // plugin_description.xml
const QString kSelectTool = "gazebo_ros_panels/SelectModel";
// The display of the model handles (gazebo_ros.model_handles) in gazebo_ros' world.rviz.
const QString kHandlesDisplay = "Move models";
const QString kHandlesClass = "rviz/InteractiveMarkers";
const QString kHandlesTopic = "/gazebo_model_handles/update";

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
  // Each button and tab has an Alt mnemonic of its own, none of the menu bar's (rviz's F, P, H
  // and GazeboMenus' V).
  tabs->addTab(scrollable(time_), "Ti&me");
  tabs->addTab(scrollable(insert_), "&Insert");
  tabs->addTab(scrollable(world_), "&World");
  // Gazebo's T (translate mode); Alt+T here, as the panel's other buttons.
  auto* move_models = new QPushButton("Move models (&T)");
  move_models->setToolTip("Gazebo's translate and rotate modes: arrows and rings on the model "
                          "clicked, dragged with the Select Model tool; pressed again, hidden");
  connect(move_models, &QPushButton::clicked, this, &GazeboPanel::toggleMoveModels);
  status_ = new QLabel;
  status_->setWordWrap(true);
  status_->setTextInteractionFlags(Qt::TextSelectableByMouse);
  auto* layout = new QVBoxLayout(this);
  layout->addWidget(status_);
  layout->addWidget(move_models);
  layout->addWidget(tabs, 1);

  new GazeboMenus(vis_manager_, client_.get(), report, this);
  view_focus_ = new ViewFocus(vis_manager_, client_.get(), report, this);
  client_->listenForViewRequests([this](ViewRequest request, const std::string& model) {
    onGuiThread(this, [this, request, model] {
      if (request == ViewRequest::kMoveTo)
        view_focus_->moveTo(model);
      else
        view_focus_->follow(model);
    });
  });

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

void GazeboPanel::useTool(const QString& class_id) {
  rviz::ToolManager* tools = vis_manager_->getToolManager();
  rviz::Tool* tool = nullptr;
  for (int i = 0; i < tools->numTools() && !tool; ++i)
    if (tools->getTool(i)->getClassId() == class_id) tool = tools->getTool(i);
  if (!tool) tool = tools->addTool(class_id);
  if (tool) tools->setCurrentTool(tool);
}

void GazeboPanel::chooseInsertPoint() { useTool(kInsertHereTool); }

rviz::Display* GazeboPanel::handlesDisplay(bool add) {
  rviz::DisplayGroup* displays = vis_manager_->getRootDisplayGroup();
  for (int i = 0; i < displays->numDisplays(); ++i) {
    rviz::Display* display = displays->getDisplayAt(i);
    if (display->getClassId() == kHandlesClass && display->getName() == kHandlesDisplay)
      return display;
  }
  if (!add) return nullptr;
  rviz::Display* display = vis_manager_->createDisplay(kHandlesClass, kHandlesDisplay, false);
  if (display) display->subProp("Update Topic")->setValue(kHandlesTopic);
  return display;
}

void GazeboPanel::toggleMoveModels() {
  // The display's own state decides: it may have been ticked in rviz's Displays panel.
  const rviz::Display* shown = handlesDisplay(false);
  const bool on = !(shown && shown->isEnabled());
  rviz::Display* display = handlesDisplay(on);
  if (!display) return;
  display->setEnabled(on);
  if (!on) {
    report("models shown without their handles");
    return;
  }
  useTool(kSelectTool);
  report("click a model, then drag its arrows and rings in the 3D view");
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
  showFrameRate(now);
}

void GazeboPanel::showFrameRate(int64_t now_wall_ns) {
  rviz::RenderPanel* render_panel = vis_manager_->getRenderPanel();
  Ogre::RenderWindow* window = render_panel ? render_panel->getRenderWindow() : nullptr;
  if (!window) return;
  // OGRE counts once a second: shown and published at that pace, the figure changes no more
  // often than it is taken.
  if (now_wall_ns - frame_rate_published_ns_ < 1000000000) return;
  frame_rate_published_ns_ = now_wall_ns;
  const double frames_per_second = window->getStatistics().lastFPS;
  time_->showFrameRate(frames_per_second);
  client_->publishFrameRate(frames_per_second);
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
