// The one list of model plugins and the one list of sensor plugins: each is one file in this
// folder and one entry here, keyed by the filename a URDF's <gazebo><plugin> or an SDF's
// <plugin> names, as Gazebo loads it (a sensor plugin: inside a <sensor> of the types it takes).
#include "registry.h"

namespace onedof_sim::plugins {

std::unique_ptr<ModelPlugin> makeGazeboRosControl(const ModelPluginContext&, std::string*);
std::unique_ptr<ModelPlugin> makeGazeboRosDiffDrive(const ModelPluginContext&, std::string*);
std::unique_ptr<ModelPlugin> makeGazeboRosFtSensor(const ModelPluginContext&, std::string*);
std::unique_ptr<ModelPlugin> makeGazeboRosImu(const ModelPluginContext&, std::string*);
std::unique_ptr<ModelPlugin> makeGazeboRosP3d(const ModelPluginContext&, std::string*);
std::unique_ptr<ModelPlugin> makeGazeboRosJointStatePublisher(const ModelPluginContext&,
                                                              std::string*);
std::unique_ptr<ModelPlugin> makeGazeboRosBlockLaser(const SensorPluginContext&, std::string*);
std::unique_ptr<ModelPlugin> makeGazeboRosBumper(const SensorPluginContext&, std::string*);
std::unique_ptr<ModelPlugin> makeGazeboRosCamera(const SensorPluginContext&, std::string*);
std::unique_ptr<ModelPlugin> makeGazeboRosDepthCamera(const SensorPluginContext&, std::string*);
std::unique_ptr<ModelPlugin> makeGazeboRosImuSensor(const SensorPluginContext&, std::string*);
std::unique_ptr<ModelPlugin> makeGazeboRosLaser(const SensorPluginContext&, std::string*);
std::unique_ptr<ModelPlugin> makeGazeboRosMultiCamera(const SensorPluginContext&, std::string*);
std::unique_ptr<ModelPlugin> makeGazeboRosOpenniKinect(const SensorPluginContext&,
                                                       std::string*);
std::unique_ptr<ModelPlugin> makeGazeboRosRange(const SensorPluginContext&, std::string*);
std::unique_ptr<ModelPlugin> makeGazeboRosTriggeredCamera(const SensorPluginContext&,
                                                          std::string*);

const std::vector<ModelPluginType>& modelPluginRegistry() {
  static const std::vector<ModelPluginType> entries{
      {"libgazebo_ros_control.so", makeGazeboRosControl},
      {"libgazebo_ros_diff_drive.so", makeGazeboRosDiffDrive},
      {"libgazebo_ros_ft_sensor.so", makeGazeboRosFtSensor},
      {"libgazebo_ros_imu.so", makeGazeboRosImu},
      {"libgazebo_ros_joint_state_publisher.so", makeGazeboRosJointStatePublisher},
      {"libgazebo_ros_p3d.so", makeGazeboRosP3d},
  };
  return entries;
}

const std::vector<SensorPluginType>& sensorPluginRegistry() {
  static const std::vector<SensorPluginType> entries{
      {"libgazebo_ros_block_laser.so", {"ray"}, makeGazeboRosBlockLaser},
      {"libgazebo_ros_bumper.so", {"contact"}, makeGazeboRosBumper},
      {"libgazebo_ros_camera.so", {"camera"}, makeGazeboRosCamera},
      {"libgazebo_ros_depth_camera.so", {"depth"}, makeGazeboRosDepthCamera},
      {"libgazebo_ros_gpu_laser.so", {"gpu_ray"}, makeGazeboRosLaser},
      {"libgazebo_ros_imu_sensor.so", {"imu"}, makeGazeboRosImuSensor},
      {"libgazebo_ros_laser.so", {"ray"}, makeGazeboRosLaser},
      {"libgazebo_ros_multicamera.so", {"multicamera"}, makeGazeboRosMultiCamera},
      {"libgazebo_ros_openni_kinect.so", {"depth"}, makeGazeboRosOpenniKinect},
      {"libgazebo_ros_range.so", {"ray"}, makeGazeboRosRange},
      {"libgazebo_ros_triggered_camera.so", {"camera"}, makeGazeboRosTriggeredCamera},
  };
  return entries;
}

}  // namespace onedof_sim::plugins
