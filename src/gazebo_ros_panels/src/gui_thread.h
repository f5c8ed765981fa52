// GazeboClient's outcomes, which arrive on its worker thread, handed to a widget's GUI thread.
#pragma once

#include <QMetaObject>
#include <QObject>
#include <QString>

#include <functional>
#include <utility>

#include "gazebo_client.h"

namespace gazebo_ros_panels {

// Runs f on `widget`'s thread, later; the widget must outlive the client that calls this (the
// panel destroys its client first).
template <class F>
void onGuiThread(QObject* widget, F f) {
  QMetaObject::invokeMethod(widget, std::move(f), Qt::QueuedConnection);
}

// A GazeboClient::Done that reports the outcome's text through `report` on the GUI thread, then
// runs `then` there.
inline GazeboClient::Done reportOnGui(QObject* widget, std::function<void(const QString&)> report,
                                      std::function<void(const Outcome&)> then = nullptr) {
  return [widget, report, then](const Outcome& outcome) {
    onGuiThread(widget, [report, then, outcome] {
      report(QString::fromStdString(outcome.text));
      if (then) then(outcome);
    });
  };
}

}  // namespace gazebo_ros_panels
