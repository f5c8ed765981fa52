// What a process on this machine is doing, read from Linux's /proc: whether every thread of it is
// blocked, and how many times its threads have been put on a CPU. Lock-step reads it to publish a
// stop's clock only while a controller cannot be between the two clock readings of its Rate.
#pragma once

#include <dirent.h>

#include <chrono>
#include <cstdint>
#include <vector>

namespace onedof_sim {

struct ProcessActivity {
  bool gone = false;    // no such process (or /proc unreadable)
  bool asleep = false;  // every thread blocked (state S) at two looks, none put on a CPU between
  uint64_t runs = 0;    // when asleep: times its threads have been put on a CPU (schedstat), summed

  // Lock-step's rule for publishing a stop's clock: the process has run since `runs_at_command`
  // (its call returned) and rests now, or it is gone.
  bool restedSince(uint64_t runs_at_command) const {
    return gone || (asleep && runs > runs_at_command);
  }
};

// How often a wait for a process to rest looks again.
constexpr std::chrono::microseconds kRestLookInterval(20);

// One process's threads as /proc shows them. Its task folder and each thread's stat and schedstat
// stay open between looks, and a look reads them again (procfs writes a file's text anew at each
// read): a look lists the threads and reads two files of each, instead of finding every file by
// its path again. Lock-step looks several times per controller period. Not thread-safe: one per
// thread that looks.
class ProcessThreads {
 public:
  explicit ProcessThreads(int pid) : pid_(pid) {}
  ~ProcessThreads() { forget(); }
  ProcessThreads(const ProcessThreads&) = delete;
  ProcessThreads& operator=(const ProcessThreads&) = delete;

  int pid() const { return pid_; }

  // Two looks at every thread's state and runs; the second only when the first found every thread
  // blocked (the first ends at a thread that is not).
  ProcessActivity activity();

  // One look: the runs alone (0 if gone).
  uint64_t runs();

 private:
  struct ThreadFiles {
    long tid = 0;
    int stat_fd = -1;
    int schedstat_fd = -1;
    bool kept = false;  // open between looks (within the budget of kept files)
  };
  struct ThreadSample {
    long tid = 0;
    char state = '?';
    uint64_t runs = 0;
  };
  enum class LookFor { kRest, kRuns };
  // One look with the files open (fresh ones when those open fail: a thread or the process went
  // away meanwhile). False if the process is gone or a thread went away between the listing and
  // the reading. For kRest, the look ends at the first thread not blocked (*all_blocked false).
  bool look(LookFor what, std::vector<ThreadSample>* threads, bool* all_blocked);
  bool lookWithOpenFiles(LookFor what, std::vector<ThreadSample>* threads, bool* all_blocked);
  // The files of thread tid, opened if they are not yet.
  const ThreadFiles* filesOf(long tid, std::vector<ThreadFiles>* listed);
  // Closes a thread's files.
  static void release(ThreadFiles* files);
  // Closes every file.
  void forget();

  int pid_;
  DIR* task_dir_ = nullptr;
  std::vector<ThreadFiles> threads_;  // in the listing's order
};

// Whether a process with this pid exists.
bool processExists(int pid);

}  // namespace onedof_sim
