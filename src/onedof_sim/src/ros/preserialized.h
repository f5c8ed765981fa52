// A message serialized before it is published, so that publishing it only hands its bytes over.
//
// ros::Publisher::publish serializes a message while it holds roscpp's topic lock
// (TopicManager's advertised_topics_mutex_), and roscpp's one network thread takes that lock
// between its polls to flush the publish queues. Serializing a 48 MB image there kept the network
// thread, and with it every service request and reply of the node, waiting for tens of ms, for
// hundreds on a busy machine. A PreSerialized message is serialized by preSerialize, with no lock
// of roscpp's held; its publishing copies no byte.
//
// A publisher advertised for M takes a PreSerialized made from an M: it carries M's md5sum and
// type, and the bytes are those roscpp itself would have made.
#pragma once

#include <ros/message_traits.h>
#include <ros/publisher.h>
#include <ros/serialization.h>

namespace onedof_sim {

struct PreSerialized {
  ros::SerializedMessage bytes;
  const char* md5sum = "*";
  const char* datatype = "*";
};

template <class M>
PreSerialized preSerialize(const M& message) {
  PreSerialized out;
  out.bytes = ros::serialization::serializeMessage(message);
  out.md5sum = ros::message_traits::md5sum<M>();
  out.datatype = ros::message_traits::datatype<M>();
  return out;
}

}  // namespace onedof_sim

namespace ros::message_traits {

template <>
struct MD5Sum<onedof_sim::PreSerialized> {
  static const char* value(const onedof_sim::PreSerialized& m) { return m.md5sum; }
  static const char* value() { return "*"; }
};

template <>
struct DataType<onedof_sim::PreSerialized> {
  static const char* value(const onedof_sim::PreSerialized& m) { return m.datatype; }
  static const char* value() { return "*"; }
};

}  // namespace ros::message_traits

namespace ros::serialization {

// What ros::Publisher::publish calls under its lock: the bytes made before.
template <>
inline SerializedMessage serializeMessage<onedof_sim::PreSerialized>(
    const onedof_sim::PreSerialized& message) {
  return message.bytes;
}

}  // namespace ros::serialization

namespace onedof_sim {

// Publishes message on publisher, serialized here first, unless nobody would receive it (no
// subscriber, not latched), in which case it is not serialized at all, as roscpp does. A
// publisher that was shut down publishes nothing (roscpp's isLatched would throw).
template <class M>
void publishPreSerialized(const ros::Publisher& publisher, const M& message) {
  if (!publisher) return;
  if (publisher.getNumSubscribers() == 0 && !publisher.isLatched()) return;
  publisher.publish(preSerialize(message));
}

}  // namespace onedof_sim
