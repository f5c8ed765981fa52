// The simulator node's start-up, named `gazebo` as gzserver + gazebo_ros is: its options from
// the parameter server and the command line, then the Gazebo API until shutdown.
#include "node_main.h"

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <ros/package.h>
#include <ros/ros.h>

#include "gazebo_api.h"
#include "master_watch.h"
#include "node_options.h"
#include "world_loading.h"

namespace {

// Where model://NAME and spawn_model -database look: this package's models/ first, so the tutorial
// always gets the models the simulator was built for, then GAZEBO_MODEL_PATH.
std::vector<std::string> modelPath() {
  std::vector<std::string> folders{ros::package::getPath("onedof_sim") + "/models"};
  const char* env = std::getenv("GAZEBO_MODEL_PATH");
  std::istringstream entries(env ? env : "");
  for (std::string folder; std::getline(entries, folder, ':');) {
    if (!folder.empty() && std::find(folders.begin(), folders.end(), folder) == folders.end())
      folders.push_back(folder);
  }
  return folders;
}

// loadWorldFile, while a thread of its own watches for SIGINT (roscpp's handler shuts the node
// down): a large world takes libsdformat most of a minute to read, which nothing can interrupt,
// so the node ends without waiting for it, its registrations with the master undone. The file
// is read on this thread: its gigabytes come from the main heap, which grows at less cost than a
// thread's.
bool readWorldFileUnlessInterrupted(const std::string& given,
                                    const std::vector<std::string>& model_path,
                                    const onedof_sim::PhysicsParams& base,
                                    onedof_sim::WorldFile* out, std::string* error) {
  std::mutex mutex;
  std::condition_variable read_cv;
  bool read = false;
  std::thread watch([&] {
    std::unique_lock<std::mutex> lock(mutex);
    while (!read) {
      if (!ros::ok()) {
        ROS_INFO_STREAM("onedof_sim: shutting down while the world file " << given << " is read");
        ros::shutdown();
        std::fflush(stdout);
        std::_Exit(0);
      }
      read_cv.wait_for(lock, std::chrono::milliseconds(50));
    }
  });
  const bool loaded = onedof_sim::loadWorldFile(given, model_path, base, out, error);
  {
    std::lock_guard<std::mutex> lock(mutex);
    read = true;
  }
  read_cv.notify_all();
  watch.join();
  return loaded;
}

}  // namespace

int runSimulatorNode(int argc, char** argv,
                     std::vector<onedof_sim::plugins::ModelPluginType> plugin_types) {
  // Each line of the log (rosconsole writes INFO to stdout) reaches a file or pipe as it is
  // written, as on a terminal: stdout into a file is otherwise flushed only when its buffer fills
  // or the node exits. Before anything is written.
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  if (argc == 2 && std::string(argv[1]) == "--list-physics") {
    // The engine registry, for the tools and tests that run one simulator per engine; before
    // ros::init, so that it needs no roscore.
    for (const std::string& name : onedof_sim::World::engineNames()) std::cout << name << "\n";
    return 0;
  }
  // The node is the clock, so it must not run on its own /clock: roscpp subscribes every node to
  // /clock when /use_sim_time is set at start-up, and then delivers each step's clock back to
  // this process, waking a thread per step (3 to 5 times the cost of the step itself). roscpp
  // 1.15 has no init option against it (no NoSimTime), but it reads the parameter
  // through name remapping, so remapping that one name for this node keeps it on wall time.
  // The node sets the real /use_sim_time for the others (SimLoop).
  std::vector<char*> args_with_own_time(argv, argv + argc);
  std::string own_time_remap = std::string(onedof_sim::kUseSimTime) + ":=" +
                               onedof_sim::kUseSimTime + "_is_for_the_clock_subscribers";
  args_with_own_time.push_back(&own_time_remap[0]);
  int ros_argc = static_cast<int>(args_with_own_time.size());
  ros::init(ros_argc, args_with_own_time.data(), "gazebo");  // removes the ROS remappings from it
  // Alive until the end: when the last NodeHandle goes, roscpp shuts down (console output too).
  ros::NodeHandle private_nh("~");
  const std::vector<std::string> args(args_with_own_time.begin() + 1,
                                      args_with_own_time.begin() + ros_argc);

  onedof_sim::NodeOptions options;
  options.model_path = modelPath();
  std::string error;
  const onedof_sim::ServerArguments arguments = onedof_sim::parseServerArguments(args);
  // A world that cannot be loaded ends the node at start-up, as gzserver ends.
  {
    onedof_sim::WorldFile world;
    if (!readWorldFileUnlessInterrupted(
            arguments.world_file.empty() ? onedof_sim::kDefaultWorldFile : arguments.world_file,
            options.model_path, options.physics, &world, &error)) {
      ROS_FATAL_STREAM("onedof_sim: " << error);
      return 1;
    }
    options.world = std::move(world);
  }
  if (!onedof_sim::readNodeOptions(private_nh, arguments, &options, &error)) {
    ROS_FATAL_STREAM("onedof_sim: " << error);
    return 1;
  }
  // Where -database and model:// look, for the tools that spawn into this simulator
  // (spawn_model -database reads it), before any service is advertised.
  private_nh.setParam("model_path", options.model_path);
  // For a restarted master: the parameters the node sets (~model_path, and /use_sim_time unless
  // set, which SimLoop sets at start-up) and those it reads through roscpp's cache (SimLoop's).
  onedof_sim::NodeParameters parameters;
  parameters.set_again = [&private_nh, &options] {
    private_nh.setParam("model_path", options.model_path);
    onedof_sim::setUseSimTimeUnlessSet();
    return std::vector<std::string>{private_nh.resolveName("model_path"), onedof_sim::kUseSimTime};
  };
  parameters.cached = {private_nh.resolveName(onedof_sim::kPubClockFrequency),
                       private_nh.resolveName(onedof_sim::kEnableCollisionMarkers)};
  try {
    onedof_sim::GazeboApi api(options, std::move(plugin_types));
    onedof_sim::MasterWatch master_watch(std::move(parameters));
    api.run();
  } catch (const std::invalid_argument& e) {
    // An unknown engine (World's constructor) or invalid physics parameters (setParams).
    ROS_FATAL_STREAM("onedof_sim: " << e.what()
                     << (!arguments.world_file.empty() ? " (the world file's <physics> with the "
                                                         "node's parameters over it)"
                                                       : ""));
    return 1;
  } catch (const onedof_sim::WorldModelRefused& e) {
    ROS_FATAL_STREAM("onedof_sim: " << e.what());
    return 1;
  }
  return 0;
}
