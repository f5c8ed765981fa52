// What a process on this machine is doing, read from Linux's /proc: whether every thread of it is
// blocked, and how many times its threads have been put on a CPU. Lock-step reads it to publish a
// stop's clock only while a controller cannot be between the two clock readings of its Rate.
#pragma once

#include <cstdint>

namespace onedof_sim {

struct ProcessActivity {
  bool gone = false;    // no such process (or /proc unreadable)
  bool asleep = false;  // every thread blocked (state S) at two looks, none put on a CPU between
  uint64_t runs = 0;    // times its threads have been put on a CPU (schedstat), summed
};

// Two looks at /proc/PID/task/*/{stat,schedstat}; the second only when the first found every
// thread blocked.
ProcessActivity readProcessActivity(int pid);

// One look: the runs alone (0 if gone).
uint64_t processRuns(int pid);

// Whether a process with this pid exists.
bool processExists(int pid);

}  // namespace onedof_sim
