// How many messages of one publication roscpp's network thread (its PollManager thread) may still
// have to write to the subscribers in other processes, counted by the thread's turns.
//
// A roscpp process has one thread for its network I/O: it writes every message a publisher hands
// it, to each subscriber, and reads every service request before a callback can answer it. The
// loop can step faster than that thread writes its clocks: every roscpp and rospy node subscribes
// to /clock under /use_sim_time, so 32 clients at 1 kHz are 32,000 writes a second, and on a busy
// machine the thread gets less of a core than that needs; the messages queue up in roscpp (a
// second of clocks a subscriber) and every service request waits behind them, for seconds. The
// loop asks this before it hands over a clock: once the thread has a budget of messages still to
// write, a step's time only replaces the one waiting, so a request waits behind at most that
// budget, and the world steps at its own pace whatever the thread's.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <string>
#include <typeinfo>
#include <utility>

#include <boost/signals2/connection.hpp>

namespace onedof_sim {

class NetworkBacklog {
 public:
  // `budget`: the messages the thread may have still to write.
  explicit NetworkBacklog(size_t budget);
  ~NetworkBacklog();
  NetworkBacklog(const NetworkBacklog&) = delete;
  NetworkBacklog& operator=(const NetworkBacklog&) = delete;

  // Re-reads whether `topic`'s publication has subscribers in other processes (those the thread
  // writes to; one in this process is handed each message directly, and counts for nothing).
  void refresh(const std::string& topic, const std::type_info& type);
  // Whether a message for `subscribers` subscribers handed over now would be past the budget.
  bool full(uint32_t subscribers);
  // A message for `subscribers` subscribers was just handed to the publication last refreshed
  // (roscpp wakes the thread for those in other processes).
  void handedOver(uint32_t subscribers);

 private:
  void turn();
  void forgetWritten();

  const size_t budget_;
  std::atomic<uint64_t> turns_{0};  // begun so far (counted by the thread)
  bool remote_ = false;  // the topic has subscribers in other processes, as last refreshed
  // The messages handed over and maybe not written yet, oldest first: (the turn that has written
  // them once it begins, how many).
  std::deque<std::pair<uint64_t, size_t>> unwritten_;
  size_t unwritten_messages_ = 0;
  boost::signals2::connection listener_;
};

}  // namespace onedof_sim
