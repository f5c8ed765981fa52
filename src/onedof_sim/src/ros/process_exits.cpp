#include "process_exits.h"

#include <poll.h>
#include <sys/eventfd.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <utility>
#include <vector>

namespace onedof_sim {
namespace {

// The system call itself: glibc's wrapper (<sys/pidfd.h>) is newer than some libcs it builds on.
int openPidfd(int pid) { return int(::syscall(SYS_pidfd_open, pid, 0)); }

// A pidfd is readable once its process has exited.
bool hasExited(int pidfd) {
  pollfd look{pidfd, POLLIN, 0};
  return ::poll(&look, 1, 0) == 1 && (look.revents & POLLIN);
}

// How often the thread looks again when it cannot be woken (no eventfd).
constexpr int kUnwokenLookMs = 50;

}  // namespace

ProcessExits::ProcessExits(std::function<void()> on_exit)
    : on_exit_(std::move(on_exit)), wake_fd_(::eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK)) {
  thread_ = std::thread([this] { run(); });
}

ProcessExits::~ProcessExits() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  wakeThread();
  thread_.join();
  for (const auto& [pid, fd] : pidfds_) ::close(fd);
  if (wake_fd_ >= 0) ::close(wake_fd_);
}

void ProcessExits::wakeThread() {
  if (wake_fd_ < 0) return;
  const uint64_t one = 1;
  const ssize_t written = ::write(wake_fd_, &one, sizeof one);
  (void)written;  // fails only with the counter full: a wake is pending already
}

ProcessExits::Watch ProcessExits::watch(int pid, int* error) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (pidfds_.count(pid)) return Watch::kWatched;
  const int fd = openPidfd(pid);
  if (fd < 0) {
    if (errno == ESRCH) {
      exited_.insert(pid);
      return Watch::kExited;
    }
    if (error) *error = errno;
    return Watch::kCannot;
  }
  if (hasExited(fd)) {  // a zombie
    ::close(fd);
    exited_.insert(pid);
    return Watch::kExited;
  }
  exited_.erase(pid);
  pidfds_[pid] = fd;
  wakeThread();
  return Watch::kWatched;
}

bool ProcessExits::exited(int pid) const {
  std::lock_guard<std::mutex> lock(mutex_);
  return exited_.count(pid) > 0;
}

// Only this thread closes the pidfds it polls (watch() only adds), so each stays open while it
// is polled.
void ProcessExits::run() {
  std::vector<pollfd> fds;
  std::vector<int> pids;
  for (;;) {
    fds.assign(1, pollfd{wake_fd_, POLLIN, 0});
    pids.clear();
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (stopping_) return;
      for (const auto& [pid, fd] : pidfds_) {
        fds.push_back({fd, POLLIN, 0});
        pids.push_back(pid);
      }
    }
    if (::poll(fds.data(), fds.size(), wake_fd_ >= 0 ? -1 : kUnwokenLookMs) < 0) continue;
    if (fds[0].revents & POLLIN) {
      uint64_t count;
      const ssize_t drained = ::read(wake_fd_, &count, sizeof count);
      (void)drained;  // nothing to read: another look drained it
    }
    bool any_exited = false;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      for (size_t i = 1; i < fds.size(); ++i) {
        if (!(fds[i].revents & (POLLIN | POLLHUP | POLLERR))) continue;
        ::close(fds[i].fd);
        pidfds_.erase(pids[i - 1]);
        exited_.insert(pids[i - 1]);
        any_exited = true;
      }
    }
    if (any_exited) on_exit_();
  }
}

}  // namespace onedof_sim
