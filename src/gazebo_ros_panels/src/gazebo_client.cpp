#include "gazebo_client.h"

#include <gazebo_msgs/GetModelProperties.h>
#include <gazebo_msgs/GetModelState.h>
#include <gazebo_msgs/GetPhysicsProperties.h>
#include <gazebo_msgs/GetWorldProperties.h>
#include <gazebo_msgs/SetModelState.h>
#include <gazebo_msgs/SetPhysicsProperties.h>
#include <gazebo_msgs/SpawnModel.h>
#include <onedof_sim/StepSimulation.h>
#include <ros/package.h>
#include <rosgraph_msgs/Clock.h>
#include <std_msgs/Float64.h>
#include <std_msgs/String.h>
#include <std_srvs/Empty.h>

#include <chrono>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "copy_names.h"

namespace gazebo_ros_panels {
namespace {

int64_t steadyNowNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

bool readFile(const std::string& path, std::string* text) {
  std::ifstream file(path);
  if (!file) return false;
  std::ostringstream content;
  content << file.rdbuf();
  *text = content.str();
  return true;
}

}  // namespace

GazeboClient::GazeboClient(const std::string& gazebo_namespace)
    : namespace_(gazebo_namespace), spinner_(1, &queue_) {
  nh_.setCallbackQueue(&queue_);
  clock_sub_ = nh_.subscribe<rosgraph_msgs::Clock>(
      "/clock", 10, [this](const rosgraph_msgs::Clock::ConstPtr& msg) {
        const int64_t wall = steadyNowNs();
        std::lock_guard<std::mutex> lock(state_mutex_);
        clock_.seen = true;
        clock_.sim_ns = static_cast<int64_t>(msg->clock.toNSec());
        clock_.wall_ns = wall;
        ++clock_.count;
      });
  states_sub_ = nh_.subscribe<gazebo_msgs::ModelStates>(
      namespace_ + "/view_model_states", 1, [this](const gazebo_msgs::ModelStates::ConstPtr& msg) {
        const int64_t wall = steadyNowNs();
        std::lock_guard<std::mutex> lock(state_mutex_);
        states_ = *msg;
        states_wall_ns_ = wall;
      });
  spinner_.start();
  worker_ = std::thread([this] { work(); });
}

GazeboClient::~GazeboClient() {
  {
    std::lock_guard<std::mutex> lock(jobs_mutex_);
    stopping_ = true;
    jobs_.clear();
  }
  jobs_cv_.notify_all();
  worker_.join();
  spinner_.stop();
}

void GazeboClient::post(std::function<void()> job) {
  {
    std::lock_guard<std::mutex> lock(jobs_mutex_);
    jobs_.push_back(std::move(job));
  }
  jobs_cv_.notify_all();
}

void GazeboClient::work() {
  std::unique_lock<std::mutex> lock(jobs_mutex_);
  while (true) {
    jobs_cv_.wait(lock, [this] { return stopping_ || !jobs_.empty(); });
    if (stopping_) return;
    std::function<void()> job = std::move(jobs_.front());
    jobs_.pop_front();
    working_ = true;
    lock.unlock();
    job();
    lock.lock();
    working_ = false;
  }
}

bool GazeboClient::busy() const {
  std::lock_guard<std::mutex> lock(jobs_mutex_);
  return working_ || !jobs_.empty();
}

ClockReading GazeboClient::clock() const {
  std::lock_guard<std::mutex> lock(state_mutex_);
  return clock_;
}

gazebo_msgs::ModelStates GazeboClient::modelStates() const {
  std::lock_guard<std::mutex> lock(state_mutex_);
  return states_;
}

bool GazeboClient::recentModelPose(const std::string& name, int64_t max_age_ns,
                                   geometry_msgs::Pose* pose) const {
  const int64_t now = steadyNowNs();
  std::lock_guard<std::mutex> lock(state_mutex_);
  if (states_wall_ns_ == 0 || now - states_wall_ns_ >= max_age_ns) return false;
  for (size_t i = 0; i < states_.name.size() && i < states_.pose.size(); ++i) {
    if (states_.name[i] == name) {
      *pose = states_.pose[i];
      return true;
    }
  }
  return false;
}

void GazeboClient::listenForViewRequests(
    std::function<void(ViewRequest, const std::string&)> handler) {
  auto listen = [this, handler](const char* topic, ViewRequest request) {
    return nh_.subscribe<std_msgs::String>(
        topic, 10, [handler, request](const std_msgs::String::ConstPtr& msg) {
          handler(request, msg->data);
        });
  };
  move_to_sub_ = listen(kMoveToTopic, ViewRequest::kMoveTo);
  follow_sub_ = listen(kFollowTopic, ViewRequest::kFollow);
}

void GazeboClient::publishFrameRate(double frames_per_second) {
  if (!frame_rate_pub_) frame_rate_pub_ = nh_.advertise<std_msgs::Float64>(kFrameRateTopic, 1);
  std_msgs::Float64 message;
  message.data = frames_per_second;
  frame_rate_pub_.publish(message);
}

template <class Srv>
bool GazeboClient::call(const std::string& name, Srv& srv, Outcome* failed, bool repeatable) {
  const std::string full = simulatorName(name);
  if (!ros::service::exists(full, false)) {
    failed->text = "no simulator: " + full + " is not served";
    return false;
  }
  bool called = ros::service::call(full, srv);
  // A call whose connection dropped (a busy machine) is made once more before it counts as
  // failed when two have the effect of one (a reading, a state set to given values); a step or
  // a spawn is not, as it may have been made.
  if (!called && repeatable) called = ros::service::call(full, srv);
  if (!called) {
    failed->text = full + " failed (the simulator's log says why)";
    return false;
  }
  return true;
}

Outcome GazeboClient::callEmpty(const std::string& name, const std::string& what) {
  Outcome outcome;
  std_srvs::Empty srv;
  if (call(name, srv, &outcome)) {
    outcome.ok = true;
    outcome.text = what;
  }
  return outcome;
}

void GazeboClient::pause(Done done) {
  post([this, done] { done(callEmpty("pause_physics", "paused")); });
}

void GazeboClient::unpause(Done done) {
  post([this, done] { done(callEmpty("unpause_physics", "running")); });
}

void GazeboClient::resetSimulation(Done done) {
  post([this, done] { done(callEmpty("reset_simulation", "time and world reset")); });
}

void GazeboClient::resetWorld(Done done) {
  post([this, done] { done(callEmpty("reset_world", "world reset")); });
}

void GazeboClient::step(uint64_t steps, Done done) {
  post([this, steps, done] {
    Outcome outcome;
    onedof_sim::StepSimulation srv;
    srv.request.steps = steps;
    if (!ros::service::exists(simulatorName("step_simulation"), false)) {
      outcome.text = simulatorName("step_simulation") +
                     " is not served: the simulator serves it when asked for, with its "
                     "~enable_step_simulation (enable_step_simulation:=true or lockstep:=true "
                     "on the launch files)";
    } else if (call("step_simulation", srv, &outcome)) {
      outcome.ok = srv.response.success;
      outcome.text = srv.response.status_message;
    }
    done(outcome);
  });
}

void GazeboClient::insert(const CatalogModel& model, const geometry_msgs::Pose& pose, Done done) {
  post([this, model, pose, done] {
    Outcome outcome;
    gazebo_msgs::SpawnModel spawn;
    if (!model.shape.empty()) {
      spawn.request.model_xml = shapeSdf(model.shape);
    } else if (!readFile(model.sdf_path, &spawn.request.model_xml)) {
      outcome.text = "cannot read " + model.sdf_path;
      return done(outcome);
    }
    gazebo_msgs::GetWorldProperties world;
    if (!call("get_world_properties", world, &outcome, true)) return done(outcome);
    spawn.request.model_name = copyName(model.uri_name, world.response.model_names);
    spawn.request.initial_pose = pose;
    if (!call("spawn_sdf_model", spawn, &outcome)) return done(outcome);
    outcome.ok = spawn.response.success;
    outcome.text = spawn.response.success
                       ? "inserted " + spawn.request.model_name
                       : spawn.request.model_name + ": " + spawn.response.status_message;
    done(outcome);
  });
}

void GazeboClient::setModelPose(const std::string& model, const geometry_msgs::Pose& pose,
                                Done done) {
  post([this, model, pose, done] {
    Outcome outcome;
    gazebo_msgs::SetModelState srv;
    srv.request.model_state.model_name = model;
    srv.request.model_state.pose = pose;
    srv.request.model_state.reference_frame = "world";
    if (call("set_model_state", srv, &outcome, true)) {
      outcome.ok = srv.response.success;
      outcome.text = srv.response.success ? "moved " + model
                                          : model + ": " + srv.response.status_message;
    }
    done(outcome);
  });
}

void GazeboClient::modelPose(
    const std::string& model,
    std::function<void(const Outcome&, const geometry_msgs::Pose&)> done) {
  post([this, model, done] {
    Outcome outcome;
    gazebo_msgs::GetModelState srv;
    srv.request.model_name = model;
    if (call("get_model_state", srv, &outcome, true)) {
      outcome.ok = srv.response.success;
      outcome.text = srv.response.success ? model : model + ": " + srv.response.status_message;
    }
    done(outcome, srv.response.pose);
  });
}

void GazeboClient::physics(std::function<void(const Outcome&, const PhysicsState&)> done) {
  post([this, done] {
    Outcome outcome;
    PhysicsState state;
    gazebo_msgs::GetPhysicsProperties srv;
    if (call("get_physics_properties", srv, &outcome, true)) {
      outcome.ok = srv.response.success;
      outcome.text = srv.response.status_message;
      state.paused = srv.response.pause;
      state.time_step = srv.response.time_step;
      state.max_update_rate = srv.response.max_update_rate;
      state.gravity = srv.response.gravity;
      state.ode = srv.response.ode_config;
    }
    done(outcome, state);
  });
}

void GazeboClient::setPhysics(const PhysicsState& state, Done done) {
  post([this, state, done] {
    Outcome outcome;
    gazebo_msgs::SetPhysicsProperties srv;
    srv.request.time_step = state.time_step;
    srv.request.max_update_rate = state.max_update_rate;
    srv.request.gravity = state.gravity;
    srv.request.ode_config = state.ode;
    if (call("set_physics_properties", srv, &outcome, true)) {
      outcome.ok = srv.response.success;
      outcome.text = srv.response.success ? "physics set" : srv.response.status_message;
    }
    done(outcome);
  });
}

void GazeboClient::modelTrees(
    std::function<void(const Outcome&, const std::vector<ModelTree>&)> done) {
  post([this, done] {
    Outcome outcome;
    std::vector<ModelTree> trees;
    gazebo_msgs::GetWorldProperties world;
    if (call("get_world_properties", world, &outcome, true)) {
      outcome.ok = true;
      for (const std::string& name : world.response.model_names) {
        gazebo_msgs::GetModelProperties model;
        model.request.model_name = name;
        ModelTree tree{name, {}, {}};
        // A model deleted between the two calls is left out.
        Outcome left_out;
        if (!call("get_model_properties", model, &left_out, true) || !model.response.success)
          continue;
        tree.links = model.response.body_names;
        tree.joints = model.response.joint_names;
        trees.push_back(tree);
      }
    }
    done(outcome, trees);
  });
}

void GazeboClient::catalog(std::function<void(const std::vector<CatalogModel>&)> done) {
  post([this, done] {
    std::vector<std::string> simulator_path;
    ros::param::get(simulatorName("model_path"), simulator_path);
    const char* env = std::getenv("GAZEBO_MODEL_PATH");
    std::vector<std::pair<std::string, std::string>> exports;
    ros::package::getPlugins("gazebo_ros", "gazebo_model_path", exports, true);
    std::vector<std::string> exported;
    for (const auto& entry : exports) exported.push_back(entry.second);
    done(listModels(modelPathFolders(simulator_path, env ? env : "", exported)));
  });
}

}  // namespace gazebo_ros_panels
