#include "ArmController.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include <ros/package.h>
#include <trajectory_msgs/JointTrajectory.h>

#include "RosConversions.hpp"

namespace rascal_control {

namespace {

constexpr double kFingerMin = 0.015;       // [m] finger position from the centreline (URDF)
constexpr double kFingerMax = 0.037;
constexpr double kWallThickness = 0.004;   // [m] discard box walls (not measured on the rig)
constexpr double kAtRest = 0.02;           // [rad/s] joint speed counted as "at rest"
constexpr double kFingerReached = 0.0005;  // [m]
constexpr double kFingerStall = 0.0001;    // [m] finger motion over kStallWindow that means stopped
constexpr double kStallWindow = 0.1;       // [s]
constexpr double kFingerStopped = 1e-4;    // [m/s] reported finger speed that means stopped
constexpr std::size_t kStoppedSamples = 3; // consecutive /joint_states messages
constexpr double kStateSilence = 2.0;      // [s] wall time without /joint_states during a move

[[noreturn]] void badParameter(const std::string& key, const std::string& why) {
  throw std::runtime_error("parameter " + key + ": " + why);
}

bool number(const XmlRpc::XmlRpcValue& v, double& out) {
  if (v.getType() == XmlRpc::XmlRpcValue::TypeDouble) {
    out = static_cast<double>(const_cast<XmlRpc::XmlRpcValue&>(v));
    return true;
  }
  if (v.getType() == XmlRpc::XmlRpcValue::TypeInt) {
    out = static_cast<int>(const_cast<XmlRpc::XmlRpcValue&>(v));
    return true;
  }
  return false;
}

// An optional number in [lo, hi] (lo excluded when `open_low`).
double readNumber(const std::string& key, double fallback, double lo, double hi, bool open_low) {
  XmlRpc::XmlRpcValue v;
  if (!ros::param::get(key, v)) {
    return fallback;
  }
  double out = 0.0;
  if (!number(v, out) || !std::isfinite(out)) {
    badParameter(key, "expected a number");
  }
  if (out < lo || out > hi || (open_low && out == lo)) {
    std::ostringstream range;
    range << "must be in " << (open_low ? "(" : "[") << lo << ", " << hi << "], got " << out;
    badParameter(key, range.str());
  }
  return out;
}

std::vector<double> readList(const std::string& key, std::size_t size) {
  XmlRpc::XmlRpcValue v;
  if (!ros::param::get(key, v)) {
    badParameter(key, "missing");
  }
  if (v.getType() != XmlRpc::XmlRpcValue::TypeArray || static_cast<std::size_t>(v.size()) != size) {
    badParameter(key, "expected a list of " + std::to_string(size) + " numbers");
  }
  std::vector<double> out(size);
  for (int i = 0; i < v.size(); ++i) {
    if (!number(v[i], out[i]) || !std::isfinite(out[i])) {
      badParameter(key, "element " + std::to_string(i) + " is not a number");
    }
  }
  return out;
}

double readPositive(const std::string& key) {
  if (!ros::param::has(key)) {
    badParameter(key, "missing");
  }
  return readNumber(key, 0.0, 0.0, 100.0, true);
}

}  // namespace

ArmController::ArmController(ros::NodeHandle& private_nh) : nh_(private_nh) {
  // 1. Parameters and the core objects they configure.
  const std::string urdf = loadUrdf();
  try {
    model_ = std::make_unique<KinematicModel>(KinematicModel::fromString(urdf));
  } catch (const std::exception& e) {
    throw std::runtime_error(std::string("robot description: ") + e.what());
  }
  readSettings();
  ik_ = std::make_unique<IkSolver>(*model_);
  collisions_ = std::make_unique<CollisionChecker>(*model_);
  readFixtures();
  TrajectoryPlanner::Options options;
  options.max_acceleration *= settings_.acceleration_share;
  planner_ = std::make_unique<TrajectoryPlanner>(*model_, *ik_, collisions_.get(), options);

  // 2. Topics, services, actions.
  ros::NodeHandle root("/");
  arm_command_pub_ = root.advertise<trajectory_msgs::JointTrajectory>("/arm/joint_trajectory", 1);
  gripper_command_pub_ = root.advertise<trajectory_msgs::JointTrajectory>("/gripper/command", 1);
  joint_state_sub_ = root.subscribe("/joint_states", 10, &ArmController::jointStateCallback, this,
                                    ros::TransportHints().tcpNoDelay());
  ik_service_ = root.advertiseService("/rascal/arm/compute_ik", &ArmController::computeIk, this);
  fk_service_ = root.advertiseService("/rascal/arm/compute_fk", &ArmController::computeFk, this);
  move_server_ = std::make_unique<actionlib::SimpleActionServer<rascal_msgs::MoveArmAction>>(
      root, "/rascal/arm/move", [this](const rascal_msgs::MoveArmGoalConstPtr& goal) { executeMove(goal); }, false);
  gripper_server_ = std::make_unique<actionlib::SimpleActionServer<rascal_msgs::GripperAction>>(
      root, "/rascal/gripper", [this](const rascal_msgs::GripperGoalConstPtr& goal) { executeGripper(goal); }, false);
  move_server_->start();
  gripper_server_->start();
  if (settings_.publish_tf) {
    std::vector<geometry_msgs::TransformStamped> fixed;
    for (const LinkTransform& t : model_->transforms({}, true)) {
      fixed.push_back(toTransform(t, ros::Time::now()));
    }
    static_broadcaster_.sendTransform(fixed);
  }

  std::string fixtures;
  for (const Fixture& f : collisions_->fixtures()) {
    if (f.name.find(" wall ") == std::string::npos || f.name.find("wall -x") != std::string::npos) {
      fixtures += (fixtures.empty() ? "" : ", ") + f.name.substr(0, f.name.find(" wall "));
    }
  }
  ROS_INFO("arm_controller started: %s IK, named poses %zu, collision fixtures: table%s%s, TF %s",
           ik_->analyticAvailable() ? "closed-form" : "KDL", settings_.named_poses.size(),
           fixtures.empty() ? "" : ", ", fixtures.c_str(), settings_.publish_tf ? "on" : "off");
}

std::string ArmController::loadUrdf() const {
  std::string xml;
  if (ros::param::get("/robot_description", xml)) {
    if (xml.empty()) {
      badParameter("/robot_description", "is empty");
    }
    return xml;
  }
  const std::string package = ros::package::getPath("rascal_description");
  if (package.empty()) {
    badParameter("/robot_description", "not set, and the rascal_description package is not found");
  }
  const std::string path = package + "/urdf/wx250s.urdf";
  std::ifstream in(path);
  if (!in) {
    badParameter("/robot_description", "not set, and " + path + " cannot be read");
  }
  std::stringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

void ArmController::readSettings() {
  XmlRpc::XmlRpcValue poses;
  if (!ros::param::get("/arm/named_poses", poses)) {
    badParameter("/arm/named_poses", "missing (load config/rascal.yaml)");
  }
  if (poses.getType() != XmlRpc::XmlRpcValue::TypeStruct) {
    badParameter("/arm/named_poses", "expected a map of name: [6 joint angles]");
  }
  for (auto it = poses.begin(); it != poses.end(); ++it) {
    const std::string key = "/arm/named_poses/" + it->first;
    const JointVector q = toJointVector(readList(key, kArmJoints));
    const int joint = model_->firstLimitViolation(q);
    if (joint >= 0) {
      badParameter(key, KinematicModel::armJointNames()[joint] + " = " + std::to_string(q[joint]) +
                            " rad is outside its limits");
    }
    settings_.named_poses[it->first] = q;
  }
  settings_.speed_scale = readNumber("/arm/speed_scale", 1.0, 0.0, 1.0, true);
  settings_.acceleration_share = readNumber("/arm/acceleration_share", 0.95, 0.0, 1.0, true);
  settings_.command_period = readNumber("/arm/command_period", 0.02, 0.0, 0.1, true);
  settings_.goal_tolerance = readNumber("/arm/goal_tolerance", 0.002, 0.0, 0.1, true);
  settings_.settle_timeout = readNumber("/arm/settle_timeout", 2.0, 0.0, 60.0, true);
  settings_.state_timeout = readNumber("/arm/state_timeout", 1.0, 0.0, 60.0, true);
  settings_.gripper_timeout = readNumber("/arm/gripper/timeout", 3.0, 0.0, 60.0, true);
  settings_.gripper_stroke_time = readNumber("/arm/gripper/stroke_time", 0.5, 0.0, 10.0, true);
  settings_.held_margin = readNumber("/arm/gripper/held_margin", 0.002, 0.0, 0.02, true);
  XmlRpc::XmlRpcValue tf;
  if (ros::param::get("/arm/publish_tf", tf)) {
    if (tf.getType() != XmlRpc::XmlRpcValue::TypeBoolean) {
      badParameter("/arm/publish_tf", "expected true or false");
    }
    settings_.publish_tf = static_cast<bool>(tf);
  }
}

void ArmController::readFixtures() {
  // Each station fixture is checked when its section is in the config.
  if (ros::param::has("/stations/camera/stand")) {
    const std::string key = "/stations/camera/stand";
    const auto position = readList(key + "/position", 2);
    const auto size = readList(key + "/size", 2);
    const double height = readPositive(key + "/height");
    if (size[0] <= 0.0 || size[1] <= 0.0) {
      badParameter(key + "/size", "must be positive");
    }
    collisions_->addFixture({"camera stand", KDL::Vector(position[0], position[1], height / 2.0),
                             KDL::Vector(size[0], size[1], height), false, {}});
  }
  if (ros::param::has("/stations/discard")) {
    const std::string key = "/stations/discard";
    const auto position = readList(key + "/position", 2);
    const auto size = readList(key + "/size", 2);
    const double wall = readPositive(key + "/wall_height");
    if (size[0] <= 2 * kWallThickness || size[1] <= 2 * kWallThickness) {
      badParameter(key + "/size", "must be larger than the box walls");
    }
    collisions_->addOpenBox("discard box", position[0], position[1], size[0], size[1], wall,
                            kWallThickness);
  }
  if (ros::param::has("/stations/scale")) {
    const std::string key = "/stations/scale";
    const auto position = readList(key + "/position", 2);
    const auto size = readList(key + "/size", 2);
    const double top = readPositive(key + "/surface_z");
    if (size[0] <= 0.0 || size[1] <= 0.0) {
      badParameter(key + "/size", "must be positive");
    }
    collisions_->addFixture({"scale", KDL::Vector(position[0], position[1], top / 2.0),
                             KDL::Vector(size[0], size[1], top), true, {}});
  }
}

void ArmController::jointStateCallback(const sensor_msgs::JointState::ConstPtr& msg) {
  try {
    onJointState(*msg);
  } catch (const std::exception& e) {
    ROS_ERROR_THROTTLE(5.0, "/joint_states: %s", e.what());
  }
}

void ArmController::onJointState(const sensor_msgs::JointState& state) {
  std::map<std::string, double> positions, velocities;
  jointStateToMaps(state, positions, velocities);
  {
    std::lock_guard<std::mutex> lock(state_mutex_);
    for (const auto& p : positions) {
      positions_[p.first] = p.second;
    }
    for (const auto& v : velocities) {
      velocities_[v.first] = v.second;
    }
    JointVector q{};
    have_state_ = armJoints(positions_, q);
    last_state_wall_ = ros::WallTime::now();
    const auto finger = positions_.find("left_finger");
    if (finger != positions_.end()) {
      // The driver's stamp, not the arrival time: under load messages arrive in bursts.
      const double t = state.header.stamp.isZero() ? ros::Time::now().toSec() : state.header.stamp.toSec();
      const auto v = velocities.find("left_finger");
      if (!finger_history_.empty() && t < finger_history_.back().t) {
        finger_history_.clear();  // time went back: the driver (simulator) restarted
      }
      finger_history_.push_back({t, finger->second,
                                 v != velocities.end() ? v->second : std::numeric_limits<double>::quiet_NaN()});
      while (finger_history_.size() > 2 && finger_history_.front().t < t - 1.0) {
        finger_history_.pop_front();
      }
    }
  }
  state_cv_.notify_all();
  if (settings_.publish_tf) {
    std::vector<geometry_msgs::TransformStamped> moving;
    const ros::Time stamp = state.header.stamp.isZero() ? ros::Time::now() : state.header.stamp;
    for (const LinkTransform& t : model_->transforms(positions, false)) {
      moving.push_back(toTransform(t, stamp));
    }
    tf_broadcaster_.sendTransform(moving);
  }
}

bool ArmController::driverListening(const ros::Publisher& publisher) const {
  // A message published before the driver's subscription is connected would be lost.
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(settings_.state_timeout);
  while (publisher.getNumSubscribers() == 0 && ros::ok() && ros::WallTime::now() < deadline) {
    ros::WallDuration(0.005).sleep();
  }
  return publisher.getNumSubscribers() > 0;
}

bool ArmController::currentJoints(JointVector& q, double wait) {
  std::unique_lock<std::mutex> lock(state_mutex_);
  state_cv_.wait_for(lock, std::chrono::duration<double>(wait), [this] { return have_state_; });
  return have_state_ && armJoints(positions_, q);
}

// ---------------------------------------------------------------------------------------------
// /rascal/arm/move

void ArmController::executeMove(const rascal_msgs::MoveArmGoalConstPtr& goal) {
  rascal_msgs::MoveArmResult result;
  try {
    result = runMove(*goal);
  } catch (const std::exception& e) {
    ROS_ERROR("/rascal/arm/move: %s", e.what());
    arm_command_pub_.publish(stopTrajectory(ros::Time::now()));
    result.code = rascal_msgs::MoveArmResult::INVALID_GOAL;
    result.message = std::string("internal error: ") + e.what();
  }
  if (result.code == rascal_msgs::MoveArmResult::OK) {
    move_server_->setSucceeded(result, result.message);
  } else if (result.code == rascal_msgs::MoveArmResult::PREEMPTED) {
    move_server_->setPreempted(result, result.message);
  } else {
    ROS_WARN("/rascal/arm/move: %s", result.message.c_str());
    move_server_->setAborted(result, result.message);
  }
}

PlanResult ArmController::plan(const rascal_msgs::MoveArmGoal& goal, const JointVector& start) {
  PlanResult failed;
  failed.code = PlanCode::InvalidGoal;
  double scale = goal.speed_scale == 0.0 ? 1.0 : goal.speed_scale;
  if (!(scale > 0.0 && scale <= 1.0)) {
    failed.message = "speed_scale " + std::to_string(goal.speed_scale) + " is outside (0, 1]";
    return failed;
  }
  scale *= settings_.speed_scale;
  if (goal.motion != rascal_msgs::MoveArmGoal::MOTION_JOINT &&
      goal.motion != rascal_msgs::MoveArmGoal::MOTION_LINEAR) {
    failed.message = "unknown motion " + std::to_string(goal.motion) + " (0 joint, 1 linear)";
    return failed;
  }
  const bool linear = goal.motion == rascal_msgs::MoveArmGoal::MOTION_LINEAR;
  JointVector target_joints{};
  KDL::Frame target_pose;
  std::lock_guard<std::mutex> lock(core_mutex_);
  switch (goal.target_type) {
    case rascal_msgs::MoveArmGoal::TARGET_POSE: {
      const std::string& frame = goal.pose.header.frame_id;
      if (!frame.empty() && frame != "base_link" && frame != "/base_link") {
        failed.message = "pose goal in frame '" + frame + "'; only base_link is accepted";
        return failed;
      }
      std::string why;
      if (!poseToFrame(goal.pose.pose, target_pose, why)) {
        failed.message = "pose goal: " + why;
        return failed;
      }
      return linear ? planner_->planLinear(start, target_pose, scale)
                    : planner_->planJointToPose(start, target_pose, scale);
    }
    case rascal_msgs::MoveArmGoal::TARGET_NAMED: {
      const auto it = settings_.named_poses.find(goal.named_pose);
      if (it == settings_.named_poses.end()) {
        std::string known;
        for (const auto& p : settings_.named_poses) {
          known += (known.empty() ? "" : ", ") + p.first;
        }
        failed.message = "unknown named pose '" + goal.named_pose + "' (known: " + known + ")";
        return failed;
      }
      target_joints = it->second;
      break;
    }
    case rascal_msgs::MoveArmGoal::TARGET_JOINTS:
      if (goal.joints.size() != kArmJoints) {
        failed.message = "joint goal has " + std::to_string(goal.joints.size()) + " values, expected 6";
        return failed;
      }
      target_joints = toJointVector(goal.joints);
      break;
    default:
      failed.message = "unknown target_type " + std::to_string(goal.target_type);
      return failed;
  }
  if (linear) {
    const int joint = model_->firstLimitViolation(target_joints);
    if (joint >= 0) {
      failed.message = "goal " + KinematicModel::armJointNames()[joint] + " is outside its limits";
      return failed;
    }
    return planner_->planLinear(start, model_->forward(target_joints), scale);
  }
  return planner_->planJoint(start, target_joints, scale);
}

rascal_msgs::MoveArmResult ArmController::runMove(const rascal_msgs::MoveArmGoal& goal) {
  rascal_msgs::MoveArmResult result;
  JointVector start{};
  if (!currentJoints(start, settings_.state_timeout)) {
    result.code = rascal_msgs::MoveArmResult::TIMEOUT;
    result.message = "no arm joints on /joint_states within " +
                     std::to_string(settings_.state_timeout) + " s; is the driver running?";
    return result;
  }
  result.joints = toStdVector(start);
  const PlanResult planned = plan(goal, start);
  if (!planned.ok()) {
    result.code = static_cast<uint8_t>(planned.code);
    result.message = planned.message;
    return result;
  }
  const Trajectory& trajectory = planned.trajectory;
  const JointVector target = trajectory.goal();
  if (!driverListening(arm_command_pub_)) {
    result.code = rascal_msgs::MoveArmResult::TIMEOUT;
    result.message = "no driver subscribes to /arm/joint_trajectory; is it running?";
    return result;
  }
  const ros::Time t0 = ros::Time::now();
  const ros::WallTime wall0 = ros::WallTime::now();
  // Stamp 0: the driver starts the trajectory when it arrives (no catching up on a late message).
  arm_command_pub_.publish(toJointTrajectory(trajectory, settings_.command_period, ros::Time(0)));

  rascal_msgs::MoveArmFeedback feedback;
  ros::Time last_feedback;
  while (true) {
    JointVector q{};
    std::map<std::string, double> velocities;
    bool silent = false;
    {
      std::unique_lock<std::mutex> lock(state_mutex_);
      state_cv_.wait_for(lock, std::chrono::milliseconds(5));
      armJoints(positions_, q);
      velocities = velocities_;
      silent = (ros::WallTime::now() - last_state_wall_).toSec() > kStateSilence;
    }
    const ros::Time now = ros::Time::now();
    const double elapsed = (now - t0).toSec();
    result.joints = toStdVector(q);
    result.duration = elapsed;
    if (move_server_->isPreemptRequested() || !ros::ok()) {
      arm_command_pub_.publish(stopTrajectory(now));
      result.code = rascal_msgs::MoveArmResult::PREEMPTED;
      result.message = "move cancelled; arm stopped";
      return result;
    }
    double worst = 0.0;
    std::size_t worst_joint = 0;
    bool resting = true;
    for (std::size_t j = 0; j < kArmJoints; ++j) {
      const double error = std::fabs(q[j] - target[j]);
      if (error > worst) {
        worst = error;
        worst_joint = j;
      }
      const auto v = velocities.find(KinematicModel::armJointNames()[j]);
      resting = resting && (v == velocities.end() || std::fabs(v->second) < kAtRest);
    }
    if (elapsed >= trajectory.duration() && worst <= settings_.goal_tolerance && resting) {
      result.code = rascal_msgs::MoveArmResult::OK;
      result.message = "arrived";
      return result;
    }
    // Time out in sim time, but never sooner than settle_timeout of wall time: a simulator running
    // many times faster than real time must not turn message latency into a TIMEOUT.
    const bool late = elapsed > trajectory.duration() + settings_.settle_timeout &&
                      (ros::WallTime::now() - wall0).toSec() > settings_.settle_timeout;
    if (late || silent) {
      arm_command_pub_.publish(stopTrajectory(now));
      char text[200];
      std::snprintf(text, sizeof(text),
                    "%s: arm not at the goal %.1f s after the planned %.2f s (%s off by %.4f rad)",
                    silent ? "driver silent" : "timeout", elapsed, trajectory.duration(),
                    KinematicModel::armJointNames()[worst_joint].c_str(), worst);
      result.code = rascal_msgs::MoveArmResult::TIMEOUT;
      result.message = text;
      return result;
    }
    if ((now - last_feedback).toSec() >= 0.05 || now < last_feedback) {
      feedback.progress = trajectory.duration() > 0.0 ? std::min(1.0, elapsed / trajectory.duration()) : 1.0;
      feedback.joints = result.joints;
      move_server_->publishFeedback(feedback);
      last_feedback = now;
    }
  }
}

// ---------------------------------------------------------------------------------------------
// /rascal/gripper

void ArmController::executeGripper(const rascal_msgs::GripperGoalConstPtr& goal) {
  rascal_msgs::GripperResult result;
  try {
    result = runGripper(*goal);
  } catch (const std::exception& e) {
    ROS_ERROR("/rascal/gripper: %s", e.what());
    result.code = rascal_msgs::GripperResult::INVALID_GOAL;
    result.message = std::string("internal error: ") + e.what();
  }
  if (result.code == rascal_msgs::GripperResult::OK) {
    gripper_server_->setSucceeded(result, result.message);
  } else if (result.code == rascal_msgs::GripperResult::PREEMPTED) {
    gripper_server_->setPreempted(result, result.message);
  } else {
    ROS_WARN("/rascal/gripper: %s", result.message.c_str());
    gripper_server_->setAborted(result, result.message);
  }
}

rascal_msgs::GripperResult ArmController::runGripper(const rascal_msgs::GripperGoal& goal) {
  rascal_msgs::GripperResult result;
  double width = 0.0;
  switch (goal.command) {
    case rascal_msgs::GripperGoal::OPEN:
      width = goal.width == 0.0 ? 2 * kFingerMax : goal.width;
      break;
    case rascal_msgs::GripperGoal::CLOSE:
      width = 2 * kFingerMin;
      break;
    case rascal_msgs::GripperGoal::WIDTH:
      width = goal.width;
      break;
    default:
      result.code = rascal_msgs::GripperResult::INVALID_GOAL;
      result.message = "unknown gripper command " + std::to_string(goal.command);
      return result;
  }
  if (!(width >= 2 * kFingerMin - 1e-9 && width <= 2 * kFingerMax + 1e-9)) {
    result.code = rascal_msgs::GripperResult::INVALID_GOAL;
    result.message = "gripper width " + std::to_string(width) + " m is outside [0.030, 0.074]";
    return result;
  }
  const double target = std::min(kFingerMax, std::max(kFingerMin, width / 2.0));
  auto fingers = [this](double& left, double& opening) {
    std::lock_guard<std::mutex> lock(state_mutex_);
    const auto l = positions_.find("left_finger");
    const auto r = positions_.find("right_finger");
    if (l == positions_.end()) {
      return false;
    }
    left = l->second;
    opening = r != positions_.end() ? l->second - r->second : 2 * l->second;
    return true;
  };
  double left = 0.0, opening = 0.0;
  {
    std::unique_lock<std::mutex> lock(state_mutex_);
    state_cv_.wait_for(lock, std::chrono::duration<double>(settings_.state_timeout),
                       [this] { return positions_.count("left_finger") > 0; });
  }
  if (!fingers(left, opening)) {
    result.code = rascal_msgs::GripperResult::TIMEOUT;
    result.message = "no left_finger on /joint_states within " +
                     std::to_string(settings_.state_timeout) + " s; is the driver running?";
    return result;
  }
  const bool closing = target < left;
  const double left_at_start = left;
  auto command = [this](double position, double seconds) {
    trajectory_msgs::JointTrajectory msg;
    msg.header.stamp = ros::Time::now();
    msg.joint_names = {"left_finger"};
    trajectory_msgs::JointTrajectoryPoint point;
    point.positions = {position};
    point.time_from_start = ros::Duration(seconds);
    msg.points.push_back(point);
    gripper_command_pub_.publish(msg);
  };
  const double stroke = settings_.gripper_stroke_time * std::fabs(target - left) / (kFingerMax - kFingerMin);
  if (!driverListening(gripper_command_pub_)) {
    result.code = rascal_msgs::GripperResult::TIMEOUT;
    result.message = "no driver subscribes to /gripper/command; is it running?";
    return result;
  }
  const ros::Time t0 = ros::Time::now();
  const ros::WallTime wall0 = ros::WallTime::now();
  command(target, stroke);
  rascal_msgs::GripperFeedback feedback;
  ros::Time last_feedback;
  while (true) {
    {
      std::unique_lock<std::mutex> lock(state_mutex_);
      state_cv_.wait_for(lock, std::chrono::milliseconds(5));
    }
    fingers(left, opening);
    const ros::Time now = ros::Time::now();
    const double elapsed = (now - t0).toSec();
    result.width = opening;
    result.duration = elapsed;
    if (gripper_server_->isPreemptRequested() || !ros::ok()) {
      command(left, 0.0);
      result.code = rascal_msgs::GripperResult::PREEMPTED;
      result.message = "gripper command cancelled";
      return result;
    }
    bool stalled = false;
    {
      std::lock_guard<std::mutex> lock(state_mutex_);
      // Only once the fingers have moved (the command has arrived), or after a full stroke's time.
      const bool moved = std::fabs(left - left_at_start) > kFingerReached;
      // Fast: the driver's finger velocity has been zero for the last few messages.
      if (moved && finger_history_.size() >= kStoppedSamples) {
        bool stopped = true;
        for (auto it = finger_history_.end() - kStoppedSamples; it != finger_history_.end(); ++it) {
          stopped = stopped && std::fabs(it->velocity) < kFingerStopped;  // false for NaN
        }
        stalled = stopped;
      }
      // Slow: the finger position has not changed over the stall window.
      if (!stalled && !finger_history_.empty() && elapsed > 1.5 * kStallWindow) {
        const double t_now = finger_history_.back().t;
        double lo = finger_history_.back().position, hi = lo;
        bool covered = false;
        for (const FingerSample& h : finger_history_) {
          if (h.t >= t_now - kStallWindow) {
            lo = std::min(lo, h.position);
            hi = std::max(hi, h.position);
          } else {
            covered = true;
          }
        }
        const double wall = (ros::WallTime::now() - wall0).toSec();
        const double still_for = settings_.gripper_stroke_time + kStallWindow;
        stalled = covered && hi - lo < kFingerStall &&
                  (moved ? wall > kStallWindow : elapsed > still_for && wall > still_for);
      }
    }
    if (std::fabs(left - target) < kFingerReached || stalled) {
      result.code = rascal_msgs::GripperResult::OK;
      result.holding = closing && left > target + settings_.held_margin / 2.0;
      char text[96];
      std::snprintf(text, sizeof(text), "opening %.1f mm%s", opening * 1000.0,
                    result.holding ? ", holding an object" : "");
      result.message = text;
      return result;
    }
    if (elapsed > settings_.gripper_timeout &&
        (ros::WallTime::now() - wall0).toSec() > settings_.gripper_timeout) {
      result.code = rascal_msgs::GripperResult::TIMEOUT;
      result.message = "fingers still moving " + std::to_string(elapsed) + " s after the command";
      return result;
    }
    if ((now - last_feedback).toSec() >= 0.05 || now < last_feedback) {
      feedback.width = opening;
      gripper_server_->publishFeedback(feedback);
      last_feedback = now;
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Services

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
    currentJoints(seed, 0.0);
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
  double finger = kFingerMin;
  {
    std::lock_guard<std::mutex> lock(state_mutex_);
    const auto l = positions_.find("left_finger");
    if (l != positions_.end()) {
      finger = l->second;
    }
  }
  if (req.joints.empty()) {
    if (!currentJoints(q, 0.0)) {
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
