#include "breast_tumour_registration/ros/registration_node.h"

#include <geometry_msgs/TransformStamped.h>
#include <shape_msgs/Mesh.h>
#include <visualization_msgs/Marker.h>

#include <time.h>

#include <algorithm>
#include <chrono>
#include <optional>

#include "breast_tumour_registration/RegistrationResult.h"
#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/geometry/margin_shell.h"
#include "breast_tumour_registration/geometry/surface_attachment.h"
#include "breast_tumour_registration/registration/live_scene.h"
#include "breast_tumour_registration/ros/converters.h"

namespace btr {
namespace {

/// The call came before the data it needs (no cloud yet, tracking settling): the caller waits
/// and calls again; not an error.
struct NotReady : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// A parameter that is set must have the right type: `~voxel_size: abc` used to fall back to
/// the default without a word (issue 11).
template <class T>
void read_param(const ros::NodeHandle& pnh, const std::string& name, T& value, const char* type) {
  if (!pnh.hasParam(name)) return;
  if (!pnh.getParam(name, value)) throw InputError("parameter ~" + name + " has the wrong type (expected " + type + ")");
}

Vec3 read_vec3(const ros::NodeHandle& pnh, const std::string& name, const Vec3& def) {
  std::vector<double> v;
  if (!pnh.hasParam(name)) return def;
  if (!pnh.getParam(name, v)) throw InputError("parameter ~" + name + " has the wrong type (expected a list of 3 numbers)");
  if (v.size() != 3) throw InputError("parameter ~" + name + " must be a list of 3 numbers");
  return Vec3(v[0], v[1], v[2]);
}

/// CPU time of the calling thread [s] (excludes time the thread waited or was preempted).
double thread_cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

}  // namespace

NodeParameters read_node_parameters(const ros::NodeHandle& pnh) {
  NodeParameters p;
  read_param(pnh, "scene", p.scene, "a file name");
  read_param(pnh, "working_frame", p.working_frame, "a frame name");
  read_param(pnh, "model_frame", p.model_frame, "a frame name");
  read_param(pnh, "preset", p.preset, "fast, balanced or accurate");
  read_param(pnh, "voxel_size", p.tracker.voxel_size, "a number [m]");
  read_param(pnh, "icp_every_n", p.icp_every_n, "an integer");
  read_param(pnh, "icp_max_iterations", p.tracker.max_iterations, "an integer");
  read_param(pnh, "icp_max_correspondence", p.tracker.max_correspondence, "a number [m]");
  read_param(pnh, "max_depth_edge", p.max_depth_edge, "a number [m]");
  read_param(pnh, "scan_smoothing_pixels", p.scan_smoothing_pixels, "a number [px]");
  read_param(pnh, "use_landmarks", p.use_landmarks, "true or false");
  read_param(pnh, "min_tracked_clouds", p.min_tracked_clouds, "an integer");
  read_param(pnh, "rigid_margin", p.rigid_margin, "a number [m]");
  read_param(pnh, "smoothing_clouds", p.tracker.smoothing_clouds, "an integer");
  p.tracker.roi_min = read_vec3(pnh, "roi_min", p.tracker.roi_min);
  p.tracker.roi_max = read_vec3(pnh, "roi_max", p.tracker.roi_max);
  std::vector<double> pose;
  if (pnh.hasParam("initial_model_pose") && !pnh.getParam("initial_model_pose", pose))
    throw InputError("parameter ~initial_model_pose has the wrong type (expected [x, y, z, roll, pitch, yaw])");
  if (!pose.empty()) {
    if (pose.size() != 6) throw InputError("parameter ~initial_model_pose must be [x, y, z, roll, pitch, yaw]");
    p.initial_model_pose = rigid_from_rpy(Vec3(pose[0], pose[1], pose[2]), Vec3(pose[3], pose[4], pose[5]));
  }
  preset_options(p.preset);  // throws for an unknown preset
  if (!(p.tracker.voxel_size >= 0) || p.icp_every_n < 1 || p.tracker.max_iterations < 1 || !(p.tracker.max_correspondence > 0) ||
      !(p.max_depth_edge > 0) || p.min_tracked_clouds < 1 || !(p.rigid_margin >= 0) || p.tracker.smoothing_clouds < 1 ||
      !(p.scan_smoothing_pixels >= 0 && p.scan_smoothing_pixels <= 50))
    throw InputError("parameters ~icp_max_correspondence, ~max_depth_edge must be > 0, ~scan_smoothing_pixels in [0, 50], ~voxel_size and "
                     "~rigid_margin >= 0, and ~icp_every_n, ~icp_max_iterations, ~min_tracked_clouds, "
                     "~smoothing_clouds >= 1");
  if ((p.tracker.roi_max - p.tracker.roi_min).minCoeff() <= 0) throw InputError("parameter ~roi_max must exceed ~roi_min on every axis");
  return p;
}

RegistrationNode::RegistrationNode(ros::NodeHandle nh, ros::NodeHandle pnh)
    : nh_(nh), pnh_(pnh), tf_listener_(tf_buffer_) {
  bool parameters_ok = true;
  try {
    params_ = read_node_parameters(pnh_);
  } catch (const InputError& e) {
    // Keep running with nothing loaded: the service and ~status say what to fix.
    parameters_ok = false;
    scene_error_ = std::string("invalid parameter: ") + e.what();
  }
  status_pub_ = pnh_.advertise<diagnostic_msgs::DiagnosticStatus>("status", 1, true);
  mesh_pub_ = pnh_.advertise<shape_msgs::Mesh>("tumour_mesh", 1, true);
  marker_pub_ = pnh_.advertise<visualization_msgs::Marker>("tumour_marker", 10, true);
  breast_marker_pub_ = pnh_.advertise<visualization_msgs::Marker>("breast_marker", 1, true);
  status_marker_pub_ = pnh_.advertise<visualization_msgs::Marker>("status_marker", 1, true);
  result_pub_ = pnh_.advertise<breast_tumour_registration::RegistrationResult>("result", 1, true);
  if (parameters_ok) {
    load_scene();
  } else {
    ROS_ERROR_STREAM(scene_error_ << " (the node keeps running; fix the parameter and restart)");
    publish_status(diagnostic_msgs::DiagnosticStatus::ERROR, scene_error_);
  }
  cloud_sub_ = nh_.subscribe("points", 2, &RegistrationNode::on_cloud, this);
  // The service has its own queue and two threads: a registration never blocks the cloud
  // callback, and a second request is answered while the first one runs.
  ros::AdvertiseServiceOptions ops = ros::AdvertiseServiceOptions::create<breast_tumour_registration::Register>(
      "register",
      [this](breast_tumour_registration::Register::Request& req, breast_tumour_registration::Register::Response& res) {
        return on_register(req, res);
      },
      ros::VoidConstPtr(), &service_queue_);
  register_srv_ = pnh_.advertiseService(ops);
  service_spinner_ = std::make_unique<ros::AsyncSpinner>(2, &service_queue_);
  service_spinner_->start();
}

RegistrationNode::~RegistrationNode() {
  if (service_spinner_) service_spinner_->stop();
}

void RegistrationNode::load_scene() {
  try {
    if (params_.scene.empty()) throw InputError("parameter ~scene is not set (path of a scene YAML file)");
    const auto t0 = std::chrono::steady_clock::now();
    engine_ = std::make_unique<RegistrationEngine>(btr::load_scene(params_.scene));
    // The default preset's simulation mesh, model and solvers, ready before any call.
    const PreparedScene& p = engine_->prepare(preset_options(params_.preset));
    for (const auto& w : p.warnings) ROS_WARN_STREAM("scene: " << w);
    const Scene& s = engine_->scene();
    if (!p.mesh_note.empty()) ROS_INFO("%s for the %s preset (%.2f s)", p.mesh_note.c_str(), params_.preset.c_str(), p.mesh_seconds);
    if (!s.prone_rigid) {
      ROS_WARN("scene has no chest_ring: depth tracking (ICP) is disabled");
    } else {
      // The supine breast bulges over the chest skin next to it: track only the part clear of it.
      // The prepared scene's mesh: a prone surface is meshed by the engine, not the loader.
      tracked_region_ = rigid_region_samples(*s.prone_rigid, boundary_surface(p.scene.prone), params_.rigid_margin, 0.002);
      ROS_INFO("depth tracking on %ld samples of the chest ring (2 mm apart, farther than %.0f mm from the breast)",
               static_cast<long>(tracked_region_->points.rows()), params_.rigid_margin * 1e3);
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    ROS_INFO("loaded scene %s: simulating on %ld vertices, %ld tetrahedra, %zu tumours; prepared in %.2f s", params_.scene.c_str(),
             static_cast<long>(p.model.rest.V.rows()), static_cast<long>(p.model.rest.T.rows()), p.model.tumours.size(),
             seconds);
    publish_status(diagnostic_msgs::DiagnosticStatus::OK, "scene loaded; waiting for depth clouds");
  } catch (const std::exception& e) {
    engine_.reset();
    tracked_region_.reset();
    scene_error_ = e.what();
    ROS_ERROR_STREAM("cannot load the scene: " << scene_error_ << " (the node keeps running; fix ~scene and restart)");
    publish_status(diagnostic_msgs::DiagnosticStatus::ERROR, "scene failed to load: " + scene_error_);
  }
}

void RegistrationNode::publish_status(uint8_t level, const std::string& message) {
  diagnostic_msgs::DiagnosticStatus st;
  st.level = level;
  st.name = ros::this_node::getName();
  st.message = message;
  st.hardware_id = params_.scene;
  status_pub_.publish(st);
  // The same as text beside the model, for RViz (white, yellow for a warning, red for an error).
  visualization_msgs::Marker mk;
  mk.header.frame_id = params_.model_frame;
  mk.header.stamp = ros::Time(0);  // the latest model pose
  mk.ns = "status";
  mk.type = visualization_msgs::Marker::TEXT_VIEW_FACING;
  mk.action = visualization_msgs::Marker::ADD;
  mk.pose.position.z = 0.10;
  mk.pose.orientation.w = 1.0;
  mk.scale.z = 0.006;
  mk.color.r = 1.0f;
  mk.color.g = level == diagnostic_msgs::DiagnosticStatus::ERROR ? 0.3f : 1.0f;
  mk.color.b = level == diagnostic_msgs::DiagnosticStatus::OK ? 1.0f : 0.3f;
  mk.color.a = 1.0f;
  mk.text = message;
  status_marker_pub_.publish(mk);
}

void RegistrationNode::on_cloud(const sensor_msgs::PointCloud2ConstPtr& msg) {
  using Clock = std::chrono::steady_clock;
  const auto t_start = Clock::now();
  const double cpu_start = thread_cpu_seconds();
  try {
    ros_conv::CloudPoints c = ros_conv::from_cloud(*msg, true);
    if (c.points.rows() == 0) throw InputError("empty point cloud");
    if (c.finite == 0) throw InputError("point cloud has no finite point (all NaN)");
    geometry_msgs::TransformStamped tf;
    const auto t_tf = Clock::now();
    try {
      tf = tf_buffer_.lookupTransform(params_.working_frame, msg->header.frame_id, msg->header.stamp, ros::Duration(0.05));
    } catch (const tf2::TransformException& e) {
      throw InputError("no transform from '" + msg->header.frame_id + "' to '" + params_.working_frame + "': " + e.what());
    }
    const double tf_wait = std::chrono::duration<double>(Clock::now() - t_tf).count();
    const Rigid T = ros_conv::from_transform(tf.transform);
    std::unique_lock<std::mutex> lock(state_mutex_);
    if (!tracker_ && tracked_region_) {
      // Without a rigid region there is nothing to track; the cloud is still kept (ROI only).
      tracker_.emplace(*tracked_region_, params_.initial_model_pose, params_.tracker);
    }
    const bool track = tracker_ && !registering_ && clouds_seen_ % params_.icp_every_n == 0;
    TrackingResult r;
    if (track) {
      r = tracker_->process(c.points, T);
    } else {
      // Keep the cloud in the working frame (ROI applied) without aligning it.
      to_working_frame(c.points, T, params_.tracker.roi_min, params_.tracker.roi_max);
    }
    latest_cloud_ = std::move(c.points);
    latest_width_ = c.organized ? c.width : 0;
    latest_height_ = c.organized ? c.height : 0;
    have_cloud_ = true;
    ++clouds_seen_;
    if (!track) return;
    if (!r.accepted) {
      lock.unlock();
      ROS_WARN_THROTTLE(2.0, "depth tracking: %s (cloud far from the model? check ~initial_model_pose and the ROI)",
                        r.icp.message.c_str());
      return;
    }
    const Rigid pose = *tracker_->pose();
    // Per-cloud processing time (conversion, filtering, ICP; not the wait for tf), logged
    // as median and 95th percentile every 300 tracked clouds.
    cloud_seconds_.push_back(std::chrono::duration<double>(Clock::now() - t_start).count() - tf_wait);
    cloud_cpu_seconds_.push_back(thread_cpu_seconds() - cpu_start);
    if (cloud_seconds_.size() == 300) {
      std::sort(cloud_seconds_.begin(), cloud_seconds_.end());
      std::sort(cloud_cpu_seconds_.begin(), cloud_cpu_seconds_.end());
      ROS_INFO("depth tracking per cloud over the last 300 (conversion, filtering and ICP): wall %.1f ms median, "
               "%.1f ms 95th percentile; CPU of the callback thread %.1f ms median, %.1f ms 95th percentile",
               1e3 * cloud_seconds_[150], 1e3 * cloud_seconds_[284], 1e3 * cloud_cpu_seconds_[150],
               1e3 * cloud_cpu_seconds_[284]);
      cloud_seconds_.clear();
      cloud_cpu_seconds_.clear();
    }
    lock.unlock();
    geometry_msgs::TransformStamped out;
    out.header.stamp = msg->header.stamp;
    out.header.frame_id = params_.working_frame;
    out.child_frame_id = params_.model_frame;
    out.transform = ros_conv::to_transform(pose);
    tf_broadcaster_.sendTransform(out);
  } catch (const InputError& e) {
    ROS_ERROR_THROTTLE(1.0, "depth cloud rejected: %s", e.what());
    publish_status(diagnostic_msgs::DiagnosticStatus::WARN, std::string("depth cloud rejected: ") + e.what());
  } catch (const std::exception& e) {
    ROS_ERROR_THROTTLE(1.0, "depth cloud processing failed: %s", e.what());
  }
}

bool RegistrationNode::on_register(breast_tumour_registration::Register::Request& req,
                                   breast_tumour_registration::Register::Response& res) {
  std::unique_lock<std::mutex> busy(registration_mutex_, std::try_to_lock);
  if (!busy.owns_lock()) {
    res.success = false;
    res.message = "a registration is already running; wait for its result on ~result and call again";
    return true;
  }
  try {
    if (!engine_) throw InputError("the node is not ready: " + scene_error_ + "; fix it and restart the node");
    const std::string preset = req.preset.empty() ? params_.preset : req.preset;
    RegistrationOptions opt = preset_options(preset);
    if (req.uncertainty != "" && req.uncertainty != "none" && req.uncertainty != "linear" && req.uncertainty != "sampling")
      throw InputError("request field 'uncertainty': '" + req.uncertainty + "' is not one of \"\", none, linear, sampling");
    const bool sampling = req.uncertainty == "sampling";
    const int samples = req.samples == 0 ? 16 : static_cast<int>(std::min<uint32_t>(req.samples, 100000));
    if (sampling && (samples < 2 || samples > 1000))
      throw InputError("request field 'samples': " + std::to_string(req.samples) + " is not 0 (16) or 2 to 1000");
    opt.uncertainty.enabled = req.uncertainty == "linear" || sampling;  // sampling gives the linear figures too
    opt.uncertainty.sources = engine_->scene().uncertainty;
    std::optional<LiveScan> scan;
    LiveSceneOptions lo;
    if (req.use_latest_cloud) {
      Points cloud;
      int w, h;
      std::optional<Rigid> T;
      std::optional<Mat6> T_covariance;
      int tracked = 0;
      {
        std::lock_guard<std::mutex> lock(state_mutex_);
        if (!have_cloud_)
          throw NotReady("no depth cloud has been received on '" + cloud_sub_.getTopic() +
                         "' yet; start the camera or play a bag, then call again");
        cloud = latest_cloud_;
        w = latest_width_;
        h = latest_height_;
        if (tracker_) {
          T = tracker_->pose();
          T_covariance = tracker_->pose_covariance();
          tracked = tracker_->consecutive();
        }
      }
      if (!T)
        throw NotReady("the model is not aligned with the depth cloud yet (ICP rejected every cloud); make sure the "
                       "chest around the breast is in view and ~initial_model_pose is close");
      if (tracked < params_.min_tracked_clouds)
        throw NotReady("the depth tracking is settling (" + std::to_string(tracked) + " of " +
                       std::to_string(params_.min_tracked_clouds) + " consecutive clouds aligned); call again shortly");
      lo.max_depth_edge = params_.max_depth_edge;
      lo.smoothing_pixels = params_.scan_smoothing_pixels;
      lo.use_landmarks = params_.use_landmarks;
      scan = LiveScan{std::move(cloud), w, h, *T, T_covariance};
    }
    publish_status(diagnostic_msgs::DiagnosticStatus::OK, "registration running (" + preset + ")");
    struct Flag {
      std::atomic<bool>& f;
      explicit Flag(std::atomic<bool>& x) : f(x) { f = true; }
      ~Flag() { f = false; }
    } running(registering_);
    RegistrationResult r = scan ? engine_->solve_live(*scan, lo, opt) : engine_->solve(opt);
    if (sampling) {
      publish_status(diagnostic_msgs::DiagnosticStatus::OK, "uncertainty: " + std::to_string(samples) + " sampled re-registrations running");
      r.sampled_uncertainty = scan ? engine_->sample_uncertainty_live(*scan, lo, opt, opt.uncertainty, samples, 1, r)
                                   : engine_->sample_uncertainty(opt, opt.uncertainty, samples, 1, r);
    }
    publish_result(r, engine_->prepared_for(opt, r).model, preset, res.result);
    res.success = true;
    res.message = "registered in " + std::to_string(r.seconds) + " s (" + r.steps.describe() + ")";
    for (const auto& step : r.reports) {
      if (step.skin_vertices > 0)
        res.message += "; " + std::to_string(step.constrained_skin) + " of " + std::to_string(step.skin_vertices) +
                       " skin vertices held to the scan";
      if (!step.converged) res.message += "; the " + step.name + " step stopped without converging (" + step.stop_reason + ")";
    }
    if (!r.converged) res.message += "; not converged: the result is the last state, see the step reports";
    if (r.implausible) res.message += "; implausible: see the result's warnings";
    publish_status(r.converged && !r.implausible ? diagnostic_msgs::DiagnosticStatus::OK : diagnostic_msgs::DiagnosticStatus::WARN,
                   res.message);
  } catch (const NotReady& e) {  // waiting for data is not an error
    res.success = false;
    res.message = e.what();
    ROS_INFO_STREAM_THROTTLE(2.0, "registration waiting: " << e.what());
    publish_status(diagnostic_msgs::DiagnosticStatus::WARN, res.message);
  } catch (const InputError& e) {
    res.success = false;
    res.message = e.what();
    ROS_ERROR_STREAM("registration refused: " << e.what());
    publish_status(diagnostic_msgs::DiagnosticStatus::ERROR, res.message);
  } catch (const std::exception& e) {
    res.success = false;
    res.message = std::string("registration failed: ") + e.what();
    ROS_ERROR_STREAM(res.message);
    publish_status(diagnostic_msgs::DiagnosticStatus::ERROR, res.message);
  }
  return true;
}

void RegistrationNode::publish_result(const RegistrationResult& r, const RegistrationModel& model,
                                      const std::string& preset, breast_tumour_registration::RegistrationResult& out) {
  const ros::Time now = ros::Time::now();
  const std::string& frame = params_.working_frame;
  out.header.stamp = now;
  out.header.frame_id = frame;
  out.preset = preset;
  out.steps = r.steps.describe();
  out.converged = r.converged;
  out.implausible = r.implausible;
  out.registration_seconds = r.seconds;
  out.landmark_residual_mean = r.landmark_residual_mean;
  out.skin_distance_mean = r.skin_distance_mean;
  out.warnings = r.warnings;
  out.uncertainty_note = r.uncertainty_note;
  if (r.sampled_uncertainty) {
    const SampledUncertainty& su = *r.sampled_uncertainty;
    out.uncertainty_note += std::string(out.uncertainty_note.empty() ? "" : "; ") + "sampled: " + std::to_string(su.samples) +
                            " samples (" + std::to_string(su.not_converged) + " not converged)" + (su.note.empty() ? "" : ": " + su.note);
  }
  for (const auto& s : r.reports) {
    out.step_names.push_back(s.name);
    out.step_seconds.push_back(s.seconds);
  }
  const Rigid model_to_working = r.supine_to_model.inverse();
  out.model_to_working.header = out.header;
  out.model_to_working.child_frame_id = params_.model_frame;
  out.model_to_working.transform = ros_conv::to_transform(model_to_working);
  int id = 0;
  for (const auto& t : r.tumours) {
    breast_tumour_registration::TumourResult tm;
    tm.name = t.name;
    tm.mesh = ros_conv::to_mesh(t.registered);
    tm.centroid.header = out.header;
    tm.centroid.point.x = t.centroid.x();
    tm.centroid.point.y = t.centroid.y();
    tm.centroid.point.z = t.centroid.z();
    tm.volume_ratio = t.volume_ratio;
    tm.axis_ratio = t.axis_ratio;
    tm.prone_axis_ratio = t.prone_axis_ratio;
    tm.has_ground_truth = t.has_ground_truth;
    tm.centroid_error = t.centroid_distance;
    if (t.uncertainty) {
      tm.has_uncertainty = true;
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b)  // symmetric to the bit (the frame change leaves round-off)
          tm.centroid_covariance[3 * a + b] = 0.5 * (t.uncertainty->covariance(a, b) + t.uncertainty->covariance(b, a));
      tm.radius_95 = t.uncertainty->radius_95;
    }
    const SampledUncertainty::Tumour* st =
        r.sampled_uncertainty && static_cast<size_t>(id) < r.sampled_uncertainty->tumours.size() ? &r.sampled_uncertainty->tumours[id] : nullptr;
    std::optional<SurfaceMesh> shell;
    if (st) {
      tm.has_sampled_uncertainty = true;
      tm.radius_95_sampled = st->radius_95;
      if (st->vertex_radius_95.size() == static_cast<size_t>(t.registered.V.rows())) {
        shell = margin_shell(t.registered, st->vertex_radius_95);
        tm.margin_shell = ros_conv::to_mesh(*shell);
      }
    }
    out.tumours.push_back(tm);
    auto mk = ros_conv::to_marker(t.registered, frame, "tumour", id, 0.9f, 0.2f, 0.2f, 0.9f);
    mk.header.stamp = now;
    marker_pub_.publish(mk);
    if (shell) {  // the margin shell, translucent orange around the tumour
      auto sm = ros_conv::to_marker(*shell, frame, "margin", id, 1.0f, 0.55f, 0.1f, 0.3f);
      sm.header.stamp = now;
      marker_pub_.publish(sm);
    }
    if (t.uncertainty) {  // the centroid's 95 % region, translucent yellow
      auto em = ros_conv::to_ellipsoid_marker(t.centroid, t.uncertainty->covariance, frame, "uncertainty", id, 1.0f, 0.85f, 0.2f, 0.35f);
      em.header.stamp = now;
      marker_pub_.publish(em);
    }
    ++id;
    geometry_msgs::TransformStamped tf;
    tf.header = out.header;
    tf.child_frame_id = "tumour_" + t.name;
    tf.transform.translation.x = t.centroid.x();
    tf.transform.translation.y = t.centroid.y();
    tf.transform.translation.z = t.centroid.z();
    tf.transform.rotation.w = 1.0;
    tf_broadcaster_.sendTransform(tf);
  }
  if (!out.tumours.empty()) mesh_pub_.publish(out.tumours.front().mesh);
  const SurfaceMesh skin = transform_surface(model_to_working, boundary_surface(TetMesh{r.x, model.rest.T}));
  auto bm = ros_conv::to_marker(skin, frame, "breast", 0, 0.9f, 0.75f, 0.65f, 0.4f);
  bm.header.stamp = now;
  breast_marker_pub_.publish(bm);
  result_pub_.publish(out);
}

}  // namespace btr
