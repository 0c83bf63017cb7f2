// rosrun rascal_sim sim: the simulated WidowX 250 s, wrist D435, archival camera and scale.
#include <cstdio>

#include <ros/ros.h>

#include "SimNode.hpp"

int main(int argc, char** argv) {
  // Line by line into a log file too: a rig's log is read while the node runs, and what a
  // crashed or killed node printed last is what tells why.
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  ros::init(argc, argv, "sim");
  ros::NodeHandle nh("~");
  try {
    rascal_sim::SimNode node(nh);
    node.run();
  } catch (const std::exception& e) {
    ROS_FATAL_STREAM("sim: " << e.what());
    return 1;
  }
  return 0;
}
