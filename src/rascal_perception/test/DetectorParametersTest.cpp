// What sherd_detector reads from config/rascal.yaml, through the parameter schema (reader
// "sherd_detector"), without a master: the node does the same from the parameter server.
#include <gtest/gtest.h>

#include <functional>
#include <string>
#include <utility>

#include "rascal_perception/DetectorParameters.hpp"

using namespace rascal_perception;
using rascal_workcell::GripperGeometry;
using rascal_workcell::ParameterError;
using rascal_workcell::Parameters;
using rascal_workcell::StationType;

namespace {
/// The shipped configuration as a YAML tree the test may change.
YAML::Node shippedYaml() { return YAML::LoadFile(RASCAL_CONFIG_PATH); }

DetectorParameters read(const YAML::Node& root) {
  return DetectorParameters::read(Parameters(root, "sherd_detector"), GripperGeometry::fromPackageUrdf());
}

/// The ParameterError's message (one line), or "" when the configuration is accepted.
std::string refusal(const YAML::Node& root) {
  try {
    read(root);
  } catch (const ParameterError& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(DetectorParameters, ReadsEveryKeyTheSchemaListsForTheDetector) {
  // read() ends with checkAllRead(): a key the schema (and so the README table) promises for
  // "sherd_detector" that the node ignores would throw std::logic_error here
  const DetectorParameters p = read(shippedYaml());
  const PerceptionConfig& c = p.config;
  EXPECT_EQ(c.background_clusters, 3);
  EXPECT_DOUBLE_EQ(c.hue_tolerance, 0.15);
  EXPECT_DOUBLE_EQ(c.max_sherd_size, 0.12);
  EXPECT_EQ(c.border_margin, 3);
  EXPECT_DOUBLE_EQ(c.grasp_tip_clearance, 0.0025);
  EXPECT_DOUBLE_EQ(c.grasp_margin, 0.012);
  EXPECT_DOUBLE_EQ(p.frame_wait, 1.0);
  EXPECT_DOUBLE_EQ(p.refresh_period, 0.0);
  // the gripper is the URDF's, not a parameter
  EXPECT_DOUBLE_EQ(c.gripper.minOpening(), 0.030);
  EXPECT_DOUBLE_EQ(c.gripper.maxOpening(), 0.074);
  EXPECT_NEAR(c.gripper.fingertip_offset, 0.0044, 0.0001);
  // stations from the workcell, found by the name a request uses
  ASSERT_EQ(p.workcell.stations().size(), 4u);
  ASSERT_NE(p.workcell.find("scale"), nullptr);
  EXPECT_DOUBLE_EQ(p.workcell.find("scale")->surface_z, 0.025);
  EXPECT_EQ(p.workcell.find("scale")->type, StationType::Scale);
  EXPECT_EQ(p.workcell.find("nowhere"), nullptr);
}

TEST(DetectorParameters, OptionalKeysTakeTheSchemaDefaults) {
  YAML::Node root = shippedYaml();
  root.remove("perception");
  const DetectorParameters p = read(root);
  const PerceptionConfig defaults;  // the core's defaults agree with the schema's
  EXPECT_EQ(p.config.background_clusters, defaults.background_clusters);
  EXPECT_DOUBLE_EQ(p.config.hue_tolerance, defaults.hue_tolerance);
  EXPECT_DOUBLE_EQ(p.config.saturation_tolerance, defaults.saturation_tolerance);
  EXPECT_DOUBLE_EQ(p.config.min_value, defaults.min_value);
  EXPECT_DOUBLE_EQ(p.config.fixture_dilation, defaults.fixture_dilation);
  EXPECT_DOUBLE_EQ(p.config.min_sherd_size, defaults.min_sherd_size);
  EXPECT_DOUBLE_EQ(p.config.max_sherd_size, defaults.max_sherd_size);
  EXPECT_EQ(p.config.border_margin, defaults.border_margin);
  EXPECT_DOUBLE_EQ(p.config.depth_min, defaults.depth_min);
  EXPECT_DOUBLE_EQ(p.config.depth_max, defaults.depth_max);
  EXPECT_DOUBLE_EQ(p.config.min_sherd_height, defaults.min_sherd_height);
  EXPECT_DOUBLE_EQ(p.config.split_min_neck, defaults.split_min_neck);
  EXPECT_DOUBLE_EQ(p.config.grasp_height_fraction, defaults.grasp_height_fraction);
  EXPECT_DOUBLE_EQ(p.config.grasp_tip_clearance, defaults.grasp_tip_clearance);
  EXPECT_DOUBLE_EQ(p.frame_wait, 1.0);
}

TEST(DetectorParameters, ABadValueNamesItsKey) {
  const std::pair<std::string, std::function<void(YAML::Node&)>> cases[] = {
      {"perception.hue_tolerance: expected", [](YAML::Node& r) { r["perception"]["hue_tolerance"] = 2.0; }},
      {"perception.border_margin: expected", [](YAML::Node& r) { r["perception"]["border_margin"] = 0.5; }},
      {"perception.depth_max: expected", [](YAML::Node& r) { r["perception"]["depth_max"] = 0.1; }},  // < depth_min
      {"arm.grasp_margin: expected", [](YAML::Node& r) { r["arm"]["grasp_margin"] = -1; }},
      {"stations.scale.surface_z: expected", [](YAML::Node& r) { r["stations"]["scale"]["surface_z"] = "abc"; }},
      {"stations: expected exactly one station of type pickup", [](YAML::Node& r) { r["stations"].remove("pickup"); }},
  };
  for (const auto& [expected, change] : cases) {
    YAML::Node root = shippedYaml();
    change(root);
    const std::string why = refusal(root);
    EXPECT_EQ(why.rfind(expected, 0), 0u) << why;
  }
}

TEST(DetectorParameters, ReadsNeitherTheSelectionPolicyNorTheFingertipOffset) {
  // the task layer chooses which sherd to pick; the fingertips are the URDF's
  YAML::Node root = shippedYaml();
  root["perception"]["selection_policy"] = "random";  // the validator's business, not the node's
  EXPECT_EQ(refusal(root), "");
  const Parameters params(shippedYaml(), "sherd_detector");
  EXPECT_THROW(params.text("perception.selection_policy"), std::logic_error);
}
