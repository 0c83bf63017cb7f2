#include <gtest/gtest.h>

#include "rascal_workcell/Parameters.hpp"

using namespace rascal_workcell;

namespace {
YAML::Node shipped() { return YAML::LoadFile(RASCAL_CONFIG_PATH); }

std::string errorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const ParameterError& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(Parameters, ReadsTheShippedValues) {
  const Parameters p(shipped(), "sherd_detector");
  EXPECT_DOUBLE_EQ(p.number("perception.min_sherd_size"), 0.015);
  EXPECT_EQ(p.integer("perception.background_clusters"), 3);
  EXPECT_DOUBLE_EQ(p.xy("stations.scale.position").x(), 0.30);
  EXPECT_EQ(p.names("stations"), (std::vector<std::string>{"pickup", "scale", "camera", "discard"}));
}

TEST(Parameters, OutOfRangeNamesTheKeyTheRangeAndTheValue) {
  YAML::Node n = shipped();
  n["perception"]["hue_tolerance"] = 0.9;
  const Parameters p(n, "sherd_detector");
  EXPECT_EQ(errorOf([&] { p.number("perception.hue_tolerance"); }),
            "perception.hue_tolerance: expected a number in [0.001, 0.5], got 0.9");
}

TEST(Parameters, MissingOptionalKeyGivesTheSchemaDefaultMissingRequiredKeyFails) {
  YAML::Node n = shipped();
  n["perception"].remove("frame_wait");
  n["stations"]["scale"].remove("surface_z");
  const Parameters p(n, "sherd_detector");
  EXPECT_DOUBLE_EQ(p.number("perception.frame_wait"), 1.0);
  EXPECT_NE(errorOf([&] { p.number("stations.scale.surface_z"); }).find("stations.scale.surface_z: missing"),
            std::string::npos);
}

TEST(Parameters, BoundNamedByAnotherKeyUsesItsValue) {
  YAML::Node n = shipped();
  n["perception"]["max_sherd_size"] = 0.01;  // below min_sherd_size 0.015
  const Parameters p(n, "sherd_detector");
  const std::string e = errorOf([&] { p.number("perception.max_sherd_size"); });
  EXPECT_NE(e.find("perception.min_sherd_size = 0.015"), std::string::npos) << e;
}

TEST(Parameters, TypesAreChecked) {
  YAML::Node n = YAML::Load(
      "perception: {background_clusters: 2.5, selection_policy: random, min_sherd_size: '0.02'}\n"
      "simulator: {wrist_camera: 'yes', archival_size: [1999, 1500], scale_colours: [[0, 0, 0]]}\n");
  const Parameters det(n, "sherd_detector");
  EXPECT_NE(errorOf([&] { det.integer("perception.background_clusters"); }).find("expected an integer"), std::string::npos);
  EXPECT_NE(errorOf([&] { det.number("perception.min_sherd_size"); }).find("got '0.02'"), std::string::npos);
  const Parameters sim(n, "sim");
  EXPECT_NE(errorOf([&] { sim.flag("simulator.wrist_camera"); }).find("expected true or false"), std::string::npos);
  EXPECT_NE(errorOf([&] { sim.vector("simulator.archival_size"); }).find("at least [2000, 1500]"), std::string::npos);
  EXPECT_NE(errorOf([&] { sim.vectors("simulator.scale_colours"); }).find("two [r, g, b]"), std::string::npos);
  const Parameters rascal(n, "rascal");
  EXPECT_NE(errorOf([&] { rascal.text("perception.selection_policy"); }).find("one of nearest, largest"), std::string::npos);
}

TEST(Parameters, ExclusiveLowerBound) {
  YAML::Node n = shipped();
  n["arm"]["speed_scale"] = 0.0;
  const Parameters p(n, "arm_controller");
  EXPECT_EQ(errorOf([&] { p.number("arm.speed_scale"); }), "arm.speed_scale: expected a number in (0, 1], got 0");
}

TEST(Parameters, ANodeCannotReadAKeyTheSchemaDoesNotListForIt) {
  const Parameters p(shipped(), "sim");
  EXPECT_THROW(p.number("perception.hue_tolerance"), std::logic_error);
  EXPECT_THROW(p.number("no.such.key"), std::logic_error);
}

TEST(Parameters, CheckAllReadNamesWhatTheReaderNeverRead) {
  const Parameters p(shipped(), "rascal");
  p.text("rig.name");
  try {
    p.checkAllRead();
    FAIL();
  } catch (const std::logic_error& e) {
    EXPECT_NE(std::string(e.what()).find("rig.site"), std::string::npos);
    EXPECT_EQ(std::string(e.what()).find("rig.name,"), std::string::npos);
  }
}

TEST(Parameters, NamedPosesNeedHomeAndSleep) {
  YAML::Node n = shipped();
  n["arm"]["named_poses"].remove("sleep");
  const Parameters p(n, "arm_controller");
  EXPECT_NE(errorOf([&] { p.names("arm.named_poses"); }).find("arm.named_poses.sleep: missing"), std::string::npos);
}
