// bench_lockstep_floor: the floor of a lock-stepped period, for the benchmark to set the simulator
// against. It stands where the simulator stands for a controller in the book's shape and does only
// what lock-step needs of a partner: it serves get_joint_properties and apply_joint_effort with
// fixed replies (fixed_replies.h), and after each command, once the reply is written and the
// controller's process rests, publishes /clock at the end of the command's job. Waiting for the
// rest is part of the floor: a clock published sooner can land between the two clock readings of
// the controller's Rate, which then sleeps a period past the stop (see SimLoop::awaitAsleep). No
// world and no physics: a period against it costs the controller's /clock wake-up, its two calls
// and the least a partner must do between them.
//
//   rosrun onedof_sim bench_lockstep_floor __name:=gazebo _controller:=/book_controller
//       _start:=0.01 _periods:=1000 _warm_up:=20   (one command line)
//
// It logs "floor: N periods in S s of wall time, T s of sim time, W wake-ups" once `periods`
// commands have come after the first `warm_up`, and goes on serving until it is stopped. Its
// threads are the simulator's: one serves apply_joint_effort and says when a reply is written,
// the main thread (the simulator's loop) waits for the rest and publishes.
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <utility>

#include <ros/callback_queue.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Clock.h>

#include "fixed_replies.h"
#include "node_process.h"
#include "process_activity.h"

namespace {

using onedof_sim::ProcessActivity;
using onedof_sim::ProcessRuns;
using onedof_sim::ProcessThreads;

constexpr auto kRestLimit = std::chrono::seconds(5);
constexpr auto kWakeAfter = std::chrono::milliseconds(500);

// The floor's state. The command's callback runs on the thread serving apply_joint_effort; the
// rest of it on the main thread (as the simulator's loop): one mutex between them, and a view of
// the controller's process for each.
class Floor {
 public:
  Floor(int64_t start_ns, int periods, int warm_up)
      : time_ns_(start_ns), periods_(periods), warm_up_(warm_up) {}

  // The command's callback: notes the job's end and the caller's runs before the reply.
  bool applyJointEffort(ros::ServiceEvent<gazebo_msgs::ApplyJointEffort::Request,
                                          gazebo_msgs::ApplyJointEffort::Response>& event) {
    const std::string caller = event.getCallerName();
    if (caller != command_caller_) {
      command_caller_ = caller;
      const std::optional<int> pid = onedof_sim::localNodePid(caller);
      command_view_.reset();
      if (pid) command_view_ = std::make_unique<ProcessThreads>(*pid);
    }
    ProcessRuns runs;
    if (command_view_) runs = command_view_->runs();
    const int64_t duration_ns = event.getRequest().duration.toNSec();
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (duration_ns > 0) {
        // Under a clock shown ahead, the command is for the period that ends at the time shown.
        next_clock_ns_ = shown_ahead_ ? time_ns_ : time_ns_ + duration_ns;
        shown_ahead_ = false;
        period_ns_ = duration_ns;
      }
      pid_ = command_view_ ? std::optional<int>(command_view_->pid()) : std::nullopt;
      runs_at_command_ = std::move(runs);
    }
    onedof_sim::bench::fixedEffortReply(&event.getResponse());
    return true;
  }

  // After a reply is written: the next period's clock once the controller rests.
  void replied(const ros::Publisher& clock_pub) {
    std::optional<int> pid;
    ProcessRuns runs_at_command;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      pid = pid_;
      runs_at_command = runs_at_command_;
    }
    if (pid && (!loop_view_ || loop_view_->pid() != *pid))
      loop_view_ = std::make_unique<ProcessThreads>(*pid);
    const auto limit = std::chrono::steady_clock::now() + kRestLimit;
    while (pid && std::chrono::steady_clock::now() < limit && ros::ok()) {
      const ProcessActivity activity = loop_view_->activity();
      if (activity.restedSince(runs_at_command)) break;
      std::this_thread::sleep_for(onedof_sim::kRestLookInterval);
    }
    publish(clock_pub, false);
    count();
  }

  // A controller that commanded before it heard any time sleeps a period from the first time it
  // hears (roscpp's Duration::sleep), past the clock it waits at: as the simulator does, the clock
  // is shown a period later when it has sent nothing for kWakeAfter. Said in the log: a wake-up in
  // the counted window is part of its figure.
  void wakeIfSilent(const ros::Publisher& clock_pub) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (period_ns_ <= 0 || std::chrono::steady_clock::now() - last_clock_at_ < kWakeAfter)
        return;
      ROS_INFO("floor: nothing for %.1f s at %.3f s of sim time: the clock shown a period later",
               std::chrono::duration<double>(kWakeAfter).count(), double(time_ns_) * 1e-9);
      next_clock_ns_ = time_ns_ + period_ns_;
      if (commands_ >= warm_up_ && commands_ < warm_up_ + periods_) ++wake_ups_;
    }
    publish(clock_pub, true);
  }

  int64_t timeNs() {
    std::lock_guard<std::mutex> lock(mutex_);
    return time_ns_;
  }

 private:
  void publish(const ros::Publisher& clock_pub, bool ahead) {
    rosgraph_msgs::Clock clock;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      last_clock_at_ = std::chrono::steady_clock::now();
      if (next_clock_ns_ <= time_ns_) return;
      time_ns_ = next_clock_ns_;
      shown_ahead_ = ahead;
      clock.clock.fromNSec(uint64_t(time_ns_));
    }
    clock_pub.publish(clock);
  }

  void count() {
    std::lock_guard<std::mutex> lock(mutex_);
    ++commands_;
    if (commands_ == warm_up_) {
      window_start_ = std::chrono::steady_clock::now();
      window_start_ns_ = time_ns_;
    } else if (commands_ == warm_up_ + periods_) {
      const double wall =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - window_start_).count();
      ROS_INFO("floor: %d periods in %.6f s of wall time, %.6f s of sim time, %d wake-ups",
               periods_, wall, double(time_ns_ - window_start_ns_) * 1e-9, wake_ups_);
    }
  }

  std::mutex mutex_;  // guards the members below but the views
  int64_t time_ns_;
  int64_t next_clock_ns_ = 0;
  int64_t period_ns_ = 0;     // the latest job's duration
  bool shown_ahead_ = false;  // the clock was shown a period ahead (wakeIfSilent)
  std::chrono::steady_clock::time_point last_clock_at_;
  std::optional<int> pid_;  // the commanding controller's process, if on this machine
  ProcessRuns runs_at_command_;
  int periods_;
  int warm_up_;
  int commands_ = 0;
  int wake_ups_ = 0;  // in the counted window
  std::chrono::steady_clock::time_point window_start_;
  int64_t window_start_ns_ = 0;
  // The controller's process as the command's callback reads it, and as the main thread does.
  std::string command_caller_;
  std::unique_ptr<ProcessThreads> command_view_;
  std::unique_ptr<ProcessThreads> loop_view_;
};

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "lockstep_floor");
  ros::NodeHandle nh;
  ros::NodeHandle private_nh("~");
  const double start = private_nh.param("start", 0.01);
  const int periods = private_nh.param("periods", 1000);
  const int warm_up = private_nh.param("warm_up", 20);
  if (!(start > 0) || periods < 1 || warm_up < 1) {
    ROS_FATAL("~start must be > 0 s, ~periods and ~warm_up >= 1");
    return 2;
  }
  const std::string controller = private_nh.param<std::string>("controller", "");
  Floor floor(int64_t(start * 1e9), periods, warm_up);
  // Latched, as the simulator's: a controller starting hears the time at once. The services come
  // only once the controller (~controller, when given) is connected to it: it then builds its
  // Rate on the time it heard, and wakes on /clock every period. A roscpp client that builds its
  // Rate before it hears any time runs a period behind the clock and never sleeps, which is not
  // the wake-up this floor is for.
  std::atomic<bool> controller_connected{controller.empty()};
  const ros::Publisher clock_pub = nh.advertise<rosgraph_msgs::Clock>(
      "/clock", 1000,
      [&](const ros::SingleSubscriberPublisher& subscriber) {
        if (subscriber.getSubscriberName() == controller) controller_connected = true;
      },
      ros::SubscriberStatusCallback(), ros::VoidConstPtr(), true);
  rosgraph_msgs::Clock first;
  first.clock.fromNSec(uint64_t(floor.timeNs()));
  clock_pub.publish(first);
  ros::AsyncSpinner spinner(1);
  spinner.start();
  while (!controller_connected && ros::ok()) ros::WallDuration(0.001).sleep();

  // apply_joint_effort on a queue of its own: callOne returns once the reply is written.
  ros::CallbackQueue effort_queue;
  ros::NodeHandle effort_nh("~");
  effort_nh.setCallbackQueue(&effort_queue);
  const ros::ServiceServer apply = effort_nh.advertiseService(
      "apply_joint_effort", &Floor::applyJointEffort, &floor);
  const ros::ServiceServer get = private_nh.advertiseService(
      "get_joint_properties", onedof_sim::bench::fixedJointProperties);
  // As the simulator: the thread that serves apply_joint_effort says when a reply is written, and
  // another (the simulator's loop) waits for the controller to rest and publishes the clock.
  std::mutex mutex;
  std::condition_variable replied;
  uint64_t replies = 0;
  std::thread effort_thread([&] {
    while (ros::ok()) {
      if (effort_queue.callOne(ros::WallDuration(0.1)) != ros::CallbackQueue::Called) continue;
      {
        std::lock_guard<std::mutex> lock(mutex);
        ++replies;
      }
      replied.notify_one();
    }
  });
  uint64_t handled = 0;
  while (ros::ok()) {
    std::unique_lock<std::mutex> lock(mutex);
    if (!replied.wait_for(lock, std::chrono::milliseconds(100), [&] { return replies > handled; })) {
      lock.unlock();
      floor.wakeIfSilent(clock_pub);
      continue;
    }
    handled = replies;
    lock.unlock();
    floor.replied(clock_pub);
  }
  effort_thread.join();
  return 0;
}
