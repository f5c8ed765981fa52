// bench_service_client: round trips of a roscpp client to a GetJointProperties or ApplyJointEffort
// service (the simulator's or the bare floor's), over one persistent connection or a fresh one
// per call (master lookup + connect, as ros::service::call does).
//
//   bench_service_client SERVICE get|apply persistent|fresh COUNT
// prints one round trip per line, in microseconds, or "failed" for a call that got no answer.
// Exits 1 if the service refuses the call (success false).
#include <chrono>
#include <cstdlib>
#include <iostream>
#include <string>

#include <ros/ros.h>

#include <gazebo_msgs/ApplyJointEffort.h>
#include <gazebo_msgs/GetJointProperties.h>

namespace {

// The controller's calls: joint1, and a 10 ms effort job starting now.
void fill(gazebo_msgs::GetJointProperties* srv) { srv->request.joint_name = "joint1"; }

void fill(gazebo_msgs::ApplyJointEffort* srv) {
  srv->request.joint_name = "joint1";
  srv->request.effort = 0.0;
  srv->request.duration = ros::Duration(0.01);
}

// Warm-up calls, not timed: the first ones pay for connection set-up and page faults.
constexpr int kWarmUp = 20;

template <class Srv>
int measure(ros::NodeHandle& nh, const std::string& service, bool persistent, int count) {
  Srv srv;
  fill(&srv);
  ros::ServiceClient client;
  if (persistent) client = nh.serviceClient<Srv>(service, true);
  for (int i = -kWarmUp; i < count; ++i) {
    const auto start = std::chrono::steady_clock::now();
    const bool ok = persistent ? client.call(srv) : ros::service::call(service, srv);
    const auto end = std::chrono::steady_clock::now();
    if (!ok) {
      // A call that got no answer (a dropped connection on a loaded machine): said, not timed.
      if (i >= 0) std::cout << "failed\n";
      if (persistent) client = nh.serviceClient<Srv>(service, true);
      continue;
    }
    if (!srv.response.success) {
      std::cerr << "bench_service_client: " << service << " refused the call: "
                << srv.response.status_message << std::endl;
      return 1;
    }
    if (i >= 0) std::cout << std::chrono::duration<double, std::micro>(end - start).count() << "\n";
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "bench_service_client", ros::init_options::AnonymousName);
  const std::string kind = argc == 5 ? argv[2] : "";
  const std::string mode = argc == 5 ? argv[3] : "";
  const int count = argc == 5 ? std::atoi(argv[4]) : 0;
  if ((kind != "get" && kind != "apply") || (mode != "persistent" && mode != "fresh") ||
      count <= 0) {
    std::cerr << "usage: bench_service_client SERVICE get|apply persistent|fresh COUNT" << std::endl;
    return 2;
  }
  const std::string service = argv[1];
  // Held for the program's life: roscpp shuts the node down when its last NodeHandle goes, and
  // ros::service::call would then start and stop the node at every call.
  ros::NodeHandle nh;
  if (!ros::service::waitForService(service, ros::Duration(30))) {
    std::cerr << "bench_service_client: no service " << service << std::endl;
    return 1;
  }
  const bool persistent = mode == "persistent";
  return kind == "get" ? measure<gazebo_msgs::GetJointProperties>(nh, service, persistent, count)
                       : measure<gazebo_msgs::ApplyJointEffort>(nh, service, persistent, count);
}
