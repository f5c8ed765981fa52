#include "process_activity.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
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

// A thread's state in the text of its stat: the field after the command name, which may hold
// spaces and parentheses, so after the last ')'. 0 if the text has none.
char stateIn(const char* stat_text) {
  const char* close_paren = std::strrchr(stat_text, ')');
  if (!close_paren || close_paren[1] != ' ') return 0;
  return close_paren[2];
}

// The state in the stat file at path, 0 if it cannot be read (its thread gone).
char stateAt(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return 0;
  char buffer[1024];
  const bool read = readAgain(fd, buffer, sizeof buffer);
  ::close(fd);
  return read ? stateIn(buffer) : 0;
}

// A thread that has exited: a zombie (its process not yet reaped, or its leader waiting for the
// other threads) or dead.
bool hasExited(char state) { return state == 'Z' || state == 'X' || state == 'x'; }

// A thread's entry in a process's runs sorted by thread id, or nullptr.
const ThreadRuns* entryOf(const ProcessRuns& threads, long tid) {
  const auto found =
      std::lower_bound(threads.begin(), threads.end(), tid,
                       [](const ThreadRuns& thread, long id) { return thread.tid < id; });
  return found != threads.end() && found->tid == tid ? &*found : nullptr;
}

void sortByTid(std::vector<ThreadRuns>* threads) {
  std::sort(threads->begin(), threads->end(),
            [](const ThreadRuns& a, const ThreadRuns& b) { return a.tid < b.tid; });
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

// Every listed thread's state (from stat) and run count (the third field of schedstat).
bool ProcessThreads::lookWithOpenFiles(LookFor what, const LeftOut& left_out,
                                       std::vector<ThreadRuns>* threads, bool* all_blocked) {
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
    ThreadRuns sample;
    sample.tid = files->tid;
    bool not_blocked = false;  // for kRest: a thread that holds the rest unless left out
    if (files->stat_fd < 0 || !readAgain(files->stat_fd, buffer, sizeof buffer)) {
      if (what == LookFor::kRuns) continue;  // a thread that ended since the listing
      complete = false;
      break;
    }
    const char state = stateIn(buffer);
    if (state == 0) {
      if (what == LookFor::kRuns) continue;
      complete = false;
      break;
    }
    if (hasExited(state)) continue;  // it will never run again
    // Blocked in the kernel waiting for an event (a futex, a socket, a timer). Not D
    // (uninterruptible: a page fault or disk wait in the middle of running code), T or t
    // (stopped anywhere), R: the process does not rest, whatever its other threads do, unless
    // the thread is left out.
    sample.blocked = state == 'S';
    if (what == LookFor::kRest && !sample.blocked) {
      not_blocked = true;
      if (!left_out) {
        *all_blocked = false;
        threads->push_back(sample);
        break;
      }
    }
    unsigned long long on_cpu_ns = 0, waited_ns = 0, runs = 0;
    if (files->schedstat_fd < 0 || !readAgain(files->schedstat_fd, buffer, sizeof buffer) ||
        std::sscanf(buffer, "%llu %llu %llu", &on_cpu_ns, &waited_ns, &runs) != 3) {
      if (what == LookFor::kRuns) continue;
      complete = false;
      break;
    }
    sample.runs = runs;
    threads->push_back(sample);
    if (not_blocked && !left_out(sample)) {
      *all_blocked = false;
      break;
    }
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

bool ProcessThreads::look(LookFor what, const LeftOut& left_out, std::vector<ThreadRuns>* threads,
                          bool* all_blocked) {
  if (lookWithOpenFiles(what, left_out, threads, all_blocked)) return true;
  // Files opened before may be of threads gone, or of a process gone whose pid was taken again:
  // the same look from fresh files, as the first look ever made.
  forget();
  return lookWithOpenFiles(what, left_out, threads, all_blocked);
}

ProcessActivity ProcessThreads::activity(const LeftOut& left_out) {
  ProcessActivity activity;
  std::vector<ThreadRuns> first, second;
  bool first_blocked = false, second_blocked = false;
  if (!look(LookFor::kRest, left_out, &first, &first_blocked)) {
    activity.gone = !processLives(pid_);
    return activity;
  }
  if (!first_blocked) return activity;
  // A thread that woke another and then blocked can be read blocked after its wakee was read
  // blocked too: only a second look with no thread run in between shows the process at rest.
  if (!look(LookFor::kRest, left_out, &second, &second_blocked) || !second_blocked)
    return activity;
  if (first.size() != second.size()) return activity;
  for (size_t i = 0; i < first.size(); ++i)
    if (first[i].tid != second[i].tid || first[i].runs != second[i].runs) return activity;
  activity.asleep = true;
  sortByTid(&second);
  activity.threads = std::move(second);
  return activity;
}

ProcessRuns ProcessThreads::runs() {
  std::vector<ThreadRuns> threads;
  bool unused;
  if (!look(LookFor::kRuns, nullptr, &threads, &unused)) return {};
  sortByTid(&threads);
  return threads;
}

bool ProcessActivity::ranSince(const ProcessRuns& at_command) const {
  if (at_command.empty()) return true;  // nothing known of the command's time: resting suffices
  for (const ThreadRuns& now : threads) {
    const ThreadRuns* then = entryOf(at_command, now.tid);
    if (then && now.runs > then->runs) return true;
  }
  return false;
}

bool ThreadsAtWork::dormant(const ProcessRuns& at_command, const ThreadRuns& now) const {
  const ThreadRuns* then = entryOf(at_command, now.tid);
  if (!then || !then->blocked || now.runs != then->runs) return false;
  const auto idle = idle_periods_.find(now.tid);
  return idle != idle_periods_.end() && idle->second >= kIdlePeriods;
}

void ThreadsAtWork::noteRest(const ProcessRuns& at_command, const ProcessRuns& at_rest) {
  std::map<long, int> idle_periods;
  for (const ThreadRuns& now : at_rest) {
    const ThreadRuns* then = entryOf(at_command, now.tid);
    const bool ran = !then || now.runs > then->runs;
    const auto before = idle_periods_.find(now.tid);
    const int idle_before = before == idle_periods_.end() ? 0 : before->second;
    idle_periods[now.tid] = ran ? 0 : std::min(idle_before + 1, kIdlePeriods);
  }
  idle_periods_ = std::move(idle_periods);
}

bool processLives(int pid) {
  const std::string dir = "/proc/" + std::to_string(pid);
  // The leader's state first, one file: a process that lives has it anything but exited, unless
  // its leader ended alone (pthread_exit) while other threads run on.
  const char leader = stateAt(dir + "/stat");
  if (leader == 0) return false;
  if (!hasExited(leader)) return true;
  DIR* tasks = ::opendir((dir + "/task").c_str());
  if (!tasks) return false;
  bool lives = false;
  while (const dirent* entry = lives ? nullptr : ::readdir(tasks)) {
    if (entry->d_name[0] < '0' || entry->d_name[0] > '9') continue;
    const char state = stateAt(dir + "/task/" + entry->d_name + "/stat");
    lives = state != 0 && !hasExited(state);
  }
  ::closedir(tasks);
  return lives;
}

}  // namespace onedof_sim
