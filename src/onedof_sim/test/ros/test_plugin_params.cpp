// A plugin's <plugin> element read as gazebo_ros's plugins read theirs (PluginParams) and TF
// frame names as tf::resolve makes them, no roscore.
#include <gtest/gtest.h>

#include <string>

#include "plugins/plugin_params.h"

namespace onedof_sim::plugins {
namespace {

const char* const kPlugin =
    "<plugin name='p' filename='libgazebo_ros_p3d.so'>"
    "<bodyName>  base_link\n</bodyName><empty/><updateRate>50</updateRate>"
    "<badRate>fast</badRate><infRate>inf</infRate><xyzOffset> 1 2.5 -3 </xyzOffset>"
    "<shortOffset>1 2</shortOffset><longOffset>1 2 3 4</longOffset>"
    "<on>TRUE</on><off>0</off><maybe>yes</maybe></plugin>";

TEST(PluginParams, ReadsTextTrimmedWithFallbacks) {
  const PluginParams params(kPlugin, "test");
  EXPECT_TRUE(params.has("bodyName"));
  EXPECT_FALSE(params.has("topicName"));
  EXPECT_EQ(params.text("bodyName", "x"), "base_link");
  EXPECT_EQ(params.text("empty", "x"), "");
  EXPECT_EQ(params.text("topicName", "odom"), "odom");
  EXPECT_EQ(params.label(), "test");
  // Not XML, or no <plugin>: every tag absent.
  const PluginParams broken("<plugin", "broken");
  EXPECT_FALSE(broken.has("bodyName"));
  EXPECT_EQ(broken.text("bodyName", "fallback"), "fallback");
}

TEST(PluginParams, ReadsNumbersAndRefusesWhatIsNotOne) {
  const PluginParams params(kPlugin, "test");
  double value = 0;
  std::string error;
  EXPECT_TRUE(params.number("updateRate", 0, &value, &error));
  EXPECT_EQ(value, 50);
  EXPECT_TRUE(params.number("gaussianNoise", 0.25, &value, &error));
  EXPECT_EQ(value, 0.25);
  EXPECT_FALSE(params.number("badRate", 0, &value, &error));
  EXPECT_EQ(error, "<badRate> is 'fast', not a number");
  EXPECT_FALSE(params.number("infRate", 0, &value, &error));
  EXPECT_EQ(error, "<infRate> is 'inf', not a number");
  EXPECT_FALSE(params.number("empty", 0, &value, &error));
  EXPECT_EQ(error, "<empty> is '', not a number");
}

TEST(PluginParams, ReadsThreeNumbers) {
  const PluginParams params(kPlugin, "test");
  Vec3 v{9, 9, 9};
  std::string error;
  EXPECT_TRUE(params.vector("rpyOffset", &v, &error));  // absent: untouched
  EXPECT_EQ(v.x, 9);
  EXPECT_TRUE(params.vector("xyzOffset", &v, &error));
  EXPECT_EQ(v.x, 1);
  EXPECT_EQ(v.y, 2.5);
  EXPECT_EQ(v.z, -3);
  EXPECT_FALSE(params.vector("shortOffset", &v, &error));
  EXPECT_EQ(error, "<shortOffset> is '1 2', not three numbers");
  EXPECT_FALSE(params.vector("longOffset", &v, &error));
  EXPECT_EQ(error, "<longOffset> is '1 2 3 4', not three numbers");
}

TEST(PluginParams, ReadsFlagsAsGazeboRosDoes) {
  const PluginParams params(kPlugin, "test");
  EXPECT_TRUE(params.flag("on", false));
  EXPECT_FALSE(params.flag("off", true));
  EXPECT_TRUE(params.flag("absent", true));
  // Neither true nor false: the fallback stays (and the plugin says so).
  EXPECT_TRUE(params.flag("maybe", true));
  EXPECT_FALSE(params.flag("maybe", false));
}

TEST(PluginParams, ResolvesTfFramesAsTfDoes) {
  EXPECT_EQ(resolveTfFrame("", "odom"), "odom");
  EXPECT_EQ(resolveTfFrame("robot1", "odom"), "robot1/odom");
  EXPECT_EQ(resolveTfFrame("/robot1", "odom"), "robot1/odom");
  EXPECT_EQ(resolveTfFrame("/", "odom"), "odom");
  EXPECT_EQ(resolveTfFrame("robot1", "/map"), "map");
}

}  // namespace
}  // namespace onedof_sim::plugins

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
