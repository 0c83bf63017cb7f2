// Notices a restarted arm driver (or simulator) from plain samples: the node feeds it every
// /joint_states message, ROS time and the number of subscribers of the driver's command topics.
// A restarted driver has lost every command and, in simulation, the world: the controller must
// refuse goals until the task has acknowledged it (and re-calibrates). No ROS.
#pragma once

#include <string>

#include "rascal_control/KinematicModel.hpp"

namespace rascal_control {

class DriverMonitor {
 public:
  struct Settings {
    double max_speed = 3.14159;  // [rad/s] fastest any joint can move (the URDF's limit)
  };
  // Speed headroom and slack [rad] before a change between two messages counts as a jump.
  static constexpr double kSpeedHeadroom = 1.5;
  static constexpr double kJumpSlack = 0.05;
  // [s] the least time a change is judged over: a position can be this much older than its
  // stamp (a driver on simulated time stamps what another process moved on its own copy of
  // /clock, which on a loaded machine stands still and then catches up), so 5 ms between two
  // messages is judged as 50 ms. A restart's step to the reset pose is still far beyond it.
  static constexpr double kLeastInterval = 0.05;

  explicit DriverMonitor(const Settings& settings) : settings_(settings) {}

  // One /joint_states message with all six arm joints; `stamp` [s] is the driver's (or the
  // arrival time when it sends none). A stamp earlier than the last, or a joint moving faster
  // than the arm can between two messages (the driver came up at its reset pose), is a restart.
  void addJointState(double stamp, const JointVector& q);
  // ROS time now [s] (0 before the first /clock under use_sim_time: ignored). Time going
  // backwards (a restarted simulator's /clock) is a restart.
  void addClock(double now);
  // Subscribers of the driver's command topic. Having had one, then none, then one again is a
  // restart (the driver process went away and came back).
  void addSubscribers(int count);

  bool restarted() const { return restarted_; }
  // What showed it, e.g. "/joint_states time went backwards (312.410 s -> 0.020 s)".
  const std::string& reason() const { return reason_; }
  // The task knows (and re-calibrates): goals are accepted again; the next samples are a new
  // baseline. Returns whether there was a restart to acknowledge.
  bool acknowledge();

 private:
  void flag(const std::string& why);

  Settings settings_;
  bool restarted_ = false;
  std::string reason_;
  bool have_state_ = false;
  double last_stamp_ = 0.0;
  JointVector last_q_{};
  double last_clock_ = 0.0;
  bool had_subscriber_ = false;
  bool lost_subscriber_ = false;
};

}  // namespace rascal_control
