// The Gazebo panel's actions from the command line: each runs the GazeboClient call a panel
// button makes, prints its outcome and exits 0 when it succeeded.
//   rosrun gazebo_ros_panels gazebo_panel_actions pause | unpause | step N | reset_time | reset_world
//   gazebo_panel_actions insert URI_NAME X Y Z     (a model of the panel's catalog, or unit_box)
//   gazebo_panel_actions catalog                   (uri_name<TAB>name per line)
#include <ros/ros.h>

#include <future>
#include <iostream>
#include <string>

#include "gazebo_client.h"

using gazebo_ros_panels::CatalogModel;
using gazebo_ros_panels::GazeboClient;
using gazebo_ros_panels::Outcome;

namespace {

int usage() {
  std::cerr << "usage: gazebo_panel_actions pause|unpause|step N|reset_time|reset_world|"
               "insert URI_NAME X Y Z|catalog\n";
  return 2;
}

std::vector<CatalogModel> catalogOf(GazeboClient& client) {
  std::promise<std::vector<CatalogModel>> listed;
  client.catalog([&listed](const std::vector<CatalogModel>& models) { listed.set_value(models); });
  return listed.get_future().get();
}

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "gazebo_panel_actions", ros::init_options::AnonymousName);
  if (argc < 2) return usage();
  const std::string action = argv[1];
  GazeboClient client;
  std::promise<Outcome> result;
  auto done = [&result](const Outcome& outcome) { result.set_value(outcome); };
  if (action == "pause" && argc == 2) {
    client.pause(done);
  } else if (action == "unpause" && argc == 2) {
    client.unpause(done);
  } else if (action == "step" && argc == 3) {
    client.step(std::stoull(argv[2]), done);
  } else if (action == "reset_time" && argc == 2) {
    client.resetSimulation(done);
  } else if (action == "reset_world" && argc == 2) {
    client.resetWorld(done);
  } else if (action == "catalog" && argc == 2) {
    for (const CatalogModel& model : catalogOf(client))
      std::cout << model.uri_name << "\t" << model.name << "\n";
    return 0;
  } else if (action == "insert" && argc == 6) {
    const std::vector<CatalogModel> models = catalogOf(client);
    const CatalogModel* chosen = nullptr;
    for (const CatalogModel& model : models)
      if (model.uri_name == argv[2]) chosen = &model;
    if (!chosen) {
      std::cout << argv[2] << " is not in the catalog\n";
      return 1;
    }
    geometry_msgs::Pose pose;
    pose.position.x = std::stod(argv[3]);
    pose.position.y = std::stod(argv[4]);
    pose.position.z = std::stod(argv[5]);
    pose.orientation.w = 1;
    client.insert(*chosen, pose, done);
  } else {
    return usage();
  }
  const Outcome outcome = result.get_future().get();
  std::cout << outcome.text << "\n";
  return outcome.ok ? 0 : 1;
}
