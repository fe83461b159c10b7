// btr_demo_client: waits for the registration node to track the depth cloud, calls the
// registration service, prints the tumour centroids, their error against the truth file
// written by btr_make_bag, and the timings; exits 0 on success (so roslaunch can end).
#include <ros/ros.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "breast_tumour_registration/Register.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "btr_demo_client");
  ros::NodeHandle pnh("~");
  std::string service = "/registration_node/register", truth_file, preset;
  double timeout = 60.0;
  pnh.param("service", service, service);
  pnh.param("truth", truth_file, truth_file);
  pnh.param("preset", preset, preset);
  pnh.param("timeout", timeout, timeout);
  std::string uncertainty;  // "" / none, linear (each tumour also gets its 95 % region) or sampling (and a margin shell)
  pnh.param("uncertainty", uncertainty, uncertainty);
  int samples = 0;  // with sampling: re-registrations (0: the node's 16)
  pnh.param("samples", samples, samples);
  if (!ros::service::waitForService(service, ros::Duration(timeout))) {
    ROS_ERROR("service %s did not appear within %.0f s", service.c_str(), timeout);
    return 1;
  }
  ros::ServiceClient client = ros::NodeHandle().serviceClient<breast_tumour_registration::Register>(service);
  breast_tumour_registration::Register srv;
  srv.request.preset = preset;
  srv.request.use_latest_cloud = true;
  srv.request.uncertainty = uncertainty;
  srv.request.samples = static_cast<uint32_t>(std::max(0, samples));
  const ros::WallTime start = ros::WallTime::now();
  // The node answers "not yet" until a cloud has arrived and the model is tracked.
  while (ros::ok()) {
    const ros::WallTime t0 = ros::WallTime::now();
    if (!client.call(srv)) {
      ROS_ERROR("service call failed");
      return 1;
    }
    const double round_trip = (ros::WallTime::now() - t0).toSec();
    if (srv.response.success) {
      const auto& r = srv.response.result;
      std::printf("[demo] %s\n[demo] service round trip %.3f s (registration %.3f s; steps:", srv.response.message.c_str(),
                  round_trip, r.registration_seconds);
      for (size_t i = 0; i < r.step_names.size(); ++i) std::printf(" %s %.3f s", r.step_names[i].c_str(), r.step_seconds[i]);
      std::printf(")\n");
      YAML::Node truth;
      if (!truth_file.empty()) truth = YAML::LoadFile(truth_file);
      for (const auto& t : r.tumours) {
        std::printf("[demo] tumour %-7s centroid (%.1f, %.1f, %.1f) mm in '%s'", t.name.c_str(), t.centroid.point.x * 1e3,
                    t.centroid.point.y * 1e3, t.centroid.point.z * 1e3, r.header.frame_id.c_str());
        if (truth && truth["tumour_centroids"][t.name]) {
          const auto c = truth["tumour_centroids"][t.name].as<std::vector<double>>();
          const double e = std::sqrt(std::pow(t.centroid.point.x - c[0], 2) + std::pow(t.centroid.point.y - c[1], 2) +
                                     std::pow(t.centroid.point.z - c[2], 2));
          std::printf(", error %.2f mm against the truth", e * 1e3);
        }
        if (t.has_uncertainty) std::printf(", 95 %% radius %.2f mm (experimental)", t.radius_95 * 1e3);
        if (t.has_sampled_uncertainty) std::printf(", sampled 95 %% radius %.2f mm", t.radius_95_sampled * 1e3);
        std::printf("\n");
      }
      if (!r.uncertainty_note.empty()) std::printf("[demo] uncertainty: %s\n", r.uncertainty_note.c_str());
      return 0;
    }
    if ((ros::WallTime::now() - start).toSec() > timeout) {
      ROS_ERROR("registration not possible within %.0f s: %s", timeout, srv.response.message.c_str());
      return 1;
    }
    ROS_INFO_THROTTLE(2.0, "waiting: %s", srv.response.message.c_str());
    ros::WallDuration(0.3).sleep();
  }
  return 1;
}
