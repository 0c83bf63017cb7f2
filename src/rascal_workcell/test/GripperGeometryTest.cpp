#include <gtest/gtest.h>

#include <cmath>

#include "rascal_workcell/GripperGeometry.hpp"

using namespace rascal_workcell;

TEST(GripperGeometry, LimitsAndFingertipsFromTheUrdf) {
  const GripperGeometry g = GripperGeometry::fromPackageUrdf();
  EXPECT_DOUBLE_EQ(g.minOpening(), 0.030);  // facts §1.4: 30 .. 74 mm between the fingers
  EXPECT_DOUBLE_EQ(g.maxOpening(), 0.074);
  EXPECT_NEAR(g.fingertip_offset, 0.012 + 0.020 - 0.027575, 1e-12);
}

TEST(GripperGeometry, TheHandAboveTheFingersFromTheUrdf) {
  // wx250s.urdf: ee_gripper_link 27.575 mm past fingers_link, the gripper bar's box ending there
  // (100 mm across the closing direction), the wrist camera's 55 mm to one side of the fingers
  const GripperGeometry g = GripperGeometry::fromPackageUrdf();
  ASSERT_GE(g.hand.size(), 3u);
  bool bar = false, camera = false;
  for (const HandBox& b : g.hand) {
    EXPECT_LE(b.hi[0], -0.027575 + 1e-9) << "nothing of the hand as low as the fingers";
    bar = bar || (std::abs(b.hi[0] + 0.027575) < 1e-9 && b.hi[1] - b.lo[1] >= 0.1 - 1e-9);
    camera = camera || (std::abs(b.lo[2] - (0.055 - 0.0125)) < 1e-6 && std::abs(b.hi[0] + 0.093575 - 0.0442) < 1e-4);
  }
  EXPECT_TRUE(bar);
  EXPECT_TRUE(camera);
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
