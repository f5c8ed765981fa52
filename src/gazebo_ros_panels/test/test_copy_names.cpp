// Copies are named as Gazebo names them: base_0, base_1, ... the first free one.
#include <gtest/gtest.h>

#include "copy_names.h"

using gazebo_ros_panels::copyName;

TEST(CopyNames, FirstFreeNumberedName) {
  EXPECT_EQ(copyName("cafe_table", {}), "cafe_table_0");
  EXPECT_EQ(copyName("cafe_table", {"cafe_table", "ground_plane"}), "cafe_table_0");
  EXPECT_EQ(copyName("cafe_table", {"cafe_table_0"}), "cafe_table_1");
  EXPECT_EQ(copyName("cafe_table", {"cafe_table_1", "cafe_table_0", "cafe_table_3"}),
            "cafe_table_2");
  EXPECT_EQ(copyName("unit_box", {"cafe_table_0"}), "unit_box_0");
}
