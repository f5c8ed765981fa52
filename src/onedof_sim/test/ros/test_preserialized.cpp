// PreSerialized: the bytes, md5sum and type roscpp itself would publish for the message.
#include <cstring>

#include <gtest/gtest.h>
#include <sensor_msgs/Image.h>

#include "preserialized.h"

namespace {

sensor_msgs::Image image() {
  sensor_msgs::Image message;
  message.header.frame_id = "camera_link";
  message.header.stamp.fromNSec(1234567890);
  message.width = 3;
  message.height = 2;
  message.encoding = "rgb8";
  message.step = 9;
  for (int i = 0; i < 18; ++i) message.data.push_back(static_cast<uint8_t>(i * 13));
  return message;
}

TEST(PreSerialized, CarriesTheBytesRoscppWouldMakeAndWhatTheMessageIs) {
  const sensor_msgs::Image message = image();
  const onedof_sim::PreSerialized pre = onedof_sim::preSerialize(message);
  const ros::SerializedMessage roscpps = ros::serialization::serializeMessage(message);
  ASSERT_EQ(pre.bytes.num_bytes, roscpps.num_bytes);
  EXPECT_EQ(0, std::memcmp(pre.bytes.buf.get(), roscpps.buf.get(), roscpps.num_bytes));
  EXPECT_EQ(pre.bytes.message_start - pre.bytes.buf.get(),
            roscpps.message_start - roscpps.buf.get());
  EXPECT_STREQ(pre.md5sum, ros::message_traits::md5sum<sensor_msgs::Image>());
  EXPECT_STREQ(pre.datatype, "sensor_msgs/Image");
  EXPECT_STREQ(ros::message_traits::md5sum(pre), pre.md5sum);
  EXPECT_STREQ(ros::message_traits::datatype(pre), "sensor_msgs/Image");
}

TEST(PreSerialized, PublishingHandsOverTheSameBytesWithoutCopyingThem) {
  const onedof_sim::PreSerialized pre = onedof_sim::preSerialize(image());
  // What ros::Publisher::publish calls while it holds roscpp's topic lock.
  const ros::SerializedMessage published =
      ros::serialization::serializeMessage<onedof_sim::PreSerialized>(pre);
  EXPECT_EQ(published.buf.get(), pre.bytes.buf.get());
  EXPECT_EQ(published.num_bytes, pre.bytes.num_bytes);
  sensor_msgs::Image back;
  ros::serialization::deserializeMessage(published, back);
  EXPECT_EQ(back.header.frame_id, "camera_link");
  EXPECT_EQ(back.header.stamp.toNSec(), 1234567890u);
  EXPECT_EQ(back.data, image().data);
}

TEST(PreSerialized, AnEmptyPublisherPublishesNothingAndThrowsNothing) {
  const ros::Publisher none;
  EXPECT_NO_THROW(onedof_sim::publishPreSerialized(none, image()));
}

}  // namespace
