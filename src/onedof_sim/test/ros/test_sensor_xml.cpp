// The sensors' XML readers, no roscore: a model's <sensor>s as the plugins find them
// (findSensors, findModelPlugins, withRobotNamespace), the <ray>, <camera> and <imu> elements with
// SDF's defaults and their refusals, a sensor's numbers and <pose>, and the update gates.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include <onedof_sim/pose_math.h>
#include <tinyxml2.h>

#include "plugins/model_plugins.h"
#include "sensors/camera_sensor.h"
#include "sensors/imu_measurement.h"
#include "sensors/ray_sensor.h"
#include "sensors/sensor_xml.h"
#include "sensors/update_gate.h"

namespace onedof_sim::plugins {
namespace {

std::string sensor(const std::string& type, const std::string& body) {
  return "<sensor type='" + type + "' name='s'>" + body + "</sensor>";
}

void expectNear(const Quat& a, const Quat& b) {
  EXPECT_NEAR(a.w, b.w, 1e-12);
  EXPECT_NEAR(a.x, b.x, 1e-12);
  EXPECT_NEAR(a.y, b.y, 1e-12);
  EXPECT_NEAR(a.z, b.z, 1e-12);
}

TEST(SensorXml, FindsAUrdfsSensorsWithTheirLinkPoseRateAndPlugins) {
  const std::string urdf =
      "<robot name='r'><link name='base'/>"
      "<gazebo reference='base'><sensor type='ray' name='laser'>"
      "<pose> 0.1 0 0.2 0 0 1.5 </pose><update_rate>40</update_rate><always_on>1</always_on>"
      "<visualize>false</visualize>"
      "<plugin name='p' filename='libgazebo_ros_laser.so'><robotNamespace>/ns</robotNamespace>"
      "</plugin></sensor></gazebo>"
      "<gazebo><plugin name='d' filename='libgazebo_ros_diff_drive.so'/></gazebo>"
      "<gazebo reference='base'><sensor type='imu' name='imu'><pose>1 2 3</pose></sensor>"
      "</gazebo></robot>";
  const std::vector<SensorElement> sensors = findSensors(urdf, ModelFormat::Urdf);
  ASSERT_EQ(sensors.size(), 2u);
  const SensorElement& laser = sensors[0];
  EXPECT_EQ(laser.name, "laser");
  EXPECT_EQ(laser.type, "ray");
  EXPECT_EQ(laser.link, "base");
  EXPECT_EQ(laser.error, "");
  EXPECT_EQ(laser.pose.position.x, 0.1);
  EXPECT_EQ(laser.pose.position.z, 0.2);
  expectNear(laser.pose.orientation, fromRpy(0, 0, 1.5));
  EXPECT_EQ(laser.update_rate, 40);
  EXPECT_TRUE(laser.always_on);
  EXPECT_FALSE(laser.visualize);
  ASSERT_EQ(laser.plugins.size(), 1u);
  EXPECT_EQ(laser.plugins[0].filename, "libgazebo_ros_laser.so");
  EXPECT_EQ(laser.plugins[0].robot_namespace, "/ns");
  EXPECT_EQ(sensors[1].error, "<pose> is '1 2 3', not six numbers");
  // The model plugins are those outside a <sensor>.
  const std::vector<PluginElement> plugins = findModelPlugins(urdf, ModelFormat::Urdf);
  ASSERT_EQ(plugins.size(), 1u);
  EXPECT_EQ(plugins[0].name, "d");
}

TEST(SensorXml, FindsAnSdfsSensorsOnTheirLinks) {
  const std::string sdf =
      "<sdf version='1.6'><model name='m'><link name='a'>"
      "<sensor type='camera' name='cam'><update_rate>abc</update_rate></sensor></link>"
      "<link name='b'><sensor name='nameless_type'/></link>"
      "<plugin name='p' filename='libgazebo_ros_p3d.so'/></model></sdf>";
  const std::vector<SensorElement> sensors = findSensors(sdf, ModelFormat::Sdf);
  ASSERT_EQ(sensors.size(), 2u);
  EXPECT_EQ(sensors[0].link, "a");
  EXPECT_EQ(sensors[0].error, "<update_rate> is 'abc', not a number of Hz >= 0");
  EXPECT_EQ(sensors[1].link, "b");
  EXPECT_EQ(sensors[1].error, "it has no type");
  EXPECT_EQ(findModelPlugins(sdf, ModelFormat::Sdf).size(), 1u);
  EXPECT_TRUE(findSensors("not xml", ModelFormat::Urdf).empty());
}

TEST(SensorXml, GivesTheSpawnsNamespaceToPluginsWithoutOne) {
  const std::string urdf =
      "<robot name='r'><gazebo><plugin name='a' filename='x.so'/>"
      "<plugin name='b' filename='y.so'><robotNamespace>/own</robotNamespace></plugin></gazebo>"
      "</robot>";
  const std::vector<PluginElement> plugins =
      findModelPlugins(withRobotNamespace(urdf, "/spawned"), ModelFormat::Urdf);
  ASSERT_EQ(plugins.size(), 2u);
  EXPECT_EQ(plugins[0].robot_namespace, "/spawned");
  EXPECT_EQ(plugins[1].robot_namespace, "/own");
  EXPECT_EQ(withRobotNamespace(urdf, ""), urdf);
}

TEST(SensorXml, ReadsARayWithSdfsDefaultsAndItsNoise) {
  RayConfig c;
  std::string error;
  ASSERT_TRUE(readRayConfig(sensor("ray", "<ray><scan><horizontal><samples>5</samples>"
                                          "<min_angle>-1</min_angle><max_angle>1</max_angle>"
                                          "</horizontal></scan><range><min>0.1</min><max>10</max>"
                                          "</range><noise type='gaussian'><stddev>0.01</stddev>"
                                          "</noise></ray>"),
                            &c, &error))
      << error;
  EXPECT_EQ(c.samples, 5);
  EXPECT_EQ(c.rangeCount(), 5);
  EXPECT_EQ(c.verticalRangeCount(), 1);
  EXPECT_DOUBLE_EQ(c.angleIncrement(), 0.5);
  EXPECT_EQ(c.range_min, 0.1);
  EXPECT_EQ(c.range_max, 10);
  EXPECT_TRUE(c.noise.on);
  EXPECT_EQ(c.noise.stddev, 0.01);
  // SDF's default: 640 rays.
  ASSERT_TRUE(readRayConfig(sensor("ray", "<ray><range><max>1</max></range></ray>"), &c, &error));
  EXPECT_EQ(c.samples, 640);
  EXPECT_FALSE(c.noise.on);
}

TEST(SensorXml, RefusesAMalformedRayNamingWhatIsWrong) {
  RayConfig c;
  std::string error;
  EXPECT_FALSE(readRayConfig(sensor("ray", ""), &c, &error));
  EXPECT_EQ(error, "it has no <ray>");
  EXPECT_FALSE(readRayConfig(sensor("ray", "<ray><range><min>1</min><max>1</max></range></ray>"),
                             &c, &error));
  EXPECT_EQ(error, "<range> is min 1.000000 max 1.000000: it needs 0 <= min < max");
  EXPECT_FALSE(readRayConfig(
      sensor("ray", "<ray><scan><horizontal><samples>2.5</samples></horizontal></scan></ray>"), &c,
      &error));
  EXPECT_EQ(error, "<horizontal><samples> is 2.500000, not a count of rays");
  EXPECT_FALSE(readRayConfig(
      sensor("ray", "<ray><range><max>1</max></range><noise type='gaussian'>"
                    "<bias_stddev>x</bias_stddev></noise></ray>"),
      &c, &error));
  EXPECT_EQ(error, "<ray><noise><bias_stddev> is 'x', not a number");
  EXPECT_FALSE(readRayConfig("<sensor", &c, &error));
  EXPECT_EQ(error, "the <sensor> is not XML");
}

TEST(SensorXml, ReadsACameraWithSdfsDefaultsItsPoseAndItsNoise) {
  CameraConfig c;
  std::string error;
  ASSERT_TRUE(readCameraConfig(sensor("camera", "<camera/>"), &c, &error)) << error;
  EXPECT_EQ(c.horizontal_fov, 1.047);
  EXPECT_EQ(c.width, 320);
  EXPECT_EQ(c.height, 240);
  EXPECT_EQ(c.pixel_format, PixelFormat::Rgb8);
  EXPECT_EQ(c.name, "__default__");
  EXPECT_TRUE(c.distortion.none());
  EXPECT_FALSE(c.noise.on);
  ASSERT_TRUE(readCameraConfig(
      sensor("camera", "<camera><horizontal_fov>1.2</horizontal_fov><image><width>64</width>"
                       "<height>48</height><format>B8G8R8</format></image><clip><near>0.05</near>"
                       "<far>30</far></clip><pose>0 0 0.1 0 0.5 0</pose>"
                       "<noise><type>gaussian</type><mean>0</mean><stddev>0.007</stddev></noise>"
                       "</camera>"),
      &c, &error))
      << error;
  EXPECT_EQ(c.width, 64);
  EXPECT_EQ(c.pixel_format, PixelFormat::Bgr8);
  EXPECT_EQ(c.far_clip, 30);
  EXPECT_EQ(c.pose.position.z, 0.1);
  expectNear(c.pose.orientation, fromRpy(0, 0.5, 0));
  EXPECT_TRUE(c.noise.on);
  EXPECT_EQ(c.noise.stddev, 0.007);
}

TEST(SensorXml, RefusesAMalformedCameraNamingWhatIsWrong) {
  CameraConfig c;
  std::string error;
  EXPECT_FALSE(readCameraConfig(sensor("camera", ""), &c, &error));
  EXPECT_EQ(error, "it has no <camera>");
  EXPECT_FALSE(readCameraConfig(sensor("camera", "<camera><image><format>FLOAT32</format>"
                                                 "</image></camera>"),
                                &c, &error));
  EXPECT_EQ(error, "<image><format> is 'FLOAT32': gazebo_ros's cameras publish R8G8B8, B8G8R8, "
                   "L8, R16G16B16, L16 and BAYER_RGGB8, _BGGR8, _GBRG8, _GRBG8 images");
  EXPECT_FALSE(readCameraConfig(sensor("camera", "<camera><distortion><k1>x</k1></distortion>"
                                                 "</camera>"),
                                &c, &error));
  EXPECT_EQ(error, "<distortion><k1> is 'x', not a number");
  EXPECT_FALSE(readCameraConfig(sensor("camera", "<camera><distortion><center>0.5</center>"
                                                 "</distortion></camera>"),
                                &c, &error));
  EXPECT_EQ(error, "<distortion><center> is '0.5', not two numbers");
  EXPECT_FALSE(readCameraConfig(sensor("camera", "<camera><horizontal_fov>3.2</horizontal_fov>"
                                                 "</camera>"),
                                &c, &error));
  EXPECT_EQ(error, "<camera><horizontal_fov> is 3.2 rad: a camera is rendered here with a field "
                   "of view in (0, pi) rad");
  EXPECT_FALSE(readCameraConfig(sensor("camera", "<camera><clip><near>2</near><far>1</far></clip>"
                                                 "</camera>"),
                                &c, &error));
  EXPECT_EQ(error, "<clip> is near 2 far 1: it needs 0 < near < far");
  EXPECT_FALSE(readCameraConfig(sensor("camera", "<camera><pose>0 0 0 0 0 nan</pose></camera>"),
                                &c, &error));
  EXPECT_EQ(error, "<camera><pose> is '0 0 0 0 0 nan', not six numbers");
  EXPECT_FALSE(readCameraConfig(sensor("camera", "<camera><noise type='gaussian'>"
                                                 "<stddev>-1</stddev></noise></camera>"),
                                &c, &error));
  EXPECT_EQ(error, "<camera><noise> has a negative stddev, bias_stddev, dynamic_bias_stddev, "
                   "dynamic_bias_correlation_time or precision");
}

TEST(SensorXml, ReadsEveryFormatGazeboRosPublishesByItsNames) {
  const std::pair<const char*, PixelFormat> names[] = {
      {"R8G8B8", PixelFormat::Rgb8},        {"RGB_INT8", PixelFormat::Rgb8},
      {"B8G8R8", PixelFormat::Bgr8},        {"L8", PixelFormat::Mono8},
      {"L_INT8", PixelFormat::Mono8},       {"L16", PixelFormat::Mono16},
      {"L_UINT16", PixelFormat::Mono16},    {"R16G16B16", PixelFormat::Rgb16},
      {"RGB_INT16", PixelFormat::Rgb16},    {"BAYER_RGGB8", PixelFormat::BayerRggb8},
      {"BAYER_GRBG8", PixelFormat::BayerGrbg8}};
  for (const auto& [name, format] : names) {
    CameraConfig c;
    std::string error;
    ASSERT_TRUE(readCameraConfig(sensor("camera", std::string("<camera><image><format>") + name +
                                                      "</format></image></camera>"),
                                 &c, &error))
        << name << ": " << error;
    EXPECT_EQ(c.pixel_format, format) << name;
  }
  EXPECT_STREQ(encodingOf(PixelFormat::Mono16), "mono16");
  EXPECT_STREQ(encodingOf(PixelFormat::BayerGbrg8), "bayer_gbrg8");
  EXPECT_EQ(bytesPerPixel(PixelFormat::Rgb16), 6);
  EXPECT_TRUE(sixteenBits(PixelFormat::Mono16));
  EXPECT_FALSE(sixteenBits(PixelFormat::BayerRggb8));
}

TEST(SensorXml, ReadsALensAndAMulticamerasCamerasInOrder) {
  std::vector<CameraConfig> cameras;
  std::string error;
  ASSERT_TRUE(readCameraConfigs(
      sensor("multicamera", "<camera name='left'><distortion><k1>-0.2</k1><p2>0.01</p2>"
                            "<center>0.4 0.6</center></distortion></camera>"
                            "<camera name='right'><pose>0 -0.07 0 0 0 0</pose></camera>"),
      &cameras, &error))
      << error;
  ASSERT_EQ(cameras.size(), 2u);
  EXPECT_EQ(cameras[0].name, "left");
  EXPECT_EQ(cameras[0].distortion.k1, -0.2);
  EXPECT_EQ(cameras[0].distortion.p2, 0.01);
  EXPECT_EQ(cameras[0].distortion.center_x, 0.4);
  EXPECT_EQ(cameras[0].distortion.center_y, 0.6);
  EXPECT_EQ(cameras[1].name, "right");
  EXPECT_EQ(cameras[1].pose.position.y, -0.07);
  EXPECT_TRUE(cameras[1].distortion.none());
  EXPECT_FALSE(readCameraConfigs(
      sensor("multicamera", "<camera name='left'/><camera name='right'><clip><near>0</near>"
                            "</clip></camera>"),
      &cameras, &error));
  EXPECT_EQ(error, "camera 'right': <clip> is near 0 far 100: it needs 0 < near < far");
  EXPECT_TRUE(cameras.empty());
  EXPECT_FALSE(readCameraConfigs(sensor("multicamera", ""), &cameras, &error));
  EXPECT_EQ(error, "it has no <camera>");
}

TEST(SensorXml, EncodesAFramesPixelsInEachFormat) {
  render::Frame frame;
  frame.width = 2, frame.height = 2;
  // Red, green / blue, grey (r g b), and 16-bit values whose bytes tell their order.
  frame.rgb = {200, 0, 0, 0, 100, 0, 0, 0, 50, 10, 20, 30};
  std::vector<uint8_t> out(12);
  encodePixels(PixelFormat::Bgr8, frame, out.data());
  EXPECT_EQ(out, (std::vector<uint8_t>{0, 0, 200, 0, 100, 0, 50, 0, 0, 30, 20, 10}));
  encodePixels(PixelFormat::Mono8, frame, out.data());
  // (299 r + 587 g + 114 b + 500) / 1000
  EXPECT_EQ(std::vector<uint8_t>(out.begin(), out.begin() + 4),
            (std::vector<uint8_t>{60, 59, 6, 18}));
  const std::pair<PixelFormat, std::vector<uint8_t>> bayer[] = {
      {PixelFormat::BayerRggb8, {200, 100, 0, 30}}, {PixelFormat::BayerBggr8, {0, 100, 0, 10}},
      {PixelFormat::BayerGbrg8, {0, 0, 0, 20}},     {PixelFormat::BayerGrbg8, {0, 0, 50, 20}}};
  for (const auto& [format, expected] : bayer) {
    encodePixels(format, frame, out.data());
    EXPECT_EQ(std::vector<uint8_t>(out.begin(), out.begin() + 4), expected)
        << encodingOf(format);
  }
  frame.rgb.clear();
  frame.rgb16 = {0x0102, 0, 0, 0, 0x0304, 0, 0, 0, 0x0506, 1000, 2000, 3000};
  encodePixels(PixelFormat::Rgb16, frame, out.data());
  EXPECT_EQ(std::vector<uint8_t>(out.begin(), out.begin() + 6),
            (std::vector<uint8_t>{0x02, 0x01, 0, 0, 0, 0}));  // little-endian
  encodePixels(PixelFormat::Mono16, frame, out.data());
  EXPECT_EQ(out[4] | out[5] << 8, 147);   // (114 x 1286 + 500) / 1000
  EXPECT_EQ(out[6] | out[7] << 8, 1815);  // (299 x 1000 + 587 x 2000 + 114 x 3000 + 500) / 1000
}

TEST(SensorXml, ReadsAnImusNoisePerAxisAndSdf14sForAll) {
  ImuNoiseParams p;
  std::string error;
  ASSERT_TRUE(readImuNoise(sensor("imu", ""), &p, &error));
  EXPECT_FALSE(p.any());
  ASSERT_TRUE(readImuNoise(
      sensor("imu", "<imu><angular_velocity><y><noise type='gaussian'><stddev>0.2</stddev>"
                    "<dynamic_bias_stddev>0.1</dynamic_bias_stddev>"
                    "<dynamic_bias_correlation_time>10</dynamic_bias_correlation_time>"
                    "</noise></y></angular_velocity></imu>"),
      &p, &error))
      << error;
  EXPECT_FALSE(p.rate[0].on);
  EXPECT_TRUE(p.rate[1].on);
  EXPECT_EQ(p.rate[1].stddev, 0.2);
  EXPECT_FALSE(p.acceleration[1].on);
  EXPECT_TRUE(p.drifts());
  // SDF 1.4: one <noise> for every axis (type gaussian when it names none); the per-axis
  // elements win.
  ASSERT_TRUE(readImuNoise(
      sensor("imu", "<imu><noise><rate><stddev>0.3</stddev></rate><accel><mean>1</mean>"
                    "<stddev>0.4</stddev></accel></noise><linear_acceleration><z>"
                    "<noise type='none'/></z></linear_acceleration></imu>"),
      &p, &error))
      << error;
  for (int i = 0; i < 3; ++i) EXPECT_EQ(p.rate[i].stddev, 0.3);
  EXPECT_EQ(p.acceleration[0].mean, 1);
  EXPECT_EQ(p.acceleration[1].stddev, 0.4);
  EXPECT_FALSE(p.acceleration[2].on);
  EXPECT_FALSE(p.drifts());
  EXPECT_FALSE(readImuNoise(
      sensor("imu", "<imu><linear_acceleration><x><noise type='gaussian'><mean>one</mean>"
                    "</noise></x></linear_acceleration></imu>"),
      &p, &error));
  EXPECT_EQ(error, "<imu><linear_acceleration><x><noise><mean> is 'one', not a number");
}

TEST(SensorXml, ReadsASensorsNumbersAndPoses) {
  tinyxml2::XMLDocument doc;
  doc.Parse("<range><min> 0.5 </min><max>inf</max></range>");
  double value = 7;
  std::string error;
  EXPECT_TRUE(readSensorNumber(doc.RootElement(), "absent", "range", &value, &error));
  EXPECT_EQ(value, 7);
  EXPECT_TRUE(readSensorNumber(doc.RootElement(), "min", "range", &value, &error));
  EXPECT_EQ(value, 0.5);
  EXPECT_FALSE(readSensorNumber(doc.RootElement(), "max", "range", &value, &error));
  EXPECT_EQ(error, "<range><max> is 'inf', not a number");
  EXPECT_EQ(sensorPath(doc.RootElement(), {"min"}), doc.RootElement()->FirstChildElement("min"));
  EXPECT_EQ(sensorPath(doc.RootElement(), {"min", "x"}), nullptr);
  Pose pose;
  EXPECT_TRUE(readPoseText(" 1 2 3 0.1 0.2 0.3 ", &pose));
  EXPECT_EQ(pose.position.y, 2);
  expectNear(pose.orientation, fromRpy(0.1, 0.2, 0.3));
  EXPECT_FALSE(readPoseText("1 2 3 0.1 0.2 0.3 4", &pose));
  EXPECT_FALSE(readPoseText("1 2 3 0.1 0.2", &pose));
}

TEST(UpdateGates, KeepToTheirRatesGridOverSimTime) {
  constexpr int64_t kMs = 1000000;
  // A model plugin's: due once more than a period passed, the last moving on by a period.
  UpdateGate every_10ms(100, 0);
  std::vector<int64_t> due;
  for (int64_t t = 3 * kMs; t <= 40 * kMs; t += 3 * kMs)
    if (every_10ms.due(t)) due.push_back(t / kMs);
  EXPECT_EQ(due, (std::vector<int64_t>{12, 21, 33}));
  // A sensor's (Sensor::Update): due once the period is reached, counting what the last update
  // came late (2 ms at 12, 1 at 21), so that 30 is on the grid again.
  SensorGate sensor_gate(100);
  due.clear();
  for (int64_t t = 3 * kMs; t <= 40 * kMs; t += 3 * kMs)
    if (sensor_gate.due(t)) due.push_back(t / kMs);
  EXPECT_EQ(due, (std::vector<int64_t>{12, 21, 30}));
  // Rate 0: every step; time going back starts over.
  SensorGate every_step;
  EXPECT_TRUE(every_step.due(kMs));
  EXPECT_TRUE(every_step.due(2 * kMs));
  EXPECT_FALSE(every_step.due(2 * kMs));
  EXPECT_TRUE(every_step.due(kMs));
  // The camera plugins' throttle over the sensor's updates.
  PublishThrottle throttle(50);
  due.clear();
  for (int64_t t = 10 * kMs; t <= 100 * kMs; t += 10 * kMs)
    if (throttle.due(t)) due.push_back(t / kMs);
  EXPECT_EQ(due, (std::vector<int64_t>{20, 40, 60, 80, 100}));
}

}  // namespace
}  // namespace onedof_sim::plugins
