#include <gtest/gtest.h>

#include "rascal_workcell/GripperGeometry.hpp"

using namespace rascal_workcell;

TEST(GripperGeometry, LimitsAndFingertipsFromTheUrdf) {
  const GripperGeometry g = GripperGeometry::fromPackageUrdf();
  EXPECT_DOUBLE_EQ(g.minOpening(), 0.030);  // facts §1.4: 30 .. 74 mm between the fingers
  EXPECT_DOUBLE_EQ(g.maxOpening(), 0.074);
  EXPECT_NEAR(g.fingertip_offset, 0.012 + 0.020 - 0.027575, 1e-12);
}

TEST(GripperGeometry, AUrdfWithoutFingerLimitsIsRefused) {
  EXPECT_THROW(GripperGeometry::fromUrdf("<robot name='r'><link name='a'/></robot>"), std::invalid_argument);
  EXPECT_THROW(GripperGeometry::fromUrdf("not xml"), std::invalid_argument);
}

TEST(GripperGeometry, PadsInsideTheFingersTakeTwoPadsOffTheOpening) {
  const GripperGeometry g = GripperGeometry::fromPackageUrdf().withPads(0.0075);
  EXPECT_DOUBLE_EQ(g.minOpening(), 0.015);  // 30 mm - 2 x 7.5 mm
  EXPECT_DOUBLE_EQ(g.maxOpening(), 0.059);
  EXPECT_DOUBLE_EQ(g.fingerFor(0.021), 0.018);  // a 21 mm chip: the joint 10.5 + 7.5 mm out
  EXPECT_DOUBLE_EQ(g.openingAt(2.0 * 0.018), 0.021);
  EXPECT_DOUBLE_EQ(GripperGeometry::fromPackageUrdf().withPads(0.0).minOpening(), 0.030);
}

TEST(GripperGeometry, PadsThatWouldMeetBeforeTheFingersCloseAreRefusedNamingTheKey) {
  const GripperGeometry g = GripperGeometry::fromPackageUrdf();
  for (const double pad : {0.015, 0.02, -0.001}) {
    try {
      g.withPads(pad);
      FAIL() << pad;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("arm.gripper.fingertip_pads"), std::string::npos) << e.what();
    }
  }
}
