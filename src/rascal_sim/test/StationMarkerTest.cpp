#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <map>
#include <opencv2/aruco.hpp>
#include <opencv2/imgproc.hpp>
#include <string>

#include "ShippedConfig.hpp"
#include "rascal_sim/Simulator.hpp"

using namespace rascal_sim;
using rascal_workcell::GripperGeometry;
using rascal_workcell::ParameterError;
using rascal_workcell::Parameters;

namespace {
/// The shipped configuration with the pickup station's markers set here (the site may change
/// the shipped ones) and every other station's taken off.
YAML::Node withPickupMarkers() {
  YAML::Node root = YAML::LoadFile(RASCAL_CONFIG_PATH);
  for (auto kv : root["stations"]) {
    kv.second.remove("marker_ids");
    kv.second.remove("marker_positions");
  }
  root["stations"]["pickup"]["marker_ids"] = YAML::Load("[3, 17]");
  root["stations"]["pickup"]["marker_positions"] = YAML::Load("[[-0.185, -0.05], [-0.185, 0.05]]");
  return root;
}

SimParameters read(const YAML::Node& root) {
  return SimParameters::read(Parameters(root, "sim"), GripperGeometry::fromPackageUrdf(), RASCAL_SIM_DATA_DIR);
}

/// Optical frame `height` above (x, y), looking straight down (image x = world x).
Eigen::Isometry3d downward(double x, double y, double height) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() << 1, 0, 0, 0, -1, 0, 0, 0, -1;
  T.translation() = Eigen::Vector3d(x, y, height);
  return T;
}
}  // namespace

TEST(StationMarker, AreReadWithTheirStationAndBothKeysOrNeither) {
  const SimParameters p = read(withPickupMarkers());  // read() ends with checkAllRead()
  ASSERT_EQ(p.layout.markers.size(), 2u);
  const Eigen::Vector2d pickup = p.layout.station(StationType::Pickup).area.centre;
  EXPECT_EQ(p.layout.markers[0].station, "pickup");
  EXPECT_EQ(p.layout.markers[0].id, 3);
  EXPECT_EQ(p.layout.markers[1].id, 17);
  EXPECT_TRUE(p.layout.markers[1].centre.isApprox(pickup + Eigen::Vector2d(-0.185, 0.05)));
  EXPECT_EQ(p.layout.markers[1].yaw, 0.0);

  YAML::Node root = withPickupMarkers();
  root["stations"]["pickup"].remove("marker_positions");
  try {
    read(root);
    FAIL() << "ids without positions accepted";
  } catch (const ParameterError& e) {
    const std::string why = e.what();
    EXPECT_EQ(why.rfind("stations.pickup.marker_positions: ", 0), 0u) << why;
    EXPECT_EQ(why.find('\n'), std::string::npos) << why;
  }
}

TEST(StationMarker, NoneConfiguredNoneDrawn) {
  YAML::Node root = withPickupMarkers();
  root["stations"]["pickup"].remove("marker_ids");
  root["stations"]["pickup"].remove("marker_positions");
  const SimParameters p = read(root);  // still every key read: has() counts
  EXPECT_TRUE(p.layout.markers.empty());
  Simulator sim(p.layout, p.options);
  EXPECT_TRUE(sim.world().layout().markers.empty());
}

TEST(StationMarker, AnOffsetMovesAndTurnsTheStationWithEverythingOnIt) {
  WorldLayout l = read(withPickupMarkers()).layout;
  const WorldLayout configured = l;
  const Station& discard = configured.station(StationType::Discard);
  l.offsetStation(discard.name, 0.03, -0.02, 0.1);
  const Eigen::Vector2d shift(0.03, -0.02);
  const Eigen::Rotation2Dd turn(0.1);
  const Station& moved_discard = l.station(StationType::Discard);
  EXPECT_TRUE(moved_discard.area.centre.isApprox(discard.area.centre + shift));
  EXPECT_NEAR(moved_discard.area.yaw, 0.1, 1e-12);
  EXPECT_TRUE(moved_discard.place_at.isApprox(discard.place_at + shift));
  for (size_t i = 0; i < l.boxes.size(); ++i) {
    const bool of_discard = l.boxes[i].station == discard.name;
    const Eigen::Vector2d was = configured.boxes[i].centre.head<2>();
    const Eigen::Vector2d expected =
        of_discard ? Eigen::Vector2d(discard.area.centre + shift + turn * (was - discard.area.centre)) : was;
    EXPECT_LT((l.boxes[i].centre.head<2>() - expected).norm(), 1e-12) << l.boxes[i].name;
    EXPECT_NEAR(l.boxes[i].yaw, of_discard ? 0.1 : 0.0, 1e-12) << l.boxes[i].name;
    EXPECT_EQ(l.boxes[i].size, configured.boxes[i].size) << l.boxes[i].name;
  }
  EXPECT_EQ(l.workcell.station(StationType::Discard).area.centre, discard.area.centre);  // as configured
  EXPECT_EQ(l.markers[0].centre, configured.markers[0].centre);  // pickup's markers stay
  EXPECT_THROW(l.offsetStation("nowhere", 0, 0, 0), std::invalid_argument);
}

TEST(StationMarker, RenderedMarkersAreDetectedWhereTheirCornersProject) {
  const SimParameters p = read(withPickupMarkers());
  SimulatorOptions o = p.options;
  o.archival_width = 400;  // small archival frames keep the test fast
  o.archival_height = 300;
  Simulator sim(p.layout, o);
  for (int i = 0; i < 10; ++i) sim.step();
  const double t = sim.time();
  Scenario s;
  const StationOffset off{0.02, -0.015, 0.06};
  s.station_offsets["pickup"] = off;
  sim.load(s);
  EXPECT_EQ(sim.time(), t);  // the rebuilt world carries the clock on
  const WorldLayout& real = sim.world().layout();
  const Eigen::Vector2d centre = p.layout.station(StationType::Pickup).area.centre;
  EXPECT_TRUE(real.station(StationType::Pickup).area.centre.isApprox(centre + Eigen::Vector2d(off.dx, off.dy)));

  // the wrist camera 25 cm straight above the middle between the two markers
  const Eigen::Vector2d between = (real.markers[0].centre + real.markers[1].centre) / 2;
  const Eigen::Isometry3d camera = downward(between.x(), between.y(), 0.25);
  const CameraModel cam = CameraModel::wristD435();
  std::vector<RenderItem> items;
  sim.world().renderItems(items, false);
  RenderOutput out;
  Renderer().render(items, cam, camera, out);
  cv::Mat grey;
  cv::cvtColor(out.colour, grey, cv::COLOR_RGB2GRAY);
  std::vector<int> ids;
  std::vector<std::vector<cv::Point2f>> found;
  const cv::Ptr<cv::aruco::DetectorParameters> params = cv::aruco::DetectorParameters::create();
  params->cornerRefinementMethod = cv::aruco::CORNER_REFINE_SUBPIX;
  cv::aruco::detectMarkers(grey, cv::aruco::getPredefinedDictionary(cv::aruco::DICT_4X4_50), found, ids, params);
  ASSERT_EQ(ids.size(), 2u);
  std::map<int, std::vector<cv::Point2f>> by_id;
  for (size_t i = 0; i < ids.size(); ++i) by_id[ids[i]] = found[i];
  ASSERT_EQ(by_id.count(3), 1u);
  ASSERT_EQ(by_id.count(17), 1u);

  // where the calibrator expects them: the configured station frame turned by dyaw about the
  // configured centre and shifted by (dx, dy); OpenCV's corner order
  const Eigen::Rotation2Dd turn(off.dyaw);
  const std::map<int, Eigen::Vector2d> configured{{3, {-0.185, -0.05}}, {17, {-0.185, 0.05}}};
  const double h = StationMarker::kSide / 2;
  const std::array<Eigen::Vector2d, 4> corner_offsets{{{-h, h}, {h, h}, {h, -h}, {-h, -h}}};
  for (const auto& [id, position] : configured) {
    for (int k = 0; k < 4; ++k) {
      const Eigen::Vector2d xy = centre + Eigen::Vector2d(off.dx, off.dy) + turn * (position + corner_offsets[k]);
      const Eigen::Vector2d uv = cam.project(camera.inverse() * Eigen::Vector3d(xy.x(), xy.y(), StationMarker::kZ));
      EXPECT_NEAR(by_id[id][k].x, uv.x(), 1.0) << "marker " << id << " corner " << k;
      EXPECT_NEAR(by_id[id][k].y, uv.y(), 1.0) << "marker " << id << " corner " << k;
    }
  }
  for (const StationMarker& m : real.markers) {
    ASSERT_TRUE(configured.count(m.id));
    EXPECT_TRUE(m.corners()[0].isApprox(centre + Eigen::Vector2d(off.dx, off.dy) +
                                        turn * (configured.at(m.id) + corner_offsets[0])));
  }
}
