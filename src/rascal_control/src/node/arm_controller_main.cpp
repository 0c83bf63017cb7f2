// rosrun rascal_control arm_controller: the arm and gripper actions, IK/FK services and the arm's TF.
#include <cstdio>
#include <exception>

#include <ros/ros.h>

#include "ArmController.hpp"

int main(int argc, char** argv) {
  // Line by line into a log file too: a rig's log is read while the node runs, and what a
  // crashed or killed node printed last is what tells why.
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  ros::init(argc, argv, "arm_controller");
  ros::NodeHandle private_nh("~");
  try {
    rascal_control::ArmController controller(private_nh);
    ros::spin();
  } catch (const std::exception& e) {
    ROS_FATAL("arm_controller: %s", e.what());
    return 1;
  }
  return 0;
}
