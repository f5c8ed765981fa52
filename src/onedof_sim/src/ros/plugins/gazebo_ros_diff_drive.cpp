// libgazebo_ros_diff_drive.so (gazebo_plugins' GazeboRosDiffDrive): a two-wheeled base driven by
// geometry_msgs/Twist on <commandTopic>, reporting nav_msgs/Odometry on <odometryTopic> and TF
// <odometryFrame> -> <robotBaseFrame> (and parent -> wheel links, and the wheels' joint_states,
// when asked), at <updateRate> of sim time, stamped in sim time.
//
// Its parameters and defaults are Gazebo's; <legacyMode> is kinetic's, default true (the left and
// right wheels' speeds swapped, as the book's robots, which name their right wheel in <leftJoint>,
// expect: noetic's plugin drops the option and turns those robots the wrong way). The wheels are
// driven as Gazebo drives them, a joint motor (World::setJointVelocityCommand) at the wheel speed
// bounded by <wheelTorque>, ramped by <wheelAcceleration> when that is set.
#include <cmath>
#include <mutex>

#include <geometry_msgs/Twist.h>
#include <nav_msgs/Odometry.h>
#include <ros/console.h>
#include <sensor_msgs/JointState.h>
#include <tf2_msgs/TFMessage.h>

#include "conversions.h"
#include "model_plugin.h"
#include "plugin_params.h"
#include "sensors/update_gate.h"

namespace onedof_sim::plugins {
namespace {

enum Side { kRight = 0, kLeft = 1 };

struct DiffDriveParams {
  std::string command_topic = "cmd_vel";
  std::string odometry_topic = "odom";
  std::string odometry_frame = "odom";
  std::string robot_base_frame = "base_footprint";
  bool publish_wheel_tf = false;
  bool publish_odom_tf = true;
  bool publish_wheel_joint_state = false;
  bool publish_tf = true;  // false: no odometry at all, as Gazebo's <publishTf>
  bool legacy_mode = true;
  bool encoder_odometry = false;  // <odometrySource> encoder; world (the default) otherwise
  double wheel_separation = 0.34;
  double wheel_diameter = 0.15;
  double wheel_acceleration = 0.0;
  double wheel_torque = 5.0;
  double update_rate = 100.0;
  std::string joint[2];         // right, left: the model's joints named by the parameters
  std::string wheel_link[2];    // their child links
  std::string wheel_parent[2];  // their parent links
};

ros::Time stamp(int64_t ns) {
  ros::Time time;
  time.fromNSec(static_cast<uint64_t>(ns));
  return time;
}

geometry_msgs::TransformStamped transform(const Pose& pose, const ros::Time& time,
                                          const std::string& parent, const std::string& child) {
  geometry_msgs::TransformStamped out;
  out.header.stamp = time;
  out.header.frame_id = parent;
  out.child_frame_id = child;
  out.transform.translation = toVector3(pose.position);
  const geometry_msgs::Pose msg = toMsg(pose);
  out.transform.rotation = msg.orientation;
  return out;
}

double yawOf(const Quat& q) {
  return std::atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z));
}

class GazeboRosDiffDrive : public ModelPlugin {
 public:
  GazeboRosDiffDrive(const ModelPluginContext& context, const DiffDriveParams& params)
      : model_(context.model), params_(params), node_(context.node) {
    const std::string prefix = tfPrefix(node_);
    odom_frame_ = resolveTfFrame(prefix, params_.odometry_frame);
    base_frame_ = resolveTfFrame(prefix, params_.robot_base_frame);
    for (int side : {kRight, kLeft}) {
      wheel_frame_[side] = resolveTfFrame(prefix, params_.wheel_link[side]);
      wheel_parent_frame_[side] = resolveTfFrame(prefix, params_.wheel_parent[side]);
    }
    {
      std::unique_lock<std::mutex> lock = context.lock_world();
      last_odom_ns_ = context.world->timeNs();
      update_gate_ = UpdateGate(params_.update_rate, last_odom_ns_);
    }
    if (params_.publish_wheel_joint_state)
      joint_state_pub_ = node_.advertise<sensor_msgs::JointState>("joint_states", 1000);
    tf_pub_ = node_.advertise<tf2_msgs::TFMessage>("/tf", 100);
    if (params_.publish_tf)
      odometry_pub_ = node_.advertise<nav_msgs::Odometry>(params_.odometry_topic, 1);
    command_sub_ = node_.subscribe(params_.command_topic, 1, &GazeboRosDiffDrive::onCommand, this);
    ROS_INFO_STREAM("gazebo_ros_diff_drive (" << model_ << "): wheels " << params_.joint[kLeft]
                    << " (left) and " << params_.joint[kRight] << " (right), commands on "
                    << command_sub_.getTopic() << ", odometry on "
                    << (params_.publish_tf ? odometry_pub_.getTopic() : std::string("(none)"))
                    << (params_.legacy_mode ? ", legacy mode" : ""));
  }

  void beforeStep(World& world, const StepTime& at) override {
    if (params_.encoder_odometry) updateEncoderOdometry(world, at.time_ns);
    int64_t elapsed_ns = 0;
    if (update_gate_.due(at.time_ns, &elapsed_ns)) {
      if (params_.publish_tf) publishOdometry(world, at.time_ns);
      if (params_.publish_wheel_tf) publishWheelTf(world, at.time_ns);
      if (params_.publish_wheel_joint_state) publishWheelJointState(world, at.time_ns);
      updateWheelTargets(world, 1e-9 * elapsed_ns);
    }
    // Gazebo's SetParam("vel") holds until the next update; the motor here is set per step.
    const double radius = params_.wheel_diameter / 2;
    for (int side : {kRight, kLeft}) {
      const Status status = world.setJointVelocityCommand(
          scoped(params_.joint[side]), target_[side] / radius, params_.wheel_torque);
      if (!status.ok() && !warned_refusal_) {
        ROS_WARN_STREAM("gazebo_ros_diff_drive (" << model_ << "): the wheel motor of "
                        << params_.joint[side] << " was refused: " << status);
        warned_refusal_ = true;
      }
    }
  }

  // As Gazebo's Reset: the command and the encoder's pose back to zero.
  void reset(World& world) override {
    last_odom_ns_ = world.timeNs();
    update_gate_.restart(last_odom_ns_);
    encoder_ = {};
    target_[kRight] = target_[kLeft] = 0;
    instructed_[kRight] = instructed_[kLeft] = 0;
    std::lock_guard<std::mutex> lock(command_mutex_);
    linear_ = angular_ = 0;
  }

  std::vector<Publication> takePublications() override { return publications_.take(); }

 private:
  struct EncoderPose {
    double x = 0, y = 0, theta = 0;
    double linear_x = 0, linear_y = 0, angular = 0;
  };

  std::string scoped(const std::string& name) const { return model_ + "::" + name; }

  void onCommand(const geometry_msgs::Twist::ConstPtr& msg) {
    std::lock_guard<std::mutex> lock(command_mutex_);
    linear_ = msg->linear.x;
    angular_ = msg->angular.z;
  }

  double jointRate(const World& world, int side) const {
    JointInfo info;
    return world.jointInfo(scoped(params_.joint[side]), &info).ok() ? info.rate : 0;
  }

  // Gazebo's getWheelVelocities and its ramp towards them (<wheelAcceleration>, m/s^2 at the rim).
  void updateWheelTargets(const World& world, double elapsed_s) {
    double linear, angular;
    {
      std::lock_guard<std::mutex> lock(command_mutex_);
      linear = linear_, angular = angular_;
    }
    const double half = angular * params_.wheel_separation / 2;
    const double sign = params_.legacy_mode ? 1 : -1;
    double wanted[2];
    wanted[kLeft] = linear + sign * half;
    wanted[kRight] = linear - sign * half;
    const double radius = params_.wheel_diameter / 2;
    double current[2];
    for (int side : {kRight, kLeft}) current[side] = jointRate(world, side) * radius;
    const double accel = params_.wheel_acceleration;
    if (accel == 0 || std::abs(wanted[kLeft] - current[kLeft]) < 0.01 ||
        std::abs(wanted[kRight] - current[kRight]) < 0.01) {
      target_[kLeft] = wanted[kLeft];
      target_[kRight] = wanted[kRight];
      return;
    }
    for (int side : {kRight, kLeft}) {
      const double gap = wanted[side] - current[side];
      instructed_[side] += gap >= 0 ? std::fmin(gap, accel * elapsed_s)
                                    : std::fmax(gap, -accel * elapsed_s);
      target_[side] = instructed_[side];
    }
  }

  // Dead reckoning from the wheels' rates since the last step (Siegwart's odometry, as Gazebo's
  // UpdateOdometryEncoder).
  void updateEncoderOdometry(const World& world, int64_t now_ns) {
    const double dt = 1e-9 * (now_ns - last_odom_ns_);
    last_odom_ns_ = now_ns;
    if (dt <= 0) return;
    const double radius = params_.wheel_diameter / 2;
    const double left = jointRate(world, kLeft) * radius * dt;
    const double right = jointRate(world, kRight) * radius * dt;
    const double sum = left + right;
    const double diff = params_.legacy_mode ? left - right : right - left;
    const double b = params_.wheel_separation;
    const double dx = sum / 2 * std::cos(encoder_.theta + diff / (2 * b));
    const double dy = sum / 2 * std::sin(encoder_.theta + diff / (2 * b));
    encoder_.x += dx;
    encoder_.y += dy;
    encoder_.theta += diff / b;
    encoder_.angular = diff / b / dt;
    encoder_.linear_x = std::sqrt(dx * dx + dy * dy) / dt;
    encoder_.linear_y = 0;
  }

  void publishOdometry(const World& world, int64_t now_ns) {
    nav_msgs::Odometry odom;
    Pose pose;
    if (params_.encoder_odometry) {
      pose.position = {encoder_.x, encoder_.y, 0};
      pose.orientation = {std::cos(encoder_.theta / 2), 0, 0, std::sin(encoder_.theta / 2)};
      odom.twist.twist.linear.x = encoder_.linear_x;
      odom.twist.twist.linear.y = encoder_.linear_y;
      odom.twist.twist.angular.z = encoder_.angular;
    } else {
      Twist twist;
      if (!world.modelState(model_, "", &pose, &twist).ok()) return;
      const double yaw = yawOf(pose.orientation);
      odom.twist.twist.angular.z = twist.angular.z;
      // The base's velocity in its own heading, as Gazebo turns it (by the yaw alone).
      odom.twist.twist.linear.x = std::cos(yaw) * twist.linear.x + std::sin(yaw) * twist.linear.y;
      odom.twist.twist.linear.y = std::cos(yaw) * twist.linear.y - std::sin(yaw) * twist.linear.x;
    }
    odom.pose.pose = toMsg(pose);
    const ros::Time time = stamp(now_ns);
    if (params_.publish_odom_tf) {
      tf2_msgs::TFMessage tf;
      tf.transforms.push_back(transform(pose, time, odom_frame_, base_frame_));
      publishTf(tf);
    }
    odom.pose.covariance[0] = 0.00001;
    odom.pose.covariance[7] = 0.00001;
    odom.pose.covariance[14] = 1000000000000.0;
    odom.pose.covariance[21] = 1000000000000.0;
    odom.pose.covariance[28] = 1000000000000.0;
    odom.pose.covariance[35] = 0.001;
    odom.header.stamp = time;
    odom.header.frame_id = odom_frame_;
    odom.child_frame_id = base_frame_;
    publications_.add(odometry_pub_, odom);
  }

  // Each wheel link in its joint's parent link.
  void publishWheelTf(const World& world, int64_t now_ns) {
    tf2_msgs::TFMessage tf;
    for (int side : {kRight, kLeft}) {
      Pose pose;
      Twist twist;
      if (!world.linkState(scoped(params_.wheel_link[side]), scoped(params_.wheel_parent[side]),
                           &pose, &twist).ok())
        continue;
      tf.transforms.push_back(
          transform(pose, stamp(now_ns), wheel_parent_frame_[side], wheel_frame_[side]));
    }
    publishTf(tf);
  }

  void publishWheelJointState(const World& world, int64_t now_ns) {
    sensor_msgs::JointState state;
    state.header.stamp = stamp(now_ns);
    for (int side : {kRight, kLeft}) {
      JointInfo info;
      if (!world.jointInfo(scoped(params_.joint[side]), &info).ok()) continue;
      state.name.push_back(info.name);
      state.position.push_back(info.position);
    }
    publications_.add(joint_state_pub_, state);
  }

  void publishTf(const tf2_msgs::TFMessage& tf) {
    publications_.add(tf_pub_, tf);
  }

  std::string model_;
  DiffDriveParams params_;
  ros::NodeHandle node_;
  std::string odom_frame_, base_frame_, wheel_frame_[2], wheel_parent_frame_[2];
  UpdateGate update_gate_;
  int64_t last_odom_ns_ = 0;
  double target_[2] = {0, 0};      // the wheels' rim speeds the motors drive to, m/s
  double instructed_[2] = {0, 0};  // the ramp's speeds (<wheelAcceleration>)
  EncoderPose encoder_;
  bool warned_refusal_ = false;
  std::mutex command_mutex_;
  double linear_ = 0, angular_ = 0;  // the last command, guarded by command_mutex_
  PublicationQueue publications_;
  ros::Publisher odometry_pub_, joint_state_pub_, tf_pub_;
  ros::Subscriber command_sub_;
};

bool readParams(const ModelPluginContext& context, DiffDriveParams* p, std::string* error) {
  const PluginParams params(context.plugin_xml, "gazebo_ros_diff_drive (" + context.model + ")");
  applyRosDebugLevel(params.text("rosDebugLevel", "na"));
  p->command_topic = params.text("commandTopic", p->command_topic);
  p->odometry_topic = params.text("odometryTopic", p->odometry_topic);
  p->odometry_frame = params.text("odometryFrame", p->odometry_frame);
  p->robot_base_frame = params.text("robotBaseFrame", p->robot_base_frame);
  p->publish_wheel_tf = params.flag("publishWheelTF", p->publish_wheel_tf);
  p->publish_odom_tf = params.flag("publishOdomTF", p->publish_odom_tf);
  p->publish_wheel_joint_state = params.flag("publishWheelJointState", p->publish_wheel_joint_state);
  p->publish_tf = params.flag("publishTf", p->publish_tf);
  p->legacy_mode = params.flag("legacyMode", p->legacy_mode);
  if (!params.has("legacyMode"))
    ROS_WARN_STREAM(params.label() << ": missing <legacyMode>, defaults to true: <leftJoint>'s "
                    "wheel goes faster on a positive angular.z, as for robots that name their "
                    "right wheel there; set it false for a new robot");
  if (!params.number("wheelSeparation", p->wheel_separation, &p->wheel_separation, error) ||
      !params.number("wheelDiameter", p->wheel_diameter, &p->wheel_diameter, error) ||
      !params.number("wheelAcceleration", p->wheel_acceleration, &p->wheel_acceleration, error) ||
      !params.number("wheelTorque", p->wheel_torque, &p->wheel_torque, error) ||
      !params.number("updateRate", p->update_rate, &p->update_rate, error))
    return false;
  if (p->wheel_diameter <= 0 || p->wheel_separation <= 0) {
    *error = "<wheelDiameter> and <wheelSeparation> must be positive";
    return false;
  }
  if (p->wheel_torque < 0) {
    *error = "<wheelTorque> must not be negative";
    return false;
  }
  const std::string source = params.text("odometrySource", "world");
  if (source != "world" && source != "encoder") {
    *error = "<odometrySource> is '" + source + "'; it is world or encoder";
    return false;
  }
  p->encoder_odometry = source == "encoder";
  p->joint[kLeft] = params.text("leftJoint", "left_joint");
  p->joint[kRight] = params.text("rightJoint", "right_joint");
  return true;
}

}  // namespace

std::unique_ptr<ModelPlugin> makeGazeboRosDiffDrive(const ModelPluginContext& context,
                                                    std::string* error) {
  DiffDriveParams params;
  if (!readParams(context, &params, error)) return nullptr;
  for (int side : {kRight, kLeft}) {
    const std::string& joint = params.joint[side];
    if (!jointLinks(context, joint, &params.wheel_parent[side], &params.wheel_link[side])) {
      *error = "couldn't get wheel hinge joint named " + joint;
      return nullptr;
    }
    std::unique_lock<std::mutex> lock = context.lock_world();
    JointInfo info;
    if (!context.world->jointInfo(context.model + "::" + joint, &info).ok() ||
        info.type == JointType::Fixed || info.type == JointType::Prismatic) {
      *error = "couldn't get wheel hinge joint named " + joint;
      return nullptr;
    }
  }
  return std::make_unique<GazeboRosDiffDrive>(context, params);
}

}  // namespace onedof_sim::plugins
