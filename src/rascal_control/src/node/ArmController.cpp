#include "ArmController.hpp"

#include <algorithm>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>

#include <ros/package.h>

#include "RosConversions.hpp"
#include "rascal_workcell/ParameterServer.hpp"

namespace rascal_control {

ArmController::ArmController(ros::NodeHandle& private_nh) : nh_(private_nh) {
  // 1. Parameters and the core objects they configure.
  const std::string urdf = loadUrdf();
  try {
    model_ = std::make_unique<KinematicModel>(KinematicModel::fromString(urdf));
    gripper_ = rascal_workcell::GripperGeometry::fromUrdf(urdf);
  } catch (const std::exception& e) {
    throw std::runtime_error(std::string("robot description: ") + e.what());
  }
  params_ = ControllerParameters::read(rascal_workcell::parametersFromServer("arm_controller"), *model_);
  gripper_ = gripper_.withPads(params_.fingertip_pads);
  ik_ = std::make_unique<IkSolver>(*model_);
  collisions_ = std::make_unique<CollisionChecker>(*model_, gripper_.finger_max);
  collisions_->addFixtures(params_.fixtures);
  TrajectoryPlanner::Options options;
  options.max_acceleration *= params_.acceleration_share;
  planner_ = std::make_unique<TrajectoryPlanner>(*model_, *ik_, collisions_.get(), options);

  DriverMonitor::Settings driver;
  driver.max_speed = 0.0;
  for (const JointLimit& limit : model_->limits()) driver.max_speed = std::max(driver.max_speed, limit.velocity);
  if (!(driver.max_speed > 0.0)) {
    driver.max_speed = DriverMonitor::Settings{}.max_speed;  // a URDF without velocity limits
  }
  states_.configureDriver(driver);

  // 2. Topics, services, actions.
  ros::NodeHandle root("/");
  move_server_ = std::make_unique<MoveServer>(root, states_, *model_, *planner_, core_mutex_, params_);
  gripper_server_ =
      std::make_unique<GripperServer>(root, states_, gripper_, params_.gripper, params_.state_timeout);
  joint_state_sub_ = root.subscribe("/joint_states", 10, &ArmController::jointStateCallback, this,
                                    ros::TransportHints().tcpNoDelay());
  ik_service_ = root.advertiseService("/rascal/arm/compute_ik", &ArmController::computeIk, this);
  fk_service_ = root.advertiseService("/rascal/arm/compute_fk", &ArmController::computeFk, this);
  acknowledge_service_ =
      root.advertiseService("/rascal/arm/acknowledge_restart", &ArmController::acknowledgeRestart, this);
  driver_timer_ = root.createWallTimer(ros::WallDuration(0.05), &ArmController::watchDriver, this);
  if (params_.publish_tf) {
    std::vector<geometry_msgs::TransformStamped> fixed;
    for (const LinkTransform& t : model_->transforms({}, true)) {
      fixed.push_back(toTransform(t, ros::Time::now()));
    }
    static_broadcaster_.sendTransform(fixed);
  }

  std::string fixtures;
  std::set<std::string> named;
  for (const Fixture& f : collisions_->fixtures()) {
    const std::string name = f.name.substr(0, f.name.find(" wall "));  // one entry per discard box
    if (named.insert(name).second) {
      fixtures += ", " + name;
    }
  }
  ROS_INFO("arm_controller started: %s IK, named poses %zu, gripper %.3f..%.3f m, collision fixtures: table%s, TF %s",
           ik_->analyticAvailable() ? "closed-form" : "KDL", params_.named_poses.size(), gripper_.minOpening(),
           gripper_.maxOpening(), fixtures.c_str(), params_.publish_tf ? "on" : "off");
}

std::string ArmController::loadUrdf() {
  std::string xml;
  if (ros::param::get("/robot_description", xml)) {
    if (xml.empty()) {
      throw std::runtime_error("/robot_description: is empty");
    }
    return xml;
  }
  const std::string package = ros::package::getPath("rascal_description");
  if (package.empty()) {
    throw std::runtime_error("/robot_description: not set, and the rascal_description package is not found");
  }
  const std::string path = package + "/urdf/wx250s.urdf";
  std::ifstream in(path);
  if (!in) {
    throw std::runtime_error("/robot_description: not set, and " + path + " cannot be read");
  }
  std::stringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

void ArmController::jointStateCallback(const sensor_msgs::JointState::ConstPtr& msg) {
  try {
    std::optional<FingerSample> finger;
    const std::map<std::string, double> positions = states_.update(*msg, ros::Time::now(), finger);
    if (finger) {
      gripper_server_->onFinger(*finger);
    }
    if (params_.publish_tf) {
      std::vector<geometry_msgs::TransformStamped> moving;
      const ros::Time stamp = msg->header.stamp.isZero() ? ros::Time::now() : msg->header.stamp;
      for (const LinkTransform& t : model_->transforms(positions, false)) {
        moving.push_back(toTransform(t, stamp));
      }
      tf_broadcaster_.sendTransform(moving);
    }
  } catch (const std::exception& e) {
    ROS_ERROR_THROTTLE(5.0, "/joint_states: %s", e.what());
  }
}

void ArmController::watchDriver(const ros::WallTimerEvent&) {
  states_.checkClock();
  states_.checkSubscribers(move_server_->driverSubscribers());
  if (states_.restartNoticed()) {
    ROS_ERROR("arm_controller: %s", restartMessage(states_.restart()).c_str());
  }
}

// ---------------------------------------------------------------------------------------------
// Services

bool ArmController::acknowledgeRestart(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& res) {
  const std::string reason = states_.acknowledgeRestart();
  res.success = true;
  res.message = reason.empty() ? "no driver restart to acknowledge" : "driver restart acknowledged (" + reason + ")";
  if (!reason.empty()) {
    ROS_WARN("arm_controller: %s; goals are accepted again", res.message.c_str());
  }
  return true;
}

bool ArmController::computeIk(rascal_msgs::ComputeIK::Request& req, rascal_msgs::ComputeIK::Response& res) {
  try {
    return solveIk(req, res);
  } catch (const std::exception& e) {
    ROS_ERROR("/rascal/arm/compute_ik: %s", e.what());
    res.code = rascal_msgs::ComputeIK::Response::INVALID;
    res.message = std::string("internal error: ") + e.what();
    return true;
  }
}

bool ArmController::solveIk(rascal_msgs::ComputeIK::Request& req, rascal_msgs::ComputeIK::Response& res) {
  const std::string& frame = req.pose.header.frame_id;
  KDL::Frame target;
  std::string why;
  if (!frame.empty() && frame != "base_link" && frame != "/base_link") {
    res.code = rascal_msgs::ComputeIK::Response::INVALID;
    res.message = "pose in frame '" + frame + "'; only base_link is accepted";
    return true;
  }
  if (!poseToFrame(req.pose.pose, target, why)) {
    res.code = rascal_msgs::ComputeIK::Response::INVALID;
    res.message = why;
    return true;
  }
  JointVector seed{};
  if (req.seed.empty()) {
    states_.arm(seed, 0.0);
  } else if (req.seed.size() != kArmJoints) {
    res.code = rascal_msgs::ComputeIK::Response::INVALID;
    res.message = "seed has " + std::to_string(req.seed.size()) + " values, expected 6";
    return true;
  } else {
    seed = toJointVector(req.seed);
  }
  std::lock_guard<std::mutex> lock(core_mutex_);
  const IkResult r = ik_->solve(target, seed);
  res.code = static_cast<uint8_t>(r.code);
  res.message = r.message;
  if (r.ok()) {
    res.joints = toStdVector(r.joints);
  }
  return true;
}

bool ArmController::computeFk(rascal_msgs::ComputeFK::Request& req, rascal_msgs::ComputeFK::Response& res) {
  try {
    return solveFk(req, res);
  } catch (const std::exception& e) {
    ROS_ERROR("/rascal/arm/compute_fk: %s", e.what());
    res.success = false;
    res.message = std::string("internal error: ") + e.what();
    return true;
  }
}

bool ArmController::solveFk(rascal_msgs::ComputeFK::Request& req, rascal_msgs::ComputeFK::Response& res) {
  JointVector q{};
  const double finger = states_.leftFinger().value_or(gripper_.finger_min);
  if (req.joints.empty()) {
    if (!states_.arm(q, 0.0)) {
      res.success = false;
      res.message = "no joints given and none received on /joint_states yet";
      return true;
    }
  } else if (req.joints.size() != kArmJoints) {
    res.success = false;
    res.message = "joints has " + std::to_string(req.joints.size()) + " values, expected 6";
    return true;
  } else {
    q = toJointVector(req.joints);
  }
  const std::string link = req.link.empty() ? KinematicModel::kTipLink : req.link;
  KDL::Frame pose;
  if (!model_->linkPose(link, q, finger, pose)) {
    res.success = false;
    res.message = "unknown link '" + link + "'";
    return true;
  }
  res.success = true;
  res.message = "ok";
  res.pose.header.frame_id = KinematicModel::kBaseLink;
  res.pose.header.stamp = ros::Time::now();
  res.pose.pose = frameToPose(pose);
  return true;
}

}  // namespace rascal_control
