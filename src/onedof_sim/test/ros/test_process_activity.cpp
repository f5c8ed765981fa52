// ProcessThreads: a child process blocked reads asleep, one spinning does not, one gone reads
// gone; its files kept open stay within their budget however many views look.
#include <dirent.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <memory>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "../../src/ros/process_activity.h"

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
  void end() {
    if (pid_ <= 0) return;
    ::kill(pid_, SIGKILL);
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
  EXPECT_GT(again.runs, 0u);
  EXPECT_EQ(view.runs(), again.runs);  // asleep: not put on a CPU since
}

TEST(ProcessThreads, AChildSpinningNeverReadsAsleep) {
  Child child(true);
  ProcessThreads view(child.pid());
  for (int i = 0; i < 200; ++i) {
    EXPECT_FALSE(view.activity().asleep);
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
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
  EXPECT_EQ(view.runs(), 0u);
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
