// rosrun rascal_perception sherd_detector: sherd detection at the stations from the wrist camera.
#include <cstdio>

#include <ros/ros.h>

#include "SherdDetectorNode.hpp"

int main(int argc, char** argv) {
  // Line by line into a log file too: a rig's log is read while the node runs, and what a
  // crashed or killed node printed last is what tells why.
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
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
