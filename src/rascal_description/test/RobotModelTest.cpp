// Checks the URDF against shared/facts/widowx250_d435.md with the parsers a node uses
// (urdfdom, kdl_parser). Needs no ROS master.
#include <gtest/gtest.h>

#include <kdl/chain.hpp>
#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/frames.hpp>
#include <kdl/jntarray.hpp>
#include <kdl/tree.hpp>
#include <kdl_parser/kdl_parser.hpp>
#include <urdf_parser/urdf_parser.h>

#include <cmath>
#include <map>
#include <string>

namespace {

urdf::ModelInterfaceSharedPtr loadModel() {
  auto model = urdf::parseURDFFile(RASCAL_URDF_PATH);
  if (!model) throw std::runtime_error("urdfdom could not parse " RASCAL_URDF_PATH);
  return model;
}

KDL::Chain armChain(const std::string& tip) {
  KDL::Tree tree;
  if (!kdl_parser::treeFromUrdfModel(*loadModel(), tree)) throw std::runtime_error("kdl_parser failed");
  KDL::Chain chain;
  if (!tree.getChain("base_link", tip, chain)) throw std::runtime_error("no chain to " + tip);
  return chain;
}

KDL::Frame fk(const std::string& tip, const std::vector<double>& q) {
  KDL::Chain chain = armChain(tip);
  KDL::JntArray jq(chain.getNrOfJoints());
  for (size_t i = 0; i < q.size(); ++i) jq(i) = q[i];
  KDL::Frame f;
  KDL::ChainFkSolverPos_recursive(chain).JntToCart(jq, f);
  return f;
}

}  // namespace

TEST(RobotModel, ParsesWithUrdfdom) {
  auto model = loadModel();
  EXPECT_EQ(model->getName(), "wx250s");
  for (const char* link : {"base_link", "ee_gripper_link", "left_finger_link", "right_finger_link",
                           "camera_link", "camera_color_optical_frame"})
    EXPECT_TRUE(model->getLink(link)) << link;
}

TEST(RobotModel, ChainHasSixArmJoints) {
  KDL::Chain chain = armChain("ee_gripper_link");
  ASSERT_EQ(chain.getNrOfJoints(), 6u);
  const char* names[] = {"waist", "shoulder", "elbow", "forearm_roll", "wrist_angle", "wrist_rotate"};
  unsigned j = 0;
  for (const auto& seg : chain.segments) {
    if (seg.getJoint().getType() != KDL::Joint::None) {
      EXPECT_EQ(seg.getJoint().getName(), names[j++]);
    }
  }
}

TEST(RobotModel, EeGripperAtHomeMatchesFacts) {
  KDL::Frame f = fk("ee_gripper_link", {0, 0, 0, 0, 0, 0});
  EXPECT_NEAR(f.p.x(), 0.458325, 1e-6);
  EXPECT_NEAR(f.p.y(), 0.0, 1e-6);
  EXPECT_NEAR(f.p.z(), 0.36065, 1e-6);
  double r, p, y;
  f.M.GetRPY(r, p, y);
  EXPECT_NEAR(std::fabs(r) + std::fabs(p) + std::fabs(y), 0.0, 1e-9);
}

TEST(RobotModel, EeGripperAtSleepMatchesFacts) {
  // facts §0: Sleep = (0, -1.80, 1.55, 0, 0.8, 0) puts ee_gripper_link at (0.12265, 0, 0.08126)
  // (5 significant digits in the facts).
  KDL::Frame f = fk("ee_gripper_link", {0, -1.80, 1.55, 0, 0.8, 0});
  EXPECT_NEAR(f.p.x(), 0.12265, 1e-5);
  EXPECT_NEAR(f.p.y(), 0.0, 1e-9);
  EXPECT_NEAR(f.p.z(), 0.08126, 1e-5);
}

TEST(RobotModel, UprightMatchesFacts) {
  KDL::Frame f = fk("ee_gripper_link", {0, 0, -1.5708, 0, 0, 0});
  EXPECT_NEAR(f.p.x(), 0.04975, 1e-4);
  EXPECT_NEAR(f.p.z(), 0.76922, 1e-4);
}

TEST(RobotModel, JointLimitsAndVelocitiesMatchFacts) {
  struct Lim { double lo, hi, vel, effort; };
  const double kPi = 3.141583;  // pi - 1e-5, the Interbotix pi_offset
  const double deg = M_PI / 180.0;
  std::map<std::string, Lim> facts = {
      {"waist", {-kPi, kPi, M_PI, 10}},
      {"shoulder", {-108 * deg, 114 * deg, M_PI, 20}},
      {"elbow", {-123 * deg, 92 * deg, M_PI, 15}},
      {"forearm_roll", {-kPi, kPi, M_PI, 2}},
      {"wrist_angle", {-100 * deg, 123 * deg, M_PI, 5}},
      {"wrist_rotate", {-kPi, kPi, M_PI, 1}},
      {"left_finger", {0.015, 0.037, 1.0, 5}},
      {"right_finger", {-0.037, -0.015, 1.0, 5}},
  };
  auto model = loadModel();
  for (const auto& [name, lim] : facts) {
    auto joint = model->getJoint(name);
    ASSERT_TRUE(joint && joint->limits) << name;
    EXPECT_NEAR(joint->limits->lower, lim.lo, 1e-6) << name;
    EXPECT_NEAR(joint->limits->upper, lim.hi, 1e-6) << name;
    EXPECT_NEAR(joint->limits->velocity, lim.vel, 1e-6) << name;
    EXPECT_NEAR(joint->limits->effort, lim.effort, 1e-9) << name;
  }
  EXPECT_EQ(model->getJoint("left_finger")->type, urdf::Joint::PRISMATIC);
  // Finger opening between the fingertips: 2 x 0.015 .. 2 x 0.037 = 30..74 mm.
}

TEST(RobotModel, InertiaIsRotatedIntoTheLinkFrame) {
  // upper_arm_link: facts give the tensor in a frame yawed +pi/2; in the link frame ixx and iyy
  // swap and iyz becomes -ixz.
  auto in = loadModel()->getLink("upper_arm_link")->inertial;
  ASSERT_TRUE(in);
  EXPECT_NEAR(in->ixx, 0.003587, 1e-9);
  EXPECT_NEAR(in->iyy, 0.003463, 1e-9);
  EXPECT_NEAR(in->ixz, -0.0004272, 1e-9);
  EXPECT_NEAR(in->mass, 0.430811, 1e-9);
  double r, p, y;
  in->origin.rotation.getRPY(r, p, y);
  EXPECT_NEAR(std::fabs(r) + std::fabs(p) + std::fabs(y), 0.0, 1e-12);
}

TEST(RobotModel, PlaceholderLinksCarryNoFakeInertia) {
  auto model = loadModel();
  for (const char* link : {"ee_arm_link", "fingers_link", "ee_gripper_link"})
    EXPECT_FALSE(model->getLink(link)->inertial) << link;
}

TEST(RobotModel, EveryLinkWithGeometryHasSimpleCollision) {
  auto model = loadModel();
  std::vector<urdf::LinkSharedPtr> links;
  model->getLinks(links);
  int with_collision = 0;
  for (const auto& link : links) {
    if (!link->collision) continue;
    ++with_collision;
    auto type = link->collision->geometry->type;
    EXPECT_TRUE(type == urdf::Geometry::BOX || type == urdf::Geometry::CYLINDER) << link->name;
  }
  EXPECT_GE(with_collision, 12);
}

TEST(RobotModel, FingertipsEndJustBeyondEeGripperLink) {
  // The fingertips end 4.4 mm (to 0.1 mm) beyond ee_gripper_link (fingers_link + 0.027575), as in the
  // simulator's finger boxes and the detector's grasp planner (perception.fingertip_offset).
  auto model = loadModel();
  for (const char* name : {"left_finger_link", "right_finger_link"}) {
    auto col = model->getLink(name)->collision;
    ASSERT_TRUE(col) << name;
    auto box = std::dynamic_pointer_cast<urdf::Box>(col->geometry);
    ASSERT_TRUE(box) << name;
    EXPECT_NEAR(col->origin.position.x + box->dim.x / 2 - 0.027575, 0.0044, 5e-5) << name;
  }
}

TEST(RobotModel, CameraOpticalFrameLooksAlongGripperAxis) {
  // With the arm at home the gripper points along +x, so the optical z axis (REP 103 optical
  // convention: z forward, x right, y down) must point along +x of base_link and y down.
  KDL::Frame f = fk("camera_color_optical_frame", {0, 0, 0, 0, 0, 0});
  EXPECT_NEAR(f.M.UnitZ().x(), 1.0, 1e-9);
  EXPECT_NEAR(f.M.UnitY().z(), -1.0, 1e-9);
  EXPECT_NEAR(f.M.UnitX().y(), -1.0, 1e-9);
  // Mounted 0.04 m ahead of and 0.055 m above gripper_link (x = 0.36475 at home), colour imager
  // 15 mm to the left of camera_link.
  EXPECT_NEAR(f.p.x(), 0.36475 + 0.04, 1e-9);
  EXPECT_NEAR(f.p.y(), 0.015, 1e-9);
  EXPECT_NEAR(f.p.z(), 0.36065 + 0.055, 1e-9);
}

TEST(RobotModel, GripperPointingDownPutsCameraAboveTheFingers) {
  // shoulder 0, elbow 0, wrist_angle pi/2: gripper points straight down.
  KDL::Frame ee = fk("ee_gripper_link", {0, 0, 0, 0, M_PI / 2, 0});
  KDL::Frame cam = fk("camera_color_optical_frame", {0, 0, 0, 0, M_PI / 2, 0});
  EXPECT_NEAR(cam.M.UnitZ().z(), -1.0, 1e-9);
  EXPECT_GT(cam.p.z(), ee.p.z() + 0.04);
}
