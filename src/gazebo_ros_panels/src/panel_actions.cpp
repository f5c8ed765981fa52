// The Gazebo panel's actions from the command line: each runs the GazeboClient call a panel
// button makes, prints its outcome and exits 0 when it succeeded.
//   rosrun gazebo_ros_panels gazebo_panel_actions pause | unpause | step N | reset_time | reset_world
//   gazebo_panel_actions insert URI_NAME X Y Z     (a model of the panel's catalog, or unit_box)
//   gazebo_panel_actions catalog                   (uri_name<TAB>name per line)
//   gazebo_panel_actions move MODEL X Y Z          (the World tab's pose, at rest)
//   gazebo_panel_actions physics                   (the World tab's physics and the pause state)
//   gazebo_panel_actions set_physics STEP MAX_UPDATE_RATE GX GY GZ
//   gazebo_panel_actions tree                      (model<TAB>links<TAB>joints per line)
#include <ros/ros.h>

#include <future>
#include <iostream>
#include <string>

#include "gazebo_client.h"

using gazebo_ros_panels::CatalogModel;
using gazebo_ros_panels::GazeboClient;
using gazebo_ros_panels::ModelTree;
using gazebo_ros_panels::Outcome;
using gazebo_ros_panels::PhysicsState;

namespace {

int usage() {
  std::cerr << "usage: gazebo_panel_actions pause|unpause|step N|reset_time|reset_world|"
               "insert URI_NAME X Y Z|catalog|move MODEL X Y Z|physics|"
               "set_physics STEP MAX_UPDATE_RATE GX GY GZ|tree\n";
  return 2;
}

std::string joined(const std::vector<std::string>& names) {
  std::string text;
  for (const std::string& name : names) text += (text.empty() ? "" : ",") + name;
  return text;
}

std::pair<Outcome, PhysicsState> physicsOf(GazeboClient& client) {
  std::promise<std::pair<Outcome, PhysicsState>> read;
  client.physics([&read](const Outcome& outcome, const PhysicsState& state) {
    read.set_value({outcome, state});
  });
  return read.get_future().get();
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
  } else if (action == "move" && argc == 6) {
    geometry_msgs::Pose pose;
    pose.position.x = std::stod(argv[3]);
    pose.position.y = std::stod(argv[4]);
    pose.position.z = std::stod(argv[5]);
    pose.orientation.w = 1;
    client.setModelPose(argv[2], pose, done);
  } else if (action == "physics" && argc == 2) {
    const auto [outcome, state] = physicsOf(client);
    if (!outcome.ok) {
      std::cout << outcome.text << "\n";
      return 1;
    }
    std::cout << "paused " << state.paused << " step " << state.time_step << " max_update_rate "
              << state.max_update_rate << " gravity " << state.gravity.x << " "
              << state.gravity.y << " " << state.gravity.z << "\n";
    return 0;
  } else if (action == "set_physics" && argc == 7) {
    // As the World tab: what the simulator says now, with the typed figures.
    auto [outcome, state] = physicsOf(client);
    if (!outcome.ok) {
      std::cout << outcome.text << "\n";
      return 1;
    }
    state.time_step = std::stod(argv[2]);
    state.max_update_rate = std::stod(argv[3]);
    state.gravity.x = std::stod(argv[4]);
    state.gravity.y = std::stod(argv[5]);
    state.gravity.z = std::stod(argv[6]);
    client.setPhysics(state, done);
  } else if (action == "tree" && argc == 2) {
    std::promise<std::pair<Outcome, std::vector<ModelTree>>> read;
    client.modelTrees([&read](const Outcome& outcome, const std::vector<ModelTree>& trees) {
      read.set_value({outcome, trees});
    });
    const auto [outcome, trees] = read.get_future().get();
    for (const ModelTree& tree : trees)
      std::cout << tree.name << "\t" << joined(tree.links) << "\t" << joined(tree.joints) << "\n";
    if (!outcome.ok) std::cout << outcome.text << "\n";
    return outcome.ok ? 0 : 1;
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
