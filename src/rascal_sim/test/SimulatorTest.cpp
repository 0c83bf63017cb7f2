#include <gtest/gtest.h>

#include <cmath>

#include "ShippedConfig.hpp"
#include "rascal_sim/Simulator.hpp"

using namespace rascal_sim;
using rascal_sim_test::gripper;
using rascal_sim_test::layout;

namespace {
const Station& scaleStation() { return layout().station(StationType::Scale); }
}  // namespace

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
  SimulatorOptions o = rascal_sim_test::shipped().options;
  o.wrist_camera = false;
  o.archival_width = 400;  // small archival frames keep the test fast
  o.archival_height = 300;
  return o;
}
}  // namespace

TEST(Simulator, ScaleReadsTheSumOfTheMassesOnIt) {
  Simulator sim(layout(), quiet());
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

TEST(Simulator, AScaleLowerThanItsPlatformThicknessStillWeighs) {
  // 5 mm: the schema (and check_config) accept it, the node used to refuse anything below 11 mm;
  // the 10 mm platform reaches below the table top, where nothing collides with it
  YAML::Node root = YAML::LoadFile(RASCAL_CONFIG_PATH);
  root["stations"]["scale"]["surface_z"] = 0.005;
  const SimParameters p = SimParameters::read(rascal_workcell::Parameters(root, "sim"), gripper(), RASCAL_SIM_DATA_DIR);
  Simulator sim(p.layout, quiet());
  Scenario sc;
  sc.sherds = {slab("a", 0.30, 0.0, 1850)};
  sim.load(sc);
  ScaleReading r;
  for (int i = 0; i < 3000; ++i) {
    sim.step();
    sim.takeScaleReading(r);
  }
  const auto s = sim.groundTruth()[0];
  EXPECT_NEAR(s.pose.translation().z() - s.box_size.z() / 2, 0.005, 0.002);
  EXPECT_NEAR(r.mass, s.mass, 1e-4) << "truth " << s.mass;
  EXPECT_TRUE(r.stable);
}

TEST(Simulator, CaptureIsRefusedWhileTheArmIsInView) {
  SimulatorOptions o = quiet();
  // arm stretched out over the archival camera's station (waist towards (0.31, -0.30))
  o.initial_joints = {std::atan2(-0.30, 0.31), 0.0, 0.0, 0.0, 0.0, 0.0};
  Simulator sim(layout(), o);
  std::string why;
  ASSERT_TRUE(sim.triggerCapture(why)) << why;
  for (int i = 0; i < 300; ++i) sim.step();
  EXPECT_EQ(sim.archival().state(), ArchivalCamera::State::kFailed);
  EXPECT_NE(sim.archival().message().find("arm in view"), std::string::npos) << sim.archival().message();
}

TEST(Simulator, CaptureArrivesShutterPlusTransferLater) {
  Simulator sim(layout(), quiet());  // sleep pose: out of view
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

/// Joints that put ee_gripper_link at (x, y, z) with the gripper pointing straight down.
static JointVector pointingDownAt(double x, double y, double z) {
  JointVector best{};
  double best_err = 1e9;
  const double waist = std::atan2(y, x), r = std::hypot(x, y);
  for (double sh = -0.5; sh < 1.5; sh += 0.005) {
    for (double el = -1.0; el < 1.6; el += 0.005) {
      JointVector q{waist, sh, el, 0, M_PI / 2 - sh - el, 0};
      const Eigen::Vector3d p = ArmKinematics::forward(q, gripper().finger_max)[kEeGripperLink].translation();
      const double err = std::abs(std::hypot(p.x(), p.y()) - r) + std::abs(p.z() - z);
      if (err < best_err) {
        best_err = err;
        best = q;
      }
    }
  }
  return best;
}

/// Gripper pointing down over (0.30, 0.20) with the fingertips 6 mm above the table.
static JointVector overSherd() { return pointingDownAt(0.30, 0.20, 0.006); }

/// Loads `s` alone, lets it settle, closes the fingers and waits for them to stop.
static void closeOn(Simulator& sim, const SherdSpec& s) {
  Scenario sc;
  sc.sherds = {s};
  sc.seed = 3;
  sim.load(sc);
  for (int i = 0; i < 200; ++i) sim.step();
  sim.commandGripper(gripper().finger_min);
  for (int i = 0; i < 800; ++i) sim.step();
}

/// Grasps a centred sherd (across its minor axis) and lifts it by 0.3 rad of shoulder.
static void graspAndLift(Simulator& sim, const JointVector& start) {
  SherdSpec s = slab("c", 0.30, 0.20, 1850);
  s.pose.z() = std::atan2(0.20, 0.30);  // fingers close across the sherd's minor axis
  closeOn(sim, s);
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
  Simulator sim(layout(), o);
  graspAndLift(sim, o.initial_joints);
  const auto truth = sim.groundTruth()[0];
  EXPECT_TRUE(truth.held);
  EXPECT_GT(truth.pose.translation().z(), 0.03);
  // the grasp is on record for the node's log: centred, across the minor axis, the model's base
  const Simulator::GraspRecord& g = sim.lastGrasp();
  EXPECT_EQ(g.count, 1);
  EXPECT_EQ(g.sherd, truth.name);
  EXPECT_LT(g.off_centre, 0.1);
  EXPECT_LT(g.along, 0.1);
  EXPECT_NEAR(g.slip_chance, 0.02, 0.01);
  EXPECT_NE(g.describe().find("grasp of " + truth.name), std::string::npos);
  EXPECT_TRUE(sim.takeBumps().empty()) << "fingers that close on a sherd and lift it bump nothing";
  // stopping the fingers where they are (a stop, or a command to their position) is no open
  sim.stopGripper();
  sim.commandGripper(sim.fingerPosition());
  for (int i = 0; i < 300; ++i) sim.step();
  EXPECT_TRUE(sim.groundTruth()[0].held);
}

TEST(Simulator, FingersClosingAboveASherdAreAMissOnRecord) {
  // closed 50 mm up over a sherd lying flat: nothing between the fingers. The miss is on record
  // with what each finger touched (nothing) and the sherd below, for the node's log
  SimulatorOptions o = quiet();
  o.initial_joints = pointingDownAt(0.30, 0.20, 0.05);
  Simulator sim(layout(), o);
  SherdSpec s = slab("c", 0.30, 0.20, 1850);
  s.pose.z() = std::atan2(0.20, 0.30);
  closeOn(sim, s);
  EXPECT_FALSE(sim.groundTruth()[0].held);
  const Simulator::GraspRecord& g = sim.lastGrasp();
  EXPECT_EQ(g.count, 1);
  EXPECT_TRUE(g.miss);
  EXPECT_EQ(g.sherd, "c");
  EXPECT_TRUE(g.left.empty() && g.right.empty());
  EXPECT_LT(g.high, g.ee_z - 0.03);
  EXPECT_NE(g.describe().find("left touched nothing, right nothing"), std::string::npos) << g.describe();
  // the node's log gets the miss once
  EXPECT_EQ(sim.takeLogLines(), std::vector<std::string>{g.describe()});
  EXPECT_TRUE(sim.takeLogLines().empty());
}

TEST(Simulator, AFingerComingDownOnASherdIsABumpOnRecord) {
  // the open gripper lowered beside a sherd's centre, one finger over the sherd: the contact is
  // on record with the finger and the sherd, once however long the finger rests there
  SimulatorOptions o = quiet();
  o.initial_joints = pointingDownAt(0.30, 0.20, 0.05);
  Simulator sim(layout(), o);
  SherdSpec s = slab("c", 0.30, 0.20, 1850);
  s.pose.z() = std::atan2(0.20, 0.30);  // the fingers' closing line across its minor axis
  s.pose.head<2>() += 0.028 * Eigen::Vector2d(-0.20, 0.30).normalized();  // under one finger
  Scenario sc;
  sc.sherds = {s};
  sim.load(sc);
  for (int i = 0; i < 200; ++i) sim.step();
  ASSERT_TRUE(sim.takeBumps().empty());
  TrajectoryPoint p;
  p.positions = pointingDownAt(0.30, 0.20, 0.006);
  p.time_from_start = 1.5;
  sim.commandArm(sim.time(), {p}, {true, true, true, true, true, true});
  for (int i = 0; i < 2500; ++i) sim.step();
  const std::vector<Simulator::BumpRecord> bumps = sim.takeBumps();
  ASSERT_EQ(bumps.size(), 1u);
  const Simulator::BumpRecord& b = bumps[0];
  EXPECT_EQ(b.sherd, "c");
  EXPECT_NE(b.link.find("finger"), std::string::npos) << b.link;
  EXPECT_LT(b.ee.z(), 0.05);
  EXPECT_NE(b.describe().find("_finger_link on c at"), std::string::npos) << b.describe();
  // where: a finger's bottom, off the fingers' centre line along the closing direction
  EXPECT_GT(std::fabs(b.contact.y()), 0.012) << b.describe();
  EXPECT_LT(b.contact.norm(), 0.05) << b.describe();
  EXPECT_NE(b.describe().find("mm in its frame"), std::string::npos) << b.describe();
}

TEST(Simulator, InjectedSlipDropsTheSherdWhichComesToRest) {
  SimulatorOptions o = quiet();
  o.initial_joints = overSherd();
  Simulator sim(layout(), o);
  std::string message;
  ASSERT_TRUE(sim.injectFault(static_cast<int>(Fault::kDropNextGrasp), 0.0, message));
  graspAndLift(sim, o.initial_joints);
  for (int i = 0; i < 2000; ++i) sim.step();
  const auto truth = sim.groundTruth()[0];
  EXPECT_FALSE(truth.held);
  EXPECT_LT(truth.pose.translation().z(), 0.03);
  EXPECT_LT(truth.linear_velocity.norm(), 1e-2);
  EXPECT_LT(sim.fingerPosition(), gripper().finger_min + 0.0005);  // nothing left between the fingers
}

/// A square slab (55 x 55 mm) on the scale pan turned 45 degrees from the fingers: its corners
/// wedge into the fully open fingers (diagonal 78 mm > 74 mm), so the close stops at once and the
/// sherd is held with the fingers fully open. The arm starts with ee_gripper_link 8 mm above the
/// pan and lifts the sherd by 8 mm.
static void wedgeOnTheScale(Simulator& sim) {
  Scenario sc;
  SherdSpec s;
  s.name = "square";
  s.outline = {{-0.0275, -0.0275}, {0.0275, -0.0275}, {0.0275, 0.0275}, {-0.0275, 0.0275}};
  s.thickness = 0.008;
  s.curvature = 4.0;
  s.density = 1900;
  const double x = scaleStation().area.centre.x(), y = scaleStation().area.centre.y();
  s.pose = {x, y, std::atan2(y, x) + M_PI / 4};
  sc.sherds = {s};
  sc.seed = 3;
  sim.load(sc);
  for (int i = 0; i < 20; ++i) sim.step();  // close before the fingers push it round
  sim.commandGripper(gripper().finger_min);
  for (int i = 0; i < 800; ++i) sim.step();
  ASSERT_TRUE(sim.groundTruth()[0].held);
  ASSERT_GT(sim.fingerPosition(), gripper().finger_max - 0.0005) << "not wedged wide open: the test lost its premise";
  TrajectoryPoint p;
  p.positions = pointingDownAt(x, y, scaleStation().surface_z + 0.016);
  p.time_from_start = 1.0;
  sim.commandArm(sim.time(), {p}, {true, true, true, true, true, true});
  for (int i = 0; i < 1500; ++i) sim.step();
  const auto truth = sim.groundTruth()[0];
  ASSERT_TRUE(truth.held);
  EXPECT_GT(truth.pose.translation().z() - truth.box_size.z() / 2, scaleStation().surface_z + 0.004);
}

/// Steps up to `seconds`; the sim time at which the sherd came to rest and stayed (-1 if never),
/// and whether it was ever held meanwhile.
static double stepUntilRest(Simulator& sim, double seconds, bool& ever_held) {
  double rest_at = -1.0;
  const double end = sim.time() + seconds;
  while (sim.time() < end) {
    sim.step();
    const auto s = sim.groundTruth()[0];
    ever_held = ever_held || s.held;
    const bool still = s.linear_velocity.norm() < 1e-3 && s.angular_velocity.norm() < 1e-2;
    if (!still) rest_at = -1.0;
    else if (rest_at < 0) rest_at = sim.time();
  }
  return rest_at;
}

TEST(Simulator, FullyOpeningReleasesADiagonallyWedgedSherd) {
  SimulatorOptions o = quiet();
  o.initial_joints = pointingDownAt(scaleStation().area.centre.x(), scaleStation().area.centre.y(),
                                    scaleStation().surface_z + 0.008);
  Simulator sim(layout(), o);
  wedgeOnTheScale(sim);
  const double t0 = sim.time();
  sim.commandGripper(gripper().finger_max);  // the fingers are already there: the command alone lets go
  sim.step();
  EXPECT_FALSE(sim.groundTruth()[0].held);
  bool ever_held = false;
  const double rest_at = stepUntilRest(sim, 2.5, ever_held);
  const auto s = sim.groundTruth()[0];
  EXPECT_FALSE(ever_held);
  ASSERT_GT(rest_at, 0.0) << "still moving";
  EXPECT_LT(rest_at - t0, 2.0);
  EXPECT_NEAR(s.pose.translation().z() - s.box_size.z() / 2, scaleStation().surface_z, 0.003);
}

TEST(Simulator, OpeningPartlyReleasesAWedgedSherdOnTheScaleForGood) {
  SimulatorOptions o = quiet();
  o.initial_joints = pointingDownAt(scaleStation().area.centre.x(), scaleStation().area.centre.y(),
                                    scaleStation().surface_z + 0.008);
  Simulator sim(layout(), o);
  wedgeOnTheScale(sim);
  // the lead's sequence: open to 70.5 mm (less than the wedged 74 mm, so the fingers move in
  // while the sherd is still between them), then fully
  sim.commandGripper(0.03525);
  sim.step();
  EXPECT_FALSE(sim.groundTruth()[0].held);
  bool ever_held = false;
  stepUntilRest(sim, 0.5, ever_held);
  EXPECT_FALSE(ever_held) << "re-attached without a new close";
  sim.commandGripper(gripper().finger_max);
  const double rest_at = stepUntilRest(sim, 2.5, ever_held);
  EXPECT_FALSE(ever_held);
  EXPECT_GT(rest_at, 0.0);
  ScaleReading r;
  for (int i = 0; i < 1000; ++i) {
    sim.step();
    sim.takeScaleReading(r);
  }
  const auto s = sim.groundTruth()[0];
  EXPECT_NEAR(s.pose.translation().z() - s.box_size.z() / 2, scaleStation().surface_z, 0.003);
  EXPECT_TRUE(r.stable);
  EXPECT_NEAR(r.mass, s.mass, 1e-4) << "truth " << s.mass;
  // the next close, back down at grasp height, grasps it again
  TrajectoryPoint down;
  down.positions = pointingDownAt(scaleStation().area.centre.x(), scaleStation().area.centre.y(),
                                  scaleStation().surface_z + 0.006);
  down.time_from_start = 0.5;
  sim.commandArm(sim.time(), {down}, {true, true, true, true, true, true});
  for (int i = 0; i < 1000; ++i) sim.step();
  sim.commandGripper(gripper().finger_min);
  for (int i = 0; i < 800; ++i) sim.step();
  EXPECT_TRUE(sim.groundTruth()[0].held);
}

TEST(Simulator, ScaleGlitchMakesReadingsUnstable) {
  Simulator sim(layout(), quiet());
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

TEST(Simulator, ScaleUnsettledTareAndGlitchOnLoadAreInjectedAndClearedByReset) {
  Simulator sim(layout(), quiet());
  std::string message;
  EXPECT_FALSE(sim.injectFault(static_cast<int>(Fault::kScaleUnsettledTare), 0.0, message));
  EXPECT_FALSE(sim.injectFault(static_cast<int>(Fault::kScaleGlitchOnLoad), -1.0, message));
  EXPECT_FALSE(sim.injectFault(5, 1.0, message));
  ASSERT_TRUE(sim.injectFault(static_cast<int>(Fault::kScaleUnsettledTare), 1.0, message));
  ScaleReading r;
  for (int i = 0; i < 1000; ++i) sim.step();
  sim.tareScale();
  for (int i = 0; i < 3000; ++i) sim.step();
  sim.takeScaleReading(r);
  EXPECT_NEAR(r.mass, -ScaleSensor::kUnsettledTareError, 1e-4) << "the tare caught the swing";
  sim.tareScale();
  ASSERT_TRUE(sim.injectFault(static_cast<int>(Fault::kScaleUnsettledTare), 1.0, message));
  sim.reset();  // disarms it
  for (int i = 0; i < 1000; ++i) sim.step();
  sim.tareScale();
  for (int i = 0; i < 3000; ++i) sim.step();
  sim.takeScaleReading(r);
  EXPECT_NEAR(r.mass, 0.0, 1e-4);
  EXPECT_TRUE(sim.injectFault(static_cast<int>(Fault::kScaleGlitchOnLoad), 2.0, message));
}

TEST(Simulator, CameraTimeoutFaultAnswersOnlyAfterItsDuration) {
  Simulator sim(layout(), quiet());
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

/// small_3's sherd_02 (the scanned fragment, box 57.7 x 55.3 x 18.9 mm) on the table, its box
/// turned 45 degrees from the fingers, which are open to 70.5 mm: the close stalls at once on the
/// box corners and the sherd is held and lifted 3 cm; an injected drop lets it go. With
/// `stop_while_held`, the arm controller's stop (a command to where the fingers are, as on a
/// cancel, and an empty trajectory) comes while it is held. Returns the sim time of the release.
static double dropAWedgedSherd(Simulator& sim, bool stop_while_held) {
  const double x = 0.30, y = 0.20;
  Scenario sc;
  SherdSpec s;
  s.name = "sherd_02";
  s.mesh_file = layout().data_dir + "/archaide_braccio_frag_1.stl";
  s.density = 1900;
  s.pose = {x, y, std::atan2(y, x) + M_PI / 4};
  sc.sherds = {s};
  sc.seed = 3;
  sim.load(sc);
  std::string message;
  EXPECT_TRUE(sim.injectFault(static_cast<int>(Fault::kDropNextGrasp), 0.0, message));
  for (int i = 0; i < 20; ++i) sim.step();
  sim.commandGripper(gripper().finger_min);
  for (int i = 0; i < 800; ++i) sim.step();
  EXPECT_TRUE(sim.groundTruth()[0].held);
  EXPECT_GT(sim.fingerPosition(), gripper().finger_max - 0.003) << "not wedged: the test lost its premise";
  if (stop_while_held) {
    sim.commandGripper(sim.fingerPosition());
    sim.stopGripper();
    for (int i = 0; i < 100; ++i) sim.step();
    EXPECT_TRUE(sim.groundTruth()[0].held) << "a stop is no open";
  }
  TrajectoryPoint p;
  p.positions = pointingDownAt(x, y, 0.038);
  p.time_from_start = 1.0;
  sim.commandArm(sim.time(), {p}, {true, true, true, true, true, true});
  while (sim.time() < 6.0) {
    sim.step();
    if (!sim.groundTruth()[0].held) return sim.time();
  }
  return -1.0;
}

static SimulatorOptions overTheFragment() {
  SimulatorOptions o = quiet();
  o.initial_joints = pointingDownAt(0.30, 0.20, 0.008);
  o.initial_finger = 0.03525;
  return o;
}

/// The scanned fragment is nearly square (57.7 x 55.3 mm box) but its corners are rounded: turned
/// 45 degrees from the fingers it still fits the open gripper, as the real one would. A single
/// bounding box as collision shape (80 mm diagonal) wedged it wide open instead.
TEST(Simulator, AScannedFragmentAcrossItsDiagonalIsGraspedOnItsOutline) {
  SimulatorOptions o = quiet();
  o.initial_joints = pointingDownAt(0.30, 0.20, 0.008);
  Simulator sim(layout(), o);
  SherdSpec s;
  s.name = "fragment";
  s.mesh_file = layout().data_dir + "/archaide_braccio_frag_1.stl";
  s.density = 1900;
  s.pose = {0.30, 0.20, std::atan2(0.20, 0.30) + M_PI / 4};
  closeOn(sim, s);
  EXPECT_TRUE(sim.groundTruth()[0].held);
  EXPECT_LT(sim.fingerPosition(), gripper().finger_max - 0.001) << "wedged on the corners of a box the sherd does not fill";
}

TEST(Simulator, FingersGoOnClosingWhenAWedgedSherdIsDropped) {
  Simulator sim(layout(), overTheFragment());
  const double released_at = dropAWedgedSherd(sim, false);
  ASSERT_GT(released_at, 0.0) << "the sherd was never let go";
  while (sim.time() < released_at + 1.0) sim.step();
  EXPECT_LT(sim.fingerPosition(), gripper().finger_min + 0.001) << "the fingers stayed open after the sherd went";
  EXPECT_FALSE(sim.groundTruth()[0].held);
  EXPECT_LT(sim.groundTruth()[0].pose.translation().z(), 0.03);
}

TEST(Simulator, AStopWhileSqueezingKeepsTheCloseWhenTheSherdGoes) {
  Simulator sim(layout(), overTheFragment());
  const double released_at = dropAWedgedSherd(sim, true);
  ASSERT_GT(released_at, 0.0) << "the sherd was never let go";
  while (sim.time() < released_at + 1.0) sim.step();
  EXPECT_LT(sim.fingerPosition(), gripper().finger_min + 0.001) << "the fingers stayed open after the sherd went";
  EXPECT_FALSE(sim.groundTruth()[0].held);
  EXPECT_LT(sim.groundTruth()[0].pose.translation().z(), 0.03);
}

TEST(Simulator, AStopWithNothingBetweenTheFingersStopsThem) {
  Simulator sim(layout(), quiet());
  sim.commandGripper(gripper().finger_min);
  for (int i = 0; i < 100; ++i) sim.step();
  sim.stopGripper();
  const double stopped = sim.fingerPosition();
  EXPECT_LT(stopped, gripper().finger_max - 0.0015);
  for (int i = 0; i < 300; ++i) sim.step();
  EXPECT_NEAR(sim.fingerPosition(), stopped, 1e-9);
}
