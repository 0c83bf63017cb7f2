// rosrun rascal_perception sherd_detector: sherd detection at the stations from the wrist camera.
#include <ros/ros.h>

#include "SherdDetectorNode.hpp"

int main(int argc, char** argv) {
  ros::init(argc, argv, "sherd_detector");
  ros::NodeHandle root, nh("~");
  try {
    rascal_perception::SherdDetectorNode node(root, nh);
    ros::AsyncSpinner spinner(3);  // services wait for frames that other threads receive
    spinner.start();
    ros::waitForShutdown();
  } catch (const std::exception& e) {
    ROS_FATAL_STREAM("sherd_detector: " << e.what());
    return 1;
  }
  return 0;
}
