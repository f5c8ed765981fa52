#include "process_activity.h"

#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

namespace onedof_sim {
namespace {

// The whole (small) file from its start, or false (its thread gone).
bool readAgain(int fd, char* buffer, size_t size) {
  const ssize_t n = ::pread(fd, buffer, size - 1, 0);
  if (n <= 0) return false;
  buffer[n] = '\0';
  return true;
}

void closeFile(int* fd) {
  if (*fd >= 0) ::close(*fd);
  *fd = -1;
}

// The threads' files kept open between looks, in every view of this process together, are at
// most this many: beyond it (many controllers, or many threads) a thread's files are opened for
// a look and closed after it, so that the node keeps its descriptors for its connections.
constexpr int kKeptFilesBudget = 256;
std::atomic<int> kept_files{0};

}  // namespace

void ProcessThreads::release(ThreadFiles* files) {
  closeFile(&files->stat_fd);
  closeFile(&files->schedstat_fd);
  if (files->kept) kept_files.fetch_sub(2);
  files->kept = false;
}

void ProcessThreads::forget() {
  for (ThreadFiles& files : threads_) release(&files);
  threads_.clear();
  if (task_dir_) ::closedir(task_dir_);
  task_dir_ = nullptr;
}

const ProcessThreads::ThreadFiles* ProcessThreads::filesOf(long tid,
                                                           std::vector<ThreadFiles>* listed) {
  auto known = std::find_if(threads_.begin(), threads_.end(),
                            [tid](const ThreadFiles& files) { return files.tid == tid; });
  if (known != threads_.end()) {
    listed->push_back(*known);
    *known = ThreadFiles{};  // moved: not closed with the threads no longer listed
    return &listed->back();
  }
  ThreadFiles files;
  files.tid = tid;
  files.kept = kept_files.fetch_add(2) + 2 <= kKeptFilesBudget;
  if (!files.kept) kept_files.fetch_sub(2);
  const int dir_fd = ::dirfd(task_dir_);
  const std::string thread_dir = std::to_string(tid);
  files.stat_fd = ::openat(dir_fd, (thread_dir + "/stat").c_str(), O_RDONLY | O_CLOEXEC);
  files.schedstat_fd =
      ::openat(dir_fd, (thread_dir + "/schedstat").c_str(), O_RDONLY | O_CLOEXEC);
  listed->push_back(files);
  return &listed->back();
}

// Every listed thread's state (from stat: the field after the command name, which may hold spaces
// and parentheses, so after the last ')') and run count (the third field of schedstat).
bool ProcessThreads::lookWithOpenFiles(LookFor what, std::vector<ThreadSample>* threads,
                                       bool* all_blocked) {
  threads->clear();
  *all_blocked = true;
  if (!task_dir_) {
    task_dir_ = ::opendir(("/proc/" + std::to_string(pid_) + "/task").c_str());
    if (!task_dir_) return false;
  }
  ::rewinddir(task_dir_);
  std::vector<ThreadFiles> listed;
  listed.reserve(threads_.size() + 1);
  bool complete = true;
  char buffer[1024];
  while (const dirent* entry = ::readdir(task_dir_)) {
    if (entry->d_name[0] < '0' || entry->d_name[0] > '9') continue;
    const ThreadFiles* files = filesOf(std::strtol(entry->d_name, nullptr, 10), &listed);
    ThreadSample sample;
    sample.tid = files->tid;
    if (what == LookFor::kRest) {
      if (files->stat_fd < 0 || !readAgain(files->stat_fd, buffer, sizeof buffer)) {
        complete = false;
        break;
      }
      const char* close_paren = std::strrchr(buffer, ')');
      if (!close_paren || close_paren[1] != ' ') {
        complete = false;
        break;
      }
      sample.state = close_paren[2];
      // Blocked in the kernel waiting for an event (a futex, a socket, a timer). Not D
      // (uninterruptible: a page fault or disk wait in the middle of running code), T or t
      // (stopped anywhere), R: the process does not rest, whatever its other threads do.
      if (sample.state != 'S') {
        *all_blocked = false;
        threads->push_back(sample);
        break;
      }
    }
    unsigned long long on_cpu_ns = 0, waited_ns = 0, runs = 0;
    if (files->schedstat_fd < 0 || !readAgain(files->schedstat_fd, buffer, sizeof buffer) ||
        std::sscanf(buffer, "%llu %llu %llu", &on_cpu_ns, &waited_ns, &runs) != 3) {
      complete = false;
      break;
    }
    sample.runs = runs;
    threads->push_back(sample);
  }
  // The files of the threads not reached by this look stay open for the next; those of threads
  // no longer listed (a whole listing: they are gone) are closed.
  const bool whole_listing = complete && *all_blocked;
  for (ThreadFiles& files : threads_) {
    if (files.tid != 0 && !whole_listing) {
      listed.push_back(files);
      continue;
    }
    release(&files);
  }
  threads_.clear();
  for (ThreadFiles& files : listed) {
    if (files.kept) {
      threads_.push_back(files);
    } else {
      release(&files);  // beyond the budget: opened for this look only
    }
  }
  return complete && !threads->empty();
}

bool ProcessThreads::look(LookFor what, std::vector<ThreadSample>* threads, bool* all_blocked) {
  if (lookWithOpenFiles(what, threads, all_blocked)) return true;
  // Files opened before may be of threads gone, or of a process gone whose pid was taken again:
  // the same look from fresh files, as the first look ever made.
  forget();
  return lookWithOpenFiles(what, threads, all_blocked);
}

ProcessActivity ProcessThreads::activity() {
  ProcessActivity activity;
  std::vector<ThreadSample> first, second;
  bool first_blocked = false, second_blocked = false;
  if (!look(LookFor::kRest, &first, &first_blocked)) {
    activity.gone = ::access(("/proc/" + std::to_string(pid_)).c_str(), F_OK) != 0;
    return activity;
  }
  if (!first_blocked) return activity;
  // A thread that woke another and then blocked can be read blocked after its wakee was read
  // blocked too: only a second look with no thread run in between shows the process at rest.
  if (!look(LookFor::kRest, &second, &second_blocked) || !second_blocked) return activity;
  if (first.size() != second.size()) return activity;
  for (size_t i = 0; i < first.size(); ++i)
    if (first[i].tid != second[i].tid || first[i].runs != second[i].runs) return activity;
  activity.asleep = true;
  for (const ThreadSample& thread : second) activity.runs += thread.runs;
  return activity;
}

uint64_t ProcessThreads::runs() {
  std::vector<ThreadSample> threads;
  bool unused;
  if (!look(LookFor::kRuns, &threads, &unused)) return 0;
  uint64_t runs = 0;
  for (const ThreadSample& thread : threads) runs += thread.runs;
  return runs;
}

bool processExists(int pid) { return ::kill(pid, 0) == 0 || errno == EPERM; }

}  // namespace onedof_sim
