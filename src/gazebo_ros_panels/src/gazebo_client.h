// The Gazebo panel's side of ROS: the simulator's services called one at a time on a worker
// thread of its own (never on rviz's GUI thread), and /clock and the window's model states
// (/gazebo/view_model_states: the simulator's poses at its views' rate, 20 times a wall second at
// most, 5 while paused, never a message per step as /gazebo/model_states) received on a spinner
// of its own, with the view requests of the model handles' right-click menu (Move To,
// Follow). Each call's outcome goes to its callback, on the worker thread; a missing
// simulator or a refusal is an outcome with the reason, never an exception. No Qt.
#pragma once

#include <gazebo_msgs/ModelStates.h>
#include <gazebo_msgs/ODEPhysics.h>
#include <geometry_msgs/Pose.h>
#include <geometry_msgs/Vector3.h>
#include <ros/callback_queue.h>
#include <ros/ros.h>

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "model_catalog.h"

namespace gazebo_ros_panels {

struct Outcome {
  bool ok = false;
  std::string text;  // what happened, or why not
};

struct PhysicsState {
  bool paused = false;
  double time_step = 0;
  double max_update_rate = 0;
  geometry_msgs::Vector3 gravity;
  gazebo_msgs::ODEPhysics ode;  // passed back unchanged by setPhysics
};

struct ModelTree {
  std::string name;
  std::vector<std::string> links;
  std::vector<std::string> joints;
};

// The model handles' (gazebo_ros.model_handles) requests for rviz's view, each a model's name
// (std_msgs/String): Move To, and Follow (an empty name stops following).
const char* const kMoveToTopic = "/gazebo_window/move_to";
const char* const kFollowTopic = "/gazebo_window/follow";
enum class ViewRequest { kMoveTo, kFollow };
// The frames per second the view draws (std_msgs/Float64, once a wall second), as the Time tab's
// FPS shows them: for what measures the window (the benchmark).
const char* const kFrameRateTopic = "/gazebo_window/frame_rate";

struct ClockReading {
  bool seen = false;
  int64_t sim_ns = 0;
  int64_t wall_ns = 0;  // steady wall time it was received at
  uint64_t count = 0;   // readings so far
};

class GazeboClient {
 public:
  using Done = std::function<void(const Outcome&)>;

  explicit GazeboClient(const std::string& gazebo_namespace = "/gazebo");
  ~GazeboClient();  // waits for the call under way; drops those queued
  GazeboClient(const GazeboClient&) = delete;
  GazeboClient& operator=(const GazeboClient&) = delete;

  void pause(Done done);
  void unpause(Done done);
  // The simulator's /gazebo/step_simulation (served when asked for: ~enable_step_simulation).
  void step(uint64_t steps, Done done);
  void resetSimulation(Done done);  // Gazebo's Edit > Reset Time
  void resetWorld(Done done);       // Gazebo's Edit > Reset World
  // Spawns `model` (a model file's SDF or a simple shape) at `pose` named as Gazebo names a copy
  // (copyName over the world's models at that moment); the outcome's text names it.
  void insert(const CatalogModel& model, const geometry_msgs::Pose& pose, Done done);
  // Moves a model to a pose in the world frame, at rest (set_model_state).
  void setModelPose(const std::string& model, const geometry_msgs::Pose& pose, Done done);
  // A model's pose in the world frame (get_model_state); a model the simulator does not have is
  // an outcome that is not ok.
  void modelPose(const std::string& model,
                 std::function<void(const Outcome&, const geometry_msgs::Pose&)> done);
  void physics(std::function<void(const Outcome&, const PhysicsState&)> done);
  // Keeps what `state.ode` says; time step, update rate and gravity as given.
  void setPhysics(const PhysicsState& state, Done done);
  void modelTrees(std::function<void(const Outcome&, const std::vector<ModelTree>&)> done);
  // The catalog of the model path as it is now: the simulator's /gazebo/model_path parameter,
  // this process's GAZEBO_MODEL_PATH, the packages' gazebo_model_path exports.
  void catalog(std::function<void(const std::vector<CatalogModel>&)> done);

  ClockReading clock() const;
  gazebo_msgs::ModelStates modelStates() const;
  // Model `name`'s pose in the latest view_model_states, when they came less than max_age_ns
  // ago (steady wall time) and have it; false otherwise (a world slowed far below real time
  // publishes them seldom).
  bool recentModelPose(const std::string& name, int64_t max_age_ns,
                       geometry_msgs::Pose* pose) const;
  // From now on, each view request (kMoveToTopic, kFollowTopic) goes to `handler`, on the
  // spinner's thread.
  void listenForViewRequests(std::function<void(ViewRequest, const std::string&)> handler);
  // The view's frames per second, as the panel shows them, on kFrameRateTopic.
  void publishFrameRate(double frames_per_second);
  bool busy() const;  // a call under way or queued

 private:
  void post(std::function<void()> job);
  void work();
  // A name of the simulator node: /gazebo/name.
  std::string simulatorName(const std::string& name) const { return namespace_ + "/" + name; }
  // Empty-request services (pause_physics, ...): "<what>" on success.
  Outcome callEmpty(const std::string& name, const std::string& what);
  // A service of the simulator; false with the reason in *failed. A repeatable call (a reading,
  // a state set to given values) is tried twice.
  template <class Srv>
  bool call(const std::string& name, Srv& srv, Outcome* failed, bool repeatable = false);

  const std::string namespace_;
  ros::NodeHandle nh_;
  ros::CallbackQueue queue_;
  ros::AsyncSpinner spinner_;
  ros::Subscriber clock_sub_, states_sub_, move_to_sub_, follow_sub_;
  ros::Publisher frame_rate_pub_;

  mutable std::mutex state_mutex_;
  ClockReading clock_;
  gazebo_msgs::ModelStates states_;
  int64_t states_wall_ns_ = 0;  // steady wall time states_ came

  mutable std::mutex jobs_mutex_;
  std::condition_variable jobs_cv_;
  std::deque<std::function<void()>> jobs_;
  bool working_ = false;
  bool stopping_ = false;
  std::thread worker_;
};

}  // namespace gazebo_ros_panels
