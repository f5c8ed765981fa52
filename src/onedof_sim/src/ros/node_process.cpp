#include "node_process.h"

#include <ifaddrs.h>
#include <netdb.h>
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>

#include <cstring>

#include <ros/master.h>
#include <ros/network.h>
#include <ros/this_node.h>
#include <xmlrpcpp/XmlRpcClient.h>
#include <xmlrpcpp/XmlRpcValue.h>

namespace onedof_sim {
namespace {

using XmlRpc::XmlRpcValue;

bool sameAddress(const sockaddr* a, const sockaddr* b) {
  if (a->sa_family != b->sa_family) return false;
  if (a->sa_family == AF_INET) {
    return reinterpret_cast<const sockaddr_in*>(a)->sin_addr.s_addr ==
           reinterpret_cast<const sockaddr_in*>(b)->sin_addr.s_addr;
  }
  if (a->sa_family == AF_INET6) {
    return std::memcmp(&reinterpret_cast<const sockaddr_in6*>(a)->sin6_addr,
                       &reinterpret_cast<const sockaddr_in6*>(b)->sin6_addr,
                       sizeof(in6_addr)) == 0;
  }
  return false;
}

bool isLoopback(const sockaddr* address) {
  if (address->sa_family == AF_INET)
    return (ntohl(reinterpret_cast<const sockaddr_in*>(address)->sin_addr.s_addr) >> 24) == 127;
  if (address->sa_family == AF_INET6)
    return IN6_IS_ADDR_LOOPBACK(&reinterpret_cast<const sockaddr_in6*>(address)->sin6_addr);
  return false;
}

// Whether `host` resolves to a loopback address or one of this machine's interfaces: a pid from
// there names a process here.
bool isThisMachine(const std::string& host) {
  addrinfo hints{};
  hints.ai_socktype = SOCK_STREAM;
  addrinfo* resolved = nullptr;
  if (::getaddrinfo(host.c_str(), nullptr, &hints, &resolved) != 0) return false;
  ifaddrs* interfaces = nullptr;
  bool local = false;
  for (const addrinfo* address = resolved; address && !local; address = address->ai_next)
    local = isLoopback(address->ai_addr);
  if (!local && ::getifaddrs(&interfaces) == 0) {
    for (const addrinfo* address = resolved; address && !local; address = address->ai_next)
      for (const ifaddrs* interface = interfaces; interface && !local;
           interface = interface->ifa_next)
        local = interface->ifa_addr && sameAddress(address->ai_addr, interface->ifa_addr);
    ::freeifaddrs(interfaces);
  }
  ::freeaddrinfo(resolved);
  return local;
}

}  // namespace

std::optional<int> localNodePid(const std::string& node, bool* silent_here) {
  if (silent_here) *silent_here = false;
  XmlRpcValue request, response, uri;
  request[0] = ros::this_node::getName();
  request[1] = node;
  if (!ros::master::execute("lookupNode", request, response, uri, false) ||
      uri.getType() != XmlRpcValue::TypeString)
    return std::nullopt;
  std::string host;
  uint32_t port = 0;
  if (!ros::network::splitURI(std::string(uri), host, port) || !isThisMachine(host))
    return std::nullopt;
  XmlRpc::XmlRpcClient client(host.c_str(), int(port), "/");
  XmlRpcValue params, answer;
  params[0] = ros::this_node::getName();
  const bool answered = client.execute("getPid", params, answer);
  client.close();
  if (!answered) {
    if (silent_here) *silent_here = true;
    return std::nullopt;
  }
  // The slave API answers [code, status message, value]; code 1 is success.
  if (answer.getType() != XmlRpcValue::TypeArray || answer.size() != 3 ||
      answer[0].getType() != XmlRpcValue::TypeInt || int(answer[0]) != 1 ||
      answer[2].getType() != XmlRpcValue::TypeInt)
    return std::nullopt;
  return int(answer[2]);
}

}  // namespace onedof_sim
