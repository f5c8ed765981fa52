// Lock-step between the simulator and the controllers that command it through apply_joint_effort.
//
// A controller in the book's shape samples the joint at its own period of sim time and commands
// a torque for that period (an effort job of one period's duration). Free-running, the world
// goes on whether or not the next command has come, so a busy machine changes the results. In
// lock-step the world stops where a lock-stepped joint's effort runs out and waits, up to a
// wall-clock timeout, for that joint's next apply_joint_effort: each controller acts on every one
// of its periods, whatever its rate (100 Hz and 10 ms jobs, 1 kHz and 1 ms jobs) and however many
// controllers there are (each joint is waited for on its own). The controllers need no change.
//
// Which joints are lock-stepped: every joint that receives an effort job of finite duration (a
// controller joins with its first command, so a world with no controller advances as ever). A
// joint the world gave up on after the timeout is left out until its next command.
//
// Each caller's process, when it runs on this machine, is kept with its threads' runs at its
// latest command: the owner publishes a stop's clock only once those processes rest (see
// SimLoop::awaitAsleep and the package README), and gives up on the joints of one that exits.
//
// Not thread-safe: the owner calls it under the lock it holds around the world.
#pragma once

#include <chrono>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <onedof_sim/world.h>

#include "process_activity.h"

namespace onedof_sim {

class Lockstep {
 public:
  using Clock = std::chrono::steady_clock;

  struct Options {
    bool enabled = false;
    Clock::duration timeout = std::chrono::seconds(5);
  };

  // A joint the world waits for, and who commanded it last.
  struct Awaited {
    std::string joint;
    std::string caller;
  };

  explicit Lockstep(const Options& options);

  bool enabled() const { return options_.enabled; }
  Clock::duration timeout() const { return options_.timeout; }

  // An accepted apply_joint_effort at sim time now_ns. Returns true when the joint joins the
  // lock-step with it (for the owner to say so once). A job that lasts until cleared never runs
  // out: it does not join. A command at time 0 does not make the world wait for the next one: ROS
  // clients have no valid time before the first nonzero /clock and sleep a whole period from the
  // first time they see, so their next command comes after that job's end.
  bool heard(const std::string& joint, const std::string& caller, bool until_cleared,
             int64_t now_ns, int64_t duration_ns);

  // The lock-stepped joints with no effort acting in the step that starts at t_ns.
  std::vector<Awaited> awaited(const World& world, int64_t t_ns) const;

  // Whether a lock-stepped joint's effort acts in the step that starts at t_ns: the world is
  // between two stops.
  bool running(const World& world, int64_t t_ns) const;

  // Where the clock may be shown ahead of the world stopped at t_ns, to wake controllers that
  // slept past the stop: the earliest end of the next period, when every lock-stepped joint is
  // awaited (each controller commanding its usual period now could not stop the world before it).
  // Empty when some controller has commanded and is asleep until later: it would wake early.
  std::optional<int64_t> wakeTime(const World& world, int64_t t_ns) const;

  // The world gave up waiting for these: they are left out until they command again.
  void giveUp(const std::vector<Awaited>& joints);

  // A controller's request (get_joint_properties or apply_joint_effort) at wall time `at`.
  void heardFrom(const std::string& caller, Clock::time_point at) { callers_[caller].last_request = at; }

  // The process of an accepted command's caller on this machine (empty: elsewhere or unknown),
  // and its threads' runs (ProcessThreads::runs) when the command came.
  void commandedFrom(const std::string& caller, std::optional<int> pid, ProcessRuns runs);

  // A lock-stepped controller's process on this machine, which a stop's clock waits for.
  struct Watched {
    std::string caller;
    int pid = 0;
    ProcessRuns runs_at_command;
  };
  // The processes of the lock-stepped joints' callers on this machine, each once.
  std::vector<Watched> watched(const World& world) const;
  // Whether some lock-stepped joint's caller runs elsewhere (or its process is unknown).
  bool someUnwatched(const World& world) const;
  // The process of a caller on this machine, if known.
  std::optional<int> pidOf(const std::string& caller) const;

  // The latest request of the callers of these joints (the epoch if none).
  Clock::time_point lastRequest(const std::vector<Awaited>& joints) const;

  // reset_simulation: every joint leaves; controllers join again with their next command.
  void reset() { joints_.clear(); }

 private:
  struct Joint {
    std::string caller;
    bool waited_for = true;  // false after a timeout or a command at time 0, until the next one
    int64_t period_ns = 0;   // the duration of its latest job
  };

  Options options_;
  struct Caller {
    Clock::time_point last_request;
    std::optional<int> pid;
    ProcessRuns runs_at_command;
  };

  // The lock-stepped joints of models in the world, each with its caller.
  template <class F>
  void forEachWaitedFor(const World& world, F&& f) const;

  std::map<std::string, Joint> joints_;
  std::map<std::string, Caller> callers_;
};

}  // namespace onedof_sim
