#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

#include "rascal_perception/GraspPlanner.hpp"

using namespace rascal_perception;

namespace {
/// The defaults with the gripper of rascal_description's URDF (what the node reads).
PerceptionConfig withGripper() {
  PerceptionConfig c;
  c.gripper = rascal_workcell::GripperGeometry::fromPackageUrdf();
  return c;
}

SherdDetection sherd(double x, double y, double yaw, double length, double width, double height) {
  SherdDetection s;
  s.centre = Eigen::Vector3d(x, y, height);
  s.yaw = yaw;
  s.length = length;
  s.width = width;
  s.height = height;
  s.area = length * width;
  s.depth_valid = true;
  const Eigen::Rotation2Dd r(yaw);
  for (const auto& c : {Eigen::Vector2d(1, 1), Eigen::Vector2d(-1, 1), Eigen::Vector2d(-1, -1), Eigen::Vector2d(1, -1)}) {
    const Eigen::Vector2d p = Eigen::Vector2d(x, y) + r * Eigen::Vector2d(c.x() * length / 2, c.y() * width / 2);
    s.outline.emplace_back(p.x(), p.y(), 0.0);
  }
  return s;
}
}  // namespace

TEST(GraspPlanner, TakesTheGripperFromTheUrdf) {
  const GraspPlanner planner(withGripper());
  EXPECT_NEAR(planner.minOpening(), 0.030, 1e-12);  // facts 1.4: 30 .. 74 mm between the fingers
  EXPECT_NEAR(planner.maxOpening(), 0.074, 1e-12);
  EXPECT_NEAR(withGripper().gripper.fingertip_offset, 0.0044, 0.0001);  // the finger box's end
  EXPECT_THROW(GraspPlanner{PerceptionConfig()}, std::invalid_argument);  // no gripper: refused
}

TEST(GraspPlanner, FingersCloseAcrossTheMinorAxisPointingDown) {
  const PerceptionConfig c = withGripper();
  SherdDetection s = sherd(0.2, 0.25, 0.7, 0.06, 0.04, 0.010);
  GraspPlanner(c).plan(s);
  const Eigen::Matrix3d R = s.grasp.linear();
  EXPECT_NEAR(R.col(0).z(), -1.0, 1e-9);  // approach: gripper x straight down
  const Eigen::Vector2d minor(-std::sin(0.7), std::cos(0.7));
  EXPECT_NEAR(std::fabs(R.col(1).head<2>().dot(minor)), 1.0, 1e-9);  // closing along y = minor axis
  EXPECT_NEAR(s.grasp.translation().z(), 0.6 * 0.010 + c.gripper.fingertip_offset, 1e-9);
  EXPECT_NEAR(s.grasp_width, 0.04 + c.grasp_margin, 1e-12);
}

TEST(GraspPlanner, ClampsTheHeightAndTheOpening) {
  const PerceptionConfig c = withGripper();
  SherdDetection thin = sherd(0.2, 0.25, 0.0, 0.05, 0.010, 0.004);
  GraspPlanner(c).plan(thin);
  EXPECT_NEAR(thin.grasp.translation().z(), c.grasp_tip_clearance + c.gripper.fingertip_offset, 1e-9);
  EXPECT_DOUBLE_EQ(thin.grasp_width, c.gripper.minOpening());
  SherdDetection wide = sherd(0.2, 0.25, 0.0, 0.09, 0.07, 0.01);
  GraspPlanner(c).plan(wide);
  EXPECT_DOUBLE_EQ(wide.grasp_width, c.gripper.maxOpening());
  std::vector<SherdDetection> v{wide};
  GraspPlanner(c).score(v);
  EXPECT_NEAR(v[0].score, 0.3, 1e-9);  // wider than the gripper opens: fit 0.3
}

TEST(GraspPlanner, ScoresCrowdedSherdsLower) {
  const PerceptionConfig c = withGripper();
  std::vector<SherdDetection> v{sherd(0.10, 0.25, 0, 0.05, 0.04, 0.01), sherd(0.155, 0.25, 0, 0.05, 0.04, 0.01),
                                sherd(0.30, 0.25, 0, 0.05, 0.04, 0.01)};
  GraspPlanner(c).score(v);
  EXPECT_NEAR(v[0].clearance, 0.005, 1e-9);
  EXPECT_LT(v[0].score, v[2].score);
  EXPECT_NEAR(v[2].score, 1.0, 1e-9);
}

namespace {
/// A camera 0.3 m straight above (0.2, 0.25) on the table z = 0, and its height map with a
/// 10 mm tall neighbour beside each long side of a sherd lying along x there: strips 44 mm long
/// (x within 22 mm of the sherd's centre), from 18 to 40 mm off its axis.
struct CrowdedView {
  CameraView view;
  cv::Mat height;
  CrowdedView() {
    view.base_T_camera.translation() = Eigen::Vector3d(0.2, 0.25, 0.3);
    view.base_T_camera.linear() = Eigen::Vector3d(1, -1, -1).asDiagonal();  // optical z down
    const CameraIntrinsics& k = view.intrinsics;
    height = cv::Mat(k.height, k.width, CV_32F, cv::Scalar(0.0f));
    for (int v = 0; v < k.height; ++v) {
      for (int u = 0; u < k.width; ++u) {
        const Eigen::Vector3d p = view.base_T_camera * (0.3 * k.ray(u, v));  // on the table
        const double dx = std::fabs(p.x() - 0.2), dy = std::fabs(p.y() - 0.25);
        if (dx <= 0.022 && dy >= 0.018 && dy <= 0.040) height.at<float>(v, u) = 0.010f;
      }
    }
  }
};

/// What the planner looks at: `height` seen from `view`.
GraspContext seenFrom(const cv::Mat& height, const CameraView& view) {
  GraspContext context;
  context.height = &height;
  context.view = &view;
  return context;
}
}  // namespace

TEST(GraspPlanner, TurnsARoundSherdClearOfItsNeighboursButNotAnElongatedOne) {
  const GraspPlanner planner(withGripper());
  const CrowdedView crowd;
  GraspContext context = seenFrom(crowd.height, crowd.view);
  // near-round (40 x 36 mm): across its minor axis the fingers land on the neighbours; turned
  // 90 degrees they close on a chord only 11 % longer, clear of them
  SherdDetection round = sherd(0.2, 0.25, 0.0, 0.040, 0.036, 0.008);
  planner.plan(round, &context);
  EXPECT_TRUE(round.grasp_clear);
  EXPECT_NEAR(std::fabs(round.grasp.linear().col(1).x()), 1.0, 1e-9);  // closing along x: turned 90 degrees
  EXPECT_NEAR(round.grasp_width, 0.040 + 0.012, 1e-9);
  // elongated (62 x 35 mm): turned 90 degrees the fingers are clear too, but would close on its
  // ends (chord 1.8x its width): not offered as clear, so it waits for its neighbours to go
  SherdDetection longer = sherd(0.2, 0.25, 0.0, 0.062, 0.035, 0.008);
  planner.plan(longer, &context);
  EXPECT_FALSE(longer.grasp_clear);
  // with the neighbours gone it is taken across its minor axis
  const cv::Mat empty = cv::Mat::zeros(crowd.height.size(), CV_32F);
  context.height = &empty;
  SherdDetection alone = sherd(0.2, 0.25, 0.0, 0.062, 0.035, 0.008);
  planner.plan(alone, &context);
  EXPECT_TRUE(alone.grasp_clear);
  EXPECT_NEAR(std::fabs(alone.grasp.linear().col(1).y()), 1.0, 1e-9);
}

TEST(GraspPlanner, MovesTheGraspAlongAnElongatedSherdPastNeighboursBesideItsMiddle) {
  // 62 x 35 mm along x at (0.2, 0.25); 10 mm tall neighbours beside both long sides from its
  // left end to 2 mm right of its middle. Across the middle, turned 15 or 30 degrees the fingers
  // land on them; moved 45 % of the half-length to the right they close across its width, clear
  const GraspPlanner planner(withGripper());
  const CrowdedView crowd;
  cv::Mat height = cv::Mat::zeros(crowd.height.size(), CV_32F);
  const CameraIntrinsics& k = crowd.view.intrinsics;
  for (int v = 0; v < k.height; ++v) {
    for (int u = 0; u < k.width; ++u) {
      const Eigen::Vector3d p = crowd.view.base_T_camera * (0.3 * k.ray(u, v));
      const double dx = p.x() - 0.2, dy = std::fabs(p.y() - 0.25);
      if (dx >= -0.040 && dx <= 0.002 && dy >= 0.020 && dy <= 0.045) height.at<float>(v, u) = 0.010f;
    }
  }
  GraspContext context = seenFrom(height, crowd.view);
  SherdDetection s = sherd(0.2, 0.25, 0.0, 0.062, 0.035, 0.008);
  planner.plan(s, &context);
  EXPECT_TRUE(s.grasp_clear);
  EXPECT_NEAR(std::fabs(s.grasp.linear().col(1).y()), 1.0, 1e-9);  // still closing across y
  EXPECT_NEAR(s.grasp.translation().x(), 0.2 + 0.45 * 0.031, 1e-9);
  EXPECT_NEAR(s.grasp.translation().y(), 0.25, 1e-9);
  EXPECT_NEAR(s.grasp_width, 0.035 + 0.012, 1e-9);
  // mirrored, it moves the other way
  cv::Mat mirrored;
  cv::flip(height, mirrored, 1);  // the camera's x is the table's x
  context.height = &mirrored;
  SherdDetection t = sherd(0.2, 0.25, 0.0, 0.062, 0.035, 0.008);
  planner.plan(t, &context);
  EXPECT_TRUE(t.grasp_clear);
  EXPECT_LT(t.grasp.translation().x(), 0.2 - 0.01);
}

TEST(GraspPlanner, MovesAnElongatedSherdsGraspBeforeTurningItFarAndTurnsARoundOne) {
  // 30 degrees off the minor axis an elongated sherd's fingers close near its narrow ends; moved
  // 45 % of the half-length they still close across it. A round sherd turns freely.
  using Offer = GraspPlanner::Offer;
  const Offer turned30{30.0, 0.0}, moved45{0.0, 0.45}, turned45{45.0, 0.0}, moved25{0.0, 0.25};
  EXPECT_LT(GraspPlanner::holdCost(moved45, 0.45), GraspPlanner::holdCost(turned30, 0.45));
  EXPECT_LT(GraspPlanner::holdCost(moved25, 0.45), GraspPlanner::holdCost(Offer{15.0, 0.25}, 0.45));
  EXPECT_LT(GraspPlanner::holdCost(turned45, 0.05), GraspPlanner::holdCost(moved25, 0.05));
  EXPECT_EQ(GraspPlanner::holdCost(Offer{0.0, 0.0}, 0.6), 0.0);  // the minor axis first, always
  EXPECT_EQ(GraspPlanner::holdCost(turned30, 0.4), GraspPlanner::holdCost(turned30, 0.9));  // in full
}

TEST(GraspPlanner, KeepsTheGripperBarOffANeighbourStandingBeyondTheFingers) {
  // 60 x 36 mm along x at (0.2, 0.25), 8 mm high; a neighbour standing on its edge along one
  // long side, 40-48 mm off the axis (past the fingers, which reach 32 mm), x within 60 mm. At
  // 50 mm tall it stands higher than the gripper bar, 32 mm over the fingertips and 100 mm
  // across the closing direction: no grasp is clear (turned 90 degrees, the bar along it, the
  // fingers would close on the sherd's ends). At 20 mm the bar passes over it.
  const GraspPlanner planner(withGripper());
  ASSERT_FALSE(withGripper().gripper.hand.empty());
  const CrowdedView crowd;
  const CameraIntrinsics& k = crowd.view.intrinsics;
  for (const float tall : {0.050f, 0.020f}) {
    cv::Mat height = cv::Mat::zeros(crowd.height.size(), CV_32F);
    for (int v = 0; v < k.height; ++v) {
      for (int u = 0; u < k.width; ++u) {
        const Eigen::Vector3d p = crowd.view.base_T_camera * (0.3 * k.ray(u, v));
        const double dx = std::fabs(p.x() - 0.2), dy = p.y() - 0.25;
        if (dx <= 0.060 && dy >= 0.040 && dy <= 0.048) height.at<float>(v, u) = tall;
      }
    }
    GraspContext context = seenFrom(height, crowd.view);
    SherdDetection s = sherd(0.2, 0.25, 0.0, 0.060, 0.036, 0.008);
    planner.plan(s, &context);
    EXPECT_EQ(s.grasp_clear, tall < 0.03f) << "neighbour " << tall * 1e3 << " mm tall";
    if (tall < 0.03f) {
      EXPECT_NEAR(std::fabs(s.grasp.linear().col(1).y()), 1.0, 1e-9);  // across its width
    } else {
      // the grasp to try is the one turned 90 degrees, its bar along the neighbour, not over it
      EXPECT_NEAR(std::fabs(s.grasp.linear().col(1).x()), 1.0, 1e-9);
    }
  }
}

TEST(GraspPlanner, TurnsASherdTooNarrowToHoldAcrossItsMinorAxis) {
  // 31 mm across: the fingers would stop 1 mm short of shut (30 mm), which the gripper reads as
  // empty; turned 15 degrees they close on a 42 mm chord of the 47 x 31 mm outline
  const GraspPlanner planner(withGripper());
  EXPECT_NEAR(planner.holdableChord(), 0.033, 1e-12);  // 30 mm shut + the 2 mm held margin + 1 mm
  const CrowdedView crowd;
  const cv::Mat empty = cv::Mat::zeros(crowd.height.size(), CV_32F);
  GraspContext context = seenFrom(empty, crowd.view);
  SherdDetection narrow = sherd(0.2, 0.25, 0.0, 0.047, 0.031, 0.012);
  planner.plan(narrow, &context);
  EXPECT_TRUE(narrow.grasp_clear);
  const double turn = std::atan2(-narrow.grasp.linear().col(1).x(), narrow.grasp.linear().col(1).y());
  EXPECT_NEAR(std::fabs(turn), 15.0 * M_PI / 180.0, 1e-9);
  EXPECT_GE(narrow.grasp_width - 0.012, planner.holdableChord());
  // 34 mm across is held as it is
  SherdDetection wider = sherd(0.2, 0.25, 0.0, 0.047, 0.034, 0.012);
  planner.plan(wider, &context);
  EXPECT_NEAR(wider.grasp_width, 0.034 + 0.012, 1e-9);
}

TEST(GraspPlanner, ClosesUnderTheLowerEndOfASherdLeaningOnAnother) {
  // 50 x 36 mm along x at (0.2, 0.25), its top rising across its width (the fingers' chord)
  // from 6 mm to 36 mm: one edge on the table, the other raised on a sherd the splitter saw it
  // lie on (support 21 mm). The rule alone (21 mm + 60 % of the 15 mm above it) closes the
  // fingertips at 30 mm: above the lower half of the sherd, the lower finger meets nothing.
  const PerceptionConfig c = withGripper();
  const GraspPlanner planner(c);
  const CrowdedView crowd;
  cv::Mat height = cv::Mat::zeros(crowd.height.size(), CV_32F);
  cv::Mat inside = cv::Mat::zeros(crowd.height.size(), CV_8U);
  const CameraIntrinsics& k = crowd.view.intrinsics;
  for (int v = 0; v < k.height; ++v) {
    for (int u = 0; u < k.width; ++u) {
      const Eigen::Vector3d p = crowd.view.base_T_camera * (0.3 * k.ray(u, v));
      const double dx = p.x() - 0.2, dy = p.y() - 0.25;
      if (std::fabs(dx) > 0.025 || std::fabs(dy) > 0.018) continue;
      height.at<float>(v, u) = static_cast<float>(0.006 + (dy + 0.018) / 0.036 * 0.030);
      inside.at<uint8_t>(v, u) = 255;
    }
  }
  Blob own;
  own.bounds = cv::boundingRect(inside);
  own.mask = inside(own.bounds).clone();
  GraspContext context = seenFrom(height, crowd.view);
  context.own = &own;
  SherdDetection leaning = sherd(0.2, 0.25, 0.0, 0.050, 0.036, 0.036);
  leaning.support = 0.021;
  planner.plan(leaning, &context);
  const double tip = leaning.grasp.translation().z() - c.gripper.fingertip_offset;
  EXPECT_LT(tip, 0.006 + 0.006 * 0.030 / 0.036);  // under the top within 6 mm of the lower edge
  EXPECT_GE(tip, c.grasp_tip_clearance - 1e-9);
  // standing steeper than 45 degrees (its top rising 44 mm across the 36 mm chord) it keeps the
  // rule's height: pinched by its lower edge it would hang from the fingers
  for (int v = 0; v < k.height; ++v) {
    for (int u = 0; u < k.width; ++u) {
      if (!inside.at<uint8_t>(v, u)) continue;
      const Eigen::Vector3d p = crowd.view.base_T_camera * (0.3 * k.ray(u, v));
      height.at<float>(v, u) = static_cast<float>(0.006 + (p.y() - 0.25 + 0.018) / 0.036 * 0.044);
    }
  }
  SherdDetection steep = sherd(0.2, 0.25, 0.0, 0.050, 0.036, 0.050);
  steep.support = 0.021;
  planner.plan(steep, &context);
  EXPECT_NEAR(steep.grasp.translation().z() - c.gripper.fingertip_offset, 0.021 + 0.6 * (0.050 - 0.021), 1e-9);
  // lying flat, 8 mm thick, the same sherd is taken where the rule says
  height.setTo(0.008f, inside);
  SherdDetection flat = sherd(0.2, 0.25, 0.0, 0.050, 0.036, 0.008);
  planner.plan(flat, &context);
  EXPECT_NEAR(flat.grasp.translation().z() - c.gripper.fingertip_offset, 0.6 * 0.008, 1e-9);
}

TEST(GraspPlanner, ANeighboursCornerUnderAFingerBlocksItAFlyingPixelDoesNot) {
  // 50 x 40 mm along x at (0.2, 0.25), 8 mm tall: across its minor axis a finger's footprint
  // reaches 26 to 34 mm off its axis, 10 mm either way along it. A 10 mm tall neighbour's
  // corner 4 x 4 mm under it (four of the footprint's 55 samples, 2 mm apart) blocks it: the
  // 90th percentile taken before let it through, and the finger came down on the neighbour.
  // A 2 x 4 mm speck (two samples: flying pixels at an edge) does not.
  const GraspPlanner planner(withGripper());
  const CrowdedView plain;  // its view; its height map is replaced
  const CameraIntrinsics& k = plain.view.intrinsics;
  auto corner = [&](double x0, double x1) {
    cv::Mat h(k.height, k.width, CV_32F, cv::Scalar(0.0f));
    for (int v = 0; v < k.height; ++v) {
      for (int u = 0; u < k.width; ++u) {
        const Eigen::Vector3d p = plain.view.base_T_camera * (0.3 * k.ray(u, v));
        const double dx = p.x() - 0.2, dy = p.y() - 0.25;
        if (dx >= x0 && dx <= x1 && dy >= 0.025 && dy <= 0.029) h.at<float>(v, u) = 0.010f;
      }
    }
    return h;
  };
  const cv::Mat blocking = corner(0.007, 0.011), speck = corner(0.007, 0.009);
  GraspContext context = seenFrom(blocking, plain.view);
  SherdDetection s = sherd(0.2, 0.25, 0.0, 0.050, 0.040, 0.008);
  planner.plan(s, &context);
  const bool across =
      std::fabs(s.grasp.linear().col(1).y()) > 0.999 && std::fabs(s.grasp.translation().x() - 0.2) < 1e-9;
  EXPECT_FALSE(across && s.finger_clearance >= GraspPlanner::kFingerClearance);  // not taken so
  context.height = &speck;
  SherdDetection t = sherd(0.2, 0.25, 0.0, 0.050, 0.040, 0.008);
  planner.plan(t, &context);
  EXPECT_TRUE(t.grasp_clear);
  EXPECT_NEAR(std::fabs(t.grasp.linear().col(1).y()), 1.0, 1e-9);  // across the minor axis
  EXPECT_NEAR(t.grasp.translation().x(), 0.2, 1e-9);
}
