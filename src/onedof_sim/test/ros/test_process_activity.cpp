// ProcessThreads: a child process blocked reads asleep, one spinning does not, one gone (or a
// zombie) reads gone; a thread that exits takes nothing from the runs of those that stay; its
// files kept open stay within their budget however many views look; a thread left out does not
// hold the rest. ThreadsAtWork: which threads may be left out. ProcessExits: a child's exit is
// told at once.
#include <dirent.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <memory>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "../../src/ros/process_activity.h"
#include "../../src/ros/process_exits.h"

namespace onedof_sim {
namespace {

// A child that blocks reading a pipe nobody writes (or spins, if asked) until killed.
class Child {
 public:
  explicit Child(bool spin) {
    int fds[2];
    EXPECT_EQ(::pipe(fds), 0);
    pid_ = ::fork();
    if (pid_ == 0) {
      char byte;
      if (spin)
        for (volatile unsigned long i = 0;; ++i) {
        }
      while (::read(fds[0], &byte, 1) != 0) {
      }
      ::_exit(0);
    }
    ::close(fds[0]);
    write_end_ = fds[1];
  }
  ~Child() {
    end();
    ::close(write_end_);
  }
  int pid() const { return pid_; }
  // Killed; reaped too unless asked not to (it stays a zombie until end()).
  void end(bool reap = true) {
    if (pid_ <= 0) return;
    ::kill(pid_, SIGKILL);
    if (!reap) return;
    ::waitpid(pid_, nullptr, 0);
    pid_ = -1;
  }

 private:
  int pid_ = -1;
  int write_end_ = -1;
};

// Whether the view reads the child asleep within a few seconds of looking again.
bool readsAsleep(ProcessThreads& view) {
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (std::chrono::steady_clock::now() < give_up) {
    if (view.activity().asleep) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return false;
}

uint64_t runsOf(const ProcessRuns& threads) {
  uint64_t sum = 0;
  for (const ThreadRuns& thread : threads) sum += thread.runs;
  return sum;
}

int openFiles() {
  int count = 0;
  DIR* dir = ::opendir("/proc/self/fd");
  while (const dirent* entry = ::readdir(dir)) count += entry->d_name[0] != '.';
  ::closedir(dir);
  return count;
}

TEST(ProcessThreads, AChildBlockedReadsAsleepWithItsRuns) {
  Child child(false);
  ProcessThreads view(child.pid());
  ASSERT_TRUE(readsAsleep(view));
  const ProcessActivity again = view.activity();  // from the files kept open
  EXPECT_TRUE(again.asleep);
  EXPECT_FALSE(again.gone);
  ASSERT_EQ(again.threads.size(), 1u);
  EXPECT_EQ(again.threads[0].tid, child.pid());
  EXPECT_GT(again.threads[0].runs, 0u);
  const ProcessRuns runs = view.runs();  // asleep: not put on a CPU since
  ASSERT_EQ(runs.size(), 1u);
  EXPECT_EQ(runs[0].runs, again.threads[0].runs);
  EXPECT_FALSE(again.ranSince(runs));
  EXPECT_FALSE(again.restedSince(runs));
}

TEST(ProcessThreads, AChildSpinningNeverReadsAsleep) {
  Child child(true);
  ProcessThreads view(child.pid());
  for (int i = 0; i < 200; ++i) {
    EXPECT_FALSE(view.activity().asleep);
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
}

// A child whose main thread blocks on a pipe while a second thread spins.
class ChildWithSpinner {
 public:
  ChildWithSpinner() {
    int fds[2];
    EXPECT_EQ(::pipe(fds), 0);
    pid_ = ::fork();
    if (pid_ == 0) {
      std::thread([] {
        for (volatile unsigned long i = 0;; ++i) {
        }
      }).detach();
      char byte;
      while (::read(fds[0], &byte, 1) != 0) {
      }
      ::_exit(0);
    }
    ::close(fds[0]);
    ::close(fds[1]);  // the child's read sees no end: its own copy of the write end stays open
  }
  ~ChildWithSpinner() {
    ::kill(pid_, SIGKILL);
    ::waitpid(pid_, nullptr, 0);
  }
  int pid() const { return pid_; }

 private:
  int pid_ = -1;
};

TEST(ProcessThreads, AThreadLeftOutDoesNotHoldTheRest) {
  ChildWithSpinner child;
  ProcessThreads view(child.pid());
  for (int i = 0; i < 100; ++i) EXPECT_FALSE(view.activity().asleep);
  // The spinner left out: its process rests when its main thread does (at two looks between which
  // the spinner was not put on a CPU again), and the spinner is among the threads with its runs.
  const auto leave_out_spinner = [&](const ThreadRuns& thread) {
    return thread.tid != child.pid();
  };
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  ProcessActivity rest;
  while (!rest.asleep && std::chrono::steady_clock::now() < give_up)
    rest = view.activity(leave_out_spinner);
  ASSERT_TRUE(rest.asleep);
  ASSERT_EQ(rest.threads.size(), 2u);
  EXPECT_EQ(rest.threads[0].tid, child.pid());
  EXPECT_NE(rest.threads[1].tid, child.pid());
  // Leaving out the main thread instead does not make the spinner rest.
  for (int i = 0; i < 100; ++i)
    EXPECT_FALSE(view.activity([&](const ThreadRuns& thread) {
                       return thread.tid == child.pid();
                     }).asleep);
}

TEST(ProcessThreads, RunsTellWhichThreadsAreBlocked) {
  ChildWithSpinner child;
  ProcessThreads view(child.pid());
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  ProcessRuns runs;
  while ((runs.size() != 2 || !runs[0].blocked) && std::chrono::steady_clock::now() < give_up)
    runs = view.runs();
  ASSERT_EQ(runs.size(), 2u);
  EXPECT_TRUE(runs[0].blocked);   // the main thread, on its pipe
  EXPECT_FALSE(runs[1].blocked);  // the spinner, running or waiting for a CPU
}

// Threads 1 (the controller's loop: runs in every period) and 2 (a timer's thread: blocked, runs
// now and then).
ProcessRuns threadRuns(uint64_t loop, bool loop_blocked, uint64_t timer, bool timer_blocked) {
  return {{1, loop, loop_blocked}, {2, timer, timer_blocked}};
}

TEST(ThreadsAtWork, AThreadIsDormantOnlyAfterIdlePeriodsAndIfNotRunSinceTheCommand) {
  ThreadsAtWork work;
  const ThreadRuns timer_woken{2, 10, false};
  // Unknown to any period: at work.
  EXPECT_FALSE(work.dormant(threadRuns(100, true, 10, true), timer_woken));
  uint64_t loop = 100;
  for (int period = 0; period < ThreadsAtWork::kIdlePeriods; ++period) {
    const ProcessRuns at_command = threadRuns(loop, true, 10, true);
    EXPECT_FALSE(work.dormant(at_command, timer_woken)) << period;
    loop += 3;
    work.noteRest(at_command, threadRuns(loop, true, 10, true));
  }
  const ProcessRuns at_command = threadRuns(loop, true, 10, true);
  EXPECT_TRUE(work.dormant(at_command, timer_woken));
  // Not once it has been put on a CPU since the command, nor if it was not blocked at it.
  EXPECT_FALSE(work.dormant(at_command, ThreadRuns{2, 11, false}));
  EXPECT_FALSE(work.dormant(threadRuns(loop, true, 10, false), timer_woken));
  // The loop's thread, which runs in every period, never.
  EXPECT_FALSE(work.dormant(at_command, ThreadRuns{1, loop, false}));
  // A thread that ran between a command and its rest is at work again.
  work.noteRest(at_command, threadRuns(loop + 3, true, 12, true));
  EXPECT_FALSE(work.dormant(threadRuns(loop + 3, true, 12, true), ThreadRuns{2, 12, false}));
  // A thread new since the command counts as having run: at work.
  work.noteRest(threadRuns(loop + 3, true, 12, true),
                {{1, loop + 6, true}, {2, 12, true}, {3, 1, true}});
  EXPECT_FALSE(work.dormant({{1, loop + 6, true}, {2, 12, true}, {3, 1, true}},
                            ThreadRuns{3, 1, false}));
}

TEST(ProcessThreads, AChildGoneReadsGoneWithNoRuns) {
  Child child(false);
  const int pid = child.pid();
  ProcessThreads view(pid);
  ASSERT_TRUE(readsAsleep(view));
  child.end();
  const ProcessActivity gone = view.activity();
  EXPECT_TRUE(gone.gone);
  EXPECT_FALSE(gone.asleep);
  EXPECT_TRUE(view.runs().empty());
  EXPECT_FALSE(processLives(pid));
}

TEST(ProcessThreads, AChildKilledReadsGoneBeforeItIsReaped) {
  Child child(false);
  const int pid = child.pid();
  ProcessThreads view(pid);
  ASSERT_TRUE(readsAsleep(view));
  EXPECT_TRUE(processLives(pid));
  child.end(/*reap=*/false);
  // A zombie: /proc still lists it, with its one thread exited.
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (processLives(pid) && std::chrono::steady_clock::now() < give_up)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  EXPECT_FALSE(processLives(pid));
  EXPECT_EQ(::access(("/proc/" + std::to_string(pid)).c_str(), F_OK), 0);
  const ProcessActivity zombie = view.activity();
  EXPECT_TRUE(zombie.gone);
  EXPECT_TRUE(zombie.restedSince({}));
}

// A child whose main thread blocks on one pipe and a second thread, after many runs, on another;
// a byte on the second ends that thread, a byte on the first wakes the main thread once. Each of
// the helper's sleeps is long enough that its timer cannot expire before the thread blocks (a
// 1 us timer can, and then the sleep returns without a run), so its 300 sleeps give it well over
// kHelperRuns runs on any machine.
class TwoThreadChild {
 public:
  static constexpr uint64_t kHelperRuns = 100;

  TwoThreadChild() {
    EXPECT_EQ(::pipe(wake_main_), 0);
    EXPECT_EQ(::pipe(end_helper_), 0);
    pid_ = ::fork();
    if (pid_ == 0) {
      std::thread helper([this] {
        for (int i = 0; i < 300; ++i) std::this_thread::sleep_for(std::chrono::microseconds(200));
        char byte;
        while (::read(end_helper_[0], &byte, 1) < 0) {
        }
      });
      char byte;
      while (::read(wake_main_[0], &byte, 1) != 0) {
        if (byte == 'j') helper.join();
      }
      ::_exit(0);
    }
  }
  ~TwoThreadChild() {
    ::kill(pid_, SIGKILL);
    ::waitpid(pid_, nullptr, 0);
  }
  int pid() const { return pid_; }
  void endHelper() { EXPECT_EQ(::write(end_helper_[1], "x", 1), 1); }
  void wakeMain(char byte) { EXPECT_EQ(::write(wake_main_[1], &byte, 1), 1); }

 private:
  int pid_ = -1;
  int wake_main_[2];
  int end_helper_[2];
};

TEST(ProcessThreads, AThreadThatExitsTakesNothingFromTheRunsOfThoseThatStay) {
  TwoThreadChild child;
  ProcessThreads view(child.pid());
  // Both threads blocked, the helper after its many runs (each a sleep, which on a busy machine
  // can wait long for a CPU: the deadline bounds only a failure).
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  ProcessRuns at_command;
  while (std::chrono::steady_clock::now() < give_up) {
    const ProcessActivity activity = view.activity();
    if (activity.asleep && activity.threads.size() == 2) {
      const ThreadRuns& helper = activity.threads[activity.threads[0].tid == child.pid()];
      if (helper.runs >= TwoThreadChild::kHelperRuns) {
        at_command = view.runs();
        break;
      }
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  ASSERT_EQ(at_command.size(), 2u);
  // The helper exits (joined by the main thread, which runs for that) and the main thread rests:
  // the process has run since, with fewer runs in all than the two threads had.
  child.endHelper();
  child.wakeMain('j');
  ProcessActivity after;
  while (std::chrono::steady_clock::now() < give_up) {
    after = view.activity();
    if (after.asleep && after.threads.size() == 1) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  ASSERT_TRUE(after.asleep);
  ASSERT_EQ(after.threads.size(), 1u);
  EXPECT_LT(runsOf(after.threads), runsOf(at_command));
  EXPECT_TRUE(after.ranSince(at_command));
  EXPECT_TRUE(after.restedSince(at_command));
  // Asleep with no run since: not rested since.
  EXPECT_FALSE(after.ranSince(view.runs()));
}

TEST(ProcessExits, AWatchedChildsExitIsToldAtOnceBeforeItIsReaped) {
  std::atomic<int> told{0};
  ProcessExits exits([&told] { ++told; });
  Child child(false);
  EXPECT_EQ(exits.watch(child.pid()), ProcessExits::Watch::kWatched);
  EXPECT_EQ(exits.watch(child.pid()), ProcessExits::Watch::kWatched);  // once
  EXPECT_FALSE(exits.exited(child.pid()));
  const int pid = child.pid();
  child.end(/*reap=*/false);
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (told.load() == 0 && std::chrono::steady_clock::now() < give_up)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  EXPECT_EQ(told.load(), 1);
  EXPECT_TRUE(exits.exited(pid));
  EXPECT_EQ(::access(("/proc/" + std::to_string(pid)).c_str(), F_OK), 0);  // not reaped yet
  // Watched again, a zombie or reaped, it has exited.
  EXPECT_EQ(exits.watch(pid), ProcessExits::Watch::kExited);
  child.end();
  EXPECT_EQ(exits.watch(pid), ProcessExits::Watch::kExited);
  EXPECT_TRUE(exits.exited(pid));
}

TEST(ProcessThreads, FilesKeptOpenStayWithinTheirBudget) {
  Child child(false);
  const int before = openFiles();
  // 300 views of a one-thread process would keep 600 thread files open without a budget.
  std::vector<std::unique_ptr<ProcessThreads>> views;
  for (int i = 0; i < 300; ++i) {
    views.push_back(std::make_unique<ProcessThreads>(child.pid()));
    ASSERT_TRUE(readsAsleep(*views.back())) << "view " << i;
  }
  // Each view keeps its task folder; thread files at most 256 in all.
  EXPECT_LE(openFiles() - before, 300 + 256);
  views.clear();
  EXPECT_EQ(openFiles(), before);
}

}  // namespace
}  // namespace onedof_sim

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
