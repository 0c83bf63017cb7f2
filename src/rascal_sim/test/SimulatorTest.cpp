#include <gtest/gtest.h>

#include <cmath>

#include "rascal_sim/Simulator.hpp"

using namespace rascal_sim;

namespace {
SherdSpec slab(const std::string& name, double x, double y, double density) {
  SherdSpec s;
  s.name = name;
  s.outline = {{-0.022, -0.017}, {0.022, -0.018}, {0.02, 0.017}, {-0.02, 0.018}};
  s.thickness = 0.007;
  s.curvature = 5.0;
  s.density = density;
  s.pose = {x, y, 0.2};
  return s;
}

SimulatorOptions quiet() {
  SimulatorOptions o;
  o.wrist_camera = false;
  o.archival_width = 400;  // small archival frames keep the test fast
  o.archival_height = 300;
  return o;
}
}  // namespace

TEST(Simulator, ScaleReadsTheSumOfTheMassesOnIt) {
  Simulator sim(WorldLayout::defaults(RASCAL_SIM_DATA_DIR), quiet());
  Scenario sc;
  sc.sherds = {slab("a", 0.27, -0.03, 1850), slab("b", 0.33, 0.03, 1950)};
  sim.load(sc);
  ScaleReading r;
  for (int i = 0; i < 3000; ++i) {
    sim.step();
    sim.takeScaleReading(r);
  }
  const auto truth = sim.groundTruth();
  const double total = truth[0].mass + truth[1].mass;
  EXPECT_GT(total, 0.02);
  EXPECT_NEAR(r.mass, total, 1e-4) << "truth " << total;
  EXPECT_TRUE(r.stable);
}

TEST(Simulator, CaptureIsRefusedWhileTheArmIsInView) {
  SimulatorOptions o = quiet();
  // arm stretched out over the archival camera's station (waist towards (0.31, -0.30))
  o.initial_joints = {std::atan2(-0.30, 0.31), 0.0, 0.0, 0.0, 0.0, 0.0};
  Simulator sim(WorldLayout::defaults(RASCAL_SIM_DATA_DIR), o);
  std::string why;
  ASSERT_TRUE(sim.triggerCapture(why)) << why;
  for (int i = 0; i < 300; ++i) sim.step();
  EXPECT_EQ(sim.archival().state(), ArchivalCamera::State::kFailed);
  EXPECT_NE(sim.archival().message().find("arm in view"), std::string::npos) << sim.archival().message();
}

TEST(Simulator, CaptureArrivesShutterPlusTransferLater) {
  Simulator sim(WorldLayout::defaults(RASCAL_SIM_DATA_DIR), quiet());  // sleep pose: out of view
  std::string why;
  const double t0 = sim.time();
  ASSERT_TRUE(sim.triggerCapture(why)) << why;
  while (sim.archival().state() != ArchivalCamera::State::kDone &&
         sim.archival().state() != ArchivalCamera::State::kFailed && sim.time() < 5.0) {
    sim.step();
  }
  ASSERT_EQ(sim.archival().state(), ArchivalCamera::State::kDone) << sim.archival().message();
  EXPECT_NEAR(sim.time() - t0, ArchivalCamera::kShutter + ArchivalCamera::kTransfer, 0.002);
  EXPECT_EQ(sim.archival().image().cols, 400);
}

/// Gripper pointing down over (0.30, 0.20) with the fingertips 6 mm above the table.
static JointVector overSherd() {
  JointVector best{};
  double best_err = 1e9;
  const double waist = std::atan2(0.20, 0.30), r = std::hypot(0.30, 0.20);
  for (double sh = -0.5; sh < 1.5; sh += 0.005) {
    for (double el = -1.0; el < 1.6; el += 0.005) {
      JointVector q{waist, sh, el, 0, M_PI / 2 - sh - el, 0};
      const Eigen::Vector3d p = ArmKinematics::forward(q, 0.037)[kEeGripperLink].translation();
      const double err = std::abs(std::hypot(p.x(), p.y()) - r) + std::abs(p.z() - 0.006);
      if (err < best_err) {
        best_err = err;
        best = q;
      }
    }
  }
  return best;
}

/// Grasps a centred sherd (across its minor axis) and lifts it by 0.3 rad of shoulder.
static void graspAndLift(Simulator& sim, const JointVector& start) {
  Scenario sc;
  SherdSpec s = slab("c", 0.30, 0.20, 1850);
  s.pose.z() = std::atan2(0.20, 0.30);  // fingers close across the sherd's minor axis
  sc.sherds = {s};
  sc.seed = 3;
  sim.load(sc);
  for (int i = 0; i < 200; ++i) sim.step();
  sim.commandGripper(0.015);
  for (int i = 0; i < 800; ++i) sim.step();
  EXPECT_TRUE(sim.groundTruth()[0].held);
  EXPECT_NEAR(sim.fingerPosition(), 0.0175, 0.002);  // stopped on the 35 mm wide sherd
  TrajectoryPoint p;
  p.positions = start;
  p.positions[1] -= 0.3;
  p.positions[4] += 0.3;
  p.time_from_start = 1.0;
  sim.commandArm(sim.time(), {p}, {true, true, true, true, true, true});
  for (int i = 0; i < 1500; ++i) sim.step();
}

TEST(Simulator, FingersCloseOnASherdAndLiftIt) {
  SimulatorOptions o = quiet();
  o.initial_joints = overSherd();
  Simulator sim(WorldLayout::defaults(RASCAL_SIM_DATA_DIR), o);
  graspAndLift(sim, o.initial_joints);
  const auto truth = sim.groundTruth()[0];
  EXPECT_TRUE(truth.held);
  EXPECT_GT(truth.pose.translation().z(), 0.03);
}

TEST(Simulator, InjectedSlipDropsTheSherdWhichComesToRest) {
  SimulatorOptions o = quiet();
  o.initial_joints = overSherd();
  Simulator sim(WorldLayout::defaults(RASCAL_SIM_DATA_DIR), o);
  std::string message;
  ASSERT_TRUE(sim.injectFault(static_cast<int>(Fault::kDropNextGrasp), 0.0, message));
  graspAndLift(sim, o.initial_joints);
  for (int i = 0; i < 2000; ++i) sim.step();
  const auto truth = sim.groundTruth()[0];
  EXPECT_FALSE(truth.held);
  EXPECT_LT(truth.pose.translation().z(), 0.03);
  EXPECT_LT(truth.linear_velocity.norm(), 1e-2);
  EXPECT_LT(sim.fingerPosition(), 0.0155);  // nothing left between the fingers
}

TEST(Simulator, ScaleGlitchMakesReadingsUnstable) {
  Simulator sim(WorldLayout::defaults(RASCAL_SIM_DATA_DIR), quiet());
  std::string message;
  EXPECT_FALSE(sim.injectFault(static_cast<int>(Fault::kScaleGlitch), 0.0, message));
  ASSERT_TRUE(sim.injectFault(static_cast<int>(Fault::kScaleGlitch), 1.0, message));
  ScaleReading r;
  bool any_stable = false;
  for (int i = 0; i < 1000; ++i) {
    sim.step();
    if (sim.takeScaleReading(r)) any_stable = any_stable || r.stable;
  }
  EXPECT_FALSE(any_stable);
  for (int i = 0; i < 1500; ++i) sim.step();
  sim.takeScaleReading(r);
  EXPECT_TRUE(r.stable);
  EXPECT_NEAR(r.mass, 0.0, 1e-4);
}

TEST(Simulator, CameraTimeoutFaultAnswersOnlyAfterItsDuration) {
  Simulator sim(WorldLayout::defaults(RASCAL_SIM_DATA_DIR), quiet());
  std::string message;
  ASSERT_TRUE(sim.injectFault(static_cast<int>(Fault::kCameraTimeout), 1.0, message)) << message;
  std::string why;
  ASSERT_TRUE(sim.triggerCapture(why)) << why;
  EXPECT_EQ(sim.archival().state(), ArchivalCamera::State::kFailed);
  EXPECT_NEAR(sim.archival().readyTime(), sim.time() + 1.0, 1e-9);
  EXPECT_NE(sim.archival().message().find("did not answer"), std::string::npos);
  sim.archival().acknowledge();
  for (int i = 0; i < 1100; ++i) sim.step();
  ASSERT_TRUE(sim.triggerCapture(why)) << why;
  EXPECT_EQ(sim.archival().state(), ArchivalCamera::State::kShutter);
}
