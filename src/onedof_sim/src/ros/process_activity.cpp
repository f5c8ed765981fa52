#include "process_activity.h"

#include <dirent.h>
#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

#include <cerrno>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

namespace onedof_sim {
namespace {

struct ThreadSample {
  long tid = 0;
  char state = '?';
  uint64_t runs = 0;
};

// The whole (small) file, or false.
bool readSmallFile(const std::string& path, char* buffer, size_t size) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return false;
  const ssize_t n = ::read(fd, buffer, size - 1);
  ::close(fd);
  if (n <= 0) return false;
  buffer[n] = '\0';
  return true;
}

// Every thread's state (from stat: the field after the command name, which may hold spaces and
// parentheses, so after the last ')') and run count (the third field of schedstat). False if the
// process is gone or a thread went away between the listing and the reading.
bool look(int pid, std::vector<ThreadSample>* threads) {
  threads->clear();
  const std::string task_dir = "/proc/" + std::to_string(pid) + "/task";
  DIR* dir = ::opendir(task_dir.c_str());
  if (!dir) return false;
  bool complete = true;
  char buffer[1024];
  while (const dirent* entry = ::readdir(dir)) {
    if (entry->d_name[0] < '0' || entry->d_name[0] > '9') continue;
    ThreadSample sample;
    sample.tid = std::strtol(entry->d_name, nullptr, 10);
    const std::string thread_dir = task_dir + "/" + entry->d_name;
    if (!readSmallFile(thread_dir + "/stat", buffer, sizeof buffer)) {
      complete = false;
      break;
    }
    const char* close_paren = std::strrchr(buffer, ')');
    if (!close_paren || close_paren[1] != ' ') {
      complete = false;
      break;
    }
    sample.state = close_paren[2];
    unsigned long long on_cpu_ns = 0, waited_ns = 0, runs = 0;
    if (!readSmallFile(thread_dir + "/schedstat", buffer, sizeof buffer) ||
        std::sscanf(buffer, "%llu %llu %llu", &on_cpu_ns, &waited_ns, &runs) != 3) {
      complete = false;
      break;
    }
    sample.runs = runs;
    threads->push_back(sample);
  }
  ::closedir(dir);
  return complete && !threads->empty();
}

uint64_t sumRuns(const std::vector<ThreadSample>& threads) {
  uint64_t runs = 0;
  for (const ThreadSample& thread : threads) runs += thread.runs;
  return runs;
}

// Blocked in the kernel waiting for an event (a futex, a socket, a timer). Not D (uninterruptible:
// a page fault or disk wait in the middle of running code), T or t (stopped anywhere), R.
bool allBlocked(const std::vector<ThreadSample>& threads) {
  for (const ThreadSample& thread : threads)
    if (thread.state != 'S') return false;
  return true;
}

bool same(const std::vector<ThreadSample>& a, const std::vector<ThreadSample>& b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i)
    if (a[i].tid != b[i].tid || a[i].runs != b[i].runs || a[i].state != b[i].state) return false;
  return true;
}

}  // namespace

ProcessActivity readProcessActivity(int pid) {
  ProcessActivity activity;
  std::vector<ThreadSample> first, second;
  if (!look(pid, &first)) {
    activity.gone = ::access(("/proc/" + std::to_string(pid)).c_str(), F_OK) != 0;
    return activity;
  }
  activity.runs = sumRuns(first);
  if (!allBlocked(first)) return activity;
  // A thread that woke another and then blocked can be read blocked after its wakee was read
  // blocked too: only a second look with no thread run in between shows the process at rest.
  if (!look(pid, &second)) return activity;
  activity.runs = sumRuns(second);
  activity.asleep = same(first, second);
  return activity;
}

uint64_t processRuns(int pid) {
  std::vector<ThreadSample> threads;
  return look(pid, &threads) ? sumRuns(threads) : 0;
}

bool processExists(int pid) { return ::kill(pid, 0) == 0 || errno == EPERM; }

}  // namespace onedof_sim
