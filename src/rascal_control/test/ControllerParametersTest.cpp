#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "TestModel.hpp"
#include "rascal_control/ControllerParameters.hpp"

using namespace rascal_control;

namespace {

YAML::Node shipped() { return YAML::LoadFile(RASCAL_CONFIG_PATH); }

ControllerParameters read(const YAML::Node& root) {
  return ControllerParameters::read(rascal_workcell::Parameters(root, "arm_controller"), testModel());
}

// The ParameterError's text, or "" when none is thrown.
std::string error(const YAML::Node& root) {
  try {
    read(root);
  } catch (const rascal_workcell::ParameterError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(ControllerParameters, ReadsTheShippedConfiguration) {
  const ControllerParameters c = read(shipped());  // every key of the reader read (checkAllRead)
  ASSERT_EQ(c.named_poses.size(), 2u);
  EXPECT_EQ(c.named_poses.at("home"), JointVector{});
  EXPECT_DOUBLE_EQ(c.named_poses.at("sleep")[1], -1.80);
  EXPECT_DOUBLE_EQ(c.speed_scale, 1.0);
  EXPECT_DOUBLE_EQ(c.acceleration_share, 0.95);
  EXPECT_DOUBLE_EQ(c.command_period, 0.02);
  EXPECT_DOUBLE_EQ(c.move.goal_tolerance, 0.002);
  EXPECT_DOUBLE_EQ(c.move.settle_timeout, 2.0);
  EXPECT_DOUBLE_EQ(c.move.tracking_tolerance, 0.1);
  EXPECT_DOUBLE_EQ(c.state_timeout, 1.0);
  EXPECT_TRUE(c.publish_tf);
  EXPECT_DOUBLE_EQ(c.gripper.timeout, 3.0);
  EXPECT_DOUBLE_EQ(c.gripper.stroke_time, 0.5);
  EXPECT_DOUBLE_EQ(c.gripper.held_margin, 0.002);
}

TEST(ControllerParameters, FixturesAreTheWorkcellsBoxes) {
  const ControllerParameters c = read(shipped());
  auto find = [&](const std::string& name) {
    return std::find_if(c.fixtures.begin(), c.fixtures.end(), [&](const auto& b) { return b.name == name; });
  };
  ASSERT_NE(find("camera stand"), c.fixtures.end());
  EXPECT_DOUBLE_EQ(find("camera stand")->size.z(), 0.60);
  ASSERT_NE(find("scale platform"), c.fixtures.end());
  EXPECT_TRUE(find("scale platform")->is_support);
  ASSERT_NE(find("discard box wall +x"), c.fixtures.end());
  EXPECT_DOUBLE_EQ(find("discard box wall +x")->size.x(), rascal_workcell::Workcell::kDiscardWallThickness);
  EXPECT_DOUBLE_EQ(rascal_workcell::Workcell::kDiscardWallThickness, 0.005);
}

TEST(ControllerParameters, ANamedPoseOutsideTheJointLimitsNamesTheKey) {
  YAML::Node root = shipped();
  root["arm"]["named_poses"]["tuck"] = std::vector<double>{0.0, 0.0, 3.0, 0.0, 0.0, 0.0};
  const std::string e = error(root);
  EXPECT_EQ(e.rfind("arm.named_poses.tuck: expected every joint within its URDF limits (elbow in [", 0), 0u) << e;
  EXPECT_NE(e.find("got [0, 0, 3, 0, 0, 0]"), std::string::npos) << e;
}

TEST(ControllerParameters, ABadValueNamesTheKey) {
  YAML::Node root = shipped();
  root["arm"]["named_poses"]["home"] = std::vector<double>{0.0, 0.0};
  EXPECT_EQ(error(root).rfind("arm.named_poses.home: ", 0), 0u) << error(root);
  root = shipped();
  root["arm"]["speed_scale"] = 0.0;
  EXPECT_EQ(error(root).rfind("arm.speed_scale: ", 0), 0u) << error(root);
  root = shipped();
  root["stations"]["camera"]["stand"]["height"] = -1.0;
  EXPECT_EQ(error(root).rfind("stations.camera.stand.height: ", 0), 0u) << error(root);
  root = shipped();
  root["arm"].remove("named_poses");
  EXPECT_EQ(error(root).rfind("arm.named_poses: missing", 0), 0u) << error(root);
}

TEST(ControllerParameters, OptionalKeysTakeTheSchemaDefaults) {
  YAML::Node root = shipped();
  root["arm"]["gripper"].remove("held_margin");
  root["arm"].remove("publish_tf");
  const ControllerParameters c = read(root);
  EXPECT_DOUBLE_EQ(c.gripper.held_margin, 0.002);
  EXPECT_TRUE(c.publish_tf);
}
