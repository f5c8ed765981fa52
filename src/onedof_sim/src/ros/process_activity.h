// What a process on this machine is doing, read from Linux's /proc: whether every thread of it is
// blocked, and how many times each of its threads has been put on a CPU. Lock-step reads it to
// publish a stop's clock only while a controller cannot be between the two clock readings of its
// Rate.
#pragma once

#include <dirent.h>

#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <vector>

namespace onedof_sim {

// A thread and the times it has been put on a CPU (the third field of its schedstat).
struct ThreadRuns {
  long tid = 0;
  uint64_t runs = 0;
  bool blocked = false;  // blocked in the kernel waiting for an event (state S) at the look
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

  // Whether a thread that is not blocked may be left out of a rest (ThreadsAtWork::dormant).
  using LeftOut = std::function<bool(const ThreadRuns& now)>;

  // Two looks at every thread's state and runs; the second only when the first found every thread
  // blocked or left out (the first ends at a thread that is neither). A thread left out is among
  // `threads` with its runs.
  ProcessActivity activity(const LeftOut& left_out = nullptr);

  // One look: each thread's runs and whether it is blocked (none if gone).
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
  bool look(LookFor what, const LeftOut& left_out, std::vector<ThreadRuns>* threads,
            bool* all_blocked);
  bool lookWithOpenFiles(LookFor what, const LeftOut& left_out, std::vector<ThreadRuns>* threads,
                         bool* all_blocked);
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

// The threads of a controller's process that do its work in each period, learned from the rests
// that followed its commands. A rospy node also has threads that wake on their own timers: the
// thread of a subscription whose publisher has gone retries it with growing sleeps for as long as
// the master names it, the XML-RPC server's thread serves the master's updates. One of those woken
// at a stop and waiting for a CPU would hold the stop's clock until the machine gives it one,
// though the controller's work is done. Such a thread is left out of the rest when it is dormant.
class ThreadsAtWork {
 public:
  // Periods in a row a thread has not run between its process's command and rest before it counts
  // as not at work.
  static constexpr int kIdlePeriods = 3;

  // Whether a thread that is not blocked may be left out of a rest: it was blocked when the command
  // came and has not been put on a CPU since (so it holds nothing the controller's work can wait
  // for that it took since, such as Python's GIL or a lock, and it has no part in that work), and
  // it has not run between command and rest in the last kIdlePeriods periods. A thread unknown at
  // the command, or to the periods before, is at work.
  bool dormant(const ProcessRuns& at_command, const ThreadRuns& now) const;

  // A rest that followed a command: which threads ran between them.
  void noteRest(const ProcessRuns& at_command, const ProcessRuns& at_rest);

 private:
  std::map<long, int> idle_periods_;  // by thread id
};

// Whether a process with this pid has a thread that has not exited: not gone, nor a zombie.
bool processLives(int pid);

}  // namespace onedof_sim
