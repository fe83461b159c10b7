// rosrun breast_tumour_registration registration_node _scene:=/path/scene.yaml points:=/camera/depth/points
#include <malloc.h>
#include <ros/ros.h>

#include "breast_tumour_registration/ros/registration_node.h"

int main(int argc, char** argv) {
  // Every depth cloud needs buffers of several MB (a 640 x 480 cloud as doubles is 7.4 MB).
  // By default glibc maps each such block fresh from the kernel and unmaps it on free, so
  // every cloud paid thousands of page faults (about 20 ms per cloud, measured). Serving
  // them from the heap and keeping freed memory lets the next cloud reuse the same pages.
  mallopt(M_MMAP_THRESHOLD, 256 * 1024 * 1024);
  mallopt(M_TRIM_THRESHOLD, 512 * 1024 * 1024);
  ros::init(argc, argv, "registration_node");
  ros::NodeHandle nh, pnh("~");
  btr::RegistrationNode node(nh, pnh);  // bad parameters or scene: logged, the node keeps running
  ros::spin();  // clouds on the global queue; the service spins on its own threads
  return 0;
}
