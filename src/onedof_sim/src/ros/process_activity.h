// What a process on this machine is doing, read from Linux's /proc: whether every thread of it is
// blocked, and how many times each of its threads has been put on a CPU. Lock-step reads it to
// publish a stop's clock only while a controller cannot be between the two clock readings of its
// Rate.
#pragma once

#include <dirent.h>

#include <chrono>
#include <cstdint>
#include <vector>

namespace onedof_sim {

// A thread and the times it has been put on a CPU (the third field of its schedstat).
struct ThreadRuns {
  long tid = 0;
  uint64_t runs = 0;
};
// A process's threads' runs, by thread id (ascending).
using ProcessRuns = std::vector<ThreadRuns>;

struct ProcessActivity {
  // No such process, or every thread of it has exited (a process killed is a zombie in /proc until
  // its parent reaps it: it will never run again), or /proc unreadable.
  bool gone = false;
  bool asleep = false;  // every thread blocked (state S) at two looks, none put on a CPU between
  ProcessRuns threads;  // when asleep: each thread's runs

  // Whether a thread that was there at `at_command` has been put on a CPU since. Threads that
  // came or went meanwhile are left out: a node's threads come and go with its peers (rospy has
  // one for each connection of a topic, and one for each XML-RPC request the master or a peer
  // sends), and a thread's runs go with it when it exits. The thread that made the call was there
  // when the command came, and is still there. With no thread known at the command (its process
  // unreadable then), true.
  bool ranSince(const ProcessRuns& at_command) const;

  // Lock-step's rule for publishing a stop's clock: the process has run since `at_command` (its
  // call returned) and rests now, or it is gone.
  bool restedSince(const ProcessRuns& at_command) const {
    return gone || (asleep && ranSince(at_command));
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

  // One look: each thread's runs alone (none if gone).
  ProcessRuns runs();

 private:
  struct ThreadFiles {
    long tid = 0;
    int stat_fd = -1;
    int schedstat_fd = -1;
    bool kept = false;  // open between looks (within the budget of kept files)
  };
  enum class LookFor { kRest, kRuns };
  // One look with the files open (fresh ones when those open fail: a thread or the process went
  // away meanwhile). False if the process is gone or a thread went away between the listing and
  // the reading. For kRest, threads that have exited (a zombie) are left out, and the look ends at
  // the first thread not blocked (*all_blocked false); false also when no thread is left.
  bool look(LookFor what, std::vector<ThreadRuns>* threads, bool* all_blocked);
  bool lookWithOpenFiles(LookFor what, std::vector<ThreadRuns>* threads, bool* all_blocked);
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

// Whether a process with this pid has a thread that has not exited: not gone, nor a zombie.
bool processLives(int pid);

}  // namespace onedof_sim
