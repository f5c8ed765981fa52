#include "sim_loop.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <stdexcept>
#include <thread>
#include <utility>

#include <unistd.h>

#include <gazebo_msgs/LinkStates.h>
#include <gazebo_msgs/ModelStates.h>
#include <rosgraph_msgs/Clock.h>

#include "conversions.h"
#include "node_process.h"
#include "process_activity.h"
#include "status_text.h"

namespace onedof_sim {
namespace {

// If the paced loop falls further behind than this, it drops the backlog instead of racing.
constexpr std::chrono::milliseconds kMaxPacingLag(100);
constexpr std::chrono::milliseconds kPacingSlice(50);
constexpr uint32_t kClockQueue = 1000;
// The clock messages roscpp's network thread may have still to write, to all subscribers
// together: a lone subscriber may fall 100 steps behind before it misses one (gazebo_ros' /clock
// queue drops beyond 10), while beside 33 subscribers a request waits behind at most 3 steps'
// clocks.
constexpr size_t kClockBacklog = 100;
// For a controller whose process is not on this machine (lock-step cannot see it rest): a
// client's two clock readings after a call are microseconds apart; a millisecond leaves them room
// and bounds such a 1 kHz controller to real time.
constexpr std::chrono::milliseconds kLockstepClockDelay(1);
// How long its wait for a reply to be written goes on before it looks for a shutdown.
constexpr std::chrono::milliseconds kAsleepWaitSlice(50);
// How long a stopped world waits for a controller's command, the controller asleep, before it
// shows the clock ahead to wake one that slept past the stop (awaitControllers).
constexpr std::chrono::milliseconds kLockstepWakeAfter(500);
// In lock-step, how long a request may wait for the world to reach a stop (WorldLock).
constexpr std::chrono::seconds kStopWaitLimit(1);
constexpr std::chrono::milliseconds kStopWaitSlice(50);
// The longest a part of a sensor's work holds the world (SensorWork::withWorld): requests that
// read the world wait at most about this long for it.
constexpr std::chrono::milliseconds kSensorWorkPart(10);
// How long the loop waits at a time for callbacks to have had the lock (letCallbacksThrough):
// it looks again then, should it not have been told.
constexpr std::chrono::milliseconds kCallbacksWaitSlice(1);

// The view of process pid in views, made when missing. Making one lets go of the views of
// processes gone (a controller restarted has another pid), and with them their open files.
template <class View>
View& viewOf(std::map<int, std::unique_ptr<View>>* views, int pid) {
  std::unique_ptr<View>& view = (*views)[pid];
  if (view) return *view;
  view = std::make_unique<View>(pid);
  for (auto it = views->begin(); it != views->end();)
    it = it->first != pid && !processLives(it->first) ? views->erase(it) : std::next(it);
  return *view;
}

// Whether a throttled output is due at sim time now_ns (frequency <= 0: every step). Time going
// back (reset_simulation) makes it due at once.
bool isDue(int64_t now_ns, int64_t last_ns, double frequency) {
  if (frequency <= 0 || last_ns < 0 || now_ns < last_ns) return true;
  return double(now_ns - last_ns) >= 1e9 / frequency;
}

}  // namespace

struct SimLoop::StepOutput {
  bool stepped = false;
  bool on_request = false;     // a step of step_simulation: not paced
  bool publish_clock = false;  // whatever pub_clock_frequency says: the world stops here
  bool hold_clock = false;     // lock-stepped controllers' efforts run: only stops are published
  Lockstep::Clock::time_point clock_not_before;  // of a lock-step stop (see stepOnce)
  Lockstep::Clock::time_point stopped_at;        // when the world reached that stop
  bool resumed = false;  // the pacing must restart (after a pause or a rate change)
  int64_t reset_clock_ns = -1;  // a reset's time, published before anything of this output
  int64_t time_ns = 0;
  double max_update_rate = 0;
  bool has_model_states = false;
  bool has_link_states = false;
  gazebo_msgs::ModelStates model_states;
  gazebo_msgs::LinkStates link_states;
  ViewMarkers::Facts views;  // what the world view's markers need, when due
  std::vector<std::string> warnings;  // what the world had to do on its own during the step
  std::vector<std::string> notes;     // what lock-step did that a user may want to know
  std::vector<plugins::Publication> plugin_publications;  // the model plugins' messages
  // Their sensors' work: its withoutWorld phase is done in publish, unlocked.
  std::vector<std::shared_ptr<plugins::SensorWork>> sensor_work;
  // At a lock-step stop: the controllers' processes the stop's clock waits to see asleep.
  std::vector<Lockstep::Watched> watched;
  // Plugins of models the world removed in the step, destroyed with this output, unlocked.
  std::vector<std::unique_ptr<plugins::ModelPlugin>> detached_plugins;
};

SimLoop::Lock::Lock(SimLoop& api, Access access) : loop_(api) {
  ++api.waiting_callbacks_;
  lock_ = std::unique_lock<std::mutex>(api.mutex_);
  --api.waiting_callbacks_;
  // In lock-step a request lands where the world stops, never inside a controller's period: a
  // controller that slept past a stop and was woken (awaitControllers) sends the next period's
  // request at once, and must find the world at that period's start, as it would have on time.
  // Bounded, so that a world paced very slowly still answers.
  const auto limit = std::chrono::steady_clock::now() + kStopWaitLimit;
  for (;;) {
    // Not cut short by a shutdown: the work may hold parts of the world a change would remove
    // (a deleted model's sensor), and ends by itself.
    if (access == Access::Change && api.sensing_) {
      ++api.held_back_;
      api.sensed_.wait_for(lock_, kStopWaitSlice);
      --api.held_back_;
    } else if (api.between_stops_ && !api.paused_ && ros::ok() &&
               std::chrono::steady_clock::now() < limit) {
      api.at_stop_.wait_for(lock_, kStopWaitSlice);
    } else {
      return;
    }
  }
}

SimLoop::Lock::~Lock() {
  if (lock_.owns_lock()) lock_.unlock();
  if (loop_.waiting_callbacks_.load() == 0) loop_.callbacks_through_.notify_all();
}

void SimLoop::letCallbacksThrough(std::unique_lock<std::mutex>& lock, bool held_back_too) {
  while (waiting_callbacks_.load() > 0 || (held_back_too && held_back_.load() > 0))
    callbacks_through_.wait_for(lock, kCallbacksWaitSlice);
}

SimLoop::SimLoop(const NodeOptions& options)
    : private_nh_("~"),
      world_(options.engine),
      paused_(options.paused),
      max_update_rate_(options.max_update_rate),
      lockstep_(options.lockstep),
      exits_([this] {
        // Under the lock, so that the loop cannot miss the wake between its look and its wait.
        { std::lock_guard<std::mutex> lock(mutex_); }
        wake_loop_.notify_all();
      }),
      states_publish_frequency_(options.states_publish_frequency),
      ros_network_(options.enable_ros_network),
      clock_backlog_(kClockBacklog) {
  const Status params = world_.setParams(options.physics);
  if (!params.ok()) throw std::invalid_argument(statusText(kSetPhysicsProperties, params));
  world_.setModelPath(options.model_path);
  setUseSimTimeUnlessSet();

  // Latched: a node started while the world is paused learns the time at once, instead of
  // running on time 0 (no valid time to roscpp and rospy) until the world moves. roscpp writes
  // each message from its poll thread and drops the oldest beyond the queue: a loop behind its
  // pace catches up by up to kMaxPacingLag of steps at once, and a busy machine delays the poll
  // thread too, so the queue holds a second of clocks at the default 1 kHz, and a subscriber
  // that keeps up hears every step's time, as long as the thread is less than kClockBacklog
  // messages behind (clock_backlog_).
  clock_pub_ = nh_.advertise<rosgraph_msgs::Clock>("/clock", kClockQueue, true);
  // Without the ROS network these stay empty publishers: no subscriber, nothing is published.
  if (!options.enable_ros_network) return;
  model_states_pub_ = private_nh_.advertise<gazebo_msgs::ModelStates>("model_states", 1);
  link_states_pub_ = private_nh_.advertise<gazebo_msgs::LinkStates>("link_states", 1);
  if (options.enable_collision_markers) setViewMarkers(true);
}

SimLoop::~SimLoop() {
  wake_loop_.notify_all();
  steps_done_.notify_all();
}

void SimLoop::run() {
  bool was_stepping = false;
  double paced_rate = -1;
  while (ros::ok()) {
    refreshParameters();
    StepOutput out;
    stepOnce(&out);
    // /clock is latched: without this a node subscribing after a reset would first hear the time
    // the world had before it (a paused world's only message until it moves). Whatever time the
    // loop held back unpublished is from before the reset, and publishClock drops it.
    if (out.reset_clock_ns >= 0) publishClock(out.reset_clock_ns);
    for (const auto& warning : out.warnings) ROS_WARN_STREAM(warning);
    for (const auto& note : out.notes) ROS_INFO_STREAM(note);
    if (!out.stepped) {
      was_stepping = false;
      publishHeldClock();
      view_markers_.publish(out.views);
      continue;
    }
    publish(out);
    if (out.on_request) continue;  // step_simulation runs its steps as fast as it can
    out.resumed = !was_stepping || out.max_update_rate != paced_rate;
    was_stepping = true;
    paced_rate = out.max_update_rate;
    pace(out.max_update_rate, out.resumed);
  }
}

void SimLoop::stepOnce(StepOutput* out) {
  const bool want_model_states = model_states_pub_.getNumSubscribers() > 0;
  const bool want_link_states = link_states_pub_.getNumSubscribers() > 0;

  // Let waiting service callbacks in first; they hold the lock only for one world call.
  std::unique_lock<std::mutex> lock(mutex_);
  letCallbacksThrough(lock, true);
  // Taken as the lock is let go, on every return: a reset during a wait below comes before this
  // output's step, so its clock must go out first.
  struct TakeResetClock {
    int64_t& from;
    int64_t& to;
    ~TakeResetClock() { std::swap(from, to); }
  } take_reset_clock{reset_clock_ns_, out->reset_clock_ns};
  const bool requested = step_request_.remaining > 0;
  const bool request_ending = step_request_.active && !requested;
  if (paused_ && !requested && !request_ending) {
    lockstep_stop_.reset();  // a wait at a stop starts afresh once the world runs again
    // Wakes on unpause or a step request; the timeout lets run() notice a shutdown.
    wake_loop_.wait_for(lock, std::chrono::milliseconds(50));
    view_markers_.collect(world_, false, &out->views);  // a standing world is still shown
    return;
  }
  if (lockstep_.enabled() && !awaitControllers(lock, out)) return;
  if (request_ending) {
    step_request_.active = false;
    steps_done_.notify_all();
    return;
  }
  // The plugins act at the step's start and end time, as Gazebo's at the world's update begin
  // and end, and never wait: lock-step waits only for apply_joint_effort's clients.
  for (auto& [model, plugins] : plugins_)
    for (auto& plugin : plugins) plugin->beforeStep(world_, {world_.timeNs(), world_.stepCount()});
  const Status stepped = world_.step();
  if (stepped.code == StatusCode::EngineFaultUnattributed) {
    // The world stood still where the step started: physics pauses, with the reason.
    paused_ = true;
    endStepRequest("a physics engine failure (the log says why)");
    const std::vector<std::string> world_warnings = world_.takeWarnings();
    out->warnings.insert(out->warnings.end(), world_warnings.begin(), world_warnings.end());
    out->warnings.push_back(engineStoppedText(stepped));
    return;
  }
  // A model the world removed after an engine failure takes its plugins with it (destroyed with
  // the output, unlocked).
  if (!stepped.ok()) detachPluginsOfRemovedModels(&out->detached_plugins);
  for (auto& [model, plugins] : plugins_) {
    for (auto& plugin : plugins) {
      plugin->afterStep(world_, {world_.timeNs(), world_.stepCount()});
      for (auto& work : plugin->takeSensorWork()) out->sensor_work.push_back(std::move(work));
      takePublications(plugin.get(), out);
    }
  }
  if (requested) {
    --step_request_.remaining;
    ++step_request_.taken;
    // The world went on without the model that made the engine fail (its warning says which);
    // the request's caller learns that its steps did not run as asked.
    if (!stepped.ok()) endStepRequest("a physics engine failure (the log names the model removed)");
  }
  out->stepped = true;
  out->on_request = requested;
  const std::vector<std::string> world_warnings = world_.takeWarnings();
  out->warnings.insert(out->warnings.end(), world_warnings.begin(), world_warnings.end());
  out->time_ns = world_.timeNs();
  out->max_update_rate = max_update_rate_;
  // Where the world stops (the last requested step, or a controller's effort running out in
  // lock-step), its time must reach the clients even when /clock is throttled: they wait for it.
  // While lock-stepped controllers' efforts run, only those stops are published: roscpp's and
  // rospy's rates read the clock twice (sleep for a remainder counted from the second reading),
  // and a clock that moves between the two readings puts their wake-up past the stop they are
  // waited for at. Held still between stops, it cannot move there.
  const bool stop = (requested && step_request_.remaining == 0) ||
                    (lockstep_.enabled() && !lockstep_.awaited(world_, out->time_ns).empty());
  out->publish_clock = stop;
  out->hold_clock = !stop && lockstep_.enabled() && lockstep_.running(world_, out->time_ns);
  between_stops_ = out->hold_clock;
  if (!between_stops_) at_stop_.notify_all();
  // After a wake-up clock (awaitControllers) the clients' time is ahead of the world's: nothing
  // earlier goes out, clocks never move back.
  if (clock_ahead_ns_ >= 0 && out->time_ns < clock_ahead_ns_) {
    out->publish_clock = false;
    out->hold_clock = true;
  } else {
    clock_ahead_ns_ = -1;
  }
  // And a stop's clock goes out only while no controller can be between those two readings,
  // which follow its call's return at once: when its process on this machine rests (awaitAsleep),
  // or, for one elsewhere, no sooner than kLockstepClockDelay after the latest command.
  if (stop && lockstep_.enabled()) {
    lockstep_stop_ = LockstepStop{out->time_ns, Lockstep::Clock::now()};
    out->stopped_at = lockstep_stop_->at;
    out->watched = lockstep_.watched(world_);
    if (lockstep_.someUnwatched(world_))
      out->clock_not_before = last_command_at_ + kLockstepClockDelay;
  }

  collectStates(out, want_model_states, want_link_states);
  doSensorWork(lock, out);
}

// The step's sensor work, the parts that need the world (SensorWork::withWorld), with the lock let
// go between them for the requests that only read it; then the messages that work made. The rest
// of the work is done unlocked, in publish.
void SimLoop::doSensorWork(std::unique_lock<std::mutex>& lock, StepOutput* out) {
  if (out->sensor_work.empty()) return;
  sensing_ = true;
  for (const auto& work : out->sensor_work) {
    while (!work->withWorld(world_, plugins::SensorWork::Clock::now() + kSensorWorkPart))
      letCallbacksThrough(lock, false);
  }
  sensing_ = false;
  sensed_.notify_all();
  for (auto& [model, plugins] : plugins_)
    for (auto& plugin : plugins) takePublications(plugin.get(), out);
}

void SimLoop::takePublications(plugins::ModelPlugin* plugin, StepOutput* out) {
  for (auto& publication : plugin->takePublications())
    out->plugin_publications.push_back(std::move(publication));
}

// The states and view markers due at this step that someone subscribes to, world locked.
void SimLoop::collectStates(StepOutput* out, bool want_model_states, bool want_link_states) {
  const bool states_due = isDue(out->time_ns, last_states_ns_, states_publish_frequency_);
  if (states_due && (want_model_states || want_link_states)) last_states_ns_ = out->time_ns;
  if (states_due && want_model_states) {
    out->has_model_states = true;
    out->model_states = modelStatesOf(world_);
  }
  if (states_due && want_link_states) {
    out->has_link_states = true;
    out->link_states = linkStatesOf(world_);
  }
  view_markers_.collect(world_, true, &out->views);
}

// Lock-step: holds the world until every lock-stepped joint has an effort acting in the coming
// step, giving up (and saying so once) on those silent for the timeout. The timeout counts from
// when the world reached the stop: the wait for the stop's clock (awaitAsleep, which a stopped
// or busy controller holds up) is part of it, so a controller that does not answer holds the
// world ~lockstep_timeout in all. Returns false when the wait ends for another reason (paused
// meanwhile, shutdown): the caller starts over.
bool SimLoop::awaitControllers(std::unique_lock<std::mutex>& lock, StepOutput* out) {
  const auto began = lockstep_stop_ && lockstep_stop_->time_ns == world_.timeNs()
                         ? lockstep_stop_->at
                         : Lockstep::Clock::now();
  const auto deadline = began + lockstep_.timeout();
  bool woken = false;
  for (;;) {
    const std::vector<Lockstep::Awaited> awaited = lockstep_.awaited(world_, world_.timeNs());
    if (awaited.empty()) return true;
    if (letGoOfExited(awaited, out)) continue;
    const auto now = Lockstep::Clock::now();
    if (now >= deadline) {
      lockstep_.giveUp(awaited);
      out->warnings.push_back(lockstepTimeoutText(awaited, world_.timeNs(), lockstep_.timeout()));
      return true;
    }
    // Woken when the awaited controllers have sent nothing for a while, here or before: one
    // still at work on its period (it asked for the joint) is left to finish it.
    const auto wake_at = std::max(began, lockstep_.lastRequest(awaited)) + kLockstepWakeAfter;
    if (!woken && now >= wake_at && awaitedAsleep(awaited)) {
      woken = true;
      showWakeUpClock(awaited);
    }
    // In slices, to notice a shutdown.
    auto until = std::min(deadline, now + std::chrono::milliseconds(50));
    if (!woken && now < wake_at) until = std::min(until, wake_at);
    wake_loop_.wait_until(lock, until);
    if (!ros::ok()) return false;
    if (paused_ && !step_request_.active) {
      lockstep_stop_.reset();
      return false;
    }
  }
}

// A controller on this machine whose process has exited commands no more: its joints leave the
// lock-step at once (the exit wakes the loop), each caller said once. Returns whether any left.
bool SimLoop::letGoOfExited(const std::vector<Lockstep::Awaited>& awaited, StepOutput* out) {
  std::map<std::string, std::vector<Lockstep::Awaited>> exited;  // by caller
  for (const Lockstep::Awaited& joint : awaited) {
    const std::optional<int> pid = lockstep_.pidOf(joint.caller);
    if (pid && exits_.exited(*pid)) exited[joint.caller].push_back(joint);
  }
  for (const auto& [caller, joints] : exited) {
    lockstep_.giveUp(joints);
    out->notes.push_back(
        lockstepExitedText(caller, *lockstep_.pidOf(caller), joints, world_.timeNs()));
  }
  return !exited.empty();
}

// roscpp's Rate (the book's C++ loop) and rospy's read the clock twice, before and after their
// sleep's start, and sleep for the remainder counted from the second reading. A stop's clock
// waits until a controller on this machine rests (awaitAsleep), so it cannot land between them;
// for one elsewhere it can (a client preempted there), and a client that sleeps for other reasons
// than its Rate can sleep past a stop too. Either sleeps one period past the stop, where the world
// waits for it: the clock is then shown at the next period's earliest end, the world staying
// where it is. The client wakes and commands for the stop (its job starts at the world's time, also when it
// names the time shown: applyJointEffort), then asks for the next period at once: that request
// waits for the next stop (Lock). The run is as if the client had woken on time.
void SimLoop::showWakeUpClock(const std::vector<Lockstep::Awaited>& awaited) {
  const std::optional<int64_t> wake_ns = lockstep_.wakeTime(world_, world_.timeNs());
  if (!wake_ns || *wake_ns <= last_clock_ns_) return;
  publishClock(*wake_ns);
  clock_ahead_ns_ = *wake_ns;
  ROS_DEBUG_STREAM("lock-step: nothing from " << awaited.front().caller << " for "
                   << std::chrono::duration<double>(kLockstepWakeAfter).count()
                   << " s (wall) at sim time " << simSeconds(world_.timeNs())
                   << "; showing the clock at " << simSeconds(*wake_ns)
                   << " to wake a controller that slept past the stop");
}

// A controller on this machine that has not answered is woken only when its process is asleep:
// a starved one (runnable, waiting for a CPU) has not slept past the stop and answers on its own.
bool SimLoop::awaitedAsleep(const std::vector<Lockstep::Awaited>& awaited) {
  for (const Lockstep::Awaited& joint : awaited) {
    const std::optional<int> pid = lockstep_.pidOf(joint.caller);
    if (pid && !loopView(*pid).threads.activity().asleep) return false;
  }
  return true;
}

SimLoop::ControllerView& SimLoop::loopView(int pid) { return viewOf(&loop_views_, pid); }

ProcessRuns SimLoop::commandRuns(int pid) {
  std::lock_guard<std::mutex> lock(command_views_mutex_);
  return viewOf(&command_views_, pid).runs();
}

// Holds a stop's clock until every lock-stepped controller's process on this machine has run since
// its command (its call has returned) and rests: every thread blocked, none run between two looks,
// but for dormant threads (ThreadsAtWork: woken by their own timers, not run since the command).
// Then none is between the two clock readings of its Rate, which run on from the call's return
// without blocking, so each wakes where the world stops, however the machine delays it. A process
// that never rests (a busy thread, or one stopped by SIGSTOP) holds the clock at most
// ~lockstep_timeout after the world reached the stop (`stopped_at`), and is named once.
void SimLoop::awaitAsleep(const std::vector<Lockstep::Watched>& controllers,
                          Lockstep::Clock::time_point stopped_at) {
  if (controllers.empty()) return;
  const auto give_up_at = stopped_at + lockstep_.timeout();
  const uint64_t heard = efforts_heard_.load();
  {
    // Until its reply is written, a controller rests waiting for it. In slices, to notice a
    // shutdown.
    std::unique_lock<std::mutex> lock(replies_mutex_);
    while (efforts_replied_ < heard && ros::ok() && Lockstep::Clock::now() < give_up_at)
      replied_.wait_until(lock, std::min(give_up_at, Lockstep::Clock::now() + kAsleepWaitSlice));
  }
  std::vector<ProcessActivity> rests(controllers.size());
  for (;;) {
    std::vector<const Lockstep::Watched*> busy;
    for (size_t i = 0; i < controllers.size(); ++i) {
      const Lockstep::Watched& controller = controllers[i];
      ControllerView& view = loopView(controller.pid);
      rests[i] = view.threads.activity([&](const ThreadRuns& thread) {
        return view.work.dormant(controller.runs_at_command, thread);
      });
      if (!rests[i].restedSince(controller.runs_at_command)) busy.push_back(&controller);
    }
    if (busy.empty()) {
      for (size_t i = 0; i < controllers.size(); ++i)
        if (!rests[i].gone)
          loopView(controllers[i].pid).work.noteRest(controllers[i].runs_at_command,
                                                     rests[i].threads);
      return;
    }
    if (!ros::ok()) return;
    if (Lockstep::Clock::now() >= give_up_at) {
      for (const Lockstep::Watched* controller : busy)
        if (busy_controllers_.insert(controller->caller).second)
          ROS_WARN_STREAM(lockstepBusyText(controller->caller, controller->pid,
                                           lockstep_.timeout()));
      return;
    }
    std::this_thread::sleep_for(kRestLookInterval);
  }
}

// The process on this machine of a controller (asked once; again if that process is gone),
// watched for its exit from then on.
std::optional<int> SimLoop::controllerPid(const std::string& caller) {
  std::optional<int> known;
  {
    std::lock_guard<std::mutex> lock(pids_mutex_);
    auto found = controller_pids_.find(caller);
    if (found != controller_pids_.end()) {
      if (!found->second || processLives(*found->second)) return found->second;
      known = found->second;
    }
  }
  bool silent_here = false;
  std::optional<int> pid = localNodePid(caller, &silent_here);
  if (pid && *pid == int(::getpid())) pid.reset();  // a client inside this node: it never rests
  if (pid) {
    int error = 0;
    if (exits_.watch(*pid, &error) == ProcessExits::Watch::kCannot)
      ROS_WARN_STREAM(lockstepUnwatchedExitText(caller, *pid, error, lockstep_.timeout()));
  } else if (silent_here) {
    // Its process has exited and the master still names it, here, where nothing answers: a
    // command it sent before it exited, served after. The caller stays that process.
    pid = known;
  }
  std::lock_guard<std::mutex> lock(pids_mutex_);
  controller_pids_[caller] = pid;
  return pid;
}

void SimLoop::publishClock(int64_t time_ns) {
  publishClock(time_ns, clock_pub_.getNumSubscribers());
}

void SimLoop::publishClock(int64_t time_ns, uint32_t subscribers) {
  last_clock_ns_ = time_ns;
  held_clock_ns_ = -1;
  rosgraph_msgs::Clock clock;
  clock.clock.fromNSec(uint64_t(time_ns));
  clock_pub_.publish(clock);
  clock_backlog_.handedOver(subscribers);
}

void SimLoop::publishHeldClock() {
  if (held_clock_ns_ >= 0) publishClock(held_clock_ns_);
}

void SimLoop::publish(const StepOutput& out) {
  if (out.publish_clock) {
    std::this_thread::sleep_until(out.clock_not_before);
    awaitAsleep(out.watched, out.stopped_at);
  }
  if (out.publish_clock ||
      (!out.hold_clock && isDue(out.time_ns, last_clock_ns_, clock_frequency_))) {
    // Latched, so roscpp wakes its poll thread for every message, subscribers or not: with
    // none, the latest time is only kept, and goes out where the loop stops (publishHeldClock).
    // So it is while roscpp's network thread has its budget of clocks still to write: the time
    // goes out with a later step's. A stop's clock always goes out (lock-step waits for it).
    const uint32_t subscribers = clock_pub_.getNumSubscribers();
    if (out.publish_clock || (subscribers > 0 && !clock_backlog_.full(subscribers))) {
      publishClock(out.time_ns, subscribers);
    } else {
      held_clock_ns_ = out.time_ns;
    }
  }
  for (const auto& publication : out.plugin_publications) publication();
  for (const auto& work : out.sensor_work)
    for (const auto& publication : work->withoutWorld()) publication();
  if (out.has_model_states) model_states_pub_.publish(out.model_states);
  if (out.has_link_states) link_states_pub_.publish(out.link_states);
  view_markers_.publish(out.views);
}

// pub_clock_frequency and enable_collision_markers may be changed while running; reading them at
// every step would cost more than the step, so they are re-read ten times per wall second, also
// while the world is paused (a view started then finds the markers' publishers).
void SimLoop::refreshParameters() {
  const auto now = std::chrono::steady_clock::now();
  if (now < next_param_refresh_) return;
  next_param_refresh_ = now + std::chrono::milliseconds(100);
  double frequency = 0;
  if (!private_nh_.getParamCached(kPubClockFrequency, frequency) || !std::isfinite(frequency)) {
    frequency = 0;
  }
  clock_frequency_ = frequency;
  clock_backlog_.refresh(clock_pub_.getTopic(), typeid(rosgraph_msgs::Clock));
  if (!ros_network_) return;
  bool markers = false;  // unset, or not a bool: off
  private_nh_.getParamCached(kEnableCollisionMarkers, markers);
  if (markers == view_markers_.advertised()) return;
  setViewMarkers(markers);
  ROS_INFO_STREAM((markers ? "publishing " : "no longer publishing ")
                  << "the world view's markers (" << private_nh_.resolveName("visual_markers")
                  << ", collision_markers, ...) ("
                  << private_nh_.resolveName(kEnableCollisionMarkers) << " is "
                  << (markers ? "true" : "false") << ")");
}

void SimLoop::setViewMarkers(bool on) {
  if (on)
    view_markers_.advertise(private_nh_);
  else
    view_markers_.shutdown();
  if (view_markers_follower_) view_markers_follower_(on);
}

void SimLoop::followViewMarkers(std::function<void(bool)> follow) {
  view_markers_follower_ = std::move(follow);
  view_markers_follower_(view_markers_.advertised());
}

// Sleeps until this step's absolute deadline (no drift: deadlines are origin + n periods).
void SimLoop::pace(double max_update_rate, bool resumed) {
  using std::chrono::steady_clock;
  const auto now = steady_clock::now();
  if (max_update_rate <= 0) return;
  if (resumed) deadline_ = now;
  deadline_ += std::chrono::duration_cast<steady_clock::duration>(
      std::chrono::duration<double>(1.0 / max_update_rate));
  if (deadline_ > now) {
    // In slices: a new max_update_rate takes effect at once (run() re-paces from the next step),
    // and a shutdown (SIGINT) is noticed, however long the period.
    while (ros::ok() && steady_clock::now() < deadline_) {
      std::this_thread::sleep_until(std::min(deadline_, steady_clock::now() + kPacingSlice));
      std::lock_guard<std::mutex> lock(mutex_);
      if (max_update_rate_ != max_update_rate) return;
    }
  } else if (now - deadline_ > kMaxPacingLag) {
    deadline_ = now;  // far behind (a loaded machine): run on from now rather than race
  }
}

// --- requests of the service callbacks ----------------------------------------------------------

void SimLoop::effortReplied() {
  {
    std::lock_guard<std::mutex> lock(replies_mutex_);
    ++efforts_replied_;
  }
  replied_.notify_all();
}

SimLoop::EffortResult SimLoop::applyJointEffort(const EffortCommand& command) {
  EffortResult result;
  efforts_heard_.fetch_add(1);
  // The caller's process and its runs before the reply: the stop's clock waits until it has run
  // since (awaitAsleep).
  std::optional<int> pid;
  ProcessRuns runs;
  if (lockstep_.enabled()) {
    pid = controllerPid(command.caller);
    if (pid) runs = commandRuns(*pid);
  }
  {
    Lock lock(*this, Access::Change);
    if (lockstep_.enabled()) lockstep_.heardFrom(command.caller, Lockstep::Clock::now());
    // Under a wake-up clock a client's "now" is the time shown, ahead of the world's: it means
    // the world's.
    const int64_t now_ns = world_.timeNs();
    int64_t start_ns = command.start_ns;
    int64_t duration_ns = command.duration_ns;
    if (clock_ahead_ns_ >= 0 && start_ns > now_ns && start_ns <= clock_ahead_ns_) start_ns = now_ns;
    // A lock-stepped period already under way or over when its command comes (a controller
    // behind the world: it started while the world ran free) acts for what is left of it only,
    // so the world's next stop falls on the controller's grid of periods and the two are in step
    // from then on. Gazebo starts such a job now for its whole duration: the world would run a
    // period ahead of the controller for good, each sample read a period after its stamp.
    if (lockstep_.enabled() && start_ns > 0 && start_ns < now_ns && duration_ns > 0) {
      duration_ns = start_ns + duration_ns - now_ns;
      if (duration_ns <= 0) result.period_over_at_ns = now_ns;
    }
    if (result.period_over_at_ns) {
      JointInfo joint;
      result.status = world_.jointInfo(command.joint, &joint);
    } else {
      result.status = world_.applyJointEffort(command.joint, command.effort, start_ns,
                                              duration_ns, &result.job);
    }
    if (result.status.ok() && result.job.queued) {
      last_command_at_ = Lockstep::Clock::now();
      lockstep_.commandedFrom(command.caller, pid, std::move(runs));
      result.joined_lockstep =
          lockstep_.heard(command.joint, command.caller, command.duration_ns < 0,
                          world_.timeNs(), command.duration_ns);
      // The last awaited command: the world moves on, and the next request waits for the next
      // stop (Lock) even when it comes before the loop has taken its first step.
      if (!paused_ && lockstep_.running(world_, now_ns) && lockstep_.awaited(world_, now_ns).empty())
        between_stops_ = true;
    }
  }
  if (lockstep_.enabled()) wake_loop_.notify_all();
  return result;
}

bool SimLoop::paused() {
  Lock lock(*this, Access::Read);
  return paused_;
}

void SimLoop::setPaused(bool paused) {
  {
    Lock lock(*this, Access::Change);
    paused_ = paused;
    endStepRequest(paused ? "pause_physics" : "unpause_physics");
  }
  if (!paused) wake_loop_.notify_all();
}

void SimLoop::endStepRequest(const char* by) {
  if (!step_request_.active) return;
  step_request_.active = false;
  step_request_.remaining = 0;
  step_request_.ended_by = by;
  steps_done_.notify_all();
}

SimLoop::StepsDone SimLoop::runSteps(uint64_t steps) {
  if (steps > kMaxRequestedSteps) throw std::invalid_argument("more steps than a request takes");
  Lock lock(*this, Access::Change);
  paused_ = true;
  step_request_ = {true, steps};
  wake_loop_.notify_all();
  while (step_request_.active && ros::ok())
    steps_done_.wait_for(lock.held(), std::chrono::milliseconds(100));
  StepsDone done{!step_request_.active && !step_request_.ended_by, step_request_.ended_by,
                 step_request_.taken, world_.timeNs(), world_.stepCount()};
  step_request_ = {};
  return done;
}

void SimLoop::resetSimulation() {
  {
    Lock lock(*this, Access::Change);
    endStepRequest("reset_simulation");
    world_.resetSimulation();
    reset_clock_ns_ = world_.timeNs();
    lockstep_.reset();
    between_stops_ = false;
    clock_ahead_ns_ = -1;
    lockstep_stop_.reset();
    for (auto& [model, plugins] : plugins_)
      for (auto& plugin : plugins) plugin->reset(world_);
  }
  wake_loop_.notify_all();
}

void SimLoop::resetWorld() {
  Lock lock(*this, Access::Change);
  world_.resetWorld();
  for (auto& [model, plugins] : plugins_)
    for (auto& plugin : plugins) plugin->reset(world_);
}

Status SimLoop::resetModel(const std::string& model) {
  Lock lock(*this, Access::Change);
  const Status reset = world_.resetModel(model);
  auto found = plugins_.find(model);
  if (reset.ok() && found != plugins_.end())
    for (auto& plugin : found->second) plugin->reset(world_);
  return reset;
}

PhysicsSettings SimLoop::physics() {
  Lock lock(*this, Access::Read);
  return {world_.params(), max_update_rate_};
}

Status SimLoop::setPhysics(const PhysicsSettings& settings) {
  Lock lock(*this, Access::Change);
  const Status set = world_.setParams(settings.params);
  if (set.ok()) max_update_rate_ = settings.max_update_rate;
  return set;
}

// --- model plugins ----------------------------------------------------------------------------

plugins::LockWorld SimLoop::lockWorld() {
  return [this] {
    Lock lock(*this, Access::Change);
    return std::move(lock.held());
  };
}

void SimLoop::attachPlugins(const std::string& model,
                            std::vector<std::unique_ptr<plugins::ModelPlugin>> plugins) {
  if (plugins.empty()) return;
  Lock lock(*this, Access::Change);
  ModelInfo unused;
  if (!world_.modelProperties(model, &unused).ok()) {
    lock.held().unlock();  // deleted meanwhile: its plugins go, unlocked
    return;
  }
  auto& attached = plugins_[model];
  for (auto& plugin : plugins) attached.push_back(std::move(plugin));
}

void SimLoop::detachPluginsOfRemovedModels(
    std::vector<std::unique_ptr<plugins::ModelPlugin>>* detached) {
  ModelInfo unused;
  for (auto it = plugins_.begin(); it != plugins_.end();) {
    if (world_.modelProperties(it->first, &unused).ok()) {
      ++it;
      continue;
    }
    for (auto& plugin : it->second) {
      plugin->stop(world_);
      detached->push_back(std::move(plugin));
    }
    it = plugins_.erase(it);
  }
}

Status SimLoop::deleteModel(const std::string& model) {
  Status deleted;
  std::vector<std::unique_ptr<plugins::ModelPlugin>> detached;
  {
    Lock lock(*this, Access::Change);
    deleted = world_.deleteModel(model);
    auto found = plugins_.find(model);
    if (deleted.ok() && found != plugins_.end()) {
      for (auto& plugin : found->second) plugin->stop(world_);
      detached = std::move(found->second);
      plugins_.erase(found);
    }
  }
  detached.clear();  // unlocked: see ModelPlugin's destructor
  return deleted;
}

}  // namespace onedof_sim
