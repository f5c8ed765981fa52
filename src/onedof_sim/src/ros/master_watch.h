// The node's registrations, told again to a restarted roscore. ROS 1 nodes register with the
// master once, when they advertise or subscribe; a roscore restarted on the same port starts
// empty, so without this every lookup through it of /gazebo/* would fail while the node and its
// peer-to-peer connections (a controller's /clock, its persistent service connections) go on.
//
// A thread of its own asks the master its pid about every second, off the step loop and never
// under the world lock. A master that answers again after it did not, or answers with another
// pid, is told again every topic the node publishes and subscribes to (from the node's own slave
// API, with their types), every service it serves, the parameters it sets, and the parameters it
// reads through roscpp's cache (whose updates come from the master it subscribed to); one line
// in the log says so. Services have no list in roscpp's public API: while the master answers, the
// thread notes the services the master lists for this node, and registers again those roscpp
// still serves. A service advertised less than a check before the master went away is not in
// that note; one advertised while the master is away is registered by roscpp itself when it
// answers again.
#pragma once

#include <condition_variable>
#include <functional>
#include <mutex>
#include <set>
#include <string>
#include <thread>
#include <vector>

namespace onedof_sim {

// The node's parameters, as the watch needs them.
struct NodeParameters {
  // Sets again the parameters the node sets; returns their names.
  std::function<std::vector<std::string>()> set_again;
  // The resolved names of those the node reads with getParamCached.
  std::vector<std::string> cached;
};

class MasterWatch {
 public:
  explicit MasterWatch(NodeParameters parameters);
  // Stops the thread (at most one check's time).
  ~MasterWatch();

  MasterWatch(const MasterWatch&) = delete;
  MasterWatch& operator=(const MasterWatch&) = delete;

 private:
  void watch();
  // The services the master lists for this node; false if it did not answer.
  bool noteServices();
  // Tells a new master everything again; false if it stopped answering on the way.
  bool registerAgain(int master_pid);

  NodeParameters parameters_;
  std::set<std::string> services_;  // the latest noted (watch thread only)
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stopping_ = false;  // guarded by mutex_
  std::thread thread_;
};

}  // namespace onedof_sim
