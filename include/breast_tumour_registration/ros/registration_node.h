// The ROS node: a thin adapter over the core library. It loads and caches a scene at
// start-up, tracks the prone model's rigid region in the depth cloud with ICP (tf2
// broadcast), runs the FEM registration in a service on its own threads, and publishes
// the tumour mesh, markers, result and status. Bad input is logged and answered with
// success: false; the node keeps running.
#pragma once

#include <diagnostic_msgs/DiagnosticStatus.h>
#include <ros/callback_queue.h>
#include <ros/ros.h>
#include <sensor_msgs/PointCloud2.h>
#include <tf2_ros/transform_broadcaster.h>
#include <tf2_ros/transform_listener.h>

#include <atomic>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "breast_tumour_registration/Register.h"
#include "breast_tumour_registration/registration/depth_tracker.h"
#include "breast_tumour_registration/registration/registration_engine.h"

namespace btr {

struct NodeParameters {
  std::string scene;                      ///< ~scene: scene file (YAML)
  std::string working_frame = "world";    ///< ~working_frame: frame of the results
  std::string model_frame = "breast_model";  ///< ~model_frame: the prone model's frame (tf child)
  std::string preset = "balanced";        ///< ~preset
  /// The depth tracking, read from ~voxel_size (cloud downsampling [m], 0: none),
  /// ~icp_max_iterations (per cloud, warm-started), ~icp_max_correspondence [m], ~roi_min and
  /// ~roi_max ([m], working frame) and ~smoothing_clouds (the published pose is the mean of
  /// this many, 1: none); the rest as DepthTrackerOptions has it.
  DepthTrackerOptions tracker;
  int icp_every_n = 1;                    ///< ~icp_every_n: track on every n-th cloud
  Rigid initial_model_pose = Rigid::Identity();  ///< ~initial_model_pose [x y z roll pitch yaw], working frame
  double max_depth_edge = 0.01;           ///< ~max_depth_edge [m]: no surface across depth jumps
  double scan_smoothing_pixels = 2.0;     ///< ~scan_smoothing_pixels: Gaussian sigma of the scan's smoothing before registration (0: none)
  bool use_landmarks = true;              ///< ~use_landmarks with the live cloud
  int min_tracked_clouds = 10;            ///< ~min_tracked_clouds: consecutive ICP successes before registering
  double rigid_margin = 0.015;            ///< ~rigid_margin [m]: track chest-ring points this far from the breast
};

/// Reads the parameters with defaults; throws InputError naming a parameter out of range.
NodeParameters read_node_parameters(const ros::NodeHandle& pnh);

class RegistrationNode {
 public:
  RegistrationNode(ros::NodeHandle nh, ros::NodeHandle pnh);
  ~RegistrationNode();

 private:
  void load_scene();
  void on_cloud(const sensor_msgs::PointCloud2ConstPtr& msg);
  bool on_register(breast_tumour_registration::Register::Request& req,
                   breast_tumour_registration::Register::Response& res);
  void publish_status(uint8_t level, const std::string& message);
  void publish_result(const RegistrationResult& r, const RegistrationModel& model, const std::string& preset,
                      breast_tumour_registration::RegistrationResult& out);

  ros::NodeHandle nh_, pnh_;
  NodeParameters params_;
  // The scene's registration engine (null when loading failed): it prepares, per simulation
  // mesh a preset asks for, the model and the steps' solvers on first use (the default preset's
  // at start-up) and keeps them; used under registration_mutex_ only.
  std::unique_ptr<RegistrationEngine> engine_;
  std::string scene_error_;
  // Latest cloud (working frame, organized with NaN) and the tracked rigid alignment.
  std::mutex state_mutex_;
  Points latest_cloud_;
  int latest_width_ = 0, latest_height_ = 0;
  bool have_cloud_ = false;
  std::optional<DepthTracker> tracker_;
  std::optional<SurfaceSamples> tracked_region_;  ///< the rigid region clear of the breast (model frame)
  long clouds_seen_ = 0;
  std::vector<double> cloud_seconds_;      ///< wall time of recent tracked clouds [s]
  std::vector<double> cloud_cpu_seconds_;  ///< their callback thread's CPU time [s]
  // Registration runs one at a time; a second request gets an answer, not a deadlock.
  std::mutex registration_mutex_;
  std::atomic<bool> registering_{false};  ///< tracking pauses meanwhile: both would share two cores

  tf2_ros::Buffer tf_buffer_;
  tf2_ros::TransformListener tf_listener_;
  tf2_ros::TransformBroadcaster tf_broadcaster_;
  ros::Subscriber cloud_sub_;
  ros::CallbackQueue service_queue_;
  std::unique_ptr<ros::AsyncSpinner> service_spinner_;
  ros::ServiceServer register_srv_;
  ros::Publisher mesh_pub_, marker_pub_, breast_marker_pub_, result_pub_, status_pub_, status_marker_pub_;
};

}  // namespace btr
