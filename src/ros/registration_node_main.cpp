// rosrun breast_tumour_registration registration_node _scene:=/path/scene.yaml points:=/camera/depth/points
#include <ros/ros.h>

#include "breast_tumour_registration/core/errors.h"
#include "breast_tumour_registration/ros/registration_node.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "registration_node");
  ros::NodeHandle nh, pnh("~");
  try {
    btr::RegistrationNode node(nh, pnh);
    ros::spin();  // clouds on the global queue; the service spins on its own threads
  } catch (const btr::InputError& e) {
    ROS_FATAL("invalid parameter: %s", e.what());
    return 2;
  }
  return 0;
}
