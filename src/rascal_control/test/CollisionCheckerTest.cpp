#include <cmath>

#include <gtest/gtest.h>

#include "TestModel.hpp"
#include "rascal_control/CollisionChecker.hpp"
#include "rascal_control/TrajectoryPlanner.hpp"
#include "rascal_workcell/GripperGeometry.hpp"
#include "rascal_workcell/Parameters.hpp"
#include "rascal_workcell/Workcell.hpp"

using namespace rascal_control;

namespace {

// The station fixtures of config/rascal.yaml, as the controller gets them: the workcell's boxes.
void addStations(CollisionChecker& checker) {
  const auto params = rascal_workcell::Parameters::fromFile(RASCAL_CONFIG_PATH, "arm_controller");
  checker.addFixtures(rascal_workcell::Workcell::fromParameters(params).collisionBoxes());
}

}  // namespace

TEST(CollisionChecker, ChecksTheArmBodiesOfTheUrdf) {
  CollisionChecker checker(testModel());
  const auto links = checker.checkedLinks();
  for (const char* link : {"upper_arm_link", "wrist_link", "gripper_link", "left_finger_link", "camera_link"}) {
    EXPECT_NE(std::find(links.begin(), links.end(), link), links.end()) << link;
  }
  EXPECT_EQ(std::find(links.begin(), links.end(), "base_link"), links.end());
}

TEST(CollisionChecker, TableAndFixtures) {
  CollisionChecker checker(testModel());
  addStations(checker);
  IkSolver ik(testModel());
  EXPECT_FALSE(checker.check(JointVector{}));
  EXPECT_FALSE(checker.check(JointVector{0, -1.80, 1.55, 0, 0.8, 0}));  // sleep
  // Gripper pointing down with the wrist in the table.
  IkResult r = ik.solve(IkSolver::topDown(0.25, 0.2, -0.06, 0.0), JointVector{});
  ASSERT_TRUE(r.ok());
  auto hit = checker.check(r.joints);
  ASSERT_TRUE(hit);
  EXPECT_EQ(hit->fixture, "table");
  // Fingertips on the table are allowed (picking flat sherds).
  r = ik.solve(IkSolver::topDown(0.25, 0.2, 0.005, 0.0), JointVector{});
  ASSERT_TRUE(r.ok());
  EXPECT_FALSE(checker.check(r.joints)) << checker.check(r.joints)->link;
  // The fingers down inside a discard wall (fingers along the wall).
  r = ik.solve(IkSolver::topDown(0.02, -0.31 + 0.063, 0.03, M_PI / 2.0), JointVector{});
  ASSERT_TRUE(r.ok());
  hit = checker.check(r.joints);
  ASSERT_TRUE(hit);
  EXPECT_NE(hit->fixture.find("discard"), std::string::npos);
}

TEST(CollisionChecker, FingertipsMayTouchTheScalePlatformButNotItsHousing) {
  CollisionChecker checker(testModel());
  addStations(checker);
  IkSolver ik(testModel());
  const double tips = rascal_workcell::GripperGeometry::fromPackageUrdf().fingertip_offset;
  // config/rascal.yaml: the scale at (0.30, 0), platform 0.13 m wide, its top 0.025 m high.
  IkResult r = ik.solve(IkSolver::topDown(0.30, 0.0, 0.025 + tips - 0.001, 0.0), JointVector{});
  ASSERT_TRUE(r.ok()) << r.message;
  EXPECT_FALSE(checker.check(r.joints)) << checker.check(r.joints)->fixture;
  // Beside the platform, down to the housing's top (0.015 m, 15 mm wider than the platform).
  r = ik.solve(IkSolver::topDown(0.30, 0.0725, 0.012 + tips, M_PI / 2.0), JointVector{});
  ASSERT_TRUE(r.ok()) << r.message;
  const auto hit = checker.check(r.joints);
  ASSERT_TRUE(hit);
  EXPECT_EQ(hit->fixture, "scale housing");
}

TEST(CollisionChecker, MoveThroughTheCameraStandIsRefused) {
  IkSolver ik(testModel());
  CollisionChecker checker(testModel());
  addStations(checker);
  TrajectoryPlanner planner(testModel(), ik, &checker);
  // Gripper horizontal, pointing away from the base, moved sideways at x = 0.50 through the
  // stand's post at (0.50, -0.30).
  const KDL::Frame from(KDL::Rotation::RotZ(std::atan2(-0.15, 0.50)), KDL::Vector(0.50, -0.15, 0.12));
  const KDL::Frame to(KDL::Rotation::RotZ(std::atan2(-0.42, 0.50)), KDL::Vector(0.50, -0.42, 0.12));
  const IkResult start = ik.solve(from, JointVector{});
  ASSERT_TRUE(start.ok()) << start.message;
  PlanResult r = planner.planLinear(start.joints, to, 1.0);
  EXPECT_EQ(r.code, PlanCode::Collision) << r.message;
  EXPECT_NE(r.message.find("camera stand"), std::string::npos) << r.message;
  const IkResult goal = ik.solve(to, start.joints);
  ASSERT_TRUE(goal.ok());
  r = planner.planJoint(start.joints, goal.joints, 1.0);
  EXPECT_EQ(r.code, PlanCode::Collision) << r.message;
  // Without the stand the same moves are fine.
  CollisionChecker table_only(testModel());
  TrajectoryPlanner free_planner(testModel(), ik, &table_only);
  EXPECT_TRUE(free_planner.planLinear(start.joints, to, 1.0).ok());
  EXPECT_TRUE(free_planner.planJoint(start.joints, goal.joints, 1.0).ok());
}

TEST(CollisionChecker, TheArmKeepsOffItsOwnBase) {
  CollisionChecker checker(testModel());
  ASSERT_EQ(checker.fixtures().size(), 1u);
  EXPECT_EQ(checker.fixtures()[0].name, "arm base");
  IkSolver ik(testModel());
  // Gripper pointing down just in front of the base, below its top (z = 0.072).
  const IkResult r = ik.solve(IkSolver::topDown(0.04, 0.0, 0.07, 0.0), JointVector{});
  ASSERT_TRUE(r.ok()) << r.message;
  const auto hit = checker.check(r.joints);
  ASSERT_TRUE(hit);
  EXPECT_EQ(hit->fixture, "arm base");
  // Reaching out over the table is fine.
  const IkResult out = ik.solve(IkSolver::topDown(0.25, 0.0, 0.07, 0.0), JointVector{});
  EXPECT_FALSE(checker.check(out.joints));
}

TEST(CollisionChecker, JointMoveToAPoseTriesOtherSolutions) {
  IkSolver ik(testModel());
  CollisionChecker checker(testModel());
  addStations(checker);
  TrajectoryPlanner planner(testModel(), ik, &checker);
  // Near the camera station: the move to the closest IK solution swings the wrist camera into the
  // stand; another solution of the same pose gets there without touching it.
  const IkResult start = ik.solve(IkSolver::topDown(0.434, -0.198, 0.035, -0.033), JointVector{});
  ASSERT_TRUE(start.ok());
  const KDL::Frame to = IkSolver::topDown(0.295, -0.343, 0.137, -0.103);
  const auto all = ik.solveAll(to, start.joints);
  ASSERT_GE(all.size(), 2u);
  for (const JointVector& q : all) {
    EXPECT_TRUE(KDL::Equal(testModel().forward(q), to, 1e-9));
    EXPECT_TRUE(testModel().withinLimits(q));
  }
  const PlanResult closest = planner.planJoint(start.joints, all.front(), 1.0);
  EXPECT_EQ(closest.code, PlanCode::Collision);
  EXPECT_NE(closest.message.find("camera stand"), std::string::npos) << closest.message;
  const PlanResult r = planner.planJointToPose(start.joints, to, 1.0);
  ASSERT_TRUE(r.ok()) << r.message;
  EXPECT_FALSE(checker.check(r.trajectory.path()));
  EXPECT_TRUE(KDL::Equal(testModel().forward(r.trajectory.goal()), to, 1e-9));
  EXPECT_EQ(planner.planJointToPose(start.joints, IkSolver::topDown(1.0, 0, 0.1, 0), 1.0).code,
            PlanCode::Unreachable);
}

TEST(CollisionChecker, MovingAwayFromAnExistingContactIsAllowed) {
  IkSolver ik(testModel());
  CollisionChecker checker(testModel());
  TrajectoryPlanner planner(testModel(), ik, &checker);
  const IkResult low = ik.solve(IkSolver::topDown(0.25, 0.2, -0.06, 0.0), JointVector{});
  ASSERT_TRUE(low.ok());
  ASSERT_TRUE(checker.check(low.joints));
  EXPECT_TRUE(planner.planLinear(low.joints, IkSolver::topDown(0.25, 0.2, 0.10, 0.0), 1.0).ok());
}
