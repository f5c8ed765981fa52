// The book's minimal joint controller, as a student writes it in C++ against gazebo_msgs: a PD law
// on joint1 at 100 Hz of ROS time, reading the joint through /gazebo/get_joint_properties and
// commanding torque through /gazebo/apply_joint_effort with non-persistent service clients.
#include <cmath>

#include <ros/ros.h>
#include <std_msgs/Float64.h>
#include <gazebo_msgs/ApplyJointEffort.h>
#include <gazebo_msgs/GetJointProperties.h>

// The book's 100 Hz; the CMakeLists builds a second executable at 1 kHz from this source.
#ifndef CONTROL_RATE_HZ
#define CONTROL_RATE_HZ 100
#endif

double g_pos_cmd = 0.0;

void posCmdCB(const std_msgs::Float64& pos_cmd_msg) {
  ROS_INFO("received value of pos_cmd is: %f", pos_cmd_msg.data);
  g_pos_cmd = pos_cmd_msg.data;
}

// The error the shorter way round the circle (joint1 is continuous).
double min_periodicity(double angle) {
  return std::remainder(angle, 2.0 * M_PI);
}

int main(int argc, char** argv) {
  ros::init(argc, argv, "book_controller");
  ros::NodeHandle n;

  ros::service::waitForService("/gazebo/apply_joint_effort");
  ros::service::waitForService("/gazebo/get_joint_properties");
  ros::ServiceClient set_trq_client =
      n.serviceClient<gazebo_msgs::ApplyJointEffort>("/gazebo/apply_joint_effort");
  ros::ServiceClient get_jnt_state_client =
      n.serviceClient<gazebo_msgs::GetJointProperties>("/gazebo/get_joint_properties");

  ros::Publisher trq_publisher = n.advertise<std_msgs::Float64>("jnt_trq", 1);
  ros::Publisher vel_publisher = n.advertise<std_msgs::Float64>("jnt_vel", 1);
  ros::Publisher pos_publisher = n.advertise<std_msgs::Float64>("jnt_pos", 1);
  ros::Subscriber pos_cmd_subscriber = n.subscribe("pos_cmd", 1, posCmdCB);

  gazebo_msgs::ApplyJointEffort effort_cmd_srv;
  effort_cmd_srv.request.joint_name = "joint1";
  effort_cmd_srv.request.start_time.fromSec(0);  // 0: start now
  effort_cmd_srv.request.duration.fromSec(1.0 / CONTROL_RATE_HZ);  // one period's job
  gazebo_msgs::GetJointProperties get_joint_state_srv;
  get_joint_state_srv.request.joint_name = "joint1";

  const double Kp = 10.0;
  const double Kv = 3.0;
  ros::Rate rate_timer(CONTROL_RATE_HZ);  // ROS time: sim time when /use_sim_time is true
  std_msgs::Float64 q_msg, qdot_msg, trq_msg;
  while (ros::ok()) {
    ros::spinOnce();
    // The book's loop reads position[0] unchecked; before the robot is spawned the arrays are
    // empty, so this one waits for the joint instead of crashing.
    if (!get_jnt_state_client.call(get_joint_state_srv) || !get_joint_state_srv.response.success ||
        get_joint_state_srv.response.position.empty()) {
      ROS_WARN_THROTTLE(5, "cannot read joint1: %s",
                        get_joint_state_srv.response.status_message.c_str());
      rate_timer.sleep();
      continue;
    }
    double q = get_joint_state_srv.response.position[0];
    double qdot = get_joint_state_srv.response.rate[0];
    double trq_cmd = Kp * min_periodicity(g_pos_cmd - q) - Kv * qdot;

    q_msg.data = q;
    qdot_msg.data = qdot;
    trq_msg.data = trq_cmd;
    pos_publisher.publish(q_msg);
    vel_publisher.publish(qdot_msg);
    trq_publisher.publish(trq_msg);

    effort_cmd_srv.request.effort = trq_cmd;
    if (!set_trq_client.call(effort_cmd_srv) || !effort_cmd_srv.response.success) {
      ROS_WARN("service call to apply_joint_effort failed: %s",
               effort_cmd_srv.response.status_message.c_str());
    }
    rate_timer.sleep();
  }
  return 0;
}
