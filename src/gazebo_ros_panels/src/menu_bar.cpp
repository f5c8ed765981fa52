#include "menu_bar.h"

#include <QAction>
#include <QKeySequence>
#include <QMainWindow>
#include <QMenuBar>
#include <rviz/display.h>
#include <rviz/display_group.h>
#include <rviz/properties/property.h>
#include <rviz/visualization_manager.h>
#include <rviz/window_manager_interface.h>

#include "gui_thread.h"

namespace gazebo_ros_panels {
namespace {

// An entry of the menu: a display's property (a ModelVisuals' mode), or with none, the display
// shown. Titles are Gazebo's; the displays' names are world.rviz's.
struct Entry {
  const char* title;
  const char* display;
  const char* property;
};
const Entry kEntries[] = {
    {"&Transparent", "Visuals", "Transparent"},
    {"&Wireframe", "Visuals", "Wireframe"},
    {"&Collisions", "Collisions", nullptr},
    {"&Joints", "Joints", nullptr},
    {"Center of &Mass", "Center of Mass", nullptr},
    {"&Inertias", "Inertias", nullptr},
    {"C&ontacts", "Contacts", nullptr},
};

rviz::Property* modeOf(rviz::Display* display, const char* property) {
  rviz::Property* mode = display->subProp(property);
  return mode && mode->getName() == property ? mode : nullptr;
}

}  // namespace

GazeboMenus::GazeboMenus(rviz::VisualizationManager* manager, GazeboClient* client,
                         std::function<void(const QString&)> report, QObject* parent)
    : QObject(parent), manager_(manager), report_(std::move(report)) {
  auto* window = dynamic_cast<QMainWindow*>(manager->getWindowManager());
  if (!window) return;  // not in rviz's main window
  // No Alt mnemonic: the panel's Step has E. Its entry has Gazebo's shortcut.
  edit_ = new QMenu("Edit", window);
  view_ = new QMenu("&View", window);
  addEditMenu(client);
  addViewMenu();
  QMenuBar* bar = window->menuBar();
  QAction* help = nullptr;
  for (QAction* action : bar->actions())
    if (action->text().remove('&') == "Help") help = action;
  bar->insertMenu(help, edit_);
  bar->insertMenu(help, view_);
}

GazeboMenus::~GazeboMenus() {
  delete edit_;
  delete view_;
}

void GazeboMenus::addEditMenu(GazeboClient* client) {
  QAction* reset = edit_->addAction("Reset &Model Poses");
  reset->setShortcut(QKeySequence("Ctrl+Shift+R"));  // Gazebo's
  connect(reset, &QAction::triggered, this,
          [this, client] { client->resetWorld(reportOnGui(this, report_)); });
}

void GazeboMenus::addViewMenu() {
  for (const Entry& entry : kEntries) {
    QAction* action = view_->addAction(entry.title);
    action->setCheckable(true);
    connect(action, &QAction::triggered, this, [this, entry](bool on) {
      rviz::Display* shown = display(entry.display);
      if (!shown) return;
      if (entry.property) {
        if (rviz::Property* mode = modeOf(shown, entry.property)) mode->setValue(on);
      } else {
        shown->setEnabled(on);
      }
      report_(QString("View: %1 %2").arg(QString(entry.title).remove('&'), on ? "on" : "off"));
    });
  }
  connect(view_, &QMenu::aboutToShow, this, &GazeboMenus::showViewStates);
}

rviz::Display* GazeboMenus::display(const QString& name) const {
  rviz::DisplayGroup* displays = manager_->getRootDisplayGroup();
  for (int i = 0; i < displays->numDisplays(); ++i)
    if (displays->getDisplayAt(i)->getName() == name) return displays->getDisplayAt(i);
  return nullptr;
}

void GazeboMenus::showViewStates() {
  const QList<QAction*> actions = view_->actions();
  for (int i = 0; i < actions.size(); ++i) {
    const Entry& entry = kEntries[i];
    rviz::Display* shown = display(entry.display);
    rviz::Property* mode = shown && entry.property ? modeOf(shown, entry.property) : nullptr;
    actions[i]->setEnabled(shown && (!entry.property || mode));
    actions[i]->setChecked(mode ? mode->getValue().toBool() : shown && shown->isEnabled());
  }
}

}  // namespace gazebo_ros_panels
