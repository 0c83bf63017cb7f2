// rosrun rascal_control arm_controller: the arm and gripper actions, IK/FK services and the arm's TF.
#include <exception>

#include <ros/ros.h>

#include "ArmController.hpp"

int main(int argc, char** argv) {
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
