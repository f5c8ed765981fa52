// The sensor thread (src/ros/sensors/sensor_thread.h), no roscore: work runs there, on one other
// thread whose nice value is higher than the caller's, the caller waiting for it; what it throws
// reaches the caller, and work it asks for itself runs at once.
#include <gtest/gtest.h>

#include <algorithm>
#include <stdexcept>
#include <thread>

#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include "sensors/sensor_thread.h"

namespace onedof_sim::plugins {
namespace {

int niceOfThisThread() {
  return getpriority(PRIO_PROCESS, static_cast<id_t>(syscall(SYS_gettid)));
}

TEST(SensorThread, RunsWorkOnOneThreadOfLowerPriorityWhileTheCallerWaits) {
  const int callers_nice = niceOfThisThread();
  std::thread::id first, second;
  int nice = callers_nice;
  bool done = false;
  onSensorThread([&] {
    first = std::this_thread::get_id();
    nice = niceOfThisThread();
    done = true;
  });
  EXPECT_TRUE(done);  // returned once the work was done
  onSensorThread([&] { second = std::this_thread::get_id(); });
  EXPECT_NE(first, std::this_thread::get_id());
  EXPECT_EQ(first, second);
  // Higher, up to the highest (a caller already at 19 stays there).
  EXPECT_EQ(nice, std::min(19, callers_nice + 10));
  EXPECT_EQ(niceOfThisThread(), callers_nice);  // the caller's own is untouched
}

TEST(SensorThread, AnExceptionReachesTheCallerAndTheThreadGoesOn) {
  EXPECT_THROW(onSensorThread([] { throw std::runtime_error("no frame"); }), std::runtime_error);
  bool ran = false;
  onSensorThread([&] { ran = true; });
  EXPECT_TRUE(ran);
}

TEST(SensorThread, WorkAskedForOnTheThreadRunsAtOnce) {
  std::thread::id outer, inner;
  onSensorThread([&] {
    outer = std::this_thread::get_id();
    onSensorThread([&] { inner = std::this_thread::get_id(); });
  });
  EXPECT_EQ(outer, inner);
}

}  // namespace
}  // namespace onedof_sim::plugins
