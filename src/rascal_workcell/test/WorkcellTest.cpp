#include <gtest/gtest.h>

#include "rascal_workcell/Workcell.hpp"

using namespace rascal_workcell;

namespace {
YAML::Node shipped() { return YAML::LoadFile(RASCAL_CONFIG_PATH); }

const FixtureBox* box(const std::vector<FixtureBox>& boxes, const std::string& name) {
  for (const auto& b : boxes) {
    if (b.name == name) return &b;
  }
  return nullptr;
}
}  // namespace

TEST(Workcell, StationsOfTheShippedConfig) {
  const Workcell w = Workcell::fromParameters(Parameters(shipped(), "arm_controller"));
  EXPECT_EQ(w.stations().size(), 4u);
  EXPECT_EQ(w.station(StationType::ArchivalCamera).name, "camera");
  EXPECT_DOUBLE_EQ(w.station(StationType::ArchivalCamera).place_at.x(), 0.28);
  EXPECT_DOUBLE_EQ(w.station(StationType::Scale).place_at.x(), 0.30);  // the centre
  EXPECT_NE(w.find("discard"), nullptr);
  EXPECT_EQ(w.find("nowhere"), nullptr);
}

TEST(Workcell, FixturesAreFoundByTypeNotByName) {
  YAML::Node n = shipped();
  YAML::Node stations(YAML::NodeType::Map);
  for (const auto& e : n["stations"]) {
    const std::string name = e.first.as<std::string>() == "camera" ? "dslr" : e.first.as<std::string>();
    stations[name] = e.second;
  }
  n["stations"] = stations;
  const auto boxes = Workcell::fromParameters(Parameters(n, "arm_controller")).collisionBoxes();
  const FixtureBox* stand = box(boxes, "camera stand");
  ASSERT_NE(stand, nullptr);
  EXPECT_EQ(stand->station, "dslr");
  EXPECT_DOUBLE_EQ(stand->size.z(), 0.60);
}

TEST(Workcell, DiscardWallsHaveOneThicknessAndCloseTheBox) {
  const auto boxes = Workcell::fromParameters(Parameters(shipped(), "sim")).collisionBoxes();
  int walls = 0;
  for (const auto& b : boxes) {
    if (b.name.rfind("discard box wall", 0) != 0) continue;
    ++walls;
    EXPECT_DOUBLE_EQ(b.size.minCoeff(), Workcell::kDiscardWallThickness);
    EXPECT_DOUBLE_EQ(b.size.z(), 0.04);
  }
  EXPECT_EQ(walls, 4);
  const FixtureBox* py = box(boxes, "discard box wall +y");
  ASSERT_NE(py, nullptr);
  EXPECT_NEAR(py->centre.y(), -0.31 + 0.13 / 2, 1e-12);
}

TEST(Workcell, SortingBinsAreBoxesBesideTheOneDiscardBox) {
  YAML::Node n = shipped();
  YAML::Node bin(YAML::NodeType::Map);
  bin["type"] = "bin";
  bin["position"] = std::vector<double>{0.14, -0.13};
  bin["size"] = std::vector<double>{0.10, 0.08};
  bin["surface_z"] = 0.0;
  bin["wall_height"] = 0.03;
  bin["rule"] = "length >= 60 mm";
  n["stations"]["large"] = bin;
  const Workcell w = Workcell::fromParameters(Parameters(n, "sim"));
  EXPECT_EQ(w.find("large")->type, StationType::Bin);
  EXPECT_EQ(w.station(StationType::Discard).name, "discard");  // still exactly one
  const auto boxes = w.collisionBoxes();
  const FixtureBox* px = box(boxes, "bin large wall +x");
  ASSERT_NE(px, nullptr);
  EXPECT_EQ(px->station, "large");
  EXPECT_NEAR(px->centre.x(), 0.14 + 0.05, 1e-12);
  EXPECT_DOUBLE_EQ(px->size.z(), 0.03);
}

TEST(Workcell, ScalePlatformIsASupportOnItsHousing) {
  const auto boxes = Workcell::fromParameters(Parameters(shipped(), "sim")).collisionBoxes();
  const FixtureBox* platform = box(boxes, "scale platform");
  const FixtureBox* housing = box(boxes, "scale housing");
  ASSERT_TRUE(platform && housing);
  EXPECT_TRUE(platform->is_support);
  EXPECT_FALSE(housing->is_support);
  EXPECT_NEAR(platform->centre.z() + platform->size.z() / 2, 0.025, 1e-12);
  EXPECT_NEAR(housing->size.x(), 0.13 + 2 * Workcell::kScaleHousingMargin, 1e-12);
}

TEST(Workcell, EachStationTypeExactlyOnce) {
  YAML::Node n = shipped();
  n["stations"]["scale2"] = YAML::Clone(n["stations"]["scale"]);
  EXPECT_THROW(Workcell::fromParameters(Parameters(n, "sim")), ParameterError);
  YAML::Node m = shipped();
  m["stations"].remove("discard");
  EXPECT_THROW(Workcell::fromParameters(Parameters(m, "sim")), ParameterError);
}

TEST(Workcell, ChartAndBarAreFlatFixtures) {
  const auto flat = Workcell::fromParameters(Parameters(shipped(), "sherd_detector")).flatFixtures();
  ASSERT_EQ(flat.size(), 2u);
  EXPECT_TRUE(flat[0].contains({0.38, -0.25}));
}
