#include "network_backlog.h"

#include <ros/poll_manager.h>
#include <ros/publication.h>
#include <ros/topic_manager.h>

namespace onedof_sim {

NetworkBacklog::NetworkBacklog(size_t budget)
    : budget_(budget),
      listener_(ros::PollManager::instance()->addPollThreadListener([this] { turn(); })) {}

NetworkBacklog::~NetworkBacklog() {
  ros::PollManager::instance()->removePollThreadListener(listener_);
}

// Called by the thread at the start of each of its turns, before it waits for its sockets and
// writes to those that can take more (as much as each takes: its whole queue, unless the
// subscriber reads more slowly).
void NetworkBacklog::turn() { turns_.fetch_add(1, std::memory_order_release); }

void NetworkBacklog::refresh(const std::string& topic, const std::type_info& type) {
  // roscpp serializes a message only for subscribers it writes to a socket.
  bool serialize = false;
  bool nocopy = false;
  if (const ros::PublicationPtr publication =
          ros::TopicManager::instance()->lookupPublication(topic))
    publication->getPublishTypes(serialize, nocopy, type);
  remote_ = serialize;
}

void NetworkBacklog::forgetWritten() {
  const uint64_t turns = turns_.load(std::memory_order_acquire);
  while (!unwritten_.empty() && unwritten_.front().first <= turns) {
    unwritten_messages_ -= unwritten_.front().second;
    unwritten_.pop_front();
  }
}

bool NetworkBacklog::full(uint32_t subscribers) {
  if (!remote_) return false;
  forgetWritten();
  return unwritten_messages_ + subscribers > budget_;
}

// The turn under way when a message is handed over may have looked at its sockets before it:
// the next one is the first sure to write it, and it has ended when the one after it begins.
void NetworkBacklog::handedOver(uint32_t subscribers) {
  if (!remote_ || subscribers == 0) return;
  const uint64_t written_at = turns_.load(std::memory_order_acquire) + 2;
  if (!unwritten_.empty() && unwritten_.back().first == written_at)
    unwritten_.back().second += subscribers;
  else
    unwritten_.emplace_back(written_at, subscribers);
  unwritten_messages_ += subscribers;
}

}  // namespace onedof_sim
