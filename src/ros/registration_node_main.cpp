// rosrun breast_tumour_registration registration_node _scene:=/path/scene.yaml points:=/camera/depth/points
#include <malloc.h>
#include <ros/ros.h>

#include "breast_tumour_registration/ros/registration_node.h"

#include <cstdio>
#include <cstring>

int main(int argc, char** argv) {
  for (int i = 1; i < argc; ++i)  // before ros::init, which would wait for a master
    if (!std::strcmp(argv[i], "--help") || !std::strcmp(argv[i], "-h")) {
      std::printf(
          "registration_node: tracks the supine depth cloud and serves prone-to-supine registrations.\n"
          "Usage: rosrun breast_tumour_registration registration_node _scene:=/path/scene.yaml "
          "points:=/camera/depth/points [_param:=value ...]\n"
          "Parameters (README, section ROS): ~scene, ~working_frame, ~model_frame, ~preset, ~voxel_size,\n"
          "~icp_every_n, ~icp_max_iterations, ~icp_max_correspondence, ~initial_model_pose, ~roi_min, ~roi_max,\n"
          "~max_depth_edge, ~scan_smoothing_pixels, ~use_landmarks, ~min_tracked_clouds, ~rigid_margin, ~smoothing_clouds.\n"
          "Service ~register; topics ~result, ~status, ~tumour_mesh, ~tumour_marker, ~breast_marker; tf.\n");
      return 0;
    }
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
