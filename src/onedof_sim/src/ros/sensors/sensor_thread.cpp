#include "sensor_thread.h"

#include <algorithm>
#include <cerrno>
#include <condition_variable>
#include <cstring>
#include <exception>
#include <mutex>
#include <thread>
#include <utility>

#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <ros/ros.h>

namespace onedof_sim::plugins {
namespace {

// How much higher the sensor thread's nice value is than the process's (at most 19, the
// highest). The scheduler gives a thread a share of a contended core by its weight: 10 steps of
// nice are a ninth of the weight, so a render still runs at a ninth of its ordinary share on a
// machine where every core is contended, and the request threads are picked before it whenever
// both are runnable.
constexpr int kSensorNiceIncrement = 10;
constexpr int kHighestNice = 19;

// The calling thread's nice value raised by kSensorNiceIncrement. Linux keeps a nice value per
// thread, and setpriority with a thread's id sets that thread's alone; raising it needs no
// privilege. Said once when refused: the work then runs at the process's priority.
void lowerThisThreadsPriority() {
  const pid_t tid = static_cast<pid_t>(syscall(SYS_gettid));
  errno = 0;
  const int nice = getpriority(PRIO_PROCESS, tid);
  if (errno != 0) return;
  if (setpriority(PRIO_PROCESS, tid, std::min(kHighestNice, nice + kSensorNiceIncrement)) != 0) {
    ROS_WARN_STREAM("sensors: their thread keeps the process's CPU priority (setpriority: "
                    << std::strerror(errno) << ")");
  }
}

class SensorThread {
 public:
  SensorThread() : thread_([this] { serve(); }) {}

  void run(const std::function<void()>& work) {
    if (std::this_thread::get_id() == thread_.get_id()) {
      work();
      return;
    }
    std::lock_guard<std::mutex> one_caller_at_a_time(callers_);
    std::unique_lock<std::mutex> lock(mutex_);
    work_ = &work;
    wake_.notify_one();
    done_.wait(lock, [this] { return work_ == nullptr; });
    if (error_) std::rethrow_exception(std::exchange(error_, nullptr));
  }

 private:
  void serve() {
    lowerThisThreadsPriority();
    std::unique_lock<std::mutex> lock(mutex_);
    for (;;) {
      wake_.wait(lock, [this] { return work_ != nullptr; });
      lock.unlock();
      std::exception_ptr error;
      try {
        (*work_)();
      } catch (...) {
        error = std::current_exception();
      }
      lock.lock();
      error_ = error;
      work_ = nullptr;
      done_.notify_all();
    }
  }

  std::mutex callers_;
  std::mutex mutex_;  // guards work_ and error_
  std::condition_variable wake_, done_;
  const std::function<void()>* work_ = nullptr;  // the caller's, while it waits
  std::exception_ptr error_;
  std::thread thread_;  // last: started once the rest is made
};

}  // namespace

void onSensorThread(const std::function<void()>& work) {
  // Kept for the process's life, as the renderer made on it is: never stopped nor joined, so no
  // exit waits for it.
  static SensorThread* thread = new SensorThread;
  thread->run(work);
}

}  // namespace onedof_sim::plugins
