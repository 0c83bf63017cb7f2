#include "rascal_control/DriverMonitor.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace rascal_control {

void DriverMonitor::flag(const std::string& why) {
  if (!restarted_) {  // the first sign is the one worth reporting
    restarted_ = true;
    reason_ = why;
  }
}

void DriverMonitor::addJointState(double stamp, const JointVector& q) {
  if (have_state_) {
    char text[200];
    if (stamp < last_stamp_) {
      std::snprintf(text, sizeof(text), "/joint_states time went backwards (%.3f s -> %.3f s)", last_stamp_, stamp);
      flag(text);
    } else {
      const double allowed =
          settings_.max_speed * kSpeedHeadroom * std::max(stamp - last_stamp_, kLeastInterval) + kJumpSlack;
      std::size_t joint = 0;
      double step = 0.0;
      for (std::size_t j = 0; j < kArmJoints; ++j) {
        if (std::fabs(q[j] - last_q_[j]) > step) {
          step = std::fabs(q[j] - last_q_[j]);
          joint = j;
        }
      }
      if (step > allowed) {
        std::snprintf(text, sizeof(text), "%s jumped %.3f rad in %.3f s on /joint_states (faster than the arm can move)",
                      KinematicModel::armJointNames()[joint].c_str(), step, stamp - last_stamp_);
        flag(text);
      }
    }
  }
  have_state_ = true;
  last_stamp_ = stamp;
  last_q_ = q;
}

void DriverMonitor::addClock(double now) {
  if (now <= 0.0) {
    return;
  }
  if (now < last_clock_) {
    char text[160];
    std::snprintf(text, sizeof(text), "ROS time went backwards (%.3f s -> %.3f s: /clock restarted)", last_clock_, now);
    flag(text);
  }
  last_clock_ = now;
}

void DriverMonitor::addSubscribers(int count) {
  if (count > 0) {
    if (lost_subscriber_) {
      flag("the driver's subscription to its command topic went away and came back");
    }
    had_subscriber_ = true;
    lost_subscriber_ = false;
  } else if (had_subscriber_) {
    lost_subscriber_ = true;
  }
}

bool DriverMonitor::acknowledge() {
  const bool was = restarted_;
  restarted_ = false;
  reason_.clear();
  have_state_ = false;  // a new baseline: the arm is wherever the restarted driver put it
  last_clock_ = 0.0;
  return was;
}

}  // namespace rascal_control
