#include "rascal_control/ControllerParameters.hpp"

#include <sstream>

namespace rascal_control {

namespace {

std::string show(const std::vector<double>& v) {
  std::ostringstream ss;
  ss << "[";
  for (std::size_t i = 0; i < v.size(); ++i) ss << (i ? ", " : "") << v[i];
  ss << "]";
  return ss.str();
}

}  // namespace

ControllerParameters ControllerParameters::read(const rascal_workcell::Parameters& p, const KinematicModel& model) {
  ControllerParameters c;
  for (const std::string& name : p.names("arm.named_poses")) {
    const std::string key = "arm.named_poses." + name;
    const std::vector<double> v = p.vector(key);
    JointVector q{};
    for (std::size_t j = 0; j < kArmJoints && j < v.size(); ++j) q[j] = v[j];
    const int joint = model.firstLimitViolation(q);
    if (joint >= 0) {
      const JointLimit& limit = model.limits()[joint];
      std::ostringstream ss;
      ss << key << ": expected every joint within its URDF limits (" << KinematicModel::armJointNames()[joint]
         << " in [" << limit.lower << ", " << limit.upper << "] rad), got " << show(v);
      throw rascal_workcell::ParameterError(ss.str());
    }
    c.named_poses[name] = q;
  }
  c.speed_scale = p.number("arm.speed_scale");
  c.acceleration_share = p.number("arm.acceleration_share");
  c.command_period = p.number("arm.command_period");
  c.state_timeout = p.number("arm.state_timeout");
  c.publish_tf = p.flag("arm.publish_tf");
  c.move.goal_tolerance = p.number("arm.goal_tolerance");
  c.move.settle_timeout = p.number("arm.settle_timeout");
  c.move.tracking_tolerance = p.number("arm.tracking_tolerance");
  c.gripper.timeout = p.number("arm.gripper.timeout");
  c.gripper.stroke_time = p.number("arm.gripper.stroke_time");
  c.gripper.held_margin = p.number("arm.gripper.held_margin");
  c.fingertip_pads = p.number("arm.gripper.fingertip_pads");
  c.fixtures = rascal_workcell::Workcell::fromParameters(p).collisionBoxes();
  p.checkAllRead();
  return c;
}

}  // namespace rascal_control
