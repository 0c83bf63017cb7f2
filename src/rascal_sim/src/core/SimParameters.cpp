#include "rascal_sim/SimParameters.hpp"

#include <sstream>

namespace rascal_sim {

namespace {
using rascal_workcell::ParameterError;

std::string show(const std::vector<double>& v) {
  std::ostringstream ss;
  ss << "[";
  for (size_t i = 0; i < v.size(); ++i) ss << (i ? ", " : "") << v[i];
  ss << "]";
  return ss.str();
}
}  // namespace

SimParameters SimParameters::read(const rascal_workcell::Parameters& p,
                                  const rascal_workcell::GripperGeometry& gripper, const std::string& data_dir) {
  SimParameters c;
  c.layout = WorldLayout::fromParameters(p, data_dir);
  c.scenario = p.text("simulator.scenario");
  c.real_time_factor = p.number("simulator.real_time_factor");
  c.options.physics_dt = p.number("simulator.physics_step");
  c.clock_period = p.number("simulator.clock_period");
  c.joint_state_period = p.number("simulator.joint_state_period");
  c.options.wrist_camera = p.flag("simulator.wrist_camera");
  c.options.wrist_rate = p.number("simulator.wrist_rate");
  c.point_cloud = p.flag("simulator.point_cloud");

  const std::vector<double> q = p.vector("simulator.initial_joints");
  const auto& lo = ArmKinematics::lowerLimits();
  const auto& hi = ArmKinematics::upperLimits();
  for (int j = 0; j < kArmJoints; ++j) {
    if (q[j] < lo[j] || q[j] > hi[j]) {
      std::ostringstream ss;
      ss << "simulator.initial_joints: expected every joint within its URDF limits (" << ArmKinematics::jointNames()[j]
         << " in [" << lo[j] << ", " << hi[j] << "] rad), got " << show(q);
      throw ParameterError(ss.str());
    }
    c.options.initial_joints[j] = q[j];
  }
  c.options.gripper = gripper.withPads(p.number("arm.gripper.fingertip_pads"));
  const double finger = p.number("simulator.initial_finger");
  if (finger < gripper.finger_min || finger > gripper.finger_max) {
    std::ostringstream ss;
    ss << "simulator.initial_finger: expected a number in m within the URDF's finger limits [" << gripper.finger_min
       << ", " << gripper.finger_max << "], got " << finger;
    throw ParameterError(ss.str());
  }
  c.options.initial_finger = finger;
  const std::vector<double> size = p.vector("simulator.archival_size");
  c.options.archival_width = static_cast<int>(size[0]);
  c.options.archival_height = static_cast<int>(size[1]);
  c.spool_dir = p.text("simulator.spool_dir");
  p.checkAllRead();
  return c;
}

}  // namespace rascal_sim
