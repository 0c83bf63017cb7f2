#include <gtest/gtest.h>

#include <string>

#include "rascal_sim/ArchivalCamera.hpp"
#include "rascal_sim/SimParameters.hpp"

using namespace rascal_sim;
using rascal_workcell::GripperGeometry;
using rascal_workcell::ParameterError;
using rascal_workcell::Parameters;

namespace {
/// The shipped configuration as a YAML tree the test may change.
YAML::Node shippedYaml() { return YAML::LoadFile(RASCAL_CONFIG_PATH); }

SimParameters read(const YAML::Node& root) {
  return SimParameters::read(Parameters(root, "sim"), GripperGeometry::fromPackageUrdf(), RASCAL_SIM_DATA_DIR);
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

TEST(SimParameters, ReadsEveryKeyTheSchemaListsForTheSimulator) {
  // read() ends with checkAllRead(): a key the schema (and so the README table) promises for
  // "sim" that the simulator ignores would throw std::logic_error here
  const SimParameters p = read(shippedYaml());
  EXPECT_EQ(p.layout.workcell.stations().size(), 4u);
  EXPECT_DOUBLE_EQ(p.options.gripper.finger_min, 0.015);  // the URDF's left_finger limits
  EXPECT_DOUBLE_EQ(p.options.gripper.finger_max, 0.037);
  EXPECT_DOUBLE_EQ(p.options.initial_finger, 0.037);
  EXPECT_DOUBLE_EQ(p.options.physics_dt, 0.001);
  EXPECT_EQ(p.options.archival_width, 2000);
  EXPECT_EQ(p.scenario, "config/scenarios/demo_10.yaml");
  EXPECT_EQ(p.layout.station(StationType::Scale).area.centre, Eigen::Vector2d(0.30, 0.0));
}

TEST(SimParameters, ABadValueIsNamedInOneLine) {
  YAML::Node root = shippedYaml();
  root["stations"]["scale"]["position"] = YAML::Load("[0.3]");
  const std::string why = refusal(root);
  EXPECT_EQ(why.rfind("stations.scale.position: ", 0), 0u) << why;
  EXPECT_EQ(why.find('\n'), std::string::npos) << why;
}

TEST(SimParameters, AcceptsWhatTheSchemaAccepts) {
  // the node used to refuse a scale lower than 11 mm, which check_config accepts
  YAML::Node root = shippedYaml();
  root["stations"]["scale"]["surface_z"] = 0.005;
  EXPECT_EQ(refusal(root), "");
}

TEST(SimParameters, InitialPoseOutsideTheUrdfLimitsIsRefused) {
  YAML::Node root = shippedYaml();
  root["simulator"]["initial_joints"] = YAML::Load("[0.0, -2.0, 1.55, 0.0, 0.8, 0.0]");  // shoulder >= -1.885
  std::string why = refusal(root);
  EXPECT_EQ(why.rfind("simulator.initial_joints: ", 0), 0u) << why;
  EXPECT_NE(why.find("shoulder"), std::string::npos) << why;

  root = shippedYaml();
  root["simulator"]["initial_finger"] = 0.04;  // within the schema's range, beyond the URDF's 0.037
  why = refusal(root);
  EXPECT_EQ(why.rfind("simulator.initial_finger: ", 0), 0u) << why;
}

TEST(SimParameters, StationsAreFoundByTypeWhateverTheSiteCallsThem) {
  YAML::Node root = shippedYaml();
  YAML::Node renamed(YAML::NodeType::Map);
  for (const auto& kv : root["stations"]) {
    const std::string name = kv.first.as<std::string>();
    renamed[name == "camera" ? "photo_stand" : name == "scale" ? "balance" : name] = kv.second;
  }
  root["stations"] = renamed;
  const SimParameters p = read(root);
  const ArchivalCamera camera(p.layout, 2000, 1500);
  EXPECT_NEAR(camera.pose().translation().x(), 0.31, 1e-12);
  EXPECT_NEAR(camera.pose().translation().y(), -0.30, 1e-12);
  EXPECT_EQ(p.layout.station(StationType::Scale).name, "balance");
}
