// rosrun rascal_sim sim: the simulated WidowX 250 s, wrist D435, archival camera and scale.
#include <ros/ros.h>

#include "SimNode.hpp"

int main(int argc, char** argv) {
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
