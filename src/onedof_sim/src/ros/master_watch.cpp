#include "master_watch.h"

#include <chrono>
#include <sstream>
#include <utility>

#include <ros/connection_manager.h>
#include <ros/master.h>
#include <ros/network.h>
#include <ros/ros.h>
#include <ros/service_manager.h>
#include <ros/xmlrpc_manager.h>
#include <xmlrpcpp/XmlRpcClient.h>
#include <xmlrpcpp/XmlRpcException.h>

namespace onedof_sim {

namespace {

using XmlRpc::XmlRpcValue;

constexpr auto kCheckPeriod = std::chrono::seconds(1);

// A call to the master with this node's name first; its payload, or false if it did not answer
// or refused.
bool callMaster(const std::string& method, XmlRpcValue args, XmlRpcValue* payload) {
  XmlRpcValue request, response;
  request[0] = ros::this_node::getName();
  for (int i = 0; i < args.size(); ++i) request[i + 1] = args[i];
  return ros::master::execute(method, request, response, *payload, false);
}

XmlRpcValue list(std::initializer_list<XmlRpcValue> values) {
  XmlRpcValue result;
  result.setSize(0);
  for (const XmlRpcValue& value : values) result[result.size()] = value;
  return result;
}

// A call to this node's own slave API (the XML-RPC server every roscpp node runs, which the
// master and peers call): its value, or false.
bool callSelf(const std::string& method, XmlRpcValue args, XmlRpcValue* value) {
  std::string host;
  uint32_t port = 0;
  if (!ros::network::splitURI(ros::XMLRPCManager::instance()->getServerURI(), host, port))
    return false;
  XmlRpcValue request, result;
  request[0] = ros::this_node::getName();
  for (int i = 0; i < args.size(); ++i) request[i + 1] = args[i];
  XmlRpc::XmlRpcClient client(host.c_str(), int(port), "/");
  if (!client.execute(method.c_str(), request, result) || client.isFault() ||
      result.getType() != XmlRpcValue::TypeArray || result.size() != 3 || int(result[0]) != 1)
    return false;
  *value = result[2];
  return true;
}

// [[topic, type], ...] of the slave API's getPublications and getSubscriptions.
std::vector<std::pair<std::string, std::string>> topicsAndTypes(const XmlRpcValue& value) {
  std::vector<std::pair<std::string, std::string>> topics;
  if (value.getType() != XmlRpcValue::TypeArray) return topics;
  for (int i = 0; i < value.size(); ++i) {
    XmlRpcValue entry = value[i];
    if (entry.getType() == XmlRpcValue::TypeArray && entry.size() == 2)
      topics.emplace_back(std::string(entry[0]), std::string(entry[1]));
  }
  return topics;
}

// The XML-RPC URIs of the publishers this node receives `topic` from (the slave API's
// getBusInfo: [connection id, peer URI, direction, transport, topic, ...] each).
std::set<std::string> connectedPublishers(const XmlRpcValue& bus_info, const std::string& topic) {
  std::set<std::string> uris;
  if (bus_info.getType() != XmlRpcValue::TypeArray) return uris;
  for (int i = 0; i < bus_info.size(); ++i) {
    XmlRpcValue connection = bus_info[i];
    if (connection.getType() != XmlRpcValue::TypeArray || connection.size() < 5) continue;
    if (std::string(connection[2]) == "i" && std::string(connection[4]) == topic)
      uris.insert(std::string(connection[1]));
  }
  return uris;
}

std::string joined(const std::vector<std::string>& names) {
  std::ostringstream text;
  for (size_t i = 0; i < names.size(); ++i) text << (i ? ", " : "") << names[i];
  return text.str();
}

}  // namespace

MasterWatch::MasterWatch(NodeParameters parameters)
    : parameters_(std::move(parameters)), thread_([this] { watch(); }) {}

MasterWatch::~MasterWatch() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  thread_.join();
}

void MasterWatch::watch() {
  int known_pid = -1;        // the master this node is registered with
  bool answered = true;      // at the latest check (roscpp registered everything at start-up)
  bool registered = true;    // everything is registered with the master that answers
  std::unique_lock<std::mutex> lock(mutex_);
  while (!stopping_ && ros::ok()) {
    lock.unlock();
    try {
      XmlRpcValue pid;
      if (callMaster("getPid", list({}), &pid) && pid.getType() == XmlRpcValue::TypeInt) {
        const bool new_master = !answered || (known_pid != -1 && int(pid) != known_pid);
        if (new_master || !registered) registered = registerAgain(int(pid));
        known_pid = int(pid);
        answered = true;
        if (registered) noteServices();
      } else {
        answered = false;
      }
    } catch (const XmlRpc::XmlRpcException& e) {
      // An answer not shaped as the ROS APIs say: tried again at the next check.
      ROS_WARN_STREAM("checking the ROS master: " << e.getMessage());
      answered = false;
    }
    lock.lock();
    wake_.wait_for(lock, kCheckPeriod, [this] { return stopping_; });
  }
}

bool MasterWatch::noteServices() {
  XmlRpcValue state;
  if (!callMaster("getSystemState", list({}), &state) ||
      state.getType() != XmlRpcValue::TypeArray || state.size() != 3)
    return false;
  const std::string me = ros::this_node::getName();
  std::set<std::string> mine;
  XmlRpcValue services = state[2];  // [[service, [node, ...]], ...]
  for (int i = 0; i < services.size(); ++i) {
    XmlRpcValue entry = services[i];
    if (entry.getType() != XmlRpcValue::TypeArray || entry.size() != 2) continue;
    XmlRpcValue nodes = entry[1];
    for (int j = 0; j < nodes.size(); ++j)
      if (std::string(nodes[j]) == me) mine.insert(std::string(entry[0]));
  }
  services_ = std::move(mine);
  return true;
}

bool MasterWatch::registerAgain(int master_pid) {
  const std::string api = ros::XMLRPCManager::instance()->getServerURI();
  XmlRpcValue publications, subscriptions, bus_info, unused;
  if (!callSelf("getPublications", list({}), &publications) ||
      !callSelf("getSubscriptions", list({}), &subscriptions) ||
      !callSelf("getBusInfo", list({}), &bus_info)) {
    ROS_WARN("the ROS master came back, and this node's own XML-RPC server did not answer: "
             "trying again");
    return false;
  }

  const auto published = topicsAndTypes(publications);
  for (const auto& [topic, type] : published)
    if (!callMaster("registerPublisher", list({topic, type, api}), &unused)) return false;

  const auto subscribed = topicsAndTypes(subscriptions);
  for (const auto& [topic, type] : subscribed) {
    XmlRpcValue publishers;
    if (!callMaster("registerSubscriber", list({topic, type, api}), &publishers)) return false;
    // Publishers that registered with the new master before this node did: this update
    // connects them. It names those already connected too, which roscpp would otherwise drop
    // (the publishers that do not register again, such as a rospy node's).
    std::set<std::string> connected = connectedPublishers(bus_info, topic);
    bool any_new = false;
    for (int i = 0; i < publishers.size(); ++i)
      any_new |= connected.insert(std::string(publishers[i])).second;
    if (!any_new) continue;
    XmlRpcValue uris;
    uris.setSize(0);
    for (const std::string& uri : connected) uris[uris.size()] = uri;
    callSelf("publisherUpdate", list({topic, uris}), &unused);
  }

  std::ostringstream rosrpc;
  rosrpc << "rosrpc://" << ros::network::getHost() << ":"
         << ros::ConnectionManager::instance()->getTCPPort();
  size_t services = 0;
  for (const std::string& service : services_) {
    if (!ros::ServiceManager::instance()->lookupServicePublication(service)) continue;
    if (!callMaster("registerService", list({service, rosrpc.str(), api}), &unused)) return false;
    ++services;
  }

  const std::vector<std::string> parameters = parameters_.set_again();
  // The cache follows the new master: its current value ({} for none, which roscpp's cache
  // takes as unset), then its updates.
  for (const std::string& name : parameters_.cached) {
    XmlRpcValue value;
    if (!callMaster("subscribeParam", list({api, name}), &value)) return false;
    callSelf("paramUpdate", list({name, value}), &unused);
  }
  ROS_INFO("the ROS master came back (pid %d): registered again %zu published topics, "
           "%zu subscribed topics, %zu services, the parameters %s and the subscription to %s",
           master_pid, published.size(), subscribed.size(), services,
           joined(parameters).c_str(), joined(parameters_.cached).c_str());
  return true;
}

}  // namespace onedof_sim
