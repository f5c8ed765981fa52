// The loop that owns the world and its time, as gzserver does: the World, the fixed-step loop and
// its pacing, pause and step requests, lock-step waiting, the model plugins' hooks around each
// step, and the publication of /clock, model_states, link_states and the world view's markers.
//
// Service callbacks (GazeboApi) run on their spinners and reach the world only through this
// class: a function run under the world lock (withWorld), a step request (runSteps), a
// controller's command (applyJointEffort). They share one mutex with the loop, held only for
// world calls, never while doing ROS I/O (stage_ros). Requests that change how the world advances
// only set state under that mutex and wake the loop; the loop alone steps.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <ros/ros.h>

#include <onedof_sim/world.h>

#include "lockstep.h"
#include "network_backlog.h"
#include "node_options.h"
#include "physics_config.h"
#include "plugins/model_plugin.h"
#include "process_activity.h"
#include "process_exits.h"
#include "view_markers.h"

namespace onedof_sim {

class SimLoop {
 public:
  // Throws std::invalid_argument for an unknown engine or invalid physics parameters.
  explicit SimLoop(const NodeOptions& options);
  ~SimLoop();

  // Steps the world at the configured pace until ROS shuts down (SIGINT).
  void run();

  // Runs f(World&) under the world lock and returns what it returns. In lock-step the lock is
  // taken where the world stops, never inside a controller's period; while sensors work on the
  // world a step left, it waits until they are done with it (see Lock).
  template <class F>
  auto withWorld(F&& f) {
    Lock lock(*this, Access::Change);
    return f(world_);
  }
  // The same for f(const World&), which only reads the world: it is answered between the parts
  // of the sensors' work too.
  template <class F>
  auto readWorld(F&& f) {
    Lock lock(*this, Access::Read);
    return f(static_cast<const World&>(world_));
  }
  // readWorld for a request of a controller (its caller name): lock-step notes it is at work.
  template <class F>
  auto readWorldFor(const std::string& caller, F&& f) {
    Lock lock(*this, Access::Read);
    if (lockstep_.enabled()) lockstep_.heardFrom(caller, Lockstep::Clock::now());
    return f(static_cast<const World&>(world_));
  }

  // apply_joint_effort from `caller`: the job, and in lock-step the joint joins or goes on
  // being waited for; the loop is woken.
  struct EffortCommand {
    std::string caller;
    std::string joint;
    double effort = 0;
    int64_t start_ns = 0;
    int64_t duration_ns = 0;  // < 0: until cleared
  };
  struct EffortResult {
    Status status;
    JobOutcome job;
    bool joined_lockstep = false;  // the joint's first command in lock-step: say so once
    // In lock-step, set when the command's period was over at this sim time: nothing applied.
    std::optional<int64_t> period_over_at_ns;
  };
  EffortResult applyJointEffort(const EffortCommand& command);
  // apply_joint_effort's reply is written (its caller may go on): said by the thread serving it
  // after each call, whatever its outcome.
  void effortReplied();

  bool paused();
  void setPaused(bool paused);

  // The most steps one step request may ask for (10,000 s of sim time at the default 1 ms step):
  // a request is stored only within it, so that none can run the world away unbounded.
  static constexpr uint64_t kMaxRequestedSteps = 10000000;

  // Pauses the world and runs exactly `steps` (at most kMaxRequestedSteps) steps (in lock-step,
  // until the controllers have acted at the last one); returns once they are done, or once
  // pause_physics, unpause_physics or reset_simulation ended the request (ended_by names it),
  // or on shutdown.
  struct StepsDone {
    bool done = false;
    const char* ended_by = nullptr;  // the request that ended it early, if any
    uint64_t steps = 0;              // steps taken for it
    int64_t time_ns = 0;
    uint64_t iterations = 0;
  };
  StepsDone runSteps(uint64_t steps);

  void resetSimulation();
  void resetWorld();
  // resetWorld() for one model and its plugins.
  Status resetModel(const std::string& model);

  // The world's physics parameters and the loop's pace.
  PhysicsSettings physics();
  // Sets both, or neither (the world's refusal).
  Status setPhysics(const PhysicsSettings& settings);

  // The model's plugins join the loop's hooks if the model is still there; else they are
  // destroyed, unlocked.
  void attachPlugins(const std::string& model,
                     std::vector<std::unique_ptr<plugins::ModelPlugin>> plugins);
  // Deletes the model; its plugins stop under the lock and are destroyed after it, unlocked.
  Status deleteModel(const std::string& model);
  // follow(true) when the world view's markers are advertised, follow(false) when they are taken
  // down, and at once with their current state: the view's other names (GazeboApi's) go with
  // them. Set before run().
  void followViewMarkers(std::function<void(bool)> follow);
  // The world, for plugins to read at creation under lockWorld().
  const World& world() const { return world_; }
  plugins::LockWorld lockWorld();

 private:
  // Whether a request only reads the world or may change it.
  enum class Access { Read, Change };
  // Locks the world for a service callback. Counts waiting callbacks so that the step loop, which
  // re-locks right after unlocking when running as fast as possible, lets them in first. In
  // lock-step it waits (bounded) until the world is at a stop. A request that may change the world
  // waits while the sensors work on it (doSensorWork).
  class Lock {
   public:
    Lock(SimLoop& loop, Access access);
    // Unlocks and tells the loop, which may be waiting for the callbacks to be through.
    ~Lock();
    std::unique_lock<std::mutex>& held() { return lock_; }

   private:
    SimLoop& loop_;
    std::unique_lock<std::mutex> lock_;
  };
  // Lock held: lets the callbacks waiting for the lock have it before the loop goes on, waiting
  // on callbacks_through_ (a loop that spun would take the CPU they need on a busy machine).
  void letCallbacksThrough(std::unique_lock<std::mutex>& lock, bool held_back_too);

  struct StepOutput;
  void stepOnce(StepOutput* out);
  void collectStates(StepOutput* out, bool want_model_states, bool want_link_states);
  void doSensorWork(std::unique_lock<std::mutex>& lock, StepOutput* out);
  // A plugin's messages so far, into the step's output.
  void takePublications(plugins::ModelPlugin* plugin, StepOutput* out);
  bool awaitControllers(std::unique_lock<std::mutex>& lock, StepOutput* out);
  bool letGoOfExited(const std::vector<Lockstep::Awaited>& awaited, StepOutput* out);
  void showWakeUpClock(const std::vector<Lockstep::Awaited>& awaited);
  bool awaitedAsleep(const std::vector<Lockstep::Awaited>& awaited);
  void awaitAsleep(const std::vector<Lockstep::Watched>& controllers,
                   Lockstep::Clock::time_point stopped_at);
  std::optional<int> controllerPid(const std::string& caller);
  // A controller's process as the loop looks at it (awaitAsleep, awaitedAsleep): its threads,
  // and which of them do its work.
  struct ControllerView {
    explicit ControllerView(int pid) : threads(pid) {}
    ProcessThreads threads;
    ThreadsAtWork work;
  };
  ControllerView& loopView(int pid);
  // Its threads' runs, as the thread serving apply_joint_effort reads them.
  ProcessRuns commandRuns(int pid);
  // Lock held: moves out the plugins of models no longer in the world, stopped.
  void detachPluginsOfRemovedModels(std::vector<std::unique_ptr<plugins::ModelPlugin>>* detached);
  void publish(const StepOutput& out);
  void publishClock(int64_t time_ns);
  // The same with the subscribers already counted (roscpp's count looks the topic up under a
  // lock): the step's publish counts them once.
  void publishClock(int64_t time_ns, uint32_t subscribers);
  // The latest time not published for want of subscribers, or while roscpp's network thread had
  // its budget of clocks still to write (-1: none): replaced by the next clock published, or
  // published once the loop stops.
  void publishHeldClock();
  // Re-reads the parameters the loop follows while running (kPubClockFrequency,
  // kEnableCollisionMarkers), at most ten times per wall second.
  void refreshParameters();
  // Advertises the world view's marker topics (view_markers.h), or takes them down.
  void setViewMarkers(bool on);
  void pace(double max_update_rate, bool resumed);

  ros::NodeHandle nh_;
  ros::NodeHandle private_nh_;

  // Guarded by mutex_.
  std::mutex mutex_;
  std::condition_variable wake_loop_;  // unpaused, steps requested, a controller's command
  std::condition_variable steps_done_;
  World world_;
  bool paused_;
  double max_update_rate_;
  Lockstep lockstep_;
  Lockstep::Clock::time_point last_command_at_;  // the latest accepted apply_joint_effort
  bool between_stops_ = false;  // a lock-stepped controller's period runs (requests wait)
  std::condition_variable at_stop_;
  int64_t clock_ahead_ns_ = -1;  // the wake-up clock shown ahead of the world, until it gets there
  // The lock-step stop the world stands at (its sim time, and the wall time it got there), from
  // which awaitControllers counts ~lockstep_timeout; empty after a pause.
  struct LockstepStop {
    int64_t time_ns = 0;
    Lockstep::Clock::time_point at;
  };
  std::optional<LockstepStop> lockstep_stop_;
  int64_t reset_clock_ns_ = -1;  // the time reset_simulation went back to, not yet on /clock
  struct StepRequest {
    bool active = false;  // until the steps are done (and, in lock-step, the controllers acted)
    uint64_t remaining = 0;
    uint64_t taken = 0;
    const char* ended_by = nullptr;  // the request that ended it before its last step
  } step_request_;
  // Ends a step request in progress, lock held: `by` is the request that ends it.
  void endStepRequest(const char* by);
  std::atomic<int> waiting_callbacks_{0};
  std::condition_variable callbacks_through_;
  // The sensors work on the world a step left (doSensorWork): requests that may change it wait on
  // sensed_, counted in held_back_ so that the loop lets them in before its next step.
  bool sensing_ = false;
  std::condition_variable sensed_;
  std::atomic<int> held_back_{0};
  std::atomic<uint64_t> efforts_heard_{0};  // apply_joint_effort calls begun
  // And answered (effortReplied): a stop's clock waits on replied_ for the replies of the calls
  // begun before it.
  std::mutex replies_mutex_;
  std::condition_variable replied_;
  uint64_t efforts_replied_ = 0;  // guarded by replies_mutex_
  // Each model's plugins, called in this order around every step.
  std::map<std::string, std::vector<std::unique_ptr<plugins::ModelPlugin>>> plugins_;

  // The processes of apply_joint_effort's callers on this machine (empty: elsewhere), by name.
  std::mutex pids_mutex_;
  std::map<std::string, std::optional<int>> controller_pids_;
  // Those processes, watched for their exit, which wakes the loop (awaitControllers).
  ProcessExits exits_;
  // Those processes' threads, by pid: as apply_joint_effort reads them (guarded by
  // command_views_mutex_), and as the loop reads them (loop thread only).
  std::mutex command_views_mutex_;
  std::map<int, std::unique_ptr<ProcessThreads>> command_views_;
  std::map<int, std::unique_ptr<ControllerView>> loop_views_;

  // Step-loop state (only the loop thread touches these).
  std::set<std::string> busy_controllers_;  // named once for never resting (awaitAsleep)
  double states_publish_frequency_;
  double clock_frequency_ = 0;  // /gazebo/pub_clock_frequency; <= 0: every step
  bool ros_network_;             // ~enable_ros_network: the /gazebo topics may be advertised
  std::chrono::steady_clock::time_point next_param_refresh_;
  std::chrono::steady_clock::time_point deadline_;
  int64_t last_clock_ns_ = -1;
  int64_t held_clock_ns_ = -1;
  int64_t last_states_ns_ = -1;

  ros::Publisher clock_pub_;
  // The clocks roscpp's network thread has still to write to the other processes
  // (network_backlog.h).
  NetworkBacklog clock_backlog_;
  ros::Publisher model_states_pub_;
  ros::Publisher link_states_pub_;
  // Advertised while ~enable_collision_markers is true, as last read.
  ViewMarkers view_markers_;
  std::function<void(bool)> view_markers_follower_;
};

}  // namespace onedof_sim
