#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "ShippedConfig.hpp"
#include "rascal_sim/MunsellTable.hpp"
#include "rascal_sim/ScenarioLoader.hpp"
#include "rascal_sim/SherdMeshBuilder.hpp"

using namespace rascal_sim;

namespace {
struct Fixture {
  const WorldLayout& layout = rascal_sim_test::layout();
  MunsellTable munsell{std::string(RASCAL_SIM_DATA_DIR) + "/munsell_soil_hues_grid_renotation.csv"};
};

void worldBox(const SherdSpec& s, Eigen::Vector2d& lo, Eigen::Vector2d& hi) {
  const Eigen::Rotation2Dd r(s.pose.z());
  lo = Eigen::Vector2d::Constant(1e9);
  hi = -lo;
  for (const auto& p : s.outline) {
    const Eigen::Vector2d w = r * p + s.pose.head<2>();
    lo = lo.cwiseMin(w);
    hi = hi.cwiseMax(w);
  }
}
}  // namespace

TEST(ScenarioLoader, GeneratesSeededSpacedSherdsOnThePickupMat) {
  Fixture f;
  ScenarioLoader loader(f.layout, f.munsell);
  const std::string yaml = "name: t\nseed: 4\ngenerate: {count: 10, station: pickup, min_spacing: 0.012}\n";
  const Scenario a = loader.parse(yaml);
  const Scenario b = loader.parse(yaml);
  ASSERT_EQ(a.sherds.size(), 10u);
  for (size_t i = 0; i < a.sherds.size(); ++i) {
    EXPECT_EQ(a.sherds[i].pose, b.sherds[i].pose);
    Eigen::Vector2d lo, hi;
    worldBox(a.sherds[i], lo, hi);
    const TableRect& mat = f.layout.station(StationType::Pickup).area;
    const Eigen::Vector2d mat_lo = mat.centre - mat.size / 2;
    const Eigen::Vector2d mat_hi = mat.centre + mat.size / 2;
    EXPECT_GE(lo.x(), mat_lo.x() - 1e-9);
    EXPECT_GE(lo.y(), mat_lo.y() - 1e-9);
    EXPECT_LE(hi.x(), mat_hi.x() + 1e-9);
    EXPECT_LE(hi.y(), mat_hi.y() + 1e-9);
    for (size_t j = 0; j < i; ++j) {
      Eigen::Vector2d lo2, hi2;
      worldBox(a.sherds[j], lo2, hi2);
      const double gap = std::max({lo.x() - hi2.x(), lo2.x() - hi.x(), lo.y() - hi2.y(), lo2.y() - hi.y()});
      EXPECT_GE(gap, 0.012 - 1e-9) << a.sherds[i].name << " vs " << a.sherds[j].name;
    }
    const SherdGeometry g = SherdMeshBuilder::build(a.sherds[i]);
    EXPECT_GT(g.mass, 0.003);   // kg
    EXPECT_LT(g.mass, 0.120);
    EXPECT_GE(g.length, 0.02 - 1e-9);
    EXPECT_LE(g.length, 0.10 + 1e-9);
    EXPECT_GE(a.sherds[i].density, 1800);
    EXPECT_LE(a.sherds[i].density, 2000);
  }
}

TEST(ScenarioLoader, MassFollowsVolumeTimesDensity) {
  SherdSpec s;
  s.name = "slab";
  s.outline = {{-0.025, -0.02}, {0.025, -0.02}, {0.025, 0.02}, {-0.025, 0.02}};
  s.thickness = 0.007;
  s.density = 1800;
  const SherdGeometry g = SherdMeshBuilder::build(s);
  // facts sherds_and_colour.md §0: 5 x 4 cm, 7 mm at 1.8 g/cm^3 is about 25 g
  EXPECT_NEAR(g.mass, 0.05 * 0.04 * 0.007 * 1800, 1e-6);
}

TEST(ScenarioLoader, LoadsTheFragmentMesh) {
  Fixture f;
  ScenarioLoader loader(f.layout, f.munsell);
  const Scenario s = loader.parse("sherds:\n  - {name: frag, mesh: fragment, pose: [0.1, 0.2, 0], density: 1900}\n");
  ASSERT_EQ(s.sherds.size(), 1u);
  const SherdGeometry g = SherdMeshBuilder::build(s.sherds[0]);
  EXPECT_NEAR(g.volume, 29.6e-6, 0.5e-6);  // data/sherds/SOURCE.md: 29.6 cm^3
}

TEST(ScenarioLoader, ErrorsNameTheKey) {
  Fixture f;
  ScenarioLoader loader(f.layout, f.munsell);
  try {
    loader.parse("sherds:\n  - {pose: [0, 0, 0], thickness: 0.5}\n");
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("sherds[0].thickness"), std::string::npos) << e.what();
  }
  try {
    loader.parse("lighting: {brightness: 3}\n");
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("lighting.brightness"), std::string::npos) << e.what();
  }
  try {
    loader.parse("lighting: {realism: {cast_shadow: 0.95}}\n");
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("lighting.realism.cast_shadow"), std::string::npos) << e.what();
  }
}

TEST(ScenarioLoader, StationOffsetsAreReadAndABadOneIsNamed) {
  Fixture f;
  ScenarioLoader loader(f.layout, f.munsell);
  const std::string pickup = f.layout.station(StationType::Pickup).name;
  const Scenario s = loader.parse("station_offsets: {" + pickup + ": [0.02, -0.015, 0.06]}\n"
                                  "generate: {count: 6, station: pickup}\n");
  ASSERT_EQ(s.station_offsets.size(), 1u);
  EXPECT_EQ(s.station_offsets.at(pickup), (StationOffset{0.02, -0.015, 0.06}));
  TableRect mat = f.layout.station(StationType::Pickup).area;
  mat.centre += Eigen::Vector2d(0.02, -0.015);
  for (const SherdSpec& sp : s.sherds) EXPECT_TRUE(mat.contains(sp.pose.head<2>())) << sp.name;  // on the moved mat
  EXPECT_TRUE(loader.parse("name: t\n").station_offsets.empty());
  const std::vector<std::string> bad_ones{pickup + ": [0.2, 0, 0]", pickup + ": [0, 0, -0.3]",
                                          pickup + ": [0, 0]", "nowhere: [0, 0, 0]"};
  for (const std::string& bad : bad_ones) {
    const std::string key = "station_offsets." + bad.substr(0, bad.find(':'));
    try {
      loader.parse("station_offsets: {" + bad + "}\n");
      FAIL() << bad << " accepted";
    } catch (const std::runtime_error& e) {
      const std::string why = e.what();
      EXPECT_EQ(why.rfind("scenario key '" + key + "': ", 0), 0u) << why;
      EXPECT_EQ(why.find('\n'), std::string::npos) << why;
    }
  }
}

TEST(ScenarioLoader, RealismIsOffUnlessAskedForAndAKeyLeftOutTakesItsDefault) {
  Fixture f;
  ScenarioLoader loader(f.layout, f.munsell);
  EXPECT_FALSE(loader.parse("lighting: {brightness: 1.0}\n").lighting.realism.any());
  const Realism r = loader.parse("lighting: {realism: {glare: 0.2}}\n").lighting.realism;
  EXPECT_DOUBLE_EQ(r.glare, 0.2);
  EXPECT_DOUBLE_EQ(r.texture, 1.0);
  EXPECT_DOUBLE_EQ(r.cast_shadow, 0.5);
}

TEST(ScenarioLoader, ShippedScenariosLoad) {
  Fixture f;
  ScenarioLoader loader(f.layout, f.munsell);
  const std::string dir = std::string(RASCAL_SIM_DATA_DIR) + "/../../../config/scenarios/";
  const Scenario demo = loader.load(dir + "demo_10.yaml");
  EXPECT_EQ(demo.sherds.size(), 10u);
  const Scenario small = loader.load(dir + "small_3.yaml");
  ASSERT_EQ(small.sherds.size(), 3u);
  EXPECT_FALSE(small.sherds[2].mesh_file.empty());
  for (const auto& s : demo.sherds) EXPECT_NO_THROW(SherdMeshBuilder::build(s)) << s.name;
  const Scenario field = loader.load(dir + "field_10.yaml");
  EXPECT_EQ(field.sherds.size(), 10u);
  EXPECT_TRUE(field.lighting.realism.any());
}

TEST(ScenarioLoader, TouchingPairsMeet) {
  Fixture f;
  ScenarioLoader loader(f.layout, f.munsell);
  const Scenario s = loader.parse("seed: 5\ngenerate: {count: 10, touching_pairs: 2}\n");
  ASSERT_EQ(s.sherds.size(), 10u);
  // the collision boxes of each pair are 0.2 mm apart: check on a fine grid of box points
  auto minDistance = [](const SherdSpec& a, const SherdSpec& b) {
    const SherdGeometry ga = SherdMeshBuilder::build(a), gb = SherdMeshBuilder::build(b);
    auto points = [](const SherdSpec& s, const SherdGeometry& g) {
      std::vector<Eigen::Vector2d> p;
      const Eigen::Rotation2Dd r(s.pose.z());
      for (int i = 0; i <= 100; ++i) {
        const double t = i / 100.0 - 0.5;
        const double hx = g.box_size.x() / 2, hy = g.box_size.y() / 2;
        for (const Eigen::Vector2d& q : {Eigen::Vector2d(t * 2 * hx, -hy), Eigen::Vector2d(t * 2 * hx, hy),
                                         Eigen::Vector2d(-hx, t * 2 * hy), Eigen::Vector2d(hx, t * 2 * hy)}) {
          p.push_back(r * q + s.pose.head<2>());
        }
      }
      return p;
    };
    double d = 1e9;
    for (const auto& p : points(a, ga)) {
      for (const auto& q : points(b, gb)) d = std::min(d, (p - q).norm());
    }
    return d;
  };
  EXPECT_LT(minDistance(s.sherds[0], s.sherds[1]), 0.001);
  EXPECT_LT(minDistance(s.sherds[2], s.sherds[3]), 0.001);
  EXPECT_GT(minDistance(s.sherds[4], s.sherds[5]), 0.015);  // the third pair stays apart
}

TEST(SherdMeshBuilder, CollisionStripsCoverTheOutlineButNotTheBoxCorners) {
  // a diamond: its bounding box corners are far outside it
  const std::vector<Eigen::Vector2d> diamond = {{0.03, 0.0}, {0.0, 0.02}, {-0.03, 0.0}, {0.0, -0.02}};
  const auto strips = SherdMeshBuilder::collisionStrips(diamond, 0.008, 6);
  ASSERT_EQ(strips.size(), 6u);
  auto covered = [&](const Eigen::Vector2d& p) {
    for (const auto& b : strips) {
      if (std::abs(p.x() - b.centre.x()) <= b.size.x() / 2 + 1e-9 &&
          std::abs(p.y() - b.centre.y()) <= b.size.y() / 2 + 1e-9) return true;
    }
    return false;
  };
  for (const auto& v : diamond) EXPECT_TRUE(covered(v));
  for (double t = 0.0; t <= 1.0; t += 0.05) EXPECT_TRUE(covered(diamond[0] * (1 - t) + diamond[1] * t));
  EXPECT_FALSE(covered({0.028, 0.018}));
  EXPECT_FALSE(covered({-0.028, -0.018}));
  for (const auto& b : strips) EXPECT_DOUBLE_EQ(b.size.z(), 0.008);
}

TEST(SherdMeshBuilder, ScannedFragmentOutlineIsItsTopViewHull) {
  SherdSpec s;
  s.name = "fragment";
  s.mesh_file = std::string(RASCAL_SIM_DATA_DIR) + "/archaide_braccio_frag_1.stl";
  s.density = 1900;
  const SherdGeometry g = SherdMeshBuilder::build(s);
  ASSERT_GE(g.outline.size(), 5u);
  double area = 0.0;
  for (size_t i = 0; i < g.outline.size(); ++i) {
    const auto& a = g.outline[i];
    const auto& b = g.outline[(i + 1) % g.outline.size()];
    area += (a.x() * b.y() - a.y() * b.x()) / 2;
  }
  EXPECT_GT(area, 0.0);  // counter-clockwise
  EXPECT_LT(area, 0.95 * g.box_size.x() * g.box_size.y());  // not the bounding box
  EXPECT_FALSE(g.collision.empty());
}

TEST(SherdMeshBuilder, PrincipalAxesOfATurnedRectangle) {
  const Eigen::Rotation2Dd r(0.5);
  std::vector<Eigen::Vector2d> rect;
  for (const Eigen::Vector2d& q : {Eigen::Vector2d(-0.03, -0.015), Eigen::Vector2d(0.03, -0.015),
                                   Eigen::Vector2d(0.03, 0.015), Eigen::Vector2d(-0.03, 0.015)}) {
    rect.push_back(r * q + Eigen::Vector2d(0.01, -0.02));
  }
  const OutlineAxes ax = SherdMeshBuilder::principalAxes(rect);
  EXPECT_NEAR(std::abs(ax.major.dot(Eigen::Vector2d(std::cos(0.5), std::sin(0.5)))), 1.0, 1e-9);
  EXPECT_NEAR(ax.length, 0.06, 1e-9);
  EXPECT_NEAR(ax.width, 0.03, 1e-9);
  std::reverse(rect.begin(), rect.end());  // clockwise: the same axes
  EXPECT_NEAR(SherdMeshBuilder::principalAxes(rect).length, 0.06, 1e-9);
}

TEST(ScenarioLoader, AHeapIsDroppedOntoOneSpotInLayersOnTheMat) {
  Fixture f;
  ScenarioLoader loader(f.layout, f.munsell);
  const Scenario s = loader.parse(
      "seed: 7\ngenerate: {count: 20, heap: {centre: [0.16, 0.25], spread: 0.03, drop_height: 0.01}}\n");
  ASSERT_EQ(s.sherds.size(), 20u);
  const TableRect& mat = f.layout.station(StationType::Pickup).area;
  int on_another = 0;
  for (size_t i = 0; i < s.sherds.size(); ++i) {
    Eigen::Vector2d lo, hi;
    worldBox(s.sherds[i], lo, hi);
    EXPECT_TRUE(mat.contains(lo) && mat.contains(hi)) << s.sherds[i].name;
    if (s.sherds[i].drop_height > 0.01 + 1e-9) ++on_another;  // let go above an earlier sherd
  }
  EXPECT_GE(on_another, 10);  // a heap, not a spread: most sherds start on others
  EXPECT_THROW(loader.parse("generate: {count: 5, heap: {centre: [0.9, 0.0]}}\n"), std::runtime_error);
}
