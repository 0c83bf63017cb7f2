#include <gtest/gtest.h>

#include <cmath>

#include "ShippedConfig.hpp"
#include "rascal_sim/MunsellTable.hpp"
#include "rascal_sim/ScenarioLoader.hpp"
#include "rascal_sim/World.hpp"

using namespace rascal_sim;
using rascal_sim_test::gripper;
using rascal_sim_test::layout;

namespace {
SherdSpec slab(const std::string& name, double x, double y, double drop = 0.0) {
  SherdSpec s;
  s.name = name;
  s.outline = {{-0.025, -0.018}, {0.02, -0.02}, {0.026, 0.015}, {-0.02, 0.02}};
  s.thickness = 0.008;
  s.curvature = 8.0;
  s.density = 1900;
  s.pose = {x, y, 0.3};
  s.drop_height = drop;
  return s;
}
}  // namespace

TEST(World, DroppedSherdComesToRestWithinTwoSeconds) {
  World world(layout(), gripper());
  world.spawn({slab("a", 0.15, 0.25, 0.05)});
  const double z0 = world.sherd(0).pose.translation().z();
  double rest_at = -1;
  for (int i = 0; i < 2000; ++i) {
    world.step(0.001);
    const SherdState s = world.sherd(0);
    const bool still = s.linear_velocity.norm() < 1e-3 && s.angular_velocity.norm() < 1e-2;
    if (still && rest_at < 0) rest_at = world.time();
    if (!still) rest_at = -1;
  }
  const SherdState s = world.sherd(0);
  EXPECT_GT(rest_at, 0.0);
  EXPECT_LT(s.pose.translation().z(), z0 - 0.045);
  EXPECT_NEAR(s.pose.translation().z(), s.box_size.z() / 2, 0.002);
}

TEST(World, ArmLinkPassingThroughASherdPushesIt) {
  World world(layout(), gripper());
  // gripper pointing down with the fingertips 1 cm above the table, found on a coarse grid
  JointVector best{};
  double best_err = 1e9;
  for (double sh = -0.5; sh < 1.5; sh += 0.01) {
    for (double el = -1.0; el < 1.6; el += 0.01) {
      JointVector q{0, sh, el, 0, M_PI / 2 - sh - el, 0};
      const auto T = ArmKinematics::forward(q, gripper().finger_max);
      const Eigen::Vector3d p = T[kEeGripperLink].translation();
      const double err = std::abs(p.x() - 0.30) + std::abs(p.z() - 0.0);
      if (err < best_err) {
        best_err = err;
        best = q;
      }
    }
  }
  ASSERT_LT(best_err, 0.01);
  // a sherd at waist angle 0 (x = 0.30, on the table); sweep the waist from -0.5 to +0.5 rad
  SherdSpec s = slab("b", 0.30, 0.0);
  s.pose.z() = 0.0;
  world.spawn({s});
  JointVector q = best;
  q[0] = -0.5;
  world.placeArm(q, gripper().finger_max);
  const Eigen::Vector3d before = world.sherd(0).pose.translation();
  for (int i = 0; i < 1000; ++i) {
    q[0] = -0.5 + 1.0 * (i + 1) / 1000.0;
    world.setArmTarget(q, gripper().finger_max);
    world.step(0.001);
  }
  for (int i = 0; i < 500; ++i) world.step(0.001);
  const Eigen::Vector3d after = world.sherd(0).pose.translation();
  EXPECT_GT((after - before).head<2>().norm(), 0.01) << "before " << before.transpose() << " after "
                                                     << after.transpose();
}

TEST(World, AHeapSettlesInLayersAndStaysOnTheMat) {
  const MunsellTable munsell(std::string(RASCAL_SIM_DATA_DIR) + "/munsell_soil_hues_grid_renotation.csv");
  const Scenario s = ScenarioLoader(layout(), munsell)
                         .parse("seed: 11\ngenerate: {count: 20, heap: {spread: 0.025, drop_height: 0.01}}\n");
  World world(layout(), gripper());
  world.spawn(s.sherds);
  for (int i = 0; i < 4000; ++i) world.step(0.001);
  const TableRect& mat = layout().station(StationType::Pickup).area;
  int above = 0;
  for (size_t i = 0; i < s.sherds.size(); ++i) {
    const SherdState st = world.sherd(i);
    const Eigen::Vector3d p = st.pose.translation();
    EXPECT_TRUE(mat.contains(p.head<2>())) << s.sherds[i].name << " at " << p.transpose();
    EXPECT_LT(st.linear_velocity.norm(), 0.01) << s.sherds[i].name;
    if (p.z() > st.box_size.z() / 2 + 0.004) ++above;  // lies on another sherd
  }
  EXPECT_GE(above, 5);
}

TEST(World, ASherdStandingOnItsLongEdgeStaysUpUntilPushed) {
  // a tipped-out bag leaves some sherds on their edges; a flat one, spawned so, stands still
  // (its wall is the base) until something pushes it
  SherdSpec s = slab("edge", 0.15, 0.25);
  s.curvature = 0.0;
  s.pose.z() = 0.0;
  s.tilt = M_PI / 2;
  World world(layout(), gripper());
  world.spawn({s});
  for (int i = 0; i < 2000; ++i) world.step(0.001);
  const SherdState st = world.sherd(0);
  EXPECT_GT(std::fabs(st.pose.linear()(2, 1)), 0.95) << "its width is no longer upright";
  EXPECT_NEAR(st.pose.translation().x(), 0.15, 0.003);
  EXPECT_NEAR(st.pose.translation().y(), 0.25, 0.003);
}
