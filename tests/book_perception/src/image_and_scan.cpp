// The book's example_opencv and lidar_wobbler in small: an image through image_transport and
// cv_bridge (OpenCV's BGR), whose red pixels' first and last columns in the middle row are
// printed, and scans projected to clouds by laser_geometry, whose point counts are printed.
#include <cv_bridge/cv_bridge.h>
#include <image_transport/image_transport.h>
#include <laser_geometry/laser_geometry.h>
#include <ros/ros.h>
#include <sensor_msgs/PointCloud2.h>

namespace {

void red_columns(const sensor_msgs::ImageConstPtr& image) {
  cv::Mat bgr = cv_bridge::toCvShare(image, "bgr8")->image;
  const int row = bgr.rows / 2;
  int first = -1, last = -1;
  for (int u = 0; u < bgr.cols; ++u) {
    const cv::Vec3b& pixel = bgr.at<cv::Vec3b>(row, u);
    if (pixel[2] > 80 && pixel[1] < 30 && pixel[0] < 30) {
      if (first < 0) first = u;
      last = u;
    }
  }
  ROS_INFO("red columns %d %d", first, last);
}

laser_geometry::LaserProjection projection;

void scan_points(const sensor_msgs::LaserScanConstPtr& scan) {
  sensor_msgs::PointCloud2 cloud;
  projection.projectLaser(*scan, cloud);
  ROS_INFO("scan points %u", cloud.width * cloud.height);
}

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "image_and_scan");
  ros::NodeHandle nh;
  image_transport::ImageTransport transport(nh);
  image_transport::Subscriber images = transport.subscribe("image", 1, red_columns);
  ros::Subscriber scans = nh.subscribe("scan", 1, scan_points);
  ros::spin();
  return 0;
}
