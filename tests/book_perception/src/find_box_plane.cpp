// The book's pcl_utils in small: the Kinect's cloud arrives through pcl_ros as a
// pcl::PointCloud, a goal of the find_box_plane action fits planes to the next one with PCL's
// RANSAC, one after another, each to the points the planes before it left (the largest first: a
// floor, then a face on it), and the answer goes back as the action's result and as an
// interactive marker on each plane's inliers.
#include <mutex>
#include <string>
#include <vector>

#include <actionlib/server/simple_action_server.h>
#include <book_perception/FindPlaneAction.h>
#include <interactive_markers/interactive_marker_server.h>
#include <pcl/common/centroid.h>
#include <pcl/common/io.h>
#include <pcl/filters/filter.h>
#include <pcl/sample_consensus/method_types.h>
#include <pcl/sample_consensus/model_types.h>
#include <pcl/segmentation/sac_segmentation.h>
#include <pcl_ros/point_cloud.h>
#include <ros/ros.h>
#include <tf/transform_datatypes.h>
#include <tf_conversions/tf_eigen.h>

using Cloud = pcl::PointCloud<pcl::PointXYZ>;
// How roscpp hands a message over (PCL's own Cloud::ConstPtr is a std::shared_ptr).
using CloudPtr = boost::shared_ptr<const Cloud>;

class PlaneFinder {
 public:
  explicit PlaneFinder(ros::NodeHandle& nh)
      : server_(nh, "find_box_plane",
                [this](const book_perception::FindPlaneGoalConstPtr& goal) { execute(goal); },
                false),
        markers_("box_plane") {
    clouds_ = nh.subscribe<Cloud>("cloud", 1, &PlaneFinder::heard, this);
    server_.start();
  }

 private:
  void heard(const CloudPtr& cloud) {
    std::lock_guard<std::mutex> lock(mutex_);
    latest_ = cloud;
    ++count_;
  }

  // The first cloud that arrives after the goal: a cloud already held may be older than it.
  CloudPtr next_cloud(int& seen) {
    int start;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      start = count_;
    }
    ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(120.0);
    while (ros::ok() && ros::WallTime::now() < deadline) {
      {
        std::lock_guard<std::mutex> lock(mutex_);
        if (count_ > start) {
          seen = count_;
          return latest_;
        }
      }
      ros::WallDuration(0.01).sleep();
    }
    return CloudPtr();
  }

  void execute(const book_perception::FindPlaneGoalConstPtr& goal) {
    book_perception::FindPlaneFeedback feedback;
    CloudPtr cloud = next_cloud(feedback.clouds_seen);
    if (!cloud) {
      server_.setAborted(book_perception::FindPlaneResult(), "no cloud on " + clouds_.getTopic());
      return;
    }
    server_.publishFeedback(feedback);
    Cloud::Ptr points(new Cloud);
    std::vector<int> kept;
    pcl::removeNaNFromPointCloud(*cloud, *points, kept);

    book_perception::FindPlaneResult result;
    result.frame_id = cloud->header.frame_id;
    for (int plane = 0; plane < goal->planes; ++plane) {
      pcl::PointIndices inliers;
      Eigen::Vector4d coefficients;
      if (!fit_plane(points, *goal, &inliers, &coefficients)) {
        server_.setAborted(result, "no plane " + std::to_string(plane) + " in the cloud");
        return;
      }
      Eigen::Vector4f centroid;
      pcl::compute3DCentroid(*points, inliers, centroid);
      Eigen::Affine3d face = Eigen::Translation3d(centroid.head<3>().cast<double>()) *
          Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitX(),
                                             coefficients.head<3>());
      result.coefficients.insert(result.coefficients.end(), coefficients.data(),
                                 coefficients.data() + 4);
      result.inliers.push_back(static_cast<int>(inliers.indices.size()));
      tf::Pose pose;
      tf::poseEigenToTF(face, pose);
      result.faces.emplace_back();
      tf::poseTFToMsg(pose, result.faces.back());
      points = without(points, inliers);
    }
    show(result);
    server_.setSucceeded(result);
  }

  // RANSAC's plane in `points`: its inliers and its coefficients, the normal a unit vector facing
  // the sensor (at the frame's origin: d > 0). False when it finds none.
  static bool fit_plane(const Cloud::Ptr& points, const book_perception::FindPlaneGoal& goal,
                        pcl::PointIndices* inliers, Eigen::Vector4d* coefficients) {
    pcl::SACSegmentation<pcl::PointXYZ> ransac;
    ransac.setModelType(pcl::SACMODEL_PLANE);
    ransac.setMethodType(pcl::SAC_RANSAC);
    ransac.setMaxIterations(goal.max_iterations);
    ransac.setDistanceThreshold(goal.distance_threshold);
    ransac.setInputCloud(points);
    pcl::ModelCoefficients plane;
    ransac.segment(*inliers, plane);
    if (inliers->indices.empty()) return false;
    *coefficients = Eigen::Vector4d(plane.values[0], plane.values[1], plane.values[2],
                                    plane.values[3]);
    *coefficients /= coefficients->head<3>().norm();
    if ((*coefficients)[3] < 0) *coefficients = -*coefficients;
    return true;
  }

  // The points of `points` that are not among `inliers`.
  static Cloud::Ptr without(const Cloud::Ptr& points, const pcl::PointIndices& inliers) {
    std::vector<bool> taken(points->size(), false);
    for (int index : inliers.indices) taken[index] = true;
    std::vector<int> rest;
    for (int index = 0; index < static_cast<int>(points->size()); ++index)
      if (!taken[index]) rest.push_back(index);
    Cloud::Ptr out(new Cloud);
    pcl::copyPointCloud(*points, rest, *out);
    return out;
  }

  // An arrow on each plane's inliers' centroid along its normal, named plane_0, plane_1, ...
  void show(const book_perception::FindPlaneResult& result) {
    for (size_t plane = 0; plane < result.faces.size(); ++plane) {
      visualization_msgs::InteractiveMarker marker;
      marker.header.frame_id = result.frame_id;
      marker.name = "plane_" + std::to_string(plane);
      marker.pose = result.faces[plane];
      visualization_msgs::Marker arrow;
      arrow.type = visualization_msgs::Marker::ARROW;
      arrow.scale.x = 0.3;
      arrow.scale.y = arrow.scale.z = 0.02;
      arrow.color.g = arrow.color.a = 1.0;
      visualization_msgs::InteractiveMarkerControl control;
      control.always_visible = true;
      control.markers.push_back(arrow);
      marker.controls.push_back(control);
      markers_.insert(marker);
    }
    markers_.applyChanges();
  }

  actionlib::SimpleActionServer<book_perception::FindPlaneAction> server_;
  interactive_markers::InteractiveMarkerServer markers_;
  ros::Subscriber clouds_;
  std::mutex mutex_;
  CloudPtr latest_;
  int count_ = 0;
};

int main(int argc, char** argv) {
  ros::init(argc, argv, "find_box_plane");
  ros::NodeHandle nh;
  PlaneFinder finder(nh);
  ros::AsyncSpinner spinner(2);
  spinner.start();
  ros::waitForShutdown();
  return 0;
}
