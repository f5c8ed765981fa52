/* Preloaded (LD_PRELOAD) into the ROS processes PrivateRos starts: a bind to the wildcard address
 * binds ROS_IP instead, so a node listens on the address it advertises and on no other.
 *
 * ROS 1 listens on every interface whatever ROS_IP says: roscpp's XML-RPC server (xmlrpcpp's
 * XmlRpcSocket::bind) always binds INADDR_ANY, and roscpp's TCPROS/UDPROS and rospy bind it
 * unless ROS_IP is a 127.x address. A node meant for loopback (or for one network of several)
 * would otherwise answer, with no authentication, on every address the machine has.
 *
 * Binds to a specific address, and every bind in a process without ROS_IP or with an ROS_IP that
 * is not a numeric address, pass through unchanged. An IPv4 ROS_IP given to an IPv6 wildcard bind
 * becomes its IPv4-mapped address. */
#define _GNU_SOURCE
#include <arpa/inet.h>
#include <dlfcn.h>
#include <netinet/in.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>

typedef int (*bind_function)(int, const struct sockaddr *, socklen_t);

static int ros_ip_as_ipv6(const char *ros_ip, struct in6_addr *address)
{
  struct in_addr ipv4;
  if (inet_pton(AF_INET6, ros_ip, address) == 1)
    return 1;
  if (inet_pton(AF_INET, ros_ip, &ipv4) != 1)
    return 0;
  memset(address, 0, sizeof *address);
  address->s6_addr[10] = 0xff;
  address->s6_addr[11] = 0xff;
  memcpy(&address->s6_addr[12], &ipv4, sizeof ipv4);
  return 1;
}

int bind(int fd, const struct sockaddr *address, socklen_t length)
{
  bind_function system_bind = (bind_function)dlsym(RTLD_NEXT, "bind");
  const char *ros_ip = getenv("ROS_IP");
  if (ros_ip && address && address->sa_family == AF_INET &&
      length >= (socklen_t)sizeof(struct sockaddr_in))
  {
    struct sockaddr_in ipv4 = *(const struct sockaddr_in *)address;
    if (ipv4.sin_addr.s_addr == htonl(INADDR_ANY) &&
        inet_pton(AF_INET, ros_ip, &ipv4.sin_addr) == 1)
      return system_bind(fd, (const struct sockaddr *)&ipv4, sizeof ipv4);
  }
  if (ros_ip && address && address->sa_family == AF_INET6 &&
      length >= (socklen_t)sizeof(struct sockaddr_in6))
  {
    struct sockaddr_in6 ipv6 = *(const struct sockaddr_in6 *)address;
    if (IN6_IS_ADDR_UNSPECIFIED(&ipv6.sin6_addr) && ros_ip_as_ipv6(ros_ip, &ipv6.sin6_addr))
      return system_bind(fd, (const struct sockaddr *)&ipv6, sizeof ipv6);
  }
  return system_bind(fd, address, length);
}
