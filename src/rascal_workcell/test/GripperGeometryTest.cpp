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
