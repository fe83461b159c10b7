// btr_make_bag: renders the supine phantom of a scene as a depth camera would see it and
// writes a rosbag of organized PointCloud2 messages at 30 Hz with their tf, plus a truth
// file (patient pose, ground-truth tumour centroids in the world frame) for evaluation.
#include <CLI/CLI.hpp>

#include "breast_tumour_registration/cli_checks.h"
#include <rosbag/bag.h>
#include <tf2_msgs/TFMessage.h>
#include <yaml-cpp/yaml.h>

#include <cstdio>
#include <fstream>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/geometry/metrics.h"
#include "breast_tumour_registration/io/scene.h"
#include "breast_tumour_registration/ros/converters.h"
#include "breast_tumour_registration/simulation/depth_camera.h"

using namespace btr;

int main(int argc, char** argv) {
  CLI::App app{"Render the supine surface and chest ring of a scene with a pinhole depth camera (visible side only,\n"
               "depth noise) and write a rosbag of PointCloud2 + /tf at 30 Hz, and <bag>.truth.yaml."};
  std::string scene_path, bag_path = "depth.bag", topic = "/camera/depth/points", camera_frame = "camera_depth_optical_frame",
                          world = "world";
  int frames = 90, width = 640, height = 480;
  double noise_mm = 1.0, distance = 0.45;
  std::vector<double> pose = {0.10, -0.05, 0.75, 0.0, 0.0, 20.0};
  app.add_option("scene", scene_path, "scene file (needs supine.surface; supine.chest_ring is rendered too)")->required();
  app.add_option("-o,--out", bag_path, "bag file")->capture_default_str();
  app.add_option("--frames", frames, "number of clouds (30 Hz)")->capture_default_str()->check(CLI::Range(1, 1000000));
  app.add_option("--noise-mm", noise_mm, "depth noise sigma [mm]")->capture_default_str()->check(btr::cli::non_negative());
  app.add_option("--width", width, "image width [px]")->capture_default_str()->check(CLI::Range(8, 8192));
  app.add_option("--height", height, "image height [px]")->capture_default_str()->check(CLI::Range(8, 8192));
  app.add_option("--distance", distance, "camera distance above the breast [m]")->capture_default_str()->check(btr::cli::positive());
  app.add_option("--patient-pose", pose, "patient (model) frame in the world: x y z [m] roll pitch yaw [deg]")
      ->expected(6)->capture_default_str();
  app.add_option("--topic", topic, "cloud topic")->capture_default_str();
  if (const int rc = btr::cli::parse(app, argc, argv); rc >= 0) return rc;
  try {
    if (frames < 1) throw InputError("--frames must be >= 1");
    const Scene scene = load_scene(scene_path);
    if (!scene.supine_surface) throw InputError(scene_path + ": field 'supine.surface' is needed to render a depth scan");
    const Rigid T_wp = rigid_from_rpy(Vec3(pose[0], pose[1], pose[2]), Vec3(pose[3], pose[4], pose[5]) * M_PI / 180);
    std::vector<SurfaceMesh> world_surfaces = {transform_surface(T_wp, *scene.supine_surface)};
    if (scene.supine_rigid) world_surfaces.push_back(transform_surface(T_wp, *scene.supine_rigid));
    std::vector<const SurfaceMesh*> ptrs;
    for (const auto& s : world_surfaces) ptrs.push_back(&s);
    // Camera above the breast (patient +z is anterior), slightly towards the feet, looking at it.
    const Rigid T_wc = look_at(T_wp * Vec3(0.0, -0.12, distance), T_wp * Vec3(0.0, 0.0, 0.02), T_wp.linear() * Vec3(0, 1, 0));
    PinholeCamera cam;
    cam.width = width;
    cam.height = height;
    cam.cx = (width - 1) / 2.0;
    cam.cy = (height - 1) / 2.0;
    cam.fx = cam.fy = 525.0 * width / 640.0;
    const Points clean = render_depth(ptrs, cam, T_wc);
    long hits = 0;
    for (Eigen::Index i = 0; i < clean.rows(); ++i) hits += clean.row(i).allFinite();
    if (hits == 0) throw InputError("the camera sees nothing of the scene");
    std::mt19937 rng(42);
    rosbag::Bag bag(bag_path, rosbag::bagmode::Write);
    const ros::WallTime wall = ros::WallTime::now();
    const ros::Time t0(wall.sec, wall.nsec);
    for (int i = 0; i < frames; ++i) {
      const ros::Time stamp = t0 + ros::Duration(i / 30.0);
      Points cloud = clean;
      add_depth_noise(cloud, noise_mm * 1e-3, rng);
      sensor_msgs::PointCloud2 msg = ros_conv::to_cloud(cloud, width, height, camera_frame);
      msg.header.stamp = stamp;
      msg.header.seq = i;
      tf2_msgs::TFMessage tf;
      geometry_msgs::TransformStamped t;
      t.header.stamp = stamp;
      t.header.frame_id = world;
      t.child_frame_id = camera_frame;
      t.transform = ros_conv::to_transform(T_wc);
      tf.transforms.push_back(t);
      bag.write("/tf", stamp, tf);
      bag.write(topic, stamp, msg);
    }
    bag.close();
    YAML::Node truth;
    truth["world_frame"] = world;
    truth["patient_pose"] = pose;
    for (const auto& t : scene.tumours)
      if (t.supine_ground_truth) {
        const Vec3 c = T_wp * volume_centroid(*t.supine_ground_truth);
        truth["tumour_centroids"][t.name] = std::vector<double>{c.x(), c.y(), c.z()};
      }
    YAML::Emitter e;
    e << truth;
    std::ofstream(bag_path + ".truth.yaml") << e.c_str() << "\n";
    std::printf("[make_bag] %d clouds of %d x %d (%ld points hit the scene, noise %.1f mm) on %s, tf %s -> %s; wrote %s "
                "and %s.truth.yaml\n",
                frames, width, height, hits, noise_mm, topic.c_str(), world.c_str(), camera_frame.c_str(), bag_path.c_str(),
                bag_path.c_str());
    return 0;
  } catch (const InputError& e) {
    std::fprintf(stderr, "btr_make_bag: invalid input: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "btr_make_bag: error: %s\n", e.what());
    return 1;
  }
}
