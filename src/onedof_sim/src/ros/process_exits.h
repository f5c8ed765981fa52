// Tells the moment a process on this machine exits. Each watched process has a pidfd (Linux 5.3),
// which becomes readable when the process exits, when /proc shows it exited (a zombie its parent
// has not reaped yet, or gone); a thread of its own waits on them all at once and calls back.
// Lock-step lets go of a controller's joints the moment its process exits, instead of waiting
// ~lockstep_timeout for a command that cannot come.
#pragma once

#include <functional>
#include <map>
#include <mutex>
#include <set>
#include <thread>

namespace onedof_sim {

class ProcessExits {
 public:
  // on_exit runs on the watch's thread when watched processes have exited (once for those it
  // finds together), with no lock of the watch held.
  explicit ProcessExits(std::function<void()> on_exit);
  // Stops the thread.
  ~ProcessExits();

  ProcessExits(const ProcessExits&) = delete;
  ProcessExits& operator=(const ProcessExits&) = delete;

  enum class Watch { kWatched, kExited, kCannot };
  // Watches the process pid from now on (nothing more if it is watched already). kExited: it had
  // exited already; kCannot: this kernel gives no pidfd (the errno of pidfd_open is in *error).
  // A pid known exited is watched again when a process with that pid lives (the pid taken again).
  Watch watch(int pid, int* error = nullptr);

  // Whether the process pid, watched, has exited.
  bool exited(int pid) const;

 private:
  void run();
  void wakeThread();

  std::function<void()> on_exit_;
  mutable std::mutex mutex_;
  std::map<int, int> pidfds_;  // of the processes watched and not exited, by pid
  std::set<int> exited_;
  bool stopping_ = false;
  int wake_fd_ = -1;  // an eventfd: the set of pidfds changed, or the watch stops
  std::thread thread_;
};

}  // namespace onedof_sim
